//! BVH build and traversal on the bumpy icosphere, one thread, for both splits and the wide tree
//! collapsed from the SAH one; with
//! `--features peer-embree`, Embree on the same mesh and rays, and the raylab/Embree ratios.
//!
//! - build: 100k and 1M triangles, SAH and object median; collapsing the SAH tree to the wide one.
//! - traverse: the primary, incoherent and shadow workloads (`raylab_bench::Workload`, 2^20
//!   rays each) on the 1M-triangle mesh.
//!
//! `cargo bench --bench bvh [--features peer-embree]`; figures in docs/PERFORMANCE.md.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput};
use raylab::geometry::{Bvh, SplitMethod, Triangle, TriangleMesh, WideBvh};
use raylab_bench::{bumpy_icosphere, grid_size_for, trace, Workload};

const SPLITS: [(SplitMethod, &str); 2] = [(SplitMethod::Sah, "sah"), (SplitMethod::ObjectMedian, "median")];

fn mesh(triangles: usize) -> TriangleMesh {
    bumpy_icosphere(grid_size_for(triangles))
}

fn build(c: &mut Criterion, one_thread: &rayon::ThreadPool) {
    let mut group = c.benchmark_group("build");
    group.sample_size(10);
    for (label, size) in [("100k", 100_000), ("1M", 1_000_000)] {
        let triangles: Vec<Triangle> = mesh(size).triangles().collect();
        group.throughput(Throughput::Elements(triangles.len() as u64));
        for (method, name) in SPLITS {
            group.bench_with_input(BenchmarkId::new(name, label), &triangles, |b, t| {
                b.iter(|| one_thread.install(|| Bvh::build(black_box(t), method)))
            });
        }
        let sah = Bvh::build(&triangles, SplitMethod::Sah);
        group.bench_function(BenchmarkId::new("collapse sah to wide", label), |b| {
            b.iter(|| WideBvh::collapse(black_box(&sah)))
        });
        #[cfg(feature = "peer-embree")]
        {
            let mesh = mesh(size);
            group.bench_function(BenchmarkId::new("embree", label), |b| {
                b.iter(|| raylab_bench::embree::EmbreeScene::new(&mesh, 1).expect("Embree builds"))
            });
        }
    }
    group.finish();
}

fn traverse(c: &mut Criterion, one_thread: &rayon::ThreadPool) {
    let mesh = mesh(1_000_000);
    let triangles: Vec<Triangle> = mesh.triangles().collect();
    let trees = SPLITS.map(|(method, name)| (name, Bvh::build(&triangles, method)));
    let wide = WideBvh::collapse(&trees[0].1);
    #[cfg(feature = "peer-embree")]
    let embree = raylab_bench::embree::EmbreeScene::new(&mesh, 1).expect("Embree builds");
    let mut group = c.benchmark_group("traverse 1M");
    group.sample_size(10);
    for workload in Workload::ALL {
        let rays = workload.rays();
        group.throughput(Throughput::Elements(rays.len() as u64));
        for (name, bvh) in &trees {
            group.bench_function(BenchmarkId::new(*name, workload), |b| {
                b.iter(|| one_thread.install(|| trace(bvh, &rays, workload.any_hit()).hits))
            });
        }
        group.bench_function(BenchmarkId::new("wide", workload), |b| {
            b.iter(|| one_thread.install(|| trace(&wide, &rays, workload.any_hit()).hits))
        });
        #[cfg(feature = "peer-embree")]
        group.bench_function(BenchmarkId::new("embree", workload), |b| {
            b.iter(|| one_thread.install(|| embree.trace(&rays, workload.any_hit()).0))
        });
    }
    group.finish();
}

fn main() {
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a thread");
    let mut criterion = Criterion::default().configure_from_args();
    build(&mut criterion, &one_thread);
    traverse(&mut criterion, &one_thread);
    criterion.final_summary();
    #[cfg(feature = "peer-embree")]
    ratios::print(&one_thread);
}

/// The raylab/Embree ratios, from the fastest of five passes of each (criterion's own report
/// has both engines' times; this puts them side by side).
#[cfg(feature = "peer-embree")]
mod ratios {
    use std::time::{Duration, Instant};

    use super::*;
    use raylab_bench::embree::EmbreeScene;

    fn fastest(mut pass: impl FnMut() -> Duration) -> Duration {
        (0..5).map(|_| pass()).min().expect("five passes")
    }

    pub fn print(one_thread: &rayon::ThreadPool) {
        let mesh = mesh(1_000_000);
        let triangles: Vec<Triangle> = mesh.triangles().collect();
        let embree_build = fastest(|| EmbreeScene::new(&mesh, 1).expect("Embree builds").build_time);
        let embree = EmbreeScene::new(&mesh, 1).expect("Embree builds");
        println!("\nraylab/Embree, 1 thread, 1M triangles (time ratio for build, throughput ratio for rays)");
        let row =
            |name: &str, build: Duration, tree: &(dyn Fn(&[raylab::math::Ray], bool) -> Duration + Sync)| {
                print!("  {name:<6} build time {:.2}", build.as_secs_f64() / embree_build.as_secs_f64());
                for workload in Workload::ALL {
                    let rays = workload.rays();
                    let ours = fastest(|| one_thread.install(|| tree(&rays, workload.any_hit())));
                    let theirs = fastest(|| one_thread.install(|| embree.trace(&rays, workload.any_hit()).1));
                    print!("  {workload} {:.2}", theirs.as_secs_f64() / ours.as_secs_f64());
                }
                println!();
            };
        for (method, name) in SPLITS {
            let build = fastest(|| {
                let start = Instant::now();
                black_box(one_thread.install(|| Bvh::build(&triangles, method)));
                start.elapsed()
            });
            let bvh = Bvh::build(&triangles, method);
            row(name, build, &|rays, any_hit| trace(&bvh, rays, any_hit).time);
        }
        // The wide tree's build is the SAH build and the collapse.
        let build = fastest(|| {
            let start = Instant::now();
            black_box(WideBvh::collapse(&one_thread.install(|| Bvh::build(&triangles, SplitMethod::Sah))));
            start.elapsed()
        });
        let wide = WideBvh::collapse(&Bvh::build(&triangles, SplitMethod::Sah));
        row("wide", build, &|rays, any_hit| trace(&wide, rays, any_hit).time);
    }
}
