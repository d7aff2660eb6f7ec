//! The exactly integrated face contact (issue 27, `face_contact = "exact"`): closed forms of a
//! uniformly pressed face, the elastic force as the exact gradient of the stored energy
//! (including the boundary force where a bounded face's edge cuts a face), the instantaneous
//! energy balance, a shoe sliding off a lip, the contact Jacobian against central
//! differences, and the launcher's pressure resultants against a 33-point lattice.
//! Every bound is fixed by physics (closed forms, conservation), not by the code's output.
//!
//! Over 700 lines: these tests and the fixtures the other face-contact files borrow (the head,
//! the lip, the pressed cube); the Jacobian blocks and the fixed-order rules already have their
//! own files.

use super::energy_passivity::random_missile_state;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use railwear::geometry::{
    ConvexShape, FaceExtent, FacePatch, HalfSpace, PlacedFace, QuadratureOrder,
};
use railwear::physics::body::BodyFrame;
use railwear::physics::contact::{Contact, FaceContact, TrackState};
use railwear::physics::friction::FrictionParams;
use railwear::physics::impact::ImpactParams;
use railwear::physics::system::MultibodySystem;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn configs() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/configs"))
}

/// Table 6.2's shoe-rail law: k 1000 N/mm², e 2, c 500 N·s/mm, d 0.01 mm.
pub(crate) fn table_6_2() -> ImpactParams {
    ImpactParams::from_adams_units(1000.0, 2.0, 500.0, 0.01)
}

/// A shoe head's size (half extents, m) and roundover (m).
pub(crate) const HALF: [f64; 3] = [0.019, 0.005, 0.04];
pub(crate) const ROUNDOVER: f64 = 5e-4;

fn head() -> ConvexShape {
    ConvexShape::rounded_box(Vector3::new(HALF[0], HALF[1], HALF[2]), ROUNDOVER).expect("head")
}

/// The plane y = 0, solid below, and its extent bounded at x = 0 (the solid for x < 0), open
/// elsewhere: a rail lip's top.
pub(crate) fn lip_plane() -> (HalfSpace, FaceExtent) {
    let plane = HalfSpace::new(Vector3::y(), 0.0).expect("plane");
    let extent = FaceExtent {
        origin: Point3::origin(),
        tangent: Vector3::x_axis(),
        s_range_m: (f64::NEG_INFINITY, 0.0),
        t_range_m: (f64::NEG_INFINITY, f64::INFINITY),
    };
    (plane, extent)
}

/// A lip top: plane y = 0 (solid below), real edge at x = 0 (the slot for x > 0), open
/// elsewhere; `bounded = false` gives the whole plane.
pub(crate) fn lip_contact(bounded: bool, friction: bool) -> Contact {
    let (plane, extent) = lip_plane();
    Contact::new(
        "head-lip",
        0,
        vec![(Isometry3::identity(), head())],
        1,
        vec![plane],
        table_6_2(),
        friction.then(FrictionParams::thesis_table_5_2),
    )
    .with_face_extents(vec![bounded.then_some(extent)])
    .with_face_contact(FaceContact::Exact)
}

fn frame(pose: &Isometry3<f64>, v: Vector3<f64>, omega: Vector3<f64>) -> BodyFrame {
    BodyFrame {
        position: pose.translation.vector,
        rotation: pose.rotation,
        velocity: v,
        angular_velocity: omega,
    }
}

fn ground() -> BodyFrame {
    frame(&Isometry3::identity(), Vector3::zeros(), Vector3::zeros())
}

/// Stored energy (J), force and torque about the head's centre on the head (N, N·m), and the
/// tracks, of `contact` with the head at `pose` moving with (v, ω).
pub(crate) fn evaluate(
    contact: &Contact,
    pose: &Isometry3<f64>,
    v: Vector3<f64>,
    omega: Vector3<f64>,
) -> (f64, Vector3<f64>, Vector3<f64>, Vec<TrackState>) {
    let frames = [frame(pose, v, omega), ground()];
    let mut wrenches = [(Vector3::zeros(), Vector3::zeros()); 2];
    let mut tracks = Vec::new();
    let energy = contact.evaluate(0, &frames, Some(&mut wrenches), &mut |t| tracks.push(*t));
    (energy, wrenches[0].0, wrenches[0].1, tracks)
}

/// The head resting level with its inner bottom face's balls `w` deep, centre at `x`.
fn level(x: f64, w: f64) -> Isometry3<f64> {
    let inner_y = HALF[1] - ROUNDOVER;
    Isometry3::translation(x, inner_y + ROUNDOVER - w, 0.0)
}

#[test]
fn a_uniformly_pressed_face_carries_k_w_e_times_its_pressed_share() {
    // The bottom face alone (FacePatch): every node at depth w, shares summing to the pressed
    // area over the face's area: 1 on a plane, (x0 + a)/(2a) when a bounded face's edge at
    // x0 cuts it.
    let impact = table_6_2();
    let order = QuadratureOrder::for_exponent(impact.exponent);
    let (a, b, r, w) = (0.0185, 0.0395, ROUNDOVER, 2e-4);
    let centre = Point3::new(0.0, r - w, 0.0);
    let plane = HalfSpace::new(Vector3::y(), 0.0).expect("plane");
    for (edge, expected_share) in [(None, 1.0), (Some(-0.005), (a - 0.005) / (2.0 * a))] {
        let extent = edge.map(|x0| FaceExtent {
            origin: Point3::new(x0, 0.0, 0.0),
            tangent: Vector3::x_axis(),
            s_range_m: (f64::NEG_INFINITY, 0.0),
            t_range_m: (f64::NEG_INFINITY, f64::INFINITY),
        });
        let face = PlacedFace::new(plane, extent.as_ref(), &Isometry3::identity());
        let patch =
            FacePatch::new(centre, Vector3::x() * a, Vector3::z() * b, r, &face).expect("pressed");
        let (mut share, mut force) = (0.0, 0.0);
        patch.for_each_node(order, &mut |x, beta| {
            share += beta;
            force += beta * impact.elastic_force(r - x.y);
        });
        let law = impact.elastic_force(w);
        assert!((share - expected_share).abs() < 1e-14, "share {share}");
        assert!(
            (force - expected_share * law).abs() < 1e-12 * law,
            "{force} vs {}",
            expected_share * law
        );
        assert!((patch.share() - expected_share).abs() < 1e-14);
    }

    // The whole box on a plane: the bottom face gives k w^e; each of the four side faces,
    // perpendicular to the plane, presses a sliver of its height H = 2 h_y (inner) whose
    // balls are w − η deep: ∫₀^w k (w−η)^e dη / H = k w^(e+1) / ((e+1) H). Total
    // k w^e (1 + 4 w / ((e+1) H)); no torque about the centre.
    let contact = lip_contact(false, false);
    let inner_height = 2.0 * (HALF[1] - ROUNDOVER);
    for w in [1e-6, 5e-5, 2e-4, 4e-4] {
        let (energy, force, torque, tracks) = evaluate(
            &contact,
            &level(0.003, w),
            Vector3::zeros(),
            Vector3::zeros(),
        );
        let e = impact.exponent;
        let k = impact.stiffness;
        let expected = k * w.powf(e) * (1.0 + 4.0 * w / ((e + 1.0) * inner_height));
        assert!(
            (force.y - expected).abs() < 1e-12 * expected,
            "w {w}: {} vs {expected}",
            force.y
        );
        assert!(force.x.abs() + force.z.abs() < 1e-12 * expected);
        assert!(torque.norm() < 1e-12 * expected * HALF[2]);
        // Stored energy: k w^(e+1)/(e+1) on the bottom, k w^(e+2)/((e+1)(e+2) H) per side.
        let stored = k * w.powf(e + 1.0) / (e + 1.0)
            + 4.0 * k * w.powf(e + 2.0) / ((e + 1.0) * (e + 2.0) * inner_height);
        assert!(
            (energy - stored).abs() < 1e-12 * stored,
            "{energy} vs {stored}"
        );
        // The track: normal force the sum, penetration the exact depth w.
        assert_eq!(tracks.len(), 1);
        assert!((tracks[0].normal_force - expected).abs() < 1e-12 * expected);
        assert!((tracks[0].penetration - w).abs() < 1e-18);
    }
}

/// Stored energy of the head at `pose` (no velocity).
pub(crate) fn stored(contact: &Contact, pose: &Isometry3<f64>) -> f64 {
    evaluate(contact, pose, Vector3::zeros(), Vector3::zeros()).0
}

/// Lever of the rotational central differences, m: a turn of `h / LEVER` moves the head's
/// faces by about `h`, and a torque residual is compared with the force's times it.
pub(crate) const LEVER: f64 = 0.05;

/// `∂U/∂x` and `∂U/∂θ` of the stored energy at `pose` by central differences: a translation
/// step `h` along each axis and a turn of `h / LEVER` about it.
pub(crate) fn energy_gradient(
    contact: &Contact,
    pose: &Isometry3<f64>,
    h: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let (mut along, mut about) = (Vector3::zeros(), Vector3::zeros());
    let angle = h / LEVER;
    for i in 0..3 {
        let moved = |s: f64| {
            Isometry3::from_parts(
                Translation3::from(pose.translation.vector + Vector3::ith(i, s * h)),
                pose.rotation,
            )
        };
        along[i] = (stored(contact, &moved(1.0)) - stored(contact, &moved(-1.0))) / (2.0 * h);
        let turn = |s: f64| {
            let r = UnitQuaternion::from_scaled_axis(Vector3::ith(i, s * angle));
            Isometry3::from_parts(pose.translation, r * pose.rotation)
        };
        about[i] = (stored(contact, &turn(1.0)) - stored(contact, &turn(-1.0))) / (2.0 * angle);
    }
    (along, about)
}

/// The power account of the head moving at `(v, omega)` from `pose`: the power its motion
/// takes from the contact `F·v + τ·ω`, the elastic `dU/dt` (central differences along the
/// motion over 1 ns) and the damping and friction power the tracks report.
pub(crate) fn power_account(
    contact: &Contact,
    pose: &Isometry3<f64>,
    (v, omega): (Vector3<f64>, Vector3<f64>),
    (force, torque, tracks): (Vector3<f64>, Vector3<f64>, &[TrackState]),
) -> PowerAccount {
    let dt = 1e-9;
    let moved = |s: f64| {
        Isometry3::from_parts(
            Translation3::from(pose.translation.vector + v * (s * dt)),
            UnitQuaternion::from_scaled_axis(omega * (s * dt)) * pose.rotation,
        )
    };
    PowerAccount {
        power: force.dot(&v) + torque.dot(&omega),
        du_dt: (stored(contact, &moved(1.0)) - stored(contact, &moved(-1.0))) / (2.0 * dt),
        damping: tracks.iter().map(|t| t.damping_power).sum(),
        friction: tracks.iter().map(|t| t.friction_power).sum(),
    }
}

/// What [`power_account`] measures, W.
pub(crate) struct PowerAccount {
    pub power: f64,
    pub du_dt: f64,
    pub damping: f64,
    pub friction: f64,
}

impl PowerAccount {
    /// `power + dU/dt + damping + friction` (zero for a passive contact) and the scale it is
    /// judged against (the sum of the terms' sizes).
    pub(crate) fn residual_and_scale(&self) -> (f64, f64) {
        (
            self.power + self.du_dt + self.damping + self.friction,
            self.power.abs() + self.du_dt.abs() + self.damping + self.friction,
        )
    }
}

/// Height of the head's centre above its lowest point when turned by `rot`: the inner box's
/// half extents projected on the vertical, plus the roundover.
pub(crate) fn lowest_point_depth(rot: &UnitQuaternion<f64>) -> f64 {
    let axis: Vector3<f64> = rot.inverse_transform_vector(&Vector3::y());
    (0..3)
        .map(|k| (HALF[k] - ROUNDOVER) * axis[k].abs())
        .sum::<f64>()
        + ROUNDOVER
}

/// A random pose of the head over the lip's edge, tilted a little, up to `max_w` deep.
pub(crate) fn random_pose(rng: &mut ChaCha8Rng, max_w: f64) -> Isometry3<f64> {
    let rot = UnitQuaternion::from_euler_angles(
        rng.gen_range(-0.01..0.01),
        rng.gen_range(-0.3..0.3),
        rng.gen_range(-0.01..0.01),
    );
    placed_over_lip(rng, rot, max_w)
}

/// The head turned by `rot`, placed over the lip's edge (x from -0.03 to 0.02 m, z within
/// 0.01 m) with its lowest point `0..max_w` deep.
pub(crate) fn placed_over_lip(
    rng: &mut ChaCha8Rng,
    rot: UnitQuaternion<f64>,
    max_w: f64,
) -> Isometry3<f64> {
    let lowest = lowest_point_depth(&rot);
    Isometry3::from_parts(
        Translation3::new(
            rng.gen_range(-0.03..0.02),
            lowest - rng.gen_range(0.0..max_w),
            rng.gen_range(-0.01..0.01),
        ),
        rot,
    )
}

/// Relative bound on `F + ∂U/∂x` and on the power balance: the pressed polygons are
/// integrated exactly; the strips beyond the lip's edge (at most a roundover wide) by Gauss
/// rules (5 nodes across the edge, graded along it) on a non-polynomial `w`, whose error is
/// what is left (measured worst 1.6e-4 of
/// the contact's power over these poses; docs/reference/models.md "Exact face contact").
const GRADIENT_TOLERANCE: f64 = 5e-4;

#[test]
fn the_elastic_force_is_minus_the_gradient_of_the_stored_energy_across_a_lip_edge() {
    // Without velocity the force is elastic: it must be −∂U/∂x and the torque −∂U/∂θ, by
    // central differences of the stored energy, on poses where the lip's edge cuts the head's
    // faces (the boundary force included) and where it does not.
    let contact = lip_contact(true, true);
    let mut rng = ChaCha8Rng::seed_from_u64(27);
    let mut cut = 0;
    let mut worst = 0.0_f64;
    for _ in 0..300 {
        let pose = random_pose(&mut rng, 4e-4);
        let (energy, force, torque, tracks) =
            evaluate(&contact, &pose, Vector3::zeros(), Vector3::zeros());
        let depth = tracks.iter().map(|t| t.penetration).fold(0.0, f64::max);
        if energy == 0.0 || depth < 1e-7 {
            continue;
        }
        if pose.translation.x.abs() < 0.018 {
            cut += 1;
        }
        let scale = force.norm();
        // Central differences: truncation (h/w)², round-off ε w / h.
        let h = (1e-3 * depth).min(1e-8);
        let (along, about) = energy_gradient(&contact, &pose, h);
        for i in 0..3 {
            worst = worst.max((force[i] + along[i]).abs() / scale);
            assert!(
                (force[i] + along[i]).abs() <= GRADIENT_TOLERANCE * scale,
                "force {i}: {} vs −∂U = {} at {pose:?}",
                force[i],
                -along[i]
            );
            worst = worst.max((torque[i] + about[i]).abs() / (scale * LEVER));
            assert!(
                (torque[i] + about[i]).abs() <= GRADIENT_TOLERANCE * scale * LEVER,
                "torque {i}: {} vs −∂U = {} at {pose:?}",
                torque[i],
                -about[i]
            );
        }
    }
    eprintln!("worst |F + ∂U| / |F|: {worst:e}");
    assert!(cut > 100, "the lip's edge must cut the head: {cut} poses");
}

#[test]
fn damping_and_friction_only_dissipate_node_by_node() {
    // With velocities: the power the contact takes from the head's motion is −dU/dt (the
    // elastic part, dU/dt by central differences along the motion) minus the damping and
    // friction the tracks report, each >= 0.
    let contact = lip_contact(true, true);
    let mut rng = ChaCha8Rng::seed_from_u64(2027);
    let mut loaded = 0;
    for _ in 0..300 {
        let pose = random_pose(&mut rng, 3e-4);
        let (v, omega) = random_motion(&mut rng, [0.05, 0.01, 0.05], [0.5, 2.0, 0.5]);
        let (_, force, torque, tracks) = evaluate(&contact, &pose, v, omega);
        if tracks.is_empty() {
            continue;
        }
        loaded += 1;
        let account = power_account(&contact, &pose, (v, omega), (force, torque, &tracks));
        let PowerAccount {
            power,
            du_dt,
            damping,
            friction,
        } = account;
        assert!(damping >= 0.0 && friction >= 0.0);
        let (residual, scale) = account.residual_and_scale();
        assert!(
            residual.abs() <= GRADIENT_TOLERANCE * scale,
            "power {power} dU/dt {du_dt} damping {damping} friction {friction}"
        );
    }
    assert!(loaded > 150, "{loaded} loaded states");
}

#[test]
fn a_head_sliding_off_a_lip_unloads_continuously_and_its_work_is_the_energy_drop() {
    // Level at w = 0.3 mm, slid along x from fully over the lip to fully over the slot: the
    // normal force falls continuously from the whole face's law to zero (no step larger than
    // the share one step uncovers), and the work of the force along the path equals minus
    // the change of the stored energy (trapezoid rule on a fine path).
    let contact = lip_contact(true, false);
    let w = 3e-4;
    let steps = 4000;
    let (x0, x1) = (-0.025, 0.025);
    let mut work = 0.0;
    let mut prev: Option<(f64, f64)> = None;
    let (e_start, ..) = evaluate(&contact, &level(x0, w), Vector3::zeros(), Vector3::zeros());
    let mut e_end = 0.0;
    let full = table_6_2().elastic_force(w);
    for i in 0..=steps {
        let x = x0 + (x1 - x0) * i as f64 / steps as f64;
        let (e, force, _, _) = evaluate(&contact, &level(x, w), Vector3::zeros(), Vector3::zeros());
        if let Some((fx_prev, fy_prev)) = prev {
            work += 0.5 * (fx_prev + force.x) * (x1 - x0) / steps as f64;
            let dx = (x1 - x0) / steps as f64;
            // One step uncovers dx / (2 a) of the face (a the inner half width) plus slivers.
            // A side face's sliver (about w / (3 H) of the law) unloads over the roundover r
            // as it crosses the edge: far below the 1 % step of a sliver cut at once.
            let per_step = full * dx * (1.0 / (2.0 * (HALF[0] - ROUNDOVER)) + 0.05 / ROUNDOVER);
            assert!(
                (force.y - fy_prev).abs() <= per_step,
                "jump at x = {x}: {} of the law",
                (force.y - fy_prev).abs() / full
            );
            assert!(
                force.y <= fy_prev + 1e-12 * full,
                "loads while sliding off at {x}"
            );
        }
        prev = Some((force.x, force.y));
        e_end = e;
    }
    assert_eq!(e_end, 0.0);
    assert!(
        (work + (e_end - e_start)).abs() <= GRADIENT_TOLERANCE * e_start,
        "work {work} vs energy drop {}",
        e_start - e_end
    );
}

/// Rattle box C with the cube tilted, pressed into the floor, spinning and sliding, in the
/// exact face contact (as the lattice's Jacobian test in `models::system_tests`).
pub(crate) fn pressed_cube(moving: bool) -> (MultibodySystem, Vec<f64>) {
    let mut case =
        railwear::models::case::load_case(&configs().join("rattle-box-c.toml")).expect("case");
    case.simulation.face_contact = Some(FaceContact::Exact);
    let model = railwear::models::case::build(&case, configs()).expect("model");
    let mut y = model.initial_state.clone();
    y[1] -= 3e-5;
    let q = UnitQuaternion::from_euler_angles(2e-3, 1e-3, -4e-3).into_inner();
    y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
    if moving {
        y[7..13].copy_from_slice(&[0.3, -0.05, 0.1, 2.0, -1.0, 0.5]);
    }
    (model.system, y)
}

/// Central differences of the derivative at `(t, y)`, with or without the contacts.
pub(crate) fn fd_jacobian(
    sys: &MultibodySystem,
    t: f64,
    y: &[f64],
    with_contacts: bool,
) -> Vec<f64> {
    let n = sys.state_len();
    let mut ws = sys.workspace();
    ws.skip_contacts = !with_contacts;
    let (mut f0, mut f1) = (vec![0.0; n], vec![0.0; n]);
    let mut jac = vec![0.0; n * n];
    for j in 0..n {
        let delta = 1e-7 * y[j].abs().max(1e-3);
        let mut yp = y.to_vec();
        yp[j] += delta;
        sys.derivative(t, &yp, &mut f1, &mut ws);
        yp[j] = y[j] - delta;
        sys.derivative(t, &yp, &mut f0, &mut ws);
        for i in 0..n {
            jac[j * n + i] = (f1[i] - f0[i]) / (2.0 * delta);
        }
    }
    jac
}

/// The analytic contact Jacobian and the contact part of the central-difference one.
pub(crate) fn jacobians(sys: &MultibodySystem, y: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = sys.state_len();
    let mut ws = sys.workspace();
    ws.linearize = true;
    let mut f = vec![0.0; n];
    sys.derivative(0.0, y, &mut f, &mut ws);
    assert!(!ws.linearization_moments.is_empty());
    let mut analytic = vec![0.0; n * n];
    sys.contact_jacobian(y, &mut ws, &mut analytic);
    let full = fd_jacobian(sys, 0.0, y, true);
    let free = fd_jacobian(sys, 0.0, y, false);
    let contact = full.iter().zip(&free).map(|(a, b)| a - b).collect();
    (analytic, contact)
}

pub(crate) fn assert_columns_agree(
    analytic: &[f64],
    fd: &[f64],
    n: usize,
    cols: std::ops::Range<usize>,
    tol: f64,
) {
    let scale = cols
        .clone()
        .flat_map(|j| (7..13).map(move |i| fd[j * n + i].abs()))
        .fold(0.0_f64, f64::max);
    assert!(scale > 1e3, "columns {cols:?} must feel the contact");
    for j in cols {
        for i in 7..13 {
            let err = (fd[j * n + i] - analytic[j * n + i]).abs();
            assert!(
                err <= tol * scale,
                "d f[{i}] / d y[{j}]: finite differences {:e}, analytic {:e}",
                fd[j * n + i],
                analytic[j * n + i]
            );
        }
    }
}

/// A random rigid motion of the head: each component of its velocity uniform in
/// `±v_max[i]` m/s, then each of its angular velocity in `±omega_max[i]` rad/s (in that order
/// of draws, so a seed gives the same motions wherever it is used).
pub(crate) fn random_motion(
    rng: &mut ChaCha8Rng,
    v_max: [f64; 3],
    omega_max: [f64; 3],
) -> (Vector3<f64>, Vector3<f64>) {
    let mut draw = |max: [f64; 3]| {
        Vector3::new(
            rng.gen_range(-max[0]..max[0]),
            rng.gen_range(-max[1]..max[1]),
            rng.gen_range(-max[2]..max[2]),
        )
    };
    let v = draw(v_max);
    let omega = draw(omega_max);
    (v, omega)
}

/// Each of the `cols` columns of the body's rows (7..13) agrees with central differences
/// within `rel` of that column's own largest entry, and feels the contact (some entry is not
/// zero): for columns whose entries are all the friction's (the tangential velocities), where
/// the normal entries give no scale.
pub(crate) fn assert_each_column_agrees(
    analytic: &[f64],
    fd: &[f64],
    n: usize,
    cols: &[usize],
    rel: f64,
) {
    for &j in cols {
        let scale = (7..13).map(|i| fd[j * n + i].abs()).fold(0.0_f64, f64::max);
        assert!(scale > 0.0, "column {j} must feel the friction");
        for i in 7..13 {
            let err = (fd[j * n + i] - analytic[j * n + i]).abs();
            assert!(
                err <= rel * scale,
                "d f[{i}] / d y[{j}]: central {:e}, analytic {:e}",
                fd[j * n + i],
                analytic[j * n + i]
            );
        }
    }
}

#[test]
fn the_exact_face_jacobian_equals_central_differences() {
    // Velocity columns (cube spinning and sliding): damping and friction at fixed geometry,
    // node by node: exact. Pose columns at rest: the elastic force, whose densities are
    // integrated exactly and vanish on the pressed polygon's moving side (w = 0), so moving
    // nodes add nothing: exact but for the rotation columns' second-order terms, as for the
    // lattice (`models::system_tests`). Not covered, and left out of the Newton matrix: the
    // pose derivatives of damping and friction through the nodes' motion (their densities
    // are not polynomial), which the lattice does not have.
    let (sys, y) = pressed_cube(true);
    let n = sys.state_len();
    let (analytic, fd) = jacobians(&sys, &y);
    assert_columns_agree(&analytic, &fd, n, 7..13, 1e-6);
    let (sys, y) = pressed_cube(false);
    let (analytic, fd) = jacobians(&sys, &y);
    assert_columns_agree(&analytic, &fd, n, 0..3, 1e-5);
    assert_columns_agree(&analytic, &fd, n, 3..7, 1e-5);
}

/// Sum of the contact forces and torques (about each body's centre) on body 0 (the missile)
/// of `sys` at `y`, and the tracks.
fn missile_resultant(
    sys: &MultibodySystem,
    y: &[f64],
) -> (Vector3<f64>, Vector3<f64>, Vec<TrackState>) {
    let mut ws = sys.workspace();
    let mut tracks = Vec::new();
    sys.tracks(0.0, y, &mut ws, &mut |t| tracks.push(*t));
    let frames = ws.frames.clone();
    let mut wrenches = vec![(Vector3::zeros(), Vector3::zeros()); frames.len()];
    for (ci, c) in sys.contacts.iter().enumerate() {
        c.evaluate(ci as u32, &frames, Some(&mut wrenches), &mut |_| {});
    }
    (wrenches[0].0, wrenches[0].1, tracks)
}

#[test]
fn the_lattice_converges_to_the_exact_face_contact_on_the_launcher() {
    // launcher-design without excitation, settled for 1 s from its assembly state (lattice,
    // 33 points per edge): the contact force and torque on the missile of the lattice at
    // 9, 17 and 33 points per edge approach the exact face contact's, each refinement closer.
    // The lattice is the exact contact's discretisation (docs/reference/models.md "Exact face
    // contact"); what it resolves last are the side faces' slivers, 0.47 mm deep here against
    // a lattice row spacing of 0.27 mm at 33 points.
    let mut case =
        railwear::models::case::load_case(&configs().join("launcher-design.toml")).expect("case");
    case.excitation = railwear::models::spec::CaseExcitation::none();
    let model_at = |n: usize, face: FaceContact| {
        let mut case = case.clone();
        case.simulation.contact_points_per_edge = n;
        case.simulation.face_contact = Some(face);
        railwear::models::case::build(&case, configs()).expect("model")
    };
    let fine = model_at(33, FaceContact::Lattice);
    let settings = railwear::models::case::integrator_settings(&case).expect("settings");
    let y =
        railwear::validation::energy::energy_run(&fine.system, &fine.initial_state, settings, 1.0)
            .expect("settles")
            .state;
    let (f_e, t_e, tracks_e) = missile_resultant(&model_at(33, FaceContact::Exact).system, &y);
    assert!(
        f_e.norm() > 100.0,
        "the missile must rest on its shoes: {f_e:?}"
    );
    let mut previous = f64::INFINITY;
    for n in [9, 17, 33] {
        let (f_l, t_l, tracks_l) = missile_resultant(&model_at(n, FaceContact::Lattice).system, &y);
        let gap = (f_e - f_l).norm() / f_e.norm();
        eprintln!(
            "lattice {n}: F {f_l:?} τ {t_l:?}, |ΔF|/|F| {gap:.4}, |Δτ|/|τ| {:.4}",
            (t_e - t_l).norm() / t_e.norm()
        );
        for tl in &tracks_l {
            if let Some(te) = tracks_e
                .iter()
                .find(|t| t.contact == tl.contact && t.track == tl.track)
            {
                eprintln!(
                    "  contact {} track {}: N {:.3} (exact {:.3})",
                    tl.contact, tl.track, tl.normal_force, te.normal_force
                );
            }
        }
        assert!(gap < previous, "lattice {n}: {gap} after {previous}");
        previous = gap;
    }
    eprintln!("exact: F {f_e:?} τ {t_e:?}");
}

/// launcher-design without excitation in the exact face contact, its integrator settings, and
/// its state after `settle_s` at rest.
pub(crate) fn settled_exact_launcher(
    settle_s: f64,
) -> (
    railwear::models::run::BuiltModel,
    railwear::physics::integrator::IntegratorSettings,
    Vec<f64>,
) {
    let mut case =
        railwear::models::case::load_case(&configs().join("launcher-design.toml")).expect("case");
    case.excitation = railwear::models::spec::CaseExcitation::none();
    case.simulation.face_contact = Some(FaceContact::Exact);
    let model = railwear::models::case::build(&case, configs()).expect("model");
    let settings = railwear::models::case::integrator_settings(&case).expect("settings");
    let rest = railwear::validation::energy::energy_run(
        &model.system,
        &model.initial_state,
        settings,
        settle_s,
    )
    .expect("settles")
    .state;
    (model, settings, rest)
}

#[test]
fn random_missile_states_never_gain_energy_with_the_exact_face_contact() {
    // As the lattice's test in `energy_passivity`: launcher-design without excitation, in the
    // exact face contact, settled, then 20 random missile states (shifted within the
    // clearances, turned, moving) run for 10 ms: the mechanical energy never rises above its
    // running minimum by more than PASSIVITY_TOLERANCE of what was available, and the energy
    // account closes within BALANCE_TOLERANCE of the dissipated work (SPEC §2).
    use railwear::validation::energy::{energy_run, BALANCE_TOLERANCE, PASSIVITY_TOLERANCE};
    let (model, settings, rest) = settled_exact_launcher(1.0);
    let sys = &model.system;
    let mut ws = sys.workspace();
    let rest_energy = sys.energy(0.0, &rest, &mut ws).total();
    let mut rng = ChaCha8Rng::seed_from_u64(127);
    for _ in 0..20 {
        let y = random_missile_state(&rest, &mut rng);
        let available = sys.energy(0.0, &y, &mut ws).total() - rest_energy;
        let run = energy_run(sys, &y, settings, 0.01).expect("runs");
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
}

/// The continuum the exact face contact integrates, by an independent brute-force rule: on
/// each of the six faces of the head's inner box an `m × m` midpoint grid, each cell a ball of
/// the roundover radius carrying `1/m²` of the face law (`dA / A`), with its own `w`, `ẇ` and
/// the per-point law `max(0, k w^e + c STEP(w) ẇ)` against the plane `y = 0`. Frictionless.
/// Returns the force and the torque about the head's centre (N, N·m), and the gross load
/// `Σ (k w^e + c STEP(w) |ẇ|)` (N): the density's magnitude the quadrature errors scale with,
/// however much of it the clamp cancels.
fn continuum_reference(
    impact: &ImpactParams,
    pose: &Isometry3<f64>,
    v: Vector3<f64>,
    omega: Vector3<f64>,
    m: usize,
) -> (Vector3<f64>, Vector3<f64>, f64) {
    let (mut force, mut torque, mut gross) = (Vector3::zeros(), Vector3::zeros(), 0.0);
    continuum_cells(pose, v, omega, m, &mut |c| {
        let f = Vector3::y() * (c.share * impact.force(c.w, c.wdot));
        gross += c.share * impact.force(c.w, c.wdot.abs());
        force += f;
        torque += c.lever.cross(&f);
    });
    (force, torque, gross)
}

/// The gross load `Σ (k w^e + c STEP(w) |ẇ|)` (N) of the head at `pose` moving with
/// `(v, ω)` on the plane `y = 0` (Table 6.2's law), on `m × m` midpoint cells per face: the
/// magnitude the face laws' quadrature errors scale with ([`continuum_reference`]).
pub(crate) fn continuum_gross(
    pose: &Isometry3<f64>,
    v: Vector3<f64>,
    omega: Vector3<f64>,
    m: usize,
) -> f64 {
    let impact = table_6_2();
    let mut gross = 0.0;
    continuum_cells(pose, v, omega, m, &mut |c| {
        gross += c.share * impact.force(c.w, c.wdot.abs());
    });
    gross
}

/// One pressed cell of the continuum: its share of the face law (`1/m²`), its depth `w` and
/// closing rate `ẇ` against the plane `y = 0`, and its lever from the head's centre.
pub struct ContinuumCell {
    pub share: f64,
    pub w: f64,
    pub wdot: f64,
    pub lever: Vector3<f64>,
}

/// Visits the pressed cells (`w > 0`) of an `m × m` midpoint grid on each of the six faces of
/// the head's inner box at `pose`, moving with `(v, ω)`: each cell a ball of the roundover
/// radius against the plane `y = 0`.
pub fn continuum_cells(
    pose: &Isometry3<f64>,
    v: Vector3<f64>,
    omega: Vector3<f64>,
    m: usize,
    visit: &mut dyn FnMut(ContinuumCell),
) {
    let normal = Vector3::y();
    let centre = pose.translation.vector;
    let rot = pose.rotation.to_rotation_matrix();
    let inner = Vector3::new(HALF[0], HALF[1], HALF[2]).map(|h| h - ROUNDOVER);
    let share = 1.0 / (m * m) as f64;
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let axis = |a: usize| rot.matrix().column(a).into_owned() * inner[a];
        for sign in [1.0, -1.0] {
            let face_centre = centre + axis(k) * sign;
            for a in 0..m {
                let u = -1.0 + (2.0 * a as f64 + 1.0) / m as f64;
                for b in 0..m {
                    let s = -1.0 + (2.0 * b as f64 + 1.0) / m as f64;
                    let x = face_centre + axis(i) * u + axis(j) * s;
                    let w = ROUNDOVER - x.y;
                    if w <= 0.0 {
                        continue;
                    }
                    let lever = x - normal * ROUNDOVER - centre;
                    let wdot = -normal.dot(&(v + omega.cross(&lever)));
                    visit(ContinuumCell {
                        share,
                        w,
                        wdot,
                        lever,
                    });
                }
            }
        }
    }
}

#[test]
fn the_exact_face_contact_is_the_continuum_integral_at_impact_states() {
    // The loose launcher's impacts (docs/journal/performance.md, eleventh pass) press a shoe head a
    // few hundredths of a millimetre into a face while it closes on one side and separates on
    // the other: the damping term c STEP(w) ẇ dominates the law, the STEP ramps over the
    // band w < d = 0.01 mm, and the force clamps to zero where the face separates. None of
    // that is a polynomial, so a rule exact for k w^e alone misses it (by 2-5 % of a wall's
    // force at those states). The exact contact cuts each pressed polygon where the law
    // changes form (w = d, ẇ = 0) and must reproduce the continuum integral: force and
    // torque within 2e-3 of the gross load G = ∫ (k w^e + c STEP |ẇ|) (the magnitude the
    // quadrature errors scale with, however much the clamp cancels) of an independent
    // midpoint rule per face, 800² and 1600² cells
    // extrapolated (its own error O(h²): the side faces' slivers, 0.05-0.2 mm high, get
    // 5-35 cells of 6 µm).
    let contact = lip_contact(false, false);
    let impact = table_6_2();
    let mut rng = ChaCha8Rng::seed_from_u64(1127);
    let (mut separating, mut loaded) = (0, 0);
    for _ in 0..8 {
        let rot = UnitQuaternion::from_euler_angles(
            rng.gen_range(-0.01..0.01),
            rng.gen_range(-0.5..0.5),
            rng.gen_range(-0.004..0.004),
        );
        let lowest = lowest_point_depth(&rot);
        let pose = Isometry3::from_parts(
            Translation3::new(0.0, lowest - rng.gen_range(5e-5..2e-4), 0.0),
            rot,
        );
        // Closing at the centre, turning fast enough that part of the face separates.
        let v = Vector3::new(0.0, -rng.gen_range(0.0..0.01), 0.0);
        let omega = Vector3::new(rng.gen_range(-2.0..2.0), 0.0, rng.gen_range(-2.0..2.0));
        let (_, force, torque, tracks) = evaluate(&contact, &pose, v, omega);
        assert_eq!(tracks.len(), 1);
        // Midpoint rules on 800² and 1600² cells per face, extrapolated (error O(h²)).
        let (f1, t1, _) = continuum_reference(&impact, &pose, v, omega, 800);
        let (f2, t2, gross) = continuum_reference(&impact, &pose, v, omega, 1600);
        let (f_ref, t_ref) = ((f2 * 4.0 - f1) / 3.0, (t2 * 4.0 - t1) / 3.0);
        if f_ref.y < 1.0 {
            // Wholly separating: the force clamps to zero everywhere.
            assert!(force.norm() <= 1e-9 * f1.norm().max(1.0), "{force:?}");
            continue;
        }
        loaded += 1;
        if (0..2).any(|s| {
            let corner = Vector3::new(HALF[0], 0.0, HALF[2] * (2.0 * s as f64 - 1.0));
            v.y + omega.cross(&(pose.rotation * corner)).y > 0.0
        }) {
            separating += 1;
        }
        let scale = gross;
        eprintln!(
            "exact {force:?} reference {f_ref:?} gross {gross:.4e}: |ΔF|/G {:.2e}, |Δτ|/(G L) {:.2e}",
            (force - f_ref).norm() / scale,
            (torque - t_ref).norm() / (scale * HALF[2])
        );
        assert!(
            (force - f_ref).norm() <= 2e-3 * scale,
            "force {force:?} vs continuum {f_ref:?}"
        );
        assert!(
            (torque - t_ref).norm() <= 2e-3 * scale * HALF[2],
            "torque {torque:?} vs continuum {t_ref:?}"
        );
    }
    assert!(loaded >= 4, "{loaded} loaded states");
    assert!(
        separating >= 2,
        "states must separate in part: {separating}"
    );
}

/// Sum over the states of `|F_lattice − F_exact|` and of `|F_exact|` (force on body a, N) per
/// shoe-rail contact of the launcher, the lattice with `n` points per edge.
fn lattice_force_gaps(
    exact: &MultibodySystem,
    lattice: &MultibodySystem,
    states: &[(f64, Vec<f64>)],
    shoes: &[usize],
) -> Vec<(f64, f64)> {
    let mut sums = vec![(0.0, 0.0); shoes.len()];
    for (t, y) in states {
        let forces = |sys: &MultibodySystem| {
            let mut ws = sys.workspace();
            sys.tracks(*t, y, &mut ws, &mut |_| {});
            shoes
                .iter()
                .map(|&ci| {
                    let c = &sys.contacts[ci];
                    let mut wrenches = vec![(Vector3::zeros(), Vector3::zeros()); ws.frames.len()];
                    c.evaluate(ci as u32, &ws.frames, Some(&mut wrenches), &mut |_| {});
                    wrenches[c.body_a].0
                })
                .collect::<Vec<_>>()
        };
        let (fe, fl) = (forces(exact), forces(lattice));
        for (k, s) in sums.iter_mut().enumerate() {
            s.0 += (fl[k] - fe[k]).norm();
            s.1 += fe[k].norm();
        }
    }
    sums
}

#[test]
fn at_loose_launcher_states_the_lattice_converges_to_the_exact_face_contact_at_first_order() {
    // launcher-loose run with the 5-point lattice; 20 states of its excitation window (shoe
    // heads rattling across the lips' edges, tilted, hitting the walls and the roof). At each,
    // the shoe-rail contacts' forces with the lattice at 33, 65 and 129 points per edge
    // against the exact face contact. The lattice is a trapezoid rule of the same continuum
    // (docs/reference/models.md "Exact face contact") whose errors are first order in its spacing
    // h = 1/(n − 1) of a box edge: each of a pressed face's 4 edge rows lacks the half weight
    // its side face's rule gives it (1/(2(n − 1)) of the law each: 2/(n − 1)), and each lip
    // edge across a head of width 2a over a lip overlap b cuts a column at most h a / b of
    // the face (a/b <= 2 for the launcher's heads: 2/(n − 1) for two lip edges). The side
    // faces' slivers, w high on a side of inner height H = 9 mm, carry up to w/H of the law
    // each (the damping does not taper with depth); the lattice resolves them once its rows
    // H/(n − 1) are closer than w, so an unresolved sliver has w < H/(n − 1) and misses at
    // most 4/(n − 1) for four sides. That sum, 8/(n − 1), is not a bound, though: a head
    // tilted into an impact presses its face along one edge over a band narrower than the
    // rows along its 80 mm length (0.63 mm at 129 points), which the lattice resolves only
    // once its spacing is below the band's width. At such states (2-4 of the 20 here) the gap
    // stays at 35-60 % of the force from 33 to 65 points and falls only at 129 (measured:
    // 153 of 605 N and 149 of 644 N at 129 points), so the summed gap is pre-asymptotic: at
    // 129 points it measured 7.4 % and 4.4 % on one sample of states, and at most 6.25 % on
    // the sample of an earlier step sequence.
    // What the test holds is the convergence: the summed gap falls at each refinement, and
    // over the fourfold one from 33 to 129 points to at most half (first order: a quarter;
    // measured 0.31-0.33). A 33-point lattice is therefore not within 0.5 % of the exact
    // contact here (issue 27, item 3).
    use railwear::models::case::{build, load_case, run_options};
    use railwear::models::run::record_states;
    use railwear::pipeline::RunControl;
    let mut case = load_case(&configs().join("launcher-loose.toml")).expect("case");
    case.simulation.settle_s = 1.0;
    case.simulation.duration_s = 0.5;
    case.simulation.face_contact = Some(FaceContact::Lattice);
    let recorder = build(&case, configs()).expect("model");
    let options = run_options(&case).expect("options");
    let states = record_states(&recorder, &options, &RunControl::silent(), 0.025).expect("runs");
    assert!(states.len() >= 19, "{} states", states.len());
    case.simulation.face_contact = Some(FaceContact::Exact);
    let exact = build(&case, configs()).expect("exact");
    let lattice_at = |n: usize| {
        let mut case = case.clone();
        case.simulation.face_contact = Some(FaceContact::Lattice);
        let mut model = build(&case, configs()).expect("lattice");
        for c in &mut model.system.contacts {
            *c = c.clone().with_points_per_edge(n);
        }
        model.system
    };
    let shoes: Vec<usize> = exact
        .system
        .contacts
        .iter()
        .enumerate()
        .filter(|(_, c)| c.name.ends_with("shoe-rail"))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(shoes.len(), 2);
    let gaps: Vec<Vec<f64>> = [33, 65, 129]
        .iter()
        .map(|&n| {
            let gaps: Vec<f64> = lattice_force_gaps(&exact.system, &lattice_at(n), &states, &shoes)
                .iter()
                .map(|(gap, total)| {
                    assert!(*total > 0.0, "the shoes must be loaded");
                    gap / total
                })
                .collect();
            eprintln!("lattice {n}: Σ|ΔF| / Σ|F| per shoe {gaps:?}");
            gaps
        })
        .collect();
    for (k, ((&g33, &g65), &g129)) in gaps[0].iter().zip(&gaps[1]).zip(&gaps[2]).enumerate() {
        assert!(g65 < g33 && g129 < g65, "shoe {k}: {g33} {g65} {g129}");
        assert!(
            g129 <= 0.5 * g33,
            "shoe {k}: {g129} at 129 points is more than half of {g33} at 33"
        );
    }
}
