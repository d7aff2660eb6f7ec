//! Bounded planar faces (SPEC §2 "Contact geometry": faces of their real extent, not unbounded
//! planes) and the signed distance of a contact point's ball to the solid behind such a face.
//!
//! A face is a rectangle (possibly open on any side) of its plane; the solid it bounds is the
//! prism behind it: `{u <= 0, s_min <= s <= s_max, t_min <= t <= t_max}` with `u` the height
//! above the plane along the outward normal and `(s, t)` in-plane coordinates. A side with a
//! finite bound is a real edge of the solid (a rail lip's edge at the slot); an open side
//! (infinite bound) continues the face, as an unbounded half-space does.
//!
//! The signed distance of a point to this prism is continuous everywhere, so a contact energy
//! that depends on it is continuous in the configuration (a point sliding off a lip's edge
//! unloads smoothly instead of jumping), and its gradient, the unit normal returned with it, is
//! the exact direction of the elastic force.

use super::shapes::{ConvexShape, HalfSpace};
use nalgebra::{Isometry3, Point3, Unit, Vector3};

/// The in-plane extent of a face, in the frame of the body that carries the face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceExtent {
    /// A point of the face's plane from which `s` and `t` are measured, m.
    pub origin: Point3<f64>,
    /// In-plane direction of `s` (unit, perpendicular to the face normal); `t` runs along
    /// `normal × tangent`.
    pub tangent: Unit<Vector3<f64>>,
    /// Bounds of `s`, m (`-inf`/`+inf` leave that side open).
    pub s_range_m: (f64, f64),
    /// Bounds of `t`, m (`-inf`/`+inf` leave that side open).
    pub t_range_m: (f64, f64),
}

/// A face placed in the world: plane plus optional extent, ready for point queries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacedFace {
    /// The face's plane; the solid is on the side opposite the normal.
    pub plane: HalfSpace,
    origin: Point3<f64>,
    tangent: Vector3<f64>,
    bitangent: Vector3<f64>,
    s_range: (f64, f64),
    t_range: (f64, f64),
    bounded: bool,
}

impl PlacedFace {
    /// Places `extent` (in the carrying body's frame, `None`: unbounded) with the body at
    /// `pose`; `plane` is the face's plane already in world coordinates.
    pub fn new(plane: HalfSpace, extent: Option<&FaceExtent>, pose: &Isometry3<f64>) -> Self {
        let n = plane.normal.into_inner();
        match extent {
            Some(e) => {
                let tangent = pose.rotation * e.tangent.into_inner();
                Self {
                    plane,
                    origin: pose * e.origin,
                    tangent,
                    bitangent: n.cross(&tangent),
                    s_range: e.s_range_m,
                    t_range: e.t_range_m,
                    bounded: true,
                }
            }
            None => Self {
                plane,
                origin: Point3::origin(),
                tangent: Vector3::zeros(),
                bitangent: Vector3::zeros(),
                s_range: (f64::NEG_INFINITY, f64::INFINITY),
                t_range: (f64::NEG_INFINITY, f64::INFINITY),
                bounded: false,
            },
        }
    }

    /// Whether the face has an extent.
    pub fn is_bounded(&self) -> bool {
        self.bounded
    }

    /// Signed distance (m, negative inside) of `x` to the solid behind the face, and the unit
    /// outward normal of the solid at the nearest boundary point (the distance's gradient).
    #[inline]
    pub fn signed_distance(&self, x: &Point3<f64>) -> (f64, Vector3<f64>) {
        let (dist, dir, outside) = self.nearest(x);
        (dist, if outside { dir / dist } else { dir })
    }

    /// [`PlacedFace::signed_distance`] of `x` when it is below `reach` (the same distance and
    /// normal, bit for bit), `None` otherwise: a ball of radius `reach` centred at `x` that
    /// does not penetrate the solid, whose normal (a division per component outside the
    /// solid) is then not taken. For the contact nodes beyond a bounded face's side.
    #[inline]
    pub fn signed_distance_within(
        &self,
        x: &Point3<f64>,
        reach: f64,
    ) -> Option<(f64, Vector3<f64>)> {
        let (dist, dir, outside) = self.nearest(x);
        (reach - dist > 0.0).then(|| (dist, if outside { dir / dist } else { dir }))
    }

    /// The signed distance of `x`, and either the unit normal (`false`) or, outside the solid
    /// beyond an edge (`true`), the vector from the nearest point to `x`, whose length is the
    /// distance.
    #[inline]
    fn nearest(&self, x: &Point3<f64>) -> (f64, Vector3<f64>, bool) {
        let n = self.plane.normal.into_inner();
        let u = n.dot(&x.coords) - self.plane.offset;
        if !self.bounded {
            return (u, n, false);
        }
        let d = x - self.origin;
        let s = self.tangent.dot(&d);
        let t = self.bitangent.dot(&d);
        // Outside excess along each axis (positive outside) and its outward direction.
        let (qs, ds) = side(s, self.s_range, &self.tangent);
        let (qt, dt) = side(t, self.t_range, &self.bitangent);
        if qs <= 0.0 && qt <= 0.0 && u >= qs.max(qt) {
            // Over the face (above or below it), nearer the face than any of its edges.
            return (u, n, false);
        }
        if u > 0.0 || qs > 0.0 || qt > 0.0 {
            let v = n * u.max(0.0) + ds * qs.max(0.0) + dt * qt.max(0.0);
            return (v.norm(), v, true);
        }
        // Inside: the nearest face of the prism.
        if u >= qs && u >= qt {
            (u, n, false)
        } else if qs >= qt {
            (qs, ds, false)
        } else {
            (qt, dt, false)
        }
    }

    /// The extent's finite sides, each as (outward unit direction `d`, a point `o` of the
    /// face, bound `b`): the extent is `d·(x − o) <= b` on every side (none when unbounded).
    pub fn sides(&self) -> impl Iterator<Item = (Vector3<f64>, Point3<f64>, f64)> + '_ {
        let sides = [
            (self.tangent, self.s_range.1),
            (-self.tangent, -self.s_range.0),
            (self.bitangent, self.t_range.1),
            (-self.bitangent, -self.t_range.0),
        ];
        sides
            .into_iter()
            .filter(move |(_, b)| self.bounded && b.is_finite())
            .map(move |(d, b)| (d, self.origin, b))
    }

    /// Share of `shape` (placed by `pose`) whose extent along the face's bounded in-plane
    /// directions lies within the face, 0..1 (1 for an unbounded face). It scales the thesis
    /// 2.5 area (overlap volume / depth against the face's plane) to the face's extent: exact
    /// for a piece whose contacting face is parallel to the plane (a shoe head on a lip), an
    /// upper bound on the clipped share for a tilted piece.
    pub fn coverage(&self, shape: &ConvexShape, pose: &Isometry3<f64>) -> f64 {
        if !self.bounded {
            return 1.0;
        }
        let mut share = 1.0;
        for (dir, range) in [(self.tangent, self.s_range), (self.bitangent, self.t_range)] {
            let centre = dir.dot(&(pose.translation.vector - self.origin.coords));
            let half = half_width(shape, pose, &dir);
            if half <= 0.0 {
                continue;
            }
            let lo = (centre - half).max(range.0);
            let hi = (centre + half).min(range.1);
            share *= ((hi - lo) / (2.0 * half)).clamp(0.0, 1.0);
        }
        share
    }
}

/// Excess of `s` beyond `range` (positive outside, the larger of the two sides' excesses
/// inside) and the outward direction of the nearer side.
#[inline]
fn side(s: f64, range: (f64, f64), dir: &Vector3<f64>) -> (f64, Vector3<f64>) {
    let below = range.0 - s;
    let above = s - range.1;
    if above >= below {
        (above, *dir)
    } else {
        (below, -dir)
    }
}

/// Half the width of `shape` placed by `pose` along the unit direction `dir`, m.
fn half_width(shape: &ConvexShape, pose: &Isometry3<f64>, dir: &Vector3<f64>) -> f64 {
    match *shape {
        ConvexShape::Sphere { radius } => radius,
        ConvexShape::RoundedBox {
            half_extents,
            roundover,
        } => {
            let local = pose.rotation.inverse_transform_vector(dir);
            (0..3)
                .map(|k| (half_extents[k] - roundover).max(0.0) * local[k].abs())
                .sum::<f64>()
                + roundover
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lip top: plane y = 0, solid below, real edge at x = 0 (slot for x > 0), open elsewhere.
    fn lip() -> PlacedFace {
        let plane = HalfSpace::new(Vector3::y(), 0.0).expect("plane");
        let extent = FaceExtent {
            origin: Point3::origin(),
            tangent: Vector3::x_axis(),
            s_range_m: (f64::NEG_INFINITY, 0.0),
            t_range_m: (f64::NEG_INFINITY, f64::INFINITY),
        };
        PlacedFace::new(plane, Some(&extent), &Isometry3::identity())
    }

    #[test]
    fn distance_is_the_euclidean_distance_to_the_prism() {
        let f = lip();
        // Above the face: height.
        let (d, n) = f.signed_distance(&Point3::new(-1e-3, 2e-4, 0.0));
        assert!((d - 2e-4).abs() < 1e-18 && (n - Vector3::y()).norm() < 1e-15);
        // Beside the edge, above and out: distance to the edge line.
        let (d, n) = f.signed_distance(&Point3::new(3e-4, 4e-4, 0.0));
        assert!((d - 5e-4).abs() < 1e-18);
        assert!((n - Vector3::new(0.6, 0.8, 0.0)).norm() < 1e-12);
        // Inside near the top: depth below the top; inside near the edge: distance to the edge.
        let (d, n) = f.signed_distance(&Point3::new(-1e-3, -1e-4, 0.0));
        assert!((d + 1e-4).abs() < 1e-18 && n == Vector3::y());
        let (d, n) = f.signed_distance(&Point3::new(-5e-5, -1e-4, 0.0));
        assert!((d + 5e-5).abs() < 1e-18 && n == Vector3::x());
    }

    #[test]
    fn distance_is_continuous_across_the_edge() {
        let f = lip();
        let mut prev = f.signed_distance(&Point3::new(-1e-3, -1e-4, 0.0)).0;
        for i in 1..=2000 {
            let x = -1e-3 + 2e-3 * i as f64 / 2000.0;
            let d = f.signed_distance(&Point3::new(x, -1e-4, 0.0)).0;
            assert!((d - prev).abs() <= 1e-6 + 1e-12, "jump at x = {x}");
            prev = d;
        }
    }

    #[test]
    fn coverage_of_a_head_across_a_slot() {
        // A 38.1 mm head centred on a 10.23 mm slot: each lip carries (38.1 - 10.23)/2 mm.
        let plane = HalfSpace::new(Vector3::y(), 0.0).expect("plane");
        let extent = FaceExtent {
            origin: Point3::origin(),
            tangent: Vector3::x_axis(),
            s_range_m: (f64::NEG_INFINITY, -5.115e-3),
            t_range_m: (f64::NEG_INFINITY, f64::INFINITY),
        };
        let f = PlacedFace::new(plane, Some(&extent), &Isometry3::identity());
        let head =
            ConvexShape::rounded_box(Vector3::new(19.05e-3, 4.8e-3, 40e-3), 5e-4).expect("head");
        let share = f.coverage(&head, &Isometry3::translation(0.0, 4.8e-3, 0.0));
        let exact = (19.05 - 5.115) / 38.1;
        assert!((share - exact).abs() < 1e-12, "{share} vs {exact}");
    }
}
