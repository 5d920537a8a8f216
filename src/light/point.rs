//! Point lights.
//!
//! A scene gives a point light's *flux* Φ, the power it emits in all directions (RGB, watts). An
//! isotropic point source spreads it over the full sphere of 4π steradians, so its *intensity*
//! (power per solid angle) is `I = Φ / (4π)`. This file is the one place that conversion is made;
//! everything else asks [`PointLight::intensity`]. At distance `r`, on a surface turned `θ` away
//! from the light, the irradiance is `E = I cos θ / r²` (see checkpoint 6).

use crate::math::Vec3;

/// An isotropic point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Where the light is.
    pub position: Vec3,
    /// Total emitted power Φ per colour channel (watts).
    pub flux: Vec3,
}

impl PointLight {
    /// Radiant intensity `I = Φ / (4π)` (watts per steradian).
    pub fn intensity(&self) -> Vec3 {
        self.flux / (4.0 * std::f32::consts::PI)
    }

    /// The power Φ it emits, per channel.
    pub fn power(&self) -> Vec3 {
        self.flux
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intensity_is_flux_over_the_full_sphere() {
        let light = PointLight { position: Vec3::ZERO, flux: Vec3::splat(4.0 * std::f32::consts::PI) };
        assert_eq!(light.intensity(), Vec3::ONE, "I = Φ / 4π: a flux of 4π gives 1");
    }
}
