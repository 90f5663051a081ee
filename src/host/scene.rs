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

/// A texture map: 8-bit RGB texels packed `r | g << 8 | b << 16 | 255 << 24`,
/// row by row from the top of the image (texture coordinate v = 1) down.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// The file it was read from, relative to the scene file.
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The texels, `width * height` of them.
    pub texels: Vec<u32>,
}

impl Texture {
    /// The texel index of (`u`, `v`) and the texel itself, packed as [`Texture::texels`].
    pub fn texel(&self, u: f32, v: f32) -> u32 {
        self.texels[Texture::index(self.width, self.height, u, v)]
    }

    /// The texel that texture coordinates (`u`, `v`) fall in: nearest texel,
    /// repeated outside [0, 1), v = 0 the bottom row. The ray-tracing kernel
    /// (`direct` in `kernels/fabianowski2011/raytrace.cu`) computes the same
    /// float and integer operations.
    pub fn index(width: u32, height: u32, u: f32, v: f32) -> usize {
        let x = (u * width as f32).floor() as i32;
        let y = ((1.0 - v) * height as f32).floor() as i32;
        (y.rem_euclid(height as i32) as u32 * width + x.rem_euclid(width as i32) as u32) as usize
    }

    /// The colour of the texel at (`u`, `v`) ([`Texture::index`]), each channel in [0, 1].
    pub fn sample(&self, u: f32, v: f32) -> [f32; 3] {
        let t = self.texel(u, v);
        [(t & 255) as f32 / 255.0, ((t >> 8) & 255) as f32 / 255.0, ((t >> 16) & 255) as f32 / 255.0]
    }
}

/// What thesis 000's ray tracer reads of a material beside its [`MaterialKind`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Surface {
    /// The diffuse texture map (index into [`Scene::textures`]); the diffuse
    /// colour is the material's colour times the texel's.
    pub texture: Option<u32>,
    /// A diffuse material's specular part: the weight per channel of a mirror
    /// reflection added to its diffuse shading (an MTL `Ks` beside a non-zero
    /// `Kd` where `illum` is 3 to 7, the models that trace reflections, or a
    /// scene file's `[[reflect]]`).
    pub reflect: [f32; 3],
    /// Thesis 003's roughness map (index into [`Scene::textures`]; a scene
    /// file's `roughness_map`): per texel the Beckmann α of the metal lobe,
    /// texel / 255 of its first channel. Only thesis 003's path tracer reads it.
    pub roughness_map: Option<u32>,
    /// Thesis 003's metalness map (a scene file's `metalness_map`): per texel
    /// the metalness m = texel / 255 of its first channel, the probability of
    /// the metal lobe. Only thesis 003's path tracer reads it.
    pub metalness_map: Option<u32>,
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
    /// Texture maps.
    pub textures: Vec<Texture>,
    /// Per material, its texture and specular part (a material past the end has neither).
    pub surfaces: Vec<Surface>,
    /// Per triangle, the texture coordinates of its three vertices (empty: none).
    pub uvs: Vec<[[f32; 2]; 3]>,
    /// Per triangle, the normals of its three vertices as the OBJ gives them
    /// (`vn`, not normalised; empty: the scene has none; all zero: this
    /// triangle has none). Only thesis 000's photon tracer reads them
    /// (`repro::fabianowski2011::photons`, eqs. 5.12–5.21); every other
    /// renderer shades with the geometric normal.
    pub normals: Vec<[[f32; 3]; 3]>,
    /// Per material, the Beckmann roughness α of a mirror or glass (a scene
    /// file's `roughness`; a material past the end, or 0, is smooth). Thesis
    /// 003's path tracer makes a rough mirror a Cook-Torrance conductor and a
    /// rough glass a Walter dielectric; the other renderers treat them as smooth.
    pub roughness: Vec<f32>,
    /// Per material, an anisotropic mirror's or rough glass's second Beckmann α, along the
    /// tangent frame's second axis (a scene file's `roughness = [ax, ay]`;
    /// `roughness` then holds α_x; 0, or a material past the end: isotropic).
    /// Only thesis 003's path tracer reads it.
    pub roughness_y: Vec<f32>,
    /// An equirectangular environment map (a scene file's `environment`, an
    /// OpenEXR file): radiance from every direction no triangle covers. Only
    /// thesis 003's path tracer reads it.
    pub environment: Option<PathBuf>,
    /// Per material, whether a glass takes the exact dielectric Fresnel
    /// equations (a scene file's `fresnel = "exact"`) rather than Schlick's
    /// approximation (a material past the end: Schlick's). Only thesis 003's
    /// path tracer reads it.
    pub exact_fresnel: Vec<bool>,
    /// A participating medium (a scene file's `[medium]`; §5.2 of thesis
    /// 003). Only thesis 003's path tracer reads it.
    pub medium: Option<Medium>,
    /// Per material, the subsurface scattering of a translucent material (a
    /// scene file's `kind = "translucent"`, §5.3 of thesis 003; its kind is
    /// glass of the same IOR, which the other renderers see; a material past
    /// the end: none). Only thesis 003's path tracer reads it.
    pub translucent: Vec<Option<Translucent>>,
    /// Per material, the coat's index of refraction of a coated material (a
    /// scene file's `kind = "coated"`, §4.5 of thesis 003: a smooth
    /// dielectric coat, Schlick's Fresnel switch, over Ashikhmin and
    /// Shirley's coupled diffuse; its kind is diffuse, which the other
    /// renderers see; a material past the end: none). Only thesis 003's path
    /// tracer reads it.
    pub coat: Vec<Option<f32>>,
}

/// A translucent material's interior and switch (thesis 003 §5.3, 003:L396;
/// `docs/reproduction-lin2017.md`): a smooth dielectric boundary around a
/// homogeneous medium, scattered at most once per stay.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Translucent {
    /// Scattering coefficient σ_s (grey, per unit length); the free path is
    /// drawn with the reduced σ_s' = (1 − g) σ_s.
    pub sigma_s: f32,
    /// Absorption coefficient σ_a per channel (per unit length).
    pub sigma_a: [f32; 3],
    /// Henyey-Greenstein asymmetry, in (−1, 1).
    pub g: f32,
    /// The Fresnel switch's second threshold (003:L265): the probability that
    /// light not reflected specularly enters the medium (else it is reflected
    /// diffusely with the colour), in [0, 1].
    pub translucency: f32,
}

/// How the march places its samples in the steps of a ray (thesis 003, 003:L367).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Jitter {
    /// Pauly's stratified pattern: one random offset for every step of a ray.
    Stratified,
    /// A random point in each step ("normal Monte Carlo sampling").
    PerStep,
}

/// A participating medium (thesis 003 §5.2): grey absorption and scattering
/// coefficients at unit density, the Henyey-Greenstein asymmetry `g`, RGB
/// emission per unit length at unit density, an optional exponential height
/// falloff, the region it fills and the march's step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    /// Absorption coefficient σ_a (per unit length).
    pub sigma_a: f32,
    /// Scattering coefficient σ_s.
    pub sigma_s: f32,
    /// Henyey-Greenstein asymmetry, in (−1, 1).
    pub g: f32,
    /// Emission L_ve per unit length (RGB).
    pub emission: [f32; 3],
    /// Scale height H of the density e^(−(y − lo.y)/H); `None`: uniform density.
    pub height_scale: Option<f32>,
    /// The box it fills (lo, hi); `None`: the scene's bounds.
    pub region: Option<([f32; 3], [f32; 3])>,
    /// The march's step Δt.
    pub step: f32,
    /// Where the samples sit in each step.
    pub jitter: Jitter,
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
        Scene::assemble_with_uvs(name, source, tris, Vec::new(), materials)
    }

    /// [`Scene::assemble`] with the texture coordinates of each triangle's
    /// vertices (`uvs`: none, or one entry per triangle of `tris`): a dropped
    /// zero-area triangle drops its coordinates with it, so that
    /// [`Scene::uv`] stays indexed like [`Scene::triangles`].
    pub fn assemble_with_uvs(
        name: &str,
        source: &Path,
        tris: Vec<Triangle>,
        uvs: Vec<[[f32; 2]; 3]>,
        materials: Vec<Material>,
    ) -> Scene {
        Scene::assemble_with_vertices(name, source, tris, uvs, Vec::new(), materials)
    }

    /// [`Scene::assemble_with_uvs`] with the vertex normals of each triangle
    /// as well (`normals`: none, or one entry per triangle of `tris`), dropped
    /// with their zero-area triangles like the texture coordinates.
    pub fn assemble_with_vertices(
        name: &str,
        source: &Path,
        tris: Vec<Triangle>,
        uvs: Vec<[[f32; 2]; 3]>,
        normals: Vec<[[f32; 3]; 3]>,
        materials: Vec<Material>,
    ) -> Scene {
        let n = tris.len();
        let mut triangles = Vec::with_capacity(n);
        let mut kept_uvs = Vec::with_capacity(uvs.len());
        let mut kept_normals = Vec::with_capacity(normals.len());
        for (i, t) in tris.into_iter().enumerate() {
            if t.double_area() > 0.0 {
                triangles.push(t);
                kept_uvs.extend(uvs.get(i).copied());
                kept_normals.extend(normals.get(i).copied());
            }
        }
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
            textures: Vec::new(),
            surfaces: Vec::new(),
            uvs: kept_uvs,
            normals: kept_normals,
            roughness: Vec::new(),
            roughness_y: Vec::new(),
            environment: None,
            exact_fresnel: Vec::new(),
            medium: None,
            translucent: Vec::new(),
            coat: Vec::new(),
        }
    }

    /// Material `m`'s coat IOR, if it is coated.
    pub fn coat(&self, m: u32) -> Option<f32> {
        self.coat.get(m as usize).copied().flatten()
    }

    /// Material `m`'s subsurface scattering, if it is translucent.
    pub fn translucent(&self, m: u32) -> Option<Translucent> {
        self.translucent.get(m as usize).copied().flatten()
    }

    /// Material `m`'s Beckmann roughness α (0: smooth).
    pub fn roughness(&self, m: u32) -> f32 {
        self.roughness.get(m as usize).copied().unwrap_or(0.0)
    }

    /// Material `m`'s second Beckmann α, along the tangent frame's second
    /// axis (0: isotropic, α_x = α_y = [`Scene::roughness`]).
    pub fn roughness_y(&self, m: u32) -> f32 {
        self.roughness_y.get(m as usize).copied().unwrap_or(0.0)
    }

    /// Material `m`'s texture and specular part.
    pub fn surface(&self, m: u32) -> Surface {
        self.surfaces.get(m as usize).copied().unwrap_or_default()
    }

    /// The weight per channel of the mirror reflection a surface of material
    /// `m` adds: a mirror's (or glass') colour, a diffuse material's specular
    /// part, zero for emitters. A hit reflects when any channel is positive.
    pub fn reflectance(&self, m: u32) -> [f32; 3] {
        let mat = &self.materials[m as usize];
        match mat.kind {
            MaterialKind::Mirror | MaterialKind::Glass { .. } => mat.color,
            MaterialKind::Diffuse => self.surface(m).reflect,
            MaterialKind::Emitter => [0.0; 3],
        }
    }

    /// Whether material `m` has a texture map (albedo, roughness or
    /// metalness): thesis 003's path tracer shades it by the metalness
    /// workflow (`kernels/lin2017/path.cu`, `texture_hit`).
    pub fn textured(&self, m: u32) -> bool {
        let s = self.surface(m);
        s.texture.is_some() || s.roughness_map.is_some() || s.metalness_map.is_some()
    }

    /// Texture coordinates of triangle `t`'s vertices (zero when the scene has none).
    pub fn uv(&self, t: u32) -> [[f32; 2]; 3] {
        self.uvs.get(t as usize).copied().unwrap_or_default()
    }

    /// The vertex normals of triangle `t` (all zero when it has none).
    pub fn vertex_normals(&self, t: u32) -> [[f32; 3]; 3] {
        self.normals.get(t as usize).copied().unwrap_or_default()
    }

    /// The diffuse colour of material `m` at barycentric weights (`u`, `v`)
    /// of vertices 1 and 2 of triangle `t`: the material's colour, times its
    /// texture's texel where it has one. The ray-tracing kernel computes the
    /// same operations in the same order.
    pub fn diffuse_color(&self, m: u32, t: u32, u: f32, v: f32) -> [f32; 3] {
        let col = self.materials[m as usize].color;
        let Some(tex) = self.surface(m).texture.and_then(|i| self.textures.get(i as usize)) else { return col };
        let uv = self.uv(t);
        let w = 1.0 - u - v;
        let tu = w * uv[0][0] + u * uv[1][0] + v * uv[2][0];
        let tv = w * uv[0][1] + u * uv[1][1] + v * uv[2][1];
        let s = tex.sample(tu, tv);
        [col[0] * s[0], col[1] * s[1], col[2] * s[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A zero-area triangle between two textured ones takes its texture
    /// coordinates with it: the kept triangles keep their own.
    #[test]
    fn a_dropped_triangle_drops_its_texture_coordinates() {
        let tri = |x: f32| Triangle { v: [Vec3::ZERO, Vec3::new(x, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)], material: 0 };
        let uv = |k: f32| [[k, 0.0], [k, 1.0], [k, 2.0]];
        let s = Scene::assemble_with_uvs(
            "t",
            Path::new("t"),
            vec![tri(1.0), tri(0.0), tri(2.0)],
            vec![uv(0.0), uv(1.0), uv(2.0)],
            Vec::new(),
        );
        assert_eq!((s.triangles.len(), s.dropped_degenerate), (2, 1));
        assert_eq!((s.uv(0), s.uv(1)), (uv(0.0), uv(2.0)));
        let plain = Scene::assemble("t", Path::new("t"), vec![tri(1.0), tri(0.0)], Vec::new());
        assert!(plain.uvs.is_empty() && plain.triangles.len() == 1);
    }
}
