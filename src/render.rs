//! The pixel loop: every pixel's radiance into a [`Film`], in parallel, deterministically.
//!
//! The film is cut into square tiles that rayon renders on any number of threads. Every pixel
//! draws its random numbers from its own generator, seeded from (scene seed, pixel index), so
//! the image is the same bit for bit whatever the thread count or the order tiles finish in.
//!
//! With one sample per pixel the ray goes through the pixel centre and no film position is drawn;
//! more samples go through [`estimate_pixel`] (checkpoint 7). Monte Carlo integrators draw their
//! numbers (light samples, bounces) from a second generator of the pixel, [`Rng::for_paths`], so
//! the film positions are the same whichever integrator renders.

use rayon::prelude::*;

use crate::film::Film;
use crate::integrator::Integrator;
use crate::math::{UVec2, Vec2, Vec3};
use crate::rng::Rng;
use crate::sampling::estimate_pixel;
use crate::scene::{RenderSettings, World};

/// Side of a square tile, in pixels.
const TILE: u32 = 16;

/// Renders the world's scene with `settings`, calling `progress` with the number of pixels of
/// every finished tile (`&|_| {}` for none; [`crate::progress::Progress`] prints).
pub fn render(world: &World, settings: &RenderSettings, progress: &(dyn Fn(u64) + Sync)) -> Film {
    render_with(world, settings, Integrator::from_settings(settings), progress)
}

/// [`render`] with another integrator than the scene's (`render`'s stand-ins, [`crate::fallback`]).
pub fn render_with(
    world: &World,
    settings: &RenderSettings,
    integrator: Integrator,
    progress: &(dyn Fn(u64) + Sync),
) -> Film {
    let camera = &world.scene().camera;
    let (width, height) = (camera.width(), camera.height());
    let tiles: Vec<UVec2> = (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| UVec2::new(tx, ty) * TILE))
        .collect();
    let rendered: Vec<(UVec2, Vec<Vec3>)> = tiles
        .par_iter()
        .map(|&corner| {
            let end = (corner + TILE).min(UVec2::new(width, height));
            let pixels: Vec<Vec3> = (corner.y..end.y)
                .flat_map(|y| (corner.x..end.x).map(move |x| UVec2::new(x, y)))
                .map(|pixel| {
                    let index = pixel.y as u64 * width as u64 + pixel.x as u64;
                    let mut paths = Rng::for_paths(settings.seed, index);
                    let mut radiance = |film: Vec2| integrator.li(world, camera.ray(film), &mut paths);
                    if settings.spp == 1 {
                        radiance(pixel.as_vec2() + 0.5)
                    } else {
                        let mut rng = Rng::for_pixel(settings.seed, index);
                        estimate_pixel(pixel, settings.spp, &mut rng, radiance)
                    }
                })
                .collect();
            progress(pixels.len() as u64);
            (corner, pixels)
        })
        .collect();
    let mut film = Film::new(width, height);
    for (corner, pixels) in rendered {
        let tile_width = (corner.x + TILE).min(width) - corner.x;
        for (i, value) in pixels.into_iter().enumerate() {
            let (dx, dy) = (i as u32 % tile_width, i as u32 / tile_width);
            film.set(corner.x + dx, corner.y + dy, value);
        }
    }
    film
}
