//! The body transient's state layout and right-hand side: Newton-Euler of the one body under
//! gravity, its force elements and its contacts (the engine's per-point law), the kinematic
//! bodies on their prescribed motion, and the quadratures the transient hands back.

use crate::physics::body::{BodyFrame, BodyKind};
use crate::physics::contact::{EvaluationOutputs, GeometryCache, PointLoad, TrackState};
use crate::physics::forces::Wrench;
use crate::physics::system::MultibodySystem;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::MAX_TRACKS;

// State layout: the body (as in the system), the time, the body's totals, then per track slot
// `PER_TRACK` quadratures.
pub(super) const POS: usize = 0;
pub(super) const QUAT: usize = 3;
pub(super) const VEL: usize = 7;
pub(super) const OMEGA: usize = 10;
pub(super) const TIME: usize = 13;
pub(super) const E_DAMP: usize = 14;
pub(super) const E_FRIC: usize = 15;
pub(super) const E_ELEM: usize = 16;
pub(super) const W_GRAV: usize = 17;
pub(super) const W_DRIVE: usize = 18;
pub(super) const W_APPLIED: usize = 19;
pub(super) const TRACKS: usize = 20;
// Per track: ∫N dt, friction impulse (3), ∫N|v_t| dt, damping work, friction work.
pub(super) const T_PN: usize = 0;
pub(super) const T_PT: usize = 1;
pub(super) const T_NSLIP: usize = 4;
pub(super) const T_DAMP: usize = 5;
pub(super) const T_FRIC: usize = 6;
pub(super) const PER_TRACK: usize = 7;
pub(super) const DIM: usize = TRACKS + PER_TRACK * MAX_TRACKS;
pub(super) type State = [f64; DIM];

/// One track at the last evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct TrackNow {
    pub(super) active: bool,
    pub(super) penetration: f64,
    pub(super) rate: f64,
}

/// The body's right-hand side: its contacts and elements, the other bodies' frames.
pub(super) struct Evaluator<'a> {
    pub(super) system: &'a MultibodySystem,
    pub(super) body: usize,
    pub(super) mass: f64,
    pub(super) inertia: Matrix3<f64>,
    pub(super) inverse_inertia: Matrix3<f64>,
    /// Contacts with the body on either side, with the sign of their track force on it.
    pub(super) contacts: Vec<(usize, f64)>,
    pub(super) elements: Vec<usize>,
    /// Kinematic bodies the contacts and elements reach.
    pub(super) kinematic: Vec<usize>,
    pub(super) frames: Vec<BodyFrame>,
    pub(super) wrenches: Vec<Wrench>,
    pub(super) geometry: GeometryCache,
    pub(super) slots: [(u32, u32); MAX_TRACKS],
    pub(super) slot_count: usize,
    pub(super) overflow: bool,
    pub(super) now: [TrackNow; MAX_TRACKS],
    /// Each slot's normal at its last active evaluation.
    pub(super) last_normal: [Vector3<f64>; MAX_TRACKS],
    /// Stored energy at the last evaluation, J.
    pub(super) stored: f64,
    /// Contact points carrying a normal force at the last evaluation.
    pub(super) loaded_points: usize,
}

impl Evaluator<'_> {
    fn slot(&mut self, key: (u32, u32)) -> Option<usize> {
        if let Some(i) = self.slots[..self.slot_count].iter().position(|k| *k == key) {
            return Some(i);
        }
        if self.slot_count == MAX_TRACKS {
            self.overflow = true;
            return None;
        }
        self.slots[self.slot_count] = key;
        self.slot_count += 1;
        Some(self.slot_count - 1)
    }

    pub(super) fn derivative(&mut self, y: &State) -> State {
        let t = y[TIME];
        let q = Quaternion::new(y[QUAT], y[QUAT + 1], y[QUAT + 2], y[QUAT + 3]);
        let rotation = UnitQuaternion::new_normalize(q);
        let omega_b = Vector3::new(y[OMEGA], y[OMEGA + 1], y[OMEGA + 2]);
        let velocity = Vector3::new(y[VEL], y[VEL + 1], y[VEL + 2]);
        self.frames[self.body] = BodyFrame {
            position: Vector3::new(y[POS], y[POS + 1], y[POS + 2]),
            rotation,
            velocity,
            angular_velocity: rotation * omega_b,
        };
        for &k in &self.kinematic {
            if let BodyKind::Kinematic(m) = &self.system.bodies[k].kind {
                let pose = m.pose(t);
                let (v, w) = m.velocity(t);
                self.frames[k] = BodyFrame {
                    position: pose.translation.vector,
                    rotation: pose.rotation,
                    velocity: v,
                    angular_velocity: w,
                };
            }
        }
        for w in self.wrenches.iter_mut() {
            *w = (Vector3::zeros(), Vector3::zeros());
        }
        let gravity = self.system.gravity * self.mass;
        self.wrenches[self.body].0 += gravity;
        let mut d = [0.0; DIM];
        let mut stored = 0.0;
        let mut loaded = 0usize;
        for &e in &self.elements {
            let p = self.system.forces[e].accumulate_with_power(&self.frames, &mut self.wrenches);
            stored += p.potential;
            d[E_ELEM] += p.dissipation;
            d[W_APPLIED] += p.applied;
        }
        for now in self.now.iter_mut() {
            now.active = false;
        }
        for ci in 0..self.contacts.len() {
            let (c, sign) = self.contacts[ci];
            let system = self.system;
            let contact = &system.contacts[c];
            let mut geometry = std::mem::take(&mut self.geometry);
            let mut wrenches = std::mem::take(&mut self.wrenches);
            let frames = std::mem::take(&mut self.frames);
            let mut sink = |tr: &TrackState| {
                d[E_DAMP] += tr.damping_power;
                d[E_FRIC] += tr.friction_power;
                let Some(s) = self.slot((tr.contact, tr.track)) else {
                    return;
                };
                let base = TRACKS + s * PER_TRACK;
                let friction = (tr.force - tr.normal * tr.normal_force) * sign;
                d[base + T_PN] += tr.normal_force;
                for i in 0..3 {
                    d[base + T_PT + i] += friction[i];
                }
                d[base + T_NSLIP] += tr.normal_force * tr.slip_speed;
                d[base + T_DAMP] += tr.damping_power;
                d[base + T_FRIC] += tr.friction_power;
                self.now[s] = TrackNow {
                    active: true,
                    penetration: tr.penetration,
                    rate: tr.penetration_rate,
                };
                self.last_normal[s] = tr.normal;
            };
            stored += contact.evaluate_with(
                c as u32,
                &frames,
                Some(&mut wrenches),
                &mut sink,
                &mut geometry,
                EvaluationOutputs {
                    points: Some(&mut |_: &PointLoad| loaded += 1),
                    ..EvaluationOutputs::default()
                },
            );
            self.geometry = geometry;
            self.wrenches = wrenches;
            self.frames = frames;
        }
        // The prescribed motions deliver minus the power of the forces on them.
        for &k in &self.kinematic {
            let (force, torque) = self.wrenches[k];
            let f = &self.frames[k];
            d[W_DRIVE] -= force.dot(&f.velocity) + torque.dot(&f.angular_velocity);
        }
        d[W_GRAV] = gravity.dot(&velocity);
        self.stored = stored;
        self.loaded_points = loaded;
        // Newton-Euler of the body, as `MultibodySystem::derivative_with` (its quaternion rate
        // from the normalised rotation).
        let (force, torque) = self.wrenches[self.body];
        d[POS..POS + 3].copy_from_slice(velocity.as_slice());
        let qn = rotation.quaternion();
        let qd = qn * Quaternion::new(0.0, omega_b.x, omega_b.y, omega_b.z) * 0.5;
        d[QUAT] = qd.w;
        d[QUAT + 1] = qd.i;
        d[QUAT + 2] = qd.j;
        d[QUAT + 3] = qd.k;
        let a = force / self.mass;
        d[VEL..VEL + 3].copy_from_slice(a.as_slice());
        let tau_b = rotation.inverse() * torque;
        let wdot = self.inverse_inertia * (tau_b - omega_b.cross(&(self.inertia * omega_b)));
        d[OMEGA..OMEGA + 3].copy_from_slice(wdot.as_slice());
        d[TIME] = 1.0;
        d
    }

    pub(super) fn kinetic_energy(&self, y: &State) -> f64 {
        let v = Vector3::new(y[VEL], y[VEL + 1], y[VEL + 2]);
        let w = Vector3::new(y[OMEGA], y[OMEGA + 1], y[OMEGA + 2]);
        0.5 * self.mass * v.norm_squared() + 0.5 * w.dot(&(self.inertia * w))
    }
}

pub(super) fn normalize_quaternion(state: &mut State) {
    let n = state[QUAT..QUAT + 4]
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt();
    if n > 0.0 {
        state[QUAT..QUAT + 4].iter_mut().for_each(|x| *x /= n);
    }
}
