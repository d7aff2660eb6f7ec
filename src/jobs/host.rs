//! Where a worker process runs, and whether another process of the same host is still alive:
//! at start-up a worker releases at once the leases of dead processes of its host (issue 17)
//! instead of leaving their jobs `running` until the leases expire.
//!
//! A process of the same host (same host name) is dead when its pid no longer exists or is a
//! zombie (`/proc/<pid>/stat`), or when it has this process's own pid but an instance id this
//! process did not make (an earlier process that got the same pid, as PID 1 in a container). Processes that share a host name
//! must share a PID namespace (one machine, one container, one pod: the default of Docker and
//! Kubernetes host names). Where `/proc` is not available every other process counts as alive,
//! and its leases end the usual way, when they expire.

use crate::store::{HostLease, WorkerHost};

impl WorkerHost {
    /// This process: the host name (`HOSTNAME`, else the kernel's, else `host`), its pid and a
    /// fresh instance id.
    pub fn current() -> Self {
        let instance = uuid::Uuid::new_v4().simple().to_string();
        if let Ok(mut mine) = INSTANCES.lock() {
            mine.push(instance.clone());
        }
        WorkerHost {
            host: host_name(),
            pid: std::process::id(),
            instance,
        }
    }

    /// True when `lease`, held by a process of this host, belongs to a process that no longer
    /// runs: its pid is gone, or it is this pid but not an instance this process made (an
    /// earlier process that had the same pid).
    pub fn holder_is_dead(&self, lease: &HostLease) -> bool {
        if lease.pid == self.pid {
            return INSTANCES
                .lock()
                .map(|mine| !mine.contains(&lease.instance))
                .unwrap_or(false);
        }
        !pid_alive(lease.pid)
    }
}

/// Instance ids made by this process (several job systems may run in one process, as in
/// tests): their leases are alive while the process is.
static INSTANCES: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// The host name workers record: `HOSTNAME` if set, else the kernel's, else `host`.
pub fn host_name() -> String {
    std::env::var("HOSTNAME")
        .ok()
        .or_else(|| std::fs::read_to_string("/proc/sys/kernel/hostname").ok())
        .or_else(|| std::fs::read_to_string("/etc/hostname").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "host".to_string())
}

/// Whether process `pid` of this host runs (Linux: `/proc/<pid>` exists and is not a zombie;
/// elsewhere always true, so nothing is released early).
pub fn pid_alive(pid: u32) -> bool {
    if !std::path::Path::new("/proc/self/stat").exists() {
        return true;
    }
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        // The state is the first field after the command name in parentheses.
        Ok(stat) => stat
            .rsplit_once(')')
            .and_then(|(_, rest)| rest.split_whitespace().next())
            .is_none_or(|state| state != "Z" && state != "X"),
        Err(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_lives_and_a_reaped_child_does_not() {
        assert!(pid_alive(std::process::id()));
        let mut child = std::process::Command::new("true")
            .spawn()
            .expect("spawn true");
        let pid = child.id();
        child.wait().expect("reaped");
        assert!(!pid_alive(pid), "pid {pid} was reaped");
    }

    #[test]
    fn a_lease_of_this_pid_from_another_instance_is_dead() {
        let me = WorkerHost::current();
        let lease = |pid, instance: &str| HostLease {
            job: uuid::Uuid::nil(),
            attempt: 1,
            pid,
            instance: instance.to_string(),
        };
        assert!(!me.holder_is_dead(&lease(me.pid, &me.instance)));
        assert!(me.holder_is_dead(&lease(me.pid, "an-earlier-start")));
        // Another job system of this same process is alive.
        let sibling = WorkerHost::current();
        assert!(!me.holder_is_dead(&lease(me.pid, &sibling.instance)));
        // PID 1 (init) always runs.
        assert!(!me.holder_is_dead(&lease(1, "other")));
        assert!(!me.host.is_empty());
    }
}
