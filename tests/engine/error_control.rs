//! Position-only error control (`error_control = "positions"`, the analogue of ADAMS
//! WSTIFF-I3): the setting reaches the integrator, free flight keeps its closed form, and the
//! energy account is kept and closes in this mode as in the default one (the passivity bounds
//! of tests/energy_passivity.rs, fixed by physics, not by output).

use railwear::models::case::{integrator_settings, load_case};
use railwear::models::spec::CaseSpec;
use railwear::physics::integrator::{ErrorControl, IntegratorSettings};
use railwear::physics::simulate::{simulate, DivergenceLimits};
use railwear::pipeline::RunControl;
use railwear::validation::energy::{
    energy_run, motionless_tube, spinning_cube, tilted_cube, MotionlessTube, BALANCE_TOLERANCE,
    PASSIVITY_TOLERANCE,
};
use std::path::Path;

fn configs() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/configs"))
}

/// Case C without excitation, integrated with position-only error control.
fn tube_positions() -> MotionlessTube {
    let mut t = motionless_tube(configs()).expect("case C loads");
    t.settings.tolerances.error_control = ErrorControl::Positions;
    t
}

#[test]
fn the_case_setting_reaches_the_integrator_and_unknown_modes_are_refused() {
    let text = std::fs::read_to_string(configs().join("rattle-box-c.toml")).expect("case C");
    let case = CaseSpec::from_toml_str(&text).expect("parses");
    assert_eq!(
        integrator_settings(&case)
            .expect("settings")
            .tolerances
            .error_control,
        ErrorControl::Full,
        "full error control stays the default"
    );
    let positions = text.replace(
        "[simulation]",
        "[simulation]\nerror_control = \"positions\"",
    );
    let case = CaseSpec::from_toml_str(&positions).expect("parses");
    assert_eq!(
        integrator_settings(&case)
            .expect("settings")
            .tolerances
            .error_control,
        ErrorControl::Positions
    );
    let wrong = text.replace(
        "[simulation]",
        "[simulation]\nerror_control = \"velocities\"",
    );
    let err = CaseSpec::from_toml_str(&wrong).expect_err("refused");
    assert!(
        err.to_string().contains("error_control"),
        "the error names the field: {err}"
    );
}

#[test]
fn free_flight_follows_its_parabola_under_position_control() {
    // The cube thrown across the middle of the motionless tube, touching nothing for 20 ms:
    // x = x0 + vx t, y = y0 + vy t − g t²/2, the velocities exact too (their error is not
    // tested in this mode, but a ballistic flight has none to make).
    let t = tube_positions();
    let mut y = t.resting.clone();
    y[0] = 0.0;
    y[1] = 0.0;
    y[7] = 0.1;
    y[8] = 0.2;
    let (x0, y0) = (y[0], y[1]);
    let t_end = 0.02;
    let mut touched = false;
    simulate(
        &t.system,
        &mut y,
        0.0,
        t_end,
        t.settings,
        DivergenceLimits::default(),
        &RunControl::silent(),
        &mut |v| touched |= !v.tracks.is_empty(),
    )
    .expect("runs");
    assert!(!touched, "the flight must stay clear of the walls");
    let g = 9.80665;
    let x = x0 + 0.1 * t_end;
    let h = y0 + 0.2 * t_end - 0.5 * g * t_end * t_end;
    assert!((y[0] - x).abs() < 1e-9, "x {} vs {x}", y[0]);
    assert!((y[1] - h).abs() < 1e-9, "y {} vs {h}", y[1]);
    assert!((y[8] - (0.2 - g * t_end)).abs() < 1e-9, "vy {}", y[8]);
}

fn check_passive(t: &MotionlessTube, y: &[f64], available: f64, what: &str) {
    let run = energy_run(&t.system, y, t.settings, 0.05).expect("runs");
    let a = &run.audit;
    eprintln!(
        "{what}: rise {:.3e} J of {available:.3e}, residual {:.3e} J, dissipated {:.3e} J",
        a.max_rise_without_drive_j, a.residual_j, a.dissipated_j
    );
    assert!(a.dissipated_j > 0.0, "{what}: the contact must dissipate");
    assert!(
        a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * available + 1e-12,
        "{what}: energy rose by {:.3e} J",
        a.max_rise_without_drive_j
    );
    assert!(
        a.residual_j.abs() <= BALANCE_TOLERANCE * a.dissipated_j + 1e-12,
        "{what}: account residual {:.3e} J of {:.3e} J dissipated",
        a.residual_j,
        a.dissipated_j
    );
    assert!(a.dissipated_j <= available * (1.0 + BALANCE_TOLERANCE));
}

#[test]
fn the_energy_account_closes_under_position_control() {
    let t = tube_positions();
    let mut ws = t.system.workspace();
    let rest = t.system.energy(0.0, &t.resting, &mut ws).total();
    let (y, _) = tilted_cube(&t, 5e-4, 0.02);
    let available = t.system.energy(0.0, &y, &mut ws).total() - rest;
    check_passive(&t, &y, available, "tilted drop");
    let (y, spin_energy) = spinning_cube(&t, 2.0);
    check_passive(&t, &y, spin_energy, "spin on the floor");
}

#[test]
fn position_control_settings_change_only_the_error_test() {
    // The mode is a field of the tolerances: every other setting of a case is untouched.
    let case = load_case(&configs().join("launcher-design.toml")).expect("launcher");
    let full: IntegratorSettings = integrator_settings(&case).expect("settings");
    let mut case_p = case.clone();
    case_p.simulation.error_control = ErrorControl::Positions;
    let mut pos = integrator_settings(&case_p).expect("settings");
    assert_eq!(pos.tolerances.error_control, ErrorControl::Positions);
    pos.tolerances.error_control = ErrorControl::Full;
    assert_eq!(pos, full);
}

#[test]
fn without_the_work_test_the_account_shows_integrator_loss_never_gain() {
    // Position control with the energy account's work test off (energy_rel_tolerance = 0):
    // the impacts' damping transients are no longer resolved, the L-stable method damps part
    // of the impact energy numerically and the account, still kept, shows it as a negative
    // residual. It must never show energy created: no rise without drive, and no positive
    // residual beyond the balance bound. On the 5-point lattice: on case C's 3 points per edge
    // (its default since the twenty-first pass of docs/journal/performance.md) the tilted drop lands
    // on an edge's 3 points, the unresolved transient's quadrature overestimates the damping
    // work and the residual reads +0.57 % of the dissipated work (bound 0.5 %), while the
    // mechanical energy still never rises (4e-19 J). So the one-sided residual bound holds
    // where the lattice resolves the landing, not for every lattice: without the work test
    // the quadrature's error can take either sign.
    let mut t = tube_positions();
    for c in &mut t.system.contacts {
        *c = c.clone().with_points_per_edge(5);
    }
    t.settings.tolerances.energy_rel = 0.0;
    let mut ws = t.system.workspace();
    let rest = t.system.energy(0.0, &t.resting, &mut ws).total();
    let (y, _) = tilted_cube(&t, 5e-4, 0.02);
    let available = t.system.energy(0.0, &y, &mut ws).total() - rest;
    let run = energy_run(&t.system, &y, t.settings, 0.05).expect("runs");
    let a = &run.audit;
    eprintln!(
        "no work test: rise {:.3e} J, residual {:.3e} J, dissipated {:.3e} J of {available:.3e}",
        a.max_rise_without_drive_j, a.residual_j, a.dissipated_j
    );
    assert!(a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * available + 1e-12);
    assert!(a.residual_j <= BALANCE_TOLERANCE * a.dissipated_j + 1e-12);
}
