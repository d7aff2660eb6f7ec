//! The report's numbers over its two windows: totals (wear mass, friction work) over the
//! excited window, rates and means over the rate window ([`super::RateWindow`]), per contact
//! and per body, from what the run's observer accumulated.

use super::rate_window::{difference, Cumulative};
use super::{BodyReport, BuiltModel, ContactReport, RateWindow, RunOptions, TrackAcc};
use crate::units::{MG_PER_KG, S_PER_H};
use crate::wear::integrate::{WearAccumulator, WearTotals};
use crate::wear::WearError;

/// What the observer accumulated over the run, per contact.
pub(super) struct Totals<'a> {
    /// Wear accumulators per track (taken as they are finished).
    pub accs: &'a mut [Vec<Option<TrackAcc>>],
    /// ∫ N dt since the excitation's start, N·s.
    pub normal_int: &'a [f64],
    /// ∫ N |v_slip| dt since the excitation's start, J.
    pub normal_slip_int: &'a [f64],
    /// Largest normal force seen, N.
    pub peak: &'a [f64],
    /// The energy account's friction work over the excited window, J.
    pub friction_window: &'a [f64],
    /// The energy account's friction work since t = 0, J.
    pub friction_now: &'a [f64],
    /// The cumulative quantities at the rate window's start, if the run passed it.
    pub rate_base: Option<Cumulative>,
}

/// The report's per-contact and per-body numbers and its means.
pub(super) struct WindowReports {
    /// Per contact, in the model's order.
    pub contacts: Vec<ContactReport>,
    /// Per body, in the model's order.
    pub bodies: Vec<BodyReport>,
    /// Length of the excited window, s.
    pub window_s: f64,
    /// Where the rates were taken.
    pub rate_window: RateWindow,
    /// Mean total normal force over the rate window, N.
    pub mean_normal_force_n: f64,
    /// Mean total N |v_slip| over the rate window, W.
    pub mean_normal_slip_power_w: f64,
    /// Mean total friction power over the rate window, W.
    pub mean_friction_power_w: f64,
}

/// Totals over the excited window and rates over the rate window: from the ramp-in's end when
/// the run passed it, else over the whole excited window.
pub(super) fn window_reports(
    model: &BuiltModel,
    options: &RunOptions,
    t: Totals<'_>,
) -> Result<WindowReports, WearError> {
    let sys = &model.system;
    let window = (model.end_time_s - model.excitation_start_s).max(f64::MIN_POSITIVE);
    // Rates over the rate window: from the ramp-in's end when the run passed it, else over the
    // whole excited window (`rate_window`).
    let rate_base = t.rate_base.filter(|b| model.end_time_s - b.t_s > 0.0);
    let rate_window = match &rate_base {
        Some(b) => RateWindow {
            start_s: b.t_s,
            length_s: model.end_time_s - b.t_s,
            after_ramp: true,
        },
        None => RateWindow {
            start_s: model.excitation_start_s,
            length_s: window,
            after_ramp: model.rate_start_s <= model.excitation_start_s,
        },
    };
    let rate_span = rate_window.length_s.max(f64::MIN_POSITIVE);
    // A cumulative quantity over the rate window: now less its base, or its value over the
    // whole excited window when there is no base.
    let over_rate_window =
        |now: &[f64], base: fn(&Cumulative) -> &Vec<f64>, whole: &[f64]| -> Vec<f64> {
            match &rate_base {
                Some(b) => difference(now, base(b)),
                None => whole.to_vec(),
            }
        };
    let normal_rate_window = over_rate_window(t.normal_int, |b| &b.normal, t.normal_int);
    let normal_slip_rate_window =
        over_rate_window(t.normal_slip_int, |b| &b.normal_slip, t.normal_slip_int);
    let friction_rate_window = over_rate_window(t.friction_now, |b| &b.friction, t.friction_window);
    let mut body_rate = vec![0.0; sys.bodies.len()];
    let mut contacts = Vec::with_capacity(sys.contacts.len());
    let mut body_mass = vec![0.0; sys.bodies.len()];
    for (ci, c) in sys.contacts.iter().enumerate() {
        let mut total: Option<WearTotals> = None;
        for a in t.accs[ci].iter_mut().filter_map(|a| a.take()) {
            let t = a.acc.finish();
            match &mut total {
                Some(tot) => tot.merge(&t)?,
                None => total = Some(t),
            }
        }
        let total = match total {
            Some(t) => t,
            None => WearAccumulator::new(options.wear_law)?.finish(),
        };
        let (ma, mb) = &model.contact_materials[ci];
        let (wa, wb) = options.volume_split.split(total.volume_m3, ma, mb)?;
        body_mass[c.body_a] += wa.mass_kg;
        body_mass[c.body_b] += wb.mass_kg;
        let rate_volume = match &rate_base {
            Some(b) => (total.volume_m3 - b.volume[ci]).max(0.0),
            None => total.volume_m3,
        };
        let (ra, rb) = options.volume_split.split(rate_volume, ma, mb)?;
        let per_h = S_PER_H / rate_span;
        body_rate[c.body_a] += ra.mass_kg * MG_PER_KG * per_h;
        body_rate[c.body_b] += rb.mass_kg * MG_PER_KG * per_h;
        contacts.push(ContactReport {
            name: c.name.clone(),
            body_a: sys.bodies[c.body_a].name.clone(),
            body_b: sys.bodies[c.body_b].name.clone(),
            work_share_above_cutoff: total.work_share_above_cutoff(),
            mass_a_mg: wa.mass_kg * MG_PER_KG,
            mass_b_mg: wb.mass_kg * MG_PER_KG,
            mass_rate_mg_per_h: (ra.mass_kg + rb.mass_kg) * MG_PER_KG * per_h,
            mass_rate_a_mg_per_h: ra.mass_kg * MG_PER_KG * per_h,
            mass_rate_b_mg_per_h: rb.mass_kg * MG_PER_KG * per_h,
            mean_normal_force_n: normal_rate_window[ci] / rate_span,
            mean_normal_slip_power_w: normal_slip_rate_window[ci] / rate_span,
            mean_friction_power_w: friction_rate_window[ci] / rate_span,
            friction_work_j: t.friction_window[ci],
            peak_normal_force_n: t.peak[ci],
            wear: total,
        });
    }
    let bodies = sys
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| BodyReport {
            name: b.name.clone(),
            mass_mg: body_mass[i] * MG_PER_KG,
            mass_rate_mg_per_h: body_rate[i],
        })
        .collect();

    Ok(WindowReports {
        contacts,
        bodies,
        window_s: window,
        rate_window,
        mean_normal_force_n: normal_rate_window.iter().sum::<f64>() / rate_span,
        mean_normal_slip_power_w: normal_slip_rate_window.iter().sum::<f64>() / rate_span,
        mean_friction_power_w: friction_rate_window.iter().sum::<f64>() / rate_span,
    })
}
