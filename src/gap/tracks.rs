//! Contact tracks kept on the integrator's own time grid, and the wear integral over them with
//! optional wear-law terms.
//!
//! A run's wear (`models::run`) integrates `K(sigma) N v_slip` per track with the trapezoid rule
//! over every accepted step, closing a vanished track with a zero sample. [`TrackRecord`] keeps
//! exactly those steps (time and, per active track, N, v_slip, A), so that
//! [`TrackRecord::wear_volumes_m3`] with no terms reproduces the run's wear, and wear-law
//! effects ([`WearTerm`]) are evaluated on the same tracks without re-simulating.

use super::GapError;
use crate::physics::simulate::StepView;
use crate::wear::law::WearLaw;
use std::collections::BTreeMap;

/// One active track at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackPoint {
    /// Contact index in the model.
    pub contact: u32,
    /// Track index within the contact.
    pub track: u32,
    /// Normal force, N.
    pub normal_force_n: f64,
    /// Slip speed, m/s.
    pub slip_speed_m_s: f64,
    /// Contact area, m² (thesis 2.5).
    pub area_m2: f64,
}

/// What a wear-law term sees at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WearSample {
    /// Mean contact pressure N/A, Pa (infinite for N > 0 on zero area).
    pub pressure_pa: f64,
    /// Normal force, N.
    pub normal_force_n: f64,
    /// Slip speed, m/s.
    pub slip_speed_m_s: f64,
    /// Slip distance the specimen has accumulated by this sample, m (see
    /// [`TrackRecord::slip_distance_m`]).
    pub slip_distance_m: f64,
}

/// A wear-law term: maps the coefficient K (m²/N) at a sample to the effective one. Terms are
/// applied in order. A term at zero magnitude must return `k` unchanged (bit for bit).
pub trait WearTerm {
    /// Effective K, m²/N, given the K so far and the sample.
    fn coefficient_m2_per_n(&self, k: f64, law: &WearLaw, sample: &WearSample) -> f64;
}

/// Where the represented test time sits relative to the simulated window: the window of
/// `window_s` stands for `represented_s` of test, which began after `slip_start_m` of slip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipHistory {
    /// Slip distance accumulated before the window's segment, m.
    pub slip_start_m: f64,
    /// Test time the window stands for divided by the window length (>= 1 for a long test).
    pub time_scale: f64,
}

impl Default for SlipHistory {
    fn default() -> Self {
        Self {
            slip_start_m: 0.0,
            time_scale: 1.0,
        }
    }
}

/// Active tracks at every accepted step of an excitation window.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrackRecord {
    /// (time s, index of the step's first point in `points`).
    steps: Vec<(f64, usize)>,
    points: Vec<TrackPoint>,
    contacts: usize,
}

impl TrackRecord {
    /// Empty record of a model with `contacts` contacts.
    pub fn new(contacts: usize) -> Self {
        Self {
            contacts,
            ..Self::default()
        }
    }

    /// Appends one step (times must not decrease).
    pub fn push_step(&mut self, time_s: f64, points: impl IntoIterator<Item = TrackPoint>) {
        self.steps.push((time_s, self.points.len()));
        self.points.extend(points);
    }

    /// Appends a step handed out by the run loop (`models::run::run_model_observed`).
    pub fn push_view(&mut self, v: &StepView) {
        self.push_step(
            v.t,
            v.tracks.iter().map(|t| TrackPoint {
                contact: t.contact,
                track: t.track,
                normal_force_n: t.normal_force,
                slip_speed_m_s: t.slip_speed,
                area_m2: t.area,
            }),
        );
    }

    /// Number of steps.
    pub fn steps(&self) -> usize {
        self.steps.len()
    }

    /// Time span covered, s.
    pub fn window_s(&self) -> f64 {
        match (self.steps.first(), self.steps.last()) {
            (Some(a), Some(b)) => b.0 - a.0,
            _ => 0.0,
        }
    }

    fn step_points(&self, i: usize) -> &[TrackPoint] {
        let start = self.steps[i].1;
        let end = self.steps.get(i + 1).map_or(self.points.len(), |s| s.1);
        &self.points[start..end]
    }

    /// Slip distance over the window, m: per track `∫ v_slip dt` while N > 0 (trapezoid, a
    /// vanished track counting as zero), summed over tracks: the distance slid on each of the
    /// surfaces in contact, added up.
    pub fn slip_distance_m(&self) -> f64 {
        self.integrate(|_, p| slip_speed_in_contact(p), &mut |_, _, _| {})
    }

    /// Friction work `∫ N v_slip dt` per bin, J: each sample carries its trapezoid weight (half
    /// the steps on either side) into the bin `bin(pressure_pa, slip_speed_m_s)` chooses (None:
    /// not counted). For where-in-the-regime breakdowns (pressure and slip-speed bands); the
    /// bins' sum differs from the track-wise trapezoid only where tracks appear or vanish.
    pub fn work_by_bin(&self, bins: usize, bin: impl Fn(f64, f64) -> Option<usize>) -> Vec<f64> {
        let mut out = vec![0.0; bins];
        let n = self.steps.len();
        for i in 0..n {
            let t = self.steps[i].0;
            let before = if i > 0 { t - self.steps[i - 1].0 } else { 0.0 };
            let after = if i + 1 < n {
                self.steps[i + 1].0 - t
            } else {
                0.0
            };
            let w = 0.5 * (before + after);
            for p in self.step_points(i) {
                if p.normal_force_n <= 0.0 {
                    continue;
                }
                let pressure = if p.area_m2 > 0.0 {
                    p.normal_force_n / p.area_m2
                } else {
                    f64::INFINITY
                };
                if let Some(b) = bin(pressure, p.slip_speed_m_s).filter(|b| *b < bins) {
                    out[b] += p.normal_force_n * p.slip_speed_m_s * w;
                }
            }
        }
        out
    }

    /// Trapezoid integral of `value(step, point)` per track over the steps, summed; a track
    /// absent from a step counts as zero there (as the run closes a vanished track). `each`
    /// sees every interval's contribution as (step at the interval's end, contact, amount).
    fn integrate(
        &self,
        mut value: impl FnMut(usize, &TrackPoint) -> f64,
        each: &mut dyn FnMut(usize, u32, f64),
    ) -> f64 {
        let mut prev: BTreeMap<(u32, u32), f64> = BTreeMap::new();
        let mut total = 0.0;
        let mut t_prev = f64::NAN;
        let mut seen: Vec<(u32, u32)> = Vec::new();
        for i in 0..self.steps.len() {
            let t = self.steps[i].0;
            let dt = t - t_prev;
            seen.clear();
            for p in self.step_points(i) {
                let key = (p.contact, p.track);
                let v = value(i, p);
                if let Some(vp) = prev.get(&key) {
                    let a = 0.5 * (vp + v) * dt;
                    total += a;
                    each(i, p.contact, a);
                }
                prev.insert(key, v);
                seen.push(key);
            }
            for (key, vp) in prev.iter_mut() {
                if !seen.contains(key) {
                    let a = 0.5 * *vp * dt;
                    total += a;
                    each(i, key.0, a);
                    *vp = 0.0;
                }
            }
            t_prev = t;
        }
        total
    }

    /// Wear volume per contact over the window, m³: `∫ K_eff N v_slip dt` per track (trapezoid
    /// on the step grid, as the run integrates), with `K_eff` the law's K(sigma) passed through
    /// `terms` in order. With no terms this is the run's own wear. The slip distance a term
    /// sees is `history.slip_start_m` plus `history.time_scale` times the window's slip so far.
    pub fn wear_volumes_m3(
        &self,
        law: &WearLaw,
        terms: &[&dyn WearTerm],
        history: SlipHistory,
    ) -> Result<Vec<f64>, GapError> {
        if matches!(law, WearLaw::LegacyAppendix { .. }) && !terms.is_empty() {
            return Err(GapError::field(
                "wear.law",
                "wear-law effects need a K(sigma) law (archard or modified); the legacy \
                 appendix law feeds N, not sigma",
            ));
        }
        // Slip accumulated by each step, for terms that depend on it.
        let mut slip_at = vec![0.0; self.steps.len()];
        if !terms.is_empty() {
            self.integrate(|_, p| slip_speed_in_contact(p), &mut |i, _, a| {
                slip_at[i] += a
            });
            let mut s = 0.0;
            for x in slip_at.iter_mut() {
                s += *x;
                *x = history.slip_start_m + history.time_scale * s;
            }
        }
        let rate = |i: usize, p: &TrackPoint| -> f64 {
            let n = p.normal_force_n;
            let v = p.slip_speed_m_s;
            let pressure_pa = if n <= 0.0 {
                0.0
            } else if p.area_m2 > 0.0 {
                n / p.area_m2
            } else {
                f64::INFINITY
            };
            if terms.is_empty() {
                return law.volume_rate_m3_s(n, v, pressure_pa);
            }
            let mut k = law.coefficient_m2_per_n(pressure_pa).unwrap_or(0.0);
            let sample = WearSample {
                pressure_pa,
                normal_force_n: n,
                slip_speed_m_s: v,
                slip_distance_m: slip_at[i],
            };
            for term in terms {
                k = term.coefficient_m2_per_n(k, law, &sample);
            }
            k * n * v
        };
        let mut volumes = vec![0.0; self.contacts];
        let mut out_of_range = None;
        self.integrate(rate, &mut |_, c, a| match volumes.get_mut(c as usize) {
            Some(slot) => *slot += a,
            None => out_of_range = Some(c),
        });
        if let Some(c) = out_of_range {
            return Err(GapError::field(
                "tracks",
                format!(
                    "contact {c} is not one of the model's {} contacts",
                    self.contacts
                ),
            ));
        }
        Ok(volumes)
    }
}

fn slip_speed_in_contact(p: &TrackPoint) -> f64 {
    if p.normal_force_n > 0.0 {
        p.slip_speed_m_s
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wear::integrate::WearAccumulator;

    fn point(track: u32, n: f64, v: f64, a: f64) -> TrackPoint {
        TrackPoint {
            contact: 0,
            track,
            normal_force_n: n,
            slip_speed_m_s: v,
            area_m2: a,
        }
    }

    /// A track that vanishes for two steps and returns: the record's wear equals the run's
    /// accumulator fed the same samples with zero samples while the track is absent.
    #[test]
    fn no_terms_equals_the_runs_accumulator() {
        let law = WearLaw::table_4_3();
        let mut rec = TrackRecord::new(1);
        let mut acc = WearAccumulator::new(law).unwrap();
        let rows = [
            (0.0, Some((10.0, 0.1, 1e-6))),
            (0.001, Some((12.0, 0.2, 2e-6))),
            (0.003, None),
            (0.004, None),
            (0.006, Some((8.0, 0.05, 1e-6))),
            (0.007, Some((9.0, 0.0, 1e-6))),
        ];
        for (t, row) in rows {
            match row {
                Some((n, v, a)) => {
                    rec.push_step(t, [point(0, n, v, a)]);
                    acc.push(t, n, v, a).unwrap();
                }
                None => {
                    rec.push_step(t, []);
                    acc.push(t, 0.0, 0.0, 0.0).unwrap();
                }
            }
        }
        let v = rec
            .wear_volumes_m3(&law, &[], SlipHistory::default())
            .unwrap();
        let expected = acc.finish().volume_m3;
        assert!(expected > 0.0);
        assert!(
            (v[0] - expected).abs() <= 1e-15 * expected,
            "{} vs {expected}",
            v[0]
        );
        // Slip distance: 0.5*(0.1+0.2)*0.001 + 0.5*0.2*0.002 + 0 + 0.5*0.05*0.002... per rule.
        let s = rec.slip_distance_m();
        let by_hand =
            0.5 * (0.1 + 0.2) * 0.001 + 0.5 * 0.2 * 0.002 + 0.5 * 0.05 * 0.002 + 0.5 * 0.05 * 0.001;
        assert!((s - by_hand).abs() < 1e-15, "{s} vs {by_hand}");
    }
}
