//! The tile test on synthetic renders whose truth is known: correct ones fail at the family-wise
//! rate, biased or noisier tiles fail where they are, broken numbers and seedless renders fail.

use super::*;
use glam::Vec3;
use raylab_base::rng::Rng;

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

fn renders(rng: &mut Rng, count: usize, sigma: f64, scale: f32, noisier: f64) -> Vec<Vec<[f64; 3]>> {
    (0..count).map(|_| tile_means(&render(rng, sigma, scale, noisier), 16)).collect()
}

/// As the rubric's tile-tested scenes have it: the expected value from 4 renders 16x less
/// noisy (256 times the samples), the spread from 64 renders at the graded noise.
fn reference(rng: &mut Rng) -> NoisyReference {
    NoisyReference {
        expected: summarise(&renders(rng, 4, 0.05 / 16.0, 1.0, 1.0)),
        solution: renders(rng, 64, 0.05, 1.0, 1.0),
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
    assert_eq!(means[0][0], (0..3).flat_map(|y| (0..4).map(move |x| (5 * y + x) as f64)).sum::<f64>() / 12.0);
    assert_eq!(means[1][1], (4.0 + 9.0 + 14.0) / 3.0);
}

/// Correct submissions (the same distribution as the solution) fail at about the rate alpha:
/// in 200 trials at alpha = 0.05 the count of failures is binomial(200, ≤ 0.05): mean ≤ 10,
/// standard deviation ≤ 3.1; more than 22 (4 standard deviations above) would mean the test
/// is miscalibrated. (The trials share one reference, so the count is binomial given it: a
/// reference whose 4 expected renders happen to sit far out would fail more; with 256 times
/// the samples each, they sit 1/16 of a render's noise from the truth.)
#[test]
fn correct_renders_fail_at_most_at_the_family_wise_rate() {
    let mut rng = Rng::new(91, 0);
    let reference = reference(&mut rng);
    let failed = (0..200)
        .filter(|_| !compare(&renders(&mut rng, 16, 0.05, 1.0, 1.0), &reference, 0.05).passed())
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
        let verdict = compare(&renders(&mut rng, 16, 0.05, 1.03, 1.0), &reference, 0.01);
        biased +=
            verdict.failures.iter().any(|f| f.tile == 5 && matches!(f.problem, TileProblem::Mean { .. }))
                as u32;
        elsewhere += verdict.failures.iter().filter(|f| f.tile != 5).count();
        let verdict = compare(&renders(&mut rng, 16, 0.05, 1.0, 8.0), &reference, 0.01);
        noisy +=
            verdict.failures.iter().any(|f| f.tile == 6 && matches!(f.problem, TileProblem::Noise { .. }))
                as u32;
    }
    assert!(biased >= 48 && noisy >= 48, "biased {biased}/50, noisy {noisy}/50");
    assert!(elsewhere <= 3, "{elsewhere} failures outside the biased tile");
}

/// A map colours a correct submission's tiles in at most [`CALM_RATE`] of trials: in 100, a
/// binomial count of mean at most 5 and standard deviation at most 2.2; more than 13 (3.7
/// standard deviations above) would mean the calm level is miscalibrated. A tile 3% too bright
/// or too dark, or 8 times too noisy, is below it and points its way.
#[test]
fn a_correct_renders_tiles_are_calm_and_an_off_tile_points_its_way() {
    let mut rng = Rng::new(96, 0);
    let reference = reference(&mut rng);
    let coloured = (0..100)
        .filter(|_| {
            let verdict = compare(&renders(&mut rng, 16, 0.05, 1.0, 1.0), &reference, 0.01);
            verdict.tiles.iter().any(|t| t.p < verdict.calm)
        })
        .count();
    assert!(coloured <= 13, "{coloured} of 100 correct submissions have a coloured tile");
    for (scale, noisier, tile, direction) in [
        (1.03, 1.0, 5, Direction::Brighter),
        (0.97, 1.0, 5, Direction::Darker),
        (1.0, 8.0, 6, Direction::Noise),
    ] {
        let verdict = compare(&renders(&mut rng, 16, 0.05, scale, noisier), &reference, 0.01);
        let outcome = verdict.tiles[tile];
        assert!(outcome.p < verdict.calm && outcome.direction == direction, "{scale} {noisier}: {outcome:?}");
    }
}

/// Correct renders whose tile means are far from normal pass as often as normal ones: one
/// pixel of tile 2 gains a bright sample (12.5 times the noise of the tile's mean) in 1 render
/// of 100, in the solution's renders and the submission's alike. An F-test of the variances
/// fails such renders whenever the submission's 16 hold a bright sample and the solution's 64
/// do not (this grader's F-test failed 13 of these 100); the rank test, exact for any
/// distribution, fails them at most at the rate alpha.
/// 100 trials at alpha = 0.01, each with a reference of its own: P(≥ 5 fail) < 4e-3.
#[test]
fn rare_bright_samples_do_not_fail_correct_renders() {
    let mut rng = Rng::new(95, 0);
    let with_rare_samples = |rng: &mut Rng, count: usize| -> Vec<Vec<[f64; 3]>> {
        (0..count)
            .map(|_| {
                let mut film = render(rng, 0.05, 1.0, 1.0);
                if rng.next_f32() < 0.01 {
                    film.set(40, 3, film.get(40, 3) + Vec3::splat(10.0));
                }
                tile_means(&film, 16)
            })
            .collect()
    };
    let failed = (0..100)
        .filter(|_| {
            let reference = NoisyReference {
                expected: summarise(&renders(&mut rng, 4, 0.05 / 16.0, 1.0, 1.0)),
                solution: with_rare_samples(&mut rng, 64),
            };
            !compare(&with_rare_samples(&mut rng, 16), &reference, 0.01).passed()
        })
        .count();
    assert!(failed <= 4, "{failed} of 100 correct submissions failed at alpha = 0.01");
}

/// A render with NaN or infinite pixels fails in those tiles: NaN compares false with every
/// level, so without its own rule a NaN tile would pass.
#[test]
fn tiles_with_nan_or_infinite_radiance_fail() {
    let mut rng = Rng::new(93, 0);
    let reference = reference(&mut rng);
    for bad in [f32::NAN, f32::INFINITY] {
        let renders: Vec<Vec<[f64; 3]>> = (0..16)
            .map(|_| {
                let mut film = render(&mut rng, 0.05, 1.0, 1.0);
                film.set(20, 3, Vec3::new(0.5, bad, 0.5));
                tile_means(&film, 16)
            })
            .collect();
        let verdict = compare(&renders, &reference, 0.01);
        assert_eq!(verdict.failures.len(), 1, "{bad}: {:?}", verdict.failures);
        assert_eq!((verdict.failures[0].tile, verdict.tiles[1].p), (1, 0.0));
    }
}

/// Code that ignores the seed renders the same image every time (one noisy render, or fixed
/// values copied from the reference): its spread is zero, so every tile fails, even against
/// a reference of only 4 high-spp renders, whose 3 degrees of freedom would let Welch's test
/// alone pass a tile off by several times its noise.
#[test]
fn renders_that_ignore_the_seed_fail() {
    let mut rng = Rng::new(94, 0);
    let reference = reference(&mut rng);
    let once = tile_means(&render(&mut rng, 0.05, 1.0, 1.0), 16);
    let copied: Vec<[f64; 3]> = reference.expected.iter().map(|t| t.map(|c| c.mean)).collect();
    for fixed in [once, copied] {
        let verdict = compare(&vec![fixed; 16], &reference, 0.01);
        assert_eq!(verdict.failures.len(), 8, "{:?}", verdict.failures);
        assert!(
            verdict.failures.iter().all(|f| matches!(f.problem, TileProblem::NoVariation { .. })),
            "{:?}",
            verdict.failures
        );
    }
    // Correct renders that happen to be far less noisy than the solution's (a fifth) pass.
    let quiet = renders(&mut rng, 16, 0.05 / 5.0, 1.0, 1.0);
    assert!(compare(&quiet, &reference, 0.01).passed());
}

/// The graded, expected and solution seeds never meet, for any base a rubric or calibration
/// uses (below 2²⁴) and up to 2¹⁶ renders.
#[test]
fn the_three_kinds_of_seed_are_disjoint() {
    let graded = [graded_seed(0, 0), graded_seed(0, 65_535), graded_seed((1 << 24) - 1, 65_535)];
    assert!(graded.iter().all(|&s| s < expected_seed(0)));
    assert!(expected_seed(65_535) < solution_seed(0));
    assert_ne!(graded_seed(1, 0), graded_seed(0, 1));
}
