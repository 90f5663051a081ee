//! The path tracer's device layout (thesis 003 §6.1, §6.4): the project's
//! CPU-built kd-tree flattened into 16-byte nodes, the concatenated leaf
//! triangle lists, affine triangles, per-triangle normals and materials, and
//! the emitting triangles for light sampling. The native path tracer reads
//! the same arrays, so both see the same floats.
//!
//! Node, 4 words: 0 = `axis << 30 | count << 24 | left` (axis 3 = leaf, count
//! the leaf's triangles, 6 bits; left the left child, 24 bits); 1 = split
//! position (f32 bits); 2 = right child; 3 = offset of the leaf's triangles
//! in the reference array. The bit order is warplight's (the thesis states
//! the 2|6|24 partition, not the order). Nodes are in depth-first order, the
//! left child right after its parent ("serial-recursive construction",
//! 003:L434).

use glam::{DVec3, Vec3};

use super::environment::Environment;
use crate::host::kdtree::{Aabb, KdTree, Node};
use crate::host::scene::{MaterialKind, Scene};

/// The leaf's axis value.
pub const LEAF_AXIS: u32 = 3;
/// The largest leaf (6-bit count).
pub const MAX_LEAF: usize = 63;
/// The most nodes a 24-bit left index reaches.
pub const MAX_NODES: usize = 1 << 24;

/// Why a scene cannot be laid out for the path tracer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LayoutError {
    /// A leaf holds more triangles than the node's 6-bit count field.
    #[error("a kd-tree leaf holds {0} triangles; the thesis' node stores at most {MAX_LEAF} (6 bits)")]
    LeafTooLarge(usize),
    /// More nodes than a 24-bit index reaches.
    #[error("the kd-tree has {0} nodes; the thesis' node indexes at most {MAX_NODES} (24 bits)")]
    TooManyNodes(usize),
    /// No triangle emits and there is no environment: the path tracer needs a light.
    #[error(
        "scene `{0}` has no emitting triangle and no environment: the path tracer needs an area light (an emitter material) or an `environment` map"
    )]
    NoLight(String),
    /// The medium's march needs more steps a ray than the kernel takes.
    #[error(
        "the medium's step {step} needs {steps:.0} steps across the scene's box; at most {} (raise `medium.step`)",
        crate::host::scene_file::MAX_MEDIUM_STEPS
    )]
    MediumSteps {
        /// The step.
        step: f32,
        /// The box's diagonal over the step.
        steps: f32,
    },
    /// An integrator that does not march the medium.
    #[error(
        "scene `{0}` has a participating medium, which only pt, nee, mis and mis-power march (volume_frame); not {1}"
    )]
    MediumIntegrator(String, &'static str),
    /// An integrator that does not run translucent materials.
    #[error(
        "scene `{0}` has a translucent material (subsurface scattering), which only pt, nee, mis and mis-power trace (sss_frame); not {1}"
    )]
    SssIntegrator(String, &'static str),
    /// Translucent materials and a participating medium in one scene.
    #[error(
        "scene `{0}` has both a translucent material and a participating medium; the path tracer takes one or the other (sss_frame or volume_frame)"
    )]
    SssMedium(String),
    /// Texture maps and a participating medium in one scene (`texture_frame` marches none).
    #[error("scene `{0}` has texture maps and a participating medium: the path tracer renders either, not both")]
    TexturedMedium(String),
    /// An integrator that does not read texture maps.
    #[error("scene `{0}` has texture maps, which only pt, nee, mis and mis-power read (texture_frame); not {1}")]
    TexturedIntegrator(String, &'static str),
    /// Texture maps and translucent materials in one scene.
    #[error(
        "scene `{0}` has texture maps and a translucent material: the path tracer renders either (texture_frame or sss_frame), not both"
    )]
    TexturedTranslucent(String),
    /// The environment map could not be read or is not one.
    #[error("environment map {path}: {msg}")]
    Environment {
        /// The map's file.
        path: String,
        /// What is wrong with it.
        msg: String,
    },
}

/// The kernel's material kind: Lambertian diffuse.
pub const KIND_DIFFUSE: u32 = 0;
/// A perfect (smooth) mirror.
pub const KIND_MIRROR: u32 = 1;
/// Smooth glass (Schlick's Fresnel switch between reflection and refraction;
/// per material the exact Fresnel equations instead).
pub const KIND_GLASS: u32 = 2;
/// An emitter.
pub const KIND_EMITTER: u32 = 3;
/// A rough mirror: Cook-Torrance with Beckmann's D, the Smith G of Walter
/// et al.'s approximation, Schlick's F with R0 the colour (§5.1, §4.5).
pub const KIND_CONDUCTOR: u32 = 4;
/// Rough glass: Walter et al. 2007's microfacet refraction, Beckmann's D,
/// Schlick's F as the Fresnel switch (§5.1, 003:L357).
pub const KIND_ROUGH_GLASS: u32 = 5;

/// A translucent material (§5.3): a smooth dielectric boundary around a
/// homogeneous medium scattered once (`sss_frame`); its three float4 are
/// `[colour, kind] [σ_a rgb, IOR] [σ_s, exact Fresnel, g, translucency]`.
pub const KIND_TRANSLUCENT: u32 = 6;
/// A diffuse material with texture maps (§5.4): `texture_frame` alone
/// shades it, as the lobe its metalness picks at each hit (`texture_hit`).
pub const KIND_TEXTURED: u32 = 7;
/// The thesis' coated diffuse (§4.5, 003:L255-263): Schlick's Fresnel term at
/// the viewer's cosine (R0 from the coat's IOR, `mats[7]`) switches between
/// a smooth coat's mirror reflection and Ashikhmin and Shirley's coupled
/// diffuse lobe with the colour (`path.cu`'s `scatter`).
pub const KIND_COATED: u32 = 8;
/// The roughness levels of an 8-bit roughness map: one conductor row of
/// [`PathScene::mats`] each.
pub const ROUGHNESS_LEVELS: usize = 256;

/// A textured scene's maps as `texture_frame` reads them.
#[derive(Debug, Clone, PartialEq)]
pub struct PathTextures {
    /// Per material: albedo, roughness and metalness map (-1: none), the
    /// first conductor row in [`PathScene::mats`] (-1: no metal lobe).
    pub mats: Vec<[i32; 4]>,
    /// Per triangle, its vertices' texture coordinates (u0, v0, u1, v1, u2, v2).
    pub uvs: Vec<[f32; 6]>,
    /// Per map: first texel, width, height, 0 (thesis 000's texture table).
    pub info: Vec<u32>,
    /// Every map's texels (`host::scene::Texture::texels`), one after the other.
    pub texels: Vec<u32>,
}

impl PathTextures {
    /// The scene's maps, or `None` when no material has one. Appends to
    /// `mats` the conductor rows of each textured material's metal lobe: one
    /// per roughness level (α = level / 255, at least
    /// [`crate::host::scene_file::MIN_ROUGHNESS`]) with a roughness map, else
    /// one with the material's `roughness`.
    fn new(scene: &Scene, mats: &mut Vec<[f32; 12]>) -> Option<PathTextures> {
        if !(0..scene.materials.len() as u32).any(|m| scene.textured(m)) {
            return None;
        }
        let id = |t: Option<u32>| t.map_or(-1, |t| t as i32);
        let conductor =
            |alpha: f32| [1.0, 1.0, 1.0, f32::from_bits(KIND_CONDUCTOR), 0.0, 0.0, 0.0, 1.0, alpha, 0.0, 0.0, 0.0];
        let mut tmats = Vec::with_capacity(scene.materials.len());
        for m in 0..scene.materials.len() as u32 {
            let s = scene.surface(m);
            let mut rows = -1;
            if scene.textured(m) && s.metalness_map.is_some() {
                rows = mats.len() as i32;
                match s.roughness_map {
                    Some(_) => mats.extend(
                        (0..ROUGHNESS_LEVELS)
                            .map(|l| conductor((l as f32 / 255.0).max(crate::host::scene_file::MIN_ROUGHNESS))),
                    ),
                    None => mats.push(conductor(scene.roughness(m))),
                }
            }
            tmats.push([id(s.texture), id(s.roughness_map), id(s.metalness_map), rows]);
        }
        let uvs = scene.uvs.iter().map(|t| [t[0][0], t[0][1], t[1][0], t[1][1], t[2][0], t[2][1]]).collect();
        let (info, texels) = crate::host::rt_kernels::texture_tables(scene);
        Some(PathTextures { mats: tmats, uvs, info, texels })
    }
}

/// Material kinds as the kernel numbers them; a mirror or glass with a
/// positive Beckmann `roughness` is rough.
pub fn kind_code(k: MaterialKind, roughness: f32) -> u32 {
    match k {
        MaterialKind::Diffuse => KIND_DIFFUSE,
        MaterialKind::Mirror if roughness > 0.0 => KIND_CONDUCTOR,
        MaterialKind::Mirror => KIND_MIRROR,
        MaterialKind::Glass { .. } if roughness > 0.0 => KIND_ROUGH_GLASS,
        MaterialKind::Glass { .. } => KIND_GLASS,
        MaterialKind::Emitter => KIND_EMITTER,
    }
}

/// The scene as the path tracer reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct PathScene {
    /// 16-byte nodes.
    pub nodes: Vec<[u32; 4]>,
    /// Per node, for kd-backtrack (Foley and Sugerman 2005): its box and its
    /// parent, `[lo.x, lo.y, lo.z, parent (u32 bits), hi.x, hi.y, hi.z, 0]`
    /// (the root is its own parent).
    pub up: Vec<[f32; 8]>,
    /// Leaf triangle lists, concatenated.
    pub refs: Vec<u32>,
    /// Per triangle, three rows (x, y, z, w) of the affine transform into unit-triangle space.
    pub tris: Vec<[f32; 12]>,
    /// Per triangle: unit geometric normal, material index (u32 bits).
    pub tri_data: Vec<[f32; 4]>,
    /// Per material: colour, kind (u32 bits); emission, index of refraction
    /// (a glass's, or a coated material's coat's);
    /// Beckmann α (0 for smooth kinds), 1 for a glass with the exact Fresnel
    /// equations (0: Schlick's), 0, 0. A translucent material
    /// ([`KIND_TRANSLUCENT`]): colour, kind; σ_a rgb, IOR; σ_s, exact Fresnel, g,
    /// translucency.
    pub mats: Vec<[f32; 12]>,
    /// Per emitting triangle: v0, cumulative area fraction; e1, triangle (u32 bits); e2, 0.
    pub lights: Vec<[f32; 12]>,
    /// Total emitting area (0 when no triangle emits).
    pub light_area: f32,
    /// The environment map seen by rays that miss every triangle (§5.4), if any.
    pub env: Option<Environment>,
    /// The texture maps (§5.4), when a material has one (`texture_frame`).
    pub textures: Option<PathTextures>,
    /// The participating medium (§5.2), as `volume_frame` reads it: [lo, Δt],
    /// [hi, g], [σ_a, σ_s, 1/H (0: uniform density), 1 for an offset per
    /// step (0: one a ray)], [L_ve, 0]; `None`: no medium (`path_frame`).
    pub medium: Option<[f32; 16]>,
    /// Scene bounds (the root's box).
    pub lo: [f32; 3],
    /// Scene bounds.
    pub hi: [f32; 3],
}

/// The affine rows of triangle (a, b, c): the inverse of [a − c, b − c, n]
/// with n = (a − c) × (b − c), and the translation −M⁻¹c in w (in f64, rounded once).
pub fn affine_rows(t: &[Vec3; 3]) -> [f32; 12] {
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    let (e0, e1) = (a - c, b - c);
    let n = e0.cross(e1);
    let m = glam::DMat3::from_cols(e0, e1, n);
    let inv = m.inverse();
    let mut out = [0.0f32; 12];
    for r in 0..3 {
        let row = inv.row(r);
        let w = -row.dot(c);
        out[4 * r..4 * r + 4].copy_from_slice(&[row.x as f32, row.y as f32, row.z as f32, w as f32]);
    }
    out
}

fn unit_normal(t: &[Vec3; 3]) -> [f32; 3] {
    let n: DVec3 = (t[1].as_dvec3() - t[0].as_dvec3()).cross(t[2].as_dvec3() - t[0].as_dvec3()).normalize();
    [n.x as f32, n.y as f32, n.z as f32]
}

impl PathScene {
    /// Lays out `scene` with `tree` (built over the scene's triangles in order).
    pub fn new(scene: &Scene, tree: &KdTree) -> Result<PathScene, LayoutError> {
        if tree.nodes.len() > MAX_NODES {
            return Err(LayoutError::TooManyNodes(tree.nodes.len()));
        }
        let mut nodes = Vec::with_capacity(tree.nodes.len());
        let mut up = Vec::with_capacity(tree.nodes.len());
        let mut refs = Vec::with_capacity(tree.tri_refs.len());
        // depth first, left child first: (tree node, its parent's slot, whether
        // it is the right child (the parent's right field to patch), its box)
        let mut todo: Vec<(u32, usize, bool, Aabb)> = vec![(0, 0, false, tree.bounds)];
        while let Some((ti, parent, is_right, b)) = todo.pop() {
            let at = nodes.len();
            if is_right {
                let p: &mut [u32; 4] = &mut nodes[parent];
                p[2] = at as u32;
            }
            up.push([b.lo.x, b.lo.y, b.lo.z, f32::from_bits(parent as u32), b.hi.x, b.hi.y, b.hi.z, 0.0]);
            match tree.nodes[ti as usize] {
                Node::Inner { axis, split, left, right } => {
                    // the left child is the next node
                    nodes.push([(axis as u32) << 30 | (at as u32 + 1), split.to_bits(), 0, 0]);
                    let (mut bl, mut br) = (b, b);
                    bl.hi[axis as usize] = split;
                    br.lo[axis as usize] = split;
                    todo.push((right, at, true, br));
                    todo.push((left, at, false, bl));
                }
                Node::Leaf { first, count } => {
                    if count as usize > MAX_LEAF {
                        return Err(LayoutError::LeafTooLarge(count as usize));
                    }
                    let off = refs.len() as u32;
                    refs.extend_from_slice(&tree.tri_refs[first as usize..(first + count) as usize]);
                    nodes.push([LEAF_AXIS << 30 | count << 24, 0, 0, off]);
                }
            }
        }
        let tris = scene.triangles.iter().map(|t| affine_rows(&t.v)).collect();
        let tri_data = scene
            .triangles
            .iter()
            .map(|t| {
                let n = unit_normal(&t.v);
                [n[0], n[1], n[2], f32::from_bits(t.material)]
            })
            .collect();
        let mut mats: Vec<[f32; 12]> = scene
            .materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let coat = scene.coat(i as u32).filter(|_| m.kind == MaterialKind::Diffuse);
                let ior = if let MaterialKind::Glass { ior } = m.kind { ior } else { coat.unwrap_or(1.0) };
                let [r, g, b] = m.color;
                let [er, eg, eb] = m.emission;
                let alpha = scene.roughness(i as u32);
                let kind = if scene.textured(i as u32) {
                    KIND_TEXTURED
                } else if coat.is_some() {
                    KIND_COATED
                } else {
                    kind_code(m.kind, alpha)
                };
                let alpha = if matches!(kind, KIND_CONDUCTOR | KIND_ROUGH_GLASS) { alpha } else { 0.0 };
                let glass = matches!(kind, KIND_GLASS | KIND_ROUGH_GLASS);
                let exact = glass && scene.exact_fresnel.get(i).copied().unwrap_or(false);
                let exact = if exact { 1.0 } else { 0.0 };
                if let Some(t) = scene.translucent(i as u32).filter(|_| kind == KIND_GLASS) {
                    let [ar, ag, ab] = t.sigma_a;
                    #[rustfmt::skip]
                    let v = [
                        r, g, b, f32::from_bits(KIND_TRANSLUCENT),
                        ar, ag, ab, ior,
                        t.sigma_s, exact, t.g, t.translucency,
                    ];
                    return v;
                }
                // an anisotropic mirror's or rough glass's alpha_y (0: isotropic), path.cu's Aniso
                let alpha_y =
                    if matches!(kind, KIND_CONDUCTOR | KIND_ROUGH_GLASS) { scene.roughness_y(i as u32) } else { 0.0 };
                [r, g, b, f32::from_bits(kind), er, eg, eb, ior, alpha, exact, alpha_y, 0.0]
            })
            .collect();
        let textures = PathTextures::new(scene, &mut mats);
        if textures.is_some() && scene.medium.is_some() {
            return Err(LayoutError::TexturedMedium(scene.name.clone()));
        }
        let emitting: Vec<(usize, f64)> = scene
            .triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| scene.materials[t.material as usize].kind == MaterialKind::Emitter)
            .map(|(i, t)| (i, 0.5 * (t.v[1] - t.v[0]).as_dvec3().cross((t.v[2] - t.v[0]).as_dvec3()).length()))
            .collect();
        let total: f64 = emitting.iter().map(|e| e.1).sum();
        let env = scene.environment.as_deref().map(Environment::load).transpose()?;
        if env.is_none() && (emitting.is_empty() || total <= 0.0) {
            return Err(LayoutError::NoLight(scene.name.clone()));
        }
        let mut acc = 0.0f64;
        let n_lights = emitting.len();
        let lights = emitting
            .iter()
            .enumerate()
            .map(|(k, &(i, area))| {
                acc += area;
                let cdf = if k + 1 == n_lights { 1.0 } else { (acc / total) as f32 };
                let v = scene.triangles[i].v;
                let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
                [v[0].x, v[0].y, v[0].z, cdf, e1.x, e1.y, e1.z, f32::from_bits(i as u32), e2.x, e2.y, e2.z, 0.0]
            })
            .collect();
        let translucent = scene.translucent.iter().any(Option::is_some);
        if translucent && scene.medium.is_some() {
            return Err(LayoutError::SssMedium(scene.name.clone()));
        }
        if translucent && textures.is_some() {
            return Err(LayoutError::TexturedTranslucent(scene.name.clone()));
        }
        let medium = match scene.medium {
            None => None,
            Some(m) => {
                let (lo, hi) = m.region.unwrap_or((tree.bounds.lo.into(), tree.bounds.hi.into()));
                let diag = (0..3).map(|k| (hi[k] - lo[k]).max(0.0).powi(2)).sum::<f32>().sqrt();
                if diag / m.step > crate::host::scene_file::MAX_MEDIUM_STEPS {
                    return Err(LayoutError::MediumSteps { step: m.step, steps: diag / m.step });
                }
                let per_step = if m.jitter == crate::host::scene::Jitter::PerStep { 1.0 } else { 0.0 };
                let [er, eg, eb] = m.emission;
                #[rustfmt::skip]
                let v = [
                    lo[0], lo[1], lo[2], m.step,
                    hi[0], hi[1], hi[2], m.g,
                    m.sigma_a, m.sigma_s, m.height_scale.map_or(0.0, |h| 1.0 / h), per_step,
                    er, eg, eb, 0.0,
                ];
                Some(v)
            }
        };
        Ok(PathScene {
            textures,
            medium,
            nodes,
            up,
            refs,
            tris,
            tri_data,
            mats,
            lights,
            light_area: total as f32,
            env,
            lo: tree.bounds.lo.into(),
            hi: tree.bounds.hi.into(),
        })
    }
}

impl PathScene {
    /// Whether `integrator` ignores the scene's medium, the medium inside
    /// its translucent materials or its texture maps: bdpt and mlt, which
    /// read none of them (`volume_frame`, `sss_frame` and `texture_frame` are
    /// the path tracer's). The renderers refuse them on such a scene; the
    /// rule is [`PathScene::check_integrator`]'s.
    pub fn ignores_medium(&self, integrator: super::Integrator) -> bool {
        self.check_integrator("", integrator).is_err()
    }

    /// Refuses an integrator that ignores the scene's medium, its
    /// translucent materials or its texture maps (bdpt, mlt), naming scene
    /// `name` and what it has.
    pub fn check_integrator(&self, name: &str, integrator: super::Integrator) -> Result<(), LayoutError> {
        if !matches!(integrator, super::Integrator::Bdpt | super::Integrator::Mlt) {
            return Ok(());
        }
        let (name, i) = (name.to_string(), integrator.name());
        if self.medium.is_some() {
            Err(LayoutError::MediumIntegrator(name, i))
        } else if self.has_translucent() {
            Err(LayoutError::SssIntegrator(name, i))
        } else if self.textures.is_some() {
            Err(LayoutError::TexturedIntegrator(name, i))
        } else {
            Ok(())
        }
    }

    /// Whether a material is translucent (the renderer then launches `sss_frame`).
    pub fn has_translucent(&self) -> bool {
        self.mats.iter().any(|m| m[3].to_bits() == KIND_TRANSLUCENT)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn affine_rows_map_the_vertices_to_the_unit_triangle() {
        let t = [Vec3::new(1.0, 0.0, 2.0), Vec3::new(0.0, 3.0, 1.0), Vec3::new(-1.0, 0.5, 0.0)];
        let r = affine_rows(&t);
        let apply = |p: Vec3| -> [f32; 3] {
            let f = |k: usize| r[4 * k] * p.x + r[4 * k + 1] * p.y + r[4 * k + 2] * p.z + r[4 * k + 3];
            [f(0), f(1), f(2)]
        };
        for (p, want) in [(t[0], [1.0, 0.0, 0.0]), (t[1], [0.0, 1.0, 0.0]), (t[2], [0.0, 0.0, 0.0])] {
            let got = apply(p);
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 1e-5, "{p:?}: {got:?}");
            }
        }
    }
}
