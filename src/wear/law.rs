//! Wear laws: lumped Archard (eq. 3.8), the modified pressure-dependent law (eq. 3.10-3.15),
//! and the behaviour of the thesis' appendix C post-processor (`CParse.C`) as a legacy option.

use super::WearError;
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Table 4.3, C1 (K in m²/N with sigma in Pa).
pub const TABLE_4_3_C1: f64 = 2.3685e-15;
/// Table 4.3, C2 (dimensionless; the exponent is 1/C2).
pub const TABLE_4_3_C2: f64 = 6.3197;
/// Table 4.3, C3, m²/N.
pub const TABLE_4_3_C3: f64 = -9.5089e-16;

/// Why a law without K(sigma) refuses wear mechanisms and wear-law effects
/// ([`WearLaw::gives_k_of_sigma`]).
pub const TERMS_NEED_K_OF_SIGMA: &str = "wear mechanisms and wear-law effects need a K(sigma) \
     law (archard or modified); the legacy appendix law feeds N, not sigma";

/// How a track's rate samples are integrated over time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quadrature {
    /// Trapezoid rule between consecutive samples; the first sample only opens the track.
    Trapezoid,
    /// `CParse.C` lines 100 and 131: rate at the current sample times (t - t_prev), with t_prev
    /// starting at 0 s, so the first sample is integrated back to t = 0.
    RightEndpointFromZero,
}

/// A wear law: the wear-volume rate of one contact track. Tagged `kind` in snake_case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WearLaw {
    /// Lumped Archard, eq. 3.8: `W = K N s`, constant `K = k/H` in m²/N (= m³ per N·m).
    Archard {
        /// Dimensional lumped wear coefficient K, m²/N (eq. 3.8).
        coefficient_m2_per_n: f64,
    },
    /// Modified law, eq. 3.10-3.15: `dW/dt = K(sigma) N v_slip`,
    /// `K(sigma) = max(0, C1 sigma^(1/C2) + C3)` for `sigma <= cutoff`, else 0.
    Modified {
        /// C1, m²/N per Pa^(1/C2) (Table 4.3: 2.3685e-15).
        c1: f64,
        /// C2, dimensionless (Table 4.3: 6.3197).
        c2: f64,
        /// C3, m²/N (Table 4.3: -9.5089e-16; negative, hence the clamp at K >= 0).
        c3: f64,
        /// Pressure above which K = 0, Pa. Eq. 3.11 says 2 S_y (default, 870 MPa for 7075);
        /// the sentence after eq. 3.12 says 2.8 S_y (1218 MPa). A parameter for that reason.
        cutoff_pressure_pa: f64,
    },
    /// The appendix C code `CParse.C` exactly (line 121 and 131):
    /// `Kw = C1 |N|^(1/C2) + 1e-3 C3`, `dW = 1e-3 Kw N v dt`, right-endpoint sums from t = 0.
    /// It feeds the normal force N, not the pressure, into K and scales C3 by 1e-3, which
    /// contradicts eq. 3.11. It has no cutoff and no clamp. Kept only to reproduce the thesis.
    LegacyAppendix {
        /// C1 as passed on the command line (`argv[4]`).
        c1: f64,
        /// C2 as passed on the command line (`argv[5]`); 0 gives Kw = 0 as in the code.
        c2: f64,
        /// C3 as passed on the command line (`argv[6]`).
        c3: f64,
        /// m/s per unit of the exported slip-speed column: ADAMS exports mm/s, so 1e-3.
        speed_unit_m_s: f64,
        /// m³ per unit of the code's output: thesis 4.4.1 calls it cubic microns, so 1e-18.
        output_unit_m3: f64,
    },
}

impl WearLaw {
    /// Modified law with Table 4.3 and the eq. 3.11 cutoff 2 S_y of 7075-T73 (870 MPa).
    pub fn table_4_3() -> Self {
        Self::Modified {
            c1: TABLE_4_3_C1,
            c2: TABLE_4_3_C2,
            c3: TABLE_4_3_C3,
            cutoff_pressure_pa: 2.0 * super::Material::aluminium_7075_t73().yield_strength_pa,
        }
    }

    /// The appendix C code fed Table 4.3, with ADAMS' mm/s and the thesis' cubic microns.
    pub fn legacy_table_4_3() -> Self {
        Self::LegacyAppendix {
            c1: TABLE_4_3_C1,
            c2: TABLE_4_3_C2,
            c3: TABLE_4_3_C3,
            speed_unit_m_s: 1.0e-3,
            output_unit_m3: 1.0e-18,
        }
    }

    /// Checks the parameters; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), WearError> {
        let finite = |x: f64| x.is_finite();
        match *self {
            Self::Archard {
                coefficient_m2_per_n,
            } => {
                FieldError::non_negative("coefficient_m2_per_n", coefficient_m2_per_n)?;
            }
            Self::Modified {
                c1,
                c2,
                c3,
                cutoff_pressure_pa,
            } => {
                if !finite(c1) {
                    return Err(FieldError::new("c1", "must be a finite number").into());
                }
                FieldError::positive("c2", c2)?;
                if !finite(c3) {
                    return Err(FieldError::new("c3", "must be a finite number").into());
                }
                if cutoff_pressure_pa.is_nan() || cutoff_pressure_pa <= 0.0 {
                    return Err(FieldError::new("cutoff_pressure_pa", "must be > 0 Pa").into());
                }
            }
            Self::LegacyAppendix {
                c1,
                c2,
                c3,
                speed_unit_m_s,
                output_unit_m3,
            } => {
                if !(finite(c1) && finite(c2) && finite(c3)) {
                    return Err(FieldError::new("c1/c2/c3", "must be finite numbers").into());
                }
                FieldError::positive("speed_unit_m_s", speed_unit_m_s)?;
                FieldError::positive("output_unit_m3", output_unit_m3)?;
            }
        }
        Ok(())
    }

    /// Whether the law gives K(sigma), which wear mechanisms and wear-law effects act on (the
    /// legacy appendix law feeds N instead: [`TERMS_NEED_K_OF_SIGMA`]).
    pub fn gives_k_of_sigma(&self) -> bool {
        !matches!(self, Self::LegacyAppendix { .. })
    }

    /// The quadrature this law is integrated with: the legacy law keeps the appendix' rule.
    pub fn quadrature(&self) -> Quadrature {
        match self {
            Self::LegacyAppendix { .. } => Quadrature::RightEndpointFromZero,
            _ => Quadrature::Trapezoid,
        }
    }

    /// Pressure above which the law gives no wear, Pa (infinite when the law has no cutoff).
    pub fn cutoff_pressure_pa(&self) -> f64 {
        match *self {
            Self::Modified {
                cutoff_pressure_pa, ..
            } => cutoff_pressure_pa,
            _ => f64::INFINITY,
        }
    }

    /// Wear coefficient K(sigma), m²/N, eq. 3.11 clamped at 0 (Archard: the constant).
    /// Not defined for the legacy law, whose K depends on N: see [`WearLaw::volume_rate_m3_s`].
    #[inline]
    pub fn coefficient_m2_per_n(&self, pressure_pa: f64) -> Option<f64> {
        match *self {
            Self::Archard {
                coefficient_m2_per_n,
            } => Some(coefficient_m2_per_n),
            Self::Modified {
                c1,
                c2,
                c3,
                cutoff_pressure_pa,
            } => {
                if pressure_pa > cutoff_pressure_pa {
                    Some(0.0)
                } else {
                    Some((c1 * pressure_pa.max(0.0).powf(1.0 / c2) + c3).max(0.0))
                }
            }
            Self::LegacyAppendix { .. } => None,
        }
    }

    /// Pressure below which the clamped K(sigma) is 0, Pa: `(-C3/C1)^C2` when C3 < 0 < C1,
    /// 0 when K(0) >= 0 already. Table 4.3 gives about 3.1e-3 Pa (far below any contact).
    pub fn zero_wear_pressure_pa(&self) -> f64 {
        match *self {
            Self::Modified { c1, c2, c3, .. } if c3 < 0.0 && c1 > 0.0 => (-c3 / c1).powf(c2),
            Self::Modified { c1, c3, .. } if c3 < 0.0 && c1 <= 0.0 => f64::INFINITY,
            _ => 0.0,
        }
    }

    /// Wear volume rate dW/dt, m³/s, for normal force `N` (N), slip speed `v` (m/s) and mean
    /// pressure `sigma = N/A` (Pa): `K(sigma) N v` (eq. 3.13), or the appendix formula.
    #[inline]
    pub fn volume_rate_m3_s(
        &self,
        normal_force_n: f64,
        slip_speed_m_s: f64,
        pressure_pa: f64,
    ) -> f64 {
        match *self {
            Self::LegacyAppendix {
                c1,
                c2,
                c3,
                speed_unit_m_s,
                output_unit_m3,
            } => {
                let kw = if c2 != 0.0 {
                    c1 * normal_force_n.abs().powf(1.0 / c2) + 1.0e-3 * c3
                } else {
                    0.0
                };
                let v_exported = slip_speed_m_s / speed_unit_m_s;
                output_unit_m3 * 1.0e-3 * kw * normal_force_n * v_exported
            }
            _ => {
                let k = self.coefficient_m2_per_n(pressure_pa).unwrap_or(0.0);
                k * normal_force_n * slip_speed_m_s
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modified_law_by_hand_at_10_mpa() {
        // 1e7^(1/6.3197) = exp(ln(1e7)/6.3197); K = 2.3685e-15 * that - 9.5089e-16 = 2.939647e-14
        let k = WearLaw::table_4_3().coefficient_m2_per_n(1.0e7).unwrap();
        let by_hand = 2.3685e-15 * (16.118095651_f64 / 6.3197).exp() - 9.5089e-16;
        assert!((k - by_hand).abs() / by_hand < 1e-9);
        assert!((k - 2.939647e-14).abs() / 2.94e-14 < 1e-6, "{k}");
    }

    #[test]
    fn cutoff_is_two_yield_strengths_and_k_vanishes_above() {
        let law = WearLaw::table_4_3();
        assert_eq!(law.cutoff_pressure_pa(), 870.0e6);
        assert!(law.coefficient_m2_per_n(870.0e6).unwrap() > 0.0);
        assert_eq!(law.coefficient_m2_per_n(870.1e6), Some(0.0));
    }

    #[test]
    fn zero_crossing_pressure() {
        let law = WearLaw::table_4_3();
        let s0 = law.zero_wear_pressure_pa();
        // (9.5089e-16 / 2.3685e-15)^6.3197 = 0.401474^6.3197 = exp(6.3197 ln 0.401474)
        let by_hand = (6.3197 * (9.5089e-16_f64 / 2.3685e-15).ln()).exp();
        assert!((s0 - by_hand).abs() / by_hand < 1e-12);
        assert!((s0 - 3.128e-3).abs() < 0.005e-3, "{s0}");
        // Unclamped K changes sign there; the clamped K is 0 below and positive above.
        assert_eq!(law.coefficient_m2_per_n(0.5 * s0), Some(0.0));
        assert_eq!(law.coefficient_m2_per_n(0.0), Some(0.0));
        assert!(law.coefficient_m2_per_n(2.0 * s0).unwrap() > 0.0);
    }

    #[test]
    fn archard_is_the_c1_zero_special_case() {
        let k_over_h = 3.0e-14;
        let archard = WearLaw::Archard {
            coefficient_m2_per_n: k_over_h,
        };
        let modified = WearLaw::Modified {
            c1: 0.0,
            c2: 1.0,
            c3: k_over_h,
            cutoff_pressure_pa: f64::INFINITY,
        };
        for sigma in [1.0, 1e5, 1e8, 1e12] {
            let a = archard.volume_rate_m3_s(50.0, 0.2, sigma);
            let m = modified.volume_rate_m3_s(50.0, 0.2, sigma);
            assert_eq!(a, 50.0 * 0.2 * k_over_h);
            assert!((a - m).abs() <= 1e-30);
        }
    }

    #[test]
    fn legacy_formula_on_a_hand_case() {
        // N = 16 N, v = 2 mm/s (exported as 2), C1 = 1e-3, C2 = 2, C3 = 5:
        // Kw = 1e-3 * sqrt(16) + 1e-3 * 5 = 9e-3; dW/dt = 1e-3 * 9e-3 * 16 * 2 = 2.88e-4 units/s.
        let law = WearLaw::LegacyAppendix {
            c1: 1e-3,
            c2: 2.0,
            c3: 5.0,
            speed_unit_m_s: 1e-3,
            output_unit_m3: 1e-18,
        };
        let r = law.volume_rate_m3_s(16.0, 2.0e-3, 123.0);
        assert!((r - 2.88e-4 * 1e-18).abs() < 1e-30, "{r}");
        // The pressure argument is ignored: the code feeds N, not sigma.
        assert_eq!(r, law.volume_rate_m3_s(16.0, 2.0e-3, 9e9));
        assert_eq!(law.quadrature(), Quadrature::RightEndpointFromZero);
    }

    #[test]
    fn serde_uses_a_snake_case_kind_tag() {
        let s = serde_json::to_string(&WearLaw::Archard {
            coefficient_m2_per_n: 1e-14,
        })
        .unwrap();
        assert_eq!(s, r#"{"kind":"archard","coefficient_m2_per_n":1e-14}"#);
        let back: WearLaw = serde_json::from_str(
            r#"{"kind":"legacy_appendix","c1":1,"c2":2,"c3":3,"speed_unit_m_s":0.001,"output_unit_m3":1e-18}"#,
        )
        .unwrap();
        assert!(matches!(back, WearLaw::LegacyAppendix { .. }));
    }

    #[test]
    fn validation_names_the_field() {
        let law = WearLaw::Modified {
            c1: 1.0,
            c2: 0.0,
            c3: 0.0,
            cutoff_pressure_pa: 1.0,
        };
        assert_eq!(
            law.validate(),
            Err(FieldError::new("c2", "must be a finite number > 0").into())
        );
        assert!(WearLaw::table_4_3().validate().is_ok());
    }
}
