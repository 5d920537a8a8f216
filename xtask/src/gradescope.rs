//! `cargo xtask gradescope-dry-run`: Gradescope's life cycle, run here on a scratch root.
//!
//! Packages the tree (the code of `grader package gradescope`), unpacks the zip into
//! `target/gradescope-dry-run/autograder/source`, runs `setup.sh` there with `AUTOGRADER_ROOT`
//! pointing at the scratch root (cargo is already installed here, so it installs nothing), then
//! `run_autograder` on four submissions, each unpacked as Gradescope would into
//! `autograder/submission`: the solution (every point), the starter (checkpoint 1's points
//! only), and the hostile fixtures `crashes` and `cheats` (exactly the points their
//! `expected.toml` commits to), each over a planted full-marks results.json; then a grader that
//! writes full marks everywhere and is killed (the 0-point fallback). Prints the time of each
//! step (docs/PERFORMANCE.md).
//!
//! With `--emulate`, every script runs as in Gradescope's container (Docker's defaults: no
//! CAP_SYS_ADMIN, no namespaces or mounts; `tools/gradescope-emulation.sh`), on the solution and
//! `crashes`, the hostile fixture that takes longest: the same points, and the walls printed into
//! the instructor's log, never into results.json.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use raylab_grade::instructor::fixture;
use raylab_grade::rubric::Rubric;
use raylab_grade::submission::scratch::{copy_tree, NOT_COPIED};

use crate::repository;

/// What a submission's results.json must show.
enum Want {
    /// This total.
    Total(f64),
    /// A hostile fixture's expectations.
    Fixture(fixture::Expected),
}

/// Packages, sets up and grades four submissions in a scratch Gradescope root (two, `emulate`d).
pub fn gradescope_dry_run(emulate: bool) -> Result<(), String> {
    let root = repository();
    let work = root.join(if emulate { "target/gradescope-emulated" } else { "target/gradescope-dry-run" });
    let scripts = Scripts { emulation: emulate.then(|| root.join("tools/gradescope-emulation.sh")) };
    let autograder = work.join("autograder");
    set_up(root, &work, &scripts, &autograder)?;
    let submission = autograder.join("submission");
    let mut problems = Vec::new();
    let names: &[&str] =
        if emulate { &["solution", "crashes"] } else { &["solution", "starter", "crashes", "cheats"] };
    for &name in names {
        if submission.exists() {
            std::fs::remove_dir_all(&submission).map_err(|e| format!("{}: {e}", submission.display()))?;
        }
        let want = submit(root, name, &submission)?;
        problems.extend(run_autograder(&scripts, &autograder, name, want)?);
    }
    problems.extend(killed_grader(&scripts, &autograder, &work)?);
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// A fresh `work` folder, the autograder packaged into it, unzipped into `autograder/source`
/// and set up by its `setup.sh`, each step timed.
fn set_up(root: &Path, work: &Path, scripts: &Scripts, autograder: &Path) -> Result<(), String> {
    if work.exists() {
        std::fs::remove_dir_all(work).map_err(|e| format!("{}: {e}", work.display()))?;
    }
    let zip = work.join("autograder.zip");
    let started = Instant::now();
    raylab_grade::instructor::package::gradescope(root, &work.join("package"), &zip)
        .map_err(|e| e.to_string())?;
    println!("packaged {} in {:.0} s", zip.display(), started.elapsed().as_secs_f64());
    let source = autograder.join("source");
    std::fs::create_dir_all(&source).map_err(|e| format!("{}: {e}", source.display()))?;
    run("unzip", Command::new("unzip").arg("-q").arg(&zip).arg("-d").arg(&source))?;
    let started = Instant::now();
    run("setup.sh", &mut scripts.command(autograder, "setup.sh"))?;
    println!(
        "setup.sh: {:.0} s (the grader built, the solution graded once)",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Puts the submission `name` at `submission`, and says what its grade must be.
fn submit(root: &Path, name: &str, submission: &Path) -> Result<Want, String> {
    let rubric = Rubric::of_tree(root).map_err(|e| e.to_string())?;
    Ok(match name {
        "solution" => {
            copy_tree(root, submission, &NOT_COPIED).map_err(|e| format!("copying the solution: {e}"))?;
            Want::Total(rubric.total_points())
        }
        // Uploaded as a zip of the repository's folder: the tree one level down.
        "starter" => {
            crate::starter::starter(&submission.join("raylab-starter"))?;
            Want::Total(rubric.checkpoints[0].test_points)
        }
        hostile => Want::Fixture(fixture::make(root, hostile, submission).map_err(|e| e.to_string())?),
    })
}

/// Runs `run_autograder` on the submission in place, over a planted full-marks result; what
/// differs from `want`.
fn run_autograder(
    scripts: &Scripts,
    autograder: &Path,
    name: &str,
    want: Want,
) -> Result<Vec<String>, String> {
    // What a graded process could leave where Gradescope reads the result: replaced.
    plant_full_marks(&autograder.join("results/results.json"))?;
    let started = Instant::now();
    run("run_autograder", &mut scripts.command(autograder, "run_autograder"))?;
    let seconds = started.elapsed().as_secs_f64();
    let path = autograder.join("results/results.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{name}: {}: {e}", path.display()))?;
    let results: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{name}: results.json: {e}"))?;
    let score = results["score"].as_f64().unwrap_or(-1.0);
    println!("run_autograder {name}: {score} points in {seconds:.0} s");
    let mut problems = Vec::new();
    if text.contains("refused: ") || text.contains("sandbox") {
        problems.push(format!("{name}: results.json speaks of the sandbox's walls: {text}"));
    }
    match want {
        Want::Total(want) if (score - want).abs() > 0.011 => {
            problems.push(format!("{name}: {score} points, expected {want}"))
        }
        Want::Total(_) => {}
        Want::Fixture(expected) => {
            problems.extend(expected.problems(&results).into_iter().map(|p| format!("{name}: {p}")))
        }
    }
    Ok(problems)
}

fn plant_full_marks(path: &Path) -> Result<(), String> {
    std::fs::create_dir_all(path.parent().unwrap_or(path)).map_err(|e| format!("{}: {e}", path.display()))?;
    std::fs::write(path, r#"{"score": 999, "output": "planted"}"#)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// A grader that writes full marks both where it was told and where Gradescope reads, then dies
/// as a killed one does: the student gets the 0-point fallback.
fn killed_grader(scripts: &Scripts, autograder: &Path, work: &Path) -> Result<Option<String>, String> {
    let fake = work.join("killed-grader");
    let grader = fake.join("release/grader");
    std::fs::create_dir_all(grader.parent().unwrap_or(&fake))
        .map_err(|e| format!("{}: {e}", fake.display()))?;
    let script = r#"#!/bin/sh
prev=
for a in "$@"; do
    [ "$prev" = --json ] && printf '{"score": 999}' > "$a"
    prev=$a
done
printf '{"score": 999}' > "$AUTOGRADER_ROOT/results/results.json"
kill -KILL $$
"#;
    std::fs::write(&grader, script).map_err(|e| format!("{}: {e}", grader.display()))?;
    run("chmod", Command::new("chmod").arg("+x").arg(&grader))?;
    run("run_autograder", scripts.command(autograder, "run_autograder").env("CARGO_TARGET_DIR", &fake))?;
    let path = autograder.join("results/results.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let results: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("results.json: {e}"))?;
    let output = results["output"].as_str().unwrap_or_default();
    println!("run_autograder with a killed grader: {} points", results["score"]);
    Ok((results["score"] != 0 || !output.contains("could not run"))
        .then(|| format!("a killed grader: {text}, expected the 0-point fallback")))
}

/// How Gradescope's scripts are started: directly, or through the container's emulation.
struct Scripts {
    /// `tools/gradescope-emulation.sh`, for `--emulate`.
    emulation: Option<std::path::PathBuf>,
}

impl Scripts {
    /// One of Gradescope's scripts, run as Gradescope runs it but below `autograder`.
    fn command(&self, autograder: &Path, script: &str) -> Command {
        let mut command = match &self.emulation {
            Some(emulation) => {
                let mut command = Command::new(emulation);
                command.arg("bash");
                command
            }
            None => Command::new("bash"),
        };
        command
            .arg(autograder.join("source").join(script))
            .current_dir(autograder.join("source"))
            .env("AUTOGRADER_ROOT", autograder)
            .env_remove("CARGO_TARGET_DIR")
            .env_remove(raylab_grade::run::child::CHILD_ENV);
        command
    }
}

fn run(what: &str, command: &mut Command) -> Result<(), String> {
    let status = command.status().map_err(|e| format!("cannot run {what}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed ({status})"))
    }
}
