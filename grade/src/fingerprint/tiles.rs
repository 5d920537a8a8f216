//! A tile-tested scene's fingerprint: not a thumbnail (16 noisy renders' mean barely differs from
//! the reference's in a 64-pixel picture for many Monte Carlo mistakes) but the tile means the
//! tile test measures, each with its standard error.
//!
//! **Distance.** Between two sets of tile means `a` and `b` (each the mean of several renders),
//! per tile `k` and channel: `z_k = (a_k − b_k) / sqrt(se_a,k² + se_b,k²)`, Welch's statistic.
//! The distance is their root mean square, `sqrt(mean z_k²)`, over the values that tell something
//! (a tile without noise on both sides that agrees, a black one, is left out): about 1 when both
//! come from the same code at independent seeds, larger the more tiles differ, and by how much.
//! A student's renders are compared so with each mistake's (rendered at a seed no grade uses) and
//! with the expected means carrying the error a correct set of as many graded renders has
//! ([`crate::noisy::NoisyVerdict::expected`]), so both distances use one yardstick. The likeness
//! [`crate::fingerprint`] ranks by is `−ln(distance)`, so a margin between two likenesses is the
//! log of the ratio of their distances.

use image::RgbImage;
use raylab_base::image_io::encode_channel;
use raylab_base::stats::Summary;
use serde::{Deserialize, Serialize};

/// A `z²` larger than this counts as this (a tile without noise on both sides, but different):
/// one such tile then weighs as much as a million agreeing ones, not infinitely.
pub const MAX_Z2: f64 = 1e6;

/// Distances are floored here (renders identical to a mistake's, same seeds): `−ln` stays finite.
pub const MIN_DISTANCE: f64 = 1e-3;

/// Tile means with their standard errors, row-major, and the tiles across, to draw them.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TileSignature {
    /// Tiles per row.
    pub across: u32,
    /// Per tile, the mean radiance of each channel (linear).
    pub means: Vec<[f32; 3]>,
    /// Per tile, the squared standard error of each mean (`variance / n`).
    pub squared_errors: Vec<[f32; 3]>,
}

impl TileSignature {
    /// The signature of tile summaries (each over renders), `across` tiles per row. Values are
    /// kept to 5 significant digits: a fingerprint file stays small, and the distance changes by
    /// far less than its noise.
    pub fn of(summaries: &[[Summary; 3]], across: u32) -> TileSignature {
        let short = |x: f64| -> f32 {
            if x == 0.0 || !x.is_finite() {
                return x as f32;
            }
            let scale = 10f64.powi(4 - x.abs().log10().floor() as i32);
            ((x * scale).round() / scale) as f32
        };
        TileSignature {
            across,
            means: summaries.iter().map(|t| t.map(|c| short(c.mean))).collect(),
            squared_errors: summaries.iter().map(|t| t.map(|c| short(c.variance_of_mean()))).collect(),
        }
    }

    /// The root mean square of Welch's `z` over the tiles and channels that tell something (a
    /// value without noise on both sides that agrees is left out: black tiles say nothing),
    /// floored at [`MIN_DISTANCE`]; `None` if the signatures do not match, a value is not finite
    /// or an error is negative, or no value tells anything.
    pub fn distance(&self, other: &TileSignature) -> Option<f64> {
        let n = self.means.len();
        let matching = [self.squared_errors.len(), other.means.len(), other.squared_errors.len()];
        if n == 0 || matching.iter().any(|&m| m != n) {
            return None;
        }
        let (mut sum, mut count) = (0.0, 0usize);
        for k in 0..n {
            for c in 0..3 {
                let (a, b) = (self.means[k][c] as f64, other.means[k][c] as f64);
                let (sa, sb) = (self.squared_errors[k][c] as f64, other.squared_errors[k][c] as f64);
                let (d2, se2) = ((a - b).powi(2), sa + sb);
                if !d2.is_finite() || !se2.is_finite() || sa < 0.0 || sb < 0.0 {
                    return None;
                }
                match (d2 == 0.0, se2 == 0.0) {
                    (true, true) => continue,
                    (false, true) => sum += MAX_Z2,
                    _ => sum += (d2 / se2).min(MAX_Z2),
                }
                count += 1;
            }
        }
        (count > 0).then(|| (sum / count as f64).sqrt().max(MIN_DISTANCE))
    }

    /// The tile means as a picture, one pixel per tile (sRGB), to show beside a render.
    pub fn mosaic(&self) -> RgbImage {
        let across = self.across.max(1);
        let down = (self.means.len() as u32).div_ceil(across);
        RgbImage::from_fn(across, down.max(1), |x, y| {
            let mean = self.means.get((y * across + x) as usize).copied().unwrap_or_default();
            image::Rgb(mean.map(encode_channel))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(mean: f64, variance: f64) -> Summary {
        Summary { mean, variance, n: 16.0 }
    }

    /// Four tiles of one grey, each with standard error 0.01.
    fn tiles(means: [f64; 4]) -> TileSignature {
        let summaries: Vec<[Summary; 3]> = means.iter().map(|&m| [summary(m, 16.0 * 1e-4); 3]).collect();
        TileSignature::of(&summaries, 2)
    }

    #[test]
    fn the_distance_is_the_rms_of_welchs_z_over_tiles_and_channels() {
        let a = tiles([0.5, 0.5, 0.5, 0.5]);
        // One tile off by 0.1, with a combined error of sqrt(2) · 0.01: z² = 50 in 3 of 12 values.
        let b = tiles([0.6, 0.5, 0.5, 0.5]);
        let want = (3.0 * 50.0 / 12.0f64).sqrt();
        assert!((a.distance(&b).unwrap() - want).abs() < 1e-3, "{:?} vs {want}", a.distance(&b));
        assert_eq!(a.distance(&a), Some(MIN_DISTANCE), "identical means: the floor");
        assert_eq!(a.distance(&TileSignature::of(&[], 2)), None, "tiles that do not match");
    }

    #[test]
    fn tiles_without_noise_count_as_very_far_only_when_they_differ() {
        let still = |m: f64| TileSignature::of(&[[summary(m, 0.0); 3]], 1);
        assert_eq!(still(0.0).distance(&still(0.0)), None, "two black tiles say nothing");
        assert_eq!(still(0.0).distance(&still(0.2)), Some(MAX_Z2.sqrt()));
        // A black tile beside a noisy one: only the noisy one counts (z = 0.1 / sqrt(2e-4)).
        let pair = |m: f64| TileSignature::of(&[[summary(0.0, 0.0); 3], [summary(m, 16.0 * 1e-4); 3]], 2);
        let want = 0.1 / (2e-4f64).sqrt();
        assert!((pair(0.5).distance(&pair(0.6)).unwrap() - want).abs() < 1e-3);
    }

    /// Each side's own error counts (a sum, not twice one side), large `z²` are capped, and
    /// malformed signatures are no match.
    #[test]
    fn errors_add_large_values_are_capped_and_malformed_signatures_do_not_compare() {
        let one = |m: f64, se2: f64| {
            TileSignature::of(&[[Summary { mean: m, variance: se2 * 16.0, n: 16.0 }; 3]], 1)
        };
        // z² = 0.01 / (1e-4 + 3e-4) = 25.
        assert!((one(0.5, 1e-4).distance(&one(0.6, 3e-4)).unwrap() - 5.0).abs() < 1e-3);
        // z² = 1 / 1e-12 = 1e12, capped.
        assert_eq!(one(0.0, 1e-13).distance(&one(1.0, 1e-13)), Some(MAX_Z2.sqrt()));
        let mut negative = one(0.5, 1e-4);
        negative.squared_errors[0][0] = -1.0;
        assert_eq!(negative.distance(&one(0.5, 1e-4)), None, "a negative error");
        let mut short = one(0.5, 1e-4);
        short.squared_errors.clear();
        assert_eq!(short.distance(&one(0.5, 1e-4)), None, "errors missing");
    }

    #[test]
    fn values_keep_five_significant_digits_and_the_mosaic_one_pixel_per_tile() {
        let s = TileSignature::of(&[[summary(0.123456789, 0.0); 3]], 1);
        assert_eq!(s.means[0][0], 0.12346);
        let m = tiles([0.0, 1.0, 0.2, 0.2]).mosaic();
        assert_eq!(m.dimensions(), (2, 2));
        assert_eq!((m.get_pixel(0, 0).0, m.get_pixel(1, 0).0), ([0; 3], [255; 3]), "sRGB, row-major");
    }
}
