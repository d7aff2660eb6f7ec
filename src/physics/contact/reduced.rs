//! The reduced-order face law (`face_contact = "reduced"`, docs/reference/models.md "Reduced face
//! law"): the exact face contact ([`super::face`]) with every part of a pressed polygon
//! taking one friction at its load centre where a computable bound says it is within the
//! contact's tolerance of the per-material-point law, and the parts where the IMPACT density
//! has no clamp (`ẇ >= 0`: the closing core and the closing damping ramp) integrated in closed
//! form instead of at nodes. The separating parts (the clamp cuts their density along a
//! curve) keep the exact contact's nodes for the normal law, summed into the part's densities
//! (no friction or Jacobian moments per node). Everywhere else (the strips beyond a lip's
//! edge, a part whose bound fails) the exact contact's per-node law runs.
//!
//! The closed forms. On a part of a pressed polygon `w` and `ẇ` are affine in the face's
//! material coordinates `ξ` (a planar face, a rigid relative motion). With `e = 2` the
//! normal density is `f = k w² + c S(w) ẇ`, `S = 1` on the core (`w >= d`) and the cycloid
//! `S = w/d − sin(2π w/d)/(2π)` on the ramp (thesis eq. 2.4); its `w`-derivative is
//! `a = 2 k w + c S'(w) ẇ`, `S' = (1 − cos(2π w/d))/d`, its rate derivative `b = c S(w)`.
//! Every quantity the per-node law sums (force, load moment, stored energy `k w³/3`,
//! damping power `c S ẇ²`, and the Jacobian's moments of `a` and `b` up to second order in
//! the position) is a product of at most three affine factors times 1, `sin θ` or `cos θ`,
//! `θ = 2π w/d` linear in `ξ`: [`PolygonMoments::product`] of the plain moments and of the
//! phase moments [`PolygonMoments::of_phase`] (the ramp is turned so that `w` depends on `u`
//! alone). Exact to round-off; the per-node law's ramp rule (5 nodes on the cycloid) is what
//! differs from it, by its own quadrature error.
//!
//! Friction per part, and its bound. The part takes one friction `−μ(|s_c|) N ŝ_c` at its
//! load centre `p_c = ∫ f p / N` (passive: power `−μ N |s_c| <= 0`). The slip is affine in
//! the position, `s(p) = s_c + P (ω_rel × (p − p_c))`, so over the part `|s − s_c| <= δ =
//! |ω_rel| ρ` (`ρ` the largest distance of a vertex from `p_c`) and the load-weighted mean of
//! `s − s_c` is zero: the per-material-point law's friction differs from the part's by the
//! second-order Taylor remainder, at most `½ N δ² sup |D²φ[h, h]|/|h|²` for `φ(s) = μ(|s|) ŝ`
//! over `|s − s_c| <= δ` ([`friction_estimate`]); likewise its power `μ |s| N` and the wear's
//! `N |s|`. The estimate is that bound relative to the part's friction (and power and
//! `N |s_c|`); where it exceeds [`Contact::reduced_tolerance`] or `δ >= |s_c|` (the stiction
//! transition, where the bound degenerates) the part's nodes run the per-node law.

use super::moments::PartDensities;
use super::point::{friction_derivatives, penetration_rate, PointOutputs};
use super::{Contact, TrackLinearization};
use crate::geometry::{FacePatch, PlacedFace, PolygonMoments, QuadratureOrder};
use crate::physics::body::BodyFrame;
use crate::physics::friction::FrictionParams;
use crate::physics::step::StepKind;
use nalgebra::{Matrix3, Point3, Vector3};
use std::f64::consts::TAU;
use std::sync::atomic::{AtomicU64, Ordering};

/// The default tolerance of the reduced law's friction per part
/// ([`Contact::reduced_tolerance`]): the largest a-priori estimate of its relative error
/// against the per-material-point law (friction force, friction power, `N |v_slip|`) a part
/// may have and still take it. 1e-3: ten times inside issue 53's 1 % on wear rates.
pub const REDUCED_TOLERANCE: f64 = 1e-3;

/// `sup_h |D²ŝ[h, h]| |s|² / |h|²` for the unit slip direction `ŝ` in the tangent plane:
/// `2/√3` (the second-order term of `ŝ(s + h)` is `(−h₂², −2 h₁ h₂)/(2|s|²)` with `h₁`
/// along `s`; its largest length over unit `h` is at `sin² = 2/3`).
const DIRECTION_CURVATURE: f64 = 1.154_700_538_379_251_5;

/// Which clamp-free part of a pressed polygon the closed forms take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ClosedPart {
    /// `w >= d`, `ẇ >= 0`: `f = k w² + c ẇ`, a polynomial.
    Core,
    /// `w < d`, `ẇ >= 0`, turned so that `w` depends on `u` alone: the cycloidal ramp.
    Ramp,
}

/// How often the reduced law took a part in closed form and how often at nodes, and the
/// largest friction estimate it accepted: counted across every evaluation of the contacts that
/// share it (a contact's clones share it).
#[derive(Debug, Default)]
pub struct ReducedCensus {
    closed: AtomicU64,
    per_node: AtomicU64,
    over_tolerance: AtomicU64,
    largest: AtomicU64,
}

/// A snapshot of a [`ReducedCensus`].
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct ReducedShare {
    /// Parts integrated in closed form with friction per part.
    pub closed_parts: u64,
    /// Parts integrated at nodes (the per-node law): no closed form for their density, or
    /// their friction estimate over the tolerance.
    pub per_node_parts: u64,
    /// Of those, the parts whose friction estimate was over the tolerance.
    pub over_tolerance_parts: u64,
    /// The largest friction estimate of a part taken in closed form (relative).
    pub largest_estimate: f64,
}

impl ReducedShare {
    /// The share of parts taken in closed form, 0..1 (0 with no parts).
    pub fn closed_share(&self) -> f64 {
        let all = self.closed_parts + self.per_node_parts;
        if all == 0 {
            0.0
        } else {
            self.closed_parts as f64 / all as f64
        }
    }
}

impl ReducedCensus {
    /// The counts so far.
    pub fn snapshot(&self) -> ReducedShare {
        ReducedShare {
            closed_parts: self.closed.load(Ordering::Relaxed),
            per_node_parts: self.per_node.load(Ordering::Relaxed),
            over_tolerance_parts: self.over_tolerance.load(Ordering::Relaxed),
            largest_estimate: f64::from_bits(self.largest.load(Ordering::Relaxed)),
        }
    }

    pub(super) fn count_per_node(&self) {
        self.per_node.fetch_add(1, Ordering::Relaxed);
    }

    fn count_over_tolerance(&self) {
        self.per_node.fetch_add(1, Ordering::Relaxed);
        self.over_tolerance.fetch_add(1, Ordering::Relaxed);
    }

    fn count_closed(&self, estimate: f64) {
        self.closed.fetch_add(1, Ordering::Relaxed);
        // Non-negative floats order as their bits.
        self.largest
            .fetch_max(estimate.to_bits(), Ordering::Relaxed);
    }
}

/// A clamp-free part's closed-form integrals, world, about `origin` (the load point of the
/// part's first vertex).
#[derive(Debug, Clone, Copy)]
pub(super) struct PartIntegrals {
    /// The moments of `f_n`, `∂f_n/∂w`, `∂f_n/∂ẇ` ([`PartDensities`]).
    pub(super) densities: PartDensities,
    /// `∫ β k w³/3`, J.
    pub(super) energy: f64,
    /// `∫ β c S(w) ẇ²`, W (>= 0: `S >= 0`).
    pub(super) damping_power: f64,
}

/// The closed-form integrals of `part` (a part of a pressed polygon of a face with unit
/// normal `normal`, balls of `radius`, penetration rate `rate`) for the IMPACT law `impact`
/// with `e = 2`; `kind` says which density. Shares are `dA_ξ / 4` (the face's area is 4 in
/// `ξ`).
pub(super) fn part_integrals(
    impact: &crate::physics::impact::ImpactParams,
    part: &FacePatch,
    kind: ClosedPart,
    rate: &crate::geometry::Line,
    radius: f64,
    normal: &Vector3<f64>,
) -> PartIntegrals {
    let (k, c, d) = (
        impact.stiffness,
        impact.max_damping,
        impact.full_damping_depth,
    );
    let poly = part.moments();
    let xi0 = poly.origin;
    let (centre, axis_u, axis_v) = part.frame();
    let origin = centre + axis_u * xi0[0] + axis_v * xi0[1] - normal * radius;
    let w = part.depth().about(xi0);
    let r = rate.about(xi0);
    // The densities as polynomials in ξ − ξ₀ (degree <= 3), each with its sine or cosine
    // part on the ramp: f = k w² + c S ẇ, a = 2 k w + c S' ẇ, b = c S, the damping power's
    // c S ẇ², with S = w/d − sin θ/(2π), S' = (1 − cos θ)/d.
    let big_w = Poly2::affine(w);
    let big_r = Poly2::affine(r);
    let w2 = big_w.times(w);
    let wr = big_w.times(r);
    let r2 = big_r.times(r);
    let one = Poly2::affine((1.0, [0.0, 0.0]));
    let zero = Poly2::default();
    let ramp = match kind {
        ClosedPart::Core => None,
        ClosedPart::Ramp => {
            let (alpha, beta) = part.depth().about([0.0, 0.0]);
            let tau = TAU / d;
            Some(PolygonMoments::of_phase(
                part.vertices(),
                tau * alpha,
                tau * beta[0],
            ))
        }
    };
    // (polynomial part, trigonometric part): on the core S = 1, S' = 0.
    let (f_poly, f_sin, a_poly, a_cos, b_poly, b_sin, damp_poly, damp_sin) = match ramp {
        None => (
            w2.scaled(k).plus(&big_r.scaled(c)),
            zero,
            big_w.scaled(2.0 * k),
            zero,
            one.scaled(c),
            zero,
            r2.scaled(c),
            zero,
        ),
        Some(_) => (
            w2.scaled(k).plus(&wr.scaled(c / d)),
            big_r.scaled(-c / TAU),
            big_w.scaled(2.0 * k).plus(&big_r.scaled(c / d)),
            big_r.scaled(-c / d),
            big_w.scaled(c / d),
            one.scaled(-c / TAU),
            wr.times(r).scaled(c / d),
            r2.scaled(-c / TAU),
        ),
    };
    let (cos_m, sin_m) = match &ramp {
        Some((cos, sin)) => (cos.m, sin.m),
        None => ([[0.0; 4]; 4], [[0.0; 4]; 4]),
    };
    // ¼ ∫ density (ξ − ξ₀)^shift: the share of dξ is dξ/4.
    let integral = |p: &Poly2, t: &Poly2, trig: &[[f64; 4]; 4], shift: (usize, usize)| {
        0.25 * (p.contract(&poly.m, shift) + t.contract(trig, shift))
    };
    let world = |m_u: f64, m_v: f64| axis_u * m_u + axis_v * m_v;
    let second = |m_uu: f64, m_uv: f64, m_vv: f64| {
        axis_u * axis_u.transpose() * m_uu
            + (axis_u * axis_v.transpose() + axis_v * axis_u.transpose()) * m_uv
            + axis_v * axis_v.transpose() * m_vv
    };
    let f = |shift| integral(&f_poly, &f_sin, &sin_m, shift);
    let a = |shift| integral(&a_poly, &a_cos, &cos_m, shift);
    let b = |shift| integral(&b_poly, &b_sin, &sin_m, shift);
    let densities = PartDensities {
        origin,
        normal: *normal,
        a0: a((0, 0)),
        a1: world(a((1, 0)), a((0, 1))),
        a2: second(a((2, 0)), a((1, 1)), a((0, 2))),
        b0: b((0, 0)),
        b1: world(b((1, 0)), b((0, 1))),
        b2: second(b((2, 0)), b((1, 1)), b((0, 2))),
        f0: f((0, 0)),
        f1: world(f((1, 0)), f((0, 1))),
    };
    PartIntegrals {
        densities,
        energy: 0.25 * k / 3.0 * w2.times(w).contract(&poly.m, (0, 0)),
        damping_power: integral(&damp_poly, &damp_sin, &sin_m, (0, 0)),
    }
}

/// A polynomial of degree <= 3 in `ξ − ξ₀`: `p[a][b]` the coefficient of
/// `(u − u₀)^a (v − v₀)^b`.
#[derive(Debug, Clone, Copy, Default)]
struct Poly2([[f64; 4]; 4]);

impl Poly2 {
    /// `c + g · (ξ − ξ₀)`.
    fn affine((c, g): (f64, [f64; 2])) -> Self {
        let mut p = [[0.0; 4]; 4];
        p[0][0] = c;
        p[1][0] = g[0];
        p[0][1] = g[1];
        Self(p)
    }

    /// The product with an affine `(c, g)` (terms beyond degree 3 are dropped: the callers'
    /// products stay within it).
    fn times(&self, (c, g): (f64, [f64; 2])) -> Self {
        let mut out = [[0.0; 4]; 4];
        for a in 0..4 {
            for b in 0..4 - a {
                let x = self.0[a][b];
                if x == 0.0 {
                    continue;
                }
                out[a][b] += x * c;
                if a + b < 3 {
                    out[a + 1][b] += x * g[0];
                    out[a][b + 1] += x * g[1];
                }
            }
        }
        Self(out)
    }

    fn scaled(&self, s: f64) -> Self {
        Self(self.0.map(|row| row.map(|x| x * s)))
    }

    fn plus(&self, other: &Self) -> Self {
        let mut out = self.0;
        for (row, o) in out.iter_mut().zip(&other.0) {
            for (x, y) in row.iter_mut().zip(o) {
                *x += y;
            }
        }
        Self(out)
    }

    /// `∫ p (u − u₀)^su (v − v₀)^sv` from the moments `m[a][b]` (degree <= 3 in all).
    fn contract(&self, m: &[[f64; 4]; 4], (su, sv): (usize, usize)) -> f64 {
        let mut sum = 0.0;
        for a in 0..4 {
            for b in 0..4 - a {
                if a + b + su + sv > 3 {
                    break;
                }
                sum += self.0[a][b] * m[a + su][b + sv];
            }
        }
        sum
    }
}

/// Upper bounds of `|μ'|` and `|μ''|` of `fr`'s coefficient over slip speeds in
/// `[low, high]` (the largest slope and curvature of each STEP segment the interval meets).
fn coefficient_bounds(fr: &FrictionParams, low: f64, high: f64) -> (f64, f64) {
    let (slope_max, curvature_max) = match fr.step {
        // u − sin(2πu)/(2π): slope 1 − cos <= 2, curvature 2π sin <= 2π.
        StepKind::Cycloidal => (2.0, TAU),
        // 3u² − 2u³: slope 6u(1 − u) <= 1.5, curvature |6 − 12u| <= 6.
        StepKind::Cubic => (1.5, 6.0),
    };
    let (vs, vd) = (fr.stiction_transition_speed, fr.friction_transition_speed);
    let (mut slope, mut curvature) = (0.0f64, 0.0f64);
    if low < vs {
        // −μ_s at −v_s to μ_s at v_s.
        let span = 2.0 * vs;
        slope = slope.max(2.0 * fr.mu_static * slope_max / span);
        curvature = curvature.max(2.0 * fr.mu_static * curvature_max / (span * span));
    }
    if low < vd && high > vs {
        let (height, span) = ((fr.mu_dynamic - fr.mu_static).abs(), vd - vs);
        slope = slope.max(height * slope_max / span);
        curvature = curvature.max(height * curvature_max / (span * span));
    }
    (slope, curvature)
}

/// The a-priori estimate of friction per part's relative error against the per-material-point
/// law on a part whose slip is `s_c` (speed `speed`) at its load centre and varies by at most
/// `delta` over it: the Taylor remainder's bound (module docs) of the friction force over
/// `μ(|s_c|) N`, of the friction power over `μ(|s_c|) |s_c| N` and of `N |s|` over
/// `N |s_c|`, the largest of the three; infinite where `delta >= speed` (the slip may turn
/// over the part: no bound).
pub(super) fn friction_estimate(fr: &FrictionParams, speed: f64, delta: f64) -> f64 {
    if delta == 0.0 {
        return 0.0;
    }
    let (low, high) = (speed - delta, speed + delta);
    if low <= 0.0 {
        return f64::INFINITY;
    }
    let mu = fr.coefficient(speed);
    if mu <= 0.0 {
        return f64::INFINITY;
    }
    let mu_max = fr.mu_static.max(fr.mu_dynamic);
    let (slope, curvature) = coefficient_bounds(fr, low, high);
    let half = 0.5 * delta * delta;
    // |D²(μ ŝ)[h, h]| <= |μ''| + 3 |μ'| / |s| + (2/√3) μ / |s|².
    let force = half * (curvature + 3.0 * slope / low + DIRECTION_CURVATURE * mu_max / (low * low));
    // |D²(μ |s|)[h, h]| <= |μ''| |s| + 3 |μ'| + μ / |s|; |D²|s|[h, h]| <= 1 / |s|.
    let power = half * (curvature * high + 3.0 * slope + mu_max / low);
    let slip = half / low;
    (force / mu).max(power / (mu * speed)).max(slip / speed)
}

impl Contact {
    /// True when the reduced law may take a part of this evaluation: `e = 2`, and neither
    /// per-point loads nor per-node derivatives asked for (those need the nodes).
    fn reduced_allowed(&self, out: &PointOutputs<'_, '_>) -> bool {
        self.impact.exponent == 2.0
            && out.points.is_none()
            && !(out.linearizations.is_some() && out.moments.is_none())
    }

    /// False when `part`'s friction estimate cannot be within the tolerance whatever its
    /// load centre `p_c` (a necessary condition, so that a part bound to take its nodes is
    /// not integrated twice). With `p̄` the vertices' mean, `ρ̄` their largest distance from
    /// it and `δ̄ = |ω_rel| ρ̄`: `|s_c| <= |s(p̄)| + δ̄`, and the estimate's `δ = |ω_rel| ρ`
    /// is at least `δ̄ / 2` (a point's largest distance from the vertices is at least half
    /// the diameter, which is at least `ρ̄`); its slip term `δ² / (2 r_min |s_c|)` is at least
    /// `δ² / (2 |s_c|²)`, so passing needs `δ̄ / 2 <= √(2 tol) (|s(p̄)| + δ̄)`.
    fn may_pass(
        &self,
        part: &FacePatch,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        normal: &Vector3<f64>,
    ) -> bool {
        if self.friction.is_none() {
            return true;
        }
        let (centre, axis_u, axis_v) = part.frame();
        let verts = part.vertices();
        let (mut mu, mut mv) = (0.0, 0.0);
        for x in verts {
            mu += x[0];
            mv += x[1];
        }
        let count = verts.len().max(1) as f64;
        let (mu, mv) = (mu / count, mv / count);
        let rho = verts
            .iter()
            .map(|x| (axis_u * (x[0] - mu) + axis_v * (x[1] - mv)).norm())
            .fold(0.0, f64::max);
        let p = centre + axis_u * mu + axis_v * mv - normal * radius;
        let v_rel = fa.point_velocity(&p) - fb.point_velocity(&p);
        let slip = (v_rel - normal * v_rel.dot(normal)).norm();
        let delta = (fa.angular_velocity - fb.angular_velocity).norm() * rho;
        0.5 * delta <= (2.0 * self.reduced_tolerance).sqrt() * (slip + delta)
    }

    /// The reduced law on `part` of a pressed polygon (no clamp on it: `kind`) in closed
    /// form, into `out`: false, with nothing added, where the caller must integrate the part
    /// at its nodes ([`Contact::reduced_allowed`], the cubic STEP on a ramp, or the friction
    /// estimate over the tolerance).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn reduced_part(
        &self,
        part: &FacePatch,
        kind: ClosedPart,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        normal: &Vector3<f64>,
        out: &mut PointOutputs<'_, '_>,
    ) -> bool {
        if !self.reduced_allowed(out)
            || (kind == ClosedPart::Ramp && self.impact.step != StepKind::Cycloidal)
        {
            self.reduced_census.count_per_node();
            return false;
        }
        if !self.may_pass(part, fa, fb, radius, normal) {
            self.reduced_census.count_over_tolerance();
            return false;
        }
        let rate = penetration_rate(part, fa, fb, radius, normal);
        let integrals = part_integrals(&self.impact, part, kind, &rate, radius, normal);
        self.apply_part(&integrals, part, fa, fb, radius, out)
    }

    /// The reduced law on a part whose density the clamp cuts along a curve (the separating
    /// ramp and the clamp band): the exact contact's nodes of `rule` (cut at the clamp,
    /// [`FacePatch::for_each_node_clamped`]) take the normal law only, summed into the part's
    /// densities, and the part takes one friction at its load centre where the estimate
    /// allows. What a node costs is then its normal law and a few sums instead of its
    /// friction and its Jacobian moments. False, with nothing added, as
    /// [`Contact::reduced_part`].
    #[allow(clippy::too_many_arguments)]
    pub(super) fn reduced_clamped_part(
        &self,
        part: &FacePatch,
        rule: QuadratureOrder,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        face: &PlacedFace,
        out: &mut PointOutputs<'_, '_>,
    ) -> bool {
        if !self.reduced_allowed(out) {
            self.reduced_census.count_per_node();
            return false;
        }
        let normal = face.plane.normal.into_inner();
        if !self.may_pass(part, fa, fb, radius, &normal) {
            self.reduced_census.count_over_tolerance();
            return false;
        }
        let offset = face.plane.offset;
        let sign = self.clamped_density(part, fa, fb, radius, &normal);
        let (centre, _, _) = part.frame();
        let origin = centre - normal * radius;
        let mut d = PartDensities::empty(origin, normal);
        let (mut energy, mut damping_power) = (0.0, 0.0);
        let linearizing = out.linearizing();
        part.for_each_node_clamped(rule, sign, &mut |x, share| {
            let w = radius - (normal.dot(&x.coords) - offset);
            if w <= 0.0 {
                return;
            }
            let p = x - normal * radius;
            let wdot = -(fa.point_velocity(&p) - fb.point_velocity(&p)).dot(&normal);
            let (spring, damping, slope) = if linearizing {
                self.impact.force_parts_with_slope(w)
            } else {
                let (spring, damping) = self.impact.force_parts(w);
                (spring, damping, 0.0)
            };
            let f = (spring + damping * wdot).max(0.0);
            energy += share * self.impact.potential(w);
            damping_power += share * (f - spring) * wdot;
            if f > 0.0 {
                let q = p - origin;
                d.f0 += share * f;
                d.f1 += q * (share * f);
                if linearizing {
                    let (dfdw, dfdwdot) = self
                        .impact
                        .unclamped_gradient_with_slope(w, wdot, damping, slope);
                    let qq = q * q.transpose();
                    d.a0 += share * dfdw;
                    d.a1 += q * (share * dfdw);
                    d.a2 += qq * (share * dfdw);
                    d.b0 += share * dfdwdot;
                    d.b1 += q * (share * dfdwdot);
                    d.b2 += qq * (share * dfdwdot);
                }
            }
        });
        let integrals = PartIntegrals {
            densities: d,
            energy,
            damping_power,
        };
        self.apply_part(&integrals, part, fa, fb, radius, out)
    }

    /// A part's normal law from `integrals` and its friction per part at its load centre,
    /// into `out`, when the friction estimate is within the tolerance (true); else nothing
    /// (false). A part whose every point is clamped (no load) takes no friction.
    fn apply_part(
        &self,
        integrals: &PartIntegrals,
        part: &FacePatch,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        out: &mut PointOutputs<'_, '_>,
    ) -> bool {
        let dens = &integrals.densities;
        let n = dens.normal;
        let load = dens.f0;
        let loaded = load > 0.0;
        let p_c = if loaded {
            dens.origin + dens.f1 / load
        } else {
            dens.origin
        };
        let v_rel = fa.point_velocity(&p_c) - fb.point_velocity(&p_c);
        let slip = v_rel - n * v_rel.dot(&n);
        let speed = slip.norm();
        let mut estimate = 0.0;
        if let (Some(fr), true) = (&self.friction, loaded) {
            let (centre, axis_u, axis_v) = part.frame();
            let rho = part
                .vertices()
                .iter()
                .map(|x| (centre + axis_u * x[0] + axis_v * x[1] - n * radius - p_c).norm())
                .fold(0.0, f64::max);
            let omega = (fa.angular_velocity - fb.angular_velocity).norm();
            estimate = friction_estimate(fr, speed, omega * rho);
            if !(estimate <= self.reduced_tolerance) {
                self.reduced_census.count_over_tolerance();
                return false;
            }
        }
        self.reduced_census.count_closed(estimate);
        let linearizing = out.linearizing();
        let mut friction = Vector3::zeros();
        let (mut ft, mut mu_both) = (0.0, None);
        if let (Some(fr), true) = (&self.friction, loaded && speed > 0.0) {
            let both = if linearizing {
                fr.coefficient_with_derivative(speed)
            } else {
                (fr.coefficient(speed), 0.0)
            };
            mu_both = Some(both);
            ft = both.0 * load;
            friction = slip * (-ft / speed);
        }
        *out.energy += integrals.energy;
        let sum = &mut out.sum;
        sum.touching = true;
        sum.force += n * load + friction;
        // Σ (p − x) × n f_n = ((o − x) N + Σ f_n q) × n; the friction at p_c.
        for (torque, x) in [
            (&mut sum.torque_a, fa.position),
            (&mut sum.torque_b, fb.position),
        ] {
            *torque += ((dens.origin.coords - x) * load + dens.f1).cross(&n)
                + (p_c.coords - x).cross(&friction);
        }
        sum.normal_force += load;
        sum.weighted_slip += slip * load;
        sum.weighted_speed += speed * load;
        sum.weighted_point += p_c.coords * load;
        sum.friction_force += ft;
        sum.damping_power += integrals.damping_power;
        sum.friction_power += ft * speed;
        if linearizing && loaded {
            let g0 = n + friction / load;
            if let Some(moments) = out.moments.as_deref_mut() {
                moments.add_part(dens, &g0, radius);
            }
            if self.friction.is_some() {
                let tangent = Matrix3::identity() - n * n.transpose();
                let (_, dforce_dslip) = friction_derivatives(
                    self.friction.as_ref(),
                    &n,
                    &tangent,
                    &slip,
                    load,
                    mu_both,
                );
                out.push_linearization(&TrackLinearization {
                    body_a: self.body_a,
                    body_b: self.body_b,
                    deepest_point: p_c,
                    point: p_c,
                    centre: Point3::from(p_c.coords + n * radius),
                    force: Vector3::zeros(),
                    normal: n,
                    dfn_dw: 0.0,
                    dfn_dwdot: 0.0,
                    dforce_dfn: Vector3::zeros(),
                    dforce_dslip,
                });
            }
        }
        true
    }
}

#[cfg(test)]
#[path = "reduced_tests.rs"]
mod tests;
