//! Variants: the reference solution with one mistake (or one correct alternative) patched into a
//! solution region, built in a scratch copy of the tree. No runtime switch exists in the solution:
//! a variant is a source patch, so what is graded is exactly what a student could have written.
//!
//! `checkpoints/variants.toml` lists them. A patch either replaces text found exactly once inside
//! a `// BEGIN SOLUTION checkpointN` ... `// END SOLUTION` region of its checkpoint, or replaces the
//! whole body of the k-th such region of a file. Calibration (`grader calibrate`) and the mistake
//! catalogue build on this.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::file_error::{read_toml, FileError};
use crate::instructor::error::{InstructorError, PatchProblem, Unpatched};
use crate::regions::stub::{region_bodies, stub_regions};
use crate::submission::scratch::{copy_tree, NOT_COPIED};

/// `checkpoints/variants.toml`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantFile {
    /// The variants.
    #[serde(rename = "variant")]
    pub variants: Vec<Variant>,
}

/// One variant of the solution.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// Short name, unique.
    pub name: String,
    /// The checkpoint whose region it patches.
    pub checkpoint: u32,
    /// Whether it is a correct alternative (must pass everything) or a mistake.
    pub correct: bool,
    /// What it does, in a student's words.
    pub description: String,
    /// For mistakes: the graded scenes that must fail.
    #[serde(default)]
    pub fails: Vec<String>,
    /// Seeds to grade with (correct variants of sampling code are tried with several).
    #[serde(default)]
    pub seeds: Vec<u64>,
    /// Replace every solution region of the checkpoint with `todo!()`, as the starter does.
    #[serde(default)]
    pub stub: bool,
    /// For a mistake written a second way: the catalogue mistake it repeats. Its renders are never
    /// a fingerprint; they measure how well the first one's fingerprints name it
    /// ([`crate::fingerprint`]), so calibration builds it only for that.
    #[serde(default)]
    pub second_of: Option<String>,
    /// The source patches (none: the solution itself).
    #[serde(default, rename = "patch")]
    pub patches: Vec<Patch>,
}

/// One change to one file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(try_from = "PatchFile")]
pub struct Patch {
    /// The file, relative to the tree's root.
    pub file: PathBuf,
    /// What changes in it.
    pub change: Change,
}

/// What a patch changes in a file's regions of the variant's checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub enum Change {
    /// Text found exactly once inside one of the regions, replaced.
    Replace {
        /// The text to find.
        find: String,
        /// What replaces it.
        replace: String,
    },
    /// A region's whole body, replaced.
    Body {
        /// Which of the checkpoint's regions in the file (0 = first).
        region: usize,
        /// The new body.
        body: String,
    },
}

/// A patch as written in `checkpoints/variants.toml`: `find` and `replace`, or `region` and
/// `body`, refused as it is read otherwise.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PatchFile {
    file: PathBuf,
    find: Option<String>,
    replace: Option<String>,
    region: Option<usize>,
    body: Option<String>,
}

/// A patch with neither or both of its two forms, or half of one: its file.
#[derive(Debug, thiserror::Error)]
#[error("{}: a patch has either find and replace, or region and body", .0.display())]
pub struct HalfPatch(PathBuf);

impl TryFrom<PatchFile> for Patch {
    type Error = HalfPatch;

    fn try_from(p: PatchFile) -> Result<Patch, HalfPatch> {
        let change = match (p.find, p.replace, p.region, p.body) {
            (Some(find), Some(replace), None, None) => Change::Replace { find, replace },
            (None, None, Some(region), Some(body)) => Change::Body { region, body },
            _ => return Err(HalfPatch(p.file)),
        };
        Ok(Patch { file: p.file, change })
    }
}

/// The checkpoints whose code the harness's wide BVH (`render --accel wide`) stands for: a render
/// through it runs none of their regions (ARCHITECTURE.md, "Which tracer").
pub const WIDE_BVH_REPLACES: [u32; 3] = [2, 3, 4];

impl Variant {
    /// Whether the variant's noisy renders may take the wide BVH, three to four times faster:
    /// only if its own checkpoint's code is not among those the wide BVH replaces (the rest of a
    /// variant's tree is the solution's).
    pub fn may_render_wide(&self) -> bool {
        !WIDE_BVH_REPLACES.contains(&self.checkpoint)
    }
}

impl VariantFile {
    /// Loads the variants file.
    pub fn load(path: &Path) -> Result<Self, FileError> {
        read_toml(path)
    }
}

/// Applies `patch` for `checkpoint` to `text`.
pub fn apply(text: &str, checkpoint: u32, patch: &Patch) -> Result<String, PatchProblem> {
    let regions = region_bodies(text, checkpoint);
    let file = patch.file.clone();
    match &patch.change {
        Change::Replace { find, replace } => {
            let hits: Vec<usize> = text.match_indices(find.as_str()).map(|(i, _)| i).collect();
            let [at] = hits[..] else {
                return Err(PatchProblem::NotOnce { file, find: find.clone(), count: hits.len() });
            };
            if !regions.iter().any(|r| r.start <= at && at + find.len() <= r.end) {
                return Err(PatchProblem::OutsideRegion { file, find: find.clone(), checkpoint });
            }
            Ok(format!("{}{replace}{}", &text[..at], &text[at + find.len()..]))
        }
        Change::Body { region, body } => {
            let r =
                regions.get(*region).ok_or(PatchProblem::NoRegion { file, region: *region, checkpoint })?;
            Ok(format!("{}{body}{}", &text[..r.start], &text[r.end..]))
        }
    }
}

/// Checks that every patch of every variant applies to the sources at `root` as they are now, so
/// a change to a solution region that breaks the catalogue is found before anything is built.
/// The error lists every patch that no longer applies, one per line.
pub fn check_patches(root: &Path, variants: &[Variant]) -> Result<(), InstructorError> {
    let mut problems = Vec::new();
    for variant in variants {
        let mut patched: Vec<(&Path, String)> = Vec::new();
        for patch in &variant.patches {
            let text = match patched.iter().position(|(file, _)| *file == patch.file.as_path()) {
                Some(i) => patched.remove(i).1,
                None => match std::fs::read_to_string(root.join(&patch.file)) {
                    Ok(text) => text,
                    Err(e) => {
                        let problem = FileError::unreadable(&patch.file, &e).into();
                        problems.push(Unpatched { variant: variant.name.clone(), problem });
                        continue;
                    }
                },
            };
            match apply(&text, variant.checkpoint, patch) {
                Ok(text) => patched.push((&patch.file, text)),
                Err(problem) => problems.push(Unpatched { variant: variant.name.clone(), problem }),
            }
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(InstructorError::Catalogue(problems))
    }
}

/// Copies the tree at `root` to `dest` (without build output or version control) and applies the
/// variant's patches there.
pub fn make_scratch_tree(root: &Path, dest: &Path, variant: &Variant) -> Result<(), InstructorError> {
    if dest.exists() {
        std::fs::remove_dir_all(dest).map_err(|e| FileError::unwritable(dest, &e))?;
    }
    copy_tree(root, dest, &NOT_COPIED).map_err(|e| FileError::unwritable(dest, &e))?;
    if variant.stub {
        stub_tree(&dest.join("src"), &[variant.checkpoint]).map_err(|e| FileError::unwritable(dest, &e))?;
    }
    for patch in &variant.patches {
        let path = dest.join(&patch.file);
        let text = std::fs::read_to_string(&path).map_err(|e| FileError::unreadable(&path, &e))?;
        let unpatched =
            |problem| InstructorError::Catalogue(vec![Unpatched { variant: variant.name.clone(), problem }]);
        let patched = apply(&text, variant.checkpoint, patch).map_err(unpatched)?;
        std::fs::write(&path, patched).map_err(|e| FileError::unwritable(&path, &e))?;
    }
    Ok(())
}

/// Replaces the solution regions of `checkpoints` in every Rust file below `dir` by stubs.
pub fn stub_tree(dir: &Path, checkpoints: &[u32]) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            stub_tree(&path, checkpoints)?;
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path)?;
            let stubbed = checkpoints.iter().fold(text.clone(), |t, &n| stub_regions(&t, n));
            if stubbed != text {
                std::fs::write(&path, stubbed)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    // Markers are assembled so that the starter generator does not stub this fixture itself.
    const TEXT: &str = concat!(
        "fn a() {\n    // BEGIN",
        " SOLUTION checkpoint2\n    let x = 1;\n    x + 1\n    // END SOLUTION\n}\nlet x = 1;\n"
    );

    fn patch(find: &str, replace: &str) -> Patch {
        Patch { file: "f.rs".into(), change: Change::Replace { find: find.into(), replace: replace.into() } }
    }

    #[test]
    fn grader_patches_apply_only_inside_their_checkpoints_regions() {
        assert_eq!(region_bodies(TEXT, 2).len(), 1);
        assert!(apply(TEXT, 2, &patch("x + 1", "x + 2")).unwrap().contains("    x + 2\n"));
        assert!(apply(TEXT, 2, &patch("let x = 1;", "")).is_err(), "found twice");
        assert!(apply(TEXT, 3, &patch("x + 1", "x")).is_err(), "not a checkpoint 3 region");
        let whole =
            Patch { file: "f.rs".into(), change: Change::Body { region: 0, body: "    todo!()\n".into() } };
        let stubbed = apply(TEXT, 2, &whole).unwrap();
        assert!(stubbed.contains("checkpoint2\n    todo!()\n    // END SOLUTION"), "{stubbed}");
        assert!(!stubbed.contains("x + 1"));
    }

    /// A patch is a replacement or a new body, never both or half of one: refused as it is read.
    #[test]
    fn a_patch_is_either_a_replacement_or_a_body() {
        let read = |fields: &str| toml::from_str::<Patch>(&format!("file = \"f.rs\"\n{fields}"));
        let replace = read("find = \"a\"\nreplace = \"b\"").unwrap().change;
        assert_eq!(replace, Change::Replace { find: "a".into(), replace: "b".into() });
        assert_eq!(
            read("region = 1\nbody = \"x\"").unwrap().change,
            Change::Body { region: 1, body: "x".into() }
        );
        for half in ["find = \"a\"", "find = \"a\"\nreplace = \"b\"\nbody = \"x\"", "region = 0", ""] {
            let error = read(half).unwrap_err().to_string();
            assert!(error.contains("either find and replace, or region and body"), "{half}: {error}");
        }
    }
}
