//! Splitting a contact's wear volume between its two bodies (SPEC section 3) and rate helpers.

use super::material::Material;
use super::WearError;
use crate::field_error::FieldError;
use crate::units::{MG_PER_KG, S_PER_H};
use serde::{Deserialize, Serialize};

/// How a contact's wear volume is shared between body A and body B. Tagged `kind`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum VolumeSplit {
    /// Each body's share is proportional to 1/H (the softer body wears more, Archard's k/H):
    /// share_A = H_B / (H_A + H_B). Equal materials split half and half.
    #[default]
    InverseHardness,
    /// A fixed share to body A, the rest to B.
    Fixed {
        /// Fraction of the volume charged to body A, in [0, 1].
        fraction_to_a: f64,
    },
}

/// Wear charged to one body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyWear {
    /// Wear volume, m³.
    pub volume_m3: f64,
    /// Wear mass = density * volume (eq. 4.17), kg.
    pub mass_kg: f64,
}

impl VolumeSplit {
    /// Fraction of the contact volume charged to body A.
    pub fn fraction_to_a(&self, a: &Material, b: &Material) -> Result<f64, WearError> {
        match *self {
            Self::InverseHardness => {
                let (ha, hb) = (a.hardness_pa(), b.hardness_pa());
                if !(ha.is_finite() && ha > 0.0 && hb.is_finite() && hb > 0.0) {
                    return Err(
                        FieldError::new("brinell_hardness", "must be a finite number > 0").into(),
                    );
                }
                Ok(hb / (ha + hb))
            }
            Self::Fixed { fraction_to_a } => {
                if !(0.0..=1.0).contains(&fraction_to_a) {
                    return Err(FieldError::new("fraction_to_a", "must lie in [0, 1]").into());
                }
                Ok(fraction_to_a)
            }
        }
    }

    /// Splits `volume_m3` (m³, >= 0) into (body A, body B) volumes and masses.
    pub fn split(
        &self,
        volume_m3: f64,
        a: &Material,
        b: &Material,
    ) -> Result<(BodyWear, BodyWear), WearError> {
        if !(volume_m3.is_finite() && volume_m3 >= 0.0) {
            return Err(FieldError::new("volume_m3", "must be a finite number >= 0").into());
        }
        let fa = self.fraction_to_a(a, b)?;
        let va = fa * volume_m3;
        let vb = volume_m3 - va;
        Ok((
            BodyWear {
                volume_m3: va,
                mass_kg: a.density_kg_per_m3 * va,
            },
            BodyWear {
                volume_m3: vb,
                mass_kg: b.density_kg_per_m3 * vb,
            },
        ))
    }
}

/// Mean mass rate in mg/h from a mass (kg) over a duration (s); 0 for a zero duration.
pub fn mass_rate_mg_per_h(mass_kg: f64, duration_s: f64) -> f64 {
    if duration_s > 0.0 {
        mass_kg * MG_PER_KG / (duration_s / S_PER_H)
    } else {
        0.0
    }
}

/// Mean volume rate in m³/h from a volume (m³) over a duration (s); 0 for a zero duration.
pub fn volume_rate_m3_per_h(volume_m3: f64, duration_s: f64) -> f64 {
    if duration_s > 0.0 {
        volume_m3 / (duration_s / S_PER_H)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_hardness_split() {
        let a = Material::aluminium_7075_t73();
        let mut b = a;
        b.brinell_hardness = 3.0 * 135.0; // B three times harder: A takes 3/4.
        let (wa, wb) = VolumeSplit::InverseHardness.split(4.0e-9, &a, &b).unwrap();
        assert!((wa.volume_m3 - 3.0e-9).abs() < 1e-21);
        assert!((wb.volume_m3 - 1.0e-9).abs() < 1e-21);
        assert!((wa.mass_kg - 2810.0 * 3.0e-9).abs() < 1e-18);
        // Equal materials: half each.
        let (h1, h2) = VolumeSplit::InverseHardness.split(2.0, &a, &a).unwrap();
        assert_eq!((h1.volume_m3, h2.volume_m3), (1.0, 1.0));
    }

    #[test]
    fn fixed_split_and_validation() {
        let m = Material::aluminium_7075_t73();
        let (wa, wb) = VolumeSplit::Fixed { fraction_to_a: 1.0 }
            .split(5.0, &m, &m)
            .unwrap();
        assert_eq!((wa.volume_m3, wb.volume_m3), (5.0, 0.0));
        assert_eq!(
            VolumeSplit::Fixed { fraction_to_a: 1.5 }.split(5.0, &m, &m),
            Err(FieldError::new("fraction_to_a", "must lie in [0, 1]").into())
        );
    }

    #[test]
    fn mg_per_hour() {
        // 1 mg over 30 min is 2 mg/h.
        assert!((mass_rate_mg_per_h(1.0e-6, 1800.0) - 2.0).abs() < 1e-12);
        assert_eq!(mass_rate_mg_per_h(1.0, 0.0), 0.0);
    }
}
