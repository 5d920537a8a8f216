//! The scene file format: TOML, read with serde into these types. Unknown keys are errors.
//!
//! Value checks that need only one value (finite numbers, a resolution in range, a non-zero
//! scale) run while deserializing, so their errors carry the value's position in the file.
//! Checks across values (a material that exists, a mesh file that loads) are in `load.rs`.
//! `scenes/README.md` documents the format with an annotated example.

use std::collections::BTreeMap;

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};
use toml::Spanned;

use glam::Vec3;

/// Largest film side accepted, in pixels.
pub const MAX_RESOLUTION: u32 = 8192;
/// Most icosphere subdivisions accepted (20 · 4^8 ≈ 1.3 million triangles).
pub const MAX_SUBDIVISIONS: u32 = 8;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// The camera and film.
    pub camera: CameraDesc,
    /// How to render.
    pub integrator: IntegratorDesc,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialDesc>,
    /// Point lights.
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// The objects.
    #[serde(default)]
    pub objects: Vec<ObjectDesc>,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position.
    #[serde(deserialize_with = "finite_vec3")]
    pub position: Vec3,
    /// The point the camera looks at.
    #[serde(deserialize_with = "finite_vec3")]
    pub look_at: Vec3,
    /// Roughly up; not parallel to the view direction.
    #[serde(deserialize_with = "finite_vec3")]
    pub up: Vec3,
    /// A pinhole camera's vertical field of view in degrees, in (0, 180).
    #[serde(default, deserialize_with = "field_of_view")]
    pub fov: Option<f32>,
    /// An orthographic camera's film height in world units, instead of `fov`: parallel rays.
    #[serde(default, deserialize_with = "positive_finite")]
    pub orthographic_height: Option<f32>,
    /// Film width in pixels, 1 to 8192.
    #[serde(deserialize_with = "resolution")]
    pub width: u32,
    /// Film height in pixels, 1 to 8192.
    #[serde(deserialize_with = "resolution")]
    pub height: u32,
}

/// `[integrator]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorDesc {
    /// Which integrator.
    pub kind: IntegratorKind,
    /// Samples per pixel, at least 1.
    #[serde(default = "one", deserialize_with = "positive")]
    pub spp: u32,
    /// Most specular bounces followed.
    #[serde(default = "default_max_depth")]
    pub max_depth: u32,
    /// Seed of the per-pixel random numbers.
    #[serde(default)]
    pub seed: u64,
}

/// The integrators a scene can ask for.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorKind {
    /// The first surface's normal, turned toward the camera, as a colour: geometry alone
    /// (checkpoints 2 to 4), no materials, no lights.
    Normals,
    /// Each object's bounding box, found by the slab test alone (checkpoint 3), coloured by the
    /// face the ray enters it through.
    Boxes,
    /// How many of the BVH's boxes each camera ray crosses before its closest hit (checkpoint 4's
    /// tree and traversal), as a heat map.
    BoxesCrossed,
    /// Checkpoint 5: surfaces shaded by albedo and viewing angle, no lights.
    IntersectionTest,
    /// Checkpoint 6: point lights, Lambertian shading, shadows.
    DirectLighting,
    /// Checkpoint 8: direct light from point and area lights, estimated by sampling them; the
    /// camera sees emitting surfaces.
    MonteCarloDirect,
    /// Checkpoint 9: global illumination by path tracing, with next-event estimation.
    PathTracer,
}

/// One `[materials.NAME]` table. Which fields a kind needs is checked in `load.rs` (a plain
/// struct, not a tagged enum, so that serde keeps every value's position for errors).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    /// Which material.
    pub kind: Spanned<MaterialKind>,
    /// For diffuse: albedo per channel, each in [0, 1].
    #[serde(default, deserialize_with = "albedo")]
    pub albedo: Option<Vec3>,
    /// For glass: index of refraction, finite and positive.
    #[serde(default, deserialize_with = "positive_finite")]
    pub ior: Option<f32>,
}

/// The kinds of material.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum MaterialKind {
    /// Lambertian, needs `albedo`.
    Diffuse,
    /// Perfect refraction, needs `ior`.
    Glass,
}

/// One `[[lights]]` entry: a point light.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    /// Position.
    #[serde(deserialize_with = "finite_vec3")]
    pub position: Vec3,
    /// Emitted power Φ per channel in watts, finite and not negative.
    #[serde(deserialize_with = "flux")]
    pub flux: Vec3,
}

/// One `[[objects]]` entry.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// Which shape.
    pub shape: Spanned<ShapeKind>,
    /// For `shape = "sphere"`: subdivisions of the icosahedron, 0 to 8.
    pub subdivisions: Option<Spanned<u32>>,
    /// For `shape = "obj"`: the mesh file, relative to the scene file.
    pub file: Option<Spanned<String>>,
    /// Name of a material in `[materials]`.
    pub material: Spanned<String>,
    /// Translation.
    #[serde(default, deserialize_with = "finite_vec3")]
    pub translate: Vec3,
    /// Rotation in degrees about the fixed X, then Y, then Z axes.
    #[serde(default, deserialize_with = "finite_vec3")]
    pub rotate: Vec3,
    /// Scale per axis, non-zero (negative mirrors).
    #[serde(default = "unit_scale", deserialize_with = "scale")]
    pub scale: Vec3,
    /// Radiance the object emits from the front of each triangle (the side its normal points
    /// to), per channel in W / (m² sr), finite and not negative: the object is an area light.
    #[serde(default, deserialize_with = "radiance")]
    pub emission: Option<Vec3>,
}

/// The shapes an object can have.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// The square [-1, 1]² in the plane y = 0, facing +y.
    Quad,
    /// The cube [-1, 1]³.
    Box,
    /// The unit sphere, as a subdivided icosahedron.
    Sphere,
    /// A mesh from an OBJ file.
    Obj,
}

impl MaterialKind {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Diffuse => "diffuse",
            Self::Glass => "glass",
        }
    }
}

fn one() -> u32 {
    1
}

fn default_max_depth() -> u32 {
    8
}

fn unit_scale() -> Vec3 {
    Vec3::ONE
}

/// Reads a value, then checks it with `valid`, failing with `message` (serde attaches the span).
fn checked<'de, D, T>(d: D, valid: impl Fn(&T) -> bool, message: &str) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let value = T::deserialize(d)?;
    if valid(&value) {
        Ok(value)
    } else {
        Err(D::Error::custom(message))
    }
}

fn finite_vec3<'de, D: Deserializer<'de>>(d: D) -> Result<Vec3, D::Error> {
    let v: [f32; 3] =
        checked(d, |v: &[f32; 3]| v.iter().all(|x| x.is_finite()), "expected three finite numbers")?;
    Ok(Vec3::from(v))
}

fn albedo<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec3>, D::Error> {
    let ok = |v: &[f32; 3]| v.iter().all(|x| (0.0..=1.0).contains(x));
    let message = "expected three numbers in [0, 1] (an albedo above 1 creates energy)";
    checked(d, ok, message).map(|v| Some(Vec3::from(v)))
}

fn flux<'de, D: Deserializer<'de>>(d: D) -> Result<Vec3, D::Error> {
    let ok = |v: &[f32; 3]| v.iter().all(|x| x.is_finite() && *x >= 0.0);
    checked(d, ok, "expected three finite numbers, none negative").map(Vec3::from)
}

fn radiance<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec3>, D::Error> {
    flux(d).map(Some)
}

fn scale<'de, D: Deserializer<'de>>(d: D) -> Result<Vec3, D::Error> {
    let ok = |v: &[f32; 3]| v.iter().all(|x| x.is_finite() && *x != 0.0);
    checked(d, ok, "expected three finite, non-zero numbers (zero flattens the object)").map(Vec3::from)
}

fn field_of_view<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    checked(d, |f: &f32| *f > 0.0 && *f < 180.0, "expected degrees between 0 and 180, exclusive").map(Some)
}

fn positive_finite<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    checked(d, |f: &f32| f.is_finite() && *f > 0.0, "expected a finite number above 0").map(Some)
}

fn resolution<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let message = format!("expected a whole number of pixels from 1 to {MAX_RESOLUTION}");
    let value = i64::deserialize(d)?;
    match u32::try_from(value) {
        Ok(v) if (1..=MAX_RESOLUTION).contains(&v) => Ok(v),
        _ => Err(D::Error::custom(message)),
    }
}

fn positive<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let value = i64::deserialize(d)?;
    match u32::try_from(value) {
        Ok(v) if v >= 1 => Ok(v),
        _ => Err(D::Error::custom("expected a whole number of at least 1")),
    }
}
