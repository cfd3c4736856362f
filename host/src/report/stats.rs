//! Summary statistics for experiment reports, and the one rule by which
//! `docs/reproduction.md` judges a result reproduced ([`Verdict`]).

/// Two-sided 95 % critical values of Student's t for 1..=30 degrees of freedom.
const T95: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
    2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
    2.052, 2.048, 2.045, 2.042,
];

/// Mean of a sample with the half-width of its 95 % confidence interval
/// (Student's t; 0 for fewer than two values).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanCi {
    /// Sample mean.
    pub mean: f64,
    /// Half-width of the 95 % confidence interval of the mean.
    pub half_width: f64,
}

impl MeanCi {
    /// Summarises a sample; an empty sample has mean 0.
    pub fn of(values: &[f64]) -> MeanCi {
        let n = values.len();
        if n == 0 {
            return MeanCi {
                mean: 0.0,
                half_width: 0.0,
            };
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        if n < 2 {
            return MeanCi {
                mean,
                half_width: 0.0,
            };
        }
        MeanCi {
            mean,
            half_width: t95((n - 1) as f64) * (variance(values) / n as f64).sqrt(),
        }
    }

    /// Lower bound of the interval.
    pub fn low(&self) -> f64 {
        self.mean - self.half_width
    }

    /// Upper bound of the interval.
    pub fn high(&self) -> f64 {
        self.mean + self.half_width
    }
}

/// The two-sided 95 % critical value of Student's t for `df` degrees of
/// freedom, rounded down to a whole number (at least 1; 1.960 above 30).
pub fn t95(df: f64) -> f64 {
    let whole = (df.floor() as usize).max(1);
    T95.get(whole - 1).copied().unwrap_or(1.960)
}

/// The sample variance (over n - 1); 0 for fewer than two values.
fn variance(values: &[f64]) -> f64 {
    let n = values.len();
    if n < 2 {
        return 0.0;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
}

/// A ratio of two means with its 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RatioCi {
    /// The ratio of the means.
    pub ratio: f64,
    /// Lower bound of the interval.
    pub low: f64,
    /// Upper bound of the interval.
    pub high: f64,
}

impl RatioCi {
    /// The mean of `ours` over the mean of `theirs`, with the interval of
    /// the delta method: `ratio ± t · ratio · √(s²ₐ/(nₐ mₐ²) + s²ᵦ/(nᵦ mᵦ²))`,
    /// `t` for the Welch–Satterthwaite degrees of freedom of those two
    /// terms. `theirs` of one value is a figure without spread: the interval
    /// is then our mean's t interval (the tables' ±) over the figure.
    /// `None` when a sample is empty or `theirs`' mean is not positive.
    pub fn of(ours: &[f64], theirs: &[f64]) -> Option<RatioCi> {
        let (na, nb) = (ours.len() as f64, theirs.len() as f64);
        if ours.is_empty() || theirs.is_empty() {
            return None;
        }
        let (ma, mb) = (
            ours.iter().sum::<f64>() / na,
            theirs.iter().sum::<f64>() / nb,
        );
        if mb <= 0.0 {
            return None;
        }
        let ratio = ma / mb;
        // the relative variances of the two means
        let ua = variance(ours) / (na * ma * ma);
        let ub = variance(theirs) / (nb * mb * mb);
        let df = if ua + ub == 0.0 {
            (na - 1.0).max(1.0)
        } else {
            let part = |u: f64, n: f64| if n > 1.0 { u * u / (n - 1.0) } else { 0.0 };
            (ua + ub).powi(2) / (part(ua, na) + part(ub, nb))
        };
        let half = t95(df) * ratio.abs() * (ua + ub).sqrt();
        Some(RatioCi {
            ratio,
            low: ratio - half,
            high: ratio + half,
        })
    }

    /// The interval divided by a figure (a ratio of ours against a ratio
    /// the thesis gives).
    pub fn over(self, figure: f64) -> RatioCi {
        RatioCi {
            ratio: self.ratio / figure,
            low: self.low / figure,
            high: self.high / figure,
        }
    }
}

/// The equivalence margin of [`Verdict`]: ours over theirs from 0.75 to
/// 4/3 (1 / 0.75), symmetric on a log scale.
pub const MARGIN: (f64, f64) = (0.75, 4.0 / 3.0);

/// The one verdict rule of the reproduction page, fixed before rendering:
/// the 95 % interval of the ratio ours / theirs ([`RatioCi`]) against the
/// [`MARGIN`]. Inside it: reproduced (equivalent within the margin);
/// wholly outside it: not reproduced, on the side ours lies; overlapping
/// it without lying inside: inconclusive (the trials cannot tell).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The interval lies inside the margin.
    Reproduced,
    /// The interval overlaps the margin without lying inside it.
    Inconclusive,
    /// The interval lies wholly outside the margin; `higher` when ours is
    /// above it.
    NotReproduced {
        /// Ours above the margin (else below it).
        higher: bool,
    },
}

impl Verdict {
    /// The verdict on an interval of ours / theirs.
    pub fn of(ci: RatioCi) -> Verdict {
        let (low, high) = MARGIN;
        if ci.low >= low && ci.high <= high {
            Verdict::Reproduced
        } else if ci.high < low || ci.low > high {
            Verdict::NotReproduced {
                higher: ci.low > high,
            }
        } else {
            Verdict::Inconclusive
        }
    }

    /// As the page writes it.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::Inconclusive => "inconclusive",
            Verdict::NotReproduced { higher: true } => "not reproduced (ours higher)",
            Verdict::NotReproduced { higher: false } => "not reproduced (ours lower)",
        }
    }
}

/// The median of a sample (the mean of the middle two of an even count);
/// `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some((v[n / 2 - 1] + v[n / 2]) / 2.0),
    }
}

/// A straight line `y = slope x + intercept`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// Slope.
    pub slope: f64,
    /// Value at x = 0.
    pub intercept: f64,
}

impl Line {
    /// The least-squares fit through the points, or `None` for fewer than
    /// two distinct x values.
    pub fn fit(points: &[(f64, f64)]) -> Option<Line> {
        let n = points.len() as f64;
        let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
        let my = points.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        if points.len() < 2 || sxx == 0.0 {
            return None;
        }
        let slope = sxy / sxx;
        Some(Line {
            slope,
            intercept: my - slope * mx,
        })
    }

    /// The line's value at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.slope * x + self.intercept
    }
}

/// The most splits [`permutation_p`] enumerates.
pub const MAX_PERMUTATIONS: u64 = 5_000_000;

/// The two-sided p-value of an exact permutation test of the difference of
/// the means of `a` and `b`: the share of all ways to split the pooled
/// values into groups of their sizes whose difference of means is at least
/// as far from zero as the observed one. `None` if a group is empty or
/// there are more than [`MAX_PERMUTATIONS`] splits.
pub fn permutation_p(a: &[f64], b: &[f64]) -> Option<f64> {
    let (n, total) = (a.len(), a.len() + b.len());
    if a.is_empty() || b.is_empty() || binomial(total as u64, n as u64)? > MAX_PERMUTATIONS {
        return None;
    }
    let pooled: Vec<f64> = a.iter().chain(b).copied().collect();
    let sum: f64 = pooled.iter().sum();
    let difference = |sum_a: f64| sum_a / n as f64 - (sum - sum_a) / (total - n) as f64;
    // a tolerance so that splits equal to the observed one count as equal
    let observed = difference(a.iter().sum()).abs() * (1.0 - 1e-12);
    let (mut extreme, mut splits) = (0u64, 0u64);
    let mut visit = |sum_a: f64| {
        splits += 1;
        if difference(sum_a).abs() >= observed {
            extreme += 1;
        }
    };
    choose(&pooled, n, 0.0, &mut visit);
    Some(extreme as f64 / splits as f64)
}

/// Calls `visit` with the sum of every choice of `k` of `values`.
fn choose(values: &[f64], k: usize, sum: f64, visit: &mut impl FnMut(f64)) {
    if k == 0 {
        visit(sum);
    } else if values.len() >= k {
        choose(&values[1..], k - 1, sum + values[0], visit);
        choose(&values[1..], k, sum, visit);
    }
}

/// `n` choose `k`, if it fits in a u64.
fn binomial(n: u64, k: u64) -> Option<u64> {
    (0..k.min(n - k)).try_fold(1u64, |c, i| Some(c.checked_mul(n - i)? / (i + 1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_interval_match_a_hand_computation() {
        // mean 5, sample sd sqrt(10/4 x ...) : values 2,4,6,8 -> var 20/3
        let ci = MeanCi::of(&[2.0, 4.0, 6.0, 8.0]);
        assert_eq!(ci.mean, 5.0);
        let expected = 3.182 * ((20.0 / 3.0) / 4.0f64).sqrt();
        assert!((ci.half_width - expected).abs() < 1e-12);
        assert_eq!(MeanCi::of(&[3.0]).half_width, 0.0);
        assert_eq!(MeanCi::of(&[]).mean, 0.0);
    }

    /// Ten trials of mean 100 and standard deviation about 3.03: a t
    /// half-width of 2.262 x 3.03 / sqrt(10) = 2.17.
    #[test]
    fn a_ratio_to_a_single_figure_is_the_means_interval_over_it() {
        let ours: Vec<f64> = (0..10).map(|i| 95.5 + i as f64).collect();
        let ci = RatioCi::of(&ours, &[50.0]).unwrap();
        let half = 2.262 * variance(&ours).sqrt() / 10f64.sqrt();
        assert!((ci.ratio - 2.0).abs() < 1e-12);
        assert!((ci.low - (100.0 - half) / 50.0).abs() < 1e-12, "{ci:?}");
        assert!((ci.high - (100.0 + half) / 50.0).abs() < 1e-12, "{ci:?}");
        assert_eq!(RatioCi::of(&ours, &[0.0]), None);
        assert_eq!(RatioCi::of(&[], &[1.0]), None);
    }

    /// Two samples of 4 whose means have relative variances 1/120 each:
    /// the ratio 2, half-width t(6) x 2 x sqrt(1/60) (Welch's df:
    /// (1/60)^2 / (2 (1/120)^2 / 3) = 6).
    #[test]
    fn a_ratio_of_two_means_takes_both_spreads() {
        let ours = [16.0, 18.0, 22.0, 24.0]; // mean 20, variance 40/3
        let theirs = [8.0, 9.0, 11.0, 12.0]; // mean 10, variance 10/3
        let ci = RatioCi::of(&ours, &theirs).unwrap();
        let half = 2.447 * 2.0 * (1.0f64 / 60.0).sqrt();
        assert!((ci.high - 2.0 - half).abs() < 1e-9, "{ci:?} {half}");
        assert_eq!(ci.over(2.0).ratio, 1.0);
    }

    #[test]
    fn verdicts_claim_equality_only_inside_the_margin() {
        let ci = |low, high| RatioCi {
            ratio: (low + high) / 2.0,
            low,
            high,
        };
        assert_eq!(Verdict::of(ci(0.8, 1.3)), Verdict::Reproduced);
        assert_eq!(Verdict::of(ci(0.75, 4.0 / 3.0)), Verdict::Reproduced);
        // a wide interval that holds 1 is not equality
        assert_eq!(Verdict::of(ci(-6.7, 47.0)), Verdict::Inconclusive);
        assert_eq!(Verdict::of(ci(0.5, 0.9)), Verdict::Inconclusive);
        assert_eq!(
            Verdict::of(ci(0.3, 0.74)).label(),
            "not reproduced (ours lower)"
        );
        assert_eq!(
            Verdict::of(ci(1.4, 2.0)).label(),
            "not reproduced (ours higher)"
        );
    }

    #[test]
    fn medians_take_the_middle_or_the_mean_of_the_middle_two() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn least_squares_recovers_a_line() {
        let pts: Vec<(f64, f64)> = (0..10).map(|x| (x as f64, 3.0 * x as f64 - 2.0)).collect();
        let line = Line::fit(&pts).unwrap();
        assert!((line.slope - 3.0).abs() < 1e-12 && (line.intercept + 2.0).abs() < 1e-12);
        assert_eq!(Line::fit(&[(1.0, 1.0), (1.0, 2.0)]), None);
    }
    #[test]
    fn a_permutation_test_counts_every_split_as_extreme_as_the_observed_one() {
        // splits of {1, 2, 3, 4} into two pairs: differences of means
        // +-2 ({1,2}|{3,4}), +-1 ({1,3}|{2,4}), 0 ({1,4}|{2,3}), each twice
        assert_eq!(permutation_p(&[1.0, 2.0], &[3.0, 4.0]), Some(2.0 / 6.0));
        assert_eq!(permutation_p(&[1.0, 3.0], &[2.0, 4.0]), Some(4.0 / 6.0));
        assert_eq!(permutation_p(&[1.0, 4.0], &[2.0, 3.0]), Some(1.0));
        // ten against ten far apart: only the two extreme splits of 184,756
        let low: Vec<f64> = (0..10).map(f64::from).collect();
        let high: Vec<f64> = (100..110).map(f64::from).collect();
        let p = permutation_p(&low, &high).unwrap();
        assert!((p - 2.0 / 184_756.0).abs() < 1e-15, "{p}");
        assert_eq!(permutation_p(&[], &[1.0]), None);
        assert_eq!(permutation_p(&[0.0; 20], &[0.0; 20]), None);
    }
}
