//! The effect library: candidate unmodelled effects, each an optional model term with few
//! parameters, shared by the virtual rig and the diagnosis (SPEC 7, issue 14 item 3).
//!
//! Each effect is data ([`EffectInfo`]: name, what it acts on, the models it applies to, its
//! parameters with unit, bounds, default and the reason for them) plus code:
//! - wear-law effects ([`Acts::WearLaw`]) give a [`WearTerm`] evaluated on recorded tracks
//!   (`gap::tracks`), never re-simulating;
//! - dynamics effects ([`Acts::Dynamics`]) edit the case before a segment is simulated, given
//!   the specimen's state (test time, slip distance) at that segment.
//!
//! The first parameter of each effect is its magnitude; magnitude 0 is the nominal model, and
//! an effect at magnitude 0 leaves the case and the wear unchanged bit for bit.

pub use super::drive_edits::transmissibility;
use super::drive_edits::{
    add_cross_axis, filter_through_mount, resolved_excitation, set_excitation,
};
use super::tracks::WearTerm;
use super::GapError;
use crate::models::spec::{CaseSpec, ModelKind};
use crate::wear::mechanism::WearMechanism;
pub use crate::wear::mechanism::{
    AboveCutoff, CoatingBreakthrough, ImpactWear, LocalPressure, SevereWear, ThirdBody,
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

/// One parameter of an effect.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ParameterInfo {
    /// Name, with its unit.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Smallest physical value.
    pub min: f64,
    /// Largest physical value.
    pub max: f64,
    /// Value when not given (the magnitude's default is its nominal 0).
    pub default: f64,
    /// Why these bounds: literature, thesis, or estimate.
    pub reason: &'static str,
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

/// The library, in issue order: (a)-(h) of issue 14, (i)-(l) of issue 26 (wear mechanisms
/// beyond sliding Archard at the lumped pressure).
pub const LIBRARY: &[EffectInfo] = &[
    EffectInfo {
        name: "wear_above_cutoff",
        letter: 'a',
        summary: "impact/plastic wear above the eq. 3.11 cutoff (2 Sy): K above it is a multiple of K at the cutoff instead of 0",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[ParameterInfo {
            name: "k_ratio_above_cutoff",
            unit: "1 (K above the cutoff / K(cutoff))",
            min: 0.0,
            max: 1000.0,
            default: 0.0,
            reason: "wear maps (Lim & Ashby 1987) put the mild-to-severe transition at contact pressures near the hardness, with K rising 100-1000x across it; thesis 5.5 and Fig. 5.7 show plastic flow at case A's corners",
        }],
        reason: "eq. 3.11 sets K = 0 above 2 Sy; thesis 5.5 reports the loose cases' pressures above yield and their measured wear 10-30x ADAMS'",
        limitation: None,
    },
    EffectInfo {
        name: "third_body",
        letter: 'b',
        summary: "three-body abrasion by trapped debris or sand: K raised by k_abr/H where pressure and slip let particles cut",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "k_abrasive",
                unit: "1 (dimensionless Archard k; K_add = k/H)",
                min: 0.0,
                max: 1.0e-2,
                default: 0.0,
                reason: "three-body abrasive wear coefficients 5e-4 to 5e-3 (Hutchings, Tribology, 1992; Rabinowicz 1995), up to 1e-2 for sharp sand",
            },
            ParameterInfo {
                name: "min_pressure_pa",
                unit: "Pa",
                min: 1.0e2,
                max: 1.0e8,
                default: 1.0e4,
                reason: "estimate: a few trapped particles carry the load, so they cut at nominal pressures far below the hardness; 10 kPa is above a resting rattle-box cube's own weight (0.7 kPa), so mere resting does not grind; uncertain by orders (100 Pa to 100 MPa)",
            },
            ParameterInfo {
                name: "min_slip_m_s",
                unit: "m/s",
                min: 0.0,
                max: 0.1,
                default: 1.0e-3,
                reason: "estimate: below about 1 mm/s (the Table 5.2 stiction speed is 6.5 mm/s) the surfaces stick and trapped particles are not dragged",
            },
        ],
        reason: "SPEC 7 lists third-body abrasion (sand, dust, wear debris trapped in a closed tube) as unmodelled; railwear's environment is `clean` only",
        limitation: None,
    },
    EffectInfo {
        name: "clearance_growth",
        letter: 'c',
        summary: "clearance opening as wear accumulates: the rattle box's tube side (launcher: the material condition) grows with test time, updated between segments",
        acts: Acts::Dynamics,
        models: BOTH,
        parameters: &[ParameterInfo {
            name: "opening_um_per_h",
            unit: "µm/h of clearance (tube side; launcher material-condition offset)",
            min: 0.0,
            max: 50.0,
            default: 0.0,
            reason: "case B's measured 97 mg/h (Table 5.3) is 34.6 mm³/h of 7075; spread over the cube's six faces it thins each by 9 µm/h (18 µm/h across a pair), localised wear a few times more: 50 µm/h bounds it",
        }],
        reason: "the thesis' model keeps the nominal enclosure; cases C and D ran 4.5 h on one specimen (thesis 5.5), their rate rising 1.53 -> 2.33 and 0.17 -> 0.87 mg/h",
        limitation: Some("the opening is a rate per test hour, not computed from the simulated wear: railwear's simulated wear is two orders below the measured (docs/validation.md), so it would open nothing"),
    },
    EffectInfo {
        name: "friction_drift",
        letter: 'd',
        summary: "friction drift: mu_s and mu_d shift by delta_mu (1 - exp(-s/s0)) with the accumulated slip distance s, updated between segments",
        acts: Acts::Dynamics,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "delta_mu",
                unit: "1",
                min: -0.1,
                max: 0.6,
                default: 0.0,
                reason: "anodize worn through leaves bare 7075 on 7075, dry mu 0.6-1.0 (ASM Handbook 18); polishing lowers mu a little; -0.1 keeps mu_d of Table 5.2 (0.166) positive",
            },
            ParameterInfo {
                name: "slip_scale_m",
                unit: "m",
                min: 1.0,
                max: 1.0e4,
                default: 100.0,
                reason: "estimate: running-in completes within 1-1000 m of sliding for light loads (Blau, Friction and Wear Transitions, 1989)",
            },
        ],
        reason: "Table 5.2 friction was fitted on fresh anodized pads (thesis 4.5); the specimens run hours",
        limitation: None,
    },
    EffectInfo {
        name: "fixture_compliance",
        letter: 'e',
        summary: "fixture compliance: the tube (rail) mounted through a spring-damper; the drive it sees is the shaker's through the mount's base-excitation transmissibility",
        acts: Acts::Dynamics,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "natural_period_ms",
                unit: "ms (1 / mount natural frequency; 0 = rigid)",
                min: 0.0,
                max: 20.0,
                default: 0.0,
                reason: "fixtures are designed with their first resonance above the test band; a bolted tube on a head expander may come down to 50-200 Hz (5-20 ms)",
            },
            ParameterInfo {
                name: "damping_ratio",
                unit: "1",
                min: 0.01,
                max: 0.3,
                default: 0.05,
                reason: "bolted aluminium joints: 1-5 % of critical, elastomer mounts up to 30 % (Harris' Shock and Vibration Handbook)",
            },
        ],
        reason: "the thesis drives the tube rigidly (motion generator, 5.4); Figures 5.1-5.2 show a bolted fixture",
        limitation: Some("approximation: tones (and random PSD breakpoints) are scaled by |T(f)| and phase-shifted; the cube's reaction on the mount is not modelled (a dynamic tube body needs a model-builder change); measured drives are refused"),
    },
    EffectInfo {
        name: "cross_axis",
        letter: 'f',
        summary: "cross-axis excitation: each drive tone repeated on the two other axes at a share of its amplitude",
        acts: Acts::Dynamics,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "share",
                unit: "1 (cross-axis amplitude / drive amplitude, each other axis)",
                min: 0.0,
                max: 0.3,
                default: 0.0,
                reason: "shaker acceptance limits cross-axis motion to 10-30 % of the drive axis (IEST-RP-DTE012, MIL-STD-810G 514.6 Annex A)",
            },
            ParameterInfo {
                name: "phase_deg",
                unit: "degree",
                min: -180.0,
                max: 180.0,
                default: 0.0,
                reason: "rocking of the armature gives in-phase or anti-phase cross motion; any phase allowed",
            },
        ],
        reason: "the thesis drives one axis only (15 g at 20 Hz transverse, 5.5); real shakers move on the other axes too",
        limitation: Some("tones only: a random background stays on its own axes"),
    },
    EffectInfo {
        name: "sharp_edges",
        letter: 'g',
        summary: "sharper edges than nominal: every roundover (cube, shoes, latch tooth, front pad) scaled by 1 - reduction",
        acts: Acts::Dynamics,
        models: BOTH,
        parameters: &[ParameterInfo {
            name: "roundover_reduction",
            unit: "1 (fraction of the nominal roundover removed)",
            min: 0.0,
            max: 0.9,
            default: 0.0,
            reason: "thesis 5.4 adds a 0.02 in roundover \"to better model the real fixture\" and notes contact area and pressure depend on it; machined edges range from sharp to the nominal break",
        }],
        reason: "a smaller roundover concentrates edge contacts: higher pressure, more work above the cutoff (thesis 5.4)",
        limitation: None,
    },
    EffectInfo {
        name: "preload_loss",
        letter: 'h',
        summary: "launcher spring preload loss: latch coil spring and rear leaf spring preloads scaled by 1 - loss",
        acts: Acts::Dynamics,
        models: &[ModelKind::Launcher],
        parameters: &[ParameterInfo {
            name: "loss",
            unit: "1 (fraction of the preload lost)",
            min: 0.0,
            max: 1.0,
            default: 0.0,
            reason: "coil and leaf springs relax by stress relaxation and set; 1 = fully lost (SPEC 7: spring preload loss or non-engagement)",
        }],
        reason: "thesis 6.3.1: the rear leaf spring may not engage when static; a lost preload lets the missile rattle",
        limitation: None,
    },
    EffectInfo {
        name: "impact_wear",
        letter: 'i',
        summary: "impact wear: a volume k_E times the energy the contact's normal (IMPACT) damping dissipates, counted while the normal speed is at least a threshold",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "k_energy_m3_per_j",
                unit: "m³/J (wear volume per joule of normal damping work)",
                min: 0.0,
                max: 1.0e-11,
                default: 0.0,
                reason: "dissipated-energy wear (Fouvry et al., Wear 2003; Huq & Celis, Wear 2002) measures 1e-15 to 1e-13 m³/J for steels and coatings in fretting; an Archard k/(H mu) for aluminium alloys in dry contact, k = 1e-6 (mild, oxidised) to 1e-2 (severe, adhesive) (Archard 1953; Hutchings 1992), H = 1.32 GPa, mu = 0.5, spans 1.5e-15 to 1.5e-11 m³/J; Engel (Impact Wear of Materials, 1976) finds repeated normal impact removes material by the same fatigue and plastic mechanisms, so the sliding range bounds it",
            },
            ParameterInfo {
                name: "min_normal_speed_m_s",
                unit: "m/s (|penetration rate| below which damping work does not wear)",
                min: 0.0,
                max: 0.5,
                default: 0.0,
                reason: "Engel's impact wear has a threshold below which impacts only deform elastically; a sliding contact's micro-motion (normal speeds of mm/s) dissipates without removing material; 0.5 m/s is above the rattle boxes' impact speeds (15 g at 20 Hz moves the tube at 1.2 m/s peak)",
            },
        ],
        reason: "the energy account shows the contact's IMPACT damping dissipating 10-100x the friction work (rattle box C: about 1.5 W against 0.02 W); thesis 5.5 and Fig. 5.7 point at impact stresses above yield and plastic flow at the corners",
        limitation: Some("the damping work is the IMPACT law's (c_max, STEP over the penetration depth d), not a measured restitution: it is as good as Table 5.2's damping"),
    },
    EffectInfo {
        name: "severe_wear",
        letter: 'j',
        summary: "severe (plastic) wear: K raised by k_severe/H at contact points whose own pressure exceeds a multiple of the yield strength",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "k_severe",
                unit: "1 (dimensionless Archard k; K_add = k/H)",
                min: 0.0,
                max: 1.0e-2,
                default: 0.0,
                reason: "severe (adhesive, plastic) wear of aluminium alloys: dimensionless k of 1e-4 to 1e-2 (Archard 1953; Lim & Ashby, Acta Metall. 1987; Hutchings 1992), against 1e-7 to 1e-5 in mild wear",
            },
            ParameterInfo {
                name: "pressure_ratio_to_yield",
                unit: "1 (local pressure / yield strength Sy where severe wear starts)",
                min: 0.5,
                max: 3.0,
                default: 1.0,
                reason: "the mild-to-severe transition lies where the local pressure reaches the flow stress: about Sy at first yield, up to the hardness (about 3 Sy, Tabor) at full plasticity (Lim & Ashby 1987); 0.5 Sy allows for the stress concentration of a rough surface",
            },
        ],
        reason: "thesis 5.5 and Fig. 5.7: impact stresses above yield and plastic flow at case A's corners; the lumped pressure N/A of eq. 3.11 averages over the face, the contact points' own pressures (gap::tracks) do not",
        limitation: Some("local pressures from the contact points' share of the face law (gap::tracks), binned at 1/50 decade; on tracks recorded without points the lumped pressure stands in"),
    },
    EffectInfo {
        name: "local_pressure",
        letter: 'k',
        summary: "local-pressure Archard: the case's K(sigma) evaluated at each contact point's own pressure instead of the lumped N/A, for a share of the wear",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[ParameterInfo {
            name: "share",
            unit: "1 (0 = lumped N/A as the thesis, 1 = every point at its own pressure)",
            min: 0.0,
            max: 1.0,
            default: 0.0,
            reason: "eq. 3.11 was written for a face's mean pressure; whether a real contact wears at the mean or at its local pressures is the modelling question, so every share between is allowed",
        }],
        reason: "a tilted face or an edge loads its deeper points above the mean; Table 4.3's K rises with pressure and cuts off at 2 Sy, so local pressures can raise the wear, or lower it where points exceed the cutoff",
        limitation: Some("on tracks recorded without points it changes nothing"),
    },
    EffectInfo {
        name: "coating_breakthrough",
        letter: 'l',
        summary: "anodic-coating breakthrough: K raised by k_bare/H once the specimen has slid past the distance that wears the coating through",
        acts: Acts::WearLaw,
        models: BOTH,
        parameters: &[
            ParameterInfo {
                name: "k_bare",
                unit: "1 (dimensionless Archard k of the bare alloy; K_add = k/H)",
                min: 0.0,
                max: 1.0e-2,
                default: 0.0,
                reason: "bare aluminium alloy on anodized or bare aluminium in dry sliding wears adhesively: k of 1e-5 to 1e-2 (Archard 1953; ASM Handbook 18, 1992), against 1e-7 to 1e-6 for an intact hard anodize",
            },
            ParameterInfo {
                name: "breakthrough_slip_m",
                unit: "m (slip distance at which the coating is worn through)",
                min: 1.0,
                max: 1.0e5,
                default: 1.0e3,
                reason: "sulphuric (type II) anodize is 5-25 µm thick, hard (type III) 25-100 µm (MIL-A-8625); worn at 1e-8-1e-6 µm per N·m of the mild regime under the rattle boxes' 1-10 N loads it lasts 1 m to 100 km of sliding",
            },
        ],
        reason: "the thesis' cubes are anodized 7075 (5.4) and Table 4.3 was fitted on fresh anodized pads; cases C and D wore faster in their later increments (1.53 -> 2.33 and 0.17 -> 0.87 mg/h, Table 5.3), as a worn-through coating would",
        limitation: Some("the breakthrough is a slip distance, not a worn depth: the local depth would need the wear's distribution over the face"),
    },
];

/// Looks an effect up by name.
pub fn info(name: &str) -> Option<&'static EffectInfo> {
    LIBRARY.iter().find(|e| e.name == name)
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

    /// The library entry.
    pub fn info(&self) -> Result<&'static EffectInfo, GapError> {
        info(&self.name)
            .ok_or_else(|| GapError::field("effect", format!("unknown effect `{}`", self.name)))
    }

    fn get(&self, name: &str) -> f64 {
        self.parameters.get(name).copied().unwrap_or(0.0)
    }

    /// The magnitude (first parameter).
    pub fn magnitude(&self) -> f64 {
        self.info().map_or(0.0, |i| self.get(i.parameters[0].name))
    }

    /// The wear-law term of a wear-law effect (None for dynamics effects). `hardness_pa` is
    /// the softer body's indentation hardness (135 HB = 1.32 GPa for 7075-T73).
    pub fn wear_term(&self, hardness_pa: f64) -> Option<Box<dyn WearTerm>> {
        self.wear_mechanism(hardness_pa)
            .map(|m| Box::new(m) as Box<dyn WearTerm>)
    }

    /// The wear mechanism of a wear-law effect at its parameters (None for dynamics effects):
    /// what a run carries as `wear.mechanism` (see [`crate::wear::mechanism`]).
    pub fn wear_mechanism(&self, hardness_pa: f64) -> Option<WearMechanism> {
        WearMechanism::from_effect(&self.name, |p| self.get(p), hardness_pa)
    }

    /// Edits `case` for a segment of the specimen in `state`. Magnitude 0 changes nothing.
    /// Wear-law effects change nothing here.
    pub fn apply(
        &self,
        case: &mut CaseSpec,
        state: &SpecimenState,
        configs_dir: &Path,
    ) -> Result<(), GapError> {
        let info = self.info()?;
        let field = format!("effect.{}", self.name);
        if !info.models.contains(&case.model) {
            return Err(GapError::field(
                field,
                format!("does not apply to a {:?} case", case.model),
            ));
        }
        if self.magnitude() == 0.0 || info.acts == Acts::WearLaw {
            return Ok(());
        }
        let bad = |e: crate::field_error::FieldError| {
            GapError::field(
                format!("effect.{}", self.name),
                format!("{}: {}", e.field, e.rule),
            )
        };
        match self.name.as_str() {
            "clearance_growth" => {
                let opening_m = self.get("opening_um_per_h") * 1e-6 * state.elapsed_h;
                if let Some(rb) = case.rattle_box.as_mut() {
                    rb.tube_inner_side_m += opening_m;
                    rb.case = format!("{}-worn", rb.case);
                } else if let Some(l) = case.launcher.as_mut() {
                    // A positive material-condition offset shrinks the shoes and opens the
                    // rail by the same amount (analysis::rattle_space).
                    l.dimensions = l.dimensions.with_material_condition(opening_m * 1e3);
                }
            }
            "friction_drift" => {
                let d = self.get("delta_mu")
                    * (1.0 - (-state.slip_distance_m / self.get("slip_scale_m")).exp());
                let shift = |f: &mut crate::physics::friction::FrictionParams| {
                    f.mu_static += d;
                    f.mu_dynamic += d;
                };
                if let Some(rb) = case.rattle_box.as_mut() {
                    shift(&mut rb.friction);
                }
                if let Some(l) = case.launcher.as_mut() {
                    shift(&mut l.friction);
                }
            }
            "fixture_compliance" => {
                let spec = resolved_excitation(case, configs_dir, &field)?;
                let period = self.get("natural_period_ms") * 1e-3;
                let zeta = self.get("damping_ratio");
                let spec = filter_through_mount(spec, period, zeta, &field)?;
                set_excitation(case, &spec, &field)?;
            }
            "cross_axis" => {
                let spec = resolved_excitation(case, configs_dir, &field)?;
                let spec = add_cross_axis(spec, self.get("share"), self.get("phase_deg"), &field)?;
                set_excitation(case, &spec, &field)?;
            }
            "sharp_edges" => {
                let keep = 1.0 - self.get("roundover_reduction");
                if let Some(rb) = case.rattle_box.as_mut() {
                    rb.edge_radius_m *= keep;
                }
                if let Some(l) = case.launcher.as_mut() {
                    l.mid_shoe.edge_radius_m *= keep;
                    l.rear_shoe.edge_radius_m *= keep;
                    l.front_pad.edge_radius_m *= keep;
                    l.latch.tooth.edge_radius_m *= keep;
                    if let Some(p) = l.mid_shoe.protrusion.as_mut() {
                        p.edge_radius_m *= keep;
                    }
                }
            }
            "preload_loss" => {
                let keep = 1.0 - self.get("loss");
                if let Some(l) = case.launcher.as_mut() {
                    l.latch_spring.preload_n *= keep;
                    l.rear_leaf_spring.preload_n *= keep;
                }
            }
            other => {
                return Err(GapError::field(
                    "effect",
                    format!("no dynamics for `{other}`"),
                ));
            }
        }
        case.validate().map_err(bad)
    }
}

/// What a specimen has been through when a segment starts (or at its middle, for effects of
/// test time).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SpecimenState {
    /// Test time, h (the segment's middle).
    pub elapsed_h: f64,
    /// Slip distance accumulated before the segment, m.
    pub slip_distance_m: f64,
}
