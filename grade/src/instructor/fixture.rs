//! Hostile submissions as fixtures (`grade/tests/hostile/NAME/`): `fixture.toml` says how to
//! turn a copy of the reference solution into the submission (region bodies replaced, files
//! written, deleted, copied, replaced by symbolic links, given raw bytes or `\r\n` line
//! endings, markers stripped), `expected.toml` what grading it must give
//! (exact points per checkpoint, substrings of the report, where `{FILE:FUNCTION+N}` stands for
//! the line N below that region's `BEGIN SOLUTION` marker, so a solution's header can grow). Used by the hostile suite
//! (`grade/tests/grader_hostile.rs`) and the Gradescope dry run (`cargo xtask
//! gradescope-dry-run`), which must agree on every fixture.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::file_error::{read_toml, FileError};
use crate::instructor::error::{FixtureProblem, InstructorError};
use crate::regions::lexer::line_at;
use crate::regions::markers::find_regions;
use crate::regions::stub::rust_files;
use crate::submission::scratch::{copy_tree, NOT_COPIED};
use crate::submission::splice::HIDDEN_DIRS;

/// Where the fixtures live, relative to the repository.
pub const HOSTILE: &str = "grade/tests/hostile";

/// How to make the submission from a copy of the solution.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Fixture {
    #[serde(default)]
    region: Vec<RegionEdit>,
    #[serde(default)]
    write: Vec<WriteEdit>,
    #[serde(default)]
    delete: Vec<PathEdit>,
    #[serde(default)]
    copy: Vec<CopyEdit>,
    #[serde(default)]
    symlink: Vec<SymlinkEdit>,
    #[serde(default)]
    append: Vec<AppendEdit>,
    #[serde(default)]
    crlf: Vec<PathEdit>,
    #[serde(default)]
    strip_markers: bool,
}

/// `path` replaced by a symbolic link to `target`, in which `{solution}` stands for the
/// repository the fixture is made from (the instructor's tree).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SymlinkEdit {
    path: PathBuf,
    target: String,
}

/// Raw bytes appended to a file (for text that is not UTF-8).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AppendEdit {
    path: PathBuf,
    bytes: Vec<u8>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RegionEdit {
    file: PathBuf,
    function: String,
    body: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WriteEdit {
    path: PathBuf,
    text: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathEdit {
    path: PathBuf,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CopyEdit {
    from: PathBuf,
    to: PathBuf,
}

/// What grading the submission must give.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expected {
    /// Substrings the report must contain.
    pub output: Vec<String>,
    /// Points per checkpoint, each judged on its own.
    pub points: BTreeMap<u32, f64>,
}

/// Written in a fixture's region body, replaced by [`unchecked_token`]: a test build of the grader
/// takes that region without the allow list ([`crate::submission::splice::UNCHECKED_ENV`]), to show what the
/// sandbox stops when the checker has a hole.
pub const UNCHECKED: &str = "{UNCHECKED}";

/// This process's unchecked token: fresh in every run, so no submission can hold it in advance.
pub fn unchecked_token() -> String {
    static TOKEN: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TOKEN
        .get_or_init(|| {
            let clock =
                std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
            format!("unchecked-{:x}-{:x}", std::process::id(), clock.as_nanos())
        })
        .clone()
}

/// The fixtures' names, sorted.
pub fn names(root: &Path) -> Result<Vec<String>, FileError> {
    let dir = root.join(HOSTILE);
    let entries = std::fs::read_dir(&dir).map_err(|e| FileError::unreadable(&dir, &e))?;
    let mut names: Vec<String> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    Ok(names)
}

/// Writes fixture `name` of the tree at `root` into `dest` (replaced): a copy of the solution
/// with the fixture's edits. Returns what grading it must give.
pub fn make(root: &Path, name: &str, dest: &Path) -> Result<Expected, InstructorError> {
    let folder = root.join(HOSTILE).join(name);
    let fixture: Fixture = read_toml(&folder.join("fixture.toml"))?;
    let expected: Expected = read_toml(&folder.join("expected.toml"))?;
    if dest.exists() {
        std::fs::remove_dir_all(dest).map_err(|e| FileError::unwritable(dest, &e))?;
    }
    // A student's tree, like the starter, has none of the instructor's hidden files.
    let skip: Vec<&str> = NOT_COPIED.into_iter().chain(HIDDEN_DIRS).collect();
    copy_tree(root, dest, &skip).map_err(|e| FileError::unwritable(dest, &e))?;
    let made = apply(&fixture, dest, root)
        .and_then(|()| expected.output.iter().map(|o| with_lines(o, dest)).collect::<Result<_, _>>());
    let output = made.map_err(|problem| InstructorError::Fixture { name: name.to_string(), problem })?;
    Ok(Expected { output, ..expected })
}

/// `text` with each `{FILE:FUNCTION+N}` replaced by the line number, in the submission at
/// `dir`, N lines below the `BEGIN SOLUTION` marker of FUNCTION's region in FILE: a line of the
/// fixture's own body, which a header edit of the solution does not move.
fn with_lines(text: &str, dir: &Path) -> Result<String, FixtureProblem> {
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        let unclosed = || FixtureProblem::BadPlace(rest[open + 1..].to_string());
        let close = rest[open..].find('}').ok_or_else(unclosed)? + open;
        let place = &rest[open + 1..close];
        let line =
            region_marker_line(dir, place).ok_or_else(|| FixtureProblem::BadPlace(place.to_string()))?;
        out += &rest[..open];
        out += &line.to_string();
        rest = &rest[close + 1..];
    }
    Ok(out + rest)
}

/// The line `N` below the `BEGIN SOLUTION` marker of FUNCTION's region in FILE, for `place`
/// written `FILE:FUNCTION+N`; `None` if it is not so written or there is no such region.
fn region_marker_line(dir: &Path, place: &str) -> Option<usize> {
    let (file, at) = place.split_once(':')?;
    let (function, below) = at.split_once('+')?;
    let below: usize = below.parse().ok()?;
    let source = std::fs::read_to_string(dir.join(file)).ok()?;
    let region = find_regions(&source).ok()?.into_iter().find(|f| f.function == function)?;
    Some(line_at(&source, region.body.start) - 1 + below)
}

/// A file error of a fixture's edit.
fn io(path: &Path, e: std::io::Error) -> FixtureProblem {
    FixtureProblem::File(FileError::unwritable(path, &e))
}

/// Applies `fixture`'s edits to the copy of the solution at `dir`: region bodies, then files, then
/// (if asked) the markers stripped.
fn apply(fixture: &Fixture, dir: &Path, solution: &Path) -> Result<(), FixtureProblem> {
    replace_regions(fixture, dir)?;
    edit_files(fixture, dir, solution)?;
    if fixture.strip_markers {
        strip_markers(dir)?;
    }
    Ok(())
}

/// Each `[[region]]` edit: the body of a function's region replaced.
fn replace_regions(fixture: &Fixture, dir: &Path) -> Result<(), FixtureProblem> {
    for edit in &fixture.region {
        let path = dir.join(&edit.file);
        let text = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
        let range = find_regions(&text)
            .unwrap_or_default()
            .into_iter()
            .find(|f| f.function == edit.function)
            .map(|f| f.body)
            .ok_or_else(|| FixtureProblem::NoRegion {
                file: edit.file.clone(),
                function: edit.function.clone(),
            })?;
        let mut out = text.clone();
        out.replace_range(range, &edit.body.trim_start_matches('\n').replace(UNCHECKED, &unchecked_token()));
        std::fs::write(&path, out).map_err(|e| io(&path, e))?;
    }
    Ok(())
}

/// The edits of whole files: written, deleted, copied, given CRLF line ends, appended to, made
/// symbolic links (`{solution}` in a link's target is the solution's absolute path).
fn edit_files(fixture: &Fixture, dir: &Path, solution: &Path) -> Result<(), FixtureProblem> {
    for edit in &fixture.write {
        let path = dir.join(&edit.path);
        std::fs::write(&path, &edit.text).map_err(|e| io(&path, e))?;
    }
    for edit in &fixture.delete {
        let path = dir.join(&edit.path);
        std::fs::remove_file(&path).map_err(|e| io(&path, e))?;
    }
    for edit in &fixture.copy {
        let (from, to) = (dir.join(&edit.from), dir.join(&edit.to));
        std::fs::copy(&from, &to).map_err(|e| io(&from, e))?;
    }
    for edit in &fixture.crlf {
        let path = dir.join(&edit.path);
        let text = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
        std::fs::write(&path, text.replace('\n', "\r\n")).map_err(|e| io(&path, e))?;
    }
    for edit in &fixture.append {
        let path = dir.join(&edit.path);
        let mut bytes = std::fs::read(&path).map_err(|e| io(&path, e))?;
        bytes.extend(&edit.bytes);
        std::fs::write(&path, bytes).map_err(|e| io(&path, e))?;
    }
    for edit in &fixture.symlink {
        let path = dir.join(&edit.path);
        let solution = std::path::absolute(solution).map_err(|e| io(solution, e))?;
        let target = edit.target.replace("{solution}", &solution.to_string_lossy());
        let _ = std::fs::remove_file(&path);
        std::os::unix::fs::symlink(&target, &path).map_err(|e| io(&path, e))?;
    }
    Ok(())
}

/// Every line with a solution marker removed from the Rust files under `dir/src`.
fn strip_markers(dir: &Path) -> Result<(), FixtureProblem> {
    for (path, text) in rust_files(&dir.join("src")).map_err(|e| io(dir, e))? {
        let kept: String = text
            .split_inclusive('\n')
            .filter(|l| !l.contains("// BEGIN SOLUTION") && !l.trim_start().starts_with("// END SOLUTION"))
            .collect();
        std::fs::write(&path, kept).map_err(|e| io(&path, e))?;
    }
    Ok(())
}

/// The points per checkpoint of a Gradescope `results.json` (its tests are numbered `N.k`).
pub fn points(results: &serde_json::Value) -> BTreeMap<u32, f64> {
    let mut points: BTreeMap<u32, f64> = BTreeMap::new();
    for test in results["tests"].as_array().into_iter().flatten() {
        let number = test["number"].as_str().unwrap_or_default();
        if let Some(checkpoint) = number.split('.').next().and_then(|n| n.parse().ok()) {
            *points.entry(checkpoint).or_default() += test["score"].as_f64().unwrap_or(0.0);
        }
    }
    points
}

impl Expected {
    /// What `results` (Gradescope's `results.json`) gets wrong, one line each: points per
    /// checkpoint to 0.01 (they are rounded so), and the report's substrings.
    pub fn problems(&self, results: &serde_json::Value) -> Vec<String> {
        let points = points(results);
        let output = results["output"].as_str().unwrap_or_default();
        let mut problems = Vec::new();
        if self.points.len() != points.len() {
            problems.push(format!(
                "expected.toml must give every checkpoint's points; the grader gave {points:?}"
            ));
        }
        for (checkpoint, want) in &self.points {
            let got = points.get(checkpoint).copied().unwrap_or(0.0);
            if (got - want).abs() > 0.011 {
                problems.push(format!("checkpoint {checkpoint}: {got} points, expected {want}"));
            }
        }
        problems
            .extend(self.output.iter().filter(|s| !output.contains(s.as_str())).map(|s| format!("no {s:?}")));
        problems
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `{FILE:FUNCTION+N}` counts from that region's marker, in the submission's own file.
    #[test]
    fn expected_lines_follow_the_region_they_name() {
        let dir = std::env::temp_dir().join(format!("raylab-fixture-lines-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("src")).unwrap();
        let text = concat!(
            "//! a header\n//! of three\n//! lines\nfn a() {\n    // BEGIN",
            " SOLUTION checkpoint2\n    1\n    // END SOLUTION\n}\n"
        );
        std::fs::write(dir.join("src/a.rs"), text).unwrap();
        let expanded = with_lines("src/a.rs:{src/a.rs:a+1}: rejected", &dir);
        let unknown = with_lines("{src/a.rs:b+1}", &dir);
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(expanded.unwrap(), "src/a.rs:6: rejected");
        assert!(matches!(unknown, Err(FixtureProblem::BadPlace(p)) if p == "src/a.rs:b+1"));
    }
}
