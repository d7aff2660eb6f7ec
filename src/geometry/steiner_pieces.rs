//! Overlap of the curved Steiner pieces of a rounded box with a half-space.
//!
//! A rounded box is the inner box `K` (half extents `h = H - r`) plus a ball of radius `r`.
//! Its normal-cone decomposition is disjoint: the inner box, 6 face slabs, 12 edge pieces
//! (edge segment × quarter disk) and 8 vertex pieces (ball octants). The boxes are clipped
//! exactly in [`super::polytope_clip`]; this file handles the edge and vertex pieces.
//!
//! Everything here is in the shape frame, with `u(x) = n·x - c` the height above the plane
//! (the overlap is `u <= 0`).

use super::disk_polygon::Poly2;
use super::halfspace_overlap::{cap_centroid_distance, cap_volume};
use super::quadrature::Breaks;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Running volume (m³) and first moment (m⁴) in the shape frame.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Accum {
    pub volume: f64,
    pub moment: Vector3<f64>,
}

impl Accum {
    #[inline]
    pub(crate) fn add(&mut self, volume: f64, moment: Vector3<f64>) {
        self.volume += volume;
        self.moment += moment;
    }
}

/// Area and first moment of `{ν : ν_x, ν_y >= 0, |ν| <= r, m·ν <= t}` (quarter disk cut by
/// a line), with quick returns for the empty and full cases.
#[inline]
fn quarter_section(r: f64, m: [f64; 2], t: f64, p_min: f64, p_max: f64) -> (f64, [f64; 2]) {
    if t <= p_min {
        return (0.0, [0.0; 2]);
    }
    if t >= p_max {
        let q = r * r * r / 3.0;
        return (PI * r * r / 4.0, [q, q]);
    }
    Poly2::square(2.0 * r)
        .clip([-1.0, 0.0], 0.0)
        .clip([0.0, -1.0], 0.0)
        .clip(m, t)
        .disk_intersection(r)
}

/// Adds the 12 edge pieces. Edge along axis `k` at transverse corner `(σi h_i, σj h_j)`:
/// points `e0 + s e_k + ν`, `s ∈ [-h_k, h_k]`, ν in the quarter disk spanned by `σi e_i`,
/// `σj e_j`. The height is `u0 + n_k s + m·ν` (`m = (σi n_i, σj n_j)`), so the section at `s`
/// is the quarter disk cut by `m·ν <= t(s) = -(u0 + n_k s)`, linear in `s`. The `s`-integral is
/// split where the cutting line passes the disk centre, the two arc ends and a tangency with
/// the arc (the last flagged singular, see [`super::quadrature`]).
pub(crate) fn add_edges(h: &Vector3<f64>, r: f64, n: &Vector3<f64>, c: f64, acc: &mut Accum) {
    if r <= 0.0 {
        return;
    }
    for k in 0..3 {
        let hk = h[k];
        if hk <= 0.0 {
            continue;
        }
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let nk = n[k];
        for (si, sj) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let mut e0 = Vector3::zeros();
            e0[i] = si * h[i];
            e0[j] = sj * h[j];
            let (mut dx, mut dy) = (Vector3::zeros(), Vector3::zeros());
            dx[i] = si;
            dy[j] = sj;
            let m = [si * n[i], sj * n[j]];
            let mu = m[0].hypot(m[1]);
            let below_tangent = m[0] < 0.0 && m[1] < 0.0;
            let above_tangent = m[0] > 0.0 && m[1] > 0.0;
            let p_min = if below_tangent {
                -r * mu
            } else {
                (r * m[0]).min(r * m[1]).min(0.0)
            };
            let p_max = if above_tangent {
                r * mu
            } else {
                (r * m[0]).max(r * m[1]).max(0.0)
            };
            let u0 = n.dot(&e0) - c;
            if u0 - nk.abs() * hk + p_min >= 0.0 {
                continue; // entirely above the plane
            }
            let length = 2.0 * hk;
            if u0 + nk.abs() * hk + p_max <= 0.0 {
                let area = PI * r * r / 4.0;
                let arm = 4.0 * r / (3.0 * PI);
                acc.add(length * area, (e0 + (dx + dy) * arm) * (length * area));
                continue;
            }
            let mut volume = 0.0;
            let mut mom_s = 0.0;
            let mut mom_q = [0.0; 2];
            if nk == 0.0 {
                let (a, mq) = quarter_section(r, m, -u0, p_min, p_max);
                volume = a * length;
                mom_q = [mq[0] * length, mq[1] * length];
            } else {
                let s_of = |t: f64| -(u0 + t) / nk;
                let mut breaks = Breaks::<8>::new((-hk, false), (hk, false));
                breaks.insert(s_of(p_min), below_tangent);
                breaks.insert(s_of(p_max), above_tangent);
                breaks.insert(s_of(0.0), false);
                breaks.insert(s_of(r * m[0]), false);
                breaks.insert(s_of(r * m[1]), false);
                breaks.for_each_node(&mut |s, w| {
                    let (a, mq) = quarter_section(r, m, -(u0 + nk * s), p_min, p_max);
                    volume += w * a;
                    mom_s += w * s * a;
                    mom_q[0] += w * mq[0];
                    mom_q[1] += w * mq[1];
                });
            }
            let mut along = Vector3::zeros();
            along[k] = mom_s;
            acc.add(volume, e0 * volume + along + dx * mom_q[0] + dy * mom_q[1]);
        }
    }
}

/// Adds the 8 vertex pieces (ball octants at the inner-box corners). In octant coordinates
/// (`ν_i >= 0` along `σ_i e_i`) the cut is `m·ν <= τ`, `m_i = σ_i n_i`. The volume is
/// integrated over slices `m·ν = ζ`: a disk of radius `sqrt(r² - ζ²)` cut by the three lines
/// `ν_i = 0`, in closed form; the `ζ`-integral is split where a line is tangent to the slice
/// circle (`ζ = ±r sqrt(1 - m_i²)`, singular), where an octant axis crosses the sphere
/// (`ζ = r m_i`) and at `ζ = 0`.
pub(crate) fn add_vertices(h: &Vector3<f64>, r: f64, n: &Vector3<f64>, c: f64, acc: &mut Accum) {
    if r <= 0.0 {
        return;
    }
    for corner in 0..8 {
        let sigma = Vector3::new(
            if corner & 1 == 0 { 1.0 } else { -1.0 },
            if corner & 2 == 0 { 1.0 } else { -1.0 },
            if corner & 4 == 0 { 1.0 } else { -1.0 },
        );
        let v = h.component_mul(&sigma);
        let m = n.component_mul(&sigma);
        let tau = c - n.dot(&v);
        let neg = Vector3::new(m.x.min(0.0), m.y.min(0.0), m.z.min(0.0));
        let pos = m - neg;
        let p_min = -r * neg.norm();
        let p_max = r * pos.norm();
        if tau <= p_min {
            continue;
        }
        if tau >= p_max {
            let vol = PI * r * r * r / 6.0;
            acc.add(vol, (v + sigma * (3.0 * r / 8.0)) * vol);
            continue;
        }
        // Cap inside the octant (the usual lowest corner): closed form. The cap around -m has
        // half angle α with cos α = -τ/r; it stays in the octant if -m_i >= sin α for all i.
        if tau < 0.0 {
            let sin_alpha = (1.0 - (tau / r) * (tau / r)).max(0.0).sqrt();
            if -m.max() >= sin_alpha {
                let w = r + tau;
                let vol = cap_volume(r, w);
                let centroid = -m * cap_centroid_distance(r, w);
                acc.add(vol, (v + centroid.component_mul(&sigma)) * vol);
                continue;
            }
        }
        // Orthonormal basis (eu, ev) of the slice plane.
        let seed = if m.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let eu = (seed - m * m.dot(&seed)).normalize();
        let ev = m.cross(&eu);
        let mut breaks = Breaks::<16>::new((p_min, true), (tau, false));
        breaks.insert(0.0, false);
        for idx in 0..3 {
            breaks.insert(r * m[idx], false);
            let t = r * (1.0 - m[idx] * m[idx]).max(0.0).sqrt();
            breaks.insert(t, true);
            breaks.insert(-t, true);
        }
        let mut volume = 0.0;
        let mut mom = Vector3::zeros();
        breaks.for_each_node(&mut |zeta, w| {
            let rho2 = r * r - zeta * zeta;
            if rho2 <= 0.0 {
                return;
            }
            let rho = rho2.sqrt();
            let mut poly = Poly2::square(2.0 * rho);
            for idx in 0..3 {
                // ν_i = ζ m_i + a eu_i + b ev_i >= 0
                poly = poly.clip([-eu[idx], -ev[idx]], zeta * m[idx]);
            }
            let (area, m2) = poly.disk_intersection(rho);
            volume += w * area;
            mom += (m * (zeta * area) + eu * m2[0] + ev * m2[1]) * w;
        });
        acc.add(volume, v * volume + mom.component_mul(&sigma));
    }
}
