//! Chapter 5: the rattle box.

use crate::analysis::rattle_space::{self, RattleSpaceError};
use crate::field_error::FieldError;
use crate::models::spec::{
    non_negative, path, positive, validate_friction, validate_material, ContactSpec, EDGE_RADIUS,
    LENGTH, MAX_TEXT_CHARS,
};
use crate::parameters::{Bound, Bounded, FieldPath};
use crate::physics::friction::{in_mm_per_s, FrictionParams};
use crate::units;
use crate::wear::material::Material;
use serde::{Deserialize, Serialize};

/// Table 5.1 enclosure (tube inner) sides, inches, for cases A-D (1 in cube).
pub const TABLE_5_1_TUBE_SIDES_IN: [(&str, f64); 4] =
    [("A", 2.0), ("B", 1.5), ("C", 1.25), ("D", 1.125)];

/// Rattle box, thesis chapter 5 (Figures 5.1-5.4): an aluminium cube free inside a long square
/// tube with capped ends; the tube is driven (kinematic) by the shaker. Frame: tube axis along z,
/// y vertical (gravity -y), x transverse (the excitation axis of Figures 5.1-5.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RattleBoxSpec {
    /// Table 5.1 case letter (`A`..`D`), or another label for a custom enclosure.
    pub case: String,
    /// Cube and tube material (thesis 5.3.1: anodized aluminium, as chapter 4).
    #[serde(default)]
    pub material: Material,
    /// Cube side, m (thesis 5.3.2: 1 in = 0.0254 m).
    pub cube_side_m: f64,
    /// Cube mass, kg. Omitted: density x side³ (the thesis matches the real fixture's mass but
    /// does not state it; 7075 at 2810 kg/m³ gives 46.05 g).
    #[serde(default)]
    pub cube_mass_kg: Option<f64>,
    /// Tube inner side, m (Table 5.1: 2.0, 1.5, 1.25, 1.125 in).
    pub tube_inner_side_m: f64,
    /// Tube inner length between the end caps, m. Estimate ("very long", thesis 5.2).
    pub tube_length_m: f64,
    /// Whether the tube ends are capped (thesis 5.3.1: yes), i.e. two end faces are contacts.
    #[serde(default = "default_true")]
    pub end_caps: bool,
    /// Edge roundover of cube and tube, m (thesis 5.4: 0.02 in = 0.508 mm).
    pub edge_radius_m: f64,
    /// Cube-tube contact, Table 5.2.
    pub contact: ContactSpec,
    /// Cube-tube friction, Table 5.2.
    #[serde(with = "in_mm_per_s")]
    pub friction: FrictionParams,
}

/// The cube's mass, kg.
const MASS: Bound = Bound::new(
    1.0e-4,
    1.0e4,
    "kg",
    "from 0.1 g (a chip, not a body) to 10 t (the heaviest air-launched stores)",
);

impl Bounded for RattleBoxSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.text("case", &self.case, MAX_TEXT_CHARS, false)?;
        at.child("material", &self.material)?;
        at.number("cube_side_m", self.cube_side_m, &LENGTH)?;
        at.optional("cube_mass_kg", self.cube_mass_kg, &MASS)?;
        at.number("tube_inner_side_m", self.tube_inner_side_m, &LENGTH)?;
        at.number("tube_length_m", self.tube_length_m, &LENGTH)?;
        at.number("edge_radius_m", self.edge_radius_m, &EDGE_RADIUS)?;
        at.child("contact", &self.contact)?;
        at.child("friction", &self.friction)
    }
}

fn default_true() -> bool {
    true
}

impl RattleBoxSpec {
    /// Cube mass, kg: the given value, else density x side³.
    pub fn cube_mass_kg(&self) -> f64 {
        self.cube_mass_kg
            .unwrap_or(self.material.density_kg_per_m3 * self.cube_side_m.powi(3))
    }

    /// Cube principal moment of inertia about its centre, kg·m²: `m a² / 6` (solid cube; the
    /// roundover changes it by under 1 %).
    pub fn cube_inertia_kg_m2(&self) -> f64 {
        self.cube_mass_kg() * self.cube_side_m * self.cube_side_m / 6.0
    }

    /// Rattle space, eq. 5.1-5.2.
    pub fn rattle_space(&self) -> Result<f64, RattleSpaceError> {
        rattle_space::rattle_space_square(self.cube_side_m, self.tube_inner_side_m)
    }

    /// Field rules, plus: the cube fits the tube (in section and length), the roundover is
    /// smaller than half the cube side, and a Table 5.1 letter uses Table 5.1's tube side.
    pub fn validate(&self, prefix: &str) -> Result<(), FieldError> {
        validate_material(&self.material, &path(prefix, "material"))?;
        positive(prefix, "cube_side_m", self.cube_side_m)?;
        if let Some(m) = self.cube_mass_kg {
            positive(prefix, "cube_mass_kg", m)?;
        }
        positive(prefix, "tube_inner_side_m", self.tube_inner_side_m)?;
        positive(prefix, "tube_length_m", self.tube_length_m)?;
        non_negative(prefix, "edge_radius_m", self.edge_radius_m)?;
        if self.edge_radius_m >= 0.5 * self.cube_side_m {
            return Err(FieldError::new(
                path(prefix, "edge_radius_m"),
                "must be smaller than half the cube side",
            ));
        }
        if self.tube_inner_side_m < self.cube_side_m {
            return Err(FieldError::new(
                path(prefix, "tube_inner_side_m"),
                format!(
                    "interference: tube inner side {} m is smaller than the cube side {} m",
                    self.tube_inner_side_m, self.cube_side_m
                ),
            ));
        }
        if self.tube_length_m < self.cube_side_m {
            return Err(FieldError::new(
                path(prefix, "tube_length_m"),
                "must be at least the cube side",
            ));
        }
        if let Some((_, side_in)) = TABLE_5_1_TUBE_SIDES_IN
            .iter()
            .find(|(c, _)| *c == self.case)
        {
            if (self.tube_inner_side_m - units::inch(*side_in)).abs() > 1e-6 {
                return Err(FieldError::new(
                    path(prefix, "tube_inner_side_m"),
                    format!(
                        "case {} of Table 5.1 has a {side_in} in ({} m) tube; use another case \
                         label for a custom enclosure",
                        self.case,
                        units::inch(*side_in)
                    ),
                ));
            }
        }
        self.contact.validate(&path(prefix, "contact"))?;
        validate_friction(&self.friction, &path(prefix, "friction"))?;
        Ok(())
    }
}
