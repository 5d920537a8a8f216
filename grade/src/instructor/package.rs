//! `grader package gradescope`: the instructor's tree as a Gradescope autograder.
//!
//! Gradescope unpacks the zip into `/autograder/source`, runs `setup.sh` once when it builds the
//! autograder's image, then `run_autograder` for each submission, which it puts in
//! `/autograder/submission`; it reads the score from `/autograder/results/results.json`. The zip
//! holds:
//!
//! - `setup.sh` and `run_autograder` (`grade/gradescope/`, where they are documented);
//! - `raylab/`: every file of the tree under version control (`git ls-files`: nothing untracked,
//!   no build output), the hidden checks included;
//! - `vendor/`: every crate the workspace needs (`cargo vendor`), so grading needs no network.
//!
//! The scripts keep every path below `$AUTOGRADER_ROOT` (default `/autograder`), so a dry run can
//! unpack the zip anywhere and run them there (`cargo xtask gradescope-dry-run`).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::file_error::FileError;
use crate::instructor::error::InstructorError;
use crate::submission::scratch::write_if_changed;

/// Gradescope's two scripts, as the zip holds them.
const SCRIPTS: [(&str, &str); 2] = [
    ("setup.sh", include_str!("../../gradescope/setup.sh")),
    ("run_autograder", include_str!("../../gradescope/run_autograder")),
];

/// Writes the autograder zip of the tree at `root` to `out`, staging it in `work` (replaced).
/// Needs `git`, `cargo` and `zip`; `cargo vendor` reads crates from the network or cargo's cache.
pub fn gradescope(root: &Path, work: &Path, out: &Path) -> Result<(), InstructorError> {
    if work.exists() {
        std::fs::remove_dir_all(work).map_err(|e| FileError::unwritable(work, &e))?;
    }
    let tree = work.join("raylab");
    for file in tracked_files(root)? {
        let to = tree.join(&file);
        std::fs::create_dir_all(to.parent().unwrap_or(&tree)).map_err(|e| FileError::unwritable(&to, &e))?;
        std::fs::copy(root.join(&file), &to).map_err(|e| FileError::unwritable(&to, &e))?;
    }
    run(Command::new("cargo")
        .args(["vendor", "--locked", "--versioned-dirs", "--quiet", "--manifest-path"])
        .arg(tree.join("Cargo.toml"))
        .arg(work.join("vendor")))?;
    for (name, text) in SCRIPTS {
        let path = work.join(name);
        write_if_changed(&path, text.as_bytes()).map_err(|e| FileError::unwritable(&path, &e))?;
        make_executable(&path)?;
    }
    let out = std::path::absolute(out).map_err(|e| FileError::unwritable(out, &e))?;
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).map_err(|e| FileError::unwritable(dir, &e))?;
    }
    // Written beside, then renamed: a failed run never leaves half a zip over a good one.
    let partial = out.with_extension("zip.partial");
    let _ = std::fs::remove_file(&partial);
    run(Command::new("zip").current_dir(work).args(["-q", "-r", "-X"]).arg(&partial).arg("."))?;
    Ok(std::fs::rename(&partial, &out).map_err(|e| FileError::unwritable(&out, &e))?)
}

/// The files of the tree under version control (`git ls-files`: nothing the working folder
/// happens to hold, such as renders or reports), relative to it.
pub fn tracked_files(root: &Path) -> Result<Vec<PathBuf>, InstructorError> {
    let listed = run(Command::new("git").arg("-C").arg(root).args(["ls-files", "-z", "--cached"]))?;
    Ok(listed
        .split('\0')
        .filter(|f| !f.is_empty())
        .map(PathBuf::from)
        .filter(|f| root.join(f).is_file())
        .collect())
}

/// Runs `command`, returning its standard output, or its standard error as the reason it failed.
fn run(command: &mut Command) -> Result<String, InstructorError> {
    let program = command.get_program().to_string_lossy().into_owned();
    let out =
        command.output().map_err(|source| InstructorError::CannotRun { program: program.clone(), source })?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last_line = stderr.trim().lines().last().unwrap_or("no message").to_string();
        return Err(InstructorError::Failed { program, last_line });
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

fn make_executable(path: &Path) -> Result<(), FileError> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .map_err(|e| FileError::unwritable(path, &e))
}
