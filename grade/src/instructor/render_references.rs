//! Rendering the references, the instructor's `grader update-references`: each graded scene's
//! image, its feature masks, and for a tile-tested scene the tile means of many renders, all
//! with the reference solution linked into this process. Only the instructor's grader has this
//! module (the `instructor` feature): a student's grader never links the renderer, so saving a
//! region never rebuilds it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use image::RgbImage;
use indicatif::ProgressBar;
use raylab::geometry::SplitMethod;
use raylab::integrator::trace_to_diffuse;
use raylab::material::Material;
use raylab::math::{spawn_ray_to, UVec2, Vec2};
use raylab::scene::{Scene, SceneError, World};
use raylab_base::film::Film;
use raylab_base::image_io::write_file_atomic;

use crate::features::Masks;
use crate::file_error::FileError;
use crate::images::{film_to_image, write_png};
use crate::instructor::error::InstructorError;
use crate::noisy::{expected_seed, solution_seed, tile_means, TileFile};
use crate::reference::{
    image_path, inputs_hash, masks_path, reference_dir, tiles_path, Manifest, ReferenceEntry,
};
use crate::rubric::{GradedScene, Rubric, TileTest};

/// How a render in this process traces rays.
pub type Tracing = for<'a> fn(&'a Scene) -> World<'a>;

/// As a graded render traces: through checkpoint 4's binary tree. The references graded by SSIM
/// and their masks are rendered so, which makes the solution's graded renders equal them bit
/// for bit (a ray through an edge two objects share may hit either, and another tree may pick
/// the other: 21 to 27 pixels of the 512 × 512 references did, SSIM 0.9995).
pub const GRADED_TRACING: Tracing = |scene| World::new(scene, SplitMethod::ObjectMedian);

/// The harness's wide BVH (the same closest hits, three to four times faster here), for the
/// references of tile-tested scenes: they are compared by their tile means, where a tie at an
/// edge is noise far below the renders' own.
pub const FAST_TRACING: Tracing = |scene| World::wide(scene);

/// Renders a graded scene in this process at `spp` with `seed`.
pub fn render_scene(
    root: &Path,
    scene: &GradedScene,
    spp: u32,
    seed: u64,
    tracing: Tracing,
) -> Result<(Scene, Film), SceneError> {
    let loaded = Scene::load(&root.join(&scene.file))?;
    let mut settings = loaded.settings;
    settings.spp = spp;
    settings.seed = seed;
    let film = raylab::render::render(&tracing(&loaded), &settings, &|_| {});
    Ok((loaded, film))
}

/// The reference of a tile-tested scene: its `reference_renders` high-spp renders (whose average
/// is returned as the reference image) and `solution_renders` renders at the graded spp, as tile
/// means written to [`tiles_path`].
fn render_tile_reference(
    root: &Path,
    scene: &GradedScene,
    test: &TileTest,
) -> Result<(Scene, Film), InstructorError> {
    let mut expected = Vec::new();
    let mut average: Option<(Scene, Film)> = None;
    for r in 0..test.reference_renders {
        let (loaded, film) = render_scene(root, scene, scene.reference_spp, expected_seed(r), FAST_TRACING)?;
        expected.push(tile_means(&film, test.tile));
        let (_, sum) = average.get_or_insert_with(|| (loaded, Film::new(film.width(), film.height())));
        sum.add_scaled(&film, 1.0 / test.reference_renders as f32);
    }
    let mut solution = Vec::new();
    for s in 0..test.solution_renders {
        solution.push(tile_means(
            &render_scene(root, scene, scene.spp, solution_seed(s), FAST_TRACING)?.1,
            test.tile,
        ));
    }
    let file =
        TileFile { tile: test.tile, reference_spp: scene.reference_spp, spp: scene.spp, expected, solution };
    file.write(&tiles_path(root, scene))?;
    average.ok_or_else(|| InstructorError::NoTileRenders(scene.name.clone()))
}

/// Re-renders every reference image and mask and rewrites the manifest (the instructor's
/// command; it must run on the reference solution).
pub fn update_references(
    root: &Path,
    rubric: &Rubric,
    progress: &ProgressBar,
) -> Result<Manifest, InstructorError> {
    let mut manifest = Manifest::default();
    for scene in &rubric.scenes {
        progress.set_message(scene.name.clone());
        manifest.references.push(render_reference(root, scene)?);
        progress.inc(1);
    }
    write_manifests(root, rubric, &manifest)?;
    Ok(manifest)
}

/// Writes `manifest` as the manifests of the rubric's public and hidden references.
pub fn write_manifests(root: &Path, rubric: &Rubric, manifest: &Manifest) -> Result<(), InstructorError> {
    // Each folder's manifest lists its own scenes, so the starter's has no word of hidden ones.
    for hidden in [false, true] {
        let names: Vec<&str> =
            rubric.scenes.iter().filter(|s| s.hidden == hidden).map(|s| s.name.as_str()).collect();
        if hidden && names.is_empty() {
            continue;
        }
        let part = Manifest {
            references: manifest
                .references
                .iter()
                .filter(|r| names.contains(&r.name.as_str()))
                .cloned()
                .collect(),
        };
        let text = toml::to_string_pretty(&part).expect("a manifest is plain data");
        let path = root.join(reference_dir(hidden)).join("manifest.toml");
        let header = "# Written by `grader update-references`; do not edit by hand.\n\n";
        write_file_atomic(&path, format!("{header}{text}").as_bytes())
            .map_err(|e| FileError::unwritable(&path, &e))?;
    }
    Ok(())
}

/// Renders the reference image and masks of one scene into its reference folder (and its tile
/// means, if it is tile-tested): the manifest's entry for it.
pub fn render_reference(root: &Path, scene: &GradedScene) -> Result<ReferenceEntry, InstructorError> {
    let dir = root.join(reference_dir(scene.hidden));
    std::fs::create_dir_all(&dir).map_err(|e| FileError::unwritable(&dir, &e))?;
    let start = Instant::now();
    let (loaded, film) = match &scene.tile_test {
        None => render_scene(root, scene, scene.reference_spp, scene.seed, GRADED_TRACING)?,
        Some(test) => render_tile_reference(root, scene, test)?,
    };
    let render_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    // Timed as the grader's renders trace, through checkpoint 4's tree.
    render_scene(root, scene, scene.spp, scene.seed, GRADED_TRACING)?;
    let graded_render_seconds = start.elapsed().as_secs_f64();
    let png =
        |path: PathBuf, image: &RgbImage| write_png(&path, image).map_err(|e| FileError::image(&path, &e));
    png(image_path(root, scene), &film_to_image(&film))?;
    let masks = render_masks(&GRADED_TRACING(&loaded));
    png(masks_path(root, scene), masks.image())?;
    Ok(ReferenceEntry {
        name: scene.name.clone(),
        inputs_hash: inputs_hash(&root.join(&scene.file))?,
        spp: scene.reference_spp,
        seed: scene.seed,
        raylab_version: env!("CARGO_PKG_VERSION").to_string(),
        render_seconds: (render_seconds * 1000.0).round() / 1000.0,
        graded_render_seconds: (graded_render_seconds * 1000.0).round() / 1000.0,
    })
}

/// The masks of the world's scene, from one ray through each pixel centre.
///
/// Glass: the first surface hit is glass. Shadow: the first diffuse surface reached (through
/// glass, as the integrators do) faces a light that something blocks. Edge: the pixel, or one
/// of its 8 neighbours, sees a different object (or nothing), so anti-aliasing changes it.
pub fn render_masks(world: &World) -> Masks {
    let scene = world.scene();
    let (width, height) = (scene.camera.width(), scene.camera.height());
    let max_depth = scene.settings.max_depth;
    let pixels: Vec<UVec2> = (0..height).flat_map(|y| (0..width).map(move |x| UVec2::new(x, y))).collect();
    let mut objects = Vec::with_capacity(pixels.len());
    let mut image = RgbImage::new(width, height);
    for &pixel in &pixels {
        let ray = scene.camera.ray(pixel.as_vec2() + Vec2::splat(0.5));
        let hit = world.intersect(&ray);
        objects.push(hit.map(|h| h.object));
        let glass = matches!(hit.map(|h| *h.material), Some(Material::PerfectRefraction { .. }));
        let shadow = trace_to_diffuse(world, ray, max_depth).is_some_and(|d| {
            let n = if d.hit.normal.dot(d.wo) < 0.0 { -d.hit.normal } else { d.hit.normal };
            scene.lights.iter().any(|light| {
                n.dot(light.position - d.hit.p) > 0.0
                    && world.occluded(&spawn_ray_to(d.hit.p, n, light.position))
            })
        });
        image.get_pixel_mut(pixel.x, pixel.y)[0] = if glass { 255 } else { 0 };
        image.get_pixel_mut(pixel.x, pixel.y)[1] = if shadow { 255 } else { 0 };
    }
    for &UVec2 { x, y } in &pixels {
        let here = objects[(y * width + x) as usize];
        let differs = (-1i64..=1).flat_map(|dy| (-1i64..=1).map(move |dx| (dx, dy))).any(|(dx, dy)| {
            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
            nx >= 0
                && ny >= 0
                && nx < width as i64
                && ny < height as i64
                && objects[(ny * width as i64 + nx) as usize] != here
        });
        image.get_pixel_mut(x, y)[2] = if differs { 255 } else { 0 };
    }
    Masks::from_image(image)
}
