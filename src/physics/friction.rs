//! ADAMS Coulomb friction with smooth steps, thesis eq. 4.5 and 4.6.
//!
//! The coefficient is a function of slip speed only. Through zero it is a smooth odd
//! function (`mu(0) = 0`, as in ADAMS: a body on a slope "creeps" at a small speed instead
//! of sticking), rises to `mu_s` at the stiction transition speed `v_s`, falls to `mu_d`
//! at the friction transition speed `v_d` and stays there.

use super::step::StepKind;
use serde::{Deserialize, Serialize};

/// Friction parameters (thesis Table 4.2 / 5.2 / 6.1). Speeds in m/s.
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
            mu_static: 0.1799,
            mu_dynamic: 0.1660,
            stiction_transition_speed: 6.4634e-3,
            friction_transition_speed: 12.0e-3,
            step: StepKind::Cycloidal,
        }
    }

    /// Checks the physical rules; returns the name of the offending field and the rule.
    pub fn validate(&self) -> Result<(), (&'static str, &'static str)> {
        let finite = [
            self.mu_static,
            self.mu_dynamic,
            self.stiction_transition_speed,
            self.friction_transition_speed,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite {
            return Err(("friction", "all parameters must be finite numbers"));
        }
        if self.mu_static < 0.0 {
            return Err(("mu_static", "must be >= 0"));
        }
        if self.mu_dynamic < 0.0 {
            return Err(("mu_dynamic", "must be >= 0"));
        }
        if self.stiction_transition_speed <= 0.0 {
            return Err(("stiction_transition_speed", "must be > 0 m/s"));
        }
        if self.friction_transition_speed <= self.stiction_transition_speed {
            return Err((
                "friction_transition_speed",
                "must be greater than stiction_transition_speed",
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_5_2_values_at_the_breakpoints() {
        let f = FrictionParams::thesis_table_5_2();
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
        assert_eq!(f.validate().unwrap_err().0, "friction_transition_speed");
    }
}
