//! Effects only the virtual rig knows (issue 14 item 4): physical and documented, but absent
//! from the diagnosis' library ([`super::effects::LIBRARY`]), so that a diagnosis claiming to
//! explain a rig campaign made with one of them can be caught.
//!
//! Both act on the wear coefficient and lower it, where every library wear-law effect raises
//! it: no library effect at any magnitude reproduces them. Each is its own wear term, declared
//! with its parameters' units, bounds and reasons (`parameter_struct!`); [`RIG_ONLY`] is built
//! from them and [`HiddenEffect`] holds one, typed.

use super::effects::{parse_spec, Acts, EffectInfo};
use super::tracks::{WearSample, WearTerm};
use super::GapError;
use crate::models::spec::ModelKind;
use crate::parameters::{parameter_struct, Parameters};
use crate::wear::law::WearLaw;
use std::collections::BTreeMap;

const BOTH: &[ModelKind] = &[ModelKind::RattleBox, ModelKind::Launcher];

parameter_struct! {
    /// K x (1 - reduction) below the breakdown pressure.
    pub struct SurfaceOxide = "surface_oxide" {
        reduction {
            unit: "1 (fraction of K removed below the breakdown pressure)",
            min: 0.0,
            max: 1.0,
            default: 0.0,
            reason: "oxide films cut mild-wear K by one to two orders while intact (Quinn's oxidational wear; Archard & Hirst 1956)",
        },
        breakdown_pressure_pa {
            unit: "Pa",
            min: 1.0e6,
            max: 1.0e9,
            default: 5.0e7,
            reason: "estimate: hard anodize (Al2O3, 25-50 µm) on 7075 cracks once the substrate yields locally; a few tens of MPa mean pressure start that at asperities",
        },
    }
}

parameter_struct! {
    /// K x (1 - reduction (1 - exp(-s/s0))).
    pub struct WorkHardening = "work_hardening" {
        reduction {
            unit: "1 (fraction of K removed once fully hardened)",
            min: 0.0,
            max: 0.9,
            default: 0.0,
            reason: "Archard K scales as 1/H; sliding raises the surface hardness of aluminium alloys up to 2-3x (Rigney 1988), so K falls by up to about 70-90 %",
        },
        slip_scale_m {
            unit: "m",
            min: 1.0,
            max: 1.0e4,
            default: 50.0,
            reason: "estimate: the near-surface layer saturates within tens to thousands of metres of sliding",
        },
    }
}

/// The rig-only effects.
pub const RIG_ONLY: &[EffectInfo] = &[
    EffectInfo {
        name: SurfaceOxide::NAME,
        letter: '-',
        summary: "a hard surface oxide (the anodize) carries light contacts: K scaled by 1 - reduction below the pressure at which the layer breaks",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: SurfaceOxide::PARAMETERS,
        reason: "thesis 5.3.1: cube and tube are anodized; Table 4.3 was fitted on pads whose anodize was worn in",
        limitation: None,
    },
    EffectInfo {
        name: WorkHardening::NAME,
        letter: '-',
        summary: "the worn surface work-hardens: K scaled by 1 - reduction (1 - exp(-s/s0)) with the specimen's accumulated slip distance s",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: WorkHardening::PARAMETERS,
        reason: "cases C and D ran three increments on one specimen (thesis 5.5): a hardening surface would lower later increments",
        limitation: None,
    },
];

/// A rig-only effect with its parameter values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HiddenEffect {
    /// A surface oxide that carries light contacts.
    SurfaceOxide(SurfaceOxide),
    /// A surface that work-hardens with slip distance.
    WorkHardening(WorkHardening),
}

impl HiddenEffect {
    /// Parses `name=magnitude[,param=value...]` against [`RIG_ONLY`].
    pub fn parse(text: &str) -> Result<Self, GapError> {
        let (name, values) = parse_spec(text, RIG_ONLY)?;
        let typed = match name {
            SurfaceOxide::NAME => Parameters::from_values(&values).map(Self::SurfaceOxide),
            WorkHardening::NAME => Parameters::from_values(&values).map(Self::WorkHardening),
            other => {
                return Err(GapError::field(
                    "effect",
                    format!("no wear term for the rig-only effect `{other}`"),
                ))
            }
        };
        typed.map_err(|e| GapError::field(format!("effect.{name}.{}", e.field), e.rule))
    }

    /// Its name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::SurfaceOxide(_) => SurfaceOxide::NAME,
            Self::WorkHardening(_) => WorkHardening::NAME,
        }
    }

    /// Its parameters by name.
    pub fn parameters(&self) -> BTreeMap<String, f64> {
        match self {
            Self::SurfaceOxide(p) => p.values(),
            Self::WorkHardening(p) => p.values(),
        }
    }

    /// The magnitude (first parameter of its [`RIG_ONLY`] entry; 0 = no effect).
    pub fn magnitude(&self) -> f64 {
        match self {
            Self::SurfaceOxide(p) => p.magnitude(),
            Self::WorkHardening(p) => p.magnitude(),
        }
    }

    /// Its wear term.
    pub fn wear_term(&self) -> Box<dyn WearTerm> {
        match *self {
            Self::SurfaceOxide(t) => Box::new(t),
            Self::WorkHardening(t) => Box::new(t),
        }
    }
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

impl WearTerm for WorkHardening {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample) -> f64 {
        if self.reduction == 0.0 {
            return k;
        }
        k * (1.0 - self.reduction * (1.0 - (-s.slip_distance_m / self.slip_scale_m).exp()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rig-only name, its parameters and the term's fields cannot drift apart: each entry
    /// parses into its own term and gives back exactly the parameters it lists.
    #[test]
    fn every_rig_only_parameter_is_a_field_of_its_term() {
        for info in RIG_ONLY {
            let hidden = HiddenEffect::parse(&format!("{}=0", info.name)).unwrap();
            assert_eq!(hidden.name(), info.name);
            let mut names: Vec<&str> = info.parameters.iter().map(|p| p.name).collect();
            names.sort_unstable();
            let read: Vec<String> = hidden.parameters().into_keys().collect();
            assert_eq!(read, names, "{}", info.name);
            assert_eq!(hidden.magnitude(), 0.0);
        }
    }
}
