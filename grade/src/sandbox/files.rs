//! The file wall of a graded process (Landlock): it may read and execute the system's programs
//! and libraries, its own program and the paths the caller names; read its own `/proc/self`
//! (the C library reads its stack's bounds there) and the cgroup limits (how many threads to
//! start); write only its own folder. Everything else, the instructor's tree, the hidden
//! references and tests, the solution's source beside the submission's, other students' folders,
//! `/proc` of other processes, is neither readable nor writable. Where the kernel has Landlock's
//! scopes (ABI 6), signals and abstract UNIX sockets are kept inside the sandbox too.
//!
//! Best effort, as the `landlock` crate defines it: a kernel without Landlock leaves this wall
//! out (`grader sandbox --check` says so); a kernel with an older ABI enforces what it knows.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use landlock::{
    path_beneath_rules, Access, AccessFs, AccessNet, Ruleset, RulesetAttr, RulesetCreatedAttr, RulesetStatus,
    Scope, ABI,
};

use super::Walls;

/// The newest Landlock ABI this wall is written for.
const TARGET: ABI = ABI::V6;

/// System folders every program needs to start: the dynamic loader, the C library and its
/// configuration.
const SYSTEM: [&str; 6] = ["/usr", "/lib", "/lib64", "/etc/ld.so.cache", "/dev/null", "/dev/urandom"];

/// What the kernel does with the process's own view of itself and its limits.
const SELF_VIEW: [&str; 2] = ["/proc/self", "/sys/fs/cgroup"];

/// Restricts the calling thread (and what it executes) to `walls`, with `program` executable.
pub fn restrict(walls: &Walls, program: &OsString) -> Result<RulesetStatus, String> {
    let error = |e: landlock::RulesetError| format!("cannot raise the file wall: {e}");
    let program = PathBuf::from(program);
    let mut read: Vec<&Path> = SYSTEM.iter().chain(&SELF_VIEW).map(Path::new).collect();
    read.extend(walls.read.iter().map(PathBuf::as_path));
    read.push(&program);
    let read = read.into_iter().filter(|p| p.exists());
    let status = Ruleset::default()
        .handle_access(AccessFs::from_all(TARGET))
        .and_then(|r| r.handle_access(AccessNet::from_all(TARGET)))
        .and_then(|r| r.scope(Scope::from_all(TARGET)))
        .and_then(|r| r.create())
        .and_then(|r| r.add_rules(path_beneath_rules(read, AccessFs::from_read(TARGET))))
        .and_then(|r| r.add_rules(path_beneath_rules([&walls.write], AccessFs::from_all(TARGET))))
        .and_then(|r| r.restrict_self())
        .map_err(error)?;
    Ok(status.ruleset)
}
