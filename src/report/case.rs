//! A finished case run ([`crate::models::case_run`]) packaged into its outcome: the summary
//! JSON, the tracks and the plots ([`super::plots`]). Running it is the model's; the two are
//! put together by `pipeline::run_case`.

use super::plots::case_plots;
use crate::analysis::spectra::welch_psd;
use crate::analysis::vdv::vibration_dose_value_uniform;
use crate::models::case::code_version;
use crate::models::case_run::CaseRun;
use crate::models::outcome::CaseOutcome;
use crate::models::run::{BuiltModel, RunOptions, RunReport};
use crate::models::spec::{CaseSpec, ModelSpecRef};
use serde_json::{json, Value};

/// A finished case run packaged: its raw report and its outcome. The track samples move to
/// the outcome (the report's `tracks` is left empty): a long run holds them once (a 60 s
/// launcher run records ~0.7 million).
pub fn package_run(case: &CaseSpec, run: CaseRun) -> (RunReport, CaseOutcome) {
    let CaseRun {
        model,
        options,
        mut report,
    } = run;
    let tracks = std::mem::take(&mut report.tracks);
    let (summary, plots) = package_parts(case, &model, &options, &report, tracks.len());
    (
        report,
        CaseOutcome {
            summary,
            tracks,
            plots,
        },
    )
}

/// Summary JSON and plots of a finished run.
pub fn package(
    case: &CaseSpec,
    model: &BuiltModel,
    options: &RunOptions,
    r: &RunReport,
) -> CaseOutcome {
    let (summary, plots) = package_parts(case, model, options, r, r.tracks.len());
    CaseOutcome {
        summary,
        tracks: r.tracks.clone(),
        plots,
    }
}

/// The summary JSON and the plots of a finished run with `track_samples` recorded samples.
fn package_parts(
    case: &CaseSpec,
    model: &BuiltModel,
    options: &RunOptions,
    r: &RunReport,
    track_samples: usize,
) -> (Value, Vec<(String, String)>) {
    let simulated = model.end_time_s;
    let rattle_space = match case.model_spec() {
        Ok(ModelSpecRef::RattleBox(s)) => s.rattle_space().ok(),
        Ok(ModelSpecRef::Launcher(s)) => s.rattle_space().ok(),
        _ => None,
    };
    let dt = 1.0 / r.response_rate_hz;
    let resp_x: Vec<f64> = r.response_acceleration.iter().map(|a| a[0]).collect();
    let vdv = vibration_dose_value_uniform(&resp_x, dt).ok();
    let psd = welch_psd(&resp_x, r.response_rate_hz, 512.min(resp_x.len().max(4))).ok();
    let summary = json!({
        "name": case.name,
        "model": case.model,
        "code_version": code_version(),
        "seed": case.simulation.seed,
        "config": case,
        "rattle_space": rattle_space,
        "integrator": {
            "kind": options.integrator.kind.name(),
            "tolerances": options.integrator.tolerances,
            "stats": r.integrator,
            "note": "wall-clock timings are kept out of the summary so results are reproducible; the job record holds durations",
        },
        "simulated_s": simulated,
        "window_s": r.window_s,
        "rate_window": r.rate_window,
        "mean_normal_force_n": r.mean_normal_force_n,
        "mean_normal_slip_power_w": r.mean_normal_slip_power_w,
        "mean_friction_power_w": r.mean_friction_power_w,
        "contacts": r.contacts,
        "bodies": r.bodies,
        "energy": r.energy,
        "response": {
            "body": model.system.bodies[model.response_body].name,
            "vdv_x_m_s2": vdv,
            "psd_x": psd.as_ref().map(|p| json!({"frequency_hz": p.frequency_hz, "density_m2_s4_per_hz": p.density})),
        },
        "track_samples": track_samples,
        "reduced_face_law": reduced_face_law(model),
    });
    (summary, case_plots(case, r, psd.as_ref()))
}

/// How the reduced face law (`face_contact = "reduced"`) took its parts over the run, per
/// contact that uses it: parts in closed form and at nodes, the share in closed form, and the
/// largest friction estimate accepted against the tolerance; null when no contact uses it.
fn reduced_face_law(model: &BuiltModel) -> Value {
    use crate::physics::contact::FaceContact;
    let rows: Vec<Value> = model
        .system
        .contacts
        .iter()
        .filter(|c| c.face_contact == FaceContact::Reduced)
        .map(|c| {
            let share = c.reduced_census.snapshot();
            json!({
                "contact": c.name,
                "closed_form_parts": share.closed_parts,
                "per_node_parts": share.per_node_parts,
                "closed_form_share": share.closed_share(),
                "largest_estimate": share.largest_estimate,
                "tolerance": c.reduced_tolerance,
            })
        })
        .collect();
    if rows.is_empty() {
        Value::Null
    } else {
        Value::Array(rows)
    }
}
