//! The exact face contact's friction taken per part at the part's load centre
//! (`FrictionRule::PerPart`, a measurement of issue 27's cheaper friction): where every node
//! slips with the same velocity, tangent to every node's normal, it is the per-node law (the
//! same `μ(|s|) ŝ` at every node, so the force is `μ N ŝ` and its torque that force at the load
//! centre); anywhere it only dissipates.

use super::face_contact::{evaluate, lip_contact, random_pose, HALF};
use nalgebra::{Isometry3, Vector3};
use railwear::physics::contact::FrictionRule;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn friction_per_part_is_the_per_node_law_under_uniform_slip() {
    // A level head across the lip's edge (its bottom face's polygon and its strips beyond the
    // edge, whose normals lie in the x-y plane), sliding along the edge (z): every node's slip
    // is the head's velocity, the same vector and tangent to each node's normal.
    let per_node = lip_contact(true, true);
    let per_part = lip_contact(true, true).with_friction_rule(FrictionRule::PerPart);
    let mut rng = ChaCha8Rng::seed_from_u64(2811);
    let mut checked = 0;
    for _ in 0..40 {
        let w = rng.gen_range(1e-5..4e-4);
        let x = rng.gen_range(-0.03..0.015);
        // The bottom face's balls `w` deep (the head's half height is the inner half height
        // plus the roundover).
        let pose = Isometry3::translation(x, HALF[1] - w, 0.0);
        // Across the friction law's stiction and transition speeds (mm/s to tens of mm/s).
        let v = Vector3::new(0.0, 0.0, rng.gen_range(-0.03..0.03));
        let (_, f_node, t_node, tr_node) = evaluate(&per_node, &pose, v, Vector3::zeros());
        let (_, f_part, t_part, tr_part) = evaluate(&per_part, &pose, v, Vector3::zeros());
        if tr_node.is_empty() || f_node.y <= 0.0 {
            continue;
        }
        checked += 1;
        let scale = f_node.norm();
        assert!(
            (f_part - f_node).norm() <= 1e-12 * scale,
            "force {f_part:?} vs per node {f_node:?}"
        );
        assert!(
            (t_part - t_node).norm() <= 1e-12 * scale * HALF[2],
            "torque {t_part:?} vs per node {t_node:?}"
        );
        let power = |tr: &[railwear::physics::contact::TrackState]| {
            tr.iter().map(|t| t.friction_power).sum::<f64>()
        };
        let (p_node, p_part) = (power(&tr_node), power(&tr_part));
        assert!(
            (p_part - p_node).abs() <= 1e-12 * p_node.abs().max(1e-300),
            "friction power {p_part} vs per node {p_node}"
        );
    }
    assert!(checked >= 30, "{checked} pressed states");
}

#[test]
fn friction_per_part_only_dissipates() {
    // Tilted, turning heads across the lip's edge: the slip varies over each part, so the rule
    // differs from the per-node law, but each part's friction does the power −μ N |s_c| at
    // its load centre, never positive: the friction force's power at the body's velocity
    // field, −Σ F·v_rel(p_c), is at least zero and equals the tracks' friction power.
    let per_part = lip_contact(true, true).with_friction_rule(FrictionRule::PerPart);
    let frictionless = lip_contact(true, false);
    let mut rng = ChaCha8Rng::seed_from_u64(2812);
    let mut loaded = 0;
    for _ in 0..200 {
        let pose = random_pose(&mut rng, 4e-4);
        let (v, omega) =
            super::face_contact::random_motion(&mut rng, [0.02, 0.005, 0.02], [0.5, 0.5, 0.5]);
        let (_, f, t, tracks) = evaluate(&per_part, &pose, v, omega);
        let (_, f0, t0, _) = evaluate(&frictionless, &pose, v, omega);
        if tracks.is_empty() {
            continue;
        }
        loaded += 1;
        // The friction's wrench on the head (about its centre) and its power on the head's
        // rigid motion (the lip is fixed).
        let (ff, tf) = (f - f0, t - t0);
        let power = ff.dot(&v) + tf.dot(&omega);
        let dissipated: f64 = tracks.iter().map(|tr| tr.friction_power).sum();
        assert!(dissipated >= 0.0, "friction power {dissipated}");
        assert!(
            (power + dissipated).abs() <= 1e-9 * dissipated.max(1e-12),
            "friction's power on the head {power} vs −{dissipated}"
        );
    }
    assert!(loaded >= 100, "{loaded} loaded states");
}

#[test]
fn the_per_part_frictions_jacobian_equals_central_differences() {
    // The per-part rule's own Jacobian (`Contact::end_lump`): each node's ∂F/∂f_n takes the
    // part's −μ ŝ_c at its own lever, one more record at the load centre takes ∂F/∂s_c.
    // Left out: the load centre's own motion in the slip, [ω_rel]× δp_c, as the load shifts
    // within a part (δp_c = Σ δf_n (p − p_c) / N; the damping moves it with the normal
    // velocity). It vanishes at rest, so the pose columns at rest keep the per-node law's
    // bound (face_contact.rs, 1e-5). On the velocity columns of the cube spinning at
    // |ω| = 2.3 rad/s and sliding at |s| = 0.32 m/s, relative to the friction's own share μ of
    // the normal entries, it is about |ω| L / |s| = 0.09 (L = 12.7 mm, the cube's half
    // edge): within μ_d · 0.09 ≈ 1.5e-2 of the largest entry; bound 2e-2. The tangential
    // velocity columns (v_x, v_z), where the friction's slip derivative is the whole entry
    // and the normal loads do not move, must agree within 1e-5 of their own largest entry.
    let per_part = |moving: bool| {
        let (mut sys, y) = super::face_contact::pressed_cube(moving);
        for c in &mut sys.contacts {
            *c = c.clone().with_friction_rule(FrictionRule::PerPart);
        }
        (sys, y)
    };
    let (sys, y) = per_part(true);
    let n = sys.state_len();
    let (analytic, fd) = super::face_contact::jacobians(&sys, &y);
    super::face_contact::assert_columns_agree(&analytic, &fd, n, 7..13, 2e-2);
    super::face_contact::assert_each_column_agrees(&analytic, &fd, n, &[7, 9], 1e-5);
    let (sys, y) = per_part(false);
    let (analytic, fd) = super::face_contact::jacobians(&sys, &y);
    super::face_contact::assert_columns_agree(&analytic, &fd, n, 0..3, 1e-5);
    super::face_contact::assert_columns_agree(&analytic, &fd, n, 3..7, 1e-5);
}
