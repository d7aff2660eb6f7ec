//! The Newton systems `(I - a J) x = b` of the implicit integrators, solved by eliminating the
//! pose entries first.
//!
//! Each dynamic body's state is its pose `p = (x, q)` (7 entries) and velocity
//! `u = (v, ω_body)` (6). The pose rates are pure kinematics of the same body, `ẋ = v` and
//! `q̇ = ½ q ⊗ (0, ω)`, so `J_pp` is block diagonal (zero for `x`, a 4×4 block `Q_q` for `q`) and
//! `J_pu` too (`X_v ≈ I` from `v` to `ẋ`, a 4×3 block `Q_ω` from `ω` to `q̇`). With
//! `P = I - a J_pp` the system
//!
//! ```text
//! [ P        -a J_pu   ] [dp]   [b_p]
//! [ -a J_up  I - a J_uu] [du] = [b_u]
//! ```
//!
//! is solved exactly through the velocity Schur complement
//! `S = I - a J_uu - a² J_up P⁻¹ J_pu`: `S du = b_u + a J_up P⁻¹ b_p`, then
//! `dp = P⁻¹ (b_p + a J_pu du)`. One body factors a 6×6 matrix instead of 13×13 (two bodies
//! 12×12 instead of 26×26), a tenth of the work, and the result is the same solution.

use super::body::BODY_STATE_LEN;

/// Pose entries per body (position 3, quaternion 4).
const POSE: usize = 7;
/// Velocity entries per body (linear 3, angular 3).
const VEL: usize = 6;

/// Factorisation of `I - a J` for `bodies` dynamic bodies (state laid out body after body).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct NewtonLu {
    bodies: usize,
    /// `a` of the factored matrix.
    scale: f64,
    /// Per body: `X_v = ∂ẋ/∂v` (3×3, row-major).
    x_v: Vec<[f64; 9]>,
    /// Per body: `(I - a Q_q)⁻¹` (4×4, row-major).
    p_inv: Vec<[f64; 16]>,
    /// Per body: `(I - a Q_q)⁻¹ Q_ω` (4×3, row-major).
    w: Vec<[f64; 12]>,
    /// `J_up` (velocity rows × pose columns, `6 bodies × 7 bodies`, row-major).
    j_up: Vec<f64>,
    /// LU of the Schur complement `S`.
    schur: DenseLu,
    /// Scratch: `P⁻¹ b_p` and the reduced right-hand side.
    pose_tmp: Vec<f64>,
    vel_tmp: Vec<f64>,
}

impl NewtonLu {
    /// Solver for a system of `bodies` dynamic bodies.
    pub fn new(bodies: usize) -> Self {
        Self {
            bodies,
            scale: 0.0,
            x_v: vec![[0.0; 9]; bodies],
            p_inv: vec![[0.0; 16]; bodies],
            w: vec![[0.0; 12]; bodies],
            j_up: vec![0.0; VEL * bodies * POSE * bodies],
            schur: DenseLu::new(VEL * bodies),
            pose_tmp: vec![0.0; POSE * bodies],
            vel_tmp: vec![0.0; VEL * bodies],
        }
    }

    /// Number of dynamic bodies the solver is sized for.
    pub fn bodies(&self) -> usize {
        self.bodies
    }

    /// Factors `I - scale * jac` (`jac` column-major, `13 bodies` square). False when singular.
    pub fn factor_newton(&mut self, jac: &[f64], scale: f64) -> bool {
        let nb = self.bodies;
        let n = BODY_STATE_LEN * nb;
        let np = POSE * nb;
        let m = VEL * nb;
        let at = |row: usize, col: usize| jac[col * n + row];
        self.scale = scale;
        for k in 0..nb {
            let base = BODY_STATE_LEN * k;
            let mut x_v = [0.0; 9];
            for i in 0..3 {
                for j in 0..3 {
                    x_v[3 * i + j] = at(base + i, base + 7 + j);
                }
            }
            self.x_v[k] = x_v;
            let mut p = [0.0; 16];
            for i in 0..4 {
                for j in 0..4 {
                    let id = if i == j { 1.0 } else { 0.0 };
                    p[4 * i + j] = id - scale * at(base + 3 + i, base + 3 + j);
                }
            }
            let Some(p_inv) = invert4(&p) else {
                return false;
            };
            self.p_inv[k] = p_inv;
            let mut w = [0.0; 12];
            for i in 0..4 {
                for j in 0..3 {
                    w[3 * i + j] = (0..4)
                        .map(|l| p_inv[4 * i + l] * at(base + 3 + l, base + 10 + j))
                        .sum();
                }
            }
            self.w[k] = w;
        }
        // S = I - a J_uu - a² J_up (P⁻¹ J_pu), with P⁻¹ J_pu block diagonal: X_v for v, W for ω.
        let a2 = scale * scale;
        let s = self.schur.matrix_mut();
        for r in 0..m {
            let row = BODY_STATE_LEN * (r / VEL) + POSE + r % VEL;
            let j_up_row = &mut self.j_up[r * np..(r + 1) * np];
            let s_row = &mut s[r * m..(r + 1) * m];
            for k in 0..nb {
                let base = BODY_STATE_LEN * k;
                let mut jp = [0.0; POSE];
                for (i, v) in jp.iter_mut().enumerate() {
                    *v = at(row, base + i);
                }
                j_up_row[POSE * k..POSE * (k + 1)].copy_from_slice(&jp);
                let (x_v, w) = (&self.x_v[k], &self.w[k]);
                for j in 0..3 {
                    let via_x = jp[0] * x_v[j] + jp[1] * x_v[3 + j] + jp[2] * x_v[6 + j];
                    let via_q =
                        jp[3] * w[j] + jp[4] * w[3 + j] + jp[5] * w[6 + j] + jp[6] * w[9 + j];
                    s_row[VEL * k + j] = -scale * at(row, base + POSE + j) - a2 * via_x;
                    s_row[VEL * k + 3 + j] = -scale * at(row, base + POSE + 3 + j) - a2 * via_q;
                }
            }
            s_row[r] += 1.0;
        }
        self.schur.factor_in_place()
    }

    /// Solves `(I - a J) x = b` in place (`b` in state order).
    pub fn solve(&mut self, b: &mut [f64]) {
        let nb = self.bodies;
        let np = POSE * nb;
        let a = self.scale;
        // P⁻¹ b_p.
        for k in 0..nb {
            let base = BODY_STATE_LEN * k;
            let t = &mut self.pose_tmp[POSE * k..POSE * (k + 1)];
            t[..3].copy_from_slice(&b[base..base + 3]);
            for i in 0..4 {
                t[3 + i] = (0..4)
                    .map(|l| self.p_inv[k][4 * i + l] * b[base + 3 + l])
                    .sum();
            }
        }
        // b_u + a J_up P⁻¹ b_p, then S du = that.
        for (r, v) in self.vel_tmp.iter_mut().enumerate() {
            let row = &self.j_up[r * np..(r + 1) * np];
            let coupled: f64 = row.iter().zip(&self.pose_tmp).map(|(j, t)| j * t).sum();
            *v = b[BODY_STATE_LEN * (r / VEL) + POSE + r % VEL] + a * coupled;
        }
        self.schur.solve(&mut self.vel_tmp);
        // dp = P⁻¹ b_p + a (P⁻¹ J_pu) du.
        for k in 0..nb {
            let base = BODY_STATE_LEN * k;
            let du = &self.vel_tmp[VEL * k..VEL * (k + 1)];
            let t = &self.pose_tmp[POSE * k..POSE * (k + 1)];
            for i in 0..3 {
                let coupled: f64 = (0..3).map(|j| self.x_v[k][3 * i + j] * du[j]).sum();
                b[base + i] = t[i] + a * coupled;
            }
            for i in 0..4 {
                let coupled: f64 = (0..3).map(|j| self.w[k][3 * i + j] * du[3 + j]).sum();
                b[base + 3 + i] = t[3 + i] + a * coupled;
            }
            b[base + POSE..base + BODY_STATE_LEN].copy_from_slice(du);
        }
    }
}

/// Inverse of a 4×4 row-major matrix by Gauss-Jordan elimination with partial pivoting.
fn invert4(m: &[f64; 16]) -> Option<[f64; 16]> {
    let mut a = *m;
    let mut inv = [0.0; 16];
    for i in 0..4 {
        inv[5 * i] = 1.0;
    }
    for k in 0..4 {
        let p = (k..4).max_by(|&i, &j| a[4 * i + k].abs().total_cmp(&a[4 * j + k].abs()))?;
        let pivot = a[4 * p + k];
        if pivot == 0.0 || !pivot.is_finite() {
            return None;
        }
        if p != k {
            for j in 0..4 {
                a.swap(4 * k + j, 4 * p + j);
                inv.swap(4 * k + j, 4 * p + j);
            }
        }
        let scale = 1.0 / pivot;
        for j in 0..4 {
            a[4 * k + j] *= scale;
            inv[4 * k + j] *= scale;
        }
        for i in (0..4).filter(|&i| i != k) {
            let f = a[4 * i + k];
            if f != 0.0 {
                for j in 0..4 {
                    a[4 * i + j] -= f * a[4 * k + j];
                    inv[4 * i + j] -= f * inv[4 * k + j];
                }
            }
        }
    }
    Some(inv)
}

/// Dense LU with partial pivoting (row-major, factored in place, allocated once): the Schur
/// complements are small (6 per body) and refactored often.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct DenseLu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl DenseLu {
    fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// The matrix to factor (row-major), filled by the caller.
    fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// Factors the matrix in place. False when singular.
    fn factor_in_place(&mut self) -> bool {
        let n = self.n;
        for k in 0..n {
            let mut p = k;
            let mut best = self.a[k * n + k].abs();
            for i in k + 1..n {
                let v = self.a[i * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return false;
            }
            self.piv[k] = p;
            if p != k {
                let (top, bottom) = self.a.split_at_mut(p * n);
                top[k * n..(k + 1) * n].swap_with_slice(&mut bottom[..n]);
            }
            // Rows below k subtract multiples of row k (slices: no index checks, vectorised).
            let (upper, lower) = self.a.split_at_mut((k + 1) * n);
            let pivot_row = &upper[k * n..];
            let inv = 1.0 / pivot_row[k];
            for row in lower.chunks_exact_mut(n) {
                let l = row[k] * inv;
                row[k] = l;
                if l != 0.0 {
                    for (x, &r) in row[k + 1..].iter_mut().zip(&pivot_row[k + 1..]) {
                        *x -= l * r;
                    }
                }
            }
        }
        true
    }

    /// Solves `A x = b` in place.
    fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        for (k, &p) in self.piv.iter().enumerate() {
            if p != k {
                b.swap(k, p);
            }
        }
        for (i, row) in self.a.chunks_exact(n).enumerate() {
            let s: f64 = row[..i].iter().zip(&b[..i]).map(|(a, x)| a * x).sum();
            b[i] -= s;
        }
        for (i, row) in self.a.chunks_exact(n).enumerate().rev() {
            let s: f64 = row[i + 1..]
                .iter()
                .zip(&b[i + 1..])
                .map(|(a, x)| a * x)
                .sum();
            b[i] = (b[i] - s) / row[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::{Rng, SeedableRng};

    /// A random Jacobian with the kinematic structure of `bodies` rigid bodies: `ẋ` depends on
    /// `v` only, `q̇` on `q` and `ω` of the same body; the accelerations on everything.
    fn structured_jacobian(bodies: usize, rng: &mut rand_chacha::ChaCha8Rng) -> Vec<f64> {
        let n = BODY_STATE_LEN * bodies;
        let mut jac = vec![0.0; n * n];
        let mut set = |row: usize, col: usize, v: f64| jac[col * n + row] = v;
        for k in 0..bodies {
            let b = BODY_STATE_LEN * k;
            for i in 0..3 {
                set(b + i, b + 7 + i, 1.0 + 1e-9 * rng.gen_range(-1.0..1.0));
            }
            for i in 0..4 {
                for j in 0..4 {
                    set(b + 3 + i, b + 3 + j, rng.gen_range(-50.0..50.0));
                }
                for j in 0..3 {
                    set(b + 3 + i, b + 10 + j, rng.gen_range(-0.5..0.5));
                }
            }
            for r in 7..13 {
                for col in 0..n {
                    // Stiff contact-like entries, 1e2..1e7 in size.
                    let mag = 10f64.powf(rng.gen_range(2.0..7.0));
                    set(b + r, col, mag * rng.gen_range(-1.0..1.0));
                }
            }
        }
        jac
    }

    #[test]
    fn block_elimination_solves_the_full_newton_system() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for bodies in 1..=3 {
            let n = BODY_STATE_LEN * bodies;
            for trial in 0..20 {
                let jac = structured_jacobian(bodies, &mut rng);
                let a = 10f64.powf(rng.gen_range(-8.0..-3.0));
                let full = DMatrix::from_fn(n, n, |i, j| {
                    let id = if i == j { 1.0 } else { 0.0 };
                    id - a * jac[j * n + i]
                });
                let b = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
                let expected = full.clone().lu().solve(&b).expect("regular");
                let mut lu = NewtonLu::new(bodies);
                assert!(lu.factor_newton(&jac, a));
                let mut x = b.as_slice().to_vec();
                lu.solve(&mut x);
                // Residual of the full system, relative to the size of its terms.
                let residual = &full * DVector::from_column_slice(&x) - &b;
                let scale = full.abs().max() * DVector::from_column_slice(&x).amax() + b.amax();
                assert!(
                    residual.amax() <= 1e-12 * scale,
                    "bodies {bodies} trial {trial}: residual {:e} of {scale:e}",
                    residual.amax()
                );
                let diff = (DVector::from_column_slice(&x) - &expected).amax();
                assert!(
                    diff <= 1e-8 * expected.amax(),
                    "bodies {bodies} trial {trial}"
                );
            }
        }
    }

    #[test]
    fn invert4_inverts() {
        let m = [
            4.0, 1.0, 0.0, 2.0, 1.0, 3.0, 1.0, 0.0, 0.0, 1.0, 5.0, 1.0, 2.0, 0.0, 1.0, 6.0,
        ];
        let inv = invert4(&m).expect("regular");
        for i in 0..4 {
            for j in 0..4 {
                let p: f64 = (0..4).map(|l| m[4 * i + l] * inv[4 * l + j]).sum();
                let id = if i == j { 1.0 } else { 0.0 };
                assert!((p - id).abs() < 1e-14);
            }
        }
        assert!(invert4(&[0.0; 16]).is_none());
    }
}
