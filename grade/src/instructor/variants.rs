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
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Patch {
    /// The file, relative to the tree's root.
    pub file: PathBuf,
    /// Text to find, exactly once, inside one of the checkpoint's regions of the file...
    pub find: Option<String>,
    /// ...and what replaces it.
    pub replace: Option<String>,
    /// Or: which of the checkpoint's regions in the file (0 = first) gets a new body...
    pub region: Option<usize>,
    /// ...and the body.
    pub body: Option<String>,
}

impl VariantFile {
    /// Loads the variants file.
    pub fn load(path: &Path) -> Result<Self, String> {
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        toml::from_str(&text).map_err(|e| format!("{}: {}", path.display(), e.message()))
    }
}

/// Applies `patch` for `checkpoint` to `text`.
pub fn apply(text: &str, checkpoint: u32, patch: &Patch) -> Result<String, String> {
    let regions = region_bodies(text, checkpoint);
    let file = patch.file.display();
    match (&patch.find, &patch.replace, patch.region, &patch.body) {
        (Some(find), Some(replace), None, None) => {
            let hits: Vec<usize> = text.match_indices(find.as_str()).map(|(i, _)| i).collect();
            let [at] = hits[..] else {
                return Err(format!("{file}: {find:?} occurs {} times, not once", hits.len()));
            };
            if !regions.iter().any(|r| r.start <= at && at + find.len() <= r.end) {
                return Err(format!(
                    "{file}: {find:?} is not inside a checkpoint {checkpoint} solution region"
                ));
            }
            Ok(format!("{}{replace}{}", &text[..at], &text[at + find.len()..]))
        }
        (None, None, Some(k), Some(body)) => {
            let r =
                regions.get(k).ok_or_else(|| format!("{file}: no region {k} of checkpoint {checkpoint}"))?;
            Ok(format!("{}{body}{}", &text[..r.start], &text[r.end..]))
        }
        _ => Err(format!("{file}: a patch has either find and replace, or region and body")),
    }
}

/// Checks that every patch of every variant applies to the sources at `root` as they are now, so
/// a change to a solution region that breaks the catalogue is found before anything is built.
/// The error lists every patch that no longer applies, one per line.
pub fn check_patches(root: &Path, variants: &[Variant]) -> Result<(), String> {
    let mut problems = Vec::new();
    for variant in variants {
        let mut patched: Vec<(&Path, String)> = Vec::new();
        for patch in &variant.patches {
            let text = match patched.iter().position(|(file, _)| *file == patch.file.as_path()) {
                Some(i) => patched.remove(i).1,
                None => match std::fs::read_to_string(root.join(&patch.file)) {
                    Ok(text) => text,
                    Err(e) => {
                        problems.push(format!("variant {}: {}: {e}", variant.name, patch.file.display()));
                        continue;
                    }
                },
            };
            match apply(&text, variant.checkpoint, patch) {
                Ok(text) => patched.push((&patch.file, text)),
                Err(e) => problems.push(format!("variant {}: {e}", variant.name)),
            }
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// Copies the tree at `root` to `dest` (without build output or version control) and applies the
/// variant's patches there.
pub fn make_scratch_tree(root: &Path, dest: &Path, variant: &Variant) -> Result<(), String> {
    if dest.exists() {
        std::fs::remove_dir_all(dest).map_err(|e| format!("{}: {e}", dest.display()))?;
    }
    copy_tree(root, dest, &NOT_COPIED)
        .map_err(|e| format!("copying {} to {}: {e}", root.display(), dest.display()))?;
    if variant.stub {
        stub_tree(&dest.join("src"), &[variant.checkpoint])
            .map_err(|e| format!("stubbing {}: {e}", dest.display()))?;
    }
    for patch in &variant.patches {
        let path = dest.join(&patch.file);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let patched =
            apply(&text, variant.checkpoint, patch).map_err(|e| format!("variant {}: {e}", variant.name))?;
        std::fs::write(&path, patched).map_err(|e| format!("{}: {e}", path.display()))?;
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
        Patch {
            file: "f.rs".into(),
            find: Some(find.into()),
            replace: Some(replace.into()),
            region: None,
            body: None,
        }
    }

    #[test]
    fn grader_patches_apply_only_inside_their_checkpoints_regions() {
        assert_eq!(region_bodies(TEXT, 2).len(), 1);
        assert!(apply(TEXT, 2, &patch("x + 1", "x + 2")).unwrap().contains("    x + 2\n"));
        assert!(apply(TEXT, 2, &patch("let x = 1;", "")).is_err(), "found twice");
        assert!(apply(TEXT, 3, &patch("x + 1", "x")).is_err(), "not a checkpoint 3 region");
        let whole = Patch {
            file: "f.rs".into(),
            find: None,
            replace: None,
            region: Some(0),
            body: Some("    todo!()\n".into()),
        };
        let stubbed = apply(TEXT, 2, &whole).unwrap();
        assert!(stubbed.contains("checkpoint2\n    todo!()\n    // END SOLUTION"), "{stubbed}");
        assert!(!stubbed.contains("x + 1"));
    }
}
