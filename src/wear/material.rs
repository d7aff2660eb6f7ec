//! Bulk material properties used by wear allocation and the quasistatic contact models.

use super::WearError;
use serde::{Deserialize, Serialize};

/// Pa per Brinell unit: HB is a load in kgf over an area in mm², so 1 HB = 9.80665 N/mm².
pub const PA_PER_HB: f64 = crate::units::STANDARD_GRAVITY * 1.0e6;

/// Isotropic material of a body (thesis eq. 2.43-2.45 and SPEC section 3 for 7075-T73).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Bulk density rho, kg/m³ (eq. 4.17: wear mass = rho * wear volume).
    pub density_kg_m3: f64,
    /// Yield strength S_y, Pa (eq. 2.45; sets the wear-law cutoff of eq. 3.11).
    pub yield_strength_pa: f64,
    /// Young's modulus E, Pa (eq. 2.43).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio nu, dimensionless (eq. 2.44).
    pub poisson_ratio: f64,
    /// Brinell hardness, HB (kgf/mm²). Used for the inverse-hardness volume split.
    pub brinell_hardness_hb: f64,
}

impl Material {
    /// 7075-T73 aluminium: 2810 kg/m³, S_y 435 MPa, E 72 GPa, nu 0.33, 135 HB (eq. 2.43-2.45).
    pub fn aluminium_7075_t73() -> Self {
        Self {
            density_kg_m3: 2810.0,
            yield_strength_pa: 435.0e6,
            youngs_modulus_pa: 72.0e9,
            poisson_ratio: 0.33,
            brinell_hardness_hb: 135.0,
        }
    }

    /// Brinell hardness in Pa (HB * 9.80665e6). 135 HB is about 1.324 GPa.
    pub fn hardness_pa(&self) -> f64 {
        self.brinell_hardness_hb * PA_PER_HB
    }

    /// Plane-strain modulus E / (1 - nu²), Pa: this body's share of eq. 2.6.
    pub fn plane_strain_modulus_pa(&self) -> f64 {
        self.youngs_modulus_pa / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }

    /// Effective modulus E* of a pair (eq. 2.6), Pa. 7075 on 7075 gives 40.39 GPa (eq. 2.47).
    pub fn effective_modulus_pa(&self, other: &Material) -> f64 {
        1.0 / (1.0 / self.plane_strain_modulus_pa() + 1.0 / other.plane_strain_modulus_pa())
    }

    /// Checks every field is finite and physical.
    pub fn validate(&self) -> Result<(), WearError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.density_kg_m3) {
            return Err(WearError::invalid(
                "density_kg_m3",
                "must be a finite number > 0",
            ));
        }
        if !positive(self.yield_strength_pa) {
            return Err(WearError::invalid(
                "yield_strength_pa",
                "must be a finite number > 0",
            ));
        }
        if !positive(self.youngs_modulus_pa) {
            return Err(WearError::invalid(
                "youngs_modulus_pa",
                "must be a finite number > 0",
            ));
        }
        if !(self.poisson_ratio.is_finite()
            && self.poisson_ratio > -1.0
            && self.poisson_ratio < 0.5)
        {
            return Err(WearError::invalid("poisson_ratio", "must lie in (-1, 0.5)"));
        }
        if !positive(self.brinell_hardness_hb) {
            return Err(WearError::invalid(
                "brinell_hardness_hb",
                "must be a finite number > 0",
            ));
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
            Err(WearError::invalid("poisson_ratio", "must lie in (-1, 0.5)"))
        );
    }
}
