//! The exact face contact's Jacobian summed once per track (`TrackMoments`) against the same
//! matrix summed node by node: an algebraic regrouping of one sum, so the two agree to
//! round-off on every entry, on the launcher (missile and latch both dynamic, spinning and
//! sliding) and on rattle box C.

use super::energy_passivity::random_missile_state;
use railwear::physics::contact::{EvaluationOutputs, FaceContact, GeometryCache, JacobianScope};
use railwear::physics::system::MultibodySystem;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn configs() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/configs"))
}

/// The contact Jacobian at `y` from the per-track moments and from the per-node derivatives
/// of the same evaluation, and the number of tracks summed.
fn both_jacobians(sys: &MultibodySystem, y: &[f64]) -> (Vec<f64>, Vec<f64>, usize) {
    let n = sys.state_len();
    let mut ws = sys.workspace();
    ws.linearize = true;
    let mut f = vec![0.0; n];
    sys.derivative(0.0, y, &mut f, &mut ws);
    assert!(ws.linearizations.is_empty(), "exact faces sum per track");
    let tracks = ws.linearization_moments.len();
    let mut by_track = vec![0.0; n * n];
    sys.contact_jacobian(y, &mut ws, &mut by_track);
    let mut per_node = Vec::new();
    for (ci, c) in sys.contacts.iter().enumerate() {
        c.evaluate_with(
            ci as u32,
            &ws.frames,
            None,
            &mut |_| {},
            &mut GeometryCache::default(),
            EvaluationOutputs {
                linearizations: Some(&mut per_node),
                ..Default::default()
            },
        );
    }
    assert!(per_node.len() > tracks, "several nodes per track");
    let mut nodes_ws = ws.clone();
    nodes_ws.linearizations = per_node;
    nodes_ws.linearization_moments.clear();
    let mut by_node = vec![0.0; n * n];
    sys.contact_jacobian(y, &mut nodes_ws, &mut by_node);
    (by_track, by_node, tracks)
}

/// Every column of `a` within `rel` of `b`'s largest entry in that column.
fn assert_round_off(a: &[f64], b: &[f64], n: usize, rel: f64) {
    let mut felt = 0;
    for j in 0..n {
        let col = |m: &[f64]| m[j * n..(j + 1) * n].to_vec();
        let (ca, cb) = (col(a), col(b));
        let scale = cb.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
        if scale > 0.0 {
            felt += 1;
        }
        for i in 0..n {
            assert!(
                (ca[i] - cb[i]).abs() <= rel * scale,
                "d f[{i}] / d y[{j}]: per track {:e}, per node {:e}",
                ca[i],
                cb[i]
            );
        }
    }
    assert!(felt >= 10, "the contacts must be felt: {felt} columns");
}

#[test]
fn the_exact_face_jacobian_per_track_is_the_sum_over_its_nodes() {
    let mut case =
        railwear::models::case::load_case(&configs().join("launcher-design.toml")).expect("case");
    case.excitation = railwear::models::spec::CaseExcitation::none();
    let lattice = railwear::models::case::build(&case, configs()).expect("model");
    let settings = railwear::models::case::integrator_settings(&case).expect("settings");
    let rest = railwear::validation::energy::energy_run(
        &lattice.system,
        &lattice.initial_state,
        settings,
        0.3,
    )
    .expect("settles")
    .state;
    case.simulation.face_contact = Some(FaceContact::Exact);
    let exact = railwear::models::case::build(&case, configs()).expect("model");
    let n = exact.system.state_len();
    let mut rng = ChaCha8Rng::seed_from_u64(2727);
    for _ in 0..5 {
        let y = random_missile_state(&rest, &mut rng);
        let (by_track, by_node, tracks) = both_jacobians(&exact.system, &y);
        assert!(tracks >= 4, "the shoes must press: {tracks} tracks");
        assert_round_off(&by_track, &by_node, n, 1e-11);
    }

    let (system, y) = super::face_contact::pressed_cube(true);
    let (by_track, by_node, _) = both_jacobians(&system, &y);
    assert_round_off(&by_track, &by_node, system.state_len(), 1e-11);
}

/// The contact Jacobian at `(t, y)` taken in `scope`, and the derivative evaluated with it.
fn jacobian_in(
    sys: &MultibodySystem,
    t: f64,
    y: &[f64],
    scope: JacobianScope,
) -> (Vec<f64>, Vec<f64>) {
    let n = sys.state_len();
    let mut ws = sys.workspace();
    ws.linearize = true;
    ws.jacobian_scope = scope;
    let mut f = vec![0.0; n];
    sys.derivative(t, y, &mut f, &mut ws);
    let mut jac = vec![0.0; n * n];
    sys.contact_jacobian(y, &mut ws, &mut jac);
    (jac, f)
}

/// The spectral radius of `(I − hd (J_free + J_newton))⁻¹ hd (J_exact − J_newton)`: the rate
/// at which a Newton iteration on `z − hd f(z) = rhs` with the matrix `newton` contracts
/// where the exact matrix would converge at once (all matrices column-major `n × n`).
fn newton_contraction(free: &[f64], newton: &[f64], exact: &[f64], n: usize, hd: f64) -> f64 {
    let entry = |m: &[f64], i: usize, j: usize| m[j * n + i];
    let a = nalgebra::DMatrix::from_fn(n, n, |i, j| {
        f64::from(u8::from(i == j)) - hd * (entry(free, i, j) + entry(newton, i, j))
    });
    let left_out =
        nalgebra::DMatrix::from_fn(n, n, |i, j| hd * (entry(exact, i, j) - entry(newton, i, j)));
    if left_out.iter().all(|v| *v == 0.0) {
        return 0.0;
    }
    let m = a.lu().solve(&left_out).expect("a regular Newton matrix");
    nalgebra::linalg::Schur::try_new(m, 1e-13, 100_000)
        .expect("the Schur form converges")
        .complex_eigenvalues()
        .iter()
        .map(|c| c.norm())
        .fold(0.0, f64::max)
}

/// The largest contraction the Newton matrix may cost an iteration (see the test).
const CONTRACTION_BOUND: f64 = 0.15;

#[test]
fn the_newton_matrix_leaves_out_only_derivatives_that_newton_does_not_need() {
    // Launcher-design at rest, then the missile shifted, turned and moving at random: the
    // shoes on the rail lips and the latch pressed at their settled depths. The side faces of
    // the latch's tooth and of the mid shoe's protrusion are slivers there (`SIDE_SHARE_MAX`);
    // the shoe heads, pressed about 0.47 mm, keep every node.
    let (model, _, rest) = super::face_contact::settled_exact_launcher(0.3);
    let sys = &model.system;
    let n = sys.state_len();
    let mut rng = ChaCha8Rng::seed_from_u64(2728);
    let mut left_out = 0;
    let mut worst: f64 = 0.0;
    for _ in 0..8 {
        let y = random_missile_state(&rest, &mut rng);
        let (exact, f_exact) = jacobian_in(sys, 0.0, &y, JacobianScope::Exact);
        let (newton, f_newton) = jacobian_in(sys, 0.0, &y, JacobianScope::NewtonMatrix);
        // The scope changes which derivatives are taken, never a force.
        assert_eq!(f_exact, f_newton, "the derivative is the same bit for bit");
        if exact != newton {
            left_out += 1;
        }
        // Steps of 1e-5 to 1e-3 s (TR-BDF2's h d = 0.29 h). Newton with the exact matrix
        // converges at once where the contacts are linear; with the Newton matrix the error
        // shrinks by this factor per iteration. The contact-aware Newton stops once
        // θ/(1 − θ) times its update is below 0.03 tolerance units (NEWTON_KAPPA) and gives up
        // at θ >= 0.99: at a contraction of 0.15 an update of a tolerance unit is one
        // iteration from the stopping test (0.18 × 0.15 < 0.03).
        let free = super::face_contact::fd_jacobian(sys, 0.0, &y, false);
        for hd in [3e-6, 3e-5, 3e-4] {
            let rho = newton_contraction(&free, &newton, &exact, n, hd);
            worst = worst.max(rho);
            assert!(rho <= CONTRACTION_BOUND, "h d {hd:e}: contraction {rho:.4}");
        }
    }
    // Measured 0.038-0.047 over these states: the latch's side faces carry about 2 % of its
    // load, and their lever arms at the piece's ends weigh its rotation.
    assert!(
        left_out >= 4,
        "the side faces must be left out: {left_out} of 8 states"
    );
    assert!(worst > 0.0);

    // launcher-loose in its excitation window: shoe heads rattling across the lips' edges,
    // tilted, hitting the walls and the roof, their strips beyond the lips' edges loaded
    // (their derivatives on 9 nodes, the force on 50). Measured 0.030-0.049 at h d up to 3e-5
    // and up to 0.099 at 3e-4, where the stiff limit `J_N⁻¹ (J − J_N)` is approached.
    use railwear::models::case::{build, load_case, run_options};
    use railwear::models::run::record_states;
    use railwear::pipeline::RunControl;
    let mut case = load_case(&configs().join("launcher-loose.toml")).expect("case");
    case.simulation.settle_s = 1.0;
    case.simulation.duration_s = 0.5;
    let loose = build(&case, configs()).expect("model");
    let options = run_options(&case).expect("options");
    let states = record_states(&loose, &options, &RunControl::silent(), 0.025).expect("runs");
    assert!(states.len() >= 19, "{} states", states.len());
    let sys = &loose.system;
    let n = sys.state_len();
    for (t, y) in &states {
        let (exact, f_exact) = jacobian_in(sys, *t, y, JacobianScope::Exact);
        let (newton, f_newton) = jacobian_in(sys, *t, y, JacobianScope::NewtonMatrix);
        assert_eq!(f_exact, f_newton, "the derivative is the same bit for bit");
        let free = super::face_contact::fd_jacobian(sys, *t, y, false);
        for hd in [3e-6, 3e-5, 3e-4] {
            let rho = newton_contraction(&free, &newton, &exact, n, hd);
            assert!(
                rho <= CONTRACTION_BOUND,
                "launcher-loose, h d {hd:e}: contraction {rho:.4}"
            );
        }
    }
}
