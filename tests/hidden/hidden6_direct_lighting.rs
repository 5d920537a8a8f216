//! Checkpoint 6, hidden: rendered floors against the closed form `ρ/π · Φ/4π · cos θ / r²`, with
//! two lights, seen from below, and under a blocker whose shadow is found geometrically.

use raylab::film::Film;
use raylab::geometry::SplitMethod;
use raylab::math::{Vec2, Vec3};
use raylab::render::render;
use raylab::scene::{Scene, World};
use std::f32::consts::PI;
use std::path::Path;

const ALBEDO: Vec3 = Vec3::new(0.6, 0.4, 0.2);

/// A floor quad of `ALBEDO` (x and z in [-10, 10], y = 0) seen from `eye`, under `lights` of flux
/// `[r, g, b]` at the given points, with `extra` objects; rendered at 32 × 32, 1 spp.
fn render_floor(eye: Vec3, lights: &[(Vec3, Vec3)], extra: &str) -> (Scene, Film) {
    let mut text = format!(
        r#"
        [camera]
        position = [{}, {}, {}]
        look_at = [0, 0, 0]
        up = [0, 1, 0]
        fov = 60
        width = 32
        height = 32
        [integrator]
        kind = "direct_lighting"
        [materials.floor]
        kind = "diffuse"
        albedo = [{}, {}, {}]
        [[objects]]
        shape = "quad"
        material = "floor"
        scale = [10, 1, 10]
        {extra}
        "#,
        eye.x, eye.y, eye.z, ALBEDO.x, ALBEDO.y, ALBEDO.z
    );
    for (p, flux) in lights {
        text += &format!(
            "[[lights]]\nposition = [{}, {}, {}]\nflux = [{}, {}, {}]\n",
            p.x, p.y, p.z, flux.x, flux.y, flux.z
        );
    }
    let scene = Scene::from_toml(&text, Path::new("hidden_floor.toml")).unwrap();
    let film = render(&World::new(&scene, SplitMethod::ObjectMedian), &scene.settings, &|_| {});
    (scene, film)
}

/// The closed form at the floor point `p` (normal `n`, toward the viewer) from one light.
fn closed_form(p: Vec3, n: Vec3, light: Vec3, flux: Vec3) -> Vec3 {
    let to_light = light - p;
    let r2 = to_light.length_squared();
    let cos = (n.dot(to_light) / r2.sqrt()).max(0.0);
    ALBEDO / PI * flux / (4.0 * PI) * cos / r2
}

/// Checks every pixel of `film` against `want(floor point)`, and returns how many were checked.
fn check_pixels(scene: &Scene, film: &Film, mut want: impl FnMut(Vec3) -> Option<Vec3>) -> usize {
    let mut checked = 0;
    for y in 0..film.height() {
        for x in 0..film.width() {
            // The pixel-centre ray meets the plane y = 0 here, solved without the BVH.
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let p = ray.at(-ray.origin.y / ray.dir.y);
            let Some(want) = want(p) else { continue };
            let got = film.get(x, y);
            // f32 rounding plus the shadow-ray offset, as in the public floor test: 1e-4 relative.
            let scale = want.max_element().max(1e-3);
            assert!(
                (got - want).abs().max_element() <= 1e-4 * scale,
                "pixel ({x}, {y}) at {p}: {got} vs {want}"
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn a_floor_under_two_lights_shows_the_sum_of_both_closed_forms() {
    let lights = [
        (Vec3::new(0.5, 1.0, -0.2), Vec3::new(12.0, 6.0, 3.0)),
        (Vec3::new(-0.7, 2.0, 0.4), Vec3::new(5.0, 10.0, 20.0)),
    ];
    let (scene, film) = render_floor(Vec3::new(0.2, 3.0, 0.9), &lights, "");
    let sum = |p| Some(lights.iter().map(|&(l, f)| closed_form(p, Vec3::Y, l, f)).sum());
    assert_eq!(check_pixels(&scene, &film, sum), 32 * 32);
}

/// Seen from below, the two-sided floor faces down: the light above it is behind the surface.
#[test]
fn a_floor_seen_from_below_is_lit_by_the_light_below_it_only() {
    let (above, below) = (
        (Vec3::new(0.3, 1.0, 0.1), Vec3::splat(30.0)),
        (Vec3::new(-0.2, -1.5, 0.3), Vec3::new(8.0, 16.0, 4.0)),
    );
    let (scene, film) = render_floor(Vec3::new(0.3, -3.0, 0.7), &[above, below], "");
    let from_below = |p| Some(closed_form(p, -Vec3::Y, below.0, below.1));
    assert_eq!(check_pixels(&scene, &film, from_below), 32 * 32);
}

/// A square blocker at height 0.6 over the floor: where the segment from a floor point to the light
/// crosses it, black; elsewhere the closed form. Pixels within 0.03 of the shadow's edge are left
/// out (there the answer depends on the shadow ray's offset).
#[test]
fn a_blocker_casts_the_shadow_its_geometry_predicts() {
    let light = (Vec3::new(0.1, 1.5, -0.1), Vec3::splat(40.0));
    let blocker = "[[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\ntranslate = [0, 0.6, 0]\nscale = [0.3, 1, 0.3]\n";
    let (scene, film) = render_floor(Vec3::new(0.2, 3.0, 2.0), &[light], blocker);
    let camera = scene.camera.ray(Vec2::ZERO).origin;
    // Where the segment from the floor point p to `eye` meets the blocker's plane, in the blocker's
    // units: below 1 it passes through the blocker.
    let through_blocker = |p: Vec3, eye: Vec3| {
        let c = p + (0.6 - p.y) / (eye.y - p.y) * (eye - p);
        c.x.abs().max(c.z.abs()) / 0.3
    };
    let margin = 0.03 / 0.3;
    let (mut lit, mut dark) = (0, 0);
    let checked = check_pixels(&scene, &film, |p| {
        // The blocker hides part of the floor from the camera too: those pixels are left out.
        if through_blocker(p, camera) < 1.0 + margin {
            return None;
        }
        match through_blocker(p, light.0) {
            s if s < 1.0 - margin => {
                dark += 1;
                Some(Vec3::ZERO)
            }
            s if s > 1.0 + margin => {
                lit += 1;
                Some(closed_form(p, Vec3::Y, light.0, light.1))
            }
            _ => None,
        }
    });
    assert!(checked > 500 && lit > 100 && dark > 20, "{checked} checked, {lit} lit, {dark} in shadow");
}
