//! The exactly integrated face contact (issue 27; docs/reference/models.md "Exact face contact"): the
//! part of one face of a rounded box's inner box that presses into a (possibly bounded) face,
//! and a quadrature over it that is exact for the IMPACT law's polynomial densities.
//!
//! A rounded box is its inner box ⊕ ball(r). The contact-point lattice
//! ([`super::lattice`]) puts balls of radius `r` on the inner box's faces with a stiffness
//! share `dA / A` per face (A the inner face's area); its limit of infinitely many points is
//! the continuum this module integrates: on an inner face with material coordinates
//! `ξ = (u, v) ∈ [−1, 1]²`, `x(ξ) = c + u a_u + v a_v`, the ball at `x` penetrates the face's
//! plane by `w(ξ) = r − (n·x − offset)`, which is **linear** in `ξ`. The pressed part of the
//! face is the convex polygon `P = square ∩ {w > 0} ∩ {x over the face's extent}`: every
//! boundary is a straight line in `ξ` (a bounded face's sides are lines `g(x) = 0`, `g` affine).
//!
//! Quadrature: `P` is sliced at its vertices' `u`; on each slice its lower and upper
//! boundaries are straight, so a polynomial density of degree `D` in `ξ` integrates over `v`
//! to a polynomial of degree `D + 1` in `u`. Gauss–Legendre with `m_v` nodes in `v` and `m_u`
//! in `u` is exact when `2 m_v − 1 >= D` and `2 m_u − 1 >= D + 1`. For the exponent `e = 2`
//! of every reference model the densities are `k w²` (force, `D = 2`), `x × n k w²` (torque)
//! and `k w³/3` (stored energy, both `D = 3`): `m_v = 2`, `m_u = 3` integrate all three to
//! round-off. The rule's degree follows the exponent ([`QuadratureOrder::for_exponent`]); for
//! a non-integer exponent it integrates `w^e` to the accuracy of a Gauss rule on a function
//! `C^⌊e⌋` at the `w = 0` edge (documented, not exact).
//!
//! Beyond a bounded face's side the face's solid is rounded off: a ball within `r` of the
//! side's edge still touches it, with `w = r − d` and `d` its distance to the solid (the
//! lattice's law, [`PlacedFace::signed_distance`]). Those parts of the inner face
//! ([`FacePatch::beyond_sides`], strips at most `r` wide) carry the rest of the continuum's
//! energy, which is continuous across the side: the region boundary terms of the two parts'
//! gradients cancel, so no force acts on the cut line, and a shoe sliding off a lip unloads
//! continuously even when a whole face crosses the edge at once. `w` is not polynomial there;
//! [`QuadratureOrder::ROUNDED_EDGE`] integrates it, along the edge graded by the density's
//! smoothness ([`FacePatch::for_each_node_graded`]; docs/reference/models.md gives the
//! measured error).
//!
//! Over 700 lines: the patch's cutting (clip, split, strips) and its rules (sliced, clamped,
//! graded along a strip's edge) all walk the same private vertex array and columns, which
//! a second file would have to open up.
//!
//! Hot path: fixed-size arrays only, no heap allocation.

use super::bounded_face::PlacedFace;
use super::polygon_moments::PolygonMoments;
use nalgebra::{Point3, Vector3};

/// Room for the vertices of a clipped face: the square's 4, one more per clipping line (the
/// `w = 0` line and up to four sides of a bounded face), with margin for repeated vertices.
const MAX_VERTICES: usize = 16;
/// Most sides of a face's extent (a rectangle).
const MAX_SIDES: usize = 4;
/// Gauss–Legendre abscissae on [-1, 1] for 1 to 5 nodes.
const GL_NODES: [&[f64]; 5] = [
    &[0.0],
    &[-0.577_350_269_189_625_8, 0.577_350_269_189_625_8],
    &[-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4],
    &[
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ],
    &[
        -0.906_179_845_938_664,
        -0.538_469_310_105_683_1,
        0.0,
        0.538_469_310_105_683_1,
        0.906_179_845_938_664,
    ],
];
/// Matching weights (sum 2).
const GL_WEIGHTS: [&[f64]; 5] = [
    &[2.0],
    &[1.0, 1.0],
    &[5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0],
    &[
        0.347_854_845_137_453_9,
        0.652_145_154_862_546_1,
        0.652_145_154_862_546_1,
        0.347_854_845_137_453_9,
    ],
    &[
        0.236_926_885_056_189_1,
        0.478_628_670_499_366_5,
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
    ],
];

/// Gauss–Legendre nodes per direction of the patch rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QuadratureOrder {
    /// Nodes across a slice (`v`): exact to degree `2 m_v − 1`.
    pub across: usize,
    /// Nodes along the slices (`u`), and along a cut side: exact to degree `2 m_u − 1`.
    pub along: usize,
}

impl QuadratureOrder {
    /// The rule on the strips beyond a bounded face's sides (`w` not polynomial): the most
    /// nodes of the table, 5 × 5 per slice (3 nodes along the edge failed the gradient test:
    /// 2.5 % of a barely touching strip's force).
    pub const ROUNDED_EDGE: Self = Self {
        across: 5,
        along: 5,
    };

    /// The rule on the strips of an inner face that does not face the plane (the ends and
    /// sides of a shoe head): one slice of 3 × 3. Such a strip is the roundover's corner
    /// beyond a lip's edge, at most `r × r`: a few 1e-4 of a pressed head's force, up to about
    /// `2 r / L` of a head that has slid off the lip to its last roundover. Its integrand is
    /// cut by the `w = 0` circle, so no low-order rule is exact there: 3 × 3 stays within 4 %
    /// of such a strip's force and energy, and within 1e-3 of the head's
    /// (tests/engine/face_contact_rules.rs), with 9 nodes against 50 for
    /// [`Self::ROUNDED_EDGE`] on two slices. Which faces take it: `physics::contact::face`.
    pub const SIDE_EDGE: Self = Self {
        across: 3,
        along: 3,
    };

    /// The smallest rule exact for the stored energy and the torque of the IMPACT law with
    /// exponent `e` (densities of degree `D = ⌈e⌉ + 1` in `ξ`): `m_v = ⌈(D + 1)/2⌉`,
    /// `m_u = ⌈(D + 2)/2⌉`, each at most 5 (exact up to `e = 7`). `e = 2`: 2 × 3 nodes.
    pub fn for_exponent(e: f64) -> Self {
        let degree = (e.max(0.0).ceil() as usize).min(8) + 1;
        Self {
            across: (degree + 1).div_ceil(2).min(5),
            along: (degree + 2).div_ceil(2).min(5),
        }
    }
}

/// The rule along the edge of a strip beyond a bounded face's side
/// ([`FacePatch::for_each_node_graded`]): a column whose density is analytic in the Bernstein
/// ellipse of parameter `ρ` around its touching interval takes `along_edge` Gauss nodes
/// there when `ρ >= full`, the fixed rule's when `ρ <= from`, and both, blended, between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradedStrip {
    /// Gauss nodes along the edge on a smooth column's touching interval (1 to 5).
    pub along_edge: usize,
    /// At or below this `ρ` the fixed rule alone.
    pub from: f64,
    /// At or above this `ρ` the coarse rule alone.
    pub full: f64,
}

impl GradedStrip {
    /// The contact's rule on a facing face's strips (with [`QuadratureOrder::ROUNDED_EDGE`]
    /// on two slices across the edge): 3 nodes along the edge from `ρ = 8` (a Gauss rule of
    /// `m` nodes errs by about `ρ^(−2m)`: 4e-6), the fixed rule's 5 on the whole column up to
    /// `ρ = 4`, both blended between.
    pub const ROUNDED_EDGE: Self = Self {
        along_edge: 3,
        from: 4.0,
        full: 8.0,
    };

    /// The coarse rule's share at `ρ`: 0 up to `from`, 1 from `full`, a smoothstep
    /// `3t² − 2t³` between (continuous with its derivative).
    pub fn share(&self, rho: f64) -> f64 {
        if rho >= self.full {
            1.0
        } else if rho <= self.from {
            0.0
        } else {
            let t = (rho - self.from) / (self.full - self.from);
            t * t * (3.0 - 2.0 * t)
        }
    }
}

/// An affine function `alpha + beta · ξ` of a patch's material coordinates (a clip keeps its
/// `>= 0` side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    alpha: f64,
    beta: [f64; 2],
}

impl Line {
    /// The value at `ξ = p`.
    #[inline]
    pub fn at(&self, p: [f64; 2]) -> f64 {
        self.alpha + self.beta[0] * p[0] + self.beta[1] * p[1]
    }

    /// The value at `origin` and the gradient in `ξ`: the function as
    /// `c + g · (ξ − origin)` ([`PolygonMoments::product`]).
    pub fn about(&self, origin: [f64; 2]) -> (f64, [f64; 2]) {
        (self.at(origin), self.beta)
    }

    /// The same function minus `c`.
    pub fn minus(&self, c: f64) -> Self {
        Self {
            alpha: self.alpha - c,
            ..*self
        }
    }
}

/// The pressed part of one inner-box face against one (possibly bounded) face.
#[derive(Debug, Clone, Copy)]
pub struct FacePatch {
    centre: Point3<f64>,
    axis_u: Vector3<f64>,
    axis_v: Vector3<f64>,
    depth: Line,
    /// On a strip beyond one side only ([`FacePatch::beyond_sides`]): that side's line `g`
    /// (positive over the face's extent), so `q = −g` is the distance beyond the edge; `None`
    /// on a pressed polygon and on a strip that also reaches beyond another side.
    edge: Option<Line>,
    verts: [[f64; 2]; MAX_VERTICES],
    len: usize,
}

impl FacePatch {
    /// The whole inner face `centre + u axis_u + v axis_v` (`|u|, |v| <= 1`, world, m), its
    /// balls of `radius` against `face`'s plane.
    fn square(
        centre: Point3<f64>,
        axis_u: Vector3<f64>,
        axis_v: Vector3<f64>,
        radius: f64,
        face: &PlacedFace,
    ) -> Option<Self> {
        let n = face.plane.normal.into_inner();
        let depth = Line {
            alpha: radius - (n.dot(&centre.coords) - face.plane.offset),
            beta: [-n.dot(&axis_u), -n.dot(&axis_v)],
        };
        // Cull: w is largest at a corner.
        if depth.alpha + depth.beta[0].abs() + depth.beta[1].abs() <= 0.0 {
            return None;
        }
        let mut patch = Self {
            centre,
            axis_u,
            axis_v,
            depth,
            edge: None,
            verts: [[0.0; 2]; MAX_VERTICES],
            len: 4,
        };
        patch.verts[..4].copy_from_slice(&[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]);
        patch.clip(&depth).then_some(patch)
    }

    /// The line `g >= 0` of a side `(d, o, b)` of `face`'s extent ([`PlacedFace::sides`]):
    /// `g(x) = b − d·(x − o)`, positive over the extent, in this face's `ξ`.
    fn side_line(&self, side: &(Vector3<f64>, Point3<f64>, f64)) -> Line {
        let (d, o, b) = side;
        Line {
            alpha: b - d.dot(&(self.centre - o)),
            beta: [-d.dot(&self.axis_u), -d.dot(&self.axis_v)],
        }
    }

    /// The part of the inner face `centre + u axis_u + v axis_v` (`|u|, |v| <= 1`, world, m)
    /// whose balls of `radius` penetrate `face`'s plane with their centres over its extent;
    /// `None` when that part is empty. There `w = radius − (n·x − offset)` is linear.
    pub fn new(
        centre: Point3<f64>,
        axis_u: Vector3<f64>,
        axis_v: Vector3<f64>,
        radius: f64,
        face: &PlacedFace,
    ) -> Option<Self> {
        Self::pressed(Self::square(centre, axis_u, axis_v, radius, face)?, face)
    }

    /// [`FacePatch::new`] and [`FacePatch::beyond_sides`] of the same inner face at once,
    /// each part handed to `each(part, beyond_side)` as it is cut: first the pressed polygon
    /// (`beyond_side` false), then the strips in the sides' order (true). The whole face's
    /// pressed square, which all start from, is clipped by the plane once instead of once for
    /// each and again for each side, and no array of patches is moved.
    pub fn for_each_part(
        centre: Point3<f64>,
        axis_u: Vector3<f64>,
        axis_v: Vector3<f64>,
        radius: f64,
        face: &PlacedFace,
        mut each: impl FnMut(&Self, bool),
    ) {
        let Some(square) = Self::square(centre, axis_u, axis_v, radius, face) else {
            return;
        };
        if let Some(patch) = Self::pressed(square, face) {
            each(&patch, false);
        }
        Self::beyond_sides_of(&square, radius, face, |_, part| each(part, true));
    }

    /// The part of `square` (the pressed square of [`FacePatch::square`]) over `face`'s extent.
    fn pressed(mut patch: Self, face: &PlacedFace) -> Option<Self> {
        for side in face.sides() {
            let line = patch.side_line(&side);
            if !patch.clip(&line) {
                return None;
            }
        }
        Some(patch)
    }

    /// The parts of the same inner face whose ball centres lie beyond a side of `face`'s
    /// extent by less than `radius` (and below `radius` above its plane): where a ball can
    /// touch the face's rounded-off edge, its penetration `radius − d` with `d` the distance
    /// to the face's solid ([`PlacedFace::signed_distance`]), not linear. One part per side,
    /// a point beyond several sides counted with the first: together with [`FacePatch::new`]
    /// they cover every ball that touches the solid, each once.
    pub fn beyond_sides(
        centre: Point3<f64>,
        axis_u: Vector3<f64>,
        axis_v: Vector3<f64>,
        radius: f64,
        face: &PlacedFace,
    ) -> [Option<Self>; MAX_SIDES] {
        let mut out = [None; MAX_SIDES];
        if let Some(square) = Self::square(centre, axis_u, axis_v, radius, face) {
            Self::beyond_sides_of(&square, radius, face, |k, strip| out[k] = Some(*strip));
        }
        out
    }

    /// [`FacePatch::beyond_sides`] from the inner face's pressed square (each side's strip
    /// starts from a copy of it), each strip to `each` with its side's index as it is cut.
    fn beyond_sides_of(
        square: &Self,
        radius: f64,
        face: &PlacedFace,
        mut each: impl FnMut(usize, &Self),
    ) {
        let sides: [_; MAX_SIDES] = {
            let mut all = [None; MAX_SIDES];
            for (slot, side) in all.iter_mut().zip(face.sides()) {
                *slot = Some(side);
            }
            all
        };
        for (k, side) in sides.iter().enumerate() {
            let Some(side) = side else { continue };
            let mut patch = *square;
            let g = patch.side_line(side);
            let beyond = Line {
                alpha: -g.alpha,
                beta: [-g.beta[0], -g.beta[1]],
            };
            let within = |reach: f64| Line {
                alpha: g.alpha + reach,
                ..g
            };
            let mut keep = patch.clip(&beyond) && patch.clip(&within(radius));
            for (j, other) in sides.iter().enumerate() {
                let Some(other) = other else { continue };
                if !keep || j == k {
                    continue;
                }
                let h = patch.side_line(other);
                keep = if j < k {
                    patch.clip(&h)
                } else {
                    patch.clip(&Line {
                        alpha: h.alpha + radius,
                        ..h
                    })
                };
            }
            if keep {
                // No ball farther beyond the edge than sqrt(r² − u²) touches it, u >= 0 the
                // lowest height of a centre over the plane: for a face parallel to the plane
                // this is exactly the `w = 0` curve, and the integrand is smooth inside.
                let lowest = patch.verts[..patch.len]
                    .iter()
                    .map(|&p| radius - patch.depth.at(p))
                    .fold(f64::INFINITY, f64::min)
                    .max(0.0);
                let reach = (radius * radius - lowest * lowest).max(0.0).sqrt();
                keep = patch.clip(&within(reach));
            }
            if keep {
                // The strip's edge line, kept when no vertex lies beyond another side (the
                // distance is then `√(h⁺² + q²)` with `q = −g` alone); turned with the strip
                // below, `g` depends on `u` alone.
                let lone = sides.iter().enumerate().all(|(j, other)| match other {
                    Some(other) if j != k => {
                        let h = patch.side_line(other);
                        patch.vertices().iter().all(|&p| h.at(p) >= 0.0)
                    }
                    _ => true,
                });
                patch.edge = lone.then_some(g);
                // Sliced exactly across the side's edge (`u` along the gradient of `g`): the
                // strip's lines `g = 0` and `g = −reach` are then slice boundaries, the strip
                // one vertex interval (a face's axis only nearly across the edge cut thin
                // end slices off it, each with the whole rule), and the integrand's kink at
                // `w = 0` lies in few slices.
                each(k, &patch.aligned_with(&g));
            }
        }
    }

    /// The inner face's frame: `ξ` is the world point `centre + u axis_u + v axis_v`.
    pub fn frame(&self) -> (Point3<f64>, Vector3<f64>, Vector3<f64>) {
        (self.centre, self.axis_u, self.axis_v)
    }

    /// The penetration `w(ξ)` of the patch's balls into the face's plane (affine).
    pub fn depth(&self) -> Line {
        self.depth
    }

    /// The affine function of `ξ` that `f` is on this face (`f` affine in the world point:
    /// sampled at `ξ = (0, 0), (1, 0), (0, 1)`).
    pub fn affine(&self, f: impl Fn(Point3<f64>) -> f64) -> Line {
        let f0 = f(self.point([0.0, 0.0]));
        Line {
            alpha: f0,
            beta: [
                f(self.point([1.0, 0.0])) - f0,
                f(self.point([0.0, 1.0])) - f0,
            ],
        }
    }

    /// The same patch in material coordinates turned so that `u` runs along the gradient of
    /// `line` (its value then depends on `u` alone): a rule sliced in `u` puts its `along`
    /// nodes across `line`'s level lines. The turn is a rotation of `ξ` (unit Jacobian), so
    /// every node keeps its share of the face; unchanged when `line` is constant.
    pub fn aligned_with(&self, line: &Line) -> Self {
        let g = (line.beta[0] * line.beta[0] + line.beta[1] * line.beta[1]).sqrt();
        if g == 0.0 {
            return *self;
        }
        let e1 = [line.beta[0] / g, line.beta[1] / g];
        let e2 = [-e1[1], e1[0]];
        let mut out = *self;
        out.axis_u = self.axis_u * e1[0] + self.axis_v * e1[1];
        out.axis_v = self.axis_u * e2[0] + self.axis_v * e2[1];
        let turn = |b: [f64; 2]| [b[0] * e1[0] + b[1] * e1[1], b[0] * e2[0] + b[1] * e2[1]];
        out.depth.beta = turn(self.depth.beta);
        if let Some(edge) = &mut out.edge {
            edge.beta = turn(edge.beta);
        }
        for (o, p) in out.verts[..self.len]
            .iter_mut()
            .zip(&self.verts[..self.len])
        {
            *o = [p[0] * e1[0] + p[1] * e1[1], p[0] * e2[0] + p[1] * e2[1]];
        }
        out
    }

    /// The parts of the patch where `line >= 0` and where `line <= 0` (each `None` when of
    /// zero area): together they cover the patch once.
    pub fn split(&self, line: &Line) -> (Option<Self>, Option<Self>) {
        // `line` at each vertex once for both parts: the opposite line `−line` is `−g` at
        // each vertex (negating every operand negates each rounded result), up to the sign of
        // a zero, which no comparison of the clip and no crossing (taken only between values
        // of strictly opposite signs) sees.
        let len = self.len;
        let mut at = [0.0; MAX_VERTICES];
        let (mut above, mut below) = (true, true);
        for (g, &p) in at.iter_mut().zip(&self.verts[..len]) {
            *g = line.at(p);
            above &= *g >= 0.0;
            below &= *g <= 0.0;
        }
        if above {
            return (Some(*self), None);
        }
        if below {
            return (None, Some(*self));
        }
        let mut opposite = [0.0; MAX_VERTICES];
        for (o, g) in opposite.iter_mut().zip(&at[..len]) {
            *o = -g;
        }
        let (mut above, mut below) = (*self, *self);
        (
            above.clip_at(&at).then_some(above),
            below.clip_at(&opposite).then_some(below),
        )
    }

    /// Sutherland–Hodgman clip of the polygon by `line` (keeping `line >= 0`); false when
    /// nothing of positive area is left.
    fn clip(&mut self, line: &Line) -> bool {
        // `line` at each vertex once (it was taken up to three times per vertex).
        let len = self.len;
        let mut at = [0.0; MAX_VERTICES];
        let mut kept = true;
        for (g, &p) in at.iter_mut().zip(&self.verts[..len]) {
            *g = line.at(p);
            kept &= *g >= 0.0;
        }
        kept || self.clip_at(&at)
    }

    /// [`FacePatch::clip`] given the line's value `at[i]` at each vertex, some negative.
    fn clip_at(&mut self, at: &[f64; MAX_VERTICES]) -> bool {
        let len = self.len;
        let mut out = [[0.0; 2]; MAX_VERTICES];
        let mut m = 0;
        for i in 0..len {
            let j = next(i, len);
            let (p, q) = (self.verts[i], self.verts[j]);
            let (gp, gq) = (at[i], at[j]);
            let crossing = || {
                let t = gp / (gp - gq);
                [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
            };
            let (first, second) = match (gp >= 0.0, gq >= 0.0) {
                (true, true) => (Some(p), None),
                (true, false) if gp == 0.0 => (Some(p), None),
                (true, false) => (Some(p), Some(crossing())),
                // q on the line is appended as the next p.
                (false, true) if gq > 0.0 => (Some(crossing()), None),
                (false, _) => (None, None),
            };
            for v in [first, second].into_iter().flatten() {
                if m < MAX_VERTICES {
                    out[m] = v;
                    m += 1;
                }
            }
        }
        // Only the kept vertices: the rest of the array is never read (`len` bounds it).
        self.verts[..m].copy_from_slice(&out[..m]);
        self.len = m;
        m >= 3 && self.area_xi() > 0.0
    }

    /// Area of the polygon in `ξ` (the square's is 4).
    fn area_xi(&self) -> f64 {
        let mut twice = 0.0;
        for i in 0..self.len {
            let p = self.verts[i];
            let q = self.verts[next(i, self.len)];
            twice += p[0] * q[1] - q[0] * p[1];
        }
        0.5 * twice
    }

    /// The polygon's vertices in `ξ`, in order.
    pub fn vertices(&self) -> &[[f64; 2]] {
        &self.verts[..self.len]
    }

    /// The polygon's closed-form monomial moments in `ξ` ([`PolygonMoments`]; a share of the
    /// face is the `ξ` area over 4).
    pub fn moments(&self) -> PolygonMoments {
        PolygonMoments::of(&self.verts[..self.len])
    }

    /// Share of the inner face that is pressed, 0..1.
    pub fn share(&self) -> f64 {
        self.area_xi() / 4.0
    }

    /// The world point of `ξ`.
    #[inline]
    fn point(&self, p: [f64; 2]) -> Point3<f64> {
        self.centre + self.axis_u * p[0] + self.axis_v * p[1]
    }

    /// `centre + u axis_u`, the part of [`FacePatch::point`] shared by a column's nodes (the
    /// same sum in the same order: `point([u, v])` is `column_base(u) + v axis_v`, bit for bit).
    #[inline]
    fn column_base(&self, u: f64) -> Point3<f64> {
        self.centre + self.axis_u * u
    }

    /// The deepest vertex of the patch: its penetration (m) and ball centre (world).
    pub fn deepest(&self) -> (f64, Point3<f64>) {
        let mut best = (f64::NEG_INFINITY, [0.0; 2]);
        for &p in &self.verts[..self.len] {
            let w = self.depth.at(p);
            if w > best.0 {
                best = (w, p);
            }
        }
        (best.0, self.point(best.1))
    }

    /// Calls `visit(centre, weight)` for every node of the patch rule: the ball centre (world)
    /// and its share of the face's stiffness (the rule's weight in `ξ` over the square's area
    /// 4, so a fully pressed face's weights sum to 1).
    pub fn for_each_node(&self, order: QuadratureOrder, visit: &mut impl FnMut(Point3<f64>, f64)) {
        self.for_each_node_sliced(order, 1, visit);
    }

    /// [`FacePatch::for_each_node`] with each slice between vertices cut into `parts` equal
    /// slices (for an integrand with a kink inside the patch).
    pub fn for_each_node_sliced(
        &self,
        order: QuadratureOrder,
        parts: usize,
        visit: &mut impl FnMut(Point3<f64>, f64),
    ) {
        let (xs_v, ws_v) = rule(order.across);
        self.for_each_column(order.along, parts, |u, half_u, wu, lo, hi| {
            let (vm, half_v) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            let base = self.column_base(u);
            for (xv, wv) in xs_v.iter().zip(ws_v) {
                let v = vm + half_v * xv;
                visit(base + self.axis_v * v, 0.25 * half_u * wu * half_v * wv);
            }
        });
    }

    /// [`FacePatch::for_each_node_sliced`] on a strip beyond one side of a bounded face
    /// ([`FacePatch::beyond_sides`]), each column along the edge on a rule sized by how
    /// smooth the balls' penetration is there ([`GradedStrip`]). On a column (fixed `u`, so
    /// fixed distance `q` beyond the edge) the balls at height `h(v) = r − w_plane(v)` (affine)
    /// touch the rounded edge where `h⁺² + q² < r²`: one interval `[a, b]`, found in closed
    /// form, on which `w = r − √(h⁺² + q²)` is analytic but at `h = 0`. With `x` the distance of
    /// `h = 0` from the interval's middle in half-lengths, the density is analytic inside the
    /// Bernstein ellipse through it, `ρ = x + √(x² − 1)`, and a Gauss rule of `m` nodes errs
    /// by about `ρ^(−2m)`. Columns with `ρ >= graded.full` take `graded.along_edge` nodes on
    /// `[a, b]`; with `ρ <= graded.from`, `order.across` nodes on the whole column (the fixed
    /// rule); between, both, their shares blended by a smooth step in `ρ`, so the rule and
    /// the stored energy it integrates are continuous in the pose. The coarse rule's interval
    /// is cut where `w = ramp` (the damping's STEP ends there; 0: no cut) when that lies
    /// inside it, each piece with `graded.along_edge` nodes. A column no ball of which
    /// touches gets no node (the fixed rule's would all add zero). A patch without an edge
    /// (a pressed polygon, a strip also beyond another side) takes the fixed rule.
    pub fn for_each_node_graded(
        &self,
        order: QuadratureOrder,
        parts: usize,
        radius: f64,
        ramp: f64,
        graded: GradedStrip,
        visit: &mut impl FnMut(Point3<f64>, f64),
    ) {
        let Some(edge) = self.edge else {
            self.for_each_node_sliced(order, parts, visit);
            return;
        };
        let (xs_v, ws_v) = rule(order.across);
        let (xs_c, ws_c) = rule(graded.along_edge);
        // The height over the plane, `h0 + s v` on a column.
        let slope = self.depth.beta[1];
        self.for_each_column(order.along, parts, |u, half_u, wu, lo, hi| {
            let q = (-edge.at([u, 0.5 * (lo + hi)])).max(0.0);
            let room = radius * radius - q * q;
            if room <= 0.0 {
                return;
            }
            let top = room.sqrt();
            let h0 = radius - self.depth.at([u, 0.0]);
            let s = -slope;
            // Where h(v) < top: the touching interval [a, b].
            let (a, b) = if s > 0.0 {
                (lo, hi.min((top - h0) / s))
            } else if s < 0.0 {
                (lo.max((top - h0) / s), hi)
            } else if h0 < top {
                (lo, hi)
            } else {
                return;
            };
            if b <= a {
                return;
            }
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            let coarse = if s == 0.0 {
                1.0
            } else {
                let x = (-h0 / s - mid).abs() / half;
                let rho = if x > 1.0 {
                    x + (x * x - 1.0).sqrt()
                } else {
                    1.0
                };
                graded.share(rho)
            };
            let base = self.column_base(u);
            let column = 0.25 * half_u * wu;
            if coarse < 1.0 {
                let (vm, half_v) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                for (xv, wv) in xs_v.iter().zip(ws_v) {
                    let v = vm + half_v * xv;
                    visit(
                        base + self.axis_v * v,
                        (1.0 - coarse) * column * half_v * wv,
                    );
                }
            }
            if coarse > 0.0 {
                // Cut where `w = ramp` (`h⁺² + q² = (r − ramp)²`) when that is inside
                // [a, b]: the damping's STEP(w) ends there, each piece its own rule.
                let core = (radius - ramp) * (radius - ramp) - q * q;
                let cut = if ramp > 0.0 && ramp < radius && core > 0.0 && s != 0.0 {
                    Some((core.sqrt() - h0) / s).filter(|c| *c > a && *c < b)
                } else {
                    None
                };
                let mut piece = |a: f64, b: f64| {
                    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                    for (xv, wv) in xs_c.iter().zip(ws_c) {
                        let v = mid + half * xv;
                        visit(base + self.axis_v * v, coarse * column * half * wv);
                    }
                };
                match cut {
                    Some(c) => {
                        piece(a, c);
                        piece(c, b);
                    }
                    None => piece(a, b),
                }
            }
        });
    }

    /// The patch rule for a density `max(0, a(u) + b(u) v)` times a polynomial in `v`, the
    /// clamp's zero `v = −a/b` a curve across the patch: `sign(u) = (a, b)`. On each node
    /// `u` of the slices, `order.across` nodes cover the part of the column where
    /// `a + b v > 0` (exact for the polynomial there), and one node in the middle of the rest
    /// carries the rest's share (its force clamped to zero; what is left there, a density
    /// constant along `v` such as the stored energy of a patch aligned with `w`
    /// ([`FacePatch::aligned_with`]), is exact with it).
    pub fn for_each_node_clamped(
        &self,
        order: QuadratureOrder,
        sign: impl Fn(f64) -> (f64, f64),
        visit: &mut impl FnMut(Point3<f64>, f64),
    ) {
        let (xs_v, ws_v) = rule(order.across);
        self.for_each_column(order.along, 1, |u, half_u, wu, lo, hi| {
            let (a, b) = sign(u);
            // The pressing part [plo, phi] of the column and the middle of the clamped rest.
            let (plo, phi, rest_mid) = if b > 0.0 {
                let cut = (-a / b).clamp(lo, hi);
                (cut, hi, 0.5 * (lo + cut))
            } else if b < 0.0 {
                let cut = (-a / b).clamp(lo, hi);
                (lo, cut, 0.5 * (cut + hi))
            } else if a > 0.0 {
                (lo, hi, lo)
            } else {
                (hi, hi, 0.5 * (lo + hi))
            };
            let base = self.column_base(u);
            if phi > plo {
                let (vm, half_v) = (0.5 * (plo + phi), 0.5 * (phi - plo));
                for (xv, wv) in xs_v.iter().zip(ws_v) {
                    let v = vm + half_v * xv;
                    visit(base + self.axis_v * v, 0.25 * half_u * wu * half_v * wv);
                }
            }
            let rest = (hi - lo) - (phi - plo);
            if rest > 0.0 {
                visit(base + self.axis_v * rest_mid, 0.25 * half_u * wu * rest);
            }
        });
    }

    /// Calls `column(u, half_u, w_u, lo, hi)` for each of the `along` Gauss nodes `u` of
    /// every slice (each slice between vertices cut into `parts` equal slices): the slice's
    /// half width, the node's weight, and the polygon's extent `lo < v < hi` at `u`.
    fn for_each_column(
        &self,
        along: usize,
        parts: usize,
        mut column: impl FnMut(f64, f64, f64, f64, f64),
    ) {
        let mut us = [0.0; MAX_VERTICES];
        for (u, p) in us.iter_mut().zip(&self.verts[..self.len]) {
            *u = p[0];
        }
        let us = &mut us[..self.len];
        us.sort_unstable_by(f64::total_cmp);
        let (xs_u, ws_u) = rule(along);
        let parts = parts.max(1);
        for k in 1..us.len() {
            let (ua, ub) = (us[k - 1], us[k]);
            if ub <= ua {
                continue;
            }
            let Some((lower, upper)) = self.chains_at(0.5 * (ua + ub)) else {
                continue;
            };
            let (lower, upper) = (
                (lower.0 - lower.1 * 0.5 * (ua + ub), lower.1),
                (upper.0 - upper.1 * 0.5 * (ua + ub), upper.1),
            );
            for part in 0..parts {
                let u0 = ua + (ub - ua) * part as f64 / parts as f64;
                let u1 = ua + (ub - ua) * (part + 1) as f64 / parts as f64;
                let mid = 0.5 * (u0 + u1);
                let half_u = 0.5 * (u1 - u0);
                let lower = (lower.0 + lower.1 * mid, lower.1);
                let upper = (upper.0 + upper.1 * mid, upper.1);
                for (xu, wu) in xs_u.iter().zip(ws_u) {
                    let u = mid + half_u * xu;
                    let (lo, hi) = (lower.0 + lower.1 * (u - mid), upper.0 + upper.1 * (u - mid));
                    if hi > lo {
                        column(u, half_u, *wu, lo, hi);
                    }
                }
            }
        }
    }

    /// The lower and upper boundary of the polygon over the slice through `u` (strictly
    /// between two vertices' `u`): each as (value at `u`, slope dv/du).
    fn chains_at(&self, u: f64) -> Option<((f64, f64), (f64, f64))> {
        let mut lower: Option<(f64, f64)> = None;
        let mut upper: Option<(f64, f64)> = None;
        for i in 0..self.len {
            let p = self.verts[i];
            let q = self.verts[next(i, self.len)];
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
}

/// The vertex after `i` of a polygon of `len` vertices: `(i + 1) % len` without the
/// integer division (clipping and slicing walk every edge of every part).
#[inline]
fn next(i: usize, len: usize) -> usize {
    if i + 1 == len {
        0
    } else {
        i + 1
    }
}

#[inline]
fn rule(n: usize) -> (&'static [f64], &'static [f64]) {
    let i = n.clamp(1, 5) - 1;
    (GL_NODES[i], GL_WEIGHTS[i])
}

/// The six faces of an inner box of half extents `inner` placed by `pose`: (centre, axis_u,
/// axis_v) in the world, each face's axes spanning it (`|u|, |v| <= 1`).
pub fn inner_box_faces(
    inner: &Vector3<f64>,
    pose: &nalgebra::Isometry3<f64>,
) -> [(Point3<f64>, Vector3<f64>, Vector3<f64>); 6] {
    let r = pose.rotation.to_rotation_matrix();
    let axes = [
        r.matrix().column(0),
        r.matrix().column(1),
        r.matrix().column(2),
    ];
    let c = Point3::from(pose.translation.vector);
    let mut out = [(c, Vector3::zeros(), Vector3::zeros()); 6];
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let normal = axes[k] * inner[k];
        let au = axes[i] * inner[i];
        let av = axes[j] * inner[j];
        out[2 * k] = (c + normal, au, av);
        out[2 * k + 1] = (c - normal, au, av);
    }
    out
}
