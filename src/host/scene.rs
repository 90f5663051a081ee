//! Scenes: triangles with materials, lights, a camera and a camera flight,
//! described by `scenes/*.toml` (format in `docs/scenes.md`).

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::camera::{Camera, Flight};

/// What a surface does to light.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum MaterialKind {
    /// Lambertian.
    Diffuse,
    /// A perfect mirror.
    Mirror,
    /// Dielectric with an index of refraction.
    Glass {
        /// Index of refraction.
        ior: f32,
    },
    /// An emitter (its triangles form an area light).
    Emitter,
}

/// A material.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Material {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: MaterialKind,
    /// Diffuse colour (or mirror/glass tint).
    pub color: [f32; 3],
    /// Emitted radiance (emitters).
    pub emission: [f32; 3],
}

impl Material {
    /// A diffuse material.
    pub fn diffuse(name: &str, color: [f32; 3]) -> Self {
        Material { name: name.into(), kind: MaterialKind::Diffuse, color, emission: [0.0; 3] }
    }
}

/// A light source.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Light {
    /// An isotropic point light.
    Point {
        /// Position.
        position: [f32; 3],
        /// Radiant intensity per channel.
        intensity: [f32; 3],
    },
    /// A directional light.
    Directional {
        /// Direction the light travels.
        direction: [f32; 3],
        /// Irradiance per channel.
        radiance: [f32; 3],
    },
    /// The emissive triangles of the scene.
    Area {
        /// Triangle indices.
        triangles: Vec<u32>,
    },
}

/// A triangle and its material index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    /// Vertices.
    pub v: [Vec3; 3],
    /// Index into [`Scene::materials`].
    pub material: u32,
}

impl Triangle {
    /// Twice the area.
    pub fn double_area(&self) -> f32 {
        (self.v[1] - self.v[0]).cross(self.v[2] - self.v[0]).length()
    }
}

/// What thesis 000 Table A.1 says of a scene.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ThesisScene {
    /// Triangle count in the thesis.
    pub triangles: u64,
    /// Extent L × W × H in metres.
    pub extent: [f32; 3],
}

/// A loaded scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Its name.
    pub name: String,
    /// The description it came from.
    pub source: PathBuf,
    /// Triangles (zero-area ones dropped).
    pub triangles: Vec<Triangle>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Lights.
    pub lights: Vec<Light>,
    /// The camera at the first frame.
    pub camera: Camera,
    /// The flight.
    pub flight: Flight,
    /// Zero-area triangles dropped at load.
    pub dropped_degenerate: usize,
    /// The thesis' numbers for this scene.
    pub thesis: Option<ThesisScene>,
    /// How this variant differs from the thesis'.
    pub variant: String,
}

impl Scene {
    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for t in &self.triangles {
            for v in t.v {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo, hi)
    }

    /// Extent sorted as the thesis reports it (x, z, y: length, width, height with y up).
    pub fn extent(&self) -> [f32; 3] {
        let (lo, hi) = self.bounds();
        let e = hi - lo;
        [e.x, e.z, e.y]
    }

    /// Builds a scene from parts, dropping zero-area triangles.
    pub fn assemble(name: &str, source: &Path, tris: Vec<Triangle>, materials: Vec<Material>) -> Scene {
        let n = tris.len();
        let triangles: Vec<Triangle> = tris.into_iter().filter(|t| t.double_area() > 0.0).collect();
        let dropped = n - triangles.len();
        Scene {
            name: name.to_string(),
            source: source.to_path_buf(),
            triangles,
            materials,
            lights: Vec::new(),
            camera: Camera::default(),
            flight: Flight::default(),
            dropped_degenerate: dropped,
            thesis: None,
            variant: String::new(),
        }
    }
}
