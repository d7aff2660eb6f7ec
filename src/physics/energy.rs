//! The energy account every run keeps (SPEC §2 "Passivity"):
//! `E_mech(t) + W_dissipated(t) − W_drive(t) − W_applied(t) = E_mech(0)`.
//!
//! `E_mech` is kinetic + gravitational + elastic (contacts and force elements) energy of the
//! accepted states; the works are the time integrals of the power terms each derivative
//! evaluation reports ([`PowerBalance`]), by the trapezoid rule between accepted states. The
//! residual of the balance measures, together, any energy a force creates and the integrator's
//! own error; the largest rise of `E_mech − W_applied` over an interval without drive can only
//! come from a force that is not passive or from the integrator (a passive system without drive
//! can only lose energy).

use super::contact::TrackState;
use super::integrator::InteriorStage;
use super::system::PowerBalance;
use serde::{Deserialize, Serialize};

/// Relative bound on the balance residual: |residual| <= this × the energy throughput
/// (max of the drive and applied work and the dissipated work) + [`ENERGY_BALANCE_FLOOR_J`].
/// Measured on the reference cases: 1e-4 to 3e-3 (docs/results/validation.md).
pub const ENERGY_BALANCE_TOLERANCE: f64 = 1e-2;

/// Absolute floor of the residual bound, J (round-off on a resting body).
pub const ENERGY_BALANCE_FLOOR_J: f64 = 1e-9;

/// Work dissipated by one contact, J.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactDissipation {
    /// Contact name.
    pub name: String,
    /// Work of the IMPACT damping (and its clamp), J.
    pub damping_j: f64,
    /// Work of friction, J.
    pub friction_j: f64,
}

/// The energy account of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyAudit {
    /// Mechanical energy at the start, J (zero of gravity at the world origin).
    pub initial_energy_j: f64,
    /// Mechanical energy at the end, J.
    pub final_energy_j: f64,
    /// Work of the prescribed motion on the free bodies, J.
    pub drive_work_j: f64,
    /// Work of applied loads (constant forces), J.
    pub applied_work_j: f64,
    /// Work dissipated in all, J.
    pub dissipated_j: f64,
    /// Work dissipated by force elements (dampers, bushings), J.
    pub element_dissipated_j: f64,
    /// Work dissipated per contact.
    pub contacts: Vec<ContactDissipation>,
    /// `E_end + W_dissipated − W_drive − W_applied − E_start`, J (0 for an exact account).
    pub residual_j: f64,
    /// `residual / W_drive` (None without drive work).
    pub residual_relative_to_drive: Option<f64>,
    /// `|residual|` over the energy throughput `max(|W_drive| + |W_applied|, W_dissipated)`.
    pub residual_relative: f64,
    /// Largest rise of `E_mech − W_applied` above its running minimum over any interval
    /// without drive, J (0 for a passive system integrated exactly).
    pub max_rise_without_drive_j: f64,
    /// Whether `|residual|` is within [`ENERGY_BALANCE_TOLERANCE`] of the throughput (+ the
    /// floor); a run outside it is flagged in its report.
    pub balanced: bool,
}

impl EnergyAudit {
    /// The account of a system integrated as independent parts (`physics::partition`): the
    /// energies and works add; each part's contacts (`(indices in the whole system, audit)`)
    /// go to their places among `names`. The largest rise without drive is the sum of the
    /// parts' (an upper bound of the whole's: the parts' intervals need not coincide).
    pub fn merge(names: &[String], parts: Vec<(Vec<usize>, EnergyAudit)>) -> EnergyAudit {
        let mut contacts: Vec<ContactDissipation> = names
            .iter()
            .map(|n| ContactDissipation {
                name: n.clone(),
                damping_j: 0.0,
                friction_j: 0.0,
            })
            .collect();
        let (mut initial, mut fin, mut drive, mut applied, mut elements, mut rise) =
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for (indices, a) in parts {
            initial += a.initial_energy_j;
            fin += a.final_energy_j;
            drive += a.drive_work_j;
            applied += a.applied_work_j;
            elements += a.element_dissipated_j;
            rise += a.max_rise_without_drive_j;
            for (local, c) in a.contacts.into_iter().enumerate() {
                if let Some(slot) = indices.get(local).and_then(|&g| contacts.get_mut(g)) {
                    slot.damping_j += c.damping_j;
                    slot.friction_j += c.friction_j;
                }
            }
        }
        let dissipated = elements
            + contacts
                .iter()
                .map(|c| c.damping_j + c.friction_j)
                .sum::<f64>();
        let residual = fin + dissipated - drive - applied - initial;
        let throughput = (drive.abs() + applied.abs()).max(dissipated);
        EnergyAudit {
            initial_energy_j: initial,
            final_energy_j: fin,
            drive_work_j: drive,
            applied_work_j: applied,
            dissipated_j: dissipated,
            element_dissipated_j: elements,
            contacts,
            residual_j: residual,
            residual_relative_to_drive: (drive != 0.0).then(|| residual / drive),
            residual_relative: if throughput > 0.0 {
                residual.abs() / throughput
            } else {
                0.0
            },
            max_rise_without_drive_j: rise,
            balanced: residual.abs()
                <= ENERGY_BALANCE_TOLERANCE * throughput + ENERGY_BALANCE_FLOOR_J,
        }
    }
}

/// Accumulates the account over accepted states (part of a run's checkpoint).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EnergyMeter {
    names: Vec<String>,
    last: Option<Sample>,
    initial: f64,
    energy: f64,
    drive: f64,
    applied: f64,
    elements: f64,
    damping: Vec<f64>,
    friction: Vec<f64>,
    undriven_min: Option<f64>,
    max_rise: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Sample {
    t: f64,
    power: PowerBalance,
    damping: Vec<f64>,
    friction: Vec<f64>,
}

impl EnergyMeter {
    /// A meter for a system with these contact names.
    pub fn new(contact_names: Vec<String>) -> Self {
        let n = contact_names.len();
        Self {
            names: contact_names,
            last: None,
            initial: 0.0,
            energy: 0.0,
            drive: 0.0,
            applied: 0.0,
            elements: 0.0,
            damping: vec![0.0; n],
            friction: vec![0.0; n],
            undriven_min: None,
            max_rise: 0.0,
        }
    }

    /// Adds the accepted state at `t` with mechanical energy `energy_j`, its power terms and
    /// its tracks (for the per-contact split); `stage` is the step's interior stage when the
    /// method has one (its weights replace the trapezoid rule).
    pub fn record(
        &mut self,
        t: f64,
        energy_j: f64,
        power: &PowerBalance,
        tracks: &[TrackState],
        stage: Option<&InteriorStage>,
    ) {
        let n = self.names.len();
        let mut damping = vec![0.0; n];
        let mut friction = vec![0.0; n];
        for tr in tracks {
            if let Some(slot) = damping.get_mut(tr.contact as usize) {
                *slot += tr.damping_power;
                friction[tr.contact as usize] += tr.friction_power;
            }
        }
        let mut undriven = power.drive == 0.0;
        match &self.last {
            None => self.initial = energy_j,
            Some(prev) => {
                let h = t - prev.t;
                let stage = stage.filter(|s| s.contacts.len() == n);
                let [w0, w1, w2] = stage.map_or([0.5, 0.0, 0.5], |s| s.weights);
                let mid = stage.map(|s| s.power).unwrap_or_default();
                let q = |a: f64, m: f64, b: f64| h * (w0 * a + w1 * m + w2 * b);
                self.drive += q(prev.power.drive, mid.drive, power.drive);
                self.applied += q(prev.power.applied, mid.applied, power.applied);
                self.elements += q(
                    prev.power.element_dissipation,
                    mid.element_dissipation,
                    power.element_dissipation,
                );
                for c in 0..n {
                    let m = stage.map_or([0.0; 2], |s| s.contacts[c]);
                    self.damping[c] += q(prev.damping[c], m[0], damping[c]);
                    self.friction[c] += q(prev.friction[c], m[1], friction[c]);
                }
                undriven &= prev.power.drive == 0.0 && mid.drive == 0.0;
            }
        }
        self.energy = energy_j;
        // E − W_applied cannot rise while nothing drives the system.
        let level = energy_j - self.applied;
        if undriven {
            let low = self.undriven_min.map_or(level, |m| m.min(level));
            self.max_rise = self.max_rise.max(level - low);
            self.undriven_min = Some(low);
        } else {
            self.undriven_min = Some(level);
        }
        self.last = Some(Sample {
            t,
            power: *power,
            damping,
            friction,
        });
    }

    /// Work dissipated by friction per contact from the run's start to the last recorded
    /// state, J (the account's own quadrature): the difference of two readings is the friction
    /// work over a window, as the run's report gives it.
    pub fn friction_work_j(&self) -> &[f64] {
        &self.friction
    }

    /// The account so far.
    pub fn audit(&self) -> EnergyAudit {
        let contacts: Vec<ContactDissipation> = self
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| ContactDissipation {
                name: name.clone(),
                damping_j: self.damping[i],
                friction_j: self.friction[i],
            })
            .collect();
        let dissipated = self.elements
            + contacts
                .iter()
                .map(|c| c.damping_j + c.friction_j)
                .sum::<f64>();
        let residual = self.energy + dissipated - self.drive - self.applied - self.initial;
        let throughput = (self.drive.abs() + self.applied.abs()).max(dissipated);
        EnergyAudit {
            initial_energy_j: self.initial,
            final_energy_j: self.energy,
            drive_work_j: self.drive,
            applied_work_j: self.applied,
            dissipated_j: dissipated,
            element_dissipated_j: self.elements,
            contacts,
            residual_j: residual,
            residual_relative_to_drive: (self.drive != 0.0).then(|| residual / self.drive),
            residual_relative: if throughput > 0.0 {
                residual.abs() / throughput
            } else {
                0.0
            },
            max_rise_without_drive_j: self.max_rise,
            balanced: residual.abs()
                <= ENERGY_BALANCE_TOLERANCE * throughput + ENERGY_BALANCE_FLOOR_J,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_damped_decay_balances_and_a_rise_without_drive_is_caught() {
        // E(t) = e^{-t}, dissipated power e^{-t}: the account closes to the trapezoid error.
        let mut m = EnergyMeter::new(vec!["c".into()]);
        let n = 1000;
        for i in 0..=n {
            let t = i as f64 / n as f64;
            let p = PowerBalance {
                element_dissipation: (-t).exp(),
                ..PowerBalance::default()
            };
            m.record(t, (-t).exp(), &p, &[], None);
        }
        let a = m.audit();
        let exact = 1.0 - (-1.0f64).exp();
        assert!((a.dissipated_j - exact).abs() < 1e-6);
        assert!(a.residual_j.abs() < 1e-6 && a.balanced);
        assert_eq!(a.max_rise_without_drive_j, 0.0);
        // Energy that appears from nowhere: unbalanced, and the rise is measured.
        m.record(
            1.001,
            (-1.0f64).exp() + 0.1,
            &PowerBalance::default(),
            &[],
            None,
        );
        let a = m.audit();
        assert!(!a.balanced);
        assert!((a.max_rise_without_drive_j - 0.1).abs() < 1e-3);
    }
}
