//! How well the fingerprints name mistakes, measured on renders they were not made from
//! ([`super::fingerprint_make`] renders them).
//!
//! **Thresholds on one half, reported on the other.** The mistakes of each checkpoint are dealt
//! alternately into two halves, each with its held-out renders, and the correct renders alike.
//! On one half each kind's margin is set to the lowest that names no correct render and no
//! mistake wrongly there, plus its gap ([`GAP`]; for tile means measured, [`TILE_GAP_SDS`]),
//! and its fit to the least alike a mistake's own render is to its fingerprint there, less the
//! gap; the other half is reported
//! with them; then the halves swap, so every mistake is reported once, by a rule its own renders
//! did not set. Each bound shipped is the stricter of the two: it names a subset of what either
//! names, so it names wrongly no more.

use std::collections::BTreeMap;
use std::fmt::Write;

use image::RgbImage;

use crate::fingerprint::{Entry, Evidence, Fingerprints, Kind, Likeness, Rule, Signature, TileSignature};
use crate::instructor::variants::Variant;

/// What the margin adds to the largest it must exceed on the tuning half (SSIM).
pub const GAP: f64 = 0.02;

/// For tile signatures, whose likeness is `−ln` of a distance, the gap is measured instead: this
/// many standard deviations of `ln` of the distance between a correct render and the expected
/// means over the tuning half's correct renders (how much a likeness moves with the seed alone).
pub const TILE_GAP_SDS: f64 = 3.0;

/// One render of one scene by one variant.
pub(super) struct Shot {
    /// The variant.
    pub(super) variant: String,
    /// The mistake it shows (`None`: a correct render).
    pub(super) truth: Option<String>,
    /// The scene.
    pub(super) scene: String,
    /// Its seed (`None`: the rubric's).
    pub(super) seed: Option<u64>,
    /// The render (a tile-tested scene's: the mean of its renders).
    pub(super) render: RgbImage,
    /// The reference image.
    pub(super) reference: RgbImage,
    /// On a tile-tested scene, its tile means and the reference's expected ones.
    pub(super) tiles: Option<(TileSignature, TileSignature)>,
    /// The checkpoints the scene runs.
    pub(super) depends_on: Vec<u32>,
}

impl Shot {
    /// What naming compares it by.
    pub(super) fn evidence(&self) -> Evidence<'_> {
        match &self.tiles {
            Some((mine, expected)) => Evidence::Tiles { mine, expected },
            None => Evidence::Picture { render: &self.render, reference: &self.reference },
        }
    }

    /// The kind of fingerprint its scene has.
    pub(super) fn kind(&self) -> Kind {
        if self.tiles.is_some() {
            Kind::Tiles
        } else {
            Kind::Thumbnail
        }
    }
}

/// A held-out render with its half and its likeness to the reference and the fingerprints.
pub(super) struct Judged<'a> {
    shot: &'a Shot,
    half: usize,
    likeness: Likeness,
    /// For a mistake's render, its likeness with every fingerprint of its checkpoint left out: a
    /// stand-in for a bug of that checkpoint the catalogue does not know, which must not be named
    /// (any name would point at another checkpoint).
    left_out: Option<Likeness>,
    /// The mistake of each fingerprint index.
    names: Vec<String>,
}

impl Judged<'_> {
    /// The mistake named under `rule`, if any.
    fn named(&self, rule: Rule) -> Option<&str> {
        self.likeness.named(rule).map(|i| self.names[i].as_str())
    }

    /// Whether a mistake is named under `rule` with its checkpoint's fingerprints left out
    /// (always wrong).
    fn named_left_out(&self, rule: Rule) -> bool {
        self.left_out.as_ref().is_some_and(|l| l.named(rule).is_some())
    }

    /// Whether naming it at all would be wrong: a correct render, or a mistake taken for another.
    fn must_not_be_named(&self) -> bool {
        let best = self.likeness.to_mistakes.first().map(|(i, _)| self.names[*i].as_str());
        self.shot.truth.is_none() || best != self.shot.truth.as_deref()
    }
}

/// Each held-out render's likeness, dealt into halves: the mistakes of each checkpoint
/// alternately (a second variant and the seeds of a mistake go with it), correct renders alike.
pub(super) fn judge<'a>(held_out: &[&'a Shot], prints: &[(Entry, Signature)]) -> Vec<Judged<'a>> {
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
            // Every fingerprint of the mistake's checkpoint left out: what a bug of that checkpoint
            // the catalogue does not know would be compared with (candidates are chosen by the
            // checkpoints the scene runs, so that checkpoint is dropped from them).
            let left_out = shot.truth.as_ref().and_then(|m| {
                let checkpoint = prints.iter().find(|(e, _)| &e.mistake == m)?.0.checkpoint;
                let others: Vec<u32> = shot.depends_on.iter().copied().filter(|&c| c != checkpoint).collect();
                fingerprints.likeness(&shot.scene, shot.evidence(), &others)
            });
            Some(Judged { shot, half, likeness, left_out, names: names.clone() })
        })
        .collect()
}

/// The gap of tile signatures on one half: [`TILE_GAP_SDS`] standard deviations of `ln` of the
/// distance from its correct renders to the expected means; `None` with fewer than two.
fn tile_gap(judged: &[Judged], half: usize) -> Option<f64> {
    let logs: Vec<f64> = (judged.iter())
        .filter(|j| j.half == half && j.shot.kind() == Kind::Tiles && j.shot.truth.is_none())
        .map(|j| -j.likeness.to_reference)
        .collect();
    (logs.len() >= 2).then(|| TILE_GAP_SDS * raylab_base::stats::Summary::of(logs).variance.sqrt())
}

/// The rule each half sets (module docs), per kind of signature: the margin is the largest a
/// render that must not be named reaches there (a correct render, a mistake taken for another, a
/// mistake with its checkpoint's fingerprints left out), plus the kind's gap; the fit is the least alike
/// a mistake's own render is to its fingerprint there, less the gap.
fn rules(judged: &[Judged]) -> [Rule; 2] {
    [0, 1].map(|half| {
        let of = |kind: Kind| judged.iter().filter(move |j| j.half == half && j.shot.kind() == kind);
        let margin = |kind: Kind, gap: f64| {
            let bad = of(kind).filter(|j| j.must_not_be_named()).map(|j| &j.likeness);
            let left_out = of(kind).filter_map(|j| j.left_out.as_ref());
            bad.chain(left_out).filter_map(Likeness::margin).fold(0.0f64, f64::max) + gap
        };
        let fit = |kind: Kind, gap: f64| {
            let own = of(kind).filter(|j| !j.must_not_be_named());
            own.filter_map(|j| j.likeness.to_mistakes.first().map(|m| m.1)).fold(f64::INFINITY, f64::min)
                - gap
        };
        let tile_gap = tile_gap(judged, half);
        Rule {
            margin: margin(Kind::Thumbnail, GAP),
            fit: Some(fit(Kind::Thumbnail, GAP)),
            tile_margin: tile_gap.map(|gap| margin(Kind::Tiles, gap)),
            tile_fit: tile_gap.map(|gap| fit(Kind::Tiles, gap)),
        }
    })
}

/// The rule shipped (each bound the stricter of the halves', so it names a subset of what either
/// names), and the table of each half judged by the other's rule.
pub(super) fn table(judged: &[Judged], named_by: &BTreeMap<&str, &Variant>) -> (Rule, String) {
    let rules = rules(judged);
    let both = |f: fn(&Rule) -> Option<f64>| rules.iter().filter_map(f).reduce(f64::max);
    let shipped = Rule {
        margin: rules[0].margin.max(rules[1].margin),
        fit: both(|r| r.fit),
        tile_margin: both(|r| r.tile_margin),
        tile_fit: both(|r| r.tile_fit),
    };
    let mut out = String::new();
    let show = |r: &Rule| {
        let value = |v: Option<f64>| v.map_or("none".to_string(), |v| format!("{v:.4}"));
        format!(
            "thumbnails margin {:.4}, fit {}; tile means margin {}, fit {} (a distance of at most {})",
            r.margin,
            value(r.fit),
            value(r.tile_margin),
            value(r.tile_fit),
            r.tile_fit.map_or("-".to_string(), |f| format!("{:.2}", (-f).exp()))
        )
    };
    let gaps = [0, 1].map(|half| tile_gap(judged, half).map_or("none".to_string(), |g| format!("{g:.4}")));
    let _ = writeln!(
        out,
        "Set on each half: {}; and {}. Shipped: {}. Tile gaps ({TILE_GAP_SDS} standard deviations of ln of a correct render's distance to the expected means): {} and {}.\n",
        show(&rules[0]),
        show(&rules[1]),
        show(&shipped),
        gaps[0],
        gaps[1]
    );
    let _ = writeln!(out, "| mistake | checkpoint | held-out renders | named | not named | named wrongly | named with its checkpoint's left out | named at the shipped margin |");
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|");
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
        let left_out = mine.iter().filter(|j| j.named_left_out(margin(j))).count();
        let _ = writeln!(
            out,
            "| {name} | {} | {} | {right} | {} | {} | {left_out} | {shipped_right} |",
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
        "| **correct renders** | all | {} | {} | {} | | | {} |",
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
