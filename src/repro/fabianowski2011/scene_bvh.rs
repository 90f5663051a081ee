//! Thesis 000 §6.2 applied to ray tracing (Table 6.5, L2800, L2819–2825): a
//! BVH over the scene's triangles, built offline by the SAH of
//! [`super::sah::Params::SCENE`], in the complete representation of [AL09]
//! (**B**, 56 bytes a sibling pair: twelve planes and two references) and the
//! compact one (**C**, 32 bytes a pair, [`super::pm_layout::compact_pairs`]),
//! traversed on the emulator by `kernels/fabianowski2011/scenebvh.cu` and
//! natively here, step for step.
//!
//! B tests both children's boxes against the ray's [t_min, t_hit] and pushes
//! the farther pair alone (4 bytes; Table 6.5 (b): "only node pairs are pushed
//! onto the stack for it", so no t_a > t_max check); C runs Algorithm 6.1 on
//! the parent's interval and pushes the farther pair with its interval
//! [t_a, t_b] (12 bytes), skipping a popped entry when t_a > t_max (L2765).
//! Both clip the ray to the root's AABB first (a launch parameter, no node
//! traffic), intersect a hit leaf child at once (Wald's test, Alg. 3.3, as
//! [`crate::host::raycast::Caster`] does it) and visit the nearer of two hit
//! inner children first (by entry distance; the left on a tie).
//!
//! Under the thesis' simplified memory model (every access served on its own)
//! a pair fetch is two node accesses, so B moves 28 bytes per node access and
//! C 16, and each push or pop moves one entry: **Bytes_B = 28·NodeAcc +
//! 4·(pushes + pops)**, **Bytes_C = 16·NodeAcc + 12·(pushes + pops)**; with
//! every pushed entry popped that is the thesis' 28·NodeAcc + 8·StackAcc
//! (extract §3.13, StackAcc = entries pushed). [`trace_kernel`] reads node
//! accesses, pushes and pops off the emulator's per-instruction counters (the
//! `@count` lines) and the bytes off its memory model's read-only and local
//! traffic, independently.

use glam::Vec3;

use super::pm_layout::{self, PmKind, PmNode, PmTree, Traffic, Walk};
use super::sah::{self, Bounds};
use crate::host::camera::{Camera, Ray};
use crate::host::kdtree::layout::wald;
use crate::host::raycast::{Caster, Hit, TraceStats};
use crate::host::rt_kernels::{count_tags, tagged_counts};
use crate::host::scene::{Light, MaterialKind, Scene};
use crate::ptx::ir::Program;
use crate::sim::device::to_bytes;
use crate::sim::{Device, LaunchStats, Module, SimError};

/// The kernels' PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/fabianowski2011/scenebvh.ptx");
/// The kernels' CUDA source, whose `@count` tags name the lines counted.
pub const SOURCE: &str = include_str!("../../../kernels/fabianowski2011/scenebvh.cu");
const SOURCE_FILE: &str = "kernels/fabianowski2011/scenebvh.cu";
/// Entry: the complete layout ([AL09]).
pub const COMPLETE: &str = "trace_complete";
/// Entry: the compact layout with Algorithm 6.1.
pub const COMPACT: &str = "trace_compact";
/// Entry: the complete layout with t_a stacked for closest-hit rays (Table 6.5 (a)'s baseline).
pub const COMPLETE_TA: &str = "trace_complete_ta";
/// The leaf bit of a complete pair's reference word.
pub const LEAF_BIT: u32 = 0x8000_0000;
/// Words of a complete pair (56 bytes).
pub const COMPLETE_WORDS: usize = 14;
/// Words of a triangle record: k, n'\[3\], e'1\[3\], e'2\[3\], triangle, end flag.
pub const TRI_WORDS: usize = 12;
/// Floats of a ray record: origin\[3\], direction\[3\], t_min, t_max, any-hit, 3 unused.
pub const RAY_FLOATS: usize = 12;
/// Entries of the kernels' traversal stacks.
pub const STACK: usize = 64;
const NONE: u32 = u32::MAX;

/// Which layout a traversal reads.
pub use pm_layout::Layout;

/// The traversals of Table 6.5: part (b)'s two and part (a)'s older baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Traversal {
    /// B of (b): [AL09]'s complete pairs, the pair alone on the stack (4 bytes).
    Complete,
    /// B of (a): the complete pairs; a closest-hit ray stacks the pair with its
    /// entry distance t_a (8 bytes) and skips a popped entry when t_a > t_max,
    /// a shadow ray the pair alone (4 bytes).
    CompleteTa,
    /// C of both: the compact pairs with Algorithm 6.1, pair and [t_a, t_b] stacked (12 bytes).
    Compact,
}

impl From<Layout> for Traversal {
    fn from(l: Layout) -> Traversal {
        match l {
            Layout::Complete => Traversal::Complete,
            Layout::Compact => Traversal::Compact,
        }
    }
}

impl Traversal {
    /// The kernel's entry in `scenebvh.cu`.
    pub fn entry(self) -> &'static str {
        match self {
            Traversal::Complete => COMPLETE,
            Traversal::CompleteTa => COMPLETE_TA,
            Traversal::Compact => COMPACT,
        }
    }

    /// The layout it reads.
    pub fn layout(self) -> Layout {
        match self {
            Traversal::Complete | Traversal::CompleteTa => Layout::Complete,
            Traversal::Compact => Layout::Compact,
        }
    }
}

/// The scene BVH in both layouts.
#[derive(Debug, Clone, Default)]
pub struct SceneBvh {
    /// The tree (root inner), leaves over [`PmTree::order`] = triangle indices.
    pub tree: PmTree,
    /// The root's AABB.
    pub root: Bounds,
    /// B: 56-byte pairs; pair 0 holds the root's children.
    pub complete: Vec<[u32; COMPLETE_WORDS]>,
    /// C: 32-byte pairs; pair 0 holds the root's children.
    pub compact: Vec<[u32; 8]>,
    /// Triangle records in leaf order.
    pub tris: Vec<[u32; TRI_WORDS]>,
}

/// The tree with an inner root: a root leaf is halved (a single triangle is
/// referenced by both children).
fn rooted(t: &PmTree) -> PmTree {
    let mut t = t.clone();
    if let Some(&PmNode { lo, hi, kind: PmKind::Leaf { first, count } }) = t.nodes.first() {
        let half = count.div_ceil(2);
        let second = if count > 1 { (first + half, count - half) } else { (first, count) };
        let a = PmNode { lo, hi, kind: PmKind::Leaf { first, count: half } };
        let b = PmNode { lo, hi, kind: PmKind::Leaf { first: second.0, count: second.1 } };
        t.nodes = vec![PmNode { lo, hi, kind: PmKind::Inner([1, 2]) }, a, b];
    }
    t
}

/// The AABB of each triangle of `scene`.
pub fn triangle_boxes(scene: &Scene) -> Vec<Bounds> {
    scene
        .triangles
        .iter()
        .map(|t| {
            let lo = t.v[0].min(t.v[1]).min(t.v[2]);
            let hi = t.v[0].max(t.v[1]).max(t.v[2]);
            [lo.to_array(), hi.to_array()]
        })
        .collect()
}

impl SceneBvh {
    /// Builds the SAH BVH of Table 6.5 over `scene`'s triangles and lays it out.
    pub fn build(scene: &Scene) -> SceneBvh {
        let tree = sah::build(&triangle_boxes(scene), &sah::Params::SCENE);
        SceneBvh::layout(scene, &tree)
    }

    /// Lays out `tree` (over `scene`'s triangles).
    pub fn layout(scene: &Scene, tree: &PmTree) -> SceneBvh {
        let mut out = SceneBvh::default();
        if tree.nodes.is_empty() {
            return out;
        }
        let t = rooted(tree);
        out.root = [t.nodes[0].lo, t.nodes[0].hi];
        // triangle records, one run per leaf
        for n in &t.nodes {
            if let PmKind::Leaf { first, count } = n.kind {
                for pos in first..first + count {
                    let tri = t.order[pos as usize];
                    let (k, np, e1, e2) = wald(&scene.triangles[tri as usize].v);
                    let mut w = [0u32; TRI_WORDS];
                    w[0] = k;
                    for c in 0..3 {
                        w[1 + c] = np[c].to_bits();
                        w[4 + c] = e1[c].to_bits();
                        w[7 + c] = e2[c].to_bits();
                    }
                    w[10] = tri;
                    w[11] = if pos + 1 == first + count { 1.0f32.to_bits() } else { 0 };
                    out.tris.push(w);
                }
            }
        }
        // the records follow the leaves' positions
        let mut at = vec![0u32; t.order.len()];
        let mut next = 0u32;
        for n in &t.nodes {
            if let PmKind::Leaf { first, count } = n.kind {
                for pos in first..first + count {
                    at[pos as usize] = next;
                    next += 1;
                }
            }
        }
        let mut t = t;
        for n in &mut t.nodes {
            if let PmKind::Leaf { first, .. } = &mut n.kind
                && let Some(&a) = at.get(*first as usize)
            {
                *first = a;
            }
        }
        // B: breadth first over the inner nodes, one pair for each one's children
        out.complete.push([0; COMPLETE_WORDS]);
        let mut todo = std::collections::VecDeque::from([(0u32, 0usize)]);
        while let Some((i, pair)) = todo.pop_front() {
            let PmKind::Inner(kids) = t.nodes[i as usize].kind else { continue };
            let mut w = [0u32; COMPLETE_WORDS];
            for (side, kid) in kids.into_iter().enumerate() {
                let n = t.nodes[kid as usize];
                for c in 0..3 {
                    w[6 * side + c] = n.lo[c].to_bits();
                    w[6 * side + 3 + c] = n.hi[c].to_bits();
                }
                w[12 + side] = match n.kind {
                    PmKind::Leaf { first, .. } => first | LEAF_BIT,
                    PmKind::Inner(_) => {
                        let p = out.complete.len();
                        out.complete.push([0; COMPLETE_WORDS]);
                        todo.push_back((kid, p));
                        p as u32
                    }
                };
            }
            out.complete[pair] = w;
        }
        out.compact = pm_layout::compact_pairs(&t);
        out.tree = t;
        out
    }

    /// Nodes of the tree (inner and leaves, the root included).
    pub fn nodes(&self) -> usize {
        self.tree.nodes.len()
    }
}

/// A ray to trace: the closest hit in [t_min, t_max], or with `any` the first found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceRay {
    /// Origin.
    pub origin: [f32; 3],
    /// Direction.
    pub dir: [f32; 3],
    /// Nearest t accepted.
    pub t_min: f32,
    /// Farthest t accepted.
    pub t_max: f32,
    /// A shadow ray: stop at the first hit.
    pub any: bool,
}

impl TraceRay {
    fn floats(&self) -> [f32; RAY_FLOATS] {
        let mut f = [0.0f32; RAY_FLOATS];
        f[..3].copy_from_slice(&self.origin);
        f[3..6].copy_from_slice(&self.dir);
        f[6] = self.t_min;
        f[7] = self.t_max;
        f[8] = if self.any { 1.0 } else { 0.0 };
        f
    }
}

/// The rays of a frame by kind.
#[derive(Debug, Clone, Default)]
pub struct FrameRays {
    /// Every ray, pixel by pixel: primary, its shadow ray, reflection, its shadow ray.
    pub rays: Vec<TraceRay>,
    /// The caster's counts (primary, reflection and shadow rays).
    pub stats: TraceStats,
}

/// The shadow ray toward the hit `h` of `ray` from each point light, as
/// [`Caster`]'s shading casts it (from the light, (ε, dist − ε)).
fn shadow_rays(caster: &Caster, ray: &Ray, h: &Hit, out: &mut Vec<TraceRay>, st: &mut TraceStats) {
    let scene = caster.scene;
    let m = &scene.materials[scene.triangles[h.tri as usize].material as usize];
    if m.kind != MaterialKind::Diffuse {
        return;
    }
    let p = ray.origin + ray.dir * h.t;
    let n = caster.normal(h.tri, ray.dir);
    for l in &scene.lights {
        if let Light::Point { position, .. } = l {
            let lp = Vec3::from(*position);
            let from = p - lp;
            let dist = from.length();
            let dir = from / dist;
            if -n.dot(dir) <= 0.0 {
                continue;
            }
            st.shadow += 1;
            let eps = caster.eps();
            out.push(TraceRay { origin: lp.to_array(), dir: dir.to_array(), t_min: eps, t_max: dist - eps, any: true });
        }
    }
}

/// Which rays a frame casts per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rays {
    /// Table 6.5 (a) (L2829: "one primary ray and, if a surface is hit, one
    /// shadow ray per pixel"): the primary ray and, where it hits a diffuse
    /// surface facing the light, the shadow ray toward the hit.
    PrimaryShadow,
    /// Table 6.5 (b), up to four rays per pixel (§A.1, L2845 "primary,
    /// reflection and shadow rays"): as [`Rays::PrimaryShadow`], plus a mirror
    /// reflection ray where the surface seen reflects and the shadow ray
    /// toward its diffuse hit.
    WithReflections,
}

fn trace_ray(r: &Ray, eps: f32) -> TraceRay {
    TraceRay { origin: r.origin.to_array(), dir: r.dir.to_array(), t_min: eps, t_max: f32::INFINITY, any: false }
}

/// The rays `which` of every pixel of `cam`, row by row; the hits that spawn
/// shadow and reflection rays come from the kd-tree caster, as it shades them.
pub fn frame_rays(caster: &Caster, cam: &Camera, which: Rays) -> FrameRays {
    let [w, h] = cam.resolution;
    let mut out = FrameRays::default();
    let st = &mut out.stats;
    let eps = caster.eps();
    for y in 0..h {
        for x in 0..w {
            let ray = cam.ray(x, y);
            st.primary += 1;
            out.rays.push(trace_ray(&ray, eps));
            let Some(hit) = caster.intersect(&ray, eps, f32::INFINITY, false, st) else { continue };
            shadow_rays(caster, &ray, &hit, &mut out.rays, st);
            if which == Rays::PrimaryShadow {
                continue;
            }
            let refl = caster.scene.reflectance(caster.scene.triangles[hit.tri as usize].material);
            if refl.iter().any(|&c| c > 0.0) {
                let n = caster.normal(hit.tri, ray.dir);
                let p = ray.origin + ray.dir * hit.t;
                let r = Ray { origin: p, dir: (ray.dir - 2.0 * ray.dir.dot(n) * n).normalize() };
                st.reflection += 1;
                out.rays.push(trace_ray(&r, eps));
                if let Some(h2) = caster.intersect(&r, eps, f32::INFINITY, false, st) {
                    shadow_rays(caster, &r, &h2, &mut out.rays, st);
                }
            }
        }
    }
    out
}

/// A traversal's result: t, u, v and the triangle (`u32::MAX`: none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Best {
    /// Ray parameter (t_max when nothing was hit).
    pub t: f32,
    /// Barycentric weight of vertex 1.
    pub u: f32,
    /// Barycentric weight of vertex 2.
    pub v: f32,
    /// Triangle index.
    pub tri: u32,
}

impl Best {
    /// The same result, bit for bit.
    pub fn same(&self, o: &Best) -> bool {
        self.t.to_bits() == o.t.to_bits()
            && self.u.to_bits() == o.u.to_bits()
            && self.v.to_bits() == o.v.to_bits()
            && self.tri == o.tri
    }
}

struct R {
    o: [f32; 3],
    d: [f32; 3],
    inv: [f32; 3],
    tmin: f32,
    any: bool,
}

fn fb(w: u32) -> f32 {
    f32::from_bits(w)
}

fn pick(v: &[f32; 3], k: u32) -> f32 {
    v[k as usize]
}

/// Alg. 3.3 over a leaf; true when an any-hit ray has its hit.
fn leaf(b: &SceneBvh, first: u32, r: &R, best: &mut Best, walk: &mut Walk) -> bool {
    for w in &b.tris[first as usize..] {
        walk.retrieved += 1;
        let k = w[0];
        let (a, c) = (if k == 2 { 0 } else { k + 1 }, if k == 0 { 2 } else { k - 1 });
        let (ok, oa, ob) = (pick(&r.o, k), pick(&r.o, a), pick(&r.o, c));
        let (dk, da, db) = (pick(&r.d, k), pick(&r.d, a), pick(&r.d, c));
        let t = (fb(w[3]) - ok - fb(w[1]) * oa - fb(w[2]) * ob) / (dk + fb(w[1]) * da + fb(w[2]) * db);
        if t >= r.tmin && t <= best.t {
            let (hx, hy) = (oa + t * da, ob + t * db);
            let u = fb(w[7]) * hx + fb(w[8]) * hy + fb(w[9]);
            let v = fb(w[4]) * hx + fb(w[5]) * hy + fb(w[6]);
            if !(u < 0.0 || v < 0.0 || u + v > 1.0) {
                *best = Best { t, u, v, tri: w[10] };
                if r.any {
                    return true;
                }
            }
        }
        if fb(w[11]) != 0.0 {
            return false;
        }
    }
    false
}

fn slab(lo: [f32; 3], hi: [f32; 3], r: &R, ta: &mut f32, tb: &mut f32) -> bool {
    for c in 0..3 {
        let (t1, t2) = ((lo[c] - r.o[c]) * r.inv[c], (hi[c] - r.o[c]) * r.inv[c]);
        *ta = ta.max(t1.min(t2));
        *tb = tb.min(t1.max(t2));
    }
    *ta <= *tb
}

/// The native traversal of `ray` through `layout` (the kernel's step for
/// step): the result and what it did (nodes: node accesses, two a pair;
/// retrieved: triangles tested).
pub fn trace(b: &SceneBvh, layout: Layout, ray: &TraceRay) -> (Best, Walk) {
    trace_with(b, layout.into(), ray)
}

/// The native traversal of `ray` by `traversal` (the kernel's step for step).
pub fn trace_with(b: &SceneBvh, traversal: Traversal, ray: &TraceRay) -> (Best, Walk) {
    let r =
        R { o: ray.origin, d: ray.dir, inv: std::array::from_fn(|c| 1.0 / ray.dir[c]), tmin: ray.t_min, any: ray.any };
    let mut best = Best { t: ray.t_max, u: 0.0, v: 0.0, tri: NONE };
    let mut walk = Walk::default();
    let (mut ta, mut tb) = (r.tmin, best.t);
    if b.complete.is_empty() || !slab(b.root[0], b.root[1], &r, &mut ta, &mut tb) {
        return (best, walk);
    }
    match traversal {
        Traversal::Complete => complete(b, &r, false, &mut best, &mut walk),
        Traversal::CompleteTa => complete(b, &r, !r.any, &mut best, &mut walk),
        Traversal::Compact => compact(b, &r, ta, tb, &mut best, &mut walk),
    }
    (best, walk)
}

/// B's traversal; with `check` the stack holds each pair's entry distance
/// t_a and a popped entry beyond the hit is skipped.
fn complete(b: &SceneBvh, r: &R, check: bool, best: &mut Best, walk: &mut Walk) {
    let mut stack: Vec<(u32, f32)> = Vec::new();
    let mut pair = 0u32;
    loop {
        let p = &b.complete[pair as usize];
        walk.nodes += 2;
        let box_of = |s: usize| -> ([f32; 3], [f32; 3]) {
            (std::array::from_fn(|c| fb(p[6 * s + c])), std::array::from_fn(|c| fb(p[6 * s + 3 + c])))
        };
        let (wl, wr) = (p[12], p[13]);
        let (mut tal, mut tbl, mut tar, mut tbr) = (r.tmin, best.t, r.tmin, best.t);
        let (ll, lh) = box_of(0);
        let (rl, rh) = box_of(1);
        let hl = slab(ll, lh, r, &mut tal, &mut tbl);
        let hr = slab(rl, rh, r, &mut tar, &mut tbr);
        let mut done = false;
        if hl && wl & LEAF_BIT != 0 {
            done = leaf(b, wl & !LEAF_BIT, r, best, walk);
        }
        if !done && hr && wr & LEAF_BIT != 0 {
            done = leaf(b, wr & !LEAF_BIT, r, best, walk);
        }
        if done {
            return;
        }
        let (il, ir) = (hl && wl & LEAF_BIT == 0, hr && wr & LEAF_BIT == 0);
        let next = if il && ir {
            let left_first = tal <= tar;
            stack.push(if left_first { (wr, tar) } else { (wl, tal) });
            walk.pushes += 1;
            Some(if left_first { wl } else { wr })
        } else if il {
            Some(wl)
        } else if ir {
            Some(wr)
        } else {
            None
        };
        if let Some(n) = next {
            pair = n;
            continue;
        }
        loop {
            let Some((n, a)) = stack.pop() else { return };
            walk.pops += 1;
            if check && a > best.t {
                continue;
            }
            pair = n;
            break;
        }
    }
}

fn compact(b: &SceneBvh, r: &R, mut ta: f32, mut tb: f32, best: &mut Best, walk: &mut Walk) {
    use pm_layout::{REF_LEAF, REF_MASK};
    let mut stack: Vec<(u32, f32, f32)> = Vec::new();
    let mut pair = 0u32;
    loop {
        let p = &b.compact[pair as usize];
        walk.nodes += 2;
        let (w0, w1) = (p[6], p[7]);
        // Algorithm 6.1
        let (mut tal, mut tar) = (ta, ta);
        let mut tbl = tb.min(best.t);
        let mut tbr = tbl;
        for k in 0..3 {
            let t1 = (fb(p[k]) - r.o[k]) * r.inv[k];
            let t2 = (fb(p[3 + k]) - r.o[k]) * r.inv[k];
            let t3 = f32::INFINITY * r.inv[k];
            let (lk, uk) = ((w0 >> (31 - k)) & 1 != 0, (w1 >> (31 - k)) & 1 != 0);
            let (t1l, t1r) = if lk { (t1, -t3) } else { (-t3, t1) };
            let (t2l, t2r) = if uk { (t2, t3) } else { (t3, t2) };
            tal = tal.max(t1l.min(t2l));
            tbl = tbl.min(t1l.max(t2l));
            tar = tar.max(t1r.min(t2r));
            tbr = tbr.min(t1r.max(t2r));
        }
        let (hl, hr) = (tal <= tbl, tar <= tbr);
        let mut done = false;
        if hl && w0 & REF_LEAF != 0 {
            done = leaf(b, w0 & REF_MASK, r, best, walk);
        }
        if !done && hr && w1 & REF_LEAF != 0 {
            done = leaf(b, w1 & REF_MASK, r, best, walk);
        }
        if done {
            return;
        }
        let (il, ir) = (hl && w0 & REF_LEAF == 0, hr && w1 & REF_LEAF == 0);
        let next = if il && ir {
            let left_first = tal <= tar;
            if left_first {
                stack.push((w1 & REF_MASK, tar, tbr));
                Some((w0 & REF_MASK, tal, tbl))
            } else {
                stack.push((w0 & REF_MASK, tal, tbl));
                Some((w1 & REF_MASK, tar, tbr))
            }
            .inspect(|_| walk.pushes += 1)
        } else if il {
            Some((w0 & REF_MASK, tal, tbl))
        } else if ir {
            Some((w1 & REF_MASK, tar, tbr))
        } else {
            None
        };
        let next = next.or_else(|| {
            while let Some(e) = stack.pop() {
                walk.pops += 1;
                if e.1 > best.t {
                    continue;
                }
                return Some(e);
            }
            None
        });
        let Some((n, a, bb)) = next else { return };
        (pair, ta, tb) = (n, a, bb);
    }
}

/// An emulated trace of a ray set.
#[derive(Debug, Clone)]
pub struct Traced {
    /// Per ray.
    pub hits: Vec<Best>,
    /// Node accesses, pushes, pops and triangles tested, read off the `@count` lines.
    pub walk: Walk,
    /// Node (read-only path) and stack (local) bytes by the memory model.
    pub traffic: Traffic,
    /// Entry distances t_a written and read on the stack (part (a)'s baseline
    /// alone: its closest-hit rays' pushes and pops), read off the `@count` lines.
    pub ta_words: u64,
    /// Everything the memory model counted.
    pub memory: crate::model::ModelStats,
    /// The launch.
    pub launch: LaunchStats,
}

/// Loads the kernels' PTX on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/fabianowski2011/scenebvh.ptx")
}

/// Per tag name, the lanes that executed the tagged instruction on a tagged line of `scenebvh.cu`.
pub fn line_counts(prog: &Program, stats: &LaunchStats) -> std::collections::BTreeMap<String, u64> {
    tagged_counts(prog, &stats.profile, SOURCE_FILE, &count_tags(SOURCE), |c| c.pred_on)
}

/// Why a ray set could not be traced on the emulator.
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    /// More rays than a launch parameter holds.
    #[error("{0} rays: more than a launch takes (at most 2^31 - 1)")]
    TooMany(usize),
    /// The emulator refused or faulted.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// Traces `rays` through `layout` on the emulator.
pub fn trace_kernel(
    dev: &mut Device,
    module: &Module,
    b: &SceneBvh,
    layout: Layout,
    rays: &[TraceRay],
) -> Result<Traced, TraceError> {
    trace_kernel_with(dev, module, b, layout.into(), rays)
}

/// Traces `rays` by `traversal` on the emulator.
pub fn trace_kernel_with(
    dev: &mut Device,
    module: &Module,
    b: &SceneBvh,
    traversal: Traversal,
    rays: &[TraceRay],
) -> Result<Traced, TraceError> {
    let n = rays.len();
    if n > i32::MAX as usize {
        return Err(TraceError::TooMany(n));
    }
    // an empty tree: a root box no ray enters
    let root = if b.complete.is_empty() { [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]] } else { b.root };
    let mut params = to_bytes(&[root[0], root[1]].concat());
    params.extend(to_bytes(&[n as i32]));
    let entry = traversal.entry();
    let nodes = match traversal.layout() {
        Layout::Complete => b.complete.concat(),
        Layout::Compact => b.compact.concat(),
    };
    let r: Vec<f32> = rays.iter().flat_map(|r| r.floats()).collect();
    let buffers = [
        (&params[..], "params"),
        (&to_bytes(&nodes)[..], "pairs"),
        (&to_bytes(&b.tris.concat())[..], "triangles"),
        (&to_bytes(&r)[..], "rays"),
    ];
    let run = pm_layout::run_traversal(dev, module, entry, &buffers, n)?;
    let c = line_counts(&module.prog, &run.launch);
    let get = |k: &str| c.get(k).copied().unwrap_or(0);
    let walk = Walk {
        nodes: 2 * get("pairs"),
        pushes: get("push"),
        pops: get("pop"),
        retrieved: get("tested"),
        contributed: 0,
    };
    let hits = run.out.chunks_exact(4).map(|h| Best { t: h[0], u: h[1], v: h[2], tri: h[3].to_bits() }).collect();
    let ta_words = get("push_ta") + get("pop_ta");
    Ok(Traced { hits, walk, traffic: run.traffic, ta_words, memory: run.memory, launch: run.launch })
}

/// The native traversals of `rays` (results per ray, the walks summed).
pub fn trace_all(b: &SceneBvh, layout: Layout, rays: &[TraceRay]) -> (Vec<Best>, Walk) {
    use rayon::prelude::*;
    let each: Vec<(Best, Walk)> = rays.par_iter().map(|r| trace(b, layout, r)).collect();
    let mut total = Walk::default();
    for (_, w) in &each {
        total.nodes += w.nodes;
        total.pushes += w.pushes;
        total.pops += w.pops;
        total.retrieved += w.retrieved;
    }
    (each.into_iter().map(|(h, _)| h).collect(), total)
}

/// Bytes by the byte model: B 28 per node access and 4 per push or pop, C 16 and 12.
pub fn model_bytes(layout: Layout, w: &Walk) -> (u64, u64) {
    match layout {
        Layout::Complete => (28 * w.nodes, 4 * w.stack()),
        Layout::Compact => (16 * w.nodes, 12 * w.stack()),
    }
}
