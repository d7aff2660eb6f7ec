//! Service life of a rail (thesis 6.8): its rattle space from measured dimensions (eq. 6.1-6.3)
//! and the design life penalized by a sweep's curve at that rattle space,
//! `T_SL,real = K_SL T_SL,design` (eq. 6.4, [`PenalizationCurve::penalized_life`]) with the
//! 0.9/0.8 bands of Figure 6.68 and, for a curve with several seeds per point, K_SL's confidence
//! interval over the seeds. The rails report (`/v1/rails/{serial}/report`) calls these.

use crate::analysis::penalization::{
    KslInterval, PenalizationCurve, PenalizationError, PenalizedLife,
};
use crate::analysis::rattle_space::{LauncherDimensions, RattleSpaceError};
use crate::field_error::FieldError;

/// Rattle space k_rs (eq. 6.1-6.3) of measured dimensions, or the field at fault and why.
pub fn rattle_space(dimensions: &LauncherDimensions) -> Result<f64, FieldError> {
    dimensions
        .rattle_space()
        .map_err(|RattleSpaceError::InvalidDimension(e)| e)
}

/// [k_rs, K_SL] at the curve's swept rattle spaces (for a plot of the curve).
pub fn k_sl_samples(curve: &PenalizationCurve) -> Vec<[f64; 2]> {
    curve
        .points()
        .iter()
        .filter_map(|p| curve.k_sl(p.rattle_space).ok().map(|k| [p.rattle_space, k]))
        .collect()
}

/// A rail's penalized service life at one rattle space.
#[derive(Debug, Clone, PartialEq)]
pub struct ServiceLife {
    /// K_SL, its bands and the penalized life with its bands (eq. 6.4).
    pub life: PenalizedLife,
    /// K_SL's confidence interval over the curve's seeds and the lives at its ends; None when
    /// the curve has one seed per point.
    pub interval: Option<LifeInterval>,
    /// How the interval was computed, or why there is none (in words, for the report).
    pub uncertainty: String,
}

/// K_SL's interval over seeds and the penalized lives at its ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LifeInterval {
    /// The interval of K_SL ([`PenalizationCurve::k_sl_interval`]).
    pub k_sl: KslInterval,
    /// `k_sl_low T_SL,design`, h.
    pub life_low_h: f64,
    /// `k_sl_high T_SL,design`, h.
    pub life_high_h: f64,
}

/// The service life at `rattle_space` for a design life of `design_life_h` hours (finite,
/// > 0), or why the curve gives none (the rattle space outside its range, a bad design life).
pub fn service_life(
    curve: &PenalizationCurve,
    rattle_space: f64,
    design_life_h: f64,
) -> Result<ServiceLife, PenalizationError> {
    let life = curve.penalized_life(design_life_h, rattle_space)?;
    let interval = curve
        .k_sl_interval(rattle_space)
        .ok()
        .flatten()
        .map(|k_sl| LifeInterval {
            k_sl,
            life_low_h: k_sl.k_sl_low * design_life_h,
            life_high_h: k_sl.k_sl_high * design_life_h,
        });
    let uncertainty = match &interval {
        Some(i) => format!(
            "90 % t-interval over {} seeds per point (t = {:.4}, {} degrees of freedom) of the \
             paired log ratio of wear rates; seed-to-seed scatter of the simulation only, not \
             model error",
            i.k_sl.seeds,
            i.k_sl.t_quantile,
            i.k_sl.seeds - 1
        ),
        None => "no interval: the curve has one seed per point; publish a sweep with seeds >= 3 \
                 for one"
            .to_string(),
    };
    Ok(ServiceLife {
        life,
        interval,
        uncertainty,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::penalization::SweepPoint;

    fn curve() -> PenalizationCurve {
        // Rail wear rate 1 mg/h at the design rattle space 0.05, 2 mg/h at 0.10.
        let points = [
            SweepPoint {
                offset_mm: None,
                rattle_space: 0.05,
                rail_wear_rate_mg_per_h: 1.0,
            },
            SweepPoint {
                offset_mm: None,
                rattle_space: 0.10,
                rail_wear_rate_mg_per_h: 2.0,
            },
        ];
        PenalizationCurve::new(&points, 0.05).expect("curve")
    }

    #[test]
    fn penalized_life_is_k_sl_times_the_design_life_with_its_bands() {
        // At 0.10 the rail wears twice as fast as at design: K_SL = 1/2 (eq. 6.4), so 1000 h
        // of design life become 500 h, 450 h and 400 h with the 0.9 and 0.8 bands.
        let s = service_life(&curve(), 0.10, 1000.0).expect("covered");
        assert!((s.life.factors.k_sl - 0.5).abs() < 1e-12);
        assert!((s.life.life_h - 500.0).abs() < 1e-9);
        assert!((s.life.life_conservative_90_h - 450.0).abs() < 1e-9);
        assert!((s.life.life_conservative_80_h - 400.0).abs() < 1e-9);
        assert!(s.interval.is_none(), "one seed per point gives no interval");
        assert!(s.uncertainty.starts_with("no interval"));
    }

    #[test]
    fn outside_the_curve_there_is_no_service_life() {
        assert!(service_life(&curve(), 0.5, 1000.0).is_err());
        assert!(service_life(&curve(), 0.07, 0.0).is_err());
    }
}
