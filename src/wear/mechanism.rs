//! Wear mechanisms beyond sliding Archard at the lumped pressure (issue 26): what each sees at a
//! sample ([`WearSample`]), the terms ([`WearTerm`]) and the closed set a case or a sweep can
//! carry ([`WearMechanism`]).
//!
//! The gap diagnosis (`gap::effects`, wear-law effects) evaluates these terms on recorded tracks
//! and fits their coefficients; a run (`models::run`) integrates the same terms per track while
//! it goes, when its case's `wear.mechanism` names one. Both call the code here, so a fitted
//! mechanism carried to a sweep is the mechanism the diagnosis fitted. Each term at magnitude 0
//! changes nothing, bit for bit.

use super::law::WearLaw;
use super::WearError;
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Contact points of one track at one step whose local pressures fall in one bin (see
/// `gap::point_pressure`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressureBin {
    /// Work-weighted geometric mean of the points' local pressures, Pa.
    pub pressure_pa: f64,
    /// Their friction-work rate over μ, `Σ N_i |v_i|`, W.
    pub work_rate_w: f64,
}

/// What a wear-law term sees at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WearSample<'a> {
    /// Mean contact pressure N/A, Pa (infinite for N > 0 on zero area).
    pub pressure_pa: f64,
    /// Normal force, N.
    pub normal_force_n: f64,
    /// Slip speed, m/s.
    pub slip_speed_m_s: f64,
    /// Slip distance the specimen has accumulated by this sample, m.
    pub slip_distance_m: f64,
    /// Power dissipated by the contact's IMPACT damping, W.
    pub damping_power_w: f64,
    /// Penetration rate of the deepest point (positive approaching), m/s.
    pub penetration_rate_m_s: f64,
    /// Yield strength of the contact's material, Pa.
    pub yield_strength_pa: f64,
    /// The contact points' local-pressure distribution (empty when not recorded).
    pub points: &'a [PressureBin],
}

/// A wear-law term: maps the coefficient K (m²/N) at a sample to the effective one, and may
/// add a wear rate of its own (a mechanism other than sliding at the lumped pressure). Terms
/// are applied in order. A term at zero magnitude must return `k` unchanged and add exactly 0
/// (bit for bit).
pub trait WearTerm {
    /// Effective K, m²/N, given the K so far and the sample.
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, _sample: &WearSample<'_>) -> f64 {
        k
    }

    /// Wear volume rate this term adds to `K_eff N v_slip`, m³/s (may be negative when it
    /// replaces part of the lumped law; the total is clamped at 0).
    fn added_volume_rate_m3_s(&self, _law: &WearLaw, _sample: &WearSample<'_>) -> f64 {
        0.0
    }
}

/// The wear rate of one sample under `law` with `terms` applied in order, m³/s: `K_eff N v`
/// plus what the terms add, clamped at 0 (the law's own rate when there are no terms).
pub fn volume_rate_with_terms_m3_s(
    law: &WearLaw,
    terms: &[&dyn WearTerm],
    sample: &WearSample<'_>,
) -> f64 {
    let (n, v) = (sample.normal_force_n, sample.slip_speed_m_s);
    if terms.is_empty() {
        return law.volume_rate_m3_s(n, v, sample.pressure_pa);
    }
    let mut k = law.coefficient_m2_per_n(sample.pressure_pa).unwrap_or(0.0);
    let mut added = 0.0;
    for term in terms {
        k = term.coefficient_m2_per_n(k, law, sample);
        added += term.added_volume_rate_m3_s(law, sample);
    }
    (k * n * v + added).max(0.0)
}

/// (a) K above the cutoff = ratio x K just below it; unchanged below.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AboveCutoff {
    /// K above the cutoff / K at the cutoff.
    pub ratio: f64,
}

impl WearTerm for AboveCutoff {
    fn coefficient_m2_per_n(&self, k: f64, law: &WearLaw, s: &WearSample) -> f64 {
        let cutoff = law.cutoff_pressure_pa();
        if s.pressure_pa > cutoff && self.ratio != 0.0 {
            let k_cut = law.coefficient_m2_per_n(cutoff).unwrap_or(0.0);
            k + self.ratio * k_cut
        } else {
            k
        }
    }
}

/// (b) K + k_abr/H where pressure and slip speed reach their thresholds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThirdBody {
    /// Added K, m²/N.
    pub k_add_m2_per_n: f64,
    /// Pressure threshold, Pa.
    pub min_pressure_pa: f64,
    /// Slip-speed threshold, m/s.
    pub min_slip_m_s: f64,
}

impl WearTerm for ThirdBody {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample) -> f64 {
        if self.k_add_m2_per_n != 0.0
            && s.pressure_pa >= self.min_pressure_pa
            && s.slip_speed_m_s >= self.min_slip_m_s
        {
            k + self.k_add_m2_per_n
        } else {
            k
        }
    }
}

/// (i) Impact wear: `k_E P_damp` added while `|ẇ| >= v_min` (all of it at `v_min = 0`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactWear {
    /// Wear volume per joule of normal damping work, m³/J.
    pub k_energy_m3_per_j: f64,
    /// Normal speed below which damping work does not wear, m/s.
    pub min_normal_speed_m_s: f64,
}

impl WearTerm for ImpactWear {
    fn added_volume_rate_m3_s(&self, _law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.k_energy_m3_per_j != 0.0
            && s.penetration_rate_m_s.abs() >= self.min_normal_speed_m_s
        {
            self.k_energy_m3_per_j * s.damping_power_w
        } else {
            0.0
        }
    }
}

/// (j) Severe wear: `K_add Σ N_i |v_i|` over the contact points whose local pressure exceeds
/// `ratio Sy` (the lumped pressure when the points were not recorded).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SevereWear {
    /// Added K, m²/N (k_severe / H).
    pub k_add_m2_per_n: f64,
    /// Threshold as a multiple of the yield strength.
    pub pressure_ratio_to_yield: f64,
}

impl WearTerm for SevereWear {
    fn added_volume_rate_m3_s(&self, _law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.k_add_m2_per_n == 0.0 {
            return 0.0;
        }
        let threshold = self.pressure_ratio_to_yield * s.yield_strength_pa;
        let work: f64 = if s.points.is_empty() {
            if s.pressure_pa > threshold {
                s.normal_force_n * s.slip_speed_m_s
            } else {
                0.0
            }
        } else {
            s.points
                .iter()
                .filter(|b| b.pressure_pa > threshold)
                .map(|b| b.work_rate_w)
                .sum()
        };
        self.k_add_m2_per_n * work
    }
}

/// (k) Local-pressure Archard: a share of the lumped `K(N/A) N v` replaced by
/// `Σ K(p_i) N_i |v_i|` over the contact points (nothing without recorded points).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocalPressure {
    /// Share of the wear at the points' own pressures, 0..1.
    pub share: f64,
}

impl WearTerm for LocalPressure {
    fn added_volume_rate_m3_s(&self, law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.share == 0.0 || s.points.is_empty() {
            return 0.0;
        }
        let k_of = |p: f64| law.coefficient_m2_per_n(p).unwrap_or(0.0);
        let local: f64 = s
            .points
            .iter()
            .map(|b| k_of(b.pressure_pa) * b.work_rate_w)
            .sum();
        let lumped = k_of(s.pressure_pa) * s.normal_force_n * s.slip_speed_m_s;
        self.share * (local - lumped)
    }
}

/// (l) Coating breakthrough: K + k_bare/H once the specimen's slip distance reaches the
/// breakthrough distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoatingBreakthrough {
    /// Added K, m²/N (k_bare / H).
    pub k_add_m2_per_n: f64,
    /// Slip distance at which the coating is worn through, m.
    pub breakthrough_slip_m: f64,
}

impl WearTerm for CoatingBreakthrough {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.k_add_m2_per_n != 0.0 && s.slip_distance_m >= self.breakthrough_slip_m {
            k + self.k_add_m2_per_n
        } else {
            k
        }
    }
}

/// A wear mechanism a case carries beside its wear law (`wear.mechanism`), tagged `kind`: the
/// wear-law effects of the gap diagnosis with their fitted parameters. Points-based mechanisms
/// (`severe_wear` and `local_pressure` with recorded point pressures) are evaluated at the
/// lumped pressure by a run, which records no contact points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WearMechanism {
    /// K above the law's cutoff = ratio x K at the cutoff.
    WearAboveCutoff(AboveCutoff),
    /// Third-body abrasion above pressure and slip thresholds.
    ThirdBody(ThirdBody),
    /// Impact wear: volume per joule of normal damping work.
    ImpactWear(ImpactWear),
    /// Severe wear above a multiple of the yield strength.
    SevereWear(SevereWear),
    /// Local-pressure Archard (adds nothing without recorded point pressures).
    LocalPressure(LocalPressure),
    /// Coating breakthrough past a slip distance.
    CoatingBreakthrough(CoatingBreakthrough),
}

impl WearMechanism {
    /// The mechanism's name, as the effect library names it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::WearAboveCutoff(_) => "wear_above_cutoff",
            Self::ThirdBody(_) => "third_body",
            Self::ImpactWear(_) => "impact_wear",
            Self::SevereWear(_) => "severe_wear",
            Self::LocalPressure(_) => "local_pressure",
            Self::CoatingBreakthrough(_) => "coating_breakthrough",
        }
    }

    /// The mechanism of the wear-law effect `name` (the gap library's names) at the parameter
    /// values `get` gives (library names and units: dimensionless wear coefficients `k_*` are
    /// divided by `hardness_pa`, the softer body's indentation hardness, to give K in m²/N).
    /// None when `name` is not a wear-law effect.
    pub fn from_effect(name: &str, get: impl Fn(&str) -> f64, hardness_pa: f64) -> Option<Self> {
        Some(match name {
            "wear_above_cutoff" => Self::WearAboveCutoff(AboveCutoff {
                ratio: get("k_ratio_above_cutoff"),
            }),
            "third_body" => Self::ThirdBody(ThirdBody {
                k_add_m2_per_n: get("k_abrasive") / hardness_pa,
                min_pressure_pa: get("min_pressure_pa"),
                min_slip_m_s: get("min_slip_m_s"),
            }),
            "impact_wear" => Self::ImpactWear(ImpactWear {
                k_energy_m3_per_j: get("k_energy_m3_per_j"),
                min_normal_speed_m_s: get("min_normal_speed_m_s"),
            }),
            "severe_wear" => Self::SevereWear(SevereWear {
                k_add_m2_per_n: get("k_severe") / hardness_pa,
                pressure_ratio_to_yield: get("pressure_ratio_to_yield"),
            }),
            "coating_breakthrough" => Self::CoatingBreakthrough(CoatingBreakthrough {
                k_add_m2_per_n: get("k_bare") / hardness_pa,
                breakthrough_slip_m: get("breakthrough_slip_m"),
            }),
            "local_pressure" => Self::LocalPressure(LocalPressure {
                share: get("share"),
            }),
            _ => return None,
        })
    }

    fn term(&self) -> &dyn WearTerm {
        match self {
            Self::WearAboveCutoff(t) => t,
            Self::ThirdBody(t) => t,
            Self::ImpactWear(t) => t,
            Self::SevereWear(t) => t,
            Self::LocalPressure(t) => t,
            Self::CoatingBreakthrough(t) => t,
        }
    }

    /// Checks the parameters (finite, non-negative; a share in [0, 1]); the error names the
    /// field and the rule.
    pub fn validate(&self) -> Result<(), WearError> {
        let fields: Vec<(&str, f64)> = match *self {
            Self::WearAboveCutoff(t) => vec![("ratio", t.ratio)],
            Self::ThirdBody(t) => vec![
                ("k_add_m2_per_n", t.k_add_m2_per_n),
                ("min_pressure_pa", t.min_pressure_pa),
                ("min_slip_m_s", t.min_slip_m_s),
            ],
            Self::ImpactWear(t) => vec![
                ("k_energy_m3_per_j", t.k_energy_m3_per_j),
                ("min_normal_speed_m_s", t.min_normal_speed_m_s),
            ],
            Self::SevereWear(t) => vec![
                ("k_add_m2_per_n", t.k_add_m2_per_n),
                ("pressure_ratio_to_yield", t.pressure_ratio_to_yield),
            ],
            Self::LocalPressure(t) => vec![("share", t.share)],
            Self::CoatingBreakthrough(t) => vec![
                ("k_add_m2_per_n", t.k_add_m2_per_n),
                ("breakthrough_slip_m", t.breakthrough_slip_m),
            ],
        };
        for (name, value) in fields {
            if !(value.is_finite() && value >= 0.0) {
                return Err(FieldError::new(name, "must be a finite number >= 0").into());
            }
        }
        if let Self::LocalPressure(t) = self {
            if t.share > 1.0 {
                return Err(FieldError::new("share", "must be at most 1").into());
            }
        }
        Ok(())
    }
}

impl WearTerm for WearMechanism {
    fn coefficient_m2_per_n(&self, k: f64, law: &WearLaw, sample: &WearSample<'_>) -> f64 {
        self.term().coefficient_m2_per_n(k, law, sample)
    }

    fn added_volume_rate_m3_s(&self, law: &WearLaw, sample: &WearSample<'_>) -> f64 {
        self.term().added_volume_rate_m3_s(law, sample)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(points: &[PressureBin]) -> WearSample<'_> {
        WearSample {
            pressure_pa: 10.0e6,
            normal_force_n: 20.0,
            slip_speed_m_s: 0.05,
            slip_distance_m: 0.0,
            damping_power_w: 1.5,
            penetration_rate_m_s: 0.02,
            yield_strength_pa: 435.0e6,
            points,
        }
    }

    #[test]
    fn impact_wear_adds_k_e_times_damping_power() {
        let law = WearLaw::table_4_3();
        let s = sample(&[]);
        let m = WearMechanism::ImpactWear(ImpactWear {
            k_energy_m3_per_j: 2.0e-13,
            min_normal_speed_m_s: 0.0,
        });
        let base = law.volume_rate_m3_s(20.0, 0.05, 10.0e6);
        let with = volume_rate_with_terms_m3_s(&law, &[&m], &s);
        // 2e-13 m³/J x 1.5 W = 3e-13 m³/s on top of the sliding rate.
        assert!(((with - base) - 3.0e-13).abs() < 1e-25, "{with} {base}");
        // Below the normal-speed threshold nothing is added.
        let slow = WearMechanism::ImpactWear(ImpactWear {
            k_energy_m3_per_j: 2.0e-13,
            min_normal_speed_m_s: 0.03,
        });
        assert_eq!(volume_rate_with_terms_m3_s(&law, &[&slow], &s), base);
    }

    #[test]
    fn zero_magnitude_changes_nothing_bit_for_bit() {
        let law = WearLaw::table_4_3();
        let bins = [PressureBin {
            pressure_pa: 900.0e6,
            work_rate_w: 0.5,
        }];
        let s = sample(&bins);
        let base = volume_rate_with_terms_m3_s(&law, &[], &s);
        let zeros = [
            WearMechanism::WearAboveCutoff(AboveCutoff { ratio: 0.0 }),
            WearMechanism::ThirdBody(ThirdBody {
                k_add_m2_per_n: 0.0,
                min_pressure_pa: 0.0,
                min_slip_m_s: 0.0,
            }),
            WearMechanism::ImpactWear(ImpactWear {
                k_energy_m3_per_j: 0.0,
                min_normal_speed_m_s: 0.0,
            }),
            WearMechanism::SevereWear(SevereWear {
                k_add_m2_per_n: 0.0,
                pressure_ratio_to_yield: 1.0,
            }),
            WearMechanism::LocalPressure(LocalPressure { share: 0.0 }),
            WearMechanism::CoatingBreakthrough(CoatingBreakthrough {
                k_add_m2_per_n: 0.0,
                breakthrough_slip_m: 0.0,
            }),
        ];
        for m in zeros {
            let r = volume_rate_with_terms_m3_s(&law, &[&m], &s);
            assert_eq!(r.to_bits(), base.to_bits(), "{}", m.name());
        }
    }

    #[test]
    fn serde_names_the_kind_and_refuses_unknown_fields() {
        let m: WearMechanism = serde_json::from_str(
            r#"{"kind":"impact_wear","k_energy_m3_per_j":2.5e-13,"min_normal_speed_m_s":0.0}"#,
        )
        .unwrap();
        assert_eq!(m.name(), "impact_wear");
        assert!(serde_json::from_str::<WearMechanism>(
            r#"{"kind":"impact_wear","k_energy":1.0,"min_normal_speed_m_s":0.0}"#
        )
        .is_err());
        let bad = WearMechanism::ImpactWear(ImpactWear {
            k_energy_m3_per_j: -1.0,
            min_normal_speed_m_s: 0.0,
        });
        assert!(bad.validate().is_err());
    }
}
