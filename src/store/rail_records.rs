//! The records of the rail registry (rails, their measurements) and of the penalization curves
//! (versions per key, fidelity, publication), with the curve helpers shared by both stores.

use super::{PageRequest, Store, StoreError};
use uuid::Uuid;

/// A registered rail.
#[derive(Debug, Clone, PartialEq, sqlx::FromRow)]
pub struct RailRecord {
    pub serial: String,
    pub seq: i64,
    pub created_ms: i64,
    pub measurements: i64,
}

/// A rail measurement to insert (the rail is registered on first measurement).
#[derive(Debug, Clone)]
pub struct NewMeasurement {
    pub id: Uuid,
    pub serial: String,
    /// Dimensions as posted, mm (JSON object).
    pub dimensions_mm: serde_json::Value,
    pub measured_by: String,
    pub measured_at: String,
    /// `measured_at` as Unix ms (what "latest" is ordered by).
    pub measured_ms: i64,
    pub location: String,
    /// Rattle space k_rs computed from the dimensions (eq. 6.1-6.3), dimensionless.
    pub rattle_space: f64,
    pub recorded_by: String,
    pub recorded_ms: i64,
}

/// A stored rail measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementRecord {
    pub id: Uuid,
    pub seq: i64,
    pub serial: String,
    pub dimensions_mm: serde_json::Value,
    pub measured_by: String,
    pub measured_at: String,
    /// `measured_at` as Unix ms.
    pub measured_ms: i64,
    pub location: String,
    pub rattle_space: f64,
    pub recorded_by: String,
    pub recorded_ms: i64,
}

/// How much simulation stands behind a curve: publishing one with less of any of these over
/// the published one needs `force` ([`CurveFidelity::shortfall`]), as does one swept on the
/// contact-point lattice over one swept with the exact face contact (their provenance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveFidelity {
    /// Points of the sweep (distinct rattle spaces).
    pub points: i64,
    /// Excited simulated duration of each run, s; `None` for curves migrated from before
    /// issue 17, whose duration was not recorded.
    pub duration_per_point_s: Option<f64>,
    /// Seeds (independent runs) per point.
    pub seeds: i64,
}

impl CurveFidelity {
    /// Why `self` is a lower fidelity than `other`, or `None` when it is not: fewer points,
    /// a shorter duration per point (when both are known) or fewer seeds per point.
    pub fn shortfall(&self, other: &CurveFidelity) -> Option<String> {
        let mut why = Vec::new();
        if self.points < other.points {
            why.push(format!("{} points < {}", self.points, other.points));
        }
        if let (Some(a), Some(b)) = (self.duration_per_point_s, other.duration_per_point_s) {
            if a < b {
                why.push(format!("{a} s per point < {b} s"));
            }
        }
        if self.seeds < other.seeds {
            why.push(format!("{} seeds per point < {}", self.seeds, other.seeds));
        }
        (!why.is_empty()).then(|| why.join(", "))
    }
}

/// A penalization curve a successful sweep stores: a new version under its key, not published.
#[derive(Debug, Clone, PartialEq)]
pub struct NewCurve {
    /// `vehicle_profile/environment/wear_law`.
    pub key: String,
    pub job_id: Uuid,
    /// Curve data (JSON of `analysis::penalization::PenalizationCurve`).
    pub curve: serde_json::Value,
    pub fidelity: CurveFidelity,
    /// Provenance (JSON object): config, vehicle_profile, environment, wear_law, range, seeds,
    /// duration per point, code version, created by.
    pub provenance: serde_json::Value,
    /// Token name of who submitted the sweep.
    pub created_by: String,
    pub code_version: String,
    pub created_ms: i64,
}

/// When and by whom a curve was made the one reports use.
#[derive(Debug, Clone, PartialEq)]
pub struct Publication {
    pub published_by: String,
    pub published_ms: i64,
}

/// A stored curve version.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveRecord {
    /// Store-wide id (`/v1/curves/{id}`).
    pub id: i64,
    /// `vehicle_profile/environment/wear_law`.
    pub key: String,
    /// 1, 2, ... per key, in the order sweeps stored them.
    pub version: i64,
    pub job_id: Uuid,
    pub curve: serde_json::Value,
    pub fidelity: CurveFidelity,
    pub provenance: serde_json::Value,
    pub created_by: String,
    pub code_version: String,
    pub created_ms: i64,
    /// Present while this version is the published one of its key.
    pub published: Option<Publication>,
}

/// What [`Store::publish_curve`] did.
#[derive(Debug, Clone, PartialEq)]
pub enum PublishOutcome {
    /// The version is now the one reports use (also when it already was).
    Published(CurveRecord),
    /// Refused without `force`: the version has a lower fidelity than the published one
    /// (`reason` from [`CurveFidelity::shortfall`], and a face contact coarser than the
    /// published one's, from their provenance). Nothing changed.
    LowerFidelity {
        published: CurveRecord,
        reason: String,
    },
    /// No curve with that id.
    NotFound,
}

/// Which curves a list shows.
#[derive(Debug, Clone, Default)]
pub struct CurveFilter {
    /// Only this key.
    pub key: Option<String>,
}

/// The newest stored version of `key`, published or not.
pub async fn latest_curve(store: &dyn Store, key: &str) -> Result<Option<CurveRecord>, StoreError> {
    let page = store
        .list_curves(
            PageRequest {
                limit: 1,
                after_seq: None,
            },
            CurveFilter {
                key: Some(key.to_string()),
            },
        )
        .await?;
    Ok(page.items.into_iter().next())
}

/// The refusal of [`Store::publish_curve`] given the candidate and the published version, or
/// `None` when it may be published.
pub fn publish_refusal(
    candidate: &CurveRecord,
    published: Option<&CurveRecord>,
    force: bool,
) -> Option<PublishOutcome> {
    match published {
        Some(current) if current.id != candidate.id && !force => {
            let why: Vec<String> = [
                candidate.fidelity.shortfall(&current.fidelity),
                contact_shortfall(&candidate.provenance, &current.provenance),
            ]
            .into_iter()
            .flatten()
            .collect();
            (!why.is_empty()).then(|| PublishOutcome::LowerFidelity {
                published: current.clone(),
                reason: why.join(", "),
            })
        }
        _ => None,
    }
}

/// Why a curve whose provenance is `candidate` rests on a coarser face contact than one whose
/// provenance is `published`, or `None`: swept on the contact-point lattice against the exact
/// face contact, the lattice's continuum limit (docs/reference/models.md "Exact face contact"; the
/// launcher's 5-point lattice is 2-4 % off its wear rates). Curves swept before the face
/// contact was recorded (no `face_contact` in their provenance) are not compared.
fn contact_shortfall(
    candidate: &serde_json::Value,
    published: &serde_json::Value,
) -> Option<String> {
    fn contact(provenance: &serde_json::Value) -> Option<&str> {
        provenance.get("face_contact")?.as_str()
    }
    match (contact(candidate)?, contact(published)?) {
        ("lattice", "exact") => {
            let points = candidate
                .get("contact_points_per_edge")
                .and_then(|v| v.as_u64())
                .map(|n| format!(" ({n} points per edge)"))
                .unwrap_or_default();
            Some(format!(
                "swept on the contact-point lattice{points} < the exact face contact"
            ))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(id: i64, seeds: i64, provenance: serde_json::Value) -> CurveRecord {
        CurveRecord {
            id,
            key: "ah64/clean/modified-archard".into(),
            version: id,
            job_id: Uuid::nil(),
            curve: serde_json::Value::Null,
            fidelity: CurveFidelity {
                points: 7,
                duration_per_point_s: Some(10.0),
                seeds,
            },
            provenance,
            created_by: "eng".into(),
            code_version: "test".into(),
            created_ms: 0,
            published: None,
        }
    }

    #[test]
    fn a_lattice_curve_over_an_exact_one_needs_force_and_unrecorded_contacts_are_not_compared() {
        let exact = serde_json::json!({"face_contact": "exact"});
        let lattice = serde_json::json!({"face_contact": "lattice", "contact_points_per_edge": 5});
        let published = curve(1, 3, exact.clone());
        let refused = publish_refusal(&curve(2, 3, lattice.clone()), Some(&published), false);
        match refused {
            Some(PublishOutcome::LowerFidelity { reason, .. }) => {
                assert!(reason.contains("lattice (5 points per edge)"), "{reason}")
            }
            other => panic!("expected a refusal, got {other:?}"),
        }
        // With force, or the other way round, or with a contact not recorded: published.
        assert_eq!(
            publish_refusal(&curve(2, 3, lattice.clone()), Some(&published), true),
            None
        );
        let on_lattice = curve(1, 3, lattice.clone());
        assert_eq!(
            publish_refusal(&curve(2, 3, exact.clone()), Some(&on_lattice), false),
            None
        );
        let unrecorded = curve(1, 3, serde_json::json!({}));
        assert_eq!(
            publish_refusal(&curve(2, 3, lattice.clone()), Some(&unrecorded), false),
            None
        );
        // Both reasons at once are both named.
        match publish_refusal(&curve(2, 1, lattice), Some(&published), false) {
            Some(PublishOutcome::LowerFidelity { reason, .. }) => {
                assert!(reason.contains("1 seeds per point < 3"), "{reason}");
                assert!(reason.contains("exact face contact"), "{reason}");
            }
            other => panic!("expected a refusal, got {other:?}"),
        }
    }
}
