//! Reference images and their manifest: how each was made, so a stale one is caught.
//!
//! `reference/manifest.toml` records, per graded scene, a hash of the scene file and every mesh it
//! reads, the spp and seed, the raylab version and the render time. Grading refuses (exit 2) a
//! reference whose scene or meshes changed since, rather than mis-grading against it. Hidden
//! scenes keep theirs, and their own manifest, in `hidden/reference/`.
//!
//! A scene graded by the tile test ([`crate::noisy`]) has, beside its image, the tile means of
//! the reference solution's renders (`<scene>.tiles.json`); its image is the average of the
//! high-spp renders. Making them is the instructor's (`render_references.rs`); this module only
//! reads them, with the scene file's description alone, so grading links no renderer.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::features::Masks;
use crate::file_error::{parse_toml, read_toml, FileError, Problem, Staleness};
use crate::images::read_png;
use crate::noisy::{NoisyReference, TileFile};
use crate::plain::NotRead;
use crate::rubric::{GradedScene, Rubric, TileTest};
use raylab_base::scene_desc::SceneDesc;

/// `reference/manifest.toml`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// One entry per graded scene.
    #[serde(rename = "reference", default)]
    pub references: Vec<ReferenceEntry>,
}

/// How one reference image was made.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReferenceEntry {
    /// The graded scene's name.
    pub name: String,
    /// FNV-1a 64 of the scene file and the meshes it reads, in order, as hex.
    pub inputs_hash: String,
    /// Samples per pixel of the reference.
    pub spp: u32,
    /// Seed of the reference.
    pub seed: u64,
    /// raylab's version when it was made.
    pub raylab_version: String,
    /// Seconds the reference render took (in process, all threads; for a tile-tested scene all
    /// its reference renders, at `reference_spp` and at the graded spp).
    pub render_seconds: f64,
    /// Seconds a single-sample render took: the base of the grader's time limit.
    pub graded_render_seconds: f64,
}

/// The reference folders, public and hidden, relative to the repository root.
pub const REFERENCE_DIRS: [&str; 2] = ["reference", "hidden/reference"];

/// The folder of a scene's reference, relative to the repository root.
pub(crate) fn reference_dir(hidden: bool) -> &'static str {
    REFERENCE_DIRS[hidden as usize]
}

/// The reference image of a scene.
pub fn image_path(root: &Path, scene: &GradedScene) -> PathBuf {
    root.join(reference_dir(scene.hidden)).join(format!("{}.png", scene.name))
}

/// The feature masks of a scene.
pub fn masks_path(root: &Path, scene: &GradedScene) -> PathBuf {
    root.join(reference_dir(scene.hidden)).join(format!("{}.masks.png", scene.name))
}

/// The reference solution's tile means of a tile-tested scene.
pub fn tiles_path(root: &Path, scene: &GradedScene) -> PathBuf {
    root.join(reference_dir(scene.hidden)).join(format!("{}.tiles.json", scene.name))
}

/// 64-bit FNV-1a: a small, fixed, well-known hash; enough to notice an edited file.
fn fnv1a(bytes: &[u8], mut hash: u64) -> u64 {
    for &b in bytes {
        hash ^= b as u64;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// `fnv1a` of `bytes` from the standard offset basis.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    fnv1a(bytes, FNV_OFFSET)
}

/// [`fnv1a64`] as 16 hex digits.
pub fn fnv1a_hex(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a64(bytes))
}

/// FNV-1a's offset basis, its starting value.
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// The hash of a scene file and every mesh file it names, in order.
pub fn inputs_hash(scene_file: &Path) -> Result<String, FileError> {
    let read = |p: &Path| std::fs::read(p).map_err(|e| FileError::unreadable(p, &e));
    let text = read(scene_file)?;
    let mut hash = fnv1a(&text, FNV_OFFSET);
    let desc: SceneDesc = parse_toml(scene_file, &String::from_utf8_lossy(&text))?;
    for file in desc.objects.iter().filter_map(|o| o.file.as_ref()) {
        let mesh = scene_file.parent().unwrap_or(Path::new("")).join(file.get_ref());
        hash = fnv1a(&read(&mesh)?, hash);
    }
    Ok(format!("{hash:016x}"))
}

/// The references' manifest of `root`, with the reference of each of `scenes` checked: in the
/// manifest, fresh, readable and of its scene's size. Checked before anything is built, so a
/// broken reference stops a grade (or a class) at once, naming the file.
pub fn checked_manifest<'a>(
    root: &Path,
    rubric: &Rubric,
    scenes: impl IntoIterator<Item = &'a GradedScene>,
) -> Result<Manifest, FileError> {
    let manifest = Manifest::load(root, rubric)?;
    for scene in scenes {
        manifest.fresh_entry(root, scene)?;
        load_reference(root, scene)?;
    }
    Ok(manifest)
}

impl Manifest {
    /// Reads `reference/manifest.toml`, and `hidden/reference/manifest.toml` if the rubric has
    /// hidden scenes.
    pub fn load(root: &Path, rubric: &Rubric) -> Result<Manifest, FileError> {
        let mut manifest = Manifest::default();
        let has_hidden = rubric.scenes.iter().any(|s| s.hidden);
        for dir in &REFERENCE_DIRS[..1 + has_hidden as usize] {
            let path = root.join(dir).join("manifest.toml");
            let text = std::fs::read_to_string(&path)
                .map_err(|e| FileError::new(&path, Problem::NoReferences(NotRead::Io(e.to_string()))))?;
            let part: Manifest = parse_toml(&path, &text)?;
            manifest.references.extend(part.references);
        }
        Ok(manifest)
    }

    /// The entry of a scene, checked against the scene's files and the rubric's spp and seed.
    pub fn fresh_entry(&self, root: &Path, scene: &GradedScene) -> Result<&ReferenceEntry, FileError> {
        let stale = |why: Staleness| {
            let image = Path::new(reference_dir(scene.hidden)).join(format!("{}.png", scene.name));
            FileError::new(&image, Problem::Stale(why))
        };
        let entry = self
            .references
            .iter()
            .find(|r| r.name == scene.name)
            .ok_or_else(|| stale(Staleness::NotInManifest))?;
        if entry.inputs_hash != inputs_hash(&root.join(&scene.file))? {
            return Err(stale(Staleness::InputsChanged(scene.file.clone())));
        }
        if entry.spp != scene.reference_spp || entry.seed != scene.seed {
            return Err(stale(Staleness::SamplesOrSeed));
        }
        Ok(entry)
    }
}

/// The film size a scene renders at, from its file.
fn film_size(root: &Path, scene: &GradedScene) -> Result<(u32, u32), FileError> {
    let desc: SceneDesc = read_toml(&root.join(&scene.file))?;
    Ok((desc.camera.width, desc.camera.height))
}

/// The reference solution's tile means of a tile-tested scene, checked against the rubric.
pub fn load_tile_reference(
    root: &Path,
    scene: &GradedScene,
    test: &TileTest,
) -> Result<NoisyReference, FileError> {
    let path = tiles_path(root, scene);
    let file = TileFile::read(&path)?;
    let counts = (file.expected.len() as u32, file.solution.len() as u32);
    let (width, height) = film_size(root, scene)?;
    let tiles = (width.div_ceil(test.tile) * height.div_ceil(test.tile)) as usize;
    if (file.tile, file.reference_spp, file.spp) != (test.tile, scene.reference_spp, scene.spp)
        || counts != (test.reference_renders, test.solution_renders)
        || file.expected.iter().chain(&file.solution).any(|r| r.len() != tiles)
    {
        return Err(FileError::new(&path, Problem::Stale(Staleness::TileTest)));
    }
    Ok(file.reference())
}

/// The reference image and masks of a scene, checked to be of the scene's film size.
pub fn load_reference(root: &Path, scene: &GradedScene) -> Result<(image::RgbImage, Masks), FileError> {
    let read = |path: &Path| read_png(path).map_err(|e| FileError::image(path, &e));
    let (image_path, masks_path) = (image_path(root, scene), masks_path(root, scene));
    let (image, masks) = (read(&image_path)?, read(&masks_path)?);
    let film = film_size(root, scene)?;
    for (path, size) in [(image_path, image.dimensions()), (masks_path, masks.dimensions())] {
        if size != film {
            return Err(FileError::new(&path, Problem::WrongSize { image: size, film }));
        }
    }
    Ok((image, Masks::from_image(masks)))
}
