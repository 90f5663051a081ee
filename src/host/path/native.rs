//! The native path tracer: `kernels/lin2017/path.cu` in Rust, operation for
//! operation (same traversal, same affine test, same random dimensions, no
//! fused multiply-adds), so that a frame traced here equals the emulated
//! kernel's frame bit for bit. It is the oracle for the kernel and the
//! native speed baseline.

// `!(a < b)` is the kernel's comparison, NaN included: kept as written
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use rayon::prelude::*;

use super::counts::Counts;
use super::layout::{
    KIND_COATED, KIND_CONDUCTOR, KIND_DIFFUSE, KIND_EMITTER, KIND_GLASS, KIND_ROUGH_GLASS, KIND_TEXTURED,
    KIND_TRANSLUCENT, LEAF_AXIS, PathScene,
};
use super::rng::{Sample, azimuth, path_key};
use super::{FrameParams, Integrator, PixelSampling, Termination, Traversal};

/// Random dimensions of the camera ray.
pub const DIMS_CAMERA: u32 = 2;
/// Random dimensions per bounce.
pub const DIMS_PER_BOUNCE: u32 = 8;
const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
/// bdpt: the most light-subpath vertices (the kernel's `LIGHT_VERTICES`).
pub const LIGHT_VERTICES: usize = 16;
/// bdpt: the first random dimension of the light subpath (5 at y0, then 8 per bounce).
pub const DIMS_LIGHT: u32 = 0x10000;

/// A vertex of bdpt's light subpath (the kernel's `LightVertex`).
struct LightVertex {
    /// Position.
    p: V3,
    /// Normal on the side the light came from (y0: the light's front).
    n: V3,
    /// Throughput arriving at the vertex (y0: Le times the lights' area).
    alpha: V3,
    /// Lambertian albedo (y0: unused).
    color: V3,
}
/// Stack entries of the traversal (the builder's depth limit).
pub const STACK_ENTRIES: usize = 32;

#[derive(Clone, Copy, Debug, PartialEq)]
struct V3 {
    x: f32,
    y: f32,
    z: f32,
}

fn v3(x: f32, y: f32, z: f32) -> V3 {
    V3 { x, y, z }
}

impl V3 {
    fn comp(self, k: u32) -> f32 {
        if k == 0 {
            self.x
        } else if k == 1 {
            self.y
        } else {
            self.z
        }
    }
    fn dot(self, b: V3) -> f32 {
        self.x * b.x + self.y * b.y + self.z * b.z
    }
    fn add(self, b: V3) -> V3 {
        v3(self.x + b.x, self.y + b.y, self.z + b.z)
    }
    fn sub(self, b: V3) -> V3 {
        v3(self.x - b.x, self.y - b.y, self.z - b.z)
    }
    fn mul(self, b: V3) -> V3 {
        v3(self.x * b.x, self.y * b.y, self.z * b.z)
    }
    fn scale(self, s: f32) -> V3 {
        v3(self.x * s, self.y * s, self.z * s)
    }
    fn normalize(self) -> V3 {
        let inv = 1.0 / (self.x * self.x + self.y * self.y + self.z * self.z).sqrt();
        v3(self.x * inv, self.y * inv, self.z * inv)
    }
}

fn xyz(a: &[f32], at: usize) -> V3 {
    v3(a[at], a[at + 1], a[at + 2])
}

/// A frame's camera and integrator settings, in the kernel's parameter form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Camera position.
    pub pos: [f32; 3],
    /// Forward, right and up unit vectors.
    pub fwd: [f32; 3],
    /// Right.
    pub right: [f32; 3],
    /// Up.
    pub up: [f32; 3],
    /// tan(fov_y / 2).
    pub tan_half: f32,
    /// Width / height.
    pub aspect: f32,
    /// Ray epsilon.
    pub eps: f32,
}

/// The scene's arrays and the frame settings, as the kernel sees them.
pub struct Tracer<'a> {
    /// The laid-out scene.
    pub scene: &'a PathScene,
    /// The camera.
    pub frame: Frame,
    /// Settings.
    pub params: FrameParams,
}

/// §6.4's affine test of ray (o, d) against the affine rows `m`
/// ([`super::layout::affine_rows`]): the hit distance in [t_min, t_max], if
/// any. The same float operations in the same order as `affine()` in
/// `kernels/lin2017/path.cu` (and `tri_affine` in `intersect.cu`).
pub fn affine_test(m: &[f32; 12], o: [f32; 3], d: [f32; 3], t_min: f32, t_max: f32) -> Option<f32> {
    let oz = m[8] * o[0] + m[9] * o[1] + m[10] * o[2] + m[11];
    let dz = m[8] * d[0] + m[9] * d[1] + m[10] * d[2];
    let tt = -oz / dz;
    if !(tt >= t_min && tt <= t_max) {
        return None;
    }
    let u = m[0] * o[0] + m[1] * o[1] + m[2] * o[2] + m[3] + tt * (m[0] * d[0] + m[1] * d[1] + m[2] * d[2]);
    if u < 0.0 {
        return None;
    }
    let v = m[4] * o[0] + m[5] * o[1] + m[6] * o[2] + m[7] + tt * (m[4] * d[0] + m[5] * d[1] + m[6] * d[2]);
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(tt)
}

impl Tracer<'_> {
    fn affine(&self, t: u32, o: V3, d: V3, t_min: f32, t_hit: &mut f32) -> bool {
        match affine_test(&self.scene.tris[t as usize], [o.x, o.y, o.z], [d.x, d.y, d.z], t_min, *t_hit) {
            Some(tt) => {
                *t_hit = tt;
                true
            }
            None => false,
        }
    }

    /// kd-restart and kd-backtrack: the kernel's `trace_stackless`.
    #[allow(clippy::too_many_arguments)]
    fn trace_stackless(
        &self,
        backtrack: bool,
        o: V3,
        d: V3,
        inv: V3,
        t_min: f32,
        t_max: f32,
        mut tnear: f32,
        t_exit: f32,
        any: bool,
        c: &mut Counts,
    ) -> Option<(u32, f32)> {
        let s = self.scene;
        let eps = self.frame.eps;
        let t_hit = t_max;
        let mut tfar = t_exit;
        let mut found: Option<u32> = None;
        let mut idx = 0u32;
        let mut hi;
        loop {
            let mut n = s.nodes[idx as usize];
            while n[0] >> 30 != LEAF_AXIS {
                c.inner += 1;
                let axis = n[0] >> 30;
                let tsplit = (f32::from_bits(n[1]) - o.comp(axis)) * inv.comp(axis);
                let (mut first, mut second) = (n[0] & 0xff_ffff, n[2]);
                if (d.comp(axis).to_bits() as i32) < 0 {
                    std::mem::swap(&mut first, &mut second);
                }
                // Fig. 15 as printed: cvt.rmi then cvt.rzi.s32 (saturating, NaN to 0), as `as i32`
                let f = ((tnear - tsplit).floor() as i32) >> 31;
                idx = (first & f as u32).wrapping_add(second & !(f as u32));
                if f < 0 && tsplit < tfar {
                    tfar = tsplit;
                }
                n = s.nodes[idx as usize];
            }
            c.leaves += 1;
            let (count, first) = ((n[0] >> 24) & 63, n[3]);
            let lo = fmax(tnear - eps, t_min);
            hi = fmin(t_hit, tfar + eps);
            for r in 0..count {
                let t = s.refs[(first + r) as usize];
                c.tri_tests += 1;
                if self.affine(t, o, d, lo, &mut hi) {
                    found = Some(t);
                    if any {
                        break;
                    }
                }
            }
            if found.is_some() {
                break;
            }
            if !(tfar < t_exit) {
                break;
            }
            tnear = tfar;
            if backtrack {
                loop {
                    idx = s.up[idx as usize][3].to_bits();
                    c.ascents += 1;
                    let b = &s.up[idx as usize];
                    tfar = fmin(t_max, box_exit(b, o, inv));
                    if idx == 0 || tnear < tfar {
                        break;
                    }
                }
            } else {
                idx = 0;
                tfar = t_exit;
            }
        }
        found.map(|t| (t, hi))
    }

    /// The nearest hit in [t_min, t_max] (with `any`, the first found).
    fn trace(&self, o: V3, d: V3, t_min: f32, t_max: f32, any: bool, c: &mut Counts) -> Option<(u32, f32)> {
        let s = self.scene;
        let eps = self.frame.eps;
        c.rays += 1;
        let inv = v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        let (t0x, t1x) = ((s.lo[0] - o.x) * inv.x, (s.hi[0] - o.x) * inv.x);
        let (t0y, t1y) = ((s.lo[1] - o.y) * inv.y, (s.hi[1] - o.y) * inv.y);
        let (t0z, t1z) = ((s.lo[2] - o.z) * inv.z, (s.hi[2] - o.z) * inv.z);
        let tn = fmax(fmax(fmin(t0x, t1x), fmin(t0y, t1y)), fmin(t0z, t1z));
        let tf = fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmax(t0z, t1z));
        let (mut tnear, mut tfar) = (fmax(t_min, tn), fmin(t_max, tf));
        if !(tnear <= tfar) {
            return None;
        }
        if matches!(self.params.traversal, Traversal::Restart | Traversal::Backtrack) {
            let backtrack = self.params.traversal == Traversal::Backtrack;
            return self.trace_stackless(backtrack, o, d, inv, t_min, t_max, tnear, tfar, any, c);
        }
        let t_hit = t_max;
        let mut found: Option<u32> = None;
        // entries {node, tfar} (8 bytes; tnear is the previous tfar on a pop)
        // or, with the full stack, {node, tfar, tnear} (12 bytes)
        let wide = self.params.traversal == Traversal::FullStack;
        let mut stack = [(0u32, 0.0f32, 0.0f32); STACK_ENTRIES];
        let mut size = 0usize;
        let mut idx = 0u32;
        let mut hi;
        loop {
            let mut n = s.nodes[idx as usize];
            while n[0] >> 30 != LEAF_AXIS {
                c.inner += 1;
                let axis = n[0] >> 30;
                let tsplit = (f32::from_bits(n[1]) - o.comp(axis)) * inv.comp(axis);
                let (mut first, mut second) = (n[0] & 0xff_ffff, n[2]);
                if (d.comp(axis).to_bits() as i32) < 0 {
                    std::mem::swap(&mut first, &mut second);
                }
                let f = -((tnear <= tsplit) as i32);
                idx = (first & f as u32).wrapping_add(second & !(f as u32));
                if f < 0 && tsplit <= tfar {
                    c.pushes += 1;
                    stack[size] = (second, tfar, tsplit);
                    size += 1;
                    tfar = tsplit;
                }
                n = s.nodes[idx as usize];
            }
            c.leaves += 1;
            let (count, first) = ((n[0] >> 24) & 63, n[3]);
            let lo = fmax(tnear - eps, t_min);
            hi = fmin(t_hit, tfar + eps);
            for r in 0..count {
                let t = s.refs[(first + r) as usize];
                c.tri_tests += 1;
                if self.affine(t, o, d, lo, &mut hi) {
                    found = Some(t);
                    if any {
                        break;
                    }
                }
            }
            if found.is_some() {
                break;
            }
            if size == 0 {
                break;
            }
            c.pops += 1;
            size -= 1;
            let (node, entry_tfar, entry_tnear) = stack[size];
            tnear = if wide { entry_tnear } else { tfar };
            (idx, tfar) = (node, entry_tfar);
        }
        found.map(|t| (t, hi))
    }

    /// The integrator that traces the paths: mlt's base, or the frame's own.
    fn base(&self) -> Integrator {
        if self.params.integrator == Integrator::Mlt { super::MLT_BASE } else { self.params.integrator }
    }

    fn mis_weight(&self, a: f32, b: f32) -> f32 {
        let (a, b) = if self.base() == Integrator::MisPower { (a * a, b * b) } else { (a, b) };
        a / (a + b)
    }

    /// Path `i`'s camera ray (origin, direction): tent-jittered in its
    /// subpixel of the 2 x 2 grid by the tent filter's uniforms `r0` (across)
    /// and `r1` (down), the kernel's `camera_ray`.
    fn camera_ray(&self, i: u32, r0: f32, r1: f32) -> (V3, V3) {
        self.camera_through(i, PixelSampling::Tent.offset(i, 0, 0, r0, r1))
    }

    /// Path `i`'s camera ray through its pixel at (`ox`, `oy`) half pixels
    /// from the top left corner ([`PixelSampling::offset`]), the kernel's `camera_through`.
    fn camera_through(&self, i: u32, (ox, oy): (f32, f32)) -> (V3, V3) {
        let cam = &self.frame;
        let (w, h) = (self.params.width, self.params.height);
        let pixel = i >> 2;
        let (x, y) = (pixel % w, pixel / w);
        let px = x as f32 + ox * 0.5;
        let py = y as f32 + oy * 0.5;
        let cx = (px / w as f32 * 2.0 - 1.0) * cam.tan_half * cam.aspect;
        let cy = (1.0 - py / h as f32 * 2.0) * cam.tan_half;
        let (fwd, right, up) = (xyz(&cam.fwd, 0), xyz(&cam.right, 0), xyz(&cam.up, 0));
        (xyz(&cam.pos, 0), fwd.add(right.scale(cx)).add(up.scale(cy)).normalize())
    }

    /// A point on a light, chosen as next-event estimation and bdpt's light
    /// subpath both choose it (the kernel's code at both places): the light
    /// by the cumulative areas in `lights[i][3]` from dimension `dim`, the
    /// point uniform on its triangle from `dim + 1` and `dim + 2`. Needs a
    /// light.
    fn light_point<S: Sample>(&self, key: S, dim: u32) -> (&[f32; 12], V3) {
        let lights = &self.scene.lights;
        let yl = key.at(dim);
        let mut li = 0usize;
        while li + 1 < lights.len() && !(yl < lights[li][3]) {
            li += 1;
        }
        let lg = &lights[li];
        let su = key.at(dim + 1).sqrt();
        let yv = key.at(dim + 2);
        let (bu, bv) = (su * (1.0 - yv), su * yv);
        (lg, xyz(lg, 0).add(xyz(lg, 4).scale(bu)).add(xyz(lg, 8).scale(bv)))
    }

    /// The light subpath of `key` (at most `nl` vertices): the kernel's `light_subpath`.
    fn light_subpath<S: Sample>(&self, key: S, nl: usize, c: &mut Counts) -> Vec<LightVertex> {
        let s = self.scene;
        let eps = self.frame.eps;
        let (lg, mut o) = self.light_point(key, DIMS_LIGHT);
        let ld = s.tri_data[lg[7].to_bits() as usize];
        let le = xyz(&s.mats[ld[3].to_bits() as usize], 4);
        let mut alpha = le.scale(s.light_area);
        let n0 = v3(ld[0], ld[1], ld[2]);
        let mut lv = Vec::with_capacity(nl);
        lv.push(LightVertex { p: o, n: n0, alpha, color: v3(0.0, 0.0, 0.0) });
        // the emitted direction, cosine-weighted: Le cos / (cos / pi) = pi Le
        let (mut d, _) = cosine_dir(n0, key.at(DIMS_LIGHT + 3), key.at(DIMS_LIGHT + 4));
        alpha = alpha.scale(std::f32::consts::PI);
        while lv.len() < nl {
            let Some((tri, t)) = self.trace(o, d, eps, f32::INFINITY, false, c) else {
                break;
            };
            let td = s.tri_data[tri as usize];
            let mat = &s.mats[td[3].to_bits() as usize];
            if mat[3].to_bits() != KIND_DIFFUSE {
                break;
            }
            let n = v3(td[0], td[1], td[2]);
            let hitp = o.add(d.scale(t));
            let ns = if d.dot(n) < 0.0 { n } else { v3(-n.x, -n.y, -n.z) };
            let color = xyz(mat, 0);
            lv.push(LightVertex { p: hitp, n: ns, alpha, color });
            if lv.len() == nl {
                break;
            }
            let dim = DIMS_LIGHT + DIMS_PER_BOUNCE * lv.len() as u32;
            (d, _) = cosine_dir(ns, key.at(dim + 3), key.at(dim + 4));
            if !roulette(self.params.termination, &mut alpha, color, key, dim) {
                break;
            }
            o = hitp;
        }
        lv
    }

    /// Radiance of bdpt's path `i` (its light and eye subpaths and their
    /// connections under the uniform weights): the kernel's `bdpt_frame`.
    fn bdpt<S: Sample>(&self, (mut o, mut d): (V3, V3), key: S, counts: &mut Counts) -> [f32; 3] {
        let s = self.scene;
        let cam = &self.frame;
        let p = &self.params;
        let nl_max = if s.lights.is_empty() { 0 } else { p.max_bounces.min(LIGHT_VERTICES as u32) as i32 };
        let lv = if nl_max > 0 { self.light_subpath(key, nl_max as usize, counts) } else { Vec::new() };
        let nl = lv.len() as i32;
        let (mut l, mut beta) = (v3(0.0, 0.0, 0.0), v3(1.0, 1.0, 1.0));
        let (mut bsdf_pdf, mut count_emission) = (0.0f32, true);
        let mut run = 0i32;
        let mut bounce = 0u32;
        loop {
            let Some((tri, t)) = self.trace(o, d, cam.eps, f32::INFINITY, false, counts) else {
                if let Some(env) = &s.env {
                    let e = env.radiance([d.x, d.y, d.z]);
                    l = l.add(beta.mul(v3(e[0], e[1], e[2])));
                }
                break;
            };
            let td = s.tri_data[tri as usize];
            let n = v3(td[0], td[1], td[2]);
            let mat = &s.mats[td[3].to_bits() as usize];
            let kind = mat[3].to_bits();
            let cos_d = d.dot(n);
            if kind == KIND_EMITTER {
                if cos_d < 0.0 {
                    let c = 1 + run.min(nl_max);
                    l = l.add(beta.mul(xyz(mat, 4)).scale(1.0 / c as f32));
                }
                break;
            }
            let hitp = o.add(d.scale(t));
            let ns = if cos_d < 0.0 { n } else { v3(-n.x, -n.y, -n.z) };
            let color = xyz(mat, 0);
            let cos_o = -d.dot(ns);
            let dim = DIMS_CAMERA + DIMS_PER_BOUNCE * bounce;
            if kind == KIND_DIFFUSE {
                // light vertex k makes a path of k + bounce + 1 bounces
                let last = (p.max_bounces_i32() - bounce as i32 - 1).min(nl - 1);
                for k in 0..=last {
                    let y = &lv[k as usize];
                    let mut w = y.p.sub(hitp);
                    let dist2 = w.dot(w);
                    let dist = dist2.sqrt();
                    w = w.scale(1.0 / dist);
                    let (cos_x, cos_y) = (ns.dot(w), -y.n.dot(w));
                    if cos_x > 0.0
                        && cos_y > 0.0
                        && self.trace(hitp, w, cam.eps, dist - cam.eps, true, counts).is_none()
                    {
                        let c = 1 + (k + 1 + run).min(nl_max);
                        let g = cos_x * cos_y / dist2 * INV_PI / c as f32;
                        let f = if k == 0 { v3(1.0, 1.0, 1.0) } else { y.color.scale(INV_PI) };
                        l = l.add(beta.mul(color).mul(f).mul(y.alpha).scale(g));
                    }
                }
            }
            run = if kind == KIND_DIFFUSE { run + 1 } else { 0 };
            if bounce == p.max_bounces {
                break;
            }
            if !self.bounce_on(
                mat,
                kind,
                ns,
                color,
                cos_d,
                cos_o,
                key,
                dim,
                &mut d,
                &mut beta,
                &mut bsdf_pdf,
                &mut count_emission,
            ) {
                break;
            }
            o = hitp;
            bounce += 1;
        }
        [l.x, l.y, l.z]
    }

    /// Radiance of path `i` in frame `frame`.
    pub fn path(&self, i: u32, frame: u32) -> [f32; 3] {
        self.path_counted(i, frame, &mut Counts::default())
    }

    /// Radiance of path `i` in frame `frame`, adding its traversal events to `c`.
    pub fn path_counted(&self, i: u32, frame: u32, counts: &mut Counts) -> [f32; 3] {
        let key = path_key(i, frame, self.params.seed);
        let offset = self.params.pixels.offset(i, frame, self.params.seed, key.at(0), key.at(1));
        self.radiance(self.camera_through(i, offset), key, counts)
    }

    /// An MLT proposal (or bootstrap sample) drawn through `m`: its path
    /// index (4 x pixel + subpixel) and radiance, the kernel's `mlt_camera`
    /// and `radiance`. The subpixel of the 2W x 2H grid and the tent jitter
    /// come from samples 0 and 1.
    pub fn mlt_sample(&self, m: super::mlt::Sampler<'_>, counts: &mut Counts) -> (u32, [f32; 3]) {
        let (w, h) = (self.params.width as i32, self.params.height as i32);
        let (x, y) = (m.at(0) * (2 * w) as f32, m.at(1) * (2 * h) as f32);
        let (sx, sy) = ((x as i32).min(2 * w - 1), (y as i32).min(2 * h - 1));
        let i = (4 * ((sy >> 1) * w + (sx >> 1)) + 2 * (sy & 1) + (sx & 1)) as u32;
        (i, self.radiance(self.camera_ray(i, x - sx as f32, y - sy as f32), m, counts))
    }

    /// The radiance the frame's integrator (mlt's base under mlt) finds along
    /// the camera ray (origin, direction), drawing its random numbers from
    /// `key`: the kernel's `radiance`.
    fn radiance<S: Sample>(&self, (mut o, mut d): (V3, V3), key: S, counts: &mut Counts) -> [f32; 3] {
        let s = self.scene;
        let cam = &self.frame;
        let p = &self.params;
        let integrator = self.base();
        if integrator == Integrator::Bdpt {
            return self.bdpt((o, d), key, counts);
        }
        let mut l = v3(0.0, 0.0, 0.0);
        let mut beta = v3(1.0, 1.0, 1.0);
        let mut count_emission = true;
        let mut bsdf_pdf = 0.0f32;
        let mut bounce = 0u32;
        let mut scattered = false; // sss_frame's Sss: scattered since it entered
        while bounce <= p.max_bounces {
            let hit = self.trace(o, d, cam.eps, f32::INFINITY, false, counts);
            if let Some(m) = &s.medium {
                let t_end = hit.map_or(f32::INFINITY, |h| h.1);
                self.march(m, key, bounce, (o, d), t_end, (&mut l, &mut beta), counts);
            }
            let Some((tri, t)) = hit else {
                // the environment: not light-sampled, its radiance counts in full after any bounce
                if let Some(env) = &s.env {
                    let e = env.radiance([d.x, d.y, d.z]);
                    l = l.add(beta.mul(v3(e[0], e[1], e[2])));
                }
                break;
            };
            let td = s.tri_data[tri as usize];
            let n = v3(td[0], td[1], td[2]);
            let mat = &s.mats[td[3].to_bits() as usize];
            let kind = mat[3].to_bits();
            let cos_d = d.dot(n);
            if kind == KIND_TRANSLUCENT {
                // the kernel's translucent() (sss_frame)
                let path = (&mut o, &mut d, &mut beta, &mut bounce, &mut scattered);
                if !self.translucent(mat, n, cos_d, t, key, path) {
                    break;
                }
                count_emission = true;
                continue;
            }
            if kind == KIND_EMITTER {
                if cos_d < 0.0 {
                    let mut wgt = 1.0;
                    if !count_emission {
                        if integrator == Integrator::Nee {
                            wgt = 0.0;
                        } else if integrator != Integrator::Pt {
                            let light_pdf = t * t / (-cos_d * s.light_area);
                            wgt = self.mis_weight(bsdf_pdf, light_pdf);
                        }
                    }
                    l = l.add(beta.mul(xyz(mat, 4)).scale(wgt));
                }
                break;
            }
            let hitp = o.add(d.scale(t));
            let ns = if cos_d < 0.0 { n } else { v3(-n.x, -n.y, -n.z) };
            let color = xyz(mat, 0);
            let cos_o = -d.dot(ns);
            let dim = DIMS_CAMERA + DIMS_PER_BOUNCE * bounce;
            // textures: the lobe of the hit
            let (mat, kind, color) = self.texture_hit((tri, t), (o, d), key, dim, (td[3].to_bits(), kind, color));
            let sampled_light = kind == KIND_DIFFUSE || kind == KIND_CONDUCTOR || kind == KIND_COATED;
            if sampled_light && integrator != Integrator::Pt && !s.lights.is_empty() && bounce < p.max_bounces {
                let (lg, q) = self.light_point(key, dim);
                let mut wl = q.sub(hitp);
                let dist2 = wl.dot(wl);
                let dist = dist2.sqrt();
                wl = wl.scale(1.0 / dist);
                let ld = s.tri_data[lg[7].to_bits() as usize];
                let cos_s = ns.dot(wl);
                let cos_l = -v3(ld[0], ld[1], ld[2]).dot(wl);
                if cos_s > 0.0 && cos_l > 0.0 {
                    // the BSDF times the cosine, as a colour fc times a scalar fs, and its sampling pdf
                    let (mut fc, mut fs, mut bsdf_pdf_l) = (color, cos_s * INV_PI, cos_s * INV_PI);
                    if kind == KIND_CONDUCTOR {
                        let alpha = mat[8];
                        let a2 = alpha * alpha;
                        let h = wl.sub(d).normalize();
                        let (ch, coh) = (h.dot(ns), -d.dot(h));
                        let (dm, g) = if mat[10] > 0.0 {
                            let a = Aniso::new(n, alpha, mat[10]);
                            (a.d(h, ch), smith_g1(a.along(d), cos_o, coh) * smith_g1(a.along(wl), cos_s, wl.dot(h)))
                        } else {
                            (beckmann(a2, ch), smith_g1(alpha, cos_o, coh) * smith_g1(alpha, cos_s, wl.dot(h)))
                        };
                        fc = v3(schlick(color.x, coh), schlick(color.y, coh), schlick(color.z, coh));
                        fs = dm * g / (4.0 * cos_o);
                        bsdf_pdf_l = dm * ch / (4.0 * coh);
                    } else if kind == KIND_COATED {
                        // the coupled diffuse; the coat's mirror lobe has no light sample
                        let r0 = coat_r0(mat[7]);
                        fs = 28.0 / 23.0 * (1.0 - r0) * as_factor(cos_s) * as_factor(cos_o) * cos_s * INV_PI;
                        bsdf_pdf_l = (1.0 - schlick(r0, cos_o)) * cos_s * INV_PI;
                    }
                    if fs > 0.0 && self.trace(hitp, wl, cam.eps, dist - cam.eps, true, counts).is_none() {
                        let le = xyz(&s.mats[ld[3].to_bits() as usize], 4);
                        let light_pdf = dist2 / (cos_l * s.light_area);
                        let mut wgt = 1.0;
                        if integrator != Integrator::Nee {
                            wgt = self.mis_weight(light_pdf, bsdf_pdf_l);
                        }
                        let mut g = fs / light_pdf * wgt;
                        if let Some(m) = &s.medium {
                            g *= medium_transmittance(m, hitp, wl, dist);
                        }
                        l = l.add(beta.mul(fc).mul(le).scale(g));
                    }
                }
            }
            if bounce == p.max_bounces {
                break;
            }
            // the next direction, and the bounce's mask f cos / p
            if !self.bounce_on(
                mat,
                kind,
                ns,
                color,
                cos_d,
                cos_o,
                key,
                dim,
                &mut d,
                &mut beta,
                &mut bsdf_pdf,
                &mut count_emission,
            ) {
                break;
            }
            o = hitp;
            bounce += 1;
        }
        [l.x, l.y, l.z]
    }

    /// The kernel's `translucent` (`sss_frame`, §5.3): the ray (`o`, `d`) hit
    /// the translucent material `mat` (normal `n`, `cos_d` = d · n) at `t`. The
    /// leg inside, if the ray left from inside (at most one scattering since
    /// the path entered: `scattered`), then the surface's 3-way Fresnel switch;
    /// the next ray, mask and bounce count in place; false when the path ends.
    #[allow(clippy::too_many_arguments)]
    fn translucent<S: Sample>(
        &self,
        mat: &[f32; 12],
        n: V3,
        cos_d: f32,
        t: f32,
        key: S,
        (o, d, beta, bounce, scattered): (&mut V3, &mut V3, &mut V3, &mut u32, &mut bool),
    ) -> bool {
        let max = self.params.max_bounces;
        let b = *bounce;
        let dim = DIMS_CAMERA + DIMS_PER_BOUNCE * b;
        let into = cos_d < 0.0;
        if !into {
            // the leg ran inside: sigma_s' = (1 - g) sigma_s (003:L396)
            let sigma_r = (1.0 - mat[10]) * mat[8];
            let mut ext = 0.0f32;
            if !*scattered {
                let dd = if sigma_r > 0.0 { -ln(1.0 - key.at(dim + 7)) / sigma_r } else { f32::INFINITY };
                if dd < t {
                    if b == max {
                        return false;
                    }
                    let wgt = v3(exp_neg(-mat[4] * dd), exp_neg(-mat[5] * dd), exp_neg(-mat[6] * dd));
                    let next = hg_dir(mat[10], *d, key.at(dim + 3), key.at(dim + 4));
                    if !roulette(self.params.termination, beta, wgt, key, dim) {
                        return false;
                    }
                    *scattered = true;
                    *o = o.add(d.scale(dd));
                    *d = next;
                    *bounce = b + 1;
                    return true;
                }
            } else {
                ext = sigma_r;
            }
            *beta = v3(
                beta.x * exp_neg(-(mat[4] + ext) * t),
                beta.y * exp_neg(-(mat[5] + ext) * t),
                beta.z * exp_neg(-(mat[6] + ext) * t),
            );
        }
        if b == max {
            return false;
        }
        let ns = if into { n } else { v3(-n.x, -n.y, -n.z) };
        let cos_i = -d.dot(ns);
        let mut next = d.add(ns.scale(2.0 * cos_i));
        let mut wgt = v3(1.0, 1.0, 1.0);
        let ior = mat[7];
        let eta = if into { 1.0 / ior } else { ior };
        let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
        if k > 0.0 {
            let cos_t = k.sqrt();
            let fr = surface_fresnel(mat, into, eta, cos_i, cos_t);
            if !(key.at(dim + 6) < fr) {
                if !into || key.at(dim + 7) < mat[11] {
                    next = d.scale(eta).add(ns.scale(eta * cos_i - cos_t));
                    *scattered = false;
                } else {
                    next = cosine_dir(ns, key.at(dim + 3), key.at(dim + 4)).0;
                    wgt = xyz(mat, 0);
                }
            }
        }
        if !roulette(self.params.termination, beta, wgt, key, dim) {
            return false;
        }
        *o = o.add(d.scale(t));
        *d = next;
        *bounce = b + 1;
        true
    }

    /// The kernel's `texture_hit`: at a hit on triangle `tri` at distance `t`
    /// along (`o`, `d`), a textured material (`m`, `kind`, `color`) becomes the
    /// lobe its metalness texel picks with dimension `dim + 6`: the Lambertian
    /// lobe with the albedo, or the conductor row of its roughness texel with
    /// the specular colour lerp(white, albedo, m). Any other material is
    /// returned as it is, with its row of the materials.
    fn texture_hit<S: Sample>(
        &self,
        (tri, t): (u32, f32),
        (o, d): (V3, V3),
        key: S,
        dim: u32,
        (m, kind, color): (u32, u32, V3),
    ) -> (&[f32; 12], u32, V3) {
        let s = self.scene;
        let mat = &s.mats[m as usize];
        let Some(x) = s.textures.as_ref().filter(|_| kind == KIND_TEXTURED) else { return (mat, kind, color) };
        let [albedo, rough, metal, rows] = x.mats[m as usize];
        // the barycentric weights of vertices 0 and 1, as the affine test computed them
        let r = &s.tris[tri as usize];
        let b0 = r[0] * o.x + r[1] * o.y + r[2] * o.z + r[3] + t * (r[0] * d.x + r[1] * d.y + r[2] * d.z);
        let b1 = r[4] * o.x + r[5] * o.y + r[6] * o.z + r[7] + t * (r[4] * d.x + r[5] * d.y + r[6] * d.z);
        let b2 = 1.0 - b0 - b1;
        let uv = &x.uvs[tri as usize];
        let tu = b0 * uv[0] + b1 * uv[2] + b2 * uv[4];
        let tv = b0 * uv[1] + b1 * uv[3] + b2 * uv[5];
        let texel = |map: i32| {
            let i = &x.info[4 * map as usize..4 * map as usize + 3];
            x.texels[i[0] as usize + crate::host::scene::Texture::index(i[1], i[2], tu, tv)]
        };
        let byte = |t: u32, shift: u32| ((t >> shift) & 255) as f32 / 255.0;
        let mut color = color;
        if albedo >= 0 {
            let a = texel(albedo);
            color = v3(color.x * byte(a, 0), color.y * byte(a, 8), color.z * byte(a, 16));
        }
        let mv = if metal >= 0 { byte(texel(metal), 0) } else { 0.0 };
        if rows >= 0 && key.at(dim + 6) < mv {
            let level = if rough >= 0 { (texel(rough) & 255) as i32 } else { 0 };
            let w = 1.0 - mv; // lerp(white, albedo, m)
            return (
                &s.mats[(rows + level) as usize],
                KIND_CONDUCTOR,
                v3(w + mv * color.x, w + mv * color.y, w + mv * color.z),
            );
        }
        (mat, KIND_DIFFUSE, color)
    }

    /// The kernel's `march`: the segment `o + t d`, t in [0, `t_end`], of a path
    /// after `bounce` bounces through the medium `m` (`PathScene::medium`):
    /// in-scattered and emitted light into `l` (if `bounce` < max bounces),
    /// the segment's transmittance into the mask `beta`.
    #[allow(clippy::too_many_arguments)]
    fn march<S: Sample>(
        &self,
        m: &[f32; 16],
        key: S,
        bounce: u32,
        (o, d): (V3, V3),
        t_end: f32,
        (l, beta): (&mut V3, &mut V3),
        counts: &mut Counts,
    ) {
        let s = self.scene;
        let eps = self.frame.eps;
        let (ta, tb) = medium_span(m, o, d, t_end);
        if !(ta < tb) {
            return;
        }
        let (sigma_t, dt) = (m[8] + m[9], m[3]);
        if bounce < self.params.max_bounces {
            let dim = MEDIUM_DIMS + MEDIUM_DIMS_PER_BOUNCE * bounce;
            let u = key.at(dim);
            let mut sum = v3(0.0, 0.0, 0.0);
            for k in 0..MEDIUM_MAX_STEPS {
                let dk = dim + 4 * k + 1;
                let uk = if m[11] > 0.0 { key.at(dk) } else { u };
                let t = ta + (k as f32 + uk) * dt;
                if !(t < tb) {
                    break;
                }
                let x = o.add(d.scale(t));
                let rho = medium_density(m, x.y);
                let mut src = xyz(m, 12).scale(rho);
                if !s.lights.is_empty() {
                    let (lg, q) = self.light_point(key, dk + 1);
                    let mut wl = q.sub(x);
                    let dist2 = wl.dot(wl);
                    let dist = dist2.sqrt();
                    wl = wl.scale(1.0 / dist);
                    let ld = s.tri_data[lg[7].to_bits() as usize];
                    let cos_l = -v3(ld[0], ld[1], ld[2]).dot(wl);
                    if cos_l > 0.0 && self.trace(x, wl, eps, dist - eps, true, counts).is_none() {
                        let le = xyz(&s.mats[ld[3].to_bits() as usize], 4);
                        let mut w = m[9] * rho * hg(m[7], wl.dot(d)) * cos_l * s.light_area / dist2;
                        w *= medium_transmittance(m, x, wl, dist);
                        src = src.add(le.scale(w));
                    }
                }
                sum = sum.add(src.scale(exp_neg(-sigma_t * medium_depth(m, o, d, ta, t))));
            }
            *l = l.add(beta.mul(sum.scale(dt)));
        }
        *beta = beta.scale(exp_neg(-sigma_t * medium_depth(m, o, d, ta, tb)));
    }

    /// The next direction at a hit (`d` in, the sampled direction out) and the
    /// bounce's mask f cos / p: the kernel's `scatter`; `None` when the path ends.
    #[allow(clippy::too_many_arguments)]
    fn scatter<S: Sample>(
        &self,
        mat: &[f32; 12],
        kind: u32,
        ns: V3,
        color: V3,
        cos_d: f32,
        cos_o: f32,
        key: S,
        dim: u32,
        d: &mut V3,
        bsdf_pdf: &mut f32,
        count_emission: &mut bool,
    ) -> Option<V3> {
        let mut wgt = color;
        if kind == KIND_DIFFUSE {
            let lz;
            (*d, lz) = cosine_dir(ns, key.at(dim + 3), key.at(dim + 4));
            *bsdf_pdf = lz * INV_PI;
            *count_emission = false;
        } else if kind == KIND_CONDUCTOR || kind == KIND_ROUGH_GLASS {
            let alpha = mat[8];
            let a2 = alpha * alpha;
            // an anisotropic mirror or rough glass: the kernel's `an`
            let an = (mat[10] > 0.0)
                .then(|| Aniso::new(if cos_d < 0.0 { ns } else { v3(-ns.x, -ns.y, -ns.z) }, alpha, mat[10]));
            let (mh, cm) = match &an {
                Some(a) => a.sample(ns, key.at(dim + 3), key.at(dim + 4)),
                None => {
                    let tan2 = a2 * -ln(1.0 - key.at(dim + 3));
                    let cm = 1.0 / (1.0 + tan2).sqrt();
                    let sm = tan2.sqrt() * cm;
                    let (cs, sn) = azimuth(key.at(dim + 4));
                    let (b1, b2) = basis(ns);
                    (b1.scale(sm * cs).add(b2.scale(sm * sn)).add(ns.scale(cm)), cm)
                }
            };
            let co = -d.dot(mh);
            if !(co > 0.0) {
                return None;
            }
            let mut next = d.add(mh.scale(2.0 * co));
            let mut scale = 1.0f32;
            let mut refracted = false;
            if kind == KIND_CONDUCTOR {
                wgt = v3(schlick(color.x, co), schlick(color.y, co), schlick(color.z, co));
                *bsdf_pdf = an.as_ref().map_or_else(|| beckmann(a2, cm), |a| a.d(mh, cm)) * cm / (4.0 * co);
                *count_emission = false;
            } else {
                let ior = mat[7];
                let into = cos_d < 0.0;
                let eta = if into { 1.0 / ior } else { ior };
                let k = 1.0 - eta * eta * (1.0 - co * co);
                if k > 0.0 {
                    let cos_t = k.sqrt();
                    let r0 = (1.0 - ior) / (1.0 + ior);
                    let fr = if mat[9] > 0.0 {
                        fresnel_exact(eta, co, cos_t)
                    } else {
                        schlick(r0 * r0, if into { co } else { cos_t })
                    };
                    if !(key.at(dim + 6) < fr) {
                        next = d.scale(eta).add(mh.scale(eta * co - cos_t));
                        scale = eta * eta;
                        refracted = true;
                    }
                }
                *count_emission = true;
            }
            let ci = next.dot(ns);
            if if refracted { !(ci < 0.0) } else { !(ci > 0.0) } {
                return None;
            }
            let g = match &an {
                Some(a) => smith_g1(a.along(*d), cos_o, co) * smith_g1(a.along(next), ci, next.dot(mh)),
                None => smith_g1(alpha, cos_o, co) * smith_g1(alpha, ci, next.dot(mh)),
            };
            let f = g * co / (cos_o * cm) * scale;
            wgt = wgt.scale(f);
            *d = next;
        } else if kind == KIND_COATED {
            // §4.5's Fresnel switch: the coat's mirror reflection, else the coupled diffuse
            let r0 = coat_r0(mat[7]);
            let fr = schlick(r0, cos_o);
            if key.at(dim + 6) < fr || !(fr < 1.0) {
                *d = d.add(ns.scale(2.0 * cos_o));
                wgt = v3(1.0, 1.0, 1.0);
                *count_emission = true;
            } else {
                let lz;
                (*d, lz) = cosine_dir(ns, key.at(dim + 3), key.at(dim + 4));
                let k = 28.0 / 23.0 * (1.0 - r0) * as_factor(lz) * as_factor(cos_o) / (1.0 - fr);
                wgt = color.scale(k);
                *bsdf_pdf = (1.0 - fr) * lz * INV_PI;
                *count_emission = false;
            }
        } else {
            let cos_i = -d.dot(ns);
            let mut next = d.add(ns.scale(2.0 * cos_i));
            if kind == KIND_GLASS {
                let ior = mat[7];
                let into = cos_d < 0.0;
                let eta = if into { 1.0 / ior } else { ior };
                let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
                if k > 0.0 {
                    let cos_t = k.sqrt();
                    let tdir = d.scale(eta).add(ns.scale(eta * cos_i - cos_t));
                    let fr = surface_fresnel(mat, into, eta, cos_i, cos_t);
                    if !(key.at(dim + 6) < fr) {
                        next = tdir;
                    }
                }
            }
            *d = next;
            *count_emission = true;
        }
        Some(wgt)
    }

    /// [`Self::scatter`] then [`roulette`]: false when the path ends at this hit.
    #[allow(clippy::too_many_arguments)]
    fn bounce_on<S: Sample>(
        &self,
        mat: &[f32; 12],
        kind: u32,
        ns: V3,
        color: V3,
        cos_d: f32,
        cos_o: f32,
        key: S,
        dim: u32,
        d: &mut V3,
        beta: &mut V3,
        bsdf_pdf: &mut f32,
        count_emission: &mut bool,
    ) -> bool {
        match self.scatter(mat, kind, ns, color, cos_d, cos_o, key, dim, d, bsdf_pdf, count_emission) {
            Some(wgt) => roulette(self.params.termination, beta, wgt, key, dim),
            None => false,
        }
    }

    /// Traces frame `frame`: adds each path's radiance to `accum` (3 floats
    /// a path) and stores it in `last`, as one kernel launch does; returns
    /// the frame's traversal events.
    pub fn frame(&self, frame: u32, accum: &mut [f32], last: &mut [f32]) -> Counts {
        accum
            .par_chunks_mut(3)
            .zip(last.par_chunks_mut(3))
            .enumerate()
            .map(|(i, (a, l))| {
                let mut c = Counts::default();
                let r = self.path_counted(i as u32, frame, &mut c);
                for ((a, l), r) in a.iter_mut().zip(l.iter_mut()).zip(r) {
                    *a += r;
                    *l = r;
                }
                c
            })
            .reduce(Counts::default, |mut a, b| {
                a.add(&b);
                a
            })
    }
}

/// The medium's first random dimension (the kernel's `MEDIUM_DIMS`): a
/// segment after b bounces draws from `MEDIUM_DIMS + MEDIUM_DIMS_PER_BOUNCE b`.
pub const MEDIUM_DIMS: u32 = 0x10_0000;
/// The medium's random dimensions per bounce.
pub const MEDIUM_DIMS_PER_BOUNCE: u32 = 0x1000;
/// The most march steps per ray segment (the kernel's `MEDIUM_MAX_STEPS`).
pub const MEDIUM_MAX_STEPS: u32 = 1023;

/// The part (ta, tb) of the ray `o + t d`, t in [0, `t_end`], inside the
/// medium's box: the kernel's `medium_span`.
fn medium_span(m: &[f32; 16], o: V3, d: V3, t_end: f32) -> (f32, f32) {
    let (ix, iy, iz) = (1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    let (t0x, t1x) = ((m[0] - o.x) * ix, (m[4] - o.x) * ix);
    let (t0y, t1y) = ((m[1] - o.y) * iy, (m[5] - o.y) * iy);
    let (t0z, t1z) = ((m[2] - o.z) * iz, (m[6] - o.z) * iz);
    let ta = fmax(fmax(fmax(fmin(t0x, t1x), fmin(t0y, t1y)), fmin(t0z, t1z)), 0.0);
    let tb = fmin(fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmax(t0z, t1z)), t_end);
    (ta, tb)
}

/// The density at height `y`: the kernel's `medium_density`.
pub fn medium_density(m: &[f32; 16], y: f32) -> f32 {
    if m[10] > 0.0 { exp_neg(-fmax(y - m[1], 0.0) * m[10]) } else { 1.0 }
}

/// The density's integral along `o + t d` over [ta, tb]: the kernel's `medium_depth`.
fn medium_depth(m: &[f32; 16], o: V3, d: V3, ta: f32, tb: f32) -> f32 {
    if !(ta < tb) {
        return 0.0;
    }
    let len = tb - ta;
    if !(m[10] > 0.0) {
        return len;
    }
    let (ya, yb) = (o.y + ta * d.y, o.y + tb * d.y);
    let rho = medium_density(m, fmin(ya, yb));
    let x = d.y.abs() * m[10] * len;
    let f = if x < 1e-3 { 1.0 - x * (0.5 - x * (1.0 / 6.0)) } else { (1.0 - exp_neg(-x)) / x };
    rho * len * f
}

/// Beer's law along a shadow ray: the kernel's `medium_transmittance`.
fn medium_transmittance(m: &[f32; 16], x: V3, w: V3, dist: f32) -> f32 {
    let (ta, tb) = medium_span(m, x, w, dist);
    exp_neg(-(m[8] + m[9]) * medium_depth(m, x, w, ta, tb))
}

/// Henyey-Greenstein for the cosine `c` between the light's and the viewer's
/// direction of travel: the kernel's `hg`.
pub fn hg(g: f32, c: f32) -> f32 {
    let den = 1.0 + g * g - 2.0 * g * c;
    (1.0 - g * g) * (0.25 * INV_PI) / (den * den.sqrt())
}

/// The Fresnel term of a smooth dielectric surface (glass, translucent) of
/// material `mat` (IOR `mat[7]`, exact when `mat[9]` > 0, else Schlick's
/// with (1 − c)^5 by multiplication) for the ray entering (`into`) at
/// `cos_i`, refracting at `cos_t` with `eta` = n_i / n_t: the kernel's
/// switch in `scatter` (glass) and `translucent`.
fn surface_fresnel(mat: &[f32; 12], into: bool, eta: f32, cos_i: f32, cos_t: f32) -> f32 {
    if mat[9] > 0.0 {
        return fresnel_exact(eta, cos_i, cos_t);
    }
    let ior = mat[7];
    let mut r0 = (1.0 - ior) / (1.0 + ior);
    r0 = r0 * r0;
    let c = 1.0 - if into { cos_i } else { cos_t };
    let c2 = c * c;
    r0 + (1.0 - r0) * (c2 * c2 * c)
}

/// A direction from Henyey-Greenstein about the unit direction of travel `d`
/// (forward peak for g > 0, as [`hg`]) from uniforms `y1` (the cosine) and
/// `y2` (the azimuth): the kernel's `hg_dir`.
fn hg_dir(g: f32, d: V3, y1: f32, y2: f32) -> V3 {
    let mut c = if g.abs() < 1e-3 {
        1.0 - 2.0 * y1
    } else {
        let q = (1.0 - g * g) / (1.0 - g + 2.0 * g * y1);
        (1.0 + g * g - q * q) / (2.0 * g)
    };
    c = fmin(fmax(c, -1.0), 1.0);
    let sn = fmax(1.0 - c * c, 0.0).sqrt();
    let (ca, sa) = azimuth(y2);
    let (b1, b2) = basis(d);
    b1.scale(sn * ca).add(b2.scale(sn * sa)).add(d.scale(c)).normalize()
}

/// Russian roulette on the bounce's mask `wgt` = f cos / p: the kernel's
/// `roulette` (continue with q = its max RGB, then divide by q); under
/// [`Termination::FixedDepth`] the mask only (the kernel's `PATH_FIXED_DEPTH` build).
fn roulette<S: Sample>(t: Termination, beta: &mut V3, wgt: V3, key: S, dim: u32) -> bool {
    if t == Termination::FixedDepth {
        *beta = beta.mul(wgt);
        return true;
    }
    let q = fmax(fmax(wgt.x, wgt.y), wgt.z);
    if q < 1.0 {
        if !(key.at(dim + 5) < q) {
            return false;
        }
        *beta = v3(beta.x * (wgt.x / q), beta.y * (wgt.y / q), beta.z * (wgt.z / q));
    } else {
        *beta = beta.mul(wgt);
    }
    true
}

/// A cosine-weighted direction about the unit `n` from uniforms `y1` (the
/// radius √y1 on the disc) and `y2` (the azimuth), and its cosine with `n`:
/// the kernel's `cosine_dir`.
fn cosine_dir(n: V3, y1: f32, y2: f32) -> (V3, f32) {
    let r = y1.sqrt();
    let (cs, sn) = azimuth(y2);
    let lz = fmax(1.0 - y1, 0.0).sqrt();
    let (b1, b2) = basis(n);
    (b1.scale(r * cs).add(b2.scale(r * sn)).add(n.scale(lz)), lz)
}

/// PTX min.f32: the non-NaN operand if one is NaN.
fn fmin(a: f32, b: f32) -> f32 {
    a.min(b)
}

/// PTX max.f32: the non-NaN operand if one is NaN.
fn fmax(a: f32, b: f32) -> f32 {
    a.max(b)
}

/// The ray's exit distance from node box `b` (`[lo, parent, hi, 0]`): the kernel's `box_exit`.
fn box_exit(b: &[f32; 8], o: V3, inv: V3) -> f32 {
    let (t0x, t1x) = ((b[0] - o.x) * inv.x, (b[4] - o.x) * inv.x);
    let (t0y, t1y) = ((b[1] - o.y) * inv.y, (b[5] - o.y) * inv.y);
    let (t0z, t1z) = ((b[2] - o.z) * inv.z, (b[6] - o.z) * inv.z);
    fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmax(t0z, t1z))
}

/// ln x for a normal positive `x`: the kernel's `ln` (x = 2^e m, m in
/// [√½, √2), 2 atanh((m − 1)/(m + 1)) by its series to s^11).
pub fn ln(x: f32) -> f32 {
    let bits = x.to_bits() as i32;
    let mut e = ((bits >> 23) & 255) - 127;
    let mut m = f32::from_bits(((bits & 0x7f_ffff) | 0x3f80_0000) as u32);
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let sv = (m - 1.0) / (m + 1.0);
    let s2 = sv * sv;
    let poly = 1.0 + s2 * (1.0 / 3.0 + s2 * (0.2 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0 + s2 * (1.0 / 11.0)))));
    e as f32 * std::f32::consts::LN_2 + 2.0 * sv * poly
}

/// e^x for x ≤ 0 (0 below −87): the kernel's `exp_neg` (Cody-Waite
/// reduction by two parts of ln 2, Taylor series to r^7).
pub fn exp_neg(x: f32) -> f32 {
    if x < -87.0 {
        return 0.0;
    }
    let n = (x * std::f32::consts::LOG2_E + 0.5).floor();
    let r = x - n * 0.693_145_75 - n * 1.428_606_8e-6; // the kernel's two parts of ln 2, as f32
    let poly = 1.0
        + r * (1.0
            + r * 0.5 * (1.0 + r / 3.0 * (1.0 + r * 0.25 * (1.0 + r * 0.2 * (1.0 + r / 6.0 * (1.0 + r / 7.0))))));
    poly * f32::from_bits(((n as i32 + 127) << 23) as u32)
}

/// Beckmann's distribution for α² = `a2` at a microfacet normal of cosine
/// `cm` with the macro normal: the kernel's `beckmann`.
pub fn beckmann(a2: f32, cm: f32) -> f32 {
    if !(cm > 0.0) {
        return 0.0;
    }
    let c2 = cm * cm;
    let tan2 = (1.0 - c2) / c2;
    exp_neg(-tan2 / a2) / (std::f32::consts::PI * a2 * (c2 * c2))
}

/// The thesis' anisotropic Beckmann lobe of a mirror (§5.1, 003:L346-352):
/// α_x along `b1`, α_y along `b2` of Duff et al.'s basis around the face's
/// winding normal: the kernel's `Aniso`.
#[derive(Clone, Copy, Debug)]
struct Aniso {
    b1: V3,
    b2: V3,
    ax: f32,
    ay: f32,
}

impl Aniso {
    /// The kernel's `aniso`.
    fn new(n: V3, ax: f32, ay: f32) -> Aniso {
        let (b1, b2) = basis(n);
        Aniso { b1, b2, ax, ay }
    }

    /// D_aniso of the unit microfacet normal `m` of cosine `cm` with the
    /// macro normal: the kernel's `beckmann_aniso`.
    fn d(&self, m: V3, cm: f32) -> f32 {
        if !(cm > 0.0) {
            return 0.0;
        }
        let (x, y) = (m.dot(self.b1) / self.ax, m.dot(self.b2) / self.ay);
        let c2 = cm * cm;
        exp_neg(-(x * x + y * y) / c2) / (std::f32::consts::PI * self.ax * self.ay * (c2 * c2))
    }

    /// The roughness Smith's G1 sees along the unit `v`: the kernel's `alpha_along`.
    fn along(&self, v: V3) -> f32 {
        let (x, y) = (v.dot(self.b1), v.dot(self.b2));
        let r2 = x * x + y * y;
        if !(r2 > 0.0) {
            return self.ax;
        }
        ((x * x * (self.ax * self.ax) + y * y * (self.ay * self.ay)) / r2).sqrt()
    }

    /// A microfacet normal from D_aniso cos on the side of `ns`, and its
    /// cosine: the kernel's `sample_aniso` (the thesis' φ and θ, 003:L350-352).
    fn sample(&self, ns: V3, y1: f32, y2: f32) -> (V3, f32) {
        let (c, sn) = azimuth(y2);
        let (ex, ey) = (self.ax * c, self.ay * sn);
        let r = 1.0 / (ex * ex + ey * ey).sqrt();
        let (cp, sp) = (ex * r, ey * r);
        let tan2 = -ln(1.0 - y1) / (cp * cp / (self.ax * self.ax) + sp * sp / (self.ay * self.ay));
        let cm = 1.0 / (1.0 + tan2).sqrt();
        let sm = tan2.sqrt() * cm;
        (self.b1.scale(sm * cp).add(self.b2.scale(sm * sp)).add(ns.scale(cm)), cm)
    }
}

/// Smith's masking by Walter et al. 2007's rational approximation for
/// Beckmann: the kernel's `smith_g1` (`cv`, `cvm` the direction's cosines
/// with the macro and the microfacet normal).
pub fn smith_g1(alpha: f32, cv: f32, cvm: f32) -> f32 {
    if !(cvm * cv > 0.0) {
        return 0.0;
    }
    let acv = cv.abs();
    let a = acv / (alpha * fmax(1.0 - acv * acv, 0.0).sqrt());
    if a >= 1.6 {
        return 1.0;
    }
    (3.535 * a + 2.181 * (a * a)) / (1.0 + 2.276 * a + 2.577 * (a * a))
}

/// Schlick's Fresnel term: the kernel's `schlick`.
pub fn schlick(r0: f32, c: f32) -> f32 {
    let x = 1.0 - c;
    let x2 = x * x;
    r0 + (1.0 - r0) * (x2 * x2 * x)
}

/// Ashikhmin and Shirley's transmission factor of the coupled diffuse lobe
/// (thesis 003 §4.5, 003:L261-263), 1 − (1 − c/2)^5, the power by
/// multiplication: the kernel's `as_factor`. Over the hemisphere,
/// ∫ as_factor(cos θ) cos θ dω = 23π/28, whence the lobe's 28/23.
pub fn as_factor(c: f32) -> f32 {
    let x = 1.0 - 0.5 * c;
    let x2 = x * x;
    1.0 - x2 * x2 * x
}

/// A coated material's Schlick reflectance at normal incidence from the
/// coat's IOR (003:L255): the kernel's `coat_r0`.
pub fn coat_r0(ior: f32) -> f32 {
    let r0 = (1.0 - ior) / (1.0 + ior);
    r0 * r0
}

/// The exact Fresnel reflectance of a dielectric for the incident cosine
/// `ci` and the transmitted cosine `ct`, `eta` = n_i / n_t (the mean of the s
/// and p reflectances): the kernel's `fresnel_exact`.
pub fn fresnel_exact(eta: f32, ci: f32, ct: f32) -> f32 {
    let rs = (eta * ci - ct) / (eta * ci + ct);
    let rp = (ci - eta * ct) / (ci + eta * ct);
    0.5 * (rs * rs + rp * rp)
}

/// Duff et al.'s orthonormal basis around the unit `n`.
fn basis(n: V3) -> (V3, V3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (v3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), v3(b, sign + n.y * n.y * a, -n.y))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel's ln and e^x (no SFU instruction) are within a few float
    /// ulps of f64's over the ranges the shading uses.
    #[test]
    fn ln_and_exp_neg_agree_with_f64() {
        for k in 1..=(1 << 12) {
            let x = k as f32 / 4096.0; // (0, 1]: 1 - y of the Beckmann sample
            let want = (x as f64).ln();
            assert!((ln(x) as f64 - want).abs() <= 2e-7 * want.abs().max(1.0), "ln {x}: {} vs {want}", ln(x));
        }
        assert_eq!(ln(1.0), 0.0);
        assert!((ln(2.0f32.powi(-24)) as f64 + 24.0 * std::f64::consts::LN_2).abs() < 1e-5);
        for k in 0..=4000 {
            let x = -(k as f32) * 0.0215; // [0, -86]
            let want = (x as f64).exp();
            assert!((exp_neg(x) as f64 - want).abs() <= 4e-7 * want, "exp {x}: {} vs {want}", exp_neg(x));
        }
        assert_eq!(exp_neg(0.0), 1.0);
        assert_eq!(exp_neg(-100.0), 0.0);
    }

    /// Henyey-Greenstein is a distribution over the sphere (∫ p dω = 1)
    /// whose mean cosine is g, and 1 / 4π for g = 0 (midpoint rule in θ).
    #[test]
    fn henyey_greenstein_integrates_to_one_with_mean_cosine_g() {
        for g in [-0.5f32, 0.0, 0.3, 0.7] {
            let n = 40_000;
            let h = std::f64::consts::PI / n as f64;
            let (mut total, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let th = (i as f64 + 0.5) * h;
                let w = hg(g, th.cos() as f32) as f64 * th.sin() * 2.0 * std::f64::consts::PI * h;
                total += w;
                mean += w * th.cos();
            }
            assert!((total - 1.0).abs() < 2e-3, "g {g}: {total}");
            assert!((mean - g as f64).abs() < 2e-3, "g {g}: mean cosine {mean}");
        }
        assert!((hg(0.0, 0.3) - 0.25 / std::f32::consts::PI).abs() < 1e-7);
    }

    /// `hg_dir` samples Henyey-Greenstein about the direction of travel: unit
    /// directions whose mean cosine is g and whose cosines fall into 8 bins
    /// as the density integrates over them (stratified cosines, hashed
    /// azimuths), for forward, backward and (near) isotropic g.
    #[test]
    fn hg_dir_samples_henyey_greenstein() {
        let d = v3(0.36, 0.48, 0.8);
        for g in [-0.6f32, -0.3, 0.0, 0.0005, 0.5, 0.9] {
            let n = 100_000u32;
            let (mut mean, mut bins) = (0.0f64, [0u32; 8]);
            for i in 0..n {
                let y1 = (i as f32 + 0.5) / n as f32;
                let y2 = (i.wrapping_mul(2_654_435_761) >> 8) as f32 / 16_777_216.0;
                let w = hg_dir(g, d, y1, y2);
                assert!((w.dot(w) - 1.0).abs() < 1e-5, "g {g}: not unit");
                let c = w.dot(d).clamp(-1.0, 1.0) as f64;
                mean += c;
                bins[(((c + 1.0) * 4.0) as usize).min(7)] += 1;
            }
            mean /= n as f64;
            assert!((mean - g as f64).abs() < 2e-3, "g {g}: mean cosine {mean}");
            for (k, &b) in bins.iter().enumerate() {
                // the density's mass in [c0, c1]: 2 pi x the midpoint sum of hg over the cosine
                let (c0, m) = (-1.0 + 0.25 * k as f64, 2000);
                let want: f64 =
                    (0..m).map(|j| hg(g, (c0 + (j as f64 + 0.5) * 0.25 / m as f64) as f32) as f64).sum::<f64>() * 0.25
                        / m as f64
                        * 2.0
                        * std::f64::consts::PI;
                let got = b as f64 / n as f64;
                assert!((got - want).abs() < 2e-3 + 0.01 * want, "g {g}, bin {k}: {got} against {want}");
            }
        }
    }

    /// The optical depth per unit σ_t: the segment's length inside the box
    /// for a uniform density; for e^(−(y − lo.y)/H) the closed form equals
    /// a fine midpoint sum along the ray, steep, shallow (the series branch)
    /// and horizontal; Beer's law on the shadow ray is e^(−σ_t depth).
    #[test]
    fn the_optical_depth_is_the_densitys_integral() {
        let mut m = [0.0f32; 16];
        m[..3].copy_from_slice(&[-1.0, 0.0, -1.0]);
        m[4..7].copy_from_slice(&[1.0, 2.0, 1.0]);
        m[8] = 0.5;
        m[9] = 1.0;
        let o = v3(-3.0, 0.5, 0.0);
        let d = v3(1.0, 0.0, 0.0);
        assert_eq!(medium_span(&m, o, d, f32::INFINITY), (2.0, 4.0));
        assert_eq!(medium_span(&m, o, d, 3.0), (2.0, 3.0));
        assert_eq!(medium_depth(&m, o, d, 2.0, 4.0), 2.0);
        let t = medium_transmittance(&m, o, d, 10.0);
        assert!((t as f64 - (-1.5f64 * 2.0).exp()).abs() < 1e-6, "{t}");
        m[10] = 1.0 / 0.5; // H = 0.5
        for (dir, ta, tb) in [
            (v3(0.6, 0.8, 0.0), 0.1f32, 2.0f32),
            (v3(0.6, -0.8, 0.0), 0.0, 0.5),
            (v3(1.0, 1e-4, 0.0), 0.0, 2.0),
            (v3(1.0, 0.0, 0.0), 0.0, 2.0),
        ] {
            let o = v3(-1.0, 0.5, 0.0);
            let n = 100_000;
            let h = (tb - ta) as f64 / n as f64;
            let want: f64 = (0..n)
                .map(|i| {
                    let y = o.y as f64 + (ta as f64 + (i as f64 + 0.5) * h) * dir.y as f64;
                    (-(y - m[1] as f64).max(0.0) * 2.0).exp() * h
                })
                .sum();
            let got = medium_depth(&m, o, dir, ta, tb) as f64;
            assert!((got - want).abs() < 1e-5 * want.max(1.0), "{dir:?}: {got} vs {want}");
        }
    }

    /// Beckmann's D is normalised: ∫ D(m) cos θ_m dω_m = 1 (midpoint rule in θ).
    #[test]
    fn beckmann_projects_to_one() {
        for alpha in [0.05f32, 0.2, 0.5, 1.0] {
            let a2 = alpha * alpha;
            let n = 20_000;
            let h = std::f64::consts::FRAC_PI_2 / n as f64;
            let integral: f64 = (0..n)
                .map(|i| {
                    let th = (i as f64 + 0.5) * h;
                    beckmann(a2, th.cos() as f32) as f64 * th.cos() * th.sin() * 2.0 * std::f64::consts::PI * h
                })
                .sum();
            assert!((integral - 1.0).abs() < 2e-3, "alpha {alpha}: {integral}");
        }
    }

    /// The anisotropic lobe (003:L346): normalised, ∫ D_aniso(m) cos θ_m dω_m
    /// = 1 (midpoint rule in θ and φ), and Beckmann's isotropic D when α_x = α_y.
    #[test]
    fn the_anisotropic_beckmann_projects_to_one() {
        let n = v3(0.0, 0.0, 1.0);
        for (ax, ay) in [(0.05f32, 0.4f32), (0.2, 0.6), (0.5, 0.1), (0.3, 0.3)] {
            let a = Aniso::new(n, ax, ay);
            let (nt, np) = (4000, 512);
            let (ht, hp) = (std::f64::consts::FRAC_PI_2 / nt as f64, 2.0 * std::f64::consts::PI / np as f64);
            let mut integral = 0.0f64;
            for i in 0..nt {
                let th = (i as f64 + 0.5) * ht;
                for j in 0..np {
                    let ph = (j as f64 + 0.5) * hp;
                    let m = v3((th.sin() * ph.cos()) as f32, (th.sin() * ph.sin()) as f32, th.cos() as f32);
                    integral += a.d(m, m.z) as f64 * th.cos() * th.sin() * ht * hp;
                }
            }
            assert!((integral - 1.0).abs() < 3e-3, "alpha ({ax}, {ay}): {integral}");
        }
        let (iso, a) = (Aniso::new(n, 0.3, 0.3), 0.3f32);
        for c in [0.2f32, 0.5, 0.9, 1.0] {
            let m = v3((1.0 - c * c).sqrt() * 0.6, (1.0 - c * c).sqrt() * 0.8, c);
            let (x, y) = (iso.d(m, c), beckmann(a * a, c));
            assert!((x - y).abs() <= 1e-5 * y.max(1.0), "cos {c}: {x} vs {y}");
            assert!((iso.along(m) - a).abs() < 1e-6);
        }
    }

    /// Smith's G1 of the anisotropic lobe sees α_x along b1, α_y along b2
    /// (Mitsuba's projected roughness), not the printed 1 / (cos²φ / α_x² +
    /// sin²φ / α_y²) of 003:L357 nor its square root: at 45°, √((α_x² + α_y²) / 2).
    #[test]
    fn the_anisotropic_g1_sees_the_projected_roughness() {
        let a = Aniso::new(v3(0.0, 0.0, 1.0), 0.1, 0.5);
        let along = |x: f32, y: f32| a.along(v3(x, y, 0.7));
        assert!((along(0.3, 0.0) - 0.1).abs() < 1e-7 && (along(0.0, -0.3) - 0.5).abs() < 1e-7);
        let diag = along(0.3, 0.3);
        assert!((diag - (0.13f32).sqrt()).abs() < 1e-6, "{diag}");
        // the printed term at 45° (units of α²), and its square root (the extract's reading)
        let printed = 1.0 / (0.5 / (0.1f32 * 0.1) + 0.5 / (0.5 * 0.5));
        assert!((diag - printed).abs() > 0.3 && (diag - printed.sqrt()).abs() > 0.2, "{diag} vs {printed}");
        // ... which agrees with the projected roughness along the axes only
        let root = |c2: f32, s2: f32| (1.0 / (c2 / (0.1f32 * 0.1) + s2 / (0.5 * 0.5))).sqrt();
        assert!((root(1.0, 0.0) - along(0.3, 0.0)).abs() < 1e-6 && (root(0.0, 1.0) - along(0.0, 0.3)).abs() < 1e-6);
        assert_eq!(a.along(v3(0.0, 0.0, 1.0)), 0.1, "along the normal: any alpha (G1 = 1)");
    }

    /// The kernel's sample is the thesis' formulas (003:L350-352) with the
    /// quadrant fix-up: φ = arctan(α_y / α_x tan 2πξ1) in 2πξ1's quadrant,
    /// θ = arctan √(−log ξ2 / (cos²φ / α_x² + sin²φ / α_y²)), ξ2 = 1 − y1;
    /// and its slopes m_x / m_z, m_y / m_z have Beckmann's variances α_x² / 2
    /// and α_y² / 2 (the lobe it samples is D_aniso cos).
    #[test]
    fn the_anisotropic_sample_is_the_thesis_formula() {
        let (ax, ay) = (0.08f32, 0.45f32);
        let a = Aniso::new(v3(0.0, 0.0, 1.0), ax, ay);
        let n = 400_000u32;
        let (mut sx, mut sy) = (0.0f64, 0.0f64);
        for i in 0..n {
            // a 2-D low-discrepancy set: i / n and the golden ratio's multiples
            let y1 = (i as f64 + 0.5) / n as f64;
            let y2 = ((i as f64) * 0.618_033_988_749_894_9).fract();
            let (m, cm) = a.sample(v3(0.0, 0.0, 1.0), y1 as f32, y2 as f32);
            assert!((m.z - cm).abs() < 1e-6 && (m.dot(m) - 1.0).abs() < 1e-5, "{m:?}");
            if i % 97 == 0 {
                let t = 2.0 * std::f64::consts::PI * y2;
                let mut ph = ((ay / ax) as f64 * t.tan()).atan();
                if t.cos() < 0.0 {
                    ph += std::f64::consts::PI; // the quadrant of 2πξ1
                }
                let (cp, sp) = (ph.cos(), ph.sin());
                let xi2 = 1.0 - y1;
                let th = (-xi2.ln() / (cp * cp / (ax * ax) as f64 + sp * sp / (ay * ay) as f64)).sqrt().atan();
                let want = [th.sin() * cp, th.sin() * sp, th.cos()];
                let got = [m.x as f64, m.y as f64, m.z as f64];
                for k in 0..3 {
                    assert!((got[k] - want[k]).abs() < 2e-5, "y ({y1}, {y2}): {got:?} vs {want:?}");
                }
            }
            sx += ((m.x / m.z) as f64).powi(2);
            sy += ((m.y / m.z) as f64).powi(2);
        }
        let (vx, vy) = (sx / n as f64, sy / n as f64);
        let (wx, wy) = ((ax * ax) as f64 / 2.0, (ay * ay) as f64 / 2.0);
        assert!((vx / wx - 1.0).abs() < 0.01 && (vy / wy - 1.0).abs() < 0.01, "{vx} vs {wx}, {vy} vs {wy}");
    }

    /// Smith's G1 by Walter et al.'s approximation: 1 at normal incidence,
    /// 0 seen from a microfacet's back, falling toward grazing, and the
    /// printed rational function at a = 1 (3.535 + 2.181) / (1 + 2.276 + 2.577).
    #[test]
    fn smith_g1_follows_walter() {
        assert_eq!(smith_g1(0.3, 1.0, 1.0), 1.0);
        assert_eq!(smith_g1(0.3, 0.5, -0.1), 0.0);
        let (g_mid, g_low) = (smith_g1(0.5, 0.3, 0.3), smith_g1(0.5, 0.1, 0.1));
        assert!(g_low < g_mid && g_mid < 1.0, "{g_low} {g_mid}");
        // a = cos / (alpha sin) = 1 at cos = alpha / sqrt(1 + alpha^2)
        let alpha = 0.5f32;
        let c = alpha / (1.0 + alpha * alpha).sqrt();
        let want = (3.535 + 2.181) / (1.0 + 2.276 + 2.577);
        assert!((smith_g1(alpha, c, c) - want).abs() < 1e-5);
        assert_eq!(schlick(1.0, 0.2), 1.0, "R0 = 1 reflects everything (the Mitsuba comparison's case)");
        assert!((schlick(0.04, 0.0) - 1.0).abs() < 1e-6 && schlick(0.04, 1.0) == 0.04);
    }

    /// The exact dielectric Fresnel term: ((n - 1) / (n + 1))^2 = 0.04 at
    /// normal incidence for n = 1.5 from either side, 1 at grazing
    /// incidence, Brewster's angle (tan θ = n) zeroes r_p so F = r_s² / 2,
    /// and it differs from Schlick's by a few percent between.
    #[test]
    fn exact_fresnel_follows_the_equations() {
        let n = 1.5f32;
        assert!((fresnel_exact(1.0 / n, 1.0, 1.0) - 0.04).abs() < 1e-7);
        assert!((fresnel_exact(n, 1.0, 1.0) - 0.04).abs() < 1e-7);
        assert!((fresnel_exact(1.0 / n, 0.0, (1.0 - 1.0 / (n * n)).sqrt()) - 1.0).abs() < 1e-6);
        let (ci, eta) = (1.0 / (1.0 + n * n).sqrt(), 1.0 / n);
        let ct = (1.0 - eta * eta * (1.0 - ci * ci)).sqrt();
        let rs = (eta * ci - ct) / (eta * ci + ct);
        assert!((fresnel_exact(eta, ci, ct) - 0.5 * rs * rs).abs() < 1e-7, "Brewster: r_p = 0");
        let ci = 0.3f32;
        let ct = (1.0 - eta * eta * (1.0 - ci * ci)).sqrt();
        let (exact, approx) = (fresnel_exact(eta, ci, ct), schlick(0.04, ci));
        assert!(exact != approx && (exact - approx).abs() < 0.03, "{exact} vs Schlick {approx}");
    }
}
