//! The two innermost tests, one call at a time: ray-triangle (checkpoint 2) and ray-box
//! (checkpoint 3). Inputs are 4096 random rays through a unit-sized region, so about half hit:
//! neither the always-hit nor the always-miss branch is favoured.
//!
//! `cargo bench --bench kernels`; figures in docs/PERFORMANCE.md.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use raylab::geometry::{intersect_triangle, Aabb};
use raylab::math::{Ray, Vec3};
use raylab::rng::Rng;

const CASES: usize = 4096;

fn point(rng: &mut Rng) -> Vec3 {
    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0
}

/// Rays from a radius-3 shell aimed at points of the cube [-1, 1]³.
fn rays(rng: &mut Rng) -> Vec<Ray> {
    (0..CASES)
        .map(|_| {
            let origin = point(rng).normalize() * 3.0;
            Ray::new(origin, point(rng) - origin)
        })
        .collect()
}

fn triangle_test(c: &mut Criterion) {
    let mut rng = Rng::new(1, 0);
    let rays = rays(&mut rng);
    let triangles: Vec<[Vec3; 3]> =
        (0..CASES).map(|_| [point(&mut rng), point(&mut rng), point(&mut rng)]).collect();
    let mut group = c.benchmark_group("kernels");
    group.throughput(Throughput::Elements(CASES as u64));
    group.bench_function("ray-triangle", |b| {
        b.iter(|| {
            rays.iter()
                .zip(&triangles)
                .filter(|(ray, [p0, p1, p2])| intersect_triangle(black_box(ray), *p0, *p1, *p2).is_some())
                .count()
        })
    });
    let boxes: Vec<Aabb> = (0..CASES).map(|_| Aabb::new(point(&mut rng), point(&mut rng))).collect();
    group.bench_function("ray-box", |b| {
        b.iter(|| {
            rays.iter().zip(&boxes).filter(|(ray, aabb)| aabb.intersect(black_box(ray)).is_some()).count()
        })
    });
    group.finish();
}

criterion_group!(benches, triangle_test);
criterion_main!(benches);
