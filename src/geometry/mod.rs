//! Contact geometry (temporary sphere-only version; replaced by the geometry branch).
use nalgebra::{Isometry3, Point3, Unit, Vector3};

/// Convex shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConvexShape {
    /// Sphere of radius m.
    Sphere { radius: f64 },
    /// Rounded box.
    RoundedBox {
        half_extents: Vector3<f64>,
        roundover: f64,
    },
}
/// Half-space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// Normal out of the solid.
    pub normal: Unit<Vector3<f64>>,
    /// Offset.
    pub offset: f64,
}
/// Overlap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneOverlap {
    /// depth
    pub depth: f64,
    /// volume
    pub volume: f64,
    /// area
    pub area: f64,
    /// centroid
    pub centroid: Point3<f64>,
    /// deepest
    pub deepest_point: Point3<f64>,
}
/// Overlap of a shape with a half-space.
pub fn shape_halfspace_overlap(
    shape: &ConvexShape,
    pose: &Isometry3<f64>,
    hs: &HalfSpace,
) -> Option<PlaneOverlap> {
    match shape {
        ConvexShape::Sphere { radius } => {
            let c = pose.translation.vector;
            let n = hs.normal.into_inner();
            let w = hs.offset - (n.dot(&c) - radius);
            if w <= 0.0 {
                return None;
            }
            let r = *radius;
            let v = std::f64::consts::PI * w * w * (r - w / 3.0);
            let deep = c - n * r;
            let zc = 3.0 * (2.0 * r - w).powi(2) / (4.0 * (3.0 * r - w));
            Some(PlaneOverlap {
                depth: w,
                volume: v,
                area: v / w,
                centroid: Point3::from(c - n * zc),
                deepest_point: Point3::from(deep),
            })
        }
        ConvexShape::RoundedBox { .. } => None,
    }
}
