//! Small statistics of the diagnosis: tail probabilities (statrs), multiple-comparison
//! corrections and a deterministic bootstrap.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

/// Upper tail `P(X >= x)` of a chi-square with `dof` degrees of freedom (1 when `dof` = 0).
pub fn chi2_sf(x: f64, dof: usize) -> f64 {
    if dof == 0 || !x.is_finite() {
        return if x.is_finite() { 1.0 } else { 0.0 };
    }
    ChiSquared::new(dof as f64).map_or(f64::NAN, |d| d.sf(x.max(0.0)))
}

/// The `x` whose upper chi-square tail (`dof` degrees of freedom, at least 1) is `p`.
pub fn chi2_isf(p: f64, dof: usize) -> f64 {
    ChiSquared::new(dof.max(1) as f64).map_or(f64::NAN, |d| d.inverse_cdf(1.0 - p.clamp(0.0, 1.0)))
}

/// Lack-of-fit p-value of a fit with `k` parameters leaving `chi2` over a weighted
/// observation count `n`: the chi-square tail at `n - k` degrees of freedom (at least 1).
pub fn lack_of_fit_p(chi2: f64, n: f64, k: f64) -> f64 {
    chi2_sf(chi2, (n - k).round().max(1.0) as usize)
}

/// Corrected Akaike information criterion of a fit with `k` parameters, negative
/// log-likelihood `nll`, over a weighted observation count `n`.
pub fn aicc(k: f64, nll: f64, n: f64) -> f64 {
    2.0 * k + 2.0 * nll + 2.0 * k * (k + 1.0) / (n - k - 1.0).max(1.0)
}

/// Two-sided p-value of a standard normal score.
pub fn normal_two_sided(z: f64) -> f64 {
    if !z.is_finite() {
        return 0.0;
    }
    Normal::new(0.0, 1.0).map_or(f64::NAN, |d| 2.0 * d.sf(z.abs()))
}

/// Holm's step-down adjustment (controls the family-wise error rate): adjusted p-values in the
/// input order.
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut out = vec![1.0; m];
    let mut running: f64 = 0.0;
    for (rank, &i) in order.iter().enumerate() {
        let adj = ((m - rank) as f64 * p[i]).min(1.0);
        running = running.max(adj);
        out[i] = running;
    }
    out
}

/// Indices of a bootstrap resample of `n` groups for each of `rounds` rounds (fixed seed: the
/// report is reproducible).
pub fn bootstrap_indices(n: usize, rounds: usize, seed: u64) -> Vec<Vec<usize>> {
    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    (0..rounds)
        .map(|_| (0..n).map(|_| rng.gen_range(0..n.max(1))).collect())
        .collect()
}

/// The `q` quantile (0..1) of `values` (linear interpolation between order statistics).
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    v[lo] + (pos - lo as f64) * (v[hi] - v[lo])
}

/// Median of `values`.
pub fn median(values: &[f64]) -> f64 {
    quantile(values, 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: chi-square with 2 dof has sf = exp(-x/2); with 1 dof at 3.841 it is 0.05.
    #[test]
    fn chi_square_tails_match_closed_forms() {
        for x in [0.1, 1.0, 4.0, 10.0] {
            assert!((chi2_sf(x, 2) - (-x / 2.0f64).exp()).abs() < 1e-12);
        }
        assert!((chi2_sf(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-9);
        assert!((normal_two_sided(1.959_963_984_540_054) - 0.05).abs() < 1e-9);
    }

    /// Holm on (0.01, 0.04, 0.03) with m = 3: 0.03, min(1, 0.06 max 0.03)=0.06, 0.06.
    #[test]
    fn holm_by_hand() {
        let a = holm(&[0.01, 0.04, 0.03]);
        assert!((a[0] - 0.03).abs() < 1e-15);
        assert!((a[2] - 0.06).abs() < 1e-15);
        assert!((a[1] - 0.06).abs() < 1e-15);
    }

    #[test]
    fn quantiles_interpolate() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(quantile(&[0.0, 10.0], 0.25), 2.5);
    }
}
