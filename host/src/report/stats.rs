//! Summary statistics for experiment reports.

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
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let t = T95.get(n - 2).copied().unwrap_or(1.960);
        MeanCi {
            mean,
            half_width: t * (var / n as f64).sqrt(),
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
