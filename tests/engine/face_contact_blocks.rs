//! The exact face contact's Jacobian summed once per track (`TrackMoments`) against the same
//! matrix summed node by node: an algebraic regrouping of one sum, so the two agree to
//! round-off on every entry, on the launcher (missile and latch both dynamic, spinning and
//! sliding) and on rattle box C.

use super::energy_passivity::random_missile_state;
use railwear::physics::contact::{EvaluationOutputs, FaceContact, GeometryCache};
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
    case.excitation = serde_json::json!({ "kind": "none" });
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
