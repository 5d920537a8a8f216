//! The hostile-submission suite (`tests/hostile/README.md`): each fixture is applied to a copy of
//! the reference solution, graded with `grader submission` from this repository, and must get
//! exactly the points its `expected.toml` commits to, with the reasons it names.

use std::path::{Path, PathBuf};
use std::process::Command;

use raylab_grade::fixture;

fn repository() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// The workspace's target folder (this test runs from `target/debug/deps`): the submissions'
/// builds reuse its compiled dependencies.
fn target_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.ancestors().nth(3).unwrap().to_path_buf()
}

/// Grades one fixture; `Err` lists what differs from its expectations.
fn grade_fixture(name: &str, scratch: &Path) -> Result<(), String> {
    let submission = scratch.join(name);
    let expected = fixture::make(&repository(), name, &submission)?;
    let json = scratch.join(format!("{name}.json"));
    let out = Command::new(env!("CARGO_BIN_EXE_grader"))
        .arg("submission")
        .arg(&submission)
        .arg("--root")
        .arg(repository())
        .arg("--work")
        .arg(scratch.join("work"))
        .arg("--json")
        .arg(&json)
        .env("CARGO_TARGET_DIR", target_dir())
        .env_remove("RAYLAB_GRADER_CHILD")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !matches!(out.status.code(), Some(0 | 1)) {
        return Err(format!("{name}: grader exited {:?}: {stderr}", out.status.code()));
    }
    let results: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let problems = expected.problems(&results);
    if problems.is_empty() {
        Ok(())
    } else {
        let output = results["output"].as_str().unwrap_or_default();
        Err(format!("{name}: {}\n--- report ---\n{output}", problems.join("; ")))
    }
}

#[test]
fn grader_holds_against_every_hostile_submission() {
    let scratch = std::env::temp_dir().join(format!("raylab-hostile-{}", std::process::id()));
    let mut names = fixture::names(&repository()).unwrap();
    // `RAYLAB_HOSTILE=files,spellings` grades only those fixtures, while writing one.
    if let Ok(only) = std::env::var("RAYLAB_HOSTILE") {
        names.retain(|n| only.split(',').any(|o| o == n));
    }
    // One after the other: they share one scratch tree and its build.
    let failures: Vec<String> = names.iter().filter_map(|n| grade_fixture(n, &scratch).err()).collect();
    let _ = std::fs::remove_dir_all(&scratch);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
