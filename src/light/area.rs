//! Checkpoint 8, part 1: area lights, and a uniformly random point on one.
//!
//! **Task.** Write [`AreaLight::sample`]: a point uniformly distributed over the light's whole
//! surface (all its triangles), its normal, and the density of that choice.
//!
//! **Maths.** An area light is a mesh whose triangles emit the radiance `L_e` from their front
//! side (the side the normal points to), the same in every direction (a Lambertian emitter): it
//! emits the power `Φ = π · A · L_e` (the exitance `π L_e` over the area `A`). To pick a point
//! uniformly over the area `A = Σ A_k`, pick triangle `k` with probability `A_k / A` (with `u₀`:
//! the first `k` whose running sum of areas passes `u₀ · A`), then a point uniformly inside it
//! with `u₁, u₂`:
//!
//! ```text
//!   s = √u₁,   p = (1 − s) · p0 + s (1 − u₂) · p1 + s u₂ · p2
//! ```
//!
//! (the square root spreads the points evenly; without it they crowd at `p0`). Every point of
//! the light is then chosen with the density `pdf_A = 1 / A` with respect to area.
//!
//! **Conventions.** `u` holds three numbers uniform in `[0, 1)`. [`AreaLight::cumulative_area`]
//! is the running sum of the triangles' areas, built for you.
//!
//! **Pitfalls.**
//! - Choosing the triangle uniformly (probability `1 / n`): small triangles get as many points as
//!   large ones, and the estimate of checkpoint 8 is biased wherever triangles differ in size.
//! - `(u₁, u₂)` as barycentrics without the square root, or folding them without care: points
//!   crowd at a corner or fall outside the triangle.
//!
//! **Check:** `cargo test checkpoint8`. Handout: `checkpoints/08-area-lights.md`.

use crate::geometry::Triangle;
use crate::math::Vec3;

/// A mesh emitting from the front of its triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    /// The `[[objects]]` entry it came from.
    pub object: u32,
    /// Its triangles, in world space.
    pub triangles: Vec<Triangle>,
    /// `cumulative_area[k]` is the area of triangles `0..=k`; the last is the total.
    pub cumulative_area: Vec<f32>,
    /// Emitted radiance `L_e` per channel, the same everywhere on the front side.
    pub radiance: Vec3,
}

/// A point chosen on an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// The point.
    pub point: Vec3,
    /// The unit normal of its triangle: the side the light shines toward.
    pub normal: Vec3,
    /// The density of choosing it, per unit area.
    pub pdf_area: f32,
}

impl AreaLight {
    /// The light made of `triangles` (at least one, with a positive total area).
    pub fn new(object: u32, triangles: Vec<Triangle>, radiance: Vec3) -> Self {
        let cumulative_area = triangles
            .iter()
            .scan(0.0, |sum, t| {
                *sum += t.area();
                Some(*sum)
            })
            .collect();
        Self { object, triangles, cumulative_area, radiance }
    }

    /// The total area `A`.
    pub fn area(&self) -> f32 {
        self.cumulative_area.last().copied().unwrap_or(0.0)
    }

    /// The power `Φ = π A L_e` it emits, per channel.
    pub fn power(&self) -> Vec3 {
        std::f32::consts::PI * self.area() * self.radiance
    }

    /// A point uniformly distributed over the light's area, from three numbers in `[0, 1)`.
    pub fn sample(&self, u: [f32; 3]) -> LightSample {
        // BEGIN SOLUTION checkpoint8
        let area = self.area();
        let target = u[0] * area;
        let k = self.cumulative_area.partition_point(|&c| c <= target).min(self.triangles.len() - 1);
        let triangle = &self.triangles[k];
        let s = u[1].sqrt();
        let point = triangle.point(s * (1.0 - u[2]), s * u[2]);
        LightSample { point, normal: triangle.normal(), pdf_area: 1.0 / area }
        // END SOLUTION
    }
}

#[cfg(test)]
mod checkpoint8 {
    use super::*;
    use crate::rng::Rng;
    use crate::stats::chi_square_upper;

    /// A trapezoid in the plane z = 0 of two triangles of areas 1 and 0.5: x in [0, 2], y in
    /// [0, 1], the top edge from x = 0 to x = 1.
    fn trapezoid() -> AreaLight {
        let (a, b, c, d) = (
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        AreaLight::new(3, vec![Triangle::new(a, b, c), Triangle::new(a, c, d)], Vec3::ONE)
    }

    /// Whether (x, y) is inside the trapezoid.
    fn inside(x: f64, y: f64) -> bool {
        (0.0..=2.0).contains(&x) && (0.0..=1.0).contains(&y) && x <= 2.0 - y
    }

    /// The density of sample points equals 1/A everywhere, by a chi-square test: counts in a 10 x 5
    /// grid of bins over the trapezoid's bounding box against the expected count of each bin, the
    /// sample count times the bin's share of the area (integrated over a 40 x 40 sub-grid per bin,
    /// so the edge bins are right to 0.1%). Bins expecting fewer than 5 points are pooled (the
    /// chi-square approximation needs about 5 per bin). A correct sampler fails with probability
    /// 1e-3 for an unlucky seed; the seed is fixed, so the test is deterministic.
    #[test]
    fn sampled_points_are_uniform_over_the_lights_area_by_a_chi_square_test() {
        let light = trapezoid();
        assert_eq!(light.area(), 1.5, "the trapezoid's two triangles cover 1.5");
        let (nx, ny, n) = (10, 5, 100_000);
        let mut counts = vec![0u32; nx * ny];
        let mut rng = Rng::new(81, 0);
        for _ in 0..n {
            let s = light.sample([rng.next_f32(), rng.next_f32(), rng.next_f32()]);
            assert_eq!(s.pdf_area, 1.0 / 1.5, "uniform over the whole light: pdf_A = 1 / A");
            assert_eq!(s.normal, Vec3::Z, "the sampled triangle's normal: the light faces +z");
            let (x, y) = (s.point.x as f64, s.point.y as f64);
            assert!(inside(x, y) && s.point.z == 0.0, "{:?} is off the light", s.point);
            let (bx, by) =
                (((x / 2.0 * nx as f64) as usize).min(nx - 1), ((y * ny as f64) as usize).min(ny - 1));
            counts[by * nx + bx] += 1;
        }
        let sub = 40;
        let mut expected = vec![0.0f64; nx * ny];
        for (bin, e) in expected.iter_mut().enumerate() {
            let (bx, by) = ((bin % nx) as f64, (bin / nx) as f64);
            let (w, h) = (2.0 / nx as f64, 1.0 / ny as f64);
            let covered = (0..sub * sub)
                .filter(|i| {
                    let (sx, sy) = ((i % sub) as f64 + 0.5, (i / sub) as f64 + 0.5);
                    inside((bx + sx / sub as f64) * w, (by + sy / sub as f64) * h)
                })
                .count();
            *e = n as f64 * covered as f64 / (sub * sub) as f64 * w * h / light.area() as f64;
        }
        let (mut chi2, mut dof, mut pooled) = (0.0, 0, (0.0, 0.0));
        for (&count, &e) in counts.iter().zip(&expected) {
            if e < 5.0 {
                pooled = (pooled.0 + count as f64, pooled.1 + e);
                assert!(e > 0.0 || count == 0, "points where the light is not");
            } else {
                chi2 += (count as f64 - e).powi(2) / e;
                dof += 1;
            }
        }
        if pooled.1 > 0.0 {
            chi2 += (pooled.0 - pooled.1).powi(2) / pooled.1;
            dof += 1;
        }
        let p = chi_square_upper(chi2, (dof - 1) as f64);
        assert!(p > 1e-3, "chi-square {chi2:.1} on {} degrees of freedom: p = {p:.2e}", dof - 1);
    }

    /// The larger triangle gets two thirds of the points (its share of the area), within five
    /// standard deviations of the binomial count.
    #[test]
    fn triangles_are_chosen_in_proportion_to_their_area() {
        let light = trapezoid();
        let mut rng = Rng::new(82, 0);
        let n = 40_000.0;
        let in_first = (0..n as u32)
            .filter(|_| {
                let p = light.sample([rng.next_f32(), rng.next_f32(), rng.next_f32()]).point;
                // The first triangle (a, b, c) lies below the diagonal from (0, 0) to (1, 1)
                // and to its right.
                p.x >= p.y
            })
            .count() as f64;
        let share: f64 = 2.0 / 3.0;
        let sd = (n * share * (1.0 - share)).sqrt();
        assert!((in_first - share * n).abs() < 5.0 * sd, "{in_first} of {n} in the larger triangle");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The power of a one-sided Lambertian emitter: π A L_e.
    #[test]
    fn a_lights_power_is_pi_times_area_times_radiance() {
        let triangles = vec![Triangle::new(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0))];
        let mut light = AreaLight::new(0, triangles, Vec3::ONE);
        light.radiance = Vec3::new(1.0, 2.0, 3.0);
        let want = std::f32::consts::PI * 2.0 * Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(light.power(), want, "a Lambertian emitter of area 2: Φ = π · A · L_e");
    }
}
