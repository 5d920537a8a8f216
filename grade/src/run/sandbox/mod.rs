//! The walls around graded code: what a render or a unit test of a submission may do while it
//! runs.
//!
//! The grader never restricts itself. It starts every graded process through a launcher, its
//! own executable started again as `grader __sandbox ...` ([`launcher`]): a fresh process with
//! one thread, which raises the walls around itself and then becomes the graded program by
//! `execveat` on a descriptor it opened. The walls hold across that exec and for every thread the
//! graded program starts:
//!
//! - **processes** (seccomp, [`filter`]): no `execve`, no `fork`/`vfork`, `clone` only for threads,
//!   `clone3` reported as missing (so the C library falls back to `clone`), no `setsid`/`setpgid`,
//!   no signals but to itself, no `ptrace`, no raising a limit, no io_uring, no namespaces. The
//!   launcher's own exec passes because it names a descriptor number the graded program cannot
//!   open: the file-descriptor limit is set just below it.
//! - **network** (seccomp): `socket` and `socketpair` for `AF_UNIX` only.
//! - **files** (Landlock, [`files`]): read the system's libraries, the program, and the folders
//!   the caller names; write only the child's own folder. Landlock also scopes signals and
//!   abstract sockets to the sandbox where the kernel has it (ABI 6).
//! - **user** ([`user`]): where the grader is root, graded code runs as a user of its own that
//!   owns nothing but its folders.
//! - **bytes written** ([`crate::run::child::written`]): the grader stops a child whose folders grow
//!   past a budget, over all files.
//! - **resources** (rlimits, [`Limits`]): address space, CPU time, file size,
//!   no core dumps.
//! - **lifetime**: the launcher asks to be killed when the grader's thread that started it ends
//!   (`PR_SET_PDEATHSIG`), so a killed grader leaves nothing running; a graded process cannot
//!   start another process, so nothing outlives it.
//!
//! Why this makes the per-checkpoint switch unreachable ([`crate::submission::splice`]): the switch is read
//! in the graded process; running the solution instead needs a second process started without it,
//! and no graded process can start one.
//!
//! Outside Linux, and when no launcher is set (the library's own tests), graded processes run
//! with the resource limits only; [`crate::run::probe::check`] says which walls this machine gives.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

#[cfg(target_os = "linux")]
pub mod files;
#[cfg(target_os = "linux")]
pub mod filter;
#[cfg(target_os = "linux")]
pub mod launcher;
mod limits;
#[cfg(target_os = "linux")]
pub mod user;
#[cfg(target_os = "linux")]
pub mod wall_error;

pub use limits::{Budget, Limits};

/// The first argument that makes the grader's executable the launcher.
pub const LAUNCH: &str = "__sandbox";

/// Which walls: a graded program's, or a build's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Profile {
    /// A render or a unit test: no processes, no exec, no network, its scenes and its folder.
    Run,
    /// `cargo` building a submission: it runs compilers and the linker (exec and processes
    /// allowed), but reaches no network, no other process, and reads only the tree, the
    /// toolchain and the system; it writes its target folder and its own folder.
    Build,
}

/// What one graded process may read and write, and its limits.
#[derive(Clone, Debug)]
pub struct Walls {
    /// A run's walls or a build's.
    pub profile: Profile,
    /// Folders and files it may read (and execute), besides the system's libraries and its
    /// own program.
    pub read: Vec<PathBuf>,
    /// Its own folder, the only place it may write (also its `TMPDIR`), and for a build its
    /// target folder.
    pub write: Vec<PathBuf>,
    /// Its resource limits.
    pub limits: Limits,
    /// CPU seconds, over all its threads.
    pub cpu_seconds: u64,
    /// The user it runs as, where the grader is root ([`user`]); `None`: the grader's own.
    pub user: Option<u32>,
}

/// One wall, as the launcher's `--without` names it (test builds only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wall {
    /// The seccomp filter: processes, exec, network, signals.
    Seccomp,
    /// Landlock: files.
    Landlock,
    /// The resource limits.
    Limits,
    /// A user of its own where the grader is root: files, signals, tracing.
    User,
}

impl Wall {
    /// Every wall.
    pub const ALL: [Wall; 4] = [Wall::Seccomp, Wall::Landlock, Wall::Limits, Wall::User];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Wall::Seccomp => "seccomp",
            Wall::Landlock => "landlock",
            Wall::Limits => "limits",
            Wall::User => "user",
        }
    }
}

/// The walls missing on this machine when someone else's code is graded here anyway.
static MISSING: OnceLock<Vec<String>> = OnceLock::new();

/// Records the required walls `grader submission DIR` or `grader batch` found missing and graded
/// without (`--no-sandbox`), for [`missing_note`].
pub fn note_missing(lines: Vec<String>) {
    let _ = MISSING.set(lines);
}

/// What every report of this run says when it was graded without some wall.
pub fn missing_note() -> Option<String> {
    let missing = MISSING.get().filter(|m| !m.is_empty())?;
    Some(format!("Graded without some of the sandbox's walls on this machine: {}.", missing.join("; ")))
}

/// The launcher: the grader's executable, set once by the `grader` binary.
static LAUNCHER: OnceLock<PathBuf> = OnceLock::new();

/// Makes `executable` (the running `grader`) the launcher of every graded process.
pub fn set_launcher(executable: PathBuf) {
    let _ = LAUNCHER.set(executable);
}

/// The launcher, if one is set and this platform has walls (Linux on the two architectures the
/// seccomp filter is written for).
pub fn launcher_path() -> Option<&'static Path> {
    if cfg!(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64"))) {
        LAUNCHER.get().map(PathBuf::as_path)
    } else {
        None
    }
}

/// `walls` with the user a process running `command` changes to, unless the user wall is left
/// out in `without` or this machine cannot have it ([`user::for_launch`]); the folders it may
/// write are given to that user.
pub fn with_user(walls: Walls, command: &Command, without: &[Wall]) -> std::io::Result<Walls> {
    #[cfg(target_os = "linux")]
    if launcher_path().is_some() && !without.contains(&Wall::User) {
        let program = on_path(command.get_program());
        let Ok(uid) = user::for_launch(&walls, &program, command.get_current_dir()) else { return Ok(walls) };
        for folder in &walls.write {
            user::give(folder, uid, true)?;
        }
        return Ok(Walls { user: Some(uid), ..walls });
    }
    let _ = (command, without);
    Ok(walls)
}

/// Test builds only: the walls named in `RAYLAB_SANDBOX_WITHOUT` (`seccomp,landlock,limits,user`) are
/// left out of every graded process, to measure what each one stops. Release builds have none.
pub fn left_out() -> Vec<Wall> {
    let names = if cfg!(debug_assertions) {
        std::env::var("RAYLAB_SANDBOX_WITHOUT").unwrap_or_default()
    } else {
        String::new()
    };
    Wall::ALL.into_iter().filter(|w| names.split(',').any(|n| n == w.name())).collect()
}

/// `command` started through `launcher` inside `walls`, leaving out the walls in `without`
/// (accepted by test builds of the launcher only): the same program, arguments and working
/// folder, the variables set on `command` and `PATH` (nothing else of the grader's environment),
/// and `TMPDIR` set to the child's own folder.
pub fn wrap(launcher: &Path, command: &Command, walls: &Walls, without: &[Wall]) -> Command {
    let mut wrapped = Command::new(launcher);
    wrapped.arg(LAUNCH);
    // The launcher starts in the child's working folder: a relative path would name another place.
    let absolute = |path: &Path| std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    if walls.profile == Profile::Build {
        wrapped.arg("--build");
    }
    for path in &walls.read {
        wrapped.arg("--read").arg(absolute(path));
    }
    for path in &walls.write {
        wrapped.arg("--write").arg(absolute(path));
    }
    let numbers = [
        ("--memory", walls.limits.memory),
        ("--file-size", walls.limits.file_size),
        ("--cpu", walls.cpu_seconds),
    ];
    for (flag, value) in numbers {
        wrapped.arg(flag).arg(value.to_string());
    }
    wrapped.arg("--parent").arg(std::process::id().to_string());
    if let Some(uid) = walls.user {
        wrapped.arg("--user").arg(uid.to_string());
    }
    for wall in without {
        wrapped.arg("--without").arg(wall.name());
    }
    wrapped.arg("--").arg(on_path(command.get_program())).args(command.get_args());
    // Nothing of the grader's environment but PATH (and a build's cargo and rustup settings):
    // the machine's variables (tokens, the test run's settings) are none of the graded code's
    // business, and a build could compile them in with `option_env!`.
    wrapped.env_clear();
    for (key, value) in std::env::vars_os().filter(|(k, _)| kept(k, walls.profile)) {
        wrapped.env(key, value);
    }
    for (key, value) in command.get_envs() {
        match value {
            Some(value) => wrapped.env(key, value),
            None => wrapped.env_remove(key),
        };
    }
    if let Some(dir) = command.get_current_dir() {
        wrapped.current_dir(dir);
    }
    if let Some(own) = walls.write.first() {
        wrapped.env("TMPDIR", own);
    }
    wrapped
}

/// Whether a variable of the grader's environment reaches a child of `profile`: `PATH`, and for a
/// build `HOME` and cargo's and rustup's own settings (`CARGO_*`, `RUSTUP_*`, `RUSTFLAGS`).
fn kept(key: &std::ffi::OsStr, profile: Profile) -> bool {
    let key = key.to_str().unwrap_or("");
    let build =
        ["HOME", "RUSTFLAGS"].contains(&key) || key.starts_with("CARGO_") || key.starts_with("RUSTUP_");
    key == "PATH" || (profile == Profile::Build && build)
}

/// `program` found on `PATH` when it is a bare name (`cargo`): the launcher opens it by path.
pub(crate) fn on_path(program: &std::ffi::OsStr) -> PathBuf {
    let name = Path::new(program);
    if name.components().count() != 1 {
        return name.to_path_buf();
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path).map(|dir| dir.join(name)).find(|p| p.is_file()).unwrap_or(name.to_path_buf())
}

/// What the launcher was asked to do, parsed from its arguments.
#[derive(Clone, Debug)]
pub struct Launch {
    /// The walls.
    pub walls: Walls,
    /// The grader's process id: the launcher stops if it is no longer its parent.
    pub parent: u32,
    /// Walls left out (test builds only).
    pub without: Vec<Wall>,
    /// The program and its arguments.
    pub program: Vec<OsString>,
}

/// What is wrong with the launcher's arguments (the grader writes them: a bug, or a person
/// starting `grader __sandbox` by hand).
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum ArgumentError {
    /// A flag without its value.
    #[error("{0} needs a value")]
    NoValue(&'static str),
    /// A flag whose value is not a whole number.
    #[error("{0} needs a number")]
    NotANumber(&'static str),
    /// `--without` names no wall.
    #[error("no wall is called {0:?}")]
    UnknownWall(String),
    /// An argument the launcher does not know.
    #[error("unknown launcher argument {0:?}")]
    Unknown(String),
    /// `--without` given to a release build.
    #[error("--without is accepted by test builds only")]
    WithoutInRelease,
    /// No program after `--`, or no folder to write.
    #[error("the launcher needs --write DIR and a program after --")]
    NoProgram,
}

/// The launcher's flags that take a value.
const VALUED: [&str; 8] =
    ["--read", "--write", "--memory", "--file-size", "--cpu", "--parent", "--user", "--without"];

/// Parses the launcher's arguments (those after [`LAUNCH`]).
pub fn parse_launch(args: &[OsString]) -> Result<Launch, ArgumentError> {
    let mut walls = Walls {
        profile: Profile::Run,
        read: Vec::new(),
        write: Vec::new(),
        limits: Limits { memory: 0, file_size: 0, written: Budget { bytes: 0, entries: 0 } },
        cpu_seconds: 0,
        user: None,
    };
    let (mut parent, mut without) = (0, Vec::new());
    let mut args = args.iter();
    while let Some(arg) = args.next() {
        let flag = match arg.to_str().unwrap_or("") {
            "--" => break,
            "--build" => {
                walls.profile = Profile::Build;
                continue;
            }
            flag => {
                VALUED.into_iter().find(|f| *f == flag).ok_or_else(|| ArgumentError::Unknown(flag.into()))?
            }
        };
        let value = args.next().ok_or(ArgumentError::NoValue(flag))?;
        let number =
            || value.to_str().and_then(|v| v.parse::<u64>().ok()).ok_or(ArgumentError::NotANumber(flag));
        match flag {
            "--read" => walls.read.push(value.into()),
            "--write" => walls.write.push(value.into()),
            "--memory" => walls.limits.memory = number()?,
            "--file-size" => walls.limits.file_size = number()?,
            "--cpu" => walls.cpu_seconds = number()?,
            "--parent" => parent = number()? as u32,
            "--user" => walls.user = Some(number()? as u32),
            _ => {
                let name = value.to_str().unwrap_or("");
                let wall = Wall::ALL.into_iter().find(|w| w.name() == name);
                without.push(wall.ok_or_else(|| ArgumentError::UnknownWall(name.to_string()))?);
            }
        }
    }
    if !without.is_empty() && !cfg!(debug_assertions) {
        return Err(ArgumentError::WithoutInRelease);
    }
    let program: Vec<OsString> = args.cloned().collect();
    if program.is_empty() || walls.write.is_empty() {
        return Err(ArgumentError::NoProgram);
    }
    Ok(Launch { walls, parent, without, program })
}

#[cfg(test)]
mod tests;
