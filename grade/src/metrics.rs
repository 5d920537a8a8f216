//! Scoring one render against its reference: the numbers a rubric's checks ask for.

use image::RgbImage;

use crate::features::Masks;
use crate::rubric::{Check, Mask, Metric, Threshold};
use crate::ssim::{SizeMismatch, SsimMap};
use raylab_base::image_io::srgb_to_linear;

/// Side of the tiles of [`worst_tile_error`], in pixels.
pub const TILE: u32 = 32;

/// A render and its reference, with what the checks share computed once.
pub struct Comparison<'a> {
    render: &'a RgbImage,
    reference: &'a RgbImage,
    masks: &'a Masks,
    ssim: SsimMap,
}

/// The value of one check, and whether it passed.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The number the check asks for.
    pub value: f64,
    /// Whether it meets the threshold (NaN never does).
    pub passed: bool,
}

impl<'a> Comparison<'a> {
    /// Compares `render` with `reference`; an error if their sizes differ.
    pub fn new(
        render: &'a RgbImage,
        reference: &'a RgbImage,
        masks: &'a Masks,
    ) -> Result<Self, SizeMismatch> {
        let ssim = SsimMap::new(render, reference)?;
        Ok(Self { render, reference, masks, ssim })
    }

    /// The per-pixel SSIM.
    pub fn ssim(&self) -> &SsimMap {
        &self.ssim
    }

    /// Evaluates `check`.
    pub fn measure(&self, check: &Check) -> Measured {
        let value = match (check.metric, check.mask) {
            (Metric::Ssim, _) => self.ssim.mean(),
            (Metric::WorstTileError, _) => worst_tile_error(self.render, self.reference),
            (Metric::MaskSsim, Some(mask)) => {
                self.ssim.mean_where(|x, y| self.masks.contains(mask, x as u32, y as u32)).unwrap_or(f64::NAN)
            }
            (Metric::MaskRmse, Some(mask)) => self.linear_rmse(mask),
            (Metric::MaskSsim | Metric::MaskRmse, None) | (Metric::TileTest, _) => f64::NAN,
        };
        let passed = match check.threshold {
            Threshold::AtLeast(min) => value >= min,
            Threshold::AtMost(max) => value <= max,
            Threshold::Diagnostic => false,
        };
        Measured { value, passed }
    }

    /// Root mean square difference of linear radiance over the pixels of `mask`, all channels.
    fn linear_rmse(&self, mask: Mask) -> f64 {
        let (mut sum, mut count) = (0.0f64, 0usize);
        for (x, y, a) in self.render.enumerate_pixels() {
            if self.masks.contains(mask, x, y) {
                let b = self.reference.get_pixel(x, y);
                for k in 0..3 {
                    let d = srgb_to_linear(a[k] as f32 / 255.0) - srgb_to_linear(b[k] as f32 / 255.0);
                    sum += (d as f64) * (d as f64);
                    count += 1;
                }
            }
        }
        if count == 0 {
            f64::NAN
        } else {
            (sum / count as f64).sqrt()
        }
    }
}

/// The largest mean, over [`TILE`] × [`TILE`] tiles, of the per-pixel error `e = |a − b|`
/// (8-bit values, mean of R, G, B) after a 3 × 3 median filter.
///
/// Why this shape: at one sample per pixel, correct implementations legitimately disagree on
/// isolated pixels (a ray through the crease where two walls meet, a glass facet's edge, a shadow
/// boundary) and a local SSIM punishes each such pixel over its whole 11 × 11 window. The median
/// removes isolated pixels and one-pixel lines; a real mistake (a missing shadow, a surface too
/// dark) changes whole regions and survives it. Calibration (docs/GRADING.md) measured at most
/// 0.13 for correct alternatives and at least 73 for mistakes.
pub fn worst_tile_error(a: &RgbImage, b: &RgbImage) -> f64 {
    let (w, h) = a.dimensions();
    let error = |x: u32, y: u32| {
        let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
        (0..3).map(|k| (p[k] as f64 - q[k] as f64).abs()).sum::<f64>() / 3.0
    };
    let errors: Vec<f64> =
        (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| error(x, y)).collect();
    let tiles_x = w.div_ceil(TILE) as usize;
    let mut tiles = vec![(0.0, 0usize); tiles_x * h.div_ceil(TILE) as usize];
    for y in 0..h {
        for x in 0..w {
            // The 3 × 3 neighbourhood, clamped at the borders.
            let mut window = [0.0; 9];
            for (i, (dx, dy)) in (-1i64..=1).flat_map(|dy| (-1i64..=1).map(move |dx| (dx, dy))).enumerate() {
                let nx = (x as i64 + dx).clamp(0, w as i64 - 1) as usize;
                let ny = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                window[i] = errors[ny * w as usize + nx];
            }
            window.sort_unstable_by(f64::total_cmp);
            let tile = &mut tiles[(y / TILE) as usize * tiles_x + (x / TILE) as usize];
            tile.0 += window[4];
            tile.1 += 1;
        }
    }
    tiles.iter().map(|t| t.0 / t.1 as f64).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    #[test]
    fn grader_tile_error_ignores_isolated_pixels_but_not_regions() {
        let grey = RgbImage::from_pixel(64, 64, Rgb([100, 100, 100]));
        let mut speckled = grey.clone();
        for i in 0..20 {
            speckled.put_pixel(i * 3, (i * 7) % 64, Rgb([255, 0, 0])); // isolated pixels
        }
        assert_eq!(worst_tile_error(&grey, &speckled), 0.0);
        let mut patch = grey.clone();
        for y in 40..50 {
            for x in 40..50 {
                patch.put_pixel(x, y, Rgb([160, 160, 160])); // a 10 x 10 region 60 levels off
            }
        }
        // 100 pixels of error 60 in one 32 x 32 tile; the median keeps the region's inside.
        let e = worst_tile_error(&grey, &patch);
        assert!(e > 60.0 * 64.0 / 1024.0 && e <= 60.0 * 100.0 / 1024.0, "{e}");
    }
}
