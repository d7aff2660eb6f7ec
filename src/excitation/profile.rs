//! Shipped vibration profiles (`configs/profiles/*.toml`) and their Rust constructors.
//!
//! The AH-64 profile carries REPRESENTATIVE levels, not MIL-STD-810G Method 514.6 table values
//! (those are not in this repository): the tone frequencies are the rotor harmonics named by the
//! thesis (6.6); amplitudes and PSD are placeholders. Load your own before trusting results.

use serde::{Deserialize, Serialize};

use super::{Axis, ExcitationError, ExcitationSpec, RampSpec, Tone, DEFAULT_SETTLE_S};

/// Descriptive header of a profile file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileInfo {
    /// Short identifier, e.g. `ah64-transverse`.
    pub name: String,
    /// One-line description, including whether levels are representative.
    pub description: String,
    /// True when the levels are placeholders rather than a standard's or measured values.
    pub representative: bool,
}

/// A profile file: `[profile]` header plus an `[excitation]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileFile {
    /// Header.
    pub profile: ProfileInfo,
    /// The excitation, as in a case config's `[excitation]` table.
    pub excitation: ExcitationSpec,
}

impl ProfileFile {
    /// Parses a profile from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, ExcitationError> {
        Ok(toml::from_str(text)?)
    }

    /// Reads and parses a profile file.
    pub fn load(path: &std::path::Path) -> Result<Self, ExcitationError> {
        let text = std::fs::read_to_string(path).map_err(|source| ExcitationError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text)
    }
}

/// AH-64 rotor 1P frequency, Hz, and the harmonics the thesis tested (6.6: 4.86 (printed 4.88 in
/// places), 19.44, 38.88, 58.32 Hz = 1, 4, 8, 12 x 1P).
pub const AH64_TONES_HZ: [f64; 4] = [4.86, 19.44, 38.88, 58.32];

/// AH-64 transverse (x) sine-on-random with REPRESENTATIVE levels (not the standard's table
/// values; load your own): tones 0.25, 1.5, 0.75, 0.5 g peak at [`AH64_TONES_HZ`], PSD 0.0005
/// g²/Hz at 5 Hz rising to 0.001 g²/Hz at 10 Hz, flat to 500 Hz; 32 s record at 2048 Hz,
/// seed 514. Identical to `configs/profiles/ah64-transverse.toml`.
pub fn ah64_transverse_representative() -> ExcitationSpec {
    let amplitudes_g = [0.25, 1.5, 0.75, 0.5];
    ExcitationSpec::SineOnRandom {
        axes: vec![Axis::X],
        tones: AH64_TONES_HZ
            .iter()
            .zip(amplitudes_g)
            .map(|(&frequency_hz, amplitude_g)| Tone {
                axis: Axis::X,
                frequency_hz,
                amplitude_g,
                phase_deg: 0.0,
            })
            .collect(),
        psd_breakpoints: vec![(5.0, 0.0005), (10.0, 0.001), (500.0, 0.001)],
        duration_s: 32.0,
        sample_rate_hz: 2048.0,
        seed: 514,
        low_cutoff_hz: 4.0,
        settle_s: DEFAULT_SETTLE_S,
        ramp: RampSpec::Cycles(3.0),
    }
}

/// Rattle-box excitation of thesis chapter 5 (5.5): transverse (x) sine, 15 g peak at 20 Hz.
/// Identical to `configs/profiles/rattle-box-20hz-15g.toml`.
pub fn rattle_box_20hz_15g() -> ExcitationSpec {
    ExcitationSpec::Sine {
        tones: vec![Tone {
            axis: Axis::X,
            frequency_hz: 20.0,
            amplitude_g: 15.0,
            phase_deg: 0.0,
        }],
        settle_s: DEFAULT_SETTLE_S,
        ramp: RampSpec::Cycles(3.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_files_match_constructors() {
        let ah64 =
            ProfileFile::from_toml_str(include_str!("../../configs/profiles/ah64-transverse.toml"))
                .unwrap();
        assert_eq!(ah64.excitation, ah64_transverse_representative());
        assert!(ah64.profile.representative);
        assert!(ah64.profile.description.contains("representative"));
        let rattle = ProfileFile::from_toml_str(include_str!(
            "../../configs/profiles/rattle-box-20hz-15g.toml"
        ))
        .unwrap();
        assert_eq!(rattle.excitation, rattle_box_20hz_15g());
        assert!(!rattle.profile.representative);
    }

    #[test]
    fn unknown_field_is_rejected() {
        let text = r#"
            [profile]
            name = "x"
            description = "y"
            representative = false
            [excitation]
            kind = "sine"
            tones = []
            setle_s = 1.0
        "#;
        let err = ProfileFile::from_toml_str(text).unwrap_err();
        assert!(err.to_string().contains("setle_s"), "{err}");
    }

    #[test]
    fn measured_spec_parses_with_defaults() {
        #[derive(Deserialize)]
        struct Wrapper {
            excitation: ExcitationSpec,
        }
        let text = r#"
            [excitation]
            kind = "measured"
            csv_path = "rail_accel.csv"
            units = "m_s2"
        "#;
        let w: Wrapper = toml::from_str(text).unwrap();
        assert_eq!(
            w.excitation,
            ExcitationSpec::Measured {
                csv_path: Some("rail_accel.csv".into()),
                samples: None,
                units: super::super::AccelUnit::MetresPerSecond2,
                highpass_hz: 2.0,
                settle_s: 2.0,
                ramp: RampSpec::Cycles(3.0),
            }
        );
    }

    #[test]
    fn spec_roundtrips_through_toml() {
        #[derive(Serialize, Deserialize, PartialEq, Debug)]
        struct Wrapper {
            excitation: ExcitationSpec,
        }
        for spec in [
            ah64_transverse_representative(),
            rattle_box_20hz_15g(),
            ExcitationSpec::None,
        ] {
            let w = Wrapper { excitation: spec };
            let text = toml::to_string(&w).unwrap();
            let back: Wrapper = toml::from_str(&text).unwrap();
            assert_eq!(back, w, "{text}");
        }
    }
}
