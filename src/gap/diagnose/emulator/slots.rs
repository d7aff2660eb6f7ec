//! The simulation plan: each test's case, one slot per effect set (effects, tolerance scale,
//! friction step, settle shift) and test, the tasks run in parallel through the window cache,
//! and a slot's increments turned into predictions.

use super::{EmulatorOptions, Prediction, TestPredictions};
use crate::cases::RunControl;
use crate::gap::effects::Effect;
use crate::gap::rig::{simulate_test, ModelIncrement, RigOptions};
use crate::gap::window::{WindowCache, WindowOptions};
use crate::gap::{Campaign, GapError};
use crate::models::spec::CaseSpec;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// A task's simulated increments.
pub(in crate::gap::diagnose) type TaskResult = Result<Vec<ModelIncrement>, GapError>;

/// One simulation task: (what, effects, tolerance scale, friction step, test).
pub(super) struct Task {
    slot: usize,
    test: usize,
    effects: Vec<Effect>,
    tolerance_scale: f64,
    friction_step: f64,
    settle_shift_s: f64,
}

/// One simulation slot: the effects on, the tolerance scale, the friction step and the settle
/// shift of its run of every test.
pub(in crate::gap::diagnose) type Slot = (Vec<Effect>, f64, f64, f64);

/// Every test's case and the number of increments simulated for it.
pub(in crate::gap::diagnose) fn plan(
    campaign: &Campaign,
    configs_dir: &Path,
) -> Result<(Vec<CaseSpec>, Vec<usize>), GapError> {
    let cases: Vec<CaseSpec> = campaign
        .tests
        .iter()
        .enumerate()
        .map(|(ti, t)| t.case(ti, configs_dir))
        .collect::<Result<_, _>>()?;
    let increments: Vec<usize> = campaign
        .tests
        .iter()
        .map(|t| {
            t.specimens
                .iter()
                .map(|s| s.increments.len())
                .max()
                .unwrap_or(0)
        })
        .collect();
    Ok((cases, increments))
}

/// Simulates every test under every slot on `options.threads` threads; returns the increments
/// `[slot][test]`. `progress(done, total)` is called after every test simulated, counting from
/// `done_before` of `total`.
#[allow(clippy::too_many_arguments)]
pub(in crate::gap::diagnose) fn simulate_slots(
    slots: &[Slot],
    campaign: &Campaign,
    (cases, increments): (&[CaseSpec], &[usize]),
    configs_dir: &Path,
    options: &EmulatorOptions,
    control: &RunControl,
    cache: &WindowCache,
    progress: &(dyn Fn(usize, usize) + Sync),
    (done_before, total): (usize, usize),
) -> Result<Vec<Vec<Vec<ModelIncrement>>>, GapError> {
    let tasks: Vec<Task> = slots
        .iter()
        .enumerate()
        .flat_map(|(slot, (effects, tol, fr, settle))| {
            (0..campaign.tests.len()).map(move |test| Task {
                slot,
                test,
                effects: effects.clone(),
                tolerance_scale: *tol,
                friction_step: *fr,
                settle_shift_s: *settle,
            })
        })
        .collect();
    let results: Mutex<Vec<Option<TaskResult>>> =
        Mutex::new((0..tasks.len()).map(|_| None).collect());
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(done_before);
    std::thread::scope(|scope| {
        for _ in 0..options.threads.max(1) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(task) = tasks.get(i) else { break };
                if control.is_cancelled() {
                    break;
                }
                let r = run_task(
                    task,
                    campaign,
                    cases,
                    configs_dir,
                    options,
                    increments,
                    control,
                    cache,
                );
                if let Ok(mut v) = results.lock() {
                    v[i] = Some(r);
                }
                progress(done.fetch_add(1, Ordering::SeqCst) + 1, total);
            });
        }
    });
    if control.is_cancelled() {
        return Err(GapError::Simulation {
            what: "diagnosis".into(),
            message: "cancelled".into(),
        });
    }
    let mut results = results.into_inner().map_err(|_| GapError::Simulation {
        what: "diagnosis".into(),
        message: "a simulation thread panicked".into(),
    })?;
    let mut by_slot: Vec<Vec<Vec<ModelIncrement>>> = (0..slots.len()).map(|_| Vec::new()).collect();
    for (i, task) in tasks.iter().enumerate() {
        let r = results[i].take().ok_or_else(|| GapError::Simulation {
            what: format!("test {}", campaign.tests[task.test].id),
            message: "not simulated".into(),
        })??;
        debug_assert_eq!(by_slot[task.slot].len(), task.test);
        by_slot[task.slot].push(r);
    }
    Ok(by_slot)
}

/// Predictions `[test][increment]` of one slot's simulated increments.
pub(in crate::gap::diagnose) fn predictions_of(slot: &[Vec<ModelIncrement>]) -> TestPredictions {
    slot.iter()
        .map(|t| t.iter().map(Prediction::from_increment).collect())
        .collect()
}

#[allow(clippy::too_many_arguments)]
pub(super) fn run_task(
    task: &Task,
    campaign: &Campaign,
    cases: &[CaseSpec],
    configs_dir: &Path,
    options: &EmulatorOptions,
    increments: &[usize],
    control: &RunControl,
    cache: &WindowCache,
) -> Result<Vec<ModelIncrement>, GapError> {
    let rig = RigOptions {
        effects: task.effects.clone(),
        window_s: options.window_s,
        settle_s: options.settle_s + task.settle_shift_s,
        accelerometer_rate_hz: Some(options.accelerometer_rate_hz),
        ..RigOptions::default()
    };
    let window = WindowOptions {
        window_s: options.window_s,
        settle_s: options.settle_s + task.settle_shift_s,
        accelerometer_rate_hz: Some(options.accelerometer_rate_hz),
        tolerance_scale: task.tolerance_scale,
    };
    let mut case = cases[task.test].clone();
    if task.friction_step != 0.0 {
        if let Some(rb) = case.rattle_box.as_mut() {
            rb.friction.mu_static += task.friction_step;
            rb.friction.mu_dynamic += task.friction_step;
        }
        if let Some(l) = case.launcher.as_mut() {
            l.friction.mu_static += task.friction_step;
            l.friction.mu_dynamic += task.friction_step;
        }
    }
    simulate_test(
        task.test,
        campaign,
        Some(&case),
        configs_dir,
        &rig,
        &window,
        increments[task.test],
        control,
        cache,
    )
}
