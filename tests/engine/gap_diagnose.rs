//! Gap diagnosis (issue 15), the method on a model with a known answer: a hand-built
//! emulator whose effects change the predictions in known, different patterns (uniform per
//! test, growing over increments, lifting the off-axis response), measurements drawn from one
//! of them with known scatter. The diagnosis must report no_gap for the control, name the true
//! effect with an interval that holds the true magnitude, and refuse (not_explained) a pattern
//! no effect can make. Secondary parameters (a cross-axis phase) are fitted over variant tables
//! and reported with an interval; an effect fitted at its bound is `partly_explained`; a pair
//! never scores worse held out than its better member. The simulator path is in
//! `gap_diagnose_simulated.rs`.

use railwear::gap::accel::AccelLocation;
use railwear::gap::campaign::{Campaign, Increment, Specimen};
use railwear::gap::diagnose::emulator::{
    Bands, EffectTable, Emulator, EmulatorOptions, JointPoint, Prediction, TestPredictions,
};
use railwear::gap::diagnose::measured::MeasuredValue;
use railwear::gap::diagnose::{diagnose_with, DiagnoseOptions, Verdict};
use railwear::gap::effects;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use std::collections::BTreeMap;

const TESTS: usize = 5;
const INCREMENTS: usize = 3;
/// Nominal mass per increment of each test, mg.
const NOMINAL_MG: [f64; TESTS] = [1.0, 0.6, 0.35, 0.2, 0.1];
/// How strongly third-body abrasion acts on each test (its work at pressure and slip).
const ABRASION_SHARE: [f64; TESTS] = [1.0, 0.9, 0.6, 0.3, 0.1];
/// How strongly cross-axis drive acts on each test's wear.
const CROSS_SHARE: [f64; TESTS] = [0.1, 0.3, 0.6, 1.0, 1.5];
const DRIVE_MS: f64 = 1.0e4;

/// The truth of the hand-built model: prediction of test `t`, increment `k` with relative
/// magnitudes (share of each effect's bound) of third-body, clearance growth and cross-axis.
fn truth(t: usize, k: usize, third: f64, growth: f64, cross: f64) -> Prediction {
    let m = NOMINAL_MG[t]
        * (1.0 + 3.0 * third * ABRASION_SHARE[t])
        * (1.0 + 2.0 * growth * (k as f64 + 0.5) / INCREMENTS as f64)
        * (1.0 + 1.5 * cross * CROSS_SHARE[t]);
    Prediction {
        mass_mg: BTreeMap::from([("cube".to_string(), m)]),
        input_ms: [DRIVE_MS, DRIVE_MS * cross * cross, DRIVE_MS * cross * cross],
        response_ms: [
            0.5 * DRIVE_MS,
            0.01 * DRIVE_MS + 0.4 * DRIVE_MS * cross * cross,
            0.01 * DRIVE_MS + 0.4 * DRIVE_MS * cross * cross,
        ],
    }
}

fn table(name: &str, which: usize, points: usize) -> EffectTable {
    let info = effects::info(name).unwrap();
    let max = info.parameters[0].max;
    let magnitudes: Vec<f64> = (0..points)
        .map(|i| max * i as f64 / (points - 1) as f64)
        .collect();
    let predictions = magnitudes
        .iter()
        .map(|m| {
            let f = m / max;
            let mut r = [0.0; 3];
            r[which] = f;
            (0..TESTS)
                .map(|t| {
                    (0..INCREMENTS)
                        .map(|k| truth(t, k, r[0], r[1], r[2]))
                        .collect()
                })
                .collect()
        })
        .collect();
    EffectTable {
        info,
        magnitudes,
        predictions,
        simulated: which != 0,
        parameters: BTreeMap::new(),
    }
}

fn emulator() -> Emulator {
    let nominal: TestPredictions = (0..TESTS)
        .map(|t| {
            (0..INCREMENTS)
                .map(|k| truth(t, k, 0.0, 0.0, 0.0))
                .collect()
        })
        .collect();
    Emulator {
        halving: nominal.clone(),
        friction_step: nominal.clone(),
        initial_state: nominal.clone(),
        bands: vec![
            vec![
                Bands {
                    pressure: vec![1.0, 0.0, 0.0, 0.0],
                    slip: vec![0.0, 0.0, 1.0, 0.0],
                    work: Default::default(),
                };
                INCREMENTS
            ];
            TESTS
        ],
        response_records: vec![(1000.0, Vec::new()); TESTS],
        halving_response_records: vec![(1000.0, Vec::new()); TESTS],
        nominal,
        effects: vec![
            table("third_body", 0, 41),
            table("clearance_growth", 1, 41),
            table("cross_axis", 2, 41),
        ],
        pairs: Vec::new(),
        joints: Vec::new(),
        measured: Vec::new(),
        simulations: 0,
        options: EmulatorOptions::default(),
    }
}

/// A campaign whose three specimens per test read `f(t, k)` with 5 % scatter and a
/// 1 µg scale; accelerometer mean squares carried as a 1 s record at 1 kHz whose samples
/// have exactly that mean square (a square wave of the right amplitude).
fn campaign(f: impl Fn(usize, usize) -> Prediction, seed: u64) -> Campaign {
    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    let mut normal = move || {
        let u1: f64 = 1.0 - rng.gen::<f64>();
        let u2: f64 = rng.gen::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let mut tests = Vec::new();
    for t in 0..TESTS {
        let mut specimens = Vec::new();
        for s in 0..3 {
            let mut increments = Vec::new();
            let mut accelerometers = Vec::new();
            for k in 0..INCREMENTS {
                let p = f(t, k);
                let m = p.mass_mg["cube"] * (1.0 + 0.05 * normal());
                increments.push(Increment {
                    mass_loss_mg: BTreeMap::from([("cube".into(), (m * 1000.0).round() / 1000.0)]),
                });
                for (location, ms) in [("input", p.input_ms), ("response", p.response_ms)] {
                    let samples: Vec<[f64; 4]> = (0..1000)
                        .map(|i| {
                            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                            [
                                i as f64 / 1000.0,
                                sign * ms[0].sqrt(),
                                sign * ms[1].sqrt(),
                                sign * ms[2].sqrt(),
                            ]
                        })
                        .collect();
                    accelerometers.push(
                        serde_json::from_value(serde_json::json!({
                            "increment": k + 1,
                            "location": location,
                            "sample_rate_hz": 1000.0,
                            "sensor_noise_m_s2": 0.0,
                            "samples": samples,
                        }))
                        .unwrap(),
                    );
                }
            }
            specimens.push(Specimen {
                id: format!("T{t}-{s}"),
                increments,
                accelerometers,
            });
        }
        tests.push(
            serde_json::from_value(serde_json::json!({
                "id": format!("T{t}"),
                "config": "rattle-box-c",
                "increment_duration_s": 5400.0,
                "scale_resolution_mg": 0.001,
                "components": ["cube"],
                "specimens": specimens,
            }))
            .unwrap(),
        );
    }
    Campaign {
        format_version: 1,
        name: format!("synthetic-{seed}"),
        description: String::new(),
        source: None,
        tests,
    }
}

fn options() -> DiagnoseOptions {
    DiagnoseOptions {
        k_rel_uncertainty: 0.0,
        bootstrap_rounds: 200,
        ..DiagnoseOptions::default()
    }
}

#[test]
fn controls_report_no_gap() {
    let em = emulator();
    for seed in 0..5 {
        let c = campaign(|t, k| truth(t, k, 0.0, 0.0, 0.0), seed);
        let r = diagnose_with(&c, &em, &options()).unwrap();
        assert_eq!(r.verdict, Verdict::NoGap, "seed {seed}: {}", r.summary);
        // 5 % scatter of each specimen, estimated from the repeats.
        let s = r.noise.mass_repeatability_rel;
        assert!((0.025..0.09).contains(&s), "repeatability {s}");
    }
}

#[test]
fn the_true_effect_is_named_with_its_magnitude() {
    let em = emulator();
    let cases = [
        ("third_body", 0usize, 0.4),
        ("clearance_growth", 1, 0.5),
        ("cross_axis", 2, 0.3),
    ];
    for (name, which, share) in cases {
        let c = campaign(
            |t, k| {
                let mut r = [0.0; 3];
                r[which] = share;
                truth(t, k, r[0], r[1], r[2])
            },
            7,
        );
        let r = diagnose_with(&c, &em, &options()).unwrap();
        assert_eq!(r.verdict, Verdict::Explained, "{name}: {}", r.summary);
        let best = r.best_effect.as_ref().unwrap();
        assert_eq!(best.name, name, "{name}: ranking {:?}", r.ranking);
        let p = &best.parameters[0];
        let true_m = share * effects::info(name).unwrap().parameters[0].max;
        let [lo, hi] = p.interval.unwrap();
        assert!(
            lo <= true_m && true_m <= hi,
            "{name}: {true_m} outside [{lo}, {hi}]"
        );
        assert!(p.bounds[0] <= lo && hi <= p.bounds[1]);
        // The held-out error falls to the noise (about 1) from well above it.
        assert!(best.held_out_error_before > 3.0, "{name}: {best:?}");
        assert!(best.held_out_error_after < 1.6, "{name}: {best:?}");
        assert!(best.shrink > 0.5 && best.shrink_interval[0] <= best.shrink);
        // Where: the groups that miss are flagged.
        assert!(r.location.any_flagged());
        // Held-out predictions of every measured mass: with the effect fitted on the other
        // tests the masses' error (in the measurement's uncertainty about the nominal) is at
        // most half the nominal's, the shrink the issue asks of a found effect; the nominal
        // misses by far more than the noise. (Cross-axis drive acts on the accelerations.)
        let masses = &r.held_out_predictions;
        assert!(!masses.is_empty());
        assert!(masses.iter().all(|m| m.effect == name));
        let rms = |f: &dyn Fn(&railwear::gap::diagnose::HeldOutPrediction) -> f64| {
            (masses.iter().map(|m| f(m).powi(2)).sum::<f64>() / masses.len() as f64).sqrt()
        };
        let with = rms(&|m| (m.measured_mg - m.with_effect_mg) / m.uncertainty_mg);
        let nominal = rms(&|m| (m.measured_mg - m.nominal_mg) / m.uncertainty_mg);
        if name != "cross_axis" {
            assert!(
                with < 0.5 * nominal && nominal > 3.0,
                "{name}: {with} vs {nominal}"
            );
        }
    }
}

/// `c` with every response y sample scaled by `gain` (an accelerometer whose sensitivity is
/// off by `gain - 1`, the same sensor on every test).
fn miscalibrated(mut c: Campaign, gain: f64) -> Campaign {
    for t in &mut c.tests {
        for s in &mut t.specimens {
            for r in &mut s.accelerometers {
                if r.location == AccelLocation::Response {
                    for x in &mut r.samples {
                        x[2] *= gain;
                    }
                }
            }
        }
    }
    c
}

#[test]
fn a_sensor_calibration_error_is_not_a_gap() {
    let em = emulator();
    // A response y sensitivity 4 % high (twice the 2 % calibration uncertainty): every
    // response y mean square reads 8.2 % above the model, on every test and increment. One
    // scale shared by the channel explains it at two prior sigmas, which is no gap.
    for seed in 0..3 {
        let c = miscalibrated(campaign(|t, k| truth(t, k, 0.0, 0.0, 0.0), seed), 1.04);
        let r = diagnose_with(&c, &em, &options()).unwrap();
        assert_eq!(r.verdict, Verdict::NoGap, "seed {seed}: {}", r.summary);
        // Read as independent errors on each mean square, the same data is a gap: the
        // structure, not a wider uncertainty, is what keeps the diagnosis quiet.
        let independent = DiagnoseOptions {
            accelerometer_calibration_rel: 0.0,
            ..options()
        };
        let r = diagnose_with(&c, &em, &independent).unwrap();
        assert_ne!(r.verdict, Verdict::NoGap, "seed {seed}: {}", r.summary);
    }
    // The same 8 % on one test only is a change between tests, not a sensor: the channel's
    // shared scale cannot take it, and the test is flagged.
    let mut c = campaign(|t, k| truth(t, k, 0.0, 0.0, 0.0), 0);
    let one = miscalibrated(
        Campaign {
            tests: vec![c.tests[0].clone()],
            ..c.clone()
        },
        1.04,
    );
    c.tests[0] = one.tests[0].clone();
    let r = diagnose_with(&c, &em, &options()).unwrap();
    assert_ne!(r.verdict, Verdict::NoGap, "{}", r.summary);
}

#[test]
fn a_pattern_no_effect_makes_is_not_explained() {
    let em = emulator();
    // Wear 40 % below the model everywhere (as a protective oxide would): every effect of this
    // library adds wear, none removes it.
    let c = campaign(
        |t, k| {
            let mut p = truth(t, k, 0.0, 0.0, 0.0);
            for v in p.mass_mg.values_mut() {
                *v *= 0.6;
            }
            p
        },
        3,
    );
    let r = diagnose_with(&c, &em, &options()).unwrap();
    assert_eq!(r.verdict, Verdict::NotExplained, "{}", r.summary);
    assert!(r.best_effect.is_none());
    let test_groups: Vec<_> = r
        .location
        .groups
        .iter()
        .filter(|g| g.by == "test")
        .collect();
    assert!(test_groups.iter().all(|g| g.mean_residual < 0.0));
}

/// The emulator with a coating breakthrough that acts on test T0 alone, from the increment
/// `from` on (a coating worn through only where the slip is longest, by then): T0's mass x
/// (1 + 3 f) at the share f of its bound.
fn with_coating_on_t0(from: usize) -> (Emulator, f64, impl Fn(usize, usize, f64) -> Prediction) {
    let mut em = emulator();
    let info = effects::info("coating_breakthrough").unwrap();
    let max = info.parameters[0].max;
    let magnitudes: Vec<f64> = (0..41).map(|i| max * i as f64 / 40.0).collect();
    let only_t0 = move |t: usize, k: usize, f: f64| {
        let mut p = truth(t, k, 0.0, 0.0, 0.0);
        if t == 0 && k >= from {
            for v in p.mass_mg.values_mut() {
                *v *= 1.0 + 3.0 * f;
            }
        }
        p
    };
    let predictions = magnitudes
        .iter()
        .map(|m| {
            (0..TESTS)
                .map(|t| (0..INCREMENTS).map(|k| only_t0(t, k, m / max)).collect())
                .collect()
        })
        .collect();
    em.effects.push(EffectTable {
        info,
        magnitudes,
        predictions,
        simulated: false,
        parameters: BTreeMap::new(),
    });
    (em, max, only_t0)
}

#[test]
fn an_effect_seen_in_one_test_only_is_confirmed_by_increment_and_named_partly() {
    // A wear-law effect that acts on test T0 alone: the campaign is drawn from it.
    // Leave-one-test-out has nothing to fit it on when T0 is held out, so no held-out gain can
    // confirm it. T0's increments can: fitted on the other increments, the effect must predict
    // the one left out. That holds within one test only, so the verdict names the effect as
    // the leading candidate (partly_explained, saying which test carries it), with the drawn
    // magnitude inside its interval, and never `explained`.
    let (em, max, only_t0) = with_coating_on_t0(0);
    let c = campaign(|t, k| only_t0(t, k, 0.5), 11);
    let r = diagnose_with(&c, &em, &options()).unwrap();
    assert_eq!(r.verdict, Verdict::PartlyExplained, "{}", r.summary);
    assert!(
        r.held_out
            .starts_with("leave-one-increment-out, as T0 carries"),
        "{}",
        r.held_out
    );
    assert!(
        r.summary
            .contains("partly explained by coating_breakthrough")
            && r.summary
                .contains("confirmed by increment within one test only"),
        "{}",
        r.summary
    );
    let b = r.best_effect.unwrap();
    assert_eq!(b.name, "coating_breakthrough");
    let [lo, hi] = b.parameters[0].interval.unwrap();
    assert!(
        lo <= 0.5 * max && 0.5 * max <= hi,
        "{} not in [{lo}, {hi}]",
        0.5 * max
    );
    // Held out by increment, the effect predicts what the nominal cannot.
    assert!(b.shrink > 0.5, "shrink {}", b.shrink);
}

#[test]
fn an_effect_seen_in_one_increment_of_one_test_stays_unconfirmable() {
    // The same coating reached only in T0's last increment: held out by test, T0 carries it;
    // held out by increment, the last increment does, and the other increments hold nothing
    // to fit it on either. No split of the data can confirm it, so the verdict stays
    // not_explained, and the summary says which test carries it and that more such tests
    // could confirm it.
    let (em, _, only_t0) = with_coating_on_t0(INCREMENTS - 1);
    let c = campaign(|t, k| only_t0(t, k, 0.5), 11);
    let r = diagnose_with(&c, &em, &options()).unwrap();
    assert_eq!(r.verdict, Verdict::NotExplained, "{}", r.summary);
    assert_eq!(r.held_out, "leave-one-test-out");
    assert!(
        r.summary
            .contains("coating_breakthrough fits every observation")
            && r.summary.contains("but T0 carries")
            && r.summary.contains("more tests like T0 could"),
        "{}",
        r.summary
    );
}

/// Where, by configuration: two of five tests (their own config) read 40 % above the model,
/// the other three (sharing another) as the model predicts. The pooled group of the two is
/// flagged, with a mean residual of the sign of the offset; the three's is not; a config
/// held by every test (the synthetic campaigns' usual case) makes no group.
#[test]
fn residuals_pool_by_shared_configuration() {
    let mut c = campaign(
        |t, k| {
            let mut p = truth(t, k, 0.0, 0.0, 0.0);
            if t < 2 {
                *p.mass_mg.get_mut("cube").unwrap() *= 1.4;
            }
            p
        },
        21,
    );
    for t in &mut c.tests[..2] {
        t.config = "rattle-box-d".into();
    }
    let report = diagnose_with(&c, &emulator(), &options()).unwrap();
    let config_groups: Vec<_> = report
        .location
        .groups
        .iter()
        .filter(|g| g.by == "config")
        .collect();
    assert_eq!(config_groups.len(), 2, "{config_groups:#?}");
    let offset = config_groups
        .iter()
        .find(|g| g.label == "rattle-box-d (2 tests)")
        .unwrap();
    assert!(offset.flagged && offset.mean_residual > 0.0, "{offset:#?}");
    let clean = config_groups
        .iter()
        .find(|g| g.label == "rattle-box-c (3 tests)")
        .unwrap();
    assert!(!clean.flagged, "{clean:#?}");
    let unchanged = diagnose_with(
        &campaign(|t, k| truth(t, k, 0.0, 0.0, 0.0), 21),
        &emulator(),
        &options(),
    )
    .unwrap();
    assert!(unchanged.location.groups.iter().all(|g| g.by != "config"));
}

/// How the hand-built cross-axis drive's wear and off-axis response depend on its phase:
/// 1 at the library default 0, 2.0 in anti-phase, 2.27 at +120° and 1.23 at -120° (the cross
/// motion leads or lags the drive: not symmetric).
fn phase_gain(phase_deg: f64) -> f64 {
    let p = phase_deg.to_radians();
    1.0 + 0.5 * (1.0 - p.cos()) + 0.6 * p.sin()
}

/// The hand-built truth with a cross-axis drive of relative share `cross` at `phase_deg`.
fn truth_phase(t: usize, k: usize, cross: f64, phase_deg: f64) -> Prediction {
    let mut p = truth(t, k, 0.0, 0.0, 0.0);
    let g = phase_gain(phase_deg);
    *p.mass_mg.get_mut("cube").unwrap() *= 1.0 + 1.5 * cross * CROSS_SHARE[t] * g;
    p.input_ms = [DRIVE_MS, DRIVE_MS * cross * cross, DRIVE_MS * cross * cross];
    for a in 1..3 {
        p.response_ms[a] = 0.01 * DRIVE_MS + 0.4 * DRIVE_MS * cross * cross * g;
    }
    p
}

/// The cross-axis table of [`emulator`] at another phase (a variant table).
fn cross_variant(phase_deg: f64) -> EffectTable {
    let mut t = table("cross_axis", 2, 41);
    let max = t.info.parameters[0].max;
    t.predictions = t
        .magnitudes
        .iter()
        .map(|m| {
            (0..TESTS)
                .map(|ti| {
                    (0..INCREMENTS)
                        .map(|k| truth_phase(ti, k, m / max, phase_deg))
                        .collect()
                })
                .collect()
        })
        .collect();
    t.parameters = BTreeMap::from([("phase_deg".to_string(), phase_deg)]);
    t
}

/// Issue 26 item 3: a cross-axis drive at 120° is fitted at share 0.3 of its bound and phase
/// 0 as well as it can be, and the residuals refuse it (its wear and off-axis response are
/// 1.6x what phase 0 gives at the share the input pins). With the phase profiled over variant
/// tables, the effect explains, its phase is fitted at 120° within an interval that holds it,
/// and the share's interval holds the truth.
#[test]
fn a_secondary_parameter_is_fitted_with_its_interval() {
    let c = campaign(|t, k| truth_phase(t, k, 0.3, 120.0), 5);
    let plain = diagnose_with(&c, &emulator(), &options()).unwrap();
    assert_ne!(plain.verdict, Verdict::Explained, "{}", plain.summary);
    let mut em = emulator();
    for phase in [-180.0, -120.0, -60.0, 60.0, 120.0, 180.0] {
        em.effects.push(cross_variant(phase));
    }
    let r = diagnose_with(&c, &em, &options()).unwrap();
    assert_eq!(r.verdict, Verdict::Explained, "{}", r.summary);
    let best = r.best_effect.as_ref().unwrap();
    assert_eq!(best.name, "cross_axis");
    let share = &best.parameters[0];
    let true_share = 0.3 * share.bounds[1];
    let [lo, hi] = share.interval.unwrap();
    assert!(lo <= true_share && true_share <= hi, "{share:?}");
    let phase = best
        .parameters
        .iter()
        .find(|p| p.name == "phase_deg")
        .unwrap();
    assert!(phase.fitted, "{phase:?}");
    assert_eq!(phase.value, 120.0);
    let [lo, hi] = phase.interval.unwrap();
    assert!(lo <= 120.0 && 120.0 <= hi && hi - lo < 360.0, "{phase:?}");
    // The ranking counts the phase as a fitted parameter.
    assert_eq!(r.ranking[0].parameters, 2);
}

/// A phase the input records measure is not fitted: with a measurement of 120° held, the
/// family keeps only the variant that agrees with it (the default at 0° and the variants at
/// ±60° and 180° contradict it), the effect explains at 120°, and the report gives the phase
/// as measured (not fitted, the measurement's interval, its source), counting one fitted
/// parameter (the share) where the profiled phase counted two.
#[test]
fn a_measured_phase_is_held_not_fitted() {
    let c = campaign(|t, k| truth_phase(t, k, 0.3, 120.0), 5);
    let mut em = emulator();
    for phase in [-180.0, -60.0, 60.0, 120.0, 180.0] {
        em.effects.push(cross_variant(phase));
    }
    em.measured.push(MeasuredValue {
        effect: "cross_axis".into(),
        parameter: "phase_deg".into(),
        value: 120.4,
        sd: 0.5,
        tolerance: 3.0 * 0.5f64.hypot(2.0),
        source: "input accelerometer records".into(),
    });
    let cross: Vec<usize> = (0..em.effects.len())
        .filter(|&t| em.effects[t].info.name == "cross_axis")
        .collect();
    assert_eq!(
        em.family(cross[0]),
        vec![cross[4]],
        "only the 120° variant agrees"
    );
    let r = diagnose_with(&c, &em, &options()).unwrap();
    assert_eq!(r.verdict, Verdict::Explained, "{}", r.summary);
    let best = r.best_effect.as_ref().unwrap();
    let phase = best
        .parameters
        .iter()
        .find(|p| p.name == "phase_deg")
        .unwrap();
    assert!(!phase.fitted, "{phase:?}");
    assert_eq!(phase.value, 120.0);
    assert_eq!(
        phase.measured_from.as_deref(),
        Some("input accelerometer records")
    );
    let [lo, hi] = phase.interval.unwrap();
    assert!((lo - (120.4 - 1.96 * 0.5)).abs() < 1e-12 && (hi - (120.4 + 1.96 * 0.5)).abs() < 1e-12);
    assert_eq!(r.ranking[0].parameters, 1);
}

/// Issue 26 item 3: an effect that fits only at its physical bound is not `explained`
/// without saying so. Abrasion 3 % beyond the bound of k_abrasive (what the library allows)
/// is fitted at the bound, within the noise: `partly_explained`, naming the parameter at its
/// bound and the test it predicts worst.
#[test]
fn an_effect_fitted_at_its_bound_is_partly_explained() {
    let c = campaign(|t, k| truth(t, k, 1.03, 0.0, 0.0), 9);
    let r = diagnose_with(&c, &emulator(), &options()).unwrap();
    assert_eq!(r.verdict, Verdict::PartlyExplained, "{}", r.summary);
    let p = r.partly_explained.as_ref().unwrap();
    assert_eq!(p.candidate, "third_body");
    assert_eq!(p.at_bound, vec!["third_body.k_abrasive".to_string()]);
    assert!(p.cannot_predict.starts_with('T'), "{p:?}");
    assert!(r.summary.starts_with("partly explained by third_body"));
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["verdict"], "partly_explained");
}

/// `explained` needs every withheld test predicted within its noise. Abrasion at 0.4 of its
/// bound on every test, and test T4 wearing 1 + `extra` times more besides, a pattern no
/// effect makes (T4 is where abrasion acts least). The pooled tests still pass: the full-data
/// lack of fit carries T4's few masses among every test's accelerometer channels, and the
/// held-out log-likelihood gain and share are abrasion's. Held out, T4's masses are about
/// `extra / 3 %` standard deviations off (5 % scatter over three specimens), a chi-square far
/// above its bound on T4's degrees of freedom: `partly_explained`, naming T4 and by how much,
/// while the other tests are predicted.
#[test]
fn a_withheld_test_that_is_not_predicted_keeps_the_verdict_from_explained() {
    let extra = 0.2;
    let c = campaign(
        |t, k| {
            let mut p = truth(t, k, 0.4, 0.0, 0.0);
            if t == 4 {
                *p.mass_mg.get_mut("cube").unwrap() *= 1.0 + extra;
            }
            p
        },
        3,
    );
    let r = diagnose_with(&c, &emulator(), &options()).unwrap();
    assert_eq!(r.verdict, Verdict::PartlyExplained, "{}", r.summary);
    let p = r.partly_explained.as_ref().unwrap();
    // Abrasion leads (alone, or with a second effect the pairs tried beside it add).
    assert!(p.candidate.contains("third_body"), "{}", r.summary);
    assert!(
        p.residual_p_value >= r.alpha,
        "the pooled lack of fit passes: {p:?}"
    );
    let unpredicted: Vec<&str> = p.unpredicted.iter().map(|g| g.group.as_str()).collect();
    assert_eq!(unpredicted, vec!["T4"], "{}", r.summary);
    assert_eq!(p.cannot_predict, "T4");
    let t4 = &p.unpredicted[0];
    assert!(t4.after > t4.bound && t4.p_adjusted < r.alpha, "{t4:?}");
    assert!(
        r.summary.contains("T4 not predicted held out"),
        "{}",
        r.summary
    );
    let best = r.best_effect.as_ref().unwrap();
    assert!(best
        .per_group
        .iter()
        .filter(|g| g.group != "T4")
        .all(|g| g.predicted));
    // The same campaign without T4's extra wear is explained.
    let clean = campaign(|t, k| truth(t, k, 0.4, 0.0, 0.0), 3);
    let r = diagnose_with(&clean, &emulator(), &options()).unwrap();
    assert_eq!(r.verdict, Verdict::Explained, "{}", r.summary);
}

/// A parameter the data cannot see is said not to be identified. Weighed only (no
/// accelerometer records), a cross-axis drive's phase acts on the masses only through the
/// product of share and phase gain: every phase of the profile fits with its own share (the
/// gain from 0.73 to 2.27 needs shares from 0.93 to 0.3 of the bound), so the phase's 95 %
/// interval is the whole circle and the report marks it not identified, with no value in the
/// summary. With the records, the off-axis response separates them (the test above).
#[test]
fn a_phase_the_data_cannot_see_is_reported_not_identified() {
    let mut c = campaign(|t, k| truth_phase(t, k, 0.3, 120.0), 5);
    for t in &mut c.tests {
        for s in &mut t.specimens {
            s.accelerometers.clear();
        }
    }
    let mut em = emulator();
    for phase in [-180.0, -120.0, -60.0, 60.0, 120.0, 180.0] {
        em.effects.push(cross_variant(phase));
    }
    let r = diagnose_with(&c, &em, &options()).unwrap();
    let best = r.best_effect.as_ref().expect("an effect is named");
    assert_eq!(best.name, "cross_axis", "{}", r.summary);
    let phase = best
        .parameters
        .iter()
        .find(|p| p.name == "phase_deg")
        .unwrap();
    assert!(phase.fitted && !phase.identified, "{phase:?}");
    assert_eq!(phase.interval, Some([-180.0, 180.0]), "{phase:?}");
    assert!(
        r.summary
            .contains("not identified by the data: cross_axis.phase_deg"),
        "{}",
        r.summary
    );
    // No value given: the label, then that the data do not identify it.
    assert!(
        phase
            .describe()
            .starts_with("cross_axis.phase_deg: not identified by the data"),
        "{}",
        phase.describe()
    );
    // The share is identified: its interval holds the truth and is narrower than its range.
    let share = &best.parameters[0];
    let true_share = 0.3 * share.bounds[1];
    let [lo, hi] = share.interval.unwrap();
    assert!(lo <= true_share && true_share <= hi, "{share:?}");
    assert!(share.identified, "{share:?}");
}

/// Issue 26 item 4: abrasion and a cross-axis drive together. No single effect explains;
/// the pair does, and its held-out error is no worse than its better member's alone (its
/// fits include each member alone, so it never fits worse, and takes both only when both
/// beat either alone on the training tests).
#[test]
fn a_pair_never_scores_worse_than_its_better_member() {
    for seed in [2, 4, 6] {
        let c = campaign(|t, k| truth(t, k, 0.4, 0.0, 0.3), seed);
        let r = diagnose_with(&c, &emulator(), &options()).unwrap();
        let single = |n: &str| r.ranking.iter().find(|e| e.name == n).unwrap();
        let better = single("third_body")
            .held_out_error
            .min(single("cross_axis").held_out_error);
        for p in &r.pairs {
            let members: Vec<&str> = p.name.split('+').collect();
            let better_member = members
                .iter()
                .map(|n| single(n).held_out_error)
                .fold(f64::INFINITY, f64::min);
            assert!(
                p.held_out_error <= better_member * (1.0 + 1e-9),
                "seed {seed}: {} {} vs {better_member}",
                p.name,
                p.held_out_error
            );
        }
        assert_eq!(r.verdict, Verdict::Explained, "seed {seed}: {}", r.summary);
        let best = r.best_effect.as_ref().unwrap();
        assert_eq!(best.name, "third_body+cross_axis", "seed {seed}");
        assert!(best.held_out_error_after < better);
        // The held-out predictions are the named pair's, both members fitted without each
        // test, every withheld group predicted within the rule's bound.
        assert!(r
            .held_out_predictions
            .iter()
            .all(|m| m.effect == best.name && m.magnitudes.len() == 2));
        assert!(best
            .per_group
            .iter()
            .all(|g| g.predicted && g.after <= g.bound));
    }
}

/// Two dynamics effects together can make a window's wear depend on the state the motion
/// enters the excitation in, where neither alone does (bench 2035). Here clearance growth and
/// a cross-axis drive, both at half their bounds: from the other initial state, test T0's
/// second and third increments wear 1.8x, and the campaign was drawn from that state. The
/// pair's joint point simulated with its settle-shifted twin carries that spread, and the
/// pair fits within the noise; the same point without its twin leaves T0's increments 16
/// standard deviations off (80 % against a 5 % scatter over three specimens) and does not.
#[test]
fn a_pairs_initial_state_spread_is_carried() {
    let (g, x) = (0.5, 0.5);
    let other_start = |t: usize, k: usize| {
        let mut p = truth(t, k, 0.0, g, x);
        if t == 0 && k > 0 {
            for m in p.mass_mg.values_mut() {
                *m *= 1.8;
            }
        }
        p
    };
    let grid = |f: &dyn Fn(usize, usize) -> Prediction| -> TestPredictions {
        (0..TESTS)
            .map(|t| (0..INCREMENTS).map(|k| f(t, k)).collect())
            .collect()
    };
    let bound = |name: &str| effects::info(name).unwrap().parameters[0].max;
    let c = campaign(other_start, 11);
    let pair_p = |twin: bool| {
        let mut em = emulator();
        em.joints.push(JointPoint {
            tables: [1, 2],
            magnitudes: [g * bound("clearance_growth"), x * bound("cross_axis")],
            predictions: grid(&|t, k| truth(t, k, 0.0, g, x)),
            initial_state: twin.then(|| grid(&other_start)),
        });
        let r = diagnose_with(&c, &em, &options()).unwrap();
        let pair = r
            .pairs
            .iter()
            .find(|p| p.name == "clearance_growth+cross_axis")
            .unwrap_or_else(|| panic!("the pair is tried: {}", r.summary));
        pair.residual_p_value
    };
    let alpha = options().alpha;
    let (with, without) = (pair_p(true), pair_p(false));
    assert!(with >= alpha, "with the twin: p = {with}");
    assert!(without < alpha, "without it: p = {without}");
}
