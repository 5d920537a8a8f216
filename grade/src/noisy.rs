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
//! means against the reference's `R`), and an F-test of the submission's variance against the
//! solution's at the same spp, one-sided: a tile far noisier than the solution's fails (a wrong
//! pdf can be unbiased and still useless). All tests of an image form one family with the
//! family-wise error rate `alpha` fixed in advance: each is run at Šidák's level, so a correct
//! submission fails anywhere in the image with probability `alpha`. See [`raylab::stats`].

use raylab::film::Film;
use raylab::stats::{f_upper, sidak, welch, Summary};

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
    /// The reference solution's spread at the graded spp: how noisy a correct render is.
    pub solution: Vec<[Summary; 3]>,
}

/// Why one tile failed.
#[derive(Clone, Debug, PartialEq)]
pub struct TileFailure {
    /// The tile's index (row-major).
    pub tile: usize,
    /// One line: which channel, which test, the values.
    pub reason: String,
}

/// The outcome of comparing one image.
#[derive(Clone, Debug, PartialEq)]
pub struct NoisyVerdict {
    /// The tiles that failed, each once (its first failing test).
    pub failures: Vec<TileFailure>,
    /// The level each test was run at (Šidák, from the family-wise rate).
    pub level: f64,
    /// The smallest p-value of any test.
    pub min_p: f64,
}

impl NoisyVerdict {
    /// Whether every tile passed.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// Tests the summary of a submission's renders against `reference` with the family-wise error
/// rate `alpha` (module docs).
pub fn compare(submission: &[[Summary; 3]], reference: &NoisyReference, alpha: f64) -> NoisyVerdict {
    // Two tests per tile and channel.
    let level = sidak(alpha, submission.len() * 3 * 2);
    let mut failures = Vec::new();
    let mut min_p: f64 = 1.0;
    for (tile, ((got, want), solution)) in
        submission.iter().zip(&reference.expected).zip(&reference.solution).enumerate()
    {
        let mut first: Option<String> = None;
        for c in 0..3 {
            let means = welch(&got[c], &want[c]);
            let (d1, d2) = (got[c].n - 1.0, solution[c].n - 1.0);
            // A solution tile without noise (all black, say) leaves the mean test to judge.
            let spread = if solution[c].variance > 0.0 {
                f_upper(got[c].variance / solution[c].variance, d1, d2)
            } else {
                1.0
            };
            min_p = min_p.min(means.p).min(spread);
            if first.is_none() && means.p < level {
                first = Some(format!(
                    "{} mean {:.4} vs {:.4} expected (p = {:.1e})",
                    CHANNELS[c], got[c].mean, want[c].mean, means.p
                ));
            } else if first.is_none() && spread < level {
                first = Some(format!(
                    "{} noise {:.1}x the solution's (p = {spread:.1e})",
                    CHANNELS[c],
                    (got[c].variance / solution[c].variance).sqrt()
                ));
            }
        }
        if let Some(reason) = first {
            failures.push(TileFailure { tile, reason });
        }
    }
    NoisyVerdict { failures, level, min_p }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab::math::Vec3;
    use raylab::rng::Rng;

    /// A standard normal number (Box-Muller).
    fn normal(rng: &mut Rng) -> f64 {
        let (u1, u2) = (1.0 - rng.next_f32() as f64, rng.next_f32() as f64);
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// A 64 × 32 film (eight 16 × 16 tiles) of a smooth image plus per-pixel Gaussian noise of
    /// standard deviation `sigma`, `scale` applied to tile 5 (its mean) and `noisier` to tile 6's
    /// noise.
    fn render(rng: &mut Rng, sigma: f64, scale: f32, noisier: f64) -> Film {
        let mut film = Film::new(64, 32);
        for y in 0..32 {
            for x in 0..64 {
                let tile = (y / 16) * 4 + x / 16;
                let truth = Vec3::new(0.2 + x as f32 / 100.0, 0.5, 0.1 + y as f32 / 50.0);
                let truth = if tile == 5 { truth * scale } else { truth };
                let s = if tile == 6 { sigma * noisier } else { sigma };
                let noise = Vec3::new(normal(rng) as f32, normal(rng) as f32, normal(rng) as f32) * s as f32;
                film.set(x, y, truth + noise);
            }
        }
        film
    }

    fn summary_of(rng: &mut Rng, count: usize, sigma: f64, scale: f32, noisier: f64) -> Vec<[Summary; 3]> {
        let renders: Vec<Vec<[f64; 3]>> =
            (0..count).map(|_| tile_means(&render(rng, sigma, scale, noisier), 16)).collect();
        summarise(&renders)
    }

    fn reference(rng: &mut Rng) -> NoisyReference {
        // The expected value from 8 renders 16x less noisy (256 times the samples), the spread
        // from 8 renders at the graded noise.
        NoisyReference {
            expected: summary_of(rng, 8, 0.05 / 16.0, 1.0, 1.0),
            solution: summary_of(rng, 8, 0.05, 1.0, 1.0),
        }
    }

    /// Tile means are plain averages over the tile's pixels, edge tiles cut.
    #[test]
    fn tile_means_average_each_tiles_pixels() {
        let pixels = (0..15).map(|i| Vec3::splat(i as f32)).collect();
        let film = Film::from_pixels(5, 3, pixels);
        let means = tile_means(&film, 4);
        // Tiles: x 0-3 and 4, y 0-2. Row y has values 5y .. 5y + 4.
        assert_eq!(means.len(), 2);
        assert_eq!(
            means[0][0],
            (0..3).flat_map(|y| (0..4).map(move |x| (5 * y + x) as f64)).sum::<f64>() / 12.0
        );
        assert_eq!(means[1][1], (4.0 + 9.0 + 14.0) / 3.0);
    }

    /// Correct submissions (the same distribution as the solution) fail at about the rate alpha:
    /// in 200 trials at alpha = 0.05 the count of failures is binomial(200, ≤ 0.05): mean ≤ 10,
    /// standard deviation ≤ 3.1; more than 22 (4 standard deviations above) would mean the test
    /// is miscalibrated.
    #[test]
    fn correct_renders_fail_at_most_at_the_family_wise_rate() {
        let mut rng = Rng::new(91, 0);
        let reference = reference(&mut rng);
        let failed = (0..200)
            .filter(|_| !compare(&summary_of(&mut rng, 8, 0.05, 1.0, 1.0), &reference, 0.05).passed())
            .count();
        assert!(failed <= 22, "{failed} of 200 correct submissions failed at alpha = 0.05");
    }

    /// A 3% error in one tile's mean, and 8 times the solution's noise in another, are each found
    /// in that tile, and only there, in (nearly) every trial.
    #[test]
    fn a_biased_tile_and_a_noisier_tile_fail_where_they_are() {
        let mut rng = Rng::new(92, 0);
        let reference = reference(&mut rng);
        let (mut biased, mut noisy, mut elsewhere) = (0, 0, 0);
        for _ in 0..50 {
            let verdict = compare(&summary_of(&mut rng, 8, 0.05, 1.03, 1.0), &reference, 0.01);
            biased += verdict.failures.iter().any(|f| f.tile == 5 && f.reason.contains("mean")) as u32;
            elsewhere += verdict.failures.iter().filter(|f| f.tile != 5).count();
            let verdict = compare(&summary_of(&mut rng, 8, 0.05, 1.0, 8.0), &reference, 0.01);
            noisy += verdict.failures.iter().any(|f| f.tile == 6 && f.reason.contains("noise")) as u32;
        }
        assert!(biased >= 48 && noisy >= 48, "biased {biased}/50, noisy {noisy}/50");
        assert!(elsewhere <= 3, "{elsewhere} failures outside the biased tile");
    }
}
