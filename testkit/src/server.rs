//! The real `railwear` binary as a child process, killed on drop: a server started with
//! `--listen 127.0.0.1:0` (its address read from the `listening on http://ADDR` line it prints),
//! or any command that prints a ready line (`railwear worker` prints `workers started: ...`).

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("starting the server: {0}")]
    Start(#[from] std::io::Error),
    #[error("the process did not print a line starting with `{prefix}` within {wait:?}")]
    NotReady { prefix: String, wait: Duration },
}

/// `bin serve --listen 127.0.0.1:0` with `DATABASE_URL`, `RAILWEAR_TOKENS`,
/// `RAILWEAR_CONFIGS_DIR` and `RUST_LOG=warn` set; add arguments and variables, then
/// [`ServerProcess::spawn`] it.
pub fn serve_command(bin: &Path, db_url: &str, tokens: &str, configs_dir: &Path) -> Command {
    let mut cmd = Command::new(bin);
    cmd.args(["serve", "--listen", "127.0.0.1:0"])
        .env("DATABASE_URL", db_url)
        .env("RAILWEAR_TOKENS", tokens)
        .env("RAILWEAR_CONFIGS_DIR", configs_dir)
        .env("RUST_LOG", "warn");
    cmd
}

/// A running process; SIGKILLed and reaped on drop.
#[derive(Debug)]
pub struct ServerProcess {
    child: Child,
    /// The rest of the ready line after its prefix.
    ready: String,
}

impl ServerProcess {
    /// Spawn a server `cmd` and wait up to `wait` for its `listening on http://ADDR` line.
    pub fn spawn(cmd: Command, wait: Duration) -> Result<ServerProcess, SpawnError> {
        Self::spawn_ready(cmd, "listening on ", wait)
    }

    /// Spawn `cmd` (stdout piped, stderr inherited) and wait up to `wait` for a stdout line
    /// starting with `prefix`.
    pub fn spawn_ready(
        mut cmd: Command,
        prefix: &str,
        wait: Duration,
    ) -> Result<ServerProcess, SpawnError> {
        let not_ready = || SpawnError::NotReady {
            prefix: prefix.to_string(),
            wait,
        };
        let mut child = cmd
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()?;
        let Some(stdout) = child.stdout.take() else {
            let _ = child.kill();
            let _ = child.wait();
            return Err(not_ready());
        };
        let (tx, rx) = mpsc::channel();
        let wanted = prefix.to_string();
        // Reads stdout to its end so the server never blocks on a full pipe.
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if let Some(rest) = line.strip_prefix(&wanted) {
                    let _ = tx.send(rest.trim().to_string());
                }
            }
        });
        let mut server = ServerProcess {
            child,
            ready: String::new(),
        };
        // On timeout `server` drops here and the process is killed.
        server.ready = rx.recv_timeout(wait).map_err(|_| not_ready())?;
        Ok(server)
    }

    /// The rest of the ready line (for a server: `http://host:port`).
    pub fn ready_line(&self) -> &str {
        &self.ready
    }

    /// `host:port` a server listens on.
    pub fn addr(&self) -> &str {
        self.ready.strip_prefix("http://").unwrap_or(&self.ready)
    }

    /// `http://host:port`.
    pub fn base_url(&self) -> String {
        format!("http://{}", self.addr())
    }

    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// The process, e.g. to wait for it after a signal.
    pub fn child_mut(&mut self) -> &mut Child {
        &mut self.child
    }

    /// SIGKILL and reap: no shutdown code runs.
    pub fn kill(mut self) {
        self.kill_now();
    }

    fn kill_now(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for ServerProcess {
    fn drop(&mut self) {
        self.kill_now();
    }
}
