//! The hostile-submission suite (`tests/hostile/README.md`), graded as one class by
//! `grader batch`, from a copy of this repository with canaries in what students must never see.
//!
//! - Every fixture is made from the reference solution and must get exactly the points its
//!   `expected.toml` commits to, with the reasons it names.
//! - The honest submission `blame` is in the class twice (and only so), first and last, with every hostile one
//!   between: both must get its exact points and the same report and grades.csv row, so nothing a
//!   hostile submission does reaches the students graded after it.
//! - The instructor's copy has a unique token in every file under `hidden/` and `tests/hidden/`
//!   (a comment, or a PNG text chunk) and in every solution region body; one more student's
//!   regions (uploaded as a zip) hold another. None may appear in any output: grades.csv, the class page, any other
//!   student's report.txt or results.json, the grader's stdout or stderr.

// The hostile submissions are made by the instructor's fixtures (`instructor::fixture`); the
// starter, which has neither, leaves this file out.
#![cfg(feature = "instructor")]

use std::path::{Path, PathBuf};
use std::process::Command;

use raylab_grade::instructor::fixture;
use raylab_grade::reference::inputs_hash;
use raylab_grade::regions::markers::find_regions;
use raylab_grade::regions::stub::rust_files;
use raylab_grade::submission::scratch::{copy_tree, NOT_COPIED};
use raylab_grade::submission::splice::{HIDDEN_DIRS, UNCHECKED_ENV};

/// Tokens planted in the instructor's hidden files, in the solution's regions, and in another
/// student's regions.
const HIDDEN_CANARY: &str = "CANARY-HIDDEN-7f3a";
const SOLUTION_CANARY: &str = "CANARY-SOLUTION-91c2";
const STUDENT_CANARY: &str = "CANARY-STUDENT-4be8";

/// The honest submission graded first and last.
const HONEST: &str = "blame";
const FIRST: &str = "0-first-blame";
const LAST: &str = "zz-last-blame";
/// The student whose regions hold [`STUDENT_CANARY`].
const CANARY_STUDENT: &str = "m-canary";

fn repository() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// The workspace's target folder (this test runs from `target/debug/deps`): the submissions'
/// builds reuse its compiled dependencies.
fn target_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.ancestors().nth(3).unwrap().to_path_buf()
}

/// CRC-32 (IEEE), as PNG chunks carry it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

/// `png` with a `tEXt` chunk holding `token` after its header chunk: the same image.
fn png_with_text(png: &[u8], token: &str) -> Vec<u8> {
    let header_end = 8 + 4 + 4 + 13 + 4;
    let body = [b"tEXt".as_slice(), b"Comment\0", token.as_bytes()].concat();
    let mut chunk = ((body.len() - 4) as u32).to_be_bytes().to_vec();
    chunk.extend_from_slice(&body);
    chunk.extend_from_slice(&crc32(&body).to_be_bytes());
    [&png[..header_end], &chunk, &png[header_end..]].concat()
}

/// `token` in a comment at the top of every region body of the Rust files below `tree/src`.
fn plant_in_regions(tree: &Path, token: &str) {
    for (path, text) in rust_files(&tree.join("src")).unwrap() {
        let mut starts: Vec<usize> = find_regions(&text).unwrap().iter().map(|f| f.body.start).collect();
        starts.sort_by(|a, b| b.cmp(a));
        let mut out = text.clone();
        for start in &starts {
            out.insert_str(*start, &format!("    // {token}\n"));
        }
        if !starts.is_empty() {
            std::fs::write(&path, out).unwrap();
        }
    }
}

/// [`HIDDEN_CANARY`] in every file below the hidden folders of `tree`, and the hidden
/// references' manifest updated to the scene files' new hashes, so every hidden check still runs.
fn plant_in_hidden(tree: &Path) {
    let mut files = Vec::new();
    let mut folders: Vec<PathBuf> = HIDDEN_DIRS.iter().map(|d| tree.join(d)).collect();
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path)
            } else {
                files.push(path)
            }
        }
    }
    let manifest = tree.join("hidden/reference/manifest.toml");
    let mut hashes = Vec::new();
    for scene in files.iter().filter(|f| f.parent().is_some_and(|p| p.ends_with("hidden/scenes"))) {
        hashes.push(inputs_hash(scene).unwrap());
    }
    for file in &files {
        let bytes = std::fs::read(file).unwrap();
        let planted = match file.extension().and_then(|e| e.to_str()) {
            Some("png") => png_with_text(&bytes, HIDDEN_CANARY),
            Some("rs") => [bytes, format!("\n// {HIDDEN_CANARY}\n").into_bytes()].concat(),
            Some("md") => [bytes, format!("\n{HIDDEN_CANARY}\n").into_bytes()].concat(),
            _ => [bytes, format!("\n# {HIDDEN_CANARY}\n").into_bytes()].concat(),
        };
        std::fs::write(file, planted).unwrap();
    }
    let mut text = std::fs::read_to_string(&manifest).unwrap();
    let scenes = files.iter().filter(|f| f.parent().is_some_and(|p| p.ends_with("hidden/scenes")));
    for (scene, old) in scenes.zip(hashes) {
        text = text.replace(&old, &inputs_hash(scene).unwrap());
    }
    std::fs::write(&manifest, text).unwrap();
}

/// Every place an output of the batch holds `token`, but the student `own`'s folder (their own
/// text may come back to them).
fn leaks(out: &Path, streams: &[(&str, &str)], token: &str, own: Option<&str>) -> Vec<String> {
    // The instructor's similarity page shows students' code and the solution's side by side by
    // design, in a folder of its own that is never given out (the test checks it is there).
    let skip = |path: &Path| {
        path.ends_with(".work")
            || path == out.join("similarity")
            || own.is_some_and(|s| path.ends_with(Path::new("students").join(s)))
    };
    let streams = streams.iter().filter(|(_, text)| text.contains(token)).map(|(name, _)| name.to_string());
    let files =
        files_below(out, &skip).into_iter().filter(|f| holds(f, token)).map(|f| f.display().to_string());
    streams.chain(files).map(|place| format!("{place}: {token}")).collect()
}

/// Every file below `folder`, but in folders `skip` names.
fn files_below(folder: &Path, skip: &dyn Fn(&Path) -> bool) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut folders = vec![folder.to_path_buf()];
    while let Some(dir) = folders.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            match (skip(&path), path.is_dir()) {
                (true, _) => {}
                (false, true) => folders.push(path),
                (false, false) => files.push(path),
            }
        }
    }
    files
}

fn holds(file: &Path, token: &str) -> bool {
    String::from_utf8_lossy(&std::fs::read(file).unwrap()).contains(token)
}

/// How many files below `folder` hold `token`, and how many there are.
fn holding(folder: &Path, token: &str) -> (usize, usize) {
    let files = files_below(folder, &|_| false);
    (files.iter().filter(|f| holds(f, token)).count(), files.len())
}

/// `folder` zipped into `into`, its entries named from `folder`'s parent.
fn zip_folder(folder: &Path, into: &Path) {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::fs::File::create(into).unwrap());
    let options =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let mut folders = vec![folder.to_path_buf()];
    while let Some(dir) = folders.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.strip_prefix(folder.parent().unwrap()).unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                zip.add_directory(name, options).unwrap();
                folders.push(path);
            } else {
                zip.start_file(name, options).unwrap();
                zip.write_all(&std::fs::read(&path).unwrap()).unwrap();
            }
        }
    }
    zip.finish().unwrap();
}

/// `student`'s report.txt without the time grading took, and their grades.csv row without their
/// name.
fn outcome(out: &Path, csv: &str, student: &str) -> (String, String) {
    let report = std::fs::read_to_string(out.join("students").join(student).join("report.txt")).unwrap();
    let untimed = |line: &str| match line.starts_with("total:") {
        true => line.rsplit_once(" in ").map_or(line, |(points, _)| points).to_string(),
        false => line.to_string(),
    };
    let report: String = report.lines().map(|l| untimed(l) + "\n").collect();
    let row = csv.lines().find(|l| l.starts_with(&format!("\"{student}\","))).unwrap_or_default();
    (report, row.split_once(',').map_or(String::new(), |(_, rest)| rest.to_string()))
}

#[test]
fn grader_holds_against_every_hostile_submission_in_one_class() {
    let repo = repository();
    let scratch = std::env::temp_dir().join(format!("raylab-hostile-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&scratch);
    let (instructor, class, out) = (scratch.join("instructor"), scratch.join("class"), scratch.join("out"));
    copy_tree(&repo, &instructor, &NOT_COPIED).unwrap();
    plant_in_hidden(&instructor);
    plant_in_regions(&instructor, SOLUTION_CANARY);
    for folder in HIDDEN_DIRS {
        let (planted, files) = holding(&instructor.join(folder), HIDDEN_CANARY);
        assert_eq!(planted, files, "{folder}");
    }
    let with_regions = rust_files(&repo.join("src")).unwrap();
    let with_regions = with_regions.iter().filter(|(_, t)| !find_regions(t).unwrap().is_empty()).count();
    assert_eq!(holding(&instructor.join("src"), SOLUTION_CANARY).0, with_regions);

    let mut names = fixture::names(&repo).unwrap();
    names.retain(|n| n != HONEST);
    // `RAYLAB_HOSTILE=files,spellings` grades only those fixtures, while writing one.
    if let Ok(only) = std::env::var("RAYLAB_HOSTILE") {
        names.retain(|n| only.split(',').any(|o| o == n));
    }
    let mut expected = Vec::new();
    for name in &names {
        expected.push((name.clone(), fixture::make(&repo, name, &class.join(name)).unwrap()));
    }
    let honest = fixture::make(&repo, HONEST, &class.join(FIRST)).unwrap();
    fixture::make(&repo, HONEST, &class.join(LAST)).unwrap();
    expected.extend([(FIRST.to_string(), honest.clone()), (LAST.to_string(), honest)]);
    // The canary student uploads a zip of their repository's folder, as Gradescope keeps it.
    let canary = scratch.join("upload").join("raylab");
    let skip: Vec<&str> = NOT_COPIED.into_iter().chain(HIDDEN_DIRS).collect();
    copy_tree(&repo, &canary, &skip).unwrap();
    plant_in_regions(&canary, STUDENT_CANARY);
    zip_folder(&canary, &class.join(format!("{CANARY_STUDENT}.zip")));

    let run = Command::new(env!("CARGO_BIN_EXE_grader"))
        .arg("batch")
        .arg(&class)
        .arg("--root")
        .arg(&instructor)
        .arg("--out")
        .arg(&out)
        .env("CARGO_TARGET_DIR", target_dir())
        .env(UNCHECKED_ENV, fixture::unchecked_token())
        .env_remove("RAYLAB_GRADER_CHILD")
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    assert!(run.status.success(), "grader batch exited {:?}: {stderr}", run.status.code());

    let mut failures = Vec::new();
    for (student, want) in &expected {
        let json = std::fs::read_to_string(out.join("students").join(student).join("results.json")).unwrap();
        let results: serde_json::Value = serde_json::from_str(&json).unwrap();
        let problems = want.problems(&results);
        if !problems.is_empty() {
            let report = results["output"].as_str().unwrap_or_default();
            failures.push(format!("{student}: {}\n--- report ---\n{report}", problems.join("; ")));
        }
    }
    let csv = std::fs::read_to_string(out.join("grades.csv")).unwrap();
    let (first, last) = (outcome(&out, &csv, FIRST), outcome(&out, &csv, LAST));
    if first != last {
        failures.push(format!("graded first and last, {HONEST} differs:\n{first:?}\n{last:?}"));
    }
    let streams = [("stdout", stdout.as_ref()), ("stderr", stderr.as_ref())];
    if !out.join("similarity/similarity.html").is_file() {
        failures.push("no similarity page in out/similarity/".to_string());
    }
    failures.extend(leaks(&out, &streams, HIDDEN_CANARY, None));
    failures.extend(leaks(&out, &streams, SOLUTION_CANARY, None));
    failures.extend(leaks(&out, &streams, STUDENT_CANARY, Some(CANARY_STUDENT)));
    let _ = std::fs::remove_dir_all(&scratch);
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
