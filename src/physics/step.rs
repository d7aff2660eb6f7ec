//! Smooth step functions used by the IMPACT damping ramp and the friction law.
//!
//! Two forms are supported:
//! - [`StepKind::Cycloidal`], thesis eq. 2.4 / 4.6:
//!   `h1 + (h2-h1) * (u - sin(2πu)/(2π))`, `u = (x-x1)/(x2-x1)` clamped to [0, 1]. Default.
//! - [`StepKind::Cubic`], the ADAMS `STEP` function: `h1 + (h2-h1) * u²(3-2u)`.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

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
        let u = ((x - x1) / span).clamp(0.0, 1.0);
        h1 + (h2 - h1) * self.unit(u)
    }

    /// Derivative of [`StepKind::eval`] with respect to `x`.
    #[inline]
    pub fn derivative(self, x: f64, x1: f64, h1: f64, x2: f64, h2: f64) -> f64 {
        let span = x2 - x1;
        if span == 0.0 {
            return 0.0;
        }
        let u = (x - x1) / span;
        if !(0.0..=1.0).contains(&u) {
            return 0.0;
        }
        (h2 - h1) * self.unit_derivative(u) / span
    }

    /// [`StepKind::eval`] and [`StepKind::derivative`] at once, bit for bit: for the
    /// cycloidal step inside `[x1, x2]` one `sin_cos` (one libm `sincos` call) instead of a
    /// `sin` and a `cos`. For a contact point's force and its Jacobian (the damping ramp, the
    /// friction coefficient), which need both at the same argument.
    #[inline]
    pub fn eval_with_derivative(self, x: f64, x1: f64, h1: f64, x2: f64, h2: f64) -> (f64, f64) {
        let span = x2 - x1;
        if span == 0.0 {
            return (if x < x1 { h1 } else { h2 }, 0.0);
        }
        let u = (x - x1) / span;
        if !(0.0..=1.0).contains(&u) {
            return (self.eval(x, x1, h1, x2, h2), 0.0);
        }
        match self {
            StepKind::Cycloidal => {
                let (sin, cos) = (2.0 * PI * u).sin_cos();
                (
                    h1 + (h2 - h1) * (u - sin / (2.0 * PI)),
                    (h2 - h1) * (1.0 - cos) / span,
                )
            }
            StepKind::Cubic => (
                h1 + (h2 - h1) * self.unit(u),
                (h2 - h1) * self.unit_derivative(u) / span,
            ),
        }
    }

    /// The normalised step on u in [0, 1].
    #[inline]
    pub fn unit(self, u: f64) -> f64 {
        match self {
            StepKind::Cycloidal => u - (2.0 * PI * u).sin() / (2.0 * PI),
            StepKind::Cubic => u * u * (3.0 - 2.0 * u),
        }
    }

    /// d/du of the normalised step.
    #[inline]
    pub fn unit_derivative(self, u: f64) -> f64 {
        match self {
            StepKind::Cycloidal => 1.0 - (2.0 * PI * u).cos(),
            StepKind::Cubic => 6.0 * u * (1.0 - u),
        }
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
