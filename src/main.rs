//! railwear command line. Each subcommand is one enum variant and one match arm.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use railwear::config::{Role, ServiceConfig};
use railwear::jobs::LibraryRunner;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "railwear",
    version,
    about = "Launcher-rail and missile-shoe wear prediction"
)]
struct Cli {
    /// Service settings file (TOML). Missing default file = built-in defaults.
    #[arg(
        long,
        global = true,
        env = "RAILWEAR_CONFIG",
        default_value = "configs/service.toml"
    )]
    config: PathBuf,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the HTTP service with its embedded worker pool.
    Serve {
        /// Listen address (overrides settings), e.g. 127.0.0.1:0 for a free port.
        #[arg(long)]
        listen: Option<String>,
        /// Worker threads (overrides settings; 0 = one per core).
        #[arg(long)]
        workers: Option<usize>,
        /// Serve the API only; jobs are left for workers elsewhere.
        #[arg(long)]
        no_workers: bool,
    },
    /// Run job workers only (no HTTP): claim jobs from the shared database, run them, store the
    /// results. Start any number of these on any hosts next to `serve --no-workers`.
    Worker {
        /// Database URL (overrides settings), e.g. postgres://user@db-host:5432/railwear.
        #[arg(long)]
        database_url: Option<String>,
        /// Worker threads in this process (overrides settings; 0 = one per core).
        #[arg(long)]
        workers: Option<usize>,
    },
    /// Print the OpenAPI document (`railwear openapi > api/openapi.json`).
    Openapi,
    /// Manage API tokens in the database.
    Token {
        #[command(subcommand)]
        command: TokenCommand,
    },
    /// Apply database migrations and exit.
    Migrate,
    /// Run one case config end to end with a progress bar; print a summary table and write
    /// summary.json, tracks.csv and SVG plots to the output directory.
    Run {
        /// Case config file, e.g. configs/rattle-box-c.toml.
        config_file: PathBuf,
        /// Output directory (default out/<case name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override the excited duration, s.
        #[arg(long)]
        duration: Option<f64>,
        /// Override the settle time, s.
        #[arg(long)]
        settle: Option<f64>,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
    /// Run rattle-box cases A-D and write the comparison page against thesis Tables 5.3/5.4.
    CompareRattleBox {
        /// Excited duration per case, s.
        #[arg(long, default_value_t = 5.0)]
        duration: f64,
        /// Settle time per case, s.
        #[arg(long, default_value_t = 1.0)]
        settle: f64,
        /// Markdown page to write.
        #[arg(long, default_value = "docs/results/validation.md")]
        out: PathBuf,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
    /// Test campaigns (measured data for the sim-to-real gap diagnosis).
    Campaign {
        #[command(subcommand)]
        command: CampaignCommand,
    },
    /// Virtual shaker rig: a campaign from the model plus hidden effects, scatter and noise;
    /// writes <out>/campaign.toml (+ CSVs, no word of the effect) and <out>/truth.json.
    Rig {
        /// Base campaign manifest (its measurements are ignored), or `thesis` for the built-in
        /// campaigns/thesis-rattle-box.toml.
        #[arg(long)]
        base: PathBuf,
        /// Hidden effect `<name>=<magnitude>[,<param>=<value>...]`, repeatable; `none` makes a
        /// control. Library effects and the rig-only `surface_oxide`, `work_hardening`.
        #[arg(long = "effect", required = true)]
        effects: Vec<String>,
        /// Relative measurement noise of each weighed mass (standard deviation / mass).
        #[arg(long, default_value_t = 0.0)]
        noise: f64,
        /// Specimen-to-specimen scatter of the wear (log-normal sigma).
        #[arg(long, default_value_t = 0.0)]
        scatter: f64,
        /// Seed of every random draw.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Simulated excitation per segment, s (it stands for the segment's test time).
        #[arg(long, default_value_t = 2.0)]
        window_s: f64,
        /// Settle time before each segment, s.
        #[arg(long, default_value_t = 0.5)]
        settle_s: f64,
        /// Segments per increment (dynamics effects update between segments).
        #[arg(long, default_value_t = 1)]
        segments_per_increment: usize,
        /// Also write input and response accelerometer records at this rate, Hz.
        #[arg(long)]
        accelerometer_rate_hz: Option<f64>,
        /// Sensor noise of those records, RMS m/s².
        #[arg(long, default_value_t = 0.0)]
        sensor_noise_m_s2: f64,
        /// Relative sensitivity error of each accelerometer (1 sigma, one draw per location
        /// and axis for the whole campaign).
        #[arg(long, default_value_t = 0.0)]
        calibration_rel: f64,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
    /// Gap diagnosis of a campaign: where the model misses, which library effect explains it
    /// (fitted and judged on held-out tests), how far the gap shrinks. Prints the verdict, or
    /// the report's JSON with --json; writes report.json and SVG plots to --out.
    Diagnose {
        /// Campaign manifest (TOML, CSV files beside it).
        campaign: PathBuf,
        /// Print the report's JSON instead of the summary.
        #[arg(long)]
        json: bool,
        /// Directory for report.json and the plots (residuals.svg, ranking.svg,
        /// before_after.svg, energy_budget.svg); default: <campaign's directory>/diagnosis.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Simulated excitation per increment, s.
        #[arg(long, default_value_t = 2.0)]
        window_s: f64,
        /// Settle before it, s.
        #[arg(long, default_value_t = 0.3)]
        settle_s: f64,
        /// Grid points of each dynamics effect (positive side).
        #[arg(long, default_value_t = 5)]
        grid_points: usize,
        /// Only these library effects (comma-separated); default every applicable one.
        #[arg(long, value_delimiter = ',')]
        effects: Option<Vec<String>>,
        /// Simulation threads.
        #[arg(long, default_value_t = 2)]
        threads: usize,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
    /// The next tests of a diagnosed campaign, planned again from its report: what would best
    /// separate the leading candidate from its rivals, as campaign entries to append.
    PlanTest(railwear::cli::PlanTestArgs),
    /// Blind check of the diagnosis: campaigns drawn from the virtual rig (controls, library
    /// effects from barely to clearly detectable, rig-only effects), diagnosed without their
    /// truth, scored against it. Prints the scores and the confusion table.
    DiagnoseBench {
        /// Campaigns to draw.
        #[arg(long, default_value_t = 60)]
        campaigns: usize,
        /// Seed of the draw.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Skeleton campaign the rig fills.
        #[arg(long, default_value = "campaigns/bench-rattle-box.toml")]
        skeleton: PathBuf,
        /// Simulated excitation per increment (rig and diagnosis), s.
        #[arg(long, default_value_t = 0.5)]
        window_s: f64,
        /// Simulation threads.
        #[arg(long, default_value_t = 2)]
        threads: usize,
        /// Keep only the campaigns whose truth names this effect, `control`, or `pairs` (every
        /// pair); each keeps the seed it has in the full draw.
        #[arg(long)]
        truth: Option<String>,
        /// Write each campaign's diagnosis report (with its truth) as <DIR>/<rig seed>.json.
        #[arg(long)]
        reports: Option<PathBuf>,
        /// For each campaign left partly or not explained while its truth is detectable, run
        /// the top proposed next test on the rig under the same truth, append it, diagnose again.
        #[arg(long)]
        confirm: bool,
        /// Keep only the campaigns with these rig seeds (seed x 1000 + index in the draw),
        /// each as the full bench draws it: `--only 1039,1042`.
        #[arg(long, value_delimiter = ',')]
        only: Vec<u64>,
        /// Write every outcome as JSON here.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Keep the skeleton's emulator in this file and reuse it when the tests, options and
        /// code version match (it depends on no measurement).
        #[arg(long)]
        emulator_file: Option<PathBuf>,
        /// Score the outcomes of earlier runs' `--out` files together instead of diagnosing.
        #[arg(long, value_delimiter = ',')]
        rescore: Vec<PathBuf>,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
    /// List the effect library of the gap diagnosis: names, what each models, its parameters
    /// with units, bounds, defaults and the reasons for them.
    Effects {
        /// Print the library as JSON.
        #[arg(long)]
        json: bool,
    },
    /// IMPACT stiffness k and exponent e (eq. 2.7) for a sphere on a flat, fitted by least
    /// squares to a quasistatic model of thesis 2.3.1 (Hertz, fully plastic, Jackson-Green,
    /// Kogut-Etsion); prints the fit with its range and weighting (docs/results/errata.md section 3).
    /// Materials default to 7075-T73 for both bodies.
    ContactFit {
        /// hertz, fully_plastic, jackson_green or kogut_etsion (`-` for `_` allowed).
        #[arg(long, value_parser = railwear::cli::contact_fit::parse_model)]
        model: railwear::contact_models::QuasistaticModel,
        /// Sphere radius, m (thesis 2.3.1: 0.05).
        #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
        radius_m: f64,
        /// Young's modulus of both bodies, Pa (default 7075-T73, 72e9).
        #[arg(long, allow_negative_numbers = true)]
        youngs_modulus_pa: Option<f64>,
        /// Poisson's ratio of both bodies (default 7075-T73, 0.33).
        #[arg(long, allow_negative_numbers = true)]
        poisson_ratio: Option<f64>,
        /// Yield strength of both bodies, Pa (default 7075-T73, 435e6).
        #[arg(long, allow_negative_numbers = true)]
        yield_strength_pa: Option<f64>,
        /// The flat's own Young's modulus, Pa.
        #[arg(long, allow_negative_numbers = true)]
        flat_youngs_modulus_pa: Option<f64>,
        /// The flat's own Poisson's ratio.
        #[arg(long, allow_negative_numbers = true)]
        flat_poisson_ratio: Option<f64>,
        /// The flat's own yield strength, Pa.
        #[arg(long, allow_negative_numbers = true)]
        flat_yield_strength_pa: Option<f64>,
        /// Upper end of the fitted interference range, m (the thesis fits 0-1 mm).
        #[arg(long, default_value_t = railwear::contact_models::impact_fit::DEFAULT_MAX_INTERFERENCE_M, allow_negative_numbers = true)]
        max_interference_m: f64,
        /// Points of the force curve fitted (3 to 1,000,000).
        #[arg(long, default_value_t = railwear::contact_models::impact_fit::DEFAULT_SAMPLES)]
        samples: usize,
        /// linear: least squares on force, samples uniform in w (the thesis' NLINFIT); log:
        /// least squares on ln F, samples log-spaced from max/1000.
        #[arg(long, default_value = "linear", value_parser = railwear::cli::contact_fit::parse_fit_space)]
        fit_space: railwear::contact_models::FitSpace,
        /// Print the fit as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Run the thesis anchors and print expected vs measured vs verdict.
    Validate {
        /// One JSON object per anchor (name, expected, measured, tolerance, pass).
        #[arg(long)]
        json: bool,
        /// Also run the slow anchors (rattle box and launcher simulations, minutes).
        #[arg(long)]
        slow: bool,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
}

#[derive(Subcommand)]
enum CampaignCommand {
    /// Load and validate a campaign; print a summary, or the error naming field and row (exit
    /// status 1).
    Check {
        /// Campaign manifest (TOML, CSV files beside it).
        file: PathBuf,
        /// Print the campaign's JSON form instead of the summary.
        #[arg(long)]
        json: bool,
        /// Directory of reference configs and profiles.
        #[arg(long, env = "RAILWEAR_CONFIGS_DIR", default_value = "configs")]
        configs_dir: PathBuf,
    },
}

#[derive(Subcommand)]
enum TokenCommand {
    /// Create a token and print it (shown once).
    Create {
        /// planner, engineer, test-engineer (also spelled test_engineer) or admin.
        #[arg(long)]
        role: String,
        /// Who holds it.
        #[arg(long, default_value = "cli")]
        name: String,
    },
}

fn load_config(cli: &Cli) -> Result<ServiceConfig> {
    let explicit = std::env::var_os("RAILWEAR_CONFIG").is_some()
        || cli.config.as_path() != std::path::Path::new("configs/service.toml");
    ServiceConfig::load(&cli.config, explicit, |key| std::env::var(key).ok())
        .with_context(|| format!("loading settings from {}", cli.config.display()))
}

fn init_logging(json: bool) {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    // Colour codes only for a person at a terminal: a log file or collector gets plain text.
    let ansi = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_ansi(ansi)
        .with_writer(std::io::stderr);
    if json {
        builder.json().init();
    } else {
        builder.init();
    }
}

async fn shutdown_signal() {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{signal, SignalKind};
        if let Ok(mut term) = signal(SignalKind::terminate()) {
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {}
                _ = term.recv() => {}
            }
            return;
        }
    }
    let _ = tokio::signal::ctrl_c().await;
}

/// Resolve the configs directory to an absolute path and log it with the database URL
/// (password redacted); warn when the directory holds no model configs (started outside the
/// repository without `RAILWEAR_CONFIGS_DIR`).
fn log_start_up(config: &mut ServiceConfig) {
    config.configs_dir = config.resolved_configs_dir();
    let models = railwear::models::reference::reference_config_names(&config.configs_dir);
    tracing::info!(
        database = %config.redacted_database_url(),
        configs_dir = %config.configs_dir.display(),
        model_configs = models.len(),
        "settings resolved"
    );
    if models.is_empty() {
        tracing::warn!(
            configs_dir = %config.configs_dir.display(),
            "no model configs in the configs directory: jobs naming a config will be refused; \
             set RAILWEAR_CONFIGS_DIR or configs_dir"
        );
    }
}

async fn serve(
    mut config: ServiceConfig,
    listen: Option<String>,
    workers: Option<usize>,
    no_workers: bool,
) -> Result<()> {
    if let Some(listen) = listen {
        config.listen = listen;
    }
    if let Some(workers) = workers {
        config.workers = workers;
    }
    init_logging(config.log_format == "json");
    log_start_up(&mut config);
    let runner = Arc::new(LibraryRunner::new(config.configs_dir.clone()));
    let service = railwear::http::start(config, runner, !no_workers).await?;
    // Tests and scripts read this line to find the port.
    println!("listening on http://{}", service.addr);
    std::io::stdout().flush()?;
    tracing::info!(addr = %service.addr, version = %railwear::jobs::code_version(), "serving");
    shutdown_signal().await;
    tracing::info!(
        grace_s = service.state.config.shutdown_grace_s,
        "shutting down"
    );
    service.stop().await;
    tracing::info!("stopped");
    exit_now()
}

async fn worker(
    mut config: ServiceConfig,
    database_url: Option<String>,
    workers: Option<usize>,
) -> Result<()> {
    if let Some(url) = database_url {
        config.database_url = url;
    }
    if let Some(workers) = workers {
        config.workers = workers;
    }
    init_logging(config.log_format == "json");
    log_start_up(&mut config);
    let store = railwear::store::open(&config.database_url)
        .await
        .context("opening the job database")?;
    let settings = config.worker_settings();
    let curve_defaults = railwear::jobs::CurveDefaults {
        vehicle_profile: config.report.vehicle_profile.clone(),
        environment: config.report.environment.clone(),
        wear_law: config.report.wear_law.clone(),
    };
    let runner = Arc::new(LibraryRunner::new(config.configs_dir.clone()));
    let jobs = railwear::jobs::Jobs::new(store, runner, settings, curve_defaults);
    let count = config.worker_count();
    // Jobs left running by dead processes of this host go back to the queue at once.
    jobs.release_dead_leases()
        .await
        .context("releasing the leases of dead workers")?;
    // Worker names carry host and pid so a lease owner can be traced to its process.
    let handles = jobs.spawn_workers(count, &jobs.worker_prefix());
    // Tests and scripts read this line to know the workers are polling.
    println!("workers started: {count}");
    std::io::stdout().flush()?;
    tracing::info!(count, version = %railwear::jobs::code_version(), "workers started");
    shutdown_signal().await;
    // Stop taking jobs; running ones stop at a step boundary and go back to the queue.
    tracing::info!(grace_s = config.shutdown_grace_s, "shutting down");
    jobs.shutdown(handles).await;
    tracing::info!("workers stopped");
    exit_now()
}

/// End the process at once: a computation that did not stop within the grace period is not
/// waited for (its job is already back in the queue, and its late result would be fenced out).
fn exit_now() -> ! {
    let _ = std::io::stdout().flush();
    std::process::exit(0)
}

/// A failed command prints its error and the chain of causes on one line (`error: a: b`) and
/// exits with status 1; never a stack backtrace, whatever `RUST_BACKTRACE` says (the errors
/// name the field and the rule; a backtrace is for a panic).
#[tokio::main]
async fn main() -> std::process::ExitCode {
    match run(Cli::parse()).await {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

async fn run(cli: Cli) -> Result<()> {
    match &cli.command {
        Command::Serve {
            listen,
            workers,
            no_workers,
        } => serve(load_config(&cli)?, listen.clone(), *workers, *no_workers).await,
        Command::Worker {
            database_url,
            workers,
        } => worker(load_config(&cli)?, database_url.clone(), *workers).await,
        Command::Effects { json } => railwear::cli::effects(*json),
        Command::ContactFit {
            model,
            radius_m,
            youngs_modulus_pa,
            poisson_ratio,
            yield_strength_pa,
            flat_youngs_modulus_pa,
            flat_poisson_ratio,
            flat_yield_strength_pa,
            max_interference_m,
            samples,
            fit_space,
            json,
        } => {
            use railwear::cli::contact_fit::{contact_fit, ContactFitArgs, MaterialFlags};
            let args = ContactFitArgs {
                model: *model,
                radius_m: *radius_m,
                material: MaterialFlags {
                    youngs_modulus_pa: *youngs_modulus_pa,
                    poisson_ratio: *poisson_ratio,
                    yield_strength_pa: *yield_strength_pa,
                },
                flat: MaterialFlags {
                    youngs_modulus_pa: *flat_youngs_modulus_pa,
                    poisson_ratio: *flat_poisson_ratio,
                    yield_strength_pa: *flat_yield_strength_pa,
                },
                max_interference_m: *max_interference_m,
                samples: *samples,
                space: *fit_space,
            };
            // A refused value is an answer, not a crash: the message names the flag and rule.
            if let Err(e) = contact_fit(&args, *json) {
                eprintln!("error: {e:#}");
                std::process::exit(1);
            }
            Ok(())
        }
        Command::Openapi => {
            print!("{}", railwear::http::openapi::openapi_json());
            Ok(())
        }
        Command::Token {
            command: TokenCommand::Create { role, name },
        } => {
            let Some(role) = Role::parse(role) else {
                bail!("--role must be planner, engineer, test-engineer or admin");
            };
            let config = load_config(&cli)?;
            let store = railwear::store::open(&config.database_url).await?;
            let token = railwear::http::auth::generate_token();
            let record = store
                .create_token(
                    name,
                    role,
                    &railwear::http::auth::token_sha256(&token),
                    railwear::store::clock::now_ms(),
                )
                .await?;
            eprintln!(
                "created {} token `{}` ({})",
                role.as_str(),
                record.name,
                record.id
            );
            println!("{token}");
            Ok(())
        }
        Command::Run {
            config_file,
            out,
            duration,
            settle,
            configs_dir,
        } => railwear::cli::run(config_file, out.as_deref(), *duration, *settle, configs_dir),
        Command::CompareRattleBox {
            duration,
            settle,
            out,
            configs_dir,
        } => railwear::cli::compare_rattle_box(*duration, *settle, out, configs_dir),
        Command::Validate {
            json,
            slow,
            configs_dir,
        } => {
            let all_pass = railwear::cli::validate(*json, *slow, configs_dir)?;
            if !all_pass {
                std::process::exit(1);
            }
            Ok(())
        }
        Command::Campaign {
            command:
                CampaignCommand::Check {
                    file,
                    json,
                    configs_dir,
                },
        } => {
            // A refused campaign is an answer, not a crash: the message names field and row.
            if let Err(e) = railwear::cli::campaign_check(file, *json, configs_dir) {
                eprintln!("error: {e:#}");
                std::process::exit(1);
            }
            Ok(())
        }
        Command::Rig {
            base,
            effects,
            noise,
            scatter,
            seed,
            out,
            window_s,
            settle_s,
            segments_per_increment,
            accelerometer_rate_hz,
            sensor_noise_m_s2,
            calibration_rel,
            configs_dir,
        } => {
            init_logging(false);
            let options = railwear::gap::rig::RigOptions {
                noise_rel: *noise,
                scatter_rel: *scatter,
                seed: *seed,
                window_s: *window_s,
                settle_s: *settle_s,
                segments_per_increment: *segments_per_increment,
                accelerometer_rate_hz: *accelerometer_rate_hz,
                sensor_noise_m_s2: *sensor_noise_m_s2,
                calibration_rel: *calibration_rel,
                ..Default::default()
            };
            railwear::cli::rig(base, effects, options, out, configs_dir)
        }
        Command::Diagnose {
            campaign,
            json,
            out,
            window_s,
            settle_s,
            grid_points,
            effects,
            threads,
            configs_dir,
        } => {
            init_logging(false);
            let mut options = railwear::gap::diagnose::DiagnoseOptions::default();
            options.emulator.window_s = *window_s;
            options.emulator.settle_s = *settle_s;
            options.emulator.grid_points = *grid_points;
            options.emulator.effects = effects.clone();
            options.emulator.threads = *threads;
            if let Err(e) =
                railwear::cli::diagnose(campaign, *json, out.as_deref(), &options, configs_dir)
            {
                eprintln!("error: {e:#}");
                std::process::exit(1);
            }
            Ok(())
        }
        Command::PlanTest(args) => {
            init_logging(false);
            railwear::cli::plan_test(args)
        }
        Command::DiagnoseBench {
            campaigns,
            seed,
            skeleton,
            window_s,
            threads,
            truth,
            reports,
            confirm,
            only,
            out,
            emulator_file,
            rescore,
            configs_dir,
        } => {
            init_logging(false);
            let mut options = railwear::gap::diagnose::bench::BenchOptions {
                campaigns: *campaigns,
                seed: *seed,
                rig_window_s: *window_s,
                truth_filter: truth.clone(),
                reports_dir: reports.clone(),
                confirm: *confirm,
                only_seeds: only.clone(),
                ..Default::default()
            };
            options.diagnose.emulator.window_s = *window_s;
            options.diagnose.emulator.threads = *threads;
            railwear::cli::diagnose_bench(
                skeleton,
                &options,
                out.as_deref(),
                emulator_file.as_deref(),
                rescore,
                configs_dir,
            )
        }
        Command::Migrate => {
            let config = load_config(&cli)?;
            railwear::store::open(&config.database_url).await?;
            eprintln!("migrations applied to {}", config.database_url);
            Ok(())
        }
    }
}
