//! One attempt of each method: TR-BDF2 (ESDIRK tableau, third-order companion for the error),
//! SDIRK2 and Dopri5, and the energy account's stage quadrature.

use super::*;

impl Integrator {
    pub(super) fn attempt_trbdf2(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<Attempt, IntegratorError> {
        self.ensure_newton_matrix(sys, ws, t, y, h, TRB_D)?;
        let n = self.n;
        let hd = h * TRB_D;
        // Stage 2 (trapezoidal to t + γh).
        // Predictor: Taylor to second order, f' from the last two step starts (first order on
        // the first step). Only Newton's starting point: the stage solves the same equation.
        let gh = TRB_GAMMA * h;
        let curvature = if self.prev_h > 0.0 {
            0.5 * gh * gh / self.prev_h
        } else {
            0.0
        };
        for i in 0..n {
            self.rhs[i] = y[i] + hd * self.k[0][i];
            self.z[i] = y[i] + gh * self.k[0][i] + curvature * (self.k[0][i] - self.k_prev[i]);
        }
        if !self.newton(sys, ws, t + TRB_GAMMA * h, hd, y, 1) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        self.capture_stage(sys, ws);
        // Stage 3 (BDF2 to t + h).
        for i in 0..n {
            self.rhs[i] = y[i] + h * TRB_W * (self.k[0][i] + self.k[1][i]);
            // Predictor: the quadratic through y with slopes k0 at t and k1 at t + γh.
            self.z[i] = y[i] + h * ((1.0 - STAGE3_K1) * self.k[0][i] + STAGE3_K1 * self.k[1][i]);
        }
        if !self.newton(sys, ws, t + h, hd, y, 2) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        let b1 = (1.0 - TRB_W) / 3.0;
        let b2 = (3.0 * TRB_W + 1.0) / 3.0;
        let b3 = TRB_D / 3.0;
        for i in 0..n {
            self.ynew[i] = self.z[i];
            self.err[i] = h
                * ((TRB_W - b1) * self.k[0][i]
                    + (TRB_W - b2) * self.k[1][i]
                    + (TRB_D - b3) * self.k[2][i]);
        }
        let mut e = std::mem::take(&mut self.err);
        self.solve_in_place(&mut e);
        let norm = self.error_norm(&e, y, h);
        self.err = e;
        let energy = self.energy_error_norm(ws, h, [TRB_W - b1, TRB_W - b2, TRB_D - b3]);
        Ok(Attempt {
            err_norm: norm.max(energy),
            newton_failed: false,
        })
    }

    /// The energy account's quadrature error on this attempt over its tolerance
    /// ([`Tolerances::energy_rel`]): the embedded estimate `h Σ (w_i − b_i) P_i` of the
    /// dissipated and the drive power against the step's work. `ws.power` holds the attempt's
    /// last evaluation (its end).
    pub(super) fn energy_error_norm(&self, ws: &Workspace, h: f64, err_weights: [f64; 3]) -> f64 {
        let rel = self.settings.tolerances.energy_rel;
        let Some(stage) = self.stage.as_ref().filter(|_| rel > 0.0) else {
            return 0.0;
        };
        let p = [self.power_start, stage.power, ws.power];
        let [w0, w1, w2] = stage.weights;
        let mut err = 0.0;
        let mut work = 0.0;
        for term in [
            |q: &crate::physics::system::PowerBalance| q.dissipation(),
            |q: &crate::physics::system::PowerBalance| q.drive,
        ] {
            let v = [term(&p[0]), term(&p[1]), term(&p[2])];
            err +=
                (h * (err_weights[0] * v[0] + err_weights[1] * v[1] + err_weights[2] * v[2])).abs();
            work += h * (w0 * v[0].abs() + w1 * v[1].abs() + w2 * v[2].abs());
        }
        err / (rel * work + ENERGY_ABS_TOLERANCE_J)
    }

    /// Keeps the power terms of the stage just solved (the workspace holds its last Newton
    /// iterate's evaluation).
    pub(super) fn capture_stage(&mut self, sys: &MultibodySystem, ws: &Workspace) {
        let stage = self.stage.get_or_insert_with(InteriorStage::default);
        stage.weights = [TRB_W, TRB_W, TRB_D];
        stage.power = ws.power;
        stage.contacts.clear();
        stage.contacts.resize(sys.contacts.len(), [0.0; 2]);
        for tr in &ws.tracks {
            if let Some(c) = stage.contacts.get_mut(tr.contact as usize) {
                c[0] += tr.damping_power;
                c[1] += tr.friction_power;
            }
        }
    }

    pub(super) fn attempt_sdirk2(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<Attempt, IntegratorError> {
        self.ensure_newton_matrix(sys, ws, t, y, h, SD_GAMMA)?;
        let n = self.n;
        let hg = h * SD_GAMMA;
        for i in 0..n {
            self.rhs[i] = y[i];
            self.z[i] = y[i] + hg * self.k[0][i];
        }
        if !self.newton(sys, ws, t + hg, hg, y, 1) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        for i in 0..n {
            self.rhs[i] = y[i] + h * (1.0 - SD_GAMMA) * self.k[1][i];
            self.z[i] = y[i] + h * self.k[1][i];
        }
        if !self.newton(sys, ws, t + h, hg, y, 2) {
            return Ok(Attempt {
                err_norm: f64::INFINITY,
                newton_failed: true,
            });
        }
        for i in 0..n {
            self.ynew[i] = self.z[i];
            self.err[i] = hg * (self.k[2][i] - self.k[1][i]);
        }
        let mut e = std::mem::take(&mut self.err);
        self.solve_in_place(&mut e);
        let norm = self.error_norm(&e, y, h);
        self.err = e;
        Ok(Attempt {
            err_norm: norm,
            newton_failed: false,
        })
    }

    pub(super) fn attempt_dopri5(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Attempt {
        const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
        const A: [[f64; 6]; 7] = [
            [0.0; 6],
            [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
            [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
            [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
            [
                19372.0 / 6561.0,
                -25360.0 / 2187.0,
                64448.0 / 6561.0,
                -212.0 / 729.0,
                0.0,
                0.0,
            ],
            [
                9017.0 / 3168.0,
                -355.0 / 33.0,
                46732.0 / 5247.0,
                49.0 / 176.0,
                -5103.0 / 18656.0,
                0.0,
            ],
            [
                35.0 / 384.0,
                0.0,
                500.0 / 1113.0,
                125.0 / 192.0,
                -2187.0 / 6784.0,
                11.0 / 84.0,
            ],
        ];
        const E: [f64; 7] = [
            71.0 / 57600.0,
            0.0,
            -71.0 / 16695.0,
            71.0 / 1920.0,
            -17253.0 / 339200.0,
            22.0 / 525.0,
            -1.0 / 40.0,
        ];
        let n = self.n;
        for s in 1..7 {
            for i in 0..n {
                let mut acc = y[i];
                for (j, a) in A[s].iter().enumerate().take(s) {
                    acc += h * a * self.k[j][i];
                }
                self.z[i] = acc;
            }
            let z = std::mem::take(&mut self.z);
            self.rhs(sys, ws, t + C[s] * h, &z, s);
            self.z = z;
        }
        for i in 0..n {
            self.ynew[i] = self.z[i];
            let mut e = 0.0;
            for (j, ej) in E.iter().enumerate() {
                e += ej * self.k[j][i];
            }
            self.err[i] = h * e;
        }
        let norm = self.weighted_norm(&self.err, y, &self.ynew);
        Attempt {
            err_norm: norm,
            newton_failed: false,
        }
    }
}
