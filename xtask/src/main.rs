//! Instructor tasks.
//!
//! `cargo xtask starter --out DIR` writes the student starter from the reference solution;
//! `cargo xtask stub-matrix` proves, for each checkpoint N stubbed alone, that every checkpoint-N
//! test fails and every test of the checkpoints before N passes; `cargo xtask zoo` runs the mistake
//! catalogue and writes which check catches each mistake.
//!
//! The starter is the whole repository with every solution region replaced by its stub
//! (`todo!("checkpoint N: ...")`, see `raylab_grade::stub`), and without what only instructors
//! need: this generator, the mistake catalogue (`checkpoints/variants.toml`) and its calibration
//! table. It then checks that no line of any solution survives in the starter.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use std::time::Duration;

use raylab_grade::calibrate::grade_images;
use raylab_grade::stub::region_bodies;
use raylab_grade::unit_tests::{build_tests, run_filter};
use raylab_grade::variants::{check_patches, make_scratch_tree, stub_tree, Variant, VariantFile};

#[derive(Parser)]
#[command(about = "raylab's instructor tasks")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write the student starter repository into DIR (replaced if it exists).
    Starter {
        /// Where to write it.
        #[arg(long)]
        out: PathBuf,
    },
    /// For each checkpoint N from 2 to 7 stubbed alone: N's tests all fail, earlier ones pass.
    StubMatrix,
    /// Run the mistake catalogue: which unit test or scene catches each variant (docs/ZOO.md).
    Zoo,
}

/// Left out of the starter: instructor-only material (this generator, the benchmarks, the
/// mistake catalogue and what it measured, and the instructor's CI, which runs them). Paths are
/// relative to the repository; a folder leaves out everything below it.
const INSTRUCTOR_ONLY: [&str; 9] = [
    "xtask",
    "bench",
    ".ci",
    "checkpoints/variants.toml",
    "docs/CALIBRATION.md",
    "docs/ZOO.md",
    "docs/PERFORMANCE.md",
    "grade/tests",
    "tools",
];

/// The workspace section of the starter's `Cargo.toml`: the renderer and the grader only, in a
/// workspace of its own, so the starter builds wherever it is unpacked.
const STARTER_WORKSPACE: &str =
    "# The root package is the renderer, what you read and edit; `grade/` is the grader that gives
# you feedback (`cargo grader`). `cargo test` at the root builds and tests the renderer alone.
[workspace]
members = [\"grade\"]
";

const CHECKPOINTS: [u32; 7] = [1, 2, 3, 4, 5, 6, 7];

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Starter { out } => {
            starter(&out).map(|()| println!("wrote the student starter to {}", out.display()))
        }
        Command::StubMatrix => stub_matrix(),
        Command::Zoo => zoo(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask: {message}");
            ExitCode::from(1)
        }
    }
}

/// The repository this xtask belongs to.
fn repository() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lives inside the repository")
}

fn starter(out: &Path) -> Result<(), String> {
    let root = repository();
    if out.exists() {
        std::fs::remove_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    for file in starter_files(root)? {
        let to = out.join(&file);
        std::fs::create_dir_all(to.parent().unwrap_or(out)).map_err(|e| format!("{}: {e}", to.display()))?;
        std::fs::copy(root.join(&file), &to).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    let edit = |file: &str, change: &dyn Fn(&str) -> Result<String, String>| {
        let path = out.join(file);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        std::fs::write(&path, change(&text)?).map_err(|e| format!("{}: {e}", path.display()))
    };
    edit("Cargo.toml", &|text| {
        let package = text.split("\n# Crates by audience.").next().unwrap_or(text).trim_end();
        let shared = text.find("[workspace.package]").map_or("", |i| &text[i..]);
        Ok(format!("{package}\n\n{STARTER_WORKSPACE}\n{shared}"))
    })?;
    edit(".cargo/config.toml", &|text| {
        Ok(text.lines().filter(|l| !l.starts_with("xtask")).map(|l| format!("{l}\n")).collect())
    })?;
    edit("README.md", &student_readme)?;
    stub_tree(&out.join("src"), &CHECKPOINTS).map_err(|e| format!("stubbing {}: {e}", out.display()))?;
    let survivors = surviving_solution_lines(&root.join("src"), &out.join("src"))?;
    if !survivors.is_empty() {
        return Err(format!("solution lines survive in the starter: {survivors:?}"));
    }
    Ok(())
}

/// The files the starter takes: those under version control (`git ls-files`, so nothing the
/// working folder happens to hold, such as renders or reports, reaches students), without the
/// instructor-only ones.
fn starter_files(root: &Path) -> Result<Vec<PathBuf>, String> {
    let out = std::process::Command::new("git")
        .arg("-C")
        .arg(root)
        .args(["ls-files", "-z", "--cached"])
        .output()
        .map_err(|e| format!("cannot run git: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "git ls-files in {}: {}",
            root.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let listed =
        String::from_utf8(out.stdout).map_err(|_| "git ls-files: a path is not UTF-8".to_string())?;
    let instructor_only = |file: &Path| INSTRUCTOR_ONLY.iter().any(|p| file.starts_with(p));
    Ok(listed
        .split('\0')
        .filter(|f| !f.is_empty())
        .map(PathBuf::from)
        .filter(|f| !instructor_only(f) && root.join(f).is_file())
        .collect())
}

/// The README as students see it: blocks between `<!-- BEGIN INSTRUCTOR -->` and
/// `<!-- END INSTRUCTOR -->` removed, and the text of `<!-- STUDENT ... -->` comments shown.
fn student_readme(text: &str) -> Result<String, String> {
    const BEGIN: &str = "<!-- BEGIN INSTRUCTOR -->\n";
    const END: &str = "<!-- END INSTRUCTOR -->\n";
    const STUDENT: &str = "<!-- STUDENT\n";
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find(BEGIN) {
        let end = rest[start..].find(END).ok_or("README.md: an instructor block is not closed")? + start;
        out.push_str(&rest[..start]);
        rest = &rest[end + END.len()..];
    }
    out.push_str(rest);
    let mut shown = String::new();
    let mut rest = out.as_str();
    while let Some(start) = rest.find(STUDENT) {
        let end = rest[start..].find("-->\n").ok_or("README.md: a student comment is not closed")? + start;
        shown.push_str(&rest[..start]);
        shown.push_str(&rest[start + STUDENT.len()..end]);
        rest = &rest[end + "-->\n".len()..];
    }
    shown.push_str(rest);
    Ok(shown)
}

/// Lines of solution regions (of at least 12 characters, not also found outside the regions)
/// that still occur anywhere in the starter's sources.
fn surviving_solution_lines(solution: &Path, starter: &Path) -> Result<Vec<String>, String> {
    let (mut inside, mut outside) = (BTreeSet::new(), BTreeSet::new());
    for text in rust_files(solution)? {
        let regions: Vec<_> = CHECKPOINTS.iter().flat_map(|&n| region_bodies(&text, n)).collect();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let set = if regions.iter().any(|r| r.contains(&offset)) { &mut inside } else { &mut outside };
            set.insert(line.trim().to_string());
            offset += line.len();
        }
    }
    let distinctive: BTreeSet<String> =
        inside.difference(&outside).filter(|l| l.len() >= 12).cloned().collect();
    let mut found = BTreeSet::new();
    for text in rust_files(starter)? {
        found.extend(text.lines().map(str::trim).filter(|l| distinctive.contains(*l)).map(str::to_string));
    }
    Ok(found.into_iter().collect())
}

fn rust_files(dir: &Path) -> Result<Vec<String>, String> {
    raylab_grade::stub::rust_files(dir).map_err(|e| format!("{}: {e}", dir.display()))
}

/// Builds each single-checkpoint stub in a scratch tree (one shared target folder) and runs the
/// test filters of that checkpoint and the ones before it.
fn stub_matrix() -> Result<(), String> {
    let work = repository().join("target/stub-matrix");
    // One target folder for every stub: cargo then reuses the dependencies built for earlier ones.
    let (tree, target) = (work.join("tree"), work.join("target"));
    let mut problems = Vec::new();
    for n in 2..=7 {
        let variant = Variant {
            name: format!("stub_{n}"),
            checkpoint: n,
            correct: false,
            description: format!("checkpoint {n} stubbed alone"),
            fails: Vec::new(),
            seeds: Vec::new(),
            stub: true,
            patches: Vec::new(),
        };
        make_scratch_tree(repository(), &tree, &variant)?;
        build_tests(&tree, Some(&target), Duration::from_secs(900))
            .map_err(|e| format!("stub {n}: the tests do not build: {e}"))?;
        let mut row = format!("checkpoint {n} stubbed:");
        for m in 1..=n {
            let run = run_filter(&tree, Some(&target), &format!("checkpoint{m}"), Duration::from_secs(300));
            row += &format!("  {m}: {}/{}", run.passed, run.passed + run.failed);
            let ok = if m < n {
                run.error.is_none() && run.failed == 0 && run.passed > 0
            } else {
                run.passed == 0 && run.failed > 0
            };
            if !ok {
                problems.push(format!(
                    "with checkpoint {n} stubbed, checkpoint {m}: {} passed, {} failed{}",
                    run.passed,
                    run.failed,
                    run.error.map(|e| format!(" ({e})")).unwrap_or_default()
                ));
            }
        }
        println!("{row}");
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// For every variant but the solution and the stubs: its own checkpoint's unit tests (all tests,
/// for a correct alternative) and every scene's checks. A mistake must be caught by its own
/// checkpoint's tests or by a scene grading that checkpoint; a correct alternative must pass all.
fn zoo() -> Result<(), String> {
    let root = repository();
    let work = root.join("target/zoo");
    let (tree, target) = (work.join("tree"), work.join("target"));
    let rubric = raylab_grade::rubric::Rubric::load(&root.join("checkpoints/rubric.toml"), root)?;
    let variants = VariantFile::load(&root.join("checkpoints/variants.toml"))?.variants;
    check_patches(root, &variants)?;
    let mut rows = vec![
        "| variant | checkpoint | kind | failing unit tests | failing scenes | verdict |".to_string(),
        "|---|---|---|---|---|---|".to_string(),
    ];
    let mut problems = Vec::new();
    for v in variants.iter().filter(|v| !v.stub && !v.patches.is_empty()) {
        make_scratch_tree(root, &tree, v)?;
        // A correct alternative must pass every checkpoint's tests (`checkpoint` matches them all;
        // the harness's own snapshots describe the reference solution and may differ).
        let filter = if v.correct { "checkpoint".to_string() } else { format!("checkpoint{}", v.checkpoint) };
        let tests = match build_tests(&tree, Some(&target), Duration::from_secs(900)) {
            Ok(()) => run_filter(&tree, Some(&target), &filter, Duration::from_secs(300)),
            Err(e) => return Err(format!("{}: does not build: {e}", v.name)),
        };
        let failing_tests: Vec<String> =
            tests.failures.iter().map(|f| f.rsplit("::").next().unwrap_or(f).to_string()).collect();
        let values = grade_images(&tree, &target, None)?;
        let graders_of = |scene: &str| {
            rubric.scenes.iter().find(|s| s.name == scene).map_or(Vec::new(), |s| s.grades.clone())
        };
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
        if verdict != "caught" && verdict != "passes everything" {
            problems.push(format!("{}: {verdict}", v.name));
        }
        let kind = if v.correct { "correct" } else { "mistake" };
        let list = |xs: &[String]| if xs.is_empty() { "-".to_string() } else { xs.join(", ") };
        let row = format!(
            "| {} | {} | {kind} | {} | {} | {verdict} |",
            v.name,
            v.checkpoint,
            list(&failing_tests),
            list(&failing_scenes)
        );
        println!("{row}");
        rows.push(row);
    }
    let table = format!(
        "# The mistake catalogue\n\nWritten by `cargo xtask zoo`: every variant of `checkpoints/variants.toml` (but the \
         stubs, which `cargo xtask stub-matrix` covers), with the unit tests of its checkpoint (all tests for a correct \
         alternative) and the graded scenes that fail. A mistake must be caught by its own checkpoint's tests or by a \
         scene grading that checkpoint.\n\n{}\n",
        rows.join("\n")
    );
    std::fs::write(root.join("docs/ZOO.md"), table).map_err(|e| format!("docs/ZOO.md: {e}"))?;
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The catalogue patches the solution's text: an edit to a solution region can silently
    /// break one. Checked here in a second, long before `zoo` or `grader calibrate` build it.
    #[test]
    fn the_student_readme_drops_instructor_blocks_and_shows_student_notes() {
        let text =
            "a\n<!-- BEGIN INSTRUCTOR -->\nsecret\n<!-- END INSTRUCTOR -->\n<!-- STUDENT\nhello\n-->\nb\n";
        assert_eq!(student_readme(text).unwrap(), "a\nhello\nb\n");
        assert!(student_readme("<!-- BEGIN INSTRUCTOR -->\nopen").is_err());
        let readme = std::fs::read_to_string(repository().join("README.md")).unwrap();
        let student = student_readme(&readme).unwrap();
        assert!(!student.contains("reference solution") && !student.contains("cargo xtask"), "{student}");
        assert!(student.contains("Your tasks are the `todo!("));
    }

    #[test]
    fn every_catalogue_patch_applies_to_the_current_solution() {
        let variants = VariantFile::load(&repository().join("checkpoints/variants.toml")).unwrap().variants;
        check_patches(repository(), &variants).unwrap_or_else(|e| panic!("{e}"));
    }
}
