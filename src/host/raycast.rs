//! The native-Rust reference ray caster: stack-based kd-tree traversal (thesis
//! 000 §3.2.4.1, the reconstruction in the seed extract §4.4), Wald's triangle
//! test (Alg. 3.3) and Whitted shading — a primary ray, a mirror reflection
//! ray where the surface seen is specular, and a shadow ray from each point
//! light toward each hit (as the thesis casts them): up to four rays per pixel. It is the oracle for the
//! ray-tracing kernels and the native speed baseline.

use glam::Vec3;

use super::camera::{Camera, Ray};
use super::image::FrameBuffer;
use super::kdtree::layout::wald;
use super::kdtree::{KdTree, Node};
use super::scene::{Light, MaterialKind, Scene};

/// Ray-epsilon fixture: offsets and interval expansion, relative to the scene diagonal.
pub const EPS_REL: f32 = 1e-5;

/// A triangle in Wald's precomputed form.
#[derive(Debug, Clone, Copy)]
pub struct WaldTri {
    /// Projection axis.
    pub k: u32,
    /// n'.
    pub n: [f32; 3],
    /// e'1.
    pub e1: [f32; 3],
    /// e'2.
    pub e2: [f32; 3],
}

/// A hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of vertex 1.
    pub u: f32,
    /// Barycentric weight of vertex 2.
    pub v: f32,
    /// Triangle index.
    pub tri: u32,
}

/// Work counted while tracing (the quantities of Table 4.3 and more).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct TraceStats {
    /// Rays traced.
    pub rays: u64,
    /// Primary rays.
    pub primary: u64,
    /// Reflection rays.
    pub reflection: u64,
    /// Shadow rays.
    pub shadow: u64,
    /// Inner-node traversal steps.
    pub inner_nodes: u64,
    /// Leaves visited.
    pub leaves: u64,
    /// Triangle-plane intersections (Alg. 3.3 line 3).
    pub plane_tests: u64,
    /// Barycentric computations (Alg. 3.3 lines 7–8).
    pub barycentric_tests: u64,
    /// Stack pushes: every entry pushed, whether it went to the local-memory
    /// stack or (kernels with stack caches I and II) into registers. Stack
    /// cache I moving its old head to local memory is a local access
    /// (`local_stack_accesses`), not a push.
    pub pushes: u64,
    /// Inner-node fetches through the texture path (kernels; node-cache hits excluded).
    pub tex_node_fetches: u64,
    /// Pushes and pops that touched the local-memory stack (kernels; register-cached entries excluded).
    pub local_stack_accesses: u64,
    /// Texels fetched from texture maps (one per shaded hit on a textured material).
    pub texel_fetches: u64,
}

impl TraceStats {
    /// Adds `o`.
    pub fn merge(&mut self, o: &TraceStats) {
        self.rays += o.rays;
        self.primary += o.primary;
        self.reflection += o.reflection;
        self.shadow += o.shadow;
        self.inner_nodes += o.inner_nodes;
        self.leaves += o.leaves;
        self.plane_tests += o.plane_tests;
        self.barycentric_tests += o.barycentric_tests;
        self.pushes += o.pushes;
        self.tex_node_fetches += o.tex_node_fetches;
        self.local_stack_accesses += o.local_stack_accesses;
        self.texel_fetches += o.texel_fetches;
    }
}

/// A scene with its tree, ready to trace.
pub struct Caster<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Its kd-tree.
    pub tree: &'a KdTree,
    tris: Vec<WaldTri>,
    eps: f32,
}

impl<'a> Caster<'a> {
    /// Prepares `scene` traced through `tree` (built over the scene's triangles in order).
    pub fn new(scene: &'a Scene, tree: &'a KdTree) -> Self {
        let tris = scene
            .triangles
            .iter()
            .map(|t| {
                let (k, n, e1, e2) = wald(&t.v);
                WaldTri { k, n, e1, e2 }
            })
            .collect();
        let d = tree.bounds.size().length().max(1e-3);
        Caster { scene, tree, tris, eps: d * EPS_REL }
    }

    /// The ray epsilon used.
    pub fn eps(&self) -> f32 {
        self.eps
    }

    /// Alg. 3.3: updates `best` if triangle `i` is hit in [t_min, best.t].
    #[inline]
    fn test(&self, i: u32, o: Vec3, d: Vec3, t_min: f32, best: &mut Hit, st: &mut TraceStats) -> bool {
        let w = &self.tris[i as usize];
        let k = w.k as usize;
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        st.plane_tests += 1;
        let t = (w.n[2] - o[k] - w.n[0] * o[a] - w.n[1] * o[b]) / (d[k] + w.n[0] * d[a] + w.n[1] * d[b]);
        if !(t >= t_min && t <= best.t) {
            return false;
        }
        st.barycentric_tests += 1;
        let (hx, hy) = (o[a] + t * d[a], o[b] + t * d[b]);
        let u = w.e2[0] * hx + w.e2[1] * hy + w.e2[2];
        let v = w.e1[0] * hx + w.e1[1] * hy + w.e1[2];
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            return false;
        }
        *best = Hit { t, u, v, tri: i };
        true
    }

    /// Nearest hit in (t_min, t_max), or with `any` the first found (shadow rays).
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32, any: bool, st: &mut TraceStats) -> Option<Hit> {
        st.rays += 1;
        let (o, d) = (ray.origin, ray.dir);
        let inv = Vec3::ONE / d;
        // clip to the scene box
        let b = &self.tree.bounds;
        let (t0, t1) = ((b.lo - o) * inv, (b.hi - o) * inv);
        let (tn, tf) = (t0.min(t1), t0.max(t1));
        let mut ta = t_min.max(tn.max_element());
        let mut tb = t_max.min(tf.min_element());
        if ta.is_nan() || tb.is_nan() || ta > tb {
            return None;
        }
        let mut best = Hit { t: t_max, u: 0.0, v: 0.0, tri: u32::MAX };
        let mut stack: Vec<(u32, f32)> = Vec::with_capacity(self.tree.depth as usize + 1);
        let mut node = 0u32;
        loop {
            while let Node::Inner { axis, split, left, right } = self.tree.nodes[node as usize] {
                st.inner_nodes += 1;
                let k = axis as usize;
                let ts = (split - o[k]) * inv[k];
                let (near, far) = if d[k].is_sign_negative() { (right, left) } else { (left, right) };
                if ts > tb || ts.is_nan() {
                    node = near;
                } else if ts < ta {
                    node = far;
                } else {
                    st.pushes += 1;
                    stack.push((far, tb));
                    tb = ts;
                    node = near;
                }
            }
            st.leaves += 1;
            if let Node::Leaf { first, count } = self.tree.nodes[node as usize] {
                let lo = (ta - self.eps).max(t_min);
                let saved = best.t;
                best.t = best.t.min(tb + self.eps);
                let mut found = false;
                for &r in &self.tree.tri_refs[first as usize..(first + count) as usize] {
                    if self.test(r, o, d, lo, &mut best, st) {
                        found = true;
                        if any {
                            return Some(best);
                        }
                    }
                }
                if found {
                    return Some(best);
                }
                best.t = saved;
            }
            match stack.pop() {
                None => return None,
                Some((n, t)) => {
                    ta = tb;
                    tb = t;
                    node = n;
                }
            }
        }
    }

    /// Whitted shading of one camera ray (frame-relative light offset given).
    pub fn shade(&self, ray: &Ray, light_offset: Vec3, st: &mut TraceStats) -> [f32; 3] {
        st.primary += 1;
        let Some(h) = self.intersect(ray, self.eps, f32::INFINITY, false, st) else { return [0.0; 3] };
        let mut c = self.direct(ray, &h, light_offset, st);
        // a specular surface (a mirror, or a diffuse one with a specular part) reflects
        let w = self.scene.reflectance(self.scene.triangles[h.tri as usize].material);
        if w[0] > 0.0 || w[1] > 0.0 || w[2] > 0.0 {
            let n = self.normal(h.tri, ray.dir);
            let p = ray.origin + ray.dir * h.t;
            let r = Ray { origin: p, dir: (ray.dir - 2.0 * ray.dir.dot(n) * n).normalize() };
            st.reflection += 1;
            if let Some(h2) = self.intersect(&r, self.eps, f32::INFINITY, false, st) {
                let c2 = self.direct(&r, &h2, light_offset, st);
                for i in 0..3 {
                    c[i] += w[i] * c2[i];
                }
            }
        }
        c
    }

    /// The geometric normal of triangle `t`, facing against `dir`, from the
    /// Wald form (n_k = 1, n_i = n'_i, n_j = n'_j) as the kernels compute it.
    pub fn normal(&self, t: u32, dir: Vec3) -> Vec3 {
        let w = &self.tris[t as usize];
        let k = w.k as usize;
        let mut n = Vec3::ZERO;
        n[k] = 1.0;
        n[(k + 1) % 3] = w.n[0];
        n[(k + 2) % 3] = w.n[1];
        let n = n * (1.0 / (n.x * n.x + n.y * n.y + n.z * n.z).sqrt());
        if n.x * dir.x + n.y * dir.y + n.z * dir.z > 0.0 { -n } else { n }
    }

    /// Emission plus diffuse direct light from the point lights (one shadow ray each).
    fn direct(&self, ray: &Ray, h: &Hit, light_offset: Vec3, st: &mut TraceStats) -> [f32; 3] {
        let mi = self.scene.triangles[h.tri as usize].material;
        let m = &self.scene.materials[mi as usize];
        let mut c = m.emission;
        if m.kind != MaterialKind::Diffuse {
            return c;
        }
        // the diffuse colour, through the texture map at the hit's barycentric weights where there is one
        st.texel_fetches += self.scene.surface(mi).texture.is_some() as u64;
        let color = self.scene.diffuse_color(mi, h.tri, h.u, h.v);
        let p = ray.origin + ray.dir * h.t;
        let n = self.normal(h.tri, ray.dir);
        for l in &self.scene.lights {
            if let Light::Point { position, intensity } = l {
                let lp = Vec3::from(*position) + light_offset;
                // the shadow ray goes from the light toward the hit point (seed 000 L3411, L1561)
                let from = p - lp;
                let dist = from.length();
                let dir = from / dist;
                let cos = -n.dot(dir);
                if cos <= 0.0 {
                    continue;
                }
                st.shadow += 1;
                // occluded only if a hit lies before the surface by more than epsilon
                let sr = Ray { origin: lp, dir };
                if self.intersect(&sr, self.eps, dist - self.eps, true, st).is_some() {
                    continue;
                }
                let g = cos / (dist * dist) / std::f32::consts::PI;
                for i in 0..3 {
                    c[i] += color[i] * intensity[i] * g;
                }
            }
        }
        // a small ambient term keeps unlit surfaces visible
        for (ci, mc) in c.iter_mut().zip(color) {
            *ci += 0.02 * mc;
        }
        c
    }
}

/// Renders frame `frame` of the scene's flight with camera `camera` overriding
/// the resolution if given.
pub fn render(caster: &Caster, camera: &Camera, light_offset: Vec3) -> (FrameBuffer, TraceStats) {
    use rayon::prelude::*;
    let [w, h] = camera.resolution;
    let rows: Vec<(Vec<[f32; 3]>, TraceStats)> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut st = TraceStats::default();
            let row = (0..w).map(|x| caster.shade(&camera.ray(x, y), light_offset, &mut st)).collect();
            (row, st)
        })
        .collect();
    let mut fb = FrameBuffer::new(w, h);
    let mut st = TraceStats::default();
    for (y, (row, s)) in rows.into_iter().enumerate() {
        for (x, c) in row.into_iter().enumerate() {
            fb.set(x as u32, y as u32, c);
        }
        st.merge(&s);
    }
    (fb, st)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::kdtree::{BuildParams, Heuristic, build};
    use crate::host::procedural;
    use crate::host::scene::Scene;
    use std::path::Path;

    fn brute(scene: &Scene, ray: &Ray, eps: f32) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        for (i, t) in scene.triangles.iter().enumerate() {
            let (e1, e2) = (t.v[1] - t.v[0], t.v[2] - t.v[0]);
            let p = ray.dir.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                continue;
            }
            let s = ray.origin - t.v[0];
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = ray.dir.dot(q) / det;
            let tt = e2.dot(q) / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && tt > eps && best.is_none_or(|b| tt < b.1) {
                best = Some((i as u32, tt));
            }
        }
        best
    }

    #[test]
    fn traversal_finds_the_nearest_hit_like_brute_force() {
        let g = procedural::scene6();
        let scene = Scene::assemble("scene6", Path::new("x"), g.triangles, g.materials);
        let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
        for h in [Heuristic::Sah, Heuristic::Siroh] {
            let tree = build(&tris, BuildParams::thesis(h));
            let c = Caster::new(&scene, &tree);
            let cam = Camera {
                position: [4.5, 1.2, 4.7],
                direction: [-1.0, -0.1, -0.8],
                up: [0.0, 1.0, 0.0],
                fov_y: 80.0,
                resolution: [24, 24],
            };
            let mut st = TraceStats::default();
            for y in 0..24 {
                for x in 0..24 {
                    let r = cam.ray(x, y);
                    let got = c.intersect(&r, c.eps(), f32::INFINITY, false, &mut st).map(|h| h.t);
                    let exp = brute(&scene, &r, c.eps()).map(|b| b.1);
                    match (got, exp) {
                        (Some(a), Some(b)) => {
                            assert!((a - b).abs() < 1e-3 * b.max(1.0), "{h}: pixel {x},{y}: {a} vs {b}")
                        }
                        (a, b) => assert_eq!(a.is_some(), b.is_some(), "{h}: pixel {x},{y}"),
                    }
                }
            }
            assert!(st.inner_nodes > 0 && st.plane_tests >= st.barycentric_tests);
        }
    }
}
