//! SSIM (Wang, Bovik, Sheikh and Simoncelli, 2004), computed exactly as scikit-image's
//! `structural_similarity(a, b, channel_axis=2, gaussian_weights=True, sigma=1.5,
//! use_sample_covariance=False, data_range=255)` on 8-bit sRGB images.
//!
//! Per channel, with local means μ, variances σ² and covariance σ_ab taken under a Gaussian
//! window (σ = 1.5, truncated at 3.5 σ: 11 × 11 pixels, weights normalized, borders mirrored as
//! `d c b a | a b c d`), population (not sample) statistics, and `C1 = (0.01 · 255)²`,
//! `C2 = (0.03 · 255)²`:
//!
//! ```text
//!   SSIM = (2 μa μb + C1)(2 σab + C2) / ((μa² + μb² + C1)(σa² + σb² + C2))
//! ```
//!
//! The image's SSIM is the mean over pixels at least 5 from the border, averaged over R, G, B.
//! [`SsimMap`] keeps the per-pixel values (channel mean) so that masks can be scored with the
//! same numbers. `grade/tests/data/ssim/` pins the result against scikit-image itself.
//!
//! Not the same quantity as image-compare's `rgb_similarity_structure` (`MSSIMSimple`), which
//! uses non-overlapping 8 × 8 tiles and summed variances: it scores mild noise around 0.45 where
//! this gives about 0.98.

use image::RgbImage;

/// Gaussian window radius: `int(3.5 σ + 0.5)` = 5, so the window is 11 pixels wide.
pub const RADIUS: usize = 5;
const SIGMA: f64 = 1.5;
const C1: f64 = (0.01 * 255.0) * (0.01 * 255.0);
const C2: f64 = (0.03 * 255.0) * (0.03 * 255.0);

/// Per-pixel SSIM of two images (the mean over R, G, B at each pixel).
#[derive(Clone, Debug)]
pub struct SsimMap {
    width: usize,
    height: usize,
    values: Vec<f64>,
}

/// Two images of different sizes cannot be compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the images differ in size: {0}x{1} and {2}x{3}")]
pub struct SizeMismatch(pub u32, pub u32, pub u32, pub u32);

impl SsimMap {
    /// The SSIM map of `a` against `b`; both at least 11 × 11 pixels and of the same size.
    pub fn new(a: &RgbImage, b: &RgbImage) -> Result<Self, SizeMismatch> {
        if a.dimensions() != b.dimensions() || a.width() < 11 || a.height() < 11 {
            return Err(SizeMismatch(a.width(), a.height(), b.width(), b.height()));
        }
        let (width, height) = (a.width() as usize, a.height() as usize);
        let mut values = vec![0.0; width * height];
        for channel in 0..3 {
            let x: Vec<f64> = a.pixels().map(|p| p[channel] as f64).collect();
            let y: Vec<f64> = b.pixels().map(|p| p[channel] as f64).collect();
            let product = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| p * q).collect::<Vec<f64>>();
            let blur = |v: &[f64]| gaussian_blur(v, width, height);
            let (mx, my) = (blur(&x), blur(&y));
            let (mxx, myy, mxy) = (blur(&product(&x, &x)), blur(&product(&y, &y)), blur(&product(&x, &y)));
            for i in 0..width * height {
                let (vx, vy, vxy) = (mxx[i] - mx[i] * mx[i], myy[i] - my[i] * my[i], mxy[i] - mx[i] * my[i]);
                let numerator = (2.0 * mx[i] * my[i] + C1) * (2.0 * vxy + C2);
                let denominator = (mx[i] * mx[i] + my[i] * my[i] + C1) * (vx + vy + C2);
                values[i] += numerator / denominator / 3.0;
            }
        }
        Ok(Self { width, height, values })
    }

    /// The image's SSIM: the mean over pixels at least [`RADIUS`] from every border.
    pub fn mean(&self) -> f64 {
        self.mean_where(|_, _| true).unwrap_or(1.0)
    }

    /// The mean over interior pixels (as in [`SsimMap::mean`]) where `inside(x, y)`; `None` if
    /// there are none.
    pub fn mean_where(&self, inside: impl Fn(usize, usize) -> bool) -> Option<f64> {
        let (mut sum, mut count) = (0.0, 0usize);
        for y in RADIUS..self.height - RADIUS {
            for x in RADIUS..self.width - RADIUS {
                if inside(x, y) {
                    sum += self.values[y * self.width + x];
                    count += 1;
                }
            }
        }
        (count > 0).then(|| sum / count as f64)
    }

    /// The SSIM at pixel `(x, y)`.
    pub fn at(&self, x: usize, y: usize) -> f64 {
        self.values[y * self.width + x]
    }
}

/// The normalized Gaussian weights for offsets −RADIUS ..= RADIUS.
fn gaussian_weights() -> [f64; 2 * RADIUS + 1] {
    let mut w = [0.0; 2 * RADIUS + 1];
    for (i, w) in w.iter_mut().enumerate() {
        let d = i as f64 - RADIUS as f64;
        *w = (-0.5 * d * d / (SIGMA * SIGMA)).exp();
    }
    let sum: f64 = w.iter().sum();
    w.map(|x| x / sum)
}

/// Mirrors an index into `0..n` the way `d c b a | a b c d` does (valid for overhangs ≤ n).
fn mirror(i: isize, n: usize) -> usize {
    let n = n as isize;
    let i = if i < 0 {
        -i - 1
    } else if i >= n {
        2 * n - i - 1
    } else {
        i
    };
    i as usize
}

/// A separable Gaussian blur of a `width × height` grid.
fn gaussian_blur(v: &[f64], width: usize, height: usize) -> Vec<f64> {
    let w = gaussian_weights();
    let r = RADIUS as isize;
    let mut rows = vec![0.0; v.len()];
    for y in 0..height {
        for x in 0..width {
            let taps = (-r..=r).map(|d| w[(d + r) as usize] * v[y * width + mirror(x as isize + d, width)]);
            rows[y * width + x] = taps.sum();
        }
    }
    let mut out = vec![0.0; v.len()];
    for y in 0..height {
        for x in 0..width {
            let taps =
                (-r..=r).map(|d| w[(d + r) as usize] * rows[mirror(y as isize + d, height) * width + x]);
            out[y * width + x] = taps.sum();
        }
    }
    out
}
