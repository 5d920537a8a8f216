//! Running a checkpoint's unit tests (`cargo test <filter>`) as a child process and counting.

use std::path::Path;
use std::time::Duration;

use crate::cargo::{cargo, first_error};
use crate::child::run_with_limit;

/// What one `cargo test <filter>` run found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TestRun {
    /// Tests that passed.
    pub passed: u32,
    /// Tests that failed.
    pub failed: u32,
    /// Names of the failing tests.
    pub failures: Vec<String>,
    /// Why the run itself went wrong (no compile, crash, time limit), if it did.
    pub error: Option<String>,
}

impl TestRun {
    /// The fraction of tests passed; 0 when the run went wrong or ran nothing.
    pub fn fraction(&self) -> f64 {
        if self.error.is_some() || self.passed + self.failed == 0 {
            0.0
        } else {
            self.passed as f64 / (self.passed + self.failed) as f64
        }
    }
}

/// The test targets that hold checkpoint tests: the renderer's unit tests and its one binary of
/// checkpoint integration tests (`tests/checkpoints/`). Leaving out the CLI tests saves a link.
const CHECKPOINT_TARGETS: [&str; 3] = ["--lib", "--test", "checkpoints"];

/// Compiles the checkpoint test binaries once (`cargo test --no-run`); `Err` carries the first
/// compiler error.
pub fn build_tests(root: &Path, target: Option<&Path>, limit: Duration) -> Result<(), String> {
    let args = [&["test", "--no-run", "--quiet"][..], &CHECKPOINT_TARGETS].concat();
    let run =
        run_with_limit(cargo(root, target, &args), limit).map_err(|e| format!("cannot run cargo: {e}"))?;
    if run.success() {
        Ok(())
    } else {
        Err(first_error(&run, limit))
    }
}

/// Runs `cargo test --no-fail-fast <filter>` over the checkpoint test binaries in `root` and
/// counts passes and failures.
pub fn run_filter(root: &Path, target: Option<&Path>, filter: &str, limit: Duration) -> TestRun {
    let args = [&["test", "--no-fail-fast"][..], &CHECKPOINT_TARGETS, &[filter]].concat();
    let run = match run_with_limit(cargo(root, target, &args), limit) {
        Ok(run) => run,
        Err(e) => return TestRun { error: Some(format!("cannot run cargo: {e}")), ..TestRun::default() },
    };
    let mut result = parse_test_output(&run.stdout);
    // A test binary that aborts (stack overflow, abort) prints no summary: the counts above miss
    // its tests, so the run is not trusted.
    if !run.success() && result.failed == 0 {
        result.error = Some(format!("the test run {}", run.failure_reason(limit)));
    }
    result
}

/// Sums `test result:` lines and collects `test NAME ... FAILED` lines of libtest's output.
pub fn parse_test_output(stdout: &str) -> TestRun {
    let mut result = TestRun::default();
    for line in stdout.lines() {
        if let Some(summary) = line.strip_prefix("test result: ") {
            let count = |word: &str| {
                summary.split(';').find_map(|part| {
                    part.trim().strip_suffix(word)?.trim().rsplit(' ').next()?.parse::<u32>().ok()
                })
            };
            result.passed += count("passed").unwrap_or(0);
            result.failed += count("failed").unwrap_or(0);
        } else if let Some(name) = line.strip_prefix("test ").and_then(|l| l.strip_suffix(" ... FAILED")) {
            result.failures.push(name.to_string());
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grader_counts_libtest_summaries_and_failures() {
        let out = "running 3 tests\ntest a::b ... ok\ntest a::c ... FAILED\n\
                   test result: FAILED. 2 passed; 1 failed; 0 ignored; 0 measured; 5 filtered out; finished in 0.01s\n\
                   test result: ok. 4 passed; 0 failed; 0 ignored; 0 measured; 0 filtered out; finished in 0.00s\n";
        let run = parse_test_output(out);
        assert_eq!((run.passed, run.failed), (6, 1));
        assert_eq!(run.failures, vec!["a::c".to_string()]);
        assert!((run.fraction() - 6.0 / 7.0).abs() < 1e-12);
    }
}
