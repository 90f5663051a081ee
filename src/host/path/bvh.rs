//! Thesis 003's SAH BVH and its automatic refitting (§3.5-3.6, 003:L191-205):
//! the binned-SAH build on the CPU, the device layout, the native traversal
//! and refit, and their emulated twins in `kernels/lin2017/bvh.cu`
//! (`bvh_trace`, `bvh_refit`).
//!
//! **Build** (003:L195-199): binned SAH after Pharr and Humphreys, [`BUCKETS`]
//! equal-width buckets over the centroid bounds on the axis of their largest
//! extent, splits tested only at bucket boundaries, cost
//! `K_T + (n_L·SA_L + n_R·SA_R) / SA` with `K_T` = [`TRAVERSAL_COST`] (an
//! intersection costs 1); a node becomes a leaf when it holds at most
//! [`MAX_LEAF`] triangles and the best split costs no less than testing them
//! all, or when its centroids coincide. Triangles go to a child by their
//! centroid; the children are stored front-back (left, the lower centroids,
//! right after its parent). The thesis states none of the bucket count, the
//! costs or the leaf size (`docs/fixtures.md`).
//!
//! **Layout**: a node is 32 bytes, two 16-byte words,
//! `[lo.x lo.y lo.z word] [hi.x hi.y hi.z count]` with `word = axis << 30 |
//! right child` (inner) or `3 << 30 | first reference` (leaf).
//!
//! **Traversal** (003:L197-199): the nearest hit cannot stop at the first
//! leaf hit, since the back child may hold a nearer one. The front child (by
//! the ray's sign on the node's axis) is visited first and the back one
//! pushed (a 4-byte node index in local memory); the range shrinks to the
//! hit, and a popped node whose box misses the trimmed range is skipped.
//!
//! **Refit** (003:L201-205): each movable object keeps a translation vector,
//! applied as an offset in the triangle test (the ray origin moves by
//! −translation; the vertices are never rewritten). The refit recomputes
//! every leaf's box from its triangles' vertices plus their objects'
//! translations, and every inner box as the union of its children's. On the
//! device one thread per leaf climbs the tree, counting its arrival at each
//! parent with an atomic add: the first of two siblings stops, the second
//! writes the parent. Every inner node gets exactly two atomic arrivals.

// `!(a < b)` is the kernel's comparison, NaN included: kept as written
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::collections::BTreeMap;

use glam::Vec3;

use super::layout::affine_rows;
use crate::host::rt_kernels::{CountTag, count_tags, tagged_counts, upload};
use crate::model::{Model, Profile};
use crate::ptx::ir::Program;
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, LaunchConfig, LaunchStats, Module, SimError};

/// The kernels' PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/lin2017/bvh.ptx");
/// The kernels' CUDA source, whose `@count` tags name the lines counted.
pub const SOURCE: &str = include_str!("../../../kernels/lin2017/bvh.cu");
/// The source's path as the PTX's `.file` directive names it (suffix).
pub const SOURCE_FILE: &str = "kernels/lin2017/bvh.cu";
/// Entry: the nearest-hit traversal.
pub const TRACE: &str = "bvh_trace";
/// Entry: the refit.
pub const REFIT: &str = "bvh_refit";
/// Threads per CTA.
pub const THREADS: u32 = 128;
/// Buckets of the binned SAH (PBRT's default; not stated by the thesis).
pub const BUCKETS: usize = 12;
/// The SAH's traversal cost relative to one triangle test (PBRT's 1/8; not stated).
pub const TRAVERSAL_COST: f64 = 0.125;
/// The most triangles a leaf holds unless its centroids coincide (not stated).
pub const MAX_LEAF: usize = 4;
/// Stack entries of the kernel's traversal.
pub const STACK_ENTRIES: usize = 64;
/// The leaf's axis value.
pub const LEAF: u32 = 3;
/// Bytes of a node (two 16-byte loads).
pub const NODE_BYTES: u64 = 32;
/// Bytes of a stack entry (the node index).
pub const STACK_ENTRY_BYTES: u64 = 4;
const INDEX_MASK: u32 = 0x3fff_ffff;

/// Why a BVH cannot be built or run.
#[derive(Debug, thiserror::Error)]
pub enum BvhError {
    /// Object ids and triangles disagree.
    #[error("{objects} object ids for {triangles} triangles: give one per triangle")]
    Objects {
        /// Ids given.
        objects: usize,
        /// Triangles.
        triangles: usize,
    },
    /// An object id has no translation.
    #[error("triangle {triangle} belongs to object {object}, but only {offsets} translations are given")]
    NoOffset {
        /// The triangle.
        triangle: usize,
        /// Its object.
        object: u32,
        /// Translations given.
        offsets: usize,
    },
    /// No triangle to build over.
    #[error("a BVH needs at least one triangle")]
    Empty,
    /// An object id past the number of triangles: ids number the objects
    /// from 0 (a translation per id up to the largest), so a sparse id such
    /// as `u32::MAX` would ask for billions of translations.
    #[error("triangle {triangle} belongs to object {object}; object ids must be below the {triangles} triangles")]
    SparseObject {
        /// The triangle.
        triangle: usize,
        /// Its object.
        object: u32,
        /// Triangles.
        triangles: usize,
    },
    /// More nodes or references than the 30-bit index fields reach.
    #[error("{0} nodes or references: the node's 30-bit index reaches 2^30")]
    TooLarge(usize),
    /// The tree is deeper than the kernel's stack.
    #[error("the BVH is {0} levels deep; the kernel's stack holds {STACK_ENTRIES} entries")]
    TooDeep(usize),
    /// The emulator refused or faulted.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// The laid-out BVH with its triangles and objects.
#[derive(Debug, Clone, PartialEq)]
pub struct Bvh {
    /// Nodes, 8 words each (see the module docs).
    pub nodes: Vec<[u32; 8]>,
    /// Per node its parent (the root's is 0).
    pub parents: Vec<u32>,
    /// The leaf nodes' indices, in node order.
    pub leaves: Vec<u32>,
    /// Leaf triangle lists, concatenated.
    pub refs: Vec<u32>,
    /// Per triangle, its vertices as built (untranslated).
    pub verts: Vec<[Vec3; 3]>,
    /// Per triangle, the affine rows of §6.4 (untranslated).
    pub tris: Vec<[f32; 12]>,
    /// Per triangle, its object.
    pub tri_obj: Vec<u32>,
    /// Levels of the tree (the root alone is 1).
    pub depth: usize,
}

#[derive(Clone, Copy)]
struct Box3 {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Box3 {
    const EMPTY: Box3 = Box3 { lo: [f64::INFINITY; 3], hi: [f64::NEG_INFINITY; 3] };
    fn grow(&mut self, p: [f64; 3]) {
        for ((l, h), v) in self.lo.iter_mut().zip(self.hi.iter_mut()).zip(p) {
            *l = l.min(v);
            *h = h.max(v);
        }
    }
    fn union(mut self, o: &Box3) -> Box3 {
        for (l, v) in self.lo.iter_mut().zip(o.lo) {
            *l = l.min(v);
        }
        for (h, v) in self.hi.iter_mut().zip(o.hi) {
            *h = h.max(v);
        }
        self
    }
    fn area(&self) -> f64 {
        let e: Vec<f64> = (0..3).map(|k| (self.hi[k] - self.lo[k]).max(0.0)).collect();
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])
    }
}

/// A node of the build before layout.
enum Built {
    Leaf(Vec<u32>),
    Inner(u32, Box<Built>, Box<Built>),
}

/// The binned-SAH split of `ids`: the axis and the left (lower-bucket) part,
/// or None for a leaf.
fn split(ids: &[u32], tbox: &[Box3], cent: &[[f64; 3]]) -> Option<(u32, Vec<u32>, Vec<u32>)> {
    let n = ids.len();
    if n <= 1 {
        return None;
    }
    let mut cb = Box3::EMPTY;
    let mut nb = Box3::EMPTY;
    for &i in ids {
        cb.grow(cent[i as usize]);
        nb = nb.union(&tbox[i as usize]);
    }
    let ext = [0, 1, 2].map(|k| cb.hi[k] - cb.lo[k]);
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    if ext[axis] <= 0.0 {
        return None; // the centroids coincide
    }
    let bucket = |i: u32| -> usize {
        let b = (BUCKETS as f64 * (cent[i as usize][axis] - cb.lo[axis]) / ext[axis]) as usize;
        b.min(BUCKETS - 1)
    };
    let mut count = [0usize; BUCKETS];
    let mut bb = [Box3::EMPTY; BUCKETS];
    for &i in ids {
        let b = bucket(i);
        count[b] += 1;
        bb[b] = bb[b].union(&tbox[i as usize]);
    }
    let area = nb.area();
    let (mut best, mut best_cost) = (0usize, f64::INFINITY);
    for s in 0..BUCKETS - 1 {
        let (mut l, mut r) = (Box3::EMPTY, Box3::EMPTY);
        let (mut nl, mut nr) = (0usize, 0usize);
        for b in 0..=s {
            l = l.union(&bb[b]);
            nl += count[b];
        }
        for b in s + 1..BUCKETS {
            r = r.union(&bb[b]);
            nr += count[b];
        }
        if nl == 0 || nr == 0 {
            continue;
        }
        let cost = TRAVERSAL_COST + (nl as f64 * l.area() + nr as f64 * r.area()) / area.max(f64::MIN_POSITIVE);
        if cost < best_cost {
            best_cost = cost;
            best = s;
        }
    }
    if !best_cost.is_finite() || (n <= MAX_LEAF && best_cost >= n as f64) {
        return None;
    }
    let (left, right): (Vec<u32>, Vec<u32>) = ids.iter().partition(|&&i| bucket(i) <= best);
    Some((axis as u32, left, right))
}

fn build_rec(ids: Vec<u32>, tbox: &[Box3], cent: &[[f64; 3]], depth: usize, max_depth: &mut usize) -> Built {
    *max_depth = (*max_depth).max(depth);
    match split(&ids, tbox, cent) {
        None => Built::Leaf(ids),
        Some((axis, l, r)) => Built::Inner(
            axis,
            Box::new(build_rec(l, tbox, cent, depth + 1, max_depth)),
            Box::new(build_rec(r, tbox, cent, depth + 1, max_depth)),
        ),
    }
}

impl Bvh {
    /// Builds the BVH over `tris`, triangle `i` belonging to object `objects[i]`
    /// (pass `&[]` for one object, 0), with the boxes of every object at rest.
    pub fn build(tris: &[[Vec3; 3]], objects: &[u32]) -> Result<Bvh, BvhError> {
        if tris.is_empty() {
            return Err(BvhError::Empty);
        }
        let tri_obj: Vec<u32> = if objects.is_empty() { vec![0; tris.len()] } else { objects.to_vec() };
        if tri_obj.len() != tris.len() {
            return Err(BvhError::Objects { objects: objects.len(), triangles: tris.len() });
        }
        if let Some(t) = tri_obj.iter().position(|&o| o as usize >= tris.len()) {
            return Err(BvhError::SparseObject { triangle: t, object: tri_obj[t], triangles: tris.len() });
        }
        let tbox: Vec<Box3> = tris
            .iter()
            .map(|t| {
                let mut b = Box3::EMPTY;
                for v in t {
                    b.grow(v.as_dvec3().into());
                }
                b
            })
            .collect();
        let cent: Vec<[f64; 3]> = tbox.iter().map(|b| [0, 1, 2].map(|k| 0.5 * (b.lo[k] + b.hi[k]))).collect();
        let mut depth = 0;
        let root = build_rec((0..tris.len() as u32).collect(), &tbox, &cent, 1, &mut depth);
        if depth > STACK_ENTRIES {
            return Err(BvhError::TooDeep(depth));
        }
        let mut bvh = Bvh {
            nodes: Vec::new(),
            parents: Vec::new(),
            leaves: Vec::new(),
            refs: Vec::new(),
            verts: tris.to_vec(),
            tris: tris.iter().map(affine_rows).collect(),
            tri_obj,
            depth,
        };
        // depth first, the left child right after its parent
        let mut todo: Vec<(&Built, u32, Option<u32>)> = vec![(&root, 0, None)];
        while let Some((b, parent, right_of)) = todo.pop() {
            let at = bvh.nodes.len() as u32;
            if let Some(p) = right_of {
                bvh.nodes[p as usize][3] |= at;
            }
            bvh.parents.push(parent);
            match b {
                Built::Leaf(ids) => {
                    let off = bvh.refs.len() as u32;
                    bvh.refs.extend_from_slice(ids);
                    bvh.leaves.push(at);
                    bvh.nodes.push([0, 0, 0, LEAF << 30 | off, 0, 0, 0, ids.len() as u32]);
                }
                Built::Inner(axis, l, r) => {
                    bvh.nodes.push([0, 0, 0, axis << 30, 0, 0, 0, 0]);
                    todo.push((r.as_ref(), at, Some(at)));
                    todo.push((l.as_ref(), at, None));
                }
            }
        }
        if bvh.nodes.len() > INDEX_MASK as usize || bvh.refs.len() > INDEX_MASK as usize {
            return Err(BvhError::TooLarge(bvh.nodes.len().max(bvh.refs.len())));
        }
        let rest = vec![[0.0f32; 4]; bvh.objects()];
        bvh.refit(&rest)?;
        Ok(bvh)
    }

    /// Objects: one more than the largest id.
    pub fn objects(&self) -> usize {
        self.tri_obj.iter().max().map_or(0, |&m| m as usize + 1)
    }

    /// Inner nodes.
    pub fn inner(&self) -> usize {
        self.nodes.len() - self.leaves.len()
    }

    fn check_offsets(&self, offsets: &[[f32; 4]]) -> Result<(), BvhError> {
        match self.tri_obj.iter().position(|&o| o as usize >= offsets.len()) {
            Some(t) => Err(BvhError::NoOffset { triangle: t, object: self.tri_obj[t], offsets: offsets.len() }),
            None => Ok(()),
        }
    }

    /// The right child of inner node `i`, or the first reference of leaf `i`.
    fn index(&self, i: usize) -> u32 {
        self.nodes[i][3] & INDEX_MASK
    }

    /// Refits every box to the objects' translations `offsets` (per object
    /// x, y, z, unused): the kernel's `bvh_refit`, serially, leaves first,
    /// then each inner node after its children.
    pub fn refit(&mut self, offsets: &[[f32; 4]]) -> Result<(), BvhError> {
        self.check_offsets(offsets)?;
        for &leaf in &self.leaves.clone() {
            let i = leaf as usize;
            let (first, count) = (self.index(i), self.nodes[i][7]);
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for r in 0..count {
                let t = self.refs[(first + r) as usize] as usize;
                let off = offsets[self.tri_obj[t] as usize];
                for v in &self.verts[t] {
                    let p = [v.x + off[0], v.y + off[1], v.z + off[2]];
                    for k in 0..3 {
                        lo[k] = fmin(lo[k], p[k]);
                        hi[k] = fmax(hi[k], p[k]);
                    }
                }
            }
            self.set_box(i, lo, hi);
        }
        // children follow their parents: a reverse sweep meets both first
        for i in (0..self.nodes.len()).rev() {
            if self.nodes[i][3] >> 30 == LEAF {
                continue;
            }
            let (l, r) = (i + 1, self.index(i) as usize);
            let (a, b) = (self.nodes[l], self.nodes[r]);
            let f = |w: u32| f32::from_bits(w);
            let lo = [0, 1, 2].map(|k| fmin(f(a[k]), f(b[k])));
            let hi = [0, 1, 2].map(|k| fmax(f(a[4 + k]), f(b[4 + k])));
            self.set_box(i, lo, hi);
        }
        Ok(())
    }

    fn set_box(&mut self, i: usize, lo: [f32; 3], hi: [f32; 3]) {
        for k in 0..3 {
            self.nodes[i][k] = lo[k].to_bits();
            self.nodes[i][4 + k] = hi[k].to_bits();
        }
    }

    /// A node's box.
    pub fn node_box(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        let n = &self.nodes[i];
        ([0, 1, 2].map(|k| f32::from_bits(n[k])), [0, 1, 2].map(|k| f32::from_bits(n[4 + k])))
    }

    /// §6.4's affine test of triangle `t` with the ray origin moved by −`off`.
    #[allow(clippy::too_many_arguments)]
    fn affine(&self, t: u32, off: [f32; 4], o: [f32; 3], d: [f32; 3], t_min: f32, t_hit: &mut f32) -> bool {
        let m = &self.tris[t as usize];
        let (px, py, pz) = (o[0] - off[0], o[1] - off[1], o[2] - off[2]);
        let qz = m[8] * px + m[9] * py + m[10] * pz + m[11];
        let ez = m[8] * d[0] + m[9] * d[1] + m[10] * d[2];
        let tt = -qz / ez;
        if !(tt >= t_min && tt <= *t_hit) {
            return false;
        }
        let u = m[0] * px + m[1] * py + m[2] * pz + m[3] + tt * (m[0] * d[0] + m[1] * d[1] + m[2] * d[2]);
        if u < 0.0 {
            return false;
        }
        let v = m[4] * px + m[5] * py + m[6] * pz + m[7] + tt * (m[4] * d[0] + m[5] * d[1] + m[6] * d[2]);
        if v < 0.0 || u + v > 1.0 {
            return false;
        }
        *t_hit = tt;
        true
    }

    /// The nearest hit of `ray` with the objects at `offsets`: the kernel's
    /// `bvh_trace`, operation for operation, counting its events into `w`.
    pub fn trace(&self, ray: &BvhRay, offsets: &[[f32; 4]], w: &mut Walk) -> Hit {
        let (o, d) = (ray.origin, ray.dir);
        w.rays += 1;
        let inv = [1.0 / d[0], 1.0 / d[1], 1.0 / d[2]];
        let (t_min, mut t_hit) = (ray.t_min, ray.t_max);
        let mut found: i32 = -1;
        let mut stack: Vec<u32> = Vec::with_capacity(STACK_ENTRIES);
        let mut idx = 0u32;
        loop {
            w.nodes += 1;
            let n = &self.nodes[idx as usize];
            let f = |k: usize| f32::from_bits(n[k]);
            let t0 = [0, 1, 2].map(|k| (f(k) - o[k]) * inv[k]);
            let t1 = [0, 1, 2].map(|k| (f(4 + k) - o[k]) * inv[k]);
            let tn = fmax(fmax(fmin(t0[0], t1[0]), fmin(t0[1], t1[1])), fmin(t0[2], t1[2]));
            let tf = fmin(fmin(fmax(t0[0], t1[0]), fmax(t0[1], t1[1])), fmax(t0[2], t1[2]));
            if fmax(tn, t_min) <= fmin(tf, t_hit) {
                let (word, kind) = (n[3], n[3] >> 30);
                if kind == LEAF {
                    w.leaves += 1;
                    let first = word & INDEX_MASK;
                    for r in 0..n[7] {
                        let t = self.refs[(first + r) as usize];
                        w.tri_tests += 1;
                        let off = offsets[self.tri_obj[t as usize] as usize];
                        if self.affine(t, off, o, d, t_min, &mut t_hit) {
                            found = t as i32;
                        }
                    }
                } else {
                    let (mut front, mut back) = (idx + 1, word & INDEX_MASK);
                    if (d[kind as usize].to_bits() as i32) < 0 {
                        std::mem::swap(&mut front, &mut back);
                    }
                    stack.push(back);
                    w.pushes += 1;
                    idx = front;
                    continue;
                }
            }
            match stack.pop() {
                Some(i) => {
                    w.pops += 1;
                    idx = i;
                }
                None => break,
            }
        }
        Hit { t: if found >= 0 { t_hit } else { 0.0 }, tri: found }
    }

    /// The nearest hit over every triangle (no tree), for checking the traversal.
    pub fn brute(&self, ray: &BvhRay, offsets: &[[f32; 4]]) -> Hit {
        let mut t_hit = ray.t_max;
        let mut found = -1;
        for t in 0..self.tris.len() as u32 {
            let off = offsets[self.tri_obj[t as usize] as usize];
            if self.affine(t, off, ray.origin, ray.dir, ray.t_min, &mut t_hit) {
                found = t as i32;
            }
        }
        Hit { t: if found >= 0 { t_hit } else { 0.0 }, tri: found }
    }
}

/// CUDA's `fminf`: the other operand when one is NaN.
fn fmin(a: f32, b: f32) -> f32 {
    a.min(b)
}

/// CUDA's `fmaxf`.
fn fmax(a: f32, b: f32) -> f32 {
    a.max(b)
}

/// A ray to trace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhRay {
    /// Origin.
    pub origin: [f32; 3],
    /// Direction (need not be unit).
    pub dir: [f32; 3],
    /// Nearest distance accepted.
    pub t_min: f32,
    /// Farthest distance accepted.
    pub t_max: f32,
}

/// A ray's nearest hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance (0 without a hit).
    pub t: f32,
    /// Triangle, −1 for none.
    pub tri: i32,
}

impl Hit {
    /// Bit-identical.
    pub fn same(&self, o: &Hit) -> bool {
        self.t.to_bits() == o.t.to_bits() && self.tri == o.tri
    }
}

/// The traversal's events, summed over rays.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Walk {
    /// Rays traced.
    pub rays: u64,
    /// Nodes fetched (box tested).
    pub nodes: u64,
    /// Leaves entered (native only: no instruction of the kernel stands for it alone).
    pub leaves: u64,
    /// Triangle tests.
    pub tri_tests: u64,
    /// Stack pushes (the back child).
    pub pushes: u64,
    /// Stack pops.
    pub pops: u64,
}

/// An emulated trace.
#[derive(Debug, Clone)]
pub struct Traced {
    /// Per ray.
    pub hits: Vec<Hit>,
    /// The events read off the `@count` lines (`leaves` stays 0).
    pub walk: Walk,
    /// Node bytes: the tagged node load's lanes × its 16 bytes × 2 loads a node.
    pub node_bytes: u64,
    /// Local-memory bytes stored and loaded (the stack), by the memory model (Maxwell).
    pub stack_bytes: (u64, u64),
    /// The launch.
    pub launch: LaunchStats,
}

/// An emulated refit.
#[derive(Debug, Clone)]
pub struct Refitted {
    /// The nodes as the kernel left them.
    pub nodes: Vec<[u32; 8]>,
    /// Atomic arrivals (the launch's atomic lane operations: the kernel's only atomic).
    pub arrivals: u64,
    /// The launch (its counters hold the atomic lane operations).
    pub launch: LaunchStats,
}

/// Loads the kernels on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/lin2017/bvh.ptx")
}

/// The `@count` tags of `bvh.cu`.
pub fn tags() -> Vec<CountTag> {
    count_tags(SOURCE)
}

/// Per tag name, the lanes that executed the tagged instruction (guard true).
pub fn line_counts(prog: &Program, stats: &LaunchStats) -> BTreeMap<String, u64> {
    tagged_counts(prog, &stats.profile, SOURCE_FILE, &tags(), |c| c.pred_on)
}

fn flat<const N: usize>(v: &[[f32; N]]) -> Vec<f32> {
    v.iter().flatten().copied().collect()
}

fn params(a: usize, b: usize) -> Vec<u8> {
    to_bytes(&[a as i32, b as i32])
}

/// Traces `rays` on the emulator with the objects at `offsets` (the BVH
/// refitted to them), with the Maxwell memory model observing the launch.
pub fn trace_kernel(
    dev: &mut Device,
    module: &Module,
    bvh: &Bvh,
    offsets: &[[f32; 4]],
    rays: &[BvhRay],
) -> Result<Traced, BvhError> {
    bvh.check_offsets(offsets)?;
    let n = rays.len();
    if n > i32::MAX as usize {
        return Err(BvhError::TooLarge(n));
    }
    let pp = upload(dev, &params(n, bvh.leaves.len()), "bvh_params")?;
    let nodes: Vec<u32> = bvh.nodes.iter().flatten().copied().collect();
    let nb = upload(dev, &to_bytes(&nodes), "bvh_nodes")?;
    let rb = upload(dev, &to_bytes(&bvh.refs), "bvh_refs")?;
    let tb = upload(dev, &to_bytes(&flat(&bvh.tris)), "bvh_tris")?;
    let ob = upload(dev, &to_bytes(&bvh.tri_obj), "bvh_tri_obj")?;
    let fb = upload(dev, &to_bytes(&flat(offsets)), "bvh_offsets")?;
    let r: Vec<f32> = rays
        .iter()
        .flat_map(|r| {
            let (o, d) = (r.origin, r.dir);
            [o[0], o[1], o[2], r.t_min, d[0], d[1], d[2], r.t_max]
        })
        .collect();
    let yb = upload(dev, &to_bytes(&r), "bvh_rays")?;
    let out = dev.alloc_zeroed::<f32>(4 * n.max(1));
    let args: Vec<Arg> = [pp, nb, rb, tb, ob, fb, yb, out].into_iter().map(Arg::Ptr).collect();
    let model = Model::new(Profile::Maxwell, &module.prog);
    let ctas = (n.div_ceil(THREADS as usize) as u32).max(1);
    let launch = dev.launch_observed(module, TRACE, LaunchConfig::linear(ctas, THREADS), &args, Some(&model))?;
    let raw = dev.read::<f32>(out, 4 * n);
    let c = line_counts(&module.prog, &launch);
    let get = |k: &str| c.get(k).copied().unwrap_or(0);
    let walk = Walk {
        rays: get("rays"),
        nodes: get("nodes"),
        leaves: 0,
        tri_tests: get("tri_tests"),
        pushes: get("push"),
        pops: get("pop"),
    };
    let m = model.finish().counters;
    let hits = raw.chunks_exact(4).map(|h| Hit { t: h[0], tri: h[1].to_bits() as i32 }).collect();
    Ok(Traced {
        hits,
        walk,
        node_bytes: NODE_BYTES * walk.nodes,
        stack_bytes: (m.local_st.bytes, m.local_ld.bytes),
        launch,
    })
}

/// Refits `bvh`'s boxes to `offsets` on the emulator (one thread per leaf).
pub fn refit_kernel(dev: &mut Device, module: &Module, bvh: &Bvh, offsets: &[[f32; 4]]) -> Result<Refitted, BvhError> {
    bvh.check_offsets(offsets)?;
    let pp = upload(dev, &params(0, bvh.leaves.len()), "bvh_params")?;
    let nodes: Vec<u32> = bvh.nodes.iter().flatten().copied().collect();
    let nb = upload(dev, &to_bytes(&nodes), "bvh_nodes")?;
    let lb = upload(dev, &to_bytes(&bvh.leaves), "bvh_leaves")?;
    let pb = upload(dev, &to_bytes(&bvh.parents), "bvh_parents")?;
    let rb = upload(dev, &to_bytes(&bvh.refs), "bvh_refs")?;
    let verts: Vec<f32> = bvh.verts.iter().flat_map(|t| t.iter().flat_map(|v| [v.x, v.y, v.z, 0.0])).collect();
    let vb = upload(dev, &to_bytes(&verts), "bvh_verts")?;
    let ob = upload(dev, &to_bytes(&bvh.tri_obj), "bvh_tri_obj")?;
    let fb = upload(dev, &to_bytes(&flat(offsets)), "bvh_offsets")?;
    let ab = dev.alloc_zeroed::<u32>(bvh.nodes.len());
    let args: Vec<Arg> = [pp, nb, lb, pb, rb, vb, ob, fb, ab].into_iter().map(Arg::Ptr).collect();
    let ctas = (bvh.leaves.len().div_ceil(THREADS as usize) as u32).max(1);
    let launch = dev.launch(module, REFIT, LaunchConfig::linear(ctas, THREADS), &args)?;
    let words = dev.read::<u32>(nb, 8 * bvh.nodes.len());
    let nodes = words.chunks_exact(8).map(|c| c.try_into().expect("8 words")).collect();
    // the kernel's only atomic is the arrival (its instruction is the prelude's
    // inlined atomicAdd, so no line of bvh.cu carries it)
    Ok(Refitted { nodes, arrivals: launch.totals.atomic_lane_ops, launch })
}
