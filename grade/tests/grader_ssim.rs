//! raylab's SSIM against scikit-image's, on the pairs `tools/ssim_expected.py` wrote.

use std::path::Path;

use raylab_grade::images::read_png;
use raylab_grade::ssim::SsimMap;

#[derive(serde::Deserialize)]
struct Expected {
    pair: Vec<Pair>,
}

#[derive(serde::Deserialize)]
struct Pair {
    a: String,
    b: String,
    ssim: f64,
}

#[test]
fn grader_ssim_matches_scikit_image_on_every_committed_pair() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/ssim");
    let expected: Expected =
        toml::from_str(&std::fs::read_to_string(dir.join("expected.toml")).unwrap()).unwrap();
    assert!(expected.pair.len() >= 7);
    for pair in expected.pair {
        let a = read_png(&dir.join(&pair.a)).unwrap();
        let b = read_png(&dir.join(&pair.b)).unwrap();
        let got = SsimMap::new(&a, &b).unwrap().mean();
        // Both sides evaluate the same formula in f64; only summation order differs (~1e-13).
        // A wrong window, sigma, border rule or constant moves the value by 1e-3 or more.
        assert!(
            (got - pair.ssim).abs() < 1e-9,
            "{} vs {}: raylab {got}, scikit-image {}",
            pair.a,
            pair.b,
            pair.ssim
        );
    }
}

#[test]
fn grader_ssim_rejects_images_of_different_sizes() {
    let a = image::RgbImage::new(20, 20);
    let b = image::RgbImage::new(20, 21);
    assert!(SsimMap::new(&a, &b).is_err());
}
