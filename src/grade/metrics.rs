//! Scoring one render against its reference: the numbers a rubric's checks ask for.

use image::RgbImage;

use super::features::Masks;
use super::rubric::{Check, Mask, Metric};
use super::ssim::SsimMap;
use crate::image_io::srgb_to_linear;

/// Side of the tiles of [`Metric::WorstTileSsim`], in pixels.
pub const TILE: usize = 32;

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
    pub fn new(render: &'a RgbImage, reference: &'a RgbImage, masks: &'a Masks) -> Result<Self, String> {
        let ssim = SsimMap::new(render, reference).map_err(|e| format!("{e} (render vs reference)"))?;
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
            (Metric::WorstTileSsim, _) => self.ssim.worst_tile(TILE),
            (Metric::MaskSsim, Some(mask)) => {
                self.ssim.mean_where(|x, y| self.masks.contains(mask, x as u32, y as u32)).unwrap_or(f64::NAN)
            }
            (Metric::MaskRmse, Some(mask)) => self.linear_rmse(mask),
            (Metric::MaskSsim | Metric::MaskRmse, None) => f64::NAN,
        };
        let passed = match (check.min, check.max) {
            (Some(min), _) => value >= min,
            (_, Some(max)) => value <= max,
            (None, None) => false,
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
