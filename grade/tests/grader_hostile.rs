//! The hostile-submission suite (`tests/hostile/README.md`): each fixture is applied to a copy of
//! the reference solution, graded with `grader submission` from this repository, and must get
//! exactly the points its `expected.toml` commits to, with the reasons it names.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use raylab_grade::stub::{region_bodies, region_function};
use raylab_grade::variants::copy_tree;
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Fixture {
    #[serde(default)]
    region: Vec<RegionEdit>,
    #[serde(default)]
    write: Vec<WriteEdit>,
    #[serde(default)]
    delete: Vec<PathEdit>,
    #[serde(default)]
    copy: Vec<CopyEdit>,
    #[serde(default)]
    strip_markers: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RegionEdit {
    file: PathBuf,
    function: String,
    body: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WriteEdit {
    path: PathBuf,
    text: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathEdit {
    path: PathBuf,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CopyEdit {
    from: PathBuf,
    to: PathBuf,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Expected {
    /// Substrings the report must contain.
    output: Vec<String>,
    /// Points per checkpoint, each judged on its own.
    points: BTreeMap<u32, f64>,
}

fn repository() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// The workspace's target folder (this test runs from `target/debug/deps`): the submissions'
/// builds reuse its compiled dependencies.
fn target_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.ancestors().nth(3).unwrap().to_path_buf()
}

fn apply(fixture: &Fixture, dir: &Path) {
    for edit in &fixture.region {
        let path = dir.join(&edit.file);
        let text = std::fs::read_to_string(&path).unwrap();
        let range = (1..=9)
            .flat_map(|n| region_bodies(&text, n))
            .find(|r| region_function(&text, r.start) == edit.function)
            .unwrap_or_else(|| panic!("no region of {} in {}", edit.function, edit.file.display()));
        let mut out = text.clone();
        out.replace_range(range, edit.body.trim_start_matches('\n'));
        std::fs::write(&path, out).unwrap();
    }
    for edit in &fixture.write {
        std::fs::write(dir.join(&edit.path), &edit.text).unwrap();
    }
    for edit in &fixture.delete {
        std::fs::remove_file(dir.join(&edit.path)).unwrap();
    }
    for edit in &fixture.copy {
        std::fs::copy(dir.join(&edit.from), dir.join(&edit.to)).unwrap();
    }
    if fixture.strip_markers {
        for (path, text) in raylab_grade::stub::rust_files(&dir.join("src")).unwrap() {
            let kept: String = text
                .split_inclusive('\n')
                .filter(|l| {
                    !l.contains("// BEGIN SOLUTION") && !l.trim_start().starts_with("// END SOLUTION")
                })
                .collect();
            std::fs::write(path, kept).unwrap();
        }
    }
}

/// Grades one fixture; `Err` lists what differs from its expectations.
fn grade_fixture(name: &str, scratch: &Path) -> Result<(), String> {
    let folder = repository().join("grade/tests/hostile").join(name);
    let fixture: Fixture =
        toml::from_str(&std::fs::read_to_string(folder.join("fixture.toml")).unwrap()).unwrap();
    let expected: Expected =
        toml::from_str(&std::fs::read_to_string(folder.join("expected.toml")).unwrap()).unwrap();
    let submission = scratch.join(name);
    let _ = std::fs::remove_dir_all(&submission);
    copy_tree(&repository(), &submission, &[".git", "target", "out"]).unwrap();
    apply(&fixture, &submission);
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
    let mut points: BTreeMap<u32, f64> = BTreeMap::new();
    for test in results["tests"].as_array().unwrap() {
        let checkpoint: u32 = test["number"].as_str().unwrap().split('.').next().unwrap().parse().unwrap();
        *points.entry(checkpoint).or_default() += test["score"].as_f64().unwrap();
    }
    let output = results["output"].as_str().unwrap_or_default();
    let mut problems = Vec::new();
    if expected.points.len() != points.len() {
        problems
            .push(format!("expected.toml must give every checkpoint's points; the grader gave {points:?}"));
    }
    for (checkpoint, want) in &expected.points {
        let got = points.get(checkpoint).copied().unwrap_or(0.0);
        if (got - want).abs() > 0.011 {
            problems.push(format!("checkpoint {checkpoint}: {got} points, expected {want}"));
        }
    }
    problems
        .extend(expected.output.iter().filter(|s| !output.contains(s.as_str())).map(|s| format!("no {s:?}")));
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("{name}: {}\n--- report ---\n{output}", problems.join("; ")))
    }
}

#[test]
fn grader_holds_against_every_hostile_submission() {
    let scratch = std::env::temp_dir().join(format!("raylab-hostile-{}", std::process::id()));
    let mut names: Vec<String> = std::fs::read_dir(repository().join("grade/tests/hostile"))
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    // One after the other: they share one scratch tree and its build.
    let failures: Vec<String> = names.iter().filter_map(|n| grade_fixture(n, &scratch).err()).collect();
    let _ = std::fs::remove_dir_all(&scratch);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
