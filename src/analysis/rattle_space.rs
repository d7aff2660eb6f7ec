//! Rattle space `k_rs = A_item / A_enclosure`, thesis eq. 5.1-5.2 (rattle box) and eq. 6.1-6.3
//! (launcher rear shoe in the rail extrusion).
//!
//! Rattle space is a planar, dimensionless measure of how much room a rattling item has: 1 means
//! no room at all (no relative motion, no wear), small values a small item in a large enclosure.
//! It is cheap to compute from measured dimensions, which is why the service-life penalization
//! (eq. 6.4, [`crate::analysis::penalization`]) is indexed by it.
//!
//! The thesis' dimension drawings (Figures 6.29, 6.30) did not survive, so the physical meaning of
//! each letter in [`LauncherDimensions`] is inferred from the role it plays in eq. 6.1-6.2; the
//! decisions are listed in `docs/reference/launcher-dimensions.md`.

use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Why a rattle space could not be computed. Names the offending field and the rule it broke.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RattleSpaceError {
    /// A dimension is not usable: not finite, not positive, implausible in magnitude, or it
    /// describes an item that cannot fit its enclosure (interference).
    /// (The field is named as in the struct / JSON body, e.g. `n_shoe_mm`.)
    #[error("invalid dimension `{}`: {}", .0.field, .0.rule)]
    InvalidDimension(#[from] FieldError),
}

/// Checks that a length is a finite number > 0.
fn positive_finite(field: &'static str, value: f64) -> Result<(), RattleSpaceError> {
    if !value.is_finite() {
        return Err(FieldError::new(field, format!("must be a finite number, got {value}")).into());
    }
    if value <= 0.0 {
        return Err(FieldError::new(field, format!("must be > 0, got {value}")).into());
    }
    Ok(())
}

/// Rattle space of a rectangular item in a rectangular enclosure, eq. 5.2:
/// `k_rs = (A1 * A2) / (B1 * B2)`. Any consistent length unit.
///
/// The item must fit: `A1 <= B1` and `A2 <= B2` (equality is the closed-form case k_rs = 1).
pub fn rattle_space_rectangular(
    item_side_1: f64,
    item_side_2: f64,
    enclosure_side_1: f64,
    enclosure_side_2: f64,
) -> Result<f64, RattleSpaceError> {
    positive_finite("item_side_1", item_side_1)?;
    positive_finite("item_side_2", item_side_2)?;
    positive_finite("enclosure_side_1", enclosure_side_1)?;
    positive_finite("enclosure_side_2", enclosure_side_2)?;
    if item_side_1 > enclosure_side_1 {
        return Err(FieldError::new(
            "item_side_1",
            format!(
                "interference: item side {item_side_1} exceeds enclosure side {enclosure_side_1}"
            ),
        )
        .into());
    }
    if item_side_2 > enclosure_side_2 {
        return Err(FieldError::new(
            "item_side_2",
            format!(
                "interference: item side {item_side_2} exceeds enclosure side {enclosure_side_2}"
            ),
        )
        .into());
    }
    // eq. 5.1 with the areas of eq. 5.2
    Ok((item_side_1 * item_side_2) / (enclosure_side_1 * enclosure_side_2))
}

/// Rattle space of the rattle box (thesis chapter 5): a cube of side `cube_side` in a square tube
/// of inner side `tube_inner_side` (same unit), eq. 5.2 with `A1 = A2`, `B1 = B2`.
/// Table 5.1: 1 in cube in 2.0 / 1.5 / 1.25 / 1.125 in tubes gives 0.25 / 0.44 / 0.64 / 0.79.
pub fn rattle_space_square(cube_side: f64, tube_inner_side: f64) -> Result<f64, RattleSpaceError> {
    rattle_space_rectangular(cube_side, cube_side, tube_inner_side, tube_inner_side).map_err(
        |RattleSpaceError::InvalidDimension(FieldError { field, rule })| {
            let field = if field.starts_with("item") {
                "cube_side"
            } else {
                "tube_inner_side"
            }
            .to_string();
            RattleSpaceError::InvalidDimension(FieldError { field, rule })
        },
    )
}

/// Smallest plausible launcher dimension, mm. Every lettered dimension of a Hellfire-class rail
/// or rear shoe is several millimetres or more; a value below this is most likely the right
/// number in the wrong unit (inches: a 1.5 in head reads 1.5; metres: 38 mm reads 0.038).
pub const MIN_PLAUSIBLE_DIMENSION_MM: f64 = 2.0;
/// Largest plausible launcher dimension, mm: larger than the 178 mm missile body diameter is not
/// a shoe or channel dimension (most likely micrometres, or a typing error).
pub const MAX_PLAUSIBLE_DIMENSION_MM: f64 = 178.0;

/// Plausible range of each measured dimension, as a fraction of its design value
/// ([`LauncherDimensions::design`]): every field must lie within ±50 % of it. Far wider than
/// the manufacturing tolerance (±0.2 mm, [`TIGHT_MATERIAL_CONDITION_MM`] to
/// [`LOOSE_MATERIAL_CONDITION_MM`]) and any wear, narrow enough to refuse another rail class
/// or a slipped digit (a 170 mm slot in a rail designed for 10.23 mm).
pub const PLAUSIBLE_FRACTION_OF_DESIGN: f64 = 0.5;

/// Tolerance (material condition) offset of the tightest in-tolerance rail, mm
/// (see [`LauncherDimensions::with_material_condition`]). Solved so that eq. 6.1-6.3 give the
/// thesis' tight rattle space 0.8317 (thesis 6.4.2) to four decimals.
pub const TIGHT_MATERIAL_CONDITION_MM: f64 = -0.201;
/// Tolerance (material condition) offset of the loosest in-tolerance rail, mm. Solved so that
/// eq. 6.1-6.3 give the thesis' loose rattle space 0.7684 (thesis 6.4.2) to four decimals.
pub const LOOSE_MATERIAL_CONDITION_MM: f64 = 0.1955;

/// The lettered rear-shoe (Figure 6.29) and rail-extrusion (Figure 6.30) dimensions that enter
/// eq. 6.1-6.2, in millimetres (the unit planners measure in).
///
/// Frame: the cross-section of the rail channel in the rail's x-y plane (x transverse, y vertical
/// towards the vehicle). The rail channel is a T-slot: two lips leave a slot of width `B_rail`
/// through which the shoe's neck passes; above the lips the chamber holds the shoe's head
/// (flange). The missile hangs below the rail. The shoe letters B..E and the other rail letters do
/// not enter eq. 6.1-6.2 and are not fields here. Letter meanings are inferred from eq. 6.1-6.2 (the
/// drawings are lost); see `docs/reference/launcher-dimensions.md`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LauncherDimensions {
    /// Shoe A, mm: overall width of the shoe head (flange), transverse (x). Eq. 6.1, 6.2.
    pub a_shoe_mm: f64,
    /// Shoe F, mm: overall height of the shoe (base to head top) at the front-left station.
    /// `F - G` is the neck height there. Eq. 6.1.
    pub f_shoe_mm: f64,
    /// Shoe G, mm: head (flange) thickness at the front-left station. Eq. 6.1.
    pub g_shoe_mm: f64,
    /// Shoe H, mm: overall shoe height at the front-right station. Eq. 6.1.
    pub h_shoe_mm: f64,
    /// Shoe I, mm: head thickness at the front-right station. Eq. 6.1.
    pub i_shoe_mm: f64,
    /// Shoe J, mm: overall shoe height at the rear-left station. Eq. 6.1.
    pub j_shoe_mm: f64,
    /// Shoe K, mm: head thickness at the rear-left station; also the head thickness used for the
    /// item area of eq. 6.2. Eq. 6.1, 6.2.
    pub k_shoe_mm: f64,
    /// Shoe L, mm: overall shoe height at the rear-right station. Eq. 6.1.
    pub l_shoe_mm: f64,
    /// Shoe M, mm: head thickness at the rear-right station. Eq. 6.1.
    pub m_shoe_mm: f64,
    /// Shoe N, mm: neck (web) width at the front end, transverse. Eq. 6.1, 6.2.
    pub n_shoe_mm: f64,
    /// Shoe O, mm: neck (web) width at the rear end, transverse. Eq. 6.1.
    pub o_shoe_mm: f64,
    /// Rail B, mm: width of the slot between the two rail lips (the neck rides in it). Eq. 6.1.
    pub b_rail_mm: f64,
    /// Rail N, mm: chamber height on the left side, lip top face to chamber roof. Eq. 6.1, 6.2.
    pub n_rail_mm: f64,
    /// Rail Q, mm: chamber height on the right side, lip top face to chamber roof. Eq. 6.1.
    pub q_rail_mm: f64,
}

impl LauncherDimensions {
    /// The named design (nominal) rail and rear shoe, an engineering estimate for a Hellfire
    /// M299-class rail (the thesis' drawings are lost): 38.10 mm (1.5 in) head, 9.53 mm (3/8 in)
    /// neck and head thickness, 6.70 mm neck height, 0.70 mm slot clearance and 0.60 mm vertical
    /// clearance. Eq. 6.1-6.3 give k_rs = 0.7990, the thesis' design value (6.4.2).
    pub const fn design() -> Self {
        Self {
            a_shoe_mm: 38.10,
            f_shoe_mm: 16.23,
            g_shoe_mm: 9.53,
            h_shoe_mm: 16.23,
            i_shoe_mm: 9.53,
            j_shoe_mm: 16.23,
            k_shoe_mm: 9.53,
            l_shoe_mm: 16.23,
            m_shoe_mm: 9.53,
            n_shoe_mm: 9.53,
            o_shoe_mm: 9.53,
            b_rail_mm: 10.23,
            n_rail_mm: 10.13,
            q_rail_mm: 10.13,
        }
    }

    /// Tightest in-tolerance rail: [`Self::design`] at [`TIGHT_MATERIAL_CONDITION_MM`]
    /// (k_rs = 0.8317, thesis 6.4.2).
    pub fn tight() -> Self {
        Self::design().with_material_condition(TIGHT_MATERIAL_CONDITION_MM)
    }

    /// Loosest in-tolerance rail: [`Self::design`] at [`LOOSE_MATERIAL_CONDITION_MM`]
    /// (k_rs = 0.7684, thesis 6.4.2).
    pub fn loose() -> Self {
        Self::design().with_material_condition(LOOSE_MATERIAL_CONDITION_MM)
    }

    /// Moves every dimension by `offset_mm` towards least material (positive: looser): rail
    /// (enclosure) dimensions grow by `offset_mm`, shoe dimensions shrink by it. Neck heights
    /// (`F - G` etc.) are unchanged; slot and vertical clearances grow by `2 * offset_mm`.
    pub fn with_material_condition(&self, offset_mm: f64) -> Self {
        let shoe = |x: f64| x - offset_mm;
        let rail = |x: f64| x + offset_mm;
        Self {
            a_shoe_mm: shoe(self.a_shoe_mm),
            f_shoe_mm: shoe(self.f_shoe_mm),
            g_shoe_mm: shoe(self.g_shoe_mm),
            h_shoe_mm: shoe(self.h_shoe_mm),
            i_shoe_mm: shoe(self.i_shoe_mm),
            j_shoe_mm: shoe(self.j_shoe_mm),
            k_shoe_mm: shoe(self.k_shoe_mm),
            l_shoe_mm: shoe(self.l_shoe_mm),
            m_shoe_mm: shoe(self.m_shoe_mm),
            n_shoe_mm: shoe(self.n_shoe_mm),
            o_shoe_mm: shoe(self.o_shoe_mm),
            b_rail_mm: rail(self.b_rail_mm),
            n_rail_mm: rail(self.n_rail_mm),
            q_rail_mm: rail(self.q_rail_mm),
        }
    }

    /// All fields with their names, in declaration order.
    pub fn named_fields(&self) -> [(&'static str, f64); 14] {
        [
            ("a_shoe_mm", self.a_shoe_mm),
            ("f_shoe_mm", self.f_shoe_mm),
            ("g_shoe_mm", self.g_shoe_mm),
            ("h_shoe_mm", self.h_shoe_mm),
            ("i_shoe_mm", self.i_shoe_mm),
            ("j_shoe_mm", self.j_shoe_mm),
            ("k_shoe_mm", self.k_shoe_mm),
            ("l_shoe_mm", self.l_shoe_mm),
            ("m_shoe_mm", self.m_shoe_mm),
            ("n_shoe_mm", self.n_shoe_mm),
            ("o_shoe_mm", self.o_shoe_mm),
            ("b_rail_mm", self.b_rail_mm),
            ("n_rail_mm", self.n_rail_mm),
            ("q_rail_mm", self.q_rail_mm),
        ]
    }

    /// Checks measured dimensions. Rules, in order (the first broken one is reported):
    /// 1. every field is a finite number > 0;
    /// 2. every field lies in [`MIN_PLAUSIBLE_DIMENSION_MM`, `MAX_PLAUSIBLE_DIMENSION_MM`] (below:
    ///    probably inches or metres entered as mm; above: larger than the missile);
    /// 3. the shoe is a T: head thickness < overall height at each station (`G < F`, `I < H`,
    ///    `K < J`, `M < L`) and neck width < head width (`N < A`, `O < A`);
    /// 4. the shoe is held: its head is wider than the slot (`A > B_rail`), or it pulls out;
    /// 5. no interference: the neck is narrower than the slot (`N < B_rail`, `O < B_rail`, which
    ///    also makes the head narrower than the chamber, whose eq. 6.1 width is
    ///    `B_rail + A - mean(N, O)`), and the head is thinner than the chamber is high
    ///    (`G, I, K, M < min(N_rail, Q_rail)`);
    /// 6. every field lies within [`PLAUSIBLE_FRACTION_OF_DESIGN`] (±50 %) of its design value.
    pub fn validate(&self) -> Result<(), RattleSpaceError> {
        for (field, value) in self.named_fields() {
            positive_finite(field, value)?;
        }
        for (field, value) in self.named_fields() {
            if value < MIN_PLAUSIBLE_DIMENSION_MM {
                return Err(FieldError::new(
                    field,
                    format!(
                        "{value} mm is below {MIN_PLAUSIBLE_DIMENSION_MM} mm, implausible for a \
                         rail or shoe dimension: probably inches or metres entered as mm"
                    ),
                )
                .into());
            }
            if value > MAX_PLAUSIBLE_DIMENSION_MM {
                return Err(FieldError::new(
                    field,
                    format!(
                        "{value} mm is above {MAX_PLAUSIBLE_DIMENSION_MM} mm (the missile \
                         diameter), implausible for a rail or shoe dimension"
                    ),
                )
                .into());
            }
        }
        let stations = [
            ("g_shoe_mm", self.g_shoe_mm, "f_shoe_mm", self.f_shoe_mm),
            ("i_shoe_mm", self.i_shoe_mm, "h_shoe_mm", self.h_shoe_mm),
            ("k_shoe_mm", self.k_shoe_mm, "j_shoe_mm", self.j_shoe_mm),
            ("m_shoe_mm", self.m_shoe_mm, "l_shoe_mm", self.l_shoe_mm),
        ];
        for (thick_name, thick, height_name, height) in stations {
            if thick >= height {
                return Err(FieldError::new(
                    thick_name,
                    format!(
                        "head thickness {thick} mm must be smaller than the overall shoe height \
                         {height_name} = {height} mm (the neck height would be <= 0)"
                    ),
                )
                .into());
            }
        }
        if self.a_shoe_mm <= self.b_rail_mm {
            return Err(FieldError::new(
                "a_shoe_mm",
                format!(
                    "shoe head width {} mm must be wider than the rail slot b_rail_mm = {} mm: \
                     a narrower head pulls out through the slot (the missile falls out)",
                    self.a_shoe_mm, self.b_rail_mm
                ),
            )
            .into());
        }
        for (neck_name, neck) in [("n_shoe_mm", self.n_shoe_mm), ("o_shoe_mm", self.o_shoe_mm)] {
            if neck >= self.a_shoe_mm {
                return Err(FieldError::new(
                    neck_name,
                    format!(
                        "neck width {neck} mm must be smaller than the head width a_shoe_mm = {} mm",
                        self.a_shoe_mm
                    ),
                ).into());
            }
            if neck >= self.b_rail_mm {
                return Err(FieldError::new(
                    neck_name,
                    format!(
                        "interference: shoe neck width {neck} mm must be smaller than the rail \
                         slot width b_rail_mm = {} mm",
                        self.b_rail_mm
                    ),
                )
                .into());
            }
        }
        let chamber = self.n_rail_mm.min(self.q_rail_mm);
        for (thick_name, thick, _, _) in stations {
            if thick >= chamber {
                return Err(FieldError::new(
                    thick_name,
                    format!(
                        "interference: shoe head thickness {thick} mm must be smaller than the \
                         rail chamber height min(n_rail_mm, q_rail_mm) = {chamber} mm"
                    ),
                )
                .into());
            }
        }
        let design = Self::design().named_fields();
        for ((field, value), (_, nominal)) in self.named_fields().into_iter().zip(design) {
            let lo = nominal * (1.0 - PLAUSIBLE_FRACTION_OF_DESIGN);
            let hi = nominal * (1.0 + PLAUSIBLE_FRACTION_OF_DESIGN);
            if !(lo..=hi).contains(&value) {
                return Err(FieldError::new(
                    field,
                    format!(
                        "{value} mm is outside the plausible range [{lo:.2}, {hi:.2}] mm (design \
                         {nominal} mm +-50 %) of this rail class: a typing error or another rail"
                    ),
                )
                .into());
            }
        }
        Ok(())
    }

    /// Mean neck height `mean(L-M, J-K, F-G, H-I)`, mm (eq. 6.1, first factor).
    pub fn mean_neck_height_mm(&self) -> f64 {
        0.25 * ((self.l_shoe_mm - self.m_shoe_mm)
            + (self.j_shoe_mm - self.k_shoe_mm)
            + (self.f_shoe_mm - self.g_shoe_mm)
            + (self.h_shoe_mm - self.i_shoe_mm))
    }

    /// Mean neck width `mean(N_shoe, O_shoe)`, mm.
    pub fn mean_neck_width_mm(&self) -> f64 {
        0.5 * (self.n_shoe_mm + self.o_shoe_mm)
    }

    /// Chamber width `2 mean((A-N)/2, (A-O)/2) + B_rail = B_rail + A - mean(N, O)`, mm
    /// (eq. 6.1, second term's width).
    pub fn chamber_width_mm(&self) -> f64 {
        2.0 * 0.5
            * (0.5 * (self.a_shoe_mm - self.n_shoe_mm) + 0.5 * (self.a_shoe_mm - self.o_shoe_mm))
            + self.b_rail_mm
    }

    /// Mean chamber height `mean(N_rail, Q_rail)`, mm.
    pub fn mean_chamber_height_mm(&self) -> f64 {
        0.5 * (self.n_rail_mm + self.q_rail_mm)
    }

    /// Transverse clearance of the neck in the slot, `B_rail - mean(N, O)`, mm (also the head's
    /// transverse clearance in the chamber under eq. 6.1's chamber width).
    pub fn transverse_clearance_mm(&self) -> f64 {
        self.b_rail_mm - self.mean_neck_width_mm()
    }

    /// Vertical clearance of the head in the chamber, `min(N_rail, Q_rail) - K`, mm.
    pub fn vertical_clearance_mm(&self) -> f64 {
        self.n_rail_mm.min(self.q_rail_mm) - self.k_shoe_mm
    }

    /// Enclosure area, eq. 6.1, mm²:
    /// `mean(L-M, J-K, F-G, H-I) B_rail + (2 mean((A-N)/2, (A-O)/2) + B_rail) mean(N_rail, Q_rail)`.
    /// Unvalidated; see [`Self::rattle_space`].
    pub fn enclosure_area_mm2(&self) -> f64 {
        self.mean_neck_height_mm() * self.b_rail_mm
            + self.chamber_width_mm() * self.mean_chamber_height_mm()
    }

    /// Rattling item (rear shoe) area, eq. 6.2, mm²: `N_rail N_shoe + K_shoe (A_shoe - N_shoe)`.
    /// Unvalidated; see [`Self::rattle_space`].
    pub fn item_area_mm2(&self) -> f64 {
        self.n_rail_mm * self.n_shoe_mm + self.k_shoe_mm * (self.a_shoe_mm - self.n_shoe_mm)
    }

    /// Rattle space `k_rs = A_ti / A_encl`, eq. 6.3, after [`Self::validate`].
    pub fn rattle_space(&self) -> Result<f64, RattleSpaceError> {
        self.validate()?;
        Ok(self.item_area_mm2() / self.enclosure_area_mm2())
    }
}

impl Default for LauncherDimensions {
    fn default() -> Self {
        Self::design()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_to(x: f64, decimals: i32) -> f64 {
        let s = 10f64.powi(decimals);
        (x * s).round() / s
    }

    #[test]
    fn table_5_1_cases_a_to_d() {
        // 1 in cube; enclosure sides from Table 5.1; rattle spaces to two decimals.
        let cases = [(2.0, 0.25), (1.5, 0.44), (1.25, 0.64), (1.125, 0.79)];
        for (side_in, expected) in cases {
            let k = rattle_space_square(1.0, side_in).unwrap();
            assert_eq!(round_to(k, 2), expected, "enclosure {side_in} in");
        }
        // Unit-free: the same in metres.
        let k_m = rattle_space_square(0.0254, 1.25 * 0.0254).unwrap();
        assert!((k_m - 0.64).abs() < 1e-12);
    }

    #[test]
    fn rattle_box_closed_form_limits_and_errors() {
        // Item equal to the enclosure: k_rs = 1 (thesis 5.3.2, no relative motion).
        assert_eq!(rattle_space_square(1.0, 1.0).unwrap(), 1.0);
        let err = rattle_space_square(1.2, 1.0).unwrap_err();
        assert!(matches!(
            err,
            RattleSpaceError::InvalidDimension(FieldError { ref field, .. }) if field == "cube_side"
        ));
        let err = rattle_space_square(1.0, f64::NAN).unwrap_err();
        assert!(matches!(
            err,
            RattleSpaceError::InvalidDimension(FieldError { ref field, .. }) if field == "tube_inner_side"
        ));
        let err = rattle_space_rectangular(1.0, -1.0, 2.0, 2.0).unwrap_err();
        assert!(matches!(
            err,
            RattleSpaceError::InvalidDimension(FieldError { ref field, .. }) if field == "item_side_2"
        ));
    }

    #[test]
    fn launcher_variants_match_thesis_6_4_2() {
        assert_eq!(
            round_to(LauncherDimensions::tight().rattle_space().unwrap(), 4),
            0.8317
        );
        assert_eq!(
            round_to(LauncherDimensions::design().rattle_space().unwrap(), 4),
            0.7990
        );
        assert_eq!(
            round_to(LauncherDimensions::loose().rattle_space().unwrap(), 4),
            0.7684
        );
    }

    #[test]
    fn tight_is_physically_tight_and_loose_is_loose() {
        let (t, d, l) = (
            LauncherDimensions::tight(),
            LauncherDimensions::design(),
            LauncherDimensions::loose(),
        );
        assert!(t.transverse_clearance_mm() < d.transverse_clearance_mm());
        assert!(d.transverse_clearance_mm() < l.transverse_clearance_mm());
        assert!(t.vertical_clearance_mm() < d.vertical_clearance_mm());
        assert!(d.vertical_clearance_mm() < l.vertical_clearance_mm());
        // Clearances stay positive (tenths of a millimetre) even when tight: no interference.
        assert!(t.transverse_clearance_mm() > 0.1 && t.vertical_clearance_mm() > 0.1);
        assert!(l.transverse_clearance_mm() < 1.5 && l.vertical_clearance_mm() < 1.5);
        // The material condition moves each clearance by twice the offset.
        let dc = l.transverse_clearance_mm() - d.transverse_clearance_mm();
        assert!((dc - 2.0 * LOOSE_MATERIAL_CONDITION_MM).abs() < 1e-12);
        // Neck heights are unchanged by the material condition.
        assert!((t.mean_neck_height_mm() - d.mean_neck_height_mm()).abs() < 1e-12);
    }

    #[test]
    fn eq_6_1_6_2_by_hand_for_the_design_rail() {
        let d = LauncherDimensions::design();
        // Eq. 6.1: 6.70 * 10.23 + (10.23 + 38.10 - 9.53) * 10.13
        let encl = 6.70 * 10.23 + (10.23 + 38.10 - 9.53) * 10.13;
        // Eq. 6.2: 10.13 * 9.53 + 9.53 * (38.10 - 9.53)
        let item = 10.13 * 9.53 + 9.53 * (38.10 - 9.53);
        assert!((d.enclosure_area_mm2() - encl).abs() < 1e-9);
        assert!((d.item_area_mm2() - item).abs() < 1e-9);
    }

    #[test]
    fn validation_names_the_field() {
        let field_of = |d: LauncherDimensions| match d.rattle_space().unwrap_err() {
            RattleSpaceError::InvalidDimension(FieldError { field, .. }) => field,
        };
        let base = LauncherDimensions::design();
        assert_eq!(
            field_of(LauncherDimensions {
                b_rail_mm: f64::NAN,
                ..base
            }),
            "b_rail_mm"
        );
        assert_eq!(
            field_of(LauncherDimensions {
                q_rail_mm: f64::INFINITY,
                ..base
            }),
            "q_rail_mm"
        );
        assert_eq!(
            field_of(LauncherDimensions {
                a_shoe_mm: -38.1,
                ..base
            }),
            "a_shoe_mm"
        );
        assert_eq!(
            field_of(LauncherDimensions {
                m_shoe_mm: 0.0,
                ..base
            }),
            "m_shoe_mm"
        );
        // Inches entered as mm (1.5 in head) and metres entered as mm.
        assert_eq!(
            field_of(LauncherDimensions {
                a_shoe_mm: 1.5,
                ..base
            }),
            "a_shoe_mm"
        );
        assert_eq!(
            field_of(LauncherDimensions {
                n_rail_mm: 0.01013,
                ..base
            }),
            "n_rail_mm"
        );
        assert_eq!(
            field_of(LauncherDimensions {
                f_shoe_mm: 1623.0,
                ..base
            }),
            "f_shoe_mm"
        );
        // Interference: the neck wider than the slot; the head thicker than the chamber.
        assert_eq!(
            field_of(LauncherDimensions {
                o_shoe_mm: 10.5,
                ..base
            }),
            "o_shoe_mm"
        );
        assert_eq!(
            field_of(LauncherDimensions {
                k_shoe_mm: 10.2,
                ..base
            }),
            "k_shoe_mm"
        );
        // Not a T: head thicker than the overall height.
        assert_eq!(
            field_of(LauncherDimensions {
                i_shoe_mm: 17.0,
                ..base
            }),
            "i_shoe_mm"
        );
        // And the rule text says why.
        let err = LauncherDimensions {
            n_shoe_mm: 11.0,
            ..base
        }
        .validate()
        .unwrap_err();
        assert!(err.to_string().contains("interference"), "{err}");
    }

    #[test]
    fn assembly_and_plausible_ranges() {
        let field_of = |d: LauncherDimensions| match d.validate().unwrap_err() {
            RattleSpaceError::InvalidDimension(FieldError { field, rule }) => (field, rule),
        };
        let base = LauncherDimensions::design();
        // Issue 17: a 10.0 mm head in a 10.23 mm slot falls out (neck 9.53 still fits).
        let (field, rule) = field_of(LauncherDimensions {
            a_shoe_mm: 10.0,
            ..base
        });
        assert_eq!(field, "a_shoe_mm");
        assert!(rule.contains("b_rail_mm"), "{rule}");
        // A 170 mm slot: within the global [2, 178] mm but not this rail class.
        let (field, rule) = field_of(LauncherDimensions {
            b_rail_mm: 170.0,
            a_shoe_mm: 175.0,
            ..base
        });
        assert!(
            field == "b_rail_mm" || field == "a_shoe_mm",
            "{field}: {rule}"
        );
        assert!(rule.contains("plausible"), "{rule}");
        // The named tolerance extremes stay valid.
        assert!(LauncherDimensions::tight().validate().is_ok());
        assert!(LauncherDimensions::loose().validate().is_ok());
    }

    #[test]
    fn measured_json_round_trips_and_rejects_unknown_fields() {
        let d = LauncherDimensions::loose();
        let json = serde_json::to_string(&d).unwrap();
        let back: LauncherDimensions = serde_json::from_str(&json).unwrap();
        assert_eq!(back, d);
        let bad = json.replace("\"a_shoe_mm\"", "\"a_shoe_in\"");
        assert!(serde_json::from_str::<LauncherDimensions>(&bad).is_err());
    }
}
