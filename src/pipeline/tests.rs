//! Unit tests of the job parameter parsers.

use super::*;
use crate::analysis::rattle_space::LauncherDimensions;
use std::path::Path;

fn configs() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

#[test]
fn a_point_child_plans_the_same_sweep_as_its_parent() {
    let parent = serde_json::json!({"points": 4, "seed": 9, "vehicle_profile": "ah64"});
    let child = sweep_point_params(&parent, 3, 1);
    assert_eq!(sweep_point_index(&child).unwrap(), 3);
    let a = SweepPlan::from_params(&parent, &configs()).unwrap();
    let b = SweepPlan::from_params(&child, &configs()).unwrap();
    assert_eq!(a.offsets_mm, b.offsets_mm);
    assert_eq!(a.base.simulation.seed, 9);
    assert_eq!(b.base.simulation.seed, 9);
    assert_eq!(a.design_rattle_space, b.design_rattle_space);
    // Tight to loose, ends at the named material conditions.
    use crate::analysis::rattle_space::{LOOSE_MATERIAL_CONDITION_MM, TIGHT_MATERIAL_CONDITION_MM};
    assert_eq!(a.offsets_mm.first(), Some(&TIGHT_MATERIAL_CONDITION_MM));
    assert_eq!(a.offsets_mm.last(), Some(&LOOSE_MATERIAL_CONDITION_MM));
    assert!(matches!(
        sweep_point_index(&parent),
        Err(RunError::InvalidConfig { field, .. }) if field == "point"
    ));
    assert!(matches!(
        sweep_point(&a, 4, 0, &configs(), &RunControl::silent()),
        Err(RunError::InvalidConfig { field, .. }) if field == "point"
    ));
}

fn field_of(e: RunError) -> String {
    match e {
        RunError::InvalidConfig { field, .. } => field,
        other => panic!("{other}"),
    }
}

#[test]
fn a_sweep_takes_its_rattle_space_range_points_and_seeds() {
    use serde_json::json;
    // Default: the thesis' band, 5 points, 3 seeds.
    let r = SweepRange::from_params(&json!({})).unwrap();
    assert_eq!(r.offsets_mm, sweep_offsets_mm(5));
    assert_eq!(r.seeds, DEFAULT_SWEEP_SEEDS as usize);
    let (lo, hi) = r.rattle_space_bounds();
    assert!((lo - 0.7684).abs() < 1e-4 && (hi - 0.8317).abs() < 1e-4);
    // A rattle-space range: evenly spaced k_rs, tight to loose, ends exact.
    let r = SweepRange::from_params(
        &json!({"rattle_space_range": {"min": 0.64, "max": 0.82}, "points": 7, "seeds": 1}),
    )
    .unwrap();
    assert_eq!(r.rattle_spaces.len(), 7);
    assert!((r.rattle_spaces[0] - 0.82).abs() < 1e-9);
    assert!((r.rattle_spaces[6] - 0.64).abs() < 1e-9);
    assert!((r.rattle_spaces[3] - 0.73).abs() < 1e-9);
    assert!(r.offsets_mm.windows(2).all(|w| w[0] < w[1]));
    // An offset range.
    let r =
        SweepRange::from_params(&json!({"offset_mm_range": {"min": -0.25, "max": 1.0}})).unwrap();
    assert_eq!(r.offsets_mm.first(), Some(&-0.25));
    assert_eq!(r.offsets_mm.last(), Some(&1.0));
    // Bounds, each naming the field.
    let bad = |p: serde_json::Value| field_of(SweepRange::from_params(&p).unwrap_err());
    // Beyond zero vertical clearance (offset -0.30 mm, k_rs 0.848) no rail assembles.
    assert_eq!(
        bad(json!({"rattle_space_range": {"min": 0.78, "max": 0.86}})),
        "rattle_space_range"
    );
    assert_eq!(
        bad(json!({"offset_mm_range": {"min": -0.35, "max": 0.1}})),
        "offset_mm_range"
    );
    // The design point must be inside (K_SL is relative to it).
    assert_eq!(
        bad(json!({"rattle_space_range": {"min": 0.60, "max": 0.70}})),
        "rattle_space_range"
    );
    assert_eq!(
        bad(json!({"rattle_space_range": {"min": 0.8, "max": 0.7}})),
        "rattle_space_range"
    );
    assert_eq!(
        bad(json!({"rattle_space_range": {"min": 0.7}})),
        "rattle_space_range.max"
    );
    assert_eq!(
        bad(json!({"rattle_space_range": {"min": 0.7, "max": 0.8, "mid": 1}})),
        "rattle_space_range.mid"
    );
    assert_eq!(
        bad(json!({"rattle_space_range": {"min": 0.7, "max": 0.8},
                   "offset_mm_range": {"min": 0, "max": 1}})),
        "offset_mm_range"
    );
    assert_eq!(bad(json!({"seeds": 0})), "seeds");
    assert_eq!(bad(json!({"seeds": 11})), "seeds");
    assert_eq!(bad(json!({"points": 50, "seeds": 5})), "seeds");
    assert_eq!(
        bad(json!({"base_dimensions_mm": {"a_shoe_mm": 38.1}})),
        "base_dimensions_mm"
    );
    let mut dims = serde_json::to_value(LauncherDimensions::design()).unwrap();
    dims["a_shoe_mm"] = json!(9.0);
    assert!(bad(json!({"base_dimensions_mm": dims})).starts_with("base_dimensions_mm."));
}

#[test]
fn the_suggested_sweep_covers_the_rail() {
    use serde_json::json;
    let template = json!({"config": "launcher-design", "points": 5, "seed": 3});
    // Looser than the thesis' band: the design family reaches it.
    let loose = LauncherDimensions::design().with_material_condition(1.075);
    let k = loose.rattle_space().unwrap();
    let p = covering_sweep_params(&template, k, Some(&loose)).unwrap();
    assert!(p.get("base_dimensions_mm").is_none(), "{p}");
    assert!(p.get("seed").is_none());
    let r = SweepRange::from_params(&p).unwrap();
    let (lo, hi) = r.rattle_space_bounds();
    assert!(lo <= k && k <= hi && hi >= design_rattle_space(), "{p}");
    // No coarser than the thesis' band in 5 points.
    assert!(r.offsets_mm.len() as f64 >= (hi - lo) / ((0.8317 - 0.7684) / 4.0));
    // Tighter than the design family reaches: around the rail's own dimensions.
    let mut tight = LauncherDimensions::design().with_material_condition(-0.28);
    tight.f_shoe_mm -= 1.0;
    tight.h_shoe_mm -= 1.0;
    tight.j_shoe_mm -= 1.0;
    tight.l_shoe_mm -= 1.0;
    let k = tight.rattle_space().unwrap();
    assert!(k > 0.86);
    assert!(covering_sweep_params(&template, k, None).is_none());
    let p = covering_sweep_params(&template, k, Some(&tight)).unwrap();
    assert!(p["base_dimensions_mm"].is_object());
    let (lo, hi) = SweepRange::from_params(&p).unwrap().rattle_space_bounds();
    assert!(lo <= design_rattle_space() && k <= hi, "{p}");
}

#[test]
fn replicas_run_their_own_seeds_below_2_pow_53() {
    assert_eq!(replica_seed(7, 0), 7);
    assert_eq!(replica_seed(7, 2), 9);
    assert_eq!(replica_seed(limits::MAX_SEED, 1), 0);
    let plan =
        SweepPlan::from_params(&serde_json::json!({"points": 2, "seed": 5}), &configs()).unwrap();
    assert_eq!(plan.seeds, vec![5, 6, 7]);
    assert_eq!(plan.runs(), 6);
    assert_eq!(plan.run_index(1, 2), 5);
}

#[test]
fn a_point_child_summary_is_its_indices_and_the_flattened_point() {
    let point = crate::analysis::penalization::SweepPoint {
        offset_mm: Some(-0.125),
        rattle_space: 0.8,
        rail_wear_rate_mg_per_h: 2.5,
    };
    let summary = SweepPointSummary {
        point: 3,
        replica: 1,
        sweep: point,
    };
    let value = serde_json::to_value(summary).unwrap();
    assert_eq!(
        value,
        serde_json::json!({
            "point": 3,
            "replica": 1,
            "offset_mm": -0.125,
            "rattle_space": 0.8,
            "rail_wear_rate_mg_per_h": 2.5,
        })
    );
    assert_eq!(
        serde_json::from_value::<SweepPointSummary>(value).unwrap(),
        summary
    );
    // A point whose rattle space is unknown (NaN) writes null, as a json! summary did.
    let unknown = SweepPointSummary {
        sweep: crate::analysis::penalization::SweepPoint {
            rattle_space: f64::NAN,
            ..point
        },
        ..summary
    };
    assert_eq!(
        serde_json::to_value(unknown).unwrap()["rattle_space"],
        serde_json::Value::Null
    );
}

#[test]
fn a_curve_built_from_sweep_points_keeps_no_offsets() {
    use crate::analysis::penalization::{PenalizationCurve, SweepPoint};
    let point = |offset_mm, rattle_space, rail_wear_rate_mg_per_h| SweepPoint {
        offset_mm: Some(offset_mm),
        rattle_space,
        rail_wear_rate_mg_per_h,
    };
    let curve = PenalizationCurve::new(&[point(-0.1, 0.7, 2.0), point(0.1, 0.8, 1.0)], 0.75)
        .expect("curve");
    assert!(curve.points().iter().all(|p| p.offset_mm.is_none()));
    let value = serde_json::to_value(&curve).unwrap();
    assert_eq!(
        value["points"][0],
        serde_json::json!({"rattle_space": 0.7, "rail_wear_rate_mg_per_h": 2.0})
    );
}

#[test]
fn a_case_resolved_from_its_parts_is_the_case_of_the_same_params() {
    let overrides = serde_json::json!({"simulation": {"duration_s": 0.5}});
    let params = serde_json::json!({"config": "rattle-box-b", "overrides": overrides, "seed": 5});
    let by_params = resolve_case(&params, &configs(), |_| Ok(())).unwrap();
    let source = CaseSource::Reference("rattle-box-b");
    let by_parts =
        resolve_config(source, Some(&overrides), Some(5), &configs(), |_| Ok(())).unwrap();
    assert_eq!(by_parts, by_params);
    assert_eq!(by_parts.simulation.seed, 5);
    assert_eq!(by_parts.simulation.duration_s, 0.5);
    // Errors name the path as job params would.
    let bad = serde_json::json!({"simulation": {"duration_s": -1.0}});
    let e = resolve_config(source, Some(&bad), None, &configs(), |_| Ok(())).unwrap_err();
    assert_eq!(field_of(e), "overrides.simulation.duration_s");
    let e = resolve_config(
        CaseSource::Reference("no-such"),
        None,
        None,
        &configs(),
        |_| Ok(()),
    );
    assert_eq!(field_of(e.unwrap_err()), "config");
}

#[test]
fn every_reference_case_round_trips_through_its_plan_json() {
    for name in crate::models::reference::reference_config_names(&configs()) {
        let path = crate::models::reference::reference_config_path(&configs(), &name).unwrap();
        let plan = SimulatePlan {
            case: crate::models::case::load_case(&path).unwrap(),
        };
        let json = plan.to_json().unwrap();
        // Stored as text and read back, as the store does.
        let stored: serde_json::Value = serde_json::from_str(&json.to_string()).unwrap();
        assert_eq!(SimulatePlan::from_json(&stored).unwrap(), plan, "{name}");
    }
}
