//! Rigid multibody dynamics: bodies, force elements, contact and friction laws, integrators.

pub mod body;
pub mod body_transient;
pub mod contact;
pub mod control;
pub mod energy;
pub mod forces;
pub mod friction;
pub mod impact;
pub mod impact_map;
pub mod integrator;
pub mod local_dopri5;
pub mod newton_matrix;
pub mod partition;
pub mod simulate;
pub mod step;
pub mod supported_impact_map;
pub mod system;
pub mod track;
