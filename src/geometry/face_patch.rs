//! The exactly integrated face contact (issue 27; docs/models.md "Exact face contact"): the
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
//! The cut sides (a bounded face's edges crossing the patch) are where the region moves
//! relative to the material: their nodes ([`FacePatch::for_each_cut_node`]) carry the
//! boundary term of the energy's gradient (docs/models.md).
//!
//! Hot path: fixed-size arrays only, no heap allocation.

use super::bounded_face::PlacedFace;
use nalgebra::{Point3, Vector3};

/// Room for the vertices of a clipped face: the square's 4, one more per clipping line (the
/// `w = 0` line and up to four sides of a bounded face), with margin for repeated vertices.
const MAX_VERTICES: usize = 16;
/// Most cut sides: a rectangular face extent has four.
const MAX_CUTS: usize = 4;
/// Edge label of the square's own sides (material boundary: no boundary term).
const LABEL_SQUARE: u8 = 0;
/// Edge label of the `w = 0` line (the density vanishes there: no boundary term).
const LABEL_SURFACE: u8 = 1;
/// Edge label of cut `k`: `LABEL_CUT + k`.
const LABEL_CUT: u8 = 2;

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

/// `alpha + beta · ξ >= 0` on the kept side.
#[derive(Debug, Clone, Copy)]
struct Line {
    alpha: f64,
    beta: [f64; 2],
}

impl Line {
    #[inline]
    fn at(&self, p: [f64; 2]) -> f64 {
        self.alpha + self.beta[0] * p[0] + self.beta[1] * p[1]
    }
}

/// A side of a bounded face that cuts the patch.
#[derive(Debug, Clone, Copy)]
struct Cut {
    line: Line,
    /// World unit direction out of the face's extent across this side.
    outward: Vector3<f64>,
}

/// A node on a cut side, carrying the boundary term of the energy's gradient.
#[derive(Debug, Clone, Copy)]
pub struct CutNode {
    /// The material point (a ball centre on the inner face), world, m.
    pub centre: Point3<f64>,
    /// Its penetration `w`, m.
    pub penetration: f64,
    /// Line weight `L_ξ ω / (4 |∇_ξ g|)`, m: the generalized force on the piece is
    /// `weight · U'(w) · outward` with `U'(w) = k w^(e+1)/(e+1)` the energy per unit share.
    pub weight: f64,
    /// World unit direction out of the face's extent (the force's direction on the piece).
    pub outward: Vector3<f64>,
}

/// The pressed part of one inner-box face against one (possibly bounded) face.
#[derive(Debug, Clone, Copy)]
pub struct FacePatch {
    centre: Point3<f64>,
    axis_u: Vector3<f64>,
    axis_v: Vector3<f64>,
    depth: Line,
    verts: [[f64; 2]; MAX_VERTICES],
    labels: [u8; MAX_VERTICES],
    len: usize,
    cuts: [Option<Cut>; MAX_CUTS],
}

impl FacePatch {
    /// The part of the inner face `centre + u axis_u + v axis_v` (`|u|, |v| <= 1`, world, m)
    /// whose balls of `radius` penetrate `face`'s plane and lie over its extent; `None` when
    /// that part is empty.
    pub fn new(
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
            verts: [[0.0; 2]; MAX_VERTICES],
            labels: [LABEL_SQUARE; MAX_VERTICES],
            len: 4,
            cuts: [None; MAX_CUTS],
        };
        patch.verts[..4].copy_from_slice(&[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]);
        if !patch.clip(&depth, LABEL_SURFACE) {
            return None;
        }
        for (k, (outward, origin, bound)) in face.sides().enumerate().take(MAX_CUTS) {
            // g(x) = bound − outward·(x − origin) >= 0 over the extent.
            let line = Line {
                alpha: bound - outward.dot(&(centre - origin)),
                beta: [-outward.dot(&axis_u), -outward.dot(&axis_v)],
            };
            if patch.verts[..patch.len].iter().all(|&p| line.at(p) >= 0.0) {
                continue;
            }
            if !patch.clip(&line, LABEL_CUT + k as u8) {
                return None;
            }
            patch.cuts[k] = Some(Cut { line, outward });
        }
        Some(patch)
    }

    /// Sutherland–Hodgman clip of the polygon by `line` (keeping `line >= 0`), labelling the
    /// new side `label`; false when nothing of positive area is left.
    fn clip(&mut self, line: &Line, label: u8) -> bool {
        let mut out = [[0.0; 2]; MAX_VERTICES];
        let mut out_labels = [0u8; MAX_VERTICES];
        let mut m = 0;
        for i in 0..self.len {
            let p = self.verts[i];
            let q = self.verts[(i + 1) % self.len];
            let (gp, gq) = (line.at(p), line.at(q));
            let crossing = || {
                let t = gp / (gp - gq);
                [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
            };
            // (vertex, label of the side leaving it) to append, at most two.
            let (first, second) = match (gp >= 0.0, gq >= 0.0) {
                (true, true) => (Some((p, self.labels[i])), None),
                // p on the line: the side from p runs along it.
                (true, false) if gp == 0.0 => (Some((p, label)), None),
                (true, false) => (Some((p, self.labels[i])), Some((crossing(), label))),
                // q on the line is appended as the next p.
                (false, true) if gq > 0.0 => (Some((crossing(), self.labels[i])), None),
                (false, _) => (None, None),
            };
            for (v, l) in [first, second].into_iter().flatten() {
                if m < MAX_VERTICES {
                    out[m] = v;
                    out_labels[m] = l;
                    m += 1;
                }
            }
        }
        self.verts = out;
        self.labels = out_labels;
        self.len = m;
        m >= 3 && self.area_xi() > 0.0
    }

    /// Area of the polygon in `ξ` (the square's is 4).
    fn area_xi(&self) -> f64 {
        let mut twice = 0.0;
        for i in 0..self.len {
            let p = self.verts[i];
            let q = self.verts[(i + 1) % self.len];
            twice += p[0] * q[1] - q[0] * p[1];
        }
        0.5 * twice
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
        let mut us = [0.0; MAX_VERTICES];
        for (u, p) in us.iter_mut().zip(&self.verts[..self.len]) {
            *u = p[0];
        }
        let us = &mut us[..self.len];
        us.sort_unstable_by(f64::total_cmp);
        let (xs_u, ws_u) = rule(order.along);
        let (xs_v, ws_v) = rule(order.across);
        for k in 1..us.len() {
            let (u0, u1) = (us[k - 1], us[k]);
            if u1 <= u0 {
                continue;
            }
            let mid = 0.5 * (u0 + u1);
            let Some((lower, upper)) = self.chains_at(mid) else {
                continue;
            };
            let half_u = 0.5 * (u1 - u0);
            for (xu, wu) in xs_u.iter().zip(ws_u) {
                let u = mid + half_u * xu;
                let (lo, hi) = (lower.0 + lower.1 * (u - mid), upper.0 + upper.1 * (u - mid));
                if hi <= lo {
                    continue;
                }
                let (vm, half_v) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                for (xv, wv) in xs_v.iter().zip(ws_v) {
                    let v = vm + half_v * xv;
                    visit(self.point([u, v]), 0.25 * half_u * wu * half_v * wv);
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
            let q = self.verts[(i + 1) % self.len];
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

    /// Calls `visit` for every node of the cut sides (the bounded face's edges crossing the
    /// patch), `order.along` Gauss–Legendre nodes per side: exact for a line density of
    /// degree `2 m_u − 1` (`w^(e+1)` and its lever: degree `e + 2`).
    pub fn for_each_cut_node(&self, order: QuadratureOrder, visit: &mut impl FnMut(&CutNode)) {
        let (xs, ws) = rule(order.along);
        for i in 0..self.len {
            let label = self.labels[i];
            if label < LABEL_CUT {
                continue;
            }
            let Some(cut) = self.cuts[(label - LABEL_CUT) as usize] else {
                continue;
            };
            let p = self.verts[i];
            let q = self.verts[(i + 1) % self.len];
            let length = (q[0] - p[0]).hypot(q[1] - p[1]);
            let grad = cut.line.beta[0].hypot(cut.line.beta[1]);
            if !(length > 0.0 && grad > 0.0) {
                continue;
            }
            for (x, w) in xs.iter().zip(ws) {
                let t = 0.5 * (1.0 + x);
                let xi = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                visit(&CutNode {
                    centre: self.point(xi),
                    penetration: self.depth.at(xi),
                    weight: 0.5 * w * length / (4.0 * grad),
                    outward: cut.outward,
                });
            }
        }
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
    let axes = [r.matrix().column(0), r.matrix().column(1), r.matrix().column(2)];
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
