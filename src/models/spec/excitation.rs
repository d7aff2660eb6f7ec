//! A case's `[excitation]` table, typed when the case is read: a shipped profile by name
//! (`kind = "profile"`, `profile = "<name>"`) or a base motion given in full (`none`, `sine`,
//! `sine_on_random`, `measured`: the schema of [`ExcitationSpec`]). A table that is neither
//! (no `kind`, an unknown kind, an unknown key) is refused where the case is read.
//!
//! The table is also kept as written, for the record only: a result's `config`, a job's stored
//! plan and a checkpoint's case hash carry the case as it was written (an omitted default stays
//! omitted, `15` stays an integer), so typing the table changes no stored result and no
//! refactor hash. Every reader of the excitation takes the typed form ([`CaseExcitation::kind`]);
//! the physical bounds read the written one ([`CaseExcitation::table`]), as they read every
//! table by its field paths.

use crate::excitation::ExcitationSpec;
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

    /// The table as written (what the case records and the bounds read).
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
