//! Rigid multibody dynamics: bodies, force elements, contact and friction laws, integrators.

pub mod body;
pub mod contact;
pub mod control;
pub mod energy;
pub mod forces;
pub mod friction;
pub mod impact;
pub mod integrator;
pub mod newton_matrix;
pub mod partition;
pub mod simulate;
pub mod step;
pub mod system;
pub mod track;
