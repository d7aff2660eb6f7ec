//! Closed-form monomial moments `∫_P (u − u₀)^a (v − v₀)^b dA` of a polygon `P` in a face's
//! material coordinates, `a + b <= 3` (docs/reference/models.md "Exact face contact", "Closed-form
//! parts"): every density of the IMPACT law with `e = 2` on a part of a pressed face where
//! `w` and `ẇ` are affine (the stored energy `k w³/3`, the clamp's dissipation `k w² ẇ`, the
//! force `k w² + c ẇ` and its first moments) is a polynomial of degree at most 3 in `ξ`, so
//! its integral is a fixed combination of these ten numbers.
//!
//! Derivation (divergence theorem as a fan of signed triangles): `P` is the signed sum of the
//! triangles `(ξ₀, p_i, p_{i+1})` over its edges. On the triangle with apex at the origin
//! `x = s p + t q`, `(s, t)` on the unit simplex, `dA = (p × q) ds dt`, and
//! `∫ s^i t^j ds dt = i! j! / (i + j + 2)!`, so
//! `∫ u^a v^b = (p × q) Σ_{i<=a, j<=b} C(a,i) C(b,j) p_u^i q_u^(a−i) p_v^j q_v^(b−j)
//! (i+j)! (a+b−i−j)! / (a+b+2)!`. No division by an edge's length or a gradient: exact to
//! round-off for every polygon, however thin. Moments are taken about the first vertex (a
//! thin ramp far from `ξ = 0` keeps its digits).

/// The moments of one polygon about its reference point `origin` (the first vertex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolygonMoments {
    /// The reference point `ξ₀`.
    pub origin: [f64; 2],
    /// `m[a][b] = ∫ (u − u₀)^a (v − v₀)^b dA` for `a + b <= 3` (zero elsewhere), in `ξ` units.
    pub m: [[f64; 4]; 4],
}

/// `(i + j)! (n − i − j)! / (n + 2)!` for `n = a + b <= 3`, indexed `[n][i + j]`.
const SIMPLEX: [[f64; 4]; 4] = [
    [1.0 / 2.0, 0.0, 0.0, 0.0],
    [1.0 / 6.0, 1.0 / 6.0, 0.0, 0.0],
    [2.0 / 24.0, 1.0 / 24.0, 2.0 / 24.0, 0.0],
    [6.0 / 120.0, 2.0 / 120.0, 2.0 / 120.0, 6.0 / 120.0],
];
/// Binomial coefficients `C(n, k)`, `n <= 3`.
const BINOMIAL: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 2.0, 1.0, 0.0],
    [1.0, 3.0, 3.0, 1.0],
];

impl PolygonMoments {
    /// The moments of the polygon with vertices `verts` (in order, either orientation: the
    /// moments of a clockwise polygon are returned with the counter-clockwise sign, so the
    /// area `m[0][0]` is positive). Empty polygons give zeros.
    pub fn of(verts: &[[f64; 2]]) -> Self {
        let mut m = [[0.0; 4]; 4];
        let origin = verts.first().copied().unwrap_or([0.0; 2]);
        if verts.len() < 3 {
            return Self { origin, m };
        }
        for k in 1..verts.len() - 1 {
            let p = [verts[k][0] - origin[0], verts[k][1] - origin[1]];
            let q = [verts[k + 1][0] - origin[0], verts[k + 1][1] - origin[1]];
            let jac = p[0] * q[1] - p[1] * q[0];
            // Powers p^i, q^i of each coordinate, i <= 3.
            let pow = |x: f64| [1.0, x, x * x, x * x * x];
            let (pu, pv, qu, qv) = (pow(p[0]), pow(p[1]), pow(q[0]), pow(q[1]));
            for a in 0..4 {
                for b in 0..4 - a {
                    let n = a + b;
                    let mut sum = 0.0;
                    for i in 0..=a {
                        for j in 0..=b {
                            sum += BINOMIAL[a][i]
                                * BINOMIAL[b][j]
                                * pu[i]
                                * qu[a - i]
                                * pv[j]
                                * qv[b - j]
                                * SIMPLEX[n][i + j];
                        }
                    }
                    m[a][b] += jac * sum;
                }
            }
        }
        if m[0][0] < 0.0 {
            for row in &mut m {
                for x in row.iter_mut() {
                    *x = -*x;
                }
            }
        }
        Self { origin, m }
    }

    /// The area.
    pub fn area(&self) -> f64 {
        self.m[0][0]
    }

    /// `∫ Π_k L_k dA` for up to three affine functions `L_k(ξ) = c_k + g_k · (ξ − ξ₀)` given
    /// as `(c_k, g_k)` about [`PolygonMoments::origin`]: the product expanded into monomials.
    pub fn product(&self, factors: &[(f64, [f64; 2])]) -> f64 {
        // Coefficients of the product polynomial in (du, dv), degree <= 3.
        let mut poly = [[0.0; 4]; 4];
        poly[0][0] = 1.0;
        let mut degree = 0;
        for &(c, g) in factors.iter().take(3) {
            let mut next = [[0.0; 4]; 4];
            for a in 0..=degree {
                for b in 0..=degree - a {
                    let x = poly[a][b];
                    if x == 0.0 {
                        continue;
                    }
                    next[a][b] += x * c;
                    next[a + 1][b] += x * g[0];
                    next[a][b + 1] += x * g[1];
                }
            }
            poly = next;
            degree += 1;
        }
        let mut sum = 0.0;
        for a in 0..=degree {
            for b in 0..=degree - a {
                sum += poly[a][b] * self.m[a][b];
            }
        }
        sum
    }
}

/// Gauss–Legendre 5-point rule on [-1, 1] (the phase integrals' short slices).
const GL5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// A slice's phase span `|β| Δu` below which its phase integrals take [`GL5`] instead of the
/// antiderivative: there the antiderivative's terms `R^(m) / β^(m+1)` cancel (at 0.3 they
/// lose at most `4!/0.3^5`, about 1e4 roundings, of the slice's integral), and the rule's
/// error on `e^{iβu} R(u)`, `R` of degree <= 4, is about 1e-11 of it (Gauss–Legendre's
/// remainder `Δ^11 (5!)^4 / (11 (10!)^3) |f^(10)|`, whose leading term here scales as
/// `(β Δ)^6`; tested against the antiderivative at the threshold).
const PHASE_SPAN_MIN: f64 = 0.3;

/// A polynomial in `t` of degree <= 4, coefficients from `t^0`.
type Poly = [f64; 5];

fn poly_mul_linear(p: &Poly, c0: f64, c1: f64) -> Poly {
    let mut out = [0.0; 5];
    for k in 0..5 {
        out[k] += p[k] * c0;
        if k + 1 < 5 {
            out[k + 1] += p[k] * c1;
        }
    }
    out
}

/// One slice's phase `θ₀ + β t`, `t ∈ [0, Δ]`, with its sines and cosines taken once for all
/// the slice's integrals ([`phase_integral`]).
enum SlicePhase {
    /// [`GL5`]'s nodes `t`, weights (times `Δ/2`) and `(cos θ, sin θ)` there.
    Gauss([(f64, f64, f64, f64); 5]),
    /// The antiderivative's ends: `Δ`, `1/β` and `(cos θ, sin θ)` at `t = 0` and `t = Δ`.
    Exact {
        delta: f64,
        inv_beta: f64,
        start: (f64, f64),
        end: (f64, f64),
    },
}

impl SlicePhase {
    /// The phase `θ₀ + β t` on `[0, Δ]`: [`GL5`] when the span `|β| Δ` is below
    /// [`PHASE_SPAN_MIN`], else the antiderivative.
    fn new(theta0: f64, beta: f64, delta: f64) -> Self {
        if (beta * delta).abs() < PHASE_SPAN_MIN {
            let mut nodes = [(0.0, 0.0, 0.0, 0.0); 5];
            for (node, (x, w)) in nodes.iter_mut().zip(GL5) {
                let t = 0.5 * delta * (1.0 + x);
                let (sin, cos) = (theta0 + beta * t).sin_cos();
                *node = (t, 0.5 * delta * w, cos, sin);
            }
            SlicePhase::Gauss(nodes)
        } else {
            let (s0, c0) = theta0.sin_cos();
            let (s1, c1) = (theta0 + beta * delta).sin_cos();
            SlicePhase::Exact {
                delta,
                inv_beta: 1.0 / beta,
                start: (c0, s0),
                end: (c1, s1),
            }
        }
    }
}

/// `∫_0^Δ e^{iθ(t)} R(t) dt` as (cosine part, sine part) on a slice's phase: the
/// antiderivative `e^{iθ} Σ_m (−1)^m R^(m)(t) / (iβ)^(m+1)` (repeated integration by parts,
/// exact), or [`GL5`] on a short span ([`SlicePhase::new`]).
fn phase_integral(phase: &SlicePhase, r: &Poly) -> (f64, f64) {
    let eval = |p: &Poly, t: f64| p.iter().rev().fold(0.0, |acc, c| acc * t + c);
    match phase {
        SlicePhase::Gauss(nodes) => {
            let (mut c, mut s) = (0.0, 0.0);
            for &(t, w, cos, sin) in nodes {
                let f = eval(r, t) * w;
                c += f * cos;
                s += f * sin;
            }
            (c, s)
        }
        SlicePhase::Exact {
            delta,
            inv_beta,
            start,
            end,
        } => {
            // Σ_m (−1)^m (−i)^(m+1) R^(m)(t) / β^(m+1) at both ends; (−1)^m (−i)^(m+1) =
            // −i^(m+1): −i, 1, i, −1, then again.
            let (mut re0, mut im0, mut re1, mut im1) = (0.0, 0.0, 0.0, 0.0);
            let mut deriv = *r;
            let mut scale = *inv_beta;
            for m in 0..5 {
                let (v0, v1) = (deriv[0], eval(&deriv, *delta));
                match m % 4 {
                    0 => {
                        im0 -= v0 * scale;
                        im1 -= v1 * scale;
                    }
                    1 => {
                        re0 += v0 * scale;
                        re1 += v1 * scale;
                    }
                    2 => {
                        im0 += v0 * scale;
                        im1 += v1 * scale;
                    }
                    _ => {
                        re0 -= v0 * scale;
                        re1 -= v1 * scale;
                    }
                }
                scale *= inv_beta;
                for k in 0..4 {
                    deriv[k] = deriv[k + 1] * (k + 1) as f64;
                }
                deriv[4] = 0.0;
            }
            // e^{iθ} (re + i im) at each end.
            let ((c0, s0), (c1, s1)) = (start, end);
            (
                (c1 * re1 - s1 * im1) - (c0 * re0 - s0 * im0),
                (s1 * re1 + c1 * im1) - (s0 * re0 + c0 * im0),
            )
        }
    }
}

impl PolygonMoments {
    /// The moments of the polygon `verts` (as [`PolygonMoments::of`]: about its first vertex,
    /// either orientation) weighted by `cos θ(u)` and by `sin θ(u)`, `θ(u) = θ₀ + β u` a phase
    /// linear in `u` alone: `∫ cos θ (u − u₀)^a (v − v₀)^b dA` and the same with the sine,
    /// `a + b <= 3`. The cycloidal STEP's sine of the IMPACT damping ramp, `w` turned to depend
    /// on `u` alone ([`crate::geometry::FacePatch::aligned_with`]).
    ///
    /// Derivation: the polygon is sliced at its vertices' `u`; on a slice its lower and upper
    /// boundaries `lo(u)`, `hi(u)` are straight, so `∫_lo^hi (v − v₀)^b dv` is a polynomial of
    /// degree `b + 1` in `u` and the slice's integrand is `e^{iθ(u)}` times a polynomial of
    /// degree <= 4, whose antiderivative is elementary (repeated integration by parts; a
    /// slice whose phase span is below `PHASE_SPAN_MIN` takes a 5-point Gauss rule, within
    /// about 1e-11 of it).
    pub fn of_phase(verts: &[[f64; 2]], theta0: f64, beta: f64) -> (Self, Self) {
        let origin = verts.first().copied().unwrap_or([0.0; 2]);
        let mut cos_m = [[0.0; 4]; 4];
        let mut sin_m = [[0.0; 4]; 4];
        let len = verts.len();
        if len >= 3 {
            let mut us = [0.0; 16];
            let n = len.min(16);
            for (u, p) in us.iter_mut().zip(&verts[..n]) {
                *u = p[0];
            }
            let us = &mut us[..n];
            us.sort_unstable_by(f64::total_cmp);
            for k in 1..n {
                let (ua, ub) = (us[k - 1], us[k]);
                if ub <= ua {
                    continue;
                }
                let Some((lo, hi)) = chains(verts, 0.5 * (ua + ub)) else {
                    continue;
                };
                // lo, hi as (value at ua, slope), relative to v₀; `t = u − ua`.
                let mid = 0.5 * (ua + ub);
                let lo = (lo.0 - lo.1 * (mid - ua) - origin[1], lo.1);
                let hi = (hi.0 - hi.1 * (mid - ua) - origin[1], hi.1);
                let delta = ub - ua;
                let phase = SlicePhase::new(theta0 + beta * ua, beta, delta);
                // ∫_lo^hi (v − v₀)^b dv = (hi − lo) Σ_j hi^j lo^(b−j) / (b + 1): no cancellation
                // on a thin slice.
                let width: Poly = [hi.0 - lo.0, hi.1 - lo.1, 0.0, 0.0, 0.0];
                let mut hi_pow = [[0.0; 5]; 4];
                let mut lo_pow = [[0.0; 5]; 4];
                hi_pow[0][0] = 1.0;
                lo_pow[0][0] = 1.0;
                for j in 1..4 {
                    hi_pow[j] = poly_mul_linear(&hi_pow[j - 1], hi.0, hi.1);
                    lo_pow[j] = poly_mul_linear(&lo_pow[j - 1], lo.0, lo.1);
                }
                for b in 0..4 {
                    let mut sum = [0.0; 5];
                    for j in 0..=b {
                        // hi^j lo^(b−j), degree b <= 3.
                        for x in 0..=j {
                            for y in 0..=(b - j) {
                                sum[x + y] += hi_pow[j][x] * lo_pow[b - j][y];
                            }
                        }
                    }
                    let mut column = [0.0; 5];
                    for (x, c) in sum.iter().enumerate().take(4) {
                        column[x] += c * width[0];
                        column[x + 1] += c * width[1];
                    }
                    let inv = 1.0 / (b + 1) as f64;
                    for c in &mut column {
                        *c *= inv;
                    }
                    // Times (u − u₀)^a = (ua − u₀ + t)^a.
                    let mut r = column;
                    for a in 0..4 - b {
                        if a > 0 {
                            r = poly_mul_linear(&r, ua - origin[0], 1.0);
                        }
                        let (c, s) = phase_integral(&phase, &r);
                        cos_m[a][b] += c;
                        sin_m[a][b] += s;
                    }
                }
            }
        }
        (Self { origin, m: cos_m }, Self { origin, m: sin_m })
    }
}

/// The lower and upper boundary of the convex polygon `verts` over the slice through `u`
/// (strictly between two vertices' `u`): each as (value at `u`, slope dv/du).
fn chains(verts: &[[f64; 2]], u: f64) -> Option<((f64, f64), (f64, f64))> {
    let mut lower: Option<(f64, f64)> = None;
    let mut upper: Option<(f64, f64)> = None;
    let len = verts.len();
    for i in 0..len {
        let p = verts[i];
        let q = verts[(i + 1) % len];
        if (p[0] - u) * (q[0] - u) >= 0.0 {
            continue;
        }
        let slope = (q[1] - p[1]) / (q[0] - p[0]);
        let v = p[1] + slope * (u - p[0]);
        if lower.is_none_or(|l| v < l.0) {
            lower = Some((v, slope));
        }
        if upper.is_none_or(|h| v > h.0) {
            upper = Some((v, slope));
        }
    }
    Some((lower?, upper?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_square_has_the_textbook_moments() {
        // Square [0, 1]²: ∫ u^a v^b = 1/((a+1)(b+1)).
        let m = PolygonMoments::of(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        for a in 0..4 {
            for b in 0..4 - a {
                let exact = 1.0 / ((a + 1) as f64 * (b + 1) as f64);
                assert!((m.m[a][b] - exact).abs() < 1e-15, "{a} {b}: {}", m.m[a][b]);
            }
        }
    }

    #[test]
    fn a_right_triangle_has_the_textbook_moments_in_either_orientation() {
        // Triangle (0,0), (1,0), (0,1): ∫ u^a v^b = a! b! / (a+b+2)!.
        let fact = |n: usize| (1..=n).product::<usize>() as f64;
        for verts in [
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
        ] {
            let m = PolygonMoments::of(&verts);
            for a in 0..4 {
                for b in 0..4 - a {
                    let exact = fact(a) * fact(b) / fact(a + b + 2);
                    assert!((m.m[a][b] - exact).abs() < 1e-15, "{a} {b}: {}", m.m[a][b]);
                }
            }
        }
    }

    /// `∫_P f dA` by composite Simpson in `u` over each slice between vertices (`panels`
    /// panels each) and in `v` on the exact column: an independent reference.
    fn simpson(verts: &[[f64; 2]], f: &dyn Fn(f64, f64) -> f64, panels: usize) -> f64 {
        let mut us: Vec<f64> = verts.iter().map(|p| p[0]).collect();
        us.sort_by(f64::total_cmp);
        let mut total = 0.0;
        for k in 1..us.len() {
            let (ua, ub) = (us[k - 1], us[k]);
            if ub <= ua {
                continue;
            }
            let Some((lo, hi)) = chains(verts, 0.5 * (ua + ub)) else {
                continue;
            };
            let mid = 0.5 * (ua + ub);
            let column = |u: f64| {
                let (l, h) = (lo.0 + lo.1 * (u - mid), hi.0 + hi.1 * (u - mid));
                let n = 16;
                let dv = (h - l) / n as f64;
                let mut s = f(u, l) + f(u, h);
                for i in 1..n {
                    s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(u, l + i as f64 * dv);
                }
                s * dv / 3.0
            };
            let du = (ub - ua) / panels as f64;
            let mut s = column(ua) + column(ub);
            for i in 1..panels {
                s += if i % 2 == 1 { 4.0 } else { 2.0 } * column(ua + i as f64 * du);
            }
            total += s * du / 3.0;
        }
        total
    }

    #[test]
    fn the_phase_moments_equal_a_fine_quadrature_and_reduce_to_the_plain_ones() {
        // Random convex polygons (a square clipped by random lines, as a pressed face's parts
        // are) and phases from a fraction of a turn to several turns across them: every
        // moment within 1e-9 of the polygon's area times its extent's power (Simpson's error
        // at 2000 panels per slice is far below that for these smooth integrands); at β = 0,
        // θ₀ = 0 the cosine moments are the plain moments to round-off.
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rand = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for trial in 0..16 {
            let mut verts = vec![[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
            for _ in 0..2 {
                let angle = std::f64::consts::TAU * rand();
                let (gu, gv) = (angle.cos(), angle.sin());
                let c = 0.8 * rand() - 0.2;
                // Keep g·ξ + c >= 0 (Sutherland–Hodgman).
                let mut out = Vec::new();
                for i in 0..verts.len() {
                    let (p, q): ([f64; 2], [f64; 2]) = (verts[i], verts[(i + 1) % verts.len()]);
                    let (fp, fq) = (gu * p[0] + gv * p[1] + c, gu * q[0] + gv * q[1] + c);
                    if fp >= 0.0 {
                        out.push(p);
                    }
                    if (fp >= 0.0) != (fq >= 0.0) {
                        let t = fp / (fp - fq);
                        out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
                    }
                }
                verts = out;
            }
            if verts.len() < 3 {
                continue;
            }
            let beta = [0.3, 2.0, 9.0, 25.0][trial % 4] * (rand() - 0.5);
            let theta0 = 7.0 * rand();
            let (cos_m, sin_m) = PolygonMoments::of_phase(&verts, theta0, beta);
            let o = verts[0];
            let plain = PolygonMoments::of(&verts);
            let scale = plain.area() * 8.0;
            for a in 0..4 {
                for b in 0..4 - a {
                    let mono =
                        |u: f64, v: f64| (u - o[0]).powi(a as i32) * (v - o[1]).powi(b as i32);
                    let c_ref =
                        simpson(&verts, &|u, v| (theta0 + beta * u).cos() * mono(u, v), 2000);
                    let s_ref =
                        simpson(&verts, &|u, v| (theta0 + beta * u).sin() * mono(u, v), 2000);
                    assert!(
                        (cos_m.m[a][b] - c_ref).abs() <= 1e-9 * scale,
                        "{trial} cos {a} {b}: {} vs {c_ref}",
                        cos_m.m[a][b]
                    );
                    assert!(
                        (sin_m.m[a][b] - s_ref).abs() <= 1e-9 * scale,
                        "{trial} sin {a} {b}: {} vs {s_ref}",
                        sin_m.m[a][b]
                    );
                }
            }
            let (flat, zero) = PolygonMoments::of_phase(&verts, 0.0, 0.0);
            for a in 0..4 {
                for b in 0..4 - a {
                    assert!((flat.m[a][b] - plain.m[a][b]).abs() <= 1e-14 * scale);
                    assert!(zero.m[a][b].abs() <= 1e-300);
                }
            }
        }
    }

    #[test]
    fn the_antiderivative_and_the_short_slice_rule_agree_at_the_threshold() {
        // On either side of PHASE_SPAN_MIN the two branches integrate the same degree-4
        // polynomial times the phase: within 1e-9 of the integral's scale.
        let r: Poly = [0.3, -1.1, 0.7, 2.0, -0.9];
        for span in [PHASE_SPAN_MIN * 0.999, PHASE_SPAN_MIN, 1.5, 3.0] {
            let delta = 0.37;
            let beta = span / delta;
            let exact = phase_integral(&SlicePhase::new(0.4, beta, delta), &r);
            // A fine composite GL5 reference: 64 sub-slices, each below the threshold.
            let (mut c, mut s) = (0.0, 0.0);
            for k in 0..64 {
                let t0 = delta * k as f64 / 64.0;
                let h = delta / 64.0;
                // Shift the polynomial to the sub-slice.
                let mut shifted = [0.0; 5];
                for (n, coef) in r.iter().enumerate() {
                    // (t0 + t)^n
                    let mut binom = 1.0;
                    for m in 0..=n {
                        shifted[m] += coef * binom * t0.powi((n - m) as i32);
                        binom = binom * (n - m) as f64 / (m + 1) as f64;
                    }
                }
                let part = phase_integral(&SlicePhase::new(0.4 + beta * t0, beta, h), &shifted);
                c += part.0;
                s += part.1;
            }
            let scale = delta * 3.0;
            assert!(
                (exact.0 - c).abs() <= 1e-9 * scale,
                "{span}: {} vs {c}",
                exact.0
            );
            assert!(
                (exact.1 - s).abs() <= 1e-9 * scale,
                "{span}: {} vs {s}",
                exact.1
            );
        }
    }
}
