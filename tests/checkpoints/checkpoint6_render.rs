//! Checkpoint 6 through the renderer: a rendered floor under a point light matches the closed form
//! at every pixel.

mod checkpoint6 {
    use raylab::geometry::SplitMethod;
    use raylab::math::{Vec2, Vec3};
    use raylab::render::render;
    use raylab::scene::{Scene, World};
    use std::f32::consts::PI;
    use std::path::Path;

    const SCENE: &str = r#"
        [camera]
        position = [0.3, 3, 0.8]
        look_at = [0, 0, 0]
        up = [0, 1, 0]
        fov = 60
        width = 24
        height = 16
        [integrator]
        kind = "direct_lighting"
        [materials.grey]
        kind = "diffuse"
        albedo = [0.5, 0.25, 0.75]
        [[lights]]
        position = [0.4, 1.2, -0.3]
        flux = [10, 20, 30]
        [[objects]]
        shape = "quad"
        material = "grey"
        scale = [10, 1, 10]
    "#;

    #[test]
    fn every_pixel_of_a_lit_floor_matches_albedo_over_pi_times_i_cos_over_r_squared() {
        let scene = Scene::from_toml(SCENE, Path::new("floor.toml")).unwrap();
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let film = render(&world, &scene.settings, &|_| {});
        let (albedo, flux, light) =
            (Vec3::new(0.5, 0.25, 0.75), Vec3::new(10.0, 20.0, 30.0), Vec3::new(0.4, 1.2, -0.3));
        for y in 0..film.height() {
            for x in 0..film.width() {
                // Where the pixel-centre ray meets the plane y = 0, solved here, not by the BVH.
                let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
                let p = ray.at(-ray.origin.y / ray.dir.y);
                let to_light = light - p;
                let r2 = to_light.length_squared();
                let cos_theta = to_light.y / r2.sqrt();
                let want = albedo / PI * (flux / (4.0 * PI)) * cos_theta / r2;
                let got = film.get(x, y);
                // f32 rounding plus the shadow-ray offset: well within 1e-4 relative.
                assert!(
                    (got - want).abs().max_element() <= 1e-4 * want.max_element(),
                    "pixel ({x}, {y}): {got} vs {want}"
                );
            }
        }
    }
}
