//! One graded scene: rendered by the tree's renderer in child processes (once, or
//! `tile_test.renders` times for a noisy scene) and scored against its reference: the rubric's
//! checks, or the tile test ([`crate::noisy`]) with the mean render's SSIM as a diagnostic.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use image::RgbImage;
use indicatif::ProgressBar;

use super::{GradeError, GradeOptions};
use crate::features::Masks;
use crate::images::{film_to_image, read_png};
use crate::metrics::{Comparison, Measured};
use crate::noisy::{compare, graded_seed, tile_means, NoisyReference};
use crate::outcome::{SceneResult, SceneStatus};
use crate::reference::{load_reference, load_tile_reference};
use crate::rubric::{Check, GradedScene, TileTest};
use crate::run::child::{graded_reads, run_graded, OwnFolder, CHILD_ENV};
use crate::scene_failure::SceneFailure;
use crate::ssim::{SizeMismatch, SsimMap};
use raylab_base::film::Film;
use raylab_base::image_io::read_pfm;

/// How the graded children render: the tree's renderer binary, the tree, the environment and
/// the time limit of one render.
struct Child<'a> {
    renderer: &'a Path,
    code: PathBuf,
    options: &'a GradeOptions,
    render: Render<'a>,
}

/// How one scene is rendered: its time limit, and the checkpoints drawn by stand-ins.
#[derive(Clone, Copy)]
pub(super) struct Render<'a> {
    /// The time one render may take.
    pub(super) limit: Duration,
    /// The checkpoints drawn by their stand-ins.
    pub(super) stand_ins: &'a [u32],
}

impl Child<'_> {
    /// Renders `scene` at its graded spp with `seed` in a child process: the PNG it writes, and
    /// the linear film if `pfm`; with the seconds it took.
    fn render(&self, scene: &GradedScene, seed: u64, pfm: bool) -> Result<(Rendered, f64), SceneFailure> {
        let own = OwnFolder::new().map_err(|e| SceneFailure::NoFolder(e.kind()))?;
        let (png, film) = (own.path().join("render.png"), own.path().join("render.pfm"));
        let mut command = Command::new(self.renderer);
        command
            .current_dir(own.path())
            .env(CHILD_ENV, "1")
            .envs(self.options.env.iter().map(|(k, v)| (k, v)))
            .arg(self.code.join(&scene.file))
            .arg("--output")
            .arg(&png)
            .arg("--spp")
            .arg(scene.spp.to_string())
            .arg("--seed")
            .arg(seed.to_string())
            // A stub fails the scene, unless the grader read from the source that it is one and
            // the scene's picture is the same with its stand-in.
            .arg("--no-fallbacks");
        if !self.render.stand_ins.is_empty() {
            let ids: Vec<String> = self.render.stand_ins.iter().map(u32::to_string).collect();
            command.arg("--stand-ins").arg(ids.join(","));
        }
        if pfm {
            command.arg("--pfm").arg(&film);
            if self.options.wide_tile_renders {
                command.arg("--accel").arg("wide");
            }
        }
        let run = run_graded(command, self.render.limit, &graded_reads(&self.code), &own).map_err(|e| {
            SceneFailure::CannotStart { renderer: self.renderer.to_path_buf(), kind: e.kind() }
        })?;
        let rendered = if !run.success() {
            Err(SceneFailure::Failed(run.failure(self.render.limit)))
        } else if !png.exists() || (pfm && !film.exists()) {
            Err(SceneFailure::NoImage)
        } else {
            let unreadable = |e: &dyn std::fmt::Display| SceneFailure::Unreadable(Some(e.to_string()));
            let image = read_png(&png).map_err(|e| unreadable(&e));
            let linear = if pfm { read_pfm(&film).map(Some).map_err(|e| unreadable(&e)) } else { Ok(None) };
            image.and_then(|image| Ok(Rendered { image, film: linear? }))
        };
        Ok((rendered?, run.seconds))
    }
}

/// What one graded render wrote.
struct Rendered {
    image: RgbImage,
    film: Option<Film>,
}

/// Renders one scene with the tree's `renderer` in child processes and scores it.
pub(super) fn grade_scene(
    options: &GradeOptions,
    renderer: Result<&Path, &SceneFailure>,
    scene: GradedScene,
    render: Render,
    progress: &ProgressBar,
) -> Result<SceneResult, GradeError> {
    let (reference, masks) = load_reference(&options.root, &scene)?;
    let tiles = match &scene.tile_test {
        Some(test) => Some(load_tile_reference(&options.root, &scene, test)?),
        None => None,
    };
    // Absolute: the renderer runs in a scratch folder, not in the tree.
    let code = options.code.as_deref().unwrap_or(&options.root);
    let code = std::path::absolute(code)
        .map_err(|source| GradeError::Unreadable { path: code.to_path_buf(), source })?;
    let mut result = SceneResult {
        scene: scene.clone(),
        checks: Vec::new(),
        error: None,
        seconds: 0.0,
        render: None,
        reference,
        ssim: None,
        tiles: None,
        stand_ins: render.stand_ins.to_vec(),
        status: SceneStatus::Failed,
        named: None,
    };
    let renderer = match renderer {
        Ok(renderer) => renderer,
        Err(e) => {
            result.error = Some(shown(e.clone(), &scene));
            return Ok(result);
        }
    };
    let child = Child { renderer, code, options, render };
    let base = options.seed.unwrap_or(scene.seed);
    let scored = match (&scene.tile_test, &tiles) {
        (Some(test), Some(tiles)) => tile_test(&child, &mut result, test, tiles, base, progress),
        _ => child.render(&scene, base, false).and_then(|(rendered, seconds)| {
            result.seconds = seconds;
            score(&scene, rendered.image, &result.reference, &masks)
        }),
    };
    match scored {
        Ok((render, checks, ssim)) => {
            result.render = Some(render);
            result.checks = checks;
            result.ssim = Some(ssim);
        }
        Err(e) => result.error = Some(shown(e, &result.scene)),
    }
    Ok(result)
}

/// `failure` as `scene` may show it: a hidden scene by its fixed words only, never with the
/// student's output.
fn shown(failure: SceneFailure, scene: &GradedScene) -> SceneFailure {
    if scene.hidden {
        failure.hidden()
    } else {
        failure
    }
}

type Scored = (RgbImage, Vec<(Check, Measured)>, SsimMap);

fn score(
    scene: &GradedScene,
    render: RgbImage,
    reference: &RgbImage,
    masks: &Masks,
) -> Result<Scored, SceneFailure> {
    let comparison = Comparison::new(&render, reference, masks).map_err(SceneFailure::Size)?;
    let checks = scene.checks.iter().map(|c| (c.clone(), comparison.measure(c))).collect();
    let ssim = comparison.ssim().clone();
    Ok((render, checks, ssim))
}

/// The tile test of a noisy scene ([`crate::noisy`]): `test.renders` renders with the seeds
/// [`graded_seed`] of `base`, their tile means against the reference's; their mean is the image
/// shown, as the reference is a mean too, with its SSIM against the reference as a diagnostic.
fn tile_test(
    child: &Child,
    result: &mut SceneResult,
    test: &TileTest,
    tiles: &NoisyReference,
    base: u64,
    progress: &ProgressBar,
) -> Result<Scored, SceneFailure> {
    let scene = &result.scene;
    let mut means = Vec::new();
    let mut mean: Option<Film> = None;
    for k in 0..test.renders {
        progress.set_message(format!("rendering {} ({} of {})", scene.name, k + 1, test.renders));
        let (rendered, seconds) = child
            .render(scene, graded_seed(base, k), true)
            .map_err(|e| SceneFailure::RenderOf { k: k + 1, n: test.renders, failure: Box::new(e) })?;
        result.seconds += seconds;
        let film = rendered.film.expect("asked for the film");
        let (w, h) = result.reference.dimensions();
        if (film.width(), film.height()) != (w, h) {
            return Err(SceneFailure::Size(SizeMismatch(film.width(), film.height(), w, h)));
        }
        means.push(tile_means(&film, test.tile));
        mean.get_or_insert_with(|| Film::new(w, h)).add_scaled(&film, 1.0 / test.renders as f32);
    }
    let verdict = compare(&means, tiles, test.alpha);
    let render = film_to_image(&mean.expect("a tile test has at least 2 renders (rubric rule)"));
    let ssim = SsimMap::new(&render, &result.reference).map_err(SceneFailure::Size)?;
    let measured = [
        Measured { value: verdict.failures.len() as f64, passed: verdict.passed() },
        Measured { value: ssim.mean(), passed: true },
    ];
    let checks = scene.graded_checks().into_iter().zip(measured).collect();
    result.tiles = Some(verdict);
    Ok((render, checks, ssim))
}
