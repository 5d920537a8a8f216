//! Making the fingerprints of the mistake catalogue and measuring how well they name mistakes
//! (`grader fingerprints`, instructor-only; [`crate::fingerprint`] uses them).
//!
//! **Made from.** Every catalogue mistake that must fail a public scene (`fails`), rendered on
//! those scenes with the rubric's seed: one thumbnail each; on a tile-tested scene, its tile
//! means instead ([`crate::fingerprint::tiles`]), from renders at [`FINGERPRINT_SEED`], a seed
//! no grade uses.
//!
//! **Measured on renders they were not made from** (*held out*): each mistake written a second
//! way (`second_of` in `checkpoints/variants.toml`) on the same scenes; on the tile-tested scenes,
//! the mistakes at the rubric's seed (what a student with that mistake is graded with) and at
//! seeds 1 to [`OTHER_SEEDS`]; and correct renders, which must never be named: every correct
//! alternative on every public scene, and the solution on each tile-tested scene at the rubric's
//! seed and at seeds 1 to [`CORRECT_SEEDS`].
//!
//! **Measured** by [`super::naming`], thresholds set on one half and reported on the other.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::Path;

use indicatif::ProgressBar;

use crate::file_error::FileError;
use crate::fingerprint::{thumbnail, Entry, FingerprintFile, Rule, Signature, DIR};
use crate::grading::checked_rubric;
use crate::images::write_png;
use crate::instructor::calibrate::grade_report;
use crate::instructor::error::InstructorError;
use crate::instructor::naming::{judge, table, Shot};
use crate::instructor::variants::{check_patches, make_scratch_tree, Variant, VariantFile};
use crate::reference::Manifest;
use crate::rubric::Rubric;

/// Held-out seeds of a mistake on a tile-tested scene.
pub const OTHER_SEEDS: u64 = 4;

/// Seeds of the solution on each tile-tested scene: correct renders that must not be named.
pub const CORRECT_SEEDS: u64 = 20;

/// The seed a mistake's fingerprint is rendered with on a tile-tested scene: one no grade uses,
/// so that its renders are independent of a graded student's (who renders with the rubric's
/// seed, as the held-out renders at that seed do).
pub const FINGERPRINT_SEED: u64 = 1000;

/// What `grader fingerprints` made: the fingerprints (written) and the naming table.
pub struct Made {
    /// The shipped rule.
    pub rule: Rule,
    /// How many fingerprints.
    pub count: usize,
    /// The table, in Markdown.
    pub table: String,
}

/// Which renders a variant gives: (scene, seed), `None` for the rubric's seed.
type Plan<'a> = Vec<(&'a Variant, Vec<(String, Option<u64>)>)>;

/// Renders the catalogue, writes `reference/fingerprints/` and measures the naming (module docs).
pub fn make(root: &Path, progress: &ProgressBar) -> Result<Made, InstructorError> {
    let rubric = checked_rubric(root)?;
    let catalogue = VariantFile::load(&root.join("checkpoints/variants.toml"))?.variants;
    check_patches(root, &catalogue)?;
    let public = |name: &String| rubric.scenes.iter().any(|s| &s.name == name && !s.hidden);
    let named_by: BTreeMap<&str, &Variant> = catalogue
        .iter()
        .filter(|v| !v.correct && !v.stub && v.second_of.is_none() && v.fails.iter().any(public))
        .map(|v| (v.name.as_str(), v))
        .collect();
    let root = std::path::absolute(root).map_err(|e| FileError::unreadable(root, &e))?;
    let (shots, unrendered) = render(&root, plan(&catalogue, &rubric, &named_by), progress)?;
    let prints = fingerprints(&shots, &named_by, &rubric, &Manifest::load(&root, &rubric)?)?;
    let held_out: Vec<&Shot> = shots.iter().filter(|s| !is_print(s, &named_by)).collect();
    let (rule, mut table) = table(&judge(&held_out, &prints), &named_by);
    if !unrendered.is_empty() {
        let _ = writeln!(table, "\nNot rendered (left out): {}.", unrendered.join("; "));
    }
    write(&root, rule, &prints)?;
    Ok(Made { rule, count: prints.len(), table })
}

/// The renders (module docs): correct variants on every public scene (the solution on the
/// tile-tested ones at seeds 1 to [`CORRECT_SEEDS`]), each named mistake on its public `fails`
/// (on a tile-tested one also at seeds 1 to [`OTHER_SEEDS`]), each second way on its first's.
fn plan<'a>(catalogue: &'a [Variant], rubric: &Rubric, named_by: &BTreeMap<&str, &Variant>) -> Plan<'a> {
    let public = |name: &String| rubric.scenes.iter().any(|s| &s.name == name && !s.hidden);
    let noisy = |name: &String| rubric.scenes.iter().any(|s| &s.name == name && s.tile_test.is_some());
    let all: Vec<&String> = rubric.scenes.iter().map(|s| &s.name).filter(|s| public(s)).collect();
    let mut plan = Vec::new();
    for v in catalogue {
        // The scenes, and how many more seeds than the rubric's on a tile-tested one.
        let (scenes, more) = if v.correct {
            (all.clone(), if v.patches.is_empty() { CORRECT_SEEDS } else { 0 })
        } else if named_by.contains_key(v.name.as_str()) {
            (v.fails.iter().filter(|s| public(s)).collect(), OTHER_SEEDS)
        } else if let Some(first) = v.second_of.as_deref().and_then(|n| named_by.get(n)) {
            (first.fails.iter().filter(|s| public(s)).collect(), 0)
        } else {
            continue;
        };
        let mut shots = Vec::new();
        for scene in scenes {
            let mut seeds: Vec<Option<u64>> = vec![None];
            if noisy(scene) {
                seeds.extend((1..=more).map(Some));
                if named_by.contains_key(v.name.as_str()) {
                    seeds.push(Some(FINGERPRINT_SEED));
                }
            }
            shots.extend(seeds.into_iter().map(|seed| (scene.clone(), seed)));
        }
        plan.push((v, shots));
    }
    plan
}

/// Builds each planned variant in a scratch tree and grades its images: the renders, and the
/// ones that could not be made (a variant that does not build, a crash), in words.
fn render(
    root: &Path,
    plan: Plan,
    progress: &ProgressBar,
) -> Result<(Vec<Shot>, Vec<String>), InstructorError> {
    progress.set_length(plan.len() as u64);
    let work = root.join("target/variants");
    let (tree, target) = (work.join("tree"), work.join("target"));
    let (mut shots, mut unrendered) = (Vec::new(), Vec::new());
    for (variant, wanted) in plan {
        progress.set_message(format!("rendering {}", variant.name));
        make_scratch_tree(root, &tree, variant)?;
        let truth = (!variant.correct).then(|| variant.second_of.clone().unwrap_or(variant.name.clone()));
        let seeds: BTreeSet<Option<u64>> = wanted.iter().map(|w| w.1).collect();
        for seed in seeds {
            let scenes: Vec<String> = wanted.iter().filter(|w| w.1 == seed).map(|w| w.0.clone()).collect();
            let report = grade_report(&tree, &target, seed, Some(scenes), variant.may_render_wide())?;
            for s in report.scenes {
                let tiles = s.tile_signatures();
                let Some(render) = s.render else {
                    let why = s.error.map(|e| e.to_string()).unwrap_or_default();
                    unrendered.push(format!("{} on {} (seed {seed:?}): {why}", variant.name, s.scene.name));
                    continue;
                };
                shots.push(Shot {
                    variant: variant.name.clone(),
                    truth: truth.clone(),
                    scene: s.scene.name,
                    seed,
                    render,
                    reference: s.reference,
                    tiles,
                    depends_on: s.scene.depends_on,
                });
            }
        }
        progress.inc(1);
    }
    Ok((shots, unrendered))
}

/// Whether `shot` is a fingerprint: a named mistake's render at the rubric's seed, or on a
/// tile-tested scene at [`FINGERPRINT_SEED`].
fn is_print(shot: &Shot, named_by: &BTreeMap<&str, &Variant>) -> bool {
    let seed = if shot.tiles.is_some() { Some(FINGERPRINT_SEED) } else { None };
    named_by.contains_key(shot.variant.as_str()) && shot.seed == seed
}

/// The fingerprints: each named mistake's render of each of its scenes ([`is_print`]).
fn fingerprints(
    shots: &[Shot],
    named_by: &BTreeMap<&str, &Variant>,
    rubric: &Rubric,
    manifest: &Manifest,
) -> Result<Vec<(Entry, Signature)>, InstructorError> {
    let mut prints = Vec::new();
    for shot in shots.iter().filter(|s| is_print(s, named_by)) {
        let Some(v) = named_by.get(shot.variant.as_str()) else { continue };
        let handout = rubric.checkpoints.iter().find(|c| c.id == v.checkpoint).map(|c| &c.handout);
        let reference = manifest.references.iter().find(|r| r.name == shot.scene);
        let (Some(handout), Some(reference)) = (handout, reference) else {
            return Err(InstructorError::NoFingerprintBase {
                variant: v.name.clone(),
                checkpoint: v.checkpoint,
                scene: shot.scene.clone(),
            });
        };
        let entry = Entry {
            scene: shot.scene.clone(),
            mistake: v.name.clone(),
            checkpoint: v.checkpoint,
            description: v.description.clone(),
            handout: handout.display().to_string(),
            inputs_hash: reference.inputs_hash.clone(),
            kind: shot.kind(),
        };
        let signature = match &shot.tiles {
            Some((mine, _)) => Signature::Tiles(mine.clone()),
            None => Signature::Thumbnail(thumbnail(&shot.render)),
        };
        prints.push((entry, signature));
    }
    Ok(prints)
}

/// Writes the signatures and the manifest, replacing the folder's previous fingerprints.
fn write(root: &Path, rule: Rule, prints: &[(Entry, Signature)]) -> Result<(), FileError> {
    let dir = root.join(DIR);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).map_err(|e| FileError::unwritable(&dir, &e))?;
    }
    std::fs::create_dir_all(&dir).map_err(|e| FileError::unwritable(&dir, &e))?;
    for (entry, signature) in prints {
        let path = dir.join(entry.file_name());
        match signature {
            Signature::Thumbnail(image) => {
                write_png(&path, image).map_err(|e| FileError::image(&path, &e))?
            }
            Signature::Tiles(tiles) => {
                let text = serde_json::to_string(tiles).expect("a signature holds only numbers and lists");
                raylab_base::image_io::write_file_atomic(&path, text.as_bytes())
                    .map_err(|e| FileError::unwritable(&path, &e))?
            }
        }
    }
    let file = FingerprintFile { rule, fingerprints: prints.iter().map(|(e, _)| e.clone()).collect() };
    let text = toml::to_string(&file).expect("a manifest is plain data");
    let header = "# Written by `grader fingerprints`; do not edit by hand.\n\n";
    let path = dir.join("manifest.toml");
    raylab_base::image_io::write_file_atomic(&path, format!("{header}{text}").as_bytes())
        .map_err(|e| FileError::unwritable(&path, &e))
}
