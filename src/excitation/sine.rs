//! Exact sine tones: `a = A sin(w tau + phi)`, `v = -(A/w) cos(w tau + phi)`,
//! `x = -(A/w²) sin(w tau + phi)`, the zero-mean integrals (no drift, no DC offset).

use super::{require_positive, ExcitationError, Tone};
use crate::units::STANDARD_GRAVITY;

/// A tone with its constants precomputed for the hot path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SineTerm {
    /// Component index 0..3 (x, y, z).
    pub axis: usize,
    /// Angular frequency, rad/s.
    pub omega_rad_s: f64,
    /// Peak acceleration, m/s².
    pub amplitude_m_s2: f64,
    /// Phase at excitation time zero, rad.
    pub phase_rad: f64,
}

impl SineTerm {
    /// Validates a tone (`field` is its path for error messages) and precomputes its constants.
    pub fn from_tone(tone: &Tone, field: &str) -> Result<Self, ExcitationError> {
        require_positive(&format!("{field}.frequency_hz"), tone.frequency_hz)?;
        if !tone.amplitude_g.is_finite() || tone.amplitude_g < 0.0 {
            return Err(super::FieldError::new(
                format!("{field}.amplitude_g"),
                format!("must be finite and >= 0, got {}", tone.amplitude_g),
            )
            .into());
        }
        if !tone.phase_deg.is_finite() {
            return Err(
                super::FieldError::new(format!("{field}.phase_deg"), "must be finite").into(),
            );
        }
        Ok(Self {
            axis: tone.axis.index(),
            omega_rad_s: 2.0 * std::f64::consts::PI * tone.frequency_hz,
            amplitude_m_s2: tone.amplitude_g * STANDARD_GRAVITY,
            phase_rad: tone.phase_deg.to_radians(),
        })
    }

    /// Displacement (m), velocity (m/s), acceleration (m/s²) at excitation time `tau_s`.
    #[inline]
    pub fn eval(&self, tau_s: f64) -> (f64, f64, f64) {
        let (s, c) = (self.omega_rad_s * tau_s + self.phase_rad).sin_cos();
        let a = self.amplitude_m_s2;
        let w = self.omega_rad_s;
        (-a / (w * w) * s, -a / w * c, a * s)
    }
}

/// Validates a list of tones, naming the offending one as `tones[i]`.
pub(crate) fn sine_terms(tones: &[Tone]) -> Result<Vec<SineTerm>, ExcitationError> {
    tones
        .iter()
        .enumerate()
        .map(|(i, t)| SineTerm::from_tone(t, &format!("tones[{i}]")))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excitation::Axis;

    #[test]
    fn tone_integrals_are_consistent() {
        let term = SineTerm::from_tone(
            &Tone {
                axis: Axis::Y,
                frequency_hz: 20.0,
                amplitude_g: 15.0,
                phase_deg: 30.0,
            },
            "tones[0]",
        )
        .unwrap();
        let w = 2.0 * std::f64::consts::PI * 20.0;
        for k in 0..50 {
            let t = 0.0137 * k as f64;
            let (x, v, a) = term.eval(t);
            assert!((a + w * w * x).abs() < 1e-9 * a.abs().max(1.0));
            // v is the derivative of x: central difference, error O(h² w³ X)
            let h = 1e-6;
            let dx = (term.eval(t + h).0 - term.eval(t - h).0) / (2.0 * h);
            assert!((dx - v).abs() < 1e-6);
        }
        // peak acceleration is 15 g
        let peak = (0..10_000)
            .map(|k| term.eval(k as f64 * 5e-6).2.abs())
            .fold(0.0, f64::max);
        assert!((peak - 15.0 * STANDARD_GRAVITY).abs() < 1e-3 * peak);
    }

    #[test]
    fn bad_tone_names_field() {
        let err = sine_terms(&[
            Tone {
                axis: Axis::X,
                frequency_hz: 5.0,
                amplitude_g: 1.0,
                phase_deg: 0.0,
            },
            Tone {
                axis: Axis::X,
                frequency_hz: -1.0,
                amplitude_g: 1.0,
                phase_deg: 0.0,
            },
        ])
        .unwrap_err();
        assert!(err.to_string().contains("tones[1].frequency_hz"), "{err}");
    }
}
