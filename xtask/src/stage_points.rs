//! `cargo xtask stage-points [MISTAKE...]`: does a catalogue mistake cost its checkpoint the same
//! points in the student's own tree as in `grader submission`? A measurement for
//! docs/GRADING.md; it fails if one differs.
//!
//! For each mistake of checkpoint N (all of them, or those named): a fresh starter with
//! checkpoints 2 to N written (the solution's region bodies spliced in) and the mistake's patches
//! applied, 1 and N + 1 onward the starter's stubs, as a student has it when N is the checkpoint
//! they just wrote. It is graded twice: by `cargo grader --checkpoint N` inside it (stand-ins for
//! the unwritten checkpoints, scenes that wait for them not counted), and by the instructor's
//! `grader submission` (N's regions from it, the solution everywhere else). Both are public
//! points: the instructor's side grades from a copy of the repository without its hidden checks,
//! which a student's tree does not have.

use std::path::Path;
use std::process::Command;

use raylab_grade::instructor::fixture::points;
use raylab_grade::instructor::variants::{apply, Variant, VariantFile};
use raylab_grade::regions::stub::{region_bodies, rust_files};
use raylab_grade::submission::scratch::{copy_tree, write_if_changed, NOT_COPIED};

use crate::repository;
use crate::starter::starter;

/// What an instructor's copy leaves out besides [`NOT_COPIED`]: the hidden checks.
const HIDDEN: [&str; 2] = ["hidden", "tests/hidden"];

/// Grades the named mistakes (every one if none is named) both ways and prints a table row each.
pub fn stage_points(names: &[String]) -> Result<(), String> {
    let work = repository().join("target/stage-points");
    let (base, tree, instructor) = (work.join("starter"), work.join("tree"), work.join("instructor"));
    starter(&base)?;
    let skip: Vec<&str> = NOT_COPIED.iter().chain(&HIDDEN).copied().collect();
    copy_tree(repository(), &instructor, &skip).map_err(|e| format!("{}: {e}", instructor.display()))?;
    cargo(repository(), &["build", "--release", "-p", "raylab-grade", "--features", "instructor"])?;
    let grader = repository().join("target/release/grader");
    let catalogue = VariantFile::load(&repository().join("checkpoints/variants.toml"))
        .map_err(|e| e.to_string())?
        .variants;
    let mut mistakes: Vec<&Variant> = catalogue
        .iter()
        .filter(|v| !v.correct && !v.stub && (names.is_empty() || names.contains(&v.name)))
        .collect();
    mistakes.sort_by_key(|v| v.checkpoint);
    println!("| mistake | checkpoint | own tree at its stage | `grader submission` | same |");
    println!("|---|---|---|---|---|");
    let mut different = Vec::new();
    for mistake in mistakes {
        let n = mistake.checkpoint;
        copy_tree(&base, &tree, &NOT_COPIED).map_err(|e| format!("{}: {e}", tree.display()))?;
        write_stage(&tree, mistake)?;
        let (own, submitted) = (work.join("own.json"), work.join("submission.json"));
        // A grader that writes no results must not be read as agreeing with the last mistake's.
        for stale in [&own, &submitted] {
            let _ = std::fs::remove_file(stale);
        }
        let target = work.join("target");
        let own_args = ["grader", "--checkpoint", &n.to_string(), "--json", path(&own)?];
        let mut own_grade = Command::new("cargo");
        own_grade.args(own_args).current_dir(&tree).env("CARGO_TARGET_DIR", &target);
        graded(own_grade, &mistake.name)?;
        let mut submission = Command::new(&grader);
        submission.args([
            "submission",
            path(&tree)?,
            "--root",
            path(&instructor)?,
            "--json",
            path(&submitted)?,
        ]);
        graded(submission, &mistake.name)?;
        let (own, submitted) = (checkpoint_points(&own, n)?, checkpoint_points(&submitted, n)?);
        let same = (own - submitted).abs() < 0.011;
        println!(
            "| {} | {n} | {own:.2} | {submitted:.2} | {} |",
            mistake.name,
            if same { "yes" } else { "**no**" }
        );
        if !same {
            different.push(mistake.name.clone());
        }
    }
    match different.is_empty() {
        true => Ok(()),
        false => Err(format!("points differ for {}", different.join(", "))),
    }
}

/// Writes checkpoints 2 to the mistake's own into the starter at `tree` (the solution's region
/// bodies) and applies the mistake's patches.
fn write_stage(tree: &Path, mistake: &Variant) -> Result<(), String> {
    let solution = rust_files(&repository().join("src")).map_err(|e| format!("src: {e}"))?;
    for (file, text) in solution {
        let relative = file.strip_prefix(repository()).map_err(|e| e.to_string())?;
        let mut written = std::fs::read_to_string(tree.join(relative))
            .map_err(|e| format!("{}: {e}", relative.display()))?;
        for c in 2..=mistake.checkpoint {
            let (bodies, stubs) = (region_bodies(&text, c), region_bodies(&written, c));
            if bodies.len() != stubs.len() {
                return Err(format!(
                    "{}: the starter has other regions of checkpoint {c}",
                    relative.display()
                ));
            }
            for (body, stub) in bodies.iter().zip(&stubs).rev() {
                written.replace_range(stub.clone(), &text[body.clone()]);
            }
        }
        for patch in mistake.patches.iter().filter(|p| p.file == relative) {
            written = apply(&written, mistake.checkpoint, patch).map_err(|e| e.to_string())?;
        }
        write_if_changed(&tree.join(relative), written.as_bytes())
            .map_err(|e| format!("{}: {e}", relative.display()))?;
    }
    Ok(())
}

/// Runs a grader, its report on stderr (stdout holds the table); exit code 1 is points lost,
/// anything else but 0 an error.
fn graded(mut grader: Command, mistake: &str) -> Result<(), String> {
    let output =
        grader.stderr(std::process::Stdio::inherit()).output().map_err(|e| format!("{grader:?}: {e}"))?;
    eprintln!("{}", String::from_utf8_lossy(&output.stdout));
    match output.status.code() {
        Some(0 | 1) => Ok(()),
        _ => Err(format!("{mistake}: {grader:?} failed ({})", output.status)),
    }
}

/// Checkpoint `n`'s points in the Gradescope `results.json` at `file`.
fn checkpoint_points(file: &Path, n: u32) -> Result<f64, String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let results = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(points(&results).get(&n).copied().unwrap_or(0.0))
}

fn cargo(dir: &Path, args: &[&str]) -> Result<(), String> {
    let status =
        Command::new("cargo").args(args).current_dir(dir).status().map_err(|e| format!("cargo: {e}"))?;
    status.success().then_some(()).ok_or_else(|| format!("cargo {} failed", args.join(" ")))
}

fn path(p: &Path) -> Result<&str, String> {
    p.to_str().ok_or_else(|| format!("{}: not UTF-8", p.display()))
}
