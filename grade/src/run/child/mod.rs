//! Running work in a child process with a time limit, so that whatever the student's code does
//! (panic, stack overflow, abort, endless loop, a thread or process that never ends, eating
//! memory, printing without end) the grader survives and reports why in one line.
//!
//! Every child runs in a process group of its own, and the whole group is killed when the child
//! ends or its wall-clock time is up: nothing it started outlives it. Children that run graded
//! code ([`run_graded`]) also get resource limits that hold even for root (address space, CPU
//! time, the size of any file they write), a folder of their own, and the sandbox's walls where
//! the grader set a launcher ([`crate::run::sandbox`]).

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use crate::plain::quote;
use crate::run::sandbox::{Budget, Limits, Profile, Walls};

pub mod written;

use written::Watch;

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
    /// The limits it ran under.
    pub limits: Option<Limits>,
    /// Whether it was stopped for filling its folders past [`Limits::written`].
    pub wrote_too_much: bool,
}

impl ChildRun {
    /// Whether it exited with status 0 in time.
    pub fn success(&self) -> bool {
        self.status.is_some_and(|s| s.success())
    }

    /// Why the child failed, in one line, with what it said quoted ([`quote()`]): for public
    /// checks.
    pub fn failure_reason(&self, limit: Duration) -> String {
        self.failure(limit).to_string()
    }

    /// Why the child failed: a fixed category, and the text it wrote that says more.
    pub fn failure(&self, limit: Duration) -> Failure {
        let (category, detail) = self.classify(limit);
        Failure { category, detail: detail.map(|d| quote(&d)) }
    }

    fn classify(&self, limit: Duration) -> (Category, Option<String>) {
        if let (true, Some(limits)) = (self.wrote_too_much, self.limits) {
            let Budget { bytes, entries } = limits.written;
            let detail = format!("its files passed {} MiB or {entries} entries in all", bytes >> 20);
            return (Category::TooMuchOutput, Some(detail));
        }
        let Some(status) = self.status else {
            return (Category::OutOfTime, Some(format!("the limit is {:.0} s", limit.as_secs_f64())));
        };
        if let Some(line) = self.stderr.lines().find_map(|l| l.strip_prefix(PANIC_PREFIX)) {
            return (Category::Panicked, Some(line.to_string()));
        }
        if self.stderr.contains("has overflowed its stack") {
            return (Category::Crashed, Some("stack overflow (unbounded recursion?)".to_string()));
        }
        if let (Some(line), Some(limits)) =
            (self.stderr.lines().find(|l| l.contains("memory allocation of")), self.limits)
        {
            return (
                Category::OutOfMemory,
                Some(format!("limit {} MiB; {}", limits.memory >> 20, line.trim())),
            );
        }
        #[cfg(unix)]
        if let Some(signal) = std::os::unix::process::ExitStatusExt::signal(&status) {
            return match (signal, self.limits) {
                (libc::SIGXCPU, _) => {
                    (Category::OutOfTime, Some("used up its CPU time (endless loop?)".to_string()))
                }
                (libc::SIGXFSZ, Some(l)) => (
                    Category::TooMuchOutput,
                    Some(format!("a file or its output passed the limit of {} MiB", l.file_size >> 20)),
                ),
                (libc::SIGABRT, _) => (Category::Crashed, Some("aborted".to_string())),
                (libc::SIGKILL, _) => {
                    (Category::Crashed, Some("killed (by the system's out-of-memory killer?)".to_string()))
                }
                (libc::SIGSEGV, _) => (Category::Crashed, Some("segmentation fault".to_string())),
                _ => (Category::Crashed, Some(format!("signal {signal}"))),
            };
        }
        let last = self.stderr.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("no message");
        (Category::Failed, Some(format!("{status}: {last}")))
    }
}

/// How a child failed, as a fixed word: all that is reported of a hidden check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    /// It ended with an error status.
    Failed,
    /// It panicked.
    Panicked,
    /// It crashed: a signal, an abort, a stack overflow.
    Crashed,
    /// It ran past its time limit or its CPU time.
    OutOfTime,
    /// It ran out of memory.
    OutOfMemory,
    /// It wrote more than the file size limit.
    TooMuchOutput,
}

impl std::fmt::Display for Category {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Category::Failed => "failed",
            Category::Panicked => "panicked",
            Category::Crashed => "crashed",
            Category::OutOfTime => "ran out of time",
            Category::OutOfMemory => "ran out of memory",
            Category::TooMuchOutput => "wrote too much output",
        })
    }
}

/// Why a child failed: its category, and what it wrote, already [`quote()`]d.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// The fixed word.
    pub category: Category,
    /// More, from the child's own output: never shown for a hidden check.
    pub detail: Option<String>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.detail {
            Some(detail) => write!(f, "{}: {detail}", self.category),
            None => write!(f, "{}", self.category),
        }
    }
}

/// A graded child's own folder, fresh and empty: its `TMPDIR` and the only place the sandbox lets
/// it write. Removed when dropped.
#[derive(Debug)]
pub struct OwnFolder(PathBuf);

impl OwnFolder {
    /// A new folder under the system's temporary folder.
    pub fn new() -> std::io::Result<OwnFolder> {
        static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("raylab-graded-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir)?;
        Ok(OwnFolder(dir))
    }

    /// Where it is.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for OwnFolder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The folders of a tree that graded code reads at run time: its scenes and meshes, public and
/// hidden. Nothing else of the tree (its sources, tests, references) is readable inside the walls.
pub fn graded_reads(root: &Path) -> Vec<PathBuf> {
    ["scenes", "hidden/scenes"].iter().map(|d| root.join(d)).collect()
}

/// Runs graded code: `command` for at most `limit`, under [`Limits::GRADED`], with `own` as its
/// folder, and inside the sandbox's walls (reading only `read` beyond its program and the system)
/// when a launcher is set.
pub fn run_graded(
    command: Command,
    limit: Duration,
    read: &[PathBuf],
    own: &OwnFolder,
) -> std::io::Result<ChildRun> {
    let walls = Walls {
        profile: Profile::Run,
        read: read.to_vec(),
        write: vec![own.path().to_path_buf()],
        limits: Limits::GRADED.expect("graded code has limits"),
        cpu_seconds: cpu_seconds(limit),
        user: None,
    };
    run_walled(command, limit, walls)
}

/// Builds graded code: `cargo` (`command`) for at most `limit`, reading `tree` and writing
/// `target`, under [`Limits::BUILD`] and the build's walls when a launcher is set.
pub fn run_build(command: Command, limit: Duration, tree: &Path, target: &Path) -> std::io::Result<ChildRun> {
    // Made here: cargo would make it beside, in a folder the build may not write.
    std::fs::create_dir_all(target)?;
    let own = OwnFolder::new()?;
    let walls = Walls {
        profile: Profile::Build,
        read: vec![tree.to_path_buf()],
        write: vec![own.path().to_path_buf(), target.to_path_buf()],
        limits: Limits::BUILD.expect("builds have limits"),
        cpu_seconds: cpu_seconds(limit),
        user: None,
    };
    run_walled(command, limit, walls)
}

/// `command` inside `walls` if a launcher is set, else with their limits only; `TMPDIR` is the
/// first folder it may write.
fn run_walled(mut command: Command, limit: Duration, walls: Walls) -> std::io::Result<ChildRun> {
    command.env("TMPDIR", &walls.write[0]);
    let Some(launcher) = crate::run::sandbox::launcher_path() else {
        return run_watched(command, limit, Some(walls.limits), Some((&walls.write, walls.limits.written)));
    };
    let without = crate::run::sandbox::left_out();
    let walls = crate::run::sandbox::with_user(walls, &command, &without)?;
    let wrapped = crate::run::sandbox::wrap(launcher, &command, &walls, &without);
    let mut run = run_watched(wrapped, limit, None, Some((&walls.write, walls.limits.written)))?;
    run.limits = Some(walls.limits);
    Ok(run)
}

/// CPU seconds for a child with wall-clock `limit`: the limit on every core, so a busy correct
/// render never meets it before the wall clock does; it stops a spinning child the wall clock
/// has not reached yet.
fn cpu_seconds(limit: Duration) -> u64 {
    limit.as_secs().max(1) * std::thread::available_parallelism().map_or(2, |n| n.get() as u64)
}

/// Runs `command` for at most `limit` (wall clock) under `limits`, then kills its process group.
/// Callers mark grader children with [`CHILD_ENV`]. Output goes through temporary files, so a
/// child printing a lot never blocks on a full pipe; each stream is read back up to 1 MiB.
pub fn run_with_limit(command: Command, limit: Duration) -> std::io::Result<ChildRun> {
    run_limited(command, limit, None)
}

/// [`run_with_limit`] with resource limits (see [`Limits::GRADED`]).
pub fn run_limited(command: Command, limit: Duration, limits: Option<Limits>) -> std::io::Result<ChildRun> {
    run_watched(command, limit, limits, None)
}

/// [`run_limited`], the child stopped when the folders of `written` grow past its budget: that
/// one is always the grader's to watch ([`written`]); the other limits are applied here when
/// `limits` is given, by the launcher otherwise.
fn run_watched(
    mut command: Command,
    limit: Duration,
    limits: Option<Limits>,
    written: Option<(&[PathBuf], Budget)>,
) -> std::io::Result<ChildRun> {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let base: PathBuf = std::env::temp_dir().join(format!("raylab-grader-{}-{n}", std::process::id()));
    let (out_path, err_path) = (base.with_extension("out"), base.with_extension("err"));
    command
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path)?)
        .stderr(std::fs::File::create(&err_path)?)
        // No report shows a backtrace, and capturing one costs about 0.1 s a panic: a stub's ten
        // failing tests took 1.1 s with RUST_BACKTRACE=1 in the grader's environment, 0.06 s without.
        .env("RUST_BACKTRACE", "0")
        .env("RUST_LIB_BACKTRACE", "0");
    #[cfg(unix)]
    isolate(&mut command, limit, limits);
    let mut watch = written.map(|(folders, budget)| Watch::start(folders, budget));
    let mut wrote_too_much = false;
    let start = Instant::now();
    let mut child = command.spawn()?;
    if let Some(watch) = watch.as_mut() {
        watch.follow(child.id());
    }
    let mut status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        if start.elapsed() >= limit {
            break None;
        }
        if watch.as_mut().is_some_and(Watch::exceeded) {
            wrote_too_much = true;
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    if status.is_some() && watch.as_ref().is_some_and(Watch::left_too_much) {
        (wrote_too_much, status) = (true, None);
    }
    // The child and everything it started: a test binary under cargo, a thread-holding grandchild.
    #[cfg(unix)]
    kill_group(child.id());
    let _ = child.kill();
    let _ = child.wait();
    let seconds = start.elapsed().as_secs_f64();
    let read = |p: &PathBuf| {
        let bytes = std::fs::read(p).unwrap_or_default();
        String::from_utf8_lossy(&bytes[..bytes.len().min(1 << 20)]).into_owned()
    };
    let (stdout, stderr) = (read(&out_path), read(&err_path));
    let run = ChildRun { status, stdout, stderr, seconds, limits, wrote_too_much };
    let _ = std::fs::remove_file(out_path);
    let _ = std::fs::remove_file(err_path);
    Ok(run)
}

/// A process group of its own (so [`kill_group`] reaches everything the child starts), and the
/// resource limits, set in the child between fork and exec.
#[cfg(unix)]
fn isolate(command: &mut Command, limit: Duration, limits: Option<Limits>) {
    use std::os::unix::process::CommandExt;
    command.process_group(0);
    let Some(limits) = limits else { return };
    let cpu = cpu_seconds(limit);
    let set = move || {
        let pairs = [
            (libc::RLIMIT_AS, limits.memory),
            (libc::RLIMIT_FSIZE, limits.file_size),
            (libc::RLIMIT_CPU, cpu),
        ];
        for (resource, value) in pairs {
            let rlimit = libc::rlimit { rlim_cur: value as libc::rlim_t, rlim_max: value as libc::rlim_t };
            // SAFETY: setrlimit is async-signal-safe and only reads the struct passed to it.
            if unsafe { libc::setrlimit(resource, &rlimit) } != 0 {
                return Err(std::io::Error::last_os_error());
            }
        }
        Ok(())
    };
    // SAFETY: the closure calls only setrlimit, which is safe between fork and exec.
    unsafe {
        command.pre_exec(set);
    }
}

/// Kills the process group `id` leads (the child's own, see [`isolate`]), if any is left.
#[cfg(unix)]
fn kill_group(id: u32) {
    if let Ok(pid) = libc::pid_t::try_from(id) {
        // SAFETY: kill only sends a signal; a group that no longer exists gives ESRCH, ignored.
        unsafe {
            libc::kill(-pid, libc::SIGKILL);
        }
    }
}

#[cfg(all(test, unix))]
mod tests;
