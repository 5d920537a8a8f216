//! A picture of where two images differ: local dissimilarity `1 − SSIM`, from black (same)
//! through red to yellow (`1 − SSIM ≥ 0.5`), over a faint grey copy of the reference so the
//! scene stays recognisable.

use image::{Rgb, RgbImage};

use crate::ssim::SsimMap;

/// The heat map of `ssim` over `reference`.
pub fn heatmap(ssim: &SsimMap, reference: &RgbImage) -> RgbImage {
    RgbImage::from_fn(reference.width(), reference.height(), |x, y| {
        let t = ((1.0 - ssim.at(x as usize, y as usize)) / 0.5).clamp(0.0, 1.0);
        let heat = [(2.0 * t).min(1.0), (2.0 * t - 1.0).max(0.0), 0.0];
        let p = reference.get_pixel(x, y);
        let grey = (p[0] as f64 + p[1] as f64 + p[2] as f64) / (3.0 * 255.0);
        Rgb(heat.map(|h| ((0.2 * grey + 0.8 * h) * 255.0).round() as u8))
    })
}
