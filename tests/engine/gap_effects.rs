//! Effect library (issue 14 item 3): data complete and bounded, zero magnitude changes nothing
//! bit for bit, and each effect moves the model the way its physics says (closed forms on
//! synthetic tracks; config edits checked against the formulas).

use railwear::gap::effects::{self, Acts, Effect, SpecimenState, LIBRARY};
use railwear::gap::rig_effects::{HiddenEffect, RIG_ONLY};
use railwear::gap::tracks::{PressureBin, SlipHistory, TrackPoint, TrackRecord, WearTerm};
use railwear::models::case::load_case;
use railwear::models::spec::CaseSpec;
use railwear::wear::law::WearLaw;
use railwear::wear::Material;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

fn case(name: &str) -> CaseSpec {
    load_case(&configs().join(format!("{name}.toml"))).unwrap()
}

#[test]
fn library_is_complete_and_bounded() {
    let letters: String = LIBRARY.iter().map(|e| e.letter).collect();
    assert_eq!(letters, "abcdefghijkl");
    for e in LIBRARY.iter().chain(RIG_ONLY) {
        assert!(!e.reason.is_empty() && !e.summary.is_empty(), "{}", e.name);
        let magnitude = &e.parameters[0];
        assert_eq!(
            magnitude.default, 0.0,
            "{}: magnitude 0 is the nominal model",
            e.name
        );
        for p in e.parameters {
            assert!(
                p.min <= p.default && p.default <= p.max,
                "{}.{}",
                e.name,
                p.name
            );
            assert!(
                !p.unit.is_empty() && !p.reason.is_empty(),
                "{}.{}",
                e.name,
                p.name
            );
        }
    }
    // The rig's own effects are not in the diagnosis' library.
    for r in RIG_ONLY {
        assert!(effects::info(r.name).is_none(), "{}", r.name);
    }
    // Parsing: bounds, unknown names and parameters are refused.
    assert!(Effect::parse("cross_axis=0.5").is_err());
    assert!(Effect::parse("cross_axis=0.1,phase=3").is_err());
    assert!(Effect::parse("sand=1").is_err());
    let e = Effect::parse("third_body=1e-3,min_pressure_pa=1e5").unwrap();
    assert_eq!(e.parameters["k_abrasive"], 1e-3);
    assert_eq!(e.parameters["min_pressure_pa"], 1e5);
    assert_eq!(
        Effect::parse("third_body=1e-3").unwrap().parameters["min_pressure_pa"],
        1e4
    );
    assert_eq!(e.parameters["min_slip_m_s"], 1e-3);
}

#[test]
fn dynamics_effects_at_zero_change_nothing() {
    let state = SpecimenState {
        elapsed_h: 4.5,
        slip_distance_m: 3000.0,
    };
    for info in LIBRARY.iter().filter(|e| e.acts == Acts::Dynamics) {
        let base = if info.name == "preload_loss" {
            case("launcher-design")
        } else {
            case("rattle-box-c")
        };
        let mut edited = base.clone();
        Effect::parse(&format!("{}=0", info.name))
            .unwrap()
            .apply(&mut edited, &state, &configs())
            .unwrap();
        assert_eq!(
            serde_json::to_string(&edited).unwrap(),
            serde_json::to_string(&base).unwrap(),
            "{}",
            info.name
        );
    }
}

/// Two steps of one track at pressure `sigma`: N = 100 N, v = 0.1 m/s for 1 s (10 J).
fn track_at(sigma: f64) -> TrackRecord {
    let area = 100.0 / sigma;
    let mut r = TrackRecord::new(1);
    for t in [0.0, 1.0] {
        r.push_step(
            t,
            [TrackPoint {
                contact: 0,
                track: 0,
                normal_force_n: 100.0,
                slip_speed_m_s: 0.1,
                area_m2: area,
                ..TrackPoint::default()
            }],
        );
    }
    r
}

fn wear(record: &TrackRecord, terms: &[&dyn WearTerm], history: SlipHistory) -> f64 {
    record
        .wear_volumes_m3(&WearLaw::table_4_3(), terms, history)
        .unwrap()[0]
}

fn term(text: &str) -> Box<dyn WearTerm> {
    match Effect::parse(text) {
        Ok(e) => e
            .wear_term(Material::aluminium_7075_t73().hardness_pa())
            .unwrap()
            .unwrap(),
        Err(_) => HiddenEffect::parse(text).unwrap().wear_term(),
    }
}

#[test]
fn wear_law_effects_at_zero_change_nothing_bit_for_bit() {
    let h = SlipHistory {
        slip_start_m: 500.0,
        time_scale: 100.0,
    };
    for sigma in [1.0e3, 2.0e6, 1.0e8, 2.0e9] {
        let r = track_at(sigma);
        let base = wear(&r, &[], h);
        for text in [
            "wear_above_cutoff=0",
            "third_body=0",
            "surface_oxide=0",
            "work_hardening=0",
            "impact_wear=0",
            "severe_wear=0",
            "local_pressure=0",
            "coating_breakthrough=0",
        ] {
            let t = term(text);
            assert_eq!(
                wear(&r, &[t.as_ref()], h).to_bits(),
                base.to_bits(),
                "{text} at {sigma}"
            );
        }
    }
}

#[test]
fn wear_above_cutoff_adds_ratio_times_k_at_the_cutoff() {
    let law = WearLaw::table_4_3();
    let k_cut = law.coefficient_m2_per_n(870.0e6).unwrap();
    let above = track_at(1.0e9); // above 2 Sy = 870 MPa
    assert_eq!(
        wear(&above, &[], SlipHistory::default()),
        0.0,
        "eq. 3.11: no wear above"
    );
    let t = term("wear_above_cutoff=50");
    let w = wear(&above, &[t.as_ref()], SlipHistory::default());
    let expected = 50.0 * k_cut * 10.0; // 10 J of friction work
    assert!(
        (w - expected).abs() <= 1e-12 * expected,
        "{w} vs {expected}"
    );
    // Below the cutoff the law is untouched.
    let below = track_at(1.0e8);
    assert_eq!(
        wear(&below, &[t.as_ref()], SlipHistory::default()),
        wear(&below, &[], SlipHistory::default())
    );
}

#[test]
fn third_body_raises_k_only_where_pressure_and_slip_allow() {
    let h_pa = Material::aluminium_7075_t73().hardness_pa();
    assert!((h_pa - 1.3239e9).abs() < 1e6, "135 HB = 1.32 GPa");
    let t = term("third_body=2e-3");
    let pressed = track_at(1.0e7);
    let base = wear(&pressed, &[], SlipHistory::default());
    let w = wear(&pressed, &[t.as_ref()], SlipHistory::default());
    let added = 2e-3 / h_pa * 10.0;
    assert!(
        (w - base - added).abs() <= 1e-12 * w,
        "{w} - {base} vs {added}"
    );
    // Below the 10 kPa default threshold: particles roll, nothing added.
    let light = track_at(5.0e3);
    assert_eq!(
        wear(&light, &[t.as_ref()], SlipHistory::default()),
        wear(&light, &[], SlipHistory::default())
    );
}

#[test]
fn rig_only_effects_lower_k() {
    // Surface oxide: K x (1 - 0.6) below 50 MPa, unchanged above.
    let t = term("surface_oxide=0.6");
    let low = track_at(1.0e6);
    let ratio =
        wear(&low, &[t.as_ref()], SlipHistory::default()) / wear(&low, &[], SlipHistory::default());
    assert!((ratio - 0.4).abs() < 1e-12, "{ratio}");
    let high = track_at(1.0e8);
    assert_eq!(
        wear(&high, &[t.as_ref()], SlipHistory::default()),
        wear(&high, &[], SlipHistory::default())
    );
    // Work hardening: the factor follows 1 - m (1 - exp(-s/s0)) with the slip so far. The track
    // slides 0.1 m in the window; scaled 100x that is 10 m, added to the 40 m already slid.
    let t = term("work_hardening=0.5,slip_scale_m=50");
    let r = track_at(1.0e7);
    let fresh = wear(&r, &[], SlipHistory::default());
    let h = SlipHistory {
        slip_start_m: 40.0,
        time_scale: 100.0,
    };
    let worn = wear(&r, &[t.as_ref()], h);
    let f = |s: f64| 1.0 - 0.5 * (1.0 - (-s / 50.0_f64).exp());
    let expected = fresh * 0.5 * (f(40.0) + f(50.0)); // trapezoid over the window
    assert!(
        (worn - expected).abs() <= 1e-12 * expected,
        "{worn} vs {expected}"
    );
    assert!(worn < fresh);
}

#[test]
fn clearance_growth_and_friction_drift_follow_their_formulas() {
    let base = case("rattle-box-d");
    let rb0 = base.rattle_box.clone().unwrap();
    let state = SpecimenState {
        elapsed_h: 3.75,
        slip_distance_m: 200.0,
    };
    let mut c = base.clone();
    Effect::parse("clearance_growth=20")
        .unwrap()
        .apply(&mut c, &state, &configs())
        .unwrap();
    let rb = c.rattle_box.clone().unwrap();
    assert!((rb.tube_inner_side_m - rb0.tube_inner_side_m - 20e-6 * 3.75).abs() < 1e-15);
    // A wider tube is a looser case: the rattle space falls (eq. 5.1).
    assert!(rb.rattle_space().unwrap() < rb0.rattle_space().unwrap());
    // Launcher: the material condition opens the rail.
    let l0 = case("launcher-design");
    let mut l = l0.clone();
    Effect::parse("clearance_growth=20")
        .unwrap()
        .apply(&mut l, &state, &configs())
        .unwrap();
    let k = |c: &CaseSpec| c.launcher.as_ref().unwrap().rattle_space().unwrap();
    assert!(k(&l) < k(&l0));
    // Friction drift: both coefficients shift by 0.3 (1 - exp(-200/100)).
    let mut c = base.clone();
    Effect::parse("friction_drift=0.3")
        .unwrap()
        .apply(&mut c, &state, &configs())
        .unwrap();
    let d = 0.3 * (1.0 - (-2.0_f64).exp());
    let f = &c.rattle_box.unwrap().friction;
    assert!((f.mu_static - rb0.friction.mu_static - d).abs() < 1e-12);
    assert!((f.mu_dynamic - rb0.friction.mu_dynamic - d).abs() < 1e-12);
}

fn tones(c: &CaseSpec) -> Vec<serde_json::Value> {
    c.excitation["tones"]
        .as_array()
        .cloned()
        .unwrap_or_default()
}

#[test]
fn drive_effects_edit_the_tones() {
    let base = case("rattle-box-c");
    let state = SpecimenState::default();
    // Fixture compliance: 10 ms (100 Hz) mount, 5 % damping, drive at 20 Hz: r = 0.2.
    let mut c = base.clone();
    Effect::parse("fixture_compliance=10,damping_ratio=0.05")
        .unwrap()
        .apply(&mut c, &state, &configs())
        .unwrap();
    let (r, z) = (0.2_f64, 0.05_f64);
    let gain =
        ((1.0 + (2.0 * z * r).powi(2)) / ((1.0 - r * r).powi(2) + (2.0 * z * r).powi(2))).sqrt();
    let amp = tones(&c)[0]["amplitude_g"].as_f64().unwrap();
    assert!(
        (amp - 15.0 * gain).abs() < 1e-12,
        "{amp} vs {}",
        15.0 * gain
    );
    assert!(gain > 1.0, "below resonance the mount amplifies");
    // At resonance the base-excitation transmissibility is sqrt(1 + 4 z²) / (2 z).
    let (g, _) = effects::transmissibility(100.0, 0.01, 0.05);
    assert!((g - (1.0 + 0.01_f64).sqrt() / 0.1).abs() < 1e-9, "{g}");
    // Cross-axis: the 15 g x tone is joined by 3 g on y and z.
    let mut c = base.clone();
    Effect::parse("cross_axis=0.2")
        .unwrap()
        .apply(&mut c, &state, &configs())
        .unwrap();
    let t = tones(&c);
    assert_eq!(t.len(), 3);
    for (tone, axis) in t[1..].iter().zip(["y", "z"]) {
        assert_eq!(tone["axis"].as_str(), Some(axis));
        assert!((tone["amplitude_g"].as_f64().unwrap() - 3.0).abs() < 1e-12);
        assert_eq!(tone["frequency_hz"].as_f64(), Some(20.0));
    }
    // Sharper edges: 0.508 mm x (1 - 0.75).
    let mut c = base.clone();
    Effect::parse("sharp_edges=0.75")
        .unwrap()
        .apply(&mut c, &state, &configs())
        .unwrap();
    assert!((c.rattle_box.unwrap().edge_radius_m - 0.000508 * 0.25).abs() < 1e-15);
}

#[test]
fn preload_loss_is_a_launcher_effect() {
    let state = SpecimenState::default();
    let e = Effect::parse("preload_loss=0.4").unwrap();
    let mut rb = case("rattle-box-c");
    let err = e.apply(&mut rb, &state, &configs()).unwrap_err();
    assert_eq!(err.field_path(), Some("effect.preload_loss"));
    let l0 = case("launcher-design");
    let mut l = l0.clone();
    e.apply(&mut l, &state, &configs()).unwrap();
    let (a, b) = (l0.launcher.unwrap(), l.launcher.unwrap());
    assert!((b.latch_spring.preload_n - 0.6 * a.latch_spring.preload_n).abs() < 1e-12);
    assert!((b.rear_leaf_spring.preload_n - 0.6 * a.rear_leaf_spring.preload_n).abs() < 1e-12);
}

/// Yield strength of 7075-T73, Pa (the record's, for the plastic-regime terms).
const SY: f64 = 435.0e6;

/// One track, two steps 1 s apart: N = 100 N, v = 0.1 m/s (10 W of N v) at lumped pressure
/// 200 MPa, normal damping dissipating `damping_w` at approach rates `rates`, and its contact
/// points' work split 3 W at 100 MPa, 7 W at 600 MPa (above Sy) in both steps.
fn impact_track(damping_w: f64, rates: [f64; 2]) -> TrackRecord {
    let bins = [
        PressureBin {
            pressure_pa: 100e6,
            work_rate_w: 3.0,
        },
        PressureBin {
            pressure_pa: 600e6,
            work_rate_w: 7.0,
        },
    ];
    let mut r = TrackRecord::new(1).with_yield_strength(SY);
    for (t, rate) in [0.0, 1.0].into_iter().zip(rates) {
        r.push_step_with_bins(
            t,
            [(
                TrackPoint {
                    contact: 0,
                    track: 0,
                    normal_force_n: 100.0,
                    slip_speed_m_s: 0.1,
                    area_m2: 100.0 / 200e6,
                    damping_power_w: damping_w,
                    penetration_rate_m_s: rate,
                    ..TrackPoint::default()
                },
                &bins[..],
            )],
        );
    }
    r
}

/// Impact wear adds k_E times the normal damping work (3 W over 1 s = 3 J), and a normal-speed
/// threshold drops the samples below it (trapezoid: half the interval's work per sample).
#[test]
fn impact_wear_is_k_e_times_the_damping_work() {
    let h = SlipHistory::default();
    let r = impact_track(3.0, [0.2, -0.05]);
    let base = wear(&r, &[], h);
    let t = term("impact_wear=1e-13");
    let added = wear(&r, &[t.as_ref()], h) - base;
    assert!((added - 3.0e-13).abs() <= 1e-12 * 3.0e-13, "{added}");
    // |rate| 0.2 counts, 0.05 does not: half of the trapezoid.
    let t = term("impact_wear=1e-13,min_normal_speed_m_s=0.1");
    let added = wear(&r, &[t.as_ref()], h) - base;
    assert!((added - 1.5e-13).abs() <= 1e-12 * 1.5e-13, "{added}");
    // The work budget sees the same 3 J.
    let w = r.work_by_contact(&WearLaw::table_4_3());
    assert_eq!(w[0].damping_j, 3.0);
}

/// Severe wear adds k/H times the work of the points above ratio x Sy: at ratio 1 the 7 W at
/// 600 MPa, at ratio 2 (870 MPa) nothing; without recorded points the lumped pressure decides.
#[test]
fn severe_wear_counts_only_points_above_the_yield_ratio() {
    let h = SlipHistory::default();
    let hardness = Material::aluminium_7075_t73().hardness_pa();
    let r = impact_track(0.0, [0.0, 0.0]);
    let base = wear(&r, &[], h);
    let t = term("severe_wear=1e-3");
    let added = wear(&r, &[t.as_ref()], h) - base;
    let expected = 1e-3 / hardness * 7.0;
    assert!(
        (added - expected).abs() <= 1e-9 * expected,
        "{added} vs {expected}"
    );
    let t = term("severe_wear=1e-3,pressure_ratio_to_yield=2");
    assert_eq!(wear(&r, &[t.as_ref()], h), base);
    // The budget's share above yield: 7 of 10.
    let w = r.work_by_contact(&WearLaw::table_4_3());
    assert!((w[0].sliding_above_yield_n_m / w[0].sliding_n_m - 0.7).abs() < 1e-12);
    // No points recorded: the lumped 200 MPa is below Sy, so nothing; at 2 GPa all 10 W.
    let lumped = track_at(2.0e9).with_yield_strength(SY);
    let base = wear(&lumped, &[], h);
    let t = term("severe_wear=1e-3");
    let added = wear(&lumped, &[t.as_ref()], h) - base;
    let expected = 1e-3 / hardness * 10.0;
    assert!(
        (added - expected).abs() <= 1e-9 * expected,
        "{added} vs {expected}"
    );
}

/// Local-pressure Archard at share 1 is Table 4.3's K at each point's pressure times its work
/// (3 W at 100 MPa, 7 W at 600 MPa), in place of K(200 MPa) x 10 W; share 0.5 is the mean.
#[test]
fn local_pressure_evaluates_k_at_each_points_pressure() {
    let h = SlipHistory::default();
    let law = WearLaw::table_4_3();
    let k = |p: f64| law.coefficient_m2_per_n(p).unwrap();
    let r = impact_track(0.0, [0.0, 0.0]);
    let lumped = wear(&r, &[], h);
    assert!((lumped - k(200e6) * 10.0).abs() <= 1e-12 * lumped);
    let local = k(100e6) * 3.0 + k(600e6) * 7.0;
    let t = term("local_pressure=1");
    let v = wear(&r, &[t.as_ref()], h);
    assert!((v - local).abs() <= 1e-12 * local, "{v} vs {local}");
    let t = term("local_pressure=0.5");
    let v = wear(&r, &[t.as_ref()], h);
    let mean = 0.5 * (lumped + local);
    assert!((v - mean).abs() <= 1e-12 * mean, "{v} vs {mean}");
    let w = r.work_by_contact(&law);
    assert!((w[0].local_archard_m3 - local).abs() <= 1e-12 * local);
    assert!((w[0].lumped_archard_m3 - lumped).abs() <= 1e-12 * lumped);
}

/// Coating breakthrough: K + k/H from the sample at which the slip distance reaches the
/// breakthrough. Track: 10 W of N v for 1 s (1 m of slip per second at 0.1 m/s over two
/// samples); history 100 windows after 50 m: the samples sit at 50 m and 60 m of slip.
#[test]
fn coating_breakthrough_switches_k_at_the_breakthrough_distance() {
    let hardness = Material::aluminium_7075_t73().hardness_pa();
    let h = SlipHistory {
        slip_start_m: 50.0,
        time_scale: 100.0,
    };
    let r = track_at(2.0e6);
    let base = wear(&r, &[], h);
    let add = 1e-3 / hardness;
    // Breakthrough before the window: both samples, the whole 10 N m.
    let t = term("coating_breakthrough=1e-3,breakthrough_slip_m=10");
    let v = wear(&r, &[t.as_ref()], h) - base;
    assert!((v - add * 10.0).abs() <= 1e-9 * add * 10.0, "{v}");
    // Between the samples (55 m): only the second, half the trapezoid.
    let t = term("coating_breakthrough=1e-3,breakthrough_slip_m=55");
    let v = wear(&r, &[t.as_ref()], h) - base;
    assert!((v - add * 5.0).abs() <= 1e-9 * add * 5.0, "{v}");
    // After the window: nothing.
    let t = term("coating_breakthrough=1e-3,breakthrough_slip_m=100");
    assert_eq!(wear(&r, &[t.as_ref()], h), base);
}
