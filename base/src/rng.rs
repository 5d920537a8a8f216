//! A small seedable random number generator: PCG32 (O'Neill, 2014).
//!
//! Renders seed one generator per pixel from (scene seed, pixel index) with [`Rng::for_pixel`], so
//! every pixel draws the same numbers whichever thread renders it, and images are identical for
//! any thread count. There is no global or thread-local generator anywhere in raylab.

/// PCG32: a 64-bit linear congruential state, output permuted by an xorshift and a random rotation.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    /// The LCG increment; always odd. Different increments give independent streams.
    increment: u64,
}

const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// Streams of path generators: pixel indices (below 2⁶²) with the top stream bit set.
const PATH_STREAMS: u64 = 1 << 62;

impl Rng {
    /// A generator for `seed` on stream `stream`; distinct streams give unrelated sequences.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Self { state: 0, increment: (stream << 1) | 1 };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The generator of one pixel: the scene's seed on the pixel's own stream.
    pub fn for_pixel(seed: u64, pixel_index: u64) -> Self {
        Self::new(seed, pixel_index)
    }

    /// The generator of one pixel's paths (light samples, bounces): the pixel's own stream in
    /// the upper half of the stream space, so it never repeats the pixel's film positions.
    pub fn for_paths(seed: u64, pixel_index: u64) -> Self {
        Self::new(seed, pixel_index | PATH_STREAMS)
    }

    /// The next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULTIPLIER).wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rotation = (old >> 59) as u32;
        xorshifted.rotate_right(rotation)
    }

    /// A uniform float in `[0, 1)`: the top 24 bits, so every value is exactly representable.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_stay_in_the_unit_interval_with_the_right_mean() {
        let mut rng = Rng::new(7, 3);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = rng.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        // The mean of n uniforms has standard deviation sqrt(1/12 / n) ≈ 9.1e-4; allow 5 sigma.
        assert!((sum / n as f64 - 0.5).abs() < 5.0 * (1.0f64 / 12.0 / n as f64).sqrt());
    }

    #[test]
    fn the_same_pixel_repeats_and_neighbouring_pixels_differ() {
        let draw = |pixel| {
            let mut rng = Rng::for_pixel(1, pixel);
            (0..64).map(|_| rng.next_u32()).collect::<Vec<_>>()
        };
        assert_eq!(draw(10), draw(10));
        let same = draw(10).iter().zip(draw(11)).filter(|(a, b)| **a == *b).count();
        assert_eq!(same, 0, "streams of neighbouring pixels must not coincide");
    }
}
