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
//! It must also *fit*: be as alike to the mistake's fingerprint as renders of that mistake are
//! (the rule's `fit`), since a render wrong in some other way can be less unlike one mistake than
//! the reference without being it.
//!
//! **Tile-tested scenes** are fingerprinted by their tile means instead ([`tiles`]): a failed
//! noisy scene's renders are compared, tile by tile in standard errors, with each mistake's
//! renders and with the reference's expected means, and the same rule applies to `−ln` of those
//! distances with its own margin and fit (`tile_margin`, `tile_fit`; none: tiles name nothing).
//!
//! A fingerprint records the reference's `inputs_hash` when it was made; once the scene changes,
//! it is stale and left out (and the test `every_fingerprint_is_fresh_and_small` fails).

pub mod tiles;

use std::path::Path;

use image::RgbImage;
use serde::{Deserialize, Serialize};

use crate::file_error::{parse_toml, read_json, FileError};
use crate::images::read_png;
use crate::reference::Manifest;
use crate::ssim::SsimMap;
pub use tiles::TileSignature;

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
    /// How alike (SSIM of thumbnails) the render must be to the mistake's at least, as renders of
    /// that mistake are: a render wrong in some other way may be less unlike one mistake than the
    /// reference without being that mistake (`None`: no such bound).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<f64>,
    /// The same as `margin` for tile signatures: by how much `−ln` of the distance must beat the
    /// others' (`None`: tile signatures name nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tile_margin: Option<f64>,
    /// The same as `fit` for tile signatures, as `−ln` of the largest distance (`None`: tile
    /// signatures name nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tile_fit: Option<f64>,
}

/// What a fingerprint keeps of a mistake's renders.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A thumbnail of its render (PNG).
    #[default]
    Thumbnail,
    /// Its tile means with their errors (JSON), for a tile-tested scene.
    Tiles,
}

/// A fingerprint's content.
#[derive(Clone, Debug, PartialEq)]
pub enum Signature {
    /// A thumbnail ([`thumbnail`]).
    Thumbnail(RgbImage),
    /// Tile means ([`TileSignature`]).
    Tiles(TileSignature),
}

impl Signature {
    /// Its kind.
    pub fn kind(&self) -> Kind {
        match self {
            Signature::Thumbnail(_) => Kind::Thumbnail,
            Signature::Tiles(_) => Kind::Tiles,
        }
    }

    /// The picture shown beside a render named by it: the thumbnail, or the tile means drawn one
    /// pixel per tile.
    pub fn picture(&self) -> RgbImage {
        match self {
            Signature::Thumbnail(image) => image.clone(),
            Signature::Tiles(tiles) => tiles.mosaic(),
        }
    }
}

/// What a failed render is compared by.
#[derive(Clone, Copy, Debug)]
pub enum Evidence<'a> {
    /// Its picture, with the reference's.
    Picture {
        /// The render.
        render: &'a RgbImage,
        /// The reference image.
        reference: &'a RgbImage,
    },
    /// A tile-tested scene's tile means, with the reference's expected ones.
    Tiles {
        /// The render's.
        mine: &'a TileSignature,
        /// The reference's.
        expected: &'a TileSignature,
    },
}

impl Evidence<'_> {
    fn kind(&self) -> Kind {
        match self {
            Evidence::Picture { .. } => Kind::Thumbnail,
            Evidence::Tiles { .. } => Kind::Tiles,
        }
    }
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
    /// What it keeps.
    #[serde(default)]
    pub kind: Kind,
}

impl Entry {
    /// The fingerprint's file name inside [`DIR`].
    pub fn file_name(&self) -> String {
        match self.kind {
            Kind::Thumbnail => format!("{}.{}.png", self.scene, self.mistake),
            Kind::Tiles => format!("{}.{}.tiles.json", self.scene, self.mistake),
        }
    }
}

/// A render named as a known mistake, with the evidence.
#[derive(Clone, Debug, PartialEq)]
pub struct Naming {
    /// The mistake's fingerprint entry.
    pub entry: Entry,
    /// How close the render is to the mistake's and to the reference.
    pub closeness: Closeness,
    /// The mistake's picture ([`Signature::picture`]), to show beside the render.
    pub picture: RgbImage,
}

/// How close a named render is to the mistake's and to the reference, in the signature's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Closeness {
    /// SSIM of thumbnails (1 is the same picture).
    Ssim {
        /// To the mistake's thumbnail.
        to_mistake: f64,
        /// To the reference's.
        to_reference: f64,
    },
    /// Distances of tile means in standard errors ([`tiles`]; about 1 for the same code).
    Tiles {
        /// To the mistake's tile means.
        to_mistake: f64,
        /// To the reference's expected ones.
        to_reference: f64,
    },
}

/// How alike a render is to the reference and to each candidate fingerprint: SSIM of thumbnails,
/// or `−ln` of the tile distance; larger is more alike either way.
#[derive(Clone, Debug, PartialEq)]
pub struct Likeness {
    /// Which signatures were compared.
    pub kind: Kind,
    /// To the reference.
    pub to_reference: f64,
    /// The candidates, most alike first: (index into the fingerprints, likeness).
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

    /// The fingerprint the rule names, by index, if any: the best candidate, if it beats the
    /// others by the margin and is as alike as renders of that mistake are (the fit).
    pub fn named(&self, rule: Rule) -> Option<usize> {
        let (margin, fit) = match self.kind {
            Kind::Thumbnail => (rule.margin, rule.fit.unwrap_or(f64::NEG_INFINITY)),
            Kind::Tiles => (rule.tile_margin?, rule.tile_fit?),
        };
        let (index, best) = *self.to_mistakes.first()?;
        (self.margin()? >= margin && best >= fit).then_some(index)
    }

    /// The closeness of the best candidate, in the signature's own terms.
    fn closeness(&self) -> Option<Closeness> {
        let (_, best) = *self.to_mistakes.first()?;
        Some(match self.kind {
            Kind::Thumbnail => Closeness::Ssim { to_mistake: best, to_reference: self.to_reference },
            Kind::Tiles => {
                Closeness::Tiles { to_mistake: (-best).exp(), to_reference: (-self.to_reference).exp() }
            }
        })
    }
}

/// The loaded fingerprints and their rule.
#[derive(Clone, Debug, Default)]
pub struct Fingerprints {
    /// The rule.
    pub rule: Rule,
    /// Each fresh fingerprint with its signature.
    pub prints: Vec<(Entry, Signature)>,
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
            let path = dir.join(entry.file_name());
            let signature = match entry.kind {
                Kind::Thumbnail => {
                    Signature::Thumbnail(read_png(&path).map_err(|e| FileError::image(&path, &e))?)
                }
                Kind::Tiles => Signature::Tiles(read_json(&path)?),
            };
            prints.push((entry, signature));
        }
        Ok(Self { rule: file.rule, prints })
    }

    /// How alike the failed render `evidence` is to the reference and to the fingerprints of
    /// `scene` of its kind whose checkpoint is one of `checkpoints`; `None` if they cannot be
    /// compared.
    pub fn likeness(&self, scene: &str, evidence: Evidence, checkpoints: &[u32]) -> Option<Likeness> {
        let kind = evidence.kind();
        let candidates = self.prints.iter().enumerate().filter(|(_, (e, signature))| {
            e.scene == scene && checkpoints.contains(&e.checkpoint) && signature.kind() == kind
        });
        let (to_reference, mut to_mistakes): (f64, Vec<(usize, f64)>) = match evidence {
            Evidence::Picture { render, reference } => {
                let mine = thumbnail(render);
                let similarity = |other: &RgbImage| SsimMap::new(&mine, other).ok().map(|m| m.mean());
                let to_mistakes = candidates
                    .filter_map(|(i, (_, s))| match s {
                        Signature::Thumbnail(t) => Some((i, similarity(t)?)),
                        Signature::Tiles(_) => None,
                    })
                    .collect();
                (similarity(&thumbnail(reference))?, to_mistakes)
            }
            Evidence::Tiles { mine, expected } => {
                let likeness = |other: &TileSignature| mine.distance(other).map(|d| -d.ln());
                let to_mistakes = candidates
                    .filter_map(|(i, (_, s))| match s {
                        Signature::Tiles(t) => Some((i, likeness(t)?)),
                        Signature::Thumbnail(_) => None,
                    })
                    .collect();
                (likeness(expected)?, to_mistakes)
            }
        };
        to_mistakes.sort_by(|a, b| b.1.total_cmp(&a.1));
        Some(Likeness { kind, to_reference, to_mistakes })
    }

    /// The known mistake the failed render `evidence` of `scene` shows, if the rule names one
    /// (module docs).
    pub fn name(&self, scene: &str, evidence: Evidence, checkpoints: &[u32]) -> Option<Naming> {
        let likeness = self.likeness(scene, evidence, checkpoints)?;
        let index = likeness.named(self.rule)?;
        let (entry, signature) = &self.prints[index];
        Some(Naming { entry: entry.clone(), closeness: likeness.closeness()?, picture: signature.picture() })
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
mod tests;
