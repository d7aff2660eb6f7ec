//! The whole diagnosis of a campaign: its options checked, the emulator built, then refined
//! where the candidates' fits land and judged, and the next tests proposed.

use super::emulator::Emulator;
use super::next_test::propose;
use super::noise;
use super::options::{check_effects, check_options, DiagnoseOptions, Simulating};
use super::refine::diagnose_refining;
use super::report::Report;
use super::verdict::no_measurement;
use crate::cases::RunControl;
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use std::path::Path;

/// Runs the diagnosis: builds the emulator (simulations, reported through `progress(done,
/// total)`), then fits, ranks and locates. The campaign is taken as validated
/// ([`Campaign::validate`]): the service validates it once on upload, the CLI as it loads it.
pub fn diagnose(
    campaign: &Campaign,
    configs_dir: &Path,
    options: &DiagnoseOptions,
    control: &RunControl,
    cache: &WindowCache,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(Report, Emulator), GapError> {
    check_options(options)?;
    if let Some(effects) = &options.emulator.effects {
        check_effects(campaign, effects, configs_dir)?;
    }
    // Refused before anything is simulated.
    if noise::observations(campaign).is_empty() {
        return Err(no_measurement());
    }
    let built = std::sync::atomic::AtomicUsize::new(0);
    let mut emulator = Emulator::build(
        campaign,
        configs_dir,
        &options.emulator,
        control,
        cache,
        &|done, total| {
            built.fetch_max(done, std::sync::atomic::Ordering::SeqCst);
            progress(done, total)
        },
    )?;
    // Refinement's simulations count on from the emulator's, so progress never goes back.
    let offset = built.into_inner();
    let mut report = diagnose_refining(
        campaign,
        &mut emulator,
        options,
        configs_dir,
        control,
        cache,
        &|done, total| progress(offset + done, offset + total),
    )?;
    let sim = Simulating {
        campaign,
        options,
        configs_dir,
        control,
        cache,
    };
    report.next_tests = propose(campaign, &report, sim)?;
    Ok((report, emulator))
}
