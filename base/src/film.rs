//! The film: a grid of linear RGB radiance values, one per pixel, row-major from the top left.

use glam::Vec3;

/// Linear radiance per pixel (f32, unclamped). Encoding to sRGB happens only when writing.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl Film {
    /// A black film.
    pub fn new(width: u32, height: u32) -> Self {
        Self::from_pixels(width, height, vec![Vec3::ZERO; width as usize * height as usize])
    }

    /// A film holding `pixels`, row-major from the top left (`width · height` of them).
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Vec3>) -> Self {
        assert_eq!(pixels.len(), width as usize * height as usize, "pixel count must be width × height");
        Self { width, height, pixels }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixel at column `x`, row `y`.
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[self.index(x, y)]
    }

    /// Sets the pixel at column `x`, row `y`.
    pub fn set(&mut self, x: u32, y: u32, value: Vec3) {
        let i = self.index(x, y);
        self.pixels[i] = value;
    }

    /// All pixels, row-major from the top left.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// Adds `weight` times `other`, a film of the same size, to every pixel: `1 / n` for each of
    /// `n` films added to a black one gives their mean.
    pub fn add_scaled(&mut self, other: &Film, weight: f32) {
        assert_eq!((self.width, self.height), (other.width, other.height), "films of different sizes");
        for (p, q) in self.pixels.iter_mut().zip(&other.pixels) {
            *p += *q * weight;
        }
    }

    fn index(&self, x: u32, y: u32) -> usize {
        debug_assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside the film");
        y as usize * self.width as usize + x as usize
    }
}
