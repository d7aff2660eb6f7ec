//! A multibody system: bodies, gravity, force elements and contacts, and its equations of
//! motion `dy/dt = f(t, y)` (Newton-Euler per body, quaternion kinematics).

use super::body::{frame_from_state, BodyFrame, BodyKind, RigidBody, BODY_STATE_LEN};
use super::contact::{
    Contact, EvaluationOutputs, GeometryCache, GeometryMode, JacobianScope, Matrix6x12, PointLoad,
    TrackLinearization, TrackMoments, TrackState,
};
use super::forces::{ForceElement, Wrench};
use nalgebra::{Matrix3, Matrix3x4, Quaternion, Vector3};
use std::ops::AddAssign;

mod carrier;

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
    /// The kinematic body that carries the excitation (rail, shaker fixture), if the model
    /// names one: [`Self::carrier_entries`].
    carrier: Option<usize>,
}

/// Scratch buffers so a derivative evaluation does not allocate.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    /// Frames of all bodies at the evaluation instant.
    pub frames: Vec<BodyFrame>,
    /// Instant of the kinematic bodies' frames in `frames`.
    kinematic_time: Option<f64>,
    /// Accumulated wrenches.
    pub wrenches: Vec<Wrench>,
    /// Contact overlaps kept between derivative evaluations at the same poses.
    pub geometry: GeometryCache,
    /// Record each active track's force derivatives during a derivative evaluation.
    pub linearize: bool,
    /// Which nodes' derivatives `linearize` takes: every node's (the exact Jacobian, the
    /// default) or a Newton matrix's ([`JacobianScope`]).
    pub jacobian_scope: JacobianScope,
    /// Force derivatives per contact point or node: filled only by an evaluation asked for
    /// them without moments (the per-point reference tests/engine/face_contact_blocks.rs
    /// compares the moments with); [`MultibodySystem::derivative`] asks for both, so the
    /// contacts sum into [`Self::linearization_moments`] and this stays empty there.
    pub linearizations: Vec<TrackLinearization>,
    /// The contacts' force derivatives of the last evaluation (when `linearize`), one sum per
    /// track: the lattice's points and the exact face contact's nodes alike.
    pub linearization_moments: Vec<TrackMoments>,
    /// Leave the contacts out of the derivative (the contact-free part of the Jacobian).
    pub skip_contacts: bool,
    /// Keep the active tracks of each derivative evaluation in `tracks`.
    pub keep_tracks: bool,
    /// Stored energy and power terms of the last derivative evaluation with contacts (like
    /// `tracks`, those of the step's last evaluation after a step).
    pub power: PowerBalance,
    /// Active tracks of the last derivative evaluation with contacts (when `keep_tracks`).
    /// After [`Integrator::advance`](super::integrator::Integrator::advance) these are the
    /// tracks of the step's last evaluation: the accepted state's, or with the contact-aware
    /// Newton its last iterate's (first order in Newton's last update off the accepted state),
    /// with the accepted state's areas.
    pub tracks: Vec<TrackState>,
    /// Scratch of [`MultibodySystem::contact_jacobian`]: one block per (source, target) body
    /// (sized there, where it is filled).
    jacobian_blocks: Vec<Option<Matrix6x12>>,
    /// Scratch of [`MultibodySystem::energy`]: the force elements' wrenches it discards (sized
    /// there).
    energy_wrenches: Vec<Wrench>,
}

/// The stored elastic energy and the power terms of one derivative evaluation, for the energy
/// account `E_mech + W_dissipated - W_drive - W_applied = E_mech(0)` (SPEC §2).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PowerBalance {
    /// Elastic energy stored in contacts and force elements, J.
    pub elastic_energy: f64,
    /// Power dissipated by contact damping (IMPACT damping and its clamp), W.
    pub contact_damping: f64,
    /// Power dissipated by contact friction, W.
    pub contact_friction: f64,
    /// Power dissipated by force elements (dampers, bushings, a clamped one-sided spring), W.
    pub element_dissipation: f64,
    /// Power the prescribed motion of the kinematic bodies delivers to the system: minus the
    /// power of the forces acting on them, W.
    pub drive: f64,
    /// Power of applied loads (constant forces), W.
    pub applied: f64,
}

impl PowerBalance {
    /// Total dissipated power, W.
    pub fn dissipation(&self) -> f64 {
        self.contact_damping + self.contact_friction + self.element_dissipation
    }
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
            carrier: None,
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
            kinematic_time: None,
            wrenches: vec![(Vector3::zeros(), Vector3::zeros()); self.bodies.len()],
            geometry: GeometryCache::default(),
            linearize: false,
            jacobian_scope: JacobianScope::Exact,
            linearizations: Vec::new(),
            linearization_moments: Vec::new(),
            skip_contacts: false,
            keep_tracks: false,
            power: PowerBalance::default(),
            tracks: Vec::new(),
            jacobian_blocks: Vec::new(),
            energy_wrenches: Vec::new(),
        }
    }

    /// Fills `ws.frames` with every body's pose and velocity at (t, y). Prescribed motions are
    /// evaluated once per instant: Newton iterations and Jacobian columns share `t`.
    pub fn frames(&self, t: f64, y: &[f64], ws: &mut Workspace) {
        let kinematic_cached = ws.kinematic_time == Some(t) && ws.frames.len() == self.bodies.len();
        for (i, b) in self.bodies.iter().enumerate() {
            let f = match &b.kind {
                BodyKind::Dynamic { offset } => frame_from_state(y, *offset),
                BodyKind::Kinematic(_) if kinematic_cached => continue,
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
            if i < ws.frames.len() {
                ws.frames[i] = f;
            } else {
                ws.frames.push(f);
            }
        }
        ws.kinematic_time = Some(t);
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
        let mut power = PowerBalance::default();
        for f in &self.forces {
            let p = f.accumulate_with_power(&ws.frames, &mut ws.wrenches);
            power.elastic_energy += p.potential;
            power.element_dissipation += p.dissipation;
            power.applied += p.applied;
        }
        ws.linearizations.clear();
        ws.linearization_moments.clear();
        if !ws.skip_contacts {
            let keep = ws.keep_tracks;
            let mut kept = std::mem::take(&mut ws.tracks);
            kept.clear();
            let (mut damping, mut friction) = (0.0, 0.0);
            let mut sink = |tr: &TrackState| {
                damping += tr.damping_power;
                friction += tr.friction_power;
                if keep {
                    kept.push(*tr);
                }
                on_track(tr);
            };
            for (ci, c) in self.contacts.iter().enumerate() {
                power.elastic_energy += c.evaluate_with(
                    ci as u32,
                    &ws.frames,
                    Some(&mut ws.wrenches),
                    &mut sink,
                    &mut ws.geometry,
                    EvaluationOutputs {
                        linearizations: ws.linearize.then_some(&mut ws.linearizations),
                        moments: ws.linearize.then_some(&mut ws.linearization_moments),
                        points: None,
                        scope: ws.jacobian_scope,
                    },
                );
            }
            power.contact_damping = damping;
            power.contact_friction = friction;
            ws.tracks = kept;
            // The kinematic bodies' motion delivers minus the power of the forces on them.
            for (i, b) in self.bodies.iter().enumerate() {
                if matches!(b.kind, BodyKind::Kinematic(_)) {
                    let (force, torque) = ws.wrenches[i];
                    let f = &ws.frames[i];
                    power.drive -= force.dot(&f.velocity) + torque.dot(&f.angular_velocity);
                }
            }
            ws.power = power;
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

    /// Adds the contact forces' Jacobian `∂(dy/dt)/∂y` (column-major `n × n`) at the state of
    /// the last derivative evaluation, made with `ws.linearize` set, to `jac`.
    ///
    /// Per contact point (see [`TrackLinearization`]) the force derivative with respect to each
    /// dynamic body's velocities and pose is mapped to the state: world linear velocity
    /// directly, body-frame angular velocity through the rotation, position directly, and the
    /// quaternion through `δθ = 2 vec(δq ⊗ q*)` (world small rotation); the force enters the
    /// linear acceleration as `F/m` and the body-frame angular acceleration as `I⁻¹ Rᵀ (r × F)`.
    /// Through the pose: the penetration (`∂w`), the point's velocity `v_rel(p)` (its lever and
    /// a's world angular velocity turn with body a: the damping rate and the slip change), the
    /// torque's lever, and the turn of the body-frame torque `Rᵀ τ` with the body. Left out:
    /// the turn of a face's normal with body b (the gyroscopic term is in the contact-free
    /// part). Checked against finite differences on every column (`physics::system` tests).
    pub fn contact_jacobian(&self, y: &[f64], ws: &mut Workspace, jac: &mut [f64]) {
        let n = self.state_len;
        let nb = self.bodies.len();
        // Per (source body k, target body m): the force and the torque about m's centre of
        // mass on m, differentiated by k's [δx, δθ, δv, δω_world]. The tracks' moments and any
        // per-point records (in the points' order) are summed into these blocks, which are mapped
        // to the state once.
        let mut blocks = std::mem::take(&mut ws.jacobian_blocks);
        blocks.clear();
        blocks.resize(nb * nb, None);
        let dynamic = |k: usize| matches!(self.bodies[k].kind, BodyKind::Dynamic { .. });
        for sum in &ws.linearization_moments {
            sum.add_blocks(&ws.frames, dynamic, &mut blocks);
        }
        for lin in &ws.linearizations {
            let ends = [(lin.body_a, 1.0), (lin.body_b, -1.0)];
            let nrm = lin.normal;
            let g = lin.dforce_dfn;
            // The rate terms below use ∂w/∂θ = ∂ẇ/∂ω = −σ (r × n)ᵀ at the force's own point:
            // force, rates and penetration belong to one material point.
            debug_assert_eq!(lin.deepest_point, lin.point);
            // ∂F/∂v_rel at the point, through ẇ = −n·v_rel and s = P v_rel: `D P − c g nᵀ`,
            // with `D P = D` (the slip derivative `D` is tangential on both sides: D n = 0).
            let df_dvrel = lin.dforce_slip_with_rate(&g, &nrm);
            let omega_a = ws.frames[lin.body_a].angular_velocity;
            let omega_b = ws.frames[lin.body_b].angular_velocity;
            let r_centre = lin.centre.coords - ws.frames[lin.body_a].position;
            let r_centre_x = r_centre.cross_matrix();
            let force_x = lin.force.cross_matrix();
            for &(k, sign_k) in &ends {
                if !matches!(self.bodies[k].kind, BodyKind::Dynamic { .. }) {
                    continue;
                }
                let fk = &ws.frames[k];
                let r_point = lin.point.coords - fk.position;
                // ∂w/∂(δx, δθ) and ∂ẇ/∂(v, ω_world): −σ (nᵀ, (r × n)ᵀ).
                let lever = r_point.cross(&nrm);
                // dF/d(k's δv, δω_world) = σ ∂F/∂v_rel [I, −[r]×] (the point's velocity).
                let a_r = df_dvrel * r_point.cross_matrix();
                let mut df_rates = nalgebra::Matrix3x6::<f64>::zeros();
                df_rates
                    .fixed_view_mut::<3, 3>(0, 0)
                    .copy_from(&(df_dvrel * sign_k));
                df_rates
                    .fixed_view_mut::<3, 3>(0, 3)
                    .copy_from(&(a_r * -sign_k));
                // dF/d(k's δx, δθ): the penetration, and v_rel through the point's motion (a),
                // its lever (a, b) and the turn of a's world angular velocity (its state is in
                // body axes): ∂v_rel/∂δx = −[ω_b]× (a), [ω_b]× (b); ∂v_rel/∂δθ (a) =
                // −[ω_a − ω_b]× [r_c]× + [r]× [ω_a]× ([u]× [v]× = v uᵀ − (u·v) I).
                let mut df = nalgebra::Matrix3x6::<f64>::zeros();
                let mut d_x = g * (nrm.transpose() * (-sign_k * lin.dfn_dw));
                if omega_b != Vector3::zeros() {
                    d_x += df_dvrel * (omega_b.cross_matrix() * -sign_k);
                }
                let mut d_theta = g * (lever.transpose() * (-sign_k * lin.dfn_dw));
                if sign_k > 0.0 {
                    let u = omega_b - omega_a;
                    let dvrel_dtheta = r_centre * u.transpose()
                        - Matrix3::from_diagonal_element(u.dot(&r_centre))
                        + omega_a * r_point.transpose()
                        - Matrix3::from_diagonal_element(r_point.dot(&omega_a));
                    d_theta += df_dvrel * dvrel_dtheta;
                }
                df.fixed_view_mut::<3, 3>(0, 0).copy_from(&d_x);
                df.fixed_view_mut::<3, 3>(0, 3).copy_from(&d_theta);
                // Torque change through the lever (p − o_m) at fixed force, per target body m.
                let (dtau_a_dtheta, dtau_b_dx, dtau_b_dtheta) = if sign_k > 0.0 {
                    let fr = force_x * r_centre_x;
                    (Some(fr), force_x, Some(-fr))
                } else {
                    (None, -force_x, None)
                };
                for &(m, sign_m) in &ends {
                    if !matches!(self.bodies[m].kind, BodyKind::Dynamic { .. }) {
                        continue;
                    }
                    let r_m = lin.point.coords - ws.frames[m].position;
                    let block = blocks[k * nb + m].get_or_insert_with(Matrix6x12::zeros);
                    let force = df * sign_m;
                    let force_rates = df_rates * sign_m;
                    let mut torque = cross_columns(&r_m, &force);
                    let (dtau_dx, dtau_dtheta) = if sign_m > 0.0 {
                        (None, dtau_a_dtheta)
                    } else {
                        (Some(dtau_b_dx), dtau_b_dtheta)
                    };
                    if let Some(d) = dtau_dx {
                        torque.fixed_view_mut::<3, 3>(0, 0).add_assign(&d);
                    }
                    if let Some(d) = dtau_dtheta {
                        torque.fixed_view_mut::<3, 3>(0, 3).add_assign(&d);
                    }
                    if m == k {
                        // The body-frame torque Rᵀ τ turns with the body: δ(Rᵀ τ) = Rᵀ [τ]× δθ.
                        let tau = r_m.cross(&(lin.force * sign_m));
                        torque
                            .fixed_view_mut::<3, 3>(0, 3)
                            .add_assign(&tau.cross_matrix());
                    }
                    block.fixed_view_mut::<3, 6>(0, 0).add_assign(&force);
                    block.fixed_view_mut::<3, 6>(0, 6).add_assign(&force_rates);
                    block.fixed_view_mut::<3, 6>(3, 0).add_assign(&torque);
                    block
                        .fixed_view_mut::<3, 6>(3, 6)
                        .add_assign(&cross_columns(&r_m, &force_rates));
                }
            }
        }
        for k in 0..nb {
            let BodyKind::Dynamic { offset: ok } = self.bodies[k].kind else {
                continue;
            };
            let theta_of_q = rotation_tangent(&y[ok + 3..ok + 7]);
            let rot_k = ws.frames[k].rotation.to_rotation_matrix().into_inner();
            for m in 0..nb {
                let Some(block) = &blocks[k * nb + m] else {
                    continue;
                };
                let BodyKind::Dynamic { offset: om } = self.bodies[m].kind else {
                    continue;
                };
                let inv_mass = 1.0 / self.bodies[m].mass.mass;
                let rot_m = ws.frames[m].rotation.to_rotation_matrix().into_inner();
                let to_body = self.inverse_inertia[m] * rot_m.transpose();
                // Columns of k's state: position, quaternion (through δθ), velocity, body-frame
                // angular velocity (through the rotation).
                let dq = block.fixed_view::<6, 3>(0, 3) * theta_of_q;
                let domega = block.fixed_view::<6, 3>(0, 9) * rot_k;
                let mut column = |state_col: usize, d: nalgebra::Vector6<f64>| {
                    let lin_acc = d.fixed_rows::<3>(0) * inv_mass;
                    let ang_acc = to_body * d.fixed_rows::<3>(3);
                    let col = &mut jac[state_col * n..(state_col + 1) * n];
                    for r in 0..3 {
                        col[om + 7 + r] += lin_acc[r];
                        col[om + 10 + r] += ang_acc[r];
                    }
                };
                for c in 0..3 {
                    column(ok + c, block.column(c).into_owned());
                    column(ok + 7 + c, block.column(6 + c).into_owned());
                    column(ok + 10 + c, domega.column(c).into_owned());
                }
                for c in 0..4 {
                    column(ok + 3 + c, dq.column(c).into_owned());
                }
            }
        }
        ws.jacobian_blocks = blocks;
    }

    /// After an implicit step accepted at `(t, y)` with the tracks of its last Newton iterate
    /// in `ws.tracks`: refreshes every contact's overlaps at `y` ([`GeometryMode::Refresh`],
    /// the patches the next step's iterates hold) and gives those tracks the thesis 2.5 area
    /// at `y` ([`Contact::refresh_areas`]). No force is evaluated.
    pub fn refresh_patches(&self, t: f64, y: &[f64], ws: &mut Workspace) {
        self.frames(t, y, ws);
        ws.geometry.set_mode(GeometryMode::Refresh);
        let mut tracks = std::mem::take(&mut ws.tracks);
        for (ci, c) in self.contacts.iter().enumerate() {
            c.refresh_areas(ci as u32, &ws.frames, &mut ws.geometry, &mut tracks);
        }
        ws.tracks = tracks;
        ws.geometry.set_mode(GeometryMode::Compute);
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

    /// Active tracks at (t, y) with every touching contact point's load (each track's points
    /// before the track); no forces accumulated.
    pub fn tracks_with_points(
        &self,
        t: f64,
        y: &[f64],
        ws: &mut Workspace,
        sink: &mut dyn FnMut(&TrackState),
        points: &mut dyn FnMut(&PointLoad),
    ) {
        self.frames(t, y, ws);
        for (ci, c) in self.contacts.iter().enumerate() {
            c.evaluate_points(ci as u32, &ws.frames, sink, points);
        }
    }

    /// Mechanical energy of the state (kinematic bodies excluded from kinetic energy).
    pub fn energy(&self, t: f64, y: &[f64], ws: &mut Workspace) -> Energy {
        let mut e = self.motion_energy(t, y, ws);
        let mut wr = std::mem::take(&mut ws.energy_wrenches);
        wr.clear();
        wr.resize(self.bodies.len(), (Vector3::zeros(), Vector3::zeros()));
        for f in &self.forces {
            e.elastic += f.accumulate(&ws.frames, &mut wr);
        }
        ws.energy_wrenches = wr;
        for (ci, c) in self.contacts.iter().enumerate() {
            e.elastic += c.evaluate(ci as u32, &ws.frames, None, &mut |_| {});
        }
        e
    }

    /// Kinetic and gravitational energy of the state (`elastic` left at zero; the last
    /// derivative evaluation's [`PowerBalance::elastic_energy`] completes it without a second
    /// contact evaluation). Leaves the state's frames in `ws`.
    pub fn motion_energy(&self, t: f64, y: &[f64], ws: &mut Workspace) -> Energy {
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
        e
    }

    /// Renormalises every dynamic body's quaternion in place.
    pub fn normalize(&self, y: &mut [f64]) {
        for offset in self.dynamic_offsets() {
            if let Some(n) = quaternion_norm(y, offset) {
                y[offset + 3..offset + 7].iter_mut().for_each(|v| *v /= n);
            }
        }
    }

    /// Turns `dy = f(t, y)` into `f(t, normalize(y))`: only the quaternion rates depend on the
    /// quaternions' length (`q' = q ⊗ ω/2`); every force uses the normalised rotation.
    pub fn rescale_quaternion_rates(&self, y: &[f64], dy: &mut [f64]) {
        for offset in self.dynamic_offsets() {
            if let Some(n) = quaternion_norm(y, offset) {
                dy[offset + 3..offset + 7].iter_mut().for_each(|v| *v /= n);
            }
        }
    }

    fn dynamic_offsets(&self) -> impl Iterator<Item = usize> + '_ {
        self.bodies.iter().filter_map(|b| match b.kind {
            BodyKind::Dynamic { offset } => Some(offset),
            BodyKind::Kinematic(_) => None,
        })
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

/// `[r]× M`: the cross product of `r` with each column of `M`.
#[inline]
fn cross_columns(r: &Vector3<f64>, m: &nalgebra::Matrix3x6<f64>) -> nalgebra::Matrix3x6<f64> {
    let mut out = nalgebra::Matrix3x6::<f64>::zeros();
    for c in 0..6 {
        let (x, y, z) = (m[(0, c)], m[(1, c)], m[(2, c)]);
        out[(0, c)] = r.y * z - r.z * y;
        out[(1, c)] = r.z * x - r.x * z;
        out[(2, c)] = r.x * y - r.y * x;
    }
    out
}

/// Length of the quaternion of the body at `offset`, when positive and finite.
fn quaternion_norm(y: &[f64], offset: usize) -> Option<f64> {
    let n = y[offset + 3..offset + 7]
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    (n > 0.0 && n.is_finite()).then_some(n)
}

/// `∂θ/∂q` (3 × 4): the world small rotation `δθ = 2 vec(δq̂ ⊗ q̂*)` produced by a change `δq`
/// of the (not necessarily unit) state quaternion `q = (w, u)`, normalised as the state reader
/// does: `δθ = 2 (−δw u + w δu + u × δu) / |q|` with `(w, u)` of the unit quaternion.
fn rotation_tangent(q: &[f64]) -> Matrix3x4<f64> {
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let s = 2.0 / (norm * norm);
    let (w, u) = (q[0], Vector3::new(q[1], q[2], q[3]));
    let block = (Matrix3::identity() * w + u.cross_matrix()) * s;
    let mut m = Matrix3x4::zeros();
    m.set_column(0, &(-u * s));
    m.fixed_view_mut::<3, 3>(0, 1).copy_from(&block);
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_tangent_is_the_world_small_rotation() {
        // q' = normalise(q + δq) must rotate the frame by δθ = (∂θ/∂q) δq to first order,
        // also for a state quaternion that drifted off unit length.
        let q = nalgebra::UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1).into_inner() * 1.02;
        let qs = [q.w, q.i, q.j, q.k];
        let m = rotation_tangent(&qs);
        let r0 = nalgebra::UnitQuaternion::new_normalize(q);
        for k in 0..4 {
            let mut dq = [0.0; 4];
            dq[k] = 1e-7;
            let q1 = Quaternion::new(qs[0] + dq[0], qs[1] + dq[1], qs[2] + dq[2], qs[3] + dq[3]);
            let rel = nalgebra::UnitQuaternion::new_normalize(q1) * r0.inverse();
            let theta = rel.scaled_axis();
            let predicted = m.column(k) * 1e-7;
            assert!(
                (theta - predicted).norm() < 1e-12,
                "column {k}: {theta:?} vs {predicted:?}"
            );
        }
    }
}
