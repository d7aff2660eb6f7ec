//! Virtual rig (issue 14 item 4): deterministic per seed, blind output, a control agrees with a
//! plain simulation, an effect at zero magnitude gives the control bit for bit, and effects
//! move the simulated measurements the way their physics says. Windows are short (0.3-0.5 s
//! of excitation after 0.05 s settle): the rig scales a window to the 90 min increment.

use railwear::gap::campaign::Campaign;
use railwear::gap::rig::{self, RigOptions, Truth};
use railwear::pipeline::RunControl;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

/// Case C, one specimen, two 90 min increments, cube and tube weighed on a 0.1 µg scale (fine
/// enough that noise shows in the masses the model predicts, about 5 µg per increment).
const BASE: &str = r#"
format_version = 1
name = "small"
[[tests]]
id = "C"
config = "rattle-box-c"
increment_duration_s = 5400.0
scale_resolution_mg = 0.0001
components = ["cube", "tube"]
[[tests.specimens]]
id = "C-1"
increments = [{}, {}]
"#;

fn base() -> Campaign {
    Campaign::from_toml_str(BASE, Path::new(".")).unwrap()
}

fn run(effects: &[&str], seed: u64, noise: f64, window_s: f64) -> (Campaign, Truth) {
    let args: Vec<String> = effects.iter().map(|s| s.to_string()).collect();
    let (effects, hidden) = rig::parse_effects(&args).unwrap();
    let options = RigOptions {
        effects,
        hidden,
        noise_rel: noise,
        seed,
        window_s,
        settle_s: 0.05,
        accelerometer_rate_hz: Some(1000.0),
        sensor_noise_m_s2: 0.01,
        ..RigOptions::default()
    };
    rig::run(&base(), &configs(), &options, &RunControl::silent()).unwrap()
}

fn files(c: &Campaign) -> (String, Vec<(String, String)>) {
    c.to_manifest().unwrap()
}

fn mass(c: &Campaign, inc: usize, comp: &str) -> f64 {
    c.tests[0].specimens[0].increments[inc].mass_loss_mg[comp]
}

#[test]
fn same_seed_same_campaign_other_seed_differs_and_zero_effect_is_the_control() {
    let (a, ta) = run(&["none"], 7, 0.1, 0.3);
    let (b, tb) = run(&["none"], 7, 0.1, 0.3);
    assert_eq!(files(&a), files(&b));
    assert_eq!(ta, tb);
    let (c, _) = run(&["none"], 8, 0.1, 0.3);
    assert_ne!(files(&a).0, files(&c).0, "masses differ with the seed");
    assert_ne!(
        files(&a).1,
        files(&c).1,
        "sensor noise differs with the seed"
    );
    // Every effect at magnitude 0, together: the control's campaign bit for bit.
    let zero = [
        "wear_above_cutoff=0",
        "third_body=0",
        "clearance_growth=0",
        "friction_drift=0",
        "fixture_compliance=0",
        "cross_axis=0",
        "sharp_edges=0",
        "surface_oxide=0",
        "work_hardening=0",
    ];
    let (z, tz) = run(&zero, 7, 0.1, 0.3);
    assert_eq!(files(&z), files(&a));
    assert_eq!(tz.tests, ta.tests);
    assert_eq!(tz.effects.len(), zero.len());
    // The written campaign validates and reads back as written.
    let scratch = railwear_testkit::TempDir::new("gap-rig").expect("scratch dir");
    let dir = scratch.path().to_path_buf();
    a.write_dir(&dir).unwrap();
    let back = Campaign::load(&dir.join("campaign.toml")).unwrap();
    back.validate(&configs()).unwrap();
    assert_eq!(files(&back), files(&a));
}

#[test]
fn control_agrees_with_a_plain_simulation_within_the_noise() {
    let noise = 0.05;
    let (c, truth) = run(&["none"], 3, noise, 0.3);
    // The plain simulation: the test's case over the same window, wear from the run itself.
    let test = &base().tests[0];
    let mut case = test.case(0, &configs()).unwrap();
    case.simulation.duration_s = 0.3;
    case.simulation.settle_s = 0.05;
    case.simulation.record_interval_s = 0.3;
    let (report, _) =
        railwear::pipeline::run_case(&case, &configs(), &RunControl::silent()).unwrap();
    let scale = 5400.0 / report.window_s;
    for comp in ["cube", "tube"] {
        let plain = report
            .bodies
            .iter()
            .find(|b| b.name == comp)
            .unwrap()
            .mass_mg
            * scale;
        assert!(plain > 0.0);
        // The rig's model mass is the run's wear, re-integrated on the same steps.
        let model = truth.tests[0].model_mass_loss_mg[0][comp];
        assert!(
            (model - plain).abs() <= 1e-9 * plain,
            "{comp}: {model} vs {plain}"
        );
        // The measurement: within 4 sigma of the noise plus half a scale step.
        for inc in 0..2 {
            let m = mass(&c, inc, comp);
            let tol = 4.0 * noise * plain + 0.5 * test.scale_resolution_mg;
            assert!(
                (m - plain).abs() <= tol,
                "{comp} {inc}: {m} vs {plain} ± {tol}"
            );
        }
    }
}

#[test]
fn output_carries_no_word_of_the_effect() {
    let (c, truth) = run(&["work_hardening=0.5", "cross_axis=0.1"], 1, 0.0, 0.3);
    let (manifest, csvs) = files(&c);
    for word in ["work_hardening", "cross_axis", "hardening", "effect"] {
        assert!(!manifest.contains(word), "{word} in the manifest");
        assert!(csvs
            .iter()
            .all(|(n, t)| !n.contains(word) && !t.contains(word)));
    }
    let names: Vec<&str> = truth.effects.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["cross_axis", "work_hardening"]);
    assert!(truth.effects[0].in_library && !truth.effects[1].in_library);
}

fn mean_square(c: &Campaign, location: &str) -> [f64; 3] {
    let rec = c.tests[0].specimens[0]
        .accelerometers
        .iter()
        .find(|r| r.location.as_str() == location && r.increment == 1)
        .unwrap();
    rec.mean_square_m2_s4()
}

#[test]
fn cross_axis_excitation_adds_response_on_the_other_axes() {
    let (control, _) = run(&["none"], 1, 0.0, 0.5);
    let (cross, _) = run(&["cross_axis=0.2"], 1, 0.0, 0.5);
    // The input on y and z: 3 g tones at 20 Hz, mean square (3 g)²/2 = 433 (m/s²)² once ramped
    // in (3 cycles = 0.15 s of the 0.5 s window ramp up from zero).
    let g3 = 3.0 * 9.80665;
    let input = mean_square(&cross, "input");
    for k in [1, 2] {
        assert!(
            input[k] > 0.5 * g3 * g3 / 2.0 && input[k] < g3 * g3 / 2.0,
            "{input:?}"
        );
    }
    // The control's cube moves in the x-y plane of the drive only as noise (0.01 m/s² rms);
    // with cross-axis drive it bounces (3 g vertical lifts it off the floor) and slides along
    // the tube.
    let (c, x) = (
        mean_square(&control, "response"),
        mean_square(&cross, "response"),
    );
    for k in [1, 2] {
        assert!(c[k] < 1e-3, "control {c:?}");
        assert!(x[k] > 100.0, "cross {x:?}");
    }
}

#[test]
fn wear_law_effects_move_the_model_masses() {
    let (_, control) = run(&["none"], 1, 0.0, 0.3);
    let m0 = &control.tests[0].model_mass_loss_mg;
    // Third-body abrasion adds wear.
    let (_, sand) = run(&["third_body=1e-3"], 1, 0.0, 0.3);
    let m1 = &sand.tests[0].model_mass_loss_mg;
    assert!(m1[0]["cube"] > 1.1 * m0[0]["cube"], "{m1:?} vs {m0:?}");
    // Work hardening lowers the wear, more in the second increment (more slip behind it).
    let (_, hard) = run(&["work_hardening=0.5"], 1, 0.0, 0.3);
    let m2 = &hard.tests[0].model_mass_loss_mg;
    assert!(m2[0]["cube"] < m0[0]["cube"]);
    assert!(m2[1]["cube"] < m2[0]["cube"]);
    // The control's increments are the same simulation: equal.
    assert_eq!(m0[0]["cube"], m0[1]["cube"]);
    // Slip distance accumulates over the increments.
    let s = &control.tests[0].slip_distance_m;
    assert!(s[0] > 0.0 && (s[1] - 2.0 * s[0]).abs() <= 1e-9 * s[1]);
}

#[test]
fn each_accelerometer_reads_through_its_own_drawn_sensitivity() {
    let options = |calibration_rel| RigOptions {
        seed: 11,
        window_s: 0.3,
        settle_s: 0.05,
        accelerometer_rate_hz: Some(1000.0),
        calibration_rel,
        ..RigOptions::default()
    };
    let control = RunControl::silent();
    let (exact, t0) = rig::run(&base(), &configs(), &options(0.0), &control).unwrap();
    let (off, t1) = rig::run(&base(), &configs(), &options(0.05), &control).unwrap();
    assert_eq!(t0.accelerometer_sensitivity, vec![1.0; 6]);
    let g = &t1.accelerometer_sensitivity;
    assert_eq!(g.len(), 6);
    // Six draws of 1 + 0.05 z: distinct, and none beyond 5 sigma.
    assert!(
        g.iter().all(|x| (x - 1.0).abs() < 0.25 && *x != 1.0),
        "{g:?}"
    );
    // The masses do not see the accelerometers.
    assert_eq!(files(&exact).0, files(&off).0);
    // Every sample of a channel is the exact one times that channel's sensitivity, on every
    // increment (one sensor for the campaign).
    let (a, b) = (&exact.tests[0].specimens[0], &off.tests[0].specimens[0]);
    assert_eq!(a.accelerometers.len(), 4);
    for (ra, rb) in a.accelerometers.iter().zip(&b.accelerometers) {
        let offset = if ra.location == railwear::gap::accel::AccelLocation::Input {
            0
        } else {
            3
        };
        for (sa, sb) in ra.samples.iter().zip(&rb.samples) {
            assert_eq!(sa[0], sb[0]);
            for axis in 0..3 {
                let want = sa[1 + axis] * g[offset + axis];
                assert!((sb[1 + axis] - want).abs() <= 1e-12 * want.abs().max(1e-9));
            }
        }
    }
}
