//! Making the fingerprints of the mistake catalogue and measuring how well they name mistakes
//! (`grader fingerprints`, instructor-only; [`crate::fingerprint`] uses them).
//!
//! **Made from.** Every catalogue mistake that must fail a public scene (`fails`), rendered on
//! those scenes with the rubric's seed: one thumbnail each.
//!
//! **Measured on renders they were not made from** (*held out*): each mistake written a second
//! way (`second_of` in `checkpoints/variants.toml`) on the same scenes; on the tile-tested scenes,
//! the mistakes at seeds 1 to [`OTHER_SEEDS`]; and correct renders, which must never be named:
//! every correct alternative on every public scene, and the solution on each tile-tested scene
//! at seeds 1 to [`CORRECT_SEEDS`].
//!
//! On a tile-tested scene the fingerprint is the mistake's tile means instead of a thumbnail
//! ([`crate::fingerprint::tiles`]), and its margin is set apart from the thumbnails' by the same
//! rule, with its own gap ([`TILE_GAP`]).
//!
//! **Thresholds on one half, reported on the other.** The mistakes of each checkpoint are dealt
//! alternately into two halves, each with its held-out renders, and the correct renders alike.
//! On one half the margin is set to the lowest that names no correct render and no mistake
//! wrongly there, plus [`GAP`]; the other half is reported with it; then the halves swap, so
//! every mistake is reported once, by a margin its own renders did not set. The margin shipped is
//! the larger of the two: it names a subset of what either names, so it names wrongly no more.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::Path;

use image::RgbImage;
use indicatif::ProgressBar;

use crate::file_error::FileError;
use crate::fingerprint::{
    thumbnail, Entry, Evidence, FingerprintFile, Fingerprints, Kind, Likeness, Rule, Signature,
    TileSignature, DIR,
};
use crate::grading::checked_rubric;
use crate::images::write_png;
use crate::instructor::calibrate::grade_report;
use crate::instructor::error::InstructorError;
use crate::instructor::variants::{check_patches, make_scratch_tree, Variant, VariantFile};
use crate::reference::Manifest;
use crate::rubric::Rubric;

/// Held-out seeds of a mistake on a tile-tested scene.
pub const OTHER_SEEDS: u64 = 4;

/// Seeds of the solution on each tile-tested scene: correct renders that must not be named.
pub const CORRECT_SEEDS: u64 = 20;

/// What the margin adds to the largest it must exceed on the tuning half (SSIM).
pub const GAP: f64 = 0.02;

/// The same for tile signatures, whose likeness is `−ln` of a root-mean-square `z` over the
/// scene's 300 tile means: for renders of the same code, the mean of 300 `z²` has a standard
/// deviation of about `sqrt(2 / 300) = 0.08`, so its log about 0.04; the gap is 2.5 of those.
pub const TILE_GAP: f64 = 0.1;

/// One render of one scene by one variant.
struct Shot {
    /// The variant.
    variant: String,
    /// The mistake it shows (`None`: a correct render).
    truth: Option<String>,
    scene: String,
    seed: Option<u64>,
    render: RgbImage,
    reference: RgbImage,
    /// On a tile-tested scene, its tile means and the reference's expected ones.
    tiles: Option<(TileSignature, TileSignature)>,
    /// The checkpoints the scene runs.
    depends_on: Vec<u32>,
}

impl Shot {
    fn evidence(&self) -> Evidence<'_> {
        match &self.tiles {
            Some((mine, expected)) => Evidence::Tiles { mine, expected },
            None => Evidence::Picture { render: &self.render, reference: &self.reference },
        }
    }

    fn kind(&self) -> Kind {
        if self.tiles.is_some() {
            Kind::Tiles
        } else {
            Kind::Thumbnail
        }
    }
}

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
    let held_out: Vec<&Shot> = shots
        .iter()
        .filter(|s| s.truth.is_none() || s.seed.is_some() || !named_by.contains_key(s.variant.as_str()))
        .collect();
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
            let seeds = if noisy(scene) { (1..=more).map(Some).collect() } else { Vec::new() };
            // The solution's correct renders of a noisy scene: the other seeds only.
            let own = !(v.correct && v.patches.is_empty() && noisy(scene));
            shots.extend(own.then_some(None).into_iter().chain(seeds).map(|seed| (scene.clone(), seed)));
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

/// The fingerprints: each named mistake's render of each of its scenes at the rubric's seed.
fn fingerprints(
    shots: &[Shot],
    named_by: &BTreeMap<&str, &Variant>,
    rubric: &Rubric,
    manifest: &Manifest,
) -> Result<Vec<(Entry, Signature)>, InstructorError> {
    let mut prints = Vec::new();
    for shot in shots.iter().filter(|s| s.seed.is_none()) {
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

/// A held-out render with its half and its likeness to the reference and the fingerprints.
struct Judged<'a> {
    shot: &'a Shot,
    half: usize,
    likeness: Likeness,
    /// The mistake of each fingerprint index.
    names: Vec<String>,
}

impl Judged<'_> {
    /// The mistake named under `rule`, if any.
    fn named(&self, rule: Rule) -> Option<&str> {
        self.likeness.named(rule).map(|i| self.names[i].as_str())
    }

    /// Whether naming it at all would be wrong: a correct render, or a mistake taken for another.
    fn must_not_be_named(&self) -> bool {
        let best = self.likeness.to_mistakes.first().map(|(i, _)| self.names[*i].as_str());
        self.shot.truth.is_none() || best != self.shot.truth.as_deref()
    }
}

/// Each held-out render's likeness, dealt into halves: the mistakes of each checkpoint
/// alternately (a second variant and the seeds of a mistake go with it), correct renders alike.
fn judge<'a>(held_out: &[&'a Shot], prints: &[(Entry, Signature)]) -> Vec<Judged<'a>> {
    let fingerprints = Fingerprints { rule: Rule::default(), prints: prints.to_vec() };
    let names: Vec<String> = prints.iter().map(|(e, _)| e.mistake.clone()).collect();
    let mut mistakes: Vec<(u32, &str)> =
        prints.iter().map(|(e, _)| (e.checkpoint, e.mistake.as_str())).collect();
    mistakes.dedup();
    let mut turn: BTreeMap<u32, usize> = BTreeMap::new();
    let half_of: BTreeMap<&str, usize> = mistakes
        .iter()
        .map(|(c, m)| {
            let k = turn.entry(*c).or_default();
            *k += 1;
            (*m, *k % 2)
        })
        .collect();
    let mut correct = 0usize;
    held_out
        .iter()
        .filter_map(|shot| {
            let half = match &shot.truth {
                Some(m) => *half_of.get(m.as_str())?,
                None => {
                    correct += 1;
                    correct % 2
                }
            };
            let likeness = fingerprints.likeness(&shot.scene, shot.evidence(), &shot.depends_on)?;
            Some(Judged { shot, half, likeness, names: names.clone() })
        })
        .collect()
}

/// The rule each half sets (module docs): per kind of signature, the largest margin a render that
/// must not be named reaches there, plus the kind's gap.
fn rules(judged: &[Judged]) -> [Rule; 2] {
    [0, 1].map(|half| {
        let set = |kind: Kind, gap: f64| {
            let bad =
                judged.iter().filter(|j| j.half == half && j.shot.kind() == kind && j.must_not_be_named());
            bad.filter_map(|j| j.likeness.margin()).fold(0.0f64, f64::max) + gap
        };
        Rule { margin: set(Kind::Thumbnail, GAP), tile_margin: Some(set(Kind::Tiles, TILE_GAP)) }
    })
}

/// The rule shipped (each margin the larger of the halves'), and the table of each half judged by
/// the other's rule.
fn table(judged: &[Judged], named_by: &BTreeMap<&str, &Variant>) -> (Rule, String) {
    let rules = rules(judged);
    let tile = |r: Rule| r.tile_margin.unwrap_or(f64::INFINITY);
    let shipped = Rule {
        margin: rules[0].margin.max(rules[1].margin),
        tile_margin: Some(tile(rules[0]).max(tile(rules[1]))),
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Margins set on each half: thumbnails {:.4} and {:.4}, tile means {:.4} and {:.4}; shipped: {:.4} and {:.4}.\n",
        rules[0].margin,
        rules[1].margin,
        tile(rules[0]),
        tile(rules[1]),
        shipped.margin,
        tile(shipped)
    );
    let _ = writeln!(out, "| mistake | checkpoint | held-out renders | named | not named | named wrongly | named at the shipped margin |");
    let _ = writeln!(out, "|---|---|---|---|---|---|---|");
    let mut rows: Vec<(&str, &Variant)> = named_by.iter().map(|(n, v)| (*n, *v)).collect();
    rows.sort_by_key(|(n, v)| (v.checkpoint, *n));
    for (name, v) in rows {
        let mine: Vec<&Judged> = judged.iter().filter(|j| j.shot.truth.as_deref() == Some(name)).collect();
        // Judged with the rule the other half set.
        let margin = |j: &Judged| rules[1 - j.half];
        let right = mine.iter().filter(|j| j.named(margin(j)) == Some(name)).count();
        let wrong: Vec<String> = mine
            .iter()
            .filter_map(|j| {
                j.named(margin(j)).filter(|n| *n != name).map(|n| format!("{n} ({})", shot_label(j.shot)))
            })
            .collect();
        let shipped_right = mine.iter().filter(|j| j.named(shipped) == Some(name)).count();
        let _ = writeln!(
            out,
            "| {name} | {} | {} | {right} | {} | {} | {shipped_right} |",
            v.checkpoint,
            mine.len(),
            mine.len() - right - wrong.len(),
            if wrong.is_empty() { "0".to_string() } else { format!("{}: {}", wrong.len(), wrong.join(", ")) }
        );
    }
    let correct: Vec<&Judged> = judged.iter().filter(|j| j.shot.truth.is_none()).collect();
    let named: Vec<String> = correct
        .iter()
        .filter_map(|j| j.named(rules[1 - j.half]).map(|n| format!("{} as {n}", shot_label(j.shot))))
        .collect();
    let _ = writeln!(
        out,
        "| **correct renders** | all | {} | {} | {} | | {} |",
        correct.len(),
        named.len(),
        correct.len() - named.len(),
        correct.iter().filter(|j| j.named(shipped).is_some()).count()
    );
    if !named.is_empty() {
        let _ = writeln!(out, "\nCorrect renders named: {}.", named.join("; "));
    }
    (shipped, out)
}

fn shot_label(shot: &Shot) -> String {
    match shot.seed {
        Some(seed) => format!("{} on {}, seed {seed}", shot.variant, shot.scene),
        None => format!("{} on {}", shot.variant, shot.scene),
    }
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
