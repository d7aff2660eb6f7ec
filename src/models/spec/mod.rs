//! What every case shares: the case file itself ([`CaseSpec`]: model kind, name, run control,
//! the one model table, excitation and wear) and the specs all three models use (contact,
//! friction and material checks, rounded boxes, planar faces, run control), with the field rules
//! the models' own specs are validated by. Each model's own spec is a file here:
//! [`persistent_contact`] (thesis chapter 4), [`rattle_box`] (chapter 5) and [`launcher`]
//! (chapter 6); each model is built in its own folder ([`crate::models::launcher`], ...), which
//! re-exports its spec. What a case is sits below how it is built, so the builders import the
//! specs and never the other way round.
//!
//! Conventions (SPEC 1, thesis 6.2.2): SI unless a field name says otherwise (`_mm`, `_deg`,
//! `_n_per_mm_e`); y is vertical (up, towards the vehicle), gravity is standard gravity along -y;
//! for the launcher the rail frame has its origin at the rail's centre of mass, z longitudinal
//! (firing direction), x transverse. Contact and friction parameters are written in the thesis'
//! ADAMS units (N, mm, s) and converted with [`ContactSpec::to_impact_params`]; friction is the
//! engine's own [`FrictionParams`](crate::physics::friction::FrictionParams), read from and
//! written to mm/s by [`in_mm_per_s`](crate::physics::friction::in_mm_per_s). Values the thesis
//! does not give are engineering estimates, flagged `estimate` in `docs/reference/models.md`.
//!
//! Every number of a case has a physical range ([`Bound`], with its unit and reason), declared
//! beside the field it bounds, in the file of its struct, and checked on the typed case
//! ([`Bounded::check_bounds`]) so a typing error (a friction coefficient of 1e6, an amplitude
//! of 1e308 g) is refused at submit naming the field instead of running into NaN. The ranges
//! are deliberately wide: they bound what is physically possible for a captive-carry launcher
//! or a shaker test, not what is usual; the thesis' values sit well inside every one of them.
//! The ranges shared by many fields (a length, a position) are the constants below.

use crate::field_error::FieldError;
use crate::parameters::{Bound, Bounded, FieldPath};
pub use excitation::{CaseExcitation, Excitation};
use launcher::LauncherSpec;
use persistent_contact::PersistentContactSpec;
use rattle_box::RattleBoxSpec;
use serde::{Deserialize, Serialize};

/// `prefix.name`, or `name` when `prefix` is empty: the dotted path of a field in a case file.
pub(in crate::models) fn path(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_string()
    } else {
        format!("{prefix}.{name}")
    }
}

pub(in crate::models) fn finite(prefix: &str, name: &str, v: f64) -> Result<(), FieldError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(FieldError::new(
            path(prefix, name),
            format!("must be a finite number, got {v}"),
        ))
    }
}

pub(in crate::models) fn positive(prefix: &str, name: &str, v: f64) -> Result<(), FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(
            path(prefix, name),
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

pub(in crate::models) fn non_negative(prefix: &str, name: &str, v: f64) -> Result<(), FieldError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(
            path(prefix, name),
            format!("must be a finite number >= 0, got {v}"),
        ))
    }
}

pub(in crate::models) fn finite3(prefix: &str, name: &str, v: [f64; 3]) -> Result<(), FieldError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(FieldError::new(
            path(prefix, name),
            format!("all components must be finite, got {v:?}"),
        ))
    }
}

pub(in crate::models) fn unit3(prefix: &str, name: &str, v: [f64; 3]) -> Result<(), FieldError> {
    finite3(prefix, name, v)?;
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (n - 1.0).abs() > 1e-6 {
        return Err(FieldError::new(
            path(prefix, name),
            format!("must be a unit vector, |v| = {n}"),
        ));
    }
    Ok(())
}

/// Principal moments must be > 0 and satisfy the triangle inequality (a real rigid body).
pub(in crate::models) fn inertia3(prefix: &str, name: &str, i: [f64; 3]) -> Result<(), FieldError> {
    if !i.iter().all(|x| x.is_finite() && *x > 0.0) {
        return Err(FieldError::new(
            path(prefix, name),
            format!("all moments must be finite and > 0, got {i:?}"),
        ));
    }
    let tol = 1e-12 * (i[0] + i[1] + i[2]);
    if i[0] + i[1] < i[2] - tol || i[1] + i[2] < i[0] - tol || i[0] + i[2] < i[1] - tol {
        return Err(FieldError::new(
            path(prefix, name),
            format!(
                "principal moments {i:?} break the triangle inequality (no real body has them)"
            ),
        ));
    }
    Ok(())
}

/// Sizes of parts and bodies, m.
pub(in crate::models) const LENGTH: Bound = Bound::new(
    1.0e-6,
    10.0,
    "m",
    "sizes from 1 µm (below the roughness of machined aluminium) to 10 m (longer than any \
     air-launched store; the Hellfire is 1.63 m)",
);
/// Positions and offsets in a body's or the rail's frame, m.
pub(in crate::models) const POSITION: Bound = Bound::new(
    -10.0,
    10.0,
    "m",
    "positions within 10 m of their frame's origin: the launcher and its missile span under \
     2 m",
);
/// The components of a unit vector (its length is the model's rule).
pub(in crate::models) const UNIT_COMPONENT: Bound =
    Bound::new(-1.0, 1.0, "", "the components of a unit vector");
/// Edge and corner roundovers, m.
pub(in crate::models) const EDGE_RADIUS: Bound = Bound::new(
    0.0,
    0.1,
    "m",
    "roundovers are fractions of a millimetre (thesis 5.4: 0.508 mm); a 10 cm radius is a \
     piece, not a roundover",
);
/// Frequencies of a base motion, Hz.
pub(in crate::models) const FREQUENCY: Bound = Bound::new(
    0.1,
    5000.0,
    "Hz",
    "vibration between 0.1 Hz (below it a tone is a manoeuvre) and 5 kHz (above it the rail's \
     structural modes, not rigid contact, decide; MIL-STD-810G 514.6 stops at 2 kHz)",
);

/// Longest text field of a case (names, labels, paths), characters: a name is read on a plot
/// or in a list; 256 characters hold any path in `configs/`.
pub const MAX_TEXT_CHARS: usize = 256;
/// Longest case description, characters: one paragraph with its thesis source.
pub const MAX_DESCRIPTION_CHARS: usize = 2000;

mod excitation;
pub mod launcher;
pub mod persistent_contact;
pub mod rattle_box;
mod shared;
#[cfg(test)]
pub(in crate::models) mod tests;
mod wear;

pub use excitation::{MAX_PSD_BREAKPOINTS, MAX_TONES};
pub use shared::{
    validate_friction, validate_material, ContactSpec, PlanarFace, RoundedBoxSpec, SimulationSpec,
    ABS_TOLERANCE_M_RANGE, DENSITY_KG_M3_RANGE, MAX_DURATION_S, MAX_SEED, MAX_SETTLE_S,
    MIN_RECORD_INTERVAL_S, REL_TOLERANCE_RANGE,
};
pub use wear::{MAX_CUTOFF_PRESSURE_PA, MAX_WEAR_COEFFICIENT_M2_PER_N};

/// Which model a case file describes (its top-level `model` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Thesis chapter 4; model table `[persistent_contact]`.
    PersistentContact,
    /// Thesis chapter 5; model table `[rattle_box]`.
    RattleBox,
    /// Thesis chapter 6; model table `[launcher]`.
    Launcher,
}

/// The model table of a case, by kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelSpecRef<'a> {
    /// Chapter 4.
    PersistentContact(&'a PersistentContactSpec),
    /// Chapter 5.
    RattleBox(&'a RattleBoxSpec),
    /// Chapter 6.
    Launcher(&'a LauncherSpec),
}

/// One case file (`configs/*.toml`): model kind, name, description, run control, the model's own
/// table and the excitation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    /// Model kind; the table of the same name must be present and no other model table.
    pub model: ModelKind,
    /// Short identifier, e.g. `rattle-box-c`.
    pub name: String,
    /// One-line description with the thesis source.
    pub description: String,
    /// Run control.
    pub simulation: SimulationSpec,
    /// Chapter 4 model table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub persistent_contact: Option<PersistentContactSpec>,
    /// Chapter 5 model table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rattle_box: Option<RattleBoxSpec>,
    /// Chapter 6 model table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub launcher: Option<LauncherSpec>,
    /// Base excitation: a profile by name or a motion given in full, typed when the case is
    /// read (the schema of its motions belongs to `crate::excitation`).
    pub excitation: CaseExcitation,
    /// Wear law and the split of wear volume between the bodies of a contact.
    #[serde(default)]
    pub wear: WearSpec,
}

/// The `[wear]` table: wear law (default thesis Table 4.3 with the eq. 3.11 cutoff 2 S_y) and
/// how each contact's volume is split between its two bodies (default inverse hardness).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearSpec {
    /// Wear law (tagged by `kind`: `archard`, `modified`, `legacy_appendix`).
    #[serde(default = "crate::wear::law::WearLaw::table_4_3")]
    pub law: crate::wear::law::WearLaw,
    /// Volume split between the two bodies of each contact.
    #[serde(default)]
    pub volume_split: crate::wear::allocation::VolumeSplit,
    /// A wear mechanism added to the law on every track (tagged by `kind`: `impact_wear`,
    /// `third_body`, ...; see `wear::mechanism`), e.g. the one a gap diagnosis fitted (a
    /// sweep's `wear_law = {diagnosis = ..}` sets it). Absent: the law alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mechanism: Option<crate::wear::mechanism::WearMechanism>,
}

impl Default for WearSpec {
    fn default() -> Self {
        Self {
            law: crate::wear::law::WearLaw::table_4_3(),
            volume_split: crate::wear::allocation::VolumeSplit::default(),
            mechanism: None,
        }
    }
}

/// The case's texts within their lengths and every number inside its bound: run control, the
/// model table, the excitation as written (a profile's motion is checked where it is resolved,
/// `cases::bounds::check_case`) and the wear law.
impl Bounded for CaseSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.text("name", &self.name, MAX_TEXT_CHARS, false)?;
        at.text(
            "description",
            &self.description,
            MAX_DESCRIPTION_CHARS,
            true,
        )?;
        at.child("simulation", &self.simulation)?;
        if let Some(spec) = &self.persistent_contact {
            at.child("persistent_contact", spec)?;
        }
        if let Some(spec) = &self.rattle_box {
            at.child("rattle_box", spec)?;
        }
        if let Some(spec) = &self.launcher {
            at.child("launcher", spec)?;
        }
        at.child("excitation", &self.excitation)?;
        at.child("wear", &self.wear)
    }
}

impl CaseSpec {
    /// Parses a TOML case file (unknown keys are errors) and validates it.
    pub fn from_toml_str(text: &str) -> Result<Self, FieldError> {
        let case = Self::from_toml_str_unchecked(text)?;
        case.validate()?;
        Ok(case)
    }

    /// Parses a TOML case file (unknown keys are errors) without validating it.
    pub fn from_toml_str_unchecked(text: &str) -> Result<Self, FieldError> {
        toml::from_str(text).map_err(|e| FieldError::new("toml", e.to_string()))
    }

    /// The model table matching `model`.
    pub fn model_spec(&self) -> Result<ModelSpecRef<'_>, FieldError> {
        let missing =
            |t: &str| FieldError::new(t, format!("model = {:?} needs a [{t}] table", self.model));
        match self.model {
            ModelKind::PersistentContact => self
                .persistent_contact
                .as_ref()
                .map(ModelSpecRef::PersistentContact)
                .ok_or_else(|| missing("persistent_contact")),
            ModelKind::RattleBox => self
                .rattle_box
                .as_ref()
                .map(ModelSpecRef::RattleBox)
                .ok_or_else(|| missing("rattle_box")),
            ModelKind::Launcher => self
                .launcher
                .as_ref()
                .map(ModelSpecRef::Launcher)
                .ok_or_else(|| missing("launcher")),
        }
    }

    /// Validates the whole case: name, the one matching model table, run control, and that the
    /// excitation is a table with a `kind`.
    pub fn validate(&self) -> Result<(), FieldError> {
        #[cfg(test)]
        crate::models::counts::validated();
        if self.name.trim().is_empty() {
            return Err(FieldError::new("name", "must not be empty"));
        }
        let extra = [
            (
                "persistent_contact",
                self.persistent_contact.is_some(),
                ModelKind::PersistentContact,
            ),
            (
                "rattle_box",
                self.rattle_box.is_some(),
                ModelKind::RattleBox,
            ),
            ("launcher", self.launcher.is_some(), ModelKind::Launcher),
        ]
        .into_iter()
        .find(|(_, present, kind)| *present && *kind != self.model);
        if let Some((table, _, _)) = extra {
            return Err(FieldError::new(
                table,
                format!("table present but model = {:?}", self.model),
            ));
        }
        self.simulation.validate("simulation")?;
        if let Some(mechanism) = &self.wear.mechanism {
            mechanism
                .validate()
                .map_err(|crate::wear::WearError::Invalid(e)| {
                    FieldError::new(format!("wear.mechanism.{}", e.field), e.rule)
                })?;
            if !self.wear.law.gives_k_of_sigma() {
                return Err(FieldError::new(
                    "wear.mechanism",
                    crate::wear::law::TERMS_NEED_K_OF_SIGMA,
                ));
            }
        }
        // The excitation's kind and keys were checked as it was typed (`CaseExcitation`).
        match self.model_spec()? {
            ModelSpecRef::PersistentContact(s) => s.validate("persistent_contact"),
            ModelSpecRef::RattleBox(s) => s.validate("rattle_box"),
            ModelSpecRef::Launcher(s) => s.validate("launcher"),
        }
    }
}
