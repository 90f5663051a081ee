//! A converged reference for the error charts ([`super::error`]), computed
//! natively: the photons traced in Rust as the kernels `emit` and `bounce`
//! trace them (`kernels/purcell2003/photons.cu`: the same emission, Russian
//! roulette, cosine-weighted bounce, Schlick glass, storage rule and random
//! numbers; `__cosf`/`__sinf` as the emulator computes them, so the photons
//! are the kernels' bit for bit: [`super::geometry::cos_approx`]), sorted
//! into map A's arrays by a host sort (the cell ranges the bitonic sort and
//! the binary search give), and estimated by the native kNN-grid
//! ([`super::native::estimate`]) at the pixels' query points. The emulator
//! runs none of it, so the reference can have many times the stated photons
//! on a small shared machine.
//!
//! The kNN estimate with a fixed k keeps a relative noise of about 1 / √k
//! per pixel whatever the photon count, so a reference with more photons at
//! the same k is no more converged than the render; the reference raises k
//! with the photons (k · `k_factor`, the radius holding k photons shrinking
//! as √(k_factor / photon factor) on a surface).

use rayon::prelude::*;

use super::geometry::{
    V3, add, at, cos_approx, cosine_dir, cross, dot, intersect, mul, normalize, sin_approx, specular, sub, tri_normal,
};
use super::grid::Grid;
use super::image;
use super::knn::{Params, State};
use super::native::{self, MapData, QueryPoints};
use super::photons::{Geometry, rng_unit};
use super::pipeline;
use super::scenes::{EYE_DEPTH, Fixture, ITERS_PER_PASS, PILOT_SEED, SEED, emitted_for};
use crate::host::image::FrameBuffer;
use crate::host::scene::Scene;

/// Seed of the reference's photons (other photons than the renders', which use [`SEED`]).
pub const REFERENCE_SEED: u32 = 7001;
/// Seed of a second, independent reference: the two references' difference
/// measures the reference's own noise.
pub const SECOND_SEED: u32 = 7002;

/// One stored photon: position, power, incoming direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Photon {
    /// Where it landed.
    pub pos: V3,
    /// Its power (rgb).
    pub power: V3,
    /// Its direction of travel when it landed.
    pub dir: V3,
    /// Its slot in the kernels' photon arrays: bounce frame × emitted + photon.
    pub slot: usize,
}

/// The kernel `emit` for photon `i` of `n`: origin and direction.
fn emit(geo: &Geometry, i: u32, seed: u32) -> (V3, V3) {
    let u: [f32; 5] = std::array::from_fn(|d| rng_unit(seed, i, 0, d as u32));
    if geo.lights.is_empty() {
        let p = geo.point.to_array();
        let cone = geo.cone;
        let z = 1.0 - u[0] * (1.0 - cone[3]);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u[1];
        let a = [cone[0], cone[1], cone[2]];
        let (mut t, mut b) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        if a[2] < 0.999_999 {
            t = normalize(cross([0.0, 0.0, 1.0], a));
            b = cross(a, t);
        }
        return (p, add(add(mul(t, r * cos_approx(phi)), mul(b, r * sin_approx(phi))), mul(a, z)));
    }
    let nl = geo.lights.len();
    let l = ((u[0] * nl as f32) as usize).min(nl - 1);
    let ti = geo.lights[l] as usize;
    let t = &geo.tris[12 * ti..];
    let (mut a, mut b) = (u[1], u[2]);
    if a + b > 1.0 {
        a = 1.0 - a;
        b = 1.0 - b;
    }
    let p = add(at(t, 0), add(mul(at(t, 3), a), mul(at(t, 6), b)));
    let mut nrm = tri_normal(&geo.tris, ti);
    let toward = ((geo.lo + geo.hi) * 0.5).to_array();
    if dot(nrm, sub(toward, p)) < 0.0 {
        nrm = mul(nrm, -1.0);
    }
    (p, cosine_dir(nrm, u[3], u[4]))
}

/// Photon `i`'s path through `bounces` bounces, as `emit` and `bounce`
/// trace it (photons straight from the light are not stored); `power`: its
/// emitted power; pushes its stored photons onto `out`.
fn trace_one(geo: &Geometry, i: u32, n: usize, bounces: usize, seed: u32, power: V3, out: &mut Vec<Photon>) {
    let eps = geo.eps();
    let (mut o, mut d) = emit(geo, i, seed);
    let mut w = power;
    for b in 1..=bounces as u32 {
        let Some((t, tri)) = intersect(&geo.tris, o, d, eps) else { return };
        let x = add(o, mul(d, t));
        let m = geo.tris[12 * tri + 9].to_bits() as usize;
        let c = &geo.mats[8 * m..8 * m + 8];
        let kind = c[3] as i32;
        let mut nrm = tri_normal(&geo.tris, tri);
        match kind {
            0 => {
                if b > 1 {
                    out.push(Photon { pos: x, power: w, dir: d, slot: b as usize * n + i as usize });
                }
                let q = c[0].max(c[1].max(c[2]));
                if rng_unit(seed, i, b, 0) >= q {
                    return;
                }
                if dot(nrm, d) > 0.0 {
                    nrm = mul(nrm, -1.0);
                }
                let nd = cosine_dir(nrm, rng_unit(seed, i, b, 1), rng_unit(seed, i, b, 2));
                w = [w[0] * c[0] / q, w[1] * c[1] / q, w[2] * c[2] / q];
                d = nd;
            }
            1 | 2 => {
                d = specular(d, nrm, kind, c[4], rng_unit(seed, i, b, 3));
                w = [w[0] * c[0], w[1] * c[1], w[2] * c[2]];
            }
            _ => return,
        }
        o = x;
    }
}

/// Traces `n` emitted photons through `bounces` bounces natively with
/// `seed`; the stored photons in slot order.
pub fn trace(geo: &Geometry, n: usize, bounces: usize, seed: u32) -> Vec<Photon> {
    let power = geo.power_per_photon(n);
    let chunks: Vec<Vec<Photon>> = (0..n as u32)
        .collect::<Vec<u32>>()
        .par_chunks(4096)
        .map(|ids| {
            let mut out = Vec::new();
            for &i in ids {
                trace_one(geo, i, n, bounces, seed, power, &mut out);
            }
            out
        })
        .collect();
    let mut all: Vec<Photon> = chunks.into_iter().flatten().collect();
    all.sort_by_key(|p| p.slot);
    all
}

/// Map A's arrays over `photons` (compacted: slot j is the j-th photon):
/// per cell its first element and one past the last, the (cell, photon)
/// elements sorted by cell.
pub fn bitonic_map(grid: &Grid, photons: &[Photon]) -> MapData {
    let mut sorted: Vec<[u32; 2]> =
        photons.iter().enumerate().map(|(j, p)| [grid.cell_of(glam::Vec3::from(p.pos)), j as u32]).collect();
    sorted.sort_unstable();
    let cells = grid.cells();
    let mut first = vec![0u32; cells + 1];
    let mut e = 0usize;
    for (c, f) in first.iter_mut().enumerate() {
        while e < sorted.len() && (sorted[e][0] as usize) < c {
            e += 1;
        }
        *f = e as u32;
    }
    if sorted.is_empty() {
        // the estimate reads one element even in an empty map
        sorted.push([cells as u32, u32::MAX]);
    }
    let four = |v: V3| [v[0], v[1], v[2], 1.0];
    MapData::Bitonic {
        first,
        sorted,
        pos: photons.iter().map(|p| four(p.pos)).collect(),
        pow: photons.iter().map(|p| four(p.power)).collect(),
        dir: photons.iter().map(|p| [p.dir[0], p.dir[1], p.dir[2], 0.0]).collect(),
    }
}

/// The emitted count for `stated` stored photons, calibrated as the pipeline
/// does (a pilot of `f.pilot` photons with [`PILOT_SEED`]), natively.
pub fn emitted(geo: &Geometry, f: &Fixture, stated: u32) -> usize {
    let pilot = trace(geo, f.pilot, f.bounces, PILOT_SEED);
    emitted_for(stated, f.pilot, pilot.len())
}

/// A reference render.
#[derive(Debug, Clone)]
pub struct Reference {
    /// Direct light (the renders' shadow rays) plus the map's estimate.
    pub image: FrameBuffer,
    /// Photons emitted.
    pub emitted: usize,
    /// Photons stored.
    pub stored: usize,
    /// Photons sought.
    pub k: u32,
}

/// The native estimate over `map` at every query point of `q`, in parallel rows.
fn estimate(grid: &Grid, map: &MapData, q: &QueryPoints, p: &Params) -> Vec<State> {
    let chunk = 256;
    let parts: Vec<Vec<State>> = (0..q.query.len().div_ceil(chunk))
        .into_par_iter()
        .map(|c| {
            let r = c * chunk..((c + 1) * chunk).min(q.query.len());
            let part = QueryPoints {
                query: q.query[r.clone()].to_vec(),
                normal: q.normal[r.clone()].to_vec(),
                albedo: q.albedo[r].to_vec(),
            };
            native::estimate(grid, map, &part, p)
        })
        .collect();
    parts.into_iter().flatten().collect()
}

/// Renders `scene` `width` pixels wide natively with `emitted` photons
/// traced with `seed` and `k` photons sought (the fixture's r_max): direct
/// light from the fixture's shadow rays (seed [`SEED`], the renders' own, so
/// the direct light is the renders' bit for bit) plus map A's estimate.
pub fn render(scene: &Scene, f: &Fixture, width: u32, emitted: usize, k: u32, seed: u32) -> Reference {
    let geo = Geometry::of(scene);
    let photons = trace(&geo, emitted, f.bounces, seed);
    let camera = pipeline::camera(scene, f, width);
    let q = native::eye_rays(&geo, &camera, EYE_DEPTH);
    let direct = native::shadow_rays(&geo, &q, f.shadow_samples, SEED);
    let grid = Grid::new(geo.lo, geo.hi, f.grid);
    let map = bitonic_map(&grid, &photons);
    let params = Params { k, r_max: f.r_max, iters: ITERS_PER_PASS, tiled: true };
    let states = estimate(&grid, &map, &q, &params);
    let [w, h] = camera.resolution;
    Reference { image: image::image(w, h, &direct, &q.albedo, &states, &params), emitted, stored: photons.len(), k }
}
