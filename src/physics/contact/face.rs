//! The exactly integrated face contact (issue 27; docs/models.md "Exact face contact"): a
//! rounded box's faces resolved by the continuum the contact-point lattice converges to,
//! integrated over each pressed polygon by a rule exact for the IMPACT law's polynomial
//! densities ([`crate::geometry::face_patch`]).
//!
//! Every quadrature node is a point of the per-material-point law
//! ([`Contact::evaluate_point`](super::Contact::evaluate_point)) with the plane's normal and
//! the node's share of the face: its force, damping and friction act at the node with the
//! node's own rates, so damping and friction do non-positive work node by node, and the
//! elastic resultants (force, torque, stored energy) over the face's extent are the exact
//! integrals. Beyond a bounded face's side, within the roundover radius, balls touch the
//! face's rounded-off edge ([`FacePatch::beyond_sides`]): the energy is continuous across the
//! side, so the region boundary terms of its gradient cancel and the elastic force is the
//! gradient of the stored energy up to the strips' quadrature error; a shoe sliding off a lip
//! unloads continuously.

use super::point::PointOutputs;
use super::Contact;
use crate::geometry::{inner_box_faces, FacePatch, PlacedFace, QuadratureOrder};
use crate::physics::body::BodyFrame;
use nalgebra::{Isometry3, Point3, Vector3};

/// How a contact resolves the faces of its rounded boxes (spheres are one point either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaceContact {
    /// Contact points on a lattice of `contact_points_per_edge` nodes per box edge
    /// ([`crate::geometry::lattice`]): converges like a trapezoid rule as the lattice refines.
    #[default]
    Lattice,
    /// Each face integrated over its pressed polygon with a Gauss rule exact for the IMPACT
    /// law's force, torque and stored energy (integer exponent), and over the strips beyond a
    /// bounded face's sides with a 5 × 5 rule: the lattice's limit of infinitely many points
    /// (docs/models.md "Exact face contact").
    Exact,
}

/// Slices per strip beyond a bounded face's side (each with the 5 × 5 rule): the strip's
/// integrand has a kink where `w = 0` crosses it on a tilted face.
const ROUNDED_EDGE_SLICES: usize = 2;

impl Contact {
    /// Evaluates the six faces of the inner box `inner` (half extents, m) of a rounded box of
    /// roundover `radius` placed by `pose` against `face`, into `out`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn evaluate_faces(
        &self,
        fa: &BodyFrame,
        fb: &BodyFrame,
        pose: &Isometry3<f64>,
        inner: &Vector3<f64>,
        radius: f64,
        face: &PlacedFace,
        out: &mut PointOutputs<'_, '_>,
    ) {
        let normal = face.plane.normal.into_inner();
        let offset = face.plane.offset;
        let order = QuadratureOrder::for_exponent(self.impact.exponent);
        let mut deepest: Option<(f64, Point3<f64>)> = None;
        for (centre, axis_u, axis_v) in inner_box_faces(inner, pose) {
            if let Some(patch) = FacePatch::new(centre, axis_u, axis_v, radius, face) {
                let d = patch.deepest();
                if deepest.is_none_or(|best| d.0 > best.0) {
                    deepest = Some(d);
                }
                patch.for_each_node(order, &mut |x, share| {
                    let distance = normal.dot(&x.coords) - offset;
                    self.evaluate_point(fa, fb, &x, radius, share, distance, &normal, out);
                });
            }
            if !face.is_bounded() {
                continue;
            }
            for strip in FacePatch::beyond_sides(centre, axis_u, axis_v, radius, face)
                .iter()
                .flatten()
            {
                let order = QuadratureOrder::ROUNDED_EDGE;
                strip.for_each_node_sliced(order, ROUNDED_EDGE_SLICES, &mut |x, share| {
                    let (distance, normal) = face.signed_distance(&x);
                    self.evaluate_point(fa, fb, &x, radius, share, distance, &normal, out);
                });
            }
        }
        // The track's penetration is the patch's deepest vertex (the exact maximum of the
        // linear `w`), not the deepest node.
        if let (Some((w, x)), true) = (deepest, out.sum.touching) {
            let p = x - normal * radius;
            let v_rel = fa.point_velocity(&p) - fb.point_velocity(&p);
            out.sum.penetration = w;
            out.sum.penetration_rate = -v_rel.dot(&normal);
            out.sum.deepest_point = p;
            out.sum.normal = normal;
        }
    }
}
