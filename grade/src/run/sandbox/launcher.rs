//! The launcher: a fresh single-threaded process that raises the walls around itself, in this
//! order, and then becomes the graded program.
//!
//! 1. Die with the grader: `PR_SET_PDEATHSIG` (SIGKILL), then stop if the parent is already gone.
//! 2. Open the program and move its descriptor to number `n`, close-on-exec; set the descriptor
//!    limit to `n`, so no descriptor numbered `n` or above can be made again (`dup2`, `fcntl` and
//!    `open` all respect it). After the exec, `n` is closed and cannot be reopened.
//! 3. Resource limits (`RLIMIT_AS`, `RLIMIT_FSIZE`, `RLIMIT_CPU`, `RLIMIT_CORE` = 0, and for a
//!    graded user `RLIMIT_NPROC`).
//! 4. Where the grader is root, the graded user ([`user`]), and step 1 again (changing user
//!    clears the parent-death signal).
//! 5. Landlock ([`super::files`]).
//! 6. The seccomp filter ([`super::filter`]), which lets `execveat` through for descriptor `n`
//!    only, and refuses every limit change from here on.
//! 7. `execveat(n, "", argv, envp, AT_EMPTY_PATH)`.
//!
//! A build's launcher forks first and does all this in its child, staying as the supervisor that
//! takes the build's compilers down with it (`supervise`).
//!
//! Any failure is printed on one line (`sandbox: ...`) and exits with status 125, before the
//! graded program ever runs: a wall that cannot be raised is never silently left out.

use std::ffi::{CString, OsString};
use std::os::unix::ffi::OsStrExt;

use super::wall_error::{Step, WallError};
use super::{files, filter, parse_launch, user, Launch, Profile, Wall};

/// Exit status of a launcher that could not raise its walls.
pub const FAILED: u8 = 125;

/// The highest descriptor number the launcher uses for the program (lower if the system's hard
/// limit is lower).
const PROGRAM_FD: libc::c_int = 1000;

/// Runs the launcher with `args` (those after `__sandbox`): a run becomes its program and returns
/// only on failure; a build returns cargo's exit status.
pub fn launch(args: &[OsString]) -> std::process::ExitCode {
    let result = parse_launch(args).map_err(WallError::from).and_then(|launch| match launch.walls.profile {
        Profile::Run => exec_inside(&launch, launch.parent).map(|()| FAILED),
        Profile::Build => supervise(&launch),
    });
    match result {
        Ok(status) => std::process::ExitCode::from(status),
        Err(message) => {
            eprintln!("sandbox: {message}");
            std::process::ExitCode::from(FAILED)
        }
    }
}

/// A build starts processes of its own (cargo runs rustc, rustc the linker), which a launcher
/// that became cargo could not take down with it. So for a build the launcher stays, as cargo's
/// parent in the same process group: when the grader dies (`PR_SET_PDEATHSIG`, SIGTERM here) it
/// kills that whole group, itself included; otherwise it waits for cargo and exits as cargo did
/// (128 + the signal that killed it). The grader kills the group when the build ends or its time
/// is up, as for every child.
fn supervise(launch: &Launch) -> Result<u8, WallError> {
    die_with(launch.parent, libc::SIGTERM)?;
    let handler = kill_own_group as extern "C" fn(libc::c_int);
    // SAFETY: the handler only calls kill, which is async-signal-safe.
    unsafe { libc::signal(libc::SIGTERM, handler as libc::sighandler_t) };
    let me = std::process::id();
    // SAFETY: this process has one thread; the child raises its walls and executes cargo (exec
    // resets the handler), or exits.
    let child = unsafe { libc::fork() };
    if child == 0 {
        if let Err(error) = exec_inside(launch, me) {
            eprintln!("sandbox: {error}");
        }
        // SAFETY: _exit ends the child without running the parent's exit handlers.
        unsafe { libc::_exit(FAILED as libc::c_int) };
    }
    if child < 0 {
        return Err(WallError::last_os(Step::StartBuild));
    }
    let mut status = 0;
    // SAFETY: waitpid writes the status of our own child.
    while unsafe { libc::waitpid(child, &mut status, 0) } != child {
        if std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted {
            return Err(WallError::last_os(Step::WaitBuild));
        }
    }
    Ok(match libc::WIFEXITED(status) {
        true => libc::WEXITSTATUS(status) as u8,
        false => 128u8.saturating_add(libc::WTERMSIG(status) as u8),
    })
}

/// SIGTERM's handler in a build's launcher: the whole group, the launcher included.
extern "C" fn kill_own_group(_: libc::c_int) {
    // SAFETY: kill is async-signal-safe; 0 names this process's group.
    unsafe { libc::kill(0, libc::SIGKILL) };
}

/// Asks for `signal` when the process `parent` (which started this one) dies, and stops if it
/// already has.
fn die_with(parent: u32, signal: libc::c_int) -> Result<(), WallError> {
    // SAFETY: prctl with PR_SET_PDEATHSIG takes a signal number and changes nothing else.
    if unsafe { libc::prctl(libc::PR_SET_PDEATHSIG, signal, 0, 0, 0) } != 0 {
        return Err(WallError::last_os(Step::DieWithGrader));
    }
    // SAFETY: getppid has no arguments and cannot fail.
    if parent != 0 && unsafe { libc::getppid() } as u32 != parent {
        return Err(WallError::GraderGone);
    }
    Ok(())
}

/// Raises the walls and executes the program; `parent` is the process whose death kills it.
fn exec_inside(launch: &Launch, parent: u32) -> Result<(), WallError> {
    die_with(parent, libc::SIGKILL)?;
    let program = CString::new(launch.program[0].as_bytes()).map_err(|_| WallError::Nul)?;
    let fd = program_descriptor(&program)?;
    let on = |wall: Wall| !launch.without.contains(&wall);
    if on(Wall::Limits) {
        set_limits(launch)?;
    }
    if let Some(uid) = launch.walls.user {
        user::become_user(uid)?;
        die_with(parent, libc::SIGKILL)?;
    }
    if on(Wall::Landlock) {
        files::restrict(&launch.walls, &launch.program[0])?;
    }
    if on(Wall::Seccomp) {
        filter::install(fd, launch.walls.profile)?;
    }
    let argv = c_strings(launch.program.iter().map(|a| a.as_bytes().to_vec()))?;
    let envp = c_strings(std::env::vars_os().map(|(k, v)| [k.as_bytes(), b"=", v.as_bytes()].concat()))?;
    let pointers = |strings: &[CString]| {
        strings.iter().map(|s| s.as_ptr()).chain(std::iter::once(std::ptr::null())).collect::<Vec<_>>()
    };
    let (argv, envp) = (pointers(&argv), pointers(&envp));
    // SAFETY: every pointer is a NUL-terminated string that lives until the call, and both
    // arrays end with a null pointer; on success this call does not return.
    unsafe {
        libc::syscall(
            libc::SYS_execveat,
            fd,
            c"".as_ptr(),
            argv.as_ptr(),
            envp.as_ptr(),
            libc::AT_EMPTY_PATH,
        );
    }
    Err(WallError::last_os(Step::Exec))
}

/// Opens `program` and moves it to the descriptor just below the new descriptor limit.
fn program_descriptor(program: &CString) -> Result<libc::c_int, WallError> {
    let os = WallError::last_os;
    let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes into the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) } != 0 {
        return Err(os(Step::ReadDescriptorLimit));
    }
    let n = PROGRAM_FD.min(limit.rlim_max.saturating_sub(1).min(libc::c_int::MAX as u64) as libc::c_int);
    // SAFETY: open reads a NUL-terminated path; dup3 and close take descriptor numbers.
    unsafe {
        let opened = libc::open(program.as_ptr(), libc::O_RDONLY | libc::O_CLOEXEC);
        if opened < 0 {
            return Err(os(Step::OpenProgram));
        }
        if libc::dup3(opened, n, libc::O_CLOEXEC) != n {
            return Err(os(Step::MoveDescriptor));
        }
        libc::close(opened);
    }
    let below = libc::rlimit { rlim_cur: n as libc::rlim_t, rlim_max: n as libc::rlim_t };
    // SAFETY: setrlimit only reads the struct it is given.
    if unsafe { libc::setrlimit(libc::RLIMIT_NOFILE, &below) } != 0 {
        return Err(os(Step::LowerDescriptorLimit));
    }
    Ok(n)
}

/// The resource limits of [`super::Walls`], each both soft and hard.
fn set_limits(launch: &Launch) -> Result<(), WallError> {
    let walls = &launch.walls;
    let pairs = [
        (libc::RLIMIT_AS, walls.limits.memory),
        (libc::RLIMIT_FSIZE, walls.limits.file_size),
        (libc::RLIMIT_CPU, walls.cpu_seconds),
        (libc::RLIMIT_CORE, 0),
    ];
    // Counted per user, so it binds only a graded user's processes; root's are the grader's.
    let processes = walls.user.map(|_| (libc::RLIMIT_NPROC, user::PROCESSES));
    for (resource, value) in pairs.into_iter().chain(processes) {
        let rlimit = libc::rlimit { rlim_cur: value as libc::rlim_t, rlim_max: value as libc::rlim_t };
        // SAFETY: setrlimit only reads the struct it is given.
        if unsafe { libc::setrlimit(resource, &rlimit) } != 0 {
            return Err(WallError::last_os(Step::SetLimit));
        }
    }
    Ok(())
}

fn c_strings(items: impl Iterator<Item = Vec<u8>>) -> Result<Vec<CString>, WallError> {
    items.map(|bytes| CString::new(bytes).map_err(|_| WallError::Nul)).collect()
}
