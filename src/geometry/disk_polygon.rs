//! Closed-form area and first moment of a disk intersected with a convex polygon (2D).
//!
//! Used for the cross-sections of the rounded-box edge pieces (quarter disk cut by a line) and
//! the slices of the vertex pieces (disk cut by the three octant planes). The polygon is built
//! by clipping a square that encloses the disk with half-planes (Sutherland–Hodgman on a fixed
//! array), then the disk ∩ polygon area is summed edge by edge over the triangles
//! (centre, edge): inside the circle a triangle, outside it a circular sector.

/// A 2D point or vector, m.
pub(crate) type V2 = [f64; 2];

/// Capacity of [`Poly2`]: a square clipped by 3 half-planes has at most 7 vertices.
const MAX_VERTS: usize = 8;

/// Convex polygon, counter-clockwise, fixed capacity (no heap).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Poly2 {
    v: [V2; MAX_VERTS],
    n: usize,
}

impl Poly2 {
    /// Axis-aligned square `[-half, half]²`, counter-clockwise.
    #[inline]
    pub(crate) fn square(half: f64) -> Self {
        let mut v = [[0.0; 2]; MAX_VERTS];
        v[0] = [-half, -half];
        v[1] = [half, -half];
        v[2] = [half, half];
        v[3] = [-half, half];
        Self { v, n: 4 }
    }

    /// The square `[0, side]²` with the vertex order `square(side).clip(x >= 0).clip(y >= 0)`
    /// produces (same polygon, same arithmetic downstream, two clips fewer): the first
    /// quadrant part of a square enclosing a disk of radius `side / 2`.
    #[inline]
    pub(crate) fn first_quadrant(side: f64) -> Self {
        let mut v = [[0.0; 2]; MAX_VERTS];
        v[0] = [side, 0.0];
        v[1] = [side, side];
        v[2] = [0.0, side];
        v[3] = [0.0, 0.0];
        Self { v, n: 4 }
    }

    /// Index of the vertex after `k` (no integer division in the hot loops).
    #[inline]
    fn next(&self, k: usize) -> usize {
        if k + 1 == self.n {
            0
        } else {
            k + 1
        }
    }

    /// Keeps the part with `a·p <= b` (Sutherland–Hodgman, one half-plane).
    #[inline]
    pub(crate) fn clip(&self, a: V2, b: f64) -> Self {
        let mut out = [[0.0; 2]; MAX_VERTS];
        let mut m = 0;
        for k in 0..self.n {
            let p = self.v[k];
            let q = self.v[self.next(k)];
            let dp = a[0] * p[0] + a[1] * p[1] - b;
            let dq = a[0] * q[0] + a[1] * q[1] - b;
            if dp <= 0.0 && m < MAX_VERTS {
                out[m] = p;
                m += 1;
            }
            if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) && m < MAX_VERTS {
                let t = dp / (dp - dq);
                out[m] = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                m += 1;
            }
        }
        Self { v: out, n: m }
    }

    /// Area (m²) and first moment (m³, about the origin) of this polygon ∩ the disk of
    /// radius `rho` centred at the origin.
    #[inline]
    pub(crate) fn disk_intersection(&self, rho: f64) -> (f64, V2) {
        let m: AreaMoment = self.green_walk(rho);
        (m.area, m.first)
    }

    /// Like [`Poly2::disk_intersection`], plus the second moments.
    #[inline]
    pub(crate) fn disk_moments(&self, rho: f64) -> DiskMoments {
        self.green_walk(rho)
    }

    /// Green's theorem along the boundary of polygon ∩ disk: polygon chords inside the circle
    /// give triangles (centre, chord); each run of the polygon outside the circle is replaced
    /// by one counter-clockwise arc from the exit to the next entry point (one `atan2` per
    /// arc). `M` says which integrals are summed.
    #[inline]
    fn green_walk<M: DiskPieces>(&self, rho: f64) -> M {
        let mut acc = M::default();
        if self.n < 3 || rho <= 0.0 {
            return acc;
        }
        let rho2 = rho * rho;
        let mut exit: Option<V2> = None;
        let mut first_entry: Option<V2> = None;
        let mut any_event = false;
        let mut all_inside = true;
        for k in 0..self.n {
            let a = self.v[k];
            let b = self.v[self.next(k)];
            if a[0] * a[0] + a[1] * a[1] > rho2 {
                all_inside = false;
            }
            let d = [b[0] - a[0], b[1] - a[1]];
            let qa = d[0] * d[0] + d[1] * d[1];
            if qa == 0.0 {
                continue;
            }
            let qb = a[0] * d[0] + a[1] * d[1];
            let qc = a[0] * a[0] + a[1] * a[1] - rho2;
            let disc = qb * qb - qa * qc;
            if disc <= 0.0 {
                continue;
            }
            let sq = disc.sqrt();
            let t1 = (-qb - sq) / qa;
            let t2 = (-qb + sq) / qa;
            let (s1, s2) = (t1.max(0.0), t2.min(1.0));
            if s1 > s2 {
                continue;
            }
            let p1 = lerp(a, b, s1);
            let p2 = lerp(a, b, s2);
            if t1 > 0.0 {
                any_event = true;
                match exit.take() {
                    Some(q) => acc.add(M::arc(q, p1, rho)),
                    None => {
                        if first_entry.is_none() {
                            first_entry = Some(p1);
                        }
                    }
                }
            }
            if s2 > s1 {
                acc.add(M::triangle(p1, p2));
            }
            if t2 < 1.0 {
                any_event = true;
                exit = Some(p2);
            }
        }
        if let (Some(q), Some(p)) = (exit, first_entry) {
            acc.add(M::arc(q, p, rho));
        }
        if !any_event && !all_inside {
            // No crossing and a vertex outside: the disk is inside the polygon iff its centre
            // is (counter-clockwise polygon: centre left of every edge), else they are apart.
            let centre_inside = (0..self.n).all(|k| cross(self.v[k], self.v[self.next(k)]) >= 0.0);
            return if centre_inside {
                M::full_disk(rho)
            } else {
                M::default()
            };
        }
        acc
    }
}

#[inline]
fn cross(p: V2, q: V2) -> f64 {
    p[0] * q[1] - p[1] * q[0]
}

#[inline]
fn lerp(p: V2, q: V2, t: f64) -> V2 {
    [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
}

/// Angle swept counter-clockwise from `p` to `q` about the origin, in [0, 2π).
#[inline]
fn sector_angle(p: V2, q: V2) -> f64 {
    let theta = cross(p, q).atan2(p[0] * q[0] + p[1] * q[1]);
    if theta < 0.0 {
        theta + 2.0 * std::f64::consts::PI
    } else {
        theta
    }
}

/// The integrals [`Poly2::green_walk`] sums over its triangles (origin, p, q) and its sectors
/// swept counter-clockwise from `p` to `q` on the circle of radius `rho`.
trait DiskPieces: Default {
    fn triangle(p: V2, q: V2) -> Self;
    fn arc(p: V2, q: V2, rho: f64) -> Self;
    fn full_disk(rho: f64) -> Self;
    fn add(&mut self, o: Self);
}

/// Area (m²) and first moment (m³) about the origin.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct AreaMoment {
    area: f64,
    first: V2,
}

impl AreaMoment {
    /// The sector from `p` to `q` (radius `rho`) whose angle `theta` is already known.
    #[inline]
    fn arc_with_angle(p: V2, q: V2, rho: f64, theta: f64) -> Self {
        // ∫ (cos θ, sin θ) dθ = (Δ sin θ, -Δ cos θ), unit vectors p/ρ and q/ρ.
        let k = rho * rho / 3.0;
        Self {
            area: 0.5 * rho * rho * theta,
            first: [k * (q[1] - p[1]), -k * (q[0] - p[0])],
        }
    }
}

impl DiskPieces for AreaMoment {
    #[inline]
    fn triangle(p: V2, q: V2) -> Self {
        let a = 0.5 * cross(p, q);
        Self {
            area: a,
            first: [a * (p[0] + q[0]) / 3.0, a * (p[1] + q[1]) / 3.0],
        }
    }

    #[inline]
    fn arc(p: V2, q: V2, rho: f64) -> Self {
        Self::arc_with_angle(p, q, rho, sector_angle(p, q))
    }

    #[inline]
    fn full_disk(rho: f64) -> Self {
        Self {
            area: std::f64::consts::PI * (rho * rho),
            first: [0.0; 2],
        }
    }

    #[inline]
    fn add(&mut self, o: Self) {
        self.area += o.area;
        self.first[0] += o.first[0];
        self.first[1] += o.first[1];
    }
}

/// Area (m²), first moment (m³) and second moments `[∫x², ∫xy, ∫y²]` (m⁴), all about the
/// origin, of a convex polygon ∩ the disk of radius `rho` centred at the origin.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct DiskMoments {
    pub area: f64,
    pub first: V2,
    pub second: [f64; 3],
}

impl DiskPieces for DiskMoments {
    #[inline]
    fn triangle(p: V2, q: V2) -> Self {
        let AreaMoment { area: a, first } = AreaMoment::triangle(p, q);
        DiskMoments {
            area: a,
            first,
            second: [
                a / 6.0 * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0]),
                a / 12.0 * (2.0 * p[0] * p[1] + p[0] * q[1] + q[0] * p[1] + 2.0 * q[0] * q[1]),
                a / 6.0 * (p[1] * p[1] + p[1] * q[1] + q[1] * q[1]),
            ],
        }
    }

    /// `∫cos² dθ = θ/2 + sin 2θ/4`, `∫sin cos dθ = sin²θ/2`.
    #[inline]
    fn arc(p: V2, q: V2, rho: f64) -> Self {
        let theta = sector_angle(p, q);
        let AreaMoment { area, first } = AreaMoment::arc_with_angle(p, q, rho, theta);
        let r2 = rho * rho;
        // unit vectors (cos, sin) at both ends
        let (pc, ps) = (p[0] / rho, p[1] / rho);
        let (qc, qs) = (q[0] / rho, q[1] / rho);
        let ds2 = qc * qs - pc * ps; // Δ(sin 2θ)/2
        let r4 = r2 * r2 / 8.0;
        DiskMoments {
            area,
            first,
            second: [
                r4 * (theta + ds2),
                r4 * (qs * qs - ps * ps),
                r4 * (theta - ds2),
            ],
        }
    }

    #[inline]
    fn full_disk(rho: f64) -> Self {
        let rho2 = rho * rho;
        let q = std::f64::consts::PI * rho2 * rho2 / 4.0;
        DiskMoments {
            area: std::f64::consts::PI * rho2,
            first: [0.0; 2],
            second: [q, 0.0, q],
        }
    }

    #[inline]
    fn add(&mut self, o: Self) {
        self.area += o.area;
        self.first[0] += o.first[0];
        self.first[1] += o.first[1];
        self.second[0] += o.second[0];
        self.second[1] += o.second[1];
        self.second[2] += o.second[2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_quadrant_is_the_clipped_square_vertex_for_vertex() {
        for side in [1.0, 0.001016, 3.7e-5] {
            let clipped = Poly2::square(side)
                .clip([-1.0, 0.0], 0.0)
                .clip([0.0, -1.0], 0.0);
            let direct = Poly2::first_quadrant(side);
            assert_eq!(clipped.n, direct.n);
            assert_eq!(clipped.v, direct.v);
        }
    }
    use std::f64::consts::PI;

    #[test]
    fn full_disk_half_disk_and_segment() {
        let sq = Poly2::square(3.0);
        let (a, m) = sq.disk_intersection(1.0);
        assert!((a - PI).abs() < 1e-14 && m[0].abs() < 1e-14 && m[1].abs() < 1e-14);
        // half disk x >= 0: centroid 4/(3π)
        let half = sq.clip([-1.0, 0.0], 0.0);
        let (a, m) = half.disk_intersection(1.0);
        assert!((a - PI / 2.0).abs() < 1e-14);
        assert!((m[0] / a - 4.0 / (3.0 * PI)).abs() < 1e-14);
        // circular segment x >= 0.6 of the unit disk
        let seg = sq.clip([-1.0, 0.0], -0.6);
        let (a, m) = seg.disk_intersection(1.0);
        let exact = (0.6f64).acos() - 0.6 * (1.0f64 - 0.36).sqrt();
        assert!((a - exact).abs() < 1e-14);
        // centroid of a segment: 2 s^3 / (3 A), s = half chord
        let s = (1.0f64 - 0.36).sqrt();
        assert!((m[0] / a - 2.0 * s.powi(3) / (3.0 * exact)).abs() < 1e-12);
        // square fully inside the disk
        let small = Poly2::square(0.5);
        let (a, _) = small.disk_intersection(1.0);
        assert!((a - 1.0).abs() < 1e-14);
    }
}
