//! The next test, on the simulator: a campaign in which one test carries the effect (third-body
//! abrasion, which the default thresholds keep out of case A at 15 g, weighed finely only in
//! case C) is `partly_explained` and proposes a test that would carry it too; the rig runs that
//! test under the same hidden truth, the campaign appends it, and the diagnosis then names the
//! effect `explained`, with no next test left to propose.

use railwear::gap::campaign::{Campaign, CampaignTest};
use railwear::gap::diagnose::{diagnose, DiagnoseOptions, Report, Verdict};
use railwear::gap::rig::{run, RigOptions};
use railwear::gap::window::WindowCache;
use railwear::gap::Effect;
use railwear::pipeline::RunControl;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

/// Window and settle of the rig and of the diagnosis alike: the emulator then predicts the
/// rig's noise-free readings exactly, and the test is about the planning, not the emulator.
const WINDOW_S: f64 = 0.25;
const SETTLE_S: f64 = 0.05;

/// The effects the diagnosis considers (wear laws: no simulation beyond the nominal's).
const EFFECTS: [&str; 3] = ["third_body", "wear_above_cutoff", "impact_wear"];

/// The hidden truth.
fn truth() -> Effect {
    Effect::parse("third_body=0.0005").unwrap()
}

/// A skeleton of the loosest case and the two tightest, three specimens of two 8 h
/// increments each, cube and tube weighed: case C on a microbalance (1 µg), A and D on a
/// 0.05 mg scale that reads D's wear (about 0.015 mg) as 0 and A's as 0.05 mg, so that C alone
/// shows the abrasion.
fn skeleton() -> Campaign {
    let test = |id: &str, config: &str, resolution_mg: f64| {
        format!(
            r#"
[[tests]]
id = "{id}"
config = "{config}"
drive = {{ level_g = 15.0, frequency_hz = 20.0 }}
increment_duration_s = 28800.0
scale_resolution_mg = {resolution_mg}
components = ["cube", "tube"]
[[tests.specimens]]
id = "{id}-1"
increments = [{{}}, {{}}]
[[tests.specimens]]
id = "{id}-2"
increments = [{{}}, {{}}]
[[tests.specimens]]
id = "{id}-3"
increments = [{{}}, {{}}]
"#
        )
    };
    let text = format!(
        "format_version = 1\nname = \"next-test\"\n{}{}{}",
        test("A", "rattle-box-a", 0.05),
        test("C", "rattle-box-c", 0.001),
        test("D", "rattle-box-d", 0.05)
    );
    Campaign::from_toml_str(&text, Path::new(".")).unwrap()
}

fn rig(base: &Campaign, seed: u64, accelerometers: bool) -> Campaign {
    let options = RigOptions {
        effects: vec![truth()],
        noise_rel: 0.03,
        scatter_rel: 0.05,
        seed,
        window_s: WINDOW_S,
        settle_s: SETTLE_S,
        accelerometer_rate_hz: accelerometers.then_some(2000.0),
        sensor_noise_m_s2: 0.5,
        ..RigOptions::default()
    };
    run(base, &configs(), &options, &RunControl::silent())
        .unwrap()
        .0
}

fn diagnosis(campaign: &Campaign, cache: &WindowCache) -> Report {
    let mut o = DiagnoseOptions::default();
    o.emulator.window_s = WINDOW_S;
    o.emulator.settle_s = SETTLE_S;
    o.emulator.grid_points = 2;
    o.emulator.effects = Some(EFFECTS.iter().map(|s| s.to_string()).collect());
    diagnose(
        campaign,
        &configs(),
        &o,
        &RunControl::silent(),
        cache,
        &|_, _| {},
    )
    .unwrap()
    .0
}

#[test]
fn a_one_test_effect_gets_a_next_test_that_confirms_it() {
    let cache = WindowCache::new();
    let campaign = rig(&skeleton(), 7, false);
    let first = diagnosis(&campaign, &cache);
    // One test carries the effect: named, but only partly (confirmed within that test).
    assert_eq!(
        first.verdict,
        Verdict::PartlyExplained,
        "{}\n{:#?}",
        first.summary,
        first.ranking
    );
    assert_eq!(
        first.best_effect.as_ref().map(|b| b.name.as_str()),
        Some("third_body"),
        "{}",
        first.summary
    );
    let next = &first.next_tests;
    assert!(!next.is_empty(), "{}", first.summary);
    for t in next {
        // The leading candidate against the nominal model and the rivals.
        assert_eq!(t.separates[0], "third_body");
        assert!(t.separates.iter().any(|s| s == "none"), "{:?}", t.separates);
        assert_eq!(t.rivals.len() + 1, t.separates.len());
        // Decisive means more than ln 20 against every rival, and the smallest is the test's.
        let least = t
            .rivals
            .iter()
            .map(|r| r.expected_log_lr)
            .fold(f64::INFINITY, f64::min);
        assert!((t.separation_nats - least).abs() <= 1e-12 * least.abs().max(1.0));
        assert_eq!(t.decisive, least > 20f64.ln());
        // Abrasion only adds wear: its prediction is never below the nominal's.
        let nominal = t
            .predictions
            .iter()
            .find(|p| p.candidate == "none")
            .unwrap();
        for (a, b) in t.predictions[0].mass_mg.iter().zip(&nominal.mass_mg) {
            assert!(a >= b, "{a} < {b}");
        }
        // Hours are increments x length x repeats.
        let hours = t.increments as f64 * t.increment_duration_s / 3600.0 * t.repeats as f64;
        assert!((t.cost_h - hours).abs() < 1e-9);
        assert_eq!(t.test.specimens.len(), t.repeats);
        assert!(campaign.tests.iter().all(|c| c.id != t.test.id));
        // Weighed on the campaign's finest scale.
        assert_eq!(t.test.scale_resolution_mg, 0.001);
    }
    // Repeats of the tests the leader cannot predict held out come first, each the test as it
    // was run; the rest are chosen by their separation.
    let repeats = next.iter().take_while(|t| t.repeats_test.is_some()).count();
    assert!(next[repeats..].iter().all(|t| t.repeats_test.is_none()));
    for (t, id) in next[..repeats].iter().zip(&first.to_repeat) {
        assert_eq!(t.repeats_test.as_ref(), Some(id), "{t:#?}");
        let original = campaign.tests.iter().find(|c| &c.id == id).unwrap();
        assert_eq!(t.test.config, original.config);
        assert_eq!(t.test.drive, original.drive);
    }
    // The first proposal carries the effect: decisive against the nominal model.
    let proposed = &next[0];
    let against_nominal = proposed
        .rivals
        .iter()
        .find(|r| r.candidate == "none")
        .unwrap();
    assert!(against_nominal.decisive, "{proposed:#?}");

    // The rig runs the proposed test under the same truth; the campaign appends it.
    let mut extended = campaign.clone();
    let mut one = skeleton();
    one.tests = vec![proposed.test.clone()];
    one.validate(&configs()).unwrap();
    let run_test: CampaignTest = rig(&one, 8, proposed.accelerometers).tests.remove(0);
    extended.tests.push(run_test);
    extended.validate(&configs()).unwrap();
    let second = diagnosis(&extended, &cache);
    assert_eq!(
        second.verdict,
        Verdict::Explained,
        "{}\n{:#?}",
        second.summary,
        second.ranking
    );
    assert_eq!(
        second.best_effect.as_ref().map(|b| b.name.as_str()),
        Some("third_body")
    );
    // Explained, with nothing it cannot tell apart: no next test.
    if second.indistinguishable.is_empty() {
        assert!(second.next_tests.is_empty(), "{:#?}", second.next_tests);
    }
    let json = serde_json::to_value(&second).unwrap();
    assert!(json["next_tests"].is_array(), "always present");
}
