//! Harness regression tests (outside every `checkpointN` filter: a student's valid tree may
//! differ): the shape of the reference solution's trees over the graded scenes, and the work a
//! primary ray costs. A change here is a change in BVH quality; review it with `cargo insta review`.

// The renderer is linked by the instructor's grader only.
#![cfg(feature = "instructor")]

use std::fmt::Write;
use std::path::Path;

use raylab::geometry::{Bvh, SplitMethod, TraversalStats};
use raylab::math::Vec2;
use raylab::scene::Scene;

/// Nodes, depth, and mean box and triangle tests per pixel-centre ray over a 64×64 grid.
fn tree_report(name: &str, method: SplitMethod) -> String {
    let scene =
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/{name}.toml"))).unwrap();
    let bvh = Bvh::build(&scene.triangles, method);
    bvh.validate().unwrap();
    let mut stats = TraversalStats::default();
    let (w, h) = (scene.camera.width() as f32, scene.camera.height() as f32);
    let n = 64;
    for j in 0..n {
        for i in 0..n {
            let film = Vec2::new((i as f32 + 0.5) / n as f32 * w, (j as f32 + 0.5) / n as f32 * h);
            bvh.intersect(&scene.camera.ray(film), &mut stats);
        }
    }
    let rays = (n * n) as f64;
    let mut report = String::new();
    writeln!(report, "triangles: {}", scene.triangles.len()).unwrap();
    writeln!(report, "nodes: {}", bvh.nodes().len()).unwrap();
    writeln!(report, "depth: {}", bvh.depth()).unwrap();
    writeln!(report, "box tests per primary ray: {:.2}", stats.box_tests as f64 / rays).unwrap();
    writeln!(report, "triangle tests per primary ray: {:.2}", stats.triangle_tests as f64 / rays).unwrap();
    report
}

#[test]
fn harness_bvh_shape_of_every_graded_scene() {
    for name in ["cornell_direct", "cornell_refract", "intersection_test", "aliasing"] {
        insta::assert_snapshot!(format!("bvh_shape_{name}"), tree_report(name, SplitMethod::ObjectMedian));
        insta::assert_snapshot!(format!("bvh_sah_shape_{name}"), tree_report(name, SplitMethod::Sah));
    }
}
