//! Rigid multibody dynamics: bodies, force elements, contact and friction laws, integrators.

pub mod friction;
pub mod step;
