//! Running `cargo` on the tree being graded: building its `render` binary and its checkpoint
//! tests. The grader never links the graded code; it builds it in child processes and runs what
//! they make, each under a time limit (see [`crate::run::child`]).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::plain::quote;
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

/// The first compiler error of a failed build with its place (`error[E0425]: cannot find value
/// `x` in this scope at src/geometry/triangle.rs:101:9`), or why the build itself went wrong;
/// the message [`quote`]d.
pub fn first_error(run: &ChildRun, limit: Duration) -> String {
    let lines: Vec<&str> = run.stderr.lines().collect();
    let Some(i) = lines.iter().position(|l| l.starts_with("error")) else { return run.failure_reason(limit) };
    let place = lines[i + 1..].iter().take(3).find_map(|l| l.trim_start().strip_prefix("--> "));
    match place {
        Some(place) => format!("{} at {}", quote(lines[i]), quote(place)),
        None => quote(lines[i]),
    }
}

/// The error code of a [`first_error`] message (`error[E0308]`), or `error`: what may be said
/// of an error in a file a student cannot see.
pub fn error_code(message: &str) -> &str {
    match message.find(']') {
        Some(end) if message.starts_with("error[") => &message[..=end],
        _ => "error",
    }
}

/// The file and line of a [`first_error`] message, if it names one.
pub fn error_place(message: &str) -> Option<(PathBuf, usize)> {
    let place = message.rsplit(" at ").next()?;
    let mut parts = place.split(':');
    let (file, line) = (parts.next()?, parts.next()?.parse().ok()?);
    Some((PathBuf::from(file), line))
}

/// Builds the tree's `render` binary (dev profile, which the checkpoint tests share) and returns
/// the executable cargo reports; `Err` carries the first compiler error.
pub fn build_renderer(root: &Path, target: Option<&Path>) -> Result<PathBuf, String> {
    let args = ["build", "--quiet", "--bin", "render", "--message-format=json-render-diagnostics"];
    let run = run_build(cargo(root, target, &args), BUILD_TIME_LIMIT, root, &target_dir(root, target))
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !run.success() {
        return Err(first_error(&run, BUILD_TIME_LIMIT));
    }
    executables(&run.stdout, false).pop().ok_or_else(|| "cargo built no `render` executable".to_string())
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
    fn the_first_compiler_error_keeps_its_place() {
        let stderr = "   Compiling raylab\nerror[E0425]: cannot find value `x` in this scope\n   --> src/geometry/triangle.rs:101:9\n    |\n";
        let run = ChildRun {
            status: None,
            stdout: String::new(),
            stderr: stderr.to_string(),
            seconds: 0.0,
            limits: None,
            wrote_too_much: false,
        };
        let message = first_error(&run, Duration::from_secs(1));
        assert_eq!(
            message,
            "error[E0425]: cannot find value `x` in this scope at src/geometry/triangle.rs:101:9"
        );
        assert_eq!(error_place(&message), Some((PathBuf::from("src/geometry/triangle.rs"), 101)));
        assert_eq!(error_place("error: linking failed"), None);
        assert_eq!(error_code(&message), "error[E0425]");
        assert_eq!(error_code("error: linking failed"), "error");
    }

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
