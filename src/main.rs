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
    /// Print the OpenAPI document (`railwear openapi > api/openapi.json`).
    Openapi,
    /// Manage API tokens in the database.
    Token {
        #[command(subcommand)]
        command: TokenCommand,
    },
    /// Apply database migrations and exit.
    Migrate,
}

#[derive(Subcommand)]
enum TokenCommand {
    /// Create a token and print it (shown once).
    Create {
        /// planner, engineer or admin.
        #[arg(long)]
        role: String,
        /// Who holds it.
        #[arg(long, default_value = "cli")]
        name: String,
    },
}

fn load_config(cli: &Cli) -> Result<ServiceConfig> {
    let explicit = std::env::var_os("RAILWEAR_CONFIG").is_some()
        || cli.config != PathBuf::from("configs/service.toml");
    ServiceConfig::load(&cli.config, explicit, |key| std::env::var(key).ok())
        .with_context(|| format!("loading settings from {}", cli.config.display()))
}

fn init_logging(json: bool) {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
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
    let runner = Arc::new(LibraryRunner {
        configs_dir: config.configs_dir.clone(),
    });
    let service = railwear::http::start(config, runner, !no_workers).await?;
    // Tests and scripts read this line to find the port.
    println!("listening on http://{}", service.addr);
    std::io::stdout().flush()?;
    tracing::info!(addr = %service.addr, version = %railwear::jobs::code_version(), "serving");
    shutdown_signal().await;
    tracing::info!("shutting down");
    service.stop().await;
    Ok(())
}

#[tokio::main]
async fn main() -> Result<()> {
    let cli = Cli::parse();
    match &cli.command {
        Command::Serve {
            listen,
            workers,
            no_workers,
        } => serve(load_config(&cli)?, listen.clone(), *workers, *no_workers).await,
        Command::Openapi => {
            print!("{}", railwear::http::openapi::openapi_json());
            Ok(())
        }
        Command::Token {
            command: TokenCommand::Create { role, name },
        } => {
            let Some(role) = Role::parse(role) else {
                bail!("--role must be planner, engineer or admin");
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
        Command::Migrate => {
            let config = load_config(&cli)?;
            railwear::store::open(&config.database_url).await?;
            eprintln!("migrations applied to {}", config.database_url);
            Ok(())
        }
    }
}
