//! The templates of the results pages (`docs/reproduction.md`,
//! `docs/robot-sensors.md` and their experiments' pages): markdown with
//! `{{ ... }}` expressions, each rendered from an experiment's published trials, so
//! that every figure the document states comes from the trials (or is
//! checked against them).
//!
//! An expression is one of (`EXP` is an experiment's name, or several
//! joined by `+` for their sum where that makes sense):
//! - `{{EXP table}}`: its thesis-layout table with the caption;
//! - `{{EXP version}}`: the result formats of its trials (the simulator
//!   versions, `plan::RESULT_FORMAT`), e.g. `2`;
//! - `{{EXP trials}}`, `{{EXP runs}}` (trials and the pre-trainings they
//!   started from), `{{EXP steps}}` (steps simulated, pre-trainings
//!   included), `{{EXP wall}}` (the last run's wall time in its
//!   `wall-time.txt`);
//! - `{{EXP | ARM | QUANTITY | STAT}}`: a statistic over an arm's trials of
//!   a per-trial QUANTITY: `formations`, `stuck`, `first_formation`,
//!   `collisions_per_1000`, `states_visited`, `collision_trend` (the slope,
//!   per step, of the least-squares line through the trial's collisions per
//!   1000-step block), `early_share` (the share of the trial's formations
//!   made in the first fifth of its steps: about 0.2 at a steady rate,
//!   more where the rate falls), or `steps_per_formation` (steps over the
//!   mean formations, STAT `value`). `ARM` may be `A / B`: each trial of A over
//!   the mean of B's. STAT: `mean`, `median`, `min`, `max`, `ci` (the 95 %
//!   half-width), `mean±ci`, `n`, `ratio` (the mean, as a ratio), `percent`,
//!   `times`, `count OP X` (trials with QUANTITY OP X; OP one of `<`, `<=`,
//!   `>`, `>=`, `=`), `thesis` (the thesis' figure from the experiment
//!   file; for `A / B` A's formations ratio, or the ratio of the two arms'
//!   figures), `over_thesis` (the mean over the thesis' figure), `verdict`
//!   (ours against the thesis' figure by the page's one rule, below),
//!   and for `A / B` `verdict X` (our ratio against X, e.g. 1 for
//!   the same), `author` (the mean of the author's own trials, the arm's `author`
//!   values in the experiment file), `author_min`, `author_max`, `over_author`, `author_verdict` (ours
//!   against the author's trials by the same rule), `p` (for `A / B`: the
//!   two-sided p-value of an exact permutation test of the difference of
//!   means, A's trials against B's). `segments STAT` (STAT one of `mean`,
//!   `median`, `min`, `max`, `n`, `verdict`, or for `A / B` `ratio`) is
//!   the same over the trials published with wall segments, before the
//!   clamping border ([`super::published::wall_segments`]: formations,
//!   stuck, first_formation and collisions_per_1000 only);
//! - `{{side-by-side table}}` and `{{side-by-side | ...}}`: the learned
//!   tables of the author's program and ours ([`super::side_by_side`]);
//! - a last part `OP X` checks the number: rendering fails when it does
//!   not hold, since the prose around it says it does.
//!
//! An arm without trials renders `(not run)` and checks nothing.
//!
//! The verdict rule ([`crate::report::stats::Verdict`]), fixed before
//! rendering: the 95 % interval of ours / theirs must lie inside 0.75 to
//! 4/3 for `reproduced`; wholly outside it is `not reproduced`, and
//! overlapping it without lying inside `inconclusive`. Theirs is the
//! thesis' figure (a single number, taken as exact: the interval is our
//! mean's, over it; for `A / B` our ratio of means with the delta method's
//! interval, over the thesis' ratio) or the author's trials (their spread
//! counts too). A verdict renders as `reproduced (L to H)`,
//! `inconclusive (L to H)` or `not reproduced (ours higher: L to H)` /
//! `(ours lower: L to H)`, L and H the interval's bounds with 2 decimals.

use super::metric::Metric;
use super::outputs;
use super::published::{Published, SegmentTrial};
use super::side_by_side::SideBySide;
use super::spec::ExperimentSpec;
use super::trial::{TrialResult, BLOCK_STEPS};
use crate::report::stats::{median, permutation_p, Line, MeanCi, RatioCi, Verdict};
use anyhow::{anyhow, bail, Context, Result};
use std::collections::BTreeSet;
use std::path::PathBuf;

/// The command that renders the results pages again, as errors tell it.
pub const REPORT_COMMAND: &str = "cargo run --release -p host -- experiment report";

/// One experiment as the template sees it.
pub struct Source {
    /// The experiment file.
    pub spec: ExperimentSpec,
    /// Its published trials.
    pub published: Published,
    /// Its published directory (`docs/reproduction/<name>`).
    pub dir: PathBuf,
    /// Its trials published with wall segments, before the clamping border.
    pub segments: Vec<SegmentTrial>,
}

/// What an arm without trials renders as.
pub const NOT_RUN: &str = "(not run)";

/// Renders a template with its experiments and side-by-side runs; errors
/// name the line and the expression.
pub fn render(template: &str, sources: &[Source], side: &SideBySide) -> Result<String> {
    let mut out = String::with_capacity(template.len() * 2);
    for (n, line) in template.split_inclusive('\n').enumerate() {
        let mut rest = line;
        while let Some(open) = rest.find("{{") {
            out.push_str(&rest[..open]);
            let after = &rest[open + 2..];
            let close = after
                .find("}}")
                .ok_or_else(|| anyhow!("template line {}: `{{{{` is not closed", n + 1))?;
            let expr = &after[..close];
            let value = expression(expr.trim(), sources, side)
                .with_context(|| format!("template line {}: {{{{{expr}}}}}", n + 1))?;
            out.push_str(&value);
            rest = &after[close + 2..];
        }
        out.push_str(rest);
    }
    Ok(out)
}

fn expression(expr: &str, sources: &[Source], side: &SideBySide) -> Result<String> {
    let parts: Vec<&str> = expr.split('|').map(str::trim).collect();
    if expr == "side-by-side table" {
        return Ok(side.table());
    }
    if parts[0] == "side-by-side" {
        let (figure, check) = match parts.last().map(|p| comparison(p)) {
            Some(Ok(check)) => (&parts[1..parts.len() - 1], Some(check)),
            _ => (&parts[1..], None),
        };
        let v = side.figure(figure)?;
        let text = match figure {
            [_, "p"] => show_p(v),
            ["runs"] => prose(v),
            [.., f] if f.starts_with("action") => format!("{v:.3}"),
            [.., "median" | "p90"] => format!("{v:.2}"),
            _ => prose(v),
        };
        if let Some((op, x)) = check {
            if !op.holds(v, x) {
                bail!(
                    "the runs give {text}, which is not {}: the text around it needs rewriting",
                    parts[parts.len() - 1]
                );
            }
        }
        return Ok(text);
    }
    if parts.len() == 1 {
        let (names, what) = expr.rsplit_once(' ').ok_or_else(|| {
            anyhow!("expected `EXP table`, `EXP trials`, ... or `EXP | ARM | QUANTITY | STAT`")
        })?;
        let experiments = experiments(names.trim(), sources)?;
        return whole(&experiments, what);
    }
    if !(4..=5).contains(&parts.len()) {
        bail!("expected EXP | ARM | QUANTITY | STAT, and optionally | OP X");
    }
    let source = experiments(parts[0], sources)?
        .into_iter()
        .next()
        .ok_or_else(|| anyhow!("no experiment"))?;
    let stat = statistic(source, parts[1], parts[2], parts[3])?;
    let Some(value) = stat.value else {
        return Ok(stat.text);
    };
    if let Some(check) = parts.get(4) {
        let (op, x) = comparison(check)?;
        if !op.holds(value, x) {
            bail!(
                "the trials give {}, which is not {check}: the text around it needs rewriting",
                stat.text
            );
        }
    }
    Ok(stat.text)
}

/// The experiments named `a+b+...`.
fn experiments<'a>(names: &str, sources: &'a [Source]) -> Result<Vec<&'a Source>> {
    names
        .split('+')
        .map(|n| {
            let n = n.trim();
            sources
                .iter()
                .find(|s| s.spec.name == n)
                .ok_or_else(|| anyhow!("no experiment {n:?}"))
        })
        .collect()
}

/// A figure of whole experiments.
fn whole(experiments: &[&Source], what: &str) -> Result<String> {
    let trials: Vec<&TrialResult> = experiments
        .iter()
        .flat_map(|s| &s.published.results)
        .collect();
    match what {
        "table" => match experiments {
            [s] => Ok(outputs::table(&s.spec, &s.published.results)
                .trim_end()
                .to_string()),
            _ => bail!("`table` takes one experiment"),
        },
        "version" => {
            let formats: BTreeSet<u32> = trials.iter().map(|r| r.format).collect();
            let formats: Vec<String> = formats.iter().map(u32::to_string).collect();
            Ok(match formats.as_slice() {
                [] => NOT_RUN.to_string(),
                [one] => one.clone(),
                [init @ .., last] => format!("{} and {last}", init.join(", ")),
            })
        }
        "trials" => Ok(prose(trials.len() as f64)),
        "runs" => Ok(prose(
            (trials.len() + pretrainings(experiments).len()) as f64,
        )),
        "steps" => {
            let steps = trials.iter().map(|r| r.steps).sum::<u64>()
                + pretrainings(experiments)
                    .iter()
                    .map(|(_, steps)| steps)
                    .sum::<u64>();
            Ok(format!("{} million", prose((steps as f64 / 1e6).round())))
        }
        "wall" => {
            let seconds: Option<u64> = experiments.iter().map(|s| last_run(s)).sum();
            Ok(seconds.map_or_else(
                || "(not recorded)".to_string(),
                |s| {
                    format!(
                        "{} s ({} min)",
                        prose(s as f64),
                        prose((s as f64 / 60.0).round())
                    )
                },
            ))
        }
        _ => bail!("unknown figure {what:?}: expected table, version, trials, runs, steps or wall"),
    }
}

/// The distinct pre-trainings (hash, steps) the published trials started from.
fn pretrainings(experiments: &[&Source]) -> BTreeSet<(String, u64)> {
    let mut out = BTreeSet::new();
    for s in experiments {
        let trials = s
            .published
            .results
            .iter()
            .map(|r| r.trial + 1)
            .max()
            .unwrap_or(0);
        for plan in super::plan::plans(&s.spec, trials, 1.0, s.spec.seed) {
            let published = s
                .published
                .results
                .iter()
                .any(|r| r.arm == plan.arm && r.trial == plan.trial);
            if let (true, Some(p)) = (published, plan.pretrain) {
                out.insert((p.hash, p.config.steps));
            }
        }
    }
    out
}

/// Seconds of the last line of the experiment's `wall-time.txt`
/// (`NAME: S s wall time ...`).
fn last_run(s: &Source) -> Option<u64> {
    let text = std::fs::read_to_string(s.dir.join("wall-time.txt")).ok()?;
    let line = text.lines().rev().find(|l| !l.trim().is_empty())?;
    line.split_once(": ")?
        .1
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// A rendered statistic and the number it stands for (none for text).
struct Stat {
    text: String,
    value: Option<f64>,
}

impl Stat {
    fn number(v: f64, text: String) -> Stat {
        Stat {
            text,
            value: Some(v),
        }
    }

    fn text(text: &str) -> Stat {
        Stat {
            text: text.to_string(),
            value: None,
        }
    }
}

/// A per-trial figure.
#[derive(Clone, Copy, PartialEq)]
enum Quantity {
    Formations,
    Stuck,
    FirstFormation,
    Collisions,
    StatesVisited,
    CollisionTrend,
    EarlyShare,
    StepsPerFormation,
}

impl Quantity {
    fn parse(s: &str) -> Result<Quantity> {
        Ok(match s {
            "formations" => Quantity::Formations,
            "stuck" => Quantity::Stuck,
            "first_formation" => Quantity::FirstFormation,
            "collisions_per_1000" => Quantity::Collisions,
            "states_visited" => Quantity::StatesVisited,
            "collision_trend" => Quantity::CollisionTrend,
            "early_share" => Quantity::EarlyShare,
            "steps_per_formation" => Quantity::StepsPerFormation,
            _ => bail!("unknown quantity {s:?}: expected formations, stuck, first_formation, collisions_per_1000, states_visited, collision_trend, early_share or steps_per_formation"),
        })
    }

    fn of(self, r: &TrialResult) -> Option<f64> {
        match self {
            Quantity::Formations | Quantity::StepsPerFormation => Some(r.formations as f64),
            Quantity::Stuck => Some(r.stuck as f64),
            Quantity::FirstFormation => r.formation_steps.first().map(|&s| s as f64),
            Quantity::Collisions => Some(r.collisions_per_1000),
            Quantity::StatesVisited => r.states_visited.map(|v| v as f64),
            Quantity::CollisionTrend => {
                let points: Vec<(f64, f64)> = r
                    .collisions_per_block
                    .iter()
                    .enumerate()
                    .map(|(b, &c)| (((b as u64 + 1) * BLOCK_STEPS) as f64, c as f64))
                    .collect();
                Line::fit(&points).map(|l| l.slope)
            }
            Quantity::EarlyShare => {
                let early = r
                    .formation_steps
                    .iter()
                    .filter(|&&s| s < r.steps / 5)
                    .count();
                (r.formations > 0).then(|| early as f64 / r.formations as f64)
            }
        }
    }

    /// The figure of a trial published with wall segments; an error for
    /// the figures that file does not keep.
    fn of_segment(self, r: &SegmentTrial) -> Result<Option<f64>> {
        Ok(match self {
            Quantity::Formations => Some(r.formations as f64),
            Quantity::Stuck => Some(r.stuck as f64),
            Quantity::FirstFormation => r.first_formation.map(|s| s as f64),
            Quantity::Collisions => Some(r.collisions_per_1000),
            _ => bail!("the trials with wall segments keep formations, stuck, first_formation and collisions_per_1000 only"),
        })
    }

    /// The experiment files' figure of this quantity.
    fn metric(self) -> Option<Metric> {
        match self {
            Quantity::Formations => Some(Metric::Formations),
            Quantity::Stuck => Some(Metric::Stuck),
            Quantity::FirstFormation => Some(Metric::FirstFormation),
            Quantity::Collisions => Some(Metric::CollisionsPer1000),
            Quantity::StatesVisited => Some(Metric::StatesVisited),
            Quantity::StepsPerFormation => Some(Metric::StepsPerFormation),
            Quantity::CollisionTrend | Quantity::EarlyShare => None,
        }
    }
}

/// The thesis' figure of `q` for arm `a`, or for `a / b`: `a`'s
/// formations ratio if the file gives one, else the ratio of the two arms'.
fn thesis(spec: &ExperimentSpec, a: &str, b: Option<&str>, q: Quantity) -> Result<f64> {
    let m = q
        .metric()
        .ok_or_else(|| anyhow!("the thesis gives no such figure"))?;
    let of = |name: &str, m: Metric| -> Result<f64> {
        let arm = spec
            .arm(name)
            .ok_or_else(|| anyhow!("{} has no arm {name:?}", spec.name))?;
        arm.thesis.get(&m).copied().ok_or_else(|| {
            anyhow!(
                "{}: arm {name:?} has no thesis figure for {}",
                spec.name,
                m.label()
            )
        })
    };
    match b {
        None => of(a, m),
        Some(b) => match of(a, Metric::FormationsRatio) {
            Ok(ratio) if q == Quantity::Formations => Ok(ratio),
            _ => Ok(of(a, m)? / of(b, m)?),
        },
    }
}

/// The per-trial values of the author's own program for `q` of arm `a`.
fn author<'a>(spec: &'a ExperimentSpec, a: &str, q: Quantity) -> Result<&'a [f64]> {
    let m = q
        .metric()
        .ok_or_else(|| anyhow!("the author's files give no such figure"))?;
    let arm = spec
        .arm(a)
        .ok_or_else(|| anyhow!("{} has no arm {a:?}", spec.name))?;
    match arm.author.get(&m) {
        Some(values) if !values.is_empty() => Ok(values),
        _ => bail!(
            "{}: arm {a:?} has no author's trials for {}",
            spec.name,
            m.label()
        ),
    }
}

fn statistic(source: &Source, arms: &str, quantity: &str, stat: &str) -> Result<Stat> {
    let spec = &source.spec;
    let q = Quantity::parse(quantity)?;
    let (a, b) = match arms.split_once(" / ") {
        Some((a, b)) => (a.trim(), Some(b.trim())),
        None => (arms, None),
    };
    spec.arm(a)
        .ok_or_else(|| anyhow!("{} has no arm {a:?}", spec.name))?;
    let of_arm = |name: &str| -> Vec<&TrialResult> {
        source
            .published
            .results
            .iter()
            .filter(|r| r.arm == name)
            .collect()
    };
    if stat == "thesis" {
        let v = thesis(spec, a, b, q)?;
        return Ok(Stat::number(
            v,
            if b.is_some() {
                format!("{v:.2}")
            } else {
                prose(v)
            },
        ));
    }
    if let Some(which) = stat.strip_prefix("author") {
        let values = author(spec, a, q)?;
        let v = match which {
            "" => Some(values.iter().sum::<f64>() / values.len() as f64),
            "_min" => values.iter().copied().reduce(f64::min),
            "_max" => values.iter().copied().reduce(f64::max),
            _ => None,
        };
        if let Some(v) = v {
            return Ok(Stat::number(v, prose(v)));
        }
    }
    if let Some(stat) = stat.strip_prefix("segments ") {
        return segments(source, a, b, q, stat.trim());
    }
    let trials = of_arm(a);
    if trials.is_empty() {
        return Ok(Stat::text(NOT_RUN));
    }
    if q == Quantity::StepsPerFormation {
        let mean = trials.iter().map(|r| r.formations as f64).sum::<f64>() / trials.len() as f64;
        let v = trials[0].steps as f64 / mean;
        return Ok(if mean > 0.0 {
            Stat::number(v, prose(v))
        } else {
            Stat::text("–")
        });
    }
    let mut values: Vec<f64> = trials.iter().filter_map(|r| q.of(r)).collect();
    if let Some(b) = b {
        spec.arm(b)
            .ok_or_else(|| anyhow!("{} has no arm {b:?}", spec.name))?;
        let reference: Vec<f64> = of_arm(b).iter().filter_map(|r| q.of(r)).collect();
        if reference.is_empty() {
            return Ok(Stat::text(NOT_RUN));
        }
        if stat == "p" {
            let p = permutation_p(&values, &reference)
                .ok_or_else(|| anyhow!("too many trials for an exact permutation test"))?;
            return Ok(Stat::number(p, show_p(p)));
        }
        if let Some(figure) = stat.strip_prefix("verdict") {
            let figure = match figure.trim() {
                "" => thesis(spec, a, Some(b), q)?,
                x => x
                    .parse()
                    .map_err(|_| anyhow!("verdict {x:?}: expected a number"))?,
            };
            return Ok(Stat::text(&judge(RatioCi::of(&values, &reference), figure)));
        }
        let mean = reference.iter().sum::<f64>() / reference.len() as f64;
        values.iter_mut().for_each(|v| *v /= mean);
    }
    if values.is_empty() {
        return Ok(Stat::text("–"));
    }
    let show = |v: f64| match (q, b.is_some()) {
        (Quantity::CollisionTrend, _) => format!("{v:+.1e}"),
        (_, true) => format!("{v:.2}"),
        _ => prose(v),
    };
    let ci = MeanCi::of(&values);
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let number = |v: f64| Ok(Stat::number(v, show(v)));
    match stat {
        "mean" | "ratio" => number(ci.mean),
        "median" => number(median(&values).unwrap_or(f64::NAN)),
        "min" => number(min),
        "max" => number(max),
        "ci" => number(ci.half_width),
        "mean±ci" => Ok(Stat::number(
            ci.mean,
            format!("{} ± {}", show(ci.mean), show(ci.half_width)),
        )),
        "n" => Ok(Stat::number(
            values.len() as f64,
            prose(values.len() as f64),
        )),
        "percent" => Ok(Stat::number(
            ci.mean * 100.0,
            format!("{:.0} %", ci.mean * 100.0),
        )),
        "times" => Ok(Stat::number(ci.mean, format!("{:.1}x", ci.mean))),
        "over_thesis" => {
            let v = ci.mean / thesis(spec, a, b, q)?;
            Ok(Stat::number(v, format!("{v:.2}")))
        }
        "over_author" | "author_verdict" if b.is_some() => {
            bail!("{stat} compares one arm with the author's trials, not a ratio")
        }
        "over_author" => {
            let theirs = author(spec, a, q)?;
            let v = ci.mean / (theirs.iter().sum::<f64>() / theirs.len() as f64);
            Ok(Stat::number(v, format!("{v:.2}")))
        }
        "p" => bail!("p compares two arms' trials: A / B"),
        "author_verdict" => Ok(Stat::text(&judge(
            RatioCi::of(&values, author(spec, a, q)?),
            1.0,
        ))),
        "verdict" => Ok(Stat::text(&judge(
            RatioCi::of(&values, &[thesis(spec, a, b, q)?]),
            1.0,
        ))),
        _ => {
            if let Some(cond) = stat.strip_prefix("count") {
                let (op, x) = comparison(cond.trim())?;
                let n = values.iter().filter(|&&v| op.holds(v, x)).count() as f64;
                return Ok(Stat::number(n, prose(n)));
            }
            bail!("unknown statistic {stat:?}: expected mean, median, min, max, ci, mean±ci, n, ratio, percent, times, over_thesis, count OP X, thesis, verdict, author, over_author, author_verdict, p or segments STAT")
        }
    }
}

/// A p-value: three decimals, or "< 0.001".
fn show_p(p: f64) -> String {
    if p < 0.001 {
        "< 0.001".into()
    } else {
        format!("{p:.3}")
    }
}

/// The page's verdict on the interval of ours / theirs, divided by
/// `figure` (the thesis' ratio for `A / B`, else 1), with the interval.
fn judge(ci: Option<RatioCi>, figure: f64) -> String {
    let Some(ci) = ci.filter(|_| figure > 0.0).map(|ci| ci.over(figure)) else {
        return "– (no positive figure to compare with)".to_string();
    };
    // 2 decimals, without the sign of a bound that rounds to zero
    let show = |v: f64| format!("{:.2}", if v.abs() < 0.005 { 0.0 } else { v });
    let bounds = format!("{} to {}", show(ci.low), show(ci.high));
    match Verdict::of(ci) {
        Verdict::NotReproduced { higher } => format!(
            "not reproduced (ours {}: {bounds})",
            if higher { "higher" } else { "lower" }
        ),
        v => format!("{} ({bounds})", v.label()),
    }
}

/// A statistic of the trials published with wall segments.
fn segments(source: &Source, a: &str, b: Option<&str>, q: Quantity, stat: &str) -> Result<Stat> {
    let of_arm = |name: &str| -> Result<Vec<f64>> {
        let rows: Vec<&SegmentTrial> = source.segments.iter().filter(|r| r.arm == name).collect();
        if rows.is_empty() {
            bail!(
                "{}: arm {name:?} has no trials with wall segments",
                source.spec.name
            );
        }
        rows.into_iter()
            .map(|r| q.of_segment(r))
            .filter_map(Result::transpose)
            .collect()
    };
    let values = of_arm(a)?;
    let show = |v: f64| {
        Ok(Stat::number(
            v,
            if b.is_some() {
                format!("{v:.2}")
            } else {
                prose(v)
            },
        ))
    };
    match (stat, b) {
        ("verdict", None) => Ok(Stat::text(&judge(
            RatioCi::of(&values, &[thesis(&source.spec, a, b, q)?]),
            1.0,
        ))),
        ("verdict", Some(b)) => Ok(Stat::text(&judge(
            RatioCi::of(&values, &of_arm(b)?),
            thesis(&source.spec, a, Some(b), q)?,
        ))),
        ("ratio", Some(b)) => {
            let ci = RatioCi::of(&values, &of_arm(b)?)
                .ok_or_else(|| anyhow!("no ratio of {a:?} to {b:?}"))?;
            show(ci.ratio)
        }
        (_, Some(_)) => bail!("segments of A / B: expected verdict or ratio"),
        (_, None) if values.is_empty() => Ok(Stat::text("–")),
        ("mean", None) => show(MeanCi::of(&values).mean),
        ("median", None) => show(median(&values).unwrap_or(f64::NAN)),
        ("min", None) => show(values.iter().copied().fold(f64::INFINITY, f64::min)),
        ("max", None) => show(values.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
        ("n", None) => show(values.len() as f64),
        _ => bail!("unknown statistic segments {stat:?}: expected mean, median, min, max, n, verdict or ratio"),
    }
}

/// A comparison operator.
#[derive(Clone, Copy)]
enum Op {
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
}

impl Op {
    fn holds(self, v: f64, x: f64) -> bool {
        match self {
            Op::Lt => v < x,
            Op::Le => v <= x,
            Op::Gt => v > x,
            Op::Ge => v >= x,
            Op::Eq => v == x,
        }
    }
}

/// `OP X`, e.g. `<= 10`.
fn comparison(s: &str) -> Result<(Op, f64)> {
    let s = s.trim();
    let (op, rest) = [
        ("<=", Op::Le),
        (">=", Op::Ge),
        ("<", Op::Lt),
        (">", Op::Gt),
        ("=", Op::Eq),
    ]
    .into_iter()
    .find_map(|(token, op)| s.strip_prefix(token).map(|rest| (op, rest)))
    .ok_or_else(|| anyhow!("{s:?}: expected OP X with OP one of <, <=, >, >=, ="))?;
    let x = rest
        .trim()
        .replace(',', "")
        .parse()
        .map_err(|_| anyhow!("{s:?}: {:?} is not a number", rest.trim()))?;
    Ok((op, x))
}

/// A number as prose writes it: whole numbers and numbers from 1,000 up
/// with thousands separators, others with 1 decimal from 10 up, else 2.
pub fn prose(v: f64) -> String {
    if !v.is_finite() {
        return "–".to_string();
    }
    let a = v.abs();
    if v.fract() == 0.0 || a >= 1000.0 {
        let digits = format!("{:.0}", a);
        let mut grouped = String::new();
        for (i, c) in digits.chars().enumerate() {
            if i > 0 && (digits.len() - i) % 3 == 0 {
                grouped.push(',');
            }
            grouped.push(c);
        }
        format!(
            "{}{grouped}",
            if v < 0.0 && v.round() != 0.0 { "-" } else { "" }
        )
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prose_numbers_group_thousands_and_round_by_size() {
        assert_eq!(prose(31700.0), "31,700");
        assert_eq!(prose(1234567.4), "1,234,567");
        assert_eq!(prose(703.34), "703.3");
        assert_eq!(prose(731.0), "731");
        assert_eq!(prose(0.456), "0.46");
        assert_eq!(prose(-1500.0), "-1,500");
        assert_eq!(prose(f64::NAN), "–");
    }

    /// One experiment with two arms whose trials formed `a` and `b` shapes.
    fn sources(a: &[u64], b: &[u64]) -> Vec<Source> {
        let text = "title = \"t\"\n[[arms]]\nname = \"A\"\nthesis = { formations = 10 }\nauthor = { formations = [9, 10, 11] }\n[[arms]]\nname = \"B\"\n";
        let spec = ExperimentSpec::parse("x", text).unwrap();
        let trial = |arm: &str, i: usize, formations: u64| TrialResult {
            format: 2,
            config_hash: String::new(),
            experiment: "x".into(),
            arm: arm.into(),
            trial: i,
            seed: 0,
            steps: 1000,
            formations,
            stuck: 0,
            formation_steps: (1..=formations).map(|s| s * 10).collect(),
            collisions_per_1000: 0.0,
            collisions_per_block: vec![],
            states_visited: None,
            states_total: None,
            steps_per_second: 0.0,
            seconds: 0.0,
        };
        let mut results: Vec<TrialResult> = a
            .iter()
            .enumerate()
            .map(|(i, &f)| trial("A", i, f))
            .collect();
        results.extend(b.iter().enumerate().map(|(i, &f)| trial("B", i, f)));
        vec![Source {
            spec,
            published: Published {
                results,
                stale: vec![],
            },
            dir: PathBuf::from("/nonexistent"),
            segments: [("A", 20), ("A", 22), ("B", 10), ("B", 12)]
                .iter()
                .enumerate()
                .map(|(trial, &(arm, formations))| SegmentTrial {
                    arm: arm.into(),
                    trial,
                    formations,
                    stuck: 0,
                    first_formation: None,
                    collisions_per_1000: 0.0,
                })
                .collect(),
        }]
    }

    #[test]
    fn expressions_render_statistics_ratios_counts_and_checks() {
        let s = sources(&[8, 12, 13], &[4, 6]);
        let r = |t: &str| render(t, &s, &SideBySide::default());
        assert_eq!(
            r("{{x | A | formations | mean}} of {{x | A | formations | thesis}}").unwrap(),
            "11 of 10"
        );
        assert_eq!(
            r("{{x | A | formations | median}} {{x | A | formations | count > 9}}").unwrap(),
            "12 2"
        );
        assert_eq!(
            r("{{x | A / B | formations | ratio}} {{x | A / B | formations | times}}").unwrap(),
            "2.20 2.2x"
        );
        assert_eq!(
            r("{{x | A | first_formation | max}} {{x trials}} {{x version}}").unwrap(),
            "10 5 2"
        );
        assert_eq!(
            r("{{x | A | formations | over_thesis | > 1}}").unwrap(),
            "1.10"
        );
        let broken = r("line\n{{x | A | formations | mean | < 11}}").unwrap_err();
        assert!(
            format!("{broken:#}").contains("line 2") && format!("{broken:#}").contains("not < 11"),
            "{broken:#}"
        );
        let none = sources(&[], &[]);
        assert_eq!(
            render(
                "{{x | A | formations | mean | > 5}}",
                &none,
                &SideBySide::default()
            )
            .unwrap(),
            NOT_RUN,
            "no trials: nothing to check"
        );
    }

    /// Of the 10 splits of {8, 12, 13, 4, 6} into 3 and 2, two have means
    /// at least the observed 11 - 5 apart: the observed one and
    /// {4, 6, 8} | {12, 13}.
    #[test]
    fn arms_are_tested_against_each_other_and_against_the_authors_trials() {
        let s = sources(&[8, 12, 13], &[4, 6]);
        let r = |t: &str| render(t, &s, &SideBySide::default()).unwrap();
        assert_eq!(r("{{x | A / B | formations | p}}"), "0.200");
        assert!(r("{{x | A / B | formations | verdict 1}}").starts_with("inconclusive"));
        assert_eq!(r("{{x | A | formations | author}}"), "10");
        assert_eq!(
            r("{{x | A | formations | author_min}} {{x | A | formations | author_max}}"),
            "9 11"
        );
        assert_eq!(r("{{x | A | formations | over_author}}"), "1.10");
        // mean 11 against 10; relative variances 7/363 and 1/300, Welch's
        // df 2.67 (t for 2 df: 4.303): 1.1 ± 4.303 x 1.1 x 0.1504
        assert_eq!(
            r("{{x | A | formations | author_verdict}}"),
            "inconclusive (0.39 to 1.81)"
        );
        let e = |t: &str| format!("{:#}", render(t, &s, &SideBySide::default()).unwrap_err());
        assert!(e("{{x | A | formations | p}}").contains("A / B"));
        assert!(e("{{x | B | formations | author}}").contains("no author's trials"));
    }

    /// Trials of 1,000 steps with formations every 10 steps: 30 of them
    /// make 19 in the first 200 steps, 8 make all theirs there.
    #[test]
    fn the_early_share_is_the_part_of_a_trials_formations_in_its_first_fifth() {
        let s = sources(&[30, 8], &[]);
        assert_eq!(
            render(
                "{{x | A | early_share | percent}}",
                &s,
                &SideBySide::default()
            )
            .unwrap(),
            "82 %"
        );
        assert_eq!(
            render("{{x | A | early_share | min}}", &s, &SideBySide::default()).unwrap(),
            "0.63"
        );
        assert!(render(
            "{{x | A | early_share | percent | < 80}}",
            &s,
            &SideBySide::default()
        )
        .is_err());
    }

    #[test]
    fn bad_expressions_are_named() {
        let s = sources(&[1], &[1]);
        let e = |t: &str| format!("{:#}", render(t, &s, &SideBySide::default()).unwrap_err());
        assert!(e("{{x | C | formations | mean}}").contains("no arm \"C\""));
        assert!(e("{{y | A | formations | mean}}").contains("no experiment \"y\""));
        assert!(e("{{x | A | speed | mean}}").contains("unknown quantity \"speed\""));
        assert!(e("{{x | A | formations | mode}}").contains("unknown statistic \"mode\""));
        assert!(e("{{x | B | formations | thesis}}").contains("no thesis figure"));
        assert!(e("{{x | A | formations | mean").contains("not closed"));
        assert!(e("{{x | A | formations | mean | ~ 3}}").contains("expected OP X"));
    }

    /// {8, 12, 13}: mean 11, half-width 4.303 x sqrt(7 / 3) = 6.57 over
    /// the thesis' 10: a wide interval that holds 1 is inconclusive.
    #[test]
    fn verdicts_claim_reproduction_only_within_the_margin() {
        let r = |a: &[u64], b: &[u64], t: &str| {
            render(t, &sources(a, b), &SideBySide::default()).unwrap()
        };
        assert_eq!(
            r(&[8, 12, 13], &[4, 6], "{{x | A | formations | verdict}}"),
            "inconclusive (0.44 to 1.76)"
        );
        assert_eq!(
            r(&[10, 11, 10, 11], &[1], "{{x | A | formations | verdict}}"),
            "reproduced (0.96 to 1.14)"
        );
        assert_eq!(
            r(&[20, 21, 20, 21], &[1], "{{x | A | formations | verdict}}"),
            "not reproduced (ours higher: 1.96 to 2.14)"
        );
        // the trials with wall segments, by the same rule: 21 ± 12.71 x 1
        assert_eq!(
            r(&[1], &[1], "{{x | A | formations | segments mean}} {{x | A | formations | segments verdict}} {{x | A / B | formations | segments ratio}}"),
            "21 inconclusive (0.83 to 3.37) 1.91"
        );
    }
}
