//! Checkpoint 7, hidden: the pixel estimate converges to the pixel's mean for functions the public
//! tests do not use, with tolerances from the estimator's own variance.

use raylab::math::{UVec2, Vec2, Vec3};
use raylab::rng::Rng;
use raylab::sampling::estimate_pixel;

/// The estimate of `f` (of the position inside the pixel, in [0, 1)²) over a few pixels, each with
/// its own generator, as the renderer seeds them.
fn estimates(spp: u32, f: impl Fn(Vec2) -> f32) -> Vec<f32> {
    [UVec2::new(0, 0), UVec2::new(17, 3), UVec2::new(250, 999)]
        .into_iter()
        .enumerate()
        .map(|(i, pixel)| {
            let mut rng = Rng::for_pixel(7, i as u64);
            let corner = pixel.as_vec2();
            estimate_pixel(pixel, spp, &mut rng, |x| Vec3::splat(f(x - corner))).x
        })
        .collect()
}

/// A slanted edge covering `x < 0.3 + 0.2 y`, 0.4 of the pixel. With N uniform samples the estimate
/// has standard deviation √(0.4 · 0.6 / N) (stratified does better); each estimate must lie within
/// 5 of them (a false failure once in 10⁶ per estimate). Summing instead of averaging, or sampling
/// around the pixel's corner (0.8 covered), is far outside.
#[test]
fn a_slanted_edge_is_estimated_by_the_fraction_of_the_pixel_it_covers() {
    for spp in [4096, 1000] {
        let tolerance = 5.0 * (0.4f32 * 0.6 / spp as f32).sqrt();
        for got in estimates(spp, |u| if u.x < 0.3 + 0.2 * u.y { 1.0 } else { 0.0 }) {
            assert!((got - 0.4).abs() < tolerance, "{spp} spp: {got}, want 0.4 ± {tolerance}");
        }
    }
}

/// The mean of x² over the pixel is 1/3 (variance of the estimate 4/45 / N); sampling the pixel's
/// centre only gives 1/4, sampling a fixed sub-grid without jitter gives a biased value.
#[test]
fn the_mean_of_x_squared_over_the_pixel_is_a_third() {
    let spp = 1024;
    let tolerance = 5.0 * (4.0f32 / 45.0 / spp as f32).sqrt();
    for got in estimates(spp, |u| u.x * u.x) {
        assert!((got - 1.0 / 3.0).abs() < tolerance, "{got}, want 1/3 ± {tolerance}");
    }
}
