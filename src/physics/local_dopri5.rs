//! Dormand–Prince 5(4) on a small autonomous state held in a fixed-size array, with the cubic
//! Hermite interpolant its event location reads.
//!
//! The engine's Dopri5 (`integrator/methods.rs`) steps the whole multibody system through its
//! workspace; this one steps a handful of contact-local variables ([`super::impact_map`]) with
//! no allocation and no system, so the same tableau is written here for arrays (an ODE crate
//! would allocate per call and cannot stop at the damping ramp's ends on our terms).

/// Coupling coefficients `a_ij` of the Dormand–Prince tableau (Hairer, Nørsett & Wanner,
/// *Solving ODEs I*, II.5); the last row is the fifth-order weights (FSAL). The system is
/// autonomous, so the nodes `c_i` are not needed here. The engine's Dopri5 reads the same
/// table.
pub const DOPRI5_A: [[f64; 6]; 7] = [
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
pub const DOPRI5_E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// One Dormand–Prince step: the fifth-order end state, its local error estimate and the
/// derivative at the end (the next step's first stage, FSAL).
#[derive(Debug, Clone, Copy)]
pub struct Dopri5Step<const N: usize> {
    /// State after the step.
    pub y: [f64; N],
    /// Embedded error estimate per component (same units as the state).
    pub error: [f64; N],
    /// Derivative at the end state.
    pub dydt: [f64; N],
}

/// One step of size `h` from `y0` (with its derivative `f0`) of the autonomous system `f`.
pub fn dopri5_step<const N: usize>(
    f: &mut impl FnMut(&[f64; N]) -> [f64; N],
    y0: &[f64; N],
    f0: &[f64; N],
    h: f64,
) -> Dopri5Step<N> {
    let mut k = [[0.0; N]; 7];
    k[0] = *f0;
    let mut z = *y0;
    for s in 1..7 {
        for i in 0..N {
            let mut acc = 0.0;
            for (j, a) in DOPRI5_A[s].iter().enumerate().take(s) {
                acc += a * k[j][i];
            }
            z[i] = y0[i] + h * acc;
        }
        k[s] = f(&z);
    }
    let mut error = [0.0; N];
    for (i, e) in error.iter_mut().enumerate() {
        let mut acc = 0.0;
        for (j, ej) in DOPRI5_E.iter().enumerate() {
            acc += ej * k[j][i];
        }
        *e = h * acc;
    }
    Dopri5Step {
        y: z,
        error,
        dydt: k[6],
    }
}

/// Cubic Hermite interpolant at `theta` in `[0, 1]` of a step of size `h` from `(y0, f0)` to
/// `(y1, f1)`: third order, enough to place an event whose time the step then lands on.
#[inline]
pub fn hermite(y0: f64, f0: f64, y1: f64, f1: f64, h: f64, theta: f64) -> f64 {
    let t2 = theta * theta;
    let t3 = t2 * theta;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + theta;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    h00 * y0 + h10 * h * f0 + h01 * y1 + h11 * h * f1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harmonic oscillator over one period: the global error falls as h^5.
    #[test]
    fn fifth_order_on_the_harmonic_oscillator() {
        let mut f = |y: &[f64; 2]| [y[1], -y[0]];
        let mut error_at = |n: usize| {
            let h = 2.0 * std::f64::consts::PI / n as f64;
            let mut y = [1.0, 0.0];
            let mut f0 = [0.0, -1.0];
            for _ in 0..n {
                let s = dopri5_step(&mut f, &y, &f0, h);
                y = s.y;
                f0 = s.dydt;
            }
            ((y[0] - 1.0).powi(2) + y[1].powi(2)).sqrt()
        };
        let ratio = error_at(40) / error_at(80);
        assert!(ratio > 25.0 && ratio < 40.0, "error ratio {ratio}");
    }

    #[test]
    fn hermite_is_exact_for_cubics() {
        let p = |t: f64| 2.0 - t + 0.5 * t * t - 0.25 * t * t * t;
        let dp = |t: f64| -1.0 + t - 0.75 * t * t;
        let h = 1.7;
        for theta in [0.0, 0.3, 0.5, 0.9, 1.0] {
            let v = hermite(p(0.0), dp(0.0), p(h), dp(h), h, theta);
            assert!((v - p(theta * h)).abs() < 1e-13);
        }
    }
}

/// Safety factor, PI exponent β and the step's growth and shrink limits of Hairer's DOPRI5
/// controller (Hairer, Nørsett & Wanner, *Solving ODEs I*, II.4: PI with β = 0.04, factors in
/// [0.2, 10]).
const SAFETY: f64 = 0.9;
const PI_BETA: f64 = 0.04;
const GROWTH_MAX: f64 = 10.0;
const SHRINK_MAX: f64 = 5.0;

/// The PI step-size control of the array steps above, one per integration: the next step size
/// from a step's error norm (`err <= 1` accepts), remembering the last accepted error and
/// whether the last attempt was rejected (no growth right after a rejection). The impulse maps
/// ([`super::impact_map`]) and the body transient ([`super::body_transient`]) step with it.
#[derive(Debug, Clone, Copy)]
pub struct PiControl {
    err_old: f64,
    last_rejected: bool,
}

impl Default for PiControl {
    fn default() -> Self {
        Self {
            err_old: 1e-4,
            last_rejected: false,
        }
    }
}

impl PiControl {
    /// The size to retry with after a step of size `h` was rejected with error `err` (> 1).
    pub fn rejected(&mut self, h: f64, err: f64) -> f64 {
        self.last_rejected = true;
        h / (pi_factor(err) / SAFETY).min(SHRINK_MAX)
    }

    /// The next step's size after a step of size `h` was accepted with error `err` (<= 1).
    pub fn accepted(&mut self, h: f64, err: f64) -> f64 {
        let mut fac = (pi_factor(err) / self.err_old.powf(PI_BETA) / SAFETY)
            .clamp(1.0 / GROWTH_MAX, SHRINK_MAX);
        if self.last_rejected {
            fac = fac.max(1.0);
        }
        self.err_old = err.max(1e-4);
        self.last_rejected = false;
        h / fac
    }
}

/// The error's part of the PI factor, `err^(1/5 − 0.75 β)`.
fn pi_factor(err: f64) -> f64 {
    err.powf(0.2 - 0.75 * PI_BETA)
}
