//! Bulk material properties used by wear allocation and the quasistatic contact models.

use super::WearError;
use crate::field_error::FieldError;
use crate::thesis;
use serde::{Deserialize, Serialize};

/// Pa per Brinell unit: HB is a load in kgf over an area in mm², so 1 HB = 9.80665 N/mm².
pub const PA_PER_HB: f64 = crate::units::STANDARD_GRAVITY * 1.0e6;

/// Isotropic material of a body (thesis eq. 2.43-2.45 and SPEC section 3 for 7075-T73).
///
/// The one material type: case files name it `material` with these field names, the models
/// build bodies and contacts from it, wear allocation splits volumes with it. Its default, and
/// the one source of the thesis' material, is [`Material::aluminium_7075_t73`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Bulk density rho, kg/m³ (eq. 4.17: wear mass = rho * wear volume).
    pub density_kg_per_m3: f64,
    /// Yield strength S_y, Pa (eq. 2.45; sets the wear-law cutoff of eq. 3.11).
    pub yield_strength_pa: f64,
    /// Young's modulus E, Pa (eq. 2.43).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio nu, dimensionless (eq. 2.44).
    pub poisson_ratio: f64,
    /// Brinell hardness, HB (kgf/mm²). Used for the inverse-hardness volume split.
    pub brinell_hardness: f64,
}

impl Default for Material {
    /// 7075-T73 aluminium, anodized (thesis 4.2.1, SPEC 3).
    fn default() -> Self {
        Self::aluminium_7075_t73()
    }
}

impl Material {
    /// 7075-T73 aluminium: 2810 kg/m³, S_y 435 MPa, E 72 GPa, nu 0.33, 135 HB (eq. 2.43-2.45).
    pub fn aluminium_7075_t73() -> Self {
        Self {
            density_kg_per_m3: thesis::DENSITY_7075_KG_PER_M3,
            yield_strength_pa: thesis::YIELD_STRENGTH_7075_PA,
            youngs_modulus_pa: thesis::YOUNGS_MODULUS_7075_PA,
            poisson_ratio: thesis::POISSON_RATIO_7075,
            brinell_hardness: thesis::BRINELL_HARDNESS_7075,
        }
    }

    /// Brinell hardness in Pa (HB * 9.80665e6). 135 HB is about 1.324 GPa.
    pub fn hardness_pa(&self) -> f64 {
        self.brinell_hardness * PA_PER_HB
    }

    /// Plane-strain modulus E / (1 - nu²), Pa: this body's share of eq. 2.6.
    pub fn plane_strain_modulus_pa(&self) -> f64 {
        self.youngs_modulus_pa / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }

    /// Effective modulus E* of a pair (eq. 2.6), Pa. 7075 on 7075 gives 40.39 GPa (eq. 2.47).
    pub fn effective_modulus_pa(&self, other: &Material) -> f64 {
        1.0 / (1.0 / self.plane_strain_modulus_pa() + 1.0 / other.plane_strain_modulus_pa())
    }

    /// Checks every field is finite and physical: all > 0, Poisson's ratio in (-1, 0.5). The
    /// error names the field and its value.
    pub fn validate(&self) -> Result<(), WearError> {
        let positive = [
            ("density_kg_per_m3", self.density_kg_per_m3),
            ("yield_strength_pa", self.yield_strength_pa),
            ("youngs_modulus_pa", self.youngs_modulus_pa),
            ("brinell_hardness", self.brinell_hardness),
        ];
        for (field, x) in positive {
            if !(x.is_finite() && x > 0.0) {
                return Err(FieldError::new(
                    field,
                    format!("must be a finite number > 0, got {x}"),
                )
                .into());
            }
        }
        let nu = self.poisson_ratio;
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(FieldError::new(
                "poisson_ratio",
                format!("must lie in (-1, 0.5), got {nu}"),
            )
            .into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn effective_modulus_matches_eq_2_47() {
        let m = Material::aluminium_7075_t73();
        // eq. 2.46: 1/E* = 2 (1 - 0.33²) / 72 GPa -> 40.39 GPa (eq. 2.47).
        let e_star = m.effective_modulus_pa(&m);
        assert!((e_star - 40.39e9).abs() < 0.01e9, "{e_star}");
        assert!(m.validate().is_ok());
    }

    #[test]
    fn brinell_to_pascal() {
        let m = Material::aluminium_7075_t73();
        assert!((m.hardness_pa() - 135.0 * 9.80665e6).abs() < 1.0);
    }

    #[test]
    fn validation_names_the_field() {
        let mut m = Material::aluminium_7075_t73();
        m.poisson_ratio = 0.7;
        assert_eq!(
            m.validate(),
            Err(FieldError::new("poisson_ratio", "must lie in (-1, 0.5), got 0.7").into())
        );
        m.poisson_ratio = 0.33;
        m.density_kg_per_m3 = -1.0;
        assert!(matches!(
            m.validate(),
            Err(WearError::Invalid(FieldError { ref field, .. })) if field == "density_kg_per_m3"
        ));
    }

    #[test]
    fn a_case_file_material_reads_into_the_one_type() {
        // The field names of case files (configs/*.toml `[rattle_box.material]`).
        let m: Material = toml::from_str(
            "density_kg_per_m3 = 2810.0\nyield_strength_pa = 435.0e6\n\
             youngs_modulus_pa = 72.0e9\npoisson_ratio = 0.33\nbrinell_hardness = 135.0\n",
        )
        .expect("material");
        assert_eq!(m, Material::default());
        assert!(toml::from_str::<Material>("density_kg_m3 = 2810.0").is_err());
    }
}
