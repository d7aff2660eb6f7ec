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
use super::quadrature::{gauss3, Breaks};
use super::sphere_cap::{cap_centroid_distance, cap_volume};
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
    Poly2::first_quadrant(2.0 * r)
        .clip(m, t)
        .disk_intersection(r)
}

/// Below this ratio of the height change along an edge (`|n_k| h_k`) to the edge's height scale
/// (`|u0| + r`) the closed form of [`edge_closed_form`] would lose digits to cancellation
/// (measured: at 1e-3 the centroid along the edge drifts by 1e-5 of its half length); such nearly parallel edges keep the quadrature, where
/// the section then varies so little along the edge that few sub-intervals arise.
const CLOSED_FORM_MIN_TILT: f64 = 3e-3;

/// An edge whose section kinks (tangency, arc ends, centre crossing) all lie at least this many
/// half lengths from its midpoint is integrated with 3 Gauss points instead of 6 (see
/// [`gauss3`]): 49 % of the quadrature edges on rattle box C, 90 % on the launcher shoes.
const FAR_KINK_HALF_LENGTHS: f64 = 100.0;

/// Volume (m³), moment along the edge (m⁴, about the edge midpoint) and transverse moment
/// (m⁴, quarter-disk coordinates) of one edge piece below the plane, in closed form.
///
/// Integrating along the edge first: at a quarter-disk point `ν` the submerged part of the
/// edge is `s <= g(ν) = -(u0 + m·ν)/n_k` (for `n_k > 0`; `n_k < 0` is mirrored), of length
/// `clamp(f, 0, 2h_k)` with `f = g + h_k` linear in `ν`. So the volume is `∫ f` over the strip
/// `0 < f < 2h_k` of the quarter disk plus `2h_k` times the area where `f >= 2h_k`, and the
/// moments need the strip's second moments; both regions are a disk ∩ polygon, exact in
/// closed form ([`Poly2::disk_moments`]). This replaces ~50 quadrature sections per tilted edge
/// by two.
fn edge_closed_form(r: f64, m: [f64; 2], u0: f64, nk: f64, hk: f64) -> (f64, f64, [f64; 2]) {
    let an = nk.abs();
    let sgn = if nk < 0.0 { -1.0 } else { 1.0 };
    let quarter = Poly2::first_quadrant(2.0 * r);
    // Strip 0 < f < 2h_k:  m·ν < h_k a_n - u0  and  -m·ν < u0 + h_k a_n.
    let strip = quarter
        .clip(m, hk * an - u0)
        .clip([-m[0], -m[1]], u0 + hk * an)
        .disk_moments(r);
    // Fully submerged edge length (f >= 2h_k):  m·ν <= -u0 - h_k a_n.
    let (full_area, full_first) = quarter.clip(m, -u0 - hk * an).disk_intersection(r);
    let alpha = hk - u0 / an;
    let beta = [-m[0] / an, -m[1] / an];
    let [sxx, sxy, syy] = strip.second;
    let b_first = beta[0] * strip.first[0] + beta[1] * strip.first[1];
    let int_f = alpha * strip.area + b_first;
    let b_s_b = beta[0] * beta[0] * sxx + 2.0 * beta[0] * beta[1] * sxy + beta[1] * beta[1] * syy;
    let int_f2 = alpha * alpha * strip.area + 2.0 * alpha * b_first + b_s_b;
    let volume = int_f + 2.0 * hk * full_area;
    // ∫ s ds over [-h_k, f - h_k] = f²/2 - h_k f; zero over the full length.
    let mom_s = sgn * (0.5 * int_f2 - hk * int_f);
    let mom_q = [
        alpha * strip.first[0] + sxx * beta[0] + sxy * beta[1] + 2.0 * hk * full_first[0],
        alpha * strip.first[1] + sxy * beta[0] + syy * beta[1] + 2.0 * hk * full_first[1],
    ];
    (volume, mom_s, mom_q)
}

/// Adds the 12 edge pieces. Edge along axis `k` at transverse corner `(σi h_i, σj h_j)`:
/// points `e0 + s e_k + ν`, `s ∈ [-h_k, h_k]`, ν in the quarter disk spanned by `σi e_i`,
/// `σj e_j`. The height is `u0 + n_k s + m·ν` (`m = (σi n_i, σj n_j)`), so the section at `s`
/// is the quarter disk cut by `m·ν <= t(s) = -(u0 + n_k s)`, linear in `s`. The `s`-integral is
/// split where the cutting line passes the disk centre, the two arc ends and a tangency with
/// the arc (the last flagged singular, see [`super::quadrature`]).
pub(crate) fn add_edges(h: &Vector3<f64>, r: f64, n: &Vector3<f64>, c: f64, acc: &mut Accum) {
    add_edges_with(h, r, n, c, acc, true, FAR_KINK_HALF_LENGTHS);
}

/// [`add_edges`], optionally without the closed form and with another threshold for the
/// 3-point rule (`f64::INFINITY`: never; the references in tests).
fn add_edges_with(
    h: &Vector3<f64>,
    r: f64,
    n: &Vector3<f64>,
    c: f64,
    acc: &mut Accum,
    closed_form: bool,
    far_kinks: f64,
) {
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
            let mu = (m[0] * m[0] + m[1] * m[1]).sqrt();
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
            if closed_form && nk.abs() * hk >= CLOSED_FORM_MIN_TILT * (u0.abs() + r) {
                let (v, ms, mq) = edge_closed_form(r, m, u0, nk, hk);
                volume = v;
                mom_s = ms;
                mom_q = mq;
            } else if nk == 0.0 {
                let (a, mq) = quarter_section(r, m, -u0, p_min, p_max);
                volume = a * length;
                mom_q = [mq[0] * length, mq[1] * length];
            } else {
                let s_of = |t: f64| -(u0 + t) / nk;
                let kinks = [p_min, p_max, 0.0, r * m[0], r * m[1]].map(s_of);
                let mut node = |s: f64, w: f64| {
                    let (a, mq) = quarter_section(r, m, -(u0 + nk * s), p_min, p_max);
                    volume += w * a;
                    mom_s += w * s * a;
                    mom_q[0] += w * mq[0];
                    mom_q[1] += w * mq[1];
                };
                if kinks.iter().all(|s| s.abs() >= far_kinks * hk) {
                    // The section is analytic far around the edge (nearly parallel edges).
                    gauss3(-hk, hk, &mut node);
                } else {
                    let mut breaks = Breaks::<8>::new((-hk, false), (hk, false));
                    breaks.insert(kinks[0], below_tangent);
                    breaks.insert(kinks[1], above_tangent);
                    for &k in &kinks[2..] {
                        breaks.insert(k, false);
                    }
                    breaks.for_each_node(&mut node);
                }
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
    add_vertices_with(h, r, n, c, acc, true);
}

/// [`add_vertices`], optionally without the closed form (the quadrature reference in tests).
fn add_vertices_with(
    h: &Vector3<f64>,
    r: f64,
    n: &Vector3<f64>,
    c: f64,
    acc: &mut Accum,
    closed_form: bool,
) {
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
        if closed_form {
            if let Some((vol, mom)) = octant_closed_form(r, &m, tau) {
                acc.add(vol, v * vol + mom.component_mul(&sigma));
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

/// Area (m²) and first moment (m³, octant coordinates) of the flat face `m·ν = τ` of the
/// octant piece: the slice disk of radius `sqrt(r² - τ²)` cut by the three lines `ν_i >= 0`.
#[inline]
fn octant_slice(r: f64, m: &Vector3<f64>, zeta: f64) -> (f64, Vector3<f64>) {
    let rho2 = r * r - zeta * zeta;
    if rho2 <= 0.0 {
        return (0.0, Vector3::zeros());
    }
    let rho = rho2.sqrt();
    let seed = if m.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let eu = (seed - m * m.dot(&seed)).normalize();
    let ev = m.cross(&eu);
    let mut poly = Poly2::square(2.0 * rho);
    for idx in 0..3 {
        poly = poly.clip([-eu[idx], -ev[idx]], zeta * m[idx]);
    }
    let (area, m2) = poly.disk_intersection(rho);
    (area, m * (zeta * area) + eu * m2[0] + ev * m2[1])
}

/// Volume (m³) and first moment (m⁴, octant coordinates about the ball centre) of the octant
/// piece `{ν >= 0, |ν| <= r, m·ν <= τ}` in closed form, for a cap smaller than a hemisphere
/// (`τ < 0`) whose circle crosses the octant's boundary; `None` otherwise (quadrature).
///
/// Divergence theorem with fields `x` and `x (a·x)`: the octant planes pass through the centre
/// and contribute nothing, so `V = (r S + τ A)/3` and `∫x dV = (r ∫_S x dA + τ ∫_A x dA)/4`,
/// with `A` the flat cut face ([`octant_slice`]) and `S` the spherical patch = octant triangle
/// ∩ cap on the sphere. `S` is walked like the disk ∩ polygon of [`Poly2::disk_intersection`]:
/// octant great-circle arcs inside the cap give spherical triangles fanned from the cap pole
/// (signed, Van Oosterom–Strackee), runs outside are replaced by cap-circle arcs (sector area
/// `(1 - cos α) Δφ`). The patch's vector area `∫ x dA` (unit sphere) is `½ ∮ x × dx`.
fn octant_closed_form(r: f64, m: &Vector3<f64>, tau: f64) -> Option<(f64, Vector3<f64>)> {
    if tau >= 0.0 || tau.is_nan() {
        return None;
    }
    let kappa = tau / r; // cap on the unit sphere: m·x <= κ, κ ∈ (-1, 0)
    let pole = -m;
    let cos_a = -kappa;
    let one_minus_cos = (r + tau) / r;
    let sin2_a = one_minus_cos * (1.0 + cos_a);
    let mut area = 0.0;
    let mut vec_area = Vector3::zeros();
    let mut exit: Option<Vector3<f64>> = None;
    let mut first_entry: Option<Vector3<f64>> = None;
    let mut any_event = false;
    let small_arc = |q: Vector3<f64>, p: Vector3<f64>, area: &mut f64, va: &mut Vector3<f64>| {
        let u = q - pole * pole.dot(&q);
        let w = p - pole * pole.dot(&p);
        let mut dphi = pole.dot(&u.cross(&w)).atan2(u.dot(&w));
        if dphi < 0.0 {
            dphi += 2.0 * PI;
        }
        *area += one_minus_cos * dphi;
        *va += (pole.cross(&(p - q)) * cos_a + pole * (sin2_a * dphi)) * 0.5;
    };
    for k in 0..3 {
        let k1 = (k + 1) % 3;
        let (ma, mb) = (m[k], m[k1]);
        let rr = (ma * ma + mb * mb).sqrt();
        // On the arc x(φ) = e_k cos φ + e_k1 sin φ: m·x = R cos(φ - φ0) <= κ.
        if rr <= -kappa {
            continue;
        }
        let phi0 = mb.atan2(ma);
        let halfw = PI - (kappa / rr).clamp(-1.0, 1.0).acos();
        let mut centre = phi0 + PI;
        if centre - PI / 4.0 >= PI {
            centre -= 2.0 * PI;
        } else if centre - PI / 4.0 < -PI {
            centre += 2.0 * PI;
        }
        let (lo, hi) = (centre - halfw, centre + halfw);
        let (lo_c, hi_c) = (lo.max(0.0), hi.min(PI / 2.0));
        if lo_c >= hi_c {
            continue;
        }
        let mut ea = Vector3::zeros();
        ea[k] = 1.0;
        let mut eb = Vector3::zeros();
        eb[k1] = 1.0;
        let p1 = ea * lo_c.cos() + eb * lo_c.sin();
        let p2 = ea * hi_c.cos() + eb * hi_c.sin();
        if lo > 0.0 {
            any_event = true;
            match exit.take() {
                Some(q) => small_arc(q, p1, &mut area, &mut vec_area),
                None => {
                    if first_entry.is_none() {
                        first_entry = Some(p1);
                    }
                }
            }
        }
        // Great-circle piece p1 -> p2: fan triangle from the pole; ∮ x × dx = e_k × e_k1 Δφ.
        let triple = pole.dot(&p1.cross(&p2));
        let denom = 1.0 + pole.dot(&p1) + p1.dot(&p2) + p2.dot(&pole);
        area += 2.0 * triple.atan2(denom);
        let mut normal = Vector3::zeros();
        normal[(k + 2) % 3] = 1.0;
        vec_area += normal * (0.5 * (hi_c - lo_c));
        if hi < PI / 2.0 {
            any_event = true;
            exit = Some(p2);
        }
    }
    if !any_event {
        return None;
    }
    if let (Some(q), Some(p)) = (exit, first_entry) {
        small_arc(q, p, &mut area, &mut vec_area);
    }
    let (a_cut, m_cut) = octant_slice(r, m, tau);
    let volume = (r * r * r * area + tau * a_cut) / 3.0;
    let moment = (vec_area * r.powi(4) + m_cut * tau) / 4.0;
    Some((volume, moment))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Independent fine reference: midpoint rule with `nodes` per half sub-interval, every
    /// sub-interval between sorted `kinks` (inside `[lo, hi]`) split in two halves clustered
    /// towards its ends by `x = end ± L y²` (the integrands behave like `δ^{3/2}` there).
    fn fine(lo: f64, hi: f64, kinks: &[f64], nodes: usize, visit: &mut impl FnMut(f64, f64)) {
        let mut pts = vec![lo, hi];
        pts.extend(kinks.iter().copied().filter(|k| *k > lo && *k < hi));
        pts.sort_by(f64::total_cmp);
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let half = 0.5 * (b - a);
            for (end, dir) in [(a, 1.0), (b, -1.0)] {
                for q in 0..nodes {
                    let y = (q as f64 + 0.5) / nodes as f64;
                    visit(end + dir * half * y * y, 2.0 * half * y / nodes as f64);
                }
            }
        }
    }

    /// Edge piece: closed form vs fine slicing along the edge.
    fn edge_reference(r: f64, m: [f64; 2], u0: f64, nk: f64, hk: f64) -> (f64, f64, [f64; 2]) {
        let s_of = |t: f64| -(u0 + t) / nk;
        let mu = m[0].hypot(m[1]);
        let kinks = [
            s_of(-r * mu),
            s_of(r * mu),
            s_of(0.0),
            s_of(r * m[0]),
            s_of(r * m[1]),
        ];
        let (mut v, mut ms, mut mq) = (0.0, 0.0, [0.0; 2]);
        fine(-hk, hk, &kinks, 4000, &mut |s, w| {
            let (a, q) = quarter_section(r, m, -(u0 + nk * s), -1.0, 1.0);
            v += w * a;
            ms += w * s * a;
            mq[0] += w * q[0];
            mq[1] += w * q[1];
        });
        (v, ms, mq)
    }

    /// Octant piece: closed form vs fine slicing `m·ν = ζ`.
    fn octant_reference(r: f64, m: &Vector3<f64>, tau: f64) -> (f64, Vector3<f64>) {
        let mut kinks = vec![0.0];
        for i in 0..3 {
            kinks.push(r * m[i]);
            let t = r * (1.0 - m[i] * m[i]).max(0.0).sqrt();
            kinks.extend([t, -t]);
        }
        let (mut v, mut mom) = (0.0, Vector3::zeros());
        fine(-r, tau, &kinks, 4000, &mut |z, w| {
            let (a, mm) = octant_slice(r, m, z);
            v += w * a;
            mom += mm * w;
        });
        (v, mom)
    }

    /// The closed forms against the fine references, piece by piece, over random orientations
    /// (half of them nearly face-down, the common rattle-box contact) and depths w/r in
    /// [1e-3, 2] of the thesis cube: volume to 1e-7; centroid to 1e-7 r (vertices), along an
    /// edge to 2e-6 of its half length (< 3e-8 m; an edge dipping < 1e-7 m at one end, a piece
    /// of < 1e-18 m³, loses digits to the strip moments' cancellation) and across it to 5e-5 of the submerged
    /// width. Forces act at the whole patch's centroid, so these are far below what matters.
    #[test]
    fn closed_forms_match_fine_slicing() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let r = 0.000508;
        let h = Vector3::repeat(0.0127 - r);
        let mut checked = [0usize; 2];
        for case in 0..300 {
            let n = if case % 2 == 0 {
                Vector3::new(
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                )
                .normalize()
            } else {
                let t = 10f64.powf(rng.gen_range(-4.0..-0.5));
                Vector3::new(
                    t * rng.gen_range(-1.0..1.0),
                    -1.0,
                    t * rng.gen_range(-1.0..1.0),
                )
                .normalize()
            };
            let support = n.x.abs() * h.x + n.y.abs() * h.y + n.z.abs() * h.z + r;
            let w = r * 10f64.powf(rng.gen_range(-3.0..0.3));
            let c = w - support;
            // edges
            for k in 0..3 {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let nk = n[k];
                for (si, sj) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                    let mut e0 = Vector3::zeros();
                    e0[i] = si * h[i];
                    e0[j] = sj * h[j];
                    let m = [si * n[i], sj * n[j]];
                    let u0 = n.dot(&e0) - c;
                    if nk.abs() * h[k] < CLOSED_FORM_MIN_TILT * (u0.abs() + r) {
                        continue;
                    }
                    let (v_ref, s_ref, q_ref) = edge_reference(r, m, u0, nk, h[k]);
                    if v_ref <= 0.0 || v_ref >= 0.999 * PI * r * r / 4.0 * 2.0 * h[k] {
                        continue;
                    }
                    let (v, ms, mq) = edge_closed_form(r, m, u0, nk, h[k]);
                    assert!(
                        (v - v_ref).abs() < 1e-7 * v_ref,
                        "edge {n:?} {w}: {v:e} vs {v_ref:e}"
                    );
                    assert!(
                        (ms / v - s_ref / v_ref).abs() < 2e-6 * h[k],
                        "edge {n:?} {w}: s {} vs {}",
                        ms / v,
                        s_ref / v_ref
                    );
                    // across the edge: the submerged section is as wide as sqrt(2 r w); at
                    // w/r ~ 1e-4 the strip moments cancel to ~1e-5 of that width (1e-10 m)
                    let width = (2.0 * r * w).sqrt().min(r);
                    for q in 0..2 {
                        assert!(
                            (mq[q] / v - q_ref[q] / v_ref).abs() < 5e-5 * width,
                            "edge {n:?} {w}: q {} vs {}",
                            mq[q] / v,
                            q_ref[q] / v_ref
                        );
                    }
                    checked[0] += 1;
                }
            }
            // vertices
            for corner in 0..8 {
                let sigma = Vector3::new(
                    if corner & 1 == 0 { 1.0 } else { -1.0 },
                    if corner & 2 == 0 { 1.0 } else { -1.0 },
                    if corner & 4 == 0 { 1.0 } else { -1.0 },
                );
                let m = n.component_mul(&sigma);
                let tau = c - n.dot(&h.component_mul(&sigma));
                let Some((v, mom)) = octant_closed_form(r, &m, tau) else {
                    continue;
                };
                let (v_ref, m_ref) = octant_reference(r, &m, tau);
                if v_ref <= 0.0 {
                    continue;
                }
                assert!(
                    (v - v_ref).abs() < 1e-7 * v_ref,
                    "vertex {m:?} {tau}: {v:e} vs {v_ref:e}"
                );
                assert!(
                    (mom / v - m_ref / v_ref).norm() < 1e-7 * r,
                    "vertex {m:?} {tau}: centroid"
                );
                checked[1] += 1;
            }
        }
        assert!(checked[0] > 100 && checked[1] > 100, "{checked:?}");
    }
    /// Octant piece against a fine, independent slicing (200 000 slices `m·ν = ζ`, midpoint
    /// rule in `ζ = p_min + L y²`): the divergence-theorem closed form to 1e-9.
    /// Nearly parallel edges (tilt 1e-8 to 1e-3 rad from face-down, depth w/r 1e-4 to 1) with
    /// the 3-point rule where every kink is >= 100 half lengths away, against the 6-point rule
    /// with kink splitting everywhere: volume to 1e-12, centroid to 1e-12 of the half length.
    #[test]
    fn three_point_rule_on_nearly_parallel_edges_matches_the_six_point_rule() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let r = 0.000508;
        let h = Vector3::repeat(0.0127 - r);
        let mut differing = 0;
        for _ in 0..400 {
            let t = 10f64.powf(rng.gen_range(-8.0..-3.0));
            let n = Vector3::new(
                t * rng.gen_range(-1.0..1.0),
                -1.0,
                t * rng.gen_range(-1.0..1.0),
            )
            .normalize();
            let support = n.x.abs() * h.x + n.y.abs() * h.y + n.z.abs() * h.z + r;
            let w = r * 10f64.powf(rng.gen_range(-4.0..0.0));
            let c = w - support;
            let (mut fast, mut reference) = (Accum::default(), Accum::default());
            add_edges_with(&h, r, &n, c, &mut fast, true, FAR_KINK_HALF_LENGTHS);
            add_edges_with(&h, r, &n, c, &mut reference, true, f64::INFINITY);
            assert!(reference.volume > 0.0);
            assert!(
                (fast.volume - reference.volume).abs() <= 1e-12 * reference.volume,
                "{n:?} {w}: {:e} vs {:e}",
                fast.volume,
                reference.volume
            );
            let d = fast.moment / fast.volume - reference.moment / reference.volume;
            assert!(d.norm() <= 1e-12 * h.x, "{n:?} {w}: centroid moved {d:?}");
            if fast.volume != reference.volume {
                differing += 1;
            }
        }
        // The 3-point path was taken (results differ in the last bits) in many cases.
        assert!(differing > 100, "{differing}");
    }

    #[test]
    fn octant_closed_form_matches_fine_slicing() {
        let r = 0.000508;
        let cases = [
            (Vector3::new(-0.000285, -1.0, -0.000846), 0.45),
            (Vector3::new(-0.2, -1.0, 0.05), 0.3),
            (Vector3::new(-0.6, -0.7, -0.1), 0.2),
            (Vector3::new(-1.0, 0.0, 0.0), 0.05),
            (Vector3::new(-0.000196, -1.0, -0.0000593), 0.018),
            (Vector3::new(0.000196, -1.0, 0.0000593), 0.018),
        ];
        let mut checked = 0;
        for (n, frac) in cases {
            let m: Vector3<f64> = n.normalize();
            let neg = Vector3::new(m.x.min(0.0), m.y.min(0.0), m.z.min(0.0));
            let p_min = -r * neg.norm();
            let tau = p_min + frac * r;
            let Some((vol, mom)) = octant_closed_form(r, &m, tau) else {
                continue;
            };
            let nodes = 200_000;
            let (mut v_ref, mut m_ref) = (0.0, Vector3::zeros());
            let l = tau - p_min;
            for i in 0..nodes {
                let y = (i as f64 + 0.5) / nodes as f64;
                let wgt = 2.0 * l * y / nodes as f64;
                let (a, mm) = octant_slice(r, &m, p_min + l * y * y);
                v_ref += wgt * a;
                m_ref += mm * wgt;
            }
            assert!(
                (vol - v_ref).abs() < 1e-9 * v_ref,
                "{m:?}: {vol:e} vs {v_ref:e}"
            );
            assert!(
                (mom - m_ref).norm() < 1e-9 * m_ref.norm(),
                "{m:?}: {mom:?} vs {m_ref:?}"
            );
            checked += 1;
        }
        assert_eq!(checked, 6);
    }
}
