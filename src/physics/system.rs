//! A multibody system: bodies, gravity, force elements and contacts, and its equations of
//! motion `dy/dt = f(t, y)` (Newton-Euler per body, quaternion kinematics).

use super::body::{frame_from_state, BodyFrame, BodyKind, RigidBody, BODY_STATE_LEN};
use super::contact::{Contact, GeometryCache, TrackState};
use super::forces::{ForceElement, Wrench};
use nalgebra::{Matrix3, Quaternion, Vector3};

/// The model the integrator advances.
#[derive(Clone)]
pub struct MultibodySystem {
    /// All bodies; dynamic ones own `BODY_STATE_LEN` entries of the state from their offset.
    pub bodies: Vec<RigidBody>,
    /// Gravitational acceleration, world frame, m/s² (thesis: -y, 9.80665).
    pub gravity: Vector3<f64>,
    /// Force elements.
    pub forces: Vec<ForceElement>,
    /// Contacts.
    pub contacts: Vec<Contact>,
    inverse_inertia: Vec<Matrix3<f64>>,
    state_len: usize,
}

/// Scratch buffers so a derivative evaluation does not allocate.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    /// Frames of all bodies at the evaluation instant.
    pub frames: Vec<BodyFrame>,
    /// Accumulated wrenches.
    pub wrenches: Vec<Wrench>,
    /// Contact overlaps kept between derivative evaluations at the same poses.
    pub geometry: GeometryCache,
}

/// Energy bookkeeping of a state, J.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energy {
    /// Kinetic energy of dynamic bodies (world frame), J.
    pub kinetic: f64,
    /// Gravitational potential, J (zero at the origin).
    pub gravitational: f64,
    /// Elastic energy in springs, bushings and contacts, J.
    pub elastic: f64,
}

impl Energy {
    /// Total mechanical energy, J.
    pub fn total(&self) -> f64 {
        self.kinetic + self.gravitational + self.elastic
    }
}

impl MultibodySystem {
    /// Assembles a system; dynamic bodies get consecutive state offsets in body order.
    pub fn new(
        mut bodies: Vec<RigidBody>,
        gravity: Vector3<f64>,
        forces: Vec<ForceElement>,
        contacts: Vec<Contact>,
    ) -> Self {
        let mut offset = 0;
        let mut inverse_inertia = Vec::with_capacity(bodies.len());
        for b in bodies.iter_mut() {
            if let BodyKind::Dynamic { offset: o } = &mut b.kind {
                *o = offset;
                offset += BODY_STATE_LEN;
            }
            inverse_inertia.push(b.mass.inertia.try_inverse().unwrap_or_else(Matrix3::zeros));
        }
        Self {
            bodies,
            gravity,
            forces,
            contacts,
            inverse_inertia,
            state_len: offset,
        }
    }

    /// Length of the state vector.
    pub fn state_len(&self) -> usize {
        self.state_len
    }

    /// Index of a body by name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Fresh workspace sized for this system.
    pub fn workspace(&self) -> Workspace {
        Workspace {
            frames: Vec::with_capacity(self.bodies.len()),
            wrenches: vec![(Vector3::zeros(), Vector3::zeros()); self.bodies.len()],
            geometry: GeometryCache::default(),
        }
    }

    /// Fills `ws.frames` with every body's pose and velocity at (t, y).
    pub fn frames(&self, t: f64, y: &[f64], ws: &mut Workspace) {
        ws.frames.clear();
        for b in &self.bodies {
            let f = match &b.kind {
                BodyKind::Dynamic { offset } => frame_from_state(y, *offset),
                BodyKind::Kinematic(m) => {
                    let pose = m.pose(t);
                    let (v, w) = m.velocity(t);
                    BodyFrame {
                        position: pose.translation.vector,
                        rotation: pose.rotation,
                        velocity: v,
                        angular_velocity: w,
                    }
                }
            };
            ws.frames.push(f);
        }
    }

    /// Evaluates dy/dt into `dy`. Calls `on_track` for every active contact track.
    pub fn derivative_with(
        &self,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
        ws: &mut Workspace,
        on_track: &mut dyn FnMut(&TrackState),
    ) {
        self.frames(t, y, ws);
        for w in ws.wrenches.iter_mut() {
            *w = (Vector3::zeros(), Vector3::zeros());
        }
        for (i, b) in self.bodies.iter().enumerate() {
            if matches!(b.kind, BodyKind::Dynamic { .. }) {
                ws.wrenches[i].0 += self.gravity * b.mass.mass;
            }
        }
        for f in &self.forces {
            f.accumulate(&ws.frames, &mut ws.wrenches);
        }
        for (ci, c) in self.contacts.iter().enumerate() {
            c.evaluate_with(
                ci as u32,
                &ws.frames,
                Some(&mut ws.wrenches),
                on_track,
                &mut ws.geometry,
            );
        }
        for (i, b) in self.bodies.iter().enumerate() {
            let BodyKind::Dynamic { offset } = b.kind else {
                continue;
            };
            let s = &y[offset..offset + BODY_STATE_LEN];
            let d = &mut dy[offset..offset + BODY_STATE_LEN];
            let q = Quaternion::new(s[3], s[4], s[5], s[6]);
            let omega_b = Vector3::new(s[10], s[11], s[12]);
            // Position and quaternion kinematics: q' = 1/2 q ⊗ (0, ω_body).
            d[0] = s[7];
            d[1] = s[8];
            d[2] = s[9];
            let qd = q * Quaternion::new(0.0, omega_b.x, omega_b.y, omega_b.z) * 0.5;
            d[3] = qd.w;
            d[4] = qd.i;
            d[5] = qd.j;
            d[6] = qd.k;
            let (force, torque) = ws.wrenches[i];
            let a = force / b.mass.mass;
            d[7] = a.x;
            d[8] = a.y;
            d[9] = a.z;
            // Euler's equations in body axes.
            let rot = ws.frames[i].rotation;
            let tau_b = rot.inverse() * torque;
            let inertia = &b.mass.inertia;
            let wdot = self.inverse_inertia[i] * (tau_b - omega_b.cross(&(inertia * omega_b)));
            d[10] = wdot.x;
            d[11] = wdot.y;
            d[12] = wdot.z;
        }
    }

    /// dy/dt without track output.
    pub fn derivative(&self, t: f64, y: &[f64], dy: &mut [f64], ws: &mut Workspace) {
        self.derivative_with(t, y, dy, ws, &mut |_| {})
    }

    /// Active tracks at (t, y) (no forces accumulated).
    pub fn tracks(&self, t: f64, y: &[f64], ws: &mut Workspace, sink: &mut dyn FnMut(&TrackState)) {
        self.frames(t, y, ws);
        for (ci, c) in self.contacts.iter().enumerate() {
            c.evaluate(ci as u32, &ws.frames, None, sink);
        }
    }

    /// Mechanical energy of the state (kinematic bodies excluded from kinetic energy).
    pub fn energy(&self, t: f64, y: &[f64], ws: &mut Workspace) -> Energy {
        self.frames(t, y, ws);
        let mut e = Energy::default();
        for (i, b) in self.bodies.iter().enumerate() {
            let BodyKind::Dynamic { offset } = b.kind else {
                continue;
            };
            let f = &ws.frames[i];
            let wb = Vector3::new(y[offset + 10], y[offset + 11], y[offset + 12]);
            e.kinetic += 0.5 * b.mass.mass * f.velocity.norm_squared()
                + 0.5 * wb.dot(&(b.mass.inertia * wb));
            e.gravitational -= b.mass.mass * self.gravity.dot(&f.position);
        }
        let mut wr = vec![(Vector3::zeros(), Vector3::zeros()); self.bodies.len()];
        for f in &self.forces {
            e.elastic += f.accumulate(&ws.frames, &mut wr);
        }
        for (ci, c) in self.contacts.iter().enumerate() {
            e.elastic += c.evaluate(ci as u32, &ws.frames, None, &mut |_| {});
        }
        e
    }

    /// Renormalises every dynamic body's quaternion in place.
    pub fn normalize(&self, y: &mut [f64]) {
        for b in &self.bodies {
            if let BodyKind::Dynamic { offset } = b.kind {
                let n = (y[offset + 3].powi(2)
                    + y[offset + 4].powi(2)
                    + y[offset + 5].powi(2)
                    + y[offset + 6].powi(2))
                .sqrt();
                if n > 0.0 && n.is_finite() {
                    for k in 3..7 {
                        y[offset + k] /= n;
                    }
                }
            }
        }
    }

    /// Which quantity each state entry holds: 0 position (m), 1 quaternion, 2 velocity (m/s),
    /// 3 angular velocity (rad/s). Used to weight error norms.
    pub fn state_kinds(&self) -> Vec<u8> {
        let mut k = Vec::with_capacity(self.state_len);
        for _ in 0..self.state_len / BODY_STATE_LEN {
            k.extend_from_slice(&[0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 3, 3, 3]);
        }
        k
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::contact::GeometryMode;
    use std::path::Path;

    /// The reference model `configs/<name>.toml`.
    fn reference_model(name: &str) -> crate::models::run::BuiltModel {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
        let case = crate::models::case::load_case(&dir.join(format!("{name}.toml"))).expect("case");
        crate::models::case::build(&case, &dir).expect("model")
    }

    /// Rattle box C with the cube tilted and pressed into the floor, spinning and sliding.
    fn pressed_cube() -> (MultibodySystem, Vec<f64>) {
        let model = reference_model("rattle-box-c");
        let mut y = model.initial_state.clone();
        y[1] -= 3e-5; // 30 µm further into the floor
        let tilt = nalgebra::UnitQuaternion::from_euler_angles(2e-3, 1e-3, -4e-3);
        let q = tilt.into_inner();
        y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        y[7..13].copy_from_slice(&[0.3, -0.05, 0.1, 2.0, -1.0, 0.5]);
        (model.system, y)
    }

    #[test]
    fn replayed_geometry_gives_the_same_derivative_for_velocity_changes() {
        let (sys, y) = pressed_cube();
        let mut ws = sys.workspace();
        let n = sys.state_len();
        let (mut computed, mut replayed) = (vec![0.0; n], vec![0.0; n]);
        let mut tracks = 0;
        sys.tracks(0.0, &y, &mut ws, &mut |_| tracks += 1);
        assert!(tracks >= 1, "the cube must touch the floor");
        ws.geometry.set_mode(GeometryMode::Record);
        sys.derivative(0.0, &y, &mut computed, &mut ws);
        for j in 7..13 {
            let mut yv = y.clone();
            yv[j] += 1e-3 * (j as f64);
            ws.geometry.set_mode(GeometryMode::Compute);
            sys.derivative(0.0, &yv, &mut computed, &mut ws);
            ws.geometry.set_mode(GeometryMode::Replay);
            sys.derivative(0.0, &yv, &mut replayed, &mut ws);
            assert_eq!(computed, replayed, "velocity column {j}");
        }
        // A pose change is not covered by the replay: the forces differ.
        let mut yp = y.clone();
        yp[1] -= 1e-6;
        ws.geometry.set_mode(GeometryMode::Compute);
        sys.derivative(0.0, &yp, &mut computed, &mut ws);
        ws.geometry.set_mode(GeometryMode::Replay);
        sys.derivative(0.0, &yp, &mut replayed, &mut ws);
        assert_ne!(computed[8], replayed[8]);
    }

    #[test]
    fn pose_columns_replay_only_contacts_of_other_bodies() {
        let model = reference_model("launcher-design");
        let (sys, y) = (model.system, model.initial_state);
        let mut ws = sys.workspace();
        let n = sys.state_len();
        let (mut computed, mut replayed) = (vec![0.0; n], vec![0.0; n]);
        ws.geometry.set_mode(GeometryMode::Record);
        sys.derivative(0.0, &y, &mut computed, &mut ws);
        for (i, b) in sys.bodies.iter().enumerate() {
            let BodyKind::Dynamic { offset } = b.kind else {
                continue;
            };
            for j in offset..offset + 7 {
                let mut yp = y.clone();
                yp[j] += 2e-6;
                ws.geometry.set_mode(GeometryMode::Compute);
                sys.derivative(0.0, &yp, &mut computed, &mut ws);
                ws.geometry.set_mode(GeometryMode::ReplayExcept(i));
                sys.derivative(0.0, &yp, &mut replayed, &mut ws);
                assert_eq!(computed, replayed, "body {} column {j}", b.name);
            }
        }
    }
}
