//! Feature masks: which pixels show glass, shadow, or an edge between objects.
//!
//! Made once per scene with the reference solution (by `grader update-references`), stored beside
//! the reference image as a PNG (red = glass, green = shadow, blue = edge), and used to score a
//! render where a checkpoint's effect shows, instead of averaging it away over the whole image.

use image::RgbImage;

use crate::rubric::Mask;
use raylab::integrator::trace_to_diffuse;
use raylab::material::Material;
use raylab::math::{spawn_ray_to, UVec2, Vec2};
use raylab::scene::World;

/// One boolean per pixel for each mask.
#[derive(Clone, Debug, PartialEq)]
pub struct Masks {
    image: RgbImage,
}

impl Masks {
    /// The masks of the world's scene, from one ray through each pixel centre.
    ///
    /// Glass: the first surface hit is glass. Shadow: the first diffuse surface reached (through
    /// glass, as the integrators do) faces a light that something blocks. Edge: the pixel, or one
    /// of its 8 neighbours, sees a different object (or nothing), so anti-aliasing changes it.
    pub fn render(world: &World) -> Self {
        let scene = world.scene();
        let (width, height) = (scene.camera.width(), scene.camera.height());
        let max_depth = scene.settings.max_depth;
        let pixels: Vec<UVec2> =
            (0..height).flat_map(|y| (0..width).map(move |x| UVec2::new(x, y))).collect();
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
        Self { image }
    }

    /// Masks stored as a PNG (red = glass, green = shadow, blue = edge).
    pub fn from_image(image: RgbImage) -> Self {
        Self { image }
    }

    /// The PNG form.
    pub fn image(&self) -> &RgbImage {
        &self.image
    }

    /// Whether pixel `(x, y)` is in `mask`.
    pub fn contains(&self, mask: Mask, x: u32, y: u32) -> bool {
        let channel = match mask {
            Mask::Glass => 0,
            Mask::Shadow => 1,
            Mask::Edge => 2,
        };
        self.image.get_pixel(x, y)[channel] >= 128
    }
}
