//! A run that goes wrong fails (issue 29): no report of zeros from a broken run.
//!
//! The engine stops on what it can see inside a step (Newton failure, penetration or speed
//! beyond `DivergenceLimits`). What it cannot see is watched here, on every accepted step, and
//! judged at the end:
//! - a non-finite number in the state or in a contact track (a NaN base motion gives a track
//!   of NaN forces that wear integrates to 0 without complaint);
//! - a body that leaves its carrier: a dynamic body in contact with a kinematic one (the cube
//!   in its tube, a missile on its rail) farther from it than the carrier's contact geometry
//!   and its own reach allow, twice over (the cube falling out of a tube whose motion broke);
//! - an energy account that does not close within its bound when the run controls it (the
//!   integrator's work test is on), or holds a non-finite number.
//!
//! The first finding becomes [`SimError::Diverged`], naming time, body, contact and the
//! mechanical energy of the last sound state, like the engine's own divergences.

use super::BuiltModel;
use crate::physics::body::{BodyKind, KinematicMotion};
use crate::physics::energy::EnergyAudit;
use crate::physics::simulate::{SimError, StepView};
use crate::physics::system::MultibodySystem;
use std::sync::Arc;

/// A dynamic body and the kinematic carrier it touches, with the farthest it may get.
struct Carried {
    body: usize,
    offset: usize,
    carrier: usize,
    motion: Arc<dyn KinematicMotion>,
    contact: String,
    max_distance_m: f64,
}

/// What went wrong first.
struct Finding {
    time_s: f64,
    body: String,
    contact: String,
    reason: String,
}

/// Watches the accepted steps of one run.
pub(super) struct Watch {
    carried: Vec<Carried>,
    finding: Option<Finding>,
    last_sound: Option<(f64, Vec<f64>)>,
}

/// Farthest a contact's geometry reaches from its body's origin, m: the face planes'
/// distances, the bounded faces' corners and the pieces' placements.
fn reach_m(sys: &MultibodySystem, contact: usize) -> f64 {
    let c = &sys.contacts[contact];
    let faces = c
        .faces_b
        .iter()
        .map(|f| f.offset.abs())
        .chain(c.face_extents.iter().flatten().map(|e| {
            let (s0, s1) = e.s_range_m;
            let (t0, t1) = e.t_range_m;
            e.origin.coords.norm() + s0.abs().max(s1.abs()) + t0.abs().max(t1.abs())
        }))
        .fold(0.0_f64, f64::max);
    let pieces = c
        .pieces_a
        .iter()
        .map(|(pose, _)| pose.translation.vector.norm())
        .fold(0.0_f64, f64::max);
    faces + pieces
}

/// Least room a carried body is given beyond its geometric reach, m.
const MIN_ROOM_M: f64 = 0.01;

impl Watch {
    /// The pairs to watch, with their distances at the start of the run.
    pub(super) fn new(model: &BuiltModel) -> Self {
        let sys = &model.system;
        let mut carried: Vec<Carried> = Vec::new();
        for (ci, c) in sys.contacts.iter().enumerate() {
            let (BodyKind::Dynamic { offset }, BodyKind::Kinematic(motion)) =
                (&sys.bodies[c.body_a].kind, &sys.bodies[c.body_b].kind)
            else {
                continue;
            };
            let y = &model.initial_state;
            let start = distance(y, *offset, motion.as_ref(), 0.0);
            let max_distance_m = if start.is_finite() {
                start + 2.0 * reach_m(sys, ci) + MIN_ROOM_M
            } else {
                f64::INFINITY // reported by the first step's state check
            };
            match carried
                .iter_mut()
                .find(|p| p.body == c.body_a && p.carrier == c.body_b)
            {
                Some(p) if p.max_distance_m < max_distance_m => {
                    p.max_distance_m = max_distance_m;
                    p.contact = c.name.clone();
                }
                Some(_) => {}
                None => carried.push(Carried {
                    body: c.body_a,
                    offset: *offset,
                    carrier: c.body_b,
                    motion: Arc::clone(motion),
                    contact: c.name.clone(),
                    max_distance_m,
                }),
            }
        }
        Self {
            carried,
            finding: None,
            last_sound: None,
        }
    }

    /// Checks one accepted step; keeps the first finding.
    pub(super) fn step(&mut self, v: &StepView) {
        if self.finding.is_some() {
            return;
        }
        self.finding = check_step(&self.carried, v);
        if self.finding.is_none() {
            match &mut self.last_sound {
                Some((t, y)) if y.len() == v.state.len() => {
                    *t = v.t;
                    y.copy_from_slice(v.state);
                }
                _ => self.last_sound = Some((v.t, v.state.to_vec())),
            }
        }
    }

    /// The run's verdict: the first finding of the steps, else the energy account's.
    /// `energy_controlled`: the integrator's work test was on, so the account must close.
    pub(super) fn verdict(
        self,
        sys: &MultibodySystem,
        energy: Option<&EnergyAudit>,
        energy_controlled: bool,
        end_time_s: f64,
    ) -> Result<(), SimError> {
        let energy_j = |sound: &Option<(f64, Vec<f64>)>| {
            sound.as_ref().map_or(f64::NAN, |(t, y)| {
                let mut ws = sys.workspace();
                sys.energy(*t, y, &mut ws).total()
            })
        };
        if let Some(f) = self.finding {
            return Err(SimError::Diverged {
                time_s: f.time_s,
                energy_j: energy_j(&self.last_sound),
                body: f.body,
                contact: f.contact,
                reason: f.reason,
            });
        }
        let Some(e) = energy else {
            return Ok(());
        };
        if let Some(reason) = energy_verdict(e, energy_controlled) {
            let contact = e
                .contacts
                .iter()
                .max_by(|a, b| {
                    (a.damping_j + a.friction_j).total_cmp(&(b.damping_j + b.friction_j))
                })
                .map_or_else(|| "none".to_string(), |c| c.name.clone());
            return Err(SimError::Diverged {
                time_s: end_time_s,
                body: "all".into(),
                contact,
                energy_j: e.final_energy_j,
                reason,
            });
        }
        Ok(())
    }
}

/// Why an energy account condemns its run, if it does.
pub(super) fn energy_verdict(e: &EnergyAudit, controlled: bool) -> Option<String> {
    let numbers = [
        e.initial_energy_j,
        e.final_energy_j,
        e.drive_work_j,
        e.applied_work_j,
        e.dissipated_j,
        e.residual_j,
    ];
    if numbers.iter().any(|x| !x.is_finite()) {
        return Some(format!(
            "the energy account holds a non-finite number (E0 {:e} J, E {:e} J, drive {:e} J, \
             dissipated {:e} J)",
            e.initial_energy_j, e.final_energy_j, e.drive_work_j, e.dissipated_j
        ));
    }
    if controlled && !e.balanced {
        return Some(format!(
            "the energy account does not close: E + W_diss - W_drive - W_applied - E0 = {:.4e} \
             J, {:.3} % of the energy throughput (bound {} %)",
            e.residual_j,
            100.0 * e.residual_relative,
            100.0 * crate::physics::energy::ENERGY_BALANCE_TOLERANCE
        ));
    }
    None
}

/// Distance from a carried body's centre of mass to its carrier's origin at `t`, m.
fn distance(y: &[f64], offset: usize, carrier: &dyn KinematicMotion, t: f64) -> f64 {
    let p = nalgebra::Vector3::new(y[offset], y[offset + 1], y[offset + 2]);
    (p - carrier.pose(t).translation.vector).norm()
}

fn check_step(carried: &[Carried], v: &StepView) -> Option<Finding> {
    let sys = v.system;
    let finding = |body: &str, contact: &str, reason: String| Finding {
        time_s: v.t,
        body: body.to_string(),
        contact: contact.to_string(),
        reason,
    };
    if let Some(i) = v.state.iter().position(|x| !x.is_finite()) {
        let body = sys
            .bodies
            .iter()
            .filter_map(|b| match b.kind {
                BodyKind::Dynamic { offset } => Some((offset, b)),
                BodyKind::Kinematic(_) => None,
            })
            .filter(|(offset, _)| *offset <= i)
            .max_by_key(|(offset, _)| *offset)
            .map_or("unknown", |(_, b)| b.name.as_str());
        return Some(finding(
            body,
            "none",
            format!("state entry {i} is {}", v.state[i]),
        ));
    }
    for tr in v.tracks {
        let values = [
            ("normal force", tr.normal_force),
            ("slip speed", tr.slip_speed),
            ("penetration", tr.penetration),
            ("penetration rate", tr.penetration_rate),
            ("area", tr.area),
            ("point x", tr.point.x),
            ("point y", tr.point.y),
            ("point z", tr.point.z),
        ];
        if let Some((what, x)) = values.iter().find(|(_, x)| !x.is_finite()) {
            let c = &sys.contacts[tr.contact as usize];
            return Some(finding(
                &sys.bodies[c.body_a].name,
                &c.name,
                format!("track {} holds a {what} of {x}", tr.track),
            ));
        }
    }
    for p in carried {
        let d = distance(v.state, p.offset, p.motion.as_ref(), v.t);
        if !(d <= p.max_distance_m) {
            return Some(finding(
                &sys.bodies[p.body].name,
                &p.contact,
                format!(
                    "the body is {d:.4e} m from the origin of `{}`, beyond the {:.4} m its \
                     contacts allow: it has left its carrier",
                    sys.bodies[p.carrier].name, p.max_distance_m
                ),
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::energy::{ContactDissipation, EnergyAudit};

    fn audit(residual_j: f64, throughput_j: f64) -> EnergyAudit {
        let balanced = residual_j.abs()
            <= crate::physics::energy::ENERGY_BALANCE_TOLERANCE * throughput_j
                + crate::physics::energy::ENERGY_BALANCE_FLOOR_J;
        EnergyAudit {
            initial_energy_j: 1.0,
            final_energy_j: 1.0 + residual_j,
            drive_work_j: throughput_j,
            applied_work_j: 0.0,
            dissipated_j: throughput_j,
            element_dissipated_j: 0.0,
            contacts: vec![ContactDissipation {
                name: "cube-tube".into(),
                damping_j: throughput_j,
                friction_j: 0.0,
            }],
            residual_j,
            residual_relative_to_drive: Some(residual_j / throughput_j),
            residual_relative: residual_j.abs() / throughput_j,
            max_rise_without_drive_j: 0.0,
            balanced,
        }
    }

    #[test]
    fn an_account_that_does_not_close_condemns_a_controlled_run() {
        // 0.5 % of the throughput closes (bound 1 %), 5 % does not.
        assert!(energy_verdict(&audit(0.005, 1.0), true).is_none());
        let reason = energy_verdict(&audit(0.05, 1.0), true).unwrap();
        assert!(reason.contains("does not close"), "{reason}");
        // Without the work test the account is kept but not enforced.
        assert!(energy_verdict(&audit(0.05, 1.0), false).is_none());
        // A non-finite number is never accepted.
        let mut nan = audit(0.0, 1.0);
        nan.final_energy_j = f64::NAN;
        assert!(energy_verdict(&nan, false).is_some());
    }
}
