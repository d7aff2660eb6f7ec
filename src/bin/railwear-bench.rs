//! `railwear-bench`: the benchmark programs of issues 2 (item 6), 4 (item 5), 5 and 6 (item 3).
//! Each subcommand prints markdown tables (or, with `--json`, one JSON object per table). These are
//! measurements, not tests: nothing here asserts a number. Wall-clock numbers depend on the load
//! of the machine; the tables say what was run so a reader can repeat it.

use anyhow::{anyhow, bail, Context, Result};
use clap::{Parser, Subcommand};
use nalgebra::{Isometry3, Vector3};
use railwear::analysis::rattle_space::LauncherDimensions;
use railwear::analysis::vdv::vibration_dose_value_uniform;
use railwear::models::case::{build, load_case, run_case, run_options};
use railwear::models::run::{run_model, BuiltModel, ModelRunError, RunOptions, RunReport};
use railwear::models::specs::CaseSpec;
use railwear::physics::body::write_state;
use railwear::physics::impact::ImpactParams;
use railwear::physics::integrator::{
    ContactPatches, IntegratorKind, IntegratorSettings, NewtonJacobian, Tolerances,
};
use railwear::physics::simulate::{simulate, DivergenceLimits, SimError, StepView};
use railwear::pipeline::{Progress, RunControl, RunError};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

#[derive(Parser)]
#[command(
    name = "railwear-bench",
    about = "railwear benchmarks: engine speed, peers, launcher, sweep, sweep over worker processes, service load (prints tables)"
)]
struct Cli {
    /// Print one JSON object per table instead of markdown.
    #[arg(long, global = true)]
    json: bool,
    /// Directory of reference configs and profiles.
    #[arg(long, global = true, default_value = "configs")]
    configs_dir: PathBuf,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Real-time factor of rattle box case C and of a bouncing sphere for each integrator,
    /// and the VDV (eq. 2.51) of each integrator normalised to trbdf2's (thesis Table 2.3 style).
    Engine {
        /// Settle time before the excitation, s.
        #[arg(long, default_value_t = 1.0)]
        settle: f64,
        /// Excitation (averaging) window of the rattle box, s.
        #[arg(long, default_value_t = 3.0)]
        window: f64,
        /// Wall-time budget per run, s; a run still going is cancelled and reported as timeout.
        #[arg(long, default_value_t = 120.0)]
        budget: f64,
        /// Simulated duration of the bouncing sphere, s.
        #[arg(long, default_value_t = 2.0)]
        sphere_duration: f64,
        /// Integrators to run (comma list of trbdf2, sdirk2, dopri5).
        #[arg(long, default_value = "trbdf2,sdirk2,dopri5")]
        integrators: String,
    },
    /// railwear beside MuJoCo/Drake (bench/peers/run_peers.sh) on rattle box case C, one run.
    Peers {
        /// Run bench/peers/run_peers.sh (installs MuJoCo and Drake into a venv on first use).
        #[arg(long)]
        with_peers: bool,
        /// Read peer JSON lines from this file instead of running the script.
        #[arg(long)]
        peers_json: Option<PathBuf>,
        /// Settle time, s (same for all engines).
        #[arg(long, default_value_t = 1.0)]
        settle: f64,
        /// Excitation (averaging) window, s (same for all engines).
        #[arg(long, default_value_t = 3.0)]
        window: f64,
        /// Extra arguments passed to run_peers.sh (e.g. "--drake-steps ''").
        #[arg(long, allow_hyphen_values = true, default_value = "")]
        peer_args: String,
    },
    /// Launcher reference run (launcher-design, AH-64 transverse): real-time factor and the
    /// peak memory of a long run with all contact tracks stored.
    Launcher {
        /// Settle time, s.
        #[arg(long, default_value_t = 1.0)]
        settle: f64,
        /// Excitation window of the timed run, s.
        #[arg(long, default_value_t = 2.0)]
        window: f64,
        /// Excitation window of the memory run, s (settle + 59 s = the 60 s run of issue 5).
        #[arg(long, default_value_t = 59.0)]
        mem_window: f64,
        /// Skip the memory run.
        #[arg(long)]
        no_mem: bool,
    },
    /// Internal: one memory run in a fresh process; prints one JSON line.
    #[command(hide = true)]
    LauncherMem {
        #[arg(long)]
        settle: f64,
        #[arg(long)]
        window: f64,
    },
    /// Tolerance sweeps (pipeline::sweep_job) with 1 worker vs 2 workers: simulations per minute.
    Sweep {
        /// Points per sweep (tight to loose).
        #[arg(long, default_value_t = 5)]
        points: u64,
        /// Sweeps run per worker setting (the work queue holds whole sweeps, as the service
        /// does). Since the fourth engine pass a point takes ~25 ms, so 4 sweeps keep the timed
        /// span near 0.4 s (2 sweeps left it at 0.1-0.2 s, inside the VM's scheduling noise).
        #[arg(long, default_value_t = 4)]
        sweeps: usize,
        /// Timed pairs (1 worker, then 2 workers), interleaved so a burst of load on this
        /// VM hits both settings; the table shows the medians.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Settle time of each point, s.
        #[arg(long, default_value_t = 0.2)]
        settle: f64,
        /// Excitation window of each point, s.
        #[arg(long, default_value_t = 0.3)]
        window: f64,
    },
    /// A sweep job fanned out to `railwear worker` processes on PostgreSQL, run with 1 and then
    /// 2 worker processes (one worker each): simulations per minute and the ratio (issue 6).
    /// Creates its own database on the server and drops it afterwards.
    SweepProcs {
        /// The railwear binary.
        #[arg(long, default_value = "target/release/railwear")]
        bin: PathBuf,
        /// Admin connection to the PostgreSQL server (the bench database is created beside).
        #[arg(long, default_value = "postgres://postgres@127.0.0.1:5432/test")]
        url: String,
        /// Points per sweep (child jobs).
        #[arg(long, default_value_t = 12)]
        points: u64,
        /// Settle time of each point, s (long enough that process start-up and polling are
        /// small beside a point's run).
        #[arg(long, default_value_t = 0.5)]
        settle: f64,
        /// Excitation window of each point, s.
        #[arg(long, default_value_t = 1.0)]
        window: f64,
    },
    /// Service load: the real `railwear serve`, N rails stored, two simulations running, then
    /// concurrent GET rail reports; GETs/s and p50/p99 latency.
    Load {
        /// The railwear binary.
        #[arg(long, default_value = "target/release/railwear")]
        bin: PathBuf,
        /// Rails to store before the load.
        #[arg(long, default_value_t = 10_000)]
        rails: usize,
        /// Concurrent client tasks (one keep-alive connection each).
        #[arg(long, default_value_t = 32)]
        concurrency: usize,
        /// Duration of the GET load, s.
        #[arg(long, default_value_t = 10.0)]
        seconds: f64,
        /// Run a short sweep job first so reports carry K_SL (else they answer `missing_curve`).
        #[arg(long)]
        no_curve: bool,
        /// Client runtime threads.
        #[arg(long, default_value_t = 2)]
        client_threads: usize,
    },
}

/// An engine configuration timed side by side with the others in the same run.
struct EngineVariant {
    name: &'static str,
    newton: NewtonJacobian,
    patches: ContactPatches,
}

/// The default engine first, then the earlier ones (issue 5's passes), so every table
/// measures each engine change in one run.
const ENGINE_VARIANTS: [EngineVariant; 3] = [
    EngineVariant {
        name: "contact-aware Newton, patches per step",
        newton: NewtonJacobian::ContactAware,
        patches: ContactPatches::PerStep,
    },
    EngineVariant {
        name: "contact-aware Newton, patches per iterate",
        newton: NewtonJacobian::ContactAware,
        patches: ContactPatches::PerIterate,
    },
    EngineVariant {
        name: "finite-difference Newton",
        newton: NewtonJacobian::FiniteDifference,
        patches: ContactPatches::PerIterate,
    },
];

fn main() -> Result<()> {
    let cli = Cli::parse();
    let tables = match &cli.command {
        Command::Engine {
            settle,
            window,
            budget,
            sphere_duration,
            integrators,
        } => engine(
            &cli.configs_dir,
            *settle,
            *window,
            *budget,
            *sphere_duration,
            integrators,
        )?,
        Command::Peers {
            with_peers,
            peers_json,
            settle,
            window,
            peer_args,
        } => peers(
            &cli.configs_dir,
            *with_peers,
            peers_json.as_deref(),
            *settle,
            *window,
            peer_args,
        )?,
        Command::Launcher {
            settle,
            window,
            mem_window,
            no_mem,
        } => launcher(&cli.configs_dir, *settle, *window, *mem_window, *no_mem)?,
        Command::LauncherMem { settle, window } => {
            launcher_mem(&cli.configs_dir, *settle, *window)?;
            return Ok(());
        }
        Command::Sweep {
            points,
            sweeps,
            repeats,
            settle,
            window,
        } => sweep(
            &cli.configs_dir,
            SweepBench {
                points: *points,
                sweeps: *sweeps,
                repeats: *repeats,
                settle: *settle,
                window: *window,
            },
        )?,
        Command::SweepProcs {
            bin,
            url,
            points,
            settle,
            window,
        } => sweep_procs(&cli.configs_dir, bin, url, *points, *settle, *window)?,
        Command::Load {
            bin,
            rails,
            concurrency,
            seconds,
            no_curve,
            client_threads,
        } => load(
            &cli.configs_dir,
            bin,
            *rails,
            *concurrency,
            *seconds,
            !*no_curve,
            *client_threads,
        )?,
    };
    for t in &tables {
        if cli.json {
            println!("{}", t.to_json());
        } else {
            println!("{}", t.to_markdown());
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Tables

#[derive(Clone)]
enum Cell {
    Num(f64),
    Int(u64),
    Text(String),
}

impl Cell {
    fn text(s: impl Into<String>) -> Self {
        Cell::Text(s.into())
    }
    fn opt(x: Option<f64>) -> Self {
        x.map(Cell::Num).unwrap_or_else(|| Cell::text("-"))
    }
    fn render(&self) -> String {
        match self {
            Cell::Num(x) => fmt_num(*x),
            Cell::Int(n) => n.to_string(),
            Cell::Text(s) => s.replace('|', "\\|"),
        }
    }
    fn json(&self) -> Value {
        match self {
            Cell::Num(x) if x.is_finite() => json!(x),
            Cell::Num(_) => Value::Null,
            Cell::Int(n) => json!(n),
            Cell::Text(s) => json!(s),
        }
    }
}

/// Four significant digits; scientific below 1e-3 and at or above 1e6.
fn fmt_num(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if !(1e-3..1e6).contains(&a) {
        return format!("{x:.3e}");
    }
    let digits = (3 - a.log10().floor() as i32).max(0) as usize;
    format!("{x:.digits$}")
}

struct Table {
    title: String,
    /// (JSON key, header).
    columns: Vec<(&'static str, &'static str)>,
    rows: Vec<Vec<Cell>>,
    notes: Vec<String>,
}

impl Table {
    fn new(title: impl Into<String>, columns: &[(&'static str, &'static str)]) -> Self {
        Self {
            title: title.into(),
            columns: columns.to_vec(),
            rows: Vec::new(),
            notes: Vec::new(),
        }
    }
    fn row(&mut self, cells: Vec<Cell>) {
        self.rows.push(cells);
    }
    fn note(&mut self, s: impl Into<String>) {
        self.notes.push(s.into());
    }
    fn to_markdown(&self) -> String {
        let mut s = format!("### {}\n\n|", self.title);
        for (_, h) in &self.columns {
            s.push_str(&format!(" {h} |"));
        }
        s.push_str("\n|");
        for _ in &self.columns {
            s.push_str("---|");
        }
        s.push('\n');
        for r in &self.rows {
            s.push('|');
            for c in r {
                s.push_str(&format!(" {} |", c.render()));
            }
            s.push('\n');
        }
        if !self.notes.is_empty() {
            s.push('\n');
            for n in &self.notes {
                s.push_str(&format!("- {n}\n"));
            }
        }
        s
    }
    fn to_json(&self) -> String {
        let rows: Vec<Value> = self
            .rows
            .iter()
            .map(|r| {
                let mut m = serde_json::Map::new();
                for ((k, _), c) in self.columns.iter().zip(r) {
                    m.insert((*k).to_string(), c.json());
                }
                Value::Object(m)
            })
            .collect();
        json!({"table": self.title, "rows": rows, "notes": self.notes}).to_string()
    }
}

fn machine_note() -> String {
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into());
    format!(
        "machine: {cores} cores visible, 1-min load average {load} when the table was printed; \
         wall-clock numbers scale with the share of a core this process got"
    )
}

// ---------------------------------------------------------------------------------------------
// Timed runs with a wall-time budget

enum Outcome<T> {
    Done(T),
    Timeout { simulated_s: f64 },
    Failed(String),
}

/// A [`RunControl`] whose cancel flag a watchdog sets after `budget`; also remembers the
/// simulated time reached. Call the returned closure when the run ends to stop the watchdog.
fn budget_control(budget: Duration) -> (RunControl, Arc<AtomicU64>, impl FnOnce() -> bool) {
    let cancel = Arc::new(AtomicBool::new(false));
    let reached = Arc::new(AtomicU64::new(0f64.to_bits()));
    let r2 = reached.clone();
    let control = RunControl {
        cancel: cancel.clone(),
        progress: Arc::new(move |p: Progress| {
            r2.store(p.simulated_time_s.to_bits(), Ordering::Relaxed);
        }),
    };
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

fn run_model_budget(
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

fn kind_from_name(name: &str) -> Result<IntegratorKind> {
    IntegratorKind::ALL
        .into_iter()
        .find(|k| k.name() == name.trim())
        .ok_or_else(|| anyhow!("unknown integrator {name:?}; use trbdf2, sdirk2 or dopri5"))
}

/// Rattle box case C with the given settle, window and integrator; tracks are not recorded
/// (the peers record nothing either; recording is output, not engine work).
fn rattle_box_c(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    kind: IntegratorKind,
) -> Result<(CaseSpec, BuiltModel, RunOptions)> {
    let mut case = load_case(&configs_dir.join("rattle-box-c.toml"))?;
    case.simulation.settle_s = settle;
    case.simulation.duration_s = window;
    case.simulation.record_interval_s = case.simulation.record_interval_s.min(window);
    case.simulation.integrator = kind.name().to_string();
    let model = build(&case, configs_dir)?;
    let mut options = run_options(&case)?;
    options.record_interval_s = -1.0;
    Ok((case, model, options))
}

fn tolerance_text(t: &Tolerances) -> String {
    format!("rel {:e}, abs {:e} m", t.rel, t.abs_position_m)
}

// ---------------------------------------------------------------------------------------------
// engine

struct SphereRun {
    simulated_s: f64,
    wall_s: f64,
    accepted: u64,
    rejected: u64,
    mean_normal_force_n: f64,
    mean_friction_power_w: f64,
    vdv_y: Option<f64>,
}

/// Time-weighted (trapezoid) means of N and N·|v_slip| and a uniformly resampled velocity, from
/// the accepted steps a simulation reports.
struct StepMeans {
    t_from: f64,
    prev: Option<(f64, f64, f64)>,
    normal_int: f64,
    power_int: f64,
    dt_resp: f64,
    next_resp: f64,
    prev_vel: Option<(f64, f64)>,
    vel: Vec<f64>,
}

impl StepMeans {
    fn new(t_from: f64, rate_hz: f64) -> Self {
        Self {
            t_from,
            prev: None,
            normal_int: 0.0,
            power_int: 0.0,
            dt_resp: 1.0 / rate_hz,
            next_resp: t_from,
            prev_vel: None,
            vel: Vec::new(),
        }
    }
    fn push(&mut self, v: &StepView, velocity: f64) {
        if v.t < self.t_from {
            return;
        }
        let n: f64 = v.tracks.iter().map(|t| t.normal_force).sum();
        let p: f64 = v.tracks.iter().map(|t| t.normal_force * t.slip_speed).sum();
        if let Some((tp, np, pp)) = self.prev {
            let dt = v.t - tp;
            self.normal_int += 0.5 * dt * (np + n);
            self.power_int += 0.5 * dt * (pp + p);
        }
        self.prev = Some((v.t, n, p));
        if let Some((tp, vp)) = self.prev_vel {
            while self.next_resp <= v.t && v.t > tp {
                let s = ((self.next_resp - tp) / (v.t - tp)).clamp(0.0, 1.0);
                self.vel.push(vp + (velocity - vp) * s);
                self.next_resp += self.dt_resp;
            }
        }
        self.prev_vel = Some((v.t, velocity));
    }
    fn acceleration(&self) -> Vec<f64> {
        self.vel
            .windows(2)
            .map(|w| (w[1] - w[0]) / self.dt_resp)
            .collect()
    }
}

/// Radius of the bouncing sphere, m (the 50 mm sphere of thesis Figure 2.7).
const SPHERE_RADIUS_M: f64 = 0.05;
/// Drop height of the sphere's lowest point above the floor, m.
const SPHERE_DROP_M: f64 = 0.1;

/// Hertz contact of a 7075 sphere (R = 50 mm) on a 7075 half-space: k = 4/3 E* sqrt(R)
/// (eq. 2.5-2.10, E = 72 GPa, nu = 0.33 on both sides), e = 1.5, no damping (elastic bounces,
/// so the time-averaged normal force over whole bounces equals m g).
fn sphere_impact() -> ImpactParams {
    let e_star = 1.0 / (2.0 * (1.0 - 0.33f64.powi(2)) / 72e9);
    let k_si = 4.0 / 3.0 * e_star * SPHERE_RADIUS_M.sqrt();
    let k_adams = k_si * 1e-3f64.powf(1.5);
    let mut p = ImpactParams::from_adams_units(k_adams, 1.5, 0.0, 0.0);
    p.full_damping_depth = 1e-9;
    p
}

fn sphere_bounce(kind: IntegratorKind, duration: f64, budget: Duration) -> Outcome<SphereRun> {
    let (sys, mut y) = railwear::validation::sphere_on_floor(SPHERE_RADIUS_M, sphere_impact(), 0.0);
    write_state(
        &mut y,
        0,
        &Isometry3::translation(0.0, SPHERE_RADIUS_M + SPHERE_DROP_M, 0.0),
        Vector3::zeros(),
        Vector3::zeros(),
    );
    let settings = IntegratorSettings {
        kind,
        tolerances: Tolerances::default(),
        initial_step_s: 1e-6,
        max_step_s: 1e-3,
        min_step_s: 1e-15,
        ..IntegratorSettings::default()
    };
    let mut means = StepMeans::new(0.0, 2000.0);
    let (control, reached, stop) = budget_control(budget);
    let res = simulate(
        &sys,
        &mut y,
        0.0,
        duration,
        settings,
        DivergenceLimits::default(),
        &control,
        &mut |v: &StepView| means.push(v, v.state[8]),
    );
    let timed_out = stop();
    match res {
        Ok(stats) => {
            let acc = means.acceleration();
            Outcome::Done(SphereRun {
                simulated_s: duration,
                wall_s: stats.wall_s,
                accepted: stats.integrator.accepted,
                rejected: stats.integrator.rejected,
                mean_normal_force_n: means.normal_int / duration,
                mean_friction_power_w: means.power_int / duration,
                vdv_y: vibration_dose_value_uniform(&acc, means.dt_resp).ok(),
            })
        }
        Err(SimError::Cancelled { time_s }) if timed_out => Outcome::Timeout {
            simulated_s: time_s.max(f64::from_bits(reached.load(Ordering::Relaxed))),
        },
        Err(e) => Outcome::Failed(e.to_string()),
    }
}

const ENGINE_COLUMNS: &[(&str, &str)] = &[
    ("case", "case"),
    ("integrator", "integrator"),
    ("tolerance", "tolerance"),
    ("real_time_factor", "real-time factor"),
    ("steps_per_s", "steps/s"),
    ("accepted", "accepted"),
    ("rejected", "rejected"),
    ("mean_normal_force_n", "mean normal force N"),
    ("mean_friction_power_w", "mean N·\\|v_slip\\| W"),
    ("vdv_ratio", "VDV/VDV_trbdf2"),
];

fn status_row(case: &str, kind: &str, tol: &str, status: String) -> Vec<Cell> {
    let mut r = vec![Cell::text(case), Cell::text(kind), Cell::text(tol)];
    r.push(Cell::text(status));
    r.extend((0..6).map(|_| Cell::text("-")));
    r
}

fn engine(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    budget_s: f64,
    sphere_duration: f64,
    integrators: &str,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0 && budget_s > 0.0 && sphere_duration > 0.0) {
        bail!("--settle must be >= 0 and --window, --budget, --sphere-duration > 0");
    }
    let kinds: Vec<IntegratorKind> = integrators
        .split(',')
        .map(kind_from_name)
        .collect::<Result<_>>()?;
    let budget = Duration::from_secs_f64(budget_s);
    let mut table = Table::new(
        format!(
            "Engine: real-time factor and VDV per integrator (one thread; rattle box C settle {settle} s + window {window} s; sphere {sphere_duration} s)"
        ),
        ENGINE_COLUMNS,
    );
    // Rattle box case C.
    let mut box_rows: Vec<(IntegratorKind, Vec<Cell>, Option<f64>)> = Vec::new();
    for &kind in &kinds {
        let (_, model, options) = rattle_box_c(configs_dir, settle, window, kind)?;
        let tol = tolerance_text(&options.integrator.tolerances);
        eprintln!("engine: rattle box C, {} ...", kind.name());
        match run_model_budget(&model, &options, budget) {
            Outcome::Done(r) => {
                let acc: Vec<f64> = r.response_acceleration.iter().map(|a| a[0]).collect();
                let vdv = vibration_dose_value_uniform(&acc, 1.0 / r.response_rate_hz).ok();
                let wall = r.wall_s.max(1e-9);
                box_rows.push((
                    kind,
                    vec![
                        Cell::text("rattle box C"),
                        Cell::text(kind.name()),
                        Cell::text(tol),
                        Cell::Num(model.end_time_s / wall),
                        Cell::Num(r.integrator.accepted as f64 / wall),
                        Cell::Int(r.integrator.accepted),
                        Cell::Int(r.integrator.rejected),
                        Cell::Num(r.mean_normal_force_n),
                        Cell::Num(r.mean_friction_power_w),
                    ],
                    vdv,
                ));
            }
            Outcome::Timeout { simulated_s } => box_rows.push((
                kind,
                status_row(
                    "rattle box C",
                    kind.name(),
                    &tol,
                    format!("timeout ({budget_s} s wall budget, reached t = {simulated_s:.4} s)"),
                ),
                None,
            )),
            Outcome::Failed(msg) => box_rows.push((
                kind,
                status_row("rattle box C", kind.name(), &tol, format!("failed: {msg}")),
                None,
            )),
        }
    }
    push_with_vdv_ratio(&mut table, box_rows);
    // Bouncing sphere.
    let mut sphere_rows = Vec::new();
    let tol = tolerance_text(&Tolerances::default());
    for &kind in &kinds {
        eprintln!("engine: bouncing sphere, {} ...", kind.name());
        match sphere_bounce(kind, sphere_duration, budget) {
            Outcome::Done(s) => {
                let wall = s.wall_s.max(1e-9);
                sphere_rows.push((
                    kind,
                    vec![
                        Cell::text("sphere bounce (Hertz)"),
                        Cell::text(kind.name()),
                        Cell::text(tol.clone()),
                        Cell::Num(s.simulated_s / wall),
                        Cell::Num(s.accepted as f64 / wall),
                        Cell::Int(s.accepted),
                        Cell::Int(s.rejected),
                        Cell::Num(s.mean_normal_force_n),
                        Cell::Num(s.mean_friction_power_w),
                    ],
                    s.vdv_y,
                ));
            }
            Outcome::Timeout { simulated_s } => sphere_rows.push((
                kind,
                status_row(
                    "sphere bounce (Hertz)",
                    kind.name(),
                    &tol,
                    format!("timeout ({budget_s} s wall budget, reached t = {simulated_s:.4} s)"),
                ),
                None,
            )),
            Outcome::Failed(msg) => sphere_rows.push((
                kind,
                status_row(
                    "sphere bounce (Hertz)",
                    kind.name(),
                    &tol,
                    format!("failed: {msg}"),
                ),
                None,
            )),
        }
    }
    push_with_vdv_ratio(&mut table, sphere_rows);
    let mass = 2810.0 * 4.0 / 3.0 * std::f64::consts::PI * SPHERE_RADIUS_M.powi(3);
    table.note(
        "rattle box C: configs/rattle-box-c.toml (Table 5.2 contact, 15 g 20 Hz), tracks not \
         recorded; real-time factor = (settle + window) / wall; steps/s = accepted steps / wall; \
         means over the window only; VDV (eq. 2.51) of the cube's x acceleration over the window",
    );
    table.note(format!(
        "sphere: R = 50 mm 7075 sphere dropped {SPHERE_DROP_M} m onto a half-space, Hertz \
         k = 4/3 E* sqrt(R), e = 1.5, no damping (elastic); means over the whole run, VDV of the \
         vertical acceleration; over whole bounces the mean normal force is m g = {:.3} N",
        mass * railwear::units::STANDARD_GRAVITY
    ));
    table.note("timeout = cancelled through RunControl after the wall budget (--budget)");
    table.note(machine_note());
    Ok(vec![table])
}

/// Appends rows with the VDV column normalised to the trbdf2 row of the same case.
fn push_with_vdv_ratio(table: &mut Table, rows: Vec<(IntegratorKind, Vec<Cell>, Option<f64>)>) {
    let reference = rows
        .iter()
        .find(|(k, _, _)| *k == IntegratorKind::Trbdf2)
        .and_then(|(_, _, v)| *v);
    for (_, mut cells, vdv) in rows {
        // Status rows (timeout, failure) already fill every column.
        if cells.len() == ENGINE_COLUMNS.len() {
            table.row(cells);
            continue;
        }
        let ratio = match (vdv, reference) {
            (Some(v), Some(r)) if r > 0.0 => Some(v / r),
            _ => None,
        };
        cells.push(Cell::opt(ratio));
        table.row(cells);
    }
}

// ---------------------------------------------------------------------------------------------
// peers

fn peers(
    configs_dir: &Path,
    with_peers: bool,
    peers_json: Option<&Path>,
    settle: f64,
    window: f64,
    peer_args: &str,
) -> Result<Vec<Table>> {
    let mut peer_rows: Vec<Value> = Vec::new();
    let mut notes = Vec::new();
    if with_peers {
        let script = Path::new("bench/peers/run_peers.sh");
        let mut cmd = std::process::Command::new("bash");
        cmd.arg(script)
            .args([
                "--window",
                &window.to_string(),
                "--settle",
                &settle.to_string(),
            ])
            .args(peer_args.split_whitespace())
            .stderr(std::process::Stdio::inherit());
        eprintln!("peers: running {} (MuJoCo, Drake) ...", script.display());
        let out = cmd.output().context("running bench/peers/run_peers.sh")?;
        if !out.status.success() {
            notes.push(format!("run_peers.sh exited with {}", out.status));
        }
        peer_rows.extend(parse_json_lines(&String::from_utf8_lossy(&out.stdout)));
        notes.push(format!(
            "peers measured in this run by bench/peers/run_peers.sh --window {window} --settle {settle} {peer_args}"
        ));
    } else if let Some(path) = peers_json {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        peer_rows.extend(parse_json_lines(&text));
        notes.push(format!(
            "peer rows read from {} (an earlier run), not measured in this run",
            path.display()
        ));
    } else {
        notes.push("no peer rows: pass --with-peers (or --peers-json FILE)".into());
    }
    // railwear in each engine variant (the default first), so the engine changes are measured
    // in the same run as the peers.
    let mut ours_rows = Vec::new();
    for variant in ENGINE_VARIANTS {
        eprintln!("peers: railwear rattle box C ({}) ...", variant.name);
        let (_, model, mut options) =
            rattle_box_c(configs_dir, settle, window, IntegratorKind::Trbdf2)?;
        options.integrator.newton = variant.newton;
        options.integrator.patches = variant.patches;
        let run = run_model(&model, &options, &RunControl::silent())
            .map_err(|e| anyhow!("railwear rattle box C: {e}"))?;
        ours_rows.push((variant, model.end_time_s, options, run));
    }
    let rw_rtf = ours_rows[0].1 / ours_rows[0].3.wall_s.max(1e-9);
    let mut table = Table::new(
        format!("Rattle box case C side by side (settle {settle} s, window {window} s, one run)"),
        &[
            ("engine", "engine"),
            ("contact_law", "contact law"),
            ("step_or_tolerance", "step or tolerance"),
            ("real_time_factor", "real-time factor"),
            ("real_time_factor_cpu", "real-time factor (CPU time)"),
            ("steps_per_s", "steps/s"),
            ("mean_normal_force_n", "mean normal force N"),
            ("mean_friction_power_w", "mean N·\\|v_slip\\| W"),
            ("ratio_vs_mujoco", "railwear RTF / this RTF"),
        ],
    );
    for (variant, end_time_s, options, run) in &ours_rows {
        let rtf = end_time_s / run.wall_s.max(1e-9);
        let newton_name = variant.name;
        table.row(vec![
            Cell::text(format!("railwear {}", env!("CARGO_PKG_VERSION"))),
            Cell::text("IMPACT eq. 2.1-2.3, Table 5.2 (k 1000 N/mm², e 2, c_max 500 N·s/mm, d 0.01 mm); ADAMS friction eq. 4.5"),
            Cell::text(format!(
                "trbdf2 {}, {newton_name}",
                tolerance_text(&options.integrator.tolerances)
            )),
            Cell::Num(rtf),
            Cell::text("-"),
            Cell::Num(run.integrator.accepted as f64 / run.wall_s.max(1e-9)),
            Cell::Num(run.mean_normal_force_n),
            Cell::Num(run.mean_friction_power_w),
            Cell::Num(rw_rtf / rtf),
        ]);
    }
    let mut mujoco_best: Option<f64> = None;
    let mut mujoco_converged: Option<f64> = None;
    for p in &peer_rows {
        let engine = p.get("engine").and_then(Value::as_str).unwrap_or("?");
        let status = p.get("status").and_then(Value::as_str);
        if let Some(st) = status {
            let reason = p.get("reason").and_then(Value::as_str).unwrap_or("");
            table.row(vec![
                Cell::text(engine),
                Cell::text(format!("{st}: {reason}")),
                Cell::text(
                    p.get("step_s")
                        .and_then(Value::as_f64)
                        .map(|s| format!("step {s:e} s"))
                        .unwrap_or_else(|| "-".into()),
                ),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
                Cell::text("-"),
            ]);
            continue;
        }
        let f = |k: &str| p.get(k).and_then(Value::as_f64);
        let version = p.get("version").and_then(Value::as_str).unwrap_or("");
        let drive = p.get("drive").and_then(Value::as_str).unwrap_or("");
        let mocap = drive.starts_with("mocap");
        let rtf = f("real_time_factor");
        if engine == "mujoco" && !mocap {
            if let Some(r) = rtf {
                mujoco_best = Some(mujoco_best.map_or(r, |b: f64| b.max(r)));
                // The step at which MuJoCo's friction power has converged (issue 5: 5e-5 s).
                if f("step_s").is_some_and(|s| (s - 5e-5).abs() < 1e-12) {
                    mujoco_converged = Some(r);
                }
            }
        }
        table.row(vec![
            Cell::text(format!(
                "{engine} {version}{}",
                if mocap { " (mocap drive)" } else { "" }
            )),
            Cell::text(p.get("contact_law").and_then(Value::as_str).unwrap_or("?")),
            Cell::text(
                f("step_s")
                    .map(|s| format!("step {s:e} s"))
                    .unwrap_or_else(|| "-".into()),
            ),
            Cell::opt(rtf),
            Cell::opt(f("real_time_factor_cpu")),
            Cell::opt(f("steps_per_s")),
            Cell::opt(f("mean_normal_force_n")),
            Cell::opt(f("mean_friction_power_w")),
            Cell::opt(rtf.filter(|r| *r > 0.0).map(|r| rw_rtf / r)),
        ]);
    }
    for n in notes {
        table.note(n);
    }
    if let Some(m) = mujoco_converged {
        table.note(format!(
            "railwear / MuJoCo at its converged 5e-5 s step, real-time factor: {:.2} (issue 5 target >= 3)",
            rw_rtf / m
        ));
    }
    if let Some(m) = mujoco_best {
        table.note(format!(
            "railwear / MuJoCo (fastest accelerating-frame row, the strictest reading) real-time factor: {:.2}",
            rw_rtf / m
        ));
    }
    table.note(
        "railwear solves the thesis' IMPACT law (near-plastic nanosecond impacts); MuJoCo and Drake \
         use their own softer contact tuned to near-zero rebound (bench/peers/README.md). The \
         rattle is chaotic: window means scatter 10-20 % between engines and settings",
    );
    table.note(
        "railwear's wall time is the whole run (settle + window) in this process, one thread, no \
         track recording; the peers' is their compiled stepping loop (rollout / AdvanceTo)",
    );
    table.note(machine_note());
    Ok(vec![table])
}

fn parse_json_lines(text: &str) -> Vec<Value> {
    text.lines()
        .filter_map(|l| serde_json::from_str::<Value>(l.trim()).ok())
        .filter(|v| v.is_object())
        .collect()
}

// ---------------------------------------------------------------------------------------------
// launcher

fn launcher_case(configs_dir: &Path, settle: f64, window: f64) -> Result<CaseSpec> {
    let mut case = load_case(&configs_dir.join("launcher-design.toml"))?;
    case.simulation.settle_s = settle;
    case.simulation.duration_s = window;
    case.simulation.record_interval_s = case.simulation.record_interval_s.min(window);
    Ok(case)
}

/// VmHWM (peak resident set) and VmRSS of this process, kB.
fn vm_kb(key: &str) -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines()
        .find(|l| l.starts_with(key))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
}

fn launcher(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    mem_window: f64,
    no_mem: bool,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0 && mem_window > 0.0) {
        bail!("--settle must be >= 0 and --window, --mem-window > 0");
    }
    let mut t = Table::new(
        "Launcher reference run (launcher-design, AH-64 transverse profile)",
        &[
            ("run", "run"),
            ("simulated_s", "simulated s"),
            ("tolerance", "tolerance"),
            ("real_time_factor", "real-time factor"),
            ("steps_per_s", "steps/s"),
            ("accepted", "accepted"),
            ("rejected", "rejected"),
            ("track_samples", "track samples stored"),
            ("peak_rss_mb", "peak RSS MB"),
            ("rail_wear_mg_per_h", "rail wear mg/h"),
        ],
    );
    let case = launcher_case(configs_dir, settle, window)?;
    let options = run_options(&case)?;
    // Every engine variant (the default first) for the same-run comparison.
    for engine in ENGINE_VARIANTS {
        let mut variant = case.clone();
        variant.simulation.newton_jacobian = engine.newton;
        variant.simulation.contact_patches = engine.patches;
        eprintln!("launcher: timed run ({}) ...", engine.name);
        let (report, _) = run_case(&variant, configs_dir, &RunControl::silent())
            .map_err(|e| anyhow!("launcher run: {e}"))?;
        let simulated = settle + window;
        let wall = report.wall_s.max(1e-9);
        let rail = rail_wear_mg_per_h(&report);
        let newton_name = engine.name;
        t.row(vec![
            Cell::text(format!(
                "timed: settle {settle} s + window {window} s, {newton_name}"
            )),
            Cell::Num(simulated),
            Cell::text(tolerance_text(&options.integrator.tolerances)),
            Cell::Num(simulated / wall),
            Cell::Num(report.integrator.accepted as f64 / wall),
            Cell::Int(report.integrator.accepted),
            Cell::Int(report.integrator.rejected),
            Cell::Int(report.tracks.len() as u64),
            Cell::opt(vm_kb("VmHWM:").map(|k| k as f64 / 1024.0)),
            Cell::opt(rail),
        ]);
    }
    if !no_mem {
        eprintln!("launcher: memory run (settle {settle} s + window {mem_window} s) in a child process ...");
        let exe = std::env::current_exe().context("locating railwear-bench")?;
        let out = std::process::Command::new(exe)
            .arg("--configs-dir")
            .arg(configs_dir)
            .args([
                "launcher-mem",
                "--settle",
                &settle.to_string(),
                "--window",
                &mem_window.to_string(),
            ])
            .stderr(std::process::Stdio::inherit())
            .output()
            .context("running the memory child")?;
        let line = String::from_utf8_lossy(&out.stdout);
        let v: Value = parse_json_lines(&line)
            .into_iter()
            .next()
            .ok_or_else(|| anyhow!("memory child printed no result ({})", out.status))?;
        let f = |k: &str| v.get(k).and_then(Value::as_f64);
        let sim = f("simulated_s").unwrap_or(f64::NAN);
        let label = if (sim - 60.0).abs() < 1e-9 {
            format!(
                "memory: 60 s run (settle {settle} s + window {mem_window} s), all tracks stored"
            )
        } else {
            format!(
                "memory: SHORTENED to {sim} s (settle {settle} s + window {mem_window} s; the target is a 60 s run), all tracks stored"
            )
        };
        t.row(vec![
            Cell::text(label),
            Cell::Num(sim),
            Cell::text(tolerance_text(&options.integrator.tolerances)),
            Cell::opt(f("real_time_factor")),
            Cell::opt(f("steps_per_s")),
            Cell::Int(f("accepted").unwrap_or(0.0) as u64),
            Cell::Int(f("rejected").unwrap_or(0.0) as u64),
            Cell::Int(f("track_samples").unwrap_or(0.0) as u64),
            Cell::opt(f("vm_hwm_kb").map(|k| k / 1024.0)),
            Cell::opt(f("rail_wear_mg_per_h")),
        ]);
        if let (Some(b), Some(h)) = (f("baseline_hwm_kb"), f("vm_hwm_kb")) {
            t.note(format!(
                "memory run: peak RSS (VmHWM of a fresh child process) {:.1} MB; {:.1} MB before the run \
                 (binary, configs); track sample = {} bytes in memory, recorded every {} s per active track; \
                 the run as the service does it (run_case: report plus packaged outcome, tracks held twice)",
                h / 1024.0,
                b / 1024.0,
                f("track_sample_bytes").unwrap_or(f64::NAN),
                case.simulation.record_interval_s
            ));
            if let (Some(n), Some(bytes)) = (f("track_samples"), f("track_sample_bytes")) {
                if sim < 60.0 && mem_window > 0.0 {
                    // Samples accrue over the window only (recording starts with the excitation).
                    let n60 = n * (60.0 - settle).max(0.0) / mem_window;
                    let est_mb = h / 1024.0 + (n60 - n) * bytes * 2.0 / 1048576.0;
                    t.note(format!(
                        "ESTIMATE, not measured: at this run's rate a 60 s run stores about {n60:.0}                          track samples; with two copies of {bytes} bytes each the peak would be about                          {est_mb:.0} MB (plus up to 2x Vec growth slack on the track buffers)"
                    ));
                }
            }
        }
    }
    t.note(
        "real-time factor = (settle + window) / wall of the simulation loop (track recording \
         included, as configured); one thread",
    );
    t.note(machine_note());
    Ok(vec![t])
}

/// Wear rate of the launcher's rail body, mg/h.
fn rail_wear_mg_per_h(report: &RunReport) -> Option<f64> {
    report
        .bodies
        .iter()
        .find(|b| b.name == "rail")
        .map(|b| b.mass_rate_mg_per_h)
}

fn launcher_mem(configs_dir: &Path, settle: f64, window: f64) -> Result<()> {
    let baseline = vm_kb("VmHWM:");
    let case = launcher_case(configs_dir, settle, window)?;
    let (report, outcome) = run_case(&case, configs_dir, &RunControl::silent())
        .map_err(|e| anyhow!("launcher memory run: {e}"))?;
    let hwm = vm_kb("VmHWM:");
    let simulated = settle + window;
    let wall = report.wall_s.max(1e-9);
    let rail = rail_wear_mg_per_h(&report);
    println!(
        "{}",
        json!({
            "simulated_s": simulated,
            "wall_s": report.wall_s,
            "real_time_factor": simulated / wall,
            "steps_per_s": report.integrator.accepted as f64 / wall,
            "accepted": report.integrator.accepted,
            "rejected": report.integrator.rejected,
            "track_samples": outcome.tracks.len(),
            "track_sample_bytes": std::mem::size_of::<railwear::physics::track::TrackSample>(),
            "vm_hwm_kb": hwm,
            "baseline_hwm_kb": baseline,
            "rail_wear_mg_per_h": rail,
        })
    );
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// sweep

/// Settings of the `sweep` benchmark.
struct SweepBench {
    points: u64,
    sweeps: usize,
    repeats: usize,
    settle: f64,
    window: f64,
}

/// Median of a non-empty list (mean of the middle two for an even length).
fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let mid = v.len() / 2;
    if v.len() % 2 == 1 {
        v[mid]
    } else {
        0.5 * (v[mid - 1] + v[mid])
    }
}

/// Runs `sweeps` whole sweeps on `workers` threads taking them from a queue; returns the
/// simulations run and the wall time, s.
fn timed_sweeps(
    configs_dir: &Path,
    params: &serde_json::Value,
    sweeps: usize,
    workers: usize,
) -> Result<(usize, f64)> {
    let next = Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let start = Instant::now();
    let results: Vec<Result<usize, String>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                let next = next.clone();
                s.spawn(move || -> Result<usize, String> {
                    let mut done = 0;
                    while next.fetch_add(1, Ordering::Relaxed) < sweeps {
                        let (_, out) = railwear::pipeline::sweep_job(
                            params,
                            configs_dir,
                            &RunControl::silent(),
                        )
                        .map_err(|e: RunError| e.to_string())?;
                        done += out.points.len();
                    }
                    Ok(done)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err("worker panicked".into())))
            .collect()
    });
    let wall = start.elapsed().as_secs_f64();
    let mut sims = 0;
    for r in results {
        sims += r.map_err(|e| anyhow!("sweep failed: {e}"))?;
    }
    Ok((sims, wall))
}

fn sweep(configs_dir: &Path, b: SweepBench) -> Result<Vec<Table>> {
    let SweepBench {
        points,
        sweeps,
        repeats,
        settle,
        window,
    } = b;
    if !(settle >= 0.0 && window > 0.0)
        || sweeps == 0
        || repeats == 0
        || !(2..=50).contains(&points)
    {
        bail!("--settle >= 0, --window > 0, --sweeps >= 1, --repeats >= 1, --points in 2..=50");
    }
    let params = json!({
        "config": "launcher-design",
        "points": points,
        "overrides": {"simulation": {
            "settle_s": settle,
            "duration_s": window,
            "record_interval_s": window.min(5e-4),
        }},
    });
    let mut t = Table::new(
        format!(
            "Tolerance sweep throughput ({points}-point pipeline::sweep_job of launcher-design, settle {settle} s + window {window} s per point, {sweeps} sweeps per setting, median of {repeats} interleaved pairs)"
        ),
        &[
            ("workers", "workers"),
            ("simulations", "simulations"),
            ("wall_s", "median wall s"),
            ("simulations_per_min", "simulations/min"),
            ("ratio", "throughput / 1 worker"),
        ],
    );
    // One untimed build first: the synthesised random record is shared between runs of the
    // same profile, so both settings are timed with it already made.
    let case = launcher_case(configs_dir, settle, window)?;
    build(&case, configs_dir).map_err(|e| anyhow!("launcher model: {e}"))?;
    let mut walls = [Vec::new(), Vec::new()];
    let mut sims = [0usize; 2];
    let mut pair_ratios = Vec::new();
    for pair in 0..repeats {
        for (slot, workers) in [1usize, 2].into_iter().enumerate() {
            eprintln!(
                "sweep: pair {}/{repeats}, {workers} worker(s) ...",
                pair + 1
            );
            let (n, wall) = timed_sweeps(configs_dir, &params, sweeps, workers)?;
            sims[slot] = n;
            walls[slot].push(wall);
        }
        // Same simulations in both settings: the throughput ratio is the wall-time ratio.
        pair_ratios.push(walls[0][pair] / walls[1][pair]);
    }
    for (slot, workers) in [1usize, 2].into_iter().enumerate() {
        let wall = median(&walls[slot]);
        let ratio = if slot == 0 { 1.0 } else { median(&pair_ratios) };
        t.row(vec![
            Cell::Int(workers as u64),
            Cell::Int(sims[slot] as u64),
            Cell::Num(wall),
            Cell::Num(sims[slot] as f64 / wall * 60.0),
            Cell::Num(ratio),
        ]);
    }
    let listed: Vec<String> = pair_ratios.iter().map(|r| format!("{r:.3}")).collect();
    t.note(format!(
        "ratio = median over the pairs of (wall with 1 worker) / (wall with 2 workers); each pair: {}",
        listed.join(", ")
    ));
    t.note(
        "workers are threads taking whole sweeps from a queue (as the service's worker pool \
         takes jobs); 2 workers can reach 2x only with 2 idle cores",
    );
    t.note("issue 5 target: 2 workers >= 1.8x the throughput of 1 worker");
    t.note(machine_note());
    Ok(vec![t])
}

// ---------------------------------------------------------------------------------------------
// sweep-procs: a fanned-out sweep on PostgreSQL with 1 and 2 `railwear worker` processes

/// A database created for the benchmark, dropped on drop.
struct BenchDb {
    admin_url: String,
    name: String,
    url: String,
}

impl BenchDb {
    async fn create(admin_url: &str) -> Result<Self> {
        use sqlx::Connection;
        let mut conn = sqlx::postgres::PgConnection::connect(admin_url)
            .await
            .with_context(|| format!("connecting to {admin_url}"))?;
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let name = format!("railwear_bench_{}_{stamp}", std::process::id());
        sqlx::query(&format!("CREATE DATABASE \"{name}\""))
            .execute(&mut conn)
            .await
            .with_context(|| format!("CREATE DATABASE {name}"))?;
        let _ = conn.close().await;
        // Same server and credentials, other database: replace the URL's path.
        let (base, query) = admin_url.split_once('?').unwrap_or((admin_url, ""));
        let host_start = base.find("://").map_or(0, |i| i + 3);
        let host_end = base[host_start..]
            .find('/')
            .map_or(base.len(), |i| host_start + i);
        let mut url = format!("{}/{name}", &base[..host_end]);
        if !query.is_empty() {
            url.push('?');
            url.push_str(query);
        }
        Ok(Self {
            admin_url: admin_url.to_string(),
            name,
            url,
        })
    }
}

impl Drop for BenchDb {
    fn drop(&mut self) {
        let (admin_url, name) = (self.admin_url.clone(), self.name.clone());
        // Drop may run inside a runtime: use one of our own on a plain thread.
        let dropped = std::thread::spawn(move || -> Option<()> {
            use sqlx::Connection;
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .ok()?;
            rt.block_on(async {
                let mut conn = sqlx::postgres::PgConnection::connect(&admin_url)
                    .await
                    .ok()?;
                sqlx::query(&format!("DROP DATABASE IF EXISTS \"{name}\" WITH (FORCE)"))
                    .execute(&mut conn)
                    .await
                    .ok()?;
                conn.close().await.ok()
            })
        })
        .join();
        if !matches!(dropped, Ok(Some(()))) {
            eprintln!("warning: could not drop benchmark database {}", self.name);
        }
    }
}

/// CPU time of this process's reaped children (user + system), s, from /proc/self/stat
/// (`cutime`, `cstime` in USER_HZ ticks, 100 per second on Linux).
fn reaped_children_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name `(...)`: state is field 3, cutime 16, cstime 17.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(13)? + ticks(14)?) / 100.0)
}

/// Worker processes, killed (SIGKILL) and reaped on drop.
struct Workers(Vec<std::process::Child>);

impl Drop for Workers {
    fn drop(&mut self) {
        for child in &mut self.0 {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

fn sweep_procs(
    configs_dir: &Path,
    bin: &Path,
    admin_url: &str,
    points: u64,
    settle: f64,
    window: f64,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0 && (2..=50).contains(&points)) {
        bail!("--settle >= 0, --window > 0, --points in 2..=50");
    }
    if !bin.exists() {
        bail!(
            "{} not found: build it first (cargo build --release)",
            bin.display()
        );
    }
    let configs_abs = std::fs::canonicalize(configs_dir).unwrap_or(configs_dir.to_path_buf());
    let params = json!({
        "config": "launcher-design",
        "points": points,
        "seed": 6,
        "overrides": {"simulation": {
            "settle_s": settle,
            "duration_s": window,
            "record_interval_s": window.min(5e-4),
        }},
    });
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    let db = rt.block_on(BenchDb::create(admin_url))?;
    let store = rt.block_on(railwear::store::open(&db.url))?;
    // Submissions go through the job system as an API process would (no workers here).
    let jobs = railwear::jobs::Jobs::new(
        Arc::clone(&store),
        Arc::new(railwear::jobs::LibraryRunner {
            configs_dir: configs_abs.clone(),
        }),
        railwear::jobs::WorkerSettings {
            lease: Duration::from_secs(15),
            heartbeat: Duration::from_secs(1),
            poll: Duration::from_millis(100),
            max_attempts: 3,
            track_block_samples: 4096,
        },
        railwear::jobs::CurveDefaults {
            vehicle_profile: "ah64".into(),
            environment: "bench".into(),
            wear_law: "modified-archard".into(),
        },
    );
    let mut t = Table::new(
        format!(
            "Fanned-out sweep on PostgreSQL ({points}-point sweep job of launcher-design, settle {settle} s + window {window} s per point, one `railwear worker --workers 1` per process)"
        ),
        &[
            ("worker_processes", "worker processes"),
            ("points", "sweep points"),
            ("wall_s", "wall s"),
            ("simulations_per_min", "simulations/min"),
            ("ratio", "ratio to 1 process"),
            ("cores_used", "worker CPU s / wall s"),
            ("points_per_process", "points run per process"),
        ],
    );
    let mut base: Option<f64> = None;
    let mut summaries = Vec::new();
    for procs in [1usize, 2] {
        eprintln!("sweep-procs: {procs} worker process(es) ...");
        let submitted = rt.block_on(jobs.submit(
            railwear::jobs::JobKind::Sweep,
            params.clone(),
            "bench",
            None,
        ));
        let id = match submitted {
            Ok(railwear::store::Submitted::Created(job)) => job.id,
            Ok(other) => bail!("unexpected submission answer {other:?}"),
            Err(e) => bail!("submission refused: {e}"),
        };
        let cpu_before = reaped_children_cpu_s();
        let start = Instant::now();
        let mut workers = Workers(Vec::new());
        for _ in 0..procs {
            let child = std::process::Command::new(bin)
                .args(["worker", "--database-url", &db.url, "--workers", "1"])
                .env("RAILWEAR_CONFIGS_DIR", &configs_abs)
                .env("RUST_LOG", "warn")
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::inherit())
                .spawn()
                .with_context(|| format!("starting {}", bin.display()))?;
            workers.0.push(child);
        }
        let job = loop {
            std::thread::sleep(Duration::from_millis(100));
            let job = rt
                .block_on(store.get_job(id))?
                .ok_or_else(|| anyhow!("job {id} vanished"))?;
            if job.status.is_terminal() {
                break job;
            }
            if start.elapsed() > Duration::from_secs(3600) {
                bail!("sweep {id} not done within an hour");
            }
        };
        let wall = start.elapsed().as_secs_f64();
        drop(workers);
        let cores_used = match (cpu_before, reaped_children_cpu_s()) {
            (Some(a), Some(b)) => Some((b - a) / wall),
            _ => None,
        };
        // Which process ran each point (the succeeded attempt's lease owner, `<host>-<pid>-0`).
        let mut per_worker: std::collections::BTreeMap<String, u64> = Default::default();
        for child in rt.block_on(store.children(id))? {
            for a in rt.block_on(store.attempts(child.id))? {
                if a.outcome == railwear::store::AttemptOutcome::Succeeded {
                    *per_worker.entry(a.worker).or_default() += 1;
                }
            }
        }
        let spread = per_worker
            .values()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(" + ");
        if job.status != railwear::jobs::JobStatus::Succeeded {
            bail!(
                "sweep {id} ended {}: {}",
                job.status.as_str(),
                job.error.unwrap_or_default()
            );
        }
        summaries.push(job.result);
        let per_min = points as f64 / wall * 60.0;
        let ratio = base.map(|b| per_min / b).unwrap_or(1.0);
        base.get_or_insert(per_min);
        t.row(vec![
            Cell::Int(procs as u64),
            Cell::Int(points),
            Cell::Num(wall),
            Cell::Num(per_min),
            Cell::Num(ratio),
            Cell::opt(cores_used),
            Cell::text(spread),
        ]);
    }
    t.note(format!(
        "wall: from starting the worker processes to the sweep's assembled result (fan-out, \
         {points} child jobs, assembly); the two runs' results are {}",
        if summaries.windows(2).all(|w| w[0] == w[1]) {
            "identical"
        } else {
            "DIFFERENT"
        }
    ));
    t.note(
        "2 processes can reach 2x only with 2 idle cores: `worker CPU s / wall s` is how many \
         cores the worker processes got (the rest went to other load on the machine)",
    );
    t.note(machine_note());
    drop(store);
    drop(jobs);
    drop(rt);
    drop(db);
    Ok(vec![t])
}

// ---------------------------------------------------------------------------------------------
// load: a minimal HTTP/1.1 keep-alive client on tokio (no HTTP client crate in the tree)

mod http1 {
    use tokio::io::{AsyncBufReadExt, AsyncReadExt, AsyncWriteExt, BufReader};
    use tokio::net::TcpStream;

    pub struct Conn {
        addr: String,
        stream: Option<BufReader<TcpStream>>,
    }

    fn bad(msg: impl Into<String>) -> std::io::Error {
        std::io::Error::new(std::io::ErrorKind::InvalidData, msg.into())
    }

    impl Conn {
        pub fn new(addr: &str) -> Self {
            Self {
                addr: addr.to_string(),
                stream: None,
            }
        }

        /// One request; reconnects when the server closed the connection.
        pub async fn request(
            &mut self,
            method: &str,
            path: &str,
            token: &str,
            body: Option<&str>,
        ) -> std::io::Result<(u16, Vec<u8>)> {
            for attempt in 0..2 {
                match self.try_request(method, path, token, body).await {
                    Ok(r) => return Ok(r),
                    Err(e) if attempt == 0 => {
                        self.stream = None;
                        let _ = e;
                    }
                    Err(e) => return Err(e),
                }
            }
            Err(bad("unreachable"))
        }

        async fn try_request(
            &mut self,
            method: &str,
            path: &str,
            token: &str,
            body: Option<&str>,
        ) -> std::io::Result<(u16, Vec<u8>)> {
            if self.stream.is_none() {
                let s = TcpStream::connect(&self.addr).await?;
                s.set_nodelay(true)?;
                self.stream = Some(BufReader::new(s));
            }
            let Some(stream) = self.stream.as_mut() else {
                return Err(bad("no connection"));
            };
            let mut req = format!(
                "{method} {path} HTTP/1.1\r\nHost: {}\r\nAuthorization: Bearer {token}\r\n",
                self.addr
            );
            if let Some(b) = body {
                req.push_str(&format!(
                    "Content-Type: application/json\r\nContent-Length: {}\r\n",
                    b.len()
                ));
            }
            req.push_str("\r\n");
            if let Some(b) = body {
                req.push_str(b);
            }
            stream.get_mut().write_all(req.as_bytes()).await?;
            let mut line = String::new();
            if stream.read_line(&mut line).await? == 0 {
                return Err(bad("connection closed"));
            }
            let status: u16 = line
                .split_whitespace()
                .nth(1)
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| bad(format!("bad status line {line:?}")))?;
            let mut content_length: Option<usize> = None;
            let mut chunked = false;
            let mut close = false;
            loop {
                line.clear();
                if stream.read_line(&mut line).await? == 0 {
                    return Err(bad("connection closed in headers"));
                }
                let h = line.trim_end();
                if h.is_empty() {
                    break;
                }
                if let Some((k, v)) = h.split_once(':') {
                    let k = k.trim().to_ascii_lowercase();
                    let v = v.trim();
                    match k.as_str() {
                        "content-length" => content_length = v.parse().ok(),
                        "transfer-encoding" => chunked = v.eq_ignore_ascii_case("chunked"),
                        "connection" => close = v.eq_ignore_ascii_case("close"),
                        _ => {}
                    }
                }
            }
            let mut body = Vec::new();
            if chunked {
                loop {
                    line.clear();
                    stream.read_line(&mut line).await?;
                    let n = usize::from_str_radix(line.trim().split(';').next().unwrap_or(""), 16)
                        .map_err(|_| bad("bad chunk size"))?;
                    let mut chunk = vec![0u8; n + 2];
                    stream.read_exact(&mut chunk).await?;
                    if n == 0 {
                        break;
                    }
                    body.extend_from_slice(&chunk[..n]);
                }
            } else if let Some(n) = content_length {
                body.resize(n, 0);
                stream.read_exact(&mut body).await?;
            } else {
                stream.read_to_end(&mut body).await?;
                close = true;
            }
            if close {
                self.stream = None;
            }
            Ok((status, body))
        }
    }
}

fn percentile(sorted: &[u64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)] as f64
}

struct Server {
    child: std::process::Child,
    addr: String,
    dir: PathBuf,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn start_server(bin: &Path, configs_dir: &Path, tokens: &str) -> Result<Server> {
    use std::io::BufRead;
    if !bin.exists() {
        bail!(
            "{} not found: build it first (cargo build --release)",
            bin.display()
        );
    }
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let dir = std::env::temp_dir().join(format!("railwear-bench-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let db = format!("sqlite://{}?mode=rwc", dir.join("bench.db").display());
    let mut child = std::process::Command::new(bin)
        .args(["serve", "--listen", "127.0.0.1:0", "--workers", "2"])
        .env("DATABASE_URL", &db)
        .env("RAILWEAR_TOKENS", tokens)
        .env("RAILWEAR_CONFIGS_DIR", configs_dir)
        .env("RUST_LOG", "warn")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::inherit())
        .spawn()
        .with_context(|| format!("starting {}", bin.display()))?;
    let Some(stdout) = child.stdout.take() else {
        let _ = child.kill();
        bail!("no stdout from the server");
    };
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
        {
            if let Some(a) = line.strip_prefix("listening on http://") {
                let _ = tx.send(a.trim().to_string());
            }
        }
    });
    let mut server = Server {
        child,
        addr: String::new(),
        dir,
    };
    server.addr = rx
        .recv_timeout(Duration::from_secs(60))
        .context("the server did not print `listening on http://ADDR` within 60 s")?;
    Ok(server)
}

fn json_body(b: &[u8]) -> Value {
    serde_json::from_slice(b).unwrap_or(Value::Null)
}

#[allow(clippy::too_many_arguments)]
fn load(
    configs_dir: &Path,
    bin: &Path,
    rails: usize,
    concurrency: usize,
    seconds: f64,
    curve: bool,
    client_threads: usize,
) -> Result<Vec<Table>> {
    if rails == 0
        || concurrency == 0
        || !(seconds.is_finite() && seconds > 0.0)
        || client_threads == 0
    {
        bail!("--rails, --concurrency, --client-threads >= 1 and --seconds > 0");
    }
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let planner = format!("bench-planner-{stamp:x}");
    let engineer = format!("bench-engineer-{stamp:x}");
    let tokens = format!("bench-p:planner:{planner},bench-e:engineer:{engineer}");
    let configs_abs = std::fs::canonicalize(configs_dir).unwrap_or(configs_dir.to_path_buf());
    let server = start_server(bin, &configs_abs, &tokens)?;
    eprintln!("load: server at {}", server.addr);
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(client_threads)
        .enable_all()
        .build()?;
    let addr = server.addr.clone();
    let result = rt.block_on(load_async(
        addr,
        planner,
        engineer,
        rails,
        concurrency,
        seconds,
        curve,
    ));
    drop(server);
    result
}

async fn load_async(
    addr: String,
    planner: String,
    engineer: String,
    rails: usize,
    concurrency: usize,
    seconds: f64,
    curve: bool,
) -> Result<Vec<Table>> {
    use http1::Conn;
    let mut notes = Vec::new();
    let mut conn = Conn::new(&addr);
    // Optional short sweep so that reports compute K_SL from a stored curve.
    let mut curve_text = "none (reports answer `missing_curve`)".to_string();
    if curve {
        eprintln!("load: short sweep job for a penalization curve ...");
        let body = json!({"kind": "sweep", "params": {
            "config": "launcher-design", "points": 3,
            "overrides": {"simulation": {"settle_s": 0.1, "duration_s": 0.1, "record_interval_s": 0.01}}}})
        .to_string();
        let (st, b) = conn
            .request("POST", "/v1/jobs", &engineer, Some(&body))
            .await?;
        let id = json_body(&b)
            .get("id")
            .and_then(Value::as_str)
            .map(str::to_string);
        match id {
            Some(id) if st < 300 => {
                let t0 = Instant::now();
                loop {
                    tokio::time::sleep(Duration::from_millis(500)).await;
                    let (_, b) = conn
                        .request("GET", &format!("/v1/jobs/{id}"), &engineer, None)
                        .await?;
                    let status = json_body(&b)
                        .get("status")
                        .and_then(Value::as_str)
                        .unwrap_or("")
                        .to_string();
                    if status == "succeeded" {
                        curve_text = format!(
                            "3-point sweep job (0.1 s + 0.1 s per point) done in {:.0} s",
                            t0.elapsed().as_secs_f64()
                        );
                        break;
                    }
                    if status == "failed" || status == "cancelled" {
                        curve_text = format!("sweep job {status}; reports answer `missing_curve`");
                        break;
                    }
                    if t0.elapsed() > Duration::from_secs(600) {
                        curve_text =
                            "sweep job not done in 600 s; reports answer `missing_curve`".into();
                        break;
                    }
                }
            }
            _ => curve_text = format!("sweep submission answered {st}"),
        }
    }
    // Store the rails concurrently.
    eprintln!("load: storing {rails} rails ...");
    let offsets = railwear::pipeline::sweep_offsets_mm(11);
    let t_store = Instant::now();
    let next = Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let mut tasks = Vec::new();
    for _ in 0..concurrency.min(16) {
        let next = next.clone();
        let addr = addr.clone();
        let planner = planner.clone();
        let offsets = offsets.clone();
        tasks.push(tokio::spawn(async move {
            let mut c = Conn::new(&addr);
            let mut failures = 0usize;
            loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= rails {
                    break;
                }
                let dims = LauncherDimensions::design()
                    .with_material_condition(offsets[i % offsets.len()]);
                let body = json!({
                    "dimensions_mm": dims,
                    "measured_by": "railwear-bench",
                    "measured_at": "2024-05-01T08:30:00Z",
                    "location": "loopback",
                })
                .to_string();
                match c
                    .request(
                        "POST",
                        &format!("/v1/rails/R-{i:05}/measurements"),
                        &planner,
                        Some(&body),
                    )
                    .await
                {
                    Ok((st, _)) if st < 300 => {}
                    _ => failures += 1,
                }
            }
            failures
        }));
    }
    let mut store_failures = 0;
    for t in tasks {
        store_failures += t.await.unwrap_or(0);
    }
    let store_s = t_store.elapsed().as_secs_f64();
    if store_failures > 0 {
        notes.push(format!("{store_failures} measurement POSTs failed"));
    }
    // Two long simulate jobs.
    let mut job_ids = Vec::new();
    for seed in [1, 2] {
        let body = json!({"kind": "simulate", "params": {"config": "rattle-box-c", "seed": seed,
            "overrides": {"simulation": {"settle_s": 1.0, "duration_s": 3600.0}}}})
        .to_string();
        let (st, b) = conn
            .request("POST", "/v1/jobs", &engineer, Some(&body))
            .await?;
        match json_body(&b).get("id").and_then(Value::as_str) {
            Some(id) if st < 300 => job_ids.push(id.to_string()),
            _ => notes.push(format!(
                "simulate submission answered {st}: {}",
                String::from_utf8_lossy(&b)
            )),
        }
    }
    // Wait until both run.
    let t_wait = Instant::now();
    let mut running = 0;
    while t_wait.elapsed() < Duration::from_secs(30) {
        running = 0;
        for id in &job_ids {
            let (_, b) = conn
                .request("GET", &format!("/v1/jobs/{id}"), &engineer, None)
                .await?;
            if json_body(&b).get("status").and_then(Value::as_str) == Some("running") {
                running += 1;
            }
        }
        if running == job_ids.len() {
            break;
        }
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    // A sample report.
    let (st, b) = conn
        .request("GET", "/v1/rails/R-00000/report", &planner, None)
        .await?;
    let sample = json_body(&b);
    let report_kind = if st != 200 {
        format!("status {st}")
    } else if sample.get("service_life").is_some_and(|v| !v.is_null()) {
        "K_SL and penalized life from the stored curve".to_string()
    } else {
        "rattle space + missing_curve".to_string()
    };
    // The GET load.
    eprintln!("load: {concurrency} tasks x {seconds} s of GET reports ...");
    let deadline = Instant::now() + Duration::from_secs_f64(seconds);
    let t_load = Instant::now();
    let mut tasks = Vec::new();
    for k in 0..concurrency {
        let addr = addr.clone();
        let planner = planner.clone();
        tasks.push(tokio::spawn(async move {
            let mut c = Conn::new(&addr);
            let mut lat_us: Vec<u64> = Vec::with_capacity(4096);
            let mut non_ok = 0usize;
            let mut errors = 0usize;
            let mut x: u64 = 0x9E37_79B9_7F4A_7C15 ^ (k as u64 + 1);
            while Instant::now() < deadline {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let i = (x % rails as u64) as usize;
                let t = Instant::now();
                match c
                    .request("GET", &format!("/v1/rails/R-{i:05}/report"), &planner, None)
                    .await
                {
                    Ok((200, _)) => lat_us.push(t.elapsed().as_micros() as u64),
                    Ok(_) => {
                        non_ok += 1;
                        lat_us.push(t.elapsed().as_micros() as u64);
                    }
                    Err(_) => errors += 1,
                }
            }
            (lat_us, non_ok, errors)
        }));
    }
    let mut lat = Vec::new();
    let mut non_ok = 0;
    let mut errors = 0;
    for t in tasks {
        if let Ok((l, n, e)) = t.await {
            lat.extend(l);
            non_ok += n;
            errors += e;
        }
    }
    let load_s = t_load.elapsed().as_secs_f64();
    lat.sort_unstable();
    // Still running? Then cancel.
    let mut still = 0;
    for id in &job_ids {
        let (_, b) = conn
            .request("GET", &format!("/v1/jobs/{id}"), &engineer, None)
            .await?;
        if json_body(&b).get("status").and_then(Value::as_str) == Some("running") {
            still += 1;
        }
        let _ = conn
            .request("POST", &format!("/v1/jobs/{id}/cancel"), &engineer, None)
            .await;
    }
    let mut t = Table::new(
        "Service load: GET /v1/rails/{serial}/report on loopback",
        &[
            ("rails", "rails stored"),
            ("store_posts_per_s", "store POSTs/s"),
            ("simulations_running", "simulations running (start/end)"),
            ("concurrency", "client tasks"),
            ("seconds", "load s"),
            ("gets", "GETs"),
            ("gets_per_s", "GETs/s"),
            ("p50_ms", "p50 ms"),
            ("p99_ms", "p99 ms"),
            ("non_200", "non-200"),
            ("errors", "I/O errors"),
        ],
    );
    t.row(vec![
        Cell::Int(rails as u64),
        Cell::Num(rails as f64 / store_s),
        Cell::text(format!("{running}/{still}")),
        Cell::Int(concurrency as u64),
        Cell::Num(load_s),
        Cell::Int(lat.len() as u64),
        Cell::Num(lat.len() as f64 / load_s),
        Cell::Num(percentile(&lat, 0.50) / 1000.0),
        Cell::Num(percentile(&lat, 0.99) / 1000.0),
        Cell::Int(non_ok as u64),
        Cell::Int(errors as u64),
    ]);
    t.note(format!(
        "server: target/release binary `railwear serve --workers 2`, fresh SQLite file, the two \
         simulations are rattle box C jobs (3600 s windows, cancelled after the load); report content: {report_kind}; curve: {curve_text}"
    ));
    t.note(
        "client: raw HTTP/1.1 keep-alive on tokio in this process, one connection per task, \
         random serials; client, server and both simulations share the same cores",
    );
    for n in notes {
        t.note(n);
    }
    t.note(machine_note());
    Ok(vec![t])
}
