//! Adaptive refinement of the emulator's dynamics tables at the magnitudes the contending
//! effects' fits land on (docs/diagnosis.md, "Adaptive refinement").

use super::{
    diagnose_with, location, stats, Candidate, DiagnoseOptions, Problem, Report, REFINE_CONTENDERS,
};
use crate::gap::diagnose::emulator::Emulator;
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use crate::physics::control::RunControl;
use std::path::Path;

/// The diagnosis after up to `options.refine_rounds` rounds of adaptive refinement of the
/// emulator's dynamics tables ([`Emulator::refine`]): while the contending effects' fits land
/// between simulated magnitudes, those magnitudes are simulated and the fits repeated, so the
/// verdict rests on the simulator at the fitted magnitudes rather than on interpolation.
/// Nothing is refined when the nominal model shows no gap.
pub fn diagnose_refining(
    campaign: &Campaign,
    emulator: &mut Emulator,
    options: &DiagnoseOptions,
    configs_dir: &Path,
    control: &RunControl,
    cache: &WindowCache,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Report, GapError> {
    // `progress` counts the test simulations of every round: a round's are added to those
    // done before it, so the count never goes back (the total grows by what a round adds).
    let mut done_before = 0;
    for _ in 0..options.refine_rounds {
        let requests = refinement_requests(campaign, emulator, options);
        if requests.is_empty() {
            break;
        }
        let offset = done_before;
        let cumulative = |done: usize, total: usize| progress(offset + done, offset + total);
        let added = emulator.refine(
            campaign,
            configs_dir,
            &requests,
            control,
            cache,
            &cumulative,
        )?;
        done_before = offset + added * campaign.tests.len();
        if added == 0 {
            break;
        }
    }
    diagnose_with(campaign, emulator, options)
}

/// Magnitudes the next refinement round simulates: for the [`REFINE_CONTENDERS`] simulated
/// effects whose held-out fit beats the nominal, the full-data and every training fold's
/// fitted magnitude. Empty when the nominal model shows no gap.
fn refinement_requests(
    campaign: &Campaign,
    emulator: &Emulator,
    options: &DiagnoseOptions,
) -> Vec<(usize, f64)> {
    let problem = Problem::new(campaign, emulator, options);
    if problem.obs.is_empty() {
        return Vec::new();
    }
    let nominal = problem.evaluate(&[], options.alpha);
    let nominal_p = stats::chi2_sf(nominal.chi2, nominal.dof.round().max(1.0) as usize);
    if nominal_p >= options.alpha && !location::locate(campaign, &problem).any_flagged() {
        return Vec::new();
    }
    let mut contenders: Vec<Candidate> = (0..emulator.effects.len())
        .filter(|&e| emulator.effects[e].simulated)
        .map(|e| problem.evaluate(&[e], options.alpha))
        .filter(|c| c.held_ll() > nominal.held_ll())
        .collect();
    contenders.sort_by(|a, b| b.held_ll().total_cmp(&a.held_ll()));
    contenders
        .iter()
        .take(REFINE_CONTENDERS)
        .flat_map(|c| {
            let e = c.effects[0];
            std::iter::once(c.magnitudes[0])
                .chain(c.fold_magnitudes.iter().map(|m| m[0]))
                .map(move |m| (e, m))
        })
        .filter(|(_, m)| *m != 0.0)
        .collect()
}
