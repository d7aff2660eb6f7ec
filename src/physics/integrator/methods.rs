//! One attempt of Dopri5 (explicit tableau), and the energy account's stage quadrature for the
//! implicit methods (whose tableaus and stage loop are in `dirk.rs`).

use super::*;

/// Coupling coefficients `a_ij` of the Dormand–Prince tableau (Hairer, Nørsett & Wanner,
/// *Solving ODEs I*, II.5); the last row is the fifth-order weights (FSAL). The nodes `c_i` are
/// in `attempt_dopri5` below.
const DOPRI5_A: [[f64; 6]; 7] = [
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

/// Fifth- minus fourth-order weights: the embedded local error estimate `h Σ e_i k_i`.
const DOPRI5_E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

impl Integrator {
    /// The energy account's quadrature error on this attempt over its tolerance
    /// ([`Tolerances::energy_rel`]): the embedded estimate `h Σ (w_i − b_i) P_i` of the
    /// dissipated and the drive power against the step's work plus `h` times the run's mean
    /// power so far ([`WorkThroughput`]). `ws.power` holds the attempt's last evaluation (its
    /// end).
    pub(super) fn energy_error_norm(
        &mut self,
        ws: &Workspace,
        h: f64,
        err_weights: [f64; 3],
    ) -> f64 {
        let rel = self.settings.tolerances.energy_rel;
        self.attempt_work_j = 0.0;
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
        self.attempt_work_j = work;
        let scale = work + h * self.work_throughput.mean_power_w();
        err / (rel * scale + ENERGY_ABS_TOLERANCE_J)
    }

    /// Keeps the power terms of the stage just solved (the workspace holds its last Newton
    /// iterate's evaluation).
    pub(super) fn capture_stage(
        &mut self,
        sys: &MultibodySystem,
        ws: &Workspace,
        weights: [f64; 3],
    ) {
        let stage = self.stage.get_or_insert_with(InteriorStage::default);
        stage.weights = weights;
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

    pub(super) fn attempt_dopri5(
        &mut self,
        sys: &MultibodySystem,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Attempt {
        const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
        const A: [[f64; 6]; 7] = DOPRI5_A;
        const E: [f64; 7] = DOPRI5_E;
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
        self.carrier_at_end(sys, ws, t + h);
        let norm = self.explicit_error_norm(&self.err, y);
        Attempt {
            err_norm: norm,
            newton_failed: false,
        }
    }
}
