//! Checkpoint 9, part 1: cosine-weighted directions on the hemisphere, where a path goes next
//! after a diffuse bounce.
//!
//! **Task.** Write [`cosine_hemisphere`]: turn two uniform numbers into a unit direction on the
//! hemisphere around the normal `n`, with density `p(ω) = cos θ / π` (per solid angle, `θ` the
//! angle between `ω` and `n`).
//!
//! **Maths** (Malley's method). Points uniform on the unit disk, lifted straight up onto the
//! hemisphere, have exactly the cosine density: the disk's area element `r dr dφ` is the
//! hemisphere's `sin θ cos θ dθ dφ` with `r = sin θ`. So with `u₁, u₂` uniform in `[0, 1)`:
//!
//! ```text
//!   r = √u₁,   φ = 2π u₂,   (x, y, z) = (r cos φ, r sin φ, √(1 − u₁))
//! ```
//!
//! in a frame whose `z` axis is `n` ([`tangent_frame`] gives the other two axes). Why the cosine:
//! a Lambertian surface reflects `f · L · cos θ` with `f = ρ / π`; sampling `ω` with `p = cos θ
//! / π` makes each sample's weight `f cos θ / p = ρ`, the same for every direction.
//!
//! **Pitfalls.**
//! - Uniform `(cos θ = u₁)` directions (density `1 / 2π`) weighted as if cosine-distributed: the
//!   image is too bright at grazing angles and too dark head-on; `cargo test checkpoint9`
//!   compares the histogram of your directions with the cosine density by a chi-square test.
//! - `r = u₁` instead of `√u₁`: directions crowd around the normal.
//! - Returning the direction in the local frame (around `z`) instead of around `n`.
//!
//! **Check:** `cargo test checkpoint9`. Handout: `checkpoints/09-path-tracing.md`.

use crate::math::{debug_assert_unit, Vec3};

// Used by the solution region below; the starter's stub does not use it yet.
#[allow(unused_imports)]
use std::f32::consts::PI;

/// Two unit vectors `(t, b)` such that `(t, b, n)` is a right-handed orthonormal frame, for a unit
/// `n` (Duff et al., "Building an orthonormal basis, revisited", 2017: no branch on a small
/// component, no square root).
pub fn tangent_frame(n: Vec3) -> (Vec3, Vec3) {
    debug_assert_unit(n, "tangent_frame's normal");
    let sign = 1f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// A unit direction on the hemisphere around the unit normal `n`, with density `cos θ / π`,
/// from two uniform numbers `u` in `[0, 1)`.
pub fn cosine_hemisphere(n: Vec3, u: [f32; 2]) -> Vec3 {
    debug_assert_unit(n, "cosine_hemisphere's normal");
    // BEGIN SOLUTION checkpoint9
    let (t, b) = tangent_frame(n);
    let r = u[0].sqrt();
    let phi = 2.0 * PI * u[1];
    let z = (1.0 - u[0]).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
    // END SOLUTION
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::test_fixtures::random_unit_vector;

    /// The frame is orthonormal and right-handed for normals near every axis, both signs.
    #[test]
    fn tangent_frames_are_orthonormal_and_right_handed() {
        let mut rng = Rng::new(90, 0);
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        for n in axes.into_iter().chain((0..100).map(|_| random_unit_vector(&mut rng))) {
            let (t, b) = tangent_frame(n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(v).abs() < 1e-5, "{n}: {u} . {v}");
            }
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5, "{n}");
            assert!((t.cross(b) - n).length() < 1e-5, "{n}: not right-handed");
        }
    }
}

#[cfg(test)]
mod checkpoint9 {
    use super::*;
    use crate::rng::Rng;
    use crate::stats::chi_square_upper;
    use crate::test_fixtures::random_unit_vector;

    /// Every sample is a unit vector in the hemisphere around `n`, for random normals.
    #[test]
    fn cosine_samples_are_unit_directions_above_the_surface() {
        let mut rng = Rng::new(91, 0);
        for _ in 0..200 {
            let n = random_unit_vector(&mut rng);
            for _ in 0..50 {
                let w = cosine_hemisphere(n, [rng.next_f32(), rng.next_f32()]);
                assert!((w.length() - 1.0).abs() < 1e-5 && w.dot(n) >= -1e-6, "n = {n}, w = {w}");
            }
        }
    }

    /// Pearson's chi-square test of the directions against the cosine density, around a tilted
    /// normal. Bins: 10 rings of equal `sin²θ` (each holding 1/10 of the cosine density:
    /// `P(θ < Θ) = sin²Θ`) times 20 sectors of `φ` measured in the normal's own frame; 100,000
    /// samples give 500 per bin. With 199 degrees of freedom, p < 1e-4 (chi-square above about
    /// 285) fails: a correct sampler fails one run in 10,000; a uniform one puts 6 times as many
    /// samples in the outermost ring as in the innermost and gives a chi-square in the tens of
    /// thousands.
    #[test]
    fn cosine_samples_follow_the_cosine_density() {
        let (rings, sectors, samples) = (10usize, 20usize, 100_000usize);
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (t, b) = tangent_frame(n);
        let mut counts = vec![0usize; rings * sectors];
        let mut rng = Rng::new(92, 0);
        for _ in 0..samples {
            let w = cosine_hemisphere(n, [rng.next_f32(), rng.next_f32()]);
            let cos = w.dot(n).clamp(0.0, 1.0);
            let ring = (((1.0 - cos * cos) * rings as f32) as usize).min(rings - 1);
            let phi = w.dot(b).atan2(w.dot(t)).rem_euclid(2.0 * PI);
            let sector = ((phi / (2.0 * PI) * sectors as f32) as usize).min(sectors - 1);
            counts[ring * sectors + sector] += 1;
        }
        let expected = samples as f64 / (rings * sectors) as f64;
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
        let p = chi_square_upper(chi2, (rings * sectors - 1) as f64);
        assert!(p > 1e-4, "chi-square {chi2:.0} with {} dof: p = {p:.1e}", rings * sectors - 1);
    }
}
