//! A real single-node Slurm cluster for the farm's test: `munged`, `slurmctld` and `slurmd`
//! from Debian's packages (`.ci/run` installs them), started in a temporary folder with their
//! own key, ports and state, and stopped by their pid files when the cluster is dropped.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A running cluster. Every Slurm command must see its configuration: run them through
/// [`SlurmCluster::command`], which sets `SLURM_CONF`.
pub struct SlurmCluster {
    dir: tempfile::TempDir,
    /// The one node's name: this machine's short host name.
    node: String,
}

/// Why a cluster could not be started here (the test then says so and runs the shell engine).
pub enum Unavailable {
    /// The daemons are not installed.
    NotInstalled(&'static str),
    /// The daemons run as root (`SlurmUser=root`), and this is not root.
    NotRoot,
}

impl std::fmt::Display for Unavailable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unavailable::NotInstalled(program) => write!(
                f,
                "{program} is not installed (apt-get install slurmctld slurmd slurm-client munge)"
            ),
            Unavailable::NotRoot => f.write_str("the test cluster's daemons must run as root"),
        }
    }
}

fn installed(program: &str) -> bool {
    ["/usr/sbin", "/usr/bin", "/sbin", "/bin"]
        .iter()
        .any(|dir| Path::new(dir).join(program).exists())
}

/// A TCP port free on loopback now (the listener is dropped at once; good enough for a test).
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free loopback port")
}

fn short_hostname() -> String {
    let output = Command::new("hostname")
        .arg("-s")
        .output()
        .expect("hostname runs");
    String::from_utf8_lossy(&output.stdout).trim().to_string()
}

fn checked(mut command: Command, what: &str) {
    let output = command.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        output.status.success(),
        "{what} failed: {}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

impl SlurmCluster {
    /// Starts munge, the controller and one compute node with every core of this machine,
    /// and waits until the node takes jobs.
    pub fn start() -> Result<SlurmCluster, Unavailable> {
        for program in ["munged", "slurmctld", "slurmd", "sbatch"] {
            if !installed(program) {
                return Err(Unavailable::NotInstalled(program));
            }
        }
        let uid = Command::new("id").arg("-u").output().map(|o| o.stdout);
        if !uid.is_ok_and(|id| id.trim_ascii() == b"0") {
            return Err(Unavailable::NotRoot);
        }
        let dir = tempfile::Builder::new()
            .prefix("whitted-slurm-")
            .tempdir()
            .expect("a temporary folder");
        let cluster = SlurmCluster {
            dir,
            node: short_hostname(),
        };
        cluster.start_munge();
        cluster.write_config();
        let conf = cluster.conf();
        let mut controller = Command::new("slurmctld");
        controller.arg("-f").arg(&conf).env("SLURM_CONF", &conf);
        checked(controller, "slurmctld");
        let mut node = Command::new("slurmd");
        node.arg("-f").arg(&conf).env("SLURM_CONF", &conf);
        checked(node, "slurmd");
        cluster.wait_for_idle_node();
        Ok(cluster)
    }

    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    fn conf(&self) -> PathBuf {
        self.path().join("slurm.conf")
    }

    fn munge_socket(&self) -> PathBuf {
        self.path().join("munge/munge.sock")
    }

    /// munged with a fresh key of its own; `-f` because a temporary folder's parent (/tmp)
    /// is writable by everyone, which munged otherwise refuses.
    fn start_munge(&self) {
        use std::os::unix::fs::PermissionsExt;
        let munge = self.path().join("munge");
        std::fs::create_dir_all(&munge).unwrap();
        let mut key = Vec::new();
        std::fs::File::open("/dev/urandom")
            .and_then(|f| std::io::Read::read_to_end(&mut std::io::Read::take(f, 1024), &mut key))
            .expect("random bytes for the munge key");
        let key_file = munge.join("munge.key");
        std::fs::write(&key_file, key).unwrap();
        std::fs::set_permissions(&key_file, std::fs::Permissions::from_mode(0o600)).unwrap();
        std::fs::set_permissions(self.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
        let mut daemon = Command::new("munged");
        daemon
            .arg("-f")
            .arg(format!("--socket={}", self.munge_socket().display()))
            .arg(format!("--key-file={}", key_file.display()))
            .arg(format!("--log-file={}", munge.join("munged.log").display()))
            .arg(format!("--pid-file={}", munge.join("munged.pid").display()))
            .arg(format!("--seed-file={}", munge.join("seed").display()));
        checked(daemon, "munged");
    }

    /// The smallest configuration that runs jobs without cgroups or accounting (the
    /// documented single-node setup: `proctrack/linuxproc`, `task/none`).
    fn write_config(&self) {
        let dir = self.path().display();
        let host = &self.node;
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let config = format!(
            "ClusterName=whittedtest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={node_port}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={socket}
SlurmUser=root
SlurmdUser=root
StateSaveLocation={dir}/state
SlurmdSpoolDir={dir}/spool
SlurmctldPidFile={dir}/slurmctld.pid
SlurmdPidFile={dir}/slurmd.pid
SlurmctldLogFile={dir}/slurmctld.log
SlurmdLogFile={dir}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
DefMemPerCPU=500
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
InactiveLimit=0
MinJobAge=600
KillWait=2
Waittime=0
NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=8000 State=UNKNOWN
PartitionName=debug Nodes={host} Default=YES MaxTime=INFINITE State=UP
",
            ctld_port = free_port(),
            node_port = free_port(),
            socket = self.munge_socket().display(),
        );
        for folder in ["state", "spool"] {
            std::fs::create_dir_all(self.path().join(folder)).unwrap();
        }
        std::fs::write(self.conf(), config).unwrap();
    }

    /// A Slurm command (sbatch, squeue, scancel, scontrol, sinfo) talking to this cluster.
    pub fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        command.env("SLURM_CONF", self.conf());
        command
    }

    /// Runs a Slurm command to completion.
    pub fn run(&self, program: &str, args: &[&str]) -> Output {
        self.command(program)
            .args(args)
            .output()
            .unwrap_or_else(|e| panic!("{program}: {e}"))
    }

    fn wait_for_idle_node(&self) {
        let started = Instant::now();
        loop {
            let state = self.run("sinfo", &["-h", "-o", "%T"]);
            if String::from_utf8_lossy(&state.stdout).trim() == "idle" {
                return;
            }
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "the test cluster's node never became idle: {}{}\n{}",
                String::from_utf8_lossy(&state.stdout),
                String::from_utf8_lossy(&state.stderr),
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    /// Stops the node taking new jobs (jobs submitted meanwhile stay pending), or lets it
    /// take them again.
    pub fn hold_node(&self, hold: bool) {
        let node = format!("nodename={}", self.node);
        let args: &[&str] = if hold {
            &["update", &node, "state=drain", "reason=test"]
        } else {
            &["update", &node, "state=resume"]
        };
        let output = self.run("scontrol", args);
        assert!(
            output.status.success(),
            "scontrol {args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }

    /// The daemons' logs, for a failing assertion's message.
    pub fn logs(&self) -> String {
        ["slurmctld.log", "slurmd.log", "munge/munged.log"]
            .iter()
            .map(|name| {
                let text = std::fs::read_to_string(self.path().join(name)).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(15).collect();
                let tail: Vec<&str> = tail.into_iter().rev().collect();
                format!("--- {name}\n{}", tail.join("\n"))
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The job ids (as `squeue` prints them, e.g. `12_3`) still queued or running.
    pub fn queued(&self) -> Vec<String> {
        let output = self.run("squeue", &["-h", "-o", "%i"]);
        String::from_utf8_lossy(&output.stdout)
            .lines()
            .map(str::to_string)
            .collect()
    }

    /// Waits until `job` (an id, or `ID_TASK`) is no longer queued or running, or fails the
    /// test after `limit`.
    pub fn wait_for(&self, job: &str, limit: Duration) {
        let started = Instant::now();
        loop {
            let output = self.run("squeue", &["-h", "-o", "%i", "-j", job]);
            assert!(
                output.status.success(),
                "squeue -j {job}: {}",
                String::from_utf8_lossy(&output.stderr)
            );
            if String::from_utf8_lossy(&output.stdout).trim().is_empty() {
                return;
            }
            assert!(
                started.elapsed() < limit,
                "job {job} did not finish in {limit:?}: queue {:?}\n{}",
                self.queued(),
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(250));
        }
    }

    /// `scontrol show job`'s `JobState=` for a job that Slurm still remembers.
    pub fn job_state(&self, job: &str) -> String {
        let output = self.run("scontrol", &["show", "job", job]);
        let text = String::from_utf8_lossy(&output.stdout);
        text.split_whitespace()
            .find_map(|field| field.strip_prefix("JobState="))
            .unwrap_or("UNKNOWN")
            .to_string()
    }
}

impl Drop for SlurmCluster {
    /// Cancels what is left, then stops the daemons by their pid files and waits for them to
    /// go, so that no daemon outlives the test.
    fn drop(&mut self) {
        let _ = self.run("scancel", &["--user", "root"]);
        let pids: Vec<String> = ["slurmd.pid", "slurmctld.pid", "munge/munged.pid"]
            .iter()
            .filter_map(|file| std::fs::read_to_string(self.path().join(file)).ok())
            .map(|text| text.trim().to_string())
            .filter(|pid| pid.parse::<u32>().is_ok())
            .collect();
        // All three at once: each takes seconds to shut down.
        let _ = Command::new("kill").args(&pids).output();
        let started = Instant::now();
        for pid in &pids {
            let alive = || Path::new(&format!("/proc/{pid}")).exists();
            while alive() && started.elapsed() < Duration::from_secs(15) {
                std::thread::sleep(Duration::from_millis(50));
            }
        }
    }
}
