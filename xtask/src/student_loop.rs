//! `cargo xtask student-loop [--runs 5]`: a student's edit-and-grade loop, timed. A benchmark,
//! not a test: it prints a table for docs/PERFORMANCE.md and fails only if a command cannot run.
//!
//! In a fresh starter with its own target folder, for each counted checkpoint N with regions, in
//! the rubric's order (2 to 7 in this course), checkpoint N is written (the solution's files
//! holding its regions are copied in; the checkpoints before it already are), the grader
//! warmed up once, and then, `runs` times: one line saved in a region of checkpoint N, and the
//! wall time to the exit of `cargo grader --checkpoint N`; then another line, and the time of
//! `cargo test checkpointN --no-run`, the build a student waits for anyway; then `grader watch
//! --from N` is left running and, `runs` times, a line saved and the time to its first answer
//! taken. Medians are printed. The targets (issue "The student's loop 1"): the grader at most
//! 10 s; watch at most 1 s more than the test build.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use raylab_grade::regions::stub::{region_bodies, rust_files};
use raylab_grade::rubric::Rubric;

use crate::repository;
use crate::starter::starter;

/// Times the loop for the counted checkpoints with regions, `runs` saves each.
pub fn student_loop(runs: usize) -> Result<(), String> {
    let work = std::env::temp_dir().join("raylab-student-loop");
    if work.exists() {
        std::fs::remove_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    }
    let (tree, target) = (work.join("starter"), work.join("target"));
    starter(&tree)?;
    println!(
        "| N | save to `cargo grader --checkpoint N` exit | save to `cargo test checkpointN --no-run` | save to watch's first answer |"
    );
    println!("|---|---|---|---|");
    let rubric = Rubric::of_tree(repository()).map_err(|e| e.to_string())?;
    let mut saves = 0;
    for n in rubric.checkpoints.iter().filter(|c| !c.extra).map(|c| c.id) {
        let files = region_files(n)?;
        if files.is_empty() {
            continue; // the environment: nothing to write
        }
        for file in &files {
            std::fs::copy(repository().join(file), tree.join(file))
                .map_err(|e| format!("{}: {e}", file.display()))?;
        }
        let grader = ["grader".to_string(), "--checkpoint".to_string(), n.to_string()];
        let build = ["test".to_string(), format!("checkpoint{n}"), "--no-run".to_string()];
        timed(&tree, &target, &grader)?;
        let (mut grading, mut building) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            for (args, times) in [(&grader, &mut grading), (&build, &mut building)] {
                saves += 1;
                save(&tree.join(&files[0]), n, saves)?;
                times.push(timed(&tree, &target, args)?);
            }
        }
        let mut watching = watch_answers(&tree, &target, &files[0], n, runs, &mut saves)?;
        println!(
            "| {n} | {:.1} s | {:.1} s | {:.1} s |",
            median(&mut grading),
            median(&mut building),
            median(&mut watching)
        );
    }
    let _ = std::fs::remove_dir_all(&work);
    Ok(())
}

/// The solution's files (relative to the repository) that hold checkpoint `n`'s regions.
fn region_files(n: u32) -> Result<Vec<PathBuf>, String> {
    let root = repository();
    let files = rust_files(&root.join("src")).map_err(|e| format!("src: {e}"))?;
    let held: Vec<PathBuf> = files
        .into_iter()
        .filter(|(_, text)| !region_bodies(text, n).is_empty())
        .filter_map(|(path, _)| path.strip_prefix(root).ok().map(Path::to_path_buf))
        .collect();
    Ok(held)
}

/// One line saved at the top of the first region of checkpoint `n` in `file`: a student's edit.
fn save(file: &Path, n: u32, count: usize) -> Result<(), String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let start = region_bodies(&text, n).first().map(|r| r.start).ok_or("the region is gone")?;
    let mut edited = text;
    edited.insert_str(start, &format!("    // save {count}\n"));
    std::fs::write(file, edited).map_err(|e| format!("{}: {e}", file.display()))
}

/// The wall time of `cargo ARGS` in `tree`; an error only if cargo cannot run or prints nothing
/// a student would read as a result.
fn timed(tree: &Path, target: &Path, args: &[String]) -> Result<f64, String> {
    let start = Instant::now();
    let out = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .current_dir(tree)
        .env("CARGO_TARGET_DIR", target)
        .env("CARGO_TERM_COLOR", "never")
        .args(args)
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    let seconds = start.elapsed().as_secs_f64();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    if !stdout.contains("total:") && !stderr.contains("Finished") {
        return Err(format!("cargo {}: {}", args.join(" "), stderr.lines().last().unwrap_or("no output")));
    }
    Ok(seconds)
}

/// `grader watch --from N` left running (checkpoint N passes, N + 1 is a stub and fails): for
/// each of `runs` saves in `file`, the time to its first answer, the line that follows the
/// round's "checking" line.
fn watch_answers(
    tree: &Path,
    target: &Path,
    file: &Path,
    n: u32,
    runs: usize,
    saves: &mut usize,
) -> Result<Vec<f64>, String> {
    let mut child = Command::new(target.join("release/grader"))
        .current_dir(tree)
        .env("CARGO_TARGET_DIR", target)
        .args(["watch", "--from", &n.to_string()])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("cannot run the grader: {e}"))?;
    let (lines, received) = mpsc::channel();
    let stdout = child.stdout.take().ok_or("no stdout")?;
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let _ = lines.send(line);
        }
    });
    let wait_for = |pattern: &str| loop {
        match received.recv_timeout(Duration::from_secs(600)) {
            Ok(line) if line.contains(pattern) => return Ok(Instant::now()),
            Ok(_) => {}
            Err(_) => return Err(format!("grader watch: no `{pattern}` line")),
        }
    };
    let result = (|| {
        wait_for("waiting for a save")?;
        let mut times = Vec::new();
        for _ in 0..runs {
            *saves += 1;
            save(&tree.join(file), n, *saves)?;
            let start = Instant::now();
            wait_for("checking checkpoint")?;
            times.push(wait_for("checkpoint ")?.duration_since(start).as_secs_f64());
            wait_for("waiting for a save")?;
        }
        Ok(times)
    })();
    let _ = child.kill();
    let _ = child.wait();
    result
}

fn median(times: &mut [f64]) -> f64 {
    times.sort_by(f64::total_cmp);
    times.get(times.len() / 2).copied().unwrap_or(f64::NAN)
}
