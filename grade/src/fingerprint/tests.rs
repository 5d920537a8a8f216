//! Naming on made-up pictures and tile means: the closest mistake named only when clearly
//! closer, each kind by its own margin, and the fingerprints the repository ships fresh and small.

use super::*;

fn entry(scene: &str, mistake: &str, checkpoint: u32) -> Entry {
    Entry {
        scene: scene.into(),
        mistake: mistake.into(),
        checkpoint,
        description: format!("{mistake}, described"),
        handout: "checkpoints/02-triangle.md".into(),
        inputs_hash: "0".into(),
        kind: Kind::Thumbnail,
    }
}

/// A 128 × 128 test picture: a gradient with a disc of `colour`, `radius` pixels.
fn picture(colour: [u8; 3], radius: f32) -> RgbImage {
    RgbImage::from_fn(128, 128, |x, y| {
        let (dx, dy) = (x as f32 - 64.0, y as f32 - 64.0);
        if dx * dx + dy * dy < radius * radius {
            image::Rgb(colour)
        } else {
            image::Rgb([(x * 2) as u8, (y * 2) as u8, 40])
        }
    })
}

#[test]
fn a_thumbnail_averages_blocks_and_keeps_the_aspect() {
    let image = RgbImage::from_fn(256, 128, |x, _| image::Rgb([if x % 2 == 0 { 0 } else { 200 }, 7, 7]));
    let t = thumbnail(&image);
    assert_eq!(t.dimensions(), (64, 32), "256 × 128 shrinks by 4 on both sides");
    assert!(t.pixels().all(|p| p.0 == [100, 7, 7]), "each pixel is its block's mean");
    assert_eq!(thumbnail(&RgbImage::new(20, 20)).dimensions(), (20, 20), "small images stay");
}

fn seen<'a>(render: &'a RgbImage, reference: &'a RgbImage) -> Evidence<'a> {
    Evidence::Picture { render, reference }
}

#[test]
fn the_closest_mistake_is_named_and_only_when_clearly_closer() {
    let reference = picture([255, 255, 255], 30.0);
    let black = picture([0, 0, 0], 30.0);
    let small = picture([255, 255, 255], 10.0);
    let print = |image: &RgbImage| Signature::Thumbnail(thumbnail(image));
    let prints = Fingerprints {
        rule: Rule { margin: 0.05, fit: None, tile_margin: None, tile_fit: None },
        prints: vec![
            (entry("room", "black_disc", 2), print(&black)),
            (entry("room", "small_disc", 2), print(&small)),
            (entry("room", "black_disc_of_4", 4), print(&black)),
        ],
    };
    let named = prints.name("room", seen(&black, &reference), &[2]).expect("named");
    assert_eq!(named.entry.mistake, "black_disc");
    let Closeness::Ssim { to_mistake, to_reference } = named.closeness else { panic!("by SSIM") };
    assert!(to_mistake > to_reference + 0.05, "{to_mistake} {to_reference}");
    let name = |scene: &str, render: &RgbImage, checkpoints: &[u32]| {
        prints.name(scene, seen(render, &reference), checkpoints).map(|n| n.entry.mistake)
    };
    // A correct render is the reference: nothing is named.
    assert_eq!(name("room", &reference, &[2]), None);
    // Two mistakes that draw the same picture: unsure, nothing is named.
    assert_eq!(name("room", &black, &[2, 4]), None);
    // Only the scene's fingerprints and the checkpoints given are candidates.
    assert_eq!(name("boxes", &black, &[2]), None);
    assert_eq!(name("room", &black, &[3]), None);
    // A render nearer the reference than any mistake names nothing.
    let light = picture([200, 200, 200], 30.0);
    let likeness = prints.likeness("room", seen(&light, &reference), &[2]).unwrap();
    assert!(likeness.to_reference > likeness.to_mistakes[0].1, "{likeness:?}");
    assert_eq!(likeness.named(prints.rule), None);
    // A fit above what the render reaches names nothing, however clear the margin.
    let strict = Rule { fit: Some(1.01), ..prints.rule };
    let black_likeness = prints.likeness("room", seen(&black, &reference), &[2]).unwrap();
    assert_eq!(black_likeness.named(strict), None, "{black_likeness:?}");
    assert!(black_likeness.named(prints.rule).is_some());
}

/// Tile means (`tiles` of 0.5 with standard error 0.01, one tile at `off`).
fn tiles(off: f64) -> TileSignature {
    let tile = |m: f64| [raylab_base::stats::Summary { mean: m, variance: 16.0 * 1e-4, n: 16.0 }; 3];
    let summaries: Vec<_> = (0..16).map(|k| tile(if k == 5 { off } else { 0.5 })).collect();
    TileSignature::of(&summaries, 4)
}

/// On a tile-tested scene the tile signatures decide, by their own margin and fit: renders like
/// a mistake's tile means are named, a correct one is not, nor one wrong some other way, and no
/// margin names nothing.
#[test]
fn tile_means_name_a_mistake_by_the_tile_margin() {
    let mut tiled = entry("cornell_path", "bright_tile", 9);
    tiled.kind = Kind::Tiles;
    let mut prints = Fingerprints {
        rule: Rule { margin: 0.05, fit: None, tile_margin: Some(0.3), tile_fit: Some(-(2f64.ln())) },
        prints: vec![
            (tiled, Signature::Tiles(tiles(0.8))),
            (entry("cornell_path", "a_thumbnail", 9), Signature::Thumbnail(RgbImage::new(16, 16))),
        ],
    };
    let expected = tiles(0.5);
    let name = |prints: &Fingerprints, mine: &TileSignature| {
        prints.name("cornell_path", Evidence::Tiles { mine, expected: &expected }, &[9])
    };
    // Like the mistake up to noise: z of 0.5 on its tile, and 22 from the reference.
    let named = name(&prints, &tiles(0.807)).expect("named");
    assert_eq!(named.entry.mistake, "bright_tile");
    let Closeness::Tiles { to_mistake, to_reference } = named.closeness else { panic!("by tiles") };
    assert!(to_mistake < 1.0 && to_reference > 3.0, "{to_mistake} {to_reference}");
    assert_eq!(named.picture.dimensions(), (4, 4), "the mistake's tile means, a pixel each");
    assert_eq!(name(&prints, &tiles(0.5)), None, "a correct render");
    assert_eq!(name(&prints, &tiles(0.65)), None, "halfway: unsure");
    // Wrong some other way: less unlike the mistake (a distance of 8.8) than the reference
    // (14.1), by a margin of 0.47, but nothing like the mistake's own renders (up to 2 here).
    let other = Evidence::Tiles { mine: &tiles(1.3), expected: &expected };
    let likeness = prints.likeness("cornell_path", other, &[9]).unwrap();
    assert!(likeness.margin().unwrap() > 0.3, "the margin alone would name it: {likeness:?}");
    assert_eq!(name(&prints, &tiles(1.3)), None, "it does not fit the mistake");
    prints.rule.tile_fit = None;
    assert_eq!(name(&prints, &tiles(0.807)), None, "no tile fit: tiles name nothing");
    prints.rule.tile_fit = Some(-(2f64.ln()));
    prints.rule.tile_margin = None;
    assert_eq!(name(&prints, &tiles(0.807)), None, "no tile margin: tiles name nothing");
}

/// The fingerprints the repository ships: each fresh (made from the current scene), each at
/// most 16 KB and all together at most 2 MB, the sizes the starter may carry.
#[test]
fn every_fingerprint_is_fresh_and_small() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let text = std::fs::read_to_string(root.join(DIR).join("manifest.toml")).unwrap();
    let file: FingerprintFile = toml::from_str(&text).unwrap();
    let rubric = crate::rubric::Rubric::of_tree(root).unwrap();
    let manifest = Manifest::load(root, &rubric).unwrap();
    let loaded = Fingerprints::load(root, &manifest).unwrap();
    assert_eq!(
        loaded.prints.len(),
        file.fingerprints.len(),
        "a fingerprint is stale: run `grader fingerprints`"
    );
    let sizes: Vec<u64> = file
        .fingerprints
        .iter()
        .map(|e| std::fs::metadata(root.join(DIR).join(e.file_name())).unwrap().len())
        .collect();
    assert!(sizes.iter().all(|&s| s <= 16 * 1024), "a fingerprint over 16 KB: {sizes:?}");
    assert!(sizes.iter().sum::<u64>() <= 2 * 1024 * 1024, "fingerprints over 2 MB in all");
    assert!(file.rule.margin > 0.0, "a margin of 0 names a tie");
}
