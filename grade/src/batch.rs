//! `grader batch DIR... --out OUT`: a class graded one submission after another, with one
//! scratch tree and one build folder, so the dependencies compile once.
//!
//! A `DIR` that holds `src/` is one submission; any other `DIR` holds one submission per
//! subfolder (a folder of folders, as Gradescope's and GitHub Classroom's downloads unpack). A
//! `.zip` is unpacked first (into `OUT/.work/unpacked/`), wherever it appears: the download itself,
//! or a student's upload inside it; a submission whose tree is one folder down is found there. Each
//! submission gets `OUT/<name>/results.json` and `report.txt`; the class gets `OUT/grades.csv`
//! (student, points per checkpoint, total, flags) and `OUT/index.html`: a histogram of the points
//! per checkpoint and the failing tests most students share. A submission the grader cannot read
//! costs only its own row.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use raylab::image_io::write_file_atomic;

use crate::child::{run_limited, Limits};
use crate::html::escape;
use crate::submission::{grade_submission, results_json, submission_root, text, SubmissionReport};

/// One student's outcome.
pub struct Row {
    /// The submission's folder name.
    pub student: String,
    /// The graded submission, or why it could not be graded.
    pub graded: Result<SubmissionReport, String>,
}

/// The submissions named by `dirs` (see the module docs), sorted by name; zips are unpacked into
/// `unpacked`.
pub fn submissions(dirs: &[PathBuf], unpacked: &Path) -> Result<Vec<PathBuf>, String> {
    let mut found = Vec::new();
    for dir in dirs {
        let dir = &through_single_folders(&unzipped(dir, unpacked)?);
        if submission_root(dir).join("src").is_dir() {
            found.push(dir.clone());
            continue;
        }
        let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let mut inner: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir() || is_zip(p))
            .map(|p| unzipped(&p, unpacked))
            .collect::<Result<_, _>>()?;
        inner.sort();
        found.extend(inner);
    }
    if found.is_empty() {
        return Err("no submissions found".to_string());
    }
    Ok(found)
}

/// `dir`, or the folder below it where a zip's single top folder leads (`download/class/`).
fn through_single_folders(dir: &Path) -> PathBuf {
    let mut dir = dir.to_path_buf();
    while !dir.join("src").is_dir() {
        let entries: Vec<PathBuf> =
            std::fs::read_dir(&dir).into_iter().flatten().filter_map(|e| e.ok().map(|e| e.path())).collect();
        match entries.as_slice() {
            [only] if only.is_dir() => dir = only.clone(),
            _ => break,
        }
    }
    dir
}

fn is_zip(path: &Path) -> bool {
    path.is_file() && path.extension().is_some_and(|e| e.eq_ignore_ascii_case("zip"))
}

/// A zip unpacked into `unpacked/<its name>` (by `unzip`, in a child with the graded children's
/// limits: a zip bomb fills no disk), or any other path as it is.
fn unzipped(path: &Path, unpacked: &Path) -> Result<PathBuf, String> {
    if !is_zip(path) {
        return Ok(path.to_path_buf());
    }
    let name = path.file_stem().map_or_else(|| "submission".into(), |s| s.to_string_lossy().into_owned());
    let dest = unpacked.join(&name);
    if dest.exists() {
        std::fs::remove_dir_all(&dest).map_err(|e| format!("{}: {e}", dest.display()))?;
    }
    std::fs::create_dir_all(&dest).map_err(|e| format!("{}: {e}", dest.display()))?;
    let mut command = std::process::Command::new("unzip");
    command.args(["-q", "-o"]).arg(path).arg("-d").arg(&dest);
    let run = run_limited(command, UNZIP_TIME_LIMIT, Limits::GRADED)
        .map_err(|e| format!("cannot run unzip for {}: {e}", path.display()))?;
    if !run.success() {
        return Err(format!("{}: cannot unpack: {}", path.display(), run.failure_reason(UNZIP_TIME_LIMIT)));
    }
    Ok(dest)
}

/// Unpacking one zip may take this long.
const UNZIP_TIME_LIMIT: Duration = Duration::from_secs(120);

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

/// Grades every submission in turn, writing each one's reports into `out` as it goes.
pub fn grade_all(
    instructor: &Path,
    dirs: &[PathBuf],
    out: &Path,
    progress: &ProgressBar,
) -> Result<Vec<Row>, String> {
    let work = out.join(".work");
    let submissions = submissions(dirs, &work.join("unpacked"))?;
    progress.set_length(submissions.len() as u64);
    let started = Instant::now();
    let mut rows = Vec::new();
    for (done, dir) in submissions.iter().enumerate() {
        let student =
            dir.file_name().map_or_else(|| dir.display().to_string(), |n| n.to_string_lossy().into_owned());
        progress.set_message(format!("{student}{}", eta(done, submissions.len(), started.elapsed())));
        let graded = grade_submission(instructor, dir, &work, &ProgressBar::hidden());
        let folder = out.join(&student);
        std::fs::create_dir_all(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
        let report = match &graded {
            Ok(g) => text(g),
            Err(e) => format!("could not be graded: {e}\n"),
        };
        write(&folder.join("report.txt"), &report)?;
        let results = serde_json::to_string_pretty(&results_json(&graded)).map_err(|e| e.to_string())?;
        write(&folder.join("results.json"), &results)?;
        rows.push(Row { student, graded });
        progress.inc(1);
    }
    write(&out.join("grades.csv"), &csv(&rows))?;
    write(&out.join("index.html"), &class_page(&rows))?;
    Ok(rows)
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    write_file_atomic(path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
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
                let _ = writeln!(out, "{quoted},{empty},,\"not graded: {}\"", e.replace('"', "'"));
            }
        }
    }
    out
}

/// The class page: per checkpoint a histogram of the points (ten bins of its maximum), and the
/// failing unit tests most students share.
pub fn class_page(rows: &[Row]) -> String {
    let graded: Vec<&SubmissionReport> = rows.iter().filter_map(|r| r.graded.as_ref().ok()).collect();
    let mut h = String::from(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>raylab: the class</title>\
         <style>body{font-family:sans-serif;max-width:60em;margin:auto}svg{display:block;margin:.5em 0 1.5em}\
         td{padding:.1em .6em}</style></head><body>\n",
    );
    let _ = writeln!(h, "<h1>raylab: {} submissions, {} graded</h1>", rows.len(), graded.len());
    let Some(first) = graded.first() else { return h + "</body></html>\n" };
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
    h + "</table>\n</body></html>\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zip(folder: &Path, what: &str, into: &Path) {
        let status = std::process::Command::new("zip")
            .current_dir(folder)
            .args(["-q", "-r"])
            .arg(into)
            .arg(what)
            .status();
        assert!(status.unwrap().success());
    }

    /// Folders, folders of folders, zips of either, and zips inside a folder (a student's upload),
    /// with the tree at the top or one folder down.
    #[test]
    fn grader_finds_one_submission_or_a_folder_of_them_zipped_or_not() {
        let dir = std::env::temp_dir().join(format!("raylab-batch-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let unpacked = dir.join("unpacked");
        for student in ["bob", "alice", "carol/raylab-main"] {
            std::fs::create_dir_all(dir.join("class").join(student).join("src")).unwrap();
        }
        let class = submissions(&[dir.join("class")], &unpacked).unwrap();
        let want = ["alice", "bob", "carol"].map(|s| dir.join("class").join(s));
        assert_eq!(class, want, "one per subfolder, sorted");
        assert_eq!(submission_root(&class[2]), dir.join("class/carol/raylab-main"));
        assert_eq!(submissions(&[dir.join("class/bob")], &unpacked).unwrap(), vec![dir.join("class/bob")]);
        std::fs::create_dir_all(dir.join("empty")).unwrap();
        assert!(submissions(&[dir.join("empty")], &unpacked).is_err());

        // The same class as one zip, and carol's upload as a zip inside the folder.
        zip(&dir, "class", &dir.join("download.zip"));
        let zipped = submissions(&[dir.join("download.zip")], &unpacked).unwrap();
        assert_eq!(
            zipped,
            ["alice", "bob", "carol"].map(|s| unpacked.join("download/class").join(s)).to_vec()
        );
        zip(&dir.join("class/carol"), "raylab-main", &dir.join("class/carol.zip"));
        std::fs::remove_dir_all(dir.join("class/carol")).unwrap();
        let mixed = submissions(&[dir.join("class")], &unpacked).unwrap();
        assert_eq!(mixed[2], unpacked.join("carol"));
        assert!(submission_root(&mixed[2]).join("src").is_dir());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn grader_keeps_a_row_for_a_submission_it_could_not_grade() {
        let rows =
            vec![Row { student: "mallory \"m\"".to_string(), graded: Err("not a folder".to_string()) }];
        let table = csv(&rows);
        assert!(table.lines().nth(1).unwrap().starts_with("\"mallory \"\"m\"\"\","), "{table}");
        assert!(table.contains("not graded: not a folder"));
        assert!(class_page(&rows).contains("1 submissions, 0 graded"));
    }
}
