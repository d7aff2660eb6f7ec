//! A case's `[excitation]` table, typed when the case is read: a shipped profile by name
//! (`kind = "profile"`, `profile = "<name>"`) or a base motion given in full (`none`, `sine`,
//! `sine_on_random`, `measured`: the schema of [`ExcitationSpec`]). A table that is neither
//! (no `kind`, an unknown kind, an unknown key) is refused where the case is read.
//!
//! The table is also kept as written, for the record only: a result's `config`, a job's stored
//! plan and a checkpoint's case hash carry the case as it was written (an omitted default stays
//! omitted, `15` stays an integer), so typing the table changes no stored result and no
//! refactor hash. Every reader of the excitation takes the typed form ([`CaseExcitation::kind`]),
//! the physical bounds too (declared here, beside the schema's use in a case).

use super::shared::{DURATION, SEED, SETTLE};
use super::{FREQUENCY, MAX_TEXT_CHARS};
use crate::excitation::{ExcitationSpec, RampSpec, Tone};
use crate::field_error::FieldError;
use crate::parameters::{Bound, Bounded, FieldPath};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::Value;

/// What a case's excitation is.
#[derive(Debug, Clone, PartialEq)]
pub enum Excitation {
    /// A profile of `configs/profiles/` by name: its motion with the case's settle time and,
    /// for a random profile, the case's seed (`models::case::resolve_excitation`).
    Profile(String),
    /// A base motion given in full (its settle time is the case's).
    Motion(ExcitationSpec),
}

/// Most tones of one excitation: a rotorcraft profile has its 1P tone and a dozen harmonics.
pub const MAX_TONES: usize = 64;
/// Most PSD breakpoints: MIL-STD-810G's tables have fewer than 20.
pub const MAX_PSD_BREAKPOINTS: usize = 256;

const AMPLITUDE: Bound = Bound::new(
    0.0,
    200.0,
    "g",
    "shakers reach about 100 g sine and captive-carry profiles stay below 10 g (thesis: 15 g \
     on the rattle box); above 200 g is shock, not vibration",
);
const PHASE: Bound = Bound::new(-360.0, 360.0, "°", "one turn either way");
const RAMP_SECONDS: Bound = Bound::new(
    0.0,
    super::MAX_SETTLE_S,
    "s",
    "a ramp-in no longer than the longest settle",
);
const RAMP_CYCLES: Bound = Bound::new(
    0.0,
    1000.0,
    "cycles",
    "a ramp-in of up to 1000 cycles of the lowest frequency (default 3)",
);
const PSD_LEVEL: Bound = Bound::new(
    0.0,
    10.0,
    "g²/Hz",
    "PSD levels above 0 and up to 10 g²/Hz (140 g rms over 2 kHz); MIL-STD-810G helicopter \
     levels stay below 0.1 g²/Hz",
)
.open_min();
const SAMPLE_RATE: Bound = Bound::new(
    1.0,
    1.0e6,
    "Hz",
    "a record sampled at 1 Hz to 1 MHz (4x the highest frequency is enough)",
);
const CUTOFF_FREQUENCY: Bound = Bound::new(
    0.01,
    1000.0,
    "Hz",
    "a drift cutoff between 0.01 Hz and 1 kHz: it must sit below the content it keeps",
);
const SAMPLE_TIME: Bound = Bound::new(
    0.0,
    super::MAX_DURATION_S + super::MAX_SETTLE_S,
    "s",
    "sample times within the longest run",
);
const ACCELERATION: Bound = Bound::new(
    -1.0e4,
    1.0e4,
    "g or m/s²",
    "measured accelerations up to 1e4 in either unit: beyond it a record is a unit error or a \
     shock",
);

/// A list field `name` of at most `max` entries.
fn at_most(at: &FieldPath, name: &str, len: usize, max: usize) -> Result<(), FieldError> {
    if len > max {
        Err(FieldError::new(
            format!("{}.{name}", at.as_str()),
            format!("has {len} entries; at most {max}"),
        ))
    } else {
        Ok(())
    }
}

impl Bounded for Tone {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.number("frequency_hz", self.frequency_hz, &FREQUENCY)?;
        at.number("amplitude_g", self.amplitude_g, &AMPLITUDE)?;
        at.number("phase_deg", self.phase_deg, &PHASE)
    }
}

impl Bounded for RampSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        match *self {
            RampSpec::Seconds(s) => at.number("seconds", s, &RAMP_SECONDS),
            RampSpec::Cycles(c) => at.number("cycles", c, &RAMP_CYCLES),
        }
    }
}

fn tones(at: &mut FieldPath, tones: &[Tone]) -> Result<(), FieldError> {
    at_most(at, "tones", tones.len(), MAX_TONES)?;
    at.field("tones", |at| {
        tones
            .iter()
            .enumerate()
            .try_for_each(|(i, tone)| at.item(i, |at| tone.check_bounds(at)))
    })
}

/// A base motion (`crate::excitation::ExcitationSpec`), as a case gives it or a profile
/// resolves to.
impl Bounded for ExcitationSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        let (settle_s, ramp) = match self {
            ExcitationSpec::None => return Ok(()),
            ExcitationSpec::Sine {
                tones: t,
                settle_s,
                ramp,
            } => {
                tones(at, t)?;
                (settle_s, ramp)
            }
            ExcitationSpec::SineOnRandom {
                tones: t,
                psd_breakpoints,
                duration_s,
                sample_rate_hz,
                seed,
                low_cutoff_hz,
                settle_s,
                ramp,
                ..
            } => {
                tones(at, t)?;
                at_most(
                    at,
                    "psd_breakpoints",
                    psd_breakpoints.len(),
                    MAX_PSD_BREAKPOINTS,
                )?;
                at.field("psd_breakpoints", |at| {
                    psd_breakpoints
                        .iter()
                        .enumerate()
                        .try_for_each(|(i, (f, level))| {
                            at.item(i, |at| {
                                at.item(0, |at| at.this(*f, &FREQUENCY))?;
                                at.item(1, |at| at.this(*level, &PSD_LEVEL))
                            })
                        })
                })?;
                at.number("duration_s", *duration_s, &DURATION)?;
                at.number("sample_rate_hz", *sample_rate_hz, &SAMPLE_RATE)?;
                at.number("seed", *seed as f64, &SEED)?;
                at.number("low_cutoff_hz", *low_cutoff_hz, &CUTOFF_FREQUENCY)?;
                (settle_s, ramp)
            }
            ExcitationSpec::Measured {
                csv_path,
                samples,
                highpass_hz,
                settle_s,
                ramp,
                ..
            } => {
                if let Some(csv_path) = csv_path {
                    at.text("csv_path", csv_path, MAX_TEXT_CHARS, false)?;
                }
                if let Some(samples) = samples {
                    at.field("samples", |at| {
                        samples.iter().enumerate().try_for_each(|(i, sample)| {
                            at.item(i, |at| {
                                at.item(0, |at| at.this(sample[0], &SAMPLE_TIME))?;
                                (1..4).try_for_each(|j| {
                                    at.item(j, |at| at.this(sample[j], &ACCELERATION))
                                })
                            })
                        })
                    })?;
                }
                at.number("highpass_hz", *highpass_hz, &CUTOFF_FREQUENCY)?;
                (settle_s, ramp)
            }
        };
        at.number("settle_s", *settle_s, &SETTLE)?;
        at.child("ramp", ramp)
    }
}

/// A profile's name as a text field; a motion given in full by its bounds. The motion a
/// profile stands for is checked where it is resolved (`cases::bounds::check_case`).
impl Bounded for CaseExcitation {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        match &self.kind {
            Excitation::Profile(name) => at.text("profile", name, MAX_TEXT_CHARS, false),
            Excitation::Motion(spec) => spec.check_bounds(at),
        }
    }
}

/// A case's `[excitation]` table: its typed form and the table as written.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseExcitation {
    kind: Excitation,
    written: Value,
}

/// The `kind = "profile"` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileTable {
    #[allow(dead_code)]
    kind: String,
    profile: String,
}

impl CaseExcitation {
    /// The table `written` (a case file's `[excitation]`, or its JSON), typed. The error is the
    /// rule it breaks, with serde's words for an unknown key or kind.
    pub fn from_table(written: Value) -> Result<Self, String> {
        let kind = match written.get("kind").and_then(Value::as_str) {
            None | Some("") => return Err("the excitation table needs a `kind` string".into()),
            Some("profile") => Excitation::Profile(
                ProfileTable::deserialize(&written)
                    .map_err(|e| e.to_string())?
                    .profile,
            ),
            Some(_) => Excitation::Motion(
                ExcitationSpec::deserialize(&written).map_err(|e| e.to_string())?,
            ),
        };
        Ok(Self { kind, written })
    }

    /// The profile `name` of `configs/profiles/`.
    pub fn profile(name: &str) -> Self {
        Self {
            kind: Excitation::Profile(name.to_string()),
            written: serde_json::json!({"kind": "profile", "profile": name}),
        }
    }

    /// No base motion.
    pub fn none() -> Self {
        Self {
            kind: Excitation::Motion(ExcitationSpec::None),
            written: serde_json::json!({"kind": "none"}),
        }
    }

    /// The base motion `spec`, written as its JSON.
    pub fn motion(spec: ExcitationSpec) -> Result<Self, serde_json::Error> {
        let written = serde_json::to_value(&spec)?;
        Ok(Self {
            kind: Excitation::Motion(spec),
            written,
        })
    }

    /// What the excitation is.
    pub fn kind(&self) -> &Excitation {
        &self.kind
    }

    /// The table as written (what the case records).
    pub fn table(&self) -> &Value {
        &self.written
    }
}

/// Reads the table as written: `case.excitation["tones"][0]["amplitude_g"]`.
impl std::ops::Index<&str> for CaseExcitation {
    type Output = Value;

    fn index(&self, key: &str) -> &Value {
        &self.written[key]
    }
}

impl Serialize for CaseExcitation {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.written.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for CaseExcitation {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let written = Value::deserialize(deserializer)?;
        Self::from_table(written).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Every kind is typed as the engine reads it, and written back exactly as it came (an
    /// integer stays an integer, an omitted default stays omitted).
    #[test]
    fn a_table_is_typed_and_written_back_as_it_came() {
        let sine = json!({"kind": "sine", "tones": [
            {"axis": "x", "amplitude_g": 15, "frequency_hz": 20}]});
        let typed = CaseExcitation::from_table(sine.clone()).unwrap();
        let Excitation::Motion(ExcitationSpec::Sine {
            tones, settle_s, ..
        }) = typed.kind()
        else {
            panic!("a sine: {:?}", typed.kind());
        };
        assert_eq!((tones[0].amplitude_g, tones[0].frequency_hz), (15.0, 20.0));
        // The default of the excitation module (thesis 6.6.1: 2 s), not a value written.
        assert_eq!(*settle_s, 2.0);
        assert_eq!(serde_json::to_string(&typed).unwrap(), sine.to_string());
        let profile = CaseExcitation::from_table(json!({"kind": "profile", "profile": "p"}));
        assert_eq!(profile.unwrap(), CaseExcitation::profile("p"));
        assert_eq!(
            CaseExcitation::from_table(json!({"kind": "none"})).unwrap(),
            CaseExcitation::none()
        );
    }

    /// What is not an excitation is refused with the rule or the unknown key.
    #[test]
    fn a_table_that_is_not_an_excitation_is_refused_saying_why() {
        for (table, says) in [
            (json!({"tones": []}), "needs a `kind`"),
            (json!({"kind": "wobble"}), "wobble"),
            (json!({"kind": "sine", "tones": [], "colour": 1}), "colour"),
            (
                json!({"kind": "profile", "profile": "p", "seed": 3}),
                "seed",
            ),
            (json!({"kind": "profile"}), "profile"),
        ] {
            let err = CaseExcitation::from_table(table.clone()).unwrap_err();
            assert!(err.contains(says), "{table}: {err}");
        }
    }
}
