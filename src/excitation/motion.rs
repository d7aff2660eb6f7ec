//! [`BaseMotion`]: the evaluated form of an [`ExcitationSpec`], used on the integrator's hot path.

use nalgebra::Vector3;
use std::sync::{Arc, Mutex};

use super::measured::{parse_acceleration_csv, AccelerationRecord};
use super::random::{synthesize_random, validate_breakpoints};
use super::sine::{sine_terms, SineTerm};
use super::{
    require_non_negative, require_positive, ExcitationError, ExcitationSpec, RampSpec,
    SampledRecord,
};
use crate::field_error::FieldError;

/// Base displacement, velocity and acceleration at one instant (rail frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionState {
    /// Displacement from the rest position, m.
    pub displacement_m: Vector3<f64>,
    /// Velocity, m/s.
    pub velocity_m_s: Vector3<f64>,
    /// Acceleration, m/s².
    pub acceleration_m_s2: Vector3<f64>,
}

/// Synthesised random records kept for reuse, newest first: the points of a tolerance sweep,
/// the fanned-out jobs of one study and the service's repeated runs of a reference profile share
/// one record (a 32 s record at 2048 Hz is 1.6 MB and ~10 ms of synthesis per build).
const SHARED_RECORDS: usize = 4;

type RecordCache = Mutex<Vec<(String, Arc<SampledRecord>)>>;

/// The record of a `SineOnRandom` spec: from the cache when an identical spec (every field, the
/// seed included) was synthesised before, else from `synthesize` (outside the lock).
fn shared_random_record(
    spec: &ExcitationSpec,
    synthesize: impl FnOnce() -> Result<SampledRecord, ExcitationError>,
) -> Result<Arc<SampledRecord>, ExcitationError> {
    static CACHE: RecordCache = Mutex::new(Vec::new());
    // The key is the whole spec (settle and ramp included: the points of one sweep share them).
    let Ok(key) = serde_json::to_string(spec) else {
        return synthesize().map(Arc::new);
    };
    let lookup = |cache: &mut Vec<(String, Arc<SampledRecord>)>| {
        let i = cache.iter().position(|(k, _)| *k == key)?;
        let hit = cache.remove(i);
        let record = Arc::clone(&hit.1);
        cache.insert(0, hit);
        Some(record)
    };
    if let Some(record) = CACHE.lock().ok().and_then(|mut c| lookup(&mut c)) {
        return Ok(record);
    }
    let record = Arc::new(synthesize()?);
    if let Ok(mut cache) = CACHE.lock() {
        if lookup(&mut cache).is_none() {
            cache.insert(0, (key, Arc::clone(&record)));
            cache.truncate(SHARED_RECORDS);
        }
    }
    Ok(record)
}

/// Prescribed base motion built once from a spec; evaluation is O(1) per call (a few tones plus
/// one Hermite interval) and never allocates.
///
/// Motion is `w(tau) * m(tau)` with `tau = t - settle_s`, `m` the sum of exact tones and a
/// sampled record, and `w` the ramp window (0 before, cycloidal step of eq. 2.4 over `ramp_s`,
/// then 1; a measured record also ramps out over `ramp_s` before its end and is zero after
/// it). Velocity and acceleration are the exact time derivatives of that product, so the
/// three outputs are consistent everywhere, ramp included.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMotion {
    tones: Vec<SineTerm>,
    record: Option<Arc<SampledRecord>>,
    settle_s: f64,
    ramp_s: f64,
    /// Excitation time at which a finite (measured) record ends, s: the motion ramps out over
    /// the `ramp_s` before it and is zero after it.
    end_s: Option<f64>,
}

impl BaseMotion {
    /// No motion at all.
    pub fn none() -> Self {
        Self {
            tones: Vec::new(),
            record: None,
            settle_s: 0.0,
            ramp_s: 0.0,
            end_s: None,
        }
    }

    /// Builds the motion from a spec. A `Measured` spec with `csv_path` reads the file; a
    /// relative path is taken as given (the caller resolves it against the config's folder).
    pub fn from_spec(spec: &ExcitationSpec) -> Result<Self, ExcitationError> {
        match spec {
            ExcitationSpec::None => Ok(Self::none()),
            ExcitationSpec::Sine {
                tones,
                settle_s,
                ramp,
            } => {
                if tones.is_empty() {
                    return Err(FieldError::new(
                        "tones",
                        "a sine excitation needs at least one tone",
                    )
                    .into());
                }
                let terms = sine_terms(tones)?;
                let lowest = terms
                    .iter()
                    .map(|t| t.omega_rad_s / std::f64::consts::TAU)
                    .fold(f64::INFINITY, f64::min);
                Self::assemble(terms, None, *settle_s, *ramp, lowest)
            }
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
            } => {
                validate_breakpoints(psd_breakpoints)?;
                let terms = sine_terms(tones)?;
                let record = shared_random_record(spec, || {
                    synthesize_random(
                        axes,
                        psd_breakpoints,
                        *duration_s,
                        *sample_rate_hz,
                        *seed,
                        *low_cutoff_hz,
                    )
                })?;
                let lowest = terms
                    .iter()
                    .map(|t| t.omega_rad_s / std::f64::consts::TAU)
                    .fold(low_cutoff_hz.max(psd_breakpoints[0].0), f64::min);
                Self::assemble(terms, Some(record), *settle_s, *ramp, lowest)
            }
            ExcitationSpec::Measured {
                csv_path,
                samples,
                units,
                highpass_hz,
                settle_s,
                ramp,
            } => {
                let record = match (csv_path, samples) {
                    (Some(path), None) => {
                        let text = std::fs::read_to_string(path).map_err(|source| {
                            ExcitationError::Io {
                                path: path.clone(),
                                source,
                            }
                        })?;
                        parse_acceleration_csv(&text, *units)?
                    }
                    (None, Some(rows)) => AccelerationRecord::from_samples(rows, *units)?,
                    _ => {
                        return Err(FieldError::new(
                            "csv_path",
                            "give exactly one of `csv_path` and `samples`",
                        )
                        .into())
                    }
                };
                let motion = record.integrate(*highpass_hz)?;
                let end_s = (motion.samples().len() - 1) as f64 * motion.dt_s();
                let mut built = Self::assemble(
                    Vec::new(),
                    Some(Arc::new(motion)),
                    *settle_s,
                    *ramp,
                    *highpass_hz,
                )?;
                built.end_s = Some(end_s);
                Ok(built)
            }
        }
    }

    /// Builds from parts: tones, an optional periodic record, the settle time and the ramp.
    /// `lowest_hz` is the frequency `RampSpec::Cycles` counts in.
    fn assemble(
        tones: Vec<SineTerm>,
        record: Option<Arc<SampledRecord>>,
        settle_s: f64,
        ramp: RampSpec,
        lowest_hz: f64,
    ) -> Result<Self, ExcitationError> {
        require_non_negative("settle_s", settle_s)?;
        let ramp_s = match ramp {
            RampSpec::Seconds(s) => {
                require_non_negative("ramp.seconds", s)?;
                s
            }
            RampSpec::Cycles(c) => {
                require_non_negative("ramp.cycles", c)?;
                require_positive("lowest excitation frequency", lowest_hz)?;
                c / lowest_hz
            }
        };
        Ok(Self {
            tones,
            record,
            settle_s,
            ramp_s,
            end_s: None,
        })
    }

    /// Settle time with no motion, s.
    pub fn settle_s(&self) -> f64 {
        self.settle_s
    }

    /// Length of the ramp-in after the settle phase, s.
    pub fn ramp_s(&self) -> f64 {
        self.ramp_s
    }

    /// Period after which the sampled part repeats, s (`None` for pure tones, no motion, or a
    /// measured record, which does not repeat).
    pub fn record_period_s(&self) -> Option<f64> {
        match self.end_s {
            Some(_) => None,
            None => self.record.as_deref().map(SampledRecord::period_s),
        }
    }

    /// Simulation time after which the motion is zero (measured records only), s.
    pub fn end_time_s(&self) -> Option<f64> {
        self.end_s.map(|e| e + self.settle_s)
    }

    /// Displacement, velocity and acceleration at simulation time `t_s`. O(1), no allocation.
    #[inline]
    pub fn state(&self, t_s: f64) -> MotionState {
        let tau = t_s - self.settle_s;
        let zero = MotionState {
            displacement_m: Vector3::zeros(),
            velocity_m_s: Vector3::zeros(),
            acceleration_m_s2: Vector3::zeros(),
        };
        if tau <= 0.0
            || (self.tones.is_empty() && self.record.is_none())
            || self.end_s.is_some_and(|end| tau >= end)
        {
            return zero;
        }
        let mut x = [0.0; 3];
        let mut v = [0.0; 3];
        let mut a = [0.0; 3];
        if let Some(record) = &self.record {
            let s = record.eval(tau);
            x = s.displacement_m;
            v = s.velocity_m_s;
            a = s.acceleration_m_s2;
        }
        for tone in &self.tones {
            let (tx, tv, ta) = tone.eval(tau);
            x[tone.axis] += tx;
            v[tone.axis] += tv;
            a[tone.axis] += ta;
        }
        let (mut w, mut dw, mut ddw) = ramp_window(tau, self.ramp_s);
        if let Some(end) = self.end_s {
            // Ramp-out: the mirror image of the ramp-in, ending at `end`; product rule.
            let (wo, dwo, ddwo) = ramp_window(end - tau, self.ramp_s);
            let (dwo, ddwo) = (-dwo, ddwo);
            (w, dw, ddw) = (
                w * wo,
                dw * wo + w * dwo,
                ddw * wo + 2.0 * dw * dwo + w * ddwo,
            );
        }
        let mut out = zero;
        for c in 0..3 {
            out.displacement_m[c] = w * x[c];
            out.velocity_m_s[c] = dw * x[c] + w * v[c];
            out.acceleration_m_s2[c] = ddw * x[c] + 2.0 * dw * v[c] + w * a[c];
        }
        out
    }

    /// Base displacement at `t_s`, m.
    #[inline]
    pub fn displacement(&self, t_s: f64) -> Vector3<f64> {
        self.state(t_s).displacement_m
    }

    /// Base velocity at `t_s`, m/s.
    #[inline]
    pub fn velocity(&self, t_s: f64) -> Vector3<f64> {
        self.state(t_s).velocity_m_s
    }

    /// Base acceleration at `t_s`, m/s².
    #[inline]
    pub fn acceleration(&self, t_s: f64) -> Vector3<f64> {
        self.state(t_s).acceleration_m_s2
    }
}

/// Ramp window and its first two derivatives: the cycloidal step of thesis eq. 2.4,
/// `u - sin(2 pi u)/(2 pi)` with `u = tau / ramp_s`, whose slope and curvature vanish at both
/// ends (so the windowed motion starts with zero displacement, velocity and acceleration).
#[inline]
fn ramp_window(tau: f64, ramp_s: f64) -> (f64, f64, f64) {
    if tau >= ramp_s {
        return (1.0, 0.0, 0.0);
    }
    if tau <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    let u = tau / ramp_s;
    let (s, c) = (std::f64::consts::TAU * u).sin_cos();
    (
        u - s / std::f64::consts::TAU,
        (1.0 - c) / ramp_s,
        std::f64::consts::TAU * s / (ramp_s * ramp_s),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excitation::profile::ah64_transverse_representative;

    #[test]
    fn identical_random_specs_share_one_record_and_other_seeds_do_not() {
        let spec = ah64_transverse_representative();
        let a = BaseMotion::from_spec(&spec).expect("builds");
        let b = BaseMotion::from_spec(&spec).expect("builds");
        let (Some(ra), Some(rb)) = (&a.record, &b.record) else {
            panic!("a sine-on-random spec has a record");
        };
        assert!(Arc::ptr_eq(ra, rb));
        let ExcitationSpec::SineOnRandom { seed, .. } = &spec else {
            panic!("the AH-64 profile is sine on random");
        };
        let mut other = spec.clone();
        if let ExcitationSpec::SineOnRandom { seed: s, .. } = &mut other {
            *s = seed + 1;
        }
        let c = BaseMotion::from_spec(&other).expect("builds");
        let rc = c.record.as_ref().expect("record");
        assert!(!Arc::ptr_eq(ra, rc));
        assert_ne!(ra.samples(), rc.samples());
    }
}
