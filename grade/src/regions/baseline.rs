//! What a submission is compared with: the instructor's tree, or, in a student's own tree, the
//! starter's manifest.
//!
//! The instructor's grader takes a submission's regions and ignores every other change; to list
//! those changes it compares each file with the instructor's, every region body blanked.
//! A student's tree has no instructor's tree beside it, so `cargo xtask starter` writes
//! [`STARTER_MANIFEST`]: every starter file's fingerprint (the same comparison, as a 64-bit FNV-1a
//! hash) and every region (file, checkpoint, function). `grader submission .` in a student's tree
//! lists what the instructor's grader would take and ignore from it. A hash is enough there: the
//! manifest serves the student's own feedback, never a grade, and the instructor's tree never has one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::file_error::{FileError, Problem};
use crate::plain::{kind, quote, read_plain, walk, FileKind, MAX_FILE_BYTES};
use crate::reference::fnv1a_hex;
use crate::regions::lexer::line_at;
use crate::regions::markers::{find_regions, Region};
use crate::regions::stub::rust_files;

/// The starter's manifest, relative to the starter (never in the instructor's tree).
pub const STARTER_MANIFEST: &str = "grade/starter-manifest.json";

/// Never compared: build output, version control, the README, cargo's files, the manifest.
const NOT_COMPARED: [&str; 6] = [".git", "target", "README.md", "Cargo.lock", ".cargo", STARTER_MANIFEST];

/// The folders where a file deleted from a submission is listed (the instructor's is used).
const KEPT_FOLDERS: [&str; 3] = ["src", "tests", "scenes"];

/// The folders of the instructor's tree that students never see: nothing of them is named in a
/// report, and a submission's files there are never compared with them.
pub const HIDDEN_DIRS: [&str; 2] = ["hidden", "tests/hidden"];

/// The starter's files and regions, as `cargo xtask starter` wrote them.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
pub struct StarterManifest {
    /// Each file (relative, `/`-separated) with its fingerprint (`fingerprint`).
    pub files: BTreeMap<String, String>,
    /// Each solution region: file, checkpoint, function.
    pub regions: Vec<(String, u32, String)>,
}

/// What a submission is compared with.
pub enum Baseline<'a> {
    /// The instructor's tree.
    Tree(&'a Path),
    /// The starter's manifest (a student's own tree).
    Starter(&'a StarterManifest),
}

impl Baseline<'_> {
    /// Every solution region.
    pub fn regions(&self) -> Result<Vec<Region>, FileError> {
        match self {
            Baseline::Tree(tree) => regions_of(tree),
            Baseline::Starter(manifest) => Ok(manifest
                .regions
                .iter()
                .map(|(file, checkpoint, function)| Region {
                    file: PathBuf::from(file),
                    checkpoint: *checkpoint,
                    function: function.clone(),
                })
                .collect()),
        }
    }

    /// The fingerprint of its `path`, if it has that file.
    fn fingerprint(&self, path: &Path) -> Option<String> {
        match self {
            Baseline::Tree(tree) => std::fs::read(tree.join(path)).ok().map(|b| fingerprint(path, &b)),
            Baseline::Starter(manifest) => manifest.files.get(&slashed(path)).cloned(),
        }
    }

    /// Its files in the folders where a deletion is listed, hidden ones left out.
    fn kept_files(&self) -> Result<Vec<PathBuf>, FileError> {
        let kept = |p: &Path| KEPT_FOLDERS.iter().any(|f| p.starts_with(f)) && !is_hidden(p);
        match self {
            Baseline::Tree(tree) => {
                let listing = walk(tree, &NOT_COMPARED).map_err(|e| FileError::unreadable(tree, &e))?;
                Ok(listing
                    .into_iter()
                    .filter(|(p, k)| *k == FileKind::File && kept(p))
                    .map(|(p, _)| p)
                    .collect())
            }
            Baseline::Starter(manifest) => {
                Ok(manifest.files.keys().map(PathBuf::from).filter(|p| kept(p)).collect())
            }
        }
    }
}

/// The regions of every Rust file below `tree/src`: file (relative), checkpoint, function.
pub fn regions_of(tree: &Path) -> Result<Vec<Region>, FileError> {
    let src = tree.join("src");
    let files = rust_files(&src).map_err(|e| FileError::unreadable(&src, &e))?;
    let mut regions = Vec::new();
    for (path, text) in files {
        let file = path.strip_prefix(tree).unwrap_or(&path).to_path_buf();
        let found = find_regions(&text).map_err(|e| {
            FileError::new(
                &file,
                Problem::Syntax { line: Some(line_at(&text, e.byte)), message: e.to_string() },
            )
        })?;
        regions.extend(found.into_iter().map(|f| Region {
            file: file.clone(),
            checkpoint: f.checkpoint,
            function: f.function,
        }));
    }
    Ok(regions)
}

/// Writes the manifest of the starter at `starter`.
pub fn write_starter_manifest(starter: &Path) -> Result<(), FileError> {
    let listing = walk(starter, &NOT_COMPARED).map_err(|e| FileError::unreadable(starter, &e))?;
    let mut manifest = StarterManifest::default();
    for (path, _) in listing.into_iter().filter(|(_, k)| *k == FileKind::File) {
        let bytes = std::fs::read(starter.join(&path)).map_err(|e| FileError::unreadable(&path, &e))?;
        manifest.files.insert(slashed(&path), fingerprint(&path, &bytes));
    }
    manifest.regions =
        regions_of(starter)?.into_iter().map(|r| (slashed(&r.file), r.checkpoint, r.function)).collect();
    let text = serde_json::to_string_pretty(&manifest).expect("a manifest is plain data");
    let path = starter.join(STARTER_MANIFEST);
    std::fs::write(&path, text + "\n").map_err(|e| FileError::unwritable(&path, &e))
}

/// Reads the starter's manifest of the tree at `root`, if it has one (a student's tree).
pub fn starter_manifest(root: &Path) -> Result<Option<StarterManifest>, FileError> {
    let path = root.join(STARTER_MANIFEST);
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).map_err(|e| FileError::unreadable(&path, &e))?;
    serde_json::from_str(&text).map(Some).map_err(|e| FileError::json(&path, &e))
}

/// Files of the submission that differ from the baseline outside the regions, that the baseline
/// does not have, or that it has and the submission deleted (under `src/`, `tests/`, `scenes/`);
/// anything that is not a plain file or folder, and files too large to read. Files where the
/// instructor keeps hidden ones are listed as ignored, never compared, and the instructor's
/// hidden files are never named.
pub fn ignored_files(baseline: &Baseline, submission: &Path) -> Result<Vec<String>, FileError> {
    let listing = walk(submission, &NOT_COMPARED).map_err(|e| FileError::unreadable(submission, &e))?;
    let mut ignored = Vec::new();
    for (path, kind) in listing {
        // A file name is the student's text too: one clean line in a report.
        let name = quote(&path.display().to_string());
        let theirs = match kind {
            FileKind::Dir => continue,
            FileKind::Other(what) => Err(format!("{what}, never read")),
            FileKind::File if is_hidden(&path) => Err("not compared".to_string()),
            FileKind::File => read_plain(&submission.join(&path), MAX_FILE_BYTES).map_err(|e| e.to_string()),
        };
        match theirs.map(|bytes| (baseline.fingerprint(&path), fingerprint(&path, &bytes))) {
            Err(why) => ignored.push(format!("{name}: {why}: ignored")),
            Ok((None, _)) => ignored.push(format!("{name}: a new file: ignored")),
            Ok((Some(ours), theirs)) if ours != theirs => {
                ignored.push(format!("{name}: changed outside your regions: ignored"))
            }
            Ok(_) => {}
        }
    }
    for file in baseline.kept_files()? {
        if kind(&submission.join(&file)).is_none() {
            ignored.push(format!("{}: deleted: ignored (the instructor's is used)", file.display()));
        }
    }
    ignored.sort();
    Ok(ignored)
}

/// What of a file is compared: a manifest up to its workspace section (the starter rewrites
/// that), a Rust file with every region body emptied, anything else whole; hashed.
fn fingerprint(path: &Path, bytes: &[u8]) -> String {
    let compared = match path.to_str() {
        Some("Cargo.toml") => package_part(bytes).into_bytes(),
        _ => blank_regions(bytes),
    };
    fnv1a_hex(&compared)
}

/// Whether `path` (relative to a tree) is where the instructor keeps hidden files.
fn is_hidden(path: &Path) -> bool {
    HIDDEN_DIRS.iter().any(|dir| path.starts_with(dir))
}

/// A relative path with `/` between its parts, on every platform.
fn slashed(path: &Path) -> String {
    path.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/")
}

/// A manifest up to its workspace section (and the comments just before it).
fn package_part(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = text.lines().take_while(|l| !l.starts_with("[workspace")).collect();
    let end = lines.iter().rposition(|l| !l.trim().is_empty() && !l.starts_with('#')).map_or(0, |i| i + 1);
    lines[..end].join("\n")
}

/// A file's bytes with every region body emptied (Rust files only). The bodies of all
/// checkpoints are cut from the last to the first, so each range still points into the text.
pub fn blank_regions(bytes: &[u8]) -> Vec<u8> {
    let Ok(text) = std::str::from_utf8(bytes) else { return bytes.to_vec() };
    let mut ranges: Vec<std::ops::Range<usize>> =
        find_regions(text).unwrap_or_default().into_iter().map(|f| f.body).collect();
    ranges.sort_by_key(|r| std::cmp::Reverse(r.start));
    let mut out = text.to_string();
    for range in ranges {
        out.replace_range(range, "");
    }
    out.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grader_blanks_only_region_bodies_when_comparing() {
        let text =
            concat!("fn a() {\n    // BEGIN", " SOLUTION checkpoint2\n    1\n    // END SOLUTION\n}\n");
        let other = text.replace("    1\n", "    2\n    3\n");
        assert_eq!(blank_regions(text.as_bytes()), blank_regions(other.as_bytes()));
        let outside = text.replace("fn a()", "fn b()");
        assert_ne!(blank_regions(text.as_bytes()), blank_regions(outside.as_bytes()));
    }

    /// A long region of a lower checkpoint before one of a higher checkpoint, in one file: both
    /// bodies are cut where they are (cutting the first moved the second's range: a panic).
    #[test]
    fn grader_blanks_regions_of_several_checkpoints_in_one_file() {
        let region = |n: u32, body: &str| {
            format!(
                "fn f{n}() {{\n    // BEGIN{} SOLUTION checkpoint{n}\n{body}    // END SOLUTION\n}}\n",
                ""
            )
        };
        let text = region(2, &"    let x = 1;\n".repeat(50)) + &region(3, "    2\n");
        let blanked = String::from_utf8(blank_regions(text.as_bytes())).unwrap();
        assert_eq!(blanked, region(2, "") + &region(3, ""));
    }
}
