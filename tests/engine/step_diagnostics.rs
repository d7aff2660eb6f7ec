//! The integrator's step diagnostics (issue 5, "where the time goes"): every rejection and
//! every error test is counted exactly once, and a body that cannot rotate never has its
//! steps limited by rotation.

use nalgebra::{Isometry3, Vector3};
use railwear::physics::body::write_state;
use railwear::physics::impact::ImpactParams;
use railwear::physics::integrator::{Integrator, IntegratorKind, IntegratorSettings, Tolerances};
use railwear::validation::sphere_on_floor;

/// A 10 mm sphere dropped at 0.5 m/s onto the floor with the thesis' Table 5.2 contact, 0.2 s.
fn run(kind: IntegratorKind, diagnose: bool) -> Integrator {
    let (sys, _) = sphere_on_floor(0.01, ImpactParams::thesis_table_5_2(), 0.0);
    let mut y = vec![0.0; sys.state_len()];
    // Released 1 mm above contact, falling straight down: no torque can arise.
    write_state(
        &mut y,
        0,
        &Isometry3::translation(0.0, 0.011, 0.0),
        Vector3::new(0.0, -0.5, 0.0),
        Vector3::zeros(),
    );
    let settings = IntegratorSettings {
        kind,
        tolerances: Tolerances::default(),
        initial_step_s: 1e-6,
        max_step_s: 1e-3,
        min_step_s: 1e-16,
        ..IntegratorSettings::default()
    };
    let mut integ = Integrator::new(&sys, settings);
    integ.diagnose = diagnose;
    let mut ws = sys.workspace();
    ws.keep_tracks = true;
    let mut t = 0.0;
    while t < 0.2 {
        t = integ
            .advance(&sys, &mut ws, t, &mut y, 0.2)
            .expect("advances");
    }
    integ
}

#[test]
fn every_rejection_and_error_test_is_counted_once() {
    for kind in [IntegratorKind::Trbdf2, IntegratorKind::Sdirk2] {
        let integ = run(kind, true);
        let (s, d) = (integ.stats, integ.diagnostics);
        assert!(s.accepted > 50, "{kind:?}: the drop takes steps: {s:?}");
        let rejections: u64 = d.rejections_by_event.iter().flatten().sum();
        assert_eq!(rejections, s.rejected, "{kind:?}: {d:?} vs {s:?}");
        let newton: u64 = d.rejections_by_event[0].iter().sum();
        assert_eq!(newton, s.newton_failures, "{kind:?}");
        // Every attempt whose Newton solve converged reached the error test.
        let tested: u64 = d.limiting_kind.iter().flatten().sum();
        assert_eq!(
            tested,
            s.accepted + s.rejected - s.newton_failures,
            "{kind:?}"
        );
    }
}

#[test]
fn a_straight_drop_is_never_limited_by_rotation() {
    let d = run(IntegratorKind::Trbdf2, true).diagnostics;
    let by_kind = |k: usize| d.limiting_kind.iter().map(|row| row[k]).sum::<u64>();
    assert_eq!(by_kind(1), 0, "quaternion entries limited a step: {d:?}");
    assert_eq!(
        by_kind(3),
        0,
        "angular velocity entries limited a step: {d:?}"
    );
    assert!(by_kind(0) + by_kind(2) > 0);
}

#[test]
fn diagnostics_are_off_by_default_and_change_no_step() {
    let off = run(IntegratorKind::Trbdf2, false);
    let on = run(IntegratorKind::Trbdf2, true);
    assert_eq!(off.diagnostics, Default::default());
    assert_eq!(off.stats, on.stats);
}
