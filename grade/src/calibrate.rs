//! Calibration: grade every variant of `checkpoints/variants.toml` and tabulate the scores, so
//! that each threshold can sit between the worst correct implementation and the best wrong one.
//!
//! Each variant is written into one scratch tree (`target/variants/tree`, rewritten per variant)
//! with a shared target folder, so only the renderer itself recompiles; this grader then grades
//! its images only (no unit tests) and records every check's value. `--check` turns the table into a verdict:
//! every correct variant must pass every scene, every mistake must fail the scenes it names.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use indicatif::ProgressBar;
use serde_json::Value;

use crate::grading::{grade, GradeOptions};
use crate::rubric::Rubric;
use crate::variants::{check_patches, make_scratch_tree, Variant, VariantFile};

/// One graded run of one variant with one seed.
#[derive(Clone, Debug)]
pub struct Run {
    /// The variant.
    pub variant: Variant,
    /// The seed override, if any.
    pub seed: Option<u64>,
    /// `{scene: {error, passed, checks: {label: {value, passed}}}}`, or why it could not be graded.
    pub values: Result<Value, String>,
}

/// Builds and grades every variant; `progress` counts runs.
pub fn run_all(root: &Path, progress: &ProgressBar) -> Result<Vec<Run>, String> {
    // Calibration needs the correct variants and the mistakes an image must show (`fails`); the
    // rest of the mistake catalogue is `cargo xtask zoo`'s.
    // Every patch must still apply, those of variants calibration does not build included.
    let catalogue = VariantFile::load(&root.join("checkpoints/variants.toml"))?.variants;
    check_patches(root, &catalogue)?;
    let variants: Vec<Variant> =
        catalogue.into_iter().filter(|v| v.correct || v.stub || !v.fails.is_empty()).collect();
    // Absolute: cargo runs inside the scratch tree, where a relative path would mean another place.
    let root = std::path::absolute(root).map_err(|e| format!("{}: {e}", root.display()))?;
    let work = root.join("target/variants");
    let (tree, target) = (work.join("tree"), work.join("target"));
    let count: usize = variants.iter().map(|v| v.seeds.len().max(1)).sum();
    progress.set_length(count as u64);
    let mut runs = Vec::new();
    for variant in variants {
        progress.set_message(format!("building {}", variant.name));
        make_scratch_tree(&root, &tree, &variant)?;
        let seeds: Vec<Option<u64>> = if variant.seeds.is_empty() {
            vec![None]
        } else {
            variant.seeds.iter().copied().map(Some).collect()
        };
        for seed in seeds {
            progress.set_message(format!("grading {}", variant.name));
            let values = grade_images(&tree, &target, seed);
            runs.push(Run { variant: variant.clone(), seed, values });
            progress.inc(1);
        }
    }
    Ok(runs)
}

/// Grades the images of the tree at `tree` (its renderer built into `target`): every check's
/// value, per scene. `Err` for bad input (a broken rubric or reference), not for a broken tree.
pub fn grade_images(tree: &Path, target: &Path, seed: Option<u64>) -> Result<Value, String> {
    let options = GradeOptions {
        target: Some(target.to_path_buf()),
        run_tests: false,
        seed,
        ..GradeOptions::new(tree)
    };
    Ok(grade(&options, &ProgressBar::hidden())?.values())
}

/// Problems with the current thresholds: a correct run failing a scene, or a mistake passing a
/// scene it must fail. Empty when the rubric tells every variant right from wrong.
pub fn verdicts(runs: &[Run]) -> Vec<String> {
    let mut problems = Vec::new();
    for run in runs {
        let label = run_label(run);
        let Ok(values) = &run.values else {
            problems.push(format!("{label}: {}", run.values.as_ref().err().map_or("", String::as_str)));
            continue;
        };
        let Some(scenes) = values.as_object() else { continue };
        for (scene, v) in scenes {
            let passed = v["passed"].as_bool().unwrap_or(false);
            if run.variant.correct && !passed {
                problems.push(format!("{label} is correct but fails {scene}: {}", failing_checks(v)));
            }
            if !run.variant.correct && passed && run.variant.fails.contains(scene) {
                problems.push(format!("{label} is a mistake but passes {scene}"));
            }
        }
    }
    problems
}

fn failing_checks(scene: &Value) -> String {
    if let Some(e) = scene["error"].as_str() {
        return e.to_string();
    }
    let checks = scene["checks"].as_object().into_iter().flatten();
    let failing = checks.filter(|(_, c)| c["passed"] == Value::Bool(false));
    failing
        .map(|(l, c)| format!("{l} = {:.4}", c["value"].as_f64().unwrap_or(f64::NAN)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn run_label(run: &Run) -> String {
    match run.seed {
        Some(seed) => format!("{} (seed {seed})", run.variant.name),
        None => run.variant.name.clone(),
    }
}

/// The calibration table in Markdown: per scene, every variant's value of every check, then the
/// worst correct and best wrong value against the threshold.
pub fn markdown(runs: &[Run], rubric: &Rubric) -> String {
    let mut out = String::new();
    for scene in &rubric.scenes {
        let labels: Vec<String> = scene.checks.iter().map(|c| c.label()).collect();
        let _ =
            writeln!(out, "### {} (grades checkpoints {:?}, {} spp)\n", scene.name, scene.grades, scene.spp);
        let _ = writeln!(out, "| variant | kind | {} |", labels.join(" | "));
        let _ = writeln!(out, "|---|---|{}", "---|".repeat(labels.len()));
        let mut extremes: BTreeMap<(usize, bool), Vec<f64>> = BTreeMap::new();
        for run in runs {
            let Ok(values) = &run.values else { continue };
            let v = &values[&scene.name];
            if v.is_null() {
                continue;
            }
            let must_fail = !run.variant.correct && run.variant.fails.contains(&scene.name);
            let kind = if run.variant.correct {
                "correct"
            } else if must_fail {
                "must fail"
            } else {
                "(other scene)"
            };
            let cells: Vec<String> = labels
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    let value = v["checks"][l]["value"].as_f64();
                    if let (Some(x), true) = (value, run.variant.correct || must_fail) {
                        extremes.entry((i, run.variant.correct)).or_default().push(x);
                    }
                    let mark = if v["checks"][l]["passed"] == Value::Bool(true) { "" } else { " ✗" };
                    value.map_or_else(
                        || v["error"].as_str().unwrap_or("-").to_string(),
                        |x| format!("{x:.4}{mark}"),
                    )
                })
                .collect();
            let _ = writeln!(out, "| {} | {kind} | {} |", run_label(run), cells.join(" | "));
        }
        let summary = |correct: bool| -> Vec<String> {
            scene
                .checks
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    let xs = extremes.get(&(i, correct)).cloned().unwrap_or_default();
                    let lower_is_better = c.max.is_some();
                    // For a similarity the worst correct is the lowest and the best wrong the highest.
                    let pick = |xs: &[f64], low: bool| {
                        xs.iter().copied().reduce(if low { f64::min } else { f64::max })
                    };
                    pick(&xs, correct != lower_is_better).map_or("-".into(), |x| format!("{x:.4}"))
                })
                .collect()
        };
        let _ = writeln!(out, "| **worst correct** | | {} |", summary(true).join(" | "));
        let _ = writeln!(out, "| **best wrong** | | {} |", summary(false).join(" | "));
        let thresholds: Vec<String> = scene.checks.iter().map(|c| c.threshold_text()).collect();
        let _ = writeln!(out, "| **threshold** | | {} |\n", thresholds.join(" | "));
    }
    out
}
