//! Checkpoint 7 through the renderer: anti-aliased images are identical for any thread count.

mod checkpoint7 {
    use raylab::geometry::SplitMethod;
    use raylab::render::render;
    use raylab::scene::{Scene, World};
    use std::path::Path;

    fn render_with_threads(threads: usize, seed: u64) -> raylab::film::Film {
        let scene = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/aliasing.toml")).unwrap();
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let mut settings = scene.settings;
        settings.spp = 4;
        settings.seed = seed;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render(&world, &settings, &|_| {}))
    }

    #[test]
    fn one_and_two_threads_give_identical_bits() {
        let one = render_with_threads(1, 3);
        let two = render_with_threads(2, 3);
        let bits = |f: &raylab::film::Film| {
            f.pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
        };
        assert!(bits(&one) == bits(&two), "thread count changed the image");
        let other_seed = render_with_threads(2, 4);
        assert!(bits(&one) != bits(&other_seed), "the seed must matter at spp > 1");
    }

    #[test]
    fn edges_get_intermediate_values_that_one_sample_cannot_give() {
        // With one centred sample every pixel of this black-and-white scene is 0 or 1; averaged
        // jittered samples give edge pixels fractional coverage.
        let film = render_with_threads(2, 5);
        let partial = film.pixels().iter().filter(|p| p.x > 0.05 && p.x < 0.95).count();
        assert!(partial > 200, "only {partial} edge pixels have fractional values");
    }
}
