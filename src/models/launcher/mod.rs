//! Hellfire-class launcher (thesis chapter 6, 6.5) as a multibody system: a kinematic rail
//! driven by the base motion, the missile as ONE rigid body carrying the mid shoe, the rear shoe
//! and the front bearing pad as convex pieces (the thesis' lock joints are exact here), the latch
//! on a penalty cylindrical joint loaded by its coil spring, two double-barrel constant forces,
//! the rear leaf spring, and the five contacts of thesis 6.5 (Table 6.2 parameters, Table 6.1
//! friction).
//!
//! The engine's contact faces are unbounded half-spaces, so each contact pairs only the pieces
//! and faces that can meet (every piece of a contact is tested against every face of it):
//! - shoe heads against the lip tops (floor), the chamber roof and the two chamber walls. The
//!   neck is left out: eq. 6.1 makes the neck's slot clearance equal to the head's chamber
//!   clearance (`docs/reference/launcher-dimensions.md`), so the head walls carry the transverse contact,
//!   and an unbounded lip-top plane would swallow a neck that hangs through the slot. Coplanar
//!   faces (left and right lip tops) are used once, or the weight would be carried twice;
//! - the front pad against the rail's bottom face;
//! - the latch tooth against the floor, roof and chamber walls;
//! - the mid shoe's front protrusion against the tooth's rear face (a latch half-space).
//!
//! What the launcher is ([`LauncherSpec`], the case file's `[launcher]` table) is in
//! `models/spec/launcher.rs`, the geometry derived from it in `geometry.rs`; how it is built is
//! here.

mod geometry;
#[cfg(test)]
mod tests;

pub use super::spec::launcher::{
    CoilSpringSpec, ConstantForceSpec, LatchJoint, LatchSpec, LauncherContacts, LauncherSpec,
    LeafSpringSpec, MissileSpec, RailSpec, ShoeSpec, MAX_STATIONS,
};

use super::outcome::RunError;
use super::run::BuiltModel;
use super::spec::{CaseSpec, PlanarFace, RoundedBoxSpec};
use crate::excitation::BaseMotion;
use crate::field_error::FieldError;
use crate::geometry::{ConvexShape, FaceExtent, HalfSpace};
use crate::models::motion::TranslatingBase;
use crate::physics::body::{write_state, BodyKind, MassProperties, RigidBody};
use crate::physics::contact::{Contact, FaceContact};
use crate::physics::forces::{
    Attachment, Bushing, ConstantForce, ForceElement, OneSidedSpring, SpringDamper,
};
use crate::physics::partition::remap_force;
use crate::physics::system::MultibodySystem;
use crate::units::STANDARD_GRAVITY;
use nalgebra::{Isometry3, Matrix3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use std::f64::consts::PI;
use std::sync::Arc;

/// Body indices of the built system.
pub const MISSILE: usize = 0;
/// Latch body index.
pub const LATCH: usize = 1;
/// Rail body index (kinematic).
pub const RAIL: usize = 2;

/// Bodies per rail station (missile, latch, rail): station `s` (from 0) holds bodies
/// `3 s .. 3 s + 3` and contacts `5 s .. 5 s + 5` (`LauncherSpec::stations`).
pub const STATION_BODIES: usize = 3;

/// Contact names in thesis numbering 1-5 (Figures 6.59-6.62): missile (front pad) - rail,
/// latch - rail, mid shoe - rail, mid shoe - latch, rear shoe - rail.
pub const CONTACT_NAMES: [&str; 5] = [
    "missile-rail",
    "latch-rail",
    "mid_shoe-rail",
    "mid_shoe-latch",
    "rear_shoe-rail",
];

/// How the launcher's faces are resolved when a case does not say (`simulation.face_contact`):
/// exactly. The contact-point lattice is not converged on the launcher (friction power and
/// shoe wear move by per cents from 5 to 17 points per edge, and a shoe head over a lip's edge
/// gets a staircase of the face law); the exact contact is its continuum limit
/// (docs/journal/performance.md, eleventh and eighteenth passes).
pub const FACE_CONTACT: FaceContact = FaceContact::Exact;

/// Index of the rear leaf spring in `system.forces`.
pub const LEAF_SPRING_FORCE: usize = 1;

/// Lowest natural frequency of the penalty cylindrical joint's stiff axes, Hz. The thesis'
/// joint is ideal; 5 kHz sits a decade above the stiffest physical mode (latch on its
/// 1e4 N/mm² contacts, about 0.4 kHz) so the joint's own compliance does not colour the
/// response, while the L-stable integrator damps it without resolving it.
pub const LATCH_JOINT_FREQUENCY_HZ: f64 = 5000.0;

/// Damping ratio of the joint's stiff axes (critical: the penalty mode dies within a period).
pub const LATCH_JOINT_DAMPING_RATIO: f64 = 1.0;

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

fn p3(a: [f64; 3]) -> Point3<f64> {
    Point3::new(a[0], a[1], a[2])
}

fn piece(b: &RoundedBoxSpec) -> (Isometry3<f64>, ConvexShape) {
    (
        Isometry3::translation(b.centre_m[0], b.centre_m[1], b.centre_m[2]),
        ConvexShape::RoundedBox {
            half_extents: v3(b.half_extents_m),
            roundover: b.edge_radius_m,
        },
    )
}

/// A rail face as a half-space of the rail frame (normal out of the rail's material).
fn half_space(f: &PlanarFace) -> HalfSpace {
    let n = v3(f.normal);
    HalfSpace {
        normal: Unit::new_normalize(n),
        offset: n.dot(&v3(f.centre_m)),
    }
}

/// A lip top as a bounded face: its plane, and its extent in the rail frame, bounded along the
/// channel (z) and at the slot edge (the real edge the shoe head overhangs); open towards the
/// chamber wall, whose corner with the lip is solid.
fn lip_face(f: &PlanarFace) -> (HalfSpace, FaceExtent) {
    let n = v3(f.normal);
    let tangent = Unit::new_normalize(v3(f.tangent));
    // t runs along normal × tangent (+x for the lip tops); the slot is on the side facing x = 0.
    let across = n.cross(&tangent);
    let slot_side_positive = across.dot(&v3(f.centre_m)) < 0.0;
    let t_range = if slot_side_positive {
        (f64::NEG_INFINITY, f.half_width_m)
    } else {
        (-f.half_width_m, f64::INFINITY)
    };
    (
        half_space(f),
        FaceExtent {
            origin: Point3::from(v3(f.centre_m)),
            tangent,
            s_range_m: (-f.half_length_m, f.half_length_m),
            t_range_m: t_range,
        },
    )
}

/// The rail faces a launcher part can touch.
struct RailPlanes {
    /// The two lip tops (left, right), bounded at the slot.
    floor: [(HalfSpace, FaceExtent); 2],
    roof: HalfSpace,
    wall_left: HalfSpace,
    wall_right: HalfSpace,
    bottom: HalfSpace,
}

fn rail_planes(spec: &LauncherSpec) -> Result<RailPlanes, RunError> {
    let faces = spec.rail_faces();
    let get = |name: &str| {
        faces
            .iter()
            .find(|f| f.name == name)
            .map(half_space)
            .ok_or_else(|| FieldError::new("launcher.rail", format!("rail face `{name}` missing")))
    };
    let (roof_l, roof_r) = (get("roof_left")?, get("roof_right")?);
    // Roof normals point -y, offset = -y_roof: the lower roof half has the larger offset. An
    // unbounded plane cannot be stepped, so a head meets the lower half first: keep that one.
    let roof = if roof_l.offset >= roof_r.offset {
        roof_l
    } else {
        roof_r
    };
    let lip = |name: &str| {
        faces
            .iter()
            .find(|f| f.name == name)
            .map(lip_face)
            .ok_or_else(|| FieldError::new("launcher.rail", format!("rail face `{name}` missing")))
    };
    Ok(RailPlanes {
        floor: [lip("lip_top_left")?, lip("lip_top_right")?],
        roof,
        wall_left: get("chamber_wall_left")?,
        wall_right: get("chamber_wall_right")?,
        bottom: get("bottom_left")?,
    })
}

/// Joint frame orientation (relative to the rail and, at assembly, the latch): joint z along
/// the hinge axis.
fn hinge_frame(axis: Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&Vector3::z(), &axis)
        .unwrap_or_else(|| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI))
}

/// Static estimate of the assembled launcher under gravity and the springs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticEstimate {
    /// Missile pose in the rail frame.
    pub missile_pose: Isometry3<f64>,
    /// Latch pose in the rail frame.
    pub latch_pose: Isometry3<f64>,
    /// Mid shoe head normal force, N.
    pub mid_shoe_normal_n: f64,
    /// Rear shoe head normal force, N.
    pub rear_shoe_normal_n: f64,
    /// Leaf spring force, N (0: free).
    pub leaf_spring_force_n: f64,
    /// Leaf spring compression δ, m (<= 0: free).
    pub leaf_spring_compression_m: f64,
    /// Latch tooth floor reaction, N.
    pub latch_floor_normal_n: f64,
}

/// IMPACT static penetration `(F/k)^(1/e)` (eq. 2.1 without damping), m.
fn penetration(force: f64, k: f64, e: f64) -> f64 {
    if force <= 0.0 {
        0.0
    } else {
        (force / k).powf(1.0 / e)
    }
}

/// Estimates the static rest state: the shoe heads sink into the lips by their IMPACT static
/// penetrations, the missile pitching rigidly between them; the leaf spring's compression
/// follows the rear shoe (fixed-point iteration). The latch takes the double-barrel push on its
/// tooth and rotates until the tooth's floor penetration carries the rest of the coil spring
/// moment; the missile moves forward by the tooth's retreat plus the protrusion's penetration.
/// Friction and the small couples of the forces' heights are neglected (the settle phase
/// removes what this leaves).
pub fn static_estimate(spec: &LauncherSpec) -> StaticEstimate {
    let g = STANDARD_GRAVITY;
    let weight = spec.missile.mass_kg * g;
    let c3 = spec.contacts.mid_shoe_rail.to_impact_params();
    let c5 = spec.contacts.rear_shoe_rail.to_impact_params();
    let leaf = &spec.rear_leaf_spring;
    let com = spec.missile_com_in_rail_m();
    let z_mid = spec.mid_shoe.head_base_in_missile_m[2];
    let z_rear = spec.rear_shoe.head_base_in_missile_m[2];
    let z_leaf = leaf.z_in_rail_m - com[2];
    let c0 = spec.leaf_spring_static_compression_m();
    let leaf_force = |c: f64| {
        if c <= 0.0 {
            0.0
        } else {
            leaf.step
                .eval(c, 0.0, 0.0, leaf.engagement_smoothing_m, 1.0)
                * (leaf.preload_n + leaf.stiffness_n_per_m * c)
        }
    };
    // Sinking (downwards) of the missile at missile-frame z, from the two head penetrations.
    let sink = |w_mid: f64, w_rear: f64, z: f64| {
        w_rear + (w_mid - w_rear) * (z - z_rear) / (z_mid - z_rear)
    };
    let (mut n_mid, mut n_rear, mut f_leaf, mut c) = (weight, 0.0, 0.0, c0);
    let (mut w_mid, mut w_rear) = (0.0, 0.0);
    for _ in 0..200 {
        let f_new = leaf_force(c);
        f_leaf = 0.5 * f_leaf + 0.5 * f_new;
        // N_mid + N_rear = W + F;  moment about the CoM: z_mid N_mid + z_rear N_rear = z_leaf F.
        let total = weight + f_leaf;
        n_rear = (z_leaf * f_leaf - z_mid * total) / (z_rear - z_mid);
        n_mid = total - n_rear;
        w_mid = penetration(n_mid, c3.stiffness, c3.exponent);
        w_rear = penetration(n_rear, c5.stiffness, c5.exponent);
        c = c0 - sink(w_mid, w_rear, z_leaf);
    }
    let slope = (w_mid - w_rear) / (z_mid - z_rear);
    let w_com = sink(w_mid, w_rear, 0.0);

    // Latch: moments about the hinge axis (rail frame, latch at assembly).
    let axis = v3(spec.latch.hinge_axis);
    let hinge = v3(spec.latch.hinge_point_in_rail_m);
    let latch_com = v3(spec.latch.com_in_rail_m);
    let tooth = &spec.latch.tooth;
    let tooth_c = latch_com + v3(tooth.centre_m);
    let bottom = tooth_c - Vector3::y() * tooth.half_extents_m[1];
    let rear_face = tooth_c - Vector3::z() * tooth.half_extents_m[2];
    let push: Vector3<f64> = spec
        .double_barrel_springs
        .iter()
        .map(|f| v3(f.direction_in_rail) * f.force_n)
        .sum();
    let ls = &spec.latch_spring;
    let spring_latch = latch_com + v3(ls.point_on_latch_m);
    let spring_dir = (spring_latch - v3(ls.point_on_rail_m)).normalize();
    let moment = |p: Vector3<f64>, f: Vector3<f64>| (p - hinge).cross(&f).dot(&axis);
    let m_other = moment(spring_latch, spring_dir * ls.preload_n)
        + moment(rear_face, Vector3::z() * push.z)
        + moment(latch_com, Vector3::y() * (-spec.latch.mass_kg * g));
    let lever = moment(bottom, Vector3::y());
    let n_tooth = if lever.abs() > 1e-12 {
        (-m_other / lever).max(0.0)
    } else {
        0.0
    };
    let c2 = spec.contacts.latch_rail.to_impact_params();
    let w2 = penetration(n_tooth, c2.stiffness, c2.exponent);
    // Rotation θ about the axis moves the tooth bottom by θ (axis × r).
    let dir_bottom = axis.cross(&(bottom - hinge));
    let theta = if dir_bottom.y.abs() > 1e-12 {
        -w2 / dir_bottom.y
    } else {
        0.0
    };
    let face_shift_z = theta * axis.cross(&(rear_face - hinge)).z;
    let c4 = spec.contacts.mid_shoe_latch.to_impact_params();
    let w4 = penetration(push.z, c4.stiffness, c4.exponent);
    let rot = UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), theta);
    let latch_pos = hinge + rot * (latch_com - hinge);
    // The pitch also moves the protrusion along z (it sits ~0.11 m above the CoM): take it off.
    let pitch = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), slope);
    let pitch_dz = spec
        .mid_shoe
        .protrusion
        .map(|p| (pitch * v3(p.centre_m) - v3(p.centre_m)).z)
        .unwrap_or(0.0);
    StaticEstimate {
        missile_pose: Isometry3::from_parts(
            Translation3::new(
                com[0],
                com[1] - w_com,
                com[2] + face_shift_z + w4 - pitch_dz,
            ),
            pitch,
        ),
        latch_pose: Isometry3::from_parts(Translation3::from(latch_pos), rot),
        mid_shoe_normal_n: n_mid,
        rear_shoe_normal_n: n_rear,
        leaf_spring_force_n: leaf_force(c),
        leaf_spring_compression_m: c,
        latch_floor_normal_n: n_tooth,
    }
}

/// Builds the launcher system (bodies: missile 0, latch 1, rail 2; contacts in thesis order
/// [`CONTACT_NAMES`]; forces: latch spring, leaf spring, two double-barrel forces, latch joint).
/// The missile and latch start at [`static_estimate`]; the settle phase does the rest.
pub fn build(
    case: &CaseSpec,
    spec: &LauncherSpec,
    motion: BaseMotion,
) -> Result<BuiltModel, RunError> {
    let rate_start_s = BuiltModel::rate_start(case.simulation.settle_s, &motion);
    let d = &spec.dimensions;
    let m = &spec.missile;
    let inertia = m.inertia_kg_m2();
    let missile = RigidBody {
        name: "missile".into(),
        mass: MassProperties {
            mass: m.mass_kg,
            inertia: Matrix3::from_diagonal(&v3(inertia)),
        },
        kind: BodyKind::Dynamic { offset: 0 },
    };
    let l = &spec.latch;
    let latch = RigidBody {
        name: "latch".into(),
        mass: MassProperties {
            mass: l.mass_kg,
            inertia: Matrix3::from_diagonal(&v3(l.inertia_kg_m2)),
        },
        kind: BodyKind::Dynamic { offset: 0 },
    };
    // The rail frame is the world frame at zero base displacement.
    let rail = RigidBody {
        name: "rail".into(),
        mass: MassProperties {
            mass: 1.0,
            inertia: Matrix3::identity(),
        },
        kind: BodyKind::Kinematic(Arc::new(TranslatingBase {
            reference: Isometry3::identity(),
            motion: motion.clone(),
        })),
    };

    // --- Forces -------------------------------------------------------------------------
    let latch_com = v3(l.com_in_rail_m);
    let ls = &spec.latch_spring;
    let latch_spring = SpringDamper {
        name: "latch_spring".into(),
        a: Attachment {
            body: LATCH,
            point: p3(ls.point_on_latch_m),
        },
        b: Attachment {
            body: RAIL,
            point: p3(ls.point_on_rail_m),
        },
        stiffness: ls.stiffness_n_per_m,
        damping: ls.damping_ns_per_m,
        free_length: spec.latch_spring_installed_length_m(),
        preload: ls.preload_n,
    };
    let leaf = &spec.rear_leaf_spring;
    let head_top = spec.rear_shoe.head_top_in_missile_m(d);
    let leaf_spring = OneSidedSpring {
        name: "rear_leaf_spring".into(),
        // The spring bears on the head top straight under its tip.
        a: Attachment {
            body: MISSILE,
            point: Point3::new(
                head_top[0],
                head_top[1],
                leaf.z_in_rail_m - m.com_z_in_rail_m,
            ),
        },
        b: Attachment {
            body: RAIL,
            point: p3(spec.leaf_spring_tip_in_rail_m()),
        },
        direction: -Vector3::y(),
        stiffness: leaf.stiffness_n_per_m,
        damping: 0.0,
        preload: leaf.preload_n,
        engagement_gap: 0.0,
        transition: leaf.engagement_smoothing_m,
        step: leaf.step,
    };
    let mut forces = vec![
        ForceElement::SpringDamper(latch_spring),
        ForceElement::OneSidedSpring(leaf_spring),
    ];
    for f in &spec.double_barrel_springs {
        // The rail-fixed direction is given in the missile frame (parallel at assembly; the
        // missile turns by under a milliradian). The reaction goes to the kinematic rail.
        forces.push(ForceElement::ConstantForce(ConstantForce {
            name: f.name.clone(),
            a: Attachment {
                body: MISSILE,
                point: p3(f.point_in_missile_m),
            },
            force_body: v3(f.direction_in_rail) * f.force_n,
            reaction: None,
        }));
    }
    // Latch joint: penalty bushing, joint z along the hinge axis. Stiff axes tuned to
    // LATCH_JOINT_FREQUENCY_HZ: k = m ω² (translation), k = (I_max + m r²) ω² (tilt about the
    // hinge point, r = hinge to CoM), damping 2 ζ sqrt(k m).
    let axis = v3(l.hinge_axis);
    let frame = hinge_frame(axis);
    let hinge = v3(l.hinge_point_in_rail_m);
    let omega = 2.0 * PI * LATCH_JOINT_FREQUENCY_HZ;
    let k_t = l.mass_kg * omega * omega;
    let c_t = 2.0 * LATCH_JOINT_DAMPING_RATIO * (k_t * l.mass_kg).sqrt();
    let i_tilt = l.inertia_kg_m2.iter().cloned().fold(0.0, f64::max)
        + l.mass_kg * (hinge - latch_com).norm_squared();
    let k_r = i_tilt * omega * omega;
    let c_r = 2.0 * LATCH_JOINT_DAMPING_RATIO * (k_r * i_tilt).sqrt();
    let axial = match l.joint {
        LatchJoint::Cylindrical => 0.0,
        LatchJoint::Revolute => 1.0,
    };
    forces.push(ForceElement::Bushing(Bushing {
        name: "latch_joint".into(),
        a: Attachment {
            body: LATCH,
            point: Point3::from(hinge - latch_com),
        },
        b: Attachment {
            body: RAIL,
            point: Point3::from(hinge),
        },
        frame_b: frame,
        frame_a: frame,
        translational_stiffness: Vector3::new(k_t, k_t, axial * k_t),
        translational_damping: Vector3::new(c_t, c_t, axial * c_t),
        rotational_stiffness: Vector3::new(k_r, k_r, 0.0),
        rotational_damping: Vector3::new(c_r, c_r, 0.0),
    }));

    // --- Contacts (thesis 6.5, numbered as Figures 6.59-6.62) ----------------------------
    let planes = rail_planes(spec)?;
    let chamber = || {
        vec![
            planes.floor[0].0,
            planes.floor[1].0,
            planes.roof,
            planes.wall_left,
            planes.wall_right,
        ]
    };
    let chamber_extents = || {
        vec![
            Some(planes.floor[0].1),
            Some(planes.floor[1].1),
            None,
            None,
            None,
        ]
    };
    let friction = Some(spec.friction);
    let c = &spec.contacts;
    let tooth = &l.tooth;
    let tooth_rear_z = tooth.centre_m[2] - tooth.half_extents_m[2];
    let protrusion = spec.mid_shoe.protrusion.ok_or_else(|| {
        FieldError::new(
            "launcher.mid_shoe.protrusion",
            "the mid shoe needs its front protrusion: it is the piece the latch tooth holds \
             (thesis 6.2.3)",
        )
    })?;
    let contacts = vec![
        Contact::new(
            CONTACT_NAMES[0],
            MISSILE,
            vec![piece(&spec.front_pad)],
            RAIL,
            vec![planes.bottom],
            c.missile_rail.to_impact_params(),
            friction,
        ),
        Contact::new(
            CONTACT_NAMES[1],
            LATCH,
            vec![piece(tooth)],
            RAIL,
            chamber(),
            c.latch_rail.to_impact_params(),
            friction,
        )
        .with_face_extents(chamber_extents()),
        Contact::new(
            CONTACT_NAMES[2],
            MISSILE,
            vec![piece(&spec.mid_shoe.head_box(d))],
            RAIL,
            chamber(),
            c.mid_shoe_rail.to_impact_params(),
            friction,
        )
        .with_face_extents(chamber_extents()),
        Contact::new(
            CONTACT_NAMES[3],
            MISSILE,
            vec![piece(&protrusion)],
            LATCH,
            // The tooth's rear face: normal -z out of the tooth, plane z = tooth_rear_z.
            vec![HalfSpace {
                normal: Unit::new_normalize(-Vector3::z()),
                offset: -tooth_rear_z,
            }],
            c.mid_shoe_latch.to_impact_params(),
            friction,
        ),
        Contact::new(
            CONTACT_NAMES[4],
            MISSILE,
            vec![piece(&spec.rear_shoe.head_box(d))],
            RAIL,
            chamber(),
            c.rear_shoe_rail.to_impact_params(),
            friction,
        )
        .with_face_extents(chamber_extents()),
    ];

    let contacts: Vec<Contact> = contacts
        .into_iter()
        .map(|c| {
            c.with_points_per_edge(case.simulation.contact_points_per_edge)
                .with_face_contact(case.simulation.face_contact.unwrap_or(FACE_CONTACT))
        })
        .collect();
    // Stations: the first is the rail above (bodies 0-2, the thesis' names); each further one
    // a copy with its own missile, latch and rail body (placed at its offset, driven by the
    // same launcher motion), its own force elements and contacts.
    let mut bodies = Vec::new();
    let mut all_forces = Vec::new();
    let mut all_contacts = Vec::new();
    for (s, offset) in spec.stations.iter().enumerate() {
        let shift = |b: usize| b + STATION_BODIES * s;
        let suffix = |name: &str| {
            if s == 0 {
                name.to_string()
            } else {
                format!("{name}#{}", s + 1)
            }
        };
        let reference = Isometry3::translation(offset[0], offset[1], offset[2]);
        for body in [&missile, &latch, &rail] {
            let mut b = body.clone();
            b.name = suffix(&body.name);
            if let BodyKind::Kinematic(_) = b.kind {
                b.kind = BodyKind::Kinematic(Arc::new(TranslatingBase {
                    reference,
                    motion: motion.clone(),
                }));
            }
            bodies.push(b);
        }
        for f in &forces {
            let mut f = f.clone();
            remap_force(&mut f, &shift);
            all_forces.push(f);
        }
        for c in &contacts {
            let mut c = c.clone();
            c.name = suffix(&c.name);
            c.body_a = shift(c.body_a);
            c.body_b = shift(c.body_b);
            all_contacts.push(c);
        }
    }
    let stations = spec.stations.len();
    // The first station's rail carries the excitation (every station's rail moves with it).
    let system = MultibodySystem::new(
        bodies,
        Vector3::new(0.0, -STANDARD_GRAVITY, 0.0),
        all_forces,
        all_contacts,
    )
    .with_carrier(RAIL);
    let est = static_estimate(spec);
    let mut y = vec![0.0; system.state_len()];
    for (s, offset) in spec.stations.iter().enumerate() {
        let reference = Isometry3::translation(offset[0], offset[1], offset[2]);
        for (body, pose) in [(MISSILE, est.missile_pose), (LATCH, est.latch_pose)] {
            let body = body + STATION_BODIES * s;
            if let BodyKind::Dynamic { offset } = system.bodies[body].kind {
                write_state(
                    &mut y,
                    offset,
                    &(reference * pose),
                    Vector3::zeros(),
                    Vector3::zeros(),
                );
            }
        }
    }
    if y.iter().any(|v| !v.is_finite()) {
        return Err(FieldError::new(
            "launcher",
            "the static rest estimate is not finite (check masses, stiffnesses and positions)",
        )
        .into());
    }
    let mat = spec.material;
    Ok(BuiltModel {
        name: case.name.clone(),
        system,
        initial_state: y,
        excitation_start_s: case.simulation.settle_s,
        rate_start_s,
        end_time_s: case.simulation.settle_s + case.simulation.duration_s,
        contact_materials: vec![(mat, mat); 5 * stations],
        response_body: MISSILE,
    })
}
