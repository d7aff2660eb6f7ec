//! ADAMS IMPACT normal contact force, thesis eq. 2.1-2.3.
//!
//! `F = max(0, k w^e + c_max STEP(w, 0, 0, d, 1) wdot)` for `w > 0`, zero otherwise, with `w` the
//! penetration and `wdot` its rate (positive while approaching). The damping always resists
//! approach. Eq. 2.2 as printed (`- c_max wdot STEP`) uses the gap coordinate's rate; read with
//! `wdot` as the penetration rate its sign is reversed (an erratum, see docs/results/errata.md).

use super::step::StepKind;
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// IMPACT parameters in SI (N/m^e, N·s/m, m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImpactParams {
    /// Stiffness k, N/m^e. Thesis Table 5.2: 1000 N/mm² = 1e9 N/m².
    pub stiffness: f64,
    /// Force exponent e (dimensionless). Thesis Table 5.2: 2.0.
    pub exponent: f64,
    /// Maximum damping c_max, N·s/m. Thesis Table 5.2: 500 N·s/mm = 5e5 N·s/m.
    pub max_damping: f64,
    /// Penetration d at which full damping is reached, m. Thesis Table 5.2: 0.01 mm.
    pub full_damping_depth: f64,
    /// Shape of the damping ramp (eq. 2.4 cycloidal by default).
    #[serde(default)]
    pub step: StepKind,
}

impl ImpactParams {
    /// Builds from the thesis' ADAMS units: k in N/mm^e, c in N·s/mm, d in mm.
    pub fn from_adams_units(k_n_per_mm_e: f64, exponent: f64, c_ns_per_mm: f64, d_mm: f64) -> Self {
        Self {
            stiffness: crate::units::impact_stiffness_si(k_n_per_mm_e, exponent),
            exponent,
            max_damping: crate::units::damping_si(c_ns_per_mm),
            full_damping_depth: crate::units::mm(d_mm),
            step: StepKind::Cycloidal,
        }
    }

    /// Thesis Table 5.2 / 4.1 / 6.2 default: k 1000 N/mm², e 2, c 500 N·s/mm, d 0.01 mm.
    pub fn thesis_table_5_2() -> Self {
        Self::from_adams_units(
            crate::thesis::IMPACT_STIFFNESS_N_PER_MM_E,
            crate::thesis::IMPACT_EXPONENT,
            crate::thesis::IMPACT_DAMPING_NS_PER_MM,
            crate::thesis::IMPACT_PENETRATION_DEPTH_MM,
        )
    }

    /// Checks the rules on each field; the first violation as a [`FieldError`].
    pub fn validate(&self) -> Result<(), FieldError> {
        FieldError::positive("stiffness", self.stiffness)?;
        if !(self.exponent.is_finite() && self.exponent >= 1.0) {
            return Err(FieldError::new("exponent", "must be a finite number >= 1"));
        }
        FieldError::non_negative("max_damping", self.max_damping)?;
        FieldError::non_negative("full_damping_depth", self.full_damping_depth)?;
        Ok(())
    }

    /// Damping coefficient at penetration `w`: `c_max STEP(w, 0, 0, d, 1)`.
    #[inline]
    pub fn damping_at(&self, w: f64) -> f64 {
        if w <= 0.0 {
            0.0
        } else if w >= self.full_damping_depth {
            self.max_damping
        } else {
            self.max_damping * self.step.eval(w, 0.0, 0.0, self.full_damping_depth, 1.0)
        }
    }

    /// Normal force magnitude (N) for penetration `w` (m) and penetration rate `wdot` (m/s,
    /// positive approaching), clamped at zero (eq. 2.1-2.3).
    #[inline]
    pub fn force(&self, w: f64, wdot: f64) -> f64 {
        if w <= 0.0 {
            return 0.0;
        }
        (self.stiffness * power(w, self.exponent) + self.damping_at(w) * wdot).max(0.0)
    }

    /// Elastic part `k w^e` of the force (N) at penetration `w` (m): the derivative of
    /// [`ImpactParams::potential`]. `force - elastic_force` is the damping part after the clamp,
    /// whose power `(force - elastic_force) · ẇ` is what the contact dissipates (>= 0).
    #[inline]
    pub fn elastic_force(&self, w: f64) -> f64 {
        if w <= 0.0 {
            0.0
        } else {
            self.stiffness * power(w, self.exponent)
        }
    }

    /// Partial derivatives (dF/dw, dF/dwdot) of [`ImpactParams::force`], zero where clamped.
    #[inline]
    pub fn force_gradient(&self, w: f64, wdot: f64) -> (f64, f64) {
        if w <= 0.0 || self.force(w, wdot) <= 0.0 {
            return (0.0, 0.0);
        }
        let dstep = if w < self.full_damping_depth {
            self.max_damping
                * self
                    .step
                    .derivative(w, 0.0, 0.0, self.full_damping_depth, 1.0)
        } else {
            0.0
        };
        (
            self.exponent * self.stiffness * power(w, self.exponent - 1.0) + dstep * wdot,
            self.damping_at(w),
        )
    }

    /// The elastic force `k w^e` (N) and the damping coefficient `c STEP(w)` (N·s/m) at
    /// `w > 0`: [`ImpactParams::force`] is `(spring + damping · ẇ).max(0)` of these, bit for bit.
    #[inline]
    pub fn force_parts(&self, w: f64) -> (f64, f64) {
        (self.stiffness * power(w, self.exponent), self.damping_at(w))
    }

    /// [`ImpactParams::force_gradient`] at a point where the force is positive (not clamped),
    /// given its damping coefficient from [`ImpactParams::force_parts`]: the same numbers
    /// without evaluating the damping STEP again.
    #[inline]
    pub fn unclamped_gradient(&self, w: f64, wdot: f64, damping: f64) -> (f64, f64) {
        let dstep = if w < self.full_damping_depth {
            self.max_damping
                * self
                    .step
                    .derivative(w, 0.0, 0.0, self.full_damping_depth, 1.0)
        } else {
            0.0
        };
        (
            self.exponent * self.stiffness * power(w, self.exponent - 1.0) + dstep * wdot,
            damping,
        )
    }

    /// [`ImpactParams::force_parts`] and the damping coefficient's slope `c dSTEP/dw`
    /// (N·s/m²) at `w > 0`, bit for bit as [`ImpactParams::unclamped_gradient`] uses it: on the
    /// ramp one `sincos` instead of a `sin` and a `cos` (a contact point's force and Jacobian).
    #[inline]
    pub fn force_parts_with_slope(&self, w: f64) -> (f64, f64, f64) {
        let spring = self.stiffness * power(w, self.exponent);
        if w >= self.full_damping_depth {
            return (spring, self.max_damping, 0.0);
        }
        let (step, slope) =
            self.step
                .eval_with_derivative(w, 0.0, 0.0, self.full_damping_depth, 1.0);
        (spring, self.max_damping * step, self.max_damping * slope)
    }

    /// [`ImpactParams::unclamped_gradient`] given the damping slope from
    /// [`ImpactParams::force_parts_with_slope`]: the same numbers without a `cos`.
    #[inline]
    pub fn unclamped_gradient_with_slope(
        &self,
        w: f64,
        wdot: f64,
        damping: f64,
        slope: f64,
    ) -> (f64, f64) {
        (
            self.exponent * self.stiffness * power(w, self.exponent - 1.0) + slope * wdot,
            damping,
        )
    }

    /// Elastic energy stored at penetration `w`, J: `∫ k w^e dw = k w^(e+1) / (e+1)`.
    #[inline]
    pub fn potential(&self, w: f64) -> f64 {
        if w <= 0.0 {
            return 0.0;
        }
        let e = self.exponent;
        self.stiffness * power(w, e) * w / (e + 1.0)
    }

    /// Static penetration under a steady load `f` (N): `(f/k)^(1/e)`.
    pub fn static_penetration(&self, f: f64) -> f64 {
        (f.max(0.0) / self.stiffness).powf(1.0 / self.exponent)
    }
}

/// `w^e` for `w >= 0`, by multiplication for the small integer exponents of the reference
/// tables (Table 5.2 and 6.2 use e = 2; `powf` was 6 % of a rattle-box run).
#[inline]
fn power(w: f64, e: f64) -> f64 {
    if e == 2.0 {
        w * w
    } else if e == 1.0 {
        w
    } else if e == 3.0 {
        w * w * w
    } else if e == 0.0 {
        1.0
    } else {
        w.powf(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_names_the_field() {
        assert!(ImpactParams::thesis_table_5_2().validate().is_ok());
        let p = ImpactParams {
            exponent: 0.5,
            ..ImpactParams::thesis_table_5_2()
        };
        assert_eq!(
            p.validate(),
            Err(FieldError::new("exponent", "must be a finite number >= 1"))
        );
    }

    #[test]
    fn force_parts_and_unclamped_gradient_are_force_and_force_gradient_bit_for_bit() {
        let p = ImpactParams::from_adams_units(1000.0, 2.0, 500.0, 0.01);
        for i in 1..200 {
            let w = 2e-7 * i as f64; // across the damping ramp (0.01 mm) and beyond it
            for wdot in [-0.3, -1e-3, 0.0, 2e-3, 0.5] {
                let (spring, damping) = p.force_parts(w);
                let f = (spring + damping * wdot).max(0.0);
                assert_eq!(f.to_bits(), p.force(w, wdot).to_bits(), "w {w} wdot {wdot}");
                assert_eq!(spring.to_bits(), p.elastic_force(w).to_bits());
                if f > 0.0 {
                    let (a, b) = p.unclamped_gradient(w, wdot, damping);
                    let (c, d) = p.force_gradient(w, wdot);
                    assert_eq!((a.to_bits(), b.to_bits()), (c.to_bits(), d.to_bits()));
                    let (spring2, damping2, slope) = p.force_parts_with_slope(w);
                    assert_eq!(
                        (spring2.to_bits(), damping2.to_bits()),
                        (spring.to_bits(), damping.to_bits())
                    );
                    let (e, g) = p.unclamped_gradient_with_slope(w, wdot, damping, slope);
                    assert_eq!((e.to_bits(), g.to_bits()), (a.to_bits(), b.to_bits()));
                }
            }
        }
    }

    #[test]
    fn integer_exponents_match_powf() {
        for e in [0.0, 1.0, 2.0, 3.0, 1.5, 2.4] {
            for w in [0.0, 1e-9, 3.7e-6, 2e-5, 0.25, 1.0, 7.5] {
                let exact = f64::powf(w, e);
                assert!((power(w, e) - exact).abs() <= 1e-15 * exact, "{w}^{e}");
            }
        }
    }

    #[test]
    fn spring_part_and_clamp() {
        let p = ImpactParams::thesis_table_5_2();
        // 0.02 mm with no rate: 1000 N/mm² * (0.02 mm)² = 0.4 N.
        assert!((p.force(2e-5, 0.0) - 0.4).abs() < 1e-9);
        // Separating fast: the damping would pull, the clamp keeps it at zero.
        assert_eq!(p.force(2e-5, -1.0), 0.0);
        assert_eq!(p.force(-1e-6, 1.0), 0.0);
    }

    #[test]
    fn damping_resists_approach() {
        let p = ImpactParams::thesis_table_5_2();
        // Beyond d the full 5e5 N·s/m acts: 0.1 m/s approach adds 5e4 N.
        let f = p.force(2e-5, 0.1);
        assert!((f - (0.4 + 5e4)).abs() < 1e-6);
    }

    #[test]
    fn static_penetration_inverts_the_spring() {
        let p = ImpactParams::thesis_table_5_2();
        let w = p.static_penetration(0.45);
        assert!((p.force(w, 0.0) - 0.45).abs() < 1e-12);
    }
}
