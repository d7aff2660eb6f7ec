//! The exactly integrated face contact (issue 27; docs/models.md "Exact face contact"): a
//! rounded box's faces resolved by the continuum the contact-point lattice converges to,
//! integrated over each pressed polygon by a rule exact for the IMPACT law's polynomial
//! densities ([`crate::geometry::face_patch`]).
//!
//! Every quadrature node is a point of the per-material-point law
//! ([`Contact::evaluate_point`](super::Contact::evaluate_point)) with the plane's normal and
//! the node's share of the face: its force, damping and friction act at the node with the
//! node's own rates, so damping and friction do non-positive work node by node, and the
//! elastic resultants (force, torque, stored energy) are the exact integrals. Where a bounded
//! face's side cuts the patch, the region moves relative to the material and the energy's
//! gradient has a boundary term: a force `U'(w)` per unit length along the cut, pointing out
//! of the face's extent ([`Contact::evaluate_faces`]). With it the elastic force is the exact
//! gradient of the stored energy, and a shoe sliding off a lip unloads continuously.

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
    /// law's force, torque and stored energy (integer exponent), plus the boundary force of a
    /// bounded face's cut sides: the lattice's limit of infinitely many points, up to the
    /// rounded strip beyond a bounded face's edge (docs/models.md "Exact face contact").
    Exact,
}

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
            let Some(patch) = FacePatch::new(centre, axis_u, axis_v, radius, face) else {
                continue;
            };
            let d = patch.deepest();
            if deepest.is_none_or(|best| d.0 > best.0) {
                deepest = Some(d);
            }
            patch.for_each_node(order, &mut |x, share| {
                let distance = normal.dot(&x.coords) - offset;
                self.evaluate_point(fa, fb, &x, radius, share, distance, &normal, out);
            });
            patch.for_each_cut_node(order, &mut |node| {
                if node.penetration > 0.0 {
                    let force = node.outward * (node.weight * self.impact.potential(node.penetration));
                    out.sum.add_boundary_force(&node.centre, &force, fa, fb);
                }
            });
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
