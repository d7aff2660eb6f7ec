//! Energy anchors of `railwear validate` (SPEC §2 "Passivity"): a contact may not create
//! energy. Each anchor runs the 1 in cube (thesis 5.4) in the motionless case-C tube and checks
//! two numbers physics fixes: without drive the mechanical energy never rises above its running
//! minimum (expected 0), and the energy account closes (residual 0).
//!
//! The scenarios are those that exposed the single-point face contact (issue "Passive
//! contact"): a resting cube given a spin about the vertical gained more energy than the spin
//! had; a cube dropped 0.5 mm with a 0.02 rad tilt gained 9 % of the drop energy.

use super::{anchor, Anchor};
use crate::models::case::{build, integrator_settings, load_case};
use crate::models::outcome::RunError;
use crate::physics::control::RunControl;
use crate::physics::energy::EnergyAudit;
use crate::physics::integrator::IntegratorSettings;
use crate::physics::simulate::{simulate, DivergenceLimits, SimError, StepView};
use crate::physics::system::MultibodySystem;
use crate::units::STANDARD_GRAVITY;
use nalgebra::{UnitQuaternion, Vector3};
use std::path::Path;

/// Largest admissible rise of `E_mech` above its running minimum without drive, as a share of
/// the energy the run starts with above its resting level (the bound).
pub const PASSIVITY_TOLERANCE: f64 = 1e-3;

/// Largest admissible |balance residual| as a share of the work dissipated.
pub const BALANCE_TOLERANCE: f64 = 5e-3;

/// The cube of rattle box case C in its tube with no excitation: system, resting state (flat on
/// the floor at the static penetration) and the case's integrator settings.
pub struct MotionlessTube {
    /// The cube (body 0) and the fixed tube (body 1).
    pub system: MultibodySystem,
    /// The cube resting on the floor.
    pub resting: Vec<f64>,
    /// The case's integrator settings.
    pub settings: IntegratorSettings,
    /// Cube mass, kg.
    pub cube_mass_kg: f64,
    /// Cube principal moment of inertia, kg·m².
    pub cube_inertia_kg_m2: f64,
    /// Half the tube's inner side, m.
    pub half_inner_side_m: f64,
    /// Half the cube's side, m.
    pub half_side_m: f64,
}

/// Loads `rattle-box-c.toml` from `configs_dir` and removes its excitation.
pub fn motionless_tube(configs_dir: &Path) -> Result<MotionlessTube, RunError> {
    let mut case = load_case(&configs_dir.join("rattle-box-c.toml"))?;
    case.excitation = crate::models::spec::CaseExcitation::none();
    case.simulation.settle_s = 0.0;
    case.simulation.duration_s = 1.0;
    let model = build(&case, configs_dir)?;
    let settings = integrator_settings(&case)?;
    let spec = match case.model_spec() {
        Ok(crate::models::spec::ModelSpecRef::RattleBox(s)) => s.clone(),
        _ => {
            return Err(RunError::InvalidConfig {
                field: "model".into(),
                rule: "rattle-box-c.toml must hold a rattle box".into(),
            })
        }
    };
    Ok(MotionlessTube {
        system: model.system,
        resting: model.initial_state,
        settings,
        cube_mass_kg: spec.cube_mass_kg(),
        cube_inertia_kg_m2: spec.cube_inertia_kg_m2(),
        half_inner_side_m: 0.5 * spec.tube_inner_side_m,
        half_side_m: 0.5 * spec.cube_side_m,
    })
}

/// What an energy run measured.
#[derive(Debug, Clone)]
pub struct EnergyRun {
    /// The run's energy account.
    pub audit: EnergyAudit,
    /// Largest total normal force on the cube at any accepted step, N.
    pub peak_normal_force_n: f64,
    /// Highest rise of the cube's centre above its start, m.
    pub max_lift_m: f64,
    /// Final state.
    pub state: Vec<f64>,
}

/// Runs `system` from `y0` over `[0, t_end]` and keeps its energy account.
pub fn energy_run(
    system: &MultibodySystem,
    y0: &[f64],
    settings: IntegratorSettings,
    t_end: f64,
) -> Result<EnergyRun, SimError> {
    let mut y = y0.to_vec();
    let (mut peak, mut lift) = (0.0f64, 0.0f64);
    let y_start = y0[1];
    let stats = simulate(
        system,
        &mut y,
        0.0,
        t_end,
        settings,
        DivergenceLimits::default(),
        &RunControl::silent(),
        &mut |v: &StepView| {
            let n: f64 = v.tracks.iter().map(|t| t.normal_force).sum();
            peak = peak.max(n);
            lift = lift.max(v.state[1] - y_start);
        },
    )?;
    Ok(EnergyRun {
        audit: stats
            .energy
            .unwrap_or_else(|| crate::physics::energy::EnergyMeter::new(Vec::new()).audit()),
        peak_normal_force_n: peak,
        max_lift_m: lift,
        state: y,
    })
}

/// The resting cube given a spin of `rate` rad/s about the vertical: (state, spin energy J).
pub fn spinning_cube(tube: &MotionlessTube, rate: f64) -> (Vec<f64>, f64) {
    let mut y = tube.resting.clone();
    y[11] = rate; // body-frame y is vertical: the cube starts unrotated
    (y, 0.5 * tube.cube_inertia_kg_m2 * rate * rate)
}

/// The cube lifted `drop` m above its resting pose and tilted `tilt` rad about the tube axis
/// then released so that its lowest corner falls `drop`: (state, the energy it has to lose to
/// come to rest flat on the floor, `m g (drop + corner rise)` J).
pub fn tilted_cube(tube: &MotionlessTube, drop: f64, tilt: f64) -> (Vec<f64>, f64) {
    let mut y = tube.resting.clone();
    let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), tilt);
    // Raise by the drop plus what the tilt lowers the lowest corner, so the corner falls `drop`.
    let h = tube.half_side_m;
    let corner_drop = h * (tilt.abs().cos() + tilt.abs().sin()) - h;
    y[1] += drop + corner_drop;
    y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
    (
        y,
        tube.cube_mass_kg * STANDARD_GRAVITY * (drop + corner_drop),
    )
}

/// Rise and residual anchors of one energy run with `scale` J of energy to lose.
fn run_anchors(name: &str, source: &str, run: &EnergyRun, scale: f64) -> Vec<Anchor> {
    vec![
        anchor(
            &format!("energy: {name}, largest rise of E_mech over its running minimum"),
            source,
            "share of the initial energy above rest",
            0.0,
            run.audit.max_rise_without_drive_j / scale,
            PASSIVITY_TOLERANCE,
        ),
        anchor(
            &format!("energy: {name}, balance residual"),
            "E_mech + W_dissipated - W_drive = E_mech(0) (SPEC 2)",
            "share of the dissipated work",
            0.0,
            run.audit.residual_j / run.audit.dissipated_j.max(f64::MIN_POSITIVE),
            BALANCE_TOLERANCE,
        ),
    ]
}

/// The energy anchors: spin on the floor (2 rad/s) and the tilted drop (0.5 mm, 0.02 rad).
pub fn energy_anchors(configs_dir: &Path) -> Vec<Anchor> {
    let failed = |name: &str, why: String| {
        vec![anchor(
            &format!("energy: {name} ({why})"),
            "SPEC 2 passivity",
            "-",
            0.0,
            f64::NAN,
            0.0,
        )]
    };
    let tube = match motionless_tube(configs_dir) {
        Ok(t) => t,
        Err(e) => return failed("motionless case-C tube", e.to_string()),
    };
    let mut out = Vec::new();
    let (spin, spin_energy) = spinning_cube(&tube, 2.0);
    match energy_run(&tube.system, &spin, tube.settings, 0.05) {
        Ok(run) => out.extend(run_anchors(
            "cube spun at 2 rad/s on the case-C floor, 50 ms",
            "passivity: a resting cube's spin can only decay (SPEC 2)",
            &run,
            spin_energy,
        )),
        Err(e) => out.extend(failed("spin on the floor", e.to_string())),
    }
    let (drop, drop_energy) = tilted_cube(&tube, 5e-4, 0.02);
    match energy_run(&tube.system, &drop, tube.settings, 0.05) {
        Ok(run) => out.extend(run_anchors(
            "cube dropped 0.5 mm tilted 0.02 rad onto the case-C floor, 50 ms",
            "passivity: a dropped cube can only lose its drop energy (SPEC 2)",
            &run,
            drop_energy,
        )),
        Err(e) => out.extend(failed("tilted drop", e.to_string())),
    }
    out
}
