//! The effect library: candidate unmodelled effects, each an optional model term with few
//! parameters, shared by the virtual rig and the diagnosis (SPEC 7, issue 14 item 3).
//!
//! The effects are a closed set, [`EffectKind`]; each kind has its own parameter struct,
//! declared with its units, bounds, defaults and reasons in one place (`parameter_struct!`:
//! the wear-law effects' in `wear::mechanism`, the dynamics effects' here), and the library
//! table users read ([`LIBRARY`], [`EffectInfo`]) is generated from the kinds. An [`Effect`]
//! keeps its values by name for reports and generic profiling; the code that applies it reads
//! them once into a [`TypedEffect`] (a missing or unknown name is an error, never 0) and
//! matches on it exhaustively:
//! - wear-law effects ([`Acts::WearLaw`]) give a [`WearTerm`] evaluated on recorded tracks
//!   (`gap::tracks`), never re-simulating;
//! - dynamics effects ([`Acts::Dynamics`]) edit the case before a segment is simulated, given
//!   the specimen's state (test time, slip distance) at that segment.
//!
//! The first parameter of each effect is its magnitude; magnitude 0 is the nominal model, and
//! an effect at magnitude 0 leaves the case and the wear unchanged bit for bit.

pub use super::drive_edits::transmissibility;
pub use super::dynamics_effects::{
    ClearanceGrowthParameters, CrossAxisParameters, FixtureComplianceParameters,
    FrictionDriftParameters, PreloadLossParameters, SharpEdgesParameters, SpecimenState,
};
use super::tracks::WearTerm;
use super::GapError;
use crate::field_error::FieldError;
use crate::models::spec::{CaseSpec, ModelKind};
pub use crate::parameters::ParameterInfo;
use crate::parameters::Parameters;
pub use crate::wear::mechanism::{
    AboveCutoff, CoatingBreakthrough, ImpactWear, LocalPressure, SevereWear, ThirdBody,
};
use crate::wear::mechanism::{
    AboveCutoffParameters, CoatingBreakthroughParameters, ImpactWearParameters,
    LocalPressureParameters, SevereWearParameters, ThirdBodyParameters, WearEffect, WearMechanism,
};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// What an effect changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Acts {
    /// The wear coefficient only: re-evaluated on recorded tracks.
    WearLaw,
    /// The model or its drive: the segment is simulated with the edited case.
    Dynamics,
}

/// One effect of the library.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EffectInfo {
    /// Name used on the command line and in results.
    pub name: &'static str,
    /// Issue 14 item 3 letter.
    pub letter: char,
    /// What it models.
    pub summary: &'static str,
    /// Wear law or dynamics.
    pub acts: Acts,
    /// Models it applies to.
    pub models: &'static [ModelKind],
    /// Parameters; the first is the magnitude (0 = nominal model).
    pub parameters: &'static [ParameterInfo],
    /// Physical reason, with sources.
    pub reason: &'static str,
    /// Approximation or limitation of this implementation, if any.
    pub limitation: Option<&'static str>,
}

const BOTH: &[ModelKind] = &[ModelKind::RattleBox, ModelKind::Launcher];

/// The effects of the library, in issue order: (a)-(h) of issue 14, (i)-(l) of issue 26 (wear
/// mechanisms beyond sliding Archard at the lumped pressure).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EffectKind {
    /// (a) Wear above the eq. 3.11 cutoff.
    WearAboveCutoff,
    /// (b) Third-body abrasion.
    ThirdBody,
    /// (c) Clearance growth.
    ClearanceGrowth,
    /// (d) Friction drift.
    FrictionDrift,
    /// (e) Fixture compliance.
    FixtureCompliance,
    /// (f) Cross-axis excitation.
    CrossAxis,
    /// (g) Sharper edges.
    SharpEdges,
    /// (h) Launcher spring preload loss.
    PreloadLoss,
    /// (i) Impact wear.
    ImpactWear,
    /// (j) Severe wear.
    SevereWear,
    /// (k) Local-pressure Archard.
    LocalPressure,
    /// (l) Anodic-coating breakthrough.
    CoatingBreakthrough,
}

impl EffectKind {
    /// Every kind, in library order (the declaration order).
    pub const ALL: [Self; 12] = [
        Self::WearAboveCutoff,
        Self::ThirdBody,
        Self::ClearanceGrowth,
        Self::FrictionDrift,
        Self::FixtureCompliance,
        Self::CrossAxis,
        Self::SharpEdges,
        Self::PreloadLoss,
        Self::ImpactWear,
        Self::SevereWear,
        Self::LocalPressure,
        Self::CoatingBreakthrough,
    ];

    /// Its library entry.
    pub fn info(self) -> &'static EffectInfo {
        &LIBRARY[self as usize]
    }

    /// The kind named `name` in the library.
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.info().name == name)
    }

    /// The library entry: name and parameters from the kind's parameter struct.
    const fn describe(self) -> EffectInfo {
        match self {
            Self::WearAboveCutoff => EffectInfo {
                name: AboveCutoffParameters::NAME,
                letter: 'a',
                summary: "impact/plastic wear above the eq. 3.11 cutoff (2 Sy): K above it is a multiple of K at the cutoff instead of 0",
                acts: Acts::WearLaw,
                models: BOTH,
                parameters: AboveCutoffParameters::PARAMETERS,
                reason: "eq. 3.11 sets K = 0 above 2 Sy; thesis 5.5 reports the loose cases' pressures above yield and their measured wear 10-30x ADAMS'",
                limitation: None,
            },
            Self::ThirdBody => EffectInfo {
                name: ThirdBodyParameters::NAME,
                letter: 'b',
                summary: "three-body abrasion by trapped debris or sand: K raised by k_abr/H where pressure and slip let particles cut",
                acts: Acts::WearLaw,
                models: BOTH,
                parameters: ThirdBodyParameters::PARAMETERS,
                reason: "SPEC 7 lists third-body abrasion (sand, dust, wear debris trapped in a closed tube) as unmodelled; railwear's environment is `clean` only",
                limitation: None,
            },
            Self::ClearanceGrowth => EffectInfo {
                name: ClearanceGrowthParameters::NAME,
                letter: 'c',
                summary: "clearance opening as wear accumulates: the rattle box's tube side (launcher: the material condition) grows with test time, updated between segments",
                acts: Acts::Dynamics,
                models: BOTH,
                parameters: ClearanceGrowthParameters::PARAMETERS,
                reason: "the thesis' model keeps the nominal enclosure; cases C and D ran 4.5 h on one specimen (thesis 5.5), their rate rising 1.53 -> 2.33 and 0.17 -> 0.87 mg/h",
                limitation: Some("the opening is a rate per test hour, not computed from the simulated wear: railwear's simulated wear is two orders below the measured (docs/results/validation.md), so it would open nothing"),
            },
            Self::FrictionDrift => EffectInfo {
                name: FrictionDriftParameters::NAME,
                letter: 'd',
                summary: "friction drift: mu_s and mu_d shift by delta_mu (1 - exp(-s/s0)) with the accumulated slip distance s, updated between segments",
                acts: Acts::Dynamics,
                models: BOTH,
                parameters: FrictionDriftParameters::PARAMETERS,
                reason: "Table 5.2 friction was fitted on fresh anodized pads (thesis 4.5); the specimens run hours",
                limitation: None,
            },
            Self::FixtureCompliance => EffectInfo {
                name: FixtureComplianceParameters::NAME,
                letter: 'e',
                summary: "fixture compliance: the tube (rail) mounted through a spring-damper; the drive it sees is the shaker's through the mount's base-excitation transmissibility",
                acts: Acts::Dynamics,
                models: BOTH,
                parameters: FixtureComplianceParameters::PARAMETERS,
                reason: "the thesis drives the tube rigidly (motion generator, 5.4); Figures 5.1-5.2 show a bolted fixture",
                limitation: Some("approximation: tones (and random PSD breakpoints) are scaled by |T(f)| and phase-shifted; the cube's reaction on the mount is not modelled (a dynamic tube body needs a model-builder change); measured drives are refused"),
            },
            Self::CrossAxis => EffectInfo {
                name: CrossAxisParameters::NAME,
                letter: 'f',
                summary: "cross-axis excitation: each drive tone repeated on the two other axes at a share of its amplitude",
                acts: Acts::Dynamics,
                models: BOTH,
                parameters: CrossAxisParameters::PARAMETERS,
                reason: "the thesis drives one axis only (15 g at 20 Hz transverse, 5.5); real shakers move on the other axes too",
                limitation: Some("tones only: a random background stays on its own axes"),
            },
            Self::SharpEdges => EffectInfo {
                name: SharpEdgesParameters::NAME,
                letter: 'g',
                summary: "sharper edges than nominal: every roundover (cube, shoes, latch tooth, front pad) scaled by 1 - reduction",
                acts: Acts::Dynamics,
                models: BOTH,
                parameters: SharpEdgesParameters::PARAMETERS,
                reason: "a smaller roundover concentrates edge contacts: higher pressure, more work above the cutoff (thesis 5.4)",
                limitation: None,
            },
            Self::PreloadLoss => EffectInfo {
                name: PreloadLossParameters::NAME,
                letter: 'h',
                summary: "launcher spring preload loss: latch coil spring and rear leaf spring preloads scaled by 1 - loss",
                acts: Acts::Dynamics,
                models: &[ModelKind::Launcher],
                parameters: PreloadLossParameters::PARAMETERS,
                reason: "thesis 6.3.1: the rear leaf spring may not engage when static; a lost preload lets the missile rattle",
                limitation: None,
            },
            Self::ImpactWear => EffectInfo {
                name: ImpactWearParameters::NAME,
                letter: 'i',
                summary: "impact wear: a volume k_E times the energy the contact's normal (IMPACT) damping dissipates, counted while the normal speed is at least a threshold",
                acts: Acts::WearLaw,
                models: BOTH,
                parameters: ImpactWearParameters::PARAMETERS,
                reason: "the energy account shows the contact's IMPACT damping dissipating 10-100x the friction work (rattle box C: about 1.5 W against 0.02 W); thesis 5.5 and Fig. 5.7 point at impact stresses above yield and plastic flow at the corners",
                limitation: Some("the damping work is the IMPACT law's (c_max, STEP over the penetration depth d), not a measured restitution: it is as good as Table 5.2's damping"),
            },
            Self::SevereWear => EffectInfo {
                name: SevereWearParameters::NAME,
                letter: 'j',
                summary: "severe (plastic) wear: K raised by k_severe/H at contact points whose own pressure exceeds a multiple of the yield strength",
                acts: Acts::WearLaw,
                models: BOTH,
                parameters: SevereWearParameters::PARAMETERS,
                reason: "thesis 5.5 and Fig. 5.7: impact stresses above yield and plastic flow at case A's corners; the lumped pressure N/A of eq. 3.11 averages over the face, the contact points' own pressures (gap::tracks) do not",
                limitation: Some("local pressures from the contact points' share of the face law (gap::tracks), binned at 1/50 decade; on tracks recorded without points the lumped pressure stands in"),
            },
            Self::LocalPressure => EffectInfo {
                name: LocalPressureParameters::NAME,
                letter: 'k',
                summary: "local-pressure Archard: the case's K(sigma) evaluated at each contact point's own pressure instead of the lumped N/A, for a share of the wear",
                acts: Acts::WearLaw,
                models: BOTH,
                parameters: LocalPressureParameters::PARAMETERS,
                reason: "a tilted face or an edge loads its deeper points above the mean; Table 4.3's K rises with pressure and cuts off at 2 Sy, so local pressures can raise the wear, or lower it where points exceed the cutoff",
                limitation: Some("on tracks recorded without points it changes nothing"),
            },
            Self::CoatingBreakthrough => EffectInfo {
                name: CoatingBreakthroughParameters::NAME,
                letter: 'l',
                summary: "anodic-coating breakthrough: K raised by k_bare/H once the specimen has slid past the distance that wears the coating through",
                acts: Acts::WearLaw,
                models: BOTH,
                parameters: CoatingBreakthroughParameters::PARAMETERS,
                reason: "the thesis' cubes are anodized 7075 (5.4) and Table 4.3 was fitted on fresh anodized pads; cases C and D wore faster in their later increments (1.53 -> 2.33 and 0.17 -> 0.87 mg/h, Table 5.3), as a worn-through coating would",
                limitation: Some("the breakthrough is a slip distance, not a worn depth: the local depth would need the wear's distribution over the face"),
            },
        }
    }
}

// `EffectKind::info` indexes the library by the kind's discriminant.
const _: () = {
    let mut i = 0;
    while i < EffectKind::ALL.len() {
        assert!(EffectKind::ALL[i] as usize == i);
        i += 1;
    }
};

const fn library() -> [EffectInfo; EffectKind::ALL.len()] {
    let mut out = [EffectKind::ALL[0].describe(); EffectKind::ALL.len()];
    let mut i = 1;
    while i < out.len() {
        out[i] = EffectKind::ALL[i].describe();
        i += 1;
    }
    out
}

/// The library, in issue order (generated from [`EffectKind`]).
pub const LIBRARY: &[EffectInfo] = &library();

/// Looks an effect up by name.
pub fn info(name: &str) -> Option<&'static EffectInfo> {
    EffectKind::named(name).map(EffectKind::info)
}

/// An effect with its parameters typed: one parameter struct per kind, so the code applying
/// an effect matches on it exhaustively and reads fields, not names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TypedEffect {
    /// A wear-law effect (a)(b)(i)-(l): a term of the wear law.
    Wear(WearEffect),
    /// (c) Clearance growth.
    ClearanceGrowth(ClearanceGrowthParameters),
    /// (d) Friction drift.
    FrictionDrift(FrictionDriftParameters),
    /// (e) Fixture compliance.
    FixtureCompliance(FixtureComplianceParameters),
    /// (f) Cross-axis excitation.
    CrossAxis(CrossAxisParameters),
    /// (g) Sharper edges.
    SharpEdges(SharpEdgesParameters),
    /// (h) Launcher spring preload loss.
    PreloadLoss(PreloadLossParameters),
}

impl TypedEffect {
    /// The effect of `kind` at `values` (every parameter by its library name). A missing or
    /// unknown name is an error whose field is that name.
    pub fn from_values(
        kind: EffectKind,
        values: &BTreeMap<String, f64>,
    ) -> Result<Self, FieldError> {
        use WearEffect as W;
        let v = values;
        Ok(match kind {
            EffectKind::WearAboveCutoff => {
                Self::Wear(W::WearAboveCutoff(Parameters::from_values(v)?))
            }
            EffectKind::ThirdBody => Self::Wear(W::ThirdBody(Parameters::from_values(v)?)),
            EffectKind::ClearanceGrowth => Self::ClearanceGrowth(Parameters::from_values(v)?),
            EffectKind::FrictionDrift => Self::FrictionDrift(Parameters::from_values(v)?),
            EffectKind::FixtureCompliance => Self::FixtureCompliance(Parameters::from_values(v)?),
            EffectKind::CrossAxis => Self::CrossAxis(Parameters::from_values(v)?),
            EffectKind::SharpEdges => Self::SharpEdges(Parameters::from_values(v)?),
            EffectKind::PreloadLoss => Self::PreloadLoss(Parameters::from_values(v)?),
            EffectKind::ImpactWear => Self::Wear(W::ImpactWear(Parameters::from_values(v)?)),
            EffectKind::SevereWear => Self::Wear(W::SevereWear(Parameters::from_values(v)?)),
            EffectKind::LocalPressure => Self::Wear(W::LocalPressure(Parameters::from_values(v)?)),
            EffectKind::CoatingBreakthrough => {
                Self::Wear(W::CoatingBreakthrough(Parameters::from_values(v)?))
            }
        })
    }

    /// Its kind.
    pub fn kind(&self) -> EffectKind {
        use WearEffect as W;
        match self {
            Self::Wear(W::WearAboveCutoff(_)) => EffectKind::WearAboveCutoff,
            Self::Wear(W::ThirdBody(_)) => EffectKind::ThirdBody,
            Self::ClearanceGrowth(_) => EffectKind::ClearanceGrowth,
            Self::FrictionDrift(_) => EffectKind::FrictionDrift,
            Self::FixtureCompliance(_) => EffectKind::FixtureCompliance,
            Self::CrossAxis(_) => EffectKind::CrossAxis,
            Self::SharpEdges(_) => EffectKind::SharpEdges,
            Self::PreloadLoss(_) => EffectKind::PreloadLoss,
            Self::Wear(W::ImpactWear(_)) => EffectKind::ImpactWear,
            Self::Wear(W::SevereWear(_)) => EffectKind::SevereWear,
            Self::Wear(W::LocalPressure(_)) => EffectKind::LocalPressure,
            Self::Wear(W::CoatingBreakthrough(_)) => EffectKind::CoatingBreakthrough,
        }
    }

    /// The values by library name.
    pub fn values(&self) -> BTreeMap<String, f64> {
        match self {
            Self::Wear(w) => w.values(),
            Self::ClearanceGrowth(p) => p.values(),
            Self::FrictionDrift(p) => p.values(),
            Self::FixtureCompliance(p) => p.values(),
            Self::CrossAxis(p) => p.values(),
            Self::SharpEdges(p) => p.values(),
            Self::PreloadLoss(p) => p.values(),
        }
    }

    /// The magnitude (first parameter; 0 = the nominal model).
    pub fn magnitude(&self) -> f64 {
        match self {
            Self::Wear(w) => w.magnitude(),
            Self::ClearanceGrowth(p) => p.magnitude(),
            Self::FrictionDrift(p) => p.magnitude(),
            Self::FixtureCompliance(p) => p.magnitude(),
            Self::CrossAxis(p) => p.magnitude(),
            Self::SharpEdges(p) => p.magnitude(),
            Self::PreloadLoss(p) => p.magnitude(),
        }
    }

    /// The wear mechanism of a wear-law effect (None for dynamics effects); `hardness_pa` is
    /// the softer body's indentation hardness (135 HB = 1.32 GPa for 7075-T73).
    pub fn wear_mechanism(&self, hardness_pa: f64) -> Option<WearMechanism> {
        match self {
            Self::Wear(w) => Some(w.mechanism(hardness_pa)),
            Self::ClearanceGrowth(_)
            | Self::FrictionDrift(_)
            | Self::FixtureCompliance(_)
            | Self::CrossAxis(_)
            | Self::SharpEdges(_)
            | Self::PreloadLoss(_) => None,
        }
    }
}

/// An effect with its parameter values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Effect {
    /// Library name.
    pub name: String,
    /// Every parameter of the effect, by name (defaults filled in).
    pub parameters: BTreeMap<String, f64>,
}

/// Parses `<name>=<magnitude>[,<param>=<value>...]` against `infos`: every parameter within
/// its bounds, unknown names and parameters refused, defaults filled in.
pub fn parse_spec(
    text: &str,
    infos: &[EffectInfo],
) -> Result<(&'static str, BTreeMap<String, f64>), GapError> {
    let field = "effect";
    let mut parts = text.split(',');
    let head = parts.next().unwrap_or_default();
    let (name, magnitude) = head
        .split_once('=')
        .ok_or_else(|| GapError::field(field, format!("`{text}`: expected <name>=<magnitude>")))?;
    let name = name.trim();
    let info = infos.iter().find(|e| e.name == name).ok_or_else(|| {
        let known: Vec<&str> = infos.iter().map(|e| e.name).collect();
        GapError::field(
            field,
            format!("unknown effect `{name}` (known: {})", known.join(", ")),
        )
    })?;
    let mut values = BTreeMap::new();
    let mut set = |pname: &str, raw: &str| -> Result<(), GapError> {
        let p = info
            .parameters
            .iter()
            .find(|p| p.name == pname)
            .ok_or_else(|| {
                GapError::field(
                    format!("effect.{name}"),
                    format!("unknown parameter `{pname}`"),
                )
            })?;
        let v: f64 = raw.trim().parse().map_err(|_| {
            GapError::field(
                format!("effect.{name}.{pname}"),
                format!("`{raw}` is not a number"),
            )
        })?;
        if !(v >= p.min && v <= p.max) {
            return Err(GapError::field(
                format!("effect.{name}.{pname}"),
                format!(
                    "{v} is outside [{}, {}] {} ({})",
                    p.min, p.max, p.unit, p.reason
                ),
            ));
        }
        values.insert(p.name.to_string(), v);
        Ok(())
    };
    set(info.parameters[0].name, magnitude)?;
    for part in parts {
        let (k, v) = part.split_once('=').ok_or_else(|| {
            GapError::field(
                format!("effect.{name}"),
                format!("`{part}`: expected <param>=<value>"),
            )
        })?;
        set(k.trim(), v)?;
    }
    for p in info.parameters {
        values.entry(p.name.to_string()).or_insert(p.default);
    }
    Ok((info.name, values))
}

impl Effect {
    /// Parses a library effect (`name=magnitude[,param=value...]`).
    pub fn parse(text: &str) -> Result<Self, GapError> {
        let (name, parameters) = parse_spec(text, LIBRARY)?;
        Ok(Self {
            name: name.to_string(),
            parameters,
        })
    }

    fn kind(&self) -> Result<EffectKind, GapError> {
        EffectKind::named(&self.name)
            .ok_or_else(|| GapError::field("effect", format!("unknown effect `{}`", self.name)))
    }

    /// The library entry.
    pub fn info(&self) -> Result<&'static EffectInfo, GapError> {
        self.kind().map(EffectKind::info)
    }

    /// The effect with its parameters read into its kind's struct: an unknown effect, or a
    /// parameter missing or not the effect's, is an error naming it.
    pub fn typed(&self) -> Result<TypedEffect, GapError> {
        TypedEffect::from_values(self.kind()?, &self.parameters)
            .map_err(|e| GapError::field(format!("effect.{}.{}", self.name, e.field), e.rule))
    }

    /// The magnitude (first parameter); 0, the nominal model, when the effect cannot be read
    /// ([`Effect::typed`] says why).
    pub fn magnitude(&self) -> f64 {
        self.typed().map_or(0.0, |t| t.magnitude())
    }

    /// The wear-law term of a wear-law effect (None for dynamics effects). `hardness_pa` is
    /// the softer body's indentation hardness (135 HB = 1.32 GPa for 7075-T73).
    pub fn wear_term(&self, hardness_pa: f64) -> Result<Option<Box<dyn WearTerm>>, GapError> {
        Ok(self
            .wear_mechanism(hardness_pa)?
            .map(|m| Box::new(m) as Box<dyn WearTerm>))
    }

    /// The wear mechanism of a wear-law effect at its parameters (None for dynamics effects):
    /// what a run carries as `wear.mechanism` (see [`crate::wear::mechanism`]).
    pub fn wear_mechanism(&self, hardness_pa: f64) -> Result<Option<WearMechanism>, GapError> {
        Ok(self.typed()?.wear_mechanism(hardness_pa))
    }

    /// Edits `case` for a segment of the specimen in `state`. Magnitude 0 changes nothing.
    /// Wear-law effects change nothing here.
    pub fn apply(
        &self,
        case: &mut CaseSpec,
        state: &SpecimenState,
        configs_dir: &Path,
    ) -> Result<(), GapError> {
        let typed = self.typed()?;
        let field = format!("effect.{}", self.name);
        if !typed.kind().info().models.contains(&case.model) {
            return Err(GapError::field(
                field,
                format!("does not apply to a {:?} case", case.model),
            ));
        }
        if typed.magnitude() == 0.0 {
            return Ok(());
        }
        match typed {
            TypedEffect::Wear(_) => return Ok(()),
            TypedEffect::ClearanceGrowth(p) => p.apply(case, state),
            TypedEffect::FrictionDrift(p) => p.apply(case, state),
            TypedEffect::FixtureCompliance(p) => p.apply(case, configs_dir, &field)?,
            TypedEffect::CrossAxis(p) => p.apply(case, configs_dir, &field)?,
            TypedEffect::SharpEdges(p) => p.apply(case),
            TypedEffect::PreloadLoss(p) => p.apply(case),
        }
        case.validate()
            .map_err(|e| GapError::field(field, format!("{}: {}", e.field, e.rule)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distinct in-bounds values, one per parameter.
    fn distinct(parameters: &[ParameterInfo]) -> BTreeMap<String, f64> {
        let n = parameters.len() as f64;
        parameters
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let v = p.min + (p.max - p.min) * (i as f64 + 1.0) / (n + 1.0);
                (p.name.to_string(), v)
            })
            .collect()
    }

    /// A library name, a parameter and the field the code reads cannot drift apart: every
    /// effect, parsed at its defaults or given a distinct value per parameter, reads into its
    /// kind's struct and gives back exactly the parameters its entry lists; its kind is the
    /// entry's, and it has a wear mechanism exactly when its entry says it acts on the wear law.
    #[test]
    fn every_library_parameter_is_a_field_of_its_kind() {
        assert_eq!(LIBRARY.len(), EffectKind::ALL.len());
        for (kind, info) in EffectKind::ALL.into_iter().zip(LIBRARY) {
            let effect = Effect::parse(&format!("{}=0", info.name)).unwrap();
            let typed = effect.typed().unwrap();
            assert_eq!(typed.kind(), kind, "{}", info.name);
            assert_eq!(EffectKind::named(info.name), Some(kind));
            assert_eq!(typed.values(), effect.parameters, "{}", info.name);
            assert_eq!(typed.magnitude(), 0.0, "{}", info.name);
            let values = distinct(info.parameters);
            let typed = TypedEffect::from_values(kind, &values).unwrap();
            assert_eq!(typed.values(), values, "{}", info.name);
            assert_eq!(
                typed.magnitude(),
                values[info.parameters[0].name],
                "{}",
                info.name
            );
            assert_eq!(
                typed.wear_mechanism(1.32e9).is_some(),
                info.acts == Acts::WearLaw,
                "{}",
                info.name
            );
        }
    }

    #[test]
    fn a_missing_or_unknown_parameter_is_an_error_not_zero() {
        let mut effect = Effect::parse("third_body=1e-3").unwrap();
        effect.parameters.remove("min_slip_m_s");
        let e = effect.typed().unwrap_err();
        assert_eq!(e.field_path(), Some("effect.third_body.min_slip_m_s"));
        assert!(effect.wear_term(1.32e9).is_err());
        effect.parameters.insert("min_slip_m_s".into(), 1e-3);
        effect.parameters.insert("min_slip".into(), 1e-3);
        let e = effect.typed().unwrap_err();
        assert_eq!(e.field_path(), Some("effect.third_body.min_slip"));
        let unknown = Effect {
            name: "sand".into(),
            parameters: BTreeMap::new(),
        };
        assert_eq!(unknown.typed().unwrap_err().field_path(), Some("effect"));
    }
}
