//! The implicit methods as Butcher tableaus, and the one stage loop that runs them.
//!
//! TR-BDF2 and SDIRK2 are both diagonally implicit, stiffly accurate and two implicit stages
//! long, so one driver ([`Integrator::attempt_dirk`]) serves both: stage `s` solves
//! `z - h d f(t + c_s h, z) = y + h Σ_{j<s} a_sj k_j` by Newton from the method's own predictor,
//! the step ends at the last stage, and the error is the embedded `h Σ e_j k_j` filtered by
//! `(I - h d J)^-1` (Hairer-Wanner II IV.8). Stage 0 is `k_0 = f(t, y)`, the step start's
//! derivative (explicit; SDIRK2's row and error weight for it are zero).
//!
//! Predictors only set Newton's starting point, but the converged stage depends on it to
//! Newton's tolerance, so each method keeps its own ([`Predictor`]); changing one moves results.

use super::*;

/// Stages of the tableaus: the explicit start and two implicit stages.
pub(super) const STAGES: usize = 3;

/// A stiffly accurate DIRK method whose stage 0 is the step start's derivative.
pub(super) struct DirkTableau {
    /// Diagonal coefficient `d` of every implicit stage: the Newton matrix is `I - h d J`.
    pub d: f64,
    /// Nodes `c_s`: stage `s` sits at `t + c_s h` (`c_s = Σ_j a_sj + d`).
    pub c: [f64; STAGES],
    /// Strictly lower stage matrix `a_sj` (`j < s`; the diagonal is `d`). The last row with `d`
    /// is also the method's quadrature weights `b` (stiffly accurate: the step ends at the last
    /// stage).
    pub a: [[f64; STAGES]; STAGES],
    /// Error weights `e_j = b_j - b̂_j` against the embedded or companion method.
    pub e: [f64; STAGES],
    /// The energy account integrates the dissipated and drive power with the method's
    /// quadrature (start, interior stage, end: [`InteriorStage`]) and tests its embedded error
    /// ([`Tolerances::energy_rel`]); otherwise the account uses the trapezoid rule and no test.
    pub energy_account: bool,
    /// Newton's starting point at each implicit stage.
    pub predictor: Predictor,
}

impl DirkTableau {
    /// Quadrature weights `b` of the start, the interior stage and the end.
    pub fn weights(&self) -> [f64; STAGES] {
        let last = &self.a[STAGES - 1];
        [last[0], last[1], self.d]
    }
}

// TR-BDF2 coefficients (ESDIRK form).
const SQRT2: f64 = std::f64::consts::SQRT_2;
const TRB_GAMMA: f64 = 2.0 - SQRT2;
const TRB_D: f64 = 1.0 - SQRT2 / 2.0;
const TRB_W: f64 = SQRT2 / 4.0;
/// TR-BDF2's third-order companion weights (Hosea & Shampine 1996).
const TRB_B_HAT: [f64; STAGES] = [(1.0 - TRB_W) / 3.0, (3.0 * TRB_W + 1.0) / 3.0, TRB_D / 3.0];
/// Stage-3 predictor weight of k1: the quadratic with slope k0 at t and k1 at t + γh reaches
/// `y + h ((1 - 1/(2γ)) k0 + 1/(2γ) k1)` at t + h (measured on the 2 s windows: -14 % / -10 %
/// right-hand sides on rattle box C / launcher against `y + h k1`).
const STAGE3_K1: f64 = 1.0 / (2.0 * TRB_GAMMA);

/// TR-BDF2 as an L-stable ESDIRK: trapezoidal stage to `t + γh`, BDF2 stage to `t + h`, with
/// its third-order companion for the error (Hosea & Shampine 1996).
pub(super) const TRBDF2: DirkTableau = DirkTableau {
    d: TRB_D,
    c: [0.0, TRB_GAMMA, 1.0],
    a: [[0.0; STAGES], [TRB_D, 0.0, 0.0], [TRB_W, TRB_W, 0.0]],
    e: [
        TRB_W - TRB_B_HAT[0],
        TRB_W - TRB_B_HAT[1],
        TRB_D - TRB_B_HAT[2],
    ],
    energy_account: true,
    predictor: Predictor::Trbdf2,
};

// SDIRK2 (Alexander 1977).
const SD_GAMMA: f64 = 1.0 - 1.0 / SQRT2;

/// Alexander's two-stage L-stable SDIRK of order 2, with the first-order estimate
/// `hγ (k2 - k1)` for the error. Its energy account stays on the trapezoid rule. Measured on
/// rattle box C (settle 0.5 s + 2 s, docs/journal/performance.md, fourteenth pass): the trapezoid
/// leaves 1.3 % of the throughput unaccounted; its own quadrature `b = (0, 1 - γ, γ)` without
/// the work test 52 %, with it 0 failures but 25x TR-BDF2's accepted steps.
pub(super) const SDIRK2: DirkTableau = DirkTableau {
    d: SD_GAMMA,
    c: [0.0, SD_GAMMA, 1.0],
    a: [[0.0; STAGES], [0.0; STAGES], [0.0, 1.0 - SD_GAMMA, 0.0]],
    e: [0.0, -SD_GAMMA, SD_GAMMA],
    energy_account: false,
    predictor: Predictor::Sdirk2,
};

/// Each method's Newton starting point per implicit stage.
#[derive(Clone, Copy)]
pub(super) enum Predictor {
    /// Stage 1: Taylor to second order, `f'` from the last two step starts (first order on the
    /// first step). Stage 2: the quadratic through `y` with slopes `k0` at `t` and `k1` at
    /// `t + γh`.
    Trbdf2,
    /// Stage 1: explicit Euler to `t + γh`; stage 2: `y + h k1`.
    Sdirk2,
}

impl Integrator {
    /// One attempt of the DIRK method `tab` from `(t, y)` with step `h`.
    pub(super) fn attempt_dirk(
        &mut self,
        tab: &DirkTableau,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<Attempt, IntegratorError> {
        self.ensure_newton_matrix(sys, ws, t, y, h, tab.d)?;
        let hd = h * tab.d;
        for s in 1..STAGES {
            self.stage_rhs(y, h, &tab.a[s]);
            self.predict(tab.predictor, s, y, h);
            if !self.newton(sys, ws, t + tab.c[s] * h, hd, y, s) {
                return Ok(Attempt {
                    err_norm: f64::INFINITY,
                    newton_failed: true,
                });
            }
            if tab.energy_account && s == 1 {
                self.capture_stage(sys, ws, tab.weights());
            }
        }
        for i in 0..self.n {
            self.ynew[i] = self.z[i];
            let mut e = 0.0;
            for (j, &ej) in tab.e.iter().enumerate() {
                if ej != 0.0 {
                    e += ej * self.k[j][i];
                }
            }
            self.err[i] = h * e;
        }
        let mut e = std::mem::take(&mut self.err);
        self.solve_in_place(&mut e);
        self.carrier_at_end(sys, ws, t + h);
        let norm = self.error_norm(&e, y, h);
        self.err = e;
        let err_norm = if tab.energy_account {
            norm.max(self.energy_error_norm(ws, h, tab.e))
        } else {
            norm
        };
        Ok(Attempt {
            err_norm,
            newton_failed: false,
        })
    }

    /// `rhs = y + h Σ_j a_j k_j` for one row of the stage matrix. Neighbouring stages that
    /// share a coefficient are summed before they are scaled (one product fewer; TR-BDF2's
    /// BDF2 stage keeps the rounding of `y + hw (k0 + k1)`).
    fn stage_rhs(&mut self, y: &[f64], h: f64, row: &[f64; STAGES]) {
        // (h a, first stage, one past the last stage) of each run of equal coefficients.
        let mut runs = [(0.0, 0, 0); STAGES];
        let mut count = 0;
        let mut j = 0;
        while j < STAGES {
            let mut end = j + 1;
            while end < STAGES && row[end] == row[j] {
                end += 1;
            }
            if row[j] != 0.0 {
                runs[count] = (h * row[j], j, end);
                count += 1;
            }
            j = end;
        }
        for i in 0..self.n {
            let mut acc = y[i];
            for &(ha, first, end) in &runs[..count] {
                let mut sum = self.k[first][i];
                for k in &self.k[first + 1..end] {
                    sum += k[i];
                }
                acc += ha * sum;
            }
            self.rhs[i] = acc;
        }
    }

    /// Newton's starting point `z` for implicit stage `s` of a step of size `h` from `y`.
    fn predict(&mut self, predictor: Predictor, s: usize, y: &[f64], h: f64) {
        let n = self.n;
        match (predictor, s) {
            (Predictor::Trbdf2, 1) => {
                let gh = TRB_GAMMA * h;
                let curvature = if self.prev_h > 0.0 {
                    0.5 * gh * gh / self.prev_h
                } else {
                    0.0
                };
                for i in 0..n {
                    self.z[i] =
                        y[i] + gh * self.k[0][i] + curvature * (self.k[0][i] - self.k_prev[i]);
                }
            }
            (Predictor::Trbdf2, _) => {
                for i in 0..n {
                    self.z[i] =
                        y[i] + h * ((1.0 - STAGE3_K1) * self.k[0][i] + STAGE3_K1 * self.k[1][i]);
                }
            }
            (Predictor::Sdirk2, 1) => {
                let hg = h * SD_GAMMA;
                for i in 0..n {
                    self.z[i] = y[i] + hg * self.k[0][i];
                }
            }
            (Predictor::Sdirk2, _) => {
                for i in 0..n {
                    self.z[i] = y[i] + h * self.k[1][i];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order_conditions(tab: &DirkTableau) -> (f64, f64, f64) {
        let b = tab.weights();
        let sum_b: f64 = b.iter().sum();
        let sum_bc: f64 = b.iter().zip(tab.c).map(|(b, c)| b * c).sum();
        let sum_e: f64 = tab.e.iter().sum();
        (sum_b, sum_bc, sum_e)
    }

    #[test]
    fn the_nodes_are_the_row_sums_with_the_diagonal() {
        for tab in [&TRBDF2, &SDIRK2] {
            assert_eq!(tab.c[0], 0.0);
            for s in 1..STAGES {
                let row: f64 = tab.a[s].iter().sum::<f64>() + tab.d;
                assert!(
                    (row - tab.c[s]).abs() < 1e-15,
                    "stage {s}: {row} vs {}",
                    tab.c[s]
                );
                assert!(tab.a[s][s..].iter().all(|&a| a == 0.0), "strictly lower");
            }
            assert_eq!(
                tab.c[STAGES - 1],
                1.0,
                "stiffly accurate: the step ends at the last stage"
            );
        }
    }

    #[test]
    fn both_methods_are_second_order_and_their_error_weights_sum_to_zero() {
        for tab in [&TRBDF2, &SDIRK2] {
            let (sum_b, sum_bc, sum_e) = order_conditions(tab);
            assert!((sum_b - 1.0).abs() < 1e-15, "Σ b = {sum_b}");
            assert!((sum_bc - 0.5).abs() < 1e-15, "Σ b c = {sum_bc}");
            assert!(sum_e.abs() < 1e-15, "Σ e = {sum_e}");
        }
    }

    #[test]
    fn the_trbdf2_companion_is_third_order() {
        let b_hat = TRB_B_HAT;
        let c = TRBDF2.c;
        let a = |s: usize, j: usize| {
            if s == j && s > 0 {
                TRBDF2.d
            } else {
                TRBDF2.a[s][j]
            }
        };
        let sum = |f: &dyn Fn(usize) -> f64| (0..STAGES).map(f).sum::<f64>();
        assert!((sum(&|j| b_hat[j]) - 1.0).abs() < 1e-15);
        assert!((sum(&|j| b_hat[j] * c[j]) - 0.5).abs() < 1e-15);
        assert!((sum(&|j| b_hat[j] * c[j] * c[j]) - 1.0 / 3.0).abs() < 1e-15);
        let bac = sum(&|s| b_hat[s] * sum(&|j| a(s, j) * c[j]));
        assert!((bac - 1.0 / 6.0).abs() < 1e-15, "Σ b̂ a c = {bac}");
    }

    #[test]
    fn the_shared_coefficients_of_trbdf2s_last_row_are_one_run() {
        // The BDF2 stage's rhs keeps the rounding of y + hw (k0 + k1) only if the driver sums
        // k0 and k1 before scaling them.
        assert_eq!(TRBDF2.a[2][0], TRBDF2.a[2][1]);
    }
}
