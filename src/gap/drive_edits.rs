//! The drive edits of the dynamics effects (`gap::effects`): the case's excitation resolved,
//! filtered through a compliant mount (fixture compliance) or repeated on the other axes
//! (cross-axis drive), and written back. A measured drive is refused: its record would need
//! the filter, and its axes are measured.

use super::GapError;
use crate::excitation::{Axis, ExcitationSpec, Tone};
use crate::models::spec::CaseSpec;
use std::path::Path;

pub(super) fn resolved_excitation(
    case: &CaseSpec,
    configs_dir: &Path,
    field: &str,
) -> Result<ExcitationSpec, GapError> {
    crate::models::case::resolve_excitation(case, configs_dir)
        .map_err(|e| GapError::field(field, e.to_string()))
}

pub(super) fn set_excitation(
    case: &mut CaseSpec,
    spec: &ExcitationSpec,
    field: &str,
) -> Result<(), GapError> {
    case.excitation = crate::models::spec::CaseExcitation::motion(spec.clone())
        .map_err(|e| GapError::field(field, e.to_string()))?;
    Ok(())
}

/// Base-excitation transmissibility of a mount with natural period `period_s` and damping
/// ratio `zeta` at `f` Hz: `T = (1 + 2iζr) / (1 - r² + 2iζr)`, `r = f T_n`. Returns (|T|,
/// phase in degrees).
pub fn transmissibility(f_hz: f64, period_s: f64, zeta: f64) -> (f64, f64) {
    let r = f_hz * period_s;
    let (nr, ni) = (1.0, 2.0 * zeta * r);
    let (dr, di) = (1.0 - r * r, 2.0 * zeta * r);
    let den = dr * dr + di * di;
    let re = (nr * dr + ni * di) / den;
    let im = (ni * dr - nr * di) / den;
    (re.hypot(im), im.atan2(re).to_degrees())
}

pub(super) fn filter_through_mount(
    spec: ExcitationSpec,
    period_s: f64,
    zeta: f64,
    field: &str,
) -> Result<ExcitationSpec, GapError> {
    let filter_tones = |tones: Vec<Tone>| -> Vec<Tone> {
        tones
            .into_iter()
            .map(|t| {
                let (gain, phase) = transmissibility(t.frequency_hz, period_s, zeta);
                Tone {
                    amplitude_g: t.amplitude_g * gain,
                    phase_deg: t.phase_deg + phase,
                    ..t
                }
            })
            .collect()
    };
    map_drive(
        spec,
        filter_tones,
        |psd| {
            psd.into_iter()
                .map(|(f, g2)| (f, g2 * transmissibility(f, period_s, zeta).0.powi(2)))
                .collect()
        },
        field,
        "not available for a measured drive (it would need the record filtered)",
    )
}

pub(super) fn add_cross_axis(
    spec: ExcitationSpec,
    share: f64,
    phase_deg: f64,
    field: &str,
) -> Result<ExcitationSpec, GapError> {
    let cross = |tones: Vec<Tone>| -> Vec<Tone> {
        let mut out = tones.clone();
        for t in &tones {
            for axis in [Axis::X, Axis::Y, Axis::Z] {
                if axis != t.axis {
                    out.push(Tone {
                        axis,
                        amplitude_g: share * t.amplitude_g,
                        phase_deg: t.phase_deg + phase_deg,
                        ..*t
                    });
                }
            }
        }
        out
    };
    map_drive(
        spec,
        cross,
        |psd| psd,
        field,
        "not available for a measured drive (its axes are measured)",
    )
}

/// `spec` with its tones and random PSD breakpoints mapped; a measured drive is refused at
/// `field` with `measured_rule`.
fn map_drive(
    spec: ExcitationSpec,
    tones_map: impl Fn(Vec<Tone>) -> Vec<Tone>,
    psd_map: impl Fn(Vec<(f64, f64)>) -> Vec<(f64, f64)>,
    field: &str,
    measured_rule: &str,
) -> Result<ExcitationSpec, GapError> {
    Ok(match spec {
        ExcitationSpec::Sine {
            tones,
            settle_s,
            ramp,
        } => ExcitationSpec::Sine {
            tones: tones_map(tones),
            settle_s,
            ramp,
        },
        ExcitationSpec::SineOnRandom {
            axes,
            tones,
            psd_breakpoints,
            duration_s,
            sample_rate_hz,
            seed,
            low_cutoff_hz,
            settle_s,
            ramp,
        } => ExcitationSpec::SineOnRandom {
            axes,
            tones: tones_map(tones),
            psd_breakpoints: psd_map(psd_breakpoints),
            duration_s,
            sample_rate_hz,
            seed,
            low_cutoff_hz,
            settle_s,
            ramp,
        },
        ExcitationSpec::None => ExcitationSpec::None,
        ExcitationSpec::Measured { .. } => return Err(GapError::field(field, measured_rule)),
    })
}
