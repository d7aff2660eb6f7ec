//! The carrier: the kinematic body that carries a model's excitation (the launcher's rail, the
//! rattle box's tube), whose rigid motion the integrators take out of each dynamic body's
//! position and velocity before they apply the relative tolerance (docs/journal/performance.md,
//! twenty-second pass).

use super::*;

impl MultibodySystem {
    /// Names `body` the carrier: the kinematic body whose rigid motion the integrators take
    /// out of every dynamic body's position and velocity before they apply the relative
    /// tolerance ([`Self::carrier_entries`]). A body that is not kinematic leaves the system
    /// without a carrier (the tolerance then applies to the world-frame state).
    pub fn with_carrier(mut self, body: usize) -> Self {
        let kinematic = self
            .bodies
            .get(body)
            .is_some_and(|b| matches!(b.kind, BodyKind::Kinematic(_)));
        self.carrier = kinematic.then_some(body);
        self
    }

    /// The carrier's index, if the model names one ([`Self::with_carrier`]).
    pub fn carrier(&self) -> Option<usize> {
        self.carrier
    }

    /// The carrier's rigid motion at `t`, as a state vector: for each dynamic body of `y`, the
    /// position of the carrier's origin, the velocity of the carrier's point under the body's
    /// centre of mass (`v_c + ω_c × (x − x_c)`) and the carrier's angular velocity in the
    /// body's frame (`Rᵀ ω_c`); zero for the quaternions. `y` minus this is each body's motion
    /// relative to the carrier, which a relative tolerance should scale with: a rail or
    /// fixture shaking at 0.1 m/s would otherwise loosen the tolerance on every velocity
    /// riding on it by `rel × 0.1 m/s`, although only the motion relative to it slips, wears
    /// and dissipates. Zeros without a carrier.
    ///
    /// The carrier's frame comes from `ws` when its last evaluation was at `t` (the step's
    /// start and the last stage's end are), else from its prescribed motion.
    pub fn carrier_entries(&self, t: f64, y: &[f64], ws: &Workspace, out: &mut [f64]) {
        out.fill(0.0);
        let Some(c) = self.carrier else {
            return;
        };
        let (origin, v, w) = match (&self.bodies[c].kind, ws.frames.get(c)) {
            (_, Some(f)) if ws.kinematic_time == Some(t) => {
                (f.position, f.velocity, f.angular_velocity)
            }
            (BodyKind::Kinematic(motion), _) => {
                let (v, w) = motion.velocity(t);
                (motion.pose(t).translation.vector, v, w)
            }
            (BodyKind::Dynamic { .. }, _) => return,
        };
        for b in &self.bodies {
            let BodyKind::Dynamic { offset } = b.kind else {
                continue;
            };
            let frame = frame_from_state(y, offset);
            let velocity = v + w.cross(&(frame.position - origin));
            let spin = frame.rotation.inverse_transform_vector(&w);
            let s = &mut out[offset..offset + BODY_STATE_LEN];
            s[0..3].copy_from_slice(origin.as_slice());
            s[7..10].copy_from_slice(velocity.as_slice());
            s[10..13].copy_from_slice(spin.as_slice());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A carrier spinning about z at `omega` while translating at `v`, its origin at `v t`.
    struct Spinning {
        v: Vector3<f64>,
        omega: f64,
    }

    impl crate::physics::body::KinematicMotion for Spinning {
        fn pose(&self, t: f64) -> nalgebra::Isometry3<f64> {
            nalgebra::Isometry3::new(self.v * t, Vector3::z() * (self.omega * t))
        }
        fn velocity(&self, _t: f64) -> (Vector3<f64>, Vector3<f64>) {
            (self.v, Vector3::z() * self.omega)
        }
        fn acceleration(&self, _t: f64) -> Vector3<f64> {
            Vector3::zeros()
        }
    }

    fn body(kind: BodyKind) -> RigidBody {
        RigidBody {
            name: "b".into(),
            mass: crate::physics::body::MassProperties {
                mass: 1.0,
                inertia: Matrix3::identity(),
            },
            kind,
        }
    }

    #[test]
    fn a_body_riding_rigidly_on_the_carrier_has_no_motion_relative_to_it() {
        // Rigid-body kinematics: a point fixed to a frame moving at (v, ω) moves at
        // v + ω × (x − x_c) and turns at ω; in its own axes the turn is Rᵀ ω.
        let carrier = Spinning {
            v: Vector3::new(0.3, -0.1, 0.05),
            omega: 7.0,
        };
        let t = 0.4;
        let origin = carrier.v * t;
        let sys = MultibodySystem::new(
            vec![
                body(BodyKind::Dynamic { offset: 0 }),
                body(BodyKind::Kinematic(std::sync::Arc::new(carrier))),
            ],
            Vector3::zeros(),
            vec![],
            vec![],
        )
        .with_carrier(1);
        assert_eq!(sys.carrier(), Some(1));
        let x = origin + Vector3::new(0.02, -0.01, 0.3);
        let rotation = nalgebra::UnitQuaternion::from_euler_angles(0.2, -0.4, 0.9);
        let omega = Vector3::z() * 7.0;
        let mut y = vec![0.0; sys.state_len()];
        crate::physics::body::write_state(
            &mut y,
            0,
            &nalgebra::Isometry3::from_parts(x.into(), rotation),
            Vector3::new(0.3, -0.1, 0.05) + omega.cross(&(x - origin)),
            omega,
        );
        let mut out = vec![f64::NAN; sys.state_len()];
        // No evaluation yet: the carrier's frame comes from its motion.
        sys.carrier_entries(t, &y, &sys.workspace(), &mut out);
        for i in 7..13 {
            assert!(
                (y[i] - out[i]).abs() < 1e-14,
                "entry {i}: {} vs {}",
                y[i],
                out[i]
            );
        }
        let relative = Vector3::new(y[0] - out[0], y[1] - out[1], y[2] - out[2]);
        assert!((relative - (x - origin)).norm() < 1e-15);
        assert!(
            out[3..7].iter().all(|&q| q == 0.0),
            "quaternions are not shifted"
        );
        // From the workspace after an evaluation at t: the same entries.
        let mut ws = sys.workspace();
        sys.frames(t, &y, &mut ws);
        let mut again = vec![f64::NAN; sys.state_len()];
        sys.carrier_entries(t, &y, &ws, &mut again);
        assert_eq!(out, again);
    }

    #[test]
    fn a_dynamic_body_is_no_carrier() {
        let sys = MultibodySystem::new(
            vec![body(BodyKind::Dynamic { offset: 0 })],
            Vector3::zeros(),
            vec![],
            vec![],
        )
        .with_carrier(0)
        .with_carrier(5);
        assert_eq!(sys.carrier(), None);
        let mut out = vec![1.0; sys.state_len()];
        sys.carrier_entries(0.0, &[0.0; 13], &sys.workspace(), &mut out);
        assert!(out.iter().all(|&v| v == 0.0));
    }
}
