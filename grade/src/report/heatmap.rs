//! Pictures of where two images differ, over a faint grey copy of the reference so the scene
//! stays recognisable: local dissimilarity `1 − SSIM`, from black (same) through red to yellow
//! (`1 − SSIM ≥ 0.5`). A noisy scene's picture is [`tile_map`](mod@crate::report::tile_map).

use image::{Rgb, RgbImage};

use crate::ssim::SsimMap;

/// The grey level of a reference pixel, 0 to 1.
pub(crate) fn grey(reference: &RgbImage, x: u32, y: u32) -> f64 {
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
