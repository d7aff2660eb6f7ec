//! An axis as plotters maps it: the scale (linear, log, symmetric log, or chosen on the
//! data), the range rounded out to round ticks, and the tick labels.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, KeyPointWeight, Ranged};
use std::ops::Range;

/// Axis scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic.
    Log10,
    /// Symmetric base-10 log: linear within `linear_within` of zero, logarithmic beyond, for
    /// data of both signs that span decades.
    SymLog10 { linear_within: f64 },
    /// [`Scale::Log10`] or [`Scale::SymLog10`] where the magnitudes span more than two decades,
    /// else [`Scale::Linear`]: decided on the data when the figure is drawn.
    Auto,
}

/// One axis: label (with its unit, e.g. "frequency (Hz)"), scale and optional fixed range.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisSpec {
    /// Label including the unit.
    pub label: String,
    /// Scale.
    pub scale: Scale,
    /// Fixed `(min, max)`; `None` fits the data (rounded out to ticks or whole decades).
    pub range: Option<(f64, f64)>,
}

impl AxisSpec {
    /// Linear axis fitted to the data.
    pub fn linear(label: impl Into<String>) -> Self {
        Self::with_scale(label, Scale::Linear)
    }

    /// Log axis fitted to the data.
    pub fn log(label: impl Into<String>) -> Self {
        Self::with_scale(label, Scale::Log10)
    }

    /// Log axis where the data span more than two decades, linear otherwise ([`Scale::Auto`]).
    pub fn auto(label: impl Into<String>) -> Self {
        Self::with_scale(label, Scale::Auto)
    }

    fn with_scale(label: impl Into<String>, scale: Scale) -> Self {
        Self {
            label: label.into(),
            scale,
            range: None,
        }
    }

    /// Same axis with a fixed range.
    pub fn with_range(mut self, min: f64, max: f64) -> Self {
        self.range = Some((min, max));
        self
    }
}

/// Whether the magnitudes of the finite, non-zero `values` span more than two decades.
pub fn spans_decades(values: impl IntoIterator<Item = f64>) -> bool {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite() && *v != 0.0)
        .map(f64::abs)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    hi > 100.0 * lo
}

/// The scale `Auto` resolves to on `values` (other scales stay).
pub(super) fn resolve(scale: Scale, values: &[f64]) -> Scale {
    if scale != Scale::Auto {
        return scale;
    }
    if !spans_decades(values.iter().copied()) {
        return Scale::Linear;
    }
    if values.iter().any(|v| *v < 0.0) {
        // Linear within the decade of the smallest magnitude, so no value sits in it unseen,
        // but at most five decades below the largest.
        let (smallest, largest) = values
            .iter()
            .filter(|v| v.is_finite() && **v != 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
                (lo.min(v.abs()), hi.max(v.abs()))
            });
        let decade = |v: f64| v.log10().floor();
        Scale::SymLog10 {
            linear_within: 10f64.powf(decade(smallest).max(decade(largest) - 5.0)),
        }
    } else {
        Scale::Log10
    }
}

/// Step 1, 2 or 5 times a power of ten, at least `raw`.
fn nice_step(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let magnitude = 10f64.powf(raw.log10().floor());
    let fraction = raw / magnitude;
    let nice = if fraction <= 1.0 {
        1.0
    } else if fraction <= 2.0 {
        2.0
    } else if fraction <= 5.0 {
        5.0
    } else {
        10.0
    };
    nice * magnitude
}

/// `value` rounded to 12 significant digits (sums of steps carry float noise: 0.30000000000000004).
fn tidy(value: f64) -> f64 {
    if value == 0.0 || !value.is_finite() {
        return value;
    }
    let digits = 11 - value.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits.clamp(-300, 300));
    (value * scale).round() / scale
}

/// Compact tick label: plain decimals between 1e-3 and 1e5, otherwise `1.5e-6` style.
pub fn format_tick(value: f64) -> String {
    let value = tidy(value);
    if value == 0.0 {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&value.abs()) {
        return format!("{value:e}");
    }
    let text = format!("{value:.6}");
    text.trim_end_matches('0').trim_end_matches('.').into()
}

/// One axis as plotters maps it: the scale, the range and the round ticks.
#[derive(Debug, Clone)]
pub(super) struct AxisCoord {
    pub(super) scale: Scale,
    /// Range in data units (`from` maps to the start of the pixel limit, `to` to its end).
    pub(super) from: f64,
    pub(super) to: f64,
    pub(super) ticks: Vec<f64>,
}

impl AxisCoord {
    /// The axis fitted to `values` (drawable ones only), range rounded out to ticks.
    pub(super) fn fit(spec: &AxisSpec, values: &[f64]) -> Self {
        let scale = resolve(spec.scale, values);
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        let (lo, hi) = match spec.range {
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() && hi > lo => (lo, hi),
            _ => match scale {
                Scale::Log10 => {
                    let positive = finite.iter().filter(|v| **v > 0.0);
                    let (lo, hi) =
                        positive.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(*v), b.max(*v)));
                    if hi <= 0.0 {
                        (1.0, 10.0)
                    } else {
                        // Whole decades, at most ten of them below the largest value.
                        let top = hi.log10().ceil();
                        let bottom = lo.log10().floor().max(top - 10.0);
                        let bottom = if bottom >= top { top - 1.0 } else { bottom };
                        (10f64.powf(bottom), 10f64.powf(top))
                    }
                }
                _ => finite
                    .iter()
                    .fold(None, |r: Option<(f64, f64)>, v| {
                        Some(r.map_or((*v, *v), |(a, b)| (a.min(*v), b.max(*v))))
                    })
                    .unwrap_or((0.0, 1.0)),
            },
        };
        let mut axis = AxisCoord {
            scale,
            from: lo,
            to: hi,
            ticks: Vec::new(),
        };
        axis.round_out(spec.range.is_some());
        axis
    }

    /// Rounds the range out to ticks (unless `fixed`) and sets the ticks.
    fn round_out(&mut self, fixed: bool) {
        let (mut lo, mut hi) = (self.from.min(self.to), self.from.max(self.to));
        match self.scale {
            Scale::Linear | Scale::Auto => {
                if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
                    lo -= 1.0;
                    hi += 1.0;
                }
                let step = nice_step((hi - lo) / 5.0);
                if !fixed {
                    lo = (lo / step).floor() * step;
                    hi = (hi / step).ceil() * step;
                }
                let first = (lo / step - 1e-9).ceil() as i64;
                let last = (hi / step + 1e-9).floor() as i64;
                self.ticks = (first..=last).map(|k| tidy(k as f64 * step)).collect();
            }
            Scale::Log10 => {
                let (a, b) = (lo.log10(), hi.log10());
                let decades = (b - a).round().max(1.0) as i32;
                // At most about eight labelled decades.
                let every = (decades + 7) / 8;
                let first = (a - 1e-9).ceil() as i32;
                let last = (b + 1e-9).floor() as i32;
                self.ticks = (first..=last)
                    .filter(|k| k.rem_euclid(every) == 0)
                    .map(|k| tidy(10f64.powi(k)))
                    .collect();
            }
            Scale::SymLog10 { linear_within } => {
                let round = |v: f64| {
                    if v.abs() <= linear_within {
                        v.signum() * linear_within
                    } else {
                        v.signum() * 10f64.powf(v.abs().log10().ceil())
                    }
                };
                if !fixed {
                    lo = if lo < 0.0 { round(lo) } else { 0.0 };
                    hi = if hi > 0.0 { round(hi) } else { 0.0 };
                }
                let c = linear_within.log10().round() as i32;
                let decades = |v: f64| {
                    if v.abs() <= linear_within {
                        c
                    } else {
                        v.abs().log10().floor() as i32
                    }
                };
                let span = (decades(lo).max(decades(hi)) - c + 1).max(1);
                let every = (span + 3) / 4;
                let mut ticks = vec![0.0];
                // The decade of the linear part sits next to zero: labelled only when no other
                // decade is, or its label would run into zero's.
                let top = decades(lo).max(decades(hi));
                let first = if top >= c + every { c + every } else { c };
                for k in (first..=top).filter(|k| (k - c) % every == 0) {
                    let v = tidy(10f64.powi(k));
                    if v <= hi * (1.0 + 1e-9) {
                        ticks.push(v);
                    }
                    if -v >= lo * (1.0 + 1e-9) {
                        ticks.push(-v);
                    }
                }
                ticks.sort_by(f64::total_cmp);
                self.ticks = ticks;
            }
        }
        if self.from <= self.to {
            (self.from, self.to) = (lo, hi);
        } else {
            (self.from, self.to) = (hi, lo);
        }
    }

    /// The axis coordinate of `v`: linear, log10 or symmetric log.
    fn forward(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear | Scale::Auto => v,
            Scale::Log10 => v.log10(),
            Scale::SymLog10 { linear_within } => {
                v.signum() * (1.0 + v.abs() / linear_within).log10()
            }
        }
    }

    /// `v` inside the range; on a log axis anything at or below its start is drawn at it.
    fn clamp(&self, v: f64) -> f64 {
        let (lo, hi) = (self.from.min(self.to), self.from.max(self.to));
        v.clamp(lo, hi)
    }

    /// Where a bar starts: zero, or the start of a log axis.
    pub(super) fn base(&self) -> f64 {
        match self.scale {
            Scale::Log10 => self.from.min(self.to),
            _ => 0.0,
        }
    }
}

impl Ranged for AxisCoord {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = (self.forward(self.from), self.forward(self.to));
        let t = (self.forward(self.clamp(*value)) - a) / (b - a);
        let px = f64::from(limit.0) + t * f64::from(limit.1 - limit.0);
        px.round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        // Labelled ticks only: no light grid lines between them.
        match hint.weight() {
            KeyPointWeight::Bold => self.ticks.clone(),
            KeyPointWeight::Any => Vec::new(),
        }
    }

    fn range(&self) -> Range<f64> {
        self.from..self.to
    }
}
