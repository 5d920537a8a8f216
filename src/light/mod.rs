//! Lights: point lights (checkpoint 6) and area lights, emitting surfaces (checkpoint 8); and the
//! choice of one light among all of a scene's, in proportion to its power (checkpoint 8).

mod area;
mod choice;
mod point;

pub use area::{AreaLight, LightSample};
pub use choice::{choose_light, light_powers, Light};
pub use point::PointLight;
