//! The figures an experiment table reports, computed over an arm's trials.

use super::metric::Metric;
use super::trial::TrialResult;
use crate::report::stats::MeanCi;

/// An arm's figure: a mean with its 95 % interval over trials, a single
/// derived number, or nothing (no trial has the figure).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// Mean over trials and the half-width of its 95 % interval; `n` trials.
    Mean {
        /// Mean and interval.
        ci: MeanCi,
        /// Trials that have the figure.
        n: usize,
        /// Trials in all (a first formation is missing from a trial that
        /// never formed).
        of: usize,
    },
    /// A figure derived from means (steps per formation, ratios).
    Derived(f64),
    /// No trial has it.
    Missing,
}

impl Value {
    /// As a table cell: `mean ± half-width`, or `–`; a mean over fewer
    /// than all trials says over how many (`(9 of 10 trials)`).
    pub fn cell(self) -> String {
        match self {
            Value::Mean { ci, n, of } => {
                let mean = if n > 1 {
                    format!("{} ± {}", number(ci.mean), number(ci.half_width))
                } else {
                    number(ci.mean)
                };
                if n < of {
                    format!("{mean} ({n} of {of} trials)")
                } else {
                    mean
                }
            }
            Value::Derived(v) if v.is_finite() => number(v),
            _ => "–".into(),
        }
    }
}

/// A number with precision suited to its size.
pub fn number(v: f64) -> String {
    let a = v.abs();
    if a >= 1000.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// One figure of one arm's trials; `reference` is the `ratio_to` arm's.
pub fn value(metric: Metric, trials: &[TrialResult], reference: Option<&[TrialResult]>) -> Value {
    let mean_of = |f: &dyn Fn(&TrialResult) -> Option<f64>| {
        let values: Vec<f64> = trials.iter().filter_map(f).collect();
        if values.is_empty() {
            Value::Missing
        } else {
            Value::Mean {
                ci: MeanCi::of(&values),
                n: values.len(),
                of: trials.len(),
            }
        }
    };
    let mean_formations = |ts: &[TrialResult]| {
        (!ts.is_empty())
            .then(|| ts.iter().map(|t| t.formations as f64).sum::<f64>() / ts.len() as f64)
    };
    match metric {
        Metric::Formations => mean_of(&|t| Some(t.formations as f64)),
        Metric::Stuck => mean_of(&|t| Some(t.stuck as f64)),
        Metric::StepsPerFormation => match (mean_formations(trials), trials.first()) {
            (Some(f), Some(t)) if f > 0.0 => Value::Derived(t.steps as f64 / f),
            _ => Value::Missing,
        },
        Metric::FirstFormation => mean_of(&|t| t.formation_steps.first().map(|&s| s as f64)),
        Metric::CollisionsPer1000 => mean_of(&|t| Some(t.collisions_per_1000)),
        Metric::FormationsRatio => {
            match (mean_formations(trials), reference.and_then(mean_formations)) {
                (Some(a), Some(b)) if b > 0.0 => Value::Derived(a / b),
                _ => Value::Missing,
            }
        }
        Metric::StatesVisited => mean_of(&|t| t.states_visited.map(|v| v as f64)),
        Metric::StepsPerSecond => mean_of(&|t| Some(t.steps_per_second)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mean_over_fewer_than_all_trials_says_over_how_many() {
        let ci = MeanCi::of(&[100.0, 200.0]);
        assert_eq!(
            Value::Mean { ci, n: 2, of: 3 }.cell(),
            "150.0 ± 635.3 (2 of 3 trials)"
        );
        assert_eq!(Value::Mean { ci, n: 2, of: 2 }.cell(), "150.0 ± 635.3");
        assert_eq!(Value::Missing.cell(), "–");
    }
}
