//! Probes: one attempt at something a wall forbids, made by the grader's own executable started
//! through the launcher as `grader __probe ATTEMPT [ARG]`. It prints `allowed` or `refused: ...`
//! and exits 0 or 3. `grader sandbox --check` and the sandbox's tests measure the walls with them,
//! never assume them.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::run::child::run_with_limit;
#[cfg(target_os = "linux")]
use crate::run::sandbox::user;
use crate::run::sandbox::{launcher_path, on_path, with_user, wrap, Limits, Profile, Wall, Walls};

/// The first argument that makes the grader's executable a probe.
pub const PROBE: &str = "__probe";

/// Exit status of a probe whose attempt was refused.
pub const REFUSED: i32 = 3;

/// One attempt, with the wall that forbids it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attempt {
    /// Run `/bin/sh -c true`.
    ExecShell,
    /// Run the probe's own executable again.
    ExecSelf,
    /// `fork()`.
    Fork,
    /// Start a thread: must always be allowed.
    Thread,
    /// Connect over TCP to the address in ARG.
    Tcp,
    /// Send a UDP datagram to the address in ARG.
    Udp,
    /// Send signal 0 to the process in ARG.
    Signal,
    /// Attach to the process in ARG with `ptrace` (`PTRACE_SEIZE`, which stops nothing).
    Ptrace,
    /// Leave its process group for the group of the process in ARG (`setpgid`), where the
    /// grader's kill of the child's group would miss it. (`setsid` needs no wall: the launcher
    /// leads its own group, and a group leader cannot start a session.)
    Setpgid,
    /// Read the file in ARG.
    Read,
    /// Write the file in ARG.
    Write,
    /// Reserve ARG bytes of memory.
    Allocate,
}

impl Attempt {
    /// Every attempt.
    pub const ALL: [Attempt; 12] = [
        Attempt::ExecShell,
        Attempt::ExecSelf,
        Attempt::Fork,
        Attempt::Thread,
        Attempt::Tcp,
        Attempt::Udp,
        Attempt::Signal,
        Attempt::Ptrace,
        Attempt::Setpgid,
        Attempt::Read,
        Attempt::Write,
        Attempt::Allocate,
    ];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Attempt::ExecShell => "exec-shell",
            Attempt::ExecSelf => "exec-self",
            Attempt::Fork => "fork",
            Attempt::Thread => "thread",
            Attempt::Tcp => "tcp",
            Attempt::Udp => "udp",
            Attempt::Signal => "signal",
            Attempt::Ptrace => "ptrace",
            Attempt::Setpgid => "setpgid",
            Attempt::Read => "read",
            Attempt::Write => "write",
            Attempt::Allocate => "allocate",
        }
    }

    /// The walls that forbid it, first the one meant for it.
    pub fn walls(self) -> &'static [Wall] {
        match self {
            Attempt::ExecShell | Attempt::ExecSelf | Attempt::Fork | Attempt::Udp => &[Wall::Seccomp],
            Attempt::Setpgid => &[Wall::Seccomp],
            Attempt::Tcp => &[Wall::Seccomp, Wall::Landlock],
            Attempt::Signal | Attempt::Ptrace => &[Wall::Seccomp, Wall::Landlock, Wall::User],
            Attempt::Read | Attempt::Write => &[Wall::Landlock, Wall::User],
            Attempt::Allocate => &[Wall::Limits],
            Attempt::Thread => &[],
        }
    }
}

/// Makes the attempt named by `args` (`ATTEMPT [ARG]`) and returns the probe's exit status.
pub fn run(args: &[std::ffi::OsString]) -> i32 {
    let name = args.first().and_then(|a| a.to_str()).unwrap_or("");
    let arg = args.get(1).map(|a| a.to_string_lossy().into_owned()).unwrap_or_default();
    let Some(attempt) = Attempt::ALL.into_iter().find(|a| a.name() == name) else {
        eprintln!("probe: no attempt is called {name:?}");
        return 2;
    };
    match attempt_result(attempt, &arg) {
        Ok(()) => {
            println!("allowed");
            0
        }
        Err(e) => {
            println!("refused: {e}");
            REFUSED
        }
    }
}

fn attempt_result(attempt: Attempt, arg: &str) -> std::io::Result<()> {
    let last = std::io::Error::last_os_error;
    let check = |result: libc::c_long| if result < 0 { Err(last()) } else { Ok(()) };
    let pid = || arg.parse::<libc::pid_t>().map_err(std::io::Error::other);
    match attempt {
        Attempt::ExecShell => Command::new("/bin/sh").args(["-c", "true"]).status().map(drop),
        Attempt::ExecSelf => Command::new(std::env::current_exe()?).arg("--version").output().map(drop),
        Attempt::Fork => {
            // SAFETY: the child exits at once without touching anything; the parent reaps it.
            let child = unsafe { libc::fork() };
            if child == 0 {
                // SAFETY: _exit is async-signal-safe.
                unsafe { libc::_exit(0) }
            }
            check(child as libc::c_long)?;
            // SAFETY: waitpid on our own child.
            unsafe { libc::waitpid(child, std::ptr::null_mut(), 0) };
            Ok(())
        }
        Attempt::Thread => {
            std::thread::spawn(|| 1 + 1).join().map(drop).map_err(|_| std::io::Error::other("join"))
        }
        Attempt::Tcp => std::net::TcpStream::connect_timeout(&addr(arg)?, Duration::from_secs(2)).map(drop),
        Attempt::Udp => std::net::UdpSocket::bind("127.0.0.1:0")?.send_to(b"probe", addr(arg)?).map(drop),
        // SAFETY: signal 0 only checks that the signal could be sent.
        Attempt::Signal => check(unsafe { libc::kill(pid()?, 0) } as libc::c_long),
        Attempt::Ptrace => {
            let (seize, detach) = (libc::PTRACE_SEIZE, libc::PTRACE_DETACH);
            // SAFETY: PTRACE_SEIZE attaches without stopping the target; detached at once.
            check(unsafe { libc::ptrace(seize, pid()?, 0, 0) })?;
            // SAFETY: as above.
            unsafe { libc::ptrace(detach, pid()?, 0, 0) };
            Ok(())
        }
        // SAFETY: getpgid and setpgid take no pointers.
        Attempt::Setpgid => check(unsafe { libc::setpgid(0, libc::getpgid(pid()?)) } as libc::c_long),
        Attempt::Read => std::fs::read(arg).map(drop),
        Attempt::Write => std::fs::write(arg, "probe"),
        Attempt::Allocate => {
            let bytes = arg.parse::<usize>().map_err(std::io::Error::other)?;
            Vec::<u8>::new().try_reserve_exact(bytes).map_err(|e| std::io::Error::other(e.to_string()))
        }
    }
}

fn addr(arg: &str) -> std::io::Result<std::net::SocketAddr> {
    arg.parse().map_err(std::io::Error::other)
}

/// Why a probe did not say whether its attempt was allowed.
#[derive(Debug, thiserror::Error)]
pub enum ProbeError {
    /// Its folder could not be made.
    #[error("cannot create {}: {source}", .dir.display())]
    Folder {
        /// The folder.
        dir: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// Its folder could not be given to the graded user.
    #[error("cannot give {} to the graded user: {source}", .dir.display())]
    GiveToUser {
        /// The folder.
        dir: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The launcher could not be started.
    #[error("cannot start the probe: {0}")]
    Start(std::io::Error),
    /// It ended without saying `allowed` or `refused` (the launcher could not raise a wall).
    #[error("the {attempt} probe did not run: {output}")]
    DidNotRun {
        /// The attempt's name.
        attempt: &'static str,
        /// What it printed.
        output: String,
    },
}

/// Whether `attempt` (with `arg`) succeeds in a probe started through `launcher` inside the
/// walls a graded run gets, leaving out `without`; `Err` if the probe did not run.
pub fn allowed(launcher: &Path, attempt: Attempt, arg: &str, without: &[Wall]) -> Result<bool, ProbeError> {
    allowed_in(launcher, Profile::Run, attempt, arg, without)
}

/// [`allowed`] inside the walls of `profile`.
pub fn allowed_in(
    launcher: &Path,
    profile: Profile,
    attempt: Attempt,
    arg: &str,
    without: &[Wall],
) -> Result<bool, ProbeError> {
    let own = tempdir("probe")?;
    let mut probe = Command::new(launcher);
    probe.arg(PROBE).arg(attempt.name()).arg(arg);
    let walls = Walls {
        profile,
        read: Vec::new(),
        write: vec![own.clone()],
        limits: Limits::GRADED.expect("graded limits"),
        cpu_seconds: 10,
        user: None,
    };
    let walls = with_user(walls, &probe, without)
        .map_err(|source| ProbeError::GiveToUser { dir: own.clone(), source })?;
    let run = run_with_limit(wrap(launcher, &probe, &walls, without), Duration::from_secs(20));
    let _ = std::fs::remove_dir_all(&own);
    let run = run.map_err(ProbeError::Start)?;
    match run.status.and_then(|s| s.code()) {
        Some(0) if run.stdout.starts_with("allowed") => Ok(true),
        Some(REFUSED) => Ok(false),
        _ => Err(ProbeError::DidNotRun {
            attempt: attempt.name(),
            output: format!("{}{}", run.stdout, run.stderr.trim()),
        }),
    }
}

/// A fresh folder under the system's temporary folder.
fn tempdir(what: &str) -> Result<PathBuf, ProbeError> {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("raylab-{what}-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|source| ProbeError::Folder { dir: dir.clone(), source })?;
    Ok(dir)
}

/// Each wall of this machine, measured: what a graded process tried and whether it was refused.
pub fn measure(launcher: &Path) -> Vec<Measured> {
    let outside = match tempdir("outside") {
        Ok(dir) => dir,
        Err(e) => return vec![Measured { line: e.to_string(), holds: false, required: true }],
    };
    let secret = outside.join("secret.txt");
    let _ = std::fs::write(&secret, "secret");
    // As the grader leaves the hidden references (`user::close_instructor_only`): readable by
    // their owner only.
    let _ = std::fs::set_permissions(&secret, std::os::unix::fs::PermissionsExt::from_mode(0o600));
    let listener = std::net::TcpListener::bind("127.0.0.1:0").ok();
    let tcp = listener.as_ref().and_then(|l| l.local_addr().ok()).map(|a| a.to_string()).unwrap_or_default();
    let me = std::process::id().to_string();
    let cases = [
        (Attempt::ExecShell, String::new(), "run a shell"),
        (Attempt::ExecSelf, String::new(), "run its own program again"),
        (Attempt::Fork, String::new(), "start a process (fork)"),
        (Attempt::Setpgid, me.clone(), "leave its process group (setpgid)"),
        (Attempt::Tcp, tcp.clone(), "connect over TCP"),
        (Attempt::Udp, tcp, "send over UDP"),
        (Attempt::Signal, me.clone(), "signal the grader"),
        (Attempt::Ptrace, me, "trace the grader"),
        (Attempt::Read, secret.display().to_string(), "read a file outside its walls"),
        (Attempt::Write, outside.join("new.txt").display().to_string(), "write outside its folder"),
        (Attempt::Allocate, (8u64 << 30).to_string(), "reserve 8 GiB of memory"),
    ];
    let mut lines: Vec<Measured> = cases
        .into_iter()
        .map(|(attempt, arg, what)| {
            let (line, holds) = match allowed(launcher, attempt, &arg, &[]) {
                Ok(false) => (format!("refused: {what}"), true),
                Ok(true) => (format!("ALLOWED: {what}"), false),
                Err(e) => (e.to_string(), false),
            };
            Measured { line, holds, required: true }
        })
        .collect();
    let (line, holds) = match allowed(launcher, Attempt::Thread, "", &[]) {
        Ok(true) => ("allowed: start a thread".to_string(), true),
        Ok(false) => ("REFUSED: start a thread (graded code cannot run)".to_string(), false),
        Err(e) => (e.to_string(), false),
    };
    lines.push(Measured { line, holds, required: true });
    #[cfg(target_os = "linux")]
    lines.extend(users(launcher));
    let _ = std::fs::remove_dir_all(&outside);
    lines
}

/// Which user graded code and builds run as: informative (the probes above measure what the user
/// wall stops); a build that stays root is not a missing wall where Landlock holds.
#[cfg(target_os = "linux")]
fn users(launcher: &Path) -> Vec<Measured> {
    if !user::is_root() {
        let line = "the grader is not root: graded code and builds run as the grader's own user".to_string();
        return vec![Measured { line, holds: true, required: false }];
    }
    let walls = |profile| Walls {
        profile,
        read: Vec::new(),
        write: Vec::new(),
        limits: Limits::GRADED.expect("graded limits"),
        cpu_seconds: 0,
        user: None,
    };
    let cargo = on_path(std::ffi::OsStr::new("cargo"));
    let cases = [
        ("graded code", walls(Profile::Run), launcher.to_path_buf()),
        ("builds", walls(Profile::Build), cargo),
    ];
    cases
        .into_iter()
        .map(|(what, walls, program)| match user::for_launch(&walls, &program, None) {
            Ok(uid) => {
                Measured { line: format!("{what} run as user {uid}, not root"), holds: true, required: false }
            }
            Err(why) => {
                Measured { line: format!("{what} run as root: {why}"), holds: false, required: false }
            }
        })
        .collect()
}

/// One wall, measured.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Measured {
    /// What a graded process tried, and whether it was refused, in one line.
    pub line: String,
    /// Whether the wall held.
    pub holds: bool,
    /// Whether grading someone else's code needs it: every probe's wall is (the file wall holds
    /// by Landlock, or where the grader is root by the graded user); which user a build runs as
    /// is information.
    pub required: bool,
}

/// The walls this machine gives a graded process, each measured by starting a probe through the
/// launcher and trying what the wall forbids (the probes above).
pub fn check() -> Vec<Measured> {
    #[cfg(target_os = "linux")]
    if let Some(launcher) = launcher_path() {
        return measure(launcher);
    }
    let line = "no walls on this platform: graded code runs with resource limits only".to_string();
    vec![Measured { line, holds: false, required: true }]
}
