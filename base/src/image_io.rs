//! From linear radiance to an 8-bit sRGB PNG on disk, and back; and the linear radiance itself as
//! a Portable Float Map, for the statistics of noisy renders.
//!
//! Output is: clamp to `[0, 1]`, apply the sRGB transfer function, round to 8 bits. The transfer
//! function is `12.92 c` for `c ≤ 0.0031308`, else `1.055 c^(1/2.4) − 0.055` (IEC 61966-2-1).
//! Files are written to a temporary name beside the target and renamed into place, so a failed
//! or interrupted write never leaves half an image over a good one.
//!
//! A PFM file is the header `PF\n<width> <height>\n-1.0\n` (colour; the negative scale means
//! little-endian) followed by `width · height` RGB triples of 32-bit floats, rows from the
//! *bottom* of the image up. It keeps every value exactly, beyond 1 and below 1/255.

use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use crate::film::Film;
use glam::Vec3;

/// Errors reading or writing images; each names the file.
#[derive(Debug)]
pub enum ImageError {
    /// Writing failed.
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// Reading or decoding failed.
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

impl std::fmt::Display for ImageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Write { path, message } => {
                write!(f, "{}: cannot write the image: {message}", path.display())
            }
            Self::Read { path, message } => write!(f, "{}: cannot read the image: {message}", path.display()),
        }
    }
}

impl std::error::Error for ImageError {}

/// The sRGB encoding of a linear value in `[0, 1]`.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The linear value of an sRGB-encoded value in `[0, 1]`.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// One linear channel as an 8-bit sRGB value. NaN becomes 0: a broken pixel shows black.
pub fn encode_channel(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    (linear_to_srgb(c) * 255.0).round() as u8
}

/// An 8-bit sRGB image: `width × height` pixels, row by row, three bytes (R, G, B) each.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rgb8Image {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `3 · width · height` bytes.
    pub data: Vec<u8>,
}

/// The film as an 8-bit sRGB image.
pub fn film_to_rgb8(film: &Film) -> Rgb8Image {
    let data = film.pixels().iter().flat_map(|p| p.to_array().map(encode_channel)).collect();
    Rgb8Image { width: film.width(), height: film.height(), data }
}

/// An 8-bit sRGB image decoded to linear values.
pub fn rgb8_to_film(image: &Rgb8Image) -> Film {
    let decode = |c: u8| srgb_to_linear(c as f32 / 255.0);
    let pixels =
        image.data.chunks_exact(3).map(|p| Vec3::new(decode(p[0]), decode(p[1]), decode(p[2]))).collect();
    Film::from_pixels(image.width, image.height, pixels)
}

/// Writes `image` as a PNG at `path`, atomically (see [`write_file_atomic`]).
pub fn write_png(path: &Path, image: &Rgb8Image) -> Result<(), ImageError> {
    let fail =
        |e: &dyn std::fmt::Display| ImageError::Write { path: path.to_path_buf(), message: e.to_string() };
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| fail(&e))?;
    writer.write_image_data(&image.data).map_err(|e| fail(&e))?;
    writer.finish().map_err(|e| fail(&e))?;
    write_file_atomic(path, &bytes).map_err(|e| fail(&e))
}

/// Writes `bytes` to a hidden temporary file beside `path`, syncs it, and renames it over `path`:
/// readers see the old file or the new one, never half of one. The temporary file is removed if
/// anything fails.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path.file_name().ok_or_else(|| std::io::Error::other("not a file name"))?;
    let temporary = path.with_file_name(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
    let result = (|| {
        let mut file = std::fs::File::create(&temporary)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&temporary, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// Reads a PNG (any bit depth or colour type) as 8-bit RGB: 16-bit samples keep their high
/// byte, palettes are expanded, grey is repeated in R, G and B, alpha is dropped.
pub fn read_png(path: &Path) -> Result<Rgb8Image, ImageError> {
    let fail =
        |e: &dyn std::fmt::Display| ImageError::Read { path: path.to_path_buf(), message: e.to_string() };
    let file = std::fs::File::open(path).map_err(|e| fail(&e))?;
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder.read_info().map_err(|e| fail(&e))?;
    let mut buffer = vec![0; reader.output_buffer_size().ok_or_else(|| fail(&"the image is too large"))?];
    let frame = reader.next_frame(&mut buffer).map_err(|e| fail(&e))?;
    let samples = &buffer[..frame.buffer_size()];
    let data = match frame.color_type {
        png::ColorType::Rgb => samples.to_vec(),
        png::ColorType::Rgba => samples.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect(),
        png::ColorType::Grayscale => samples.iter().flat_map(|&g| [g; 3]).collect(),
        png::ColorType::GrayscaleAlpha => samples.chunks_exact(2).flat_map(|p| [p[0]; 3]).collect(),
        png::ColorType::Indexed => return Err(fail(&"a palette image that was not expanded")),
    };
    Ok(Rgb8Image { width: frame.width, height: frame.height, data })
}

/// Writes the film as an sRGB PNG, atomically.
pub fn write_film(path: &Path, film: &Film) -> Result<(), ImageError> {
    write_png(path, &film_to_rgb8(film))
}

/// Writes the film's linear values as a little-endian colour PFM, atomically.
pub fn write_pfm(path: &Path, film: &Film) -> Result<(), ImageError> {
    let (width, height) = (film.width(), film.height());
    let mut bytes = format!("PF\n{width} {height}\n-1.0\n").into_bytes();
    for y in (0..height).rev() {
        for x in 0..width {
            bytes.extend(film.get(x, y).to_array().iter().flat_map(|c| c.to_le_bytes()));
        }
    }
    write_file_atomic(path, &bytes)
        .map_err(|e| ImageError::Write { path: path.to_path_buf(), message: e.to_string() })
}

/// Reads a colour PFM (either byte order) into a film.
pub fn read_pfm(path: &Path) -> Result<Film, ImageError> {
    let fail = |message: &str| ImageError::Read { path: path.to_path_buf(), message: message.to_string() };
    let bytes = std::fs::read(path).map_err(|e| fail(&e.to_string()))?;
    // Three header fields, each ended by one whitespace byte.
    let mut fields = Vec::new();
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate().take(256) {
        if b.is_ascii_whitespace() {
            if i > start {
                fields
                    .push(std::str::from_utf8(&bytes[start..i]).map_err(|_| fail("the header is not text"))?);
            }
            start = i + 1;
            if fields.len() == 4 {
                break;
            }
        }
    }
    let [magic, width, height, scale] = fields[..] else { return Err(fail("the header is incomplete")) };
    if magic != "PF" {
        return Err(fail("not a colour PFM (it must start with PF)"));
    }
    let number = |field: &str| field.parse::<u32>().ok().filter(|&n| n > 0);
    let (Some(width), Some(height)) = (number(width), number(height)) else {
        return Err(fail("the width and height must be positive whole numbers"));
    };
    let little = match scale.parse::<f32>() {
        Ok(s) if s < 0.0 => true,
        Ok(s) if s > 0.0 => false,
        _ => return Err(fail("the scale must be a non-zero number")),
    };
    let data = &bytes[start..];
    let expected = width as usize * height as usize * 12;
    if data.len() != expected {
        return Err(fail(&format!(
            "{width}x{height} needs {expected} bytes of pixels, the file has {}",
            data.len()
        )));
    }
    let value = |chunk: &[u8]| {
        let word = [chunk[0], chunk[1], chunk[2], chunk[3]];
        if little {
            f32::from_le_bytes(word)
        } else {
            f32::from_be_bytes(word)
        }
    };
    let mut film = Film::new(width, height);
    for (i, pixel) in data.chunks_exact(12).enumerate() {
        let (x, row) = (i as u32 % width, i as u32 / width);
        film.set(
            x,
            height - 1 - row,
            Vec3::new(value(&pixel[0..4]), value(&pixel[4..8]), value(&pixel[8..12])),
        );
    }
    Ok(film)
}

#[cfg(test)]
mod checkpoint1 {
    use super::*;

    #[test]
    fn the_srgb_curve_matches_known_values_and_inverts() {
        // Linear 0.5 is sRGB 0.7354; linear 0.2140 is sRGB 0.5 (IEC 61966-2-1).
        assert!((linear_to_srgb(0.5) - 0.735_356_6).abs() < 1e-5);
        assert!((srgb_to_linear(0.5) - 0.214_041_1).abs() < 1e-5);
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(c)) - c).abs() < 1e-5);
        }
    }

    #[test]
    fn encoding_clamps_and_blacks_out_nan() {
        assert_eq!(encode_channel(-1.0), 0);
        assert_eq!(encode_channel(7.0), 255);
        assert_eq!(encode_channel(f32::NAN), 0);
        assert_eq!(encode_channel(0.5), 188);
    }

    #[test]
    fn a_film_round_trips_through_a_png_file() {
        let dir = std::env::temp_dir().join(format!("raylab-film-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("film.png");
        let pixels = (0..12).map(|i| Vec3::new(i as f32 / 11.0, 1.0 - i as f32 / 11.0, 0.25)).collect();
        let film = Film::from_pixels(4, 3, pixels);
        write_film(&path, &film).unwrap();
        let back = read_png(&path).unwrap();
        assert_eq!(back, film_to_rgb8(&film), "8-bit values survive exactly");
        // Decoded, each value is within half an 8-bit step of the original, in sRGB terms.
        for (a, b) in film.pixels().iter().zip(rgb8_to_film(&back).pixels()) {
            for k in 0..3 {
                assert!((linear_to_srgb(a[k]) - linear_to_srgb(b[k])).abs() <= 0.5 / 255.0 + 1e-6);
            }
        }
        let leftovers = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1, "no temporary file is left behind");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Every value survives exactly, above 1 and below an 8-bit step included, with the rows in
    /// the right order; a file of the wrong size or kind is refused, naming the file.
    #[test]
    fn a_film_round_trips_through_a_pfm_file_bit_for_bit() {
        let dir = std::env::temp_dir().join(format!("raylab-pfm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("film.pfm");
        let pixels = (0..15).map(|i| Vec3::new(i as f32 * 3.7, 1e-6 * i as f32, -0.5 + i as f32)).collect();
        let film = Film::from_pixels(5, 3, pixels);
        write_pfm(&path, &film).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"PF\n5 3\n-1.0\n"));
        // The first pixel stored is the bottom row's first.
        assert_eq!(&bytes[12..16], &film.get(0, 2).x.to_le_bytes());
        assert_eq!(read_pfm(&path).unwrap().pixels(), film.pixels());
        std::fs::write(&path, &bytes[..bytes.len() - 1]).unwrap();
        let err = read_pfm(&path).unwrap_err().to_string();
        assert!(err.contains("film.pfm") && err.contains("needs 180 bytes"), "{err}");
        std::fs::write(&path, b"P6\n5 3\n255\n").unwrap();
        assert!(read_pfm(&path).unwrap_err().to_string().contains("not a colour PFM"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_failed_write_names_the_file_and_leaves_nothing() {
        let path = std::env::temp_dir().join("raylab-no-such-dir/x/out.png");
        let err = write_film(&path, &Film::new(2, 2)).unwrap_err();
        assert!(err.to_string().contains("out.png"), "{err}");
        assert!(!path.exists());
    }
}
