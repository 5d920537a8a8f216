//! Pictures of where two images differ, over a faint grey copy of the reference so the scene
//! stays recognisable: local dissimilarity `1 − SSIM`, from black (same) through red to yellow
//! (`1 − SSIM ≥ 0.5`); and for a noisy scene the tile test's verdict per tile.

use image::{Rgb, RgbImage};

use crate::noisy::NoisyVerdict;
use crate::ssim::SsimMap;

/// The grey level of a reference pixel, 0 to 1.
fn grey(reference: &RgbImage, x: u32, y: u32) -> f64 {
    let p = reference.get_pixel(x, y);
    (p[0] as f64 + p[1] as f64 + p[2] as f64) / (3.0 * 255.0)
}

/// The heat map of `ssim` over `reference`.
pub fn heatmap(ssim: &SsimMap, reference: &RgbImage) -> RgbImage {
    RgbImage::from_fn(reference.width(), reference.height(), |x, y| {
        let t = ((1.0 - ssim.at(x as usize, y as usize)) / 0.5).clamp(0.0, 1.0);
        let heat = [(2.0 * t).min(1.0), (2.0 * t - 1.0).max(0.0), 0.0];
        let grey = grey(reference, x, y);
        Rgb(heat.map(|h| ((0.2 * grey + 0.8 * h) * 255.0).round() as u8))
    })
}

/// The tile test's map: a failing tile red, a passing one from clear (p near 1) to amber as its
/// smallest p-value nears the test's level (on a log scale), tile edges drawn faintly.
pub fn tile_map(verdict: &NoisyVerdict, tile: u32, reference: &RgbImage) -> RgbImage {
    let failed: Vec<usize> = verdict.failures.iter().map(|f| f.tile).collect();
    let tiles_x = reference.width().div_ceil(tile);
    RgbImage::from_fn(reference.width(), reference.height(), |x, y| {
        let index = ((y / tile) * tiles_x + x / tile) as usize;
        let grey = grey(reference, x, y);
        let edge = x % tile == 0 || y % tile == 0;
        let (colour, weight) = if failed.contains(&index) {
            ([1.0, 0.1, 0.1], 0.75)
        } else {
            let p = verdict.tile_p.get(index).copied().unwrap_or(1.0).max(f64::MIN_POSITIVE);
            ([1.0, 0.7, 0.0], 0.6 * (p.ln() / verdict.level.ln()).clamp(0.0, 1.0))
        };
        let weight = if edge { weight.max(0.3) } else { weight };
        let base = if edge { 0.5 } else { 0.4 * grey };
        Rgb(colour.map(|c: f64| (((1.0 - weight) * base + weight * c) * 255.0).round() as u8))
    })
}
