//! The tile test's picture of a noisy scene: which tiles of the submission's renders are off, and
//! which way, over a faint grey copy of the reference.
//!
//! Each tile shows its least likely test ([`crate::noisy::TileOutcome`]): blue where the mean is
//! too dark, red where it is too bright, purple where the noise is off (too noisy, not varying
//! with the seed, or not a number). A failed tile is filled strongly and outlined; a passing tile
//! is tinted only when its p-value is below the calm level, where a correct render's tiles stay
//! but with probability 1 in 20 ([`crate::noisy::CALM_RATE`]), from faint there to a third
//! at the test's level (on a log scale). So a correct render's map is plain grey, and colour means
//! something.

use image::{Rgb, RgbImage};

use crate::noisy::{Direction, NoisyVerdict};
use crate::report::heatmap::grey;

/// The caption that explains the colours.
pub const LEGEND: &str =
    "tile test: blue too dark, red too bright, purple noise off; outlined tiles failed, faint ones are less likely than a correct render's";

/// The colour of a direction.
fn colour(direction: Direction) -> [f64; 3] {
    match direction {
        Direction::Darker => [0.15, 0.45, 1.0],
        Direction::Brighter => [1.0, 0.2, 0.1],
        Direction::Noise => [0.8, 0.2, 1.0],
    }
}

/// How strongly a tile is coloured: 0 for a calm one, 0.12 to 0.35 for a passing tile between
/// the calm level and the test's level (log scale), 0.55 for a failed one (the scene still shows
/// through).
fn weight(p: f64, calm: f64, level: f64, failed: bool) -> f64 {
    if failed {
        return 0.55;
    }
    if p >= calm {
        return 0.0;
    }
    let towards_level = (calm.ln() - p.max(f64::MIN_POSITIVE).ln()) / (calm.ln() - level.ln());
    0.12 + 0.23 * towards_level.clamp(0.0, 1.0)
}

/// The map of `verdict` for tiles of `tile` pixels over `reference`.
pub fn tile_map(verdict: &NoisyVerdict, tile: u32, reference: &RgbImage) -> RgbImage {
    let failed: Vec<usize> = verdict.failures.iter().map(|f| f.tile).collect();
    let tiles_x = reference.width().div_ceil(tile);
    RgbImage::from_fn(reference.width(), reference.height(), |x, y| {
        let index = ((y / tile) * tiles_x + x / tile) as usize;
        let edge = [x % tile, y % tile].iter().any(|&i| i == 0 || i == tile - 1);
        // The scene in grey, the tile grid faintly lighter.
        let base = 0.4 * grey(reference, x, y) + if edge { 0.06 } else { 0.0 };
        let is_failed = failed.contains(&index);
        let outline = is_failed && edge;
        let (w, c) = match verdict.tiles.get(index) {
            Some(o) if outline => (1.0, colour(o.direction)),
            Some(o) => (weight(o.p, verdict.calm, verdict.level, is_failed), colour(o.direction)),
            None => (0.0, [0.0; 3]),
        };
        Rgb(c.map(|c| (((1.0 - w) * base + w * c) * 255.0).round() as u8))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noisy::{Channel, TileFailure, TileOutcome, TileProblem};

    fn verdict(tiles: Vec<TileOutcome>, failed: &[usize]) -> NoisyVerdict {
        let failures = failed
            .iter()
            .map(|&tile| TileFailure {
                tile,
                channel: Channel::Red,
                problem: TileProblem::NotFinite { mean: f64::NAN },
            })
            .collect();
        NoisyVerdict { failures, level: 1e-6, tiles, calm: 1e-3, yours: Vec::new(), expected: Vec::new() }
    }

    /// Calm tiles stay grey; a tile below the calm level is tinted its direction's colour; a
    /// failed one is filled more strongly and outlined in full colour.
    #[test]
    fn only_unlikely_tiles_are_coloured_each_by_its_direction() {
        let grey = RgbImage::from_pixel(8, 8, Rgb([100; 3]));
        let outcome = |p, direction| TileOutcome { p, direction };
        let tiles = vec![
            outcome(0.01, Direction::Brighter),
            outcome(1e-4, Direction::Darker),
            outcome(1e-9, Direction::Brighter),
            outcome(0.0, Direction::Noise),
        ];
        let map = tile_map(&verdict(tiles, &[2, 3]), 4, &grey);
        let plain = map.get_pixel(1, 1);
        assert_eq!(plain, map.get_pixel(2, 2), "a calm tile is one grey: {plain:?}");
        assert_eq!(plain[0], plain[2], "a calm tile is grey: {plain:?}");
        let dark = map.get_pixel(5, 1);
        assert!(dark[2] > dark[0] + 10, "too dark is blue: {dark:?}");
        let bright = map.get_pixel(1, 5);
        assert!(bright[0] > bright[2] + 100, "a failed bright tile is strongly red: {bright:?}");
        assert_eq!(map.get_pixel(0, 4), &Rgb([255, 51, 26]), "and outlined in full colour");
        let noise = map.get_pixel(5, 5);
        assert!(noise[0] > noise[1] + 50 && noise[2] > noise[1] + 50, "noise is purple: {noise:?}");
    }
}
