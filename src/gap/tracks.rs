//! Contact tracks kept on the integrator's own time grid, and the wear integral over them with
//! optional wear-law terms.
//!
//! A run's wear (`models::run`) integrates `K(sigma) N v_slip` per track with the trapezoid rule
//! over every accepted step, closing a vanished track with a zero sample. [`TrackRecord`] keeps
//! exactly those steps (time and, per active track, N, v_slip, A, the damping and friction
//! powers, and the distribution of the contact points' own pressures), so that
//! [`TrackRecord::wear_volumes_m3`] with no terms reproduces the run's wear, and wear-law
//! effects ([`WearTerm`]) are evaluated on the same tracks without re-simulating.
//!

use super::point_pressure::push_pressure_bins;
pub use super::point_pressure::{PressureBin, PRESSURE_BINS_PER_DECADE};
pub use super::track_point::TrackPoint;
use super::GapError;
use crate::physics::contact::PointLoad;
use crate::physics::simulate::StepView;
use crate::physics::system::Workspace;
use crate::wear::law::WearLaw;
use std::collections::BTreeMap;

use crate::wear::mechanism::volume_rate_with_terms_m3_s;
pub use crate::wear::mechanism::{WearSample, WearTerm};

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
    bins: Vec<PressureBin>,
    /// Power the drive delivers at each step, W (the steps' order; empty for hand-made steps).
    drive_w: Vec<f64>,
    /// Mechanical energy (kinetic, gravitational, elastic) at the first and the latest step
    /// recorded with points, J.
    energy_j: Option<(f64, f64)>,
    contacts: usize,
    yield_strength_pa: f64,
}

impl TrackRecord {
    /// Empty record of a model with `contacts` contacts.
    pub fn new(contacts: usize) -> Self {
        Self {
            contacts,
            yield_strength_pa: f64::INFINITY,
            ..Self::default()
        }
    }

    /// The contact material's yield strength, Pa, for terms of the plastic regime (default:
    /// infinite, no point above it).
    pub fn with_yield_strength(mut self, yield_strength_pa: f64) -> Self {
        self.yield_strength_pa = yield_strength_pa;
        self
    }

    /// Number of contacts of the model.
    pub fn contacts(&self) -> usize {
        self.contacts
    }

    /// Appends one step (times must not decrease).
    pub fn push_step(&mut self, time_s: f64, points: impl IntoIterator<Item = TrackPoint>) {
        self.steps.push((time_s, self.points.len()));
        self.points.extend(points);
    }

    /// Appends one step whose tracks carry their point-pressure bins (hand-made records;
    /// a run's come from [`TrackRecord::push_view_with_points`]).
    pub fn push_step_with_bins<'a>(
        &mut self,
        time_s: f64,
        tracks: impl IntoIterator<Item = (TrackPoint, &'a [PressureBin])>,
    ) {
        self.steps.push((time_s, self.points.len()));
        for (mut p, bins) in tracks {
            p.first_bin = self.bins.len() as u32;
            p.bin_count = bins.len() as u32;
            self.bins.extend_from_slice(bins);
            self.points.push(p);
        }
    }

    /// Appends a step handed out by the run loop (`models::run::run_model_observed`), without
    /// the point-pressure distribution.
    pub fn push_view(&mut self, v: &StepView) {
        self.drive_w.push(v.power.drive + v.power.applied);
        self.push_step(
            v.t,
            v.tracks.iter().map(|t| TrackPoint {
                contact: t.contact,
                track: t.track,
                normal_force_n: t.normal_force,
                slip_speed_m_s: t.slip_speed,
                area_m2: t.area,
                damping_power_w: t.damping_power,
                friction_power_w: t.friction_power,
                penetration_rate_m_s: t.penetration_rate,
                first_bin: 0,
                bin_count: 0,
            }),
        );
    }

    /// [`TrackRecord::push_view`] with each track's point-pressure distribution: the contact
    /// points are evaluated once more at the step's state (`ws` a workspace of the view's
    /// system, reused between steps; `scratch` reused too).
    pub fn push_view_with_points(
        &mut self,
        v: &StepView,
        ws: &mut Workspace,
        scratch: &mut Vec<PointLoad>,
    ) {
        scratch.clear();
        let motion = v.system.motion_energy(v.t, v.state, ws);
        let e = motion.kinetic + motion.gravitational + v.power.elastic_energy;
        self.energy_j = Some((self.energy_j.map_or(e, |(first, _)| first), e));
        v.system
            .tracks_with_points(v.t, v.state, ws, &mut |_| {}, &mut |p| scratch.push(*p));
        let start = self.points.len();
        self.push_view(v);
        for i in start..self.points.len() {
            let tp = self.points[i];
            let mine = scratch
                .iter()
                .filter(|p| p.contact == tp.contact && p.track == tp.track);
            let first = self.bins.len();
            push_pressure_bins(&mut self.bins, &tp, mine);
            self.points[i].first_bin = first as u32;
            self.points[i].bin_count = (self.bins.len() - first) as u32;
        }
    }

    /// The point-pressure bins of `p` (a point of this record).
    pub fn bins_of(&self, p: &TrackPoint) -> &[PressureBin] {
        let a = p.first_bin as usize;
        self.bins.get(a..a + p.bin_count as usize).unwrap_or(&[])
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
        if !law.gives_k_of_sigma() && !terms.is_empty() {
            return Err(GapError::field(
                "wear.law",
                crate::wear::law::TERMS_NEED_K_OF_SIGMA,
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
            let sample = WearSample {
                pressure_pa: lumped_pressure_pa(p),
                normal_force_n: p.normal_force_n,
                slip_speed_m_s: p.slip_speed_m_s,
                slip_distance_m: slip_at[i],
                damping_power_w: p.damping_power_w,
                penetration_rate_m_s: p.penetration_rate_m_s,
                yield_strength_pa: self.yield_strength_pa,
                points: self.bins_of(p),
            };
            volume_rate_with_terms_m3_s(law, terms, &sample)
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

    /// Work the drive (and applied loads) delivered over the window, J: trapezoid over the
    /// steps of the power at each (0 for a record without it).
    pub fn drive_work_j(&self) -> f64 {
        if self.drive_w.len() != self.steps.len() {
            return 0.0;
        }
        self.steps
            .windows(2)
            .zip(self.drive_w.windows(2))
            .map(|(t, p)| 0.5 * (p[0] + p[1]) * (t[1].0 - t[0].0))
            .sum()
    }

    /// Change of the mechanical energy over the window, J (0 when not recorded).
    pub fn energy_change_j(&self) -> f64 {
        self.energy_j.map_or(0.0, |(first, last)| last - first)
    }

    /// Whether the contact points' pressures were recorded ([`TrackRecord::push_view_with_points`]).
    pub fn has_point_pressures(&self) -> bool {
        !self.bins.is_empty()
    }

    /// Per contact, over the window: the work by kind and what each wear mechanism is driven
    /// by (the energy budget of the diagnosis' "where"). Trapezoid per track, as the wear.
    pub fn work_by_contact(&self, law: &WearLaw) -> Vec<ContactWork> {
        let mut out = vec![ContactWork::default(); self.contacts];
        let k_of = |pressure: f64| law.coefficient_m2_per_n(pressure).unwrap_or(0.0);
        let yield_pa = self.yield_strength_pa;
        let mut add = |value: &dyn Fn(&TrackPoint) -> f64,
                       slot: fn(&mut ContactWork) -> &mut f64| {
            self.integrate(
                |_, p| {
                    if p.normal_force_n > 0.0 {
                        value(p)
                    } else {
                        0.0
                    }
                },
                &mut |_, c, a| {
                    if let Some(w) = out.get_mut(c as usize) {
                        *slot(w) += a;
                    }
                },
            );
        };
        add(&|p| p.friction_power_w, |w| &mut w.friction_j);
        add(&|p| p.damping_power_w, |w| &mut w.damping_j);
        add(&|p| p.normal_force_n * p.slip_speed_m_s, |w| {
            &mut w.sliding_n_m
        });
        add(
            &|p| {
                let bins = self.bins_of(p);
                if bins.is_empty() {
                    if lumped_pressure_pa(p) > yield_pa {
                        p.normal_force_n * p.slip_speed_m_s
                    } else {
                        0.0
                    }
                } else {
                    bins.iter()
                        .filter(|b| b.pressure_pa > yield_pa)
                        .map(|b| b.work_rate_w)
                        .sum()
                }
            },
            |w| &mut w.sliding_above_yield_n_m,
        );
        add(
            &|p| k_of(lumped_pressure_pa(p)) * p.normal_force_n * p.slip_speed_m_s,
            |w| &mut w.lumped_archard_m3,
        );
        add(
            &|p| {
                let bins = self.bins_of(p);
                if bins.is_empty() {
                    k_of(lumped_pressure_pa(p)) * p.normal_force_n * p.slip_speed_m_s
                } else {
                    bins.iter()
                        .map(|b| k_of(b.pressure_pa) * b.work_rate_w)
                        .sum()
                }
            },
            |w| &mut w.local_archard_m3,
        );
        out
    }
}

/// One contact's work over a window, by kind, and the integrals the wear mechanisms scale.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ContactWork {
    /// Work of friction `∫ Σ μ_i N_i |v_i| dt`, J.
    pub friction_j: f64,
    /// Work of the IMPACT damping (normal, the impacts) `∫ P_damp dt`, J.
    pub damping_j: f64,
    /// Sliding integral `∫ N v_slip dt` (Archard's load times distance), N·m.
    pub sliding_n_m: f64,
    /// The part of it at contact points whose local pressure exceeds the yield strength, N·m.
    pub sliding_above_yield_n_m: f64,
    /// Wear volume of the case's law at the lumped pressure `N/A` (the run's own wear), m³.
    pub lumped_archard_m3: f64,
    /// Wear volume of the same law at each contact point's own pressure, m³ (equal to the
    /// lumped one when the points were not recorded).
    pub local_archard_m3: f64,
}

impl ContactWork {
    /// Adds `scale` times `other` (another window or increment of the same contact).
    pub fn add_scaled(&mut self, other: &ContactWork, scale: f64) {
        self.friction_j += scale * other.friction_j;
        self.damping_j += scale * other.damping_j;
        self.sliding_n_m += scale * other.sliding_n_m;
        self.sliding_above_yield_n_m += scale * other.sliding_above_yield_n_m;
        self.lumped_archard_m3 += scale * other.lumped_archard_m3;
        self.local_archard_m3 += scale * other.local_archard_m3;
    }
}

/// A track's lumped pressure `N/A`, Pa (0 without load, infinite on zero area).
fn lumped_pressure_pa(p: &TrackPoint) -> f64 {
    if p.normal_force_n <= 0.0 {
        0.0
    } else if p.area_m2 > 0.0 {
        p.normal_force_n / p.area_m2
    } else {
        f64::INFINITY
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
            damping_power_w: 0.0,
            friction_power_w: 0.0,
            penetration_rate_m_s: 0.0,
            first_bin: 0,
            bin_count: 0,
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
