//! The contact-local impulse map (issue 28, first part): closed forms of the undamped impact, the
//! energy account, a damped drop against a fine fixed-step reference, the friction limits,
//! passivity over random inputs, typed input errors. Every number is fixed by physics (a closed
//! form, a bound, the 1 %), never copied from the map's output.

use nalgebra::{UnitQuaternion, Vector3};
use railwear::physics::body::{effective_mass, MassProperties};
use railwear::physics::friction::FrictionParams;
use railwear::physics::impact::ImpactParams;
use railwear::physics::impact_map::{
    impact_map, ContactApproach, ContactEnd, ImpactMap, ImpactMapError, ImpactMapSettings,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use statrs::function::gamma::gamma;

/// The rattle box's cube, kg (thesis Table 5.1).
const CUBE_MASS: f64 = 0.046;

fn head_on(mass: f64, speed: f64) -> ContactApproach {
    ContactApproach::head_on(mass, speed)
}

fn undamped(exponent: f64) -> ImpactParams {
    ImpactParams {
        stiffness: 1e9,
        exponent,
        max_damping: 0.0,
        ..ImpactParams::thesis_table_5_2()
    }
}

fn run(a: &ContactApproach, p: &ImpactParams, time_limit: f64) -> ImpactMap {
    let f = FrictionParams::thesis_table_5_2();
    let settings = ImpactMapSettings {
        time_limit,
        max_steps: 20_000_000,
        ..ImpactMapSettings::default()
    };
    impact_map(a, p, &f, &settings).expect("valid input")
}

fn kinetic_energy(a: &ContactApproach, wdot: f64, slip: [f64; 2]) -> f64 {
    0.5 * a.normal_mass * wdot * wdot
        + 0.5 * a.tangential_mass * (slip[0] * slip[0] + slip[1] * slip[1])
}

/// `½ m v_in² + W_ext − (½ m v_out² + V(w_end) + E_damp + E_fric)`, J.
fn energy_residual(a: &ContactApproach, p: &ImpactParams, m: &ImpactMap) -> f64 {
    kinetic_energy(a, a.approach_speed, a.slip_velocity) + m.external_work
        - kinetic_energy(a, m.exit_normal_velocity, m.exit_slip_velocity)
        - p.potential(m.end_penetration)
        - m.damping_dissipation
        - m.friction_dissipation
}

/// Undamped F = k w^e: energy conservation gives the peak `w_max = ((e+1) m v0² / 2k)^(1/(e+1))`
/// and the duration `t_c = 2 (w_max/v0) ∫_0^1 ds/√(1 − s^(e+1)) = 2 (w_max/v0) B(1/(e+1), 1/2)/(e+1)`.
#[test]
fn undamped_impact_matches_the_closed_form() {
    let (m, v0) = (CUBE_MASS, 0.5);
    for e in [1.0, 1.5, 2.0] {
        let p = undamped(e);
        let map = run(&head_on(m, v0), &p, 1.0);
        assert_eq!(map.end, ContactEnd::Separated, "e {e}");
        let w_max = ((e + 1.0) * m * v0 * v0 / (2.0 * p.stiffness)).powf(1.0 / (e + 1.0));
        let a = 1.0 / (e + 1.0);
        let beta = gamma(a) * gamma(0.5) / gamma(a + 0.5);
        let t_c = 2.0 * w_max / v0 * beta / (e + 1.0);
        if e == 1.0 {
            let harmonic = std::f64::consts::PI * (m / p.stiffness).sqrt();
            assert!((t_c / harmonic - 1.0).abs() < 1e-12, "B(1/2,1/2)/2 = pi/2");
        }
        let duration_error = (map.duration / t_c - 1.0).abs();
        let restitution = map.restitution(v0).unwrap();
        let energy_error = (kinetic_energy(&head_on(m, v0), map.exit_normal_velocity, [0.0; 2])
            / (0.5 * m * v0 * v0)
            - 1.0)
            .abs();
        let peak_error = (map.max_penetration / w_max - 1.0).abs();
        println!(
            "e {e}: duration error {duration_error:.2e}, |COR - 1| {:.2e}, energy error \
             {energy_error:.2e}, peak error {peak_error:.2e}, {} steps",
            (restitution - 1.0).abs(),
            map.steps
        );
        assert!(duration_error < 1e-6, "e {e}: t {} vs {t_c}", map.duration);
        assert!((restitution - 1.0).abs() < 1e-9, "e {e}: COR {restitution}");
        assert!(energy_error < 1e-9, "e {e}");
        assert!(
            peak_error < 1e-9,
            "e {e}: {} vs {w_max}",
            map.max_penetration
        );
        assert!(map.end_penetration.abs() < 1e-9 * w_max);
        assert_eq!(map.damping_dissipation, 0.0);
    }
}

/// The account `½ m v_in² + W_ext = ½ m v_out² + V(w_end) + E_damp + E_fric` closes within 1e-9
/// of the dissipated work: a bouncing contact with 2-D slip, gravity and a drive, and the thesis'
/// damping (persistent within the horizon).
#[test]
fn energy_account_closes_with_damping_friction_and_external_force() {
    let a = ContactApproach {
        normal_mass: CUBE_MASS,
        tangential_mass: 0.7 * CUBE_MASS,
        approach_speed: 0.3,
        slip_velocity: [0.02, -0.01],
        external_normal_force: CUBE_MASS * 9.81,
        external_tangential_force: [0.1, -0.05],
    };
    let bouncing = ImpactParams {
        max_damping: 20.0,
        ..ImpactParams::thesis_table_5_2()
    };
    for (p, end) in [
        (bouncing, ContactEnd::Separated),
        (ImpactParams::thesis_table_5_2(), ContactEnd::TimeLimit),
    ] {
        let map = run(&a, &p, 2e-3);
        assert_eq!(map.end, end);
        let dissipated = map.damping_dissipation + map.friction_dissipation;
        let residual = energy_residual(&a, &p, &map);
        println!(
            "c_max {}: dissipated {dissipated:.4e} J, residual/dissipated {:.2e}, {} steps",
            p.max_damping,
            residual / dissipated,
            map.steps
        );
        assert!(map.friction_dissipation > 0.0 && map.damping_dissipation > 0.0);
        assert!(residual.abs() < 1e-9 * dissipated);
    }
}

/// Classic RK4 on (w, ẇ, E_damp) with the law's own `force` (damping ramp and clamp), step
/// `h` and 100 substeps on any step crossing w = 0 or w = d or the clamp's switch; until `t_end`
/// or w back to 0. Returns the damping dissipation, J.
fn reference_drop(p: &ImpactParams, m: f64, v0: f64, h: f64, t_end: f64) -> f64 {
    let rhs = |y: [f64; 3]| {
        let n = p.force(y[0], y[1]);
        [y[1], -n / m, (n - p.elastic_force(y[0])) * y[1]]
    };
    let rk4 = |y: [f64; 3], h: f64| {
        let add = |y: [f64; 3], k: [f64; 3], s: f64| [0, 1, 2].map(|i| y[i] + s * k[i]);
        let k1 = rhs(y);
        let k2 = rhs(add(y, k1, h / 2.0));
        let k3 = rhs(add(y, k2, h / 2.0));
        let k4 = rhs(add(y, k3, h));
        [0, 1, 2].map(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    };
    let side = |y: [f64; 3]| {
        let unclamped = p.elastic_force(y[0]) + p.damping_at(y[0]) * y[1];
        (y[0] > 0.0, y[0] > p.full_damping_depth, unclamped > 0.0)
    };
    let (mut y, mut t) = ([0.0, v0, 0.0], 0.0);
    while t < t_end && !(t > 0.0 && y[0] <= 0.0) {
        let next = rk4(y, h);
        y = if side(next) != side(y) && t > 0.0 {
            (0..100).fold(y, |z, _| rk4(z, h / 100.0))
        } else {
            next
        };
        t += h;
    }
    y[2]
}

/// Thesis damping (c_max 5e5 N·s/m, d 0.01 mm) on the 46 g cube: the map's dissipated energy
/// against RK4 at 1e-3 of the undamped contact duration (and 1/100 of m/c_max) to 0.1 of that
/// duration (the approach is over by then), within the 1 %. Then to separation: the
/// approach is stopped inside the ramp, the cube creeps out along the overdamped slow manifold
/// `ẇ ≈ −k w^e / c(w)`, which every approach joins, so the exit speed hardly depends on v0 and
/// the restitution falls as 1/v0.
#[test]
fn damped_drop_matches_a_fine_fixed_step_reference() {
    let p = ImpactParams::thesis_table_5_2();
    let m = CUBE_MASS;
    let mut last_restitution = 1.0;
    let mut exit_speeds = Vec::new();
    for v0 in [1e-3, 1e-2, 1e-1, 1.0] {
        let w_max = (3.0 * m * v0 * v0 / (2.0 * p.stiffness)).cbrt();
        let t_c = 2.0 * w_max / v0 * gamma(1.0 / 3.0) * gamma(0.5) / gamma(1.0 / 3.0 + 0.5) / 3.0;
        let horizon = 0.1 * t_c;
        let h = (1e-3 * t_c).min(1e-2 * m / p.max_damping);
        let reference = reference_drop(&p, m, v0, h, horizon);
        let map = run(&head_on(m, v0), &p, horizon);
        assert_eq!(map.end, ContactEnd::TimeLimit);
        let error = map.damping_dissipation / reference - 1.0;
        let share = reference / (0.5 * m * v0 * v0);
        println!(
            "v0 {v0}: dissipated {reference:.6e} J ({share:.6} of the drop), map error {error:.2e}, \
             {} steps",
            map.steps
        );
        assert!(error.abs() < 0.01, "v0 {v0}: {error}");

        let full = run(&head_on(m, v0), &p, 100.0);
        assert_eq!(full.end, ContactEnd::Separated, "v0 {v0}");
        let restitution = full.restitution(v0).unwrap();
        let full_error = full.damping_dissipation / reference - 1.0;
        println!(
            "  to separation: {:.3} s, COR {restitution:.3e}, exit speed {:.3e} m/s, \
             dissipation vs reference {full_error:.2e}, {} steps",
            full.duration, -full.exit_normal_velocity, full.steps
        );
        assert!(
            restitution > 0.0 && restitution < last_restitution,
            "v0 {v0}"
        );
        assert!(full_error.abs() < 0.01, "v0 {v0}: {full_error}");
        last_restitution = restitution;
        exit_speeds.push(-full.exit_normal_velocity);
    }
    let (lo, hi) = exit_speeds
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    println!("exit speeds {exit_speeds:?}");
    assert!(hi / lo < 1.01, "one slow manifold: {exit_speeds:?}");
}

fn sliding(approach_speed: f64, slip_velocity: [f64; 2]) -> ContactApproach {
    ContactApproach {
        slip_velocity,
        ..head_on(CUBE_MASS, approach_speed)
    }
}

/// A slip the normal impulse cannot stop (`μ_s P_n < m_t (|v_t| − v_d)`) stays above the
/// friction transition speed `v_d`, where the regularized law is exactly `μ_d`: the tangential
/// impulse is `μ_d P_n` against the slip, with no regularization error (1-D and 2-D).
#[test]
fn fast_slip_takes_the_dynamic_coefficient_times_the_normal_impulse() {
    let p = ImpactParams::thesis_table_5_2();
    let f = FrictionParams::thesis_table_5_2();
    for slip in [[1.0, 0.0], [0.6, -0.8]] {
        let a = sliding(0.1, slip);
        let map = run(&a, &p, 1e-3);
        let speed_in = slip[0].hypot(slip[1]);
        assert!(f.mu_static * map.normal_impulse < a.tangential_mass * (speed_in - 0.012));
        let [px, py] = map.tangential_impulse;
        let expected = f.mu_dynamic * map.normal_impulse;
        let error = px.hypot(py) / expected - 1.0;
        println!("slip {slip:?}: |P_t| / (mu_d P_n) - 1 = {error:.2e}");
        assert!(error.abs() < 1e-8, "{error}");
        // Against the slip, and the slip's loss is the impulse over the mass.
        assert!((px * slip[1] - py * slip[0]).abs() < 1e-9 * expected * speed_in);
        assert!(px * slip[0] + py * slip[1] < 0.0);
        let speed_out = map.exit_slip_velocity[0].hypot(map.exit_slip_velocity[1]);
        let loss = expected / a.tangential_mass;
        assert!((speed_in - speed_out - loss).abs() < 1e-8 * loss);
        // ∫N|v_t| dt is the friction work over μ_d.
        assert!(
            (map.normal_force_slip_integral * f.mu_dynamic / map.friction_dissipation - 1.0).abs()
                < 1e-8
        );
    }
}

/// A slow slip (below `v_s`, no tangential force) is stopped. The law is regularized (μ(0) = 0,
/// no true stick): on `[0, v_s]` the cycloidal step is concave, so `μ(v) >= μ_s v / v_s` and
/// `m_t d|v|/dt <= −(μ_s/v_s) N |v|`, hence `|v_out| <= |v_in| exp(−μ_s P_n / (m_t v_s))`.
#[test]
fn slow_slip_is_stopped_within_the_regularization_bound() {
    let p = ImpactParams::thesis_table_5_2();
    let f = FrictionParams::thesis_table_5_2();
    for slip in [[1e-3, 0.0], [6e-4, -8e-4]] {
        let a = sliding(0.3, slip);
        let map = run(&a, &p, 1e-3);
        let speed_in = slip[0].hypot(slip[1]);
        let bound = speed_in
            * (-f.mu_static * map.normal_impulse
                / (a.tangential_mass * f.stiction_transition_speed))
                .exp();
        let speed_out = map.exit_slip_velocity[0].hypot(map.exit_slip_velocity[1]);
        println!("slip {speed_in:.1e} m/s: out {speed_out:.3e} m/s, bound {bound:.3e} m/s");
        assert!(bound < 1e-3 * speed_in, "the bound itself is a stop");
        // Slack: the error control's absolute scale on speeds (1e-10 of 0.3 m/s).
        assert!(speed_out <= bound + 1e-9, "{speed_out} > {bound}");
        // The friction never exceeds μ_s N.
        let [px, py] = map.tangential_impulse;
        assert!(px.hypot(py) <= f.mu_static * map.normal_impulse * (1.0 + 1e-9));
    }
}

/// Never creates energy: over seeded random contacts (masses, speeds, 2-D slip, external forces,
/// both STEP shapes, clamp and no ramp, friction laws), the exit kinetic plus stored energy
/// stays below the entry kinetic energy plus the external work, the dissipations are >= 0, and
/// the account closes.
#[test]
fn random_transients_are_passive() {
    use railwear::physics::step::StepKind;
    let mut rng = ChaCha8Rng::seed_from_u64(28);
    let log_uniform = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| 10f64.powf(rng.gen_range(lo..hi));
    let mut separated = 0;
    for case in 0..200 {
        let mass = log_uniform(&mut rng, -2.0, 0.0);
        let a = ContactApproach {
            normal_mass: mass,
            tangential_mass: mass * rng.gen_range(0.3..1.0),
            approach_speed: log_uniform(&mut rng, -3.0, 0.3),
            slip_velocity: [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)],
            external_normal_force: mass * 9.81 * rng.gen_range(-1.0..2.0),
            external_tangential_force: [
                mass * rng.gen_range(-3.0..3.0),
                mass * rng.gen_range(-3.0..3.0),
            ],
        };
        let step = if rng.gen_bool(0.5) {
            StepKind::Cycloidal
        } else {
            StepKind::Cubic
        };
        let p = ImpactParams {
            stiffness: log_uniform(&mut rng, 8.0, 10.0),
            exponent: [1.0, 1.5, 2.0, 2.4][rng.gen_range(0..4)],
            max_damping: if rng.gen_bool(0.2) {
                0.0
            } else {
                log_uniform(&mut rng, 0.0, 5.7)
            },
            full_damping_depth: if rng.gen_bool(0.2) {
                0.0
            } else {
                log_uniform(&mut rng, -6.0, -4.0)
            },
            step,
        };
        let vs = log_uniform(&mut rng, -3.5, -2.0);
        let f = FrictionParams {
            mu_static: rng.gen_range(0.0..0.5),
            mu_dynamic: rng.gen_range(0.0..0.5),
            stiction_transition_speed: vs,
            friction_transition_speed: vs * rng.gen_range(1.2..3.0),
            step,
        };
        let settings = ImpactMapSettings {
            time_limit: 1e-3,
            ..ImpactMapSettings::default()
        };
        let map = impact_map(&a, &p, &f, &settings).expect("valid input");
        separated += usize::from(map.end == ContactEnd::Separated);
        let entry = kinetic_energy(&a, a.approach_speed, a.slip_velocity);
        let exit = kinetic_energy(&a, map.exit_normal_velocity, map.exit_slip_velocity)
            + p.potential(map.end_penetration);
        let scale = entry + map.external_work.abs();
        assert!(
            exit <= entry + map.external_work + 1e-9 * scale,
            "case {case}: {exit} > {entry} + {}",
            map.external_work
        );
        assert!(map.damping_dissipation >= -1e-9 * scale, "case {case}");
        assert!(map.friction_dissipation >= -1e-9 * scale, "case {case}");
        assert!(
            energy_residual(&a, &p, &map).abs() < 1e-8 * scale,
            "case {case}"
        );
        let mu_max = f.mu_static.max(f.mu_dynamic);
        let [px, py] = map.tangential_impulse;
        assert!(px.hypot(py) <= mu_max * map.normal_impulse * (1.0 + 1e-9) + 1e-12 * scale);
    }
    println!("{separated} of 200 separated within 1 ms");
    assert!(separated > 0 && separated < 200, "both endings exercised");
}

/// Bad input is a typed error naming the field, never a panic.
#[test]
fn bad_input_names_the_field() {
    let a = head_on(CUBE_MASS, 0.1);
    let p = ImpactParams::thesis_table_5_2();
    let f = FrictionParams::thesis_table_5_2();
    let s = ImpactMapSettings::default();
    let cases: Vec<(ImpactMapError, &str)> = vec![
        (
            impact_map(
                &ContactApproach {
                    normal_mass: 0.0,
                    ..a
                },
                &p,
                &f,
                &s,
            )
            .unwrap_err(),
            "normal_mass",
        ),
        (
            impact_map(
                &ContactApproach {
                    tangential_mass: f64::NAN,
                    ..a
                },
                &p,
                &f,
                &s,
            )
            .unwrap_err(),
            "tangential_mass",
        ),
        (
            impact_map(
                &ContactApproach {
                    approach_speed: -0.1,
                    ..a
                },
                &p,
                &f,
                &s,
            )
            .unwrap_err(),
            "approach_speed",
        ),
        (
            impact_map(
                &ContactApproach {
                    slip_velocity: [f64::INFINITY, 0.0],
                    ..a
                },
                &p,
                &f,
                &s,
            )
            .unwrap_err(),
            "slip_velocity",
        ),
        (
            impact_map(
                &ContactApproach {
                    external_normal_force: f64::NAN,
                    ..a
                },
                &p,
                &f,
                &s,
            )
            .unwrap_err(),
            "external_normal_force",
        ),
        (
            impact_map(
                &a,
                &ImpactParams {
                    stiffness: -1.0,
                    ..p
                },
                &f,
                &s,
            )
            .unwrap_err(),
            "stiffness",
        ),
        (
            impact_map(
                &a,
                &p,
                &FrictionParams {
                    mu_static: f64::NAN,
                    ..f
                },
                &s,
            )
            .unwrap_err(),
            "mu_static",
        ),
        (
            impact_map(
                &a,
                &p,
                &f,
                &ImpactMapSettings {
                    time_limit: 0.0,
                    ..s
                },
            )
            .unwrap_err(),
            "time_limit",
        ),
    ];
    for (error, field) in cases {
        assert_eq!(error.field(), Some(field), "{error}");
        assert!(error.to_string().contains(field), "{error}");
    }
    assert!(matches!(
        impact_map(
            &ContactApproach {
                normal_mass: -1.0,
                ..a
            },
            &p,
            &f,
            &s
        ),
        Err(ImpactMapError::Approach(_))
    ));
}

/// The effective mass a touching point meets, against the rigid-body closed forms of a solid
/// cube of side `a` (inertia `m a²/6` about every axis): `1/m + |r × u|² · 6/(m a²)`.
#[test]
fn effective_mass_matches_the_cube_closed_forms() {
    let a = 0.0254;
    let cube = MassProperties::solid_box(Vector3::new(a, a, a), 2810.0);
    let m = cube.mass;
    let identity = UnitQuaternion::identity();
    let close = |x: Option<f64>, expected: f64| {
        let x = x.expect("an effective mass");
        assert!(
            (x - expected).abs() <= 1e-12 * expected,
            "{x} != {expected}"
        );
    };
    let corner = Vector3::new(a / 2.0, a / 2.0, a / 2.0);
    let face_centre = Vector3::new(a / 2.0, 0.0, 0.0);
    // At the centre of mass, and along the lever arm: no rotation is excited, the mass is m.
    close(
        effective_mass(&cube, &identity, &Vector3::zeros(), &Vector3::y()),
        m,
    );
    close(effective_mass(&cube, &identity, &corner, &corner), m);
    close(
        effective_mass(&cube, &identity, &face_centre, &Vector3::x()),
        m,
    );
    // A corner struck along a face normal: |r × x|² = a²/2, so 1/m + 3/m, a quarter of m.
    close(
        effective_mass(&cube, &identity, &corner, &Vector3::x()),
        m / 4.0,
    );
    // A face centre pushed in the face's plane: |r × y|² = a²/4, so 1/m + 1.5/m.
    close(
        effective_mass(&cube, &identity, &face_centre, &Vector3::y()),
        m / 2.5,
    );
    // The direction's length does not matter.
    close(
        effective_mass(&cube, &identity, &corner, &(3.0 * Vector3::x())),
        m / 4.0,
    );
    // Turning the body, its lever arm and the direction together changes nothing.
    let turn = UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0);
    close(
        effective_mass(&cube, &turn, &(turn * corner), &(turn * Vector3::x())),
        m / 4.0,
    );
    // No direction, no mass.
    assert!(effective_mass(&cube, &identity, &corner, &Vector3::zeros()).is_none());
}
