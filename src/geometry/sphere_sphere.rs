//! Sphere–sphere overlap (lens), closed form.

use super::sphere_cap::{cap_centroid_distance, cap_volume};
use nalgebra::{Point3, Unit, Vector3};
use std::f64::consts::PI;

/// Overlap of two balls (world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereOverlap {
    /// Penetration, m: `ra + rb - |cb - ca|` (> 0).
    pub depth: f64,
    /// Lens volume, m³.
    pub volume: f64,
    /// Contact area, m² = `volume / depth` (thesis 2.5).
    pub area: f64,
    /// Centroid of the lens, world, m.
    pub centroid: Point3<f64>,
    /// Unit normal from A's centre towards B's; +z when the centres coincide.
    pub normal: Unit<Vector3<f64>>,
}

/// Lens overlap of ball A (radius `ra` m at `ca`) and ball B (`rb`, `cb`); `None` when apart.
/// When one ball contains the other the overlap is the smaller ball.
pub fn sphere_sphere_overlap(
    ra: f64,
    ca: &Point3<f64>,
    rb: f64,
    cb: &Point3<f64>,
) -> Option<SphereOverlap> {
    let delta = cb - ca;
    let d = delta.norm();
    let depth = ra + rb - d;
    if depth.is_nan() || depth <= 0.0 {
        return None;
    }
    let normal = if d > 0.0 {
        Unit::new_unchecked(delta / d)
    } else {
        Vector3::z_axis()
    };
    let (volume, centroid) = if d <= (ra - rb).abs() {
        if ra <= rb {
            (4.0 / 3.0 * PI * ra.powi(3), *ca)
        } else {
            (4.0 / 3.0 * PI * rb.powi(3), *cb)
        }
    } else {
        // Radical plane at distance x from A's centre; caps of heights ha (on A), hb (on B).
        let x = (d * d + ra * ra - rb * rb) / (2.0 * d);
        let ha = ra - x;
        let hb = rb - (d - x);
        let va = cap_volume(ra, ha);
        let vb = cap_volume(rb, hb);
        let ga = ca + normal.into_inner() * cap_centroid_distance(ra, ha);
        let gb = cb - normal.into_inner() * cap_centroid_distance(rb, hb);
        let v = va + vb;
        (v, Point3::from((ga.coords * va + gb.coords * vb) / v))
    };
    Some(SphereOverlap {
        depth,
        volume,
        area: volume / depth,
        centroid,
        normal,
    })
}
