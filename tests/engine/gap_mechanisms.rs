//! Wear mechanisms beyond sliding Archard (issue 26 item 1) through the whole simulator path:
//! the virtual rig injects a mechanism into real rattle-box windows (cases C and D, 0.25 s),
//! and the diagnosis recovers its magnitude within the interval it reports; the energy budget
//! of "where" names the coefficient that the measured wear needs, which for the injected
//! mechanism is the injected one (all of the wear above the nominal comes from it).

use railwear::gap::campaign::Campaign;
use railwear::gap::diagnose::{diagnose, DiagnoseOptions, Report, Verdict};
use railwear::gap::effects::Effect;
use railwear::gap::rig::{run, RigOptions};
use railwear::gap::window::WindowCache;
use railwear::pipeline::RunControl;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

/// A rig campaign on the small fixture (C and D, two increments of 1.5 h, one specimen each)
/// with `effect` injected, 2 % weighing noise, then its diagnosis over `effects`, both on the
/// same 0.25 s windows after 0.05 s.
fn inject_and_diagnose(effect: &str, effects: &[&str]) -> Report {
    let base = Campaign::from_toml_str(
        include_str!("../fixtures/small-campaign.toml"),
        Path::new("."),
    )
    .unwrap();
    let rig = RigOptions {
        effects: vec![Effect::parse(effect).unwrap()],
        noise_rel: 0.02,
        seed: 26,
        window_s: 0.25,
        settle_s: 0.05,
        ..RigOptions::default()
    };
    let cache = WindowCache::new();
    let (campaign, _) = run(&base, &configs(), &rig, &RunControl::silent()).unwrap();
    let mut o = DiagnoseOptions::default();
    o.emulator.window_s = 0.25;
    o.emulator.settle_s = 0.05;
    o.emulator.grid_points = 2;
    o.emulator.effects = Some(effects.iter().map(|e| e.to_string()).collect());
    let (report, _) = diagnose(
        &campaign,
        &configs(),
        &o,
        &RunControl::silent(),
        &cache,
        &|_, _| {},
    )
    .unwrap();
    report
}

/// The fitted magnitude's interval holds the truth, and the verdict names the effect.
fn assert_recovered(report: &Report, name: &str, truth: f64) {
    let best = report
        .best_effect
        .as_ref()
        .unwrap_or_else(|| panic!("no effect named: {:?} {}", report.verdict, report.summary));
    assert_eq!(best.name, name, "{}", report.summary);
    assert_ne!(report.verdict, Verdict::NoGap);
    let p = &best.parameters[0];
    let [lo, hi] = p.interval.expect("a fitted magnitude has an interval");
    assert!(
        lo <= truth && truth <= hi,
        "{name}: truth {truth} outside [{lo}, {hi}] (fitted {})",
        p.value
    );
}

/// A sweep can carry the recovered mechanism: the record holds the fitted k_E, whose
/// interval holds the truth; a dynamics effect or a not_explained verdict is refused, naming
/// `wear_law.diagnosis`.
fn assert_carried(report: &Report, truth: f64) {
    use railwear::gap::diagnose::carry::carried_wear_law;
    use railwear::wear::mechanism::WearMechanism;
    let id = uuid::Uuid::new_v4();
    let json = serde_json::to_value(report).unwrap();
    let carried = carried_wear_law(id, &json).unwrap();
    assert_eq!(carried.effect, "impact_wear");
    assert_eq!(carried.curve_name(), format!("diagnosis-{id}"));
    let best = report.best_effect.as_ref().unwrap();
    match carried.mechanism(1.32e9).unwrap() {
        WearMechanism::ImpactWear(m) => {
            assert_eq!(m.k_energy_m3_per_j, best.parameters[0].value);
            let [lo, hi] = best.parameters[0].interval.unwrap();
            assert!(lo <= truth && truth <= hi);
        }
        other => panic!("{other:?}"),
    }
    let mut dynamics = json.clone();
    dynamics["best_effect"]["name"] = "cross_axis".into();
    assert_eq!(
        carried_wear_law(id, &dynamics).unwrap_err().field,
        "wear_law.diagnosis"
    );
    let mut none = json;
    none["verdict"] = "not_explained".into();
    let e = carried_wear_law(id, &none).unwrap_err();
    assert!(e.rule.contains("not_explained"), "{}", e.rule);
}

/// A run carrying impact wear as its case's `wear.mechanism` adds exactly k_E times each
/// contact's IMPACT damping work to the law's wear (the accumulator's trapezoid on the same
/// accepted steps), and at k_E = 0 its wear is the plain run's, bit for bit.
#[test]
fn a_run_carrying_impact_wear_adds_k_e_times_the_damping_work() {
    use railwear::wear::mechanism::{ImpactWear, WearMechanism};
    let configs = configs();
    let text = std::fs::read_to_string(configs.join("rattle-box-c.toml")).unwrap();
    let mut case = railwear::models::spec::CaseSpec::from_toml_str(&text).unwrap();
    case.simulation.duration_s = 0.3;
    let run = |k: Option<f64>| {
        let mut c = case.clone();
        c.wear.mechanism = k.map(|k| {
            WearMechanism::ImpactWear(ImpactWear {
                k_energy_m3_per_j: k,
                min_normal_speed_m_s: 0.0,
            })
        });
        railwear::pipeline::run_case(&c, &configs, &RunControl::silent())
            .unwrap()
            .0
    };
    let plain = run(None);
    let zero = run(Some(0.0));
    let k_e = 1e-13;
    let with = run(Some(k_e));
    let contacts = |r: &railwear::models::run::RunReport| r.contacts.clone();
    let mut damping = 0.0;
    for ((p, z), w) in contacts(&plain)
        .iter()
        .zip(contacts(&zero).iter())
        .zip(contacts(&with).iter())
    {
        assert_eq!(p.wear.volume_m3.to_bits(), z.wear.volume_m3.to_bits());
        let added = w.wear.volume_m3 - p.wear.volume_m3;
        let expected = k_e * w.wear.damping_work_j;
        assert!(
            (added - expected).abs() <= 1e-9 * expected.max(1e-30),
            "{}: added {added} m³, k_E x damping work {expected} m³",
            p.name
        );
        assert!((w.wear.mechanism_volume_m3 - expected).abs() <= 1e-9 * expected.max(1e-30));
        damping += w.wear.damping_work_j;
    }
    assert!(damping > 0.0, "the rattle box dissipates by impact damping");
}

/// Impact wear at k_E = 2e-14 m³/J (about 40x the nominal wear on these windows): recovered,
/// and the budget's needed k_E for each test lies within 10 % of the truth (the 2 % noise,
/// and the nominal sliding wear the budget also charges to impact); the budget's energy
/// account closes.
#[test]
fn impact_wear_injected_by_the_rig_is_recovered() {
    let truth = 2e-14;
    let report = inject_and_diagnose(&format!("impact_wear={truth}"), &["impact_wear"]);
    assert_recovered(&report, "impact_wear", truth);
    assert_carried(&report, truth);
    let budget = &report.location.energy_budget;
    assert_eq!(budget.tests.len(), 2);
    for t in &budget.tests {
        assert!(t.contacts[0].damping_j > 0.0, "{}", t.test);
        let dissipated = t.contacts[0].damping_j + t.contacts[0].friction_j;
        // The budget closes the energy account: the drive's work leaves as the contact's
        // friction and damping work plus the change of the cube's mechanical energy (the
        // trapezoid of the powers over the accepted steps; measured 1e-4 of the drive).
        let residual = t.drive_j - dissipated - t.energy_change_j;
        assert!(
            residual.abs() <= 1e-3 * t.drive_j,
            "{}: drive {} J, dissipated {dissipated} J, change {} J",
            t.test,
            t.drive_j,
            t.energy_change_j
        );
        let needed = t
            .needed
            .iter()
            .find(|n| n.mechanism == "impact_wear")
            .and_then(|n| n.value)
            .unwrap();
        assert!(
            (needed / truth - 1.0).abs() < 0.1,
            "{}: needed {needed} vs {truth}",
            t.test
        );
    }
}

/// Coating breakthrough at k_bare = 2e-4 after 100 m of slip (inside the first increment):
/// recovered with the breakthrough distance the rig used.
#[test]
fn coating_breakthrough_injected_by_the_rig_is_recovered() {
    let truth = 2e-4;
    let report = inject_and_diagnose(
        &format!("coating_breakthrough={truth},breakthrough_slip_m=1000"),
        &["coating_breakthrough"],
    );
    assert_recovered(&report, "coating_breakthrough", truth);
}
