//! The bench's interval coverage: each fitted parameter's 95 % interval against the value the
//! rig drew, per parameter and kind.

use super::Outcome;
use std::collections::BTreeMap;

/// Every fitted parameter of `o` with an interval whose effect the rig injected: (is it the
/// effect's magnitude, does the interval hold the drawn value). The check the issue asks of
/// every effect ("the diagnosis recovers its magnitude within the reported interval"), on
/// campaigns drawn unlike the bench's defaults.
pub(super) fn interval_hits(o: &Outcome) -> Vec<(bool, bool)> {
    parameter_hits(o).into_iter().map(|h| (h.1, h.2)).collect()
}

/// [`interval_hits`] with each parameter's name and whether the report gave it identified:
/// (name, is it the magnitude, does the interval hold the drawn value, identified).
fn parameter_hits(o: &Outcome) -> Vec<(String, bool, bool, bool)> {
    o.fitted
        .iter()
        .filter(|f| f.fitted)
        .filter_map(|f| {
            let [lo, hi] = f.interval?;
            let (effect, parameter) = f.name.split_once('.')?;
            let drawn = o.scenario.effects.iter().find(|e| e.name == effect)?;
            let info = crate::gap::effects::info(effect)?;
            let value = *drawn.parameters.get(parameter)?;
            let magnitude = info.parameters.first().is_some_and(|p| p.name == parameter);
            Some((
                f.name.clone(),
                magnitude,
                holds([lo, hi], value),
                f.identified,
            ))
        })
        .collect()
}

/// `Scores::coverage_by_parameter` of the outcomes whose leading candidate is the truth.
pub(super) fn coverage_by_parameter<'a>(
    led_right: impl Iterator<Item = &'a Outcome>,
) -> BTreeMap<String, [usize; 3]> {
    let mut out: BTreeMap<String, [usize; 3]> = BTreeMap::new();
    for (name, magnitude, held, identified) in led_right
        .filter(|o| o.scenario.in_library)
        .flat_map(parameter_hits)
    {
        let kind = if magnitude {
            "magnitudes"
        } else {
            "secondary parameters"
        };
        for key in [name, kind.to_string()] {
            let row = out.entry(key).or_default();
            row[0] += 1;
            row[1] += usize::from(held);
            row[2] += usize::from(identified);
        }
    }
    out
}

/// Whether `[lo, hi]` holds `value`, to round-off: the diagnosis' candidate magnitudes are
/// computed between grid points (0.01875 + 3/5 of 0.00375 = 0.020999999999999998) and the
/// rig draws the value as written (0.021), so an endpoint within 1e-9 of the value,
/// relative, holds it.
pub(super) fn holds([lo, hi]: [f64; 2], value: f64) -> bool {
    let tol = 1e-9 * lo.abs().max(hi.abs()).max(value.abs());
    lo - tol <= value && value <= hi + tol
}
