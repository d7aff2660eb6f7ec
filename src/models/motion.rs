//! Adapts an excitation [`BaseMotion`] to the engine's [`KinematicMotion`]: the driven body
//! (shaker fixture, rail) translates by the prescribed base displacement from a reference pose.

use crate::excitation::BaseMotion;
use crate::physics::body::KinematicMotion;
use nalgebra::{Isometry3, Translation3, Vector3};

/// A body translating with a base motion from `reference` (its pose at zero displacement).
pub struct TranslatingBase {
    /// Pose at zero displacement.
    pub reference: Isometry3<f64>,
    /// Prescribed base motion.
    pub motion: BaseMotion,
}

impl KinematicMotion for TranslatingBase {
    fn pose(&self, t: f64) -> Isometry3<f64> {
        Translation3::from(self.motion.displacement(t)) * self.reference
    }
    fn velocity(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        (self.motion.velocity(t), Vector3::zeros())
    }
    fn acceleration(&self, t: f64) -> Vector3<f64> {
        self.motion.acceleration(t)
    }
}
