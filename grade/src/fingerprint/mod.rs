//! Naming a known mistake: when a scene fails, is the render the picture of one of the mistake
//! catalogue's mistakes (`checkpoints/variants.toml`)?
//!
//! A *fingerprint* is a thumbnail of one catalogue mistake's render of one scene: the render
//! shrunk by a box filter to at most [`SIDE`] pixels a side (a signature of the picture, not a
//! measurement of light: the sRGB bytes are averaged). The instructor makes them
//! (`grader fingerprints`, `instructor::fingerprint_make`) into `reference/fingerprints/`, a PNG each
//! and `manifest.toml`, which also holds the naming rule measured there; the starter ships them.
//!
//! **The rule.** A failed render's thumbnail is compared, by the grader's SSIM, with the
//! reference's thumbnail and with the fingerprints of that scene whose checkpoint runs the
//! student's code. The best fingerprint names its mistake only if its similarity exceeds both the
//! reference's and the runner-up fingerprint's by at least the rule's `margin`: two mistakes that
//! draw the same picture, or a render as close to the reference as to the mistake, name nothing.
//! When unsure, say nothing. A name never changes a point: it is a pointer to the handout.
//!
//! A fingerprint records the reference's `inputs_hash` when it was made; once the scene changes,
//! it is stale and left out (and the test `every_fingerprint_is_fresh_and_small` fails).

use std::path::Path;

use image::RgbImage;
use serde::{Deserialize, Serialize};

use crate::file_error::{parse_toml, FileError};
use crate::images::read_png;
use crate::reference::Manifest;
use crate::ssim::SsimMap;

/// A thumbnail's longest side, in pixels: an RGB thumbnail is at most 12 KB raw.
pub const SIDE: u32 = 64;

/// The folder of the fingerprints, relative to the repository root.
pub const DIR: &str = "reference/fingerprints";

/// `reference/fingerprints/manifest.toml`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FingerprintFile {
    /// When a fingerprint names its mistake.
    pub rule: Rule,
    /// One entry per mistake and scene.
    #[serde(rename = "fingerprint", default)]
    pub fingerprints: Vec<Entry>,
}

/// When a fingerprint names its mistake (module docs).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Rule {
    /// How much more similar (SSIM of thumbnails) the render must be to the mistake's than to
    /// the reference and to any other mistake's.
    pub margin: f64,
}

/// One fingerprint: which mistake drew which scene.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    /// The graded scene.
    pub scene: String,
    /// The catalogue mistake's name.
    pub mistake: String,
    /// The checkpoint whose region it is in.
    pub checkpoint: u32,
    /// What it does, in a student's words (the catalogue's description).
    pub description: String,
    /// The checkpoint's handout, whose "Symptoms of common mistakes" explain it.
    pub handout: String,
    /// The scene reference's `inputs_hash` when the fingerprint was made.
    pub inputs_hash: String,
}

impl Entry {
    /// The thumbnail's file name inside [`DIR`].
    pub fn file_name(&self) -> String {
        format!("{}.{}.png", self.scene, self.mistake)
    }
}

/// A render named as a known mistake, with the evidence.
#[derive(Clone, Debug, PartialEq)]
pub struct Naming {
    /// The mistake's fingerprint entry.
    pub entry: Entry,
    /// SSIM of the render's thumbnail to the mistake's.
    pub to_mistake: f64,
    /// SSIM of the render's thumbnail to the reference's.
    pub to_reference: f64,
    /// The mistake's thumbnail, to show beside the render.
    pub thumbnail: RgbImage,
}

/// How alike a render is to the reference and to each candidate fingerprint.
#[derive(Clone, Debug, PartialEq)]
pub struct Likeness {
    /// SSIM of the thumbnails of the render and the reference.
    pub to_reference: f64,
    /// The candidates, most alike first: (index into the fingerprints, SSIM).
    pub to_mistakes: Vec<(usize, f64)>,
}

impl Likeness {
    /// By how much the best fingerprint beats both the reference and the runner-up; `None`
    /// without a candidate.
    pub fn margin(&self) -> Option<f64> {
        let (_, best) = *self.to_mistakes.first()?;
        let runner_up = self.to_mistakes.get(1).map_or(f64::NEG_INFINITY, |m| m.1);
        Some(best - self.to_reference.max(runner_up))
    }

    /// The fingerprint the rule names, by index, if any.
    pub fn named(&self, rule: Rule) -> Option<usize> {
        (self.margin()? >= rule.margin).then(|| self.to_mistakes[0].0)
    }
}

/// The loaded fingerprints and their rule.
#[derive(Clone, Debug, Default)]
pub struct Fingerprints {
    /// The rule.
    pub rule: Rule,
    /// Each fresh fingerprint with its thumbnail.
    pub prints: Vec<(Entry, RgbImage)>,
}

impl Fingerprints {
    /// Reads `reference/fingerprints/`; none if it is missing. Stale fingerprints (their scene
    /// changed since) are left out.
    pub fn load(root: &Path, manifest: &Manifest) -> Result<Self, FileError> {
        let dir = root.join(DIR);
        let path = dir.join("manifest.toml");
        let Ok(text) = std::fs::read_to_string(&path) else { return Ok(Self::default()) };
        let file: FingerprintFile = parse_toml(&path, &text)?;
        let fresh = |e: &Entry| {
            manifest.references.iter().any(|r| r.name == e.scene && r.inputs_hash == e.inputs_hash)
        };
        let mut prints = Vec::new();
        for entry in file.fingerprints.into_iter().filter(fresh) {
            let image = dir.join(entry.file_name());
            let thumbnail = read_png(&image).map_err(|e| FileError::image(&image, &e))?;
            prints.push((entry, thumbnail));
        }
        Ok(Self { rule: file.rule, prints })
    }

    /// How alike `render` is to `reference` and to the fingerprints of `scene` whose checkpoint
    /// is one of `checkpoints`; `None` if the images cannot be compared.
    pub fn likeness(
        &self,
        scene: &str,
        render: &RgbImage,
        reference: &RgbImage,
        checkpoints: &[u32],
    ) -> Option<Likeness> {
        let mine = thumbnail(render);
        let similarity = |other: &RgbImage| SsimMap::new(&mine, other).ok().map(|m| m.mean());
        let to_reference = similarity(&thumbnail(reference))?;
        let mut to_mistakes: Vec<(usize, f64)> = self
            .prints
            .iter()
            .enumerate()
            .filter(|(_, (e, _))| e.scene == scene && checkpoints.contains(&e.checkpoint))
            .filter_map(|(i, (_, t))| Some((i, similarity(t)?)))
            .collect();
        to_mistakes.sort_by(|a, b| b.1.total_cmp(&a.1));
        Some(Likeness { to_reference, to_mistakes })
    }

    /// The known mistake `render` of `scene` shows, if the rule names one (module docs).
    pub fn name(
        &self,
        scene: &str,
        render: &RgbImage,
        reference: &RgbImage,
        checkpoints: &[u32],
    ) -> Option<Naming> {
        let likeness = self.likeness(scene, render, reference, checkpoints)?;
        let index = likeness.named(self.rule)?;
        let (entry, thumbnail) = self.prints[index].clone();
        let (to_mistake, to_reference) = (likeness.to_mistakes[0].1, likeness.to_reference);
        Some(Naming { entry, to_mistake, to_reference, thumbnail })
    }
}

/// `image` shrunk by a box filter so that its longest side is at most [`SIDE`] (never below the
/// 11 pixels SSIM needs); each thumbnail pixel is the mean of the image pixels whose centres
/// fall in it.
pub fn thumbnail(image: &RgbImage) -> RgbImage {
    let (width, height) = image.dimensions();
    let factor = width.max(height).div_ceil(SIDE).max(1);
    let size = |n: u32| (n / factor).max(11.min(n));
    let (w, h) = (size(width), size(height));
    RgbImage::from_fn(w, h, |x, y| {
        let (mut sum, mut count) = ([0u32; 3], 0u32);
        let xs = x * width / w..((x + 1) * width / w).max(x * width / w + 1);
        for sy in y * height / h..((y + 1) * height / h).max(y * height / h + 1) {
            for sx in xs.clone() {
                let p = image.get_pixel(sx, sy);
                (0..3).for_each(|c| sum[c] += p[c] as u32);
                count += 1;
            }
        }
        image::Rgb(sum.map(|s| ((s + count / 2) / count) as u8))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(scene: &str, mistake: &str, checkpoint: u32) -> Entry {
        Entry {
            scene: scene.into(),
            mistake: mistake.into(),
            checkpoint,
            description: format!("{mistake}, described"),
            handout: "checkpoints/02-triangle.md".into(),
            inputs_hash: "0".into(),
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

    #[test]
    fn the_closest_mistake_is_named_and_only_when_clearly_closer() {
        let reference = picture([255, 255, 255], 30.0);
        let black = picture([0, 0, 0], 30.0);
        let small = picture([255, 255, 255], 10.0);
        let prints = Fingerprints {
            rule: Rule { margin: 0.05 },
            prints: vec![
                (entry("room", "black_disc", 2), thumbnail(&black)),
                (entry("room", "small_disc", 2), thumbnail(&small)),
                (entry("room", "black_disc_of_4", 4), thumbnail(&black)),
            ],
        };
        let named = prints.name("room", &black, &reference, &[2]).expect("named");
        assert_eq!(named.entry.mistake, "black_disc");
        assert!(named.to_mistake > named.to_reference + 0.05, "{} {}", named.to_mistake, named.to_reference);
        let name = |scene: &str, render: &RgbImage, checkpoints: &[u32]| {
            prints.name(scene, render, &reference, checkpoints).map(|n| n.entry.mistake)
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
        let likeness = prints.likeness("room", &light, &reference, &[2]).unwrap();
        assert!(likeness.to_reference > likeness.to_mistakes[0].1, "{likeness:?}");
        assert_eq!(likeness.named(prints.rule), None);
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
}
