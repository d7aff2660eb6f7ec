//! Streaming per-track wear integration (eq. 3.13-3.15), as the thesis' `CParse.C` does per
//! track, but with the pressure sigma = N/A in K (eq. 3.11) and the trapezoid rule.
//!
//! Samples are consumed one at a time; nothing per sample is stored, so tracks of millions of
//! samples cost O(1) memory and `push` does not allocate.

use super::law::{Quadrature, WearLaw};
use super::mechanism::{volume_rate_with_terms_m3_s, WearMechanism, WearSample};
use super::pressure_pdf::PressureHistogram;
use super::WearError;
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// What one track (or, after [`WearTotals::merge`], one contact) accumulated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WearTotals {
    /// Wear volume W, m³ (eq. 3.15).
    pub volume_m3: f64,
    /// Normal-load-times-slip work ∫ N |v_slip| dt, J (the "work" K multiplies in eq. 3.13;
    /// friction dissipates μ times it where the contact slides: the run report's
    /// `friction_work_j` is the energy account's). Read as `friction_work_j` from JSON written
    /// before the name said what it is.
    #[serde(alias = "friction_work_j")]
    pub normal_slip_work_j: f64,
    /// Part of `normal_slip_work_j` done at sigma above the law's cutoff, J (thesis 5.5: a large
    /// share means the law is outside its validity range; that wear is not counted).
    pub work_above_cutoff_j: f64,
    /// Time with N > 0, s (trapezoid on the contact indicator).
    pub contact_time_s: f64,
    /// Time of the first sample, s.
    pub start_time_s: f64,
    /// Time of the last sample, s.
    pub end_time_s: f64,
    /// Number of samples pushed.
    pub samples: u64,
    /// Samples with N > 0 but zero area (sigma taken as infinite, so above any cutoff).
    pub zero_area_samples: u64,
    /// Largest finite contact pressure seen, Pa.
    pub peak_pressure_pa: f64,
    /// Cutoff pressure of the law used, Pa (`null` in JSON when the law has none).
    pub cutoff_pressure_pa: Option<f64>,
    /// Contact time and normal-load-times-slip work per pressure bin (Figure 6.65).
    pub pressure_histogram: PressureHistogram,
    /// Part of `volume_m3` the case's wear mechanism added to (or, negative, took from) the
    /// law's own wear, m³ (0 without a mechanism; see [`super::mechanism`]).
    #[serde(default)]
    pub mechanism_volume_m3: f64,
    /// Work of the contact's IMPACT damping ∫ P_damp dt, J (the impacts; what impact wear
    /// scales; 0 for tracks pushed without it).
    #[serde(default)]
    pub damping_work_j: f64,
}

impl WearTotals {
    fn empty(law: &WearLaw, histogram: PressureHistogram) -> Self {
        let cutoff = law.cutoff_pressure_pa();
        Self {
            volume_m3: 0.0,
            normal_slip_work_j: 0.0,
            work_above_cutoff_j: 0.0,
            contact_time_s: 0.0,
            start_time_s: f64::NAN,
            end_time_s: f64::NAN,
            samples: 0,
            zero_area_samples: 0,
            peak_pressure_pa: 0.0,
            cutoff_pressure_pa: cutoff.is_finite().then_some(cutoff),
            pressure_histogram: histogram,
            mechanism_volume_m3: 0.0,
            damping_work_j: 0.0,
        }
    }

    /// Share of the normal-load-times-slip work done above the cutoff (0 when there was no
    /// work).
    pub fn work_share_above_cutoff(&self) -> f64 {
        if self.normal_slip_work_j > 0.0 {
            self.work_above_cutoff_j / self.normal_slip_work_j
        } else {
            0.0
        }
    }

    /// Wall-clock span covered, s (0 before two samples).
    pub fn duration_s(&self) -> f64 {
        let d = self.end_time_s - self.start_time_s;
        if d.is_finite() {
            d
        } else {
            0.0
        }
    }

    /// Adds another track of the same contact: sums volumes, work, times and histograms.
    pub fn merge(&mut self, other: &WearTotals) -> Result<(), WearError> {
        if self.cutoff_pressure_pa != other.cutoff_pressure_pa {
            return Err(FieldError::new(
                "cutoff_pressure_pa",
                "tracks must use the same law to merge",
            )
            .into());
        }
        self.pressure_histogram.merge(&other.pressure_histogram)?;
        self.volume_m3 += other.volume_m3;
        self.mechanism_volume_m3 += other.mechanism_volume_m3;
        self.damping_work_j += other.damping_work_j;
        self.normal_slip_work_j += other.normal_slip_work_j;
        self.work_above_cutoff_j += other.work_above_cutoff_j;
        self.contact_time_s += other.contact_time_s;
        self.start_time_s = self.start_time_s.min(other.start_time_s);
        self.end_time_s = self.end_time_s.max(other.end_time_s);
        self.samples += other.samples;
        self.zero_area_samples += other.zero_area_samples;
        self.peak_pressure_pa = self.peak_pressure_pa.max(other.peak_pressure_pa);
        Ok(())
    }
}

#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Point {
    time_s: f64,
    rate_m3_s: f64,
    mechanism_rate_m3_s: f64,
    damping_power_w: f64,
    slip_speed_m_s: f64,
    power_w: f64,
    power_above_w: f64,
    pressure_pa: f64,
    in_contact: bool,
}

/// Integrates one contact track sample by sample (serializable: part of a run's checkpoint).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WearAccumulator {
    #[serde(with = "as_json_text")]
    law: WearLaw,
    quadrature: Quadrature,
    cutoff_pressure_pa: f64,
    prev: Option<Point>,
    totals: WearTotals,
    mechanism: Option<MechanismState>,
}

/// A wear mechanism carried by the accumulator, with what it needs between samples.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct MechanismState {
    #[serde(with = "as_json_text")]
    mechanism: WearMechanism,
    /// Yield strength of the softer body, Pa (severe wear's threshold).
    yield_strength_pa: f64,
    /// Slip distance of this track so far, m (trapezoid on the slip speed in contact).
    slip_distance_m: f64,
}

/// One sample of a contact track as the run hands it over.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrackLoad {
    /// Normal force N, N (>= 0; 0 = not touching).
    pub normal_force_n: f64,
    /// Slip speed, m/s (>= 0).
    pub slip_speed_m_s: f64,
    /// Contact area (thesis 2.5), m² (>= 0).
    pub area_m2: f64,
    /// Power dissipated by the contact's IMPACT damping, W (>= 0).
    pub damping_power_w: f64,
    /// Penetration rate of the deepest point (positive approaching), m/s.
    pub penetration_rate_m_s: f64,
}

/// A tagged enum (the law, the mechanism) as its JSON text inside a checkpoint: internally
/// tagged enums are read back only by self-describing formats, and the checkpoint's bincode
/// is not.
mod as_json_text {
    use serde::de::{DeserializeOwned, Error as _};
    use serde::ser::Error as _;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<T: Serialize, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&serde_json::to_string(value).map_err(S::Error::custom)?)
    }

    pub fn deserialize<'de, T: DeserializeOwned, D: Deserializer<'de>>(
        d: D,
    ) -> Result<T, D::Error> {
        let text = String::deserialize(d)?;
        serde_json::from_str(&text).map_err(D::Error::custom)
    }
}

impl WearAccumulator {
    /// New accumulator with the default pressure bins (1 kPa to 100 GPa, 10 per decade).
    pub fn new(law: WearLaw) -> Result<Self, WearError> {
        Self::with_histogram(law, PressureHistogram::default())
    }

    /// New accumulator with the given (empty) pressure histogram.
    pub fn with_histogram(law: WearLaw, histogram: PressureHistogram) -> Result<Self, WearError> {
        law.validate()?;
        Ok(Self {
            quadrature: law.quadrature(),
            cutoff_pressure_pa: law.cutoff_pressure_pa(),
            prev: None,
            totals: WearTotals::empty(&law, histogram),
            law,
            mechanism: None,
        })
    }

    /// New accumulator that adds `mechanism`'s wear to the law's (see [`super::mechanism`]);
    /// `yield_strength_pa` is the softer body's. The law must give K(sigma) (not the legacy
    /// appendix law, which feeds N).
    pub fn with_mechanism(
        law: WearLaw,
        mechanism: WearMechanism,
        yield_strength_pa: f64,
    ) -> Result<Self, WearError> {
        mechanism.validate()?;
        if !law.gives_k_of_sigma() {
            return Err(FieldError::new("mechanism", super::law::TERMS_NEED_K_OF_SIGMA).into());
        }
        FieldError::positive("yield_strength_pa", yield_strength_pa)?;
        let mut acc = Self::new(law)?;
        acc.mechanism = Some(MechanismState {
            mechanism,
            yield_strength_pa,
            slip_distance_m: 0.0,
        });
        Ok(acc)
    }

    /// Adds one sample: time (s), normal force N (N, >= 0; 0 = not touching), slip speed
    /// (m/s, >= 0) and contact area (m², >= 0). sigma = N/A; N > 0 with A = 0 counts as
    /// infinite pressure. Times must not decrease.
    #[inline]
    pub fn push(
        &mut self,
        time_s: f64,
        normal_force_n: f64,
        slip_speed_m_s: f64,
        area_m2: f64,
    ) -> Result<(), WearError> {
        self.push_track(
            time_s,
            &TrackLoad {
                normal_force_n,
                slip_speed_m_s,
                area_m2,
                ..TrackLoad::default()
            },
        )
    }

    /// [`WearAccumulator::push`] with the damping power and penetration rate a mechanism may
    /// need (impact wear scales the damping work).
    #[inline]
    pub fn push_track(&mut self, time_s: f64, track: &TrackLoad) -> Result<(), WearError> {
        let TrackLoad {
            normal_force_n,
            slip_speed_m_s,
            area_m2,
            damping_power_w,
            penetration_rate_m_s,
        } = *track;
        FieldError::non_negative("damping_power_w", damping_power_w)?;
        if !penetration_rate_m_s.is_finite() {
            return Err(FieldError::new("penetration_rate_m_s", "must be finite").into());
        }
        if !time_s.is_finite() {
            return Err(FieldError::new("time_s", "must be finite").into());
        }
        FieldError::non_negative("normal_force_n", normal_force_n)?;
        FieldError::non_negative("slip_speed_m_s", slip_speed_m_s)?;
        FieldError::non_negative("area_m2", area_m2)?;
        let in_contact = normal_force_n > 0.0;
        let pressure_pa = if !in_contact {
            0.0
        } else if area_m2 > 0.0 {
            normal_force_n / area_m2
        } else {
            self.totals.zero_area_samples += 1;
            f64::INFINITY
        };
        if pressure_pa.is_finite() {
            self.totals.peak_pressure_pa = self.totals.peak_pressure_pa.max(pressure_pa);
        }
        let power_w = normal_force_n * slip_speed_m_s;
        let law_rate = self
            .law
            .volume_rate_m3_s(normal_force_n, slip_speed_m_s, pressure_pa);
        let slip_in_contact = if in_contact { slip_speed_m_s } else { 0.0 };
        let rate_m3_s = match &mut self.mechanism {
            None => law_rate,
            Some(m) => {
                if let Some(p) = self.prev {
                    let dt = (time_s - p.time_s).max(0.0);
                    m.slip_distance_m += 0.5 * (p.slip_speed_m_s + slip_in_contact) * dt;
                }
                let sample = WearSample {
                    pressure_pa,
                    normal_force_n,
                    slip_speed_m_s,
                    slip_distance_m: m.slip_distance_m,
                    damping_power_w,
                    penetration_rate_m_s,
                    yield_strength_pa: m.yield_strength_pa,
                    points: &[],
                };
                volume_rate_with_terms_m3_s(&self.law, &[&m.mechanism], &sample)
            }
        };
        let point = Point {
            time_s,
            rate_m3_s,
            mechanism_rate_m3_s: rate_m3_s - law_rate,
            damping_power_w,
            slip_speed_m_s: slip_in_contact,
            power_w,
            power_above_w: if pressure_pa > self.cutoff_pressure_pa {
                power_w
            } else {
                0.0
            },
            pressure_pa,
            in_contact,
        };
        let t = &mut self.totals;
        match self.prev {
            None => {
                t.start_time_s = time_s;
                if self.quadrature == Quadrature::RightEndpointFromZero {
                    // CParse.C: tprev = 0 before the first row.
                    t.volume_m3 += point.rate_m3_s * time_s;
                }
            }
            Some(p) => {
                let dt = time_s - p.time_s;
                if dt < 0.0 {
                    return Err(FieldError::new("time_s", "must not decrease along a track").into());
                }
                t.volume_m3 += match self.quadrature {
                    Quadrature::Trapezoid => 0.5 * (p.rate_m3_s + point.rate_m3_s) * dt,
                    Quadrature::RightEndpointFromZero => point.rate_m3_s * dt,
                };
                t.normal_slip_work_j += 0.5 * (p.power_w + point.power_w) * dt;
                t.damping_work_j += 0.5 * (p.damping_power_w + point.damping_power_w) * dt;
                t.mechanism_volume_m3 += match self.quadrature {
                    Quadrature::Trapezoid => {
                        0.5 * (p.mechanism_rate_m3_s + point.mechanism_rate_m3_s) * dt
                    }
                    Quadrature::RightEndpointFromZero => point.mechanism_rate_m3_s * dt,
                };
                t.work_above_cutoff_j += 0.5 * (p.power_above_w + point.power_above_w) * dt;
                let half = 0.5 * dt;
                if p.in_contact {
                    t.contact_time_s += half;
                    t.pressure_histogram
                        .add(p.pressure_pa, half, p.power_w * half);
                }
                if point.in_contact {
                    t.contact_time_s += half;
                    t.pressure_histogram
                        .add(point.pressure_pa, half, point.power_w * half);
                }
            }
        }
        t.end_time_s = time_s;
        t.samples += 1;
        self.prev = Some(point);
        Ok(())
    }

    /// Wear volume so far, m³ (for wear-versus-time output while the run goes on).
    pub fn volume_m3(&self) -> f64 {
        self.totals.volume_m3
    }

    /// Totals so far.
    pub fn totals(&self) -> &WearTotals {
        &self.totals
    }

    /// Ends the track.
    pub fn finish(self) -> WearTotals {
        self.totals
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wear::law::{TABLE_4_3_C1, TABLE_4_3_C2, TABLE_4_3_C3};

    /// eq. 3.11 evaluated directly, unclamped (positive at the pressures used here).
    fn k_by_hand(sigma: f64) -> f64 {
        TABLE_4_3_C1 * (sigma.ln() / TABLE_4_3_C2).exp() + TABLE_4_3_C3
    }

    #[test]
    fn constant_force_speed_and_pressure() {
        // N = 100 N, v = 0.1 m/s, A = 1e-5 m² (sigma = 10 MPa) for 10 s in 1001 samples.
        let mut acc = WearAccumulator::new(WearLaw::table_4_3()).unwrap();
        for i in 0..=1000 {
            acc.push(i as f64 * 0.01, 100.0, 0.1, 1.0e-5).unwrap();
        }
        let t = acc.finish();
        let expected = k_by_hand(1.0e7) * 100.0 * 0.1 * 10.0;
        assert!((t.volume_m3 - expected).abs() / expected < 1e-12);
        assert!((t.normal_slip_work_j - 100.0).abs() < 1e-9);
        assert!((t.contact_time_s - 10.0).abs() < 1e-9);
        assert_eq!(t.work_above_cutoff_j, 0.0);
        assert_eq!(t.peak_pressure_pa, 1.0e7);
        // Histogram conservation: all time and work sit in the 10 MPa bin.
        let h = &t.pressure_histogram;
        assert!((h.total_time_s() - 10.0).abs() < 1e-9);
        assert!((h.total_work_j() - 100.0).abs() < 1e-9);
        assert_eq!(h.underflow_time_s + h.overflow_time_s, 0.0);
    }

    #[test]
    fn pressure_crossing_the_cutoff_mid_track() {
        // N = 100 N, v = 0.1 m/s (10 W); sigma = 100 MPa at t = 0, 1 s and 1000 MPa (> 870 MPa
        // cutoff) at t = 2, 3 s. Trapezoid: above-cutoff work = 0 + 5 + 10 = 15 J of 30 J;
        // volume = K(1e8)*10 W * (1 + 0.5 + 0) s.
        let mut acc = WearAccumulator::new(WearLaw::table_4_3()).unwrap();
        for (t, a) in [(0.0, 1e-6), (1.0, 1e-6), (2.0, 1e-7), (3.0, 1e-7)] {
            acc.push(t, 100.0, 0.1, a).unwrap();
        }
        let t = acc.finish();
        assert!((t.normal_slip_work_j - 30.0).abs() < 1e-12);
        assert!((t.work_above_cutoff_j - 15.0).abs() < 1e-12);
        assert!((t.work_share_above_cutoff() - 0.5).abs() < 1e-12);
        let expected = k_by_hand(1.0e8) * 10.0 * 1.5;
        assert!((t.volume_m3 - expected).abs() / expected < 1e-12);
        assert_eq!(t.cutoff_pressure_pa, Some(870.0e6));
    }

    #[test]
    fn two_simultaneous_tracks_sum() {
        let law = WearLaw::Archard {
            coefficient_m2_per_n: 2.0e-14,
        };
        let mut a = WearAccumulator::new(law).unwrap();
        let mut b = WearAccumulator::new(law).unwrap();
        for i in 0..=10 {
            let time = i as f64 * 0.1;
            a.push(time, 10.0, 0.5, 1e-6).unwrap(); // 5 W for 1 s
            b.push(time, 40.0, 0.25, 1e-5).unwrap(); // 10 W for 1 s
        }
        let mut contact = a.finish();
        contact.merge(&b.finish()).unwrap();
        assert!((contact.volume_m3 - 2.0e-14 * 15.0).abs() < 1e-27);
        assert!((contact.normal_slip_work_j - 15.0).abs() < 1e-12);
        assert!((contact.contact_time_s - 2.0).abs() < 1e-12);
        assert_eq!(contact.samples, 22);
        assert!((contact.pressure_histogram.total_work_j() - 15.0).abs() < 1e-12);
    }

    #[test]
    fn trapezoid_is_exact_for_a_linear_force_ramp() {
        // Archard with N rising 0 -> 100 N over 2 s at 1 m/s: W = K * 100 J exactly.
        let k = 1.0e-14;
        let mut acc = WearAccumulator::new(WearLaw::Archard {
            coefficient_m2_per_n: k,
        })
        .unwrap();
        for i in 0..=7 {
            let time = 2.0 * i as f64 / 7.0;
            acc.push(time, 50.0 * time, 1.0, 1e-6).unwrap();
        }
        let t = acc.finish();
        assert!((t.volume_m3 - k * 100.0).abs() < 1e-26);
        // The first sample has N = 0: half of the first interval is out of contact.
        assert!((t.contact_time_s - (2.0 - 0.5 * 2.0 / 7.0)).abs() < 1e-12);
    }

    #[test]
    fn legacy_right_endpoint_from_zero() {
        // C1 = 1e-3, C2 = 2, C3 = 5, unit output: rate(N, v_mm) = 1e-3 (1e-3 sqrt N + 5e-3) N v.
        // Rows t = 1 s (N 16, v 2 mm/s) and t = 3 s (N 4, v 1 mm/s):
        // 1e-3*9e-3*16*2*(1-0) + 1e-3*7e-3*4*1*(3-1) = 2.88e-4 + 5.6e-5 = 3.44e-4.
        let law = WearLaw::LegacyAppendix {
            c1: 1e-3,
            c2: 2.0,
            c3: 5.0,
            speed_unit_m_s: 1e-3,
            output_unit_m3: 1.0,
        };
        let mut acc = WearAccumulator::new(law).unwrap();
        acc.push(1.0, 16.0, 2.0e-3, 0.0).unwrap();
        acc.push(3.0, 4.0, 1.0e-3, 0.0).unwrap();
        assert!(
            (acc.volume_m3() - 3.44e-4).abs() < 1e-15,
            "{}",
            acc.volume_m3()
        );
    }

    #[test]
    fn bad_samples_name_the_field() {
        let mut acc = WearAccumulator::new(WearLaw::table_4_3()).unwrap();
        assert_eq!(
            acc.push(0.0, f64::NAN, 0.0, 1.0),
            Err(FieldError::new("normal_force_n", "must be a finite number >= 0").into())
        );
        acc.push(1.0, 1.0, 0.0, 1.0).unwrap();
        assert_eq!(
            acc.push(0.5, 1.0, 0.0, 1.0),
            Err(FieldError::new("time_s", "must not decrease along a track").into())
        );
    }

    #[test]
    fn zero_area_counts_as_above_cutoff() {
        let mut acc = WearAccumulator::new(WearLaw::table_4_3()).unwrap();
        acc.push(0.0, 10.0, 1.0, 0.0).unwrap();
        acc.push(1.0, 10.0, 1.0, 0.0).unwrap();
        let t = acc.finish();
        assert_eq!(t.volume_m3, 0.0);
        assert_eq!(t.work_share_above_cutoff(), 1.0);
        assert_eq!(t.zero_area_samples, 2);
    }

    #[test]
    fn impact_wear_mechanism_adds_k_e_times_damping_work() {
        use crate::wear::mechanism::{ImpactWear, WearMechanism};
        // N = 10 N on 1 mm² (10 MPa), 0.1 m/s slip, 2 W of damping for 3 s.
        let law = WearLaw::table_4_3();
        let k_e = 2.5e-13;
        let mechanism = WearMechanism::ImpactWear(ImpactWear {
            k_energy_m3_per_j: k_e,
            min_normal_speed_m_s: 0.0,
        });
        let mut plain = WearAccumulator::new(law).unwrap();
        let mut with = WearAccumulator::with_mechanism(law, mechanism, 435.0e6).unwrap();
        for i in 0..=300 {
            let t = i as f64 * 0.01;
            let track = TrackLoad {
                normal_force_n: 10.0,
                slip_speed_m_s: 0.1,
                area_m2: 1.0e-6,
                damping_power_w: 2.0,
                penetration_rate_m_s: 0.01,
            };
            plain.push_track(t, &track).unwrap();
            with.push_track(t, &track).unwrap();
        }
        let (plain, with) = (plain.finish(), with.finish());
        // Sliding part: K(10 MPa) x 10 N x 0.1 m/s x 3 s.
        let sliding = k_by_hand(1.0e7) * 10.0 * 0.1 * 3.0;
        assert!((plain.volume_m3 - sliding).abs() / sliding < 1e-9);
        // Impact part: k_E x 2 W x 3 s = 1.5e-12 m³, all of it the mechanism's.
        let impact = k_e * 2.0 * 3.0;
        assert!((with.mechanism_volume_m3 - impact).abs() / impact < 1e-9);
        assert!((with.volume_m3 - (sliding + impact)).abs() / (sliding + impact) < 1e-9);
        assert!((with.damping_work_j - 6.0).abs() < 1e-9);
        assert_eq!(plain.mechanism_volume_m3, 0.0);
    }

    #[test]
    fn a_mechanism_needs_a_k_sigma_law() {
        use crate::wear::mechanism::{ImpactWear, WearMechanism};
        let mechanism = WearMechanism::ImpactWear(ImpactWear {
            k_energy_m3_per_j: 1e-13,
            min_normal_speed_m_s: 0.0,
        });
        let err = WearAccumulator::with_mechanism(WearLaw::legacy_table_4_3(), mechanism, 435e6)
            .unwrap_err();
        assert!(err.to_string().contains("mechanism"), "{err}");
    }
}
