//! Checkpoint 7: anti-aliasing, several jittered samples per pixel, averaged.
//!
//! **Task.** Write [`estimate_pixel`]: estimate the average radiance over a pixel's square from
//! `spp` samples at random positions inside it.
//!
//! **Maths.** A pixel `(i, j)` covers `[i, i+1) × [j, j+1)` on the film. Its value is the mean of
//! the radiance over that square (a box filter), `∫ L(x) dx` over the unit square. With `spp`
//! points `x_k` uniform in the square, `(1/spp) Σ L(x_k)` is an unbiased estimate of it whose
//! error falls like `1/√spp`. *Stratified* jitter does better: when `spp = n²`, split the square
//! into an `n × n` grid and put one uniform point in each cell; the estimate stays unbiased and
//! its error falls faster on edges. Otherwise (spp not a square), use uniform points in the whole
//! pixel. The tests accept any pattern that is unbiased within the pixel and different from pixel
//! to pixel: stratification is the better choice, not the only correct one.
//!
//! **Conventions.** Draw random numbers only from `rng`: the renderer seeds it from the scene's
//! seed and the pixel's index, so images are identical for any thread count, and neighbouring
//! pixels get different samples. With `spp = 1` the renderer does not call this function: it
//! samples the pixel centre, so checkpoints 2-6 render the same with or without checkpoint 7.
//!
//! **Pitfalls.**
//! - Summing without dividing by `spp`: the image gets brighter with more samples.
//! - The same offsets for every pixel (a generator made here, with a fixed seed): the
//!   aliasing is only shifted, and moiré appears.
//! - Sampling `[−0.5, 0.5)` around the pixel's corner instead of inside the pixel shifts the
//!   image by half a pixel.
//!
//! **Check:** `cargo test checkpoint7`, and render `scenes/aliasing.toml` with `--spp 16`.
//! Handout: `checkpoints/07-antialiasing.md`.

use crate::math::{UVec2, Vec2, Vec3};
use crate::rng::Rng;

/// The mean of `radiance` over pixel `pixel`, estimated from `spp` jittered film positions (in
/// pixels, see [`crate::camera`]), stratified when `spp` is a perfect square.
pub fn estimate_pixel(pixel: UVec2, spp: u32, rng: &mut Rng, mut radiance: impl FnMut(Vec2) -> Vec3) -> Vec3 {
    // BEGIN SOLUTION checkpoint7
    let root = (spp as f64).sqrt().round() as u32;
    let n = if root * root == spp { root } else { 1 };
    let cell = 1.0 / n as f32;
    let corner = pixel.as_vec2();
    let mut sum = Vec3::ZERO;
    for k in 0..spp {
        let stratum = Vec2::new((k % n) as f32, (k / n % n) as f32);
        let jitter = Vec2::new(rng.next_f32(), rng.next_f32());
        sum += radiance(corner + (stratum + jitter) * cell);
    }
    sum / spp as f32
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint7 {
    use super::*;

    /// Radiance 1 left of the slanted line `x = 0.3 + 0.4 y` (film coordinates), else 0.
    /// Inside pixel (0, 0) that region covers exactly 0.3 + 0.4 / 2 = 0.5 of the area.
    fn half_plane(film: Vec2) -> Vec3 {
        let x = film.x - film.x.floor();
        let y = film.y - film.y.floor();
        Vec3::splat(if x < 0.3 + 0.4 * y { 1.0 } else { 0.0 })
    }

    #[test]
    fn every_part_of_the_pixel_is_sampled_evenly() {
        // Radiance 1 on the two off-diagonal quarters of the pixel, 0 on the diagonal quarters
        // and outside the pixel: the pixel's mean is exactly 1/2. One estimate from spp samples
        // has a standard deviation of at most 0.5 / sqrt(spp) (unstratified; strata only lower
        // it), so the mean of 4096 estimates lands within 5 standard errors of 1/2. Samples
        // confined to some strata, or leaving the pixel, land far outside.
        let pixels = 4096;
        for spp in [16, 5] {
            let mut total = 0.0;
            for p in 0..pixels {
                let pixel = UVec2::new(p % 64, p / 64);
                let off_diagonal = |film: Vec2| {
                    let local = film - pixel.as_vec2();
                    let inside = local.cmpge(Vec2::ZERO).all() && local.cmplt(Vec2::ONE).all();
                    Vec3::splat(if inside && ((local.x < 0.5) != (local.y < 0.5)) { 1.0 } else { 0.0 })
                };
                total += estimate_pixel(pixel, spp, &mut Rng::for_pixel(3, p as u64), off_diagonal).x as f64;
            }
            let mean = total / pixels as f64;
            let five_sigma = 5.0 * 0.5 / (spp as f64).sqrt() / (pixels as f64).sqrt();
            assert!((mean - 0.5).abs() < five_sigma, "spp {spp}: mean {mean}, 5 sigma {five_sigma}");
        }
    }

    #[test]
    fn samples_stay_inside_their_pixel_and_are_averaged() {
        let mut rng = Rng::for_pixel(1, 0);
        let mut count = 0;
        let value = estimate_pixel(UVec2::new(7, 3), 9, &mut rng, |p| {
            count += 1;
            assert!(p.x >= 7.0 && p.x <= 8.0 && p.y >= 3.0 && p.y <= 4.0, "{p} outside pixel (7, 3)");
            Vec3::splat(2.0)
        });
        assert_eq!(count, 9, "spp = 9: expected exactly 9 radiance samples");
        assert!((value - Vec3::splat(2.0)).abs().max_element() < 1e-6, "a constant stays constant: {value}");
    }

    /// Mean and standard error of the estimates of pixel (0, 0) of `half_plane` over `pixels` pixel seeds.
    fn estimates(spp: u32, seed: u64, pixels: u64) -> (f64, f64) {
        let values: Vec<f64> = (0..pixels)
            .map(|i| estimate_pixel(UVec2::ZERO, spp, &mut Rng::for_pixel(seed, i), half_plane).x as f64)
            .collect();
        let mean = values.iter().sum::<f64>() / pixels as f64;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (pixels - 1) as f64;
        (mean, (var / pixels as f64).sqrt())
    }

    #[test]
    fn an_edge_pixel_converges_to_its_coverage() {
        // Unbiased: the mean over many pixels lies within 5 standard errors of the coverage 0.5
        // (a correct estimator fails this once in 1.7 million runs). The 1/spp quantisation of
        // a single estimate is averaged out; spp = 1 through the renderer is not this function.
        for (spp, seed) in [(4, 1), (7, 2), (16, 3), (64, 4)] {
            let (mean, std_err) = estimates(spp, seed, 4000);
            assert!((mean - 0.5).abs() < 5.0 * std_err.max(1e-4), "spp {spp}: mean {mean} ± {std_err}");
        }
    }

    #[test]
    fn the_error_falls_with_more_samples() {
        // The standard error of one estimate falls at least like 1/√spp (faster when stratified):
        // from 4 to 64 samples it must fall by at least a factor 4, give or take sampling noise.
        let (_, e4) = estimates(4, 5, 4000);
        let (_, e64) = estimates(64, 6, 4000);
        assert!(e64 < e4 / 3.0, "error at 4 spp {e4}, at 64 spp {e64}");
    }

    #[test]
    fn neighbouring_pixels_use_different_samples() {
        let mut first = Vec::new();
        estimate_pixel(UVec2::ZERO, 4, &mut Rng::for_pixel(1, 0), |p| {
            first.push(p);
            Vec3::ZERO
        });
        let mut second = Vec::new();
        estimate_pixel(UVec2::new(1, 0), 4, &mut Rng::for_pixel(1, 1), |p| {
            second.push(p - Vec2::X);
            Vec3::ZERO
        });
        assert_ne!(first, second);
    }
}
