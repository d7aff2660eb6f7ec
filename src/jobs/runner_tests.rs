//! Every job kind is parsed and checked once at submission into its typed plan, and each
//! attempt runs that plan: one case validation and one model build where a model is built,
//! none where it is not, and a diagnosis does not validate its stored campaign again (issue 30
//! items 1 and 2).

use super::model::JobKind;
use super::runner::{CaseRunner, JobInputs, JobPlan, LibraryRunner, StoredInput};
use crate::pipeline::{counts, RunControl, RunError};
use serde_json::json;
use std::path::{Path, PathBuf};

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

/// No stored inputs.
fn none() -> JobInputs {
    JobInputs::default()
}

/// `params` as the worker hands them to the runner: with the job's seed.
fn with_seed(params: &serde_json::Value, seed: u64) -> serde_json::Value {
    let mut params = params.clone();
    params["seed"] = json!(seed);
    params
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
        .run_from(&kind, &params, Some(&plan), &none(), &control, None)
        .expect("the attempt runs");
    assert_eq!(counts::take(), (1, 1), "(validations, builds) per attempt");
    // A second attempt of the same job does the same, and gets the same result bit for bit.
    let again = runner
        .run_from(&kind, &params, Some(&plan), &none(), &control, None)
        .expect("the attempt runs");
    assert_eq!(counts::take(), (1, 1), "(validations, builds) per attempt");
    assert_eq!(again.tracks, from_plan.tracks);
    assert_eq!(again.summary, from_plan.summary);
    // A job stored without a plan (queued before plans were stored) is planned from its
    // params, to the same result.
    let from_params = runner
        .run_from(&kind, &params, None, &none(), &control, None)
        .expect("the attempt runs");
    assert!(!from_plan.tracks.is_empty());
    assert_eq!(from_params.tracks, from_plan.tracks);
    assert_eq!(from_params.summary, from_plan.summary);
}

#[test]
fn a_stored_plan_that_is_not_one_is_refused_naming_it() {
    let runner = LibraryRunner::new(configs());
    let err = runner
        .run_from(
            &JobKind::Simulate,
            &json!({}),
            Some(&json!({"case": 1})),
            &none(),
            &RunControl::silent(),
            None,
        )
        .unwrap_err();
    assert!(
        matches!(&err, RunError::InvalidConfig { field, .. } if field == "plan"),
        "{err}"
    );
}

#[test]
fn a_sweep_is_planned_once_and_its_points_run_their_plans() {
    let runner = LibraryRunner::new(configs());
    let kind = JobKind::Sweep;
    let submitted = json!({
        "overrides": {"simulation": {"settle_s": 0.002, "duration_s": 0.002,
            "record_interval_s": 0.002}},
        "points": 2,
        "seeds": 1,
    });
    let params = with_seed(&submitted, 11);
    counts::take();
    let plan = runner
        .submit_plan(&kind, &submitted, 11)
        .expect("a valid sweep")
        .expect("a sweep has a plan");
    assert_eq!(
        counts::take(),
        (1, 1),
        "(validations, builds) at submission"
    );
    // The job's seed is in the plan, though the params as submitted had none.
    assert_eq!(plan["base"]["simulation"]["seed"], json!(11));
    assert_eq!(plan["point"], serde_json::Value::Null);

    // The fan-out attempt reads the plan: nothing validated or built.
    let fan_out = runner
        .fan_out(&kind, &params, Some(&plan))
        .expect("fans out")
        .expect("a sweep fans out");
    assert_eq!(
        counts::take(),
        (0, 0),
        "(validations, builds) of the fan-out"
    );
    assert_eq!(fan_out.children.len(), 2);
    // Planned from the params (a sweep stored before plans were), the same children.
    let from_params = runner.fan_out(&kind, &params, None).unwrap().unwrap();
    assert_eq!(from_params, fan_out);
    counts::take();

    let control = RunControl::silent();
    let mut summaries = Vec::new();
    for (index, child) in fan_out.children.iter().enumerate() {
        assert_eq!(child.kind, JobKind::SweepPoint);
        let child_plan = child.plan.as_ref().expect("a child has a plan");
        let out = runner
            .run_from(
                &child.kind,
                &child.params,
                Some(child_plan),
                &none(),
                &control,
                None,
            )
            .expect("the point runs");
        assert_eq!(
            counts::take(),
            (1, 1),
            "(validations, builds) per point attempt"
        );
        if index == 0 {
            // A child stored without a plan is planned from its params, to the same point.
            let from_params = runner
                .run_from(&child.kind, &child.params, None, &none(), &control, None)
                .expect("the point runs");
            assert_eq!(from_params.summary, out.summary);
            counts::take();
        }
        summaries.push(out.summary);
    }
    let assembled = runner
        .assemble(&kind, &params, Some(&plan), &summaries)
        .expect("assembles");
    assert_eq!(
        counts::take(),
        (0, 0),
        "(validations, builds) of the assembly"
    );
    let from_params = runner.assemble(&kind, &params, None, &summaries).unwrap();
    assert_eq!(assembled.summary, from_params.summary);
    assert_eq!(assembled.curve_info, from_params.curve_info);
}

#[test]
fn a_calibration_is_planned_once() {
    let runner = LibraryRunner::new(configs());
    let kind = JobKind::Calibrate;
    let records: Vec<_> = (0..4)
        .map(|i| {
            json!({"normal_load_n": 10.0 * f64::from(i + 1), "contact_pressure_pa": 1e7,
                "sliding_distance_m": 100.0, "wear_mass_kg": 1e-9 * f64::from(i + 1)})
        })
        .collect();
    let submitted = json!({"wear_law": {"records": records}});
    let plan = runner
        .submit_plan(&kind, &submitted, 3)
        .expect("valid data")
        .expect("a calibration has a plan");
    assert_eq!(plan["wear_law"]["density_kg_m3"], json!(2810.0));
    let control = RunControl::silent();
    counts::take();
    let params = with_seed(&submitted, 3);
    let from_plan = runner.run_from(&kind, &params, Some(&plan), &none(), &control, None);
    let from_params = runner.run_from(&kind, &params, None, &none(), &control, None);
    assert_eq!(counts::take(), (0, 0), "a calibration builds no model");
    match (from_plan, from_params) {
        (Ok(a), Ok(b)) => assert_eq!(a.summary, b.summary),
        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
        (a, b) => panic!("the plan and the params disagree: {a:?} / {b:?}"),
    }
}

/// A diagnosis of the test fixture's campaign: its params as the service stores them.
fn diagnosis_params() -> (serde_json::Value, String) {
    let text = include_str!("../../tests/fixtures/small-campaign.toml");
    let campaign = crate::pipeline::Campaign::from_toml_str(text, Path::new(".")).unwrap();
    let content = serde_json::to_string(&campaign).unwrap();
    let sha = super::hex(&sha2::Sha256::digest(content.as_bytes()));
    let params = json!({
        "campaign_id": "6f1c1c64-0f4e-4d57-9a53-0d7c2b3a1e10",
        "campaign_sha256": sha,
        "window_s": 0.1,
        "grid_points": 2,
        "effects": ["third_body"],
    });
    (params, content)
}

use sha2::Digest;

#[test]
fn a_diagnosis_is_planned_once_and_reads_its_campaign_without_validating_it() {
    let runner = LibraryRunner::new(configs());
    let kind = JobKind::Diagnose;
    let (submitted, content) = diagnosis_params();
    counts::take_campaign_validations();
    let plan = runner
        .submit_plan(&kind, &submitted, 5)
        .expect("valid options")
        .expect("a diagnosis has a plan");
    assert_eq!(plan["window_s"], json!(0.1));
    let JobPlan::Diagnose(parsed) = JobPlan::from_json(&kind, &plan).unwrap() else {
        panic!("a diagnose plan");
    };
    assert_eq!(parsed.options().emulator.grid_points, 2);
    // What the worker reads for it.
    let params = with_seed(&submitted, 5);
    let wanted = runner.stored_inputs(&kind, &params, Some(&plan)).unwrap();
    assert_eq!(
        wanted,
        [StoredInput::Campaign {
            id: parsed.campaign_id,
            sha256: submitted["campaign_sha256"].as_str().unwrap().to_string(),
        }]
    );
    assert_eq!(runner.stored_inputs(&kind, &params, None).unwrap(), wanted);
    // Without the campaign read, the attempt says so; with it, it runs (stopped here before
    // its first simulation) without validating the campaign again.
    let control = RunControl::silent();
    let err = runner
        .run_from(&kind, &params, Some(&plan), &none(), &control, None)
        .unwrap_err();
    assert!(
        matches!(&err, RunError::InvalidConfig { field, .. } if field == "campaign_id"),
        "{err}"
    );
    control
        .cancel
        .store(true, std::sync::atomic::Ordering::Relaxed);
    let inputs = JobInputs {
        campaign: Some(content),
    };
    let stopped = runner.run_from(&kind, &params, Some(&plan), &inputs, &control, None);
    assert!(matches!(stopped, Err(RunError::Cancelled)), "{stopped:?}");
    assert_eq!(
        counts::take_campaign_validations(),
        0,
        "campaign validations at submission and per attempt"
    );
}

#[test]
fn every_kind_refuses_a_stored_plan_of_another() {
    let (params, _) = diagnosis_params();
    let runner = LibraryRunner::new(configs());
    let plan = runner
        .submit_plan(&JobKind::Diagnose, &params, 1)
        .unwrap()
        .unwrap();
    for kind in [
        JobKind::Simulate,
        JobKind::Sweep,
        JobKind::SweepPoint,
        JobKind::Calibrate,
    ] {
        let err = JobPlan::from_json(&kind, &plan).unwrap_err();
        assert!(
            matches!(&err, RunError::InvalidConfig { field, .. } if field == "plan"),
            "{}: {err}",
            kind.as_str()
        );
    }
}

#[test]
fn a_diagnosis_reads_100_percent_only_once_its_report_is_made() {
    // The small campaign's diagnosis, run to its end with every progress call kept.
    let runner = LibraryRunner::new(configs());
    let kind = JobKind::Diagnose;
    let (submitted, content) = diagnosis_params();
    let plan = runner.submit_plan(&kind, &submitted, 5).unwrap().unwrap();
    let calls = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let kept = calls.clone();
    let control = RunControl {
        progress: std::sync::Arc::new(move |p| kept.lock().unwrap().push(p)),
        ..RunControl::silent()
    };
    let inputs = JobInputs {
        campaign: Some(content),
    };
    runner
        .run_from(
            &kind,
            &with_seed(&submitted, 5),
            Some(&plan),
            &inputs,
            &control,
            None,
        )
        .expect("the diagnosis runs");
    let calls = calls.lock().unwrap();
    let (last, before) = calls.split_last().expect("progress was reported");
    // The final stage counts: 100 % is the last call, made after the report, and no call
    // before it reads 100 %.
    assert_eq!(last.fraction, 1.0);
    assert_eq!(last.simulated_time_s, last.end_time_s);
    assert!(before.len() >= 2, "{} calls", calls.len());
    for p in before {
        assert!(
            p.fraction < 1.0,
            "{} of {} units read {} before the report was made",
            p.simulated_time_s,
            p.end_time_s,
            p.fraction
        );
    }
}
