//! Feature masks: which pixels show glass, shadow, or an edge between objects.
//!
//! Made once per scene with the reference solution (by `grader update-references`), stored beside
//! the reference image as a PNG (red = glass, green = shadow, blue = edge), and used to score a
//! render where a checkpoint's effect shows, instead of averaging it away over the whole image.
//! Rendering them is the instructor's (`render_references.rs`); grading only reads them.

use image::RgbImage;

use crate::rubric::Mask;

/// One boolean per pixel for each mask.
#[derive(Clone, Debug, PartialEq)]
pub struct Masks {
    image: RgbImage,
}

impl Masks {
    /// Masks stored as a PNG (red = glass, green = shadow, blue = edge).
    pub fn from_image(image: RgbImage) -> Self {
        Self { image }
    }

    /// The PNG form.
    pub fn image(&self) -> &RgbImage {
        &self.image
    }

    /// Whether pixel `(x, y)` is in `mask`.
    pub fn contains(&self, mask: Mask, x: u32, y: u32) -> bool {
        let channel = match mask {
            Mask::Glass => 0,
            Mask::Shadow => 1,
            Mask::Edge => 2,
        };
        self.image.get_pixel(x, y)[channel] >= 128
    }
}
