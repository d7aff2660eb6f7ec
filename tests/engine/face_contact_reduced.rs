//! The reduced face law (`face_contact = "reduced"`, docs/reference/models.md "Reduced face law")
//! against the exact per-node contact on the same states: the same stored energy (both exact
//! for `k w³/3`), forces within the exact contact's own ramp-rule bound where friction is off,
//! friction within the tolerance its a-priori estimate enforces, damping and friction only
//! dissipating, its Jacobian against central differences, and the energy account of runs.

use super::face_contact::{
    continuum_gross, evaluate, lip_contact, lowest_point_depth, random_pose, HALF,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use railwear::physics::contact::{Contact, FaceContact, TrackState};
use railwear::physics::friction::FrictionParams;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn reduced(contact: Contact) -> Contact {
    contact.with_face_contact(FaceContact::Reduced)
}

fn power(tracks: &[TrackState], f: impl Fn(&TrackState) -> f64) -> f64 {
    tracks.iter().map(f).sum()
}

#[test]
fn without_friction_the_reduced_law_stores_what_the_exact_one_does_and_differs_by_its_ramp_rule() {
    // Heads tilted and turning on a lip (bounded) at impact-like rates: closing on one side,
    // separating on the other. The stored energy is exact in both (k w³/3 is integrated
    // exactly by the exact contact's every rule, and in closed form here): within 1e-12. The
    // forces differ by the exact contact's 5-node rule on the closing ramp's cycloid only (the
    // reduced law is the continuum there): within 2e-3 of the gross load G, the exact
    // contact's own bound against the continuum (face_contact.rs); the damping powers as well.
    let exact = lip_contact(true, false);
    let red = reduced(lip_contact(true, false));
    let mut rng = ChaCha8Rng::seed_from_u64(5301);
    let mut compared = 0;
    for _ in 0..60 {
        let pose = random_pose(&mut rng, 2e-4);
        let v = Vector3::new(0.0, -rng.gen_range(0.0..0.01), 0.0);
        let omega = Vector3::new(rng.gen_range(-2.0..2.0), 0.0, rng.gen_range(-2.0..2.0));
        let (e_ex, f_ex, t_ex, tr_ex) = evaluate(&exact, &pose, v, omega);
        let (e_red, f_red, t_red, tr_red) = evaluate(&red, &pose, v, omega);
        if tr_ex.is_empty() {
            assert!(tr_red.is_empty());
            continue;
        }
        compared += 1;
        assert!(
            (e_red - e_ex).abs() <= 1e-12 * e_ex.abs(),
            "stored energy {e_red} vs exact {e_ex}"
        );
        let gross = continuum_gross(&pose, v, omega, 200);
        assert!(
            (f_red - f_ex).norm() <= 2e-3 * gross,
            "force {f_red:?} vs exact {f_ex:?} (G {gross:e})"
        );
        assert!(
            (t_red - t_ex).norm() <= 2e-3 * gross * HALF[2],
            "torque {t_red:?} vs exact {t_ex:?}"
        );
        let damping = |tr: &[TrackState]| power(tr, |t| t.damping_power);
        assert!(damping(&tr_red) >= 0.0);
        assert!(
            (damping(&tr_red) - damping(&tr_ex)).abs()
                <= 2e-3 * gross * (v.norm() + omega.norm() * HALF[0].hypot(HALF[2])),
            "damping power {} vs exact {}",
            damping(&tr_red),
            damping(&tr_ex)
        );
    }
    assert!(compared >= 30, "{compared} pressed states");
    let share = red.reduced_census.snapshot();
    assert!(share.closed_parts > 0, "{share:?}");
}

#[test]
fn where_its_estimate_holds_the_reduced_friction_is_within_the_tolerance_of_the_per_node_law() {
    // Heads pressed level to slightly tilted on a lip, sliding along and across it at 15 to
    // 60 mm/s (beyond the stiction transition) and turning slowly: most parts take friction
    // per part. The friction's part of the force (each law with friction minus the same law
    // without) differs from the per-node law's by at most the tolerance times μ_s times the
    // normal load (what the estimate bounds on each part taken per part) plus μ_s times the
    // two laws' normal-load difference (the exact contact's ramp rule, 2e-3 of the gross
    // load). The friction power and N·|v_slip| likewise.
    let exact = lip_contact(true, true);
    let exact0 = lip_contact(true, false);
    let red = reduced(lip_contact(true, true));
    let red0 = reduced(lip_contact(true, false));
    let mu_s = FrictionParams::thesis_table_5_2().mu_static;
    let tol = red.reduced_tolerance;
    let mut rng = ChaCha8Rng::seed_from_u64(5302);
    let mut compared = 0;
    for _ in 0..80 {
        let rot = UnitQuaternion::from_euler_angles(
            rng.gen_range(-2e-3..2e-3),
            rng.gen_range(-0.05..0.05),
            rng.gen_range(-2e-3..2e-3),
        );
        let lowest = lowest_point_depth(&rot);
        let pose = Isometry3::from_parts(
            Translation3::new(
                rng.gen_range(-0.03..0.01),
                lowest - rng.gen_range(2e-5..3e-4),
                0.0,
            ),
            rot,
        );
        let speed = rng.gen_range(0.015..0.06);
        let angle: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
        let v = Vector3::new(speed * angle.cos(), 0.0, speed * angle.sin());
        let omega = Vector3::new(
            rng.gen_range(-0.02..0.02),
            rng.gen_range(-0.1..0.1),
            rng.gen_range(-0.02..0.02),
        );
        let (_, f_ex, _, tr_ex) = evaluate(&exact, &pose, v, omega);
        let (_, f_ex0, _, _) = evaluate(&exact0, &pose, v, omega);
        let (_, f_red, _, tr_red) = evaluate(&red, &pose, v, omega);
        let (_, f_red0, _, _) = evaluate(&red0, &pose, v, omega);
        let load = power(&tr_ex, |t| t.normal_force);
        if load <= 0.0 {
            continue;
        }
        compared += 1;
        let gross = continuum_gross(&pose, v, omega, 200);
        let bound = tol * mu_s * load + mu_s * 2e-3 * gross;
        // The largest slip over the head.
        let fastest = speed + omega.norm() * HALF[0].hypot(HALF[2]);
        let (fr_ex, fr_red) = (f_ex - f_ex0, f_red - f_red0);
        assert!(
            (fr_red - fr_ex).norm() <= bound,
            "friction {fr_red:?} vs per node {fr_ex:?}, bound {bound:e}"
        );
        let fp = |tr: &[TrackState]| power(tr, |t| t.friction_power);
        assert!(
            (fp(&tr_red) - fp(&tr_ex)).abs() <= bound * fastest,
            "friction power {} vs {}",
            fp(&tr_red),
            fp(&tr_ex)
        );
        let nv = |tr: &[TrackState]| power(tr, |t| t.normal_force * t.slip_speed);
        assert!(
            (nv(&tr_red) - nv(&tr_ex)).abs() <= (tol * load + 2e-3 * gross) * fastest,
            "N |v_slip| {} vs {}",
            nv(&tr_red),
            nv(&tr_ex)
        );
    }
    assert!(compared >= 40, "{compared} pressed states");
    let share = red.reduced_census.snapshot();
    assert!(
        share.closed_parts > share.per_node_parts / 4,
        "friction per part must be taken on many parts: {share:?}"
    );
    assert!(share.largest_estimate <= tol, "{share:?}");
}

#[test]
fn the_reduced_laws_damping_and_friction_only_dissipate() {
    // Tilted, turning, sliding heads across the lip's edge: each track's damping and friction
    // power is non-negative, and the power balance of the contact on the head's rigid motion
    // (the lip fixed) closes: F·v + τ·ω = −dU/dt − Σ damping power − Σ friction power, with
    // dU/dt by central differences along the motion. Every part's friction acts at the point
    // whose slip it uses and its normal law is the gradient of the stored energy, so nothing
    // else may appear, but for the per-node parts' quadrature of the stored energy where the
    // nodes move with the cuts (the strips beyond the lip's edge: 5e-4 of the force,
    // face_contact.rs `GRADIENT_TOLERANCE`; a clamped head's rate of energy against its clamp
    // dissipation, up to 1.6e-3 measured): within 2e-3 of the powers' magnitude, the exact
    // contact's own bound against the continuum.
    let red = reduced(lip_contact(true, true)).with_reduced_tolerance(1.0);
    let mut rng = ChaCha8Rng::seed_from_u64(5303);
    let mut loaded = 0;
    for _ in 0..200 {
        let pose = random_pose(&mut rng, 4e-4);
        let (v, omega) =
            super::face_contact::random_motion(&mut rng, [0.05, 0.005, 0.05], [0.5, 0.5, 0.5]);
        let (_, f, t, tracks) = evaluate(&red, &pose, v, omega);
        if tracks.is_empty() {
            continue;
        }
        loaded += 1;
        for tr in &tracks {
            assert!(
                tr.damping_power >= 0.0,
                "damping power {}",
                tr.damping_power
            );
            assert!(
                tr.friction_power >= 0.0,
                "friction power {}",
                tr.friction_power
            );
        }
        let h = 1e-7;
        let moved = |s: f64| {
            Isometry3::from_parts(
                Translation3::from(pose.translation.vector + v * s),
                UnitQuaternion::from_scaled_axis(omega * s) * pose.rotation,
            )
        };
        let energy = |s: f64| evaluate(&red, &moved(s), v, omega).0;
        let du_dt = (energy(h) - energy(-h)) / (2.0 * h);
        let on_head = f.dot(&v) + t.dot(&omega);
        let damping = power(&tracks, |t| t.damping_power);
        let friction = power(&tracks, |t| t.friction_power);
        let scale =
            damping + friction + du_dt.abs() + f.norm() * v.norm() + t.norm() * omega.norm();
        assert!(
            (on_head + du_dt + damping + friction).abs() <= 2e-3 * scale,
            "power on the head {on_head} vs −dU/dt {} − damping {damping} − friction {friction}",
            -du_dt
        );
    }
    assert!(loaded >= 100, "{loaded} loaded states");
    assert!(red.reduced_census.snapshot().closed_parts > 0);
}

#[test]
fn the_reduced_laws_jacobian_equals_central_differences() {
    // The pressed cube of rattle box C in the reduced law, every part taken per part (the
    // tolerance opened to 1): its Jacobian is the per-part friction's (face_friction_rule.rs)
    // with the normal law's derivatives from the closed-form moments of ∂f/∂w and ∂f/∂ẇ.
    // Left out as there: the load centre's own motion in the slip, `[ω_rel]× δp_c`, which
    // vanishes at rest. Bounds as the per-part friction's: velocity columns of the spinning,
    // sliding cube within 2e-2, its tangential velocity columns within 1e-5; the pose columns
    // at rest within 1e-5.
    let with_reduced = |moving: bool| {
        let (mut sys, y) = super::face_contact::pressed_cube(moving);
        for c in &mut sys.contacts {
            *c = c
                .clone()
                .with_face_contact(FaceContact::Reduced)
                .with_reduced_tolerance(1.0);
        }
        (sys, y)
    };
    let (sys, y) = with_reduced(true);
    let n = sys.state_len();
    let (analytic, fd) = super::face_contact::jacobians(&sys, &y);
    super::face_contact::assert_columns_agree(&analytic, &fd, n, 7..13, 2e-2);
    super::face_contact::assert_each_column_agrees(&analytic, &fd, n, &[7, 9], 1e-5);
    assert!(sys.contacts[0].reduced_census.snapshot().closed_parts > 0);
    let (sys, y) = with_reduced(false);
    let (analytic, fd) = super::face_contact::jacobians(&sys, &y);
    super::face_contact::assert_columns_agree(&analytic, &fd, n, 0..3, 1e-5);
    super::face_contact::assert_columns_agree(&analytic, &fd, n, 3..7, 1e-5);
    assert!(sys.contacts[0].reduced_census.snapshot().closed_parts > 0);
}

#[test]
fn random_missile_states_never_gain_energy_with_the_reduced_face_law() {
    // As the exact contact's test (face_contact.rs): launcher-design without excitation,
    // settled, switched to the reduced law, then 10 random missile states run for 10 ms: the
    // mechanical energy never rises above its running minimum by more than
    // PASSIVITY_TOLERANCE of what was available, and the energy account closes within
    // BALANCE_TOLERANCE (0.5 %) of the dissipated work.
    use super::energy_passivity::random_missile_state;
    use railwear::validation::energy::{energy_run, BALANCE_TOLERANCE, PASSIVITY_TOLERANCE};
    let (model, settings, rest) = super::face_contact::settled_exact_launcher(1.0);
    let mut sys = model.system;
    for c in &mut sys.contacts {
        if c.face_contact == FaceContact::Exact {
            c.face_contact = FaceContact::Reduced;
        }
    }
    let mut ws = sys.workspace();
    let rest_energy = sys.energy(0.0, &rest, &mut ws).total();
    let mut rng = ChaCha8Rng::seed_from_u64(5304);
    for _ in 0..10 {
        let y = random_missile_state(&rest, &mut rng);
        let available = sys.energy(0.0, &y, &mut ws).total() - rest_energy;
        let run = energy_run(&sys, &y, settings, 0.01).expect("runs");
        let a = &run.audit;
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
    let closed: u64 = sys
        .contacts
        .iter()
        .map(|c| c.reduced_census.snapshot().closed_parts)
        .sum();
    assert!(closed > 0, "the runs must take parts in closed form");
}
