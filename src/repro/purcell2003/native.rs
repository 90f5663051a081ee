//! A native mirror of the pipeline's per-pixel passes: the eye rays, the
//! shadow rays and the kNN-grid radiance estimate over either map, in Rust,
//! f32 operation for operation as `kernels/purcell2003/photons.cu` and
//! `knn.cu` compute them (no contraction, the same order of additions,
//! correctly rounded division and square root), so that the emulated images
//! and these are bit for bit alike. It starts from the photon maps' arrays
//! (built and tested on their own: `tests/purcell2003.rs`).

use super::geometry::{add, at, cross, dot, intersect, mul, normalize, specular, sub, tri_normal};
use super::grid::Grid;
use super::knn::{Params, State};
use super::photons::{Geometry, camera_array, rng_unit};
use crate::host::camera::Camera;

/// Per pixel query point, normal and albedo (as the kernel `eye_rays` writes them).
#[derive(Debug, Clone, PartialEq)]
pub struct QueryPoints {
    /// (x, y, z, 1), or w = 0 where there is none.
    pub query: Vec<[f32; 4]>,
    /// Normal facing the eye.
    pub normal: Vec<[f32; 4]>,
    /// Diffuse albedo.
    pub albedo: Vec<[f32; 4]>,
}

/// The kernel `eye_rays`, natively.
pub fn eye_rays(geo: &Geometry, camera: &Camera, depth: u32) -> QueryPoints {
    let cam = camera_array(camera);
    let [w, h] = camera.resolution;
    let eps = geo.eps();
    let n = (w * h) as usize;
    let mut out = QueryPoints { query: vec![[0.0; 4]; n], normal: vec![[0.0; 4]; n], albedo: vec![[0.0; 4]; n] };
    for i in 0..n {
        let (px, py) = ((i as u32 % w) as f32, (i as u32 / w) as f32);
        let sx = (2.0 * (px + 0.5) / w as f32 - 1.0) * cam[12] * cam[13];
        let sy = (1.0 - 2.0 * (py + 0.5) / h as f32) * cam[12];
        let mut o = at(&cam, 0);
        let mut d = normalize(add(at(&cam, 3), add(mul(at(&cam, 6), sx), mul(at(&cam, 9), sy))));
        for _ in 0..=depth {
            let Some((t, tri)) = intersect(&geo.tris, o, d, eps) else { break };
            let x = add(o, mul(d, t));
            let m = geo.tris[12 * tri + 9].to_bits() as usize;
            let c = &geo.mats[8 * m..8 * m + 4];
            let kind = c[3] as i32;
            if kind == 0 {
                let mut nrm = tri_normal(&geo.tris, tri);
                if dot(nrm, d) > 0.0 {
                    nrm = mul(nrm, -1.0);
                }
                out.query[i] = [x[0], x[1], x[2], 1.0];
                out.normal[i] = [nrm[0], nrm[1], nrm[2], 0.0];
                out.albedo[i] = [c[0], c[1], c[2], 0.0];
                break;
            }
            if kind == 3 {
                break;
            }
            d = specular(d, tri_normal(&geo.tris, tri), kind, geo.mats[8 * m + 4], 1.0);
            o = x;
        }
    }
    out
}

/// The kernel `shadow_rays`, natively: direct light per pixel (r, g, b, 0).
pub fn shadow_rays(geo: &Geometry, q: &QueryPoints, samples: u32, seed: u32) -> Vec<[f32; 4]> {
    let eps = geo.eps();
    let nl_count = geo.lights.len() as i32;
    (0..q.query.len())
        .map(|i| {
            let q4 = q.query[i];
            if q4[3] == 0.0 {
                return [0.0; 4];
            }
            let (x, n) = ([q4[0], q4[1], q4[2]], [q.normal[i][0], q.normal[i][1], q.normal[i][2]]);
            let mut acc = [0.0, 0.0, 0.0];
            for s in 0..samples {
                let pass = 16 + s;
                let mut l = geo.point.to_array();
                let mut weight = 1.0f32;
                let mut nl = [0.0, 0.0, 0.0];
                if nl_count > 0 {
                    let k = ((rng_unit(seed, i as u32, pass, 0) * nl_count as f32) as i32).min(nl_count - 1);
                    let t = &geo.tris[12 * geo.lights[k as usize] as usize..];
                    let (mut a, mut bb) = (rng_unit(seed, i as u32, pass, 1), rng_unit(seed, i as u32, pass, 2));
                    if a + bb > 1.0 {
                        a = 1.0 - a;
                        bb = 1.0 - bb;
                    }
                    let (e1, e2) = (at(t, 3), at(t, 6));
                    l = add(at(t, 0), add(mul(e1, a), mul(e2, bb)));
                    let c = cross(e1, e2);
                    let len = dot(c, c).sqrt();
                    nl = mul(c, 1.0 / len);
                    weight = 0.5 * len * nl_count as f32;
                }
                let to = sub(l, x);
                let d2 = dot(to, to);
                let dist = d2.sqrt();
                let wi = mul(to, 1.0 / dist);
                let cx = dot(n, wi);
                if cx <= 0.0 {
                    continue;
                }
                let cl = if nl_count > 0 { dot(nl, wi).abs() } else { 1.0 };
                if intersect(&geo.tris, x, wi, eps).is_some_and(|(t, _)| t < dist - eps) {
                    continue;
                }
                let g = cx * cl * weight / d2;
                let r = geo.radiance;
                acc = [acc[0] + r[0] * g, acc[1] + r[1] * g, acc[2] + r[2] * g];
            }
            let a4 = q.albedo[i];
            let f = 1.0 / (std::f32::consts::PI * samples as f32);
            [acc[0] * a4[0] * f, acc[1] * a4[1] * f, acc[2] * a4[2] * f, 0.0]
        })
        .collect()
}

/// A photon map's arrays as the estimate reads them (read back from the device).
#[derive(Debug, Clone)]
pub enum MapData {
    /// Map A: per cell its first element (and one past the last), the sorted
    /// (cell, photon slot) elements, the photon arrays (position, power, direction).
    Bitonic {
        /// First element per cell.
        first: Vec<u32>,
        /// Sorted elements.
        sorted: Vec<[u32; 2]>,
        /// Photon positions.
        pos: Vec<[f32; 4]>,
        /// Photon powers.
        pow: Vec<[f32; 4]>,
        /// Photon incoming directions.
        dir: Vec<[f32; 4]>,
    },
    /// Map B: photons stored per cell, redistribution factors, the cells' blocks.
    Stencil {
        /// Slots per cell.
        slots: usize,
        /// Photons stored per cell.
        stored: Vec<u32>,
        /// Power redistribution factor per cell.
        scale: Vec<f32>,
        /// Positions per cell slot.
        pos: Vec<[f32; 4]>,
        /// Powers per cell slot.
        pow: Vec<[f32; 4]>,
        /// Directions per cell slot.
        dir: Vec<[f32; 4]>,
    },
}

struct Range {
    lo: i32,
    hi: i32,
}

fn clip(base: i32, n: i32, ring: i32) -> Range {
    Range { lo: (-ring).max(-base), hi: ring.min(n - 1 - base) }
}

fn first_x(x: &Range, dy: i32, dz: i32, r: i32) -> i32 {
    if dy.abs() == r || dz.abs() == r {
        return x.lo;
    }
    if x.lo == -r {
        return -r;
    }
    if x.hi == r {
        return r;
    }
    r + 1
}

fn next_x(x: &Range, dx: i32, dy: i32, dz: i32, r: i32) -> i32 {
    if dy.abs() == r || dz.abs() == r {
        return if dx < x.hi { dx + 1 } else { r + 1 };
    }
    if dx == -r && x.hi == r && r > 0 {
        return r;
    }
    r + 1
}

/// The search's grid as the kernels' `Search` holds it.
struct G {
    lo: [f32; 3],
    inv: [f32; 3],
    size: [f32; 3],
    dims: [i32; 3],
}

fn covers(g: &G, q: &[f32; 3], b: &[i32; 3], r: i32, rad: f32) -> bool {
    for a in 0..3 {
        if b[a] - r > 0 {
            let face = g.lo[a] + (b[a] - r) as f32 * g.size[a];
            if q[a] - face < rad {
                return false;
            }
        }
        if b[a] + r < g.dims[a] - 1 {
            let face = g.lo[a] + (b[a] + r + 1) as f32 * g.size[a];
            if face - q[a] < rad {
                return false;
            }
        }
    }
    true
}

fn advance(g: &G, p: &Params, q: &[f32; 3], b: &[i32; 3], st: &mut State) {
    st.local = 0;
    let mut r = st.ring;
    let (mut x, mut y, mut z) = (clip(b[0], g.dims[0], r), clip(b[1], g.dims[1], r), clip(b[2], g.dims[2], r));
    let (mut dx, mut dy, mut dz) = (next_x(&x, st.cell[0], st.cell[1], st.cell[2], r), st.cell[1], st.cell[2]);
    while dx > r {
        if dy < y.hi {
            dy += 1;
        } else if dz < z.hi {
            dy = y.lo;
            dz += 1;
        } else {
            let rad = if st.n >= p.k as i32 { st.r } else { p.r_max };
            let whole = x.lo == -b[0]
                && x.hi == g.dims[0] - 1 - b[0]
                && y.lo == -b[1]
                && y.hi == g.dims[1] - 1 - b[1]
                && z.lo == -b[2]
                && z.hi == g.dims[2] - 1 - b[2];
            if whole || covers(g, q, b, r, rad) {
                st.done = true;
                return;
            }
            r += 1;
            st.ring = r;
            x = clip(b[0], g.dims[0], r);
            y = clip(b[1], g.dims[1], r);
            z = clip(b[2], g.dims[2], r);
            dy = y.lo;
            dz = z.lo;
        }
        dx = first_x(&x, dy, dz, r);
    }
    st.cell = [dx, dy, dz];
}

fn consider(p: &Params, st: &mut State, d: f32, w: [f32; 4], scale: f32) {
    if d > p.r_max {
        return;
    }
    if st.n < p.k as i32 {
        st.r = st.r.max(d);
    } else if d > st.r {
        return;
    }
    st.n += 1;
    for (s, w) in st.sum.iter_mut().zip(w) {
        *s += w * scale;
    }
}

/// The kernels `knn_bitonic` / `knn_stencil` run to completion at every
/// query point of `q` (the final state does not depend on how the lookups
/// are split into passes: the state carries everything).
pub fn estimate(grid: &Grid, map: &MapData, q: &QueryPoints, p: &Params) -> Vec<State> {
    let size = grid.size();
    let inv = grid.inv();
    let g = G { lo: grid.lo.to_array(), inv: inv.to_array(), size: size.to_array(), dims: grid.dims.map(|d| d as i32) };
    q.query
        .iter()
        .zip(&q.normal)
        .map(|(q4, nrm)| {
            let mut st = State { done: q4[3] == 0.0, ..State::default() };
            let qp = [q4[0], q4[1], q4[2]];
            let b: [i32; 3] =
                std::array::from_fn(|a| (((qp[a] - g.lo[a]) * g.inv[a]).floor() as i32).max(0).min(g.dims[a] - 1));
            while !st.done {
                let cx = (b[0] + st.cell[0]).max(0).min(g.dims[0] - 1);
                let cy = (b[1] + st.cell[1]).max(0).min(g.dims[1] - 1);
                let cz = (b[2] + st.cell[2]).max(0).min(g.dims[2] - 1);
                let c = ((cz * g.dims[1] + cy) * g.dims[0] + cx) as usize;
                let (valid, pp, w, d, sc) = match map {
                    MapData::Bitonic { first, sorted, pos, pow, dir } => {
                        let (start, end) = (first[c], first[c + 1]);
                        let j = start.wrapping_add(st.local as u32);
                        let e = sorted[(j as i32).min(sorted.len() as i32 - 1) as usize];
                        let ph = if e[1] == u32::MAX { 0 } else { e[1] as usize };
                        (j < end, pos[ph], pow[ph], dir[ph], 1.0f32)
                    }
                    MapData::Stencil { slots, stored, scale, pos, pow, dir } => {
                        let slot = c * slots + (st.local as usize).min(slots - 1);
                        ((st.local as u32) < stored[c], pos[slot], pow[slot], dir[slot], scale[c])
                    }
                };
                st.used += 1;
                if valid {
                    let (ex, ey, ez) = (pp[0] - qp[0], pp[1] - qp[1], pp[2] - qp[2]);
                    let front = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2] < 0.0;
                    if front {
                        consider(p, &mut st, (ex * ex + ey * ey + ez * ez).sqrt(), w, sc);
                    }
                    st.local += 1;
                } else {
                    advance(&g, p, &qp, &b, &mut st);
                }
            }
            st
        })
        .collect()
}
