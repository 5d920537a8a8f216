//! `cargo xtask first-build`: a student's first hour, timed. A benchmark, not a test: it prints
//! figures for docs/PERFORMANCE.md and fails only if the commands cannot run.
//!
//! In a fresh starter with a cold target folder it times the first `cargo test checkpoint2` and
//! counts the crates it compiles, then edits `src/geometry/triangle.rs` (checkpoint 2's file) and
//! times the same command again: edit to result.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use crate::starter::starter;

/// One timed `cargo test checkpoint2`.
struct Timed {
    seconds: f64,
    compiled: usize,
}

/// Writes a starter into a scratch folder and times the two builds.
pub fn first_build() -> Result<(), String> {
    let work = std::env::temp_dir().join("raylab-first-build");
    if work.exists() {
        std::fs::remove_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    }
    let (tree, target) = (work.join("starter"), work.join("target"));
    starter(&tree)?;
    let first = cargo_test(&tree, &target)?;
    let file = tree.join("src/geometry/triangle.rs");
    let text = std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
    std::fs::write(&file, format!("{text}// an edit\n")).map_err(|e| format!("{}: {e}", file.display()))?;
    let again = cargo_test(&tree, &target)?;
    println!(
        "first `cargo test checkpoint2` in a fresh starter: {:.1} s, {} crates compiled",
        first.seconds, first.compiled
    );
    println!(
        "after one edit to src/geometry/triangle.rs:       {:.1} s, {} crates compiled",
        again.seconds, again.compiled
    );
    let _ = std::fs::remove_dir_all(&work);
    Ok(())
}

/// `cargo test checkpoint2` in `tree`; the stubs make its tests fail, which is expected here.
fn cargo_test(tree: &Path, target: &Path) -> Result<Timed, String> {
    let start = Instant::now();
    let out = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .current_dir(tree)
        .env("CARGO_TARGET_DIR", target)
        .env("CARGO_TERM_COLOR", "never")
        .args(["test", "checkpoint2"])
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    let seconds = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !String::from_utf8_lossy(&out.stdout).contains("test result:") {
        return Err(format!("cargo test checkpoint2 ran no tests: {}", stderr.lines().last().unwrap_or("")));
    }
    let compiled = stderr.lines().filter(|l| l.trim_start().starts_with("Compiling ")).count();
    Ok(Timed { seconds, compiled })
}
