//! Rigid bodies: mass properties, dynamic state layout, and kinematic (prescribed) motion.

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};
use std::sync::Arc;

/// Number of state entries of one dynamic body: position (3), unit quaternion (4, w i j k),
/// linear velocity in world (3), angular velocity in body frame (3).
pub const BODY_STATE_LEN: usize = 13;

/// Mass properties of a rigid body about its centre of mass, in its body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Mass, kg.
    pub mass: f64,
    /// Inertia tensor about the centre of mass in body axes, kg·m².
    pub inertia: Matrix3<f64>,
}

impl MassProperties {
    /// A solid box of full side lengths `size` (m) and density (kg/m³).
    pub fn solid_box(size: Vector3<f64>, density: f64) -> Self {
        let m = density * size.x * size.y * size.z;
        let (a2, b2, c2) = (size.x * size.x, size.y * size.y, size.z * size.z);
        Self {
            mass: m,
            inertia: Matrix3::from_diagonal(&Vector3::new(
                m * (b2 + c2) / 12.0,
                m * (a2 + c2) / 12.0,
                m * (a2 + b2) / 12.0,
            )),
        }
    }

    /// A solid sphere of radius `r` (m) and density (kg/m³).
    pub fn solid_sphere(r: f64, density: f64) -> Self {
        let m = density * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
        Self {
            mass: m,
            inertia: Matrix3::from_diagonal_element(0.4 * m * r * r),
        }
    }

    /// A solid cylinder of radius `r` and length `l` with its axis along body z.
    pub fn solid_cylinder_z(mass: f64, r: f64, l: f64) -> Self {
        let it = mass * (3.0 * r * r + l * l) / 12.0;
        Self {
            mass,
            inertia: Matrix3::from_diagonal(&Vector3::new(it, it, 0.5 * mass * r * r)),
        }
    }
}

/// Motion prescribed as a function of time (kinematic bodies: rail, shaker fixture, coupon).
pub trait KinematicMotion: Send + Sync {
    /// Pose of the body frame in world at time `t` (s).
    fn pose(&self, t: f64) -> Isometry3<f64>;
    /// Linear velocity of the body-frame origin (m/s) and angular velocity (rad/s), world frame.
    fn velocity(&self, t: f64) -> (Vector3<f64>, Vector3<f64>);
    /// Linear acceleration of the body-frame origin, world frame, m/s² (for reporting).
    fn acceleration(&self, t: f64) -> Vector3<f64>;
}

/// A body that never moves.
#[derive(Debug, Clone, Copy)]
pub struct Fixed(pub Isometry3<f64>);

impl KinematicMotion for Fixed {
    fn pose(&self, _t: f64) -> Isometry3<f64> {
        self.0
    }
    fn velocity(&self, _t: f64) -> (Vector3<f64>, Vector3<f64>) {
        (Vector3::zeros(), Vector3::zeros())
    }
    fn acceleration(&self, _t: f64) -> Vector3<f64> {
        Vector3::zeros()
    }
}

/// How a body moves.
#[derive(Clone)]
pub enum BodyKind {
    /// Integrated from forces; `offset` is its first index in the state vector.
    Dynamic { offset: usize },
    /// Prescribed motion.
    Kinematic(Arc<dyn KinematicMotion>),
}

/// A rigid body of the model.
#[derive(Clone)]
pub struct RigidBody {
    /// Name used in diagnostics and reports ("cube", "missile", "rail").
    pub name: String,
    /// Mass properties (ignored for kinematic bodies).
    pub mass: MassProperties,
    /// Dynamic or kinematic.
    pub kind: BodyKind,
}

/// Pose and velocities of a body at one instant, world frame.
#[derive(Debug, Clone, Copy)]
pub struct BodyFrame {
    /// Centre-of-mass position / frame origin, m.
    pub position: Vector3<f64>,
    /// Orientation (body -> world).
    pub rotation: UnitQuaternion<f64>,
    /// Linear velocity of the origin, m/s.
    pub velocity: Vector3<f64>,
    /// Angular velocity, world frame, rad/s.
    pub angular_velocity: Vector3<f64>,
}

impl BodyFrame {
    /// Isometry body -> world.
    pub fn isometry(&self) -> Isometry3<f64> {
        Isometry3::from_parts(Translation3::from(self.position), self.rotation)
    }

    /// Velocity of the material point at world position `p`.
    #[inline]
    pub fn point_velocity(&self, p: &Point3<f64>) -> Vector3<f64> {
        self.velocity + self.angular_velocity.cross(&(p.coords - self.position))
    }

    /// World position of a point given in body coordinates.
    #[inline]
    pub fn to_world(&self, local: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.position + self.rotation * local.coords)
    }

    /// Body coordinates of a world point.
    #[inline]
    pub fn to_local(&self, world: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.rotation.inverse() * (world.coords - self.position))
    }
}

/// Reads a dynamic body's frame from the state vector.
#[inline]
pub fn frame_from_state(y: &[f64], offset: usize) -> BodyFrame {
    let s = &y[offset..offset + BODY_STATE_LEN];
    let q = nalgebra::Quaternion::new(s[3], s[4], s[5], s[6]);
    let rotation = UnitQuaternion::new_normalize(q);
    let omega_body = Vector3::new(s[10], s[11], s[12]);
    BodyFrame {
        position: Vector3::new(s[0], s[1], s[2]),
        rotation,
        velocity: Vector3::new(s[7], s[8], s[9]),
        angular_velocity: rotation * omega_body,
    }
}

/// Writes an initial pose and velocity of a dynamic body into the state vector.
pub fn write_state(
    y: &mut [f64],
    offset: usize,
    pose: &Isometry3<f64>,
    velocity: Vector3<f64>,
    angular_velocity_world: Vector3<f64>,
) {
    let s = &mut y[offset..offset + BODY_STATE_LEN];
    let t = pose.translation.vector;
    let q = pose.rotation;
    let wb = q.inverse() * angular_velocity_world;
    s[0..3].copy_from_slice(t.as_slice());
    s[3] = q.w;
    s[4] = q.i;
    s[5] = q.j;
    s[6] = q.k;
    s[7..10].copy_from_slice(velocity.as_slice());
    s[10..13].copy_from_slice(wb.as_slice());
}
