//! Overlap of a convex shape with a solid half-space: penetration, volume, area, centroid.
//!
//! Thesis 2.5: the contact area is the intersecting volume divided by the penetration depth.
//! The volume is exact (closed forms plus Gauss–Legendre on analytic pieces, see the module
//! doc of [`super`]).

use super::polytope_clip::box_below_plane;
use super::shapes::{ConvexShape, HalfSpace};
use super::sphere_cap::{cap_centroid_distance, cap_volume};
use super::steiner_pieces::{add_edges, add_vertices, Accum};
use nalgebra::{Isometry3, Point3, Vector3};
use std::f64::consts::PI;

/// Result of a shape pressed into a half-space (world frame).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlaneOverlap {
    /// Penetration, m: how far the deepest point lies below the plane (> 0). ADAMS IMPACT
    /// `w` (thesis eq. 2.1).
    pub depth: f64,
    /// Overlap volume below the plane, m³.
    pub volume: f64,
    /// Contact area, m² = `volume / depth` (thesis 2.5).
    pub area: f64,
    /// Centroid of the overlap volume, world, m: where the contact force is applied.
    pub centroid: Point3<f64>,
    /// Deepest point of the shape, world, m; on a flat face the centre of that face.
    pub deepest_point: Point3<f64>,
}

/// Overlap of `shape` placed by `pose` (shape frame -> world) with the solid `half_space`
/// (world). `None` when the shape does not reach below the plane. Allocation-free.
pub fn shape_halfspace_overlap(
    shape: &ConvexShape,
    pose: &Isometry3<f64>,
    half_space: &HalfSpace,
) -> Option<PlaneOverlap> {
    let n_world = half_space.normal.into_inner();
    // Plane in the shape frame: n·x <= c.
    let n = pose.rotation.inverse_transform_vector(&n_world);
    let c = half_space.offset - n_world.dot(&pose.translation.vector);
    let (depth, volume, centroid, deepest) = match *shape {
        ConvexShape::Sphere { radius } => sphere_below_plane(radius, &n, c)?,
        ConvexShape::RoundedBox {
            half_extents,
            roundover,
        } => rounded_box_below_plane(&half_extents, roundover, &n, c)?,
    };
    Some(PlaneOverlap {
        depth,
        volume,
        area: volume / depth,
        centroid: pose * Point3::from(centroid),
        deepest_point: pose * Point3::from(deepest),
    })
}

/// Penetration (m) and deepest point (world) of `shape` placed by `pose` in the solid
/// `half_space`, without the overlap volume: the same numbers as
/// [`shape_halfspace_overlap`]'s `depth` and `deepest_point`, from the support function alone
/// (a few dozen flops). `None` when the shape does not reach below the plane.
pub fn shape_halfspace_depth(
    shape: &ConvexShape,
    pose: &Isometry3<f64>,
    half_space: &HalfSpace,
) -> Option<(f64, Point3<f64>)> {
    let n_world = half_space.normal.into_inner();
    let n = pose.rotation.inverse_transform_vector(&n_world);
    let c = half_space.offset - n_world.dot(&pose.translation.vector);
    let (depth, deepest) = match *shape {
        ConvexShape::Sphere { radius } => sphere_support(radius, &n, c)?,
        ConvexShape::RoundedBox {
            half_extents,
            roundover,
        } => rounded_box_support(&half_extents, roundover, &n, c)?,
    };
    Some((depth, pose * Point3::from(deepest)))
}

/// Depth and deepest point of a ball at the origin below the plane `n·x <= c` (shape frame).
#[inline]
fn sphere_support(r: f64, n: &Vector3<f64>, c: f64) -> Option<(f64, Vector3<f64>)> {
    let depth = r + c; // centre at u = -c
    if depth.is_nan() || depth <= 0.0 {
        return None;
    }
    Some((depth, -n * r))
}

/// Depth, volume, centroid and deepest point for a ball at the origin (shape frame).
#[inline]
fn sphere_below_plane(
    r: f64,
    n: &Vector3<f64>,
    c: f64,
) -> Option<(f64, f64, Vector3<f64>, Vector3<f64>)> {
    let (depth, deepest) = sphere_support(r, n, c)?;
    if depth >= 2.0 * r {
        return Some((depth, 4.0 / 3.0 * PI * r.powi(3), Vector3::zeros(), deepest));
    }
    let volume = cap_volume(r, depth);
    let centroid = -n * cap_centroid_distance(r, depth);
    Some((depth, volume, centroid, deepest))
}

/// Components of `n` smaller than this are treated as zero when placing the deepest point at
/// the centre of a flat face (1e-12 rad of tilt moves the true support point by < 1e-12 m).
const FLAT_TOLERANCE: f64 = 1e-12;

/// Depth and deepest point of a rounded box (outer half extents, roundover `r`) at the origin
/// below the plane `n·x <= c` (shape frame): the support point of the inner box in `-n`, moved
/// by `r` along `-n`; on a flat face the centre of that face.
#[inline]
fn rounded_box_support(
    outer: &Vector3<f64>,
    r: f64,
    n: &Vector3<f64>,
    c: f64,
) -> Option<(f64, Vector3<f64>)> {
    let h = outer - Vector3::repeat(r);
    let depth = c + n.x.abs() * h.x + n.y.abs() * h.y + n.z.abs() * h.z + r;
    if depth.is_nan() || depth <= 0.0 {
        return None;
    }
    let support = |ni: f64, hi: f64| {
        if ni.abs() < FLAT_TOLERANCE {
            0.0
        } else {
            -hi.copysign(ni)
        }
    };
    Some((
        depth,
        Vector3::new(support(n.x, h.x), support(n.y, h.y), support(n.z, h.z)) - n * r,
    ))
}

fn rounded_box_below_plane(
    outer: &Vector3<f64>,
    r: f64,
    n: &Vector3<f64>,
    c: f64,
) -> Option<(f64, f64, Vector3<f64>, Vector3<f64>)> {
    let (depth, deepest) = rounded_box_support(outer, r, n, c)?;
    let h = outer - Vector3::repeat(r);
    let mut acc = Accum::default();
    let (v, m) = box_below_plane(&Vector3::zeros(), &h, n, c);
    acc.add(v, m);
    if r > 0.0 {
        for axis in 0..3 {
            let mut half = h;
            half[axis] = 0.5 * r;
            for sign in [1.0, -1.0] {
                let mut centre = Vector3::zeros();
                centre[axis] = sign * (h[axis] + 0.5 * r);
                let (v, m) = box_below_plane(&centre, &half, n, c);
                acc.add(v, m);
            }
        }
        add_edges(&h, r, n, c, &mut acc);
        add_vertices(&h, r, n, c, &mut acc);
    }
    if acc.volume <= 0.0 {
        // Touching with zero measure (depth at round-off level).
        return None;
    }
    Some((depth, acc.volume, acc.moment / acc.volume, deepest))
}
