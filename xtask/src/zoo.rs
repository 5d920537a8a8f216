//! The mistake catalogue's run: which unit test or scene catches each variant of
//! `checkpoints/variants.toml` (docs/ZOO.md).

use std::path::Path;
use std::time::Duration;

use raylab_grade::instructor::calibrate::grade_images;
use raylab_grade::instructor::variants::{check_patches, make_scratch_tree, Variant, VariantFile};
use raylab_grade::rubric::Rubric;
use raylab_grade::run::unit_tests::build_tests;

use crate::repository;

/// For every variant but the solution and the stubs: its own checkpoint's unit tests (all tests,
/// for a correct alternative) and every scene's checks. A mistake must be caught by its own
/// checkpoint's tests or by a scene grading that checkpoint; a correct alternative must pass all.
pub fn zoo() -> Result<(), String> {
    let root = repository();
    let work = root.join("target/zoo");
    let (tree, target) = (work.join("tree"), work.join("target"));
    let rubric = Rubric::of_tree(root).map_err(|e| e.to_string())?;
    let variants =
        VariantFile::load(&root.join("checkpoints/variants.toml")).map_err(|e| e.to_string())?.variants;
    check_patches(root, &variants).map_err(|e| e.to_string())?;
    let mut rows = vec![
        "| variant | checkpoint | kind | failing unit tests | failing scenes | verdict |".to_string(),
        "|---|---|---|---|---|---|".to_string(),
    ];
    let mut problems = Vec::new();
    for v in variants.iter().filter(|v| !v.stub && !v.patches.is_empty()) {
        make_scratch_tree(root, &tree, v).map_err(|e| e.to_string())?;
        let caught = catch(v, &rubric, &tree, &target)?;
        if caught.verdict != "caught" && caught.verdict != "passes everything" {
            problems.push(format!("{}: {}", v.name, caught.verdict));
        }
        let row = caught.row(v);
        println!("{row}");
        rows.push(row);
    }
    write_table(root, &rows)?;
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// What fails for one variant, and what that makes it.
struct Caught {
    /// Its unit tests that fail (last path segment).
    tests: Vec<String>,
    /// The graded scenes that fail.
    scenes: Vec<String>,
    verdict: &'static str,
}

/// Runs `v`'s tests and grades every scene in its scratch tree at `tree`.
fn catch(v: &Variant, rubric: &Rubric, tree: &Path, target: &Path) -> Result<Caught, String> {
    // A correct alternative must pass every checkpoint's tests (`checkpoint` matches them all;
    // the harness's own snapshots describe the reference solution and may differ).
    let filter = if v.correct { "checkpoint".to_string() } else { format!("checkpoint{}", v.checkpoint) };
    let tests = match build_tests(tree, Some(target), Duration::from_secs(900)) {
        Ok(binaries) => binaries.run_filter(tree, &filter, &[], &[], Duration::from_secs(300)),
        Err(e) => return Err(format!("{}: does not build: {e}", v.name)),
    };
    let failing_tests: Vec<String> =
        tests.failures.iter().map(|f| f.rsplit("::").next().unwrap_or(f).to_string()).collect();
    let values = grade_images(tree, target, None, None, v.may_render_wide()).map_err(|e| e.to_string())?;
    let graders_of =
        |scene: &str| rubric.scenes.iter().find(|s| s.name == scene).map_or(Vec::new(), |s| s.grades.clone());
    let failing_scenes: Vec<String> = values
        .as_object()
        .into_iter()
        .flatten()
        .filter(|(_, s)| s["passed"].as_bool() != Some(true))
        .map(|(name, _)| name.clone())
        .collect();
    let caught_by_scene = failing_scenes.iter().any(|s| graders_of(s).contains(&v.checkpoint));
    let verdict =
        match (v.correct, failing_tests.is_empty() && tests.error.is_none(), failing_scenes.is_empty()) {
            (true, true, true) => "passes everything",
            (true, _, _) => "CORRECT BUT FAILS",
            (false, false, _) => "caught",
            (false, true, _) if caught_by_scene => "caught",
            (false, true, _) => "NOT CAUGHT",
        };
    Ok(Caught { tests: failing_tests, scenes: failing_scenes, verdict })
}

impl Caught {
    /// `v`'s row of docs/ZOO.md's table.
    fn row(&self, v: &Variant) -> String {
        let kind = if v.correct { "correct" } else { "mistake" };
        let list = |xs: &[String]| if xs.is_empty() { "-".to_string() } else { xs.join(", ") };
        let (tests, scenes) = (list(&self.tests), list(&self.scenes));
        format!("| {} | {} | {kind} | {tests} | {scenes} | {} |", v.name, v.checkpoint, self.verdict)
    }
}

/// Writes docs/ZOO.md: the table of `rows`, then the hand-written sections after the old table
/// (from its first `## ` heading on), kept.
fn write_table(root: &Path, rows: &[String]) -> Result<(), String> {
    let table = format!(
        "# The mistake catalogue\n\nWritten by `cargo xtask zoo`: every variant of `checkpoints/variants.toml` (but the \
         stubs, which `cargo xtask stub-matrix` covers), with the unit tests of its checkpoint (all tests for a correct \
         alternative) and the graded scenes that fail. A mistake must be caught by its own checkpoint's tests or by a \
         scene grading that checkpoint.\n\n{}\n",
        rows.join("\n")
    );
    let path = root.join("docs/ZOO.md");
    let kept = std::fs::read_to_string(&path)
        .ok()
        .and_then(|old| old.find("\n## ").map(|i| old[i..].to_string()))
        .unwrap_or_default();
    std::fs::write(&path, format!("{table}{kept}")).map_err(|e| format!("docs/ZOO.md: {e}"))
}
