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

    /// Why the child failed, in one line, with what it said quoted ([`quote`]): for public
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

/// Why a child failed: its category, and what it wrote, already [`quote`]d.
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
mod tests {
    use super::*;
    use crate::plain::MAX_QUOTE_CHARS;

    fn sh(script: &str) -> Command {
        let mut c = Command::new("sh");
        c.arg("-c").arg(script);
        c
    }

    /// A marker file that a background job of the child would create after a second.
    fn marker_after_a_second(name: &str) -> (PathBuf, String) {
        let marker = std::env::temp_dir().join(format!("raylab-{name}-{}", std::process::id()));
        let job = format!("(sleep 1; touch {}) &", marker.display());
        (marker, job)
    }

    #[test]
    fn grader_kills_what_a_child_leaves_running() {
        let (marker, job) = marker_after_a_second("orphan");
        let run = run_with_limit(sh(&format!("{job} exit 0")), Duration::from_secs(10)).unwrap();
        assert!(run.success());
        std::thread::sleep(Duration::from_millis(1500));
        assert!(!marker.exists(), "the background job outlived its parent");
    }

    #[test]
    fn grader_stops_a_child_and_its_group_at_the_time_limit() {
        let (marker, job) = marker_after_a_second("timeout");
        let limit = Duration::from_millis(300);
        let run = run_with_limit(sh(&format!("{job} sleep 30")), limit).unwrap();
        assert!(run.status.is_none() && run.failure(limit).category == Category::OutOfTime);
        std::thread::sleep(Duration::from_millis(1500));
        assert!(!marker.exists(), "the background job outlived the time limit");
    }

    #[test]
    fn grader_limits_the_size_of_files_a_graded_child_writes() {
        let limits = Some(Limits { file_size: 1 << 20, ..Limits::GRADED.unwrap() });
        let path = std::env::temp_dir().join(format!("raylab-big-{}", std::process::id()));
        let script = format!("head -c 4000000 /dev/zero > {}", path.display());
        let run = run_limited(sh(&script), Duration::from_secs(10), limits).unwrap();
        let size = std::fs::metadata(&path).map_or(0, |m| m.len());
        let _ = std::fs::remove_file(&path);
        assert!(!run.success() && size <= 1 << 20, "wrote {size} bytes");
    }

    /// 300 files of 1 MiB, each under the per-file limit, pass a 64 MiB budget: the child is
    /// stopped near it, with the reason a report gives. It pauses 10 ms a file, so the whole
    /// takes at least 3 s and the watch looks a dozen times before it could end.
    #[test]
    fn grader_bounds_what_a_graded_child_writes_in_all() {
        let own = OwnFolder::new().unwrap();
        let limits =
            Limits { written: Budget { bytes: 64 << 20, entries: 1_000 }, ..Limits::GRADED.unwrap() };
        let script = format!(
            "for i in $(seq 300); do head -c 1048576 /dev/zero > {}/$i; sleep 0.01; done",
            own.path().display()
        );
        let limit = Duration::from_secs(60);
        let walls = Walls {
            profile: Profile::Run,
            read: Vec::new(),
            write: vec![own.path().to_path_buf()],
            limits,
            cpu_seconds: 60,
            user: None,
        };
        let run = run_walled(sh(&script), limit, walls).unwrap();
        let written = std::fs::read_dir(own.path()).unwrap().count();
        assert!(run.wrote_too_much && !run.success(), "{run:?}");
        assert!((64..300).contains(&written), "{written} files of 1 MiB left");
        assert_eq!(
            run.failure(limit).to_string(),
            "wrote too much output: its files passed 64 MiB or 1000 entries in all"
        );
    }

    /// Files opened and unlinked hold disk that no walk of the folder sees (until the child ends,
    /// so this one holds seven of 10 MiB open): the bytes the child wrote count anyway.
    #[test]
    fn grader_counts_what_a_graded_child_writes_into_unlinked_files() {
        let own = OwnFolder::new().unwrap();
        let limits =
            Limits { written: Budget { bytes: 64 << 20, entries: 1_000 }, ..Limits::GRADED.unwrap() };
        let script = format!(
            "cd {}; for i in 3 4 5 6 7 8 9; do eval \"exec $i>f\"; rm f; head -c 10485760 /dev/zero >&$i; done; sleep 30",
            own.path().display()
        );
        let walls = Walls {
            profile: Profile::Run,
            read: Vec::new(),
            write: vec![own.path().to_path_buf()],
            limits,
            cpu_seconds: 60,
            user: None,
        };
        let run = run_walled(sh(&script), Duration::from_secs(60), walls).unwrap();
        assert!(run.wrote_too_much && run.seconds < 30.0, "{run:?}");
        assert!(std::fs::read_dir(own.path()).unwrap().next().is_none(), "the files were unlinked");
    }

    /// A child that ends before the first look is measured once more: what it left behind counts,
    /// what it wrote and removed again does not.
    #[test]
    fn grader_measures_what_a_quick_child_left_behind() {
        let own = OwnFolder::new().unwrap();
        let file = own.path().join("big");
        std::fs::write(&file, vec![1u8; 2 << 20]).unwrap();
        let limits = Limits { written: Budget { bytes: 1 << 20, entries: 1_000 }, ..Limits::GRADED.unwrap() };
        let run = |script: String| {
            let walls = Walls {
                profile: Profile::Run,
                read: Vec::new(),
                write: vec![own.path().to_path_buf()],
                limits,
                cpu_seconds: 60,
                user: None,
            };
            run_walled(sh(&script), Duration::from_secs(60), walls).unwrap()
        };
        let copy = format!("cp {0} {0}.copy", file.display());
        let removed = run(format!("{copy}; rm {}.copy", file.display()));
        assert!(removed.success(), "{removed:?}");
        let left = run(copy);
        assert!(left.wrote_too_much && !left.success() && left.seconds < 0.25, "{left:?}");
    }

    /// What a child writes reaches a report on one clean line of at most 200 characters, and
    /// each way of failing has its fixed word.
    #[test]
    fn grader_quotes_a_child_on_one_short_clean_line() {
        let text = format!("\x1b[31mred\x1b[0m\r\nsecond\tline {}", "é".repeat(500));
        let quoted = quote(&text);
        assert!(quoted.starts_with("[31mred [0m second line éé"), "{quoted}");
        assert!(!quoted.chars().any(char::is_control));
        assert_eq!(quoted.chars().count(), MAX_QUOTE_CHARS + 3);
        let limit = Duration::from_secs(10);
        let failure = |script: &str| run_with_limit(sh(script), limit).unwrap().failure(limit);
        let panicked = failure(&format!("echo 'x\n{PANIC_PREFIX}boom\x1b[2J' >&2; exit 101"));
        assert_eq!(panicked, Failure { category: Category::Panicked, detail: Some("boom [2J".to_string()) });
        assert_eq!(failure("echo last words >&2; exit 3").to_string(), "failed: exit status: 3: last words");
        assert_eq!(failure("kill -ABRT $$").to_string(), "crashed: aborted");
        let mut head = Command::new("head");
        head.args(["-c", "3000000", "/dev/zero"]);
        let too_much =
            run_limited(head, limit, Some(Limits { file_size: 1 << 20, ..Limits::GRADED.unwrap() })).unwrap();
        assert_eq!(too_much.failure(limit).category, Category::TooMuchOutput);
    }
}
