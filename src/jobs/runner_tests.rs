//! A simulate job is parsed and checked once at submission into its typed plan, and each
//! attempt runs that plan with one validation and one model build (issue 30 item 1).

use super::model::JobKind;
use super::runner::{CaseRunner, LibraryRunner};
use crate::models::counts;
use crate::pipeline::{RunControl, SimulatePlan};
use serde_json::json;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

#[test]
fn a_simulate_attempt_validates_and_builds_its_case_once() {
    let runner = LibraryRunner::new(configs());
    let kind = JobKind::Simulate;
    // What the worker hands the runner for a job planned from its params: them with its seed.
    let params = json!({
        "config": "rattle-box-c",
        "overrides": {"simulation": {"settle_s": 0.01, "duration_s": 0.01}},
        "seed": 7,
    });
    counts::take();
    // At submission: the params as submitted (here without the seed) and the job's seed.
    let mut submitted = params.clone();
    submitted.as_object_mut().unwrap().remove("seed");
    let plan = runner
        .submit_plan(&kind, &submitted, 7)
        .expect("a valid job")
        .expect("a simulate job has a plan");
    // Submission: the merged case validated once, and built once to prove it builds.
    assert_eq!(
        counts::take(),
        (1, 1),
        "(validations, builds) at submission"
    );
    assert_eq!(plan["case"]["simulation"]["seed"], json!(7));
    assert_eq!(plan["case"]["simulation"]["duration_s"], json!(0.01));

    let control = RunControl::silent();
    let from_plan = runner
        .run_from(&kind, &params, Some(&plan), &control, None)
        .expect("the attempt runs");
    assert_eq!(counts::take(), (1, 1), "(validations, builds) per attempt");
    // A second attempt of the same job does the same, and gets the same result bit for bit.
    let again = runner
        .run_from(&kind, &params, Some(&plan), &control, None)
        .expect("the attempt runs");
    assert_eq!(counts::take(), (1, 1), "(validations, builds) per attempt");
    assert_eq!(again.tracks, from_plan.tracks);
    assert_eq!(again.summary, from_plan.summary);
    // A job stored without a plan (queued before plans were stored) is planned from its
    // params, to the same result.
    let from_params = runner
        .run_from(&kind, &params, None, &control, None)
        .expect("the attempt runs");
    assert!(!from_plan.tracks.is_empty());
    assert_eq!(from_params.tracks, from_plan.tracks);
    assert_eq!(from_params.summary, from_plan.summary);
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

#[test]
fn a_stored_plan_that_is_not_one_is_refused_naming_it() {
    let runner = LibraryRunner::new(configs());
    let err = runner
        .run_from(
            &JobKind::Simulate,
            &json!({}),
            Some(&json!({"case": 1})),
            &RunControl::silent(),
            None,
        )
        .unwrap_err();
    assert!(
        matches!(&err, crate::pipeline::RunError::InvalidConfig { field, .. } if field == "plan"),
        "{err}"
    );
}
