//! Checkpoint 5, hidden: Snell's law on random directions from both sides, stated in tangential
//! components (no angles), and the reversibility of light paths.

use crate::oracle::direction;
use raylab::material::refract_or_reflect;
use raylab::math::Vec3;
use raylab::rng::Rng;

/// The part of `v` perpendicular to the unit `n`.
fn tangential(v: Vec3, n: Vec3) -> Vec3 {
    v - v.dot(n) * n
}

/// Snell's law `η_i sin θ_i = η_t sin θ_t` with the transmitted direction in the plane of `wo` and
/// `n` is, in vectors: the transmitted tangential part is `-(η_i/η_t)` times `wo`'s (the ray
/// continues, `wo` points back), on the far side. Beyond the critical angle: the mirror direction.
#[test]
fn random_directions_refract_by_tangential_components_or_reflect_beyond_the_critical_angle() {
    let mut rng = Rng::new(51, 0);
    let (mut refracted, mut reflected) = (0, 0);
    for _ in 0..5_000 {
        let (n, wo) = (direction(&mut rng), direction(&mut rng));
        let cos_o = n.dot(wo);
        if cos_o.abs() < 1e-3 {
            continue;
        }
        let ior = 1.1 + 1.3 * rng.next_f32();
        let d = refract_or_reflect(wo, n, ior);
        assert!((d.length() - 1.0).abs() < 1e-4, "not unit: {d}");
        let eta = if cos_o > 0.0 { 1.0 / ior } else { ior };
        let sin_t = eta * tangential(wo, n).length();
        if sin_t < 1.0 - 1e-4 {
            refracted += 1;
            let want = -eta * tangential(wo, n);
            assert!((tangential(d, n) - want).length() < 1e-4, "ior {ior}, wo {wo}, n {n}: {d}");
            assert!(d.dot(n) * cos_o < 0.0, "not transmitted: wo {wo}, n {n}, {d}");
        } else if sin_t > 1.0 + 1e-4 {
            reflected += 1;
            let mirror = 2.0 * cos_o * n - wo;
            assert!(
                (d - mirror).length() < 1e-4,
                "total internal reflection: wo {wo}, n {n}: {d} vs {mirror}"
            );
        }
    }
    assert!(refracted > 1_000 && reflected > 300, "{refracted} refracted, {reflected} reflected");
}

/// A ray sent back along its refracted direction comes out where the first one came from.
#[test]
fn light_paths_through_a_surface_are_reversible() {
    let mut rng = Rng::new(52, 0);
    for _ in 0..1_000 {
        let n = direction(&mut rng);
        let mut wo = direction(&mut rng);
        if n.dot(wo) < 0.0 {
            wo = -wo;
        }
        if n.dot(wo) < 1e-2 {
            continue;
        }
        let ior = 1.1 + 1.3 * rng.next_f32();
        let inside = refract_or_reflect(wo, n, ior);
        let back = refract_or_reflect(inside, n, ior);
        assert!((back - wo).length() < 1e-3, "ior {ior}, n {n}: {wo} -> {inside} -> {back}");
    }
}
