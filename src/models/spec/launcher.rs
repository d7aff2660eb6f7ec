//! Chapter 6: what the launcher is, the case file's `[launcher]` table (its lettered dimensions,
//! rail, missile, shoes, latch, springs, contacts, friction and stations) and its field and
//! assembly rules. The geometry derived from it (rail faces, shoe heads) is in
//! `models/launcher/geometry.rs`.

use crate::analysis::rattle_space::{LauncherDimensions, RattleSpaceError};
use crate::field_error::FieldError;
use crate::models::spec::{
    finite, finite3, inertia3, non_negative, path, positive, unit3, validate_friction,
    validate_material, ContactSpec, RoundedBoxSpec, EDGE_RADIUS, LENGTH, MAX_TEXT_CHARS, POSITION,
    UNIT_COMPONENT,
};
use crate::parameters::{Bound, Bounded, FieldPath};
use crate::physics::friction::{in_mm_per_s, FrictionParams};
use crate::physics::step::StepKind;
use crate::units;
use crate::wear::material::Material;
use serde::{Deserialize, Serialize};

/// Rail extrusion layout (kinematic body, driven at its centre of mass, thesis 6.5). The channel
/// cross-section comes from [`LauncherDimensions`]; this places it in the rail frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RailSpec {
    /// Length of the channel along z, m. Estimate.
    pub channel_length_m: f64,
    /// z of the channel's mid-length in the rail frame, m. Estimate.
    pub channel_centre_z_m: f64,
    /// y of the lip top faces (the chamber floor the shoe heads rest on), m. Estimate.
    pub lip_top_y_m: f64,
    /// Lip thickness (slot depth), m; the rail's bottom face is at `lip_top_y_m` minus this.
    /// Must be smaller than the shoes' neck height. Estimate.
    pub lip_thickness_m: f64,
    /// Half width of the rail's bottom face (from the channel centreline to the outer edge), m.
    /// Estimate.
    pub bottom_half_width_m: f64,
}

/// The missile body (rigid, carrying the shoes and the front bearing pad). Missile frame: origin
/// at its centre of mass, axes parallel to the rail frame at assembly (z along the missile axis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissileSpec {
    /// Mass, kg. SPEC 4: about 45 kg (Hellfire class; not given in the thesis).
    pub mass_kg: f64,
    /// Body length, m. SPEC 4: 1.63 m.
    pub length_m: f64,
    /// Body diameter, m. SPEC 4: 0.178 m.
    pub diameter_m: f64,
    /// Principal moments (x, y, z) about the centre of mass, kg·m². Omitted: a solid cylinder of
    /// the given mass, length and diameter (estimate; the thesis gives no inertia).
    #[serde(default)]
    pub inertia_kg_m2: Option<[f64; 3]>,
    /// z of the missile's centre of mass in the rail frame at assembly, m. Estimate. (x is 0;
    /// y follows from the rear shoe resting on the lips, [`LauncherSpec::missile_com_in_rail_m`].)
    pub com_z_in_rail_m: f64,
}

impl MissileSpec {
    /// Principal moments, kg·m²: the given ones or a solid cylinder's
    /// (`I_xx = I_yy = m (3 r² + L²) / 12`, `I_zz = m r² / 2`).
    pub fn inertia_kg_m2(&self) -> [f64; 3] {
        self.inertia_kg_m2.unwrap_or_else(|| {
            let r = 0.5 * self.diameter_m;
            let transverse = self.mass_kg * (3.0 * r * r + self.length_m * self.length_m) / 12.0;
            [transverse, transverse, 0.5 * self.mass_kg * r * r]
        })
    }
}

/// A shoe (mid or rear), rigidly fastened to the missile (thesis 6.5: locked joints). Its T-head
/// and neck cross-sections come from [`LauncherDimensions`]; this places it on the missile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShoeSpec {
    /// Centre of the head's underside (the face that rests on the rail lips), m, missile frame.
    pub head_base_in_missile_m: [f64; 3],
    /// Shoe length along z, m. Estimate.
    pub length_m: f64,
    /// Edge roundover, m (thesis 6.5: "a small roundover specified in the design"). Estimate.
    pub edge_radius_m: f64,
    /// Extra contact piece, missile frame: the mid shoe's front protrusion that enlarges the
    /// latch interface (thesis 6.2.3). None for the rear shoe.
    #[serde(default)]
    pub protrusion: Option<RoundedBoxSpec>,
}

/// Joint of the latch on the rail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LatchJoint {
    /// Rotation about and translation along the hinge axis (thesis 6.5).
    Cylindrical,
    /// Rotation only (translation locked): for builders that prefer to bound the axial slide.
    Revolute,
}

/// The latch rocker (thesis 6.2.3, Figures 6.9-6.10): pivots on the rail, its tooth bears on the
/// mid shoe's front to retain the missile longitudinally, and rests on the rail lips (the
/// latch-rail contact stops its rotation). Latch frame: origin at its centre of mass, axes
/// parallel to the rail frame at assembly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatchSpec {
    /// Mass, kg. Estimate.
    pub mass_kg: f64,
    /// Principal moments about the centre of mass along the latch frame axes, kg·m². Estimate.
    pub inertia_kg_m2: [f64; 3],
    /// Centre of mass in the rail frame at assembly, m. Estimate.
    pub com_in_rail_m: [f64; 3],
    /// A point on the hinge axis, rail frame, m. Estimate.
    pub hinge_point_in_rail_m: [f64; 3],
    /// Hinge axis direction (unit), rail frame. Transverse (x) by the latch's function.
    pub hinge_axis: [f64; 3],
    /// Joint type (thesis 6.5: cylindrical).
    pub joint: LatchJoint,
    /// The tooth (contact piece bearing on the mid shoe and on the rail), latch frame.
    pub tooth: RoundedBoxSpec,
}

/// The latch coil springs (two concentric springs, thesis 6.2.3, modelled as one two-point coil
/// spring, thesis 6.5). Compression spring: the force pushes the two points apart,
/// `F = preload + k (L_installed - L) - c dL/dt`, with `L_installed` the distance at assembly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoilSpringSpec {
    /// Combined stiffness k, N/m. Estimate.
    pub stiffness_n_per_m: f64,
    /// Damping c, N·s/m. Estimate.
    pub damping_ns_per_m: f64,
    /// Force at the installed length, N (> 0: compressed at assembly). Estimate.
    pub preload_n: f64,
    /// Attachment on the rail (latch cover), rail frame, m. Estimate.
    pub point_on_rail_m: [f64; 3],
    /// Attachment on the latch, latch frame, m. Estimate.
    pub point_on_latch_m: [f64; 3],
}

/// A constant point force on the missile (a double-barrel spring, thesis 6.5: "modeled as
/// constant point forces because of the small displacements").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantForceSpec {
    /// Label, e.g. `double_barrel_left`.
    pub name: String,
    /// Force magnitude, N. Estimate.
    pub force_n: f64,
    /// Point of application on the mid shoe, missile frame, m. Estimate.
    pub point_in_missile_m: [f64; 3],
    /// Direction (unit), fixed in the rail frame: +z, opposite the latch (thesis 6.2.3).
    pub direction_in_rail: [f64; 3],
}

/// The rear leaf spring (thesis 6.2.3, 6.5): fixed to the rail above the rear shoe, it presses
/// the shoe head down onto the lips. Modelled as a vertical one-sided point force with a smooth
/// engagement: with `c` the compression (shoe head top above the spring's free tip),
/// `F_y = -STEP(c, 0, 0, s, 1) (preload + k c)` on the shoe for `c > 0`, zero otherwise, `s` the
/// engagement smoothing. The free tip hangs `reach_below_roof_m` below the chamber roof, so the
/// static engagement depends on the rail's vertical clearance: it may not engage when static for
/// a loose rail (thesis 6.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeafSpringSpec {
    /// Stiffness k, N/m. Estimate.
    pub stiffness_n_per_m: f64,
    /// Force at first touch (c = 0+), N. Estimate.
    pub preload_n: f64,
    /// How far the free tip hangs below the chamber roof, m. Estimate.
    pub reach_below_roof_m: f64,
    /// z of the spring tip in the rail frame, m (over the rear shoe at assembly). Estimate.
    pub z_in_rail_m: f64,
    /// Engagement smoothing s (smooth-step width), m. Estimate.
    pub engagement_smoothing_m: f64,
    /// Step shape for the engagement (default cycloidal, eq. 2.4).
    #[serde(default)]
    pub step: StepKind,
}

/// The five solid-solid contacts of thesis 6.5 (numbered 1-5 as in Figures 6.59-6.62, 6.65-6.66).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LauncherContacts {
    /// Contact 1: missile front (front bearing pad) - rail. Table 6.2 default.
    pub missile_rail: ContactSpec,
    /// Contact 2: latch - rail. Stiffer than default (thesis 6.5.2, 6.6.3; value estimate).
    pub latch_rail: ContactSpec,
    /// Contact 3: mid shoe - rail. Table 6.2 default.
    pub mid_shoe_rail: ContactSpec,
    /// Contact 4: mid shoe - latch. Stiffer than default (thesis 6.5.2, 6.6.3; value estimate).
    pub mid_shoe_latch: ContactSpec,
    /// Contact 5: rear shoe - rail. Table 6.2 default.
    pub rear_shoe_rail: ContactSpec,
}

/// The Hellfire-class launcher of thesis chapter 6: kinematic rail, missile with mid and rear
/// shoes and a front bearing pad, latch on a cylindrical joint with its coil spring, two
/// double-barrel springs, the rear leaf spring, five contacts (Table 6.2) and friction (Table
/// 6.1). `dimensions` sets the channel and shoe cross-sections, so the tight, design and loose
/// variants (eq. 6.1-6.3) change the clearances.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LauncherSpec {
    /// Rail and shoe material (anodized 7075, thesis 4.2.1).
    #[serde(default)]
    pub material: Material,
    /// Rear shoe and rail cross-section dimensions (eq. 6.1-6.2), mm.
    pub dimensions: LauncherDimensions,
    /// Rail layout.
    pub rail: RailSpec,
    /// Missile body.
    pub missile: MissileSpec,
    /// Mid shoe (latch side).
    pub mid_shoe: ShoeSpec,
    /// Rear shoe.
    pub rear_shoe: ShoeSpec,
    /// Missile front bearing pad (contact 1, the "front shoe (missile)" of Figure 6.59): where the
    /// missile's forward body meets the rail's bottom face, missile frame. Estimate.
    pub front_pad: RoundedBoxSpec,
    /// Latch rocker.
    pub latch: LatchSpec,
    /// Latch coil spring.
    pub latch_spring: CoilSpringSpec,
    /// The two double-barrel springs on the mid shoe.
    pub double_barrel_springs: Vec<ConstantForceSpec>,
    /// Rear leaf spring.
    pub rear_leaf_spring: LeafSpringSpec,
    /// Contact parameters (Table 6.2).
    pub contacts: LauncherContacts,
    /// Friction for all contacts (Table 6.1).
    #[serde(with = "in_mm_per_s")]
    pub friction: FrictionParams,
    /// Rail stations of a multi-rail launcher (the AH-64's M299 carries four missiles): the
    /// offset of each rail's frame from the launcher's reference, m. Every station is the
    /// rail above with its own missile, latch, springs and five contacts; all rails move with
    /// the launcher's one prescribed motion. Default: one station at the origin (the thesis'
    /// single rail).
    #[serde(
        default = "default_stations",
        skip_serializing_if = "is_single_station"
    )]
    pub stations: Vec<[f64; 3]>,
}

fn default_stations() -> Vec<[f64; 3]> {
    vec![[0.0; 3]]
}

fn is_single_station(s: &[[f64; 3]]) -> bool {
    s == [[0.0; 3]]
}

/// Rail and shoe section letters, mm (eq. 6.1-6.2).
const LAUNCHER_DIMENSION: Bound = Bound::new(
    0.01,
    1000.0,
    "mm",
    "rail and shoe section letters (eq. 6.1-6.2) from 10 µm (a machining tolerance) to 1 m; \
     the thesis' are 9.5-38 mm",
);
/// The missile's and the latch's mass, kg.
const MASS: Bound = Bound::new(
    1.0e-4,
    1.0e4,
    "kg",
    "from 0.1 g (a chip, not a body) to 10 t (the heaviest air-launched stores; the Hellfire \
     is 45 kg)",
);
/// Principal moments of inertia, kg·m².
const INERTIA: Bound = Bound::new(
    1.0e-12,
    1.0e5,
    "kg·m²",
    "from a 1 mm part to a 10 t store 10 m long (m L²/12 = 8e4 kg·m²)",
);
/// Spring stiffness, N/m.
const SPRING_STIFFNESS: Bound = Bound::new(
    0.0,
    1.0e9,
    "N/m",
    "springs up to 1 GN/m, stiffer than the rail's own aluminium section; 0 is no spring",
);
/// Spring damping, N·s/m.
const SPRING_DAMPING: Bound = Bound::new(
    0.0,
    1.0e6,
    "N·s/m",
    "spring damping up to 1 MN·s/m, which locks a 45 kg missile within 50 µs",
);
/// Spring preloads and point forces, N.
const FORCE: Bound = Bound::new(
    0.0,
    1.0e5,
    "N",
    "spring and point forces up to 100 kN: 226 g on a 45 kg missile",
);

/// The lettered cross-section dimensions (`analysis::rattle_space::LauncherDimensions`).
impl Bounded for LauncherDimensions {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        for (name, v) in self.named_fields() {
            at.number(name, v, &LAUNCHER_DIMENSION)?;
        }
        Ok(())
    }
}

impl Bounded for RailSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("channel_length_m", self.channel_length_m, &LENGTH)?;
        at.number("channel_centre_z_m", self.channel_centre_z_m, &POSITION)?;
        at.number("lip_top_y_m", self.lip_top_y_m, &POSITION)?;
        at.number("lip_thickness_m", self.lip_thickness_m, &LENGTH)?;
        at.number("bottom_half_width_m", self.bottom_half_width_m, &LENGTH)
    }
}

impl Bounded for MissileSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("mass_kg", self.mass_kg, &MASS)?;
        at.number("length_m", self.length_m, &LENGTH)?;
        at.number("diameter_m", self.diameter_m, &LENGTH)?;
        if let Some(inertia) = &self.inertia_kg_m2 {
            at.numbers("inertia_kg_m2", inertia, &INERTIA)?;
        }
        at.number("com_z_in_rail_m", self.com_z_in_rail_m, &POSITION)
    }
}

impl Bounded for ShoeSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.numbers(
            "head_base_in_missile_m",
            &self.head_base_in_missile_m,
            &POSITION,
        )?;
        at.number("length_m", self.length_m, &LENGTH)?;
        at.number("edge_radius_m", self.edge_radius_m, &EDGE_RADIUS)?;
        if let Some(protrusion) = &self.protrusion {
            at.child("protrusion", protrusion)?;
        }
        Ok(())
    }
}

impl Bounded for LatchSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("mass_kg", self.mass_kg, &MASS)?;
        at.numbers("inertia_kg_m2", &self.inertia_kg_m2, &INERTIA)?;
        at.numbers("com_in_rail_m", &self.com_in_rail_m, &POSITION)?;
        at.numbers(
            "hinge_point_in_rail_m",
            &self.hinge_point_in_rail_m,
            &POSITION,
        )?;
        at.numbers("hinge_axis", &self.hinge_axis, &UNIT_COMPONENT)?;
        at.child("tooth", &self.tooth)
    }
}

impl Bounded for CoilSpringSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number(
            "stiffness_n_per_m",
            self.stiffness_n_per_m,
            &SPRING_STIFFNESS,
        )?;
        at.number("damping_ns_per_m", self.damping_ns_per_m, &SPRING_DAMPING)?;
        at.number("preload_n", self.preload_n, &FORCE)?;
        at.numbers("point_on_rail_m", &self.point_on_rail_m, &POSITION)?;
        at.numbers("point_on_latch_m", &self.point_on_latch_m, &POSITION)
    }
}

impl Bounded for ConstantForceSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.text("name", &self.name, MAX_TEXT_CHARS, false)?;
        at.number("force_n", self.force_n, &FORCE)?;
        at.numbers("point_in_missile_m", &self.point_in_missile_m, &POSITION)?;
        at.numbers(
            "direction_in_rail",
            &self.direction_in_rail,
            &UNIT_COMPONENT,
        )
    }
}

impl Bounded for LeafSpringSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number(
            "stiffness_n_per_m",
            self.stiffness_n_per_m,
            &SPRING_STIFFNESS,
        )?;
        at.number("preload_n", self.preload_n, &FORCE)?;
        at.number("reach_below_roof_m", self.reach_below_roof_m, &POSITION)?;
        at.number("z_in_rail_m", self.z_in_rail_m, &POSITION)?;
        at.number(
            "engagement_smoothing_m",
            self.engagement_smoothing_m,
            &LENGTH,
        )
    }
}

impl Bounded for LauncherContacts {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.child("missile_rail", &self.missile_rail)?;
        at.child("latch_rail", &self.latch_rail)?;
        at.child("mid_shoe_rail", &self.mid_shoe_rail)?;
        at.child("mid_shoe_latch", &self.mid_shoe_latch)?;
        at.child("rear_shoe_rail", &self.rear_shoe_rail)
    }
}

impl Bounded for LauncherSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.child("material", &self.material)?;
        at.child("dimensions", &self.dimensions)?;
        at.child("rail", &self.rail)?;
        at.child("missile", &self.missile)?;
        at.child("mid_shoe", &self.mid_shoe)?;
        at.child("rear_shoe", &self.rear_shoe)?;
        at.child("front_pad", &self.front_pad)?;
        at.child("latch", &self.latch)?;
        at.child("latch_spring", &self.latch_spring)?;
        at.field("double_barrel_springs", |at| {
            self.double_barrel_springs
                .iter()
                .enumerate()
                .try_for_each(|(i, spring)| at.item(i, |at| spring.check_bounds(at)))
        })?;
        at.child("rear_leaf_spring", &self.rear_leaf_spring)?;
        at.child("contacts", &self.contacts)?;
        at.child("friction", &self.friction)?;
        at.field("stations", |at| {
            self.stations
                .iter()
                .enumerate()
                .try_for_each(|(i, station)| {
                    at.item(i, |at| {
                        station
                            .iter()
                            .enumerate()
                            .try_for_each(|(j, v)| at.item(j, |at| at.this(*v, &POSITION)))
                    })
                })
        })
    }
}

/// Most rail stations on one launcher.
pub const MAX_STATIONS: usize = 8;

impl LauncherSpec {
    /// Field rules and assembly checks: dimensions (eq. 6.1-6.2 rules), positive masses and
    /// stiffnesses, real inertias, unit axes, exactly two double-barrel springs pushing +z, both
    /// shoes seated at the same height, shoes and pad inside the channel length, lips thinner
    /// than the neck, front pad clear of the rail bottom, latch tooth not below the lip tops.
    pub fn validate(&self, prefix: &str) -> Result<(), FieldError> {
        let p = |name: &str| path(prefix, name);
        validate_material(&self.material, &p("material"))?;
        if self.stations.is_empty() || self.stations.len() > MAX_STATIONS {
            return Err(FieldError::new(
                p("stations"),
                format!(
                    "must list 1 to {MAX_STATIONS} rail offsets, got {}",
                    self.stations.len()
                ),
            ));
        }
        for (i, a) in self.stations.iter().enumerate() {
            if a.iter().any(|v| !v.is_finite()) {
                return Err(FieldError::new(
                    format!("{}[{i}]", p("stations")),
                    "must be finite",
                ));
            }
            // No missile-missile contact is modelled: the missiles must not overlap.
            for b in &self.stations[..i] {
                let apart = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                if apart < self.missile.diameter_m {
                    return Err(FieldError::new(
                        format!("{}[{i}]", p("stations")),
                        format!(
                            "is {apart} m across the rails from another station: the missiles \
                             ({} m diameter) would overlap",
                            self.missile.diameter_m
                        ),
                    ));
                }
            }
        }
        self.dimensions
            .validate()
            .map_err(|RattleSpaceError::InvalidDimension(e)| e.at(&p("dimensions")))?;
        // Rail
        let rp = p("rail");
        positive(&rp, "channel_length_m", self.rail.channel_length_m)?;
        finite(&rp, "channel_centre_z_m", self.rail.channel_centre_z_m)?;
        finite(&rp, "lip_top_y_m", self.rail.lip_top_y_m)?;
        positive(&rp, "lip_thickness_m", self.rail.lip_thickness_m)?;
        let neck_h = units::mm(self.dimensions.mean_neck_height_mm());
        if self.rail.lip_thickness_m >= neck_h {
            return Err(FieldError::new(
                path(&rp, "lip_thickness_m"),
                format!("must be smaller than the shoes' mean neck height {neck_h} m"),
            ));
        }
        let half_w = 0.5 * units::mm(self.dimensions.chamber_width_mm());
        if !(self.rail.bottom_half_width_m.is_finite() && self.rail.bottom_half_width_m > half_w) {
            return Err(FieldError::new(
                path(&rp, "bottom_half_width_m"),
                format!("must exceed the chamber half width {half_w} m"),
            ));
        }
        // Missile
        let mp = p("missile");
        positive(&mp, "mass_kg", self.missile.mass_kg)?;
        positive(&mp, "length_m", self.missile.length_m)?;
        positive(&mp, "diameter_m", self.missile.diameter_m)?;
        inertia3(&mp, "inertia_kg_m2", self.missile.inertia_kg_m2())?;
        finite(&mp, "com_z_in_rail_m", self.missile.com_z_in_rail_m)?;
        // Shoes and pad
        let (z_lo, z_hi) = (
            self.rail.channel_centre_z_m - 0.5 * self.rail.channel_length_m,
            self.rail.channel_centre_z_m + 0.5 * self.rail.channel_length_m,
        );
        for (name, shoe) in [("mid_shoe", &self.mid_shoe), ("rear_shoe", &self.rear_shoe)] {
            let sp = p(name);
            finite3(&sp, "head_base_in_missile_m", shoe.head_base_in_missile_m)?;
            positive(&sp, "length_m", shoe.length_m)?;
            non_negative(&sp, "edge_radius_m", shoe.edge_radius_m)?;
            let head = shoe.head_box(&self.dimensions);
            let neck = shoe.neck_box(&self.dimensions);
            if head
                .half_extents_m
                .iter()
                .chain(neck.half_extents_m.iter())
                .any(|h| *h <= shoe.edge_radius_m)
            {
                return Err(FieldError::new(
                    path(&sp, "edge_radius_m"),
                    "must be smaller than every half size of the head and neck",
                ));
            }
            if let Some(pr) = &shoe.protrusion {
                pr.validate(&path(&sp, "protrusion"))?;
                if pr.min_y_m() < shoe.head_base_in_missile_m[1] {
                    return Err(FieldError::new(
                        path(&sp, "protrusion"),
                        "reaches below the head base: it would intersect the rail lips at assembly",
                    ));
                }
            }
            let zc = self.missile_to_rail_m(shoe.head_base_in_missile_m)[2];
            if zc - 0.5 * shoe.length_m < z_lo || zc + 0.5 * shoe.length_m > z_hi {
                return Err(FieldError::new(
                    path(&sp, "head_base_in_missile_m"),
                    "the shoe lies outside the rail channel's length",
                ));
            }
        }
        if (self.mid_shoe.head_base_in_missile_m[1] - self.rear_shoe.head_base_in_missile_m[1])
            .abs()
            > 1e-6
            || (self.mid_shoe.head_base_in_missile_m[0] - self.rear_shoe.head_base_in_missile_m[0])
                .abs()
                > 1e-6
        {
            return Err(FieldError::new(
                p("mid_shoe.head_base_in_missile_m"),
                "x and y must equal the rear shoe's: both heads ride on the same lips",
            ));
        }
        let fp = p("front_pad");
        self.front_pad.validate(&fp)?;
        let pad_top =
            self.missile_to_rail_m(self.front_pad.centre_m)[1] + self.front_pad.half_extents_m[1];
        let bottom = self.rail.lip_top_y_m - self.rail.lip_thickness_m;
        if pad_top > bottom {
            return Err(FieldError::new(
                path(&fp, "centre_m"),
                format!("the pad top ({pad_top} m) is above the rail bottom face ({bottom} m): interference at assembly"),
            ));
        }
        let pz = self.missile_to_rail_m(self.front_pad.centre_m)[2];
        if pz - self.front_pad.half_extents_m[2] < z_lo
            || pz + self.front_pad.half_extents_m[2] > z_hi
        {
            return Err(FieldError::new(
                path(&fp, "centre_m"),
                "the pad lies outside the rail channel's length",
            ));
        }
        // Latch
        let lp = p("latch");
        positive(&lp, "mass_kg", self.latch.mass_kg)?;
        inertia3(&lp, "inertia_kg_m2", self.latch.inertia_kg_m2)?;
        finite3(&lp, "com_in_rail_m", self.latch.com_in_rail_m)?;
        finite3(
            &lp,
            "hinge_point_in_rail_m",
            self.latch.hinge_point_in_rail_m,
        )?;
        unit3(&lp, "hinge_axis", self.latch.hinge_axis)?;
        self.latch.tooth.validate(&path(&lp, "tooth"))?;
        let tooth_bottom =
            self.latch.tooth_centre_in_rail_m()[1] - self.latch.tooth.half_extents_m[1];
        if tooth_bottom < self.rail.lip_top_y_m - 1e-9 {
            return Err(FieldError::new(
                path(&lp, "tooth"),
                format!("the tooth bottom ({tooth_bottom} m) is below the lip tops: interference at assembly"),
            ));
        }
        // Springs
        let sp = p("latch_spring");
        positive(
            &sp,
            "stiffness_n_per_m",
            self.latch_spring.stiffness_n_per_m,
        )?;
        non_negative(&sp, "damping_ns_per_m", self.latch_spring.damping_ns_per_m)?;
        non_negative(&sp, "preload_n", self.latch_spring.preload_n)?;
        finite3(&sp, "point_on_rail_m", self.latch_spring.point_on_rail_m)?;
        finite3(&sp, "point_on_latch_m", self.latch_spring.point_on_latch_m)?;
        if self.latch_spring_installed_length_m() <= 0.0 {
            return Err(FieldError::new(
                path(&sp, "point_on_rail_m"),
                "the two attachment points coincide at assembly",
            ));
        }
        if self.double_barrel_springs.len() != 2 {
            return Err(FieldError::new(
                p("double_barrel_springs"),
                format!(
                    "there are two double-barrel springs (thesis 6.5), got {}",
                    self.double_barrel_springs.len()
                ),
            ));
        }
        for (i, f) in self.double_barrel_springs.iter().enumerate() {
            let fp = p(&format!("double_barrel_springs[{i}]"));
            positive(&fp, "force_n", f.force_n)?;
            finite3(&fp, "point_in_missile_m", f.point_in_missile_m)?;
            unit3(&fp, "direction_in_rail", f.direction_in_rail)?;
            if f.direction_in_rail[2] <= 0.0 {
                return Err(FieldError::new(
                    path(&fp, "direction_in_rail"),
                    "must push forward (+z), opposite the latch (thesis 6.2.3)",
                ));
            }
        }
        let lf = p("rear_leaf_spring");
        positive(
            &lf,
            "stiffness_n_per_m",
            self.rear_leaf_spring.stiffness_n_per_m,
        )?;
        non_negative(&lf, "preload_n", self.rear_leaf_spring.preload_n)?;
        non_negative(
            &lf,
            "reach_below_roof_m",
            self.rear_leaf_spring.reach_below_roof_m,
        )?;
        finite(&lf, "z_in_rail_m", self.rear_leaf_spring.z_in_rail_m)?;
        positive(
            &lf,
            "engagement_smoothing_m",
            self.rear_leaf_spring.engagement_smoothing_m,
        )?;
        // Contacts and friction
        let cp = p("contacts");
        let c = &self.contacts;
        c.missile_rail.validate(&path(&cp, "missile_rail"))?;
        c.latch_rail.validate(&path(&cp, "latch_rail"))?;
        c.mid_shoe_rail.validate(&path(&cp, "mid_shoe_rail"))?;
        c.mid_shoe_latch.validate(&path(&cp, "mid_shoe_latch"))?;
        c.rear_shoe_rail.validate(&path(&cp, "rear_shoe_rail"))?;
        validate_friction(&self.friction, &p("friction"))?;
        Ok(())
    }
}
