//! A course that skips a checkpoint, made and graded with no change to the grader or to this
//! crate: `cargo xtask course-without N` copies the tree, gives checkpoint N's solution as code
//! (its markers removed), takes N out of the rubrics (its row, the scenes that grade only N, N in
//! other scenes' `depends_on` and `stand_ins`), then grades the copy's solution (every other
//! checkpoint in full, no row for N) and stubs it as the starter does (N's code stays, every other
//! region is a stub). docs/INSTRUCTORS.md, "Add or change a checkpoint", lists the steps.

use std::path::{Path, PathBuf};
use std::time::Instant;

use raylab_grade::grading::{grade, GradeOptions};
use raylab_grade::instructor::package::tracked_files;
use raylab_grade::instructor::variants::stub_tree;
use raylab_grade::regions::markers::find_regions;
use raylab_grade::regions::stub::{is_stub, rust_files};
use raylab_grade::report::progress::progress_bar;
use raylab_grade::rubric::{Rubric, HIDDEN_RUBRIC, RUBRIC};

use crate::repository;

/// Makes the course without checkpoint `id` in `target/course-without/` and checks it.
pub fn without(id: u32) -> Result<(), String> {
    let started = Instant::now();
    let work = repository().join("target/course-without");
    let tree = work.join("tree");
    copy_tracked(repository(), &tree)?;
    for rubric in [RUBRIC, HIDDEN_RUBRIC] {
        drop_from_rubric(&tree.join(rubric), id)?;
    }
    let given = unmark(&tree.join("src"), id)?;
    if given.is_empty() {
        return Err(format!("no region of checkpoint {id} in src/"));
    }
    println!("course without checkpoint {id}: {} region(s) given as code; grading its solution", given.len());
    let rubric = Rubric::of_tree(&tree).map_err(|e| e.to_string())?;
    let options = GradeOptions { target: Some(work.join("target")), ..GradeOptions::new(&tree) };
    let progress = progress_bar(0);
    let graded = grade(&options, &progress);
    progress.finish_and_clear();
    let report = graded.map_err(|e| e.to_string())?;
    print!("{}", raylab_grade::report::text(&report));
    let graded: Vec<u32> = report.checkpoints.iter().map(|c| c.checkpoint.id).collect();
    let wanted: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    if graded != wanted || graded.contains(&id) || !report.all_passed() {
        return Err(format!(
            "the course without {id} graded {graded:?}, not all in full (wanted {wanted:?})"
        ));
    }
    starter_keeps_only(&tree, &wanted, &given, &work.join("starter-src"))?;
    println!(
        "course without checkpoint {id}: graded in full and stubbed in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The files git tracks in `root`, copied to `to` (replaced).
pub(crate) fn copy_tracked(root: &Path, to: &Path) -> Result<(), String> {
    if to.exists() {
        std::fs::remove_dir_all(to).map_err(|e| format!("{}: {e}", to.display()))?;
    }
    for file in tracked_files(root).map_err(|e| e.to_string())? {
        let dest = to.join(&file);
        std::fs::create_dir_all(dest.parent().unwrap_or(to))
            .map_err(|e| format!("{}: {e}", dest.display()))?;
        std::fs::copy(root.join(&file), &dest).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    Ok(())
}

/// The rubric at `path` without checkpoint `id`: its row, the scenes that grade nothing else, and
/// `id` in every other scene's `grades`, `depends_on` and `stand_ins`.
fn drop_from_rubric(path: &Path, id: u32) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut rubric: toml::Table = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let is_id = |v: &toml::Value| v.as_integer() == Some(i64::from(id));
    if let Some(toml::Value::Array(rows)) = rubric.get_mut("checkpoint") {
        rows.retain(|row| !row.get("id").is_some_and(is_id));
    }
    if let Some(toml::Value::Array(scenes)) = rubric.get_mut("scene") {
        for scene in scenes.iter_mut().filter_map(toml::Value::as_table_mut) {
            for key in ["grades", "depends_on", "stand_ins"] {
                if let Some(toml::Value::Array(ids)) = scene.get_mut(key) {
                    ids.retain(|v| !is_id(v));
                }
            }
        }
        scenes.retain(|s| s.get("grades").and_then(toml::Value::as_array).is_some_and(|g| !g.is_empty()));
    }
    let text = toml::to_string(&rubric).map_err(|e| format!("{}: {e}", path.display()))?;
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Removes the markers of checkpoint `id`'s regions below `src` (their bodies stay, as code the
/// students are given); each region's file, relative to `src`, and body.
fn unmark(src: &Path, id: u32) -> Result<Vec<(PathBuf, String)>, String> {
    let mut given = Vec::new();
    for (path, text) in rust_files(src).map_err(|e| format!("{}: {e}", src.display()))? {
        let regions: Vec<_> =
            find_regions(&text).unwrap_or_default().into_iter().filter(|f| f.checkpoint == id).collect();
        if regions.is_empty() {
            continue;
        }
        let relative = path.strip_prefix(src).unwrap_or(&path).to_path_buf();
        given.extend(regions.iter().map(|r| (relative.clone(), text[r.body.clone()].to_string())));
        let begin = format!("// BEGIN SOLUTION checkpoint{id}");
        let kept: Vec<&str> = text
            .split_inclusive('\n')
            .filter(|l| {
                l.trim() != begin && !(l.trim() == "// END SOLUTION" && ends_a_region(&text, l, &regions))
            })
            .collect();
        std::fs::write(&path, kept.concat()).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(given)
}

/// Whether `line` (a slice of `text`) is the END marker of one of `regions`: it starts where a
/// region's body ends.
fn ends_a_region(text: &str, line: &str, regions: &[raylab_grade::regions::markers::Found]) -> bool {
    let at = line.as_ptr() as usize - text.as_ptr() as usize;
    regions.iter().any(|r| r.body.end == at)
}

/// Stubs a copy of `tree`'s sources for the rubric's checkpoints `ids`, as the starter does, and
/// checks that every region left is a stub and the `given` code (file, body) is still there.
pub(crate) fn starter_keeps_only(
    tree: &Path,
    ids: &[u32],
    given: &[(PathBuf, String)],
    out: &Path,
) -> Result<(), String> {
    copy_dir(&tree.join("src"), out)?;
    stub_tree(out, ids).map_err(|e| format!("{}: {e}", out.display()))?;
    for (path, text) in rust_files(out).map_err(|e| format!("{}: {e}", out.display()))? {
        for region in find_regions(&text).unwrap_or_default() {
            if !is_stub(&text, region.body.clone(), region.checkpoint) {
                return Err(format!(
                    "{}: `{}` is not stubbed in the starter",
                    path.display(),
                    region.function
                ));
            }
        }
    }
    for (file, body) in given {
        let text = std::fs::read_to_string(out.join(file)).map_err(|e| format!("{}: {e}", file.display()))?;
        if !text.contains(body.as_str()) {
            return Err(format!(
                "{}: the given code of the skipped checkpoint is not in the starter",
                file.display()
            ));
        }
    }
    Ok(())
}

/// `from` copied to `to` (replaced).
fn copy_dir(from: &Path, to: &Path) -> Result<(), String> {
    if to.exists() {
        std::fs::remove_dir_all(to).map_err(|e| format!("{}: {e}", to.display()))?;
    }
    raylab_grade::submission::scratch::copy_tree(from, to, &[]).map_err(|e| format!("{}: {e}", to.display()))
}
