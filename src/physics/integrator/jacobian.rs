//! The Newton matrix `I - h d J`: the contact-free part by forward differences (or the whole
//! Jacobian), the contacts' analytic part at each iterate, factorisation and solves.

use super::*;

impl Integrator {
    pub(super) fn compute_jacobian(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) {
        if self.contact_aware() {
            self.compute_contact_free_jacobian(sys, ws, t, y);
        } else {
            self.compute_full_jacobian(sys, ws, t, y);
        }
        self.stats.jacobians += 1;
        self.jac_fresh = true;
        self.jac_age = 0;
        self.lu_valid = false;
    }

    /// Forward differences of the right-hand side without contacts: rigid-body kinematics,
    /// gyroscopic terms and force elements (no overlap geometry, a small fraction of a full
    /// right-hand side each).
    pub(super) fn compute_contact_free_jacobian(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) {
        let n = self.n;
        ws.skip_contacts = true;
        let mut reference = std::mem::take(&mut self.tmp);
        sys.derivative(t, y, &mut reference, ws);
        self.jac_y.copy_from_slice(y);
        for j in 0..n {
            self.difference_column(sys, ws, t, y, j, &reference);
        }
        self.tmp = reference;
        ws.skip_contacts = false;
        self.stats.contact_free_rhs_evals += n as u64 + 1;
    }

    pub(super) fn compute_full_jacobian(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) {
        // Forward differences around (t, y); f(t, y) is k[0] (valid: FSAL). A velocity column
        // leaves every pose unchanged and a pose column moves one body: contacts whose poses
        // are unchanged replay the geometry (bit-identical forces, no overlap computation).
        let n = self.n;
        self.jac_y.copy_from_slice(y);
        let reference = std::mem::take(&mut self.k[0]);
        // Velocity columns first: the first records the geometry at the unperturbed poses.
        let mut recorded = false;
        // Velocity entries (kinds 2 and 3): their columns keep all poses.
        let kind = std::mem::take(&mut self.state_kind);
        let velocity_column = |j: usize| kind[j] >= 2;
        let velocity_first = (0..n)
            .filter(|&j| velocity_column(j))
            .chain((0..n).filter(|&j| !velocity_column(j)));
        for j in velocity_first {
            let mode = if !velocity_column(j) {
                if recorded {
                    GeometryMode::ReplayExcept(self.column_body[j])
                } else {
                    GeometryMode::Compute
                }
            } else if recorded {
                GeometryMode::Replay
            } else {
                recorded = true;
                GeometryMode::Record
            };
            ws.geometry.set_mode(mode);
            self.difference_column(sys, ws, t, y, j, &reference);
            self.stats.rhs_evals += 1;
        }
        self.state_kind = kind;
        self.k[0] = reference;
        ws.geometry.set_mode(GeometryMode::Compute);
    }

    /// Column `j` of `jac` by a forward difference of the derivative around `(t, y)`, whose
    /// value there is `reference`; `jac_y` holds `y` on entry and on return.
    pub(super) fn difference_column(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        j: usize,
        reference: &[f64],
    ) {
        let n = self.n;
        let scale = self.abs_tol[j] * 1e3;
        let delta = 1.5e-8 * y[j].abs().max(scale);
        self.jac_y[j] = y[j] + delta;
        sys.derivative(t, &self.jac_y, &mut self.jac_f, ws);
        let col = &mut self.jac[j * n..(j + 1) * n];
        for i in 0..n {
            col[i] = (self.jac_f[i] - reference[i]) / delta;
        }
        self.jac_y[j] = y[j];
    }

    /// Contact-aware Newton: factors `I - h d (J_free + J_contacts(z))` with the contacts'
    /// Jacobian of the derivative just evaluated at the iterate `z` (`ws.linearize` set).
    /// Without active tracks the contact-free matrix is kept while `h d` is unchanged.
    pub(super) fn factorize_at_iterate(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        hd: f64,
        t: f64,
    ) -> bool {
        if ws.linearizations.is_empty() && ws.linearization_moments.is_empty() {
            if self.lu_valid && self.lu_contact_free && self.lu_h == hd {
                return true;
            }
            self.lu_contact_free = true;
            self.lu_h = hd;
            self.stats.factorizations += 1;
            self.lu_valid = self.lu.factor_newton(&self.jac, hd);
            return self.lu_valid;
        }
        self.newton_jac.copy_from_slice(&self.jac);
        sys.contact_jacobian(&self.z, ws, &mut self.newton_jac);
        if self.lu_valid && !self.lu_contact_free && self.lu_h == hd {
            // Keep the factorisation while no entry of I - h d J moved by more than
            // LU_REUSE_CHANGE of its size (persistent contact; Newton still contracts).
            let close = self
                .newton_jac
                .iter()
                .zip(&self.lu_jac)
                .all(|(&a, &b)| hd * (a - b).abs() <= LU_REUSE_CHANGE * (1.0 + hd * b.abs()));
            if close {
                return true;
            }
        }
        self.lu_jac.copy_from_slice(&self.newton_jac);
        self.lu_h = hd;
        self.lu_contact_free = false;
        self.stats.factorizations += 1;
        self.lu_valid = self.lu.factor_newton(&self.newton_jac, hd);
        if !self.lu_valid {
            tracing::debug!(t, "singular contact-aware Newton matrix");
        }
        self.lu_valid
    }

    pub(super) fn factorize(&mut self, h: f64, diag: f64, t: f64) -> Result<(), IntegratorError> {
        if !self.lu.factor_newton(&self.jac, h * diag) {
            self.lu_valid = false;
            return Err(IntegratorError::Singular { t });
        }
        self.lu_valid = true;
        self.lu_h = h;
        self.stats.factorizations += 1;
        Ok(())
    }

    pub(super) fn solve_in_place(&mut self, v: &mut [f64]) {
        if self.lu_valid {
            self.lu.solve(v);
        }
    }

    pub(super) fn ensure_newton_matrix(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
        diag: f64,
    ) -> Result<(), IntegratorError> {
        if self.jac_age > 20 {
            self.compute_jacobian(sys, ws, t, y);
        }
        if self.contact_aware() {
            // Factored at every Newton iterate (`factorize_at_iterate`).
            return Ok(());
        }
        if !self.lu_valid || self.lu_h != h {
            self.factorize(h, diag, t)?;
        }
        Ok(())
    }
}
