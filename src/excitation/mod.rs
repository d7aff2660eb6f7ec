//! Prescribed base motion of the kinematic body (the shaker fixture or the rail).
//!
//! An [`ExcitationSpec`] is the `[excitation]` table of a case config. It is turned once into a
//! [`BaseMotion`], which the integrator evaluates at arbitrary times: every evaluation is O(1) and
//! allocation-free (tables are precomputed at build time).
//!
//! Axes are the rail frame of thesis 6.2.2: x transverse, y vertical, z longitudinal.
//!
//! Timeline (thesis 6.6.1): no motion during `settle_s` (default 2 s) so the system can reach
//! static equilibrium, then a smooth ramp-in of length `ramp` during which the motion is multiplied
//! by the cycloidal step of eq. 2.4 (zero value, slope and curvature at both ends), so displacement
//! and velocity start at zero without a jump. Excitation time `tau = t - settle_s` starts at the end
//! of the settle phase; tone phases refer to `tau = 0`.

mod hermite;
mod measured;
mod motion;
pub mod profile;
mod random;
mod sine;
#[cfg(test)]
mod tests;

pub use hermite::{MotionSample, SampledRecord};
pub use measured::{parse_acceleration_csv, AccelerationRecord};
pub use motion::{BaseMotion, MotionState};
pub use random::{psd_at, psd_mean_square, synthesize_random};

use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Default settle time before any input, s (thesis 6.6.1: "2 seconds of no input").
pub const DEFAULT_SETTLE_S: f64 = 2.0;
/// Default ramp-in length in cycles of the lowest excitation frequency.
pub const DEFAULT_RAMP_CYCLES: f64 = 3.0;
/// Largest number of samples a synthesised or measured record may have (memory guard:
/// 2^24 samples x 9 doubles = 1.2 GB would be too much; 2^22 is about 300 MB).
pub const MAX_RECORD_SAMPLES: usize = 1 << 22;

/// Axis of the rail frame (thesis 6.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Transverse.
    X,
    /// Vertical (towards the vehicle).
    Y,
    /// Longitudinal (firing direction).
    Z,
}

impl Axis {
    /// Component index in a `Vector3` (x = 0, y = 1, z = 2).
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// One sinusoidal tone of base acceleration, `a(tau) = A sin(2 pi f tau + phase)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tone {
    /// Axis the tone drives.
    pub axis: Axis,
    /// Tone frequency, Hz (> 0).
    pub frequency_hz: f64,
    /// Peak acceleration amplitude, g (standard gravity 9.80665 m/s²).
    pub amplitude_g: f64,
    /// Phase of the acceleration at excitation time zero, degrees.
    #[serde(default)]
    pub phase_deg: f64,
}

/// Length of the smooth ramp-in that follows the settle phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RampSpec {
    /// Ramp length in seconds (>= 0; 0 means no ramp: velocity then jumps at `settle_s`).
    Seconds(f64),
    /// Ramp length in cycles of the lowest frequency of the excitation (lowest tone, or the
    /// low cutoff of a random background, or the high-pass of a measured record).
    Cycles(f64),
}

impl Default for RampSpec {
    fn default() -> Self {
        RampSpec::Cycles(DEFAULT_RAMP_CYCLES)
    }
}

/// Physical unit of a measured acceleration record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AccelUnit {
    /// Multiples of standard gravity (9.80665 m/s²).
    G,
    /// Metres per second squared.
    #[serde(rename = "m_s2")]
    MetresPerSecond2,
}

impl AccelUnit {
    /// Factor converting a value in this unit to m/s².
    pub fn to_si(self) -> f64 {
        match self {
            AccelUnit::G => crate::units::STANDARD_GRAVITY,
            AccelUnit::MetresPerSecond2 => 1.0,
        }
    }
}

fn default_settle_s() -> f64 {
    DEFAULT_SETTLE_S
}
fn default_low_cutoff_hz() -> f64 {
    1.0
}
fn default_highpass_hz() -> f64 {
    2.0
}

/// The `[excitation]` table of a case config: prescribed base acceleration of the kinematic body.
///
/// All variants except `None` carry `settle_s` (default 2 s, thesis 6.6.1) and `ramp`
/// (default 3 cycles of the lowest frequency); see the module docs for the timeline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ExcitationSpec {
    /// No base motion (static load cases, settling studies).
    None,
    /// Sum of pure tones (the thesis' shaker tests: chapter 5 15 g at 20 Hz, chapter 6 single
    /// tones of the AH-64 profile).
    Sine {
        /// Tones; several may share an axis.
        tones: Vec<Tone>,
        /// Time with no input before the excitation starts, s (thesis 6.6.1: 2 s).
        #[serde(default = "default_settle_s")]
        settle_s: f64,
        /// Smooth ramp-in length after the settle phase.
        #[serde(default)]
        ramp: RampSpec,
    },
    /// Sine tones on a broadband random background (MIL-STD-810G Method 514.6 helicopter
    /// profiles). The background is synthesised by random-phase inverse FFT of the PSD with a
    /// seeded ChaCha20 generator: the same seed gives a bit-identical record. The record repeats
    /// with period `duration_s`; tones are exact sines.
    SineOnRandom {
        /// Axes that receive the random background (independent phases per axis).
        axes: Vec<Axis>,
        /// Tones added as exact sines.
        tones: Vec<Tone>,
        /// One-sided acceleration PSD breakpoints `(frequency Hz, g²/Hz)`, interpolated linearly
        /// in log-log; zero outside the first..last breakpoint. Frequencies strictly increasing,
        /// levels > 0, last frequency below the Nyquist frequency `sample_rate_hz / 2`.
        psd_breakpoints: Vec<(f64, f64)>,
        /// Length of the synthesised record, s; the record repeats periodically after it. The
        /// frequency resolution of the synthesis is `1 / duration_s`.
        duration_s: f64,
        /// Sample rate of the synthesised record, Hz. Between samples the motion is a quintic
        /// Hermite interpolant of (displacement, velocity, acceleration); keep it at least 4x
        /// the highest PSD frequency for accurate acceleration between samples.
        sample_rate_hz: f64,
        /// Seed of the ChaCha20 phase generator.
        seed: u64,
        /// Random content below this frequency is zeroed before integration, Hz (> 0): the
        /// displacement of a PSD grows as 1/f^4, so very low frequencies would give metre-scale
        /// shaker strokes. Default 1 Hz.
        #[serde(default = "default_low_cutoff_hz")]
        low_cutoff_hz: f64,
        /// Time with no input before the excitation starts, s (thesis 6.6.1: 2 s).
        #[serde(default = "default_settle_s")]
        settle_s: f64,
        /// Smooth ramp-in length after the settle phase.
        #[serde(default)]
        ramp: RampSpec,
    },
    /// A measured acceleration record (the thesis splined the rail accelerometers into ADAMS,
    /// 6.6). Exactly one of `csv_path` or `samples` must be given.
    Measured {
        /// Path of a CSV file with header `time_s,a_x,a_y,a_z`.
        #[serde(default)]
        csv_path: Option<String>,
        /// Inline samples `[time_s, a_x, a_y, a_z]`.
        #[serde(default)]
        samples: Option<Vec<[f64; 4]>>,
        /// Unit of the acceleration columns.
        units: AccelUnit,
        /// High-pass cutoff of the drift removal, Hz (> 0): content below it is zeroed before
        /// integrating to velocity and displacement. Default 2 Hz.
        #[serde(default = "default_highpass_hz")]
        highpass_hz: f64,
        /// Time with no input before the excitation starts, s (thesis 6.6.1: 2 s).
        #[serde(default = "default_settle_s")]
        settle_s: f64,
        /// Smooth ramp-in length after the settle phase.
        #[serde(default)]
        ramp: RampSpec,
    },
}

/// Errors building a base motion from a spec or a measured record. Each names the field or the
/// CSV row/column and the rule broken.
#[derive(Debug, thiserror::Error)]
pub enum ExcitationError {
    /// A spec field breaks a rule.
    /// (The field is a dotted path, e.g. `tones[2].frequency_hz`.)
    #[error("excitation field `{}`: {}", .0.field, .0.rule)]
    InvalidField(#[from] FieldError),
    /// A measured CSV cell or row is malformed.
    #[error("acceleration CSV row {row}, column `{column}`: {rule}")]
    Csv {
        /// 1-based line number in the file (the header is line 1).
        row: usize,
        /// Column name from the header `time_s,a_x,a_y,a_z`.
        column: String,
        /// The rule broken.
        rule: String,
    },
    /// Reading a CSV or profile file failed.
    #[error("reading {path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
    /// A profile file is not valid TOML for the expected schema.
    #[error("parsing profile: {0}")]
    Toml(#[from] toml::de::Error),
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn require_positive(field: &str, value: f64) -> Result<(), ExcitationError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(field, format!("must be finite and > 0, got {value}")).into())
    }
}

/// Checks that `value` is finite and >= 0.
pub(crate) fn require_non_negative(field: &str, value: f64) -> Result<(), ExcitationError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(field, format!("must be finite and >= 0, got {value}")).into())
    }
}
