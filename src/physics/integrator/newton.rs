//! Simplified Newton iteration on one implicit stage `z - h d f(t, z) = rhs`.

use super::*;

impl Integrator {
    /// Solves `z - h*d*f(ts, z) = rhs` by simplified Newton starting from `self.z`;
    /// stores f(ts, z) in k[out_k]. Returns false when Newton does not converge.
    pub(super) fn newton(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        ts: f64,
        hd: f64,
        y0: &[f64],
        out_k: usize,
    ) -> bool {
        self.last_update = f64::INFINITY;
        let mut prev = f64::INFINITY;
        let contact_aware = self.contact_aware();
        let frozen = self.frozen_patches();
        self.newton_z_is_new = false;
        for iter in 0..10 {
            let mut fz = std::mem::take(&mut self.fz);
            ws.linearize = contact_aware;
            ws.jacobian_scope = JacobianScope::NewtonMatrix;
            if frozen {
                ws.geometry.set_mode(GeometryMode::Frozen);
            }
            sys.derivative(ts, &self.z, &mut fz, ws);
            ws.geometry.set_mode(GeometryMode::Compute);
            ws.linearize = false;
            ws.jacobian_scope = JacobianScope::Exact;
            self.stats.rhs_evals += 1;
            for i in 0..self.n {
                self.tmp[i] = -(self.z[i] - hd * fz[i] - self.rhs[i]);
            }
            self.fz = fz;
            // The residual itself must be within tolerance once the updates have converged:
            // a stale Jacobian can make updates small while the equation is far from solved.
            let residual = self.weighted_norm(&self.tmp, y0, &self.z);
            if !residual.is_finite() {
                return false;
            }
            if iter > 0 && residual < 0.1 {
                let theta = if prev.is_finite() {
                    self.last_update / prev
                } else {
                    1.0
                };
                if theta < 0.9 || self.last_update < 1e-3 {
                    for i in 0..self.n {
                        self.k[out_k][i] = (self.z[i] - self.rhs[i]) / hd;
                    }
                    if iter > 3 {
                        self.jac_age = u32::MAX; // slow: refresh next step
                    }
                    return true;
                }
            }
            if contact_aware && !self.factorize_at_iterate(sys, ws, hd, ts) {
                return false;
            }
            let mut dz = std::mem::take(&mut self.tmp);
            self.solve_in_place(&mut dz);
            for i in 0..self.n {
                self.z[i] += dz[i];
            }
            let norm = self.weighted_norm(&dz, y0, &self.z);
            self.tmp = dz;
            if !norm.is_finite() {
                return false;
            }
            if contact_aware {
                // Hairer-Wanner II IV.8: with contraction θ the distance of the new iterate
                // to the solution is at most θ/(1-θ) times the update; at the first iteration
                // θ comes from the previous solve.
                let eta = if iter == 0 {
                    self.newton_eta.max(1e-2).powf(0.8)
                } else {
                    let theta = norm / self.last_update;
                    if theta >= 0.99 {
                        return false;
                    }
                    theta / (1.0 - theta)
                };
                if iter > 0 {
                    self.newton_eta = eta;
                }
                if eta * norm <= NEWTON_KAPPA {
                    for i in 0..self.n {
                        self.k[out_k][i] = (self.z[i] - self.rhs[i]) / hd;
                    }
                    self.last_dz.copy_from_slice(&self.tmp);
                    self.newton_z_is_new = true;
                    return true;
                }
            }
            if iter > 1 && norm > 0.9 * self.last_update {
                return false;
            }
            prev = self.last_update;
            self.last_update = norm;
        }
        false
    }
}
