//! Photon-mapped images of thesis 000 chapter 5: photons traced with photon
//! differentials ([`super::photons`]), kernels built and gathered by VKDE
//! ([`super::vkde`]) or the kNN baseline ([`super::knn`]), estimated at the
//! primary and reflection hits of the camera rays (§5.2.3, L2468: "density
//! estimation at the primary and reflection ray hit points").
//!
//! The query points come from the native caster (chapter 4's tests show it
//! hits bit for bit as the emulated ray tracer does); the density estimates
//! come from the native reference or from the emulated kernels, which agree
//! bit for bit (`tests/vkde.rs`). The image is the indirect radiance estimate
//! (two-bounce indirect light: interactions 2 and 3, L2468), optionally added
//! to the ray tracer's direct light.

use super::knn::{self, KdMap, KnnError};
use super::photons::{self, Emission, Photon, PhotonError};
use super::vkde::{self, Constructed, Estimate, PhotonMap, Query, Settings, Shape};
use crate::host::camera::{Camera, Ray};
use crate::host::image::FrameBuffer;
use crate::host::kdtree::KdTree;
use crate::host::raycast::{Caster, TraceStats};
use crate::host::scene::{MaterialKind, Scene};
use crate::sim::{Device, LaunchStats};

/// The density estimator.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Estimator {
    /// VKDE with kernels from photon differentials.
    Vkde,
    /// The k nearest interactions (k).
    Knn(usize),
}

/// Everything a photon-mapped image needs besides the scene and camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Photons emitted.
    pub photons: usize,
    /// Spread factor s.
    pub spread: f32,
    /// h_max (the VKDE clamp and the kNN search radius).
    pub h_max: f32,
    /// The estimator.
    pub estimator: Estimator,
    /// The smoothing kernel.
    pub shape: Shape,
    /// Run the photon and estimation kernels on the emulator (else the native reference).
    pub emulated: bool,
}

/// The query point seen through pixel ray `ray`: the primary hit if diffuse,
/// else the hit of its mirror reflection if diffuse (weighted by the tint).
pub fn query(caster: &Caster, ray: &Ray, st: &mut TraceStats) -> Option<Query> {
    let eps = caster.eps();
    let h = caster.intersect(ray, eps, f32::INFINITY, false, st)?;
    let scene = caster.scene;
    let m = &scene.materials[scene.triangles[h.tri as usize].material as usize];
    let n = caster.normal(h.tri, ray.dir);
    let p = ray.origin + ray.dir * h.t;
    match m.kind {
        MaterialKind::Diffuse => Some(Query { x: p.to_array(), n: n.to_array(), weight: m.color }),
        MaterialKind::Mirror | MaterialKind::Glass { .. } => {
            let r = Ray { origin: p, dir: (ray.dir - 2.0 * ray.dir.dot(n) * n).normalize() };
            let h2 = caster.intersect(&r, eps, f32::INFINITY, false, st)?;
            let m2 = &scene.materials[scene.triangles[h2.tri as usize].material as usize];
            if m2.kind != MaterialKind::Diffuse {
                return None;
            }
            let n2 = caster.normal(h2.tri, r.dir);
            let p2 = r.origin + r.dir * h2.t;
            let w = std::array::from_fn(|c| m.color[c] * m2.color[c]);
            Some(Query { x: p2.to_array(), n: n2.to_array(), weight: w })
        }
        MaterialKind::Emitter => None,
    }
}

/// The query points of every pixel of `cam`, row by row from the top.
pub fn queries(caster: &Caster, cam: &Camera) -> Vec<Option<Query>> {
    use rayon::prelude::*;
    let [w, h] = cam.resolution;
    (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let mut st = TraceStats::default();
            (0..w).map(move |x| query(caster, &cam.ray(x, y), &mut st)).collect::<Vec<_>>()
        })
        .collect()
}

/// The photons, kernels and maps of one photon tracing pass.
#[derive(Debug, Clone)]
pub struct PhotonMaps {
    /// Stored interactions per photon.
    pub photons: Vec<[Option<Photon>; 2]>,
    /// Constructed kernels and counts.
    pub constructed: Constructed,
    /// The BVH over the kernels (VKDE).
    pub bvh: PhotonMap,
    /// The kd-tree over the interactions (kNN).
    pub kd: KdMap,
    /// The emulator's counters of the photon and construction kernels (emulated runs).
    pub launches: Vec<LaunchStats>,
}

/// Why an image could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PhotonImageError {
    /// Photon tracing or estimation failed.
    #[error(transparent)]
    Photon(#[from] PhotonError),
    /// The kNN estimate failed.
    #[error(transparent)]
    Knn(#[from] KnnError),
}

/// Traces `o.photons` photons from `scene`'s point light and builds both photon maps.
pub fn photon_maps(
    scene: &Scene,
    tree: &KdTree,
    o: &Options,
    dev: Option<&mut Device>,
) -> Result<PhotonMaps, PhotonError> {
    let e = Emission::of(scene, o.photons)?;
    let s = Settings { h_max: o.h_max, ..Settings::thesis(o.photons, o.spread) };
    let (photons, constructions, launches) = match dev {
        None => {
            let p = photons::reference(scene, tree, &e);
            let c = vkde::construct_all(&p, &s);
            (p, c, Vec::new())
        }
        Some(dev) => {
            let m = photons::load(dev)?;
            let k = photons::trace_kernel(dev, &m, scene, tree, &e)?;
            let vm = vkde::load(dev)?;
            let (c, l) = vkde::construct_kernel(dev, &vm, &k.photons, &s)?;
            (k.photons, c, vec![k.launch, l])
        }
    };
    let constructed = Constructed::collect(constructions.iter());
    let bvh = PhotonMap::build(&constructed.kernels);
    let kd = KdMap::build(&photons);
    Ok(PhotonMaps { photons, constructed, bvh, kd, launches })
}

/// The estimates at `queries` by `o`'s estimator, natively or on `dev`.
pub fn estimates(
    maps: &PhotonMaps,
    queries: &[Option<Query>],
    o: &Options,
    dev: Option<&mut Device>,
) -> Result<(Vec<Estimate>, Option<LaunchStats>), PhotonImageError> {
    use rayon::prelude::*;
    match (dev, o.estimator) {
        (None, Estimator::Vkde) => Ok((
            queries
                .par_iter()
                .map(|q| q.map_or_else(Estimate::default, |q| vkde::estimate(&maps.bvh, &q, o.shape)))
                .collect(),
            None,
        )),
        (None, Estimator::Knn(k)) => {
            if k == 0 || k > knn::K_MAX {
                return Err(KnnError::BadK(k).into());
            }
            Ok((
                queries
                    .par_iter()
                    .map(|q| q.map_or_else(Estimate::default, |q| knn::estimate(&maps.kd, &q, k, o.h_max, o.shape)))
                    .collect(),
                None,
            ))
        }
        (Some(dev), Estimator::Vkde) => {
            let m = vkde::load(dev).map_err(PhotonError::from)?;
            let (e, l) = vkde::estimate_kernel(dev, &m, &maps.bvh, queries, o.shape)?;
            Ok((e, Some(l)))
        }
        (Some(dev), Estimator::Knn(k)) => {
            let m = knn::load(dev).map_err(PhotonError::from)?;
            let (e, l) = knn::estimate_kernel(dev, &m, &maps.kd, queries, k, o.h_max, o.shape)?;
            Ok((e, Some(l)))
        }
    }
}

/// The estimates as an image of `cam`'s resolution (indirect radiance).
pub fn image(cam: &Camera, est: &[Estimate]) -> FrameBuffer {
    let [w, h] = cam.resolution;
    FrameBuffer { width: w, height: h, pixels: est.iter().map(|e| e.radiance).collect() }
}

/// A photon-mapped image with its statistics.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The indirect radiance estimate per pixel.
    pub indirect: FrameBuffer,
    /// The maps it was estimated from.
    pub maps: PhotonMaps,
    /// Query points (pixels seeing a diffuse surface directly or in a mirror).
    pub queries: usize,
    /// Contributions summed over the query points.
    pub contributions: u64,
    /// The estimation kernel's counters (emulated runs).
    pub launch: Option<LaunchStats>,
}

/// Renders the indirect light of `scene` seen by `cam` with options `o`
/// (an emulated run on a device of the default configuration).
pub fn render(scene: &Scene, tree: &KdTree, cam: &Camera, o: &Options) -> Result<Rendered, PhotonImageError> {
    render_on(scene, tree, cam, o, o.emulated.then(Device::new))
}

/// As [`render`], the kernels on `dev` when given (its profile, FMA
/// contraction and fidelity are the caller's), else natively; `o.emulated`
/// is not read.
pub fn render_on(
    scene: &Scene,
    tree: &KdTree,
    cam: &Camera,
    o: &Options,
    mut dev: Option<Device>,
) -> Result<Rendered, PhotonImageError> {
    let maps = photon_maps(scene, tree, o, dev.as_mut())?;
    let caster = Caster::new(scene, tree);
    let q = queries(&caster, cam);
    let (est, launch) = estimates(&maps, &q, o, dev.as_mut())?;
    let contributions = est.iter().map(|e| e.contributions as u64).sum();
    Ok(Rendered { indirect: image(cam, &est), maps, queries: q.iter().flatten().count(), contributions, launch })
}

/// The image `render --method photon-map` writes: the SIROH kd-tree over
/// `scene`, the native ray caster's direct light from the light moved by
/// `light_offset` plus the photon-mapped indirect light of photons emitted
/// from there, the kernels on `dev` when given.
pub fn render_scene(
    scene: &Scene,
    cam: &Camera,
    o: &Options,
    light_offset: glam::Vec3,
    dev: Option<Device>,
) -> Result<(FrameBuffer, Rendered), PhotonImageError> {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = crate::host::kdtree::build(
        &tris,
        crate::host::kdtree::BuildParams::thesis(crate::host::kdtree::Heuristic::Siroh),
    );
    let moved;
    let lit = if light_offset == glam::Vec3::ZERO {
        scene
    } else {
        let mut m = scene.clone();
        for l in &mut m.lights {
            if let crate::host::scene::Light::Point { position, .. } = l {
                *position = (glam::Vec3::from(*position) + light_offset).to_array();
            }
        }
        moved = m;
        &moved
    };
    let r = render_on(lit, &tree, cam, o, dev)?;
    let caster = Caster::new(scene, &tree);
    let (direct, _) = crate::host::raycast::render(&caster, cam, light_offset);
    Ok((add(&direct, &r.indirect), r))
}

/// Host bytes a photon-mapped render of `photons` photons and `pixels` pixels
/// holds at its peak, an upper bound: per photon its two stored interactions
/// and their kernels (twice over when emulated: the device's buffers and
/// their copies), the BVH and kd-tree over them (a node and an index a
/// kernel), and per pixel a query point, an estimate and the frame buffers.
pub fn host_bytes(photons: usize, pixels: u64, emulated: bool) -> u64 {
    use std::mem::size_of;
    let per_interaction = size_of::<Option<Photon>>() + size_of::<vkde::Kernel>() + 2 * 32 + 2 * 4;
    let per_photon = (2 * per_interaction) as u64 * if emulated { 2 } else { 1 };
    let per_pixel = (size_of::<Option<Query>>() + size_of::<Estimate>() + 3 * 12) as u64;
    (photons as u64).saturating_mul(per_photon).saturating_add(pixels.saturating_mul(per_pixel))
}

/// `a` + `b`, pixel by pixel (direct light plus the indirect estimate).
pub fn add(a: &FrameBuffer, b: &FrameBuffer) -> FrameBuffer {
    let pixels = a.pixels.iter().zip(&b.pixels).map(|(x, y)| std::array::from_fn(|c| x[c] + y[c])).collect();
    FrameBuffer { width: a.width, height: a.height, pixels }
}

/// Photons and spread of a `render --method photon-map` of `scene`: Table 5.1's
/// for its scenes, else [`DEFAULT_PHOTONS`] and [`DEFAULT_SPREAD`].
pub fn render_parameters(scene: &str) -> (usize, f32) {
    super::table_5_1::parameters(scene).unwrap_or((DEFAULT_PHOTONS, DEFAULT_SPREAD))
}

/// Photons of a render of a scene outside Table 5.1 (its "2^17 all others", L2466).
pub const DEFAULT_PHOTONS: usize = 1 << 17;
/// Spread s of a render of a scene outside Table 5.1 (the smallest the table uses, the Ring's).
pub const DEFAULT_SPREAD: f32 = 10.0;
/// k of the kNN estimator for a scene outside Table 5.1.
pub const DEFAULT_K: usize = 50;

/// The estimator and kernel named by `render --estimator`: `vkde`, `vkde-epanechnikov`,
/// `knn` (Table 5.1's k_kNN for its scenes, else [`DEFAULT_K`]) or `knn:K`.
pub fn parse_estimator(s: &str, scene: &str) -> Option<(Estimator, Shape)> {
    let table_k =
        || super::table_5_1::THESIS.row(scene).map_or(DEFAULT_K, |r| r.cells[6].value() as usize).min(knn::K_MAX);
    match s {
        "vkde" => Some((Estimator::Vkde, Shape::Uniform)),
        "vkde-epanechnikov" => Some((Estimator::Vkde, Shape::Epanechnikov)),
        "knn" => Some((Estimator::Knn(table_k()), Shape::Uniform)),
        _ => {
            let k: usize = s.strip_prefix("knn:")?.parse().ok()?;
            (1..=knn::K_MAX).contains(&k).then_some((Estimator::Knn(k), Shape::Uniform))
        }
    }
}
