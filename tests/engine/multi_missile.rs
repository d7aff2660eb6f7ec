//! A launcher carrying several missiles (`[launcher] stations`, configs/launcher-m299-*.toml):
//! each missile has its own latch, springs and contacts; the rails share the launcher's one
//! prescribed motion, so the missiles are independent systems (physics::partition) and each is
//! integrated on its own. Checked against physics: translation invariance (a station is the
//! single rail moved; it must wear as the single rail does), the account of the merged run
//! closes, and stations whose missiles would overlap are refused.

use railwear::models::case::{build, load_case};
use railwear::models::spec::{CaseSpec, ModelSpecRef};
use railwear::physics::partition::independent_parts;
use railwear::pipeline::{run_case, RunControl};
use std::path::Path;

fn configs() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/configs"))
}

fn short(name: &str) -> CaseSpec {
    let mut case = load_case(&configs().join(format!("{name}.toml"))).expect("case loads");
    case.simulation.settle_s = 0.2;
    case.simulation.duration_s = 0.3;
    case.simulation.record_interval_s = 1e-3;
    case
}

#[test]
fn the_four_rail_launcher_splits_into_one_part_per_missile() {
    let case = short("launcher-m299-4");
    let model = build(&case, configs()).expect("builds");
    let sys = &model.system;
    assert_eq!(sys.bodies.len(), 12, "missile, latch and rail per station");
    assert_eq!(sys.contacts.len(), 20, "five contacts per station");
    let parts = independent_parts(sys);
    assert_eq!(parts.len(), 4, "one independent part per missile");
    for (s, part) in parts.iter().enumerate() {
        // Each part: its station's missile, latch and rail, and only its own contacts, which
        // carry the station's suffix.
        assert_eq!(part.bodies, vec![3 * s, 3 * s + 1, 3 * s + 2]);
        assert_eq!(part.contacts, (5 * s..5 * s + 5).collect::<Vec<_>>());
        for c in &part.contacts {
            let name = &sys.contacts[*c].name;
            assert_eq!(s == 0, !name.contains('#'), "contact {name} of station {s}");
        }
        // The part's state is the whole state's entries of its bodies.
        let y = part.state_from(sys, &model.initial_state);
        assert_eq!(y.len(), 26);
        assert_eq!(&y[..], &model.initial_state[26 * s..26 * (s + 1)]);
    }
    // The single rail is one part: the whole system.
    let single = build(&short("launcher-design"), configs()).expect("builds");
    assert_eq!(independent_parts(&single.system).len(), 1);
}

#[test]
fn each_missile_of_a_two_rail_launcher_wears_as_the_single_rail_does() {
    // The two stations are the single rail translated by ±0.2 m and driven by the same
    // translation: the same equations up to rounding of the coordinates. Their wear must be
    // the single rail's (to the rounding the impacts amplify over 0.5 s).
    let (one, _) = run_case(&short("launcher-design"), configs(), &RunControl::silent())
        .expect("single rail runs");
    let (two, two_out) = run_case(&short("launcher-m299-2"), configs(), &RunControl::silent())
        .expect("two rails run");
    assert_eq!(two.contacts.len(), 2 * one.contacts.len());
    for (i, c1) in one.contacts.iter().enumerate() {
        for station in 0..2 {
            let c2 = &two.contacts[5 * station + i];
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-3 * a.abs().max(b.abs()) + 1e-12;
            assert!(
                close(c1.mass_rate_mg_per_h, c2.mass_rate_mg_per_h),
                "{} station {station}: {} vs {} mg/h",
                c1.name,
                c2.mass_rate_mg_per_h,
                c1.mass_rate_mg_per_h
            );
            assert!(close(c1.mean_friction_power_w, c2.mean_friction_power_w));
        }
    }
    let rail = |r: &railwear::models::run::RunReport, name: &str| {
        r.bodies
            .iter()
            .find(|b| b.name == name)
            .map(|b| b.mass_rate_mg_per_h)
            .expect("rail body")
    };
    let single_rail = rail(&one, "rail");
    for name in ["rail", "rail#2"] {
        let r = rail(&two, name);
        assert!(
            (r - single_rail).abs() <= 1e-3 * single_rail,
            "{name}: {r} vs {single_rail} mg/h"
        );
    }
    // Every part did its own steps: the merged counters are the parts' sums.
    assert!(two.integrator.accepted >= 2 * one.integrator.accepted * 9 / 10);
    // The merged energy account closes like the single one.
    let e = two.energy.as_ref().expect("account kept");
    assert!(e.balanced, "residual {:e} J", e.residual_j);
    assert!(e.dissipated_j > 1.9 * one.energy.as_ref().expect("account").dissipated_j);
    // Track samples (moved to the outcome): both stations' contacts, in time order.
    assert!(
        two.tracks.is_empty(),
        "run_case moves the samples to the outcome"
    );
    assert!(two_out.tracks.iter().any(|t| t.contact >= 5));
    assert!(two_out.tracks.iter().any(|t| t.contact < 5));
    assert!(two_out
        .tracks
        .windows(2)
        .all(|w| w[0].time_s <= w[1].time_s));
}

#[test]
fn stations_whose_missiles_would_overlap_are_refused() {
    let text = std::fs::read_to_string(configs().join("launcher-m299-2.toml")).expect("config");
    let case = CaseSpec::from_toml_str(&text).expect("parses");
    let ModelSpecRef::Launcher(spec) = case.model_spec().expect("launcher") else {
        panic!("launcher-m299-2 is a launcher case");
    };
    assert_eq!(spec.stations.len(), 2);
    let close = text.replace(
        "stations = [[0.20, 0.0, 0.0], [-0.20, 0.0, 0.0]]",
        "stations = [[0.05, 0.0, 0.0], [-0.05, 0.0, 0.0]]",
    );
    let err = CaseSpec::from_toml_str(&close).expect_err("refused");
    assert!(
        err.to_string().contains("launcher.stations[1]"),
        "the error names the station: {err}"
    );
}
