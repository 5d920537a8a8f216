//! Grading noisy (Monte Carlo) renders by a per-tile statistical test, not by SSIM: two correct
//! renders at 16 spp differ pixel by pixel, but their tile means agree within their noise.
//!
//! **The data.** The grader renders the submission `K` times with different seeds, as linear float
//! films (PFM), and summarises each render by the mean radiance of every `T × T` tile and colour
//! channel; across the `K` renders that gives, per tile and channel, a sample mean and variance
//! that the grader computed itself (never a variance the graded code reports). The reference is
//! the same summary of the reference solution: the tile means of `R` renders at a high spp (the
//! expected value, with its own small variance), and the spread of its tile means at the graded
//! spp (how noisy a correct render is).
//!
//! **The tests**, per tile and channel: Welch's t-test of equal means (the submission's `K` tile
//! means against the reference's `R`), and a one-sided rank test of the spread: the distances of
//! the submission's `K` tile means from the expected mean against those of the solution's renders
//! at the same spp (Mann-Whitney, [`RankTest`]): a tile far noisier than the solution's fails (a
//! wrong pdf can be unbiased and still useless). The spread test is a rank test, not an F-test of
//! variances, because tile means are not always near normal: a tile whose light comes from one
//! partly covered pixel, or from a rare bright path, has a few renders far out (measured on
//! glass_light over 400 correct renders: excess kurtosis 65 in a corner tile), and an F-test at the
//! levels below then fails correct renders (11% of them there, measured by resampling those
//! renders), where the rank test's tail is exact for any distribution (0 of 2000). In Welch's test
//! the submission's variance is never taken below the solution's: a correct render is at least
//! that noisy, and renders that hardly vary (code that ignores the seed, or returns fixed values)
//! must not be judged by the reference's few degrees of freedom alone.
//!
//! **A structural check** beside the tests: a tile whose spread is below [`MIN_SPREAD`] times the
//! solution's (standard deviations) fails: such renders do not vary with the seed, so they are
//! not independent estimates. It is not a test at the level below: correct renders can be far
//! less spread than a solution whose renders hold one rare bright sample (measured: a correct
//! tile at 0.17 times the solution's spread), where a deterministic render has exactly 0. All
//! tests of an image form one family with the family-wise error rate `alpha` fixed in advance:
//! each is run at Šidák's level, so a correct submission fails anywhere in the image with
//! probability at most `alpha`. See [`raylab_base::stats`].
//! A tile whose numbers are not finite (NaN or infinite radiance) fails, whatever its p-values.
//!
//! **The seeds** are fixed in advance and never shared between the three kinds of render, so the
//! graded renders are independent of the reference's: see [`graded_seed`], [`expected_seed`],
//! [`solution_seed`].

use std::path::Path;

use serde::{Deserialize, Serialize};

use raylab_base::film::Film;
use raylab_base::stats::{welch, Summary};

use crate::stats::{sidak, RankTest};

use crate::file_error::{read_json, FileError};

/// Below this fraction of the solution's standard deviation a tile's renders count as not
/// varying with the seed (module docs): 17 times below the lowest a correct render was seen at.
pub const MIN_SPREAD: f64 = 0.01;

/// The seed of the graded code's `k`-th render of a scene whose seed is `base` (the rubric's, or
/// one calibration tries): `base · 2¹⁶ + k`, so that different bases never share a render.
pub fn graded_seed(base: u64, k: u32) -> u64 {
    (base << 16) | k as u64
}

/// The seed of the reference solution's `r`-th high-spp render: far above every graded seed.
pub fn expected_seed(r: u32) -> u64 {
    (1 << 40) | r as u64
}

/// The seed of the reference solution's `s`-th render at the graded spp.
pub fn solution_seed(s: u32) -> u64 {
    (1 << 41) | s as u64
}

/// The tile means of one render: per tile (row-major, tiles of `tile × tile` pixels, the last
/// row and column of tiles cut at the image's edge) the mean of each channel.
pub fn tile_means(film: &Film, tile: u32) -> Vec<[f64; 3]> {
    let (tiles_x, tiles_y) = (film.width().div_ceil(tile), film.height().div_ceil(tile));
    let mut sums = vec![([0.0f64; 3], 0u32); (tiles_x * tiles_y) as usize];
    for y in 0..film.height() {
        for x in 0..film.width() {
            let (sum, count) = &mut sums[((y / tile) * tiles_x + x / tile) as usize];
            let p = film.get(x, y);
            for (s, c) in sum.iter_mut().zip(p.to_array()) {
                *s += c as f64;
            }
            *count += 1;
        }
    }
    sums.into_iter().map(|(sum, count)| sum.map(|s| s / count as f64)).collect()
}

/// The top-left pixel of tile `index` (row-major) of an image `width` pixels wide.
pub fn tile_origin(index: usize, tile: u32, width: u32) -> (u32, u32) {
    let tiles_x = width.div_ceil(tile) as usize;
    ((index % tiles_x) as u32 * tile, (index / tiles_x) as u32 * tile)
}

/// Per tile and channel, the summary of the tile means of several renders.
pub fn summarise(renders: &[Vec<[f64; 3]>]) -> Vec<[Summary; 3]> {
    let tiles = renders.first().map_or(0, Vec::len);
    (0..tiles).map(|t| [0, 1, 2].map(|c| Summary::of(renders.iter().map(|r| r[t][c])))).collect()
}

/// What a submission's renders are compared with.
#[derive(Clone, Debug)]
pub struct NoisyReference {
    /// The expected tile means: the reference solution's at a high spp, over several seeds.
    pub expected: Vec<[Summary; 3]>,
    /// The reference solution's renders at the graded spp (each one's tile means): how noisy a
    /// correct render is.
    pub solution: Vec<Vec<[f64; 3]>>,
}

/// Why one tile failed: its first failing test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileFailure {
    /// The tile's index (row-major).
    pub tile: usize,
    /// The colour channel tested.
    pub channel: Channel,
    /// The test it failed, with its values.
    pub problem: TileProblem,
}

/// A colour channel of a film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Red.
    Red,
    /// Green.
    Green,
    /// Blue.
    Blue,
}

/// The test a tile's channel failed ([`crate::report::reasons::tile_problem_text`] words it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TileProblem {
    /// The mean of the submission's tile means is infinite or NaN.
    NotFinite {
        /// That mean.
        mean: f64,
    },
    /// The renders barely differ from seed to seed (below [`MIN_SPREAD`] of the solution's spread).
    NoVariation {
        /// The submission's spread over the solution's.
        spread_ratio: f64,
    },
    /// The mean is off the expected one (Welch's test).
    Mean {
        /// The submission's mean.
        got: f64,
        /// The expected mean.
        want: f64,
        /// The test's p-value.
        p: f64,
    },
    /// The renders scatter more around the expected mean than the solution's (rank test).
    Noise {
        /// The submission's spread over the solution's.
        spread_ratio: f64,
        /// The test's p-value.
        p: f64,
    },
}

/// Which way a tile is off, by its least likely test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Its mean is below the expected one.
    Darker,
    /// Its mean is above the expected one.
    Brighter,
    /// Its spread is off (too noisy, or not varying with the seed), or its numbers are not finite.
    Noise,
}

/// One tile's smallest p-value over its tests and channels, and which way that test points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileOutcome {
    /// The p-value (0 for numbers that are not finite or renders that do not vary).
    pub p: f64,
    /// Which way.
    pub direction: Direction,
}

/// The outcome of comparing one image.
#[derive(Clone, Debug, PartialEq)]
pub struct NoisyVerdict {
    /// The tiles that failed, each once (its first failing test).
    pub failures: Vec<TileFailure>,
    /// The level each test was run at (Šidák, from the family-wise rate).
    pub level: f64,
    /// Per tile (row-major), its outcome.
    pub tiles: Vec<TileOutcome>,
    /// The p-value above which a tile is as a correct render's would be ([`CALM_RATE`]): a map
    /// colours only the tiles below it.
    pub calm: f64,
    /// Per tile, the submission's tile means over its renders (what naming a mistake compares).
    pub yours: Vec<[Summary; 3]>,
    /// Per tile, the expected means, with the spread of the solution's renders at the graded spp
    /// and the submission's count of renders: the summary a correct submission would have, so
    /// that its distance to the expected means is measured as the distance between two
    /// submissions is ([`crate::fingerprint::tiles`]).
    pub expected: Vec<[Summary; 3]>,
}

impl NoisyVerdict {
    /// Whether every tile passed.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

const CHANNELS: [Channel; 3] = [Channel::Red, Channel::Green, Channel::Blue];

/// The rate at which a correct render has some tile below [`NoisyVerdict::calm`], at most: a map
/// of a correct render is uncoloured 19 times in 20.
pub const CALM_RATE: f64 = 0.05;

/// Tests a submission's renders (each one's tile means) against `reference` with the family-wise
/// error rate `alpha` (module docs).
pub fn compare(submission: &[Vec<[f64; 3]>], reference: &NoisyReference, alpha: f64) -> NoisyVerdict {
    let (failures, tiles) = test_tiles(submission, reference, sidak(alpha, tests(submission)));
    let calm = calm_level(reference, submission.len(), tests(submission));
    NoisyVerdict {
        failures,
        level: sidak(alpha, tests(submission)),
        tiles,
        calm,
        yours: summarise(submission),
        expected: as_graded(reference, submission.len()),
    }
}

/// The expected means with the spread a correct set of `renders` graded renders has (the
/// solution's, at the graded spp): see [`NoisyVerdict::expected`].
fn as_graded(reference: &NoisyReference, renders: usize) -> Vec<[Summary; 3]> {
    let spread = summarise(&reference.solution);
    let graded = |e: &Summary, s: &Summary| Summary { mean: e.mean, variance: s.variance, n: renders as f64 };
    reference.expected.iter().zip(&spread).map(|(e, s)| [0, 1, 2].map(|c| graded(&e[c], &s[c]))).collect()
}

/// Two tests per tile and channel.
fn tests(renders: &[Vec<[f64; 3]>]) -> usize {
    renders.first().map_or(0, Vec::len) * 3 * 2
}

/// Each tile's outcome, and the tiles that fail at `level`.
fn test_tiles(
    submission: &[Vec<[f64; 3]>],
    reference: &NoisyReference,
    level: f64,
) -> (Vec<TileFailure>, Vec<TileOutcome>) {
    let rank = RankTest::new(submission.len(), reference.solution.len());
    let channel = |renders: &[Vec<[f64; 3]>], tile: usize, c: usize| -> Vec<f64> {
        renders.iter().map(|r| r[tile][c]).collect()
    };
    let mut failures = Vec::new();
    let mut outcomes = Vec::new();
    for (tile, want) in reference.expected.iter().enumerate().take(submission.first().map_or(0, Vec::len)) {
        let mut worst = TileOutcome { p: 1.0, direction: Direction::Noise };
        let mut first = None;
        for (c, name) in CHANNELS.into_iter().enumerate() {
            let (got, solution) = (channel(submission, tile, c), channel(&reference.solution, tile, c));
            let (outcome, problem) = test_channel(&got, &solution, &want[c], &rank, level);
            if outcome.p < worst.p {
                worst = outcome;
            }
            first = first.or(problem.map(|problem| TileFailure { tile, channel: name, problem }));
        }
        outcomes.push(worst);
        failures.extend(first);
    }
    (failures, outcomes)
}

/// One channel of one tile: the submission's tile means `got` and the solution's at the same
/// spp against the expected mean `want`. Its outcome, and why it fails at `level` if it does.
fn test_channel(
    got: &[f64],
    solution: &[f64],
    want: &Summary,
    rank: &RankTest,
    level: f64,
) -> (TileOutcome, Option<TileProblem>) {
    let (g, s) = (Summary::of(got.iter().copied()), Summary::of(solution.iter().copied()));
    let broken = |problem| (TileOutcome { p: 0.0, direction: Direction::Noise }, Some(problem));
    if !(g.mean.is_finite() && g.variance.is_finite()) {
        return broken(TileProblem::NotFinite { mean: g.mean });
    }
    // A solution tile without noise (all black, say) leaves the mean test to judge.
    let spread_ratio = if s.variance > 0.0 { (g.variance / s.variance).sqrt() } else { 1.0 };
    if spread_ratio < MIN_SPREAD {
        return broken(TileProblem::NoVariation { spread_ratio });
    }
    let means = welch(&Summary { variance: g.variance.max(s.variance), ..g }, want);
    let spread = if s.variance > 0.0 {
        let distance = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| (x - want.mean).abs()).collect() };
        rank.p_greater(&distance(got), &distance(solution))
    } else {
        1.0
    };
    let problem = if means.p < level {
        Some(TileProblem::Mean { got: g.mean, want: want.mean, p: means.p })
    } else if spread < level {
        Some(TileProblem::Noise { spread_ratio, p: spread })
    } else {
        None
    };
    // A mean off its mark also spreads the distances from it: the mean test names the direction
    // whenever it fails.
    let outcome = if means.p <= spread || means.p < level {
        let direction = if g.mean < want.mean { Direction::Darker } else { Direction::Brighter };
        TileOutcome { p: means.p.min(spread), direction }
    } else {
        TileOutcome { p: spread, direction: Direction::Noise }
    };
    (outcome, problem)
}

/// The p-value a correct render's tiles stay above but with probability [`CALM_RATE`]: Šidák's
/// level for that rate over `tests` tests, lowered to what the solution's own renders at the
/// graded spp reach, taken `renders` at a time (each group against the spread of the others), for
/// a test whose p-values are not quite uniform.
fn calm_level(reference: &NoisyReference, renders: usize, tests: usize) -> f64 {
    let solution = &reference.solution;
    // Each group needs others beside it to measure a spread with.
    let groups = match renders {
        0 => 0,
        r if solution.len() >= r + 2 => solution.len() / r,
        _ => 0,
    };
    let mut calm = sidak(CALM_RATE, tests);
    for g in 0..groups {
        let group = &solution[g * renders..(g + 1) * renders];
        let others = [&solution[..g * renders], &solution[(g + 1) * renders..]].concat();
        let without = NoisyReference { expected: reference.expected.clone(), solution: others };
        let (_, outcomes) = test_tiles(group, &without, 0.0);
        calm = outcomes.iter().map(|o| o.p).fold(calm, f64::min);
    }
    calm
}

/// The reference solution's tile means, as `grader update-references` writes them beside the
/// reference image (`reference/<scene>.tiles.json`): every render's, so the file says exactly
/// what the summaries were computed from.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TileFile {
    /// Side of the tiles, in pixels.
    pub tile: u32,
    /// Samples per pixel of the `expected` renders...
    pub reference_spp: u32,
    /// ...and of the `solution` renders (the graded spp).
    pub spp: u32,
    /// Per high-spp render (seeds [`expected_seed`] 0, 1, ...), its tile means.
    pub expected: Vec<Vec<[f64; 3]>>,
    /// Per render at the graded spp (seeds [`solution_seed`] 0, 1, ...), its tile means.
    pub solution: Vec<Vec<[f64; 3]>>,
}

impl TileFile {
    /// The summaries the test compares with.
    pub fn reference(&self) -> NoisyReference {
        NoisyReference { expected: summarise(&self.expected), solution: self.solution.clone() }
    }

    /// Reads the file.
    pub fn read(path: &Path) -> Result<TileFile, FileError> {
        read_json(path)
    }

    /// Writes the file (to a temporary name, then renamed).
    pub fn write(&self, path: &Path) -> Result<(), FileError> {
        let text = serde_json::to_string(self).expect("a tile file holds only numbers and lists");
        raylab_base::image_io::write_file_atomic(path, text.as_bytes())
            .map_err(|e| FileError::unwritable(path, &e))
    }
}

#[cfg(test)]
mod tests;
