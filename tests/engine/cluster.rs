//! `render --shard K/N` on a real Slurm cluster (issue 49, item 7): a
//! one-node cluster from Debian's `slurm-wlm` and `munge` (which `.ci/run`
//! installs), its daemons on the loopback with their own key, ports and
//! folders, runs a job array of four shards of a 12-frame path-traced
//! animation; every frame equals, byte for byte, the frame one process
//! rendering all twelve writes. octovox schedules nothing: each task
//! renders its shard.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use super::vox_scene::assets;

/// The render every task and the one process make (the task adds its shard).
fn render_args(out: &Path) -> Vec<String> {
    let input = assets().join("anim/animation.vox");
    let pattern = out.join("frame_%02d.png");
    ["render", input.to_str().unwrap(), "--frames", "0..11", "--spp", "2", "--size", "64x48", "-o"]
        .map(str::to_owned)
        .into_iter()
        .chain([pattern.to_str().unwrap().to_owned()])
        .collect()
}

/// The daemons of a one-node cluster, stopped when dropped.
struct Cluster {
    dir: tempfile::TempDir,
    daemons: Vec<Child>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for daemon in &mut self.daemons {
            let _ = daemon.kill();
            let _ = daemon.wait();
        }
    }
}

/// A port nothing listens on now.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn user() -> String {
    let out = Command::new("id").arg("-un").output().expect("id");
    String::from_utf8(out.stdout).unwrap().trim().to_owned()
}

impl Cluster {
    fn start() -> Cluster {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().to_path_buf();
        let at = |name: &str| root.join(name);
        for folder in ["state", "spool"] {
            std::fs::create_dir(at(folder)).unwrap();
        }
        let key: Vec<u8> = (0..1024u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
        std::fs::write(at("munge.key"), key).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(at("munge.key"), std::fs::Permissions::from_mode(0o600)).unwrap();
        let path = |name: &str| at(name).to_str().unwrap().to_owned();
        let conf = format!(
            "ClusterName=octovox\nSlurmctldHost=localhost\nSlurmctldPort={}\nSlurmdPort={}\n\
             SlurmUser={user}\nSlurmdUser={user}\nAuthType=auth/munge\nAuthInfo=socket={sock}\nCredType=cred/munge\n\
             StateSaveLocation={state}\nSlurmdSpoolDir={spool}\nSlurmctldPidFile={ctldpid}\nSlurmdPidFile={dpid}\n\
             SlurmctldLogFile={ctldlog}\nSlurmdLogFile={dlog}\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nSchedulerType=sched/builtin\nMpiDefault=none\n\
             ReturnToService=2\nJobCompType=jobcomp/none\nAccountingStorageType=accounting_storage/none\n\
             JobAcctGatherType=jobacct_gather/none\n\
             NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN\n\
             PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n",
            free_port(),
            free_port(),
            user = user(),
            sock = path("munge.sock"),
            state = path("state"),
            spool = path("spool"),
            ctldpid = path("slurmctld.pid"),
            dpid = path("slurmd.pid"),
            ctldlog = path("slurmctld.log"),
            dlog = path("slurmd.log"),
        );
        std::fs::write(at("slurm.conf"), conf).unwrap();
        let mut cluster = Cluster { dir, daemons: Vec::new() };
        let munge = [
            "--foreground".to_owned(),
            format!("--key-file={}", path("munge.key")),
            format!("--socket={}", path("munge.sock")),
            format!("--pid-file={}", path("munged.pid")),
            format!("--log-file={}", path("munged.log")),
            format!("--seed-file={}", path("munged.seed")),
        ];
        cluster.spawn("munged", &munge);
        cluster.wait_for("munge's socket", || at("munge.sock").exists());
        cluster.spawn("slurmctld", &["-D".into(), "-f".into(), path("slurm.conf")]);
        cluster.spawn("slurmd", &["-D".into(), "-N".into(), "localhost".into(), "-f".into(), path("slurm.conf")]);
        cluster.wait_for("the node to be idle", || {
            let out = cluster.command("sinfo").args(["-h", "-o", "%t"]).output();
            out.is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
        });
        cluster
    }

    /// Starts a daemon from the Debian packages (`/usr/sbin` is not on
    /// every user's PATH).
    fn spawn(&mut self, name: &str, args: &[String]) {
        let program = ["/usr/sbin", "/usr/bin", "/sbin"].iter().map(|d| Path::new(d).join(name)).find(|p| p.exists());
        let program = program.unwrap_or_else(|| {
            panic!(
                "{name} is not installed: the cluster test needs Debian's slurm-wlm and munge (.ci/run installs them)"
            )
        });
        let child = Command::new(program).args(args).stdout(Stdio::null()).stderr(Stdio::null()).spawn();
        self.daemons.push(child.unwrap_or_else(|e| panic!("cannot start {name}: {e}")));
    }

    /// A Slurm client command speaking to this cluster.
    fn command(&self, name: &str) -> Command {
        let mut command = Command::new(name);
        command.env("SLURM_CONF", self.dir.path().join("slurm.conf"));
        command
    }

    fn wait_for(&self, what: &str, ready: impl Fn() -> bool) {
        let start = Instant::now();
        while !ready() {
            assert!(start.elapsed() < Duration::from_secs(60), "timed out waiting for {what}: {}", self.logs());
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    fn logs(&self) -> String {
        ["munged.log", "slurmctld.log", "slurmd.log"]
            .iter()
            .map(|name| {
                let text = std::fs::read_to_string(self.dir.path().join(name)).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(8).collect();
                format!("\n--- {name}:\n{}", tail.into_iter().rev().collect::<Vec<_>>().join("\n"))
            })
            .collect()
    }
}

/// The PNG files of a folder, by name.
fn frames_in(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    files.iter().map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(p).unwrap())).collect()
}

#[test]
fn a_slurm_job_array_renders_the_frames_one_process_renders() {
    let cluster = Cluster::start();
    let (sharded, whole) = (cluster.dir.path().join("sharded"), cluster.dir.path().join("whole"));
    std::fs::create_dir(&sharded).unwrap();
    std::fs::create_dir(&whole).unwrap();
    let octovox = env!("CARGO_BIN_EXE_octovox");
    let script = format!(
        "#!/bin/sh\nexec {octovox} {} --shard \"$SLURM_ARRAY_TASK_ID/4\"\n",
        render_args(&sharded).iter().map(|a| format!("'{a}'")).collect::<Vec<_>>().join(" ")
    );
    let job = cluster.dir.path().join("job.sh");
    std::fs::write(&job, script).unwrap();
    let log = cluster.dir.path().join("task_%a.log");
    let mut sbatch = cluster
        .command("sbatch")
        .args(["--array=0-3", "--wait", "--export=ALL"])
        .arg(format!("--output={}", log.display()))
        .arg(&job)
        .spawn()
        .expect("sbatch");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = sbatch.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(300) {
            let _ = sbatch.kill();
            panic!("the job array took over 5 minutes: {}", cluster.logs());
        }
        std::thread::sleep(Duration::from_millis(250));
    };
    let task_logs: String = (0..4)
        .map(|k| std::fs::read_to_string(cluster.dir.path().join(format!("task_{k}.log"))).unwrap_or_default())
        .collect();
    assert!(status.success(), "sbatch: {status}; tasks said:\n{task_logs}{}", cluster.logs());
    for k in 0..4 {
        let said = std::fs::read_to_string(cluster.dir.path().join(format!("task_{k}.log"))).unwrap();
        assert!(said.contains("wrote 3 frames"), "task {k} said: {said}");
    }
    let one = Command::new(octovox).args(render_args(&whole)).output().unwrap();
    assert!(one.status.success(), "{}", String::from_utf8_lossy(&one.stderr));
    let (a, b) = (frames_in(&sharded), frames_in(&whole));
    assert_eq!(a.len(), 12, "{:?}", a.iter().map(|f| &f.0).collect::<Vec<_>>());
    for ((name, bytes), (whole_name, whole_bytes)) in a.iter().zip(&b) {
        assert_eq!(name, whole_name);
        assert!(bytes == whole_bytes, "{name}: the shard's frame differs from the one process's");
    }
    // The frames show the object moving: not one picture twelve times.
    assert_ne!(a[0].1, a[11].1);
}
