//! A 512 × 512 render of each reference scene at its own samples per pixel, on every core: what
//! the grader spends per scene, BVH build included.
//!
//! `cargo bench --bench render`; figures in docs/PERFORMANCE.md.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use raylab::geometry::SplitMethod;
use raylab::render::render;
use raylab::scene::{Scene, World};

const SCENES: [&str; 4] = ["cornell_direct", "cornell_refract", "intersection_test", "aliasing"];

fn render_scenes(c: &mut Criterion) {
    let mut group = c.benchmark_group("render 512x512");
    group.sample_size(10);
    for name in SCENES {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/{name}.toml"));
        let mut scene = Scene::load(&path).expect("the reference scenes load");
        scene.camera = scene.camera.with_resolution(512, 512);
        group.bench_function(name, |b| {
            b.iter(|| {
                let world = World::new(&scene, SplitMethod::ObjectMedian);
                render(&world, &scene.settings, &|_| {})
            })
        });
    }
    group.finish();
}

criterion_group!(benches, render_scenes);
criterion_main!(benches);
