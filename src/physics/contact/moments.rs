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
}
