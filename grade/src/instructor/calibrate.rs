//! Calibration: grade every variant of `checkpoints/variants.toml` and tabulate the scores, so
//! that each threshold can sit between the worst correct implementation and the best wrong one.
//!
//! Each variant is written into one scratch tree (`target/variants/tree`, rewritten per variant)
//! with a shared target folder, so only the renderer itself recompiles; this grader then grades
//! its images only (no unit tests) and records every check's value. `--check` turns the table into a verdict:
//! every correct variant must pass every scene, every mistake must fail the scenes it names (and
//! is graded on those only).
//!
//! **Noisy scenes** (a `[scene.tile_test]`) fail a correct render with probability `alpha` by
//! design, so there the verdict is statistical: the correct variants' false fails must be a count
//! that `alpha` explains (binomial tail at least [`TOO_MANY`]). `--sweep N` measures the rates:
//! every correct variant, and every mistake that must fail a noisy scene, on the noisy scenes with
//! seeds 1 to N; [`sweep_markdown`] tabulates the false-fail rate and each mistake's power with
//! their Clopper-Pearson intervals.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use indicatif::ProgressBar;
use serde_json::Value;

use crate::file_error::FileError;
use crate::grading::{grade, GradeError, GradeOptions};
use crate::instructor::error::InstructorError;
use crate::outcome::GradeReport;
use crate::rubric::{Check, GradedScene, Rubric, Threshold};
use crate::stats::{binomial_at_least, clopper_pearson};

/// A count of false fails whose binomial tail under `alpha` is below this is too many.
pub const TOO_MANY: f64 = 1e-3;
use crate::instructor::variants::{check_patches, make_scratch_tree, Variant, VariantFile};

/// One graded run of one variant with one seed.
#[derive(Debug)]
pub struct Run {
    /// The variant.
    pub variant: Variant,
    /// The seed override, if any.
    pub seed: Option<u64>,
    /// `{scene: {error, passed, checks: {label: {value, passed}}}}`, or why it could not be graded.
    pub values: Result<Value, GradeError>,
}

/// A sweep of the noisy scenes (module docs): seeds 1 to `seeds` for the solution and the
/// correct variants of the checkpoints a noisy scene grades; 1 to `other_seeds` for the other
/// correct variants (which change the noisy renders only through code they share with them) and
/// for the mistakes (which fail far from any threshold).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sweep {
    /// Seeds of the solution and of each correct variant of a noisy scene's checkpoint.
    pub seeds: u64,
    /// Seeds of every other variant.
    pub other_seeds: u64,
}

/// Which variants calibration grades, on which scenes, with which seeds.
struct Plan {
    /// The tile-tested scenes.
    noisy: Vec<String>,
    /// The checkpoints they grade.
    noisy_graded: Vec<u32>,
    sweep: Option<Sweep>,
}

impl Plan {
    fn new(rubric: &Rubric, sweep: Option<Sweep>) -> Plan {
        let noisy_scenes = || rubric.scenes.iter().filter(|s| s.tile_test.is_some());
        Plan {
            noisy: noisy_scenes().map(|s| s.name.clone()).collect(),
            noisy_graded: noisy_scenes().flat_map(|s| s.grades.clone()).collect(),
            sweep,
        }
    }

    /// The scenes `v` is graded on (`None`: all of them). A mistake is graded on the scenes it
    /// must fail (`fails`), the noisy ones only in a sweep.
    fn scenes_of(&self, v: &Variant) -> Option<Vec<String>> {
        let wanted = |name: &String| self.sweep.is_none() || self.noisy.contains(name);
        match v.correct {
            true if self.sweep.is_none() => None,
            true => Some(self.noisy.clone()),
            false => Some(v.fails.iter().filter(|n| wanted(n)).cloned().collect()),
        }
    }

    /// Whether calibration builds `v` at all: a correct variant, a stub, or a mistake an image
    /// must show, written its first way, with a scene to grade it on.
    fn builds(&self, v: &Variant) -> bool {
        (v.correct || v.stub || !v.fails.is_empty())
            && v.second_of.is_none()
            && self.scenes_of(v).is_none_or(|s| !s.is_empty())
    }

    /// The seeds `v` is graded with (`None`: the scene's own). In a sweep, the solution (the
    /// variant without patches) and the correct variants of checkpoints a noisy scene grades get
    /// the full count of seeds.
    fn seeds_of(&self, v: &Variant) -> Vec<Option<u64>> {
        let full_sweep = v.correct && (v.patches.is_empty() || self.noisy_graded.contains(&v.checkpoint));
        match self.sweep {
            Some(s) => (1..=if full_sweep { s.seeds } else { s.other_seeds }).map(Some).collect(),
            None if v.seeds.is_empty() => vec![None],
            None => v.seeds.iter().copied().map(Some).collect(),
        }
    }
}

/// Builds and grades every variant: each correct one on every scene, each mistake on the scenes
/// it must fail, with the seeds it lists; with a [`Sweep`] only the noisy scenes, with its seeds.
/// `progress` counts runs.
pub fn run_all(
    root: &Path,
    sweep: Option<Sweep>,
    progress: &ProgressBar,
) -> Result<Vec<Run>, InstructorError> {
    // Calibration needs the correct variants and the mistakes an image must show (`fails`); the
    // rest of the mistake catalogue is `cargo xtask zoo`'s.
    // Every patch must still apply, those of variants calibration does not build included.
    let catalogue = VariantFile::load(&root.join("checkpoints/variants.toml"))?.variants;
    check_patches(root, &catalogue)?;
    let plan = Plan::new(&Rubric::of_tree(root)?, sweep);
    let variants: Vec<Variant> = catalogue.into_iter().filter(|v| plan.builds(v)).collect();
    // Absolute: cargo runs inside the scratch tree, where a relative path would mean another place.
    let root = std::path::absolute(root).map_err(|e| FileError::unreadable(root, &e))?;
    let work = root.join("target/variants");
    let (tree, target) = (work.join("tree"), work.join("target"));
    progress.set_length(variants.iter().map(|v| plan.seeds_of(v).len()).sum::<usize>() as u64);
    let mut runs = Vec::new();
    for variant in variants {
        progress.set_message(format!("building {}", variant.name));
        make_scratch_tree(&root, &tree, &variant)?;
        let scenes = plan.scenes_of(&variant);
        for seed in plan.seeds_of(&variant) {
            progress.set_message(format!("grading {}", variant.name));
            let values = grade_images(&tree, &target, seed, scenes.clone(), variant.may_render_wide());
            runs.push(Run { variant: variant.clone(), seed, values });
            progress.inc(1);
        }
    }
    Ok(runs)
}

/// Grades the images of the tree at `tree` (its renderer built into `target`): every check's
/// value, per scene (the `scenes` named, or all), the tile-tested scenes through the wide BVH if
/// `wide_tile_renders` (for trees whose checkpoints 2-4 are the solution's). `Err` for bad input
/// (a broken rubric or reference), not for a broken tree.
pub fn grade_images(
    tree: &Path,
    target: &Path,
    seed: Option<u64>,
    scenes: Option<Vec<String>>,
    wide_tile_renders: bool,
) -> Result<Value, GradeError> {
    Ok(grade_report(tree, target, seed, scenes, wide_tile_renders)?.values())
}

/// The images of the tree graded as in [`grade_images`], the whole report.
pub fn grade_report(
    tree: &Path,
    target: &Path,
    seed: Option<u64>,
    scenes: Option<Vec<String>>,
    wide_tile_renders: bool,
) -> Result<GradeReport, GradeError> {
    let options = GradeOptions {
        target: Some(target.to_path_buf()),
        run_tests: false,
        seed,
        scenes,
        wide_tile_renders,
        ..GradeOptions::new(tree)
    };
    grade(&options, &ProgressBar::hidden())
}

/// Problems with the current thresholds: a correct run failing a scene (on a noisy scene: more
/// correct runs failing than its `alpha` explains), or a mistake passing a scene it must fail.
/// Empty when the rubric tells every variant right from wrong.
pub fn verdicts(runs: &[Run], rubric: &Rubric) -> Vec<String> {
    let mut problems = Vec::new();
    for run in runs {
        let label = run_label(run);
        let values = match &run.values {
            Ok(values) => values,
            Err(e) => {
                problems.push(format!("{label}: {e}"));
                continue;
            }
        };
        let Some(scenes) = values.as_object() else { continue };
        for (scene, v) in scenes {
            let passed = v["passed"].as_bool().unwrap_or(false);
            // On a noisy scene a correct run may fail by chance (judged below), never by an error.
            let noisy = rubric.scenes.iter().any(|s| &s.name == scene && s.tile_test.is_some());
            if run.variant.correct && !passed && (!noisy || !v["error"].is_null()) {
                problems.push(format!("{label} is correct but fails {scene}: {}", failing_checks(v)));
            }
            if !run.variant.correct && passed && run.variant.fails.contains(scene) {
                problems.push(format!("{label} is a mistake but passes {scene}"));
            }
        }
    }
    for scene in rubric.scenes.iter().filter(|s| s.tile_test.is_some()) {
        let (failed, n) = false_fails(runs, scene);
        let alpha = scene.tile_test.as_ref().map_or(0.0, |t| t.alpha);
        if binomial_at_least(failed, n, alpha) < TOO_MANY {
            problems.push(format!(
                "{}: {failed} of {n} correct runs fail, more than alpha = {alpha} explains (P = {:.1e})",
                scene.name,
                binomial_at_least(failed, n, alpha)
            ));
        }
    }
    problems
}

/// The runs of correct variants that fail `scene` (by the test, or by an error), and how many
/// graded it.
fn false_fails(runs: &[Run], scene: &GradedScene) -> (u64, u64) {
    outcomes(runs.iter().filter(|r| r.variant.correct), scene)
}

/// Of `runs`, how many failed `scene`, and how many graded it.
fn outcomes<'a>(runs: impl Iterator<Item = &'a Run>, scene: &GradedScene) -> (u64, u64) {
    let graded: Vec<bool> =
        runs.filter_map(|r| r.values.as_ref().ok()?.get(&scene.name)?["passed"].as_bool()).collect();
    (graded.iter().filter(|p| !**p).count() as u64, graded.len() as u64)
}

/// The sweep's table (module docs): per noisy scene, each variant's fails over its seeds, the
/// correct variants pooled, with 95% Clopper-Pearson intervals.
pub fn sweep_markdown(runs: &[Run], rubric: &Rubric) -> String {
    let mut out = String::new();
    let interval = |x: u64, n: u64| {
        let (lo, hi) = clopper_pearson(x, n, 0.95);
        format!("{:.1}% [{:.1}%, {:.1}%]", 100.0 * x as f64 / n.max(1) as f64, 100.0 * lo, 100.0 * hi)
    };
    for scene in rubric.scenes.iter().filter(|s| s.tile_test.is_some()) {
        let alpha = scene.tile_test.as_ref().map_or(0.0, |t| t.alpha);
        let _ =
            writeln!(out, "### {} (grades checkpoints {:?}, alpha = {alpha})\n", scene.name, scene.grades);
        let _ = writeln!(out, "| variant | kind | failed | rate [95% interval] |");
        let _ = writeln!(out, "|---|---|---|---|");
        let mut names: Vec<&str> = runs.iter().map(|r| r.variant.name.as_str()).collect();
        names.dedup();
        for name in names {
            let of_variant = || runs.iter().filter(|r| r.variant.name == name);
            let (x, n) = outcomes(of_variant(), scene);
            let Some(first) = of_variant().next().filter(|_| n > 0) else { continue };
            let kind = if first.variant.correct { "correct: false fails" } else { "mistake: caught (power)" };
            let _ = writeln!(out, "| {name} | {kind} | {x}/{n} | {} |", interval(x, n));
        }
        let (x, n) = false_fails(runs, scene);
        let _ = writeln!(out, "| **all correct** | false-fail rate | {x}/{n} | {} |\n", interval(x, n));
    }
    out
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
        scene_table(&mut out, runs, scene);
    }
    out
}

/// One scene's table: every run's check values, then the worst correct, the best wrong and the
/// thresholds.
fn scene_table(out: &mut String, runs: &[Run], scene: &GradedScene) {
    let checks = scene.graded_checks();
    let labels: Vec<String> = checks.iter().map(|c| c.label()).collect();
    let _ = writeln!(out, "### {} (grades checkpoints {:?}, {} spp)\n", scene.name, scene.grades, scene.spp);
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
        let kind = match (run.variant.correct, must_fail) {
            (true, _) => "correct",
            (false, true) => "must fail",
            (false, false) => "(other scene)",
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
    let _ =
        writeln!(out, "| **worst correct** | | {} |", extreme_cells(&checks, &extremes, true).join(" | "));
    let _ = writeln!(out, "| **best wrong** | | {} |", extreme_cells(&checks, &extremes, false).join(" | "));
    let thresholds: Vec<String> = checks.iter().map(|c| c.threshold_text()).collect();
    let _ = writeln!(out, "| **threshold** | | {} |\n", thresholds.join(" | "));
}

/// Per check, the worst value of a correct run (`correct`) or the best of a wrong one: for a
/// similarity the worst correct is the lowest and the best wrong the highest.
fn extreme_cells(
    checks: &[Check],
    extremes: &BTreeMap<(usize, bool), Vec<f64>>,
    correct: bool,
) -> Vec<String> {
    checks
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let xs = extremes.get(&(i, correct)).cloned().unwrap_or_default();
            let lower_is_better = matches!(c.threshold, Threshold::AtMost(_));
            let low = correct != lower_is_better;
            let pick = xs.iter().copied().reduce(if low { f64::min } else { f64::max });
            pick.map_or("-".into(), |x| format!("{x:.4}"))
        })
        .collect()
}
