//! The user wall: where the grader runs as root, graded code does not. Root passes every file
//! permission, so without Landlock a graded process of root's could read the hidden references
//! and write anywhere. Each graded process runs instead as a user of its own that owns nothing on
//! the machine: a build as [`BUILD_UID`], a render or a unit test as [`RUN_UID`]. The run user
//! cannot write what the build user made (the binaries a batch reuses), and neither can read a
//! file that is not readable by all (the grader closes the solution's source and the hidden
//! files, [`close_instructor_only`]), signal or trace the grader, or raise a limit.
//!
//! The ids have no name in `/etc/passwd` and need none (as the IOI's `isolate` does). A graded
//! process can only run as such a user if what it needs is readable by all: its program, its
//! scenes, its working folder, and for a build the toolchain (rustup's default under `/root` is
//! not, which is why the Gradescope `setup.sh` installs it under `/usr/local`). Where it is not,
//! the process runs as root inside the other walls, and `grader sandbox --check` says why.

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

use super::wall_error::{Step, WallError};
use super::{Profile, Walls};

/// The user (and group) every build runs as when the grader is root.
pub const BUILD_UID: u32 = 61_000;

/// The user (and group) every render and unit test runs as when the grader is root.
pub const RUN_UID: u32 = 61_001;

/// Processes (threads included) the graded user may have at once: a render's threads or a
/// build's compilers, far from a fork bomb.
pub const PROCESSES: u64 = 512;

/// Whether this process is root, the only case where graded code changes user.
pub fn is_root() -> bool {
    // SAFETY: geteuid has no arguments and cannot fail.
    unsafe { libc::geteuid() == 0 }
}

/// Whether a run of `program`, the machine's temporary folder its own, changes user here.
pub fn runs_as_user(program: &Path) -> bool {
    is_root() && readable_by_all(program) && readable_by_all(&std::env::temp_dir())
}

/// The user a process of `profile` with `program`, working in `cwd`, runs as inside `walls`;
/// `Err` says why it cannot change user.
pub fn for_launch(walls: &Walls, program: &Path, cwd: Option<&Path>) -> Result<u32, SameUser> {
    if !is_root() {
        return Err(SameUser::NotRoot);
    }
    let mut needed: Vec<PathBuf> = vec![program.to_path_buf()];
    needed.extend(walls.read.iter().cloned());
    needed.extend(cwd.map(Path::to_path_buf));
    if walls.profile == Profile::Build {
        needed.extend(super::files::toolchain().into_iter().filter(|p| p.exists()));
    }
    match needed.iter().find(|p| !readable_by_all(p)) {
        Some(path) => Err(SameUser::NotReadable(path.clone())),
        None => Ok(match walls.profile {
            Profile::Build => BUILD_UID,
            Profile::Run => RUN_UID,
        }),
    }
}

/// Why a graded process runs as the grader's own user.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum SameUser {
    /// Only root can change user.
    #[error("the grader is not root: graded code runs as the grader's own user")]
    NotRoot,
    /// Something the process needs could not be read by a user that owns nothing.
    #[error("{} is not readable by other users", .0.display())]
    NotReadable(PathBuf),
}

/// Whether a user that owns nothing can reach `path` (every folder above it searchable by all)
/// and read it (a folder also searchable).
fn readable_by_all(path: &Path) -> bool {
    let Ok(path) = std::path::absolute(path) else { return false };
    let mode = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.permissions().mode());
    let searchable = path.ancestors().skip(1).all(|a| mode(a) & 0o001 != 0);
    let own = mode(&path);
    let readable = own & 0o004 != 0 && (!path.is_dir() || own & 0o001 != 0);
    searchable && (readable || !path.exists())
}

/// Gives `folder` (and with `recursive` everything in it) to `uid`, so the graded user may write
/// there: its own folder, a build's target.
pub fn give(folder: &Path, uid: u32, recursive: bool) -> std::io::Result<()> {
    std::os::unix::fs::lchown(folder, Some(uid), Some(uid))?;
    if recursive && folder.is_dir() {
        for entry in std::fs::read_dir(folder)? {
            let entry = entry?;
            let foreign = entry.metadata().is_ok_and(|m| m.uid() != uid);
            if foreign || entry.file_type()?.is_dir() {
                give(&entry.path(), uid, entry.file_type()?.is_dir())?;
            }
        }
    }
    Ok(())
}

/// Becomes `uid` (group `uid`, no other groups), for good: real, effective and saved ids.
pub fn become_user(uid: u32) -> Result<(), WallError> {
    let os = WallError::last_os;
    // SAFETY: setgroups with a count of 0 reads no pointer; the set*id calls take numbers only.
    unsafe {
        if libc::setgroups(0, std::ptr::null()) != 0 {
            return Err(os(Step::DropGroups));
        }
        if libc::setresgid(uid, uid, uid) != 0 {
            return Err(os(Step::ChangeGroup));
        }
        if libc::setresuid(uid, uid, uid) != 0 {
            return Err(os(Step::ChangeUser));
        }
    }
    Ok(())
}

/// What of the instructor's tree the starter does not ship: the solution's source and the hidden
/// files (references, scenes, tests, rubric).
pub const INSTRUCTOR_ONLY: [&str; 3] =
    ["src", crate::regions::baseline::HIDDEN_DIRS[0], crate::regions::baseline::HIDDEN_DIRS[1]];

/// Closes [`INSTRUCTOR_ONLY`] of the instructor's tree at `root` to everyone but its owner (mode
/// 700 on each folder), before a submission is graded from it: the hidden references are what a
/// graded process could copy into a mark. Graded code never needs them: it is built from a
/// scratch copy, and reads that copy's scenes. Only root's graded code runs as another user, so
/// only then does this matter; git does not track a folder's mode.
pub fn close_instructor_only(root: &Path) -> std::io::Result<()> {
    for folder in INSTRUCTOR_ONLY.map(|f| root.join(f)).iter().filter(|f| f.is_dir()) {
        if is_root() {
            std::fs::set_permissions(folder, std::fs::Permissions::from_mode(0o700))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_is_readable_by_all_only_when_every_folder_above_is_searchable() {
        let dir = std::env::temp_dir().join(format!("raylab-user-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("closed")).unwrap();
        std::fs::write(dir.join("open.txt"), "").unwrap();
        std::fs::write(dir.join("closed/inside.txt"), "").unwrap();
        let set =
            |p: &str, mode| std::fs::set_permissions(dir.join(p), std::fs::Permissions::from_mode(mode));
        set("open.txt", 0o644).unwrap();
        set("closed", 0o700).unwrap();
        set("closed/inside.txt", 0o644).unwrap();
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        assert!(readable_by_all(&dir.join("open.txt")));
        assert!(!readable_by_all(&dir.join("closed")));
        assert!(!readable_by_all(&dir.join("closed/inside.txt")));
        set("open.txt", 0o600).unwrap();
        assert!(!readable_by_all(&dir.join("open.txt")));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Root closes the solution's source and the hidden files, and nothing the graded code reads.
    #[test]
    fn root_closes_what_the_starter_does_not_ship() {
        let root = std::env::temp_dir().join(format!("raylab-close-{}", std::process::id()));
        for folder in ["src", "hidden/reference", "tests/hidden", "scenes"] {
            std::fs::create_dir_all(root.join(folder)).unwrap();
        }
        close_instructor_only(&root).unwrap();
        let closed = |f: &str| !readable_by_all(&root.join(f));
        let expected = is_root();
        assert_eq!(["src", "hidden/reference", "tests/hidden"].map(closed), [expected; 3]);
        assert!(!closed("scenes"));
        let _ = std::fs::remove_dir_all(&root);
    }
}
