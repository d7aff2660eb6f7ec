//! One Jacobian block per track for the exactly integrated face contact: its quadrature nodes'
//! force derivatives summed into moments about a reference point as they are evaluated, and
//! the blocks of
//! [`MultibodySystem::contact_jacobian`](crate::physics::system::MultibodySystem::contact_jacobian)
//! built from those moments once per track instead of once per node.
//!
//! Why it is the same matrix: every term of a node's block is a product of the node's own
//! derivatives (`∂F/∂f_n`, `∂f_n/∂w`, `∂F/∂v_rel`, `F`) with cross-product matrices of its
//! levers `r_k = p − x_k`, `r_c = c − x_a` (each at most once on either side). With
//! `q = p − o`, `q_c = c − o` and `e_k = o − x_k` for a reference point `o`,
//! `[r_k]× = [q]× + [e_k]×`, so the sum over the nodes is a fixed combination of the sums of
//! the products with `[q]×`, `[q_c]×` and of the plain derivatives, and `e_k` enters once per
//! track. The result equals the per-node sum up to round-off (tested on random nodes).

use super::TrackLinearization;
use crate::physics::body::BodyFrame;
use nalgebra::{Matrix3, Point3, Vector3};

/// The force (rows 0-2) and the torque about the target's centre of mass (rows 3-5) on one
/// body, differentiated by another body's `[δx, δθ, δv, δω_world]` (columns).
pub(crate) type Matrix6x12 = nalgebra::SMatrix<f64, 6, 12>;

/// A track's node derivatives as moments about `origin` (the first node's force point).
///
/// Per node: `g = ∂F/∂f_n`, `a = ∂f_n/∂w`, `D = ∂F/∂v_rel` (slip and rate), `F`, the normal
/// `n`, `q = p − o`, `q_c = c − o`, and `u = ω_b − ω_a` of the evaluation.
#[derive(Debug, Clone, Copy)]
pub struct TrackMoments {
    /// Body carrying the pieces (force +F).
    pub body_a: usize,
    /// Body carrying the faces (force −F).
    pub body_b: usize,
    /// The reference point `o`, world.
    origin: Point3<f64>,
    /// `ω_b − ω_a` at the evaluation, rad/s, world.
    spin: Vector3<f64>,
    /// Number of nodes summed.
    nodes: usize,
    /// `Σ a g nᵀ`.
    g_n: Matrix3<f64>,
    /// `Σ a g (q × n)ᵀ`.
    g_qn: Matrix3<f64>,
    /// `Σ a (q × g) nᵀ`.
    qg_n: Matrix3<f64>,
    /// `Σ a (q × g)(q × n)ᵀ`.
    qg_qn: Matrix3<f64>,
    /// `Σ D`.
    d: Matrix3<f64>,
    /// `Σ D [q]×`.
    d_q: Matrix3<f64>,
    /// `Σ [q]× D`.
    q_d: Matrix3<f64>,
    /// `Σ [q]× D [q]×`.
    q_d_q: Matrix3<f64>,
    /// `Σ D q_c`.
    d_qc: Vector3<f64>,
    /// `Σ (u·q_c) D`.
    u_qc_d: Matrix3<f64>,
    /// `Σ q × D q_c`.
    q_d_qc: Vector3<f64>,
    /// `Σ (u·q_c) [q]× D`.
    u_qc_q_d: Matrix3<f64>,
    /// `Σ F`.
    force: Vector3<f64>,
    /// `Σ q × F`.
    q_force: Vector3<f64>,
    /// `Σ [F]× [q_c]×`.
    force_qc: Matrix3<f64>,
}

/// A part's density moments for [`TrackMoments::add_part`]: about `origin` (world), with
/// `a = ∂f_n/∂w` (N/m per unit share), `b = ∂f_n/∂ẇ` (N·s/m) and the normal force `f_n` (N)
/// integrated against the part's share (each sum is what the nodes' `Σ` would be for a rule
/// exact on the part).
#[derive(Debug, Clone, Copy)]
pub(super) struct PartDensities {
    /// The reference point, world.
    pub(super) origin: Point3<f64>,
    /// The part's normal (the face's), world.
    pub(super) normal: Vector3<f64>,
    /// `Σ a`, `Σ a q`, `Σ a q qᵀ`.
    pub(super) a0: f64,
    pub(super) a1: Vector3<f64>,
    pub(super) a2: Matrix3<f64>,
    /// `Σ b`, `Σ b q`, `Σ b q qᵀ`.
    pub(super) b0: f64,
    pub(super) b1: Vector3<f64>,
    pub(super) b2: Matrix3<f64>,
    /// `Σ f_n`, `Σ f_n q`.
    pub(super) f0: f64,
    pub(super) f1: Vector3<f64>,
}

impl PartDensities {
    /// No density yet, about `origin` with `normal`: what a part's sums start from.
    pub(super) fn empty(origin: Point3<f64>, normal: Vector3<f64>) -> Self {
        Self {
            origin,
            normal,
            a0: 0.0,
            a1: Vector3::zeros(),
            a2: Matrix3::zeros(),
            b0: 0.0,
            b1: Vector3::zeros(),
            b2: Matrix3::zeros(),
            f0: 0.0,
            f1: Vector3::zeros(),
        }
    }
}

/// `M [q]×`, row by row `(m_i × q)ᵀ`: the same sums as nalgebra's product with
/// `q.cross_matrix()` in the same order, without the products with its zeros (bit for bit up
/// to the sign of a zero).
#[inline]
fn times_cross(m: &Matrix3<f64>, q: &Vector3<f64>) -> Matrix3<f64> {
    let mut out = Matrix3::zeros();
    for i in 0..3 {
        let (r0, r1, r2) = (m[(i, 0)], m[(i, 1)], m[(i, 2)]);
        out[(i, 0)] = r1 * q[2] - r2 * q[1];
        out[(i, 1)] = r2 * q[0] - r0 * q[2];
        out[(i, 2)] = r0 * q[1] - r1 * q[0];
    }
    out
}

/// `[q]× M`, column by column `q × m_j`: as [`times_cross`], nalgebra's product's sums
/// without the products with zeros.
#[inline]
fn cross_times(q: &Vector3<f64>, m: &Matrix3<f64>) -> Matrix3<f64> {
    let mut out = Matrix3::zeros();
    for j in 0..3 {
        let (c0, c1, c2) = (m[(0, j)], m[(1, j)], m[(2, j)]);
        out[(0, j)] = q[1] * c2 - q[2] * c1;
        out[(1, j)] = q[2] * c0 - q[0] * c2;
        out[(2, j)] = q[0] * c1 - q[1] * c0;
    }
    out
}

impl TrackMoments {
    /// Empty moments of a track between `body_a` (frame `fa`) and `body_b` (frame `fb`).
    pub(super) fn new(body_a: usize, body_b: usize, fa: &BodyFrame, fb: &BodyFrame) -> Self {
        let z = Matrix3::zeros();
        Self {
            body_a,
            body_b,
            origin: Point3::origin(),
            spin: fb.angular_velocity - fa.angular_velocity,
            nodes: 0,
            g_n: z,
            g_qn: z,
            qg_n: z,
            qg_qn: z,
            d: z,
            d_q: z,
            q_d: z,
            q_d_q: z,
            d_qc: Vector3::zeros(),
            u_qc_d: z,
            q_d_qc: Vector3::zeros(),
            u_qc_q_d: z,
            force: Vector3::zeros(),
            q_force: Vector3::zeros(),
            force_qc: z,
        }
    }

    /// True when no node was added.
    pub fn is_empty(&self) -> bool {
        self.nodes == 0
    }

    /// Adds one node's derivatives (the fields of a [`TrackLinearization`]).
    #[inline]
    pub(super) fn add(&mut self, lin: &TrackLinearization) {
        if self.nodes == 0 {
            self.origin = lin.point;
        }
        self.nodes += 1;
        let n = lin.normal;
        let g = lin.dforce_dfn * lin.dfn_dw;
        let q = lin.point - self.origin;
        let qc = lin.centre - self.origin;
        let qn = q.cross(&n);
        let qg = q.cross(&g);
        self.g_n += g * n.transpose();
        self.g_qn += g * qn.transpose();
        self.qg_n += qg * n.transpose();
        self.qg_qn += qg * qn.transpose();
        let d = lin.dforce_slip_with_rate(&lin.dforce_dfn, &n);
        let d_q = times_cross(&d, &q);
        let q_d = cross_times(&q, &d);
        self.d += d;
        self.d_q += d_q;
        self.q_d += q_d;
        self.q_d_q += times_cross(&q_d, &q);
        if self.spin != Vector3::zeros() {
            // D [u]× [q_c]× = (D q_c) uᵀ − (u·q_c) D: the sums of the two parts.
            let d_qc = d * qc;
            let u_qc = self.spin.dot(&qc);
            self.d_qc += d_qc;
            self.u_qc_d += d * u_qc;
            self.q_d_qc += q.cross(&d_qc);
            self.u_qc_q_d += q_d * u_qc;
        }
        self.force += lin.force;
        self.q_force += q.cross(&lin.force);
        // [F]× [q_c]× = q_c Fᵀ − (F·q_c) I.
        self.force_qc +=
            qc * lin.force.transpose() - Matrix3::from_diagonal_element(lin.force.dot(&qc));
    }

    /// Adds a whole part's derivatives at once (the reduced face law, `reduced.rs`): the sums
    /// [`TrackMoments::add`] would take over a continuum of nodes on the part, all with the
    /// same normal `n`, the same `∂F/∂f_n = g₀` (friction per part) and no slip derivative of
    /// their own, given the part's density moments about `origin` (world points `p` of the
    /// nodes, `q = p − origin`): `Σ a`, `Σ a q`, `Σ a q qᵀ` of `a = ∂f_n/∂w`, the same of
    /// `b = ∂f_n/∂ẇ`, and `Σ f_n`, `Σ f_n q` of the normal force; `radius` is the balls'
    /// (`c = p + radius n`). Each sum of [`TrackMoments`] is then a product of these with
    /// `g₀` and `n` (the node terms are linear in `a`, `b`, `f_n` and at most quadratic in `q`).
    pub(super) fn add_part(&mut self, part: &PartDensities, g0: &Vector3<f64>, radius: f64) {
        if self.nodes == 0 {
            self.origin = part.origin;
        }
        self.nodes += 1;
        let n = part.normal;
        // The part's moments about the track's origin: q = q_part + e.
        let e = part.origin - self.origin;
        let shift = |m0: f64, m1: &Vector3<f64>, m2: &Matrix3<f64>| {
            let m1s = m1 + e * m0;
            let m2s = m2 + m1 * e.transpose() + e * m1.transpose() + e * e.transpose() * m0;
            (m1s, m2s)
        };
        let (a1, a2) = shift(part.a0, &part.a1, &part.a2);
        let (b1, b2) = shift(part.b0, &part.b1, &part.b2);
        let f1 = part.f1 + e * part.f0;
        let (a0, b0, f0) = (part.a0, part.b0, part.f0);
        let gx = g0.cross_matrix();
        let nx = n.cross_matrix();
        // Σ a g nᵀ, Σ a g (q × n)ᵀ, Σ a (q × g) nᵀ, Σ a (q × g)(q × n)ᵀ = −[g]× Σ a q qᵀ [n]×.
        self.g_n += g0 * n.transpose() * a0;
        self.g_qn += g0 * a1.cross(&n).transpose();
        self.qg_n += a1.cross(g0) * n.transpose();
        self.qg_qn -= gx * a2 * nx;
        // D = −b g nᵀ at every node: Σ D, Σ D [q]× (nᵀ [q]× = (n × q)ᵀ), Σ [q]× D,
        // Σ [q]× D [q]× = −Σ b (q × g)(n × q)ᵀ = −[g]× Σ b q qᵀ [n]×.
        self.d -= g0 * n.transpose() * b0;
        self.d_q -= g0 * n.cross(&b1).transpose();
        self.q_d -= b1.cross(g0) * n.transpose();
        self.q_d_q -= gx * b2 * nx;
        if self.spin != Vector3::zeros() {
            // q_c = q + radius n.
            let u = self.spin;
            let b_nqc = n.dot(&b1) + radius * b0;
            self.d_qc -= g0 * b_nqc;
            self.u_qc_d -= g0 * n.transpose() * (u.dot(&b1) + radius * u.dot(&n) * b0);
            self.q_d_qc -= (b2 * n + b1 * radius).cross(g0);
            self.u_qc_q_d -= (b2 * u + b1 * (radius * u.dot(&n))).cross(g0) * n.transpose();
        }
        // F = g f_n at every node.
        self.force += g0 * f0;
        self.q_force += f1.cross(g0);
        let fc = f1 + n * (radius * f0);
        self.force_qc += fc * g0.transpose() - Matrix3::from_diagonal_element(g0.dot(&fc));
    }

    /// Adds the track's blocks to `blocks` (`nb × nb`, source body `k` by target body `m`),
    /// for the bodies `dynamic` says move: the per-node blocks of
    /// [`MultibodySystem::contact_jacobian`](crate::physics::system::MultibodySystem::contact_jacobian)
    /// summed over the nodes.
    pub(crate) fn add_blocks(
        &self,
        frames: &[BodyFrame],
        dynamic: impl Fn(usize) -> bool,
        blocks: &mut [Option<Matrix6x12>],
    ) {
        if self.nodes == 0 {
            return;
        }
        let nb = frames.len();
        let ends = [(self.body_a, 1.0), (self.body_b, -1.0)];
        let omega_a = frames[self.body_a].angular_velocity;
        let omega_b = frames[self.body_b].angular_velocity;
        let u = self.spin;
        let e_a = (self.origin.coords - frames[self.body_a].position).cross_matrix();
        let w_a = omega_a.cross_matrix();
        let w_b = omega_b.cross_matrix();
        let u_x = u.cross_matrix();
        // Σ [F]× [r_c]× with r_c = q_c + e_a.
        let force_rc = self.force_qc + self.force.cross_matrix() * e_a;
        for &(k, sign_k) in &ends {
            if !dynamic(k) {
                continue;
            }
            let e_k = (self.origin.coords - frames[k].position).cross_matrix();
            // Σ over the nodes of the force derivative (3 × 12) and of [q]× times it.
            let mut df = nalgebra::SMatrix::<f64, 3, 12>::zeros();
            let mut q_df = nalgebra::SMatrix::<f64, 3, 12>::zeros();
            // δx: −σ (a g nᵀ + D [ω_b]×).
            df.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&((self.g_n + self.d * w_b) * -sign_k));
            q_df.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&((self.qg_n + self.q_d * w_b) * -sign_k));
            // δθ: −σ a g (r_k × n)ᵀ, (r_k × n)ᵀ = (q × n)ᵀ − nᵀ [e_k]×; and for body a the
            // turn of v_rel: D ([u]× [r_c]× + [r_k]× [ω_a]×).
            let mut d_theta = (self.g_qn - self.g_n * e_k) * -sign_k;
            let mut q_d_theta = (self.qg_qn - self.qg_n * e_k) * -sign_k;
            if sign_k > 0.0 {
                let d_u_qc = self.d_qc * u.transpose() - self.u_qc_d;
                let q_d_u_qc = self.q_d_qc * u.transpose() - self.u_qc_q_d;
                d_theta += d_u_qc + self.d * u_x * e_a + self.d_q * w_a + self.d * e_a * w_a;
                q_d_theta +=
                    q_d_u_qc + self.q_d * u_x * e_a + self.q_d_q * w_a + self.q_d * e_a * w_a;
            }
            df.fixed_view_mut::<3, 3>(0, 3).copy_from(&d_theta);
            q_df.fixed_view_mut::<3, 3>(0, 3).copy_from(&q_d_theta);
            // δv, δω: σ D [I, −[r_k]×].
            df.fixed_view_mut::<3, 3>(0, 6)
                .copy_from(&(self.d * sign_k));
            q_df.fixed_view_mut::<3, 3>(0, 6)
                .copy_from(&(self.q_d * sign_k));
            df.fixed_view_mut::<3, 3>(0, 9)
                .copy_from(&((self.d_q + self.d * e_k) * -sign_k));
            q_df.fixed_view_mut::<3, 3>(0, 9)
                .copy_from(&((self.q_d_q + self.q_d * e_k) * -sign_k));
            for &(m, sign_m) in &ends {
                if !dynamic(m) {
                    continue;
                }
                let e_m = self.origin.coords - frames[m].position;
                let block = blocks[k * nb + m].get_or_insert_with(Matrix6x12::zeros);
                // Torque about x_m: Σ [r_m]× (·) = Σ [q]× (·) + [e_m]× Σ (·).
                let mut torque = (q_df + e_m.cross_matrix() * df) * sign_m;
                // The lever's own change at fixed force.
                if sign_k > 0.0 {
                    let mut theta = torque.fixed_view_mut::<3, 3>(0, 3);
                    if sign_m > 0.0 {
                        theta += force_rc;
                    } else {
                        theta -= force_rc;
                    }
                }
                if sign_m < 0.0 {
                    let mut x = torque.fixed_view_mut::<3, 3>(0, 0);
                    x += self.force.cross_matrix() * sign_k;
                }
                if m == k {
                    // The body-frame torque Rᵀ τ turns with the body: δ(Rᵀ τ) = Rᵀ [τ]× δθ.
                    let tau = (self.q_force + e_m.cross(&self.force)) * sign_m;
                    let mut theta = torque.fixed_view_mut::<3, 3>(0, 3);
                    theta += tau.cross_matrix();
                }
                let mut rows = block.fixed_view_mut::<3, 12>(0, 0);
                rows += df * sign_m;
                let mut rows = block.fixed_view_mut::<3, 12>(3, 0);
                rows += torque;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cross_products_are_the_matrix_products_with_the_cross_matrix() {
        // Bit for bit on non-zero results: the same three products summed in the same order,
        // less the products with the cross matrix's zeros (which add nothing).
        let m = Matrix3::new(0.3, -1.7, 2.2, 4.1e-3, 9.0, -0.25, 1.0 / 3.0, -7.5e2, 0.61);
        let q = Vector3::new(-2.5e-3, 7.0e-4, 1.3e-2);
        let qx = q.cross_matrix();
        for (got, want) in [(times_cross(&m, &q), m * qx), (cross_times(&q, &m), qx * m)] {
            for (a, b) in got.iter().zip(want.iter()) {
                assert_eq!(a.to_bits(), b.to_bits(), "{got} vs {want}");
            }
        }
    }

    #[test]
    fn a_parts_moments_are_the_sum_of_its_nodes_records() {
        // Nodes sharing a normal and ∂F/∂f_n (friction per part), each with its own a, b, f_n
        // and point: `add_part` of their density sums (about a point away from the track's
        // origin, so the shift is exercised) equals `add` node by node, field by field, to
        // round-off, with the track spinning (the spin terms) and a node of another part first.
        use nalgebra::UnitQuaternion;
        let frame = |omega: Vector3<f64>| BodyFrame {
            position: Vector3::new(0.1, -0.2, 0.3),
            rotation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: omega,
        };
        let (fa, fb) = (
            frame(Vector3::new(0.3, -1.2, 0.7)),
            frame(Vector3::new(-0.4, 0.1, 0.2)),
        );
        let n = Vector3::new(0.1, 0.97, -0.2).normalize();
        let g0 = n - Vector3::new(0.9, 0.0, 0.4).normalize() * 0.17;
        let radius = 5e-4;
        let mut per_node = TrackMoments::new(0, 1, &fa, &fb);
        let mut per_part = TrackMoments::new(0, 1, &fa, &fb);
        let first = TrackLinearization {
            body_a: 0,
            body_b: 1,
            deepest_point: Point3::new(0.02, 0.01, -0.03),
            point: Point3::new(0.02, 0.01, -0.03),
            centre: Point3::new(0.02, 0.0105, -0.03),
            force: Vector3::new(1.0, 30.0, -2.0),
            normal: Vector3::y(),
            dfn_dw: 4e6,
            dfn_dwdot: 2e4,
            dforce_dfn: Vector3::new(0.1, 1.0, 0.0),
            dforce_dslip: Matrix3::new(-3.0, 0.1, 0.0, 0.1, 0.0, 0.2, 0.0, 0.2, -5.0),
        };
        per_node.add(&first);
        per_part.add(&first);
        let origin = Point3::new(0.05, -0.01, 0.02);
        let mut part = PartDensities::empty(origin, n);
        for i in 0..23 {
            let x = i as f64;
            let p = Point3::new(
                0.04 + 0.003 * (1.3 * x).sin(),
                -0.012 + 0.002 * (0.7 * x).cos(),
                0.01 + 0.02 * (0.31 * x).sin(),
            );
            let (a, b, f) = (
                1e6 * (1.5 + (2.1 * x).sin()),
                3e3 * (1.2 + (0.9 * x).cos()),
                2.0 + x,
            );
            per_node.add(&TrackLinearization {
                body_a: 0,
                body_b: 1,
                deepest_point: p,
                point: p,
                centre: p + n * radius,
                force: g0 * f,
                normal: n,
                dfn_dw: a,
                dfn_dwdot: b,
                dforce_dfn: g0,
                dforce_dslip: Matrix3::zeros(),
            });
            let q = p - origin;
            part.a0 += a;
            part.a1 += q * a;
            part.a2 += q * q.transpose() * a;
            part.b0 += b;
            part.b1 += q * b;
            part.b2 += q * q.transpose() * b;
            part.f0 += f;
            part.f1 += q * f;
        }
        per_part.add_part(&part, &g0, radius);
        let pairs: [(&Matrix3<f64>, &Matrix3<f64>); 11] = [
            (&per_node.g_n, &per_part.g_n),
            (&per_node.g_qn, &per_part.g_qn),
            (&per_node.qg_n, &per_part.qg_n),
            (&per_node.qg_qn, &per_part.qg_qn),
            (&per_node.d, &per_part.d),
            (&per_node.d_q, &per_part.d_q),
            (&per_node.q_d, &per_part.q_d),
            (&per_node.q_d_q, &per_part.q_d_q),
            (&per_node.u_qc_d, &per_part.u_qc_d),
            (&per_node.u_qc_q_d, &per_part.u_qc_q_d),
            (&per_node.force_qc, &per_part.force_qc),
        ];
        for (k, (a, b)) in pairs.iter().enumerate() {
            assert!(
                (*a - *b).norm() <= 1e-12 * a.norm().max(1e-300),
                "sum {k}: {a} vs {b}"
            );
        }
        for (k, (a, b)) in [
            (per_node.d_qc, per_part.d_qc),
            (per_node.q_d_qc, per_part.q_d_qc),
            (per_node.force, per_part.force),
            (per_node.q_force, per_part.q_force),
        ]
        .iter()
        .enumerate()
        {
            assert!((a - b).norm() <= 1e-12 * a.norm(), "vector {k}: {a} vs {b}");
        }
    }
}
