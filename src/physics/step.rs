//! Smooth step functions used by the IMPACT damping ramp and the friction law.
//!
//! Two forms are supported:
//! - [`StepKind::Cycloidal`], thesis eq. 2.4 / 4.6:
//!   `h1 + (h2-h1) * (u - sin(2πu)/(2π))`, `u = (x-x1)/(x2-x1)` clamped to [0, 1]. Default.
//! - [`StepKind::Cubic`], the ADAMS `STEP` function: `h1 + (h2-h1) * u²(3-2u)`.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// `1 / (2π)`: the cycloid's sine term as a product (a division was one of a contact node's
/// dozen).
const FRAC_1_TAU: f64 = 0.5 / PI;

/// Which smooth step to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StepKind {
    /// Thesis eq. 2.4 (cycloidal). C² at both ends (zero slope and curvature).
    #[default]
    Cycloidal,
    /// ADAMS STEP (cubic Hermite). C¹ at both ends.
    Cubic,
}

impl StepKind {
    /// Smooth step from `(x1, h1)` to `(x2, h2)`; constant outside `[x1, x2]`.
    /// `x2 < x1` is allowed (the step then runs backwards), `x1 == x2` gives a hard switch at x1.
    #[inline]
    pub fn eval(self, x: f64, x1: f64, h1: f64, x2: f64, h2: f64) -> f64 {
        let span = x2 - x1;
        if span == 0.0 {
            return if x < x1 { h1 } else { h2 };
        }
        let u = ((x - x1) * (1.0 / span)).clamp(0.0, 1.0);
        h1 + (h2 - h1) * self.unit(u)
    }

    /// Derivative of [`StepKind::eval`] with respect to `x`.
    #[inline]
    pub fn derivative(self, x: f64, x1: f64, h1: f64, x2: f64, h2: f64) -> f64 {
        let span = x2 - x1;
        if span == 0.0 {
            return 0.0;
        }
        let inv_span = 1.0 / span;
        let u = (x - x1) * inv_span;
        if !(0.0..=1.0).contains(&u) {
            return 0.0;
        }
        (h2 - h1) * self.unit_derivative(u) * inv_span
    }

    /// [`StepKind::eval`] and [`StepKind::derivative`] at once, bit for bit: for the
    /// cycloidal step inside `[x1, x2]` one [`sin_cos_turns`] instead of its sine and its
    /// cosine apart. For a contact point's force and its Jacobian (the damping ramp, the
    /// friction coefficient), which need both at the same argument.
    #[inline]
    pub fn eval_with_derivative(self, x: f64, x1: f64, h1: f64, x2: f64, h2: f64) -> (f64, f64) {
        let span = x2 - x1;
        if span == 0.0 {
            return (if x < x1 { h1 } else { h2 }, 0.0);
        }
        // One division: the argument and the slope share `1 / span`.
        let inv_span = 1.0 / span;
        let u = (x - x1) * inv_span;
        if !(0.0..=1.0).contains(&u) {
            return (self.eval(x, x1, h1, x2, h2), 0.0);
        }
        match self {
            StepKind::Cycloidal => {
                let (sin, cos) = sin_cos_turns(u);
                (
                    h1 + (h2 - h1) * (u - sin * FRAC_1_TAU),
                    (h2 - h1) * (1.0 - cos) * inv_span,
                )
            }
            StepKind::Cubic => (
                h1 + (h2 - h1) * self.unit(u),
                (h2 - h1) * self.unit_derivative(u) * inv_span,
            ),
        }
    }

    /// The normalised step on u in [0, 1].
    #[inline]
    pub fn unit(self, u: f64) -> f64 {
        match self {
            StepKind::Cycloidal => u - sin_cos_turns(u).0 * FRAC_1_TAU,
            StepKind::Cubic => u * u * (3.0 - 2.0 * u),
        }
    }

    /// d/du of the normalised step.
    #[inline]
    pub fn unit_derivative(self, u: f64) -> f64 {
        match self {
            StepKind::Cycloidal => 1.0 - sin_cos_turns(u).1,
            StepKind::Cubic => 6.0 * u * (1.0 - u),
        }
    }
}

/// Taylor coefficients of `sin θ / θ` in `θ²`: `(-1)^k / (2k + 1)!`, k = 0..7.
const SIN_TAYLOR: [f64; 8] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
];
/// Taylor coefficients of `cos θ` in `θ²`: `(-1)^k / (2k)!`, k = 0..8.
const COS_TAYLOR: [f64; 9] = [
    1.0,
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// `(sin 2πu, cos 2πu)` for a fraction of a turn `u` in `[0, 1]` (the cycloidal step's
/// argument; outside it the result is still right but loses accuracy as `|u|` grows).
///
/// The turn is split into exact quarters, `4u = k + r` with `|r| <= 1/2` (both exact in
/// floating point), and `θ = r π/2` (`|θ| <= π/4`) goes through the Taylor series of `sin`
/// to `θ¹⁵` and of `cos` to `θ¹⁶`: the first terms left out are below `θ¹⁷/17! < 4.7e-17`
/// and `θ¹⁸/18! < 2.1e-18` there, under half an ulp of the results. Checked offline against
/// 120-bit values over 2·10⁵ arguments: within 2.2e-16, where libm's `sin(2πu)` is off by up to
/// 7.2e-16 because its argument `2πu` is already rounded (the test holds both to 1e-15 of each
/// other and to the exact values at the eighths of a turn).
///
/// Why not libm: its `sincos` was 9.5 % of a launcher run's samples (perf), with its range
/// reduction and rounding-mode save. A Horner form of these polynomials cut instructions but
/// no time (docs/journal/performance.md, seventeenth pass: the chain's latency); evaluated as Estrin's
/// tree it takes 1.5-9 % off the launcher's CPU time, run to run, and 5.4 % of its
/// instructions (twenty-fourth pass).
#[inline]
pub fn sin_cos_turns(u: f64) -> (f64, f64) {
    let x = 4.0 * u;
    // The nearest quarter: truncation is the floor where `x + 1/2 >= 0` (`u >= -1/8`); below,
    // `r` leaves `[-1/2, 1/2]` but stays exact, so the identity below still holds.
    let k = (x + 0.5) as i64;
    let r = x - k as f64;
    let theta = r * std::f64::consts::FRAC_PI_2;
    let t2 = theta * theta;
    // Estrin's scheme: the two polynomials in `t2` as a tree of depth 4 instead of a Horner
    // chain of 8 dependent multiply-adds (the result feeds the node's force at once, so the
    // chain's latency, not its operation count, is what a contact node waits for).
    let (t4, c, d) = (t2 * t2, &SIN_TAYLOR, &COS_TAYLOR);
    let t8 = t4 * t4;
    let sin = theta
        * ((c[0] + c[1] * t2)
            + t4 * (c[2] + c[3] * t2)
            + t8 * ((c[4] + c[5] * t2) + t4 * (c[6] + c[7] * t2)));
    let cos = (d[0] + d[1] * t2)
        + t4 * (d[2] + d[3] * t2)
        + t8 * ((d[4] + d[5] * t2) + t4 * (d[6] + d[7] * t2))
        + t8 * t8 * d[8];
    // sin(θ + kπ/2), cos(θ + kπ/2).
    match k.rem_euclid(4) {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_steps_hit_their_end_values_and_midpoint() {
        for kind in [StepKind::Cycloidal, StepKind::Cubic] {
            assert_eq!(kind.eval(-1.0, 0.0, 2.0, 1.0, 5.0), 2.0);
            assert_eq!(kind.eval(3.0, 0.0, 2.0, 1.0, 5.0), 5.0);
            // Both are point-symmetric about the midpoint.
            assert!((kind.eval(0.5, 0.0, 2.0, 1.0, 5.0) - 3.5).abs() < 1e-12);
            assert_eq!(kind.derivative(0.0, 0.0, 2.0, 1.0, 5.0), 0.0);
        }
    }

    #[test]
    fn eval_with_derivative_is_eval_and_derivative_bit_for_bit() {
        for kind in [StepKind::Cycloidal, StepKind::Cubic] {
            for i in -50..=1050 {
                let x = 1e-3 * i as f64 * 0.731 + 0.2;
                for (x1, h1, x2, h2) in [(0.2, 0.0, 0.931, 1.0), (-0.4, -0.18, 0.4, 0.18)] {
                    let (v, d) = kind.eval_with_derivative(x, x1, h1, x2, h2);
                    assert_eq!(v.to_bits(), kind.eval(x, x1, h1, x2, h2).to_bits(), "{x}");
                    assert_eq!(d.to_bits(), kind.derivative(x, x1, h1, x2, h2).to_bits());
                }
            }
        }
    }

    #[test]
    fn sin_cos_turns_is_libms_sin_and_cos_to_round_off() {
        // Exact values at the eighths of a turn.
        let half = std::f64::consts::FRAC_1_SQRT_2;
        let eighths = [
            (0.0, 1.0),
            (half, half),
            (1.0, 0.0),
            (half, -half),
            (0.0, -1.0),
            (-half, -half),
            (-1.0, 0.0),
            (-half, half),
            (0.0, 1.0),
        ];
        for (i, &(s, c)) in eighths.iter().enumerate() {
            let (ts, tc) = sin_cos_turns(i as f64 / 8.0);
            assert!(
                (ts - s).abs() <= 2.3e-16 && (tc - c).abs() <= 2.3e-16,
                "{i}/8"
            );
        }
        // Against libm on the rounded argument 2πu, whose own error is up to 2πu 2⁻⁵³ (7e-16);
        // a wrong Taylor coefficient or quarter shows as 1e-10 or worse.
        let n = 1_000_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let u = i as f64 / n as f64 + 1e-13 * (i % 7) as f64;
            let u = u.min(1.0);
            let (s, c) = sin_cos_turns(u);
            let (ls, lc) = (2.0 * PI * u).sin_cos();
            worst = worst.max((s - ls).abs()).max((c - lc).abs());
            assert!((s * s + c * c - 1.0).abs() <= 4.5e-16, "{u}");
        }
        assert!(worst <= 1e-15, "worst difference {worst:e}");
    }

    #[test]
    fn derivative_matches_finite_difference() {
        for kind in [StepKind::Cycloidal, StepKind::Cubic] {
            for &x in &[0.1, 0.37, 0.8] {
                let h = 1e-6;
                let fd = (kind.eval(x + h, 0.0, 1.0, 1.0, 3.0)
                    - kind.eval(x - h, 0.0, 1.0, 1.0, 3.0))
                    / (2.0 * h);
                assert!((fd - kind.derivative(x, 0.0, 1.0, 1.0, 3.0)).abs() < 1e-6);
            }
        }
    }
}
