//! Stand-ins `render` draws with while a checkpoint is still the starter's `todo!()`, so that a
//! student sees a picture from checkpoint 2 on.
//!
//! `render` runs the real code; when it panics with a starter stub's message
//! (`not yet implemented: checkpoint N: ...`), it takes checkpoint N's stand-in, says so in one
//! line and starts again. Any other panic is reported as it is, never hidden. The stand-ins need
//! no solution and give none away:
//!
//! | checkpoint not written | stand-in |
//! |---|---|
//! | 2 (triangle) | none: nothing can be seen without it |
//! | 3 (box), 4 (BVH) | every triangle is tested for every ray (no BVH, no boxes); slow |
//! | 5 (glass, intersection test) | the first surface shaded by its normal; glass is not followed |
//! | 6 (direct lighting), 8 (area lights) | checkpoint 5's shading, or the normal if 5 is not written either |
//! | 9 (path tracing) | checkpoint 8's direct light only (no bounces), or as for 8 if 8 is not written |
//! | 7 (anti-aliasing) | one ray through each pixel centre |
//!
//! The grader renders with `render --no-fallbacks`, where a stub fails the scene, except for the
//! stand-ins a scene lists in the rubric (`stand_ins`) because they draw its picture exactly as the
//! solution's code does: it reads from the source which checkpoints are still stubs and asks for
//! those stand-ins up front (`render --stand-ins 3,4`), and they earn their checkpoints nothing.

use crate::geometry::SplitMethod;
use crate::integrator::{Integrator, IntersectionTestIntegrator, MonteCarloDirectIntegrator};
use crate::scene::{RenderSettings, Scene, World};

/// How the starter's stubs panic (`todo!("checkpoint N: ...")`).
const STUB_PANIC: &str = "not yet implemented: checkpoint ";

/// The checkpoint whose starter stub a panic message comes from, if it is one.
pub fn stub_checkpoint(message: &str) -> Option<u32> {
    let rest = message.strip_prefix(STUB_PANIC)?;
    rest.split(':').next()?.parse().ok()
}

/// How surfaces are shaded instead of the integrator the scene asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shading {
    /// Checkpoint 5's intersection-test integrator (no lights).
    IntersectionTest,
    /// Checkpoint 8's Monte Carlo direct lighting (no bounces).
    DirectOnly,
    /// The first surface's normal as a colour ([`crate::integrator::normal_colour`]).
    Normals,
}

/// The stand-ins taken so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Fallbacks {
    /// Test every triangle instead of building and traversing the BVH.
    pub every_triangle: bool,
    /// Shade this way instead of with the scene's integrator.
    pub shading: Option<Shading>,
    /// One ray through each pixel centre, whatever the samples per pixel.
    pub pixel_centre: bool,
}

impl Fallbacks {
    /// The stand-ins of `checkpoints` taken from the start, or the first checkpoint without one.
    pub fn standing_in(checkpoints: &[u32]) -> Result<Fallbacks, u32> {
        let mut fallbacks = Fallbacks::default();
        for &checkpoint in checkpoints {
            if fallbacks.take(checkpoint).is_none() && !fallbacks.covers(checkpoint) {
                return Err(checkpoint);
            }
        }
        Ok(fallbacks)
    }

    /// Whether the stand-ins taken replace all of `checkpoint`'s code.
    pub fn covers(&self, checkpoint: u32) -> bool {
        match checkpoint {
            3 | 4 => self.every_triangle,
            5 => self.shading == Some(Shading::Normals),
            6 | 8 => matches!(self.shading, Some(Shading::IntersectionTest | Shading::Normals)),
            9 => self.shading.is_some(),
            7 => self.pixel_centre,
            _ => false,
        }
    }

    /// Takes the stand-in for `checkpoint`, returning the line that tells the user, or `None` if
    /// there is none (checkpoint 2) or it was already taken (the stub is then an error).
    pub fn take(&mut self, checkpoint: u32) -> Option<&'static str> {
        match checkpoint {
            3 | 4 if !self.every_triangle => {
                self.every_triangle = true;
                Some("tracing every triangle instead of the BVH; slow")
            }
            5 if self.shading != Some(Shading::Normals) => {
                self.shading = Some(Shading::Normals);
                Some("shading the first surface by its normal; glass is not followed")
            }
            9 if self.shading.is_none() => {
                self.shading = Some(Shading::DirectOnly);
                Some("direct light only, as checkpoint 8 estimates it; no bounces")
            }
            6 | 8 if matches!(self.shading, None | Some(Shading::DirectOnly)) => {
                self.shading = Some(Shading::IntersectionTest);
                Some("shading as checkpoint 5 does, without lights")
            }
            7 if !self.pixel_centre => {
                self.pixel_centre = true;
                Some("one ray through each pixel centre, no anti-aliasing")
            }
            _ => None,
        }
    }
}

impl Fallbacks {
    /// The world to trace: with the BVH, or testing every triangle.
    pub fn world<'a>(&self, scene: &'a Scene) -> World<'a> {
        if self.every_triangle {
            World::tracing_every_triangle(scene)
        } else {
            World::new(scene, SplitMethod::ObjectMedian)
        }
    }

    /// The integrator to shade with, and the settings to render with.
    pub fn integrator(&self, settings: &RenderSettings) -> (Integrator, RenderSettings) {
        let integrator = match self.shading {
            None => Integrator::from_settings(settings),
            Some(Shading::IntersectionTest) => {
                Integrator::IntersectionTest(IntersectionTestIntegrator { max_depth: settings.max_depth })
            }
            Some(Shading::DirectOnly) => {
                Integrator::MonteCarloDirect(MonteCarloDirectIntegrator { max_depth: settings.max_depth })
            }
            Some(Shading::Normals) => Integrator::Normals,
        };
        let spp = if self.pixel_centre { 1 } else { settings.spp };
        (integrator, RenderSettings { spp, ..*settings })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_starters_stub_messages_name_a_checkpoint() {
        assert_eq!(stub_checkpoint("not yet implemented: checkpoint 4: write `traverse`: ..."), Some(4));
        assert_eq!(stub_checkpoint("not yet implemented"), None);
        assert_eq!(stub_checkpoint("index out of bounds: checkpoint 4: ..."), None);
    }

    #[test]
    fn each_stand_in_is_taken_once_and_checkpoint_2_has_none() {
        let mut f = Fallbacks::default();
        assert_eq!(f.take(2), None);
        assert!(f.take(6).is_some());
        assert_eq!(f.shading, Some(Shading::IntersectionTest));
        assert!(f.take(5).is_some(), "checkpoint 5 unwritten too: down to normals");
        assert_eq!(f.take(5), None, "a stub still reached after its stand-in is a real failure");
        assert!(f.take(4).is_some());
        assert_eq!(f.take(3), None, "3 and 4 share one stand-in");
        assert!(f.take(7).is_some() && f.pixel_centre);
    }

    /// Stand-ins asked for up front cover each checkpoint named, in any order, 3 and 4 by one;
    /// checkpoint 2 has none.
    #[test]
    fn stand_ins_taken_up_front_cover_each_checkpoint_named() {
        for ids in [[3, 4, 5, 6, 7, 8, 9], [9, 8, 7, 6, 5, 4, 3]] {
            let f = Fallbacks::standing_in(&ids).unwrap();
            assert!(ids.iter().all(|&c| f.covers(c)), "{ids:?}: {f:?}");
            assert_eq!(f.shading, Some(Shading::Normals));
        }
        let f = Fallbacks::standing_in(&[4]).unwrap();
        assert!(f.covers(3) && f.every_triangle && f.shading.is_none() && !f.pixel_centre);
        assert_eq!(Fallbacks::standing_in(&[3, 2]), Err(2));
        assert_eq!(Fallbacks::standing_in(&[]), Ok(Fallbacks::default()));
    }

    /// Path tracing unwritten: checkpoint 8's direct light; then 8 unwritten too: checkpoint 5's
    /// shading, then the normals.
    #[test]
    fn path_tracing_falls_back_to_direct_light_then_to_checkpoint_5() {
        let mut f = Fallbacks::default();
        assert!(f.take(9).is_some());
        assert_eq!(f.shading, Some(Shading::DirectOnly));
        assert!(f.take(8).is_some());
        assert_eq!(f.shading, Some(Shading::IntersectionTest));
        assert_eq!(f.take(9), None);
        assert!(f.take(5).is_some());
        assert_eq!(f.shading, Some(Shading::Normals));
    }
}
