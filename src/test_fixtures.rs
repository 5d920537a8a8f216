//! Shared test fixtures: random geometry, awkward meshes, and an f64 ray-triangle oracle.

use crate::geometry::{Bvh, BvhHit, SplitMethod, TraversalStats, Triangle, TriangleHit, TriangleMesh};
use crate::math::{Ray, Vec3};
use crate::rng::Rng;

/// A uniformly distributed direction (by rejection from the cube).
pub fn random_unit_vector(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        let len2 = v.length_squared();
        if len2 > 1e-4 && len2 <= 1.0 {
            return v / len2.sqrt();
        }
    }
}

/// A triangle with vertices uniform in `[-scale, scale]³`.
pub fn random_triangle(rng: &mut Rng, scale: f32) -> Triangle {
    let mut p = || (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * scale;
    Triangle::new(p(), p(), p())
}

/// `n` small random triangles in `[-0.5, 0.5]³`.
pub fn random_mesh(rng: &mut Rng, n: usize) -> Vec<Triangle> {
    (0..n)
        .map(|_| {
            let centre = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            let t = random_triangle(rng, 0.15);
            Triangle::new(centre + t.p0, centre + t.p1, centre + t.p2)
        })
        .collect()
}

/// `n` parallel triangles along z, 0.005 apart from z = 0, each spanning x and y in `[-1, 1]`
/// with its apex at `(0, 1)`: a ray down the z axis crosses them all.
pub fn stack_of_planes(n: usize) -> Vec<Triangle> {
    (0..n)
        .map(|i| {
            let z = i as f32 * 0.005;
            Triangle::new(Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(0.0, 1.0, z))
        })
        .collect()
}

/// The closest hit by testing every triangle.
fn brute_force(triangles: &[Triangle], ray: &Ray) -> Option<(u32, TriangleHit)> {
    let hits = triangles.iter().enumerate().filter_map(|(i, t)| t.intersect(ray).map(|h| (i as u32, h)));
    hits.min_by(|a, b| a.1.t.total_cmp(&b.1.t))
}

/// Random rays from outside and inside the meshes' unit-cube region.
fn random_ray(rng: &mut Rng) -> Ray {
    let origin = (1.0 + 2.0 * rng.next_f32()) * random_unit_vector(rng);
    let target = 0.8 * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.4;
    Ray::new(origin, target - origin)
}

/// Builds a tree over `triangles` with `method` and checks `rays` random rays against testing
/// every triangle: the same closest `t`, and any-hit agreeing with closest-hit.
#[track_caller]
pub fn check_against_brute_force(triangles: &[Triangle], method: SplitMethod, rays: usize, rng: &mut Rng) {
    let bvh = Bvh::build(triangles, method);
    let mut stats = TraversalStats::default();
    check_tracer_against_brute_force(triangles, rays, rng, |ray, any_hit| {
        bvh.traverse(ray, any_hit, &mut stats)
    });
}

/// [`check_against_brute_force`] for any tracer: `trace(ray, any_hit)` answers as
/// [`Bvh::traverse`] does.
#[track_caller]
pub fn check_tracer_against_brute_force(
    triangles: &[Triangle],
    rays: usize,
    rng: &mut Rng,
    mut trace: impl FnMut(&Ray, bool) -> Option<BvhHit>,
) {
    for _ in 0..rays {
        let ray = random_ray(rng);
        let want = brute_force(triangles, &ray);
        let got = trace(&ray, false);
        assert_eq!(trace(&ray, true).is_some(), want.is_some(), "any-hit on {ray:?}");
        match (got, want) {
            (None, None) => {}
            (Some(got), Some((prim, hit))) => {
                // The same f32 test on the same ray gives the same t bit for bit: compare
                // exactly. Two triangles at the same t (a shared edge) may both be right.
                assert_eq!(got.hit.t, hit.t, "{ray:?}");
                if got.prim != prim {
                    let other = triangles[got.prim as usize].intersect(&ray);
                    assert_eq!(other.map(|h| h.t), Some(hit.t), "{ray:?}");
                }
            }
            (got, want) => {
                panic!("{} triangles, {ray:?}: bvh {got:?}, brute force {want:?}", triangles.len())
            }
        }
    }
}

/// Twenty random meshes of 1 to 704 triangles, then the awkward ones: what tree tests build on.
pub fn random_and_awkward_meshes(seed: u64) -> Vec<Vec<Triangle>> {
    let mut rng = Rng::new(seed, 0);
    let mut meshes: Vec<Vec<Triangle>> = (0..20).map(|i| random_mesh(&mut rng, 1 + i * 37)).collect();
    meshes.extend(awkward_meshes());
    meshes
}

/// Meshes that break naive builders: none, one triangle, all centroids equal, coplanar,
/// slivers, and a closed sphere.
pub fn awkward_meshes() -> Vec<Vec<Triangle>> {
    let one =
        vec![Triangle::new(Vec3::new(-0.3, -0.3, 0.0), Vec3::new(0.3, -0.3, 0.0), Vec3::new(0.0, 0.3, 0.1))];
    // Triangles rotated about a common centroid at the origin.
    let same_centroid = (0..40)
        .map(|i| {
            let a = i as f32 * 0.37;
            let (s, c) = a.sin_cos();
            let p0 = Vec3::new(c, s, 0.3 * c) * 0.4;
            let p1 = Vec3::new(-s, c, 0.2) * 0.3;
            Triangle::new(p0, p1, -p0 - p1)
        })
        .collect();
    let coplanar = (0..60)
        .map(|i| {
            let (x, z) = ((i % 8) as f32 * 0.1 - 0.4, (i / 8) as f32 * 0.1 - 0.4);
            Triangle::new(Vec3::new(x, 0.0, z), Vec3::new(x + 0.1, 0.0, z), Vec3::new(x, 0.0, z + 0.1))
        })
        .collect();
    let slivers = (0..50)
        .map(|i| {
            let y = i as f32 * 0.015 - 0.4;
            Triangle::new(Vec3::new(-0.5, y, -0.2), Vec3::new(0.5, y, 0.2), Vec3::new(0.5, y + 1e-4, 0.2))
        })
        .collect();
    let sphere = TriangleMesh::icosphere(2).transformed(&crate::math::Mat4::from_scale(Vec3::splat(0.4)));
    vec![vec![], one, same_centroid, coplanar, slivers, sphere.triangles().collect()]
}

/// The f64 answer to a ray-triangle query, computed differently from Möller-Trumbore: intersect
/// the plane, then take barycentrics as ratios of areas.
///
/// Returns `None` when the f32 answer may legitimately differ (the case lies within rounding of
/// an edge, of either end of the t window, or of parallel), else `Some(hit)` with the hit as
/// `(t, b1, b2, bound)` where `bound` is the f32 error to allow on each barycentric.
#[allow(clippy::type_complexity)]
pub fn oracle_f64(ray: &Ray, tri: &Triangle) -> Option<Option<(f64, f64, f64, f64)>> {
    let v = |p: Vec3| p.as_dvec3();
    let (o, d) = (v(ray.origin), v(ray.dir));
    let (p0, e1, e2) = (v(tri.p0), v(tri.p1 - tri.p0), v(tri.p2 - tri.p0));
    let n = e1.cross(e2);
    let det = n.dot(d).abs();
    // f32 Möller-Trumbore forms each quantity from products of vectors no longer than
    // s = |o − p0| + |e1| + |e2|: its error is a few ε·s² over |det| (16 gives ample room).
    let s = (o - p0).length() + e1.length() + e2.length();
    let bound = 16.0 * f32::EPSILON as f64 * s * s / det;
    if det < 1e-4 * n.length() || !bound.is_finite() {
        return None;
    }
    let t = n.dot(p0 - o) / n.dot(d);
    let x = o + t * d - p0;
    let (b1, b2) = (x.cross(e2).dot(n) / n.length_squared(), e1.cross(x).dot(n) / n.length_squared());
    let margins = [b1, b2, 1.0 - b1 - b2];
    let t_margin = (t - ray.t_min as f64).min(ray.t_max as f64 - t) / t.abs().max(1.0);
    if margins.iter().any(|m| m.abs() < bound) || t_margin.abs() < bound {
        return None;
    }
    let inside = margins.iter().all(|&m| m > 0.0) && t_margin > 0.0;
    Some(inside.then_some((t, b1, b2, bound)))
}

/// A scene from the TOML of its materials, lights and objects, with a small default camera.
pub fn scene_from_toml(body: &str) -> crate::scene::Scene {
    scene_from_toml_at(body, std::path::Path::new("test.toml"))
}

/// The same, as if read from `path` (meshes are found beside it).
pub fn scene_from_toml_at(body: &str, path: &std::path::Path) -> crate::scene::Scene {
    let text = format!(
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\nwidth = 8\nheight = 8\n\
         [integrator]\nkind = \"direct_lighting\"\n{body}"
    );
    crate::scene::Scene::from_toml(&text, path).unwrap_or_else(|e| panic!("{e}"))
}

/// An estimator's mean equals the closed form `want` by a t-test at p > 1e-3 (a correct
/// estimator fails one run in a thousand; with the tests' tens of thousands of samples the
/// standard error is well under 1% of the mean, so a bias of a few percent fails).
#[track_caller]
pub fn assert_mean(got: &crate::stats::Summary, want: f64) {
    let se = got.variance_of_mean().sqrt();
    let t = (got.mean - want) / se;
    let p = crate::stats::student_t_two_sided(t, got.n - 1.0);
    assert!(p > 1e-3, "mean {:.5} ± {se:.5}, closed form {want:.5}: t = {t:.1}, p = {p:.1e}", got.mean);
}
