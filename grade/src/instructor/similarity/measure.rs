//! The engine measured on synthetic classes drawn from the independent implementations.
//!
//! A class of [`CLASS_SIZE`] students: most are mosaics, each region's text one author's (drawn at
//! random), put on with a disguise drawn for that student and region (none, each alone, each
//! combination); the others are copiers, each copying 2, 4 or all of an earlier student's
//! regions under one disguise of their own (a person disguises the way they disguise), their
//! other regions drawn from authors other than the source's. Two students share a region when
//! its text comes from the same author, copied or by the draw (with sixteen authors, eight a
//! half, a draw gives two students the same author in a region one time in eight: that is the
//! price of a test set of this size, and why the tables count shared regions, not intent).
//!
//! Halves: the null and the threshold come from one half of the authors, everything is reported
//! on classes of the other half, whose authors the engine has never seen.

use std::collections::BTreeMap;

use raylab_base::rng::Rng;

use crate::instructor::similarity::disguise::{disguise, Disguise};
use crate::instructor::similarity::{compare, Author};

/// Students per synthetic class.
pub const CLASS_SIZE: usize = 60;

/// Copiers per synthetic class: one in four.
const COPIERS: usize = 15;

/// The numbers of regions a copier copies (all = every region).
pub const COPIED: [Copied; 3] = [Copied::Some(2), Copied::Some(4), Copied::All];

/// How many regions a copier copies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Copied {
    /// That many.
    Some(usize),
    /// Every region.
    All,
}

/// One pair of a synthetic class, scored, with what it truly is.
#[derive(Clone, Debug)]
pub struct Labelled {
    /// The first student, by index in its class.
    pub a: usize,
    /// The second (`a < b`).
    pub b: usize,
    /// The engine's score.
    pub score: f64,
    /// Regions whose text comes from the same author.
    pub shared: usize,
    /// For a copier and its source: how many regions were copied, and the copier's disguise.
    pub copy: Option<(Copied, &'static [Disguise])>,
}

/// The disguise options a student draws from: none, each alone, each combination.
fn options() -> Vec<&'static [Disguise]> {
    let alone: [&'static [Disguise]; 6] = [
        &[Disguise::Rename],
        &[Disguise::Literals],
        &[Disguise::Layout],
        &[Disguise::Comments],
        &[Disguise::Reorder],
        &[Disguise::DeadCode],
    ];
    std::iter::once(&[][..]).chain(alone).chain(Disguise::COMBINATIONS).collect()
}

/// One student of a synthetic class: per region, the author its text comes from.
struct Drawn {
    authors: BTreeMap<String, usize>,
    copy: Option<(usize, Copied, &'static [Disguise])>,
}

/// One synthetic class: its students' texts, and where each region came from.
pub struct Synthetic {
    /// The students, each a mosaic of authors' disguised texts.
    pub students: Vec<Author>,
    drawn: Vec<Drawn>,
    regions: Vec<String>,
}

impl Synthetic {
    /// Class `class` drawn from `authors` with `seed`, over the regions of `stubs` they all wrote.
    pub fn draw(authors: &[Author], stubs: &BTreeMap<String, String>, class: usize, seed: u64) -> Synthetic {
        let regions: Vec<String> =
            stubs.keys().filter(|r| authors.iter().all(|a| a.regions.contains_key(*r))).cloned().collect();
        let mut rng = Rng::new(seed, class as u64);
        let drawn = draw_class(authors.len(), &regions, &mut rng);
        let students = write_class(&drawn, authors, &mut rng);
        Synthetic { students, drawn, regions }
    }

    /// What students `a < b` truly are to each other, with `score`.
    pub fn label(&self, a: usize, b: usize, score: f64) -> Labelled {
        let (da, db) = (&self.drawn[a], &self.drawn[b]);
        let shared = self.regions.iter().filter(|r| da.authors[*r] == db.authors[*r]).count();
        let copy = db.copy.filter(|c| c.0 == a).map(|(_, copied, d)| (copied, d));
        Labelled { a, b, score, shared, copy }
    }
}

/// Every pair of `classes` classes drawn from `authors` (seeded by `seed`), scored against the
/// null of `independent`, with the `stubs`' fingerprints left out.
pub fn measure(
    authors: &[Author],
    independent: &[Author],
    stubs: &BTreeMap<String, String>,
    classes: usize,
    seed: u64,
) -> Vec<Labelled> {
    let mut out = Vec::new();
    for class in 0..classes {
        let synthetic = Synthetic::draw(authors, stubs, class, seed);
        for pair in compare(&synthetic.students, &[], independent, stubs).pairs {
            out.push(synthetic.label(pair.a, pair.b, pair.score));
        }
    }
    out
}

/// Which author each student's regions come from, and who copies whom.
fn draw_class(authors: usize, regions: &[String], rng: &mut Rng) -> Vec<Drawn> {
    let pick = |rng: &mut Rng, n: usize| rng.next_u32() as usize % n;
    let options = options();
    let mut drawn: Vec<Drawn> = Vec::with_capacity(CLASS_SIZE);
    for student in 0..CLASS_SIZE {
        let mut own: BTreeMap<String, usize> =
            regions.iter().map(|r| (r.clone(), pick(rng, authors))).collect();
        let copier = student >= CLASS_SIZE - COPIERS;
        let copy = copier.then(|| {
            let source = pick(rng, student);
            let copied = COPIED[student % COPIED.len()];
            let count = match copied {
                Copied::Some(n) => n.min(regions.len()),
                Copied::All => regions.len(),
            };
            let mut order: Vec<&String> = regions.iter().collect();
            for i in (1..order.len()).rev() {
                order.swap(i, pick(rng, i + 1));
            }
            for (k, region) in order.into_iter().enumerate() {
                let theirs = drawn[source].authors[region];
                own.insert(
                    region.clone(),
                    if k < count { theirs } else { (theirs + 1 + pick(rng, authors - 1)) % authors },
                );
            }
            (source, copied, options[1 + pick(rng, options.len() - 1)])
        });
        drawn.push(Drawn { authors: own, copy });
    }
    drawn
}

/// The students' texts: each region its author's, disguised (a copier's copied regions by its
/// own disguise, every other region by one drawn for it).
fn write_class(drawn: &[Drawn], authors: &[Author], rng: &mut Rng) -> Vec<Author> {
    let options = options();
    drawn
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let regions = d
                .authors
                .iter()
                .map(|(region, &author)| {
                    let copied = d.copy.is_some_and(|(source, ..)| drawn[source].authors[region] == author);
                    let how = match d.copy {
                        Some((.., how)) if copied => how,
                        _ => options[rng.next_u32() as usize % options.len()],
                    };
                    let body = disguise(&authors[author].regions[region], how, rng.next_u32() as u64);
                    (region.clone(), body)
                })
                .collect();
            Author { name: format!("student {i}"), regions }
        })
        .collect()
}

/// The flag threshold from the half it is set on: the score that at most one independent pair
/// (no region shared) in a thousand exceeds.
pub fn threshold(pairs: &[Labelled]) -> f64 {
    let mut independent: Vec<f64> = pairs.iter().filter(|p| p.shared == 0).map(|p| p.score).collect();
    independent.sort_by(f64::total_cmp);
    let at = ((independent.len() as f64) * 0.999).ceil() as usize;
    independent.get(at.saturating_sub(1)).copied().unwrap_or(f64::INFINITY)
}

/// One row of the measured table: which pairs, how many, how many flagged.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Which pairs.
    pub label: String,
    /// How many.
    pub pairs: usize,
    /// How many scored above the threshold.
    pub flagged: usize,
}

/// The rows of the table at `threshold`: the copiers by disguise and by regions copied, then
/// every pair by regions shared.
pub fn rows(pairs: &[Labelled], threshold: f64) -> Vec<Row> {
    let row = |label: String, keep: &dyn Fn(&Labelled) -> bool| {
        let kept: Vec<&Labelled> = pairs.iter().filter(|p| keep(p)).collect();
        Row { label, pairs: kept.len(), flagged: kept.iter().filter(|p| p.score > threshold).count() }
    };
    let mut rows = Vec::new();
    for how in options().into_iter().skip(1) {
        let name = how.iter().map(|d| d.name()).collect::<Vec<_>>().join(" + ");
        rows.push(row(format!("copied 4 or all, disguise: {name}"), &|p| {
            p.copy.is_some_and(|(n, d)| n != Copied::Some(2) && d == how)
        }));
    }
    for copied in COPIED {
        let name = match copied {
            Copied::Some(n) => format!("{n}"),
            Copied::All => "all".to_string(),
        };
        rows.push(row(format!("copied {name} regions, any disguise"), &|p| {
            p.copy.is_some_and(|(n, _)| n == copied)
        }));
    }
    let most = pairs.iter().map(|p| p.shared).max().unwrap_or(0);
    for shared in 0..=most {
        rows.push(row(format!("sharing {shared} regions (copied or drawn)"), &|p| p.shared == shared));
    }
    rows
}

/// The area under the precision-recall curve of the scores, a pair sharing 2 or more regions
/// being a positive: average precision, the mean over positives of the precision at their score
/// (ties ranked together).
pub fn average_precision(pairs: &[Labelled]) -> f64 {
    let mut sorted: Vec<&Labelled> = pairs.iter().collect();
    sorted.sort_by(|a, b| b.score.total_cmp(&a.score));
    let positives = sorted.iter().filter(|p| p.shared >= 2).count();
    let (mut seen, mut hits, mut sum) = (0, 0, 0.0);
    let mut i = 0;
    while i < sorted.len() {
        // At least one: a NaN score (never made) would otherwise stop `i` from moving.
        let tie = sorted[i..].iter().take_while(|p| p.score.total_cmp(&sorted[i].score).is_eq()).count();
        let tie_hits = sorted[i..i + tie].iter().filter(|p| p.shared >= 2).count();
        seen += tie;
        hits += tie_hits;
        sum += tie_hits as f64 * hits as f64 / seen as f64;
        i += tie;
    }
    if positives == 0 {
        0.0
    } else {
        sum / positives as f64
    }
}
