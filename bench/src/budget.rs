//! Timed runs with a wall-time budget, and shared case helpers.

use super::*;

pub(crate) enum Outcome<T> {
    Done(T),
    Timeout { simulated_s: f64 },
    Failed(String),
}

/// A [`RunControl`] whose cancel flag a watchdog sets after `budget`; also remembers the
/// simulated time reached. Call the returned closure when the run ends to stop the watchdog.
pub(crate) fn budget_control(
    budget: Duration,
) -> (RunControl, Arc<AtomicU64>, impl FnOnce() -> bool) {
    let cancel = Arc::new(AtomicBool::new(false));
    let reached = Arc::new(AtomicU64::new(0f64.to_bits()));
    let r2 = reached.clone();
    let control = RunControl::new(
        cancel.clone(),
        Arc::new(move |p: Progress| {
            r2.store(p.simulated_time_s.to_bits(), Ordering::Relaxed);
        }),
    );
    let (tx, rx) = mpsc::channel::<()>();
    let c2 = cancel.clone();
    let watchdog = std::thread::spawn(move || {
        if let Err(mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(budget) {
            c2.store(true, Ordering::Relaxed);
        }
    });
    let stop = move || {
        let _ = tx.send(());
        let _ = watchdog.join();
        cancel.load(Ordering::Relaxed)
    };
    (control, reached, stop)
}

pub(crate) fn run_model_budget(
    model: &BuiltModel,
    options: &RunOptions,
    budget: Duration,
) -> Outcome<RunReport> {
    let (control, reached, stop) = budget_control(budget);
    let res = run_model(model, options, &control);
    let timed_out = stop();
    match res {
        Ok(r) => Outcome::Done(r),
        Err(ModelRunError::Sim(SimError::Cancelled { time_s })) if timed_out => Outcome::Timeout {
            simulated_s: time_s.max(f64::from_bits(reached.load(Ordering::Relaxed))),
        },
        Err(e) => Outcome::Failed(e.to_string()),
    }
}

pub(crate) fn kind_from_name(name: &str) -> Result<IntegratorKind> {
    IntegratorKind::ALL
        .into_iter()
        .find(|k| k.name() == name.trim())
        .ok_or_else(|| anyhow!("unknown integrator {name:?}; use trbdf2, sdirk2 or dopri5"))
}

/// Rattle box case C with the given settle, window and integrator; tracks are not recorded
/// (the peers record nothing either; recording is output, not engine work).
pub(crate) fn rattle_box_c(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    kind: IntegratorKind,
) -> Result<(CaseSpec, BuiltModel, RunOptions)> {
    rattle_box_c_points(configs_dir, settle, window, kind, None)
}

/// [`rattle_box_c`] with `points` contact points per box edge (None: the case's).
pub(crate) fn rattle_box_c_points(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    kind: IntegratorKind,
    points: Option<usize>,
) -> Result<(CaseSpec, BuiltModel, RunOptions)> {
    let mut case = load_case(&configs_dir.join("rattle-box-c.toml"))?;
    if let Some(n) = points {
        case.simulation.contact_points_per_edge = n;
    }
    case.simulation.settle_s = settle;
    case.simulation.duration_s = window;
    case.simulation.record_interval_s = case.simulation.record_interval_s.min(window);
    case.simulation.integrator = kind.name().to_string();
    let model = build(&case, configs_dir)?;
    let mut options = run_options(&case)?;
    options.record_interval_s = -1.0;
    Ok((case, model, options))
}

pub(crate) fn tolerance_text(t: &Tolerances) -> String {
    format!("rel {:e}, abs {:e} m", t.rel, t.abs_position_m)
}
