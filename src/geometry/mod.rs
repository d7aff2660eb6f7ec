//! Contact geometry of convex pieces against half-spaces and of sphere pairs (thesis 2.5,
//! SPEC §2 "Contact geometry", "Contact area").
//!
//! Every contact in railwear is a convex body piece (rounded box or sphere) against a plane
//! (tube walls, rail faces, the latch face, the fixture coupon) or sphere against sphere. For
//! each touching pair we need the penetration (depth of the deepest point), the overlap volume,
//! its centroid (where the force acts) and the thesis 2.5 area `volume / depth`.
//!
//! Decision: railwear does NOT use parry. parry gives depth and contact points but not the
//! overlap volume that thesis 2.5 needs, and every pair we need is convex-vs-plane or
//! sphere-sphere, so the overlap is computed here exactly:
//! - sphere: cap volume `π w² (R - w/3)` and cap centroid, closed form;
//! - rounded box = inner box ⊕ ball(r), split by its normal cones into the inner box, 6 face
//!   slabs, 12 edge pieces and 8 ball octants (disjoint). Boxes are clipped exactly
//!   (`polytope_clip`); edge and vertex pieces are integrated along one coordinate of closed
//!   form sections (disk ∩ convex polygon, `disk_polygon`) with Gauss–Legendre on sub-intervals
//!   split at every kink and with node clustering at tangencies (`quadrature`), which is
//!   exact to round-off in the tests (see docs/reference/geometry.md for the measured bounds).
//!
//! Hot path (about 10⁶ calls per simulated second): no heap allocation, fixed-size arrays only.

pub mod bounded_face;
mod disk_polygon;
pub mod face_patch;
#[cfg(test)]
mod face_patch_tests;
pub mod halfspace_overlap;
pub mod lattice;
pub mod polygon_moments;
mod polytope_clip;
mod quadrature;
pub mod shapes;
mod sphere_cap;
pub mod sphere_sphere;
mod steiner_pieces;
#[cfg(test)]
mod tests;

pub use bounded_face::{FaceExtent, PlacedFace};
pub use face_patch::{inner_box_faces, FacePatch, GradedStrip, Line, QuadratureOrder};
pub use halfspace_overlap::{shape_halfspace_depth, shape_halfspace_overlap, PlaneOverlap};
pub use lattice::{contact_points, ContactPoint, DEFAULT_POINTS_PER_EDGE};
pub use polygon_moments::PolygonMoments;
pub use shapes::{ConvexShape, GeometryError, HalfSpace};
pub use sphere_sphere::{sphere_sphere_overlap, SphereOverlap};
