//! Running a checkpoint's unit tests and counting them by exit status, one process per test.
//!
//! The test binaries are built once (`cargo test --no-run`). Their test names come from
//! `--list`, which runs no test code; then every test under the checkpoint's filter
//! ([`is_under`]: a module named by it, so `checkpoint1` never takes checkpoint 10's) runs
//! alone (`--exact NAME`) in its own process, and passes if and only if that process exits with
//! status 0 in time. Nothing a test prints is read for the count: a solution region
//! printing `test result: ok. 40 passed` changes nothing.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use crate::plain::quote;
use crate::regions::stub::stub_panic;
use crate::run::build_error::BuildError;
use crate::run::cargo::{build, executables};
use crate::run::child::{graded_reads, run_graded, ChildRun, OwnFolder, CHILD_ENV};

/// What one `cargo test <filter>` run found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TestRun {
    /// Tests that passed.
    pub passed: u32,
    /// Tests that failed.
    pub failed: u32,
    /// Names of the failing tests.
    pub failures: Vec<String>,
    /// Why the run itself went wrong (no compile, no test binary, time limit), if it did.
    pub error: Option<TestsFailure>,
    /// The first failing test and what it said (for a student: where to look first).
    pub first_failure: Option<(String, String)>,
    /// The failing tests that stopped in a stub's `todo!()`, with the stub's checkpoint, as
    /// their panic message says ([`crate::regions::stub::stub_panic`]).
    pub stub_panics: Vec<(String, u32)>,
}

/// Why a run of tests counted nothing.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TestsFailure {
    /// The tests do not build: what the build said ([`BuildError`]'s words).
    #[error("the tests do not compile: {0}")]
    NoBuild(String),
    /// The tests of one checkpoint ran out of their time together.
    #[error("the tests took longer than {:.0} s in all", .0.as_secs_f64())]
    OutOfTime(Duration),
    /// The grader could not make a test's own folder (its machine, not the student's code).
    #[error("cannot make a folder for a test: {0}")]
    NoFolder(std::io::ErrorKind),
    /// A test binary could not be started.
    #[error("cannot run {}: {kind}", .program.display())]
    CannotStart {
        /// The test binary.
        program: PathBuf,
        /// What the system said.
        kind: std::io::ErrorKind,
    },
    /// Hidden tests that could not run: nothing more is said of them.
    #[error("the hidden tests could not run")]
    Hidden,
}

impl TestRun {
    /// This run as a hidden check may be reported: the counts and the failing tests' names, no
    /// text a test or the compiler wrote.
    pub fn hidden(self) -> TestRun {
        let error = self.error.map(|_| TestsFailure::Hidden);
        TestRun { error, first_failure: None, stub_panics: Vec::new(), ..self }
    }

    /// The fraction of tests passed; 0 when the run went wrong or ran nothing.
    pub fn fraction(&self) -> f64 {
        if self.error.is_some() || self.passed + self.failed == 0 {
            0.0
        } else {
            self.passed as f64 / (self.passed + self.failed) as f64
        }
    }
}

/// The test targets that hold checkpoint tests: the renderer's unit tests, its one binary of
/// checkpoint integration tests (`tests/checkpoints/`), and the instructor's hidden tests
/// (`tests/hidden/`) if the tree has them. Leaving out the CLI tests saves a link.
fn checkpoint_targets(root: &Path) -> Vec<&'static str> {
    let mut targets = vec!["--lib", "--test", "checkpoints"];
    if root.join("tests/hidden/main.rs").is_file() {
        targets.extend(["--test", "hidden"]);
    }
    targets
}

/// A checkpoint test binary of a tree, and its tests.
#[derive(Clone, Debug)]
struct TestBinary {
    executable: PathBuf,
    tests: Vec<String>,
}

/// The checkpoint test binaries of a tree, built.
#[derive(Clone, Debug)]
pub struct TestBinaries {
    binaries: Vec<TestBinary>,
}

/// One test may take this long; a correct one takes well under a second (the slowest, 0.4 s
/// here, in the dev profile the grader builds).
const TEST_TIME_LIMIT: Duration = Duration::from_secs(10);

/// Compiles the checkpoint test binaries once (`cargo test --no-run`) and lists their tests.
pub fn build_tests(root: &Path, target: Option<&Path>, limit: Duration) -> Result<TestBinaries, BuildError> {
    let args = [&["test", "--no-run", "--message-format=json"][..], &checkpoint_targets(root)].concat();
    let run = build(root, target, &args, limit)?;
    let binaries = executables(&run.stdout, true)
        .into_iter()
        .map(|executable| {
            let tests = list_tests(root, &executable)?;
            Ok(TestBinary { executable, tests })
        })
        .collect::<Result<Vec<_>, BuildError>>()?;
    Ok(TestBinaries { binaries })
}

/// The names of the tests in a test binary (`--list` runs none of them).
fn list_tests(root: &Path, executable: &Path) -> Result<Vec<String>, BuildError> {
    let mut command = Command::new(executable);
    command.current_dir(root).env(CHILD_ENV, "1").args(["--list", "--format", "terse"]);
    let cannot_start = |source| BuildError::CannotStart { program: executable.to_path_buf(), source };
    let own = OwnFolder::new().map_err(cannot_start)?;
    let run = run_graded(command, TEST_TIME_LIMIT, &graded_reads(root), &own).map_err(cannot_start)?;
    if !run.success() {
        let failure = run.failure(TEST_TIME_LIMIT);
        return Err(BuildError::CannotList { executable: executable.to_path_buf(), failure });
    }
    Ok(run.stdout.lines().filter_map(|l| l.strip_suffix(": test")).map(str::to_string).collect())
}

impl TestBinaries {
    /// Runs every test whose name contains `filter`, each alone in its own process (in `root`,
    /// with `env` added), for at most `limit` in all; a test passes if its process exits 0. Tests
    /// whose function is named in `first` run first, in that order, so the first failure is the
    /// most telling one. After a test that does not finish in time, the remaining ones count as
    /// failed without running: an endless loop costs one time limit, not one per test.
    pub fn run_filter(
        &self,
        root: &Path,
        filter: &str,
        first: &[String],
        env: &[(String, String)],
        limit: Duration,
    ) -> TestRun {
        let start = Instant::now();
        let mut result = TestRun::default();
        let mut timed_out = false;
        let mut tests: Vec<(&TestBinary, &String)> = self
            .binaries
            .iter()
            .flat_map(|b| b.tests.iter().filter(|t| is_under(t, filter)).map(move |t| (b, t)))
            .collect();
        let function = |name: &str| name.rsplit("::").next().unwrap_or(name).to_string();
        tests.sort_by_key(|(_, name)| first.iter().position(|f| *f == function(name)).unwrap_or(first.len()));
        for (binary, name) in tests {
            if timed_out {
                result.failed += 1;
                result.failures.push(name.clone());
                continue;
            }
            let left = limit.saturating_sub(start.elapsed());
            if left.is_zero() {
                result.error = Some(TestsFailure::OutOfTime(limit));
                return result;
            }
            let this_limit = left.min(TEST_TIME_LIMIT);
            match binary.run_one(name, root, env, this_limit) {
                Ok(run) => timed_out = result.count(name, &run, this_limit),
                Err(e) => {
                    result.error = Some(e);
                    return result;
                }
            }
        }
        result
    }
}

impl TestBinary {
    /// Runs its test `name` alone, in `root` with `env` added, for at most `limit`.
    fn run_one(
        &self,
        name: &str,
        root: &Path,
        env: &[(String, String)],
        limit: Duration,
    ) -> Result<ChildRun, TestsFailure> {
        let mut command = Command::new(&self.executable);
        command.current_dir(root).env(CHILD_ENV, "1").envs(env.iter().map(|(k, v)| (k, v)));
        command.args(["--exact", name, "--test-threads", "1"]);
        let own = OwnFolder::new().map_err(|e| TestsFailure::NoFolder(e.kind()))?;
        run_graded(command, limit, &graded_reads(root), &own)
            .map_err(|e| TestsFailure::CannotStart { program: self.executable.clone(), kind: e.kind() })
    }
}

impl TestRun {
    /// Counts test `name`'s `run` (limited to `limit`); whether it ran out of time.
    fn count(&mut self, name: &str, run: &ChildRun, limit: Duration) -> bool {
        if run.success() {
            self.passed += 1;
            return false;
        }
        self.failed += 1;
        self.failures.push(name.to_string());
        let message = failure_message(run, limit);
        if let Some(k) = stub_panic(&message) {
            self.stub_panics.push((name.to_string(), k));
        }
        self.first_failure.get_or_insert_with(|| (name.to_string(), message));
        run.status.is_none()
    }
}

/// What a failed test said: the panic message libtest printed, or why the process ended.
fn failure_message(run: &ChildRun, limit: Duration) -> String {
    let lines: Vec<&str> = run.stdout.lines().collect();
    let message =
        lines.iter().position(|l| l.contains("panicked at")).and_then(|i| lines.get(i + 1)).map(|l| quote(l));
    message.unwrap_or_else(|| run.failure_reason(limit))
}

/// Whether the test at `path` (`module::...::name`) is one of `filter`'s: a module on its path is
/// named `filter`, or `filter_...` (`checkpoint1_environment`, `hidden3_aabb`). `cargo test
/// checkpoint1` matches any name containing the text, checkpoint 10's tests too; the grade does
/// not.
pub fn is_under(path: &str, filter: &str) -> bool {
    let modules = path.rsplit_once("::").map_or("", |(modules, _name)| modules);
    modules
        .split("::")
        .any(|m| m.strip_prefix(filter).is_some_and(|rest| rest.is_empty() || rest.starts_with('_')))
}

#[cfg(test)]
mod tests {
    use super::is_under;

    #[test]
    fn a_filter_takes_its_modules_and_no_longer_id() {
        assert!(is_under("geometry::aabb::checkpoint3::a_box_is_hit", "checkpoint3"));
        assert!(is_under("checkpoint1_environment::checkpoint1::scenes_load", "checkpoint1"));
        assert!(is_under("hidden3_aabb::grazing_rays", "hidden3"));
        assert!(!is_under("math::checkpoint10::reflect_mirrors", "checkpoint1"), "10 is not 1");
        assert!(!is_under("geometry::checkpoint3", "checkpoint3"), "a test's own name is not a module");
        assert!(!is_under("geometry::checkpoint3x::t", "checkpoint3"));
    }
}
