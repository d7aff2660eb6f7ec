//! Step control: the weighted error norms of an attempt and the step-size factors after an
//! accepted or rejected step (Hairer-Wanner II IV.8, with the holds measured on this problem).

use super::diagnostics::STEP_DECADES;
use super::{Integrator, IntegratorKind};
use crate::physics::system::{MultibodySystem, Workspace};

/// Contact-aware Newton: a failed Newton iteration halves the step, and the next
/// `HOLD_STEPS_AFTER_NEWTON_FAILURE` accepted steps grow by at most `HELD_GROWTH` each, so the
/// step creeps back instead of jumping straight into the next contact event (measured on the
/// 2 s windows of rattle box C and the launcher: 0.25 without the hold 84 479 launcher
/// right-hand sides, 0.5 with a 20-step hold at 1.2 74 064, 7 868 -> 3 756 rejections).
pub(super) const CONTACT_AWARE_NEWTON_CUT: f64 = 0.5;
pub(super) const HOLD_STEPS_AFTER_NEWTON_FAILURE: u32 = 20;
const HELD_GROWTH: f64 = 1.2;

/// The exponent of the error in the step-size factor (1 / (order + 1) of the error estimate)
/// and the largest growth of one step, per method.
pub(super) fn step_exponent_and_growth(kind: IntegratorKind) -> (f64, f64) {
    match kind {
        IntegratorKind::Trbdf2 => (1.0 / 3.0, 4.0),
        IntegratorKind::Sdirk2 => (0.5, 4.0),
        IntegratorKind::Dopri5 => (0.2, 5.0),
    }
}

/// The factor on the step after a rejection with error norm `err` (> 1 or not finite).
pub(super) fn rejected_step_factor(err: f64, order_exp: f64) -> f64 {
    if err.is_finite() {
        (0.9 * err.powf(-order_exp)).clamp(0.1, 0.9)
    } else {
        0.1
    }
}

impl Integrator {
    /// Entry `i` of `e` in units of its tolerance between states `y0` and `y1`.
    #[inline]
    pub(super) fn weighted_entry(&self, i: usize, e: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        self.over_tolerance(i, e[i], y0[i].abs().max(y1[i].abs()))
    }

    /// An error `e_i` of entry `i` in units of its tolerance `abs_i + rel × size`.
    #[inline]
    fn over_tolerance(&self, i: usize, e_i: f64, size: f64) -> f64 {
        e_i / (self.abs_tol[i] + self.settings.tolerances.rel * size)
    }

    /// Entry `i` of an attempt's local error `e` from `y0` (to `ynew`) in units of its
    /// tolerance, the relative part scaled by the motion relative to the carrier (the
    /// world-frame state without one: [`MultibodySystem::carrier_entries`]).
    #[inline]
    fn local_error_entry(&self, i: usize, e: &[f64], y0: &[f64]) -> f64 {
        if self.carrier_start.is_empty() {
            return self.weighted_entry(i, e, y0, &self.ynew);
        }
        let start = (y0[i] - self.carrier_start[i]).abs();
        let end = (self.ynew[i] - self.carrier_end[i]).abs();
        self.over_tolerance(i, e[i], start.max(end))
    }

    /// The carrier's motion at the attempt's end `t` (no-op without a carrier).
    pub(super) fn carrier_at_end(&mut self, sys: &MultibodySystem, ws: &Workspace, t: f64) {
        if !self.carrier_end.is_empty() {
            sys.carrier_entries(t, &self.ynew, ws, &mut self.carrier_end);
        }
    }

    /// The largest over the bodies of the root mean square of `entries` (ascending state
    /// indices) of one body, each as [`Self::local_error_entry`] weighs it: every body is
    /// resolved to the tolerance on its own, so a heavy body's small errors do not dilute a
    /// light one's (the launcher's latch beside its missile), and adding a body leaves the
    /// others' test as it was. One body: the root mean square of its entries.
    fn per_body_norm(&self, entries: impl Iterator<Item = usize>, e: &[f64], y0: &[f64]) -> f64 {
        let mut norm = 0.0f64;
        let (mut sum, mut count, mut body) = (0.0, 0usize, usize::MAX);
        for i in entries {
            let b = self.column_body[i];
            if b != body && count > 0 {
                norm = norm.max((sum / count as f64).sqrt());
                (sum, count) = (0.0, 0);
            }
            body = b;
            let r = self.local_error_entry(i, e, y0);
            sum += r * r;
            count += 1;
        }
        if count > 0 {
            norm = norm.max((sum / count as f64).sqrt());
        }
        norm
    }

    /// The explicit method's error norm: every entry ([`Self::per_body_norm`]).
    pub(super) fn explicit_error_norm(&self, e: &[f64], y0: &[f64]) -> f64 {
        self.per_body_norm(0..self.n, e, y0)
    }

    pub(super) fn weighted_norm(&self, e: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        let mut s = 0.0;
        for i in 0..self.n {
            let r = self.weighted_entry(i, e, y0, y1);
            s += r * r;
        }
        (s / self.n.max(1) as f64).sqrt()
    }

    /// The error norm of an implicit attempt of size `h` over the entries
    /// [`ErrorControl`] selects, body by body ([`Self::per_body_norm`]); with `diagnose`,
    /// counted by the kind of the entry that limits it.
    pub(super) fn error_norm(&mut self, e: &[f64], y0: &[f64], h: f64) -> f64 {
        let norm = self.per_body_norm(self.error_entries.iter().copied(), e, y0);
        if !self.diagnose {
            return norm;
        }
        // The first entry of largest weighted size.
        let mut worst = (0.0, 0);
        for &i in &self.error_entries {
            let r = self.local_error_entry(i, e, y0).abs();
            if r > worst.0 {
                worst = (r, i);
            }
        }
        if let Some(&kind) = self.state_kind.get(worst.1) {
            let decade = (-h.log10()).floor().clamp(0.0, (STEP_DECADES - 1) as f64) as usize;
            self.diagnostics.limiting_kind[decade][usize::from(kind.min(3))] += 1;
        }
        norm
    }

    /// The factor on the step after an accepted step with error norm `err` (<= 1), updating
    /// the growth holds: no growth right after a rejection (Hairer-Wanner II IV.8: growing back
    /// at once re-triggers the same failure; measured: -40 % rejections), at most
    /// `HELD_GROWTH` while a Newton failure's hold lasts.
    pub(super) fn accepted_step_factor(&mut self, err: f64, order_exp: f64, facmax: f64) -> f64 {
        let fmax = if self.after_reject {
            1.0
        } else if self.hold_steps > 0 {
            HELD_GROWTH
        } else {
            facmax
        };
        self.hold_steps = self.hold_steps.saturating_sub(1);
        self.after_reject = false;
        if err == 0.0 {
            fmax
        } else {
            (0.9 * err.powf(-order_exp)).clamp(0.2, fmax)
        }
    }
}
