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

/// Decades below its bound a threshold starting at 0 is profiled over
/// ([`threshold_values`]).
pub const THRESHOLD_DECADES: f64 = 3.0;

/// Values of a wear law's threshold over its whole range: as [`profile_values`], except that a
/// threshold whose range starts at 0 is tried at 0 and at `n - 1` values log-spaced over the
/// [`THRESHOLD_DECADES`] decades below its bound (a slip-speed threshold of 0.1 mm/s and one of
/// 1 mm/s act as differently on the tracks as 1 and 10 cm/s; evenly spaced values would try
/// nothing between 0 and an eighth of the bound).
pub fn threshold_values(p: &ParameterInfo, n: usize) -> Vec<f64> {
    if !zero_log(p) {
        return profile_values(p, n);
    }
    let lo = p.max * 10f64.powf(-THRESHOLD_DECADES);
    std::iter::once(0.0)
        .chain((0..n - 1).map(|i| lo * (p.max / lo).powf(i as f64 / (n - 2).max(1) as f64)))
        .collect()
}

/// Whether `p` is a threshold from 0 profiled on [`threshold_values`]' scale.
fn zero_log(p: &ParameterInfo) -> bool {
    p.min == 0.0 && p.max > 0.0
}

/// Midpoint of two values of `p` on the profile's scale.
pub(super) fn midpoint(p: &ParameterInfo, a: f64, b: f64) -> f64 {
    if p.min > 0.0 && p.max / p.min > 20.0 {
        (a * b).sqrt()
    } else {
        0.5 * (a + b)
    }
}

/// Midpoint of two values of a threshold on [`threshold_values`]' scale (geometric between
/// positive values, half the other from 0).
pub(super) fn threshold_midpoint(p: &ParameterInfo, a: f64, b: f64) -> f64 {
    if zero_log(p) {
        if a > 0.0 && b > 0.0 {
            (a * b).sqrt()
        } else {
            0.5 * (a + b)
        }
    } else {
        midpoint(p, a, b)
    }
}

/// The values midway between `values[i]` and each of its neighbours in the ascending
/// `values` (on `p`'s profile scale): a bisection's next values toward the best.
pub(super) fn midpoints_beside(p: &ParameterInfo, values: &[f64], i: usize) -> Vec<f64> {
    beside(values, i, |a, b| midpoint(p, a, b))
}

/// [`midpoints_beside`] on [`threshold_values`]' scale.
pub(super) fn threshold_midpoints_beside(p: &ParameterInfo, values: &[f64], i: usize) -> Vec<f64> {
    beside(values, i, |a, b| threshold_midpoint(p, a, b))
}

fn beside(values: &[f64], i: usize, mid: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    let mut more = Vec::new();
    if i > 0 {
        more.push(mid(values[i - 1], values[i]));
    }
    if i + 1 < values.len() {
        more.push(mid(values[i], values[i + 1]));
    }
    more
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gap::effects;

    fn param(effect: &str, name: &str) -> &'static ParameterInfo {
        effects::info(effect)
            .unwrap()
            .parameters
            .iter()
            .find(|p| p.name == name)
            .unwrap()
    }

    #[test]
    fn a_threshold_from_zero_is_tried_at_zero_and_over_three_decades() {
        // third_body's slip-speed threshold, [0, 0.1] m/s: 0, then 1e-4 ... 0.1 in eight
        // log steps (a factor 10^(3/7) apart), so its default 1e-3 lies between two values
        // a factor 2.7 apart, where even values would try nothing below 0.0125.
        let p = param("third_body", "min_slip_m_s");
        let v = threshold_values(p, 9);
        assert_eq!(v.len(), 9);
        assert_eq!(v[0], 0.0);
        assert!(
            (v[1] - 1e-4).abs() < 1e-15 && (v[8] - 0.1).abs() < 1e-15,
            "{v:?}"
        );
        for w in v[1..].windows(2) {
            assert!((w[1] / w[0] - 10f64.powf(3.0 / 7.0)).abs() < 1e-9, "{v:?}");
        }
        assert_eq!(threshold_midpoint(p, 0.0, 1e-4), 5e-5);
        assert!((threshold_midpoint(p, 1e-4, 1e-2) - 1e-3).abs() < 1e-15);
        // A threshold with a positive lower bound keeps the profile's own scale.
        let q = param("third_body", "min_pressure_pa");
        assert_eq!(threshold_values(q, 9), profile_values(q, 9));
    }
}
