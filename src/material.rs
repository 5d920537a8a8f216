//! Checkpoint 5, part 1: materials, and the `PerfectRefraction` material (Snell's law).
//!
//! **Task.** Write [`refract`] (Snell's law for a direction) and [`refract_or_reflect`], the one
//! direction a ray continues in after meeting a perfectly refracting surface.
//!
//! **Maths.** With `wo` pointing away from the surface on the incident side, `n` the unit normal
//! on that same side, `cos θi = n · wo`, and `eta = eta_i / eta_t`, Snell's law
//! `eta_i sin θi = eta_t sin θt` gives `sin² θt = eta² (1 − cos² θi)`. If that is at least 1 there
//! is no transmitted ray: *total internal reflection*. Otherwise `cos θt = √(1 − sin² θt)` and the
//! transmitted direction, pointing away from the surface on the other side, is
//!
//! ```text
//!   wt = −eta · wo + (eta · cos θi − cos θt) · n
//! ```
//!
//! **Conventions** ([`crate::math`]): `eta` is incident over transmitted, so entering glass of index
//! `ior` from air uses `eta = 1 / ior` and leaving it uses `eta = ior`. Whether the ray enters is
//! read from the *outward* geometric normal: it enters when `wo` is on the outside
//! (`n_outward · wo > 0`). Under total internal reflection the ray reflects as a mirror would.
//! raylab's glass has no Fresnel term: every ray refracts when it can (a real glass surface also
//! reflects a few percent, more at grazing angles).
//!
//! **Pitfalls.**
//! - `eta` upside down: rays bend away from the normal when entering, and the glass looks
//!   like a hollow bubble.
//! - Leaving glass, both the normal and eta must flip; flipping only one bends rays the wrong way.
//! - glam's `Vec3::refract` expects the incident direction pointing *into* the surface and returns
//!   zero under total internal reflection; raylab's [`refract`] takes `wo` and returns `None`.
//!
//! **Check:** `cargo test checkpoint5`. Handout: `checkpoints/05-refraction.md`.

use crate::math::{debug_assert_unit, Vec3};

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use crate::math::reflect;

/// What a surface is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// An ideal diffuse (Lambertian) reflector of the given albedo ρ, each channel in `[0, 1]`.
    Diffuse {
        /// Fraction of incident light reflected, per channel.
        albedo: Vec3,
    },
    /// A smooth dielectric that refracts perfectly (no Fresnel reflection), with index `ior`
    /// relative to the surrounding air.
    PerfectRefraction {
        /// Index of refraction of the inside.
        ior: f32,
    },
}

/// The direction a ray from `wo` continues in at a glass surface of index `ior` with outward
/// normal `n_outward`: refracted, or mirror-reflected under total internal reflection.
pub fn refract_or_reflect(wo: Vec3, n_outward: Vec3, ior: f32) -> Vec3 {
    debug_assert_unit(wo, "refract_or_reflect's wo");
    debug_assert_unit(n_outward, "refract_or_reflect's n_outward");
    // BEGIN SOLUTION checkpoint5
    let entering = n_outward.dot(wo) > 0.0;
    let (n, eta) = if entering { (n_outward, 1.0 / ior) } else { (-n_outward, ior) };
    refract(wo, n, eta).unwrap_or_else(|| reflect(wo, n))
    // END SOLUTION
}

/// Snell's law: the transmitted direction for `wo` (unit, pointing away from the surface on
/// the side of the unit normal `n`) and the relative index `eta = eta_i / eta_t`, or `None`
/// under total internal reflection.
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    debug_assert_unit(wo, "refract's wo");
    debug_assert_unit(n, "refract's normal");
    // BEGIN SOLUTION checkpoint5
    let cos_theta_i = n.dot(wo);
    let sin2_theta_i = (1.0 - cos_theta_i * cos_theta_i).max(0.0);
    let sin2_theta_t = eta * eta * sin2_theta_i;
    if sin2_theta_t >= 1.0 {
        return None;
    }
    let cos_theta_t = (1.0 - sin2_theta_t).sqrt();
    Some(-eta * wo + (eta * cos_theta_i - cos_theta_t) * n)
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint5 {
    use super::*;
    use crate::rng::Rng;
    use crate::test_fixtures::random_unit_vector;

    /// `wo` at `degrees` from the normal +y, in the xy-plane, on the +x side.
    fn wo_at(degrees: f32) -> Vec3 {
        let (s, c) = degrees.to_radians().sin_cos();
        Vec3::new(s, c, 0.0)
    }

    /// The sine of the angle between a direction and the axis ±y.
    fn sin_to_normal(w: Vec3) -> f32 {
        w.cross(Vec3::Y).length()
    }

    #[test]
    fn snells_law_holds_entering_and_leaving() {
        for degrees in [5.0, 20.0, 30.0, 41.0, 60.0, 89.0] {
            let wo = wo_at(degrees);
            let wt = refract(wo, Vec3::Y, 1.0 / 1.5).expect("air to glass always refracts");
            assert!((wt.length() - 1.0).abs() < 1e-6, "unit length");
            assert!(wt.y < 0.0 && wt.x < 0.0, "crosses to the other side, continuing forward");
            let (si, st) = (sin_to_normal(wo), sin_to_normal(wt));
            assert!(
                (1.0 * si - 1.5 * st).abs() < 1e-6,
                "{degrees}° from air into glass: Snell wants 1.0 sin θi = 1.5 sin θt, got {si} and {st} (is eta = 1 / 1.5?)"
            );
        }
        let wt = refract(wo_at(30.0), Vec3::Y, 1.5).expect("below the critical angle");
        assert!((1.5 * 0.5 - sin_to_normal(wt)).abs() < 1e-6, "glass to air: sin θt = 1.5 sin θi");
    }

    #[test]
    fn normal_incidence_passes_straight_through() {
        let wt = refract(Vec3::Y, Vec3::Y, 1.0 / 1.5).expect("head-on always refracts");
        assert!((wt + Vec3::Y).length() < 1e-6, "head-on: expected straight through (-n), got {wt}");
    }

    #[test]
    fn total_internal_reflection_beyond_the_critical_angle() {
        // Critical angle from glass of 1.5: asin(1 / 1.5) = 41.81 degrees.
        assert!(
            refract(wo_at(41.0), Vec3::Y, 1.5).is_some(),
            "41° from glass is below the critical 41.8°: refracts"
        );
        let beyond = refract(wo_at(42.0), Vec3::Y, 1.5);
        assert_eq!(
            beyond, None,
            "42° from glass is beyond the critical 41.8°: total internal reflection, no ray"
        );
        // Leaving glass at 60 degrees inside: the ray reflects inside, as a mirror.
        let inside_wo = -wo_at(60.0); // below the surface, outward normal +y
        let wi = refract_or_reflect(inside_wo, Vec3::Y, 1.5);
        assert!((wi - Vec3::new(-inside_wo.x, inside_wo.y, 0.0)).length() < 1e-6, "{wi}");
    }

    #[test]
    fn refraction_is_reversible() {
        let mut rng = Rng::new(8, 0);
        for _ in 0..1000 {
            let mut wo = random_unit_vector(&mut rng);
            wo.y = wo.y.abs().max(0.05);
            let wo = wo.normalize();
            let wt = refract(wo, Vec3::Y, 1.0 / 1.5).unwrap();
            // Travelling back along −wt, the ray's wo is wt, on the side of the normal −y.
            let back = refract(wt, -Vec3::Y, 1.5).expect("the way back never reflects");
            assert!((back - wo).length() < 1e-5, "{wo} -> {wt} -> {back}");
        }
    }

    #[test]
    fn entering_and_leaving_are_read_from_the_outward_normal() {
        // Seen from outside at 45 degrees: bends toward the normal (sin θt = sin 45° / 1.5).
        let enter = refract_or_reflect(wo_at(45.0), Vec3::Y, 1.5);
        assert!(
            enter.y < 0.0,
            "entering from outside (n_outward · wo > 0) must cross into the glass: {enter}"
        );
        let want = 45f32.to_radians().sin() / 1.5;
        let got = sin_to_normal(enter);
        assert!(
            (got - want).abs() < 1e-6,
            "entering at 45°: sin θt = sin 45° / 1.5 = {want}, got {got} (eta = 1 / ior)"
        );
        // From inside at 20 degrees: leaves bending away from the normal.
        let leave = refract_or_reflect(-wo_at(20.0), Vec3::Y, 1.5);
        assert!(leave.y > 0.0, "leaving from inside must cross out of the glass (flip the normal): {leave}");
        let want = 1.5 * 20f32.to_radians().sin();
        let got = sin_to_normal(leave);
        assert!(
            (got - want).abs() < 1e-6,
            "leaving at 20°: sin θt = 1.5 sin 20° = {want}, got {got} (eta = ior)"
        );
    }
}
