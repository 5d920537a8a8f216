//! Running work in a child process with a time limit, so that whatever the student's code does
//! (panic, stack overflow, abort, endless loop) the grader survives and reports why.

use std::path::PathBuf;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Set in every child the grader starts; a grader that finds it refuses to start children of
/// its own, so a test that runs the grader can never recurse.
pub const CHILD_ENV: &str = "RAYLAB_GRADER_CHILD";

/// The `render` binary prints a panic's message on one line starting with this.
pub const PANIC_PREFIX: &str = "render: panicked: ";

/// How a child ended.
#[derive(Clone, Debug)]
pub struct ChildRun {
    /// `None` if the time limit killed it.
    pub status: Option<ExitStatus>,
    /// Everything it printed to standard output.
    pub stdout: String,
    /// Everything it printed to standard error.
    pub stderr: String,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl ChildRun {
    /// Whether it exited with status 0 in time.
    pub fn success(&self) -> bool {
        self.status.is_some_and(|s| s.success())
    }

    /// One line saying why it failed: the panic message, a crash signal, or the time limit.
    pub fn failure_reason(&self, limit: Duration) -> String {
        let Some(status) = self.status else {
            return format!(
                "did not finish within the time limit of {:.0} s (endless loop?)",
                limit.as_secs_f64()
            );
        };
        if let Some(line) = self.stderr.lines().find_map(|l| l.strip_prefix(PANIC_PREFIX)) {
            return format!("panicked: {line}");
        }
        if self.stderr.contains("has overflowed its stack") {
            return "crashed: stack overflow (unbounded recursion?)".to_string();
        }
        #[cfg(unix)]
        if let Some(signal) = std::os::unix::process::ExitStatusExt::signal(&status) {
            return format!("crashed with signal {signal}");
        }
        let last = self.stderr.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("no message");
        format!("failed ({status}): {last}")
    }
}

/// Runs `command` for at most `limit`, killing it when the time is up. Callers mark grader
/// children with [`CHILD_ENV`].
/// Output goes through temporary files, so a child printing a lot never blocks on a full pipe.
pub fn run_with_limit(mut command: Command, limit: Duration) -> std::io::Result<ChildRun> {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let base: PathBuf = std::env::temp_dir().join(format!("raylab-grader-{}-{n}", std::process::id()));
    let (out_path, err_path) = (base.with_extension("out"), base.with_extension("err"));
    command
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path)?)
        .stderr(std::fs::File::create(&err_path)?);
    let start = Instant::now();
    let mut child = command.spawn()?;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        if start.elapsed() >= limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let seconds = start.elapsed().as_secs_f64();
    let read = |p: &PathBuf| String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into_owned();
    let run = ChildRun { status, stdout: read(&out_path), stderr: read(&err_path), seconds };
    let _ = std::fs::remove_file(out_path);
    let _ = std::fs::remove_file(err_path);
    Ok(run)
}
