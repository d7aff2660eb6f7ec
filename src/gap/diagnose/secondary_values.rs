//! Values of a secondary parameter to simulate: the profile's first grid and the bisection's
//! midpoints, on the parameter's own scale (log-spaced over a wide positive range).

use crate::gap::effects::ParameterInfo;

/// Values of a secondary parameter in the profile's first pass: `n`, log-spaced when its
/// bounds are positive and span more than a factor 20, evenly spaced otherwise, bounds
/// included.
pub fn profile_values(p: &ParameterInfo, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64;
            if p.min > 0.0 && p.max / p.min > 20.0 {
                p.min * (p.max / p.min).powf(t)
            } else {
                p.min + t * (p.max - p.min)
            }
        })
        .collect()
}

/// Midpoint of two values of `p` on the profile's scale.
pub(super) fn midpoint(p: &ParameterInfo, a: f64, b: f64) -> f64 {
    if p.min > 0.0 && p.max / p.min > 20.0 {
        (a * b).sqrt()
    } else {
        0.5 * (a + b)
    }
}

/// The values midway between `values[i]` and each of its neighbours in the ascending
/// `values` (on `p`'s profile scale): a bisection's next values toward the best.
pub(super) fn midpoints_beside(p: &ParameterInfo, values: &[f64], i: usize) -> Vec<f64> {
    let mut more = Vec::new();
    if i > 0 {
        more.push(midpoint(p, values[i - 1], values[i]));
    }
    if i + 1 < values.len() {
        more.push(midpoint(p, values[i], values[i + 1]));
    }
    more
}
