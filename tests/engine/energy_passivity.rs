//! Passive contact (SPEC §2 "Passivity"): with no drive the mechanical energy never rises, the
//! energy account closes, a symmetric planar motion stays planar, friction work matches its
//! closed form, and a kicked launcher gives back its static pose and dissipates the kick.
//! Every bound is the ("Passive contact", item 4) and fixed by physics, not by output.

use nalgebra::UnitQuaternion;
use railwear::validation::energy::{
    energy_run, motionless_tube, spinning_cube, tilted_cube, MotionlessTube, BALANCE_TOLERANCE,
    PASSIVITY_TOLERANCE,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn configs() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/configs"))
}

fn tube() -> MotionlessTube {
    motionless_tube(configs()).expect("case C loads")
}

/// Mechanical energy of `y` above the lowest state the cube can reach (resting flat on the
/// floor), J: the energy a passive run may dissipate and must never exceed.
fn available_energy(t: &MotionlessTube, y: &[f64]) -> f64 {
    let mut ws = t.system.workspace();
    let e = t.system.energy(0.0, y, &mut ws).total();
    let rest = t.system.energy(0.0, &t.resting, &mut ws).total();
    e - rest
}

#[test]
fn spin_on_the_floor_only_decays() {
    let t = tube();
    let (y, spin_energy) = spinning_cube(&t, 2.0);
    assert!(
        (spin_energy - 9.9e-6).abs() < 0.05e-6,
        "the issue's 9.9e-6 J"
    );
    let run = energy_run(&t.system, &y, t.settings, 0.05).expect("runs");
    let a = &run.audit;
    eprintln!(
        "spin: rise {:.3e} J, residual {:.3e} J, dissipated {:.3e} J, peak N {:.3} N, lift {:.3e} m",
        a.max_rise_without_drive_j, a.residual_j, a.dissipated_j, run.peak_normal_force_n, run.max_lift_m
    );
    assert!(a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * spin_energy);
    assert!(a.residual_j.abs() <= BALANCE_TOLERANCE * a.dissipated_j + 1e-12);
    // Spinning about its normal changes no penetration: the floor carries the weight
    // (0.45 N) and nothing more, and the cube does not leave the floor.
    let weight = t.cube_mass_kg * 9.80665;
    assert!(
        run.peak_normal_force_n < 1.01 * weight,
        "peak {}",
        run.peak_normal_force_n
    );
    assert!(run.max_lift_m < 1e-9, "lift {}", run.max_lift_m);
    // Friction (the only loss) took the spin energy it could: the spin decays.
    assert!(a.dissipated_j > 0.0 && a.dissipated_j <= spin_energy * (1.0 + 1e-3));
}

#[test]
fn tilted_drop_loses_its_drop_energy() {
    let t = tube();
    let (y, drop_energy) = tilted_cube(&t, 5e-4, 0.02);
    let run = energy_run(&t.system, &y, t.settings, 0.05).expect("runs");
    let a = &run.audit;
    eprintln!(
        "drop: rise {:.3e} J of {:.3e}, residual {:.3e} J, dissipated {:.3e} J, peak N {:.1} N",
        a.max_rise_without_drive_j,
        drop_energy,
        a.residual_j,
        a.dissipated_j,
        run.peak_normal_force_n
    );
    let available = available_energy(&t, &y);
    assert!(a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * available + 1e-12);
    assert!(a.residual_j.abs() <= BALANCE_TOLERANCE * a.dissipated_j + 1e-12);
    assert!(a.dissipated_j <= available * (1.0 + BALANCE_TOLERANCE));
}

/// A random state of the cube inside the case-C tube: any orientation that fits; along x and
/// along y, with even odds, the cube pressed up to 20 µm into one of the two walls or anywhere
/// between them (so most states start on one or two walls, a random contact set); a random
/// twist.
fn random_cube_state(t: &MotionlessTube, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let l = t.half_inner_side_m;
    let h = t.half_side_m;
    let round = t.system.contacts[0].points(0)[0].radius;
    loop {
        let q: UnitQuaternion<f64> = UnitQuaternion::from_euler_angles(
            rng.gen_range(-0.4..0.4),
            rng.gen_range(-3.2..3.2),
            rng.gen_range(-0.4..0.4),
        );
        let r = q.to_rotation_matrix();
        // Half width of the rounded cube along world x and y (its support function).
        let half = |axis: usize| {
            (0..3)
                .map(|k| (h - round) * r[(axis, k)].abs())
                .sum::<f64>()
                + round
        };
        let (hx, hy) = (half(0), half(1));
        if hx > l || hy > l {
            continue;
        }
        let pen = 2e-5;
        let mut place = |room: f64| {
            let side = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
            if rng.gen_bool(0.5) {
                side * (room + rng.gen_range(0.0..pen))
            } else {
                rng.gen_range(-room..room)
            }
        };
        let mut y = t.resting.clone();
        y[0] = place(l - hx);
        y[1] = place(l - hy);
        y[2] = rng.gen_range(-1e-3..1e-3);
        y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        for v in y[7..10].iter_mut() {
            *v = rng.gen_range(-0.2..0.2);
        }
        for w in y[10..13].iter_mut() {
            *w = rng.gen_range(-20.0..20.0);
        }
        return y;
    }
}

#[test]
fn five_hundred_random_cube_states_never_gain_energy() {
    let t = tube();
    let states: Vec<Vec<f64>> = {
        let mut rng = ChaCha8Rng::seed_from_u64(19);
        (0..500).map(|_| random_cube_state(&t, &mut rng)).collect()
    };
    let check = |chunk: &[Vec<f64>]| -> (usize, f64, f64) {
        let (mut touching, mut worst_rise, mut worst_residual) = (0, 0.0f64, 0.0f64);
        for y in chunk {
            let available = available_energy(&t, y);
            let run = energy_run(&t.system, y, t.settings, 4e-3).expect("runs");
            let a = &run.audit;
            touching += usize::from(a.dissipated_j > 0.0);
            let rise = a.max_rise_without_drive_j / (available + 1e-9);
            let residual = a.residual_j.abs() / (a.dissipated_j + 1e-9);
            worst_rise = worst_rise.max(rise);
            worst_residual = worst_residual.max(residual);
            assert!(
                a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * available + 1e-12,
                "energy rose by {:.3e} J of {available:.3e} J from {y:?}",
                a.max_rise_without_drive_j
            );
            assert!(
                a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * available + 1e-12,
                "energy rose by {:.3e} J of {available:.3e} J from {y:?}",
                a.max_rise_without_drive_j
            );
            if std::env::var("RW_PROBE").is_ok() {
                eprintln!("PROBE {residual:.3e} {:.3e} {:.3e}", a.dissipated_j, rise);
                if residual > 1e-2 {
                    for f in [1.0, 0.1, 0.01] {
                        let mut st = t.settings;
                        st.tolerances.rel *= f;
                        st.tolerances.abs_position_m *= f;
                        st.tolerances.abs_velocity_m_s *= f;
                        st.tolerances.abs_rotation *= f;
                        st.tolerances.abs_angular_velocity_rad_s *= f;
                        let r2 = energy_run(&t.system, y, st, 4e-3).expect("runs");
                        eprintln!(
                            "TOL {f} residual {:.3e} diss {:.3e} rise {:.3e}",
                            r2.audit.residual_j,
                            r2.audit.dissipated_j,
                            r2.audit.max_rise_without_drive_j
                        );
                    }
                }
                continue;
            }
            // Floor: 1e-6 of the energy in play, the free-flight integration error of a run that
            // only grazes a wall (it dissipates 1e-11 J and its account is then round-off).
            assert!(
                a.residual_j.abs() <= BALANCE_TOLERANCE * a.dissipated_j + 1e-6 * available,
                "balance residual {:.3e} J of {:.3e} J dissipated from {y:?}",
                a.residual_j,
                a.dissipated_j
            );
        }
        (touching, worst_rise, worst_residual)
    };
    let (a, b) = std::thread::scope(|s| {
        let h = s.spawn(|| check(&states[..250]));
        let b = check(&states[250..]);
        (h.join().expect("thread"), b)
    });
    eprintln!(
        "random cube states: {} of 500 touched; worst rise {:.2e}, worst residual {:.2e}",
        a.0 + b.0,
        a.1.max(b.1),
        a.2.max(b.2)
    );
    assert!(
        a.0 + b.0 >= 400,
        "most states must touch a wall within 4 ms"
    );
}

#[test]
fn a_symmetric_planar_rattle_stays_planar() {
    // The cube centred on the tube's mid-plane z = 0, unrotated, driven along x with gravity
    // along y: every force is symmetric about z = 0, so the rotations about x and y stay zero.
    let mut case =
        railwear::models::case::load_case(&configs().join("rattle-box-c.toml")).expect("case C");
    case.simulation.settle_s = 0.2;
    case.simulation.duration_s = 10.0;
    let model = railwear::models::case::build(&case, configs()).expect("model");
    let settings = railwear::models::case::integrator_settings(&case).expect("settings");
    let mut y = model.initial_state.clone();
    let mut worst = 0.0f64;
    railwear::physics::simulate::simulate(
        &model.system,
        &mut y,
        0.0,
        model.end_time_s,
        settings,
        Default::default(),
        &railwear::pipeline::RunControl::silent(),
        &mut |v| {
            let s = v.state;
            // Out-of-plane rotation angle: 2 |(q_x, q_y)|, and z drift.
            let tilt = 2.0 * (s[4] * s[4] + s[5] * s[5]).sqrt();
            worst = worst.max(tilt).max(s[2].abs());
        },
    )
    .expect("runs");
    eprintln!("planar: worst out-of-plane rotation or z drift {worst:e}");
    assert!(worst < 1e-9, "out of plane by {worst:e}");
}

#[test]
fn friction_work_on_a_driven_plate_matches_its_closed_form() {
    // The cube on a floor plate without walls, the plate driven along itself (x) at 15 g,
    // 20 Hz: far above μ g, so the cube slides all the time and friction decelerates it at
    // μ_d g towards the plate's velocity (a triangle-wave velocity). Mean friction power
    // = μ_d m g <|v_cube − v_plate|>, the mean taken from the 1-D Coulomb motion integrated
    // here independently of the engine (the ADAMS transitions below 12 mm/s act during 0.6 %
    // of the time).
    let mut case =
        railwear::models::case::load_case(&configs().join("rattle-box-c.toml")).expect("case C");
    case.simulation.settle_s = 0.05;
    case.simulation.duration_s = 1.0;
    let mut model = railwear::models::case::build(&case, configs()).expect("model");
    let settings = railwear::models::case::integrator_settings(&case).expect("settings");
    // Only the floor (the fourth wall, normal +y), as a 120 mm plate.
    let contact = &mut model.system.contacts[0];
    let floor = contact.faces_b[3];
    assert!(floor.normal.y > 0.99, "the fourth wall is the floor");
    let mut extent = contact.face_extents[3].expect("tube walls are bounded");
    extent.s_range_m = (-0.06, 0.06);
    contact.faces_b = vec![floor];
    contact.face_extents = vec![Some(extent)];
    let sys = &model.system;
    let plate_velocity = |t: f64| match &sys.bodies[1].kind {
        railwear::physics::body::BodyKind::Kinematic(m) => m.velocity(t).0.x,
        railwear::physics::body::BodyKind::Dynamic { .. } => unreachable!("the tube is driven"),
    };
    let (t0, t1) = (model.excitation_start_s, model.end_time_s);
    let mut y = model.initial_state.clone();
    let (mut worst_offset, mut samples) = (0.0f64, Vec::new());
    let stats = railwear::physics::simulate::simulate(
        sys,
        &mut y,
        0.0,
        t1,
        settings,
        Default::default(),
        &railwear::pipeline::RunControl::silent(),
        &mut |v| {
            let plate_x = match &v.system.bodies[1].kind {
                railwear::physics::body::BodyKind::Kinematic(m) => m.pose(v.t).translation.x,
                railwear::physics::body::BodyKind::Dynamic { .. } => 0.0,
            };
            worst_offset = worst_offset.max((v.state[0] - plate_x).abs());
            samples.push((v.t, v.tracks.iter().map(|t| t.friction_power).sum::<f64>()));
        },
    )
    .expect("runs");
    // Engine: friction power averaged over the window (trapezoid over accepted steps).
    let mut work = 0.0;
    for w in samples.windows(2) {
        if w[0].0 >= t0 {
            work += 0.5 * (w[1].0 - w[0].0) * (w[0].1 + w[1].1);
        }
    }
    let engine = work / (t1 - t0);
    // Independent 1-D reference from the same start (cube at rest when the drive starts).
    let mu = sys.contacts[0]
        .friction
        .expect("Table 5.2 friction")
        .mu_dynamic;
    let (m, g) = (sys.bodies[0].mass.mass, 9.80665);
    let (mut v_cube, mut sum, dt) = (0.0f64, 0.0, 1e-6);
    let steps = ((t1 - t0) / dt).round() as usize;
    for i in 0..steps {
        let tm = t0 + (i as f64 + 0.5) * dt;
        let rel = plate_velocity(tm) - v_cube;
        v_cube += mu * g * rel.signum() * dt;
        sum += rel.abs() * dt;
    }
    let reference = mu * m * g * sum / (t1 - t0);
    eprintln!(
        "plate: engine {engine:.5} W, closed form {reference:.5} W, energy residual {:.2e}",
        stats
            .energy
            .as_ref()
            .map_or(f64::NAN, |a| a.residual_relative)
    );
    assert!(
        (engine / reference - 1.0).abs() < 0.05,
        "{engine} vs {reference}"
    );
    // The cube never leaves the plate: its centre stays within the plate minus its half side.
    assert!(worst_offset < 0.06 - 0.0127, "offset {worst_offset}");
}

/// launcher-design without excitation: system, initial state, integrator settings.
fn still_launcher() -> (
    railwear::physics::system::MultibodySystem,
    Vec<f64>,
    railwear::physics::integrator::IntegratorSettings,
) {
    let mut case = railwear::models::case::load_case(&configs().join("launcher-design.toml"))
        .expect("launcher loads");
    case.excitation = railwear::models::spec::CaseExcitation::none();
    case.simulation.settle_s = 0.0;
    case.simulation.duration_s = 1.0;
    let model = railwear::models::case::build(&case, configs()).expect("model");
    let settings = railwear::models::case::integrator_settings(&case).expect("settings");
    (model.system, model.initial_state, settings)
}

/// The launcher settled from its assembly estimate for `t` s: (state, mechanical energy J).
fn settled_launcher(t: f64) -> (Vec<f64>, f64) {
    let (sys, y0, settings) = still_launcher();
    let run = energy_run(&sys, &y0, settings, t).expect("settles");
    let mut ws = sys.workspace();
    let e = sys.energy(0.0, &run.state, &mut ws).total();
    (run.state, e)
}

/// The settled launcher `rest` with its missile (body 0) shifted within its clearances
/// (0.2 mm along the rail, 0.1 mm across), turned by under a milliradian (5 mrad about the
/// rail) and moving (0.02 m/s, 0.2 rad/s); the latch as settled.
pub(crate) fn random_missile_state(rest: &[f64], rng: &mut ChaCha8Rng) -> Vec<f64> {
    let mut y = rest.to_vec();
    y[0] += rng.gen_range(-2e-4..2e-4);
    y[1] += rng.gen_range(-1e-4..1e-4);
    y[2] += rng.gen_range(-1e-4..1e-4);
    let turn = UnitQuaternion::from_euler_angles(
        rng.gen_range(-5e-4..5e-4),
        rng.gen_range(-5e-4..5e-4),
        rng.gen_range(-5e-3..5e-3),
    );
    let q =
        turn * UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(y[3], y[4], y[5], y[6]));
    y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
    for v in y[7..10].iter_mut() {
        *v = rng.gen_range(-0.02..0.02);
    }
    for w in y[10..13].iter_mut() {
        *w = rng.gen_range(-0.2..0.2);
    }
    y
}

#[test]
fn a_hundred_random_missile_states_never_gain_energy() {
    let (sys, _, settings) = still_launcher();
    let (rest, rest_energy) = settled_launcher(1.0);
    let mut rng = ChaCha8Rng::seed_from_u64(61);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..100 {
        // Missile (body 0): shifted within its clearances, turned by under a milliradian,
        // moving; the latch as settled.
        let y = random_missile_state(&rest, &mut rng);
        let mut ws = sys.workspace();
        let available = sys.energy(0.0, &y, &mut ws).total() - rest_energy;
        let run = energy_run(&sys, &y, settings, 0.01).expect("runs");
        let a = &run.audit;
        worst.0 = worst
            .0
            .max(a.max_rise_without_drive_j / available.abs().max(1e-12));
        worst.1 = worst.1.max(a.residual_j.abs() / a.dissipated_j.max(1e-12));
        assert!(
            a.max_rise_without_drive_j <= PASSIVITY_TOLERANCE * available.abs() + 1e-12,
            "energy rose by {:.3e} J of {available:.3e} J",
            a.max_rise_without_drive_j
        );
        assert!(
            a.residual_j.abs() <= BALANCE_TOLERANCE * a.dissipated_j + 1e-12,
            "residual {:.3e} J of {:.3e} J dissipated",
            a.residual_j,
            a.dissipated_j
        );
    }
    eprintln!(
        "random missile states: worst rise {:.2e}, worst residual {:.2e}",
        worst.0, worst.1
    );
}

#[test]
fn a_kicked_missile_settles_back_and_dissipates_the_kick() {
    // Settled, then given a roll rate of 1 rad/s about its axis (z): it rattles in its rails,
    // comes back to rest, and the work dissipated after the kick is the kick's energy.
    let (sys, _, settings) = still_launcher();
    let (rest, _) = settled_launcher(6.0);
    let forces = |y: &[f64]| {
        let mut ws = sys.workspace();
        let mut per_contact = vec![0.0; sys.contacts.len()];
        sys.tracks(0.0, y, &mut ws, &mut |t| {
            per_contact[t.contact as usize] += t.normal_force
        });
        per_contact
    };
    let before = forces(&rest);
    let mut kicked = rest.clone();
    kicked[12] += 1.0; // body-frame z: the missile's axis
    let i_roll = sys.bodies[0].mass.inertia[(2, 2)];
    let kick = 0.5 * i_roll * ((rest[12] + 1.0).powi(2) - rest[12].powi(2));
    let run = energy_run(&sys, &kicked, settings, 6.0).expect("runs");
    let after = forces(&run.state);
    let a = &run.audit;
    eprintln!(
        "kick {kick:.4e} J: dissipated {:.4e} J, applied {:.3e} J, E change {:.3e} J; forces before {before:.3?} after {after:.3?}",
        a.dissipated_j,
        a.applied_work_j,
        a.final_energy_j - a.initial_energy_j
    );
    let total: f64 = before.iter().sum();
    for (b, f) in before.iter().zip(&after) {
        assert!((b - f).abs() <= 0.02 * total, "{before:?} -> {after:?}");
    }
    assert!(
        (a.dissipated_j / kick - 1.0).abs() < 0.01,
        "dissipated {} of {kick}",
        a.dissipated_j
    );
}

#[test]
fn validate_reports_the_energy_anchors_and_they_pass() {
    let anchors = railwear::validation::energy::energy_anchors(configs());
    assert_eq!(
        anchors.len(),
        4,
        "spin and tilted drop, rise and residual each"
    );
    for a in &anchors {
        assert!(a.name.starts_with("energy: "), "{}", a.name);
        assert!(
            a.pass,
            "{} measured {} (tolerance {})",
            a.name, a.measured, a.tolerance
        );
    }
}
