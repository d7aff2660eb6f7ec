//! Passive contact (SPEC §2 "Passivity"): with no drive the mechanical energy never rises, the
//! energy account closes, a symmetric planar motion stays planar, friction work matches its
//! closed form, and a kicked launcher gives back its static pose and dissipates the kick.
//! Every bound is the ("Passive contact", item 4) and fixed by physics, not by output.

use nalgebra::UnitQuaternion;
use railwear::validation_energy::{
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

/// A random state of the cube inside the case-C tube: any orientation that fits, the centre
/// anywhere the cube fits with up to 20 µm of penetration into any wall, a random twist.
fn random_cube_state(t: &MotionlessTube, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let l = t.half_inner_side_m;
    let h = t.half_side_m;
    loop {
        let q: UnitQuaternion<f64> = UnitQuaternion::from_euler_angles(
            rng.gen_range(-0.4..0.4),
            rng.gen_range(-3.2..3.2),
            rng.gen_range(-0.4..0.4),
        );
        let r = q.to_rotation_matrix();
        // Half width of the cube along world x and y (sharp box bound).
        let half = |axis: usize| (0..3).map(|k| h * r[(axis, k)].abs()).sum::<f64>();
        let (hx, hy) = (half(0), half(1));
        if hx > l || hy > l {
            continue;
        }
        let pen = 2e-5;
        let mut y = t.resting.clone();
        y[0] = rng.gen_range(-(l - hx) - pen..(l - hx) + pen);
        y[1] = rng.gen_range(-(l - hy) - pen..(l - hy) + pen);
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
            assert!(
                a.residual_j.abs() <= BALANCE_TOLERANCE * a.dissipated_j + 1e-12,
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
    assert!(a.0 + b.0 >= 400, "most states must hit a wall within 4 ms");
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
