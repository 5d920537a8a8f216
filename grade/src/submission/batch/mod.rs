//! `grader batch DIR... --out OUT`: a class graded one submission after another, with one
//! scratch tree and one build folder, so the dependencies compile once.
//!
//! A `DIR` whose tree is at its top (it holds `src/`), or down a chain of single folders, is one
//! submission; any other `DIR` holds one submission per entry, a folder or a `.zip` (a folder of
//! folders, as Gradescope's and GitHub Classroom's downloads unpack), and is never taken for one
//! student's tree. A `.zip` is unpacked first by [`crate::submission::unpack`] (into `OUT/.work/unpacked/`,
//! removed once graded), wherever it appears: the download itself, or a student's upload inside
//! it; a submission whose tree is one folder down is found there. Each submission gets
//! `OUT/students/<name>/results.json` and `report.txt`; the class gets `OUT/grades.csv` (student,
//! points per checkpoint, total, flags) and `OUT/index.html`: a histogram of the points per
//! checkpoint and the failing tests most students share. These names are the grader's: no
//! student's folder can be called so.
//!
//! **A batch never dies of one student.** A zip that cannot be unpacked, a tree that cannot be
//! read, a grader error or even a panic while grading one submission costs that submission's row,
//! with the reason; grades.csv and the class page are always written.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use raylab_base::image_io::write_file_atomic;

use crate::file_error::FileError;
use crate::grading::checked_rubric;
use crate::plain::{is_plain_dir, kind, FileKind};
use crate::report::html::escape;
use crate::submission::unpack::unpack_zip;
use crate::submission::{grade_submission, results_json, text, SubmissionError, SubmissionReport};

/// One student's outcome.
pub struct Row {
    /// The submission's folder (or zip) name.
    pub student: String,
    /// The graded submission, or why it could not be graded.
    pub graded: Result<SubmissionReport, SubmissionError>,
}

/// One submission found in the class: its name, and its folder or why there is none.
#[derive(Debug)]
pub struct Entry {
    /// The student, by the folder or zip's name.
    pub student: String,
    /// The folder to grade, or why it cannot be read (a zip that does not unpack).
    pub dir: Result<PathBuf, SubmissionError>,
    /// Whether `dir` was unpacked by the grader (and is removed once graded).
    pub unpacked: bool,
}

/// The submissions named by `dirs` (see the module docs), each class sorted by name; zips are
/// unpacked into `unpacked`. `Err` only when none is found.
pub fn submissions(dirs: &[PathBuf], unpacked: &Path) -> Result<Vec<Entry>, SubmissionError> {
    let mut names = BTreeSet::new();
    let mut found = Vec::new();
    for (i, dir) in dirs.iter().enumerate() {
        let top = entry(dir, &unpacked.join(format!("download-{i}")), unique_name(dir, &mut names));
        let Ok(folder) = &top.dir else {
            found.push(top);
            continue;
        };
        let folder = through_single_folders(folder);
        if is_plain_dir(&folder.join("src")) {
            found.push(Entry { dir: Ok(folder), ..top });
            continue;
        }
        names.remove(&top.student);
        let listing = std::fs::read_dir(&folder).map_err(|e| FileError::unreadable(&folder, &e))?;
        let mut inner: Vec<PathBuf> = listing
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| is_plain_dir(p) || is_zip(p))
            .collect();
        inner.sort();
        let students = unpacked.join("students");
        found.extend(inner.iter().map(|p| {
            let student = unique_name(p, &mut names);
            entry(p, &students.join(&student), student)
        }));
    }
    if found.is_empty() {
        return Err(SubmissionError::NoSubmissions);
    }
    Ok(found)
}

/// A folder or a zip (unpacked into `dest`) as `student`'s submission.
fn entry(path: &Path, dest: &Path, student: String) -> Entry {
    if !is_zip(path) {
        return Entry { student, dir: Ok(path.to_path_buf()), unpacked: false };
    }
    let _ = std::fs::remove_dir_all(dest);
    let parent = dest.parent().unwrap_or(dest);
    let made = std::fs::create_dir_all(parent).map_err(|e| FileError::unwritable(parent, &e).into());
    let dir = made.and_then(|()| Ok(unpack_zip(path, dest)?)).map(|()| dest.to_path_buf());
    Entry { student, dir, unpacked: true }
}

/// The student's name for `path`: its file name without `.zip`, with characters other than
/// letters, digits, `-`, `_`, `.` and `@` replaced by `_`, never starting with a dot (no `..`, no
/// hidden folder), and `-2`, `-3`... added when two submissions would share a folder.
fn unique_name(path: &Path, names: &mut BTreeSet<String>) -> String {
    let file = path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let stem = if is_zip(path) { &file[..file.len() - 4] } else { file.as_str() };
    let safe: String =
        stem.chars().map(|c| if c.is_alphanumeric() || "-_.@".contains(c) { c } else { '_' }).collect();
    let base = match safe.trim_start_matches('.') {
        "" => "submission".to_string(),
        trimmed if trimmed.len() == safe.len() => safe,
        _ => format!("_{safe}"),
    };
    let name =
        (1..).map(|n| if n == 1 { base.clone() } else { format!("{base}-{n}") }).find(|n| !names.contains(n));
    let name = name.unwrap_or(base);
    names.insert(name.clone());
    name
}

/// `dir`, or the folder below it where a chain of single folders leads (`download/class/`).
fn through_single_folders(dir: &Path) -> PathBuf {
    let mut dir = dir.to_path_buf();
    while !is_plain_dir(&dir.join("src")) {
        let entries: Vec<PathBuf> =
            std::fs::read_dir(&dir).into_iter().flatten().filter_map(|e| e.ok().map(|e| e.path())).collect();
        match entries.as_slice() {
            [only] if is_plain_dir(only) => dir = only.clone(),
            _ => break,
        }
    }
    dir
}

fn is_zip(path: &Path) -> bool {
    kind(path) == Some(FileKind::File) && path.extension().is_some_and(|e| e.eq_ignore_ascii_case("zip"))
}

/// "about 3 min left" after `done` of `total` submissions in `elapsed`.
fn eta(done: usize, total: usize, elapsed: Duration) -> String {
    if done == 0 {
        return String::new();
    }
    let left = elapsed.as_secs_f64() / done as f64 * (total - done) as f64;
    match left {
        s if s < 90.0 => format!(", about {s:.0} s left"),
        s => format!(", about {:.0} min left", s / 60.0),
    }
}

/// The folder of the class page, grades.csv and the students' folders.
pub const STUDENTS: &str = "students";

/// Grades every submission in turn, writing each one's reports into `out/students/` as it goes;
/// grades.csv and the class page are written whatever one submission does.
pub fn grade_all(
    instructor: &Path,
    dirs: &[PathBuf],
    out: &Path,
    progress: &ProgressBar,
) -> Result<Vec<Row>, SubmissionError> {
    // The instructor's inputs first: a broken rubric or reference stops the class at once, not
    // as every student's "not graded".
    checked_rubric(instructor)?;
    let work = out.join(".work");
    let unpacked = work.join("unpacked");
    let submissions = submissions(dirs, &unpacked)?;
    let total = submissions.len();
    progress.set_length(total as u64);
    let started = Instant::now();
    let mut rows = Vec::new();
    for (done, entry) in submissions.into_iter().enumerate() {
        let student = entry.student;
        progress.set_message(format!("{student}{}", eta(done, total, started.elapsed())));
        let graded = entry.dir.and_then(|dir| {
            let graded = grade_one(instructor, &dir, &work);
            if entry.unpacked {
                let _ = std::fs::remove_dir_all(&dir);
            }
            graded
        });
        let written = write_reports(&out.join(STUDENTS).join(&student), &graded);
        let graded = written.map_err(SubmissionError::from).and(graded);
        rows.push(Row { student, graded });
        progress.inc(1);
    }
    let _ = std::fs::remove_dir_all(&unpacked);
    write(&out.join("grades.csv"), &csv(&rows))?;
    write(&out.join("index.html"), &class_page(&rows, ""))?;
    Ok(rows)
}

/// One submission graded; a panic of the grader's own is that submission's error only.
fn grade_one(instructor: &Path, dir: &Path, work: &Path) -> Result<SubmissionReport, SubmissionError> {
    let grading =
        std::panic::catch_unwind(|| grade_submission(instructor, dir, work, &ProgressBar::hidden()));
    grading.unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned());
        Err(SubmissionError::Panicked(message))
    })
}

/// A student's report.txt and results.json.
fn write_reports(folder: &Path, graded: &Result<SubmissionReport, SubmissionError>) -> Result<(), FileError> {
    std::fs::create_dir_all(folder).map_err(|e| FileError::unwritable(folder, &e))?;
    let report = match graded {
        Ok(g) => text(g),
        Err(e) => format!("could not be graded: {e}\n"),
    };
    write(&folder.join("report.txt"), &report)?;
    let results = serde_json::to_string_pretty(&results_json(graded)).expect("JSON values print");
    write(&folder.join("results.json"), &results)
}

fn write(path: &Path, text: &str) -> Result<(), FileError> {
    write_file_atomic(path, text.as_bytes()).map_err(|e| FileError::unwritable(path, &e))
}

/// `student,1,2,...,total,flags`: each checkpoint judged on its own.
pub fn csv(rows: &[Row]) -> String {
    let ids: Vec<u32> = rows
        .iter()
        .find_map(|r| r.graded.as_ref().ok())
        .map_or(Vec::new(), |g| g.isolated.checkpoints.iter().map(|c| c.checkpoint.id).collect());
    let mut out = format!(
        "student,{},total,flags\n",
        ids.iter().map(|id| format!("checkpoint {id}")).collect::<Vec<_>>().join(",")
    );
    for row in rows {
        let quoted = format!("\"{}\"", row.student.replace('"', "\"\""));
        match &row.graded {
            Ok(g) => {
                let points: Vec<String> =
                    g.isolated.checkpoints.iter().map(|c| format!("{:.2}", c.score())).collect();
                let mut flags = Vec::new();
                if !g.submission.rejected().is_empty() {
                    flags.push(format!("rejected code in {:?}", g.submission.rejected()));
                }
                if !g.submission.notes().is_empty() {
                    flags.push(format!("{} regions not taken", g.submission.notes().len()));
                }
                if !g.submission.ignored.is_empty() {
                    flags.push(format!("{} files ignored", g.submission.ignored.len()));
                }
                let _ = writeln!(
                    out,
                    "{quoted},{},{:.2},\"{}\"",
                    points.join(","),
                    g.isolated.score(),
                    flags.join("; ")
                );
            }
            Err(e) => {
                let empty = vec![""; ids.len()].join(",");
                let _ =
                    writeln!(out, "{quoted},{empty},,\"not graded: {}\"", e.to_string().replace('"', "'"));
            }
        }
    }
    out
}

/// The class page: per checkpoint a histogram of the points (ten bins of its maximum), the
/// failing unit tests most students share, and `more` (HTML: the instructor's similarity section).
pub fn class_page(rows: &[Row], more: &str) -> String {
    let graded: Vec<&SubmissionReport> = rows.iter().filter_map(|r| r.graded.as_ref().ok()).collect();
    let mut h = String::from(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>raylab: the class</title>\
         <style>body{font-family:sans-serif;max-width:60em;margin:auto}svg{display:block;margin:.5em 0 1.5em}\
         td{padding:.1em .6em}</style></head><body>\n",
    );
    let _ = writeln!(h, "<h1>raylab: {} submissions, {} graded</h1>", rows.len(), graded.len());
    let Some(first) = graded.first() else { return h + more + "</body></html>\n" };
    for (i, c) in first.isolated.checkpoints.iter().enumerate() {
        let max = c.max_score(true).max(1e-9);
        let mut bins = [0usize; 10];
        for g in &graded {
            let share = g.isolated.checkpoints[i].score() / max;
            bins[((share * 10.0) as usize).min(9)] += 1;
        }
        let tallest = *bins.iter().max().unwrap_or(&1).max(&1) as f64;
        let _ = writeln!(
            h,
            "<h2>Checkpoint {}: {} (out of {max:.0})</h2>",
            c.checkpoint.id,
            escape(&c.checkpoint.title)
        );
        let _ = write!(h, "<svg width=\"420\" height=\"130\" role=\"img\">");
        for (b, &n) in bins.iter().enumerate() {
            let height = 100.0 * n as f64 / tallest;
            let x = 10 + b * 40;
            let _ = write!(
                h,
                "<rect x=\"{x}\" y=\"{:.1}\" width=\"34\" height=\"{height:.1}\" fill=\"#4a7\"><title>{n} students</title></rect>\
                 <text x=\"{}\" y=\"125\" font-size=\"10\" text-anchor=\"middle\">{}%</text>",
                105.0 - height,
                x + 17,
                b * 10
            );
        }
        h.push_str("</svg>\n");
    }
    let mut failing: BTreeMap<&str, usize> = BTreeMap::new();
    for g in &graded {
        for test in g.isolated.checkpoints.iter().filter_map(|c| c.tests.as_ref()).flat_map(|t| &t.failures) {
            *failing.entry(test.as_str()).or_default() += 1;
        }
    }
    let mut shared: Vec<(&str, usize)> = failing.into_iter().collect();
    shared.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    h.push_str("<h2>Failing tests most students share</h2>\n<table>\n");
    for (test, n) in shared.iter().take(15) {
        let width = 300.0 * *n as f64 / graded.len() as f64;
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{n}</td><td><svg width=\"300\" height=\"12\" style=\"margin:0\"><rect width=\"{width:.0}\" height=\"12\" fill=\"#c55\"/></svg></td></tr>",
            escape(test)
        );
    }
    h + "</table>\n" + more + "</body></html>\n"
}

#[cfg(test)]
mod tests;
