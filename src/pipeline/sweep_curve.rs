//! A finished sweep's penalization curve (eq. 6.4, Figure 6.68): the geometric mean over seeds
//! at each point, its plot, and what the curve records about how it was made.

use super::{RunError, SweepOutcome, SweepPlan};
use crate::analysis::penalization::PenalizationCurve;

/// A finished sweep's curve: its outcome as the job's summary, the penalization curve (eq.
/// 6.4) with the rates of each seed, its plot, and the curve's fidelity and provenance.
#[derive(Debug, Clone)]
pub struct SweepCurve {
    /// The sweep's outcome (JSON).
    pub summary: serde_json::Value,
    /// The penalization curve.
    pub curve: PenalizationCurve,
    /// Its plot: (file name, SVG).
    pub plot: (String, String),
    /// Points of the curve.
    pub points: usize,
    /// Excited duration per point, s.
    pub duration_per_point_s: f64,
    /// Seeds per point.
    pub seeds: usize,
    /// Provenance (JSON object): config, vehicle_profile, environment, wear_law, range,
    /// offsets, base dimensions, settle, seeds, the face contact the runs used.
    pub provenance: serde_json::Value,
}

/// A sweep's curve from its outcome (sequential or assembled from its points' jobs).
pub fn sweep_curve(
    plan: &SweepPlan,
    params: &serde_json::Value,
    sweep: &SweepOutcome,
) -> Result<SweepCurve, RunError> {
    let ks: Vec<f64> = sweep.points.iter().map(|p| p.rattle_space).collect();
    let rates: Vec<Vec<f64>> = if sweep.rate_by_seed_mg_per_h.len() == ks.len() {
        sweep.rate_by_seed_mg_per_h.clone()
    } else {
        sweep
            .points
            .iter()
            .map(|p| vec![p.rail_wear_rate_mg_per_h])
            .collect()
    };
    let curve =
        PenalizationCurve::from_seeds(&ks, &rates, sweep.design_rattle_space).map_err(|e| {
            RunError::Diverged(format!("sweep produced no usable penalization curve: {e}"))
        })?;
    let (k_min, k_max) = plan.range.rattle_space_bounds();
    let config = match params.get("config") {
        None => serde_json::Value::from("launcher-design"),
        Some(serde_json::Value::String(name)) => serde_json::Value::from(name.as_str()),
        Some(_) => serde_json::Value::from("inline"),
    };
    // Which face contact the runs used (`face_contact`, with the lattice its points per edge):
    // the launcher's default changed from the lattice to the exact contact, and a curve must
    // say which one its rates come from.
    let contact = crate::models::case::face_contact_record(&plan.base)?;
    let mut provenance = serde_json::json!({
        "config": config,
        "overrides": params.get("overrides").cloned().unwrap_or(serde_json::Value::Null),
        "vehicle_profile": plan.vehicle_profile,
        "environment": plan.environment,
        "wear_law": plan.wear_law,
        "diagnosed_wear_law": plan.diagnosed,
        "points": plan.len(),
        "duration_per_point_s": plan.duration_per_point_s(),
        "settle_s": plan.base.simulation.settle_s,
        "seeds": plan.seeds,
        "rattle_space_range": {"min": k_min, "max": k_max},
        "offsets_mm": plan.offsets_mm,
        "base_dimensions_mm": plan.range.base,
        "design_base": plan.range.design_base,
    });
    if let (Some(map), serde_json::Value::Object(contact)) = (provenance.as_object_mut(), contact) {
        map.extend(contact);
    }
    let plot = crate::report::curve_plot(&curve);
    let summary = serde_json::to_value(sweep).map_err(|e| RunError::InvalidConfig {
        field: "sweep".into(),
        rule: e.to_string(),
    })?;
    Ok(SweepCurve {
        summary,
        curve,
        plot: ("penalization.svg".to_string(), plot),
        points: plan.len(),
        duration_per_point_s: plan.duration_per_point_s(),
        seeds: plan.seeds.len(),
        provenance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::penalization::SweepPoint;

    /// A sweep's curve names the face contact its runs used: the launcher's default (exact)
    /// when the sweep says nothing, and the lattice with its points per edge when an override
    /// names it.
    #[test]
    fn a_sweeps_curve_records_the_face_contact_its_runs_used() {
        let configs = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
        let provenance = |params: serde_json::Value| {
            let plan = SweepPlan::from_params(&params, &configs).expect("plan");
            // Three points of any wear rates: only the provenance is read here.
            let points = (0..3)
                .map(|i| SweepPoint {
                    offset_mm: None,
                    rattle_space: 0.2 + 0.1 * i as f64,
                    rail_wear_rate_mg_per_h: 1.0 + i as f64,
                })
                .collect();
            let outcome = SweepOutcome {
                design_rattle_space: 0.3,
                points,
                seeds: Vec::new(),
                rate_by_seed_mg_per_h: Vec::new(),
            };
            sweep_curve(&plan, &params, &outcome)
                .expect("curve")
                .provenance
        };
        let exact = provenance(serde_json::json!({"config": "launcher-design"}));
        assert_eq!(exact["face_contact"], "exact", "{exact}");
        assert!(exact.get("contact_points_per_edge").is_none(), "{exact}");
        let lattice = provenance(serde_json::json!({
            "config": "launcher-design",
            "overrides": {"simulation": {"face_contact": "lattice", "contact_points_per_edge": 9}},
        }));
        assert_eq!(lattice["face_contact"], "lattice", "{lattice}");
        assert_eq!(lattice["contact_points_per_edge"], 9, "{lattice}");
    }
}
