//! The engine test binary: physics, models, the gap diagnosis, checkpoints, closed forms, energy
//! and error control, called as a library (no HTTP, no store). One module per concern.

mod carrier_frame;
mod checkpoint_resume;
mod cli_errors;
mod contact_fit;
mod energy_passivity;
mod engine_closed_forms;
mod error_control;
mod face_contact;
mod face_contact_blocks;
mod face_contact_closed_form;
mod face_contact_reduced;
mod face_contact_rules;
mod face_contact_strips;
mod face_friction_rule;
mod gap_campaign;
mod gap_diagnose;
mod gap_diagnose_simulated;
mod gap_effects;
mod gap_mechanisms;
mod gap_next_test;
mod gap_rig;
mod launcher_model;
mod launcher_trend;
mod multi_missile;
mod newton_matrix;
mod rattle_box;
mod step_diagnostics;
