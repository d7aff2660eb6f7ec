//! Service-life penalization for manufacturing tolerances, thesis eq. 6.4 and Figure 6.68.
//!
//! `T_SL,real = K_SL T_SL,design` with `K_SL(k_rs) = min(1, rate(k_design) / rate(k_rs))`, where
//! `rate` is the rail wear rate (sum of the rail contacts, mg/h) from a simulated tolerance sweep
//! for one vehicle profile, environment and wear law. A conservative factor never lengthens the
//! service life (thesis 6.7), hence the `min(1, ...)`. Between sweep points the rate is
//! interpolated linearly in `ln(rate)`: wear rates span orders of magnitude, and interpolating
//! their logarithm keeps the rate positive and, like any piecewise-linear interpolant, monotone
//! between neighbouring points. Outside the swept range there is no data, so asking there is an
//! error, not an extrapolation.
//!
//! Uncertainty (issue 17): a sweep runs every point with the same n seeds (common random
//! numbers: seed j drives the same excitation at every k_rs). Each seed j gives its own curve
//! `L_j(k) = ln rate_j(k)` (interpolated as above) and its own log ratio
//! `D_j(k) = L_j(k_design) - L_j(k)`. The curve's rates are the geometric means over the seeds,
//! so `K_SL = min(1, exp(mean_j D_j))`. Pairing by seed keeps the correlation the common seeds
//! induce between the design point and k (it mostly cancels): the n values `D_j` are treated as
//! independent draws of the log ratio and the two-sided t-interval at [`CONFIDENCE`] (90 %) is
//! `mean D ± t(0.95; n-1) s_D / sqrt(n)`; K_SL's interval is `min(1, exp(.))` of its ends and the
//! life interval that times the design life. It covers the seed-to-seed scatter of the simulated
//! wear (excitation draws) only, not model error, and assumes `D_j` roughly normal (log rates
//! are); with one seed there is no interval.

use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Factor of the first conservative band of Figure 6.68 (10 % below K_SL).
pub const CONSERVATIVE_BAND_90: f64 = 0.9;
/// Factor of the second conservative band of Figure 6.68 (20 % below K_SL).
pub const CONSERVATIVE_BAND_80: f64 = 0.8;
/// Two-sided confidence level of K_SL's interval over seeds.
pub const CONFIDENCE: f64 = 0.9;

/// Upper 5 % quantiles of Student's t, `t(0.95; df)` for df = 1..=30 (the 90 % two-sided
/// interval), to six significant digits.
const T_95: [f64; 30] = [
    6.313752, 2.919986, 2.353363, 2.131847, 2.015048, 1.943180, 1.894579, 1.859548, 1.833113,
    1.812461, 1.795885, 1.782288, 1.770933, 1.761310, 1.753050, 1.745884, 1.739607, 1.734064,
    1.729133, 1.724718, 1.720743, 1.717144, 1.713872, 1.710882, 1.708141, 1.705618, 1.703288,
    1.701131, 1.699127, 1.697261,
];

/// `t(0.95; df)`: the table for df <= 30, the normal quantile 1.644854 beyond (within 1.2 %).
pub fn t_quantile_95(df: usize) -> f64 {
    match df {
        0 => f64::INFINITY,
        d if d <= T_95.len() => T_95[d - 1],
        _ => 1.644_854,
    }
}

/// Why a penalization curve could not be built or evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PenalizationError {
    /// Fewer than two distinct rattle spaces: there is no curve to interpolate.
    #[error("the sweep needs at least 2 distinct rattle spaces, got {distinct}")]
    TooFewPoints {
        /// Number of distinct k_rs values given.
        distinct: usize,
    },
    /// An input is unusable: a sweep point (non-finite k_rs, k_rs outside (0, 1], rate not
    /// finite and > 0), named by its path (`points[1].rattle_space`), or a query's argument
    /// (non-finite, or a non-positive life), e.g. `design_rattle_space`, `design_life_h`.
    #[error("invalid `{}`: {}", .0.field, .0.rule)]
    InvalidInput(#[from] FieldError),
    /// The requested rattle space lies outside the swept range: no extrapolation.
    #[error(
        "rattle space {rattle_space} is outside the swept range [{min}, {max}]; \
         run a tolerance sweep that covers it"
    )]
    OutOfRange {
        /// The requested k_rs.
        rattle_space: f64,
        /// Smallest swept k_rs.
        min: f64,
        /// Largest swept k_rs.
        max: f64,
    },
}

/// One point of a tolerance sweep: a rail configuration's rattle space and its simulated rail
/// wear rate (thesis Figure 6.67: sum of rail contacts 1, 3 and 5), with the material-condition
/// offset that made the configuration when the point comes from a sweep's run. A curve's points
/// carry no offset: the curve is a function of the rattle space alone, and
/// [`PenalizationCurve::new`] drops it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepPoint {
    /// Material-condition offset applied to the launcher dimensions, mm (negative = tighter);
    /// absent on a curve's points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset_mm: Option<f64>,
    /// Rattle space k_rs of the configuration (eq. 6.3), dimensionless, in (0, 1].
    pub rattle_space: f64,
    /// Rail wear rate at that configuration, mg/h (> 0).
    pub rail_wear_rate_mg_per_h: f64,
}

/// Stored form of a curve, validated on deserialization.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PenalizationCurveData {
    design_rattle_space: f64,
    points: Vec<SweepPoint>,
    /// Per point (same order), the rate of each seed, mg/h; absent for one seed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    rate_by_seed_mg_per_h: Vec<Vec<f64>>,
}

/// The penalization curve of one tolerance sweep (thesis Figure 6.68).
///
/// Serializes as `{ "design_rattle_space": k, "points": [{ "rattle_space", "rail_wear_rate_mg_per_h" }] }`
/// with the points sorted by rattle space (repeats merged); deserializing re-validates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PenalizationCurveData", into = "PenalizationCurveData")]
pub struct PenalizationCurve {
    /// Design (nominal) rattle space, inside the swept range.
    design_rattle_space: f64,
    /// Sweep points sorted by strictly increasing rattle space.
    points: Vec<SweepPoint>,
    /// Interpolated wear rate at the design point, mg/h.
    design_rate_mg_per_h: f64,
    /// Per point, the rate of each seed (all points the same seeds, in the same order), mg/h;
    /// empty when the curve has one seed.
    rate_by_seed: Vec<Vec<f64>>,
}

/// K_SL's confidence interval over seeds at one rattle space (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KslInterval {
    /// Two-sided confidence level, 0.9.
    pub confidence: f64,
    /// Seeds behind each point (n).
    pub seeds: usize,
    /// Mean over seeds of the log ratio `D_j = ln rate_j(design) - ln rate_j(k)`.
    pub mean_log_ratio: f64,
    /// Sample standard deviation of `D_j` (n - 1 denominator).
    pub std_log_ratio: f64,
    /// `t(0.95; n - 1)`.
    pub t_quantile: f64,
    /// Lower and upper end of K_SL, each `min(1, exp(mean ∓ t s / sqrt(n)))`.
    pub k_sl_low: f64,
    pub k_sl_high: f64,
}

/// K_SL and its conservative bands at one rattle space (Figure 6.68).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PenalizationFactors {
    /// The rattle space asked about.
    pub rattle_space: f64,
    /// K_SL = min(1, rate(design)/rate(k_rs)), eq. 6.4.
    pub k_sl: f64,
    /// 0.9 K_SL (Figure 6.68, 10 % band).
    pub k_sl_conservative_90: f64,
    /// 0.8 K_SL (Figure 6.68, 20 % band).
    pub k_sl_conservative_80: f64,
}

/// Penalized service life (eq. 6.4) with the conservative bands.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PenalizedLife {
    /// The factors used.
    pub factors: PenalizationFactors,
    /// Design service life T_SL,design, h.
    pub design_life_h: f64,
    /// T_SL,real = K_SL T_SL,design, h.
    pub life_h: f64,
    /// 0.9 K_SL T_SL,design, h.
    pub life_conservative_90_h: f64,
    /// 0.8 K_SL T_SL,design, h.
    pub life_conservative_80_h: f64,
}

impl TryFrom<PenalizationCurveData> for PenalizationCurve {
    type Error = PenalizationError;
    fn try_from(data: PenalizationCurveData) -> Result<Self, Self::Error> {
        if data.rate_by_seed_mg_per_h.is_empty() {
            Self::new(&data.points, data.design_rattle_space)
        } else {
            let ks: Vec<f64> = data.points.iter().map(|p| p.rattle_space).collect();
            Self::from_seeds(&ks, &data.rate_by_seed_mg_per_h, data.design_rattle_space)
        }
    }
}

impl From<PenalizationCurve> for PenalizationCurveData {
    fn from(curve: PenalizationCurve) -> Self {
        Self {
            design_rattle_space: curve.design_rattle_space,
            points: curve.points,
            rate_by_seed_mg_per_h: curve.rate_by_seed,
        }
    }
}

impl PenalizationCurve {
    /// Builds the curve from sweep points (any order) and the design rattle space.
    ///
    /// Rules: each k_rs finite and in (0, 1]; each rate finite and > 0; at least two distinct
    /// k_rs; the design k_rs inside the swept range. Repeated k_rs (repeat runs, other seeds) are
    /// merged by the geometric mean of their rates (the mean of ln(rate), the interpolated
    /// quantity).
    pub fn new(points: &[SweepPoint], design_rattle_space: f64) -> Result<Self, PenalizationError> {
        for (index, p) in points.iter().enumerate() {
            if !(p.rattle_space.is_finite() && p.rattle_space > 0.0 && p.rattle_space <= 1.0) {
                return Err(FieldError::new(
                    format!("points[{index}].rattle_space"),
                    format!("must be a finite number in (0, 1], got {}", p.rattle_space),
                )
                .into());
            }
            let rate = p.rail_wear_rate_mg_per_h;
            if !(rate.is_finite() && rate > 0.0) {
                return Err(FieldError::new(
                    format!("points[{index}].rail_wear_rate_mg_per_h"),
                    format!("must be a finite number > 0 mg/h, got {rate}"),
                )
                .into());
            }
        }
        let mut sorted: Vec<SweepPoint> = points.to_vec();
        sorted.sort_by(|a, b| a.rattle_space.total_cmp(&b.rattle_space));
        // Merge repeats: geometric mean of the rates at equal k_rs.
        let mut merged: Vec<SweepPoint> = Vec::with_capacity(sorted.len());
        let mut i = 0;
        while i < sorted.len() {
            let k = sorted[i].rattle_space;
            let mut j = i;
            let mut log_sum = 0.0;
            while j < sorted.len() && sorted[j].rattle_space == k {
                log_sum += sorted[j].rail_wear_rate_mg_per_h.ln();
                j += 1;
            }
            merged.push(SweepPoint {
                offset_mm: None,
                rattle_space: k,
                rail_wear_rate_mg_per_h: (log_sum / (j - i) as f64).exp(),
            });
            i = j;
        }
        if merged.len() < 2 {
            return Err(PenalizationError::TooFewPoints {
                distinct: merged.len(),
            });
        }
        if !design_rattle_space.is_finite() {
            return Err(FieldError::new(
                "design_rattle_space",
                format!("must be a finite number, got {design_rattle_space}"),
            )
            .into());
        }
        let mut curve = Self {
            design_rattle_space,
            points: merged,
            design_rate_mg_per_h: 0.0,
            rate_by_seed: Vec::new(),
        };
        curve.design_rate_mg_per_h =
            curve
                .rail_wear_rate_mg_per_h(design_rattle_space)
                .map_err(|e| match e {
                    PenalizationError::OutOfRange { min, max, .. } => FieldError::new(
                        "design_rattle_space",
                        format!(
                            "{design_rattle_space} must lie inside the swept range [{min}, {max}]"
                        ),
                    )
                    .into(),
                    other => other,
                })?;
        Ok(curve)
    }

    /// Builds the curve from the rates of each seed at each rattle space: `rates_by_seed[i]`
    /// holds point `i`'s rate for every seed, the same seeds in the same order at every point
    /// (a sweep's replicas). The curve's rate at a point is the geometric mean over its seeds;
    /// [`PenalizationCurve::k_sl_interval`] gives K_SL's confidence interval. The rattle spaces
    /// must be distinct; other rules as [`PenalizationCurve::new`]. One seed is a curve without
    /// an interval.
    pub fn from_seeds(
        rattle_spaces: &[f64],
        rates_by_seed: &[Vec<f64>],
        design_rattle_space: f64,
    ) -> Result<Self, PenalizationError> {
        let n = rates_by_seed.first().map_or(0, Vec::len);
        if rates_by_seed.len() != rattle_spaces.len() {
            return Err(FieldError::new(
                "rate_by_seed_mg_per_h",
                format!(
                    "needs one list of rates per point ({}), got {}",
                    rattle_spaces.len(),
                    rates_by_seed.len()
                ),
            )
            .into());
        }
        let mut points = Vec::with_capacity(rattle_spaces.len());
        for (index, (k, rates)) in rattle_spaces.iter().zip(rates_by_seed).enumerate() {
            if rates.len() != n || n == 0 {
                return Err(FieldError::new(
                    format!("rate_by_seed_mg_per_h[{index}]"),
                    format!(
                        "every point needs the same seeds ({n} at the first point), got {}",
                        rates.len()
                    ),
                )
                .into());
            }
            if let Some(bad) = rates.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
                return Err(FieldError::new(
                    format!("rate_by_seed_mg_per_h[{index}]"),
                    format!("must be a finite number > 0 mg/h, got {bad}"),
                )
                .into());
            }
            let rate = if n == 1 {
                rates[0]
            } else {
                (rates.iter().map(|r| r.ln()).sum::<f64>() / n as f64).exp()
            };
            points.push(SweepPoint {
                offset_mm: None,
                rattle_space: *k,
                rail_wear_rate_mg_per_h: rate,
            });
        }
        let mut curve = Self::new(&points, design_rattle_space)?;
        if curve.points.len() != points.len() {
            return Err(FieldError::new(
                "rattle_space",
                "points with seeds need distinct rattle spaces",
            )
            .into());
        }
        if n > 1 {
            // Align the seeds' rates with the sorted points.
            let mut order: Vec<usize> = (0..points.len()).collect();
            order.sort_by(|&a, &b| rattle_spaces[a].total_cmp(&rattle_spaces[b]));
            curve.rate_by_seed = order.iter().map(|&i| rates_by_seed[i].clone()).collect();
        }
        Ok(curve)
    }

    /// Seeds behind each point (1 for a curve without per-seed rates).
    pub fn seeds(&self) -> usize {
        self.rate_by_seed.first().map_or(1, Vec::len)
    }

    /// ln(rate) of seed `j` at `k` (in range), interpolated as the curve.
    fn seed_log_rate(&self, j: usize, k: f64) -> f64 {
        let right = self
            .points
            .iter()
            .position(|p| p.rattle_space >= k)
            .unwrap_or(self.points.len() - 1)
            .max(1);
        let (a, b) = (self.points[right - 1], self.points[right]);
        let t = (k - a.rattle_space) / (b.rattle_space - a.rattle_space);
        (1.0 - t) * self.rate_by_seed[right - 1][j].ln() + t * self.rate_by_seed[right][j].ln()
    }

    /// K_SL's 90 % confidence interval over seeds at `rattle_space` (module documentation);
    /// `Ok(None)` for a curve with one seed.
    pub fn k_sl_interval(
        &self,
        rattle_space: f64,
    ) -> Result<Option<KslInterval>, PenalizationError> {
        self.rail_wear_rate_mg_per_h(rattle_space)?;
        let n = self.seeds();
        if n < 2 || self.rate_by_seed.is_empty() {
            return Ok(None);
        }
        let d: Vec<f64> = (0..n)
            .map(|j| {
                self.seed_log_rate(j, self.design_rattle_space)
                    - self.seed_log_rate(j, rattle_space)
            })
            .collect();
        let mean = d.iter().sum::<f64>() / n as f64;
        let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let std = var.sqrt();
        let t = t_quantile_95(n - 1);
        let half = t * std / (n as f64).sqrt();
        Ok(Some(KslInterval {
            confidence: CONFIDENCE,
            seeds: n,
            mean_log_ratio: mean,
            std_log_ratio: std,
            t_quantile: t,
            k_sl_low: (mean - half).exp().min(1.0),
            k_sl_high: (mean + half).exp().min(1.0),
        }))
    }

    /// Design rattle space.
    pub fn design_rattle_space(&self) -> f64 {
        self.design_rattle_space
    }

    /// The merged sweep points, sorted by increasing rattle space.
    pub fn points(&self) -> &[SweepPoint] {
        &self.points
    }

    /// Swept range `(min, max)` of rattle space.
    pub fn range(&self) -> (f64, f64) {
        // `new` guarantees at least two points.
        let first = self.points.first().map_or(f64::NAN, |p| p.rattle_space);
        let last = self.points.last().map_or(f64::NAN, |p| p.rattle_space);
        (first, last)
    }

    /// Interpolated rail wear rate at the design point, mg/h.
    pub fn design_rate_mg_per_h(&self) -> f64 {
        self.design_rate_mg_per_h
    }

    /// Rail wear rate at `rattle_space`, mg/h: piecewise-linear in ln(rate) between sweep points;
    /// an error outside the swept range.
    pub fn rail_wear_rate_mg_per_h(&self, rattle_space: f64) -> Result<f64, PenalizationError> {
        if !rattle_space.is_finite() {
            return Err(FieldError::new(
                "rattle_space",
                format!("must be a finite number, got {rattle_space}"),
            )
            .into());
        }
        let (min, max) = self.range();
        if rattle_space < min || rattle_space > max {
            return Err(PenalizationError::OutOfRange {
                rattle_space,
                min,
                max,
            });
        }
        // First segment whose right end is >= k (points are strictly increasing).
        let right = self
            .points
            .iter()
            .position(|p| p.rattle_space >= rattle_space)
            .unwrap_or(self.points.len() - 1)
            .max(1);
        let (a, b) = (self.points[right - 1], self.points[right]);
        let t = (rattle_space - a.rattle_space) / (b.rattle_space - a.rattle_space);
        let ln_rate =
            (1.0 - t) * a.rail_wear_rate_mg_per_h.ln() + t * b.rail_wear_rate_mg_per_h.ln();
        Ok(ln_rate.exp())
    }

    /// Service-life penalization factor `K_SL = min(1, rate(design) / rate(k_rs))`, eq. 6.4.
    pub fn k_sl(&self, rattle_space: f64) -> Result<f64, PenalizationError> {
        let rate = self.rail_wear_rate_mg_per_h(rattle_space)?;
        Ok((self.design_rate_mg_per_h / rate).min(1.0))
    }

    /// K_SL with the conservative 0.9 and 0.8 bands of Figure 6.68.
    pub fn factors(&self, rattle_space: f64) -> Result<PenalizationFactors, PenalizationError> {
        let k_sl = self.k_sl(rattle_space)?;
        Ok(PenalizationFactors {
            rattle_space,
            k_sl,
            k_sl_conservative_90: CONSERVATIVE_BAND_90 * k_sl,
            k_sl_conservative_80: CONSERVATIVE_BAND_80 * k_sl,
        })
    }

    /// Penalized service life `T_SL,real = K_SL T_SL,design` (eq. 6.4) and its bands.
    /// `design_life_h` must be a finite number > 0.
    pub fn penalized_life(
        &self,
        design_life_h: f64,
        rattle_space: f64,
    ) -> Result<PenalizedLife, PenalizationError> {
        if !(design_life_h.is_finite() && design_life_h > 0.0) {
            return Err(FieldError::new(
                "design_life_h",
                format!("must be a finite number > 0 h, got {design_life_h}"),
            )
            .into());
        }
        let factors = self.factors(rattle_space)?;
        Ok(PenalizedLife {
            factors,
            design_life_h,
            life_h: factors.k_sl * design_life_h,
            life_conservative_90_h: factors.k_sl_conservative_90 * design_life_h,
            life_conservative_80_h: factors.k_sl_conservative_80 * design_life_h,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(k: f64, rate: f64) -> SweepPoint {
        SweepPoint {
            offset_mm: None,
            rattle_space: k,
            rail_wear_rate_mg_per_h: rate,
        }
    }

    /// Thesis-shaped sweep (Figure 6.67): loose 0.7684, design 0.7990, tight 0.8317; looser
    /// wears faster. Rates chosen as round numbers so the expected values are by hand.
    fn field_of(e: &PenalizationError) -> &str {
        match e {
            PenalizationError::InvalidInput(e) => &e.field,
            other => panic!("not an invalid input: {other}"),
        }
    }

    fn thesis_like() -> PenalizationCurve {
        PenalizationCurve::new(&[pt(0.8317, 1.0), pt(0.7684, 4.0), pt(0.7990, 2.0)], 0.7990)
            .unwrap()
    }

    #[test]
    fn k_sl_is_one_at_design_and_never_above_one() {
        let c = thesis_like();
        assert_eq!(c.k_sl(0.7990).unwrap(), 1.0);
        // Tighter rails wear slower: K_SL would exceed 1 but is capped (conservative, thesis 6.7).
        assert_eq!(c.k_sl(0.8317).unwrap(), 1.0);
        for i in 0..=100 {
            let k = 0.7684 + (0.8317 - 0.7684) * i as f64 / 100.0;
            assert!(c.k_sl(k).unwrap() <= 1.0);
        }
    }

    #[test]
    fn k_sl_below_one_where_the_rate_is_higher() {
        let c = thesis_like();
        // Loose end: rate 4 vs design 2 -> 0.5.
        assert!((c.k_sl(0.7684).unwrap() - 0.5).abs() < 1e-12);
        // Midway in k between loose and design, ln-linear: rate = sqrt(4*2) -> K = 2/sqrt(8).
        let mid = 0.5 * (0.7684 + 0.7990);
        assert!((c.rail_wear_rate_mg_per_h(mid).unwrap() - 8f64.sqrt()).abs() < 1e-12);
        assert!((c.k_sl(mid).unwrap() - 2.0 / 8f64.sqrt()).abs() < 1e-12);
        // Monotone between points: K_SL rises from loose to design.
        let mut last = 0.0;
        for i in 0..=50 {
            let k = 0.7684 + (0.7990 - 0.7684) * i as f64 / 50.0;
            let v = c.k_sl(k).unwrap();
            assert!(v >= last - 1e-15);
            last = v;
        }
    }

    #[test]
    fn bands_and_penalized_life() {
        let c = thesis_like();
        let life = c.penalized_life(1000.0, 0.7684).unwrap();
        assert!((life.life_h - 500.0).abs() < 1e-9);
        assert!((life.life_conservative_90_h - 450.0).abs() < 1e-9);
        assert!((life.life_conservative_80_h - 400.0).abs() < 1e-9);
        assert!((life.factors.k_sl_conservative_90 - 0.45).abs() < 1e-12);
        let err = c.penalized_life(-5.0, 0.79).unwrap_err();
        assert_eq!(field_of(&err), "design_life_h");
        assert_eq!(
            err.to_string(),
            "invalid `design_life_h`: must be a finite number > 0 h, got -5"
        );
    }

    #[test]
    fn outside_the_sweep_is_an_error_naming_the_range() {
        let c = thesis_like();
        let err = c.k_sl(0.70).unwrap_err();
        assert_eq!(
            err,
            PenalizationError::OutOfRange {
                rattle_space: 0.70,
                min: 0.7684,
                max: 0.8317
            }
        );
        assert!(err.to_string().contains("[0.7684, 0.8317]"));
        assert!(c.k_sl(0.9).is_err());
        assert!(c.k_sl(f64::NAN).is_err());
    }

    #[test]
    fn sweep_point_validation() {
        let e = PenalizationCurve::new(&[pt(0.8, 1.0)], 0.8).unwrap_err();
        assert_eq!(e, PenalizationError::TooFewPoints { distinct: 1 });
        let e = PenalizationCurve::new(&[pt(0.8, 1.0), pt(0.8, 3.0)], 0.8).unwrap_err();
        assert_eq!(e, PenalizationError::TooFewPoints { distinct: 1 });
        let e = PenalizationCurve::new(&[pt(0.8, 1.0), pt(0.7, 0.0)], 0.75).unwrap_err();
        assert_eq!(field_of(&e), "points[1].rail_wear_rate_mg_per_h");
        // The point's index is in the field's path (it read `sweep point 1: invalid
        // `rail_wear_rate_mg_per_h`: ...` before the one FieldError).
        assert_eq!(
            e.to_string(),
            "invalid `points[1].rail_wear_rate_mg_per_h`: must be a finite number > 0 mg/h, got 0"
        );
        let e = PenalizationCurve::new(&[pt(f64::NAN, 1.0), pt(0.7, 1.0)], 0.75).unwrap_err();
        assert_eq!(field_of(&e), "points[0].rattle_space");
        let e = PenalizationCurve::new(&[pt(0.8, f64::INFINITY), pt(0.7, 1.0)], 0.75).unwrap_err();
        assert_eq!(field_of(&e), "points[0].rail_wear_rate_mg_per_h");
        // Design outside the sweep.
        let e = PenalizationCurve::new(&[pt(0.8, 1.0), pt(0.7, 2.0)], 0.9).unwrap_err();
        assert_eq!(field_of(&e), "design_rattle_space");
    }

    #[test]
    fn repeats_merge_by_geometric_mean() {
        let c = PenalizationCurve::new(&[pt(0.7, 1.0), pt(0.7, 4.0), pt(0.8, 1.0)], 0.8).unwrap();
        assert_eq!(c.points().len(), 2);
        assert!((c.rail_wear_rate_mg_per_h(0.7).unwrap() - 2.0).abs() < 1e-12);
    }

    /// Closed form: design rate 1 mg/h for every seed, rates e^0.1, e^0.2, e^0.3 at k = 0.75,
    /// so D_j = -0.1, -0.2, -0.3: mean -0.2, s = 0.1, t(0.95; 2) = 2.919986.
    #[test]
    fn k_sl_interval_is_the_t_interval_over_seeds() {
        let e = f64::exp;
        let c = PenalizationCurve::from_seeds(
            &[0.75, 0.80, 0.85],
            &[
                vec![e(0.1), e(0.2), e(0.3)],
                vec![1.0, 1.0, 1.0],
                vec![0.5, 0.6, 0.7],
            ],
            0.80,
        )
        .unwrap();
        assert_eq!(c.seeds(), 3);
        // The curve's rate is the geometric mean: e^0.2 at 0.75.
        assert!((c.rail_wear_rate_mg_per_h(0.75).unwrap() - e(0.2)).abs() < 1e-12);
        let i = c.k_sl_interval(0.75).unwrap().unwrap();
        let half = 2.919986 * 0.1 / 3f64.sqrt();
        assert!((i.mean_log_ratio + 0.2).abs() < 1e-12);
        assert!((i.std_log_ratio - 0.1).abs() < 1e-12);
        assert!((i.k_sl_low - e(-0.2 - half)).abs() < 1e-9, "{i:?}");
        assert!((i.k_sl_high - e(-0.2 + half)).abs() < 1e-9, "{i:?}");
        let k = c.k_sl(0.75).unwrap();
        assert!(i.k_sl_low < k && k < i.k_sl_high);
        assert!((k - e(-0.2)).abs() < 1e-12);
        // At the design point every seed's ratio is 1: a zero-width interval at 1.
        let at_design = c.k_sl_interval(0.80).unwrap().unwrap();
        assert_eq!((at_design.k_sl_low, at_design.k_sl_high), (1.0, 1.0));
        // Tighter rails: capped at 1 like K_SL.
        assert!(c.k_sl_interval(0.85).unwrap().unwrap().k_sl_high <= 1.0);
        // Outside the range: the same error as K_SL.
        assert!(c.k_sl_interval(0.9).is_err());
        // Stored and read back with its seeds.
        let back: PenalizationCurve =
            serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
        assert_eq!(back, c);
        assert_eq!(back.k_sl_interval(0.75).unwrap(), Some(i));
        // One seed: no interval.
        assert_eq!(thesis_like().k_sl_interval(0.78).unwrap(), None);
        // Seeds must line up.
        assert!(
            PenalizationCurve::from_seeds(&[0.7, 0.8], &[vec![1.0, 2.0], vec![1.0]], 0.8).is_err()
        );
    }

    #[test]
    fn t_quantiles_match_the_table() {
        assert!((t_quantile_95(1) - 6.313752).abs() < 1e-6);
        assert!((t_quantile_95(2) - 2.919986).abs() < 1e-6);
        assert!((t_quantile_95(9) - 1.833113).abs() < 1e-6);
        assert!(t_quantile_95(1000) < t_quantile_95(30));
    }

    #[test]
    fn serde_round_trip_revalidates() {
        let c = thesis_like();
        let json = serde_json::to_string(&c).unwrap();
        assert!(json.contains("design_rattle_space"));
        let back: PenalizationCurve = serde_json::from_str(&json).unwrap();
        assert_eq!(back, c);
        let bad = r#"{"design_rattle_space":0.8,"points":[{"rattle_space":0.8,"rail_wear_rate_mg_per_h":1.0}]}"#;
        assert!(serde_json::from_str::<PenalizationCurve>(bad).is_err());
    }
}
