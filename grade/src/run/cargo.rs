//! Running `cargo` on the tree being graded: building its `render` binary and its checkpoint
//! tests. The grader never links the graded code; it builds it in child processes and runs what
//! they make, each under a time limit (see [`crate::run::child`]).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::run::build_error::BuildError;
use crate::run::child::{run_build, ChildRun, CHILD_ENV};

/// Compiling a tree may take minutes on a cold machine (its dependencies: about 2 on 2 cores);
/// 8 leave a build that never ends (a constant whose evaluation does not stop) inside
/// Gradescope's 10 minutes.
pub const BUILD_TIME_LIMIT: Duration = Duration::from_secs(480);

/// `cargo ARGS` in `root`, marked as a grader child, with its own target folder if `target` is
/// given (calibration and the catalogue share one between scratch trees).
pub fn cargo(root: &Path, target: Option<&Path>, args: &[&str]) -> Command {
    let mut command = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    command.current_dir(root).args(args).env(CHILD_ENV, "1");
    if let Some(target) = target {
        command.env("CARGO_TARGET_DIR", target);
    }
    command
}

/// Where cargo builds `root`: `target` if given, else `CARGO_TARGET_DIR` (relative to the tree),
/// else the tree's `target/`.
pub fn target_dir(root: &Path, target: Option<&Path>) -> PathBuf {
    let from_env = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from);
    root.join(target.map(Path::to_path_buf).or(from_env).unwrap_or_else(|| PathBuf::from("target")))
}

/// Builds the tree's `render` binary (dev profile, which the checkpoint tests share) and returns
/// the executable cargo reports.
pub fn build_renderer(root: &Path, target: Option<&Path>) -> Result<PathBuf, BuildError> {
    let args = ["build", "--quiet", "--bin", "render", "--message-format=json"];
    let run = build(root, target, &args, BUILD_TIME_LIMIT)?;
    executables(&run.stdout, false).pop().ok_or(BuildError::NoRenderer)
}

/// `cargo ARGS` (which must ask for `--message-format=json`) as a build of `root`, for at most
/// `limit`: its run if it succeeded, else why not.
pub fn build(
    root: &Path,
    target: Option<&Path>,
    args: &[&str],
    limit: Duration,
) -> Result<ChildRun, BuildError> {
    let command = cargo(root, target, args);
    let program = PathBuf::from(command.get_program());
    let run = run_build(command, limit, root, &target_dir(root, target))
        .map_err(|source| BuildError::CannotStart { program, source })?;
    match run.success() {
        true => Ok(run),
        false => Err(BuildError::of_failed_build(&run.stdout, &run.stderr, run.failure(limit))),
    }
}

/// The executables of the compiler artifacts in cargo's JSON messages: the test harnesses if
/// `tests`, else the binaries.
pub fn executables(messages: &str, tests: bool) -> Vec<PathBuf> {
    messages
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["profile"]["test"].as_bool() == Some(tests))
        .filter_map(|m| m["executable"].as_str().map(PathBuf::from))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_executable_is_read_from_cargos_artifact_messages() {
        let messages = concat!(
            r#"{"reason":"compiler-artifact","profile":{"test":false},"executable":null}"#,
            "\n",
            r#"{"reason":"compiler-artifact","profile":{"test":false},"executable":"/t/debug/render"}"#,
            "\n",
            r#"{"reason":"compiler-artifact","profile":{"test":true},"executable":"/t/debug/deps/raylab-1"}"#,
            "\n",
            r#"{"reason":"build-finished","success":true}"#,
            "\n"
        );
        assert_eq!(executables(messages, false), vec![PathBuf::from("/t/debug/render")]);
        assert_eq!(executables(messages, true), vec![PathBuf::from("/t/debug/deps/raylab-1")]);
        assert!(executables(r#"{"reason":"build-finished","success":true}"#, false).is_empty());
    }
}
