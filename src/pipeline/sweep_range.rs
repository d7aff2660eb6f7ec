//! The rattle-space range of a tolerance sweep and the sweep that covers a given rail.

use super::{check_keys, limits, RunError, DEFAULT_SWEEP_SEEDS};
use crate::field_error::FieldError;

/// Material-condition offsets (mm) of an n-point sweep from tight to loose.
pub fn sweep_offsets_mm(n: usize) -> Vec<f64> {
    use crate::analysis::rattle_space::{LOOSE_MATERIAL_CONDITION_MM, TIGHT_MATERIAL_CONDITION_MM};
    let n = n.max(2);
    (0..n)
        .map(|i| {
            TIGHT_MATERIAL_CONDITION_MM
                + (LOOSE_MATERIAL_CONDITION_MM - TIGHT_MATERIAL_CONDITION_MM) * i as f64
                    / (n - 1) as f64
        })
        .collect()
}

/// The rattle-space range, points and seeds of a tolerance sweep, read from its params alone
/// (no config is loaded: the report reads it from a queued sweep's params to tell whether that
/// sweep will cover a rail).
///
/// Every point is `base.with_material_condition(offset)`: rail dimensions grow by the offset,
/// shoe dimensions shrink by it (docs/reference/launcher-dimensions.md). The range is given as one of
/// - `rattle_space_range: {"min": k1, "max": k2}`: points evenly spaced in k_rs, or
/// - `offset_mm_range: {"min": d1, "max": d2}`: points evenly spaced in the offset, mm,
/// - neither: the thesis' tolerance band, offsets -0.201 to +0.1955 mm (k_rs 0.8317 to 0.7684).
///
/// Bounds, with their reasons: every point's dimensions must pass the checks a measured rail
/// passes ([`LauncherDimensions::validate`]: assembly, +-50 % of design), so a sweep reaches
/// exactly the rails a planner can record; for the design base that is offsets in
/// (-0.30, +4.765] mm, k_rs about 0.28 to 0.848. The range must contain the design rattle
/// space, because K_SL is the ratio to the wear rate there (eq. 6.4). A rail tighter than the
/// design family reaches (a measured k_rs of 0.861) is covered by a sweep around its own
/// dimensions: `base_dimensions_mm` (default: the design rail).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepRange {
    /// Dimensions the offsets apply to, mm.
    pub base: LauncherDimensions,
    /// True when `base` is the design rail.
    pub design_base: bool,
    /// Offsets of the points, mm, tight to loose (increasing).
    pub offsets_mm: Vec<f64>,
    /// Rattle space of each point (eq. 6.1-6.3), decreasing.
    pub rattle_spaces: Vec<f64>,
    /// Seeds per point.
    pub seeds: usize,
}

use crate::analysis::rattle_space::LauncherDimensions;

/// Rattle space of `base` moved by `offset_mm`, if those dimensions are a valid rail.
fn offset_rattle_space(base: &LauncherDimensions, offset_mm: f64) -> Option<f64> {
    base.with_material_condition(offset_mm).rattle_space().ok()
}

/// The offsets (mm) over which `base` stays a valid rail ([`LauncherDimensions::validate`]):
/// each rule is linear in the offset, so they form an interval around 0; its ends are found by
/// bisection to 1e-9 mm and returned on the valid side.
pub fn offset_limits_mm(base: &LauncherDimensions) -> (f64, f64) {
    let valid = |o: f64| offset_rattle_space(base, o).is_some();
    let edge = |far: f64| {
        let (mut good, mut bad) = (0.0, far);
        if valid(far) {
            return far;
        }
        while (bad - good).abs() > 1e-9 {
            let mid = 0.5 * (good + bad);
            if valid(mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        good
    };
    (edge(-100.0), edge(100.0))
}

/// The offset (mm) at which `base` has rattle space `target`, within `limits`; k_rs falls as the
/// offset grows (looser). `None` if no offset in the limits reaches it to 1e-9.
fn offset_for_rattle_space(
    base: &LauncherDimensions,
    target: f64,
    limits: (f64, f64),
) -> Option<f64> {
    let k = |o: f64| offset_rattle_space(base, o).unwrap_or(f64::NAN);
    let (mut lo, mut hi) = limits;
    if !(k(lo) >= target && k(hi) <= target) {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if k(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-13 {
            break;
        }
    }
    let o = 0.5 * (lo + hi);
    ((k(o) - target).abs() < 1e-9).then_some(o)
}

/// `{"min": a, "max": b}` at `field`, with `a < b`, both finite.
fn parse_min_max(value: &serde_json::Value, field: &str) -> Result<(f64, f64), RunError> {
    let map = check_keys(value, field, &["min", "max"])?;
    let num = |name: &str| {
        map.get(name)
            .and_then(serde_json::Value::as_f64)
            .filter(|x| x.is_finite())
            .ok_or_else(|| {
                FieldError::new(format!("{field}.{name}"), "is required (a finite number)")
            })
    };
    let (min, max) = (num("min")?, num("max")?);
    if min >= max {
        return Err(FieldError::new(
            field,
            format!("needs min < max, got min {min} and max {max}"),
        )
        .into());
    }
    Ok((min, max))
}

impl SweepRange {
    /// Reads `points`, `seeds`, `base_dimensions_mm` and `rattle_space_range` or
    /// `offset_mm_range` (see the type's documentation); errors name the params field.
    pub fn from_params(params: &serde_json::Value) -> Result<Self, RunError> {
        let n = match params.get("points") {
            None => 5,
            Some(v) => v
                .as_u64()
                .filter(|n| limits::SWEEP_POINTS.contains(n))
                .ok_or_else(|| {
                    FieldError::new(
                        "points",
                        format!(
                            "must be an integer in {}..={}",
                            limits::SWEEP_POINTS.start(),
                            limits::SWEEP_POINTS.end()
                        ),
                    )
                })? as usize,
        };
        let seeds = match params.get("seeds") {
            None => DEFAULT_SWEEP_SEEDS,
            Some(v) => v
                .as_u64()
                .filter(|n| limits::SWEEP_SEEDS.contains(n))
                .ok_or_else(|| {
                    FieldError::new(
                        "seeds",
                        format!(
                            "must be an integer in {}..={} (seeds per point; 1 gives no \
                             confidence interval)",
                            limits::SWEEP_SEEDS.start(),
                            limits::SWEEP_SEEDS.end()
                        ),
                    )
                })?,
        };
        if n as u64 * seeds > limits::MAX_SWEEP_RUNS {
            return Err(FieldError::new(
                "seeds",
                format!(
                    "points x seeds = {} simulations; at most {} per sweep",
                    n as u64 * seeds,
                    limits::MAX_SWEEP_RUNS
                ),
            )
            .into());
        }
        let (base, design_base) = match params.get("base_dimensions_mm") {
            None => (LauncherDimensions::design(), true),
            Some(v) => {
                if !v.is_object() {
                    return Err(FieldError::new(
                        "base_dimensions_mm",
                        "must be an object of named dimensions in mm (as a measurement's \
                         dimensions_mm)",
                    )
                    .into());
                }
                let dims: LauncherDimensions = serde_path_to_error::deserialize(v.clone())
                    .map_err(|e| {
                        let path = e.path().to_string();
                        let field = if path == "." || path.is_empty() {
                            "base_dimensions_mm".to_string()
                        } else {
                            format!("base_dimensions_mm.{path}")
                        };
                        FieldError::new(&field, e.into_inner().to_string())
                    })?;
                crate::parameters::Bounded::check_bounds(
                    &dims,
                    &mut crate::parameters::FieldPath::new("base_dimensions_mm"),
                )?;
                dims.rattle_space().map_err(
                    |crate::analysis::rattle_space::RattleSpaceError::InvalidDimension(e)| {
                        e.at("base_dimensions_mm")
                    },
                )?;
                (dims, dims == LauncherDimensions::design())
            }
        };
        let limits_mm = offset_limits_mm(&base);
        let k_of = |o: f64| offset_rattle_space(&base, o).unwrap_or(f64::NAN);
        let (k_hi, k_lo) = (k_of(limits_mm.0), k_of(limits_mm.1));
        let spaced = |a: f64, b: f64| -> Vec<f64> {
            (0..n)
                .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
                .collect()
        };
        let (offsets_mm, field) = match (
            params.get("rattle_space_range"),
            params.get("offset_mm_range"),
        ) {
            (Some(_), Some(_)) => {
                return Err(FieldError::new(
                    "offset_mm_range",
                    "give either rattle_space_range or offset_mm_range, not both",
                )
                .into())
            }
            (Some(range), None) => {
                let (min, max) = parse_min_max(range, "rattle_space_range")?;
                if min < k_lo || max > k_hi {
                    return Err(FieldError::new(
                        "rattle_space_range",
                        format!(
                            "[{min}, {max}] leaves the rattle spaces the base dimensions reach \
                             as a valid rail, [{k_lo:.4}, {k_hi:.4}] (offsets {:.3} to {:.3} \
                             mm); for a tighter or looser rail give its own dimensions as \
                             base_dimensions_mm",
                            limits_mm.0, limits_mm.1
                        ),
                    )
                    .into());
                }
                let offsets = spaced(max, min)
                    .into_iter()
                    .map(|k| {
                        offset_for_rattle_space(&base, k, limits_mm).ok_or_else(|| {
                            FieldError::new(
                                "rattle_space_range",
                                format!("rattle space {k} is not reached by the base dimensions"),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                (offsets, "rattle_space_range")
            }
            (None, Some(range)) => {
                let (min, max) = parse_min_max(range, "offset_mm_range")?;
                if min < limits_mm.0 || max > limits_mm.1 {
                    return Err(FieldError::new(
                        "offset_mm_range",
                        format!(
                            "[{min}, {max}] mm leaves the offsets at which the base dimensions \
                             stay a valid rail, [{:.4}, {:.4}] mm (assembly and +-50 % of \
                             design, docs/reference/launcher-dimensions.md)",
                            limits_mm.0, limits_mm.1
                        ),
                    )
                    .into());
                }
                (spaced(min, max), "offset_mm_range")
            }
            (None, None) => (sweep_offsets_mm(n), "base_dimensions_mm"),
        };
        let rattle_spaces = offsets_mm
            .iter()
            .map(|&o| {
                offset_rattle_space(&base, o).ok_or_else(|| {
                    FieldError::new(
                        field,
                        format!(
                            "offset {o} mm does not give a valid rail from the base dimensions"
                        ),
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let design = design_rattle_space();
        let (k_min, k_max) = rattle_spaces
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &k| {
                (a.min(k), b.max(k))
            });
        if !(k_min <= design && design <= k_max) {
            return Err(FieldError::new(
                field,
                format!(
                    "gives rattle spaces [{k_min:.4}, {k_max:.4}], which must contain the design \
                     rattle space {design:.4}: K_SL is the ratio to the wear rate there (eq. 6.4)"
                ),
            )
            .into());
        }
        Ok(Self {
            base,
            design_base,
            offsets_mm,
            rattle_spaces,
            seeds: seeds as usize,
        })
    }

    /// Swept rattle-space range `(min, max)`.
    pub fn rattle_space_bounds(&self) -> (f64, f64) {
        self.rattle_spaces
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &k| {
                (a.min(k), b.max(k))
            })
    }
}

/// Rattle space of the design rail (eq. 6.1-6.3), 0.7990.
pub fn design_rattle_space() -> f64 {
    LauncherDimensions::design()
        .rattle_space()
        .unwrap_or(f64::NAN)
}

/// Params of a sweep whose range covers rattle space `k_rs` (and the design point), built on
/// `template` (the published curve's sweep params, or a bare sweep): its range is replaced by
/// `rattle_space_range` from `min(k_rs, design) - 0.005` to `max(k_rs, design) + 0.005`
/// (clipped to what a valid rail reaches), with no fewer points than the template nor a coarser
/// spacing than the thesis' band in 5 points. A k_rs the design family cannot reach (tighter
/// than its zero vertical clearance) gets `base_dimensions_mm` = the rail's own dimensions.
/// `None` when even the rail's own dimensions cannot span it.
pub fn covering_sweep_params(
    template: &serde_json::Value,
    k_rs: f64,
    rail: Option<&LauncherDimensions>,
) -> Option<serde_json::Value> {
    let design = design_rattle_space();
    let mut params = template.as_object().cloned().unwrap_or_default();
    for key in [
        "rattle_space_range",
        "offset_mm_range",
        "base_dimensions_mm",
        "seed",
    ] {
        params.remove(key);
    }
    let margin = 0.005;
    let candidates: Vec<(LauncherDimensions, bool)> =
        std::iter::once((LauncherDimensions::design(), true))
            .chain(rail.map(|r| (*r, false)))
            .collect();
    for (base, is_design) in candidates {
        let limits_mm = offset_limits_mm(&base);
        let k_of = |o: f64| offset_rattle_space(&base, o).unwrap_or(f64::NAN);
        // Keep a hair inside the valid interval so the ends are reachable by bisection.
        let (k_lo, k_hi) = (k_of(limits_mm.1), k_of(limits_mm.0));
        let lo = (k_rs.min(design) - margin).max(k_lo + 1e-6);
        let hi = (k_rs.max(design) + margin).min(k_hi - 1e-6);
        if !(lo <= k_rs.min(design) && hi >= k_rs.max(design) && lo < hi) {
            continue;
        }
        let thesis_spacing = (0.8317 - 0.7684) / 4.0;
        let template_points = template
            .get("points")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(5);
        let needed = ((hi - lo) / thesis_spacing).ceil() as u64 + 1;
        let seeds = template
            .get("seeds")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(DEFAULT_SWEEP_SEEDS)
            .max(1);
        let max_points = (limits::MAX_SWEEP_RUNS / seeds).min(*limits::SWEEP_POINTS.end());
        let points = needed.max(template_points).clamp(2, max_points);
        params.insert("points".into(), points.into());
        let (rlo, rhi) = (round_to(lo, 4, false), round_to(hi, 4, true));
        let rlo = if rlo > k_lo + 1e-6 { rlo } else { lo };
        let rhi = if rhi < k_hi - 1e-6 { rhi } else { hi };
        params.insert(
            "rattle_space_range".into(),
            serde_json::json!({"min": rlo, "max": rhi}),
        );
        if !is_design {
            params.insert(
                "base_dimensions_mm".into(),
                serde_json::to_value(base).unwrap_or_default(),
            );
        }
        let candidate = serde_json::Value::Object(params.clone());
        // The suggestion must itself be a valid range (rounding stays inside the limits).
        if SweepRange::from_params(&candidate).is_ok() {
            return Some(candidate);
        }
        params.remove("base_dimensions_mm");
    }
    None
}

/// `x` rounded to `digits` decimals, up or down.
fn round_to(x: f64, digits: i32, up: bool) -> f64 {
    let f = 10f64.powi(digits);
    let y = if up { (x * f).ceil() } else { (x * f).floor() };
    y / f
}

/// The seed of replica `replica` of a sweep seeded `seed`: `seed + replica` modulo 2^53, so
/// replica 0 runs the sweep's own seed (a one-seed sweep is the sweep of before) and every seed
/// stays below 2^53 ([`limits::MAX_SEED`]).
pub fn replica_seed(seed: u64, replica: usize) -> u64 {
    (seed.wrapping_add(replica as u64)) & limits::MAX_SEED
}
