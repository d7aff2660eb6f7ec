//! Effects only the virtual rig knows (issue 14 item 4): physical and documented, but absent
//! from the diagnosis' library ([`super::effects::LIBRARY`]), so that a diagnosis claiming to
//! explain a rig campaign made with one of them can be caught.
//!
//! Both act on the wear coefficient and lower it, where every library wear-law effect raises
//! it: no library effect at any magnitude reproduces them.

use super::effects::{parse_spec, Acts, EffectInfo, ParameterInfo};
use super::tracks::{WearSample, WearTerm};
use super::GapError;
use crate::models::spec::ModelKind;
use crate::wear::law::WearLaw;
use std::collections::BTreeMap;

const BOTH: &[ModelKind] = &[ModelKind::RattleBox, ModelKind::Launcher];

/// The rig-only effects.
pub const RIG_ONLY: &[EffectInfo] = &[
    EffectInfo {
        name: "surface_oxide",
        letter: '-',
        summary: "a hard surface oxide (the anodize) carries light contacts: K scaled by 1 - reduction below the pressure at which the layer breaks",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "reduction",
                unit: "1 (fraction of K removed below the breakdown pressure)",
                min: 0.0,
                max: 1.0,
                default: 0.0,
                reason: "oxide films cut mild-wear K by one to two orders while intact (Quinn's oxidational wear; Archard & Hirst 1956)",
            },
            ParameterInfo {
                name: "breakdown_pressure_pa",
                unit: "Pa",
                min: 1.0e6,
                max: 1.0e9,
                default: 5.0e7,
                reason: "estimate: hard anodize (Al2O3, 25-50 µm) on 7075 cracks once the substrate yields locally; a few tens of MPa mean pressure start that at asperities",
            },
        ],
        reason: "thesis 5.3.1: cube and tube are anodized; Table 4.3 was fitted on pads whose anodize was worn in",
        limitation: None,
    },
    EffectInfo {
        name: "work_hardening",
        letter: '-',
        summary: "the worn surface work-hardens: K scaled by 1 - reduction (1 - exp(-s/s0)) with the specimen's accumulated slip distance s",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "reduction",
                unit: "1 (fraction of K removed once fully hardened)",
                min: 0.0,
                max: 0.9,
                default: 0.0,
                reason: "Archard K scales as 1/H; sliding raises the surface hardness of aluminium alloys up to 2-3x (Rigney 1988), so K falls by up to about 70-90 %",
            },
            ParameterInfo {
                name: "slip_scale_m",
                unit: "m",
                min: 1.0,
                max: 1.0e4,
                default: 50.0,
                reason: "estimate: the near-surface layer saturates within tens to thousands of metres of sliding",
            },
        ],
        reason: "cases C and D ran three increments on one specimen (thesis 5.5): a hardening surface would lower later increments",
        limitation: None,
    },
];

/// A rig-only effect with its parameter values.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HiddenEffect {
    /// Name.
    pub name: String,
    /// Parameters by name (defaults filled in).
    pub parameters: BTreeMap<String, f64>,
}

impl HiddenEffect {
    /// Parses `name=magnitude[,param=value...]` against [`RIG_ONLY`].
    pub fn parse(text: &str) -> Result<Self, GapError> {
        let (name, parameters) = parse_spec(text, RIG_ONLY)?;
        Ok(Self {
            name: name.to_string(),
            parameters,
        })
    }

    fn get(&self, name: &str) -> f64 {
        self.parameters.get(name).copied().unwrap_or(0.0)
    }

    /// The magnitude (first parameter of its [`RIG_ONLY`] entry; 0 = no effect).
    pub fn magnitude(&self) -> f64 {
        RIG_ONLY
            .iter()
            .find(|e| e.name == self.name)
            .map_or(0.0, |e| self.get(e.parameters[0].name))
    }

    /// Its wear term.
    pub fn wear_term(&self) -> Box<dyn WearTerm> {
        match self.name.as_str() {
            "surface_oxide" => Box::new(SurfaceOxide {
                reduction: self.get("reduction"),
                breakdown_pressure_pa: self.get("breakdown_pressure_pa"),
            }),
            _ => Box::new(WorkHardening {
                reduction: self.get("reduction"),
                slip_scale_m: self.get("slip_scale_m"),
            }),
        }
    }
}

/// K x (1 - reduction) below the breakdown pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceOxide {
    /// Fraction of K removed.
    pub reduction: f64,
    /// Breakdown pressure, Pa.
    pub breakdown_pressure_pa: f64,
}

impl WearTerm for SurfaceOxide {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample) -> f64 {
        if self.reduction != 0.0 && s.pressure_pa < self.breakdown_pressure_pa {
            k * (1.0 - self.reduction)
        } else {
            k
        }
    }
}

/// K x (1 - reduction (1 - exp(-s/s0))).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkHardening {
    /// Fraction of K removed when saturated.
    pub reduction: f64,
    /// Slip scale, m.
    pub slip_scale_m: f64,
}

impl WearTerm for WorkHardening {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample) -> f64 {
        if self.reduction == 0.0 {
            return k;
        }
        k * (1.0 - self.reduction * (1.0 - (-s.slip_distance_m / self.slip_scale_m).exp()))
    }
}
