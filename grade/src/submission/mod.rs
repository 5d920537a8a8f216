//! `grader submission DIR`: a submission graded from the instructor's tree, each checkpoint
//! judged on its own.
//!
//! The submission's regions are spliced into a scratch copy of the instructor's tree
//! ([`splice`]), built once, and graded twice over: checkpoint N *on its own* (its regions from
//! the submission, the solution's everywhere else: the grade), and the *whole renderer*
//! (every region from the submission: shown beside it). A bug in checkpoint 2 then costs
//! checkpoint 2's points only; where the two differ, the whole renderer's reason names the
//! checkpoint to blame.

pub mod batch;
mod error;
pub mod scratch;
pub mod splice;
pub mod unpack;

use std::fmt::Write;
use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use crate::file_error::FileError;
use crate::grading::{checked_rubric, grade, GradeOptions};
use crate::outcome::{Blame, CheckpointResult, GradeReport, Phases};
use crate::plain::is_plain_dir;
use crate::regions::allow::StudentApi;
use crate::regions::baseline::{starter_manifest, Baseline, StarterManifest};
use crate::report::gradescope_json;
use crate::report::reasons::{advice_line, reason_lines};
use crate::rubric::Rubric;
use crate::run::build_error::BuildError;
use crate::run::cargo::BUILD_TIME_LIMIT;
use crate::run::unit_tests::build_tests;
use crate::submission::splice::{
    read_submission, write_spliced_tree, NotCompiling, Submission, Taken, STUDENT_ENV,
};
use crate::verdict::Reason;

pub use error::SubmissionError;

/// A graded submission.
#[derive(Clone, Debug)]
pub struct SubmissionReport {
    /// Each checkpoint judged on its own: the grade. Its scenes are the whole renderer's.
    pub isolated: GradeReport,
    /// The whole submission's renderer.
    pub cumulative: GradeReport,
    /// What was taken from the submission and what was ignored.
    pub submission: Submission,
    /// Seconds spent reading the submission and writing the spliced tree.
    pub splice_seconds: f64,
    /// Seconds of every grading run's phases, summed.
    pub phases: Phases,
    /// A student's own tree (it has the starter's manifest, no solution): graded once, as it
    /// stands, `isolated` and `cumulative` the same grade.
    pub own_tree: bool,
}

/// Grades the submission at `dir` with the instructor's tree at `instructor`, building in `work`
/// (its `target/` is reused from one submission to the next). `Err` only for bad input.
pub fn grade_submission(
    instructor: &Path,
    dir: &Path,
    work: &Path,
    progress: &ProgressBar,
) -> Result<SubmissionReport, SubmissionError> {
    if !dir.is_dir() {
        return Err(SubmissionError::NotAFolder(dir.to_path_buf()));
    }
    let dir = &submission_root(dir);
    if let Some(manifest) = starter_manifest(instructor)? {
        return grade_own_tree(instructor, dir, &manifest, progress);
    }
    let rubric = checked_rubric(instructor)?;
    let start = std::time::Instant::now();
    let mut submission = read_submission(&Baseline::Tree(instructor), dir, &StudentApi::of(&rubric))?;
    let tree = work.join("tree");
    let target = build_target(work, std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from));
    write_spliced_tree(instructor, &submission, &tree)?;
    let splice_seconds = start.elapsed().as_secs_f64();
    progress.set_message("compiling the submission");
    let compiling = std::time::Instant::now();
    build_what_compiles(instructor, &mut submission, &tree, &target)?;
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    let base = GradeOptions {
        code: Some(tree),
        target: Some(target),
        not_started: Some(submission.not_started()),
        ..GradeOptions::new(instructor)
    };
    let compiling_seconds = compiling.elapsed().as_secs_f64();
    progress.set_message("the whole renderer");
    let cumulative = grade(&with_students(&base, &ids, None, Blame::Culprit), progress)?;
    let mut phases = cumulative.phases;
    phases.build += compiling_seconds;
    let mut checkpoints = Vec::new();
    for &id in &ids {
        progress.set_message(format!("checkpoint {id} on its own"));
        let report = grade(&with_students(&base, &[id], Some(vec![id]), Blame::Isolated), progress)?;
        phases += report.phases;
        let mut result =
            report.checkpoints.into_iter().next().expect("a grade of one checkpoint has its row");
        // A rejected region's code never runs: the starter's stub stands in its place, so it
        // scores exactly what the stub scores there.
        if submission.rejected().contains(&id) {
            result.reasons.insert(0, Reason::RegionRejected { own_tree: false });
        }
        checkpoints.push(result);
    }
    let isolated = GradeReport {
        scenes: cumulative.scenes.clone(),
        checkpoints,
        tests_ran: true,
        needed: Vec::new(),
        seconds: start.elapsed().as_secs_f64(),
        phases,
    };
    Ok(SubmissionReport { isolated, cumulative, submission, splice_seconds, phases, own_tree: false })
}

/// `base` grading `checkpoints` (all if `None`) with the regions of `students` running the
/// submission's code (the solution's everywhere else), blamed as `blame` says.
fn with_students(
    base: &GradeOptions,
    students: &[u32],
    checkpoints: Option<Vec<u32>>,
    blame: Blame,
) -> GradeOptions {
    let ids: Vec<String> = students.iter().map(u32::to_string).collect();
    GradeOptions { env: vec![(STUDENT_ENV.to_string(), ids.join(","))], checkpoints, blame, ..base.clone() }
}

/// Builds the spliced `tree` until it compiles: a region that does not is replaced by its stub and
/// the tree built again, so that one stray line costs its own region only. An error in a file
/// that is not the student's stubs every region of theirs.
fn build_what_compiles(
    instructor: &Path,
    submission: &mut Submission,
    tree: &Path,
    target: &Path,
) -> Result<(), FileError> {
    while let Err(error) = build_tests(tree, Some(target), BUILD_TIME_LIMIT) {
        let region = error.place().and_then(|(file, line)| submission.code_region_at(tree, file, line));
        if let (Some(taken), BuildError::Compile(compile)) = (region, &error) {
            *taken = Taken::DoesNotCompile(NotCompiling::Here(compile.clone()));
        } else if !submission.stub_every_region(&error.heading()) {
            break; // the starter's stubs do not build either: the instructor's tree is at fault
        }
        write_spliced_tree(instructor, submission, tree)?;
    }
    Ok(())
}

/// `grader submission` in a student's tree, where `root` holds the starter's manifest and no
/// solution: what the instructor's grader would take and ignore, read against the manifest, and
/// one grade of the tree as it stands (in its own build folder, nothing built twice).
fn grade_own_tree(
    root: &Path,
    dir: &Path,
    manifest: &StarterManifest,
    progress: &ProgressBar,
) -> Result<SubmissionReport, SubmissionError> {
    let start = std::time::Instant::now();
    // The student's own rubric: here the allow list is a lint that explains the rules.
    let api = StudentApi::of(&Rubric::of_tree(root)?);
    let submission = read_submission(&Baseline::Starter(manifest), dir, &api)?;
    let splice_seconds = start.elapsed().as_secs_f64();
    let mut report =
        grade(&GradeOptions { code: Some(dir.to_path_buf()), ..GradeOptions::new(root) }, progress)?;
    for c in report.checkpoints.iter_mut().filter(|c| submission.rejected().contains(&c.checkpoint.id)) {
        c.reasons.insert(0, Reason::RegionRejected { own_tree: true });
    }
    let phases = report.phases;
    Ok(SubmissionReport {
        cumulative: report.clone(),
        isolated: report,
        submission,
        splice_seconds,
        phases,
        own_tree: true,
    })
}

/// The folder of a submission that holds its tree: `dir` if it holds `src/`, else the one folder
/// inside it that does (an upload of the repository's folder, as a zip or from GitHub).
pub fn submission_root(dir: &Path) -> PathBuf {
    if is_plain_dir(&dir.join("src")) {
        return dir.to_path_buf();
    }
    let inner: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_plain_dir(p) && is_plain_dir(&p.join("src")))
        .collect();
    match inner.as_slice() {
        [only] => only.clone(),
        _ => dir.to_path_buf(),
    }
}

/// Gradescope's `results.json` for a submission: the grade (each checkpoint on its own) with the
/// whole report as its output; for a submission that could not be graded, 0 and why.
pub fn results_json(graded: &Result<SubmissionReport, SubmissionError>) -> serde_json::Value {
    match graded {
        Ok(g) => {
            let mut results = gradescope_json(&g.isolated);
            results["output"] = serde_json::Value::String(text(g));
            results
        }
        Err(e) => serde_json::json!({"score": 0.0, "output": format!("Not graded: {e}"), "tests": []}),
    }
}

/// The report a person reads: per checkpoint the grade and the whole renderer's points, why
/// points were lost, the regions not taken, the files ignored.
pub fn text(report: &SubmissionReport) -> String {
    if report.own_tree {
        return own_tree_text(report);
    }
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Each checkpoint is judged on its own: its regions from your code, the reference solution everywhere else.\n"
    );
    let _ = writeln!(out, "{:<3} {:<44} {:>10} {:>15}", "#", "checkpoint", "points", "whole renderer");
    for (own, whole) in report.isolated.checkpoints.iter().zip(&report.cumulative.checkpoints) {
        let points = |c: &CheckpointResult| format!("{:.1}/{:.0}", c.score(), c.max_score(true));
        let _ = writeln!(
            out,
            "{:<3} {:<44} {:>10} {:>15}",
            own.checkpoint.id,
            own.checkpoint.title,
            points(own),
            points(whole)
        );
        for reason in reason_lines(own) {
            let _ = writeln!(out, "      - {reason}");
        }
        if let Some(advice) = advice_line(own) {
            let _ = writeln!(out, "      hint: {advice}");
        }
        if (own.score() - whole.score()).abs() > 1e-9 {
            let own_lines = reason_lines(own);
            for reason in reason_lines(whole).into_iter().filter(|r| !own_lines.contains(r)) {
                let _ = writeln!(out, "      whole renderer: {reason}");
            }
        }
    }
    let _ = writeln!(
        out,
        "\ntotal: {:.1} / {:.0} points{} (whole renderer: {:.1}) in {:.1} s (splice {:.1}, build {:.1}, tests {:.1}, renders {:.1})",
        report.isolated.score(),
        report.isolated.max_score(),
        crate::report::extra_text(&report.isolated),
        report.cumulative.score(),
        report.isolated.seconds,
        report.splice_seconds,
        report.phases.build,
        report.phases.tests,
                report.phases.renders
    );
    if let Some(note) = crate::run::sandbox::missing_note() {
        let _ = writeln!(out, "{note}");
    }
    lists(
        &mut out,
        [("Regions not taken", report.submission.notes()), ("Ignored", report.submission.ignored.clone())],
    );
    out
}

/// Where the scratch tree `work/tree` is built: `CARGO_TARGET_DIR` when set (it shares compiled
/// dependencies with other builds), unless the tree lies inside it. Cargo records a tree inside its
/// target folder by paths relative to that folder and names its builds independently of where the
/// tree is, so a later tree elsewhere sharing the folder would be found "fresh" against the old
/// tree's files and graded with the old tree's binaries (seen: every student of a class graded with
/// one earlier submission's code). Such a tree gets `work/target` of its own.
fn build_target(work: &Path, shared: Option<PathBuf>) -> PathBuf {
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let outside = |t: &PathBuf| !absolute(&work.join("tree")).starts_with(absolute(t));
    shared.filter(outside).unwrap_or_else(|| work.join("target"))
}

/// The text of a student's own tree graded once ([`SubmissionReport::own_tree`]).
fn own_tree_text(report: &SubmissionReport) -> String {
    let mut out = String::from(
        "Your own tree, graded once as it stands: there is no reference solution here to judge each\n\
         checkpoint on its own, so a scene also runs your other checkpoints. The instructor's grader\n\
         takes only your regions (listed below), each checkpoint with the solution everywhere else.\n\n",
    );
    out += &crate::report::text(&report.isolated);
    let regions = report.submission.regions.iter().map(|(r, t)| r.line(t));
    let ignored = report.submission.ignored.clone();
    lists(
        &mut out,
        [
            ("Regions the instructor's grader takes", regions.collect()),
            ("Ignored by the instructor's grader", ignored),
        ],
    );
    out
}

/// Titled lists of lines, the empty ones left out.
fn lists<const N: usize>(out: &mut String, lists: [(&str, Vec<String>); N]) {
    for (title, lines) in lists {
        if !lines.is_empty() {
            let _ = writeln!(out, "\n{title}:");
            for line in lines {
                let _ = writeln!(out, "  - {line}");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch tree inside the shared target folder is built in a target of its own.
    #[test]
    fn a_tree_inside_the_shared_target_folder_gets_its_own() {
        let shared = PathBuf::from("/ci/target");
        assert_eq!(build_target(Path::new("/ci/work"), Some(shared.clone())), shared);
        let inside = Path::new("/ci/target/grader-submission");
        assert_eq!(build_target(inside, Some(shared)), inside.join("target"));
        assert_eq!(build_target(Path::new("/w"), None), PathBuf::from("/w/target"));
    }
}
