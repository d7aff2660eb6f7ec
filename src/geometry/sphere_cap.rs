//! Spherical caps (closed forms used by the overlap of spheres and of a rounded box's corner
//! pieces with a half-space; thesis 2.5 sphere-on-plane area `π R w (1 − w/(3R))`).

use std::f64::consts::PI;

/// Volume of a spherical cap of height `w` on a ball of radius `r`, m³.
#[inline]
pub(crate) fn cap_volume(r: f64, w: f64) -> f64 {
    PI * w * w * (r - w / 3.0)
}

/// Distance from the ball centre to the centroid of a cap of height `w`, m.
#[inline]
pub(crate) fn cap_centroid_distance(r: f64, w: f64) -> f64 {
    let t = 2.0 * r - w;
    3.0 * t * t / (4.0 * (3.0 * r - w))
}
