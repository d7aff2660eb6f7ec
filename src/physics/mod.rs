//! Rigid multibody dynamics: bodies, force elements, contact and friction laws, integrators.

pub mod friction;
pub mod impact;
pub mod step;
pub mod track;
