//! Wear mechanisms beyond sliding Archard at the lumped pressure (issue 26): what each sees at a
//! sample ([`WearSample`]), the terms ([`WearTerm`]) and the closed set a case or a sweep can
//! carry ([`WearMechanism`]).
//!
//! The gap diagnosis (`gap::effects`, wear-law effects, typed here as [`WearEffect`] in the
//! library's names and units) evaluates these terms on recorded tracks and fits their
//! coefficients; a run (`models::run`) integrates the same terms per track while
//! it goes, when its case's `wear.mechanism` names one. Both call the code here, so a fitted
//! mechanism carried to a sweep is the mechanism the diagnosis fitted. Each term at magnitude 0
//! changes nothing, bit for bit.

use super::law::WearLaw;
use super::WearError;
use crate::field_error::FieldError;
use crate::parameters::{parameter_struct, Parameters};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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
            Self::WearAboveCutoff(_) => AboveCutoffParameters::NAME,
            Self::ThirdBody(_) => ThirdBodyParameters::NAME,
            Self::ImpactWear(_) => ImpactWearParameters::NAME,
            Self::SevereWear(_) => SevereWearParameters::NAME,
            Self::LocalPressure(_) => LocalPressureParameters::NAME,
            Self::CoatingBreakthrough(_) => CoatingBreakthroughParameters::NAME,
        }
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
            FieldError::non_negative(name, value)?;
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

parameter_struct! {
    /// (a) The gap library's `wear_above_cutoff`: K above the cutoff as a multiple of K there.
    pub struct AboveCutoffParameters = "wear_above_cutoff" {
        k_ratio_above_cutoff {
            unit: "1 (K above the cutoff / K(cutoff))",
            min: 0.0,
            max: 1000.0,
            default: 0.0,
            reason: "wear maps (Lim & Ashby 1987) put the mild-to-severe transition at contact pressures near the hardness, with K rising 100-1000x across it; thesis 5.5 and Fig. 5.7 show plastic flow at case A's corners",
        },
    }
}

parameter_struct! {
    /// (b) The gap library's `third_body`: three-body abrasion above pressure and slip
    /// thresholds.
    pub struct ThirdBodyParameters = "third_body" {
        k_abrasive {
            unit: "1 (dimensionless Archard k; K_add = k/H)",
            min: 0.0,
            max: 1.0e-2,
            default: 0.0,
            reason: "three-body abrasive wear coefficients 5e-4 to 5e-3 (Hutchings, Tribology, 1992; Rabinowicz 1995), up to 1e-2 for sharp sand",
        },
        min_pressure_pa {
            unit: "Pa",
            min: 1.0e2,
            max: 1.0e8,
            default: 1.0e4,
            reason: "estimate: a few trapped particles carry the load, so they cut at nominal pressures far below the hardness; 10 kPa is above a resting rattle-box cube's own weight (0.7 kPa), so mere resting does not grind; uncertain by orders (100 Pa to 100 MPa)",
        },
        min_slip_m_s {
            unit: "m/s",
            min: 0.0,
            max: 0.1,
            default: 1.0e-3,
            reason: "estimate: below about 1 mm/s (the Table 5.2 stiction speed is 6.5 mm/s) the surfaces stick and trapped particles are not dragged",
        },
    }
}

parameter_struct! {
    /// (i) The gap library's `impact_wear`: volume per joule of normal damping work.
    pub struct ImpactWearParameters = "impact_wear" {
        k_energy_m3_per_j {
            unit: "m³/J (wear volume per joule of normal damping work)",
            min: 0.0,
            max: 1.0e-11,
            default: 0.0,
            reason: "dissipated-energy wear (Fouvry et al., Wear 2003; Huq & Celis, Wear 2002) measures 1e-15 to 1e-13 m³/J for steels and coatings in fretting; an Archard k/(H mu) for aluminium alloys in dry contact, k = 1e-6 (mild, oxidised) to 1e-2 (severe, adhesive) (Archard 1953; Hutchings 1992), H = 1.32 GPa, mu = 0.5, spans 1.5e-15 to 1.5e-11 m³/J; Engel (Impact Wear of Materials, 1976) finds repeated normal impact removes material by the same fatigue and plastic mechanisms, so the sliding range bounds it",
        },
        min_normal_speed_m_s {
            unit: "m/s (|penetration rate| below which damping work does not wear)",
            min: 0.0,
            max: 0.5,
            default: 0.0,
            reason: "Engel's impact wear has a threshold below which impacts only deform elastically; a sliding contact's micro-motion (normal speeds of mm/s) dissipates without removing material; 0.5 m/s is above the rattle boxes' impact speeds (15 g at 20 Hz moves the tube at 1.2 m/s peak)",
        },
    }
}

parameter_struct! {
    /// (j) The gap library's `severe_wear`: added K where the local pressure exceeds a
    /// multiple of the yield strength.
    pub struct SevereWearParameters = "severe_wear" {
        k_severe {
            unit: "1 (dimensionless Archard k; K_add = k/H)",
            min: 0.0,
            max: 1.0e-2,
            default: 0.0,
            reason: "severe (adhesive, plastic) wear of aluminium alloys: dimensionless k of 1e-4 to 1e-2 (Archard 1953; Lim & Ashby, Acta Metall. 1987; Hutchings 1992), against 1e-7 to 1e-5 in mild wear",
        },
        pressure_ratio_to_yield {
            unit: "1 (local pressure / yield strength Sy where severe wear starts)",
            min: 0.5,
            max: 3.0,
            default: 1.0,
            reason: "the mild-to-severe transition lies where the local pressure reaches the flow stress: about Sy at first yield, up to the hardness (about 3 Sy, Tabor) at full plasticity (Lim & Ashby 1987); 0.5 Sy allows for the stress concentration of a rough surface",
        },
    }
}

parameter_struct! {
    /// (k) The gap library's `local_pressure`: a share of the wear at the contact points'
    /// own pressures.
    pub struct LocalPressureParameters = "local_pressure" {
        share {
            unit: "1 (0 = lumped N/A as the thesis, 1 = every point at its own pressure)",
            min: 0.0,
            max: 1.0,
            default: 0.0,
            reason: "eq. 3.11 was written for a face's mean pressure; whether a real contact wears at the mean or at its local pressures is the modelling question, so every share between is allowed",
        },
    }
}

parameter_struct! {
    /// (l) The gap library's `coating_breakthrough`: added K past a slip distance.
    pub struct CoatingBreakthroughParameters = "coating_breakthrough" {
        k_bare {
            unit: "1 (dimensionless Archard k of the bare alloy; K_add = k/H)",
            min: 0.0,
            max: 1.0e-2,
            default: 0.0,
            reason: "bare aluminium alloy on anodized or bare aluminium in dry sliding wears adhesively: k of 1e-5 to 1e-2 (Archard 1953; ASM Handbook 18, 1992), against 1e-7 to 1e-6 for an intact hard anodize",
        },
        breakthrough_slip_m {
            unit: "m (slip distance at which the coating is worn through)",
            min: 1.0,
            max: 1.0e5,
            default: 1.0e3,
            reason: "sulphuric (type II) anodize is 5-25 µm thick, hard (type III) 25-100 µm (MIL-A-8625); worn at 1e-8-1e-6 µm per N·m of the mild regime under the rattle boxes' 1-10 N loads it lasts 1 m to 100 km of sliding",
        },
    }
}

/// A wear-law effect of the gap library (`gap::effects`) with its parameters in the library's
/// names and units (dimensionless wear coefficients `k_*` before the hardness divides them):
/// what a diagnosis fits and a sweep carries. [`WearEffect::mechanism`] gives the
/// [`WearMechanism`] a run integrates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WearEffect {
    /// (a) Wear above the eq. 3.11 cutoff.
    WearAboveCutoff(AboveCutoffParameters),
    /// (b) Third-body abrasion.
    ThirdBody(ThirdBodyParameters),
    /// (i) Impact wear.
    ImpactWear(ImpactWearParameters),
    /// (j) Severe wear.
    SevereWear(SevereWearParameters),
    /// (k) Local-pressure Archard.
    LocalPressure(LocalPressureParameters),
    /// (l) Coating breakthrough.
    CoatingBreakthrough(CoatingBreakthroughParameters),
}

impl WearEffect {
    /// The wear-law effect `name` at `values` (every parameter by its library name; a missing
    /// or unknown name is an error naming it). None when `name` is not a wear-law effect.
    pub fn from_values(
        name: &str,
        values: &BTreeMap<String, f64>,
    ) -> Result<Option<Self>, FieldError> {
        Ok(Some(match name {
            AboveCutoffParameters::NAME => Self::WearAboveCutoff(Parameters::from_values(values)?),
            ThirdBodyParameters::NAME => Self::ThirdBody(Parameters::from_values(values)?),
            ImpactWearParameters::NAME => Self::ImpactWear(Parameters::from_values(values)?),
            SevereWearParameters::NAME => Self::SevereWear(Parameters::from_values(values)?),
            LocalPressureParameters::NAME => Self::LocalPressure(Parameters::from_values(values)?),
            CoatingBreakthroughParameters::NAME => {
                Self::CoatingBreakthrough(Parameters::from_values(values)?)
            }
            _ => return Ok(None),
        }))
    }

    /// The values by library name.
    pub fn values(&self) -> BTreeMap<String, f64> {
        match self {
            Self::WearAboveCutoff(p) => p.values(),
            Self::ThirdBody(p) => p.values(),
            Self::ImpactWear(p) => p.values(),
            Self::SevereWear(p) => p.values(),
            Self::LocalPressure(p) => p.values(),
            Self::CoatingBreakthrough(p) => p.values(),
        }
    }

    /// The magnitude (first parameter; 0 = the nominal wear law).
    pub fn magnitude(&self) -> f64 {
        match self {
            Self::WearAboveCutoff(p) => p.magnitude(),
            Self::ThirdBody(p) => p.magnitude(),
            Self::ImpactWear(p) => p.magnitude(),
            Self::SevereWear(p) => p.magnitude(),
            Self::LocalPressure(p) => p.magnitude(),
            Self::CoatingBreakthrough(p) => p.magnitude(),
        }
    }

    /// The mechanism for a contact whose softer body has indentation hardness `hardness_pa`
    /// (dimensionless coefficients `k_*` divided by it give K in m²/N).
    pub fn mechanism(&self, hardness_pa: f64) -> WearMechanism {
        match *self {
            Self::WearAboveCutoff(p) => WearMechanism::WearAboveCutoff(AboveCutoff {
                ratio: p.k_ratio_above_cutoff,
            }),
            Self::ThirdBody(p) => WearMechanism::ThirdBody(ThirdBody {
                k_add_m2_per_n: p.k_abrasive / hardness_pa,
                min_pressure_pa: p.min_pressure_pa,
                min_slip_m_s: p.min_slip_m_s,
            }),
            Self::ImpactWear(p) => WearMechanism::ImpactWear(ImpactWear {
                k_energy_m3_per_j: p.k_energy_m3_per_j,
                min_normal_speed_m_s: p.min_normal_speed_m_s,
            }),
            Self::SevereWear(p) => WearMechanism::SevereWear(SevereWear {
                k_add_m2_per_n: p.k_severe / hardness_pa,
                pressure_ratio_to_yield: p.pressure_ratio_to_yield,
            }),
            Self::LocalPressure(p) => {
                WearMechanism::LocalPressure(LocalPressure { share: p.share })
            }
            Self::CoatingBreakthrough(p) => {
                WearMechanism::CoatingBreakthrough(CoatingBreakthrough {
                    k_add_m2_per_n: p.k_bare / hardness_pa,
                    breakthrough_slip_m: p.breakthrough_slip_m,
                })
            }
        }
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

    #[test]
    fn each_wear_effect_reads_its_own_names_and_names_its_mechanism() {
        fn check<P: Parameters>(wrap: fn(P) -> WearEffect) {
            let d = P::defaults();
            let e = WearEffect::from_values(P::NAME, &d.values()).unwrap();
            assert_eq!(e, Some(wrap(d)), "{}", P::NAME);
            assert_eq!(wrap(d).mechanism(1.32e9).name(), P::NAME);
            assert_eq!(wrap(d).values(), d.values());
        }
        check(WearEffect::WearAboveCutoff);
        check(WearEffect::ThirdBody);
        check(WearEffect::ImpactWear);
        check(WearEffect::SevereWear);
        check(WearEffect::LocalPressure);
        check(WearEffect::CoatingBreakthrough);
        assert_eq!(
            WearEffect::from_values("cross_axis", &BTreeMap::new()),
            Ok(None)
        );
    }
}
