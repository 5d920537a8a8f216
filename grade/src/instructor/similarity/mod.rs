//! Copied solutions across a class: which pairs of submissions are more alike, region by region,
//! than independent solutions of the same regions are.
//!
//! Only the text of solution regions is compared: everything else is the starter's, the same for
//! every student. Each region's text is normalised so that disguise changes nothing
//! ([`mod@normalise`]: names bound in the region, literal spelling, whitespace, comments, layout, the
//! order of independent `let`s, dead `let`s), fingerprinted by winnowing ([`mod@winnow`], the method
//! of MOSS and Dolos: chosen over JPlag's greedy string tiling because fingerprints compare a
//! class of `n` in `n` fingerprintings and cheap set intersections, and their matches point at
//! lines), and scored against what independent implementations of that region reach ([`score`]).
//! A pair's score weighs how many of its regions are as alike as independent students' rarely are.
//!
//! It flags for a person to look at. Code written with the same assistant or tutorial can look
//! copied; a flag is a reason to talk with a student, never evidence, and it never changes a grade.

pub mod class;
pub mod disguise;
pub mod measure;
pub mod normalise;
pub mod page;
pub mod read;
pub mod score;
pub mod test_set;
pub mod winnow;

use std::collections::{BTreeMap, HashSet};

use crate::regions::allow::{MAX_NESTING, MAX_REGION_BYTES, PARSER_STACK_BYTES};
use crate::regions::lexer::{nesting, tokens};
use normalise::{normalise, Token};
use score::{copy_score, Null, RegionTexts, Weights};
use winnow::{winnow, Print};

/// The score above which a pair is flagged for a person to look at: the score at most one pair of
/// independent students in a thousand exceeds, set on classes drawn from one half of the test
/// set's authors (`grade/tests/similarity.rs` checks it is that measurement's, rounded up).
pub const FLAG_SCORE: f64 = 1.88;

/// One author's region texts: a student, an independent implementation, the solution.
#[derive(Clone, Debug, Default)]
pub struct Author {
    /// The name shown for it.
    pub name: String,
    /// Each region it wrote (`file::function`) and its body.
    pub regions: BTreeMap<String, String>,
}

/// One region text, read.
#[derive(Clone, Debug)]
pub struct Text {
    /// The body as written.
    pub body: String,
    /// Its normalised tokens.
    pub tokens: Vec<Token>,
    /// Its fingerprints.
    pub prints: Vec<Print>,
}

impl Text {
    /// Reads `body`; `None` for a body the allow list would refuse before parsing it (longer than
    /// [`MAX_REGION_BYTES`], not Rust tokens, unbalanced, nested deeper than [`MAX_NESTING`]):
    /// such a region costs the submission its points anyway, and is not compared. Called on a
    /// thread with [`PARSER_STACK_BYTES`] of stack, as the allow list parses.
    pub fn of(body: &str) -> Option<Text> {
        if body.len() > MAX_REGION_BYTES {
            return None;
        }
        match nesting(&tokens(body).ok()?) {
            (depth, true) if depth <= MAX_NESTING => {}
            _ => return None,
        }
        let tokens = normalise(body);
        let prints = winnow(&tokens);
        Some(Text { body: body.to_string(), tokens, prints })
    }
}

/// How alike a pair is in one region.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionScore {
    /// The region (`file::function`).
    pub region: String,
    /// Its similarity `S`, in `[0, 1]`.
    pub similarity: f64,
    /// `Λ`: how much likelier this similarity is for a copy than for independent work.
    pub ratio: f64,
}

/// How alike two authors are.
#[derive(Clone, Debug, PartialEq)]
pub struct Pair {
    /// The first author (a student).
    pub a: usize,
    /// The second: a student, or one of the others (the solution, an earlier class).
    pub b: usize,
    /// The regions both wrote, most unusual first.
    pub regions: Vec<RegionScore>,
    /// The log-likelihood ratio of copying over independence ([`score::copy_score`]).
    pub score: f64,
}

/// A class compared.
pub struct Comparison {
    /// The texts not compared: the author, and the region (see [`Text::of`]).
    pub refused: Vec<(usize, String)>,
    /// The regions no pair is scored on: no independent implementation of theirs to judge by.
    pub unjudged: Vec<String>,
    /// Every author: the students first, then the others.
    pub names: Vec<String>,
    /// Each author's texts.
    pub texts: Vec<BTreeMap<String, Text>>,
    /// Every pair of a student with a student or another, highest score first.
    pub pairs: Vec<Pair>,
    /// Each region's null, from the independent implementations.
    pub nulls: BTreeMap<String, Null>,
}

/// Compares every pair of `students`, and each student with each of `others` (the solution, an
/// earlier class), against the `independent` implementations of each region; `stubs` are the
/// starter's region bodies, whose fingerprints never count.
pub fn compare(
    students: &[Author],
    others: &[Author],
    independent: &[Author],
    stubs: &BTreeMap<String, String>,
) -> Comparison {
    let everyone: Vec<&Author> = students.iter().chain(others).chain(independent).collect();
    let read: Vec<BTreeMap<String, Option<Text>>> = on_parser_stack(|| {
        everyone
            .iter()
            .map(|a| a.regions.iter().map(|(r, body)| (r.clone(), Text::of(body))).collect())
            .collect()
    });
    let mut refused = Vec::new();
    let mut texts: Vec<BTreeMap<String, Text>> = Vec::new();
    for (author, regions) in read.into_iter().enumerate() {
        let mut kept = BTreeMap::new();
        for (region, text) in regions {
            match text {
                Some(text) => {
                    kept.insert(region, text);
                }
                None => refused.push((author, region)),
            }
        }
        texts.push(kept);
    }
    let independent: Vec<BTreeMap<String, Text>> = texts.split_off(students.len() + others.len());
    refused.retain(|(author, _)| *author < texts.len());
    let mut weights = BTreeMap::new();
    let mut nulls = BTreeMap::new();
    let mut unjudged = Vec::new();
    for region in stubs.keys() {
        let stub: HashSet<u64> = winnow(&normalise(&stubs[region])).into_iter().map(|p| p.hash).collect();
        let all: Vec<&[Print]> = texts
            .iter()
            .chain(&independent)
            .filter_map(|t| t.get(region))
            .map(|t| t.prints.as_slice())
            .collect();
        let w = Weights::of(&RegionTexts { prints: all, stub });
        let sample: Vec<&Text> = independent.iter().filter_map(|t| t.get(region)).collect();
        if sample.len() < 2 {
            unjudged.push(region.clone());
            continue;
        }
        let s: Vec<f64> =
            pairs_of(sample.len()).map(|(i, j)| w.similarity(&sample[i].prints, &sample[j].prints)).collect();
        nulls.insert(region.clone(), Null::of(&s));
        weights.insert(region.clone(), w);
    }
    let n = students.len();
    let mut pairs: Vec<Pair> = (0..n)
        .flat_map(|a| (a + 1..texts.len()).map(move |b| (a, b)))
        .map(|(a, b)| pair(a, b, &texts, &weights, &nulls))
        .collect();
    pairs.sort_by(|p, q| q.score.total_cmp(&p.score).then((p.a, p.b).cmp(&(q.a, q.b))));
    let names = students.iter().chain(others).map(|a| a.name.clone()).collect();
    Comparison { refused, unjudged, names, texts, pairs, nulls }
}

/// `read()` on a thread with the parser's stack (`syn` recurses on nested syntax).
fn on_parser_stack<T: Send>(read: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|scope| {
        let reading = std::thread::Builder::new().stack_size(PARSER_STACK_BYTES).spawn_scoped(scope, read);
        reading.expect("a thread starts").join().expect("reading a region never panics")
    })
}

/// Every pair `(i, j)`, `i < j < n`.
fn pairs_of(n: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..n).flat_map(move |i| (i + 1..n).map(move |j| (i, j)))
}

/// The scores of authors `a` and `b` over the regions both wrote.
fn pair(
    a: usize,
    b: usize,
    texts: &[BTreeMap<String, Text>],
    weights: &BTreeMap<String, Weights>,
    nulls: &BTreeMap<String, Null>,
) -> Pair {
    let mut regions: Vec<RegionScore> = texts[a]
        .iter()
        .filter_map(|(region, ta)| {
            let tb = texts[b].get(region)?;
            let similarity = weights.get(region)?.similarity(&ta.prints, &tb.prints);
            let ratio = nulls.get(region)?.likelihood_ratio(similarity);
            Some(RegionScore { region: region.clone(), similarity, ratio })
        })
        .collect();
    regions.sort_by(|p, q| q.ratio.total_cmp(&p.ratio).then_with(|| p.region.cmp(&q.region)));
    let score = copy_score(&regions.iter().map(|r| r.ratio).collect::<Vec<_>>());
    Pair { a, b, regions, score }
}
