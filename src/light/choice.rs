//! Checkpoint 8, part 2: choosing one light among all of a scene's, in proportion to its power.
//!
//! **Task.** Write [`choose_light`]: given every light's power (point lights first, then area
//! lights, in scene order: [`crate::scene::Scene::light`]) and a number `u` uniform in `[0, 1)`,
//! pick light `i` with probability `P(i) = Φ_i / Σ Φ` and return it with that probability.
//!
//! **Maths.** Walk the running sum of the powers and take the first light whose running sum
//! passes `u · Σ Φ`. A Monte Carlo estimate that picks one light this way and divides its
//! contribution by `P(i)` is unbiased: each light's share is counted `P(i) · (1 / P(i)) = 1`
//! times on average. Bright lights get more samples, dim ones fewer, so the noise goes where the
//! light is. The scalar power of a light is the mean of its three channels.
//!
//! **Pitfalls.**
//! - Returning probability `1 / n` for a light chosen by power (or choosing uniformly and
//!   dividing by `Φ_i / Σ Φ`): bright lights come out too bright and dim ones too dark.
//! - Choosing a light of zero power: its probability is 0 and dividing by it gives infinity.
//!
//! **Check:** `cargo test checkpoint8`. Handout: `checkpoints/08-area-lights.md`.

use super::{AreaLight, PointLight};
use crate::math::Vec3;

/// One light of a scene, of either kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light<'a> {
    /// A point light (checkpoint 6).
    Point(&'a PointLight),
    /// An emitting mesh.
    Area(&'a AreaLight),
}

impl Light<'_> {
    /// The power it emits, per channel.
    pub fn power(&self) -> Vec3 {
        match self {
            Light::Point(light) => light.power(),
            Light::Area(light) => light.power(),
        }
    }
}

/// Each light's scalar power, the mean of its channels, in the order given.
pub fn light_powers<'a>(lights: impl IntoIterator<Item = Light<'a>>) -> Vec<f32> {
    lights.into_iter().map(|l| l.power().element_sum() / 3.0).collect()
}

/// Picks light `i` with probability `powers[i] / Σ powers` using `u` in `[0, 1)`, and returns
/// `(i, P(i))`; `None` if no light has any power.
pub fn choose_light(powers: &[f32], u: f32) -> Option<(usize, f32)> {
    // BEGIN SOLUTION checkpoint8
    let total: f32 = powers.iter().sum();
    if total <= 0.0 {
        return None;
    }
    let target = u * total;
    let mut running = 0.0;
    for (i, &power) in powers.iter().enumerate() {
        running += power;
        if running > target && power > 0.0 {
            return Some((i, power / total));
        }
    }
    // Rounding can leave the running sum just below the target: the last light with power.
    let last = powers.iter().rposition(|&p| p > 0.0)?;
    Some((last, powers[last] / total))
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint8 {
    use super::*;
    use crate::rng::Rng;
    use crate::stats::chi_square_upper;

    /// Lights of power 1, 0, 6 and 3 are chosen 10%, 0%, 60% and 30% of the time (a chi-square
    /// test of 50,000 choices, p > 1e-3), each returned with exactly that probability.
    #[test]
    fn lights_are_chosen_in_proportion_to_their_power() {
        let powers = [1.0, 0.0, 6.0, 3.0];
        let mut counts = [0u32; 4];
        let mut rng = Rng::new(83, 0);
        let n = 50_000;
        for _ in 0..n {
            let (i, p) = choose_light(&powers, rng.next_f32()).expect("a light");
            assert!((p - powers[i] / 10.0).abs() < 1e-6, "light {i} returned with probability {p}");
            counts[i] += 1;
        }
        assert_eq!(counts[1], 0, "a light of no power is never chosen");
        let chi2: f64 = [0, 2, 3]
            .iter()
            .map(|&i| {
                let e = n as f64 * powers[i] as f64 / 10.0;
                (counts[i] as f64 - e).powi(2) / e
            })
            .sum();
        let p = chi_square_upper(chi2, 2.0);
        assert!(p > 1e-3, "counts {counts:?}: chi-square {chi2:.1}, p = {p:.2e}");
    }

    /// The ends of [0, 1) pick the first and the last light with power; no power, no light.
    #[test]
    fn the_ends_of_the_unit_interval_pick_the_first_and_last_lights() {
        let powers = [0.0, 2.0, 2.0, 0.0];
        assert_eq!(choose_light(&powers, 0.0).map(|c| c.0), Some(1), "u = 0: the first light with power");
        assert_eq!(choose_light(&powers, 0.999_999_9).map(|c| c.0), Some(2), "u near 1: the last with power");
        assert_eq!(choose_light(&[5.0], 0.3), Some((0, 1.0)), "one light: chosen with probability 1");
        assert_eq!(choose_light(&[0.0, 0.0], 0.5), None, "no power: no light (a probability of 0)");
        assert_eq!(choose_light(&[], 0.5), None, "no lights: none chosen");
    }
}
