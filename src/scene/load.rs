//! Loading a scene: parse the TOML, check what spans several values, load and place the meshes.
//!
//! Loading never builds the BVH: that is [`super::World::new`]'s job, so a scene can be loaded
//! and checked (checkpoint 1) before the BVH exists (checkpoint 4).

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use super::desc::{
    CameraDesc, MaterialDesc, MaterialKind, ObjectDesc, SceneDesc, ShapeKind, MAX_SUBDIVISIONS,
};
use super::error::{DisplayPath, SceneError, SourceMap};
use super::{RenderSettings, Scene};
use crate::camera::{Camera, Projection};
use crate::geometry::{transform_matrix, Aabb, TriangleMesh};
use crate::light::{AreaLight, PointLight};
use crate::material::Material;
use crate::math::Vec3;

/// Icosphere subdivisions when a sphere gives none: 1280 triangles, smooth at 512 px.
const DEFAULT_SUBDIVISIONS: u32 = 3;

impl Scene {
    /// Loads the scene file at `path`; mesh files are found relative to it.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| SceneError::Read { path: DisplayPath(path.to_path_buf()), source })?;
        Self::from_toml(&text, path)
    }

    /// Loads a scene from its text; `path` names it in errors and anchors relative mesh paths.
    pub fn from_toml(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let map = SourceMap { path, text };
        let desc: SceneDesc = toml::from_str(text).map_err(|e| map.error(e.span(), e.message()))?;

        let camera = camera(&desc.camera, &map)?;

        let names: BTreeMap<&str, u32> =
            desc.materials.keys().enumerate().map(|(i, k)| (k.as_str(), i as u32)).collect();
        let materials =
            desc.materials.iter().map(|(name, m)| material(name, m, &map)).collect::<Result<_, _>>()?;
        let lights = desc.lights.iter().map(|l| PointLight { position: l.position, flux: l.flux }).collect();

        let mut scene = Scene {
            camera,
            settings: RenderSettings {
                integrator: desc.integrator.kind,
                spp: desc.integrator.spp,
                max_depth: desc.integrator.max_depth,
                seed: desc.integrator.seed,
            },
            triangles: Vec::new(),
            triangle_materials: Vec::new(),
            triangle_objects: Vec::new(),
            materials,
            lights,
            area_lights: Vec::new(),
            object_emission: Vec::new(),
            object_boxes: Vec::new(),
            light_powers: Vec::new(),
        };
        for (index, object) in desc.objects.iter().enumerate() {
            let material = *names.get(object.material.get_ref().as_str()).ok_or_else(|| {
                let known: Vec<&str> = names.keys().copied().collect();
                let message = format!(
                    "no material named {:?} (known: {})",
                    object.material.get_ref(),
                    known.join(", ")
                );
                map.error(Some(object.material.span()), message)
            })?;
            scene.add_object(index as u32, object, material, &map)?;
        }
        scene.update_light_powers();
        Ok(scene)
    }

    /// Places the object `index` of the scene file, of material `material`: its triangles, its
    /// bounding box, its emission (an area light if not zero).
    fn add_object(
        &mut self,
        index: u32,
        object: &ObjectDesc,
        material: u32,
        map: &SourceMap,
    ) -> Result<(), SceneError> {
        let mesh = object_mesh(object, map)?;
        let m = transform_matrix(object.translate, object.rotate, object.scale);
        let placed = mesh.transformed(&m);
        let first = self.triangles.len();
        self.triangles.extend(placed.triangles());
        self.triangle_materials.resize(self.triangles.len(), material);
        self.triangle_objects.resize(self.triangles.len(), index);
        let emission = object.emission.unwrap_or(Vec3::ZERO);
        self.object_emission.push(emission);
        let corners = self.triangles[first..].iter().flat_map(|t| [t.p0, t.p1, t.p2]);
        self.object_boxes.push(corners.fold(Aabb::EMPTY, Aabb::grow));
        if emission != Vec3::ZERO {
            let triangles = self.triangles[first..].to_vec();
            self.area_lights.push(AreaLight::new(index, triangles, emission));
        }
        Ok(())
    }
}

/// The camera the `[camera]` table describes: a view direction that is not zero nor parallel to
/// `up`, and one projection.
fn camera(c: &CameraDesc, map: &SourceMap) -> Result<Camera, SceneError> {
    let view = c.look_at - c.position;
    if view.length() < 1e-6 * (1.0 + c.position.abs().max_element()) {
        return Err(map.error(map.key_span("camera", "look_at"), "must differ from the camera position"));
    }
    if view.normalize().cross(c.up).length() < 1e-3 * c.up.length() {
        return Err(
            map.error(map.key_span("camera", "up"), "must not be parallel to the view direction (or zero)")
        );
    }
    let projection = match (c.fov, c.orthographic_height) {
        (Some(fov_degrees), None) => Projection::Pinhole { fov_degrees },
        (None, Some(height)) => Projection::Orthographic { height },
        (Some(_), Some(_)) => {
            let span = map.key_span("camera", "orthographic_height");
            return Err(map.error(span, "a camera has a fov (pinhole) or an orthographic_height, not both"));
        }
        (None, None) => {
            let message = "needs fov = DEGREES (a pinhole camera) or orthographic_height = UNITS";
            return Err(map.error(map.header_span("camera"), message));
        }
    };
    Ok(Camera::with_projection(c.position, c.look_at, c.up, projection, c.width, c.height))
}

/// The material a `[materials.NAME]` table describes, with the fields its kind needs.
fn material(name: &str, desc: &MaterialDesc, map: &SourceMap) -> Result<Material, SceneError> {
    let table = format!("materials.{name}");
    let unexpected = |key: &str| {
        map.error(
            map.key_span(&table, key),
            format!("a {} material has no {key}", desc.kind.get_ref().name()),
        )
    };
    let missing = |key: &str| map.error(Some(desc.kind.span()), format!("this material needs {key} = ..."));
    match desc.kind.get_ref() {
        MaterialKind::Diffuse if desc.ior.is_some() => Err(unexpected("ior")),
        MaterialKind::Diffuse => {
            Ok(Material::Diffuse { albedo: desc.albedo.ok_or_else(|| missing("albedo"))? })
        }
        MaterialKind::Glass if desc.albedo.is_some() => Err(unexpected("albedo")),
        MaterialKind::Glass => {
            Ok(Material::PerfectRefraction { ior: desc.ior.ok_or_else(|| missing("ior"))? })
        }
    }
}

/// The object's mesh in its own space, with the shape's own fields checked.
fn object_mesh(object: &ObjectDesc, map: &SourceMap) -> Result<TriangleMesh, SceneError> {
    let shape = *object.shape.get_ref();
    if let (Some(s), false) = (&object.subdivisions, shape == ShapeKind::Sphere) {
        return Err(map.error(Some(s.span()), "only a sphere has subdivisions"));
    }
    if let (Some(f), false) = (&object.file, shape == ShapeKind::Obj) {
        return Err(map.error(Some(f.span()), "only shape = \"obj\" reads a file"));
    }
    Ok(match shape {
        ShapeKind::Quad => TriangleMesh::quad(),
        ShapeKind::Box => TriangleMesh::cuboid(),
        ShapeKind::Sphere => {
            let subdivisions = object.subdivisions.as_ref().map_or(DEFAULT_SUBDIVISIONS, |s| *s.get_ref());
            if subdivisions > MAX_SUBDIVISIONS {
                let span = object.subdivisions.as_ref().map(|s| s.span());
                return Err(map.error(span, format!("at most {MAX_SUBDIVISIONS}")));
            }
            TriangleMesh::icosphere(subdivisions)
        }
        ShapeKind::Obj => {
            let file = object.file.as_ref().ok_or_else(|| {
                map.error(Some(object.shape.span()), "shape = \"obj\" needs file = \"...\"")
            })?;
            load_obj_relative(file.get_ref(), file.span(), map)?
        }
    })
}

/// Loads an OBJ file named relative to the scene file, and checks it has finite triangles.
fn load_obj_relative(name: &str, span: Range<usize>, map: &SourceMap) -> Result<TriangleMesh, SceneError> {
    let path = map.path.parent().unwrap_or(Path::new("")).join(name);
    let mesh = TriangleMesh::load_obj(&path)
        .map_err(|e| map.error(Some(span.clone()), format!("cannot load mesh {}: {e}", path.display())))?;
    if mesh.indices.is_empty() {
        return Err(map.error(Some(span), format!("mesh {} has no triangles", path.display())));
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(map.error(Some(span), format!("mesh {}: vertex {} is not finite", path.display(), i + 1)));
    }
    Ok(mesh)
}
