//! `railwear-bench`: the benchmark programs of issues 2 (item 6), 4 (item 5), 5 and 6 (item 3).
//! Each subcommand prints markdown tables (or, with `--json`, one JSON object per table). These are
//! measurements, not tests: nothing here asserts a number. Wall-clock numbers depend on the load
//! of the machine; the tables say what was run so a reader can repeat it.

use anyhow::{anyhow, bail, Context, Result};
use clap::{Parser, Subcommand};
use nalgebra::{Isometry3, Vector3};
use railwear::analysis::rattle_space::LauncherDimensions;
use railwear::analysis::vdv::vibration_dose_value_uniform;
use railwear::models::case::{build, load_case, run_options};
use railwear::models::run::{run_model, BuiltModel, ModelRunError, RunOptions, RunReport};
use railwear::models::spec::CaseSpec;
use railwear::physics::body::write_state;
use railwear::physics::impact::ImpactParams;
use railwear::physics::integrator::{
    ContactPatches, IntegratorKind, IntegratorSettings, NewtonJacobian, Tolerances,
};
use railwear::physics::simulate::{simulate, DivergenceLimits, SimError, StepView};
use railwear::pipeline::{run_case, Progress, RunControl, RunError};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

mod budget;
mod convergence;
mod engine;
mod face_states;
mod faces;
mod launcher;
mod load;
mod missiles;
mod peers;
mod sweep;
mod sweep_procs;
mod table;

use budget::*;
use convergence::*;
use engine::*;
use launcher::*;
use load::*;
use missiles::*;
use peers::*;
use sweep::*;
use sweep_procs::*;
use table::*;

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
        /// Also run railwear's default engine at these factors on the case tolerance (comma
        /// list; 1 is always run), e.g. the loosest converged one of `convergence --ladder`.
        #[arg(long, default_value = "1")]
        tolerance_factors: String,
        /// Contact points per box edge of those extra runs (default: the case's; given, the
        /// factor 1 runs at it too).
        #[arg(long)]
        points_per_edge: Option<usize>,
        /// Timed runs of each engine row (railwear's and the peers'); the fastest is reported.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
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
        /// Only the engine's default variant in the timed run (the earlier Newton variants
        /// are slow and were measured in earlier passes).
        #[arg(long)]
        default_only: bool,
        /// Windows (s) of the duration-linearity table, comma list (empty: no table).
        #[arg(long, default_value = "")]
        durations: String,
    },
    /// Issue 16's error-control decision: user quantities (friction power, wear rate and
    /// above-cutoff share per contact, response PSD in 1/3-octave bands to 500 Hz) at the
    /// case tolerance and half of it, for full and position-only error control, against a
    /// tight full-control reference, with the chaotic spread of a 1 nm nudge.
    Convergence {
        /// Cases (config names, comma list).
        #[arg(long, default_value = "rattle-box-c,rattle-box-d,launcher-design")]
        cases: String,
        /// Settle time of the rattle boxes, s.
        #[arg(long, default_value_t = 0.5)]
        settle_box: f64,
        /// Settle time of the launcher, s.
        #[arg(long, default_value_t = 1.0)]
        settle_launcher: f64,
        /// Averaging window after the settle, s.
        #[arg(long, default_value_t = 8.0)]
        window: f64,
        /// Tolerance factor of the reference run (full error control).
        #[arg(long, default_value_t = 0.25)]
        reference_factor: f64,
        /// Largest admissible |difference| (0.02 = the 2 %).
        #[arg(long, default_value_t = 0.02)]
        criterion: f64,
        /// Also run the position-only mode without the energy account's work test.
        #[arg(long)]
        with_energy_off: bool,
        /// Instead of the mode study, the tolerance ladder: these factors on the case
        /// tolerance (comma list, e.g. 1,4,16,64), full error control, each against its half
        /// and the reference.
        #[arg(long)]
        ladder: Option<String>,
        /// Ladder: contact points per box edge of its runs (default: the case's).
        #[arg(long)]
        points_per_edge: Option<usize>,
        /// Ladder: contact points per box edge of the reference (default: the case's).
        #[arg(long)]
        reference_points_per_edge: Option<usize>,
        /// Instead of the mode study, issue 27's face study: the lattice at these points per
        /// edge (comma list, e.g. 5,9,13,17; the last three extrapolated to the reference) and
        /// the exact face contact, each at the case tolerance.
        #[arg(long)]
        faces: Option<String>,
        /// Face study: also the exact face contact with friction per part at each part's load
        /// centre (`FrictionRule::PerPart`, a measurement of issue 27's cheaper friction).
        #[arg(long)]
        friction_per_part: bool,
    },
    /// Issue 53's reduced face law against the exact face contact: cost, census and the
    /// friction power and wear rates of each case, one run of each law.
    Reduced {
        /// Cases (config names, comma list).
        #[arg(long, default_value = "launcher-design,launcher-tight,launcher-loose")]
        cases: String,
        /// Settle time, s.
        #[arg(long, default_value_t = 0.5)]
        settle: f64,
        /// Averaging window after the settle, s.
        #[arg(long, default_value_t = 4.0)]
        window: f64,
        /// The reduced law's tolerances to run (comma list; empty: the contacts' default).
        #[arg(long, default_value = "")]
        tolerances: String,
    },
    /// Issue 27's per-state face study: a case run with the lattice, its states recorded, and
    /// at each the contacts evaluated with the exact face contact, the exact contact with
    /// friction per part at its load centre (`FrictionRule::PerPart`), and the lattice at
    /// several points per edge (normal force, force, torque, friction power, per contact and
    /// track).
    FaceStates {
        /// Case (config name).
        #[arg(long, default_value = "launcher-loose")]
        case: String,
        /// Lattice points per edge of the recording run.
        #[arg(long, default_value_t = 9)]
        record_points: usize,
        /// Lattice points per edge evaluated at the states (comma list).
        #[arg(long, default_value = "9,17,33,65")]
        ladder: String,
        /// Settle time, s.
        #[arg(long, default_value_t = 1.0)]
        settle: f64,
        /// Excitation window, s.
        #[arg(long, default_value_t = 2.0)]
        window: f64,
        /// Interval between recorded states, s.
        #[arg(long, default_value_t = 0.01)]
        every: f64,
    },
    /// Cost per missile of a launcher with 1, 2 and 4 missiles (issue 16).
    Missiles {
        /// Settle time, s.
        #[arg(long, default_value_t = 1.0)]
        settle: f64,
        /// Excitation window, s.
        #[arg(long, default_value_t = 2.0)]
        window: f64,
        /// Also integrate each launcher as one system with one integrator.
        #[arg(long)]
        monolithic: bool,
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

/// A comma list of numbers (empty items skipped); the error names the option.
fn parse_list(list: &str, option: &str) -> Result<Vec<f64>> {
    list.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .with_context(|| format!("{option}: `{s}` is not a number"))
        })
        .collect()
}

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
            tolerance_factors,
            points_per_edge,
            repeats,
        } => peers(
            &cli.configs_dir,
            *with_peers,
            peers_json.as_deref(),
            *settle,
            *window,
            peer_args,
            &ExtraRuns {
                tolerance_factors: parse_list(tolerance_factors, "--tolerance-factors")?,
                points_per_edge: *points_per_edge,
                repeats: *repeats,
            },
        )?,
        Command::Launcher {
            settle,
            window,
            mem_window,
            no_mem,
            default_only,
            durations,
        } => {
            let mut tables = launcher(
                &cli.configs_dir,
                *settle,
                *window,
                *mem_window,
                *no_mem,
                *default_only,
            )?;
            let windows = parse_list(durations, "--durations")?;
            if !windows.is_empty() {
                tables.push(launcher_linearity(&cli.configs_dir, *settle, &windows)?);
            }
            tables
        }
        Command::Convergence {
            cases,
            settle_box,
            settle_launcher,
            window,
            reference_factor,
            criterion,
            with_energy_off,
            ladder,
            points_per_edge,
            reference_points_per_edge,
            faces,
            friction_per_part,
        } => {
            let bench = ConvergenceBench {
                faces: match faces {
                    Some(list) => parse_list(list, "--faces")?
                        .into_iter()
                        .map(|n: f64| n as usize)
                        .collect(),
                    None => Vec::new(),
                },
                friction_per_part: *friction_per_part,
                cases: cases.clone(),
                settle_box: *settle_box,
                settle_launcher: *settle_launcher,
                window: *window,
                reference_factor: *reference_factor,
                criterion: *criterion,
                with_energy_off: *with_energy_off,
                points_per_edge: *points_per_edge,
                reference_points_per_edge: *reference_points_per_edge,
            };
            match ladder {
                _ if !bench.faces.is_empty() => faces::faces(&cli.configs_dir, &bench)?,
                Some(list) => {
                    convergence::ladder(&cli.configs_dir, &bench, &parse_list(list, "--ladder")?)?
                }
                None => convergence(&cli.configs_dir, &bench)?,
            }
        }
        Command::Reduced {
            cases,
            settle,
            window,
            tolerances,
        } => faces::reduced(
            &cli.configs_dir,
            cases,
            *settle,
            *window,
            &parse_list(tolerances, "--tolerances")?,
        )?,
        Command::FaceStates {
            case,
            record_points,
            ladder,
            settle,
            window,
            every,
        } => face_states::face_states(
            &cli.configs_dir,
            &face_states::FaceStatesBench {
                case: case.clone(),
                record_points: *record_points,
                ladder: parse_list(ladder, "--ladder")?
                    .into_iter()
                    .map(|n| n as usize)
                    .collect(),
                settle: *settle,
                window: *window,
                every: *every,
            },
        )?,
        Command::Missiles {
            settle,
            window,
            monolithic,
        } => missiles(&cli.configs_dir, *settle, *window, *monolithic)?,
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
