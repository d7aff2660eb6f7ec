//! Tests of the multibody system's contact evaluation (geometry modes, patch reuse, contact
//! Jacobian, the tracks the integrator leaves) and of a model run's soundness on the reference
//! models: they build rattle box C and the launcher from `configs/`, so they live above the
//! physics floor and above `models::run` (which `models::case` builds for).

use crate::physics::body::BodyKind;
use crate::physics::contact::{GeometryMode, TrackState};
use crate::physics::system::{MultibodySystem, Workspace};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::path::Path;

/// The reference model `configs/<name>.toml`.
fn reference_model(name: &str) -> super::run::BuiltModel {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let case = super::case::load_case(&dir.join(format!("{name}.toml"))).expect("case");
    super::case::build(&case, &dir).expect("model")
}

/// Rattle box C with the cube tilted and pressed into the floor, spinning and sliding.
fn pressed_cube() -> (MultibodySystem, Vec<f64>) {
    let model = reference_model("rattle-box-c");
    let mut y = model.initial_state.clone();
    y[1] -= 3e-5; // 30 µm further into the floor
    let tilt = nalgebra::UnitQuaternion::from_euler_angles(2e-3, 1e-3, -4e-3);
    let q = tilt.into_inner();
    y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
    y[7..13].copy_from_slice(&[0.3, -0.05, 0.1, 2.0, -1.0, 0.5]);
    (model.system, y)
}

/// The tracks of one derivative evaluation at `y` in geometry mode `mode`.
fn tracks_in_mode(
    sys: &MultibodySystem,
    ws: &mut Workspace,
    y: &[f64],
    mode: GeometryMode,
) -> Vec<TrackState> {
    let mut f = vec![0.0; sys.state_len()];
    ws.keep_tracks = true;
    ws.geometry.set_mode(mode);
    sys.derivative(0.0, y, &mut f, ws);
    ws.geometry.set_mode(GeometryMode::Compute);
    std::mem::take(&mut ws.tracks)
}

#[test]
fn frozen_patches_keep_the_normal_force_exact_and_move_with_the_piece() {
    let (sys, y) = pressed_cube();
    let mut ws = sys.workspace();
    let recorded = tracks_in_mode(&sys, &mut ws, &y, GeometryMode::Record);
    assert!(!recorded.is_empty(), "the cube must touch the floor");
    // Pressed 0.2 µm deeper, moving faster: penetration, its rate and the normal force
    // come from the support function, bit for bit as a full evaluation.
    let mut deeper = y.clone();
    deeper[1] -= 2e-7;
    deeper[8] -= 0.05;
    let full = tracks_in_mode(&sys, &mut ws, &deeper, GeometryMode::Compute);
    let frozen = tracks_in_mode(&sys, &mut ws, &deeper, GeometryMode::Frozen);
    assert_eq!(full.len(), frozen.len());
    for (a, b) in full.iter().zip(&frozen) {
        assert_eq!((a.contact, a.track), (b.contact, b.track));
        assert_eq!(a.penetration, b.penetration);
        assert_eq!(a.penetration_rate, b.penetration_rate);
        assert_eq!(a.normal_force, b.normal_force);
        assert_ne!(a.area, b.area, "the area is the recorded one");
    }
    // Slid 0.1 mm along the floor and turned 0.01 rad about its normal: the overlap moves
    // rigidly with the cube, so the held centroid is the true one (to round-off).
    let mut slid = y.clone();
    slid[0] += 1e-4;
    slid[2] -= 5e-5;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(y[3], y[4], y[5], y[6]));
    let turned = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.01) * q;
    slid[3..7].copy_from_slice(&[turned.w, turned.i, turned.j, turned.k]);
    let _ = tracks_in_mode(&sys, &mut ws, &y, GeometryMode::Record);
    let full = tracks_in_mode(&sys, &mut ws, &slid, GeometryMode::Compute);
    let frozen = tracks_in_mode(&sys, &mut ws, &slid, GeometryMode::Frozen);
    assert_eq!(full.len(), frozen.len());
    for (a, b) in full.iter().zip(&frozen) {
        assert!(
            (a.point - b.point).norm() < 1e-12,
            "{:?} vs {:?}",
            a.point,
            b.point
        );
        assert!((a.area - b.area).abs() < 1e-9 * a.area);
        assert!((a.slip_velocity - b.slip_velocity).norm() < 1e-12);
    }
    // Recorded clear of the floor, evaluated touching it: the new patch is computed in full.
    let mut above = y.clone();
    above[1] += 1e-3;
    let none = tracks_in_mode(&sys, &mut ws, &above, GeometryMode::Record);
    assert!(none.is_empty());
    let full = tracks_in_mode(&sys, &mut ws, &y, GeometryMode::Compute);
    let frozen = tracks_in_mode(&sys, &mut ws, &y, GeometryMode::Frozen);
    assert_eq!(full.len(), frozen.len());
    for (a, b) in full.iter().zip(&frozen) {
        assert_eq!(
            (a.point, a.area, a.normal_force),
            (b.point, b.area, b.normal_force)
        );
    }
}

#[test]
fn refreshed_patches_are_reused_within_their_bound_and_recomputed_beyond_it() {
    use crate::physics::contact::PATCH_REUSE;
    let (sys, y) = pressed_cube();
    let mut ws = sys.workspace();
    let recorded = tracks_in_mode(&sys, &mut ws, &y, GeometryMode::Refresh);
    assert_eq!(recorded.len(), 1, "the cube rests on the floor only");
    let (w, area) = (recorded[0].penetration, recorded[0].area);
    let half: f64 = 0.0254 / 2.0;
    let radius = (3.0 * half * half).sqrt();
    // Pressed deeper by half the reuse bound: the patch is kept (area as recorded), within
    // the bound's error of a full computation; the penetration is exact.
    let mut near = y.clone();
    near[1] -= 0.5 * PATCH_REUSE * w;
    let full = tracks_in_mode(&sys, &mut ws, &near, GeometryMode::Compute);
    let kept = tracks_in_mode(&sys, &mut ws, &near, GeometryMode::Refresh);
    assert_eq!(kept[0].area, area);
    assert_ne!(full[0].area, area);
    assert_eq!(kept[0].penetration, full[0].penetration);
    assert_eq!(kept[0].normal_force, full[0].normal_force);
    assert!((kept[0].area - full[0].area).abs() <= 7.0 * PATCH_REUSE * full[0].area);
    assert!((kept[0].point - full[0].point).norm() <= 12.0 * PATCH_REUSE * radius);
    // Twice the bound further: recomputed, bit for bit a full computation.
    let mut far = y.clone();
    far[1] -= 2.0 * PATCH_REUSE * w;
    let full = tracks_in_mode(&sys, &mut ws, &far, GeometryMode::Compute);
    let redone = tracks_in_mode(&sys, &mut ws, &far, GeometryMode::Refresh);
    assert_eq!(
        (redone[0].area, redone[0].point),
        (full[0].area, full[0].point)
    );
    // A tilt of the same size is caught through the bounding radius.
    let q = UnitQuaternion::from_quaternion(Quaternion::new(far[3], far[4], far[5], far[6]));
    let tilt = 2.0 * PATCH_REUSE * w / radius;
    let tilted = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), tilt) * q;
    far[3..7].copy_from_slice(&[tilted.w, tilted.i, tilted.j, tilted.k]);
    let full = tracks_in_mode(&sys, &mut ws, &far, GeometryMode::Compute);
    let redone = tracks_in_mode(&sys, &mut ws, &far, GeometryMode::Refresh);
    assert_eq!(
        (redone[0].area, redone[0].point),
        (full[0].area, full[0].point)
    );
}

#[test]
fn replayed_geometry_gives_the_same_derivative_for_velocity_changes() {
    let (sys, y) = pressed_cube();
    let mut ws = sys.workspace();
    let n = sys.state_len();
    let (mut computed, mut replayed) = (vec![0.0; n], vec![0.0; n]);
    let mut tracks = 0;
    sys.tracks(0.0, &y, &mut ws, &mut |_| tracks += 1);
    assert!(tracks >= 1, "the cube must touch the floor");
    ws.geometry.set_mode(GeometryMode::Record);
    sys.derivative(0.0, &y, &mut computed, &mut ws);
    for j in 7..13 {
        let mut yv = y.clone();
        yv[j] += 1e-3 * (j as f64);
        ws.geometry.set_mode(GeometryMode::Compute);
        sys.derivative(0.0, &yv, &mut computed, &mut ws);
        ws.geometry.set_mode(GeometryMode::Replay);
        sys.derivative(0.0, &yv, &mut replayed, &mut ws);
        assert_eq!(computed, replayed, "velocity column {j}");
    }
    // A pose change: the forces come from the contact points, computed exactly in every
    // mode; only the tracks' area (the overlap) is the replayed one.
    let mut yp = y.clone();
    yp[1] -= 1e-6;
    ws.keep_tracks = true;
    ws.geometry.set_mode(GeometryMode::Compute);
    sys.derivative(0.0, &yp, &mut computed, &mut ws);
    let area_computed = ws.tracks[0].area;
    ws.geometry.set_mode(GeometryMode::Replay);
    sys.derivative(0.0, &yp, &mut replayed, &mut ws);
    assert_eq!(computed, replayed);
    assert_ne!(area_computed, ws.tracks[0].area);
}

#[test]
fn pose_columns_replay_only_contacts_of_other_bodies() {
    let model = reference_model("launcher-design");
    let (sys, y) = (model.system, model.initial_state);
    let mut ws = sys.workspace();
    let n = sys.state_len();
    let (mut computed, mut replayed) = (vec![0.0; n], vec![0.0; n]);
    ws.geometry.set_mode(GeometryMode::Record);
    sys.derivative(0.0, &y, &mut computed, &mut ws);
    for (i, b) in sys.bodies.iter().enumerate() {
        let BodyKind::Dynamic { offset } = b.kind else {
            continue;
        };
        for j in offset..offset + 7 {
            let mut yp = y.clone();
            yp[j] += 2e-6;
            ws.geometry.set_mode(GeometryMode::Compute);
            sys.derivative(0.0, &yp, &mut computed, &mut ws);
            ws.geometry.set_mode(GeometryMode::ReplayExcept(i));
            sys.derivative(0.0, &yp, &mut replayed, &mut ws);
            assert_eq!(computed, replayed, "body {} column {j}", b.name);
        }
    }
}

/// Forward-difference Jacobian of the derivative, column-major, with or without contacts.
fn fd_jacobian(sys: &MultibodySystem, y: &[f64], with_contacts: bool) -> Vec<f64> {
    let n = sys.state_len();
    let mut ws = sys.workspace();
    ws.skip_contacts = !with_contacts;
    let (mut f0, mut f1) = (vec![0.0; n], vec![0.0; n]);
    sys.derivative(0.0, y, &mut f0, &mut ws);
    let mut jac = vec![0.0; n * n];
    for j in 0..n {
        // Central differences: the contact force is smooth away from the clamp.
        let delta = 1e-7 * y[j].abs().max(1e-3);
        let mut yp = y.to_vec();
        yp[j] += delta;
        sys.derivative(0.0, &yp, &mut f1, &mut ws);
        yp[j] = y[j] - delta;
        sys.derivative(0.0, &yp, &mut f0, &mut ws);
        for i in 0..n {
            jac[j * n + i] = (f1[i] - f0[i]) / (2.0 * delta);
        }
    }
    jac
}

fn analytic_contact_jacobian(sys: &MultibodySystem, y: &[f64]) -> (Vec<f64>, usize) {
    let n = sys.state_len();
    let mut ws = sys.workspace();
    ws.linearize = true;
    let mut f = vec![0.0; n];
    sys.derivative(0.0, y, &mut f, &mut ws);
    let mut jac = vec![0.0; n * n];
    sys.contact_jacobian(y, &mut ws, &mut jac);
    // Points' records (list) and tracks' summed records (moments).
    (
        jac,
        ws.linearizations.len() + ws.linearization_moments.len(),
    )
}

#[test]
fn contact_jacobian_velocity_columns_equal_finite_differences() {
    // A velocity change moves no pose, so the contact force's velocity derivatives are
    // exactly those of the IMPACT damping and the friction law at fixed geometry.
    let (sys, y) = pressed_cube();
    let n = sys.state_len();
    let (analytic, tracks) = analytic_contact_jacobian(&sys, &y);
    assert!(tracks >= 1);
    let full = fd_jacobian(&sys, &y, true);
    let free = fd_jacobian(&sys, &y, false);
    for j in 7..13 {
        let col = |m: &[f64], i: usize| m[j * n + i];
        let scale = (0..n).map(|i| col(&full, i).abs()).fold(0.0_f64, f64::max);
        assert!(scale > 1e3, "column {j} must feel the contact damping");
        for i in 0..n {
            let contact_fd = col(&full, i) - col(&free, i);
            let err = (contact_fd - col(&analytic, i)).abs();
            assert!(
                err <= 1e-6 * scale,
                "d f[{i}] / d y[{j}]: finite differences {contact_fd:e}, analytic {:e}",
                col(&analytic, i)
            );
        }
    }
}

#[test]
fn contact_jacobian_pose_columns_equal_finite_differences() {
    // Each contact point's force, the rates it uses and its point of application belong to
    // the same material point: translating the cube moves them together, so every row of
    // the translation columns is exact. The rotation columns leave out the second-order
    // geometric terms (the lever of the point in the torque, the turn of the slip's lever):
    // relative size F / (k_eff r), bounded here by 1e-3 of the column.
    let (sys, y) = pressed_cube();
    let n = sys.state_len();
    let (analytic, _) = analytic_contact_jacobian(&sys, &y);
    let full = fd_jacobian(&sys, &y, true);
    let free = fd_jacobian(&sys, &y, false);
    for (cols, tol) in [(0..3, 1e-5), (3..7, 1e-5)] {
        let scale = cols
            .clone()
            .flat_map(|j| (7..13).map(move |i| (j, i)))
            .map(|(j, i)| (full[j * n + i] - free[j * n + i]).abs())
            .fold(0.0_f64, f64::max);
        assert!(scale > 1e3, "columns {cols:?} must feel the contact");
        for j in cols {
            for i in 7..13 {
                let contact_fd = full[j * n + i] - free[j * n + i];
                let err = (contact_fd - analytic[j * n + i]).abs();
                assert!(
                    err <= tol * scale,
                    "d f[{i}] / d y[{j}]: finite differences {contact_fd:e}, analytic {:e}",
                    analytic[j * n + i]
                );
            }
        }
    }
}

#[test]
fn integrator_leaves_the_tracks_of_its_last_evaluation() {
    // simulate() records each step's tracks from the integrator's last derivative evaluation
    // instead of recomputing them. For the finite-difference Newton and Dopri5 that evaluation
    // is at the accepted state. The contact-aware Newton takes the next step's start from its
    // last iterate `z − Δz` (Δz its last update): the tracks are that iterate's, with the
    // area (thesis 2.5) of the accepted state, refreshed as the next step's patches are.
    use crate::physics::contact::PATCH_REUSE;
    use crate::physics::integrator::{Integrator, IntegratorKind, NewtonJacobian};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let case = super::case::load_case(&dir.join("rattle-box-c.toml")).expect("case");
    let base_settings = super::case::integrator_settings(&case).expect("settings");
    // Pressed in, spinning and sliding: the tracks change on every step.
    let (sys, y0) = pressed_cube();
    for (kind, newton) in [
        (IntegratorKind::Trbdf2, NewtonJacobian::ContactAware),
        (IntegratorKind::Trbdf2, NewtonJacobian::FiniteDifference),
        (IntegratorKind::Sdirk2, NewtonJacobian::ContactAware),
        (IntegratorKind::Dopri5, NewtonJacobian::ContactAware),
    ] {
        let mut settings = base_settings;
        settings.kind = kind;
        settings.newton = newton;
        let mut integ = Integrator::new(&sys, settings);
        let mut ws = sys.workspace();
        ws.keep_tracks = true;
        let mut check = sys.workspace();
        let mut y = y0.clone();
        let (mut t, mut steps_in_contact, mut from_iterate) = (0.0, 0, 0);
        while t < 2e-4 {
            t = integ
                .advance(&sys, &mut ws, t, &mut y, 2e-4)
                .expect("advances");
            let mut at = y.clone();
            if let Some(dz) = integ.last_newton_update() {
                at.iter_mut().zip(dz).for_each(|(v, d)| *v -= d);
                from_iterate += 1;
            }
            let mut fresh = Vec::new();
            sys.tracks(t, &at, &mut check, &mut |tr| fresh.push(*tr));
            let mut accepted = Vec::new();
            sys.tracks(t, &y, &mut check, &mut |tr| accepted.push(*tr));
            assert_eq!(fresh.len(), ws.tracks.len(), "{kind:?} {newton:?} t = {t}");
            for ((a, b), c) in fresh.iter().zip(&ws.tracks).zip(&accepted) {
                assert_eq!((a.contact, a.track), (b.contact, b.track));
                let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(1e-12);
                assert!(close(a.penetration, b.penetration), "{kind:?} t = {t}");
                assert!(close(a.normal_force, b.normal_force), "{kind:?} t = {t}");
                // The area is the accepted state's, computed again or kept while its plane
                // moved by less than PATCH_REUSE of the penetration (7 PATCH_REUSE of it).
                assert!(
                    (b.area - c.area).abs() <= 7.0 * PATCH_REUSE * c.area,
                    "{kind:?} {newton:?} t = {t}: area {} vs {}",
                    b.area,
                    c.area
                );
            }
            steps_in_contact += usize::from(!fresh.is_empty());
        }
        assert!(steps_in_contact > 10, "the cube must touch the floor");
        let contact_aware =
            newton == NewtonJacobian::ContactAware && kind != IntegratorKind::Dopri5;
        assert_eq!(contact_aware, from_iterate > 0, "{kind:?} {newton:?}");
    }
}

#[test]
fn the_next_steps_start_removes_the_iterates_lag_to_second_order() {
    // The contact-aware Newton's next step starts from `f(z_p) + J(z_p) Δz` instead of
    // evaluating f at the accepted `z = z_p + Δz`: the Jacobian term removes the first-order
    // part of the lag `f(z_p) − f(z)`, leaving its second-order part. Over a pressed, spinning,
    // sliding cube the accelerations (the rows that carry the contacts) left at the start must be
    // a small share of the iterate's lag: second order, the share scales with Δz, which lies
    // within Newton's tolerance (1 % asked; without the Jacobian term it is all of it).
    use crate::physics::body::BODY_STATE_LEN;
    use crate::physics::integrator::Integrator;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let case = super::case::load_case(&dir.join("rattle-box-c.toml")).expect("case");
    let settings = super::case::integrator_settings(&case).expect("settings");
    let (sys, mut y) = pressed_cube();
    let mut integ = Integrator::new(&sys, settings);
    let mut ws = sys.workspace();
    let mut check = sys.workspace();
    let mut fresh = vec![0.0; y.len()];
    let (mut t, mut left, mut lag, mut moved) = (0.0, 0.0, 0.0, 0);
    while t < 2e-4 {
        t = integ
            .advance(&sys, &mut ws, t, &mut y, 2e-4)
            .expect("advances");
        if integ.last_newton_update().is_none() {
            continue;
        }
        moved += 1;
        sys.derivative(t, &y, &mut fresh, &mut check);
        let (start, iterate) = integ.start_and_iterate_derivatives();
        for body in 0..y.len() / BODY_STATE_LEN {
            for i in body * BODY_STATE_LEN + 7..(body + 1) * BODY_STATE_LEN {
                left += (start[i] - fresh[i]).abs();
                lag += (iterate[i] - fresh[i]).abs();
            }
        }
    }
    eprintln!("{moved} steps from a moved iterate: left {left:.3e}, lag {lag:.3e}");
    assert!(moved > 10, "steps that start from a moved iterate: {moved}");
    assert!(lag > 0.0, "the iterates lag the accepted states");
    assert!(
        left <= 1e-2 * lag,
        "left {left:.3e} against the iterates' lag {lag:.3e} (summed accelerations, m/s², rad/s²)"
    );
}

/// Issue 29's case, past the submit-time bounds: rattle box C shaken at 1e308 g. Its base
/// motion is not finite, so its run must fail naming time, body and contact, not report
/// zero wear.
#[test]
fn a_run_with_a_non_finite_base_motion_fails_with_a_diagnostic() {
    use super::case::{build, run_options};
    use super::run::{run_model, ModelRunError};
    use crate::physics::simulate::SimError;
    let configs = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let mut case = crate::models::spec::tests::load("rattle-box-c.toml");
    case.simulation.settle_s = 0.01;
    case.simulation.duration_s = 0.02;
    case.simulation.record_interval_s = 1e-3;
    let mut table = case.excitation.table().clone();
    table["tones"][0]["amplitude_g"] = serde_json::json!(1e308);
    case.excitation = crate::models::spec::CaseExcitation::from_table(table).unwrap();
    let model = build(&case, &configs).unwrap();
    let options = run_options(&case).unwrap();
    let control = crate::physics::control::RunControl::silent();
    match run_model(&model, &options, &control) {
        Err(ModelRunError::Sim(SimError::Diverged {
            time_s,
            body,
            contact,
            reason,
            ..
        })) => {
            // The excitation starts after the settle; the failure is found within it.
            assert!(
                (0.0..=case.simulation.settle_s + case.simulation.duration_s).contains(&time_s),
                "{time_s}"
            );
            assert!(body == "cube" || body == "tube", "{body}");
            assert!(!contact.is_empty() && !reason.is_empty());
        }
        Err(other) => panic!("failed without the diagnostic: {other}"),
        Ok(report) => panic!(
            "succeeded with wear {:?} mg",
            report.bodies.iter().map(|b| b.mass_mg).collect::<Vec<_>>()
        ),
    }
}

#[test]
fn face_contact_defaults_per_model_and_a_case_that_names_it_keeps_it() {
    use crate::physics::contact::FaceContact;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let faces = |name: &str, set: Option<FaceContact>| -> Vec<FaceContact> {
        let mut case = super::case::load_case(&dir.join(format!("{name}.toml"))).expect("case");
        case.simulation.face_contact = set;
        let model = super::case::build(&case, &dir).expect("model");
        let built: Vec<FaceContact> = model
            .system
            .contacts
            .iter()
            .map(|c| c.face_contact)
            .collect();
        // What a curve's provenance records is what the builder used.
        let resolved = super::case::face_contact(&case).expect("resolved");
        assert!(
            built.iter().all(|f| Some(*f) == resolved),
            "{name}: built {built:?}, resolved {resolved:?}"
        );
        built
    };
    // Absent: the launcher integrates its faces exactly (its lattice is not converged), the
    // rattle box keeps the lattice (converged at 3 points per edge).
    let launcher = faces("launcher-design", None);
    assert_eq!(launcher.len(), 5);
    assert!(
        launcher.iter().all(|f| *f == FaceContact::Exact),
        "{launcher:?}"
    );
    let rattle = faces("rattle-box-c", None);
    assert!(!rattle.is_empty());
    assert!(
        rattle.iter().all(|f| *f == FaceContact::Lattice),
        "{rattle:?}"
    );
    // Named: kept, either way round.
    let named = faces("launcher-design", Some(FaceContact::Lattice));
    assert!(
        named.iter().all(|f| *f == FaceContact::Lattice),
        "{named:?}"
    );
    let named = faces("rattle-box-c", Some(FaceContact::Exact));
    assert!(named.iter().all(|f| *f == FaceContact::Exact), "{named:?}");
}
