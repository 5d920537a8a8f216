//! `raybench`: ray-tracing throughput on a mesh, with the machine-independent counts beside it.
//!
//! ```text
//! raybench --generate icosphere --triangles 1000000 -o target/ico1m.obj
//! raybench target/ico1m.obj --workload primary --threads 1 --split sah
//! raybench target/ico1m.obj --workload all --threads 2 --split median --peer embree
//! ```
//!
//! Every workload is traced through the binary BVH (checkpoint 4's tree, split as `--split` says)
//! and through the wide BVH collapsed from it (`raylab::geometry::wide`), one row each.
//! The workloads are fixed (see `raylab_bench::Workload`) so any engine can trace the same rays.
//! Each workload is traced `--repeat` times and the fastest pass is reported (the counts are the
//! same every pass). Exit codes: 0 on success, 2 for bad input, with one line on standard error.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Parser, ValueEnum};
use raylab::geometry::{Bvh, SplitMethod, Triangle, TriangleMesh, WideBvh};
use raylab_bench::{self as bench, Workload};

/// Trace fixed ray workloads through a mesh's BVH and report speed and work per ray.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// The mesh (Wavefront OBJ) to trace, or, with --generate, the mesh to write.
    #[arg(required_unless_present = "generate", conflicts_with = "generate")]
    mesh: Option<PathBuf>,
    /// Which rays to trace.
    #[arg(long, value_enum, default_value = "all")]
    workload: WorkloadArg,
    /// Threads for tracing (and for the peer's build).
    #[arg(long, default_value = "1", value_parser = clap::value_parser!(u32).range(1..))]
    threads: u32,
    /// How the BVH splits nodes.
    #[arg(long, value_enum, default_value = "sah")]
    split: SplitArg,
    /// Passes per workload; the fastest is reported.
    #[arg(long, default_value = "3", value_parser = clap::value_parser!(u32).range(1..))]
    repeat: u32,
    /// Trace the same mesh and rays through a peer engine too, and print the ratios.
    #[arg(long, value_enum)]
    peer: Option<Peer>,
    /// Write a generated mesh instead of tracing one.
    #[arg(long, value_enum, requires_all = ["triangles", "output"])]
    generate: Option<Generate>,
    /// Triangles wanted in the generated mesh (rounded to 20 n²).
    #[arg(long, value_parser = clap::value_parser!(u64).range(20..=200_000_000))]
    triangles: Option<u64>,
    /// Where to write the generated mesh.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum WorkloadArg {
    Primary,
    Incoherent,
    Shadow,
    All,
}

#[derive(Clone, Copy, ValueEnum)]
enum SplitArg {
    Sah,
    Median,
}

#[derive(Clone, Copy, ValueEnum)]
enum Peer {
    Embree,
}

#[derive(Clone, Copy, ValueEnum)]
enum Generate {
    /// The bumpy geodesic sphere (`raylab_bench::bumpy_icosphere`).
    Icosphere,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("raybench: {message}");
            ExitCode::from(2)
        }
    }
}

fn run(args: Args) -> Result<(), String> {
    if let (Some(Generate::Icosphere), Some(triangles), Some(output)) =
        (args.generate, args.triangles, &args.output)
    {
        let n = bench::grid_size_for(triangles as usize);
        let mesh = bench::bumpy_icosphere(n);
        bench::write_obj(output, &mesh).map_err(|e| format!("{}: {e}", output.display()))?;
        println!("wrote {}: bumpy icosphere, n = {n}, {} triangles", output.display(), mesh.indices.len());
        return Ok(());
    }
    let path = args.mesh.as_ref().expect("clap requires a mesh without --generate");
    let mesh = load_mesh(path)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads as usize)
        .build()
        .map_err(|e| format!("cannot start {} threads: {e}", args.threads))?;
    let method = match args.split {
        SplitArg::Sah => SplitMethod::Sah,
        SplitArg::Median => SplitMethod::ObjectMedian,
    };
    let (bvh, wide, built) = build_trees(&mesh, method, &pool, args.threads);
    print_memory("after build");
    let peer = Peers::new(args.peer, &mesh, args.threads as usize, built)?;
    println!("workload   tree        rays  Mrays/s  box/ray  tri/ray  hits{}", peer.header());
    let workloads = match args.workload {
        WorkloadArg::Primary => vec![Workload::Primary],
        WorkloadArg::Incoherent => vec![Workload::Incoherent],
        WorkloadArg::Shadow => vec![Workload::Shadow],
        WorkloadArg::All => Workload::ALL.to_vec(),
    };
    for workload in workloads {
        let rays = workload.rays();
        let pass = Pass { pool: &pool, rays: &rays, workload, repeat: args.repeat };
        trace_both(&pass, &bvh, &wide, &peer)?;
    }
    print_memory("at the end");
    Ok(())
}

/// The mesh at `path`, with the time it took to load.
fn load_mesh(path: &std::path::Path) -> Result<TriangleMesh, String> {
    let start = Instant::now();
    let mesh = TriangleMesh::load_obj(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if mesh.indices.is_empty() {
        return Err(format!("{}: the mesh has no triangles", path.display()));
    }
    println!(
        "mesh      {}: {} triangles, loaded in {:.2} s",
        path.display(),
        mesh.indices.len(),
        secs(start.elapsed())
    );
    Ok(mesh)
}

/// The binary BVH built by `method` on `pool`, and the wide one collapsed from it, each timed;
/// the time of both.
fn build_trees(
    mesh: &TriangleMesh,
    method: SplitMethod,
    pool: &rayon::ThreadPool,
    threads: u32,
) -> (Bvh, WideBvh, Duration) {
    let triangles: Vec<Triangle> = mesh.triangles().collect();
    let start = Instant::now();
    let bvh = pool.install(|| Bvh::build(&triangles, method));
    let build_time = start.elapsed();
    drop(triangles);
    println!(
        "build     {method:?}, {threads} thread(s): {:.3} s, {} nodes, depth {}",
        secs(build_time),
        bvh.nodes().len(),
        bvh.depth()
    );
    let start = Instant::now();
    let wide = WideBvh::collapse(&bvh);
    let collapse_time = start.elapsed();
    println!(
        "collapse  wide, {} children: {:.3} s ({:.3} s with the build), {} nodes, {} leaves",
        raylab::geometry::wide::WIDTH,
        secs(collapse_time),
        secs(build_time + collapse_time),
        wide.nodes().len(),
        wide.packets().len()
    );
    (bvh, wide, build_time + collapse_time)
}

/// One workload's rays through both trees (and the peer, if any): a row each. The trees must hit
/// the same number of rays.
fn trace_both(pass: &Pass, bvh: &Bvh, wide: &WideBvh, peer: &Peers) -> Result<(), String> {
    let workload = pass.workload;
    let rows = [("binary", pass.best(bvh)), ("wide", pass.best(wide))];
    if rows[0].1.hits != rows[1].1.hits {
        return Err(format!(
            "{workload}: the binary tree hit {} rays, the wide {}",
            rows[0].1.hits, rows[1].1.hits
        ));
    }
    let peer_mrays = peer.mrays(pass, &rows[0].1)?;
    for (tree, best) in &rows {
        println!(
            "{:<10} {tree:<6} {:>9} {:>8.2} {:>8.1} {:>8.1}  {}{}",
            workload.to_string(),
            best.rays,
            best.mrays_per_second(),
            best.box_tests_per_ray(),
            best.triangle_tests_per_ray(),
            best.hits,
            peer_mrays
                .map_or(String::new(), |m| format!("  {m:>10.2}  {:>13.2}", best.mrays_per_second() / m)),
        );
    }
    Ok(())
}

fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

fn print_memory(when: &str) {
    if let Some(bytes) = bench::peak_memory_bytes() {
        println!("memory    peak {:.0} MB {when}", bytes as f64 / 1e6);
    }
}

/// The optional peer engine, traced on the same rays as raylab.
struct Peers {
    #[cfg(feature = "peer-embree")]
    embree: Option<bench::embree::EmbreeScene>,
}

impl Peers {
    #[cfg(feature = "peer-embree")]
    fn new(
        peer: Option<Peer>,
        mesh: &TriangleMesh,
        threads: usize,
        raylab_build: Duration,
    ) -> Result<Self, String> {
        let Some(Peer::Embree) = peer else { return Ok(Self { embree: None }) };
        let scene = bench::embree::EmbreeScene::new(mesh, threads)?;
        println!(
            "peer      Embree build {:.3} s: raylab (build + collapse) / Embree build time {:.2}",
            secs(scene.build_time),
            secs(raylab_build) / secs(scene.build_time)
        );
        Ok(Self { embree: Some(scene) })
    }

    #[cfg(not(feature = "peer-embree"))]
    fn new(peer: Option<Peer>, _: &TriangleMesh, _: usize, _: Duration) -> Result<Self, String> {
        match peer {
            Some(Peer::Embree) => {
                Err("--peer embree needs the peer-embree feature: cargo run --release --features peer-embree --bin raybench".into())
            }
            None => Ok(Self {}),
        }
    }

    /// Extra column titles when a peer runs.
    fn header(&self) -> &'static str {
        #[cfg(feature = "peer-embree")]
        if self.embree.is_some() {
            return "     Embree Mrays/s  raylab/Embree";
        }
        ""
    }

    /// The peer's throughput on one workload (its fastest pass), checked against raylab's hits.
    #[cfg(feature = "peer-embree")]
    fn mrays(&self, pass: &Pass, raylab: &bench::TraceReport) -> Result<Option<f64>, String> {
        let Some(scene) = &self.embree else { return Ok(None) };
        let passes: Vec<_> = (0..pass.repeat)
            .map(|_| pass.pool.install(|| scene.trace(pass.rays, pass.workload.any_hit())))
            .collect();
        let (hits, time) = passes.into_iter().min_by_key(|p| p.1).expect("at least one pass");
        // Both engines must agree on what was hit, or the comparison means nothing. Rays grazing
        // an edge may differ; allow one in 10^4.
        if hits.abs_diff(raylab.hits) > pass.rays.len() / 10_000 {
            return Err(format!("Embree hit {hits} rays, raylab {}: the engines disagree", raylab.hits));
        }
        Ok(Some(pass.rays.len() as f64 / secs(time) / 1e6))
    }

    /// No peer is compiled in: no columns.
    #[cfg(not(feature = "peer-embree"))]
    fn mrays(&self, _: &Pass, _: &bench::TraceReport) -> Result<Option<f64>, String> {
        Ok(None)
    }
}

/// One workload's passes: where, what, and how often.
struct Pass<'a> {
    pool: &'a rayon::ThreadPool,
    rays: &'a [raylab::math::Ray],
    workload: Workload,
    repeat: u32,
}

impl Pass<'_> {
    /// raylab's fastest pass through `tree` (the counts are the same in every pass).
    fn best(&self, tree: &impl bench::Tracer) -> bench::TraceReport {
        let passes = (0..self.repeat)
            .map(|_| self.pool.install(|| bench::trace(tree, self.rays, self.workload.any_hit())));
        passes.min_by_key(|r| r.time).expect("at least one pass")
    }
}
