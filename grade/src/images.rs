//! The grader's images are `image::RgbImage`s (for SSIM, heat maps, masks); the renderer's PNG
//! reading and writing (`raylab_base::image_io`) carries them to and from disk.

use std::path::Path;

use image::RgbImage;
use raylab_base::film::Film;
use raylab_base::image_io::{self, film_to_rgb8, ImageError, Rgb8Image};

/// Reads a PNG (any bit depth or colour type) as 8-bit RGB.
pub fn read_png(path: &Path) -> Result<RgbImage, ImageError> {
    let image = image_io::read_png(path)?;
    RgbImage::from_raw(image.width, image.height, image.data).ok_or_else(|| ImageError::Read {
        path: path.to_path_buf(),
        message: "the decoded pixels do not fill the image".to_string(),
    })
}

/// Writes `image` as a PNG, atomically.
pub fn write_png(path: &Path, image: &RgbImage) -> Result<(), ImageError> {
    let (width, height) = image.dimensions();
    image_io::write_png(path, &Rgb8Image { width, height, data: image.as_raw().clone() })
}

/// The film as an 8-bit sRGB image.
pub fn film_to_image(film: &Film) -> RgbImage {
    let Rgb8Image { width, height, data } = film_to_rgb8(film);
    let image = RgbImage::from_raw(width, height, data);
    debug_assert!(image.is_some(), "a film has width × height pixels");
    image.unwrap_or_default()
}
