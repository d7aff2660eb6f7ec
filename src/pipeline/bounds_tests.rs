//! The bad-value table: every numeric field of every reference config (and of each optional
//! table, serialized from its type) is checked against a bound by the typed checker, and a
//! value outside that bound is refused naming the field.

use super::bounds::{check_case_at, Bound, Bounded, FieldPath};
use super::{case_from_params, RunError};
use crate::models::case::{load_case, resolve_excitation};
use crate::models::spec::CaseSpec;
use crate::wear::law::WearLaw;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

/// Every reference case that runs as a job, as an inline config with its profile resolved,
/// plus the same cases with each optional table filled from its type's own values.
fn sample_cases() -> Vec<(String, Value)> {
    let mut out = Vec::new();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(configs())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    for path in paths {
        let Ok(case) = load_case(&path) else {
            continue; // service.toml
        };
        if case.model == crate::models::spec::ModelKind::PersistentContact {
            continue; // not a dynamic case: refused as a job before its fields matter
        }
        let mut value = serde_json::to_value(&case).unwrap();
        let excitation = resolve_excitation(&case, &configs()).unwrap();
        value["excitation"] = serde_json::to_value(&excitation).unwrap();
        out.push((case.name.clone(), value));
    }
    // Optional tables and other variants, each serialized from the library's own values.
    let (_, rattle) = out
        .iter()
        .find(|(n, _)| n == "rattle-box-c")
        .cloned()
        .unwrap();
    let mut v = rattle.clone();
    v["rattle_box"]["cube_mass_kg"] = json!(0.046);
    v["simulation"]["energy_rel_tolerance"] = json!(1e-3);
    v["wear"]["law"] = serde_json::to_value(WearLaw::legacy_table_4_3()).unwrap();
    v["wear"]["volume_split"] =
        serde_json::to_value(crate::wear::allocation::VolumeSplit::Fixed { fraction_to_a: 0.5 })
            .unwrap();
    out.push(("rattle-box-c, legacy law, fixed split".into(), v));
    let mut v = rattle.clone();
    v["wear"]["law"] = serde_json::to_value(WearLaw::Archard {
        coefficient_m2_per_n: 1e-14,
    })
    .unwrap();
    v["excitation"] = json!({
        "kind": "measured", "units": "g", "highpass_hz": 2.0,
        "samples": [[0.0, 0.0, 0.0, 0.0], [0.01, 1.0, 0.0, 0.0], [0.02, 0.0, 0.0, 0.0]],
        "ramp": serde_json::to_value(crate::excitation::RampSpec::Seconds(0.5)).unwrap(),
    });
    out.push(("rattle-box-c, Archard, measured".into(), v));
    let (_, launcher) = out
        .iter()
        .find(|(n, _)| n == "launcher-design")
        .cloned()
        .unwrap();
    let mut v = launcher;
    v["launcher"]["missile"]["inertia_kg_m2"] = json!([10.0, 10.0, 0.2]);
    out.push(("launcher-design, given inertia".into(), v));
    // Each wear mechanism a case can carry, from the library's own values.
    use crate::wear::mechanism::*;
    let mechanisms = [
        WearMechanism::WearAboveCutoff(AboveCutoff { ratio: 3.0 }),
        WearMechanism::ThirdBody(ThirdBody {
            k_add_m2_per_n: 1e-14,
            min_pressure_pa: 1e4,
            min_slip_m_s: 1e-3,
        }),
        WearMechanism::ImpactWear(ImpactWear {
            k_energy_m3_per_j: 2.5e-13,
            min_normal_speed_m_s: 0.01,
        }),
        WearMechanism::SevereWear(SevereWear {
            k_add_m2_per_n: 1e-13,
            pressure_ratio_to_yield: 1.0,
        }),
        WearMechanism::LocalPressure(LocalPressure { share: 0.5 }),
        WearMechanism::CoatingBreakthrough(CoatingBreakthrough {
            k_add_m2_per_n: 1e-13,
            breakthrough_slip_m: 1e3,
        }),
    ];
    for m in mechanisms {
        let mut v = rattle.clone();
        v["wear"]["mechanism"] = serde_json::to_value(m).unwrap();
        out.push((format!("rattle-box-c, {} mechanism", m.name()), v));
    }
    out
}

/// `a.b[2].c` as a JSON pointer.
fn pointer(path: &str) -> String {
    let mut p = String::new();
    for part in path.split('.') {
        let (key, indices) = part.split_once('[').unwrap_or((part, ""));
        p.push('/');
        p.push_str(key);
        for index in indices.split('[').filter(|s| !s.is_empty()) {
            p.push('/');
            p.push_str(index.trim_end_matches(']'));
        }
    }
    p
}

/// The path of every number in `value` (`a.b[2].c`, as `serde_path_to_error` writes it).
fn number_paths(value: &Value, path: &mut String, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                number_paths(v, path, out);
                path.truncate(len);
            }
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                let len = path.len();
                path.push_str(&format!("[{i}]"));
                number_paths(v, path, out);
                path.truncate(len);
            }
        }
        Value::Number(_) => out.push(path.clone()),
        _ => {}
    }
}

struct NumericLeaf {
    path: String,
    bound: Option<Bound>,
}

/// Each number of the case written as `case`, with the bound the typed checker held it to
/// (`None`: the checker did not visit it).
fn numeric_leaves(case: &Value) -> Vec<NumericLeaf> {
    let typed: CaseSpec = serde_json::from_value(case.clone()).unwrap();
    let mut at = FieldPath::recording("");
    check_case_at(&typed, None, &mut at).unwrap();
    let mut paths = Vec::new();
    number_paths(case, &mut String::new(), &mut paths);
    paths
        .into_iter()
        .map(|path| NumericLeaf {
            bound: at
                .checked()
                .iter()
                .find(|(p, _)| *p == path)
                .map(|(_, b)| *b),
            path,
        })
        .collect()
}

#[test]
fn the_typed_checker_bounds_every_numeric_field() {
    let mut missing = Vec::new();
    let mut leaves = 0;
    for (name, case) in sample_cases() {
        for leaf in numeric_leaves(&case) {
            leaves += 1;
            if leaf.bound.is_none() {
                missing.push(format!("{name}: {}", leaf.path));
            }
        }
    }
    assert!(missing.is_empty(), "fields no bound checked: {missing:#?}");
    assert!(leaves > 500, "only {leaves} numeric fields");
    // The reference configs themselves are inside every bound.
    for (name, case) in sample_cases() {
        let params = json!({"config": case});
        if let Err(e) = case_from_params(&params, &configs()) {
            // Only the variants may fail later rules (a measured record too short to build).
            assert!(name.contains(','), "{name}: {e}");
            if let RunError::InvalidConfig { field, rule } = &e {
                assert!(!rule.contains("must lie in"), "{name}: {field} {rule}");
            }
        }
    }
}

/// The field a rattle-box-c case with `overrides` is refused at (panics if it is accepted or
/// refused otherwise).
fn refused_field(overrides: Value) -> String {
    match case_from_params(
        &json!({"config": "rattle-box-c", "overrides": overrides}),
        &configs(),
    ) {
        Err(RunError::InvalidConfig { field, .. }) => field,
        other => panic!("{:?}", other.map(|_| ())),
    }
}

/// A wrong type inside a table serde reads whole (the tagged wear law and mechanism, the
/// excitation) is named at its own field, as one in a plain table is.
#[test]
fn a_wrong_type_is_named_at_its_field_inside_tagged_tables() {
    assert_eq!(
        refused_field(
            json!({"wear": {"law": {"kind": "modified", "c1": "NaN", "c2": 6.3197, "c3": 0.0,
            "cutoff_pressure_pa": 8.7e8}}})
        ),
        "overrides.wear.law.c1"
    );
    assert_eq!(
        refused_field(
            json!({"excitation": {"tones": [{"axis": "x", "frequency_hz": 20.0,
            "amplitude_g": true}]}})
        ),
        "overrides.excitation.tones[0].amplitude_g"
    );
    assert_eq!(
        refused_field(
            json!({"wear": {"mechanism": {"kind": "third_body", "k_add_m2_per_n": 1e-14,
            "min_pressure_pa": "1e4", "min_slip_m_s": 1e-3}}})
        ),
        "overrides.wear.mechanism.min_pressure_pa"
    );
    assert_eq!(
        refused_field(json!({"simulation": {"seed": -3}})),
        "overrides.simulation.seed"
    );
}

#[test]
fn every_value_outside_a_bound_is_refused_naming_the_field() {
    let bad_values = [-1.0, 0.0, 1e308, -1e308, 1e-300];
    let mut refused = 0;
    for (name, case) in sample_cases() {
        for leaf in numeric_leaves(&case) {
            let bound = leaf.bound.expect("covered by the test above");
            assert!(!bound.admits(f64::NAN) && !bound.admits(f64::INFINITY));
            let at = pointer(&leaf.path);
            let mut candidates: Vec<Value> = bad_values
                .iter()
                .filter(|v| !bound.admits(**v))
                .map(|v| json!(v))
                .collect();
            candidates.push(json!("NaN"));
            for bad in candidates {
                let mut edited = case.clone();
                *edited.pointer_mut(&at).unwrap() = bad.clone();
                let params = json!({"config": edited});
                match case_from_params(&params, &configs()) {
                    Err(RunError::InvalidConfig { field, rule }) => {
                        let want = format!("config.{}", leaf.path);
                        // A field read whole (a vector, a tuple) may be named as a whole.
                        let whole = want.split('[').next().unwrap_or(&want);
                        assert!(
                            field == want || field == whole,
                            "{name}: {} = {bad}: named `{field}` ({rule})",
                            leaf.path
                        );
                        refused += 1;
                    }
                    Err(other) => panic!("{name}: {} = {bad}: {other}", leaf.path),
                    Ok(_) => panic!("{name}: {} = {bad} was accepted", leaf.path),
                }
            }
        }
    }
    assert!(refused > 1000, "only {refused} refusals tried");
}

#[test]
fn the_issue_cases_are_refused_at_their_field() {
    assert_eq!(
        refused_field(
            json!({"excitation": {"tones": [{"axis": "x", "frequency_hz": 20.0, "amplitude_g": 1e308}]}})
        ),
        "overrides.excitation.tones[0].amplitude_g"
    );
    assert_eq!(
        refused_field(json!({"rattle_box": {"friction": {"mu_static": 1e6}}})),
        "overrides.rattle_box.friction.mu_static"
    );
    assert_eq!(
        refused_field(json!({"rattle_box": {"material": {"density_kg_per_m3": 1e308}}})),
        "overrides.rattle_box.material.density_kg_per_m3"
    );
    assert_eq!(
        refused_field(json!({"rattle_box": {"contact": {"exponent": 1e308}}})),
        "overrides.rattle_box.contact.exponent"
    );
    assert_eq!(
        refused_field(
            json!({"wear": {"law": {"kind": "modified", "c1": 1e308, "c2": 6.3197, "c3": 0.0, "cutoff_pressure_pa": 8.7e8}}})
        ),
        "overrides.wear.law.c1"
    );
    assert_eq!(
        refused_field(
            json!({"wear": {"law": {"kind": "modified", "c1": 2.3685e-15, "c2": 6.3197, "c3": 0.0, "cutoff_pressure_pa": -1.0}}})
        ),
        "overrides.wear.law.cutoff_pressure_pa"
    );
    // Within every field bound, a peak coefficient beyond severe adhesive wear: C1 at its
    // bound with C2 = 0.5 gives 1e-10 * (8.7e8)^2 m²/N.
    assert_eq!(
        refused_field(
            json!({"wear": {"law": {"kind": "modified", "c1": 1e-10, "c2": 0.5, "c3": 0.0, "cutoff_pressure_pa": 8.7e8}}})
        ),
        "overrides.wear.law.c1"
    );
    assert_eq!(
        refused_field(json!({"name": "x".repeat(10_000)})),
        "overrides.name"
    );
    // The Table 4.3 law at its cutoff stays two decades below the ceiling.
    let table = WearLaw::table_4_3();
    if let WearLaw::Modified {
        c1,
        c2,
        c3,
        cutoff_pressure_pa,
    } = table
    {
        let peak = c1 * cutoff_pressure_pa.powf(1.0 / c2) + c3;
        assert!(peak > 0.0 && peak < super::bounds::MAX_WEAR_COEFFICIENT_M2_PER_N / 100.0);
    }
}

/// One mechanism for a case's fields and a named parameter's: a [`Bound`] in words, open or
/// closed at its lower end, with its unit and reason.
#[test]
fn a_bound_admits_its_range_and_says_it() {
    let closed = Bound::new(0.0, 2.0, "", "why");
    assert!(closed.admits(0.0) && closed.admits(2.0));
    assert!(!closed.admits(-1e-300) && !closed.admits(2.000_000_1) && !closed.admits(f64::NAN));
    assert_eq!(closed.rule(), "must lie in [0e0, 2e0]: why");
    let open = Bound::new(-1.0, 0.5, "m", "because").open_min();
    assert!(!open.admits(-1.0) && open.admits(-0.999) && open.admits(0.5));
    assert_eq!(
        open.check("x.y", 7.0).unwrap_err().to_string(),
        "field `x.y` must lie in (-1e0, 5e-1] m: because, got 7"
    );
    let info = crate::parameters::ParameterInfo {
        name: "share",
        unit: "1",
        min: 0.0,
        max: 1.0,
        default: 0.0,
        reason: "r",
    };
    assert_eq!(info.bound(), Bound::new(0.0, 1.0, "1", "r"));
}

#[test]
fn every_number_of_a_calibration_data_set_is_bounded() {
    use super::CalibrateParams;
    let records: Vec<Value> = (0..8)
        .map(|i| {
            json!({"time_s": f64::from(i), "angle_rad": f64::from(i), "angular_velocity_rad_s": 1.0,
                "normal_load_n": 10.0, "input_torque_n_m": 0.5})
        })
        .collect();
    let wear: Vec<Value> = (0..4)
        .map(|i| {
            json!({"normal_load_n": 10.0, "contact_pressure_pa": 1e6 * f64::from(i + 1),
                "sliding_distance_m": 100.0, "wear_mass_kg": 1e-6})
        })
        .collect();
    let params = json!({
        "friction": {"fixture": {"polar_inertia_kg_m2": 1.0, "mean_radius_m": 0.1},
            "records": records},
        "wear_law": {"density_kg_m3": 2810.0, "cutoff_pressure_pa": 8.7e8, "records": wear},
    });
    // The bounds the typed records are held to, by path.
    let parsed = CalibrateParams::parse(&params).unwrap();
    let mut checked = Vec::new();
    let friction = parsed.friction.as_ref().unwrap();
    let mut at = FieldPath::recording("friction.fixture");
    friction.fixture.check_bounds(&mut at).unwrap();
    checked.extend_from_slice(at.checked());
    for (field, records) in [
        (
            "friction.records",
            friction
                .records
                .iter()
                .map(|r| r as &dyn Bounded)
                .collect::<Vec<_>>(),
        ),
        (
            "wear_law.records",
            parsed
                .wear_law
                .as_ref()
                .unwrap()
                .records
                .iter()
                .map(|r| r as &dyn Bounded)
                .collect(),
        ),
    ] {
        let mut at = FieldPath::recording(field);
        for (i, r) in records.iter().enumerate() {
            at.item(i, |at| r.check_bounds(at)).unwrap();
        }
        checked.extend_from_slice(at.checked());
    }
    let mut paths = Vec::new();
    number_paths(&params, &mut String::new(), &mut paths);
    let mut refused = 0;
    for path in paths {
        if path.ends_with("density_kg_m3") || path.ends_with("cutoff_pressure_pa") {
            continue; // bounded by `limits` in the parser itself
        }
        let bound = checked
            .iter()
            .find(|(p, _)| *p == path)
            .map(|(_, b)| *b)
            .unwrap_or_else(|| panic!("{path} has no bound"));
        for bad in [-1e308, 1e308, -1.0] {
            if bound.admits(bad) {
                continue;
            }
            let mut edited = params.clone();
            *edited.pointer_mut(&pointer(&path)).unwrap() = json!(bad);
            match CalibrateParams::parse(&edited) {
                Err(RunError::InvalidConfig { field, .. }) => assert_eq!(field, path),
                Err(other) => panic!("{path} = {bad}: {other}"),
                Ok(_) => panic!("{path} = {bad} accepted"),
            }
            refused += 1;
        }
    }
    assert!(refused >= 2 * 13, "{refused}");
}

/// A contact exponent at its bound is accepted at submit; its run then either succeeds with a
/// finite wear and a closed energy account or fails with a diagnostic, never with NaN or zeros
/// from a broken state.
#[test]
fn a_run_at_the_contact_exponent_bound_is_sound_or_fails_loudly() {
    let case = serde_json::to_value(
        crate::models::case::load_case(&configs().join("rattle-box-c.toml")).unwrap(),
    )
    .unwrap();
    let exponent = numeric_leaves(&case)
        .into_iter()
        .find(|leaf| leaf.path == "rattle_box.contact.exponent")
        .and_then(|leaf| leaf.bound)
        .unwrap()
        .max;
    // Above every contact law the thesis' sources fit (Hertz 1.5, rough surfaces about 3).
    assert!(exponent >= 3.0, "{exponent}");
    let params = json!({"config": "rattle-box-c", "overrides": {
        "rattle_box": {"contact": {"exponent": exponent}},
        "simulation": {"settle_s": 0.02, "duration_s": 0.05, "record_interval_s": 0.005}}});
    let control = super::RunControl::silent();
    match super::simulate_job(&params, &configs(), &control) {
        Ok(outcome) => {
            let energy = &outcome.summary["energy"];
            assert_eq!(energy["balanced"], true, "{energy}");
            for t in &outcome.tracks {
                assert!(t.normal_force_n.is_finite() && t.penetration_m.is_finite());
            }
        }
        Err(RunError::Diverged(diagnostic)) => {
            for word in ["t =", "body", "contact", "energy"] {
                assert!(diagnostic.contains(word), "{diagnostic}");
            }
        }
        Err(other) => panic!("{other}"),
    }
}
