//! The supported impulse map (issue 28: the wall's transient with the body's other pressed
//! contacts as rigid supports): the reduction to the 1-D map, the momentum closed forms of a
//! support loaded by the contact's friction, the energy account, passivity over random inputs,
//! a support that lets go, typed input errors. Every number is fixed by physics (a closed
//! form, a conservation law, a bound), never copied from the map's output.

use railwear::physics::friction::FrictionParams;
use railwear::physics::impact::ImpactParams;
use railwear::physics::impact_map::{impact_map, ContactApproach, ContactEnd, ImpactMapSettings};
use railwear::physics::supported_impact_map::{
    supported_impact_map, Support, SupportedImpactMap, SupportedMapError, MAX_SUPPORTS,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The rattle box's cube, kg (thesis Table 5.1).
const CUBE_MASS: f64 = 0.046;
const GRAVITY: f64 = 9.81;
/// The hybrid's horizon, s.
const HORIZON: f64 = 2e-5;

fn settings(time_limit: f64) -> ImpactMapSettings {
    ImpactMapSettings {
        time_limit,
        max_steps: 20_000_000,
        ..ImpactMapSettings::default()
    }
}

/// A floor under the body: its normal is the frame's axis 1 (up), the body at rest on it.
fn floor() -> Support {
    Support {
        normal: [0.0, 1.0, 0.0],
        velocity_offset: [0.0; 3],
        friction: FrictionParams::thesis_table_5_2(),
    }
}

/// The cube meeting a wall at `approach_speed` with `slip` in the wall's plane (axis 1 up,
/// axis 2 along the wall), under its weight (along −axis 1).
fn cube_on_wall(approach_speed: f64, slip: [f64; 2]) -> ContactApproach {
    ContactApproach {
        normal_mass: CUBE_MASS,
        tangential_mass: CUBE_MASS,
        approach_speed,
        slip_velocity: slip,
        external_normal_force: 0.0,
        external_tangential_force: [-CUBE_MASS * GRAVITY, 0.0],
    }
}

fn kinetic_energy(a: &ContactApproach, wdot: f64, slip: [f64; 2]) -> f64 {
    0.5 * a.normal_mass * wdot * wdot
        + 0.5 * a.tangential_mass * (slip[0] * slip[0] + slip[1] * slip[1])
}

/// `½ v_inᵀM v_in + W_ext + W_sup − (½ v_outᵀM v_out + V(w_end) + E_damp + E_fric + Σ E_fric,j)`.
fn energy_residual(a: &ContactApproach, p: &ImpactParams, m: &SupportedImpactMap) -> f64 {
    let c = &m.contact;
    kinetic_energy(a, a.approach_speed, a.slip_velocity) + c.external_work + m.support_work
        - kinetic_energy(a, c.exit_normal_velocity, c.exit_slip_velocity)
        - p.potential(c.end_penetration)
        - m.dissipated()
}

/// With no support the equations, the steps and so every number are the 1-D map's: bit for
/// bit, over a head-on drop, a 2-D slip under a drive and gravity, and a bouncing contact.
#[test]
fn without_supports_it_is_the_one_dimensional_map_bit_for_bit() {
    let friction = FrictionParams::thesis_table_5_2();
    let bouncing = ImpactParams {
        max_damping: 20.0,
        ..ImpactParams::thesis_table_5_2()
    };
    let cases = [
        (
            ContactApproach::head_on(CUBE_MASS, 0.3),
            ImpactParams::thesis_table_5_2(),
        ),
        (
            ContactApproach {
                normal_mass: CUBE_MASS,
                tangential_mass: 0.7 * CUBE_MASS,
                approach_speed: 0.3,
                slip_velocity: [0.02, -0.01],
                external_normal_force: CUBE_MASS * GRAVITY,
                external_tangential_force: [0.1, -0.05],
            },
            ImpactParams::thesis_table_5_2(),
        ),
        (cube_on_wall(0.5, [0.1, 0.2]), bouncing),
    ];
    for (a, p) in cases {
        let s = settings(2e-3);
        let one = impact_map(&a, &p, &friction, &s).expect("valid");
        let supported = supported_impact_map(&a, &[], &p, &friction, &s).expect("valid");
        assert_eq!(supported.contact, one, "{a:?}");
        assert_eq!(supported.support_work, 0.0);
        assert_eq!(supported.support_count, 0);
    }
}

/// The cube's wall point slides up the wall (the frozen rotation: the floor point, offset by
/// `−v_up`, stays at rest on the floor) at a speed above the friction law's `v_d` throughout:
/// the wall's friction is `μ_d N` straight down, so the floor's extra normal impulse over the
/// weight's is the wall's friction impulse along the floor's normal, `μ_d P_n` (momentum along
/// the floor's normal, whose velocity the support holds). And generally, for any slip: the
/// floor's extra impulse equals minus the wall's friction impulse along its normal.
#[test]
fn floor_takes_the_wall_friction_pressing_the_body_into_it() {
    let p = ImpactParams::thesis_table_5_2();
    let friction = FrictionParams::thesis_table_5_2();
    let mu_d = friction.mu_dynamic;
    let v_up = 0.05;
    let mut support = floor();
    support.velocity_offset = [0.0, -v_up, 0.0];
    let a = cube_on_wall(0.3, [v_up, 0.0]);
    let m = supported_impact_map(&a, &[support], &p, &friction, &settings(HORIZON)).expect("valid");
    assert_eq!(m.contact.end, ContactEnd::TimeLimit);
    let weight_impulse = CUBE_MASS * GRAVITY * m.contact.duration;
    let floor_extra = m.supports[0].normal_impulse - weight_impulse;
    let expected = mu_d * m.contact.normal_impulse;
    let error = (floor_extra / expected - 1.0).abs();
    println!(
        "wall P_n {:.4e} N·s, floor extra {floor_extra:.6e} vs μ_d P_n {expected:.6e}: {error:.2e}",
        m.contact.normal_impulse
    );
    assert!(error < 1e-9, "{floor_extra} vs {expected}");
    // The wall point keeps its upward slip: the support holds the velocity along its normal.
    assert!((m.contact.exit_slip_velocity[0] / v_up - 1.0).abs() < 1e-9);
    assert!(!m.supports[0].lifted);

    // Any slip, the floor sliding too: the floor's extra load is the wall friction's push.
    for slip in [[0.02, 0.3], [0.2, -0.1], [1e-4, 0.05]] {
        let mut support = floor();
        support.velocity_offset = [0.0, -slip[0], 0.0];
        let a = cube_on_wall(0.3, slip);
        let m =
            supported_impact_map(&a, &[support], &p, &friction, &settings(HORIZON)).expect("valid");
        let floor_extra = m.supports[0].normal_impulse - CUBE_MASS * GRAVITY * m.contact.duration;
        let push = -m.contact.tangential_impulse[0];
        let error = (floor_extra - push).abs() / m.supports[0].normal_impulse;
        println!("slip {slip:?}: floor extra {floor_extra:.6e}, wall push {push:.6e}: {error:.2e}");
        assert!(error < 1e-9, "slip {slip:?}");
    }
}

/// The cube slides along the wall (axis 2) above `v_d`, no vertical slip: the wall's friction
/// is `μ_d N` along −axis 2, nothing presses the body into the floor, so the floor carries the
/// weight only (`P_f = m g T`), dissipates `μ_d ∫N_f|s_f| dt` (its slip `(ẇ, 0, v_2)` stays
/// above `v_d`), and its `∫N_f|s_f| dt` lies between `m g` times the distance slid along the
/// wall and that plus `m g ∫|ẇ| dt <= m g · 2 w_max`. Momentum along axis 2:
/// `m Δv_2 = −μ_d P_n + P_f,2`.
#[test]
fn sliding_along_wall_and_floor_loses_dynamic_friction_on_both() {
    let p = ImpactParams::thesis_table_5_2();
    let friction = FrictionParams::thesis_table_5_2();
    let mu_d = friction.mu_dynamic;
    let v0 = 0.5;
    let a = cube_on_wall(0.3, [0.0, v0]);
    let m = supported_impact_map(&a, &[floor()], &p, &friction, &settings(HORIZON)).expect("valid");
    let t = m.contact.duration;
    let weight = CUBE_MASS * GRAVITY;
    let s = &m.supports[0];
    let dv = m.contact.exit_slip_velocity[1] - v0;
    let checks = [
        ("floor normal impulse", s.normal_impulse, weight * t),
        (
            "wall friction impulse",
            m.contact.tangential_impulse[1],
            -mu_d * m.contact.normal_impulse,
        ),
        (
            "floor friction dissipation",
            s.friction_dissipation,
            mu_d * s.normal_force_slip_integral,
        ),
        (
            "m Δv_2",
            CUBE_MASS * dv,
            -mu_d * m.contact.normal_impulse + s.friction_impulse[2],
        ),
    ];
    for (name, got, want) in checks {
        let error = (got / want - 1.0).abs();
        println!("{name}: {got:.8e} vs {want:.8e}: {error:.2e}");
        assert!(error < 1e-9, "{name}: {got} vs {want}");
    }
    assert!(m.contact.tangential_impulse[0].abs() < 1e-12 * weight * t);
    assert!(s.friction_impulse[1].abs() < 1e-12 * weight * t);
    let (low, high) = (
        weight * m.displacement[2],
        weight * (m.displacement[2] + 2.0 * m.contact.max_penetration),
    );
    println!(
        "floor ∫N|s| dt {:.6e} in [{low:.6e}, {high:.6e}]",
        s.normal_force_slip_integral
    );
    assert!(s.normal_force_slip_integral >= low * (1.0 - 1e-9));
    assert!(s.normal_force_slip_integral <= high * (1.0 + 1e-9));
}

/// The account closes within 1e-8 of the dissipated work on the rattle box's cases (one floor,
/// the wall point sliding in 2-D, the thesis damping; a bouncing law) and two supports (a
/// floor and a side wall of a corner), with offsets (support work).
#[test]
fn energy_account_closes_with_supports() {
    let friction = FrictionParams::thesis_table_5_2();
    let bouncing = ImpactParams {
        max_damping: 20.0,
        ..ImpactParams::thesis_table_5_2()
    };
    let side = Support {
        normal: [0.2, 0.0, 1.0],
        velocity_offset: [0.0, 0.01, 0.0],
        friction: FrictionParams {
            mu_static: 0.3,
            mu_dynamic: 0.25,
            ..FrictionParams::thesis_table_5_2()
        },
    };
    let mut tilted_floor = floor();
    tilted_floor.velocity_offset = [0.003, -0.04, 0.001];
    for (p, horizon) in [
        (ImpactParams::thesis_table_5_2(), HORIZON),
        (bouncing, 2e-3),
    ] {
        for supports in [vec![floor()], vec![tilted_floor, side]] {
            let a = ContactApproach {
                external_normal_force: 0.02,
                ..cube_on_wall(0.3, [0.04, -0.2])
            };
            let m = supported_impact_map(&a, &supports, &p, &friction, &settings(horizon))
                .expect("valid");
            let residual = energy_residual(&a, &p, &m);
            let dissipated = m.dissipated();
            println!(
                "c_max {}, {} supports: {:?}, dissipated {dissipated:.4e} J, support work \
                 {:.3e} J, residual/dissipated {:.2e}, {} steps",
                p.max_damping,
                supports.len(),
                m.contact.end,
                m.support_work,
                residual / dissipated,
                m.contact.steps
            );
            assert!(m.shares().iter().all(|s| s.friction_dissipation > 0.0));
            assert!(residual.abs() < 1e-8 * dissipated);
        }
    }
}

/// 200 seeded random transients (masses, speeds, slips, forces, damping, friction laws, up to
/// [`MAX_SUPPORTS`] supports with random normals and offsets): every dissipation and every
/// support's normal impulse >= 0, never more energy out than in plus the external and support
/// work, and the account within 1e-7 of the energy turned over.
#[test]
fn random_supported_transients_are_passive() {
    let mut rng = ChaCha8Rng::seed_from_u64(282);
    let mut worst = 0.0f64;
    let mut lifted = 0;
    for case in 0..200 {
        let unit = |rng: &mut ChaCha8Rng| {
            let n: [f64; 3] = [
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            ];
            n
        };
        let a = ContactApproach {
            normal_mass: rng.gen_range(0.01..1.0),
            tangential_mass: rng.gen_range(0.01..1.0),
            approach_speed: 10f64.powf(rng.gen_range(-3.0..0.3)),
            slip_velocity: [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)],
            external_normal_force: rng.gen_range(-1.0..2.0),
            external_tangential_force: [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)],
        };
        let p = ImpactParams {
            max_damping: 10f64.powf(rng.gen_range(0.0..5.7)),
            ..ImpactParams::thesis_table_5_2()
        };
        let friction = FrictionParams {
            mu_static: rng.gen_range(0.05..0.6),
            mu_dynamic: rng.gen_range(0.03..0.5),
            ..FrictionParams::thesis_table_5_2()
        };
        let count = rng.gen_range(0..=MAX_SUPPORTS);
        let mut supports = Vec::new();
        while supports.len() < count {
            let normal = unit(&mut rng);
            let length = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
            if length < 0.1 || normal[0].abs() > 0.9 * length {
                continue;
            }
            supports.push(Support {
                normal,
                velocity_offset: [
                    rng.gen_range(-0.1..0.1),
                    rng.gen_range(-0.1..0.1),
                    rng.gen_range(-0.1..0.1),
                ],
                friction: FrictionParams {
                    mu_static: rng.gen_range(0.05..0.6),
                    mu_dynamic: rng.gen_range(0.03..0.5),
                    ..FrictionParams::thesis_table_5_2()
                },
            });
        }
        let horizon = 10f64.powf(rng.gen_range(-5.0..-3.0));
        let m =
            supported_impact_map(&a, &supports, &p, &friction, &settings(horizon)).expect("valid");
        let c = &m.contact;
        assert!(
            c.damping_dissipation >= 0.0 && c.friction_dissipation >= 0.0,
            "case {case}"
        );
        for s in m.shares() {
            assert!(s.normal_impulse >= 0.0, "case {case}");
            assert!(s.friction_dissipation >= 0.0, "case {case}");
            assert!(s.normal_force_slip_integral >= 0.0, "case {case}");
            lifted += usize::from(s.lifted);
        }
        let e_in = kinetic_energy(&a, a.approach_speed, a.slip_velocity);
        let e_out = kinetic_energy(&a, c.exit_normal_velocity, c.exit_slip_velocity)
            + p.potential(c.end_penetration);
        let turned_over =
            e_in + e_out + c.external_work.abs() + m.support_work.abs() + m.dissipated();
        let residual = energy_residual(&a, &p, &m) / turned_over;
        worst = worst.max(residual.abs());
        assert!(
            e_out <= e_in + c.external_work + m.support_work + 1e-7 * turned_over,
            "case {case}: out {e_out} in {e_in}"
        );
        assert!(residual.abs() < 1e-7, "case {case}: {residual}");
    }
    println!("largest |residual| / energy turned over {worst:.2e}; supports let go {lifted}");
}

/// Gravity pulling the body off its "floor": the support lets go, carries nothing, and says
/// so; the body then moves as without it.
#[test]
fn a_support_pulled_away_from_lets_go() {
    let p = ImpactParams::thesis_table_5_2();
    let friction = FrictionParams::thesis_table_5_2();
    let mut a = cube_on_wall(0.3, [0.0, 0.1]);
    a.external_tangential_force = [CUBE_MASS * GRAVITY, 0.0];
    let s = settings(HORIZON);
    let m = supported_impact_map(&a, &[floor()], &p, &friction, &s).expect("valid");
    let free = impact_map(&a, &p, &friction, &s).expect("valid");
    assert!(m.supports[0].lifted);
    assert_eq!(m.supports[0].normal_impulse, 0.0);
    assert!((m.contact.damping_dissipation / free.damping_dissipation - 1.0).abs() < 1e-9);
}

/// Bad supports name their field and index; too many are refused; the contact's own fields
/// are named as in the 1-D map.
#[test]
fn bad_supports_name_the_field() {
    let p = ImpactParams::thesis_table_5_2();
    let friction = FrictionParams::thesis_table_5_2();
    let a = cube_on_wall(0.3, [0.0, 0.1]);
    let s = settings(HORIZON);
    let with = |support: Support| supported_impact_map(&a, &[floor(), support], &p, &friction, &s);
    let cases = [
        (
            Support {
                normal: [0.0; 3],
                ..floor()
            },
            "normal",
        ),
        (
            Support {
                normal: [1.0, 0.01, 0.0],
                ..floor()
            },
            "normal",
        ),
        (
            Support {
                normal: [0.0, f64::NAN, 1.0],
                ..floor()
            },
            "normal",
        ),
        (
            Support {
                velocity_offset: [0.0, f64::INFINITY, 0.0],
                ..floor()
            },
            "velocity_offset",
        ),
        (
            Support {
                friction: FrictionParams {
                    mu_dynamic: -0.1,
                    ..FrictionParams::thesis_table_5_2()
                },
                ..floor()
            },
            "mu_dynamic",
        ),
    ];
    for (support, field) in cases {
        let error = with(support).expect_err("refused");
        assert!(
            matches!(error, SupportedMapError::Support { index: 1, .. }),
            "{error}"
        );
        assert_eq!(error.field(), Some(field), "{error}");
    }
    let many = vec![floor(); MAX_SUPPORTS + 1];
    let error = supported_impact_map(&a, &many, &p, &friction, &s).expect_err("refused");
    assert!(matches!(error, SupportedMapError::TooManySupports { .. }));
    assert_eq!(error.field(), Some("supports"));
    let bad = ContactApproach {
        normal_mass: -1.0,
        ..a
    };
    let error = supported_impact_map(&bad, &[floor()], &p, &friction, &s).expect_err("refused");
    assert_eq!(error.field(), Some("normal_mass"));
}
