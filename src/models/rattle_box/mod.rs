//! Rattle box (thesis chapter 5): a rounded 1 in cube free inside a square tube that the shaker
//! drives transversely. One contact "cube-tube" with one track per wall the cube touches.
//! What the box is ([`RattleBoxSpec`], the case file's `[rattle_box]` table) is in
//! `models/spec/rattle_box.rs`; how it is built as a multibody system is here.

#[cfg(test)]
mod tests;

pub use super::spec::rattle_box::{RattleBoxSpec, TABLE_5_1_TUBE_SIDES_IN};

use super::run::BuiltModel;
use super::spec::CaseSpec;
use crate::excitation::BaseMotion;
use crate::geometry::{ConvexShape, FaceExtent, HalfSpace};
use crate::models::motion::TranslatingBase;
use crate::physics::body::{write_state, BodyKind, MassProperties, RigidBody};
use crate::physics::contact::{Contact, FaceContact};
use crate::physics::system::MultibodySystem;
use crate::units::STANDARD_GRAVITY;
use nalgebra::{Isometry3, Matrix3, Point3, Unit, Vector3};
use std::sync::Arc;

/// How the rattle box's faces are resolved when a case does not say (`simulation.face_contact`):
/// the contact-point lattice, converged here at 3 points per edge (friction power and wear
/// within 0.06 % of the exact contact at the default 5) at about a third of the exact
/// contact's cost (docs/journal/performance.md, tenth and fourteenth passes).
pub const FACE_CONTACT: FaceContact = FaceContact::Lattice;

/// Wall thickness of the rattle-box tube, m (estimate: 1/8 in; it only sets how far each
/// wall's face extends past the inner corners, so that the corners are solid).
pub const TUBE_WALL_THICKNESS_M: f64 = 3.175e-3;

/// Half-space whose solid lies beyond `offset` along `-inward` (wall faces of a cavity):
/// `inward` points from the wall into the cavity.
pub fn wall(inward: Vector3<f64>, distance_from_origin: f64) -> HalfSpace {
    HalfSpace {
        normal: Unit::new_normalize(inward),
        offset: -distance_from_origin,
    }
}

/// Builds the rattle box system. The cube starts resting on the tube floor at its static
/// penetration (IMPACT spring alone carrying the weight), centred in the tube.
pub fn build(case: &CaseSpec, spec: &RattleBoxSpec, motion: BaseMotion) -> BuiltModel {
    let rate_start_s = BuiltModel::rate_start(case.simulation.settle_s, &motion);
    let side = spec.cube_side_m;
    let half = 0.5 * side;
    let l = 0.5 * spec.tube_inner_side_m;
    let mass = spec.cube_mass_kg();
    let cube = RigidBody {
        name: "cube".into(),
        mass: MassProperties {
            mass,
            inertia: Matrix3::from_diagonal_element(spec.cube_inertia_kg_m2()),
        },
        kind: BodyKind::Dynamic { offset: 0 },
    };
    let tube = RigidBody {
        name: "tube".into(),
        mass: MassProperties {
            mass: 1.0,
            inertia: Matrix3::identity(),
        },
        kind: BodyKind::Kinematic(Arc::new(TranslatingBase {
            reference: Isometry3::identity(),
            motion,
        })),
    };
    let lz = 0.5 * spec.tube_length_m;
    let mut faces = vec![
        wall(-Vector3::x(), l),
        wall(Vector3::x(), l),
        wall(-Vector3::y(), l),
        wall(Vector3::y(), l),
    ];
    if spec.end_caps {
        faces.push(wall(-Vector3::z(), lz));
        faces.push(wall(Vector3::z(), lz));
    }
    // Each wall is the tube's real face: as wide as the tube's outside (so the corners are
    // solid) and as long as the tube.
    let outer = l + TUBE_WALL_THICKNESS_M;
    let extent = |origin: Vector3<f64>, tangent: Vector3<f64>, t_half: f64| {
        Some(FaceExtent {
            origin: Point3::from(origin),
            tangent: Unit::new_normalize(tangent),
            s_range_m: (-outer, outer),
            t_range_m: (-t_half, t_half),
        })
    };
    let mut extents = vec![
        extent(Vector3::new(l, 0.0, 0.0), Vector3::y(), lz),
        extent(Vector3::new(-l, 0.0, 0.0), Vector3::y(), lz),
        extent(Vector3::new(0.0, l, 0.0), Vector3::x(), lz),
        extent(Vector3::new(0.0, -l, 0.0), Vector3::x(), lz),
    ];
    if spec.end_caps {
        extents.push(extent(Vector3::new(0.0, 0.0, lz), Vector3::x(), outer));
        extents.push(extent(Vector3::new(0.0, 0.0, -lz), Vector3::x(), outer));
    }
    let impact = spec.contact.to_impact_params();
    let contact = Contact::new(
        "cube-tube",
        0,
        vec![(
            Isometry3::identity(),
            ConvexShape::RoundedBox {
                half_extents: Vector3::new(half, half, half),
                roundover: spec.edge_radius_m,
            },
        )],
        1,
        faces,
        impact,
        Some(spec.friction),
    )
    .with_face_extents(extents)
    .with_points_per_edge(case.simulation.contact_points_per_edge)
    .with_face_contact(case.simulation.face_contact.unwrap_or(FACE_CONTACT));
    // The tube carries the shaker's motion.
    let system = MultibodySystem::new(
        vec![cube, tube],
        Vector3::new(0.0, -STANDARD_GRAVITY, 0.0),
        vec![],
        vec![contact],
    )
    .with_carrier(1);
    let w_static = impact.static_penetration(mass * STANDARD_GRAVITY);
    let mut y = vec![0.0; system.state_len()];
    write_state(
        &mut y,
        0,
        &Isometry3::translation(0.0, -l + half - w_static, 0.0),
        Vector3::zeros(),
        Vector3::zeros(),
    );
    let mat = spec.material;
    BuiltModel {
        name: case.name.clone(),
        system,
        initial_state: y,
        excitation_start_s: case.simulation.settle_s,
        rate_start_s,
        end_time_s: case.simulation.settle_s + case.simulation.duration_s,
        contact_materials: vec![(mat, mat)],
        response_body: 0,
    }
}
