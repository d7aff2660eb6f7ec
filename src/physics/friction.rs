//! ADAMS Coulomb friction with smooth steps, thesis eq. 4.5 and 4.6.
//!
//! The coefficient is a function of slip speed only. Through zero it is a smooth odd
//! function (`mu(0) = 0`, as in ADAMS: a body on a slope "creeps" at a small speed instead
//! of sticking), rises to `mu_s` at the stiction transition speed `v_s`, falls to `mu_d`
//! at the friction transition speed `v_d` and stays there.

use super::step::StepKind;
use crate::field_error::FieldError;
use crate::{thesis, units};
use serde::{Deserialize, Serialize};

/// Friction parameters (thesis Table 4.2 / 5.2 / 6.1): the one friction type, speeds in m/s.
///
/// Case files write it with the speeds in mm/s, as the thesis tables print them: the spec
/// fields read and write it through [`in_mm_per_s`], the one place the units are converted.
/// Its own serde form (SI field names and units) is the calibration's output.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrictionParams {
    /// Static coefficient mu_s (dimensionless). Thesis Table 5.2: 0.1799.
    pub mu_static: f64,
    /// Dynamic coefficient mu_d (dimensionless). Thesis Table 5.2: 0.1660.
    pub mu_dynamic: f64,
    /// Stiction transition speed v_s, m/s. Thesis Table 5.2: 6.4634 mm/s.
    pub stiction_transition_speed: f64,
    /// Friction transition speed v_d, m/s (> v_s). Thesis Table 5.2: 12.00 mm/s.
    pub friction_transition_speed: f64,
    /// Smooth step used for both transitions (eq. 4.6 cycloidal by default).
    #[serde(default)]
    pub step: StepKind,
}

impl FrictionParams {
    /// Thesis Table 5.2 (dry 7075-T73 on 7075-T73), in SI.
    pub fn thesis_table_5_2() -> Self {
        Self {
            mu_static: thesis::MU_STATIC,
            mu_dynamic: thesis::MU_DYNAMIC,
            stiction_transition_speed: thesis::STICTION_TRANSITION_SPEED_MM_PER_S * units::M_PER_MM,
            friction_transition_speed: thesis::FRICTION_TRANSITION_SPEED_MM_PER_S * units::M_PER_MM,
            step: StepKind::Cycloidal,
        }
    }

    /// Checks the rules of eq. 4.5: mu_s, mu_d finite and >= 0, 0 < v_s < v_d, both finite.
    /// The error names the field as case files write it (speeds in mm/s, with the value in
    /// mm/s), for the caller to place under its path.
    pub fn validate(&self) -> Result<(), FieldError> {
        for (field, mu) in [
            ("mu_static", self.mu_static),
            ("mu_dynamic", self.mu_dynamic),
        ] {
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(FieldError::new(
                    field,
                    format!("must be a finite number >= 0, got {mu}"),
                ));
            }
        }
        let vs = self.stiction_transition_speed;
        if !(vs.is_finite() && vs > 0.0) {
            return Err(FieldError::new(
                "stiction_transition_speed_mm_per_s",
                format!("must be a finite number > 0, got {}", units::to_mm(vs)),
            ));
        }
        let vd = self.friction_transition_speed;
        if !vd.is_finite() {
            return Err(FieldError::new(
                "friction_transition_speed_mm_per_s",
                format!("must be a finite number, got {}", units::to_mm(vd)),
            ));
        }
        if vd <= vs {
            return Err(FieldError::new(
                "friction_transition_speed_mm_per_s",
                "must be greater than stiction_transition_speed_mm_per_s",
            ));
        }
        Ok(())
    }

    /// Friction coefficient magnitude at slip speed `speed >= 0` (eq. 4.5).
    #[inline]
    pub fn coefficient(&self, speed: f64) -> f64 {
        let v = speed.abs();
        let vs = self.stiction_transition_speed;
        let vd = self.friction_transition_speed;
        if v < vs {
            // step(V, -Vs, mu_s, Vs, -mu_s) read as a magnitude: odd through zero.
            self.step.eval(v, -vs, -self.mu_static, vs, self.mu_static)
        } else if v < vd {
            self.step.eval(v, vs, self.mu_static, vd, self.mu_dynamic)
        } else {
            self.mu_dynamic
        }
    }

    /// [`FrictionParams::coefficient`] and [`FrictionParams::coefficient_derivative`] at once,
    /// bit for bit (one `sincos` in a transition instead of a `sin` and a `cos`).
    #[inline]
    pub fn coefficient_with_derivative(&self, speed: f64) -> (f64, f64) {
        let v = speed.abs();
        let vs = self.stiction_transition_speed;
        let vd = self.friction_transition_speed;
        if v < vs {
            self.step
                .eval_with_derivative(v, -vs, -self.mu_static, vs, self.mu_static)
        } else if v < vd {
            self.step
                .eval_with_derivative(v, vs, self.mu_static, vd, self.mu_dynamic)
        } else {
            (self.mu_dynamic, 0.0)
        }
    }

    /// d(mu)/d(speed) at `speed >= 0`.
    #[inline]
    pub fn coefficient_derivative(&self, speed: f64) -> f64 {
        let v = speed.abs();
        let vs = self.stiction_transition_speed;
        let vd = self.friction_transition_speed;
        if v < vs {
            self.step
                .derivative(v, -vs, -self.mu_static, vs, self.mu_static)
        } else if v < vd {
            self.step
                .derivative(v, vs, self.mu_static, vd, self.mu_dynamic)
        } else {
            0.0
        }
    }
}

/// The case-file form of [`FrictionParams`] (`#[serde(with = "in_mm_per_s")]` on a spec
/// field): the speeds in mm/s under `_mm_per_s` names, as the thesis tables print them. Reading
/// converts with [`units::mm`] (the engine's SI values); writing converts back with its exact
/// inverse [`units::to_mm`], so a case written and read again (the overrides merge, the job
/// store) runs with the same bits.
pub mod in_mm_per_s {
    use super::{FrictionParams, StepKind};
    use crate::units;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// ADAMS Coulomb friction (eq. 4.5) with speeds in mm/s: the wire shape only (named as the
    /// case files' schema has always named it, which serde's messages quote).
    #[derive(Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct FrictionSpec {
        mu_static: f64,
        mu_dynamic: f64,
        stiction_transition_speed_mm_per_s: f64,
        friction_transition_speed_mm_per_s: f64,
        #[serde(default)]
        step: StepKind,
    }

    /// Writes `f` with its speeds in mm/s.
    pub fn serialize<S: Serializer>(f: &FrictionParams, serializer: S) -> Result<S::Ok, S::Error> {
        FrictionSpec {
            mu_static: f.mu_static,
            mu_dynamic: f.mu_dynamic,
            stiction_transition_speed_mm_per_s: units::to_mm(f.stiction_transition_speed),
            friction_transition_speed_mm_per_s: units::to_mm(f.friction_transition_speed),
            step: f.step,
        }
        .serialize(serializer)
    }

    /// Reads friction with its speeds in mm/s into SI.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<FrictionParams, D::Error> {
        let f = FrictionSpec::deserialize(deserializer)?;
        Ok(FrictionParams {
            mu_static: f.mu_static,
            mu_dynamic: f.mu_dynamic,
            stiction_transition_speed: units::mm(f.stiction_transition_speed_mm_per_s),
            friction_transition_speed: units::mm(f.friction_transition_speed_mm_per_s),
            step: f.step,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_5_2_values_at_the_breakpoints() {
        let f = FrictionParams::thesis_table_5_2();
        // Table 5.2 in SI, the bits a case file's 6.4634 and 12.0 mm/s read as.
        assert_eq!(f.stiction_transition_speed, 6.4634e-3);
        assert_eq!(f.friction_transition_speed, 12.0e-3);
        assert_eq!(f.coefficient(0.0), 0.0);
        assert!((f.coefficient(6.4634e-3) - 0.1799).abs() < 1e-12);
        assert!((f.coefficient(12.0e-3) - 0.1660).abs() < 1e-12);
        assert!((f.coefficient(1.0) - 0.1660).abs() < 1e-12);
        // Halfway through the stiction ramp the cycloidal step is half way: mu_s/2.
        assert!((f.coefficient(0.5 * 6.4634e-3) - 0.1799 * 0.5).abs() > 0.0);
        // Odd and monotone below v_s.
        assert!(f.coefficient(1e-3) > 0.0 && f.coefficient(1e-3) < f.coefficient(3e-3));
    }

    #[test]
    fn coefficient_with_derivative_is_both_bit_for_bit() {
        let f = FrictionParams::thesis_table_5_2();
        for i in 0..3000 {
            let v = 5e-6 * i as f64; // through both transitions and beyond
            let (mu, dmu) = f.coefficient_with_derivative(v);
            assert_eq!(mu.to_bits(), f.coefficient(v).to_bits(), "{v}");
            assert_eq!(dmu.to_bits(), f.coefficient_derivative(v).to_bits(), "{v}");
        }
    }

    #[test]
    fn slope_at_zero_is_two_mu_s_over_v_s_for_cycloidal_step() {
        // eq. 4.6 around u = 1/2: d/dV = (2 mu_s) * (1 - cos(pi)) / (2 Vs) = 2 mu_s / Vs.
        let f = FrictionParams::thesis_table_5_2();
        let expected = 2.0 * 0.1799 / 6.4634e-3;
        assert!((f.coefficient_derivative(0.0) - expected).abs() / expected < 1e-12);
    }

    #[test]
    fn validation_names_the_field() {
        let mut f = FrictionParams::thesis_table_5_2();
        f.friction_transition_speed = 1e-3;
        let e = f.validate().unwrap_err();
        assert_eq!(e.field, "friction_transition_speed_mm_per_s");
        assert_eq!(
            e.rule,
            "must be greater than stiction_transition_speed_mm_per_s"
        );
        f = FrictionParams::thesis_table_5_2();
        f.stiction_transition_speed = -2.5e-3;
        assert_eq!(
            f.validate().unwrap_err().rule,
            "must be a finite number > 0, got -2.5"
        );
        assert!(FrictionParams::thesis_table_5_2().validate().is_ok());
    }

    #[test]
    fn case_files_write_the_speeds_in_mm_per_s() {
        #[derive(Debug, PartialEq, Serialize, Deserialize)]
        struct Spec {
            #[serde(with = "in_mm_per_s")]
            friction: FrictionParams,
        }
        let text = "[friction]\nmu_static = 0.1799\nmu_dynamic = 0.166\n\
                    stiction_transition_speed_mm_per_s = 6.4634\n\
                    friction_transition_speed_mm_per_s = 12.0\n";
        let spec: Spec = toml::from_str(text).unwrap();
        assert_eq!(spec.friction, FrictionParams::thesis_table_5_2());
        // Written back: the typed decimals, and the same bits when read again.
        let json = serde_json::to_value(&spec).unwrap();
        assert_eq!(
            json["friction"]["stiction_transition_speed_mm_per_s"],
            6.4634
        );
        assert_eq!(json["friction"]["friction_transition_speed_mm_per_s"], 12.0);
        let back: Spec = serde_json::from_value(json).unwrap();
        assert_eq!(back, spec);
        let unknown = toml::from_str::<Spec>(&text.replace("mu_static", "mu_s")).unwrap_err();
        assert!(
            unknown.to_string().contains("unknown field `mu_s`"),
            "{unknown}"
        );
    }
}
