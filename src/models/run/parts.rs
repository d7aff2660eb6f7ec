//! A model of independent parts (missiles on the rails of one prescribed launcher): each part
//! integrated on its own ([`crate::physics::partition`]) and the reports merged back into the
//! model's order, so the merged report reads as the whole model's.

use super::records::{Appended, RecordWriter};
use super::{
    bad_checkpoint, run_whole, BodyReport, BuiltModel, ContactReport, ModelCheckpoint,
    ModelRunError, RunOptions, RunReport,
};
use crate::physics::body::BodyKind;
use crate::physics::control::{Progress, RunControl};
use crate::physics::energy::EnergyAudit;
use crate::physics::integrator::IntegratorStats;
use crate::physics::partition::Part;

/// Runs each independent part on its own and merges the reports (from a checkpoint: the
/// finished parts' reports, the part in progress from its checkpoint, then the rest); each
/// part writes its records to `writer`, and its report when it finishes.
pub(super) fn run_parts(
    model: &BuiltModel,
    parts: &[Part],
    options: &RunOptions,
    control: &RunControl,
    resume: Option<ModelCheckpoint>,
    writer: &mut RecordWriter,
) -> Result<RunReport, ModelRunError> {
    let count = parts.len() as f64;
    let (mut finished, mut current): (Appended<RunReport>, _) = match resume {
        Some(cp) if cp.finished_parts.len() >= parts.len() => {
            return Err(bad_checkpoint(format!(
                "{} finished parts of a model with {} parts",
                cp.finished_parts.len(),
                parts.len()
            )))
        }
        Some(cp) => (cp.finished_parts, Some(cp.current)),
        None => (Appended::default(), None),
    };
    writer.part_of_several = true;
    let first = finished.len();
    for (i, part) in parts.iter().enumerate().skip(first) {
        let response_body = part
            .bodies
            .iter()
            .position(|&b| b == model.response_body)
            .or_else(|| {
                (0..part.bodies.len())
                    .find(|&b| matches!(part.system.bodies[b].kind, BodyKind::Dynamic { .. }))
            })
            .unwrap_or(0);
        let sub = BuiltModel {
            name: model.name.clone(),
            system: part.system.clone(),
            initial_state: part.state_from(&model.system, &model.initial_state),
            excitation_start_s: model.excitation_start_s,
            rate_start_s: model.rate_start_s,
            end_time_s: model.end_time_s,
            contact_materials: part
                .contacts
                .iter()
                .map(|&c| model.contact_materials[c])
                .collect(),
            response_body,
        };
        // Progress of the whole: the parts run one after the other.
        let outer = control.progress.clone();
        let sub_control = RunControl {
            progress: std::sync::Arc::new(move |p: Progress| {
                outer(Progress {
                    fraction: (i as f64 + p.fraction) / count,
                    ..p
                })
            }),
            ..control.clone()
        };
        writer.part = i as u32;
        match run_whole(
            &sub,
            options,
            &sub_control,
            &mut |_| {},
            current.take(),
            writer,
        ) {
            Ok(report) => writer.part_finished(&mut finished, report),
            Err(e) => return Err(e.within_parts(finished, writer.mark())),
        }
    }
    let reports = parts
        .iter()
        .zip(finished.into_items())
        .map(|(part, report)| (report, part.bodies.contains(&model.response_body)))
        .collect();
    Ok(merge_reports(model, parts, reports))
}

/// The whole model's report from its parts' (each part's contacts and bodies put back in the
/// model's order; sums of the additive quantities).
fn merge_reports(model: &BuiltModel, parts: &[Part], reports: Vec<(RunReport, bool)>) -> RunReport {
    let sys = &model.system;
    let mut contacts: Vec<Option<ContactReport>> = vec![None; sys.contacts.len()];
    let mut body_mass_mg = vec![0.0; sys.bodies.len()];
    let mut body_rate = vec![0.0; sys.bodies.len()];
    let mut integrator = IntegratorStats::default();
    let (mut wall_s, mut mean_n, mut mean_p, mut mean_friction) = (0.0, 0.0, 0.0, 0.0);
    let mut tracks = Vec::new();
    let mut response = None;
    let mut histories = Vec::new();
    let mut audits = Vec::new();
    let mut window_s = 0.0;
    let mut rate_window = None;
    for (part, (r, holds_response)) in parts.iter().zip(reports) {
        window_s = r.window_s;
        rate_window.get_or_insert(r.rate_window);
        for (local, c) in r.contacts.into_iter().enumerate() {
            contacts[part.contacts[local]] = Some(c);
        }
        for (local, b) in r.bodies.iter().enumerate() {
            body_mass_mg[part.bodies[local]] += b.mass_mg;
            body_rate[part.bodies[local]] += b.mass_rate_mg_per_h;
        }
        let s = r.integrator;
        integrator.accepted += s.accepted;
        integrator.rejected += s.rejected;
        integrator.newton_failures += s.newton_failures;
        integrator.rhs_evals += s.rhs_evals;
        integrator.jacobians += s.jacobians;
        integrator.factorizations += s.factorizations;
        integrator.contact_free_rhs_evals += s.contact_free_rhs_evals;
        wall_s += r.wall_s;
        mean_n += r.mean_normal_force_n;
        mean_p += r.mean_normal_slip_power_w;
        mean_friction += r.mean_friction_power_w;
        tracks.extend(r.tracks.into_iter().map(|mut t| {
            t.contact = part.contacts[t.contact as usize] as u32;
            t
        }));
        if holds_response && response.is_none() {
            response = Some((
                r.response_acceleration,
                r.base_acceleration,
                r.response_rate_hz,
            ));
        }
        histories.push((part, r.wear_history));
        if let Some(e) = r.energy {
            audits.push((part, e));
        }
    }
    // Track samples in time order (stable: within one instant, the model's contact order).
    tracks.sort_by(|a, b| {
        a.time_s
            .total_cmp(&b.time_s)
            .then(a.contact.cmp(&b.contact))
    });
    // Wear history on the first part's instants; each other part holds its last sample.
    let mut wear_history = Vec::new();
    if let Some((_, first)) = histories.first() {
        for (t, _) in first {
            let mut vols = vec![0.0; sys.contacts.len()];
            for (part, h) in &histories {
                if let Some((_, v)) = h.iter().take_while(|(th, _)| th <= t).last() {
                    for (local, vol) in v.iter().enumerate() {
                        vols[part.contacts[local]] = *vol;
                    }
                }
            }
            wear_history.push((*t, vols));
        }
    }
    let energy = (!audits.is_empty()).then(|| {
        let names: Vec<String> = sys.contacts.iter().map(|c| c.name.clone()).collect();
        EnergyAudit::merge(
            &names,
            audits
                .into_iter()
                .map(|(part, e)| (part.contacts.clone(), e))
                .collect(),
        )
    });
    let (response_acceleration, base_acceleration, response_rate_hz) = response.unwrap_or_default();
    RunReport {
        contacts: contacts.into_iter().flatten().collect(),
        bodies: sys
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| BodyReport {
                name: b.name.clone(),
                mass_mg: body_mass_mg[i],
                mass_rate_mg_per_h: body_rate[i],
            })
            .collect(),
        window_s,
        rate_window: rate_window.unwrap_or(super::RateWindow {
            start_s: model.excitation_start_s,
            length_s: window_s,
            after_ramp: false,
        }),
        mean_normal_force_n: mean_n,
        mean_normal_slip_power_w: mean_p,
        mean_friction_power_w: mean_friction,
        integrator,
        wall_s,
        tracks,
        response_acceleration,
        response_rate_hz,
        base_acceleration,
        wear_history,
        energy,
        resumed_from_s: None,
    }
}
