//! Thesis 000 §6.2: the BVH photon map in the complete (B) and the compact
//! (C) representation, gathered by VKDE on the emulator
//! (`kernels/fabianowski2011/pmgather.cu`) and natively, step for step.
//!
//! **B** (L2796, L986): 32 bytes a node, lo\[3\], hi\[3\] and two words (inner:
//! the children, stored side by side; leaf: first kernel and count), tested
//! with Alg. 3.5's strict point test; inside an inner node the left child is
//! pushed and the right one visited.
//!
//! **C** (§6.2.1, L2712–2722): 32 bytes a sibling pair: the pair's six new
//! planes m\[3\], M\[3\] and two words, each a 28-bit child (the children's
//! pair, or a leaf's first kernel), a leaf bit (bit 28) and three mask bits
//! (bits 29–31, x highest: l in the left word, L in the right). Per axis and
//! side the stored plane is the left child's if it differs from the parent's
//! (mask 1), else the right child's if it differs (mask 0), else the parent's,
//! assigned to the left (L2720). A leaf ends at the kernel whose end flag is
//! set ("a flag bit on the last primitive", L2722). Tested with Alg. 6.2:
//! miss = the six plane tests (a point on a plane misses), left = (l ≪ 3) | L;
//! when both children are inner and contain x, the left one's pair is pushed
//! and the right one's visited (L2792).
//!
//! Both start at the root's two children after testing the root's AABB (a
//! launch parameter, not node traffic), so n_T counts the same nodes in both:
//! every child of an inner node that contains x (the thesis: "the number and
//! order of nodes traversed is identical for both", L2798). Under the
//! thesis' simplified memory model (every access served on its own) the
//! traversal moves **Bytes_B = 32·n_T + 4·Stack_B** and **Bytes_C = 16·n_T +
//! 4·Stack_C** (a 32-byte pair holds two nodes); with B's one push and one pop
//! per inner node containing x, Stack_B = n_T and Bytes_B = 36·n_T (extract
//! §3.12). [`gather_kernel`] counts n_T, stack pushes and pops,
//! retrievals and contributions (k) off the emulator's per-instruction
//! counters (the source lines tagged `@count`), and the bytes off the memory model's read-only and local
//! traffic, independently, so the byte model is checked against the emulator.

use std::collections::BTreeMap;

use super::photons::PhotonError;
use super::vkde::{Kernel, Query, Shape, d2};
use crate::host::rt_kernels::{count_tags, tagged_counts, upload};
use crate::model::{Model, Profile};
use crate::ptx::ir::Program;
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, LaunchConfig, LaunchStats, Module, SimError};

/// The kernels' PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/fabianowski2011/pmgather.ptx");
/// The kernels' CUDA source, whose `@count` tags name the lines counted.
pub const SOURCE: &str = include_str!("../../../kernels/fabianowski2011/pmgather.cu");
const SOURCE_FILE: &str = "kernels/fabianowski2011/pmgather.cu";
/// Entry: VKDE through the complete layout.
pub const COMPLETE: &str = "gather_complete";
/// Entry: VKDE through the compact layout.
pub const COMPACT: &str = "gather_compact";
/// The leaf bit of a complete node's second word.
pub const LEAF_BIT: u32 = 0x8000_0000;
/// The child bits of a compact pair's word.
pub const REF_MASK: u32 = 0x0fff_ffff;
/// The leaf bit of a compact pair's word.
pub const REF_LEAF: u32 = 0x1000_0000;
/// Entries of the kernels' traversal stack.
pub const STACK: usize = 64;
/// Floats of a kernel record: z, M, m', Φ', n, end flag.
pub const KERNEL_FLOATS: usize = 16;
/// Threads per CTA of the traversal launches (the gathers and the scene BVH's rays).
pub(super) const THREADS: u32 = 256;
/// The most CTAs of a traversal launch.
pub(super) const MAX_CTAS: u32 = 30;

/// What a node of a photon-map tree is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PmKind {
    /// Children (indices into [`PmTree::nodes`]).
    Inner([u32; 2]),
    /// Kernels `first..first + count` of [`PmTree::order`].
    Leaf {
        /// First position.
        first: u32,
        /// Kernels.
        count: u32,
    },
}

/// A node of a photon-map tree: its AABB and kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PmNode {
    /// Lower corner.
    pub lo: [f32; 3],
    /// Upper corner.
    pub hi: [f32; 3],
    /// Inner or leaf.
    pub kind: PmKind,
}

/// A BVH over kernels, as a builder makes it: each inner node's AABB is the
/// union of its children's (exactly), each leaf a run of [`PmTree::order`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PmTree {
    /// Nodes, the root first (empty: no kernels).
    pub nodes: Vec<PmNode>,
    /// Leaf position → kernel index.
    pub order: Vec<u32>,
}

/// Sizes of a tree.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TreeStats {
    /// Inner nodes.
    pub inner: usize,
    /// Leaves.
    pub leaves: usize,
    /// Longest root-to-leaf path in nodes.
    pub depth: usize,
}

impl PmTree {
    /// Inner nodes, leaves and depth.
    pub fn stats(&self) -> TreeStats {
        let mut s = TreeStats::default();
        if self.nodes.is_empty() {
            return s;
        }
        let mut todo = vec![(0u32, 1usize)];
        while let Some((i, d)) = todo.pop() {
            s.depth = s.depth.max(d);
            match self.nodes[i as usize].kind {
                PmKind::Inner([l, r]) => {
                    s.inner += 1;
                    todo.push((l, d + 1));
                    todo.push((r, d + 1));
                }
                PmKind::Leaf { .. } => s.leaves += 1,
            }
        }
        s
    }

    /// The same tree with an inner root: a lone leaf gets an empty sibling
    /// whose box differs from the root's only in an x-min plane of +∞.
    fn rooted(&self) -> PmTree {
        let mut t = self.clone();
        if let Some(&PmNode { lo, hi, kind: PmKind::Leaf { .. } }) = t.nodes.first() {
            let leaf = t.nodes[0];
            let empty = PmNode { lo: [f32::INFINITY, lo[1], lo[2]], hi, kind: PmKind::Leaf { first: 0, count: 0 } };
            t.nodes = vec![PmNode { lo, hi, kind: PmKind::Inner([1, 2]) }, leaf, empty];
        }
        t
    }
}

/// The two device layouts of a photon map, with its kernels in leaf order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Layouts {
    /// The root's AABB corners (the launch parameter both traversals test first).
    pub root: [[f32; 3]; 2],
    /// B: 32-byte nodes; node 0 is the root (never read), the root's children are 1 and 2.
    pub complete: Vec<[u32; 8]>,
    /// C: 32-byte sibling pairs; pair 0 holds the root's children.
    pub compact: Vec<[u32; 8]>,
    /// The kernels in leaf order.
    pub kernels: Vec<Kernel>,
    /// Whether a kernel ends its leaf.
    pub ends: Vec<bool>,
}

fn plane(parent: f32, l: f32, r: f32) -> (f32, u32) {
    if l != parent {
        (l, 1)
    } else if r != parent {
        (r, 0)
    } else {
        (parent, 1)
    }
}

impl Layouts {
    /// Lays out `tree` over `kernels` (indexed by [`PmTree::order`]).
    pub fn new(tree: &PmTree, kernels: &[Kernel]) -> Layouts {
        let mut out = Layouts::default();
        if tree.nodes.is_empty() {
            return out;
        }
        let t = tree.rooted();
        out.kernels = t.order.iter().map(|&i| kernels[i as usize]).collect();
        out.ends = vec![false; out.kernels.len()];
        let root = t.nodes[0];
        out.root = [root.lo, root.hi];
        // B: breadth first, siblings side by side
        out.complete.push([0; 8]);
        let mut todo = std::collections::VecDeque::from([(0u32, 0usize)]);
        while let Some((i, slot)) = todo.pop_front() {
            let n = t.nodes[i as usize];
            let mut w = [0u32; 8];
            for c in 0..3 {
                w[c] = n.lo[c].to_bits();
                w[3 + c] = n.hi[c].to_bits();
            }
            match n.kind {
                PmKind::Inner([l, r]) => {
                    let s = out.complete.len();
                    out.complete.extend([[0; 8], [0; 8]]);
                    w[6] = s as u32;
                    w[7] = s as u32 + 1;
                    todo.push_back((l, s));
                    todo.push_back((r, s + 1));
                }
                PmKind::Leaf { first, count } => {
                    w[6] = first;
                    w[7] = count | LEAF_BIT;
                    if count > 0 {
                        out.ends[(first + count - 1) as usize] = true;
                    }
                }
            }
            out.complete[slot] = w;
        }
        out.compact = compact_pairs(&t);
        out
    }

    /// The kernels as the gather kernels read them.
    pub fn kernel_floats(&self) -> Vec<f32> {
        let mut v = Vec::with_capacity(KERNEL_FLOATS * self.kernels.len());
        for (k, &end) in self.kernels.iter().zip(&self.ends) {
            for a in [k.z, k.major, k.m_prime, k.flux, k.normal] {
                v.extend_from_slice(&a);
            }
            v.push(if end { 1.0 } else { 0.0 });
        }
        v
    }
}

/// The compact layout of `t` (its root inner): breadth first over the inner
/// nodes, one 32-byte pair for each one's children; pair 0 holds the root's.
/// Per axis and side the stored plane is the left child's if it differs from
/// the parent's (mask 1), else the right child's if it differs (mask 0), else
/// the parent's, assigned to the left (L2720). A leaf child's word holds its
/// first position with [`REF_LEAF`].
pub fn compact_pairs(t: &PmTree) -> Vec<[u32; 8]> {
    let mut out = vec![[0u32; 8]];
    let mut todo = std::collections::VecDeque::from([(0u32, 0usize)]);
    while let Some((i, pair)) = todo.pop_front() {
        let n = t.nodes[i as usize];
        let PmKind::Inner(kids) = n.kind else { continue };
        let (l, r) = (t.nodes[kids[0] as usize], t.nodes[kids[1] as usize]);
        let mut w = [0u32; 8];
        let (mut lmask, mut umask) = (0u32, 0u32);
        for c in 0..3 {
            let (m, a) = plane(n.lo[c], l.lo[c], r.lo[c]);
            let (mm, b) = plane(n.hi[c], l.hi[c], r.hi[c]);
            w[c] = m.to_bits();
            w[3 + c] = mm.to_bits();
            lmask |= a << (2 - c);
            umask |= b << (2 - c);
        }
        for (side, kid) in kids.into_iter().enumerate() {
            let word = match t.nodes[kid as usize].kind {
                PmKind::Leaf { first, .. } => first | REF_LEAF,
                PmKind::Inner(_) => {
                    let p = out.len();
                    out.push([0; 8]);
                    todo.push_back((kid, p));
                    p as u32
                }
            };
            w[6 + side] = word | ([lmask, umask][side] << 29);
        }
        out[pair] = w;
    }
    out
}

/// Which layout a traversal reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Layout {
    /// The complete representation (32 B a node).
    Complete,
    /// The compact representation (32 B a sibling pair).
    Compact,
}

/// What a traversal did (natively: counted; on the emulator: read off the `@count` lines).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Walk {
    /// Nodes whose AABB was tested (n_T; a compact pair counts two).
    pub nodes: u64,
    /// Stack pushes.
    pub pushes: u64,
    /// Stack pops.
    pub pops: u64,
    /// Kernels retrieved from leaves (n_I).
    pub retrieved: u64,
    /// Retrieved kernels that contributed (facing, ‖d‖ < 1): k summed over the queries.
    pub contributed: u64,
}

impl Walk {
    /// Stack accesses: pushes and pops.
    pub fn stack(&self) -> u64 {
        self.pushes + self.pops
    }

    /// Adds `o`'s counts.
    pub fn add(&mut self, o: &Walk) {
        self.nodes += o.nodes;
        self.pushes += o.pushes;
        self.pops += o.pops;
        self.retrieved += o.retrieved;
        self.contributed += o.contributed;
    }
}

fn evaluate(k: &Kernel, q: &Query, shape: Shape, sum: &mut [f32; 3], walk: &mut Walk) {
    use std::cmp::Ordering::{Greater, Less};
    walk.retrieved += 1;
    if super::photons::dot(k.normal, q.n).partial_cmp(&0.0) != Some(Greater) {
        return;
    }
    let d = d2(k.z, k.m_prime, k.major, q.x);
    if d.partial_cmp(&1.0) != Some(Less) {
        return;
    }
    walk.contributed += 1;
    let w = shape.weight(d);
    for (s, f) in sum.iter_mut().zip(k.flux) {
        *s += w * f;
    }
}

fn in_root(l: &Layouts, x: [f32; 3]) -> bool {
    let [lo, hi] = l.root;
    lo[0] < x[0] && lo[1] < x[1] && lo[2] < x[2] && hi[0] > x[0] && hi[1] > x[1] && hi[2] > x[2]
}

fn f(w: u32) -> f32 {
    f32::from_bits(w)
}

/// The native gather at `q` through `layout` (the kernel's traversal step for step).
pub fn gather(l: &Layouts, layout: Layout, q: &Query, shape: Shape) -> ([f32; 3], Walk) {
    let mut sum = [0.0f32; 3];
    let mut w = Walk::default();
    let x = q.x;
    if !l.complete.is_empty() && in_root(l, x) {
        match layout {
            Layout::Complete => complete(l, q, shape, &mut sum, &mut w),
            Layout::Compact => compact(l, q, shape, &mut sum, &mut w),
        }
    }
    (std::array::from_fn(|c| q.weight[c] * std::f32::consts::FRAC_1_PI * sum[c]), w)
}

fn complete(l: &Layouts, q: &Query, shape: Shape, sum: &mut [f32; 3], w: &mut Walk) {
    let x = q.x;
    let mut stack = vec![1u32];
    w.pushes += 1;
    let mut node = 2u32;
    loop {
        let n = &l.complete[node as usize];
        w.nodes += 1;
        if f(n[0]) < x[0] && f(n[1]) < x[1] && f(n[2]) < x[2] && f(n[3]) > x[0] && f(n[4]) > x[1] && f(n[5]) > x[2] {
            let (a, b) = (n[6], n[7]);
            if b & LEAF_BIT == 0 {
                stack.push(a);
                w.pushes += 1;
                node = b;
                continue;
            }
            for k in &l.kernels[a as usize..(a + (b & !LEAF_BIT)) as usize] {
                evaluate(k, q, shape, sum, w);
            }
        }
        let Some(next) = stack.pop() else { break };
        w.pops += 1;
        node = next;
    }
}

fn leaf(l: &Layouts, first: u32, q: &Query, shape: Shape, sum: &mut [f32; 3], w: &mut Walk) {
    for (k, &end) in l.kernels[first as usize..].iter().zip(&l.ends[first as usize..]) {
        evaluate(k, q, shape, sum, w);
        if end {
            return;
        }
    }
}

fn compact(l: &Layouts, q: &Query, shape: Shape, sum: &mut [f32; 3], w: &mut Walk) {
    let x = q.x;
    let mut stack = Vec::new();
    let mut pair = 0u32;
    loop {
        let p = &l.compact[pair as usize];
        w.nodes += 2;
        let bit = |b: bool, s: u32| (b as u32) << s;
        let miss = bit(f(p[0]) >= x[0], 5)
            | bit(f(p[1]) >= x[1], 4)
            | bit(f(p[2]) >= x[2], 3)
            | bit(f(p[3]) <= x[0], 2)
            | bit(f(p[4]) <= x[1], 1)
            | bit(f(p[5]) <= x[2], 0);
        let (w0, w1) = (p[6], p[7]);
        let left = ((w0 >> 29) << 3) | (w1 >> 29);
        let (in_l, in_r) = (left & miss == 0, !left & miss == 0);
        let mut next = None;
        if in_l {
            if w0 & REF_LEAF != 0 {
                leaf(l, w0 & REF_MASK, q, shape, sum, w);
            } else {
                next = Some(w0 & REF_MASK);
            }
        }
        if in_r {
            if w1 & REF_LEAF != 0 {
                leaf(l, w1 & REF_MASK, q, shape, sum, w);
            } else {
                if let Some(n) = next {
                    stack.push(n);
                    w.pushes += 1;
                }
                next = Some(w1 & REF_MASK);
            }
        }
        if let Some(n) = next {
            pair = n;
            continue;
        }
        let Some(n) = stack.pop() else { break };
        w.pops += 1;
        pair = n;
    }
}

/// Traffic of the traversal by the emulator's memory model (gt200 profile),
/// in bytes the threads asked for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Traffic {
    /// Nodes or pairs through the read-only (texture) path.
    pub nodes: u64,
    /// Local-memory loads and stores (the stack).
    pub stack: u64,
}

/// An emulated gather: the radiance per query, the walk read off the
/// `@count` lines, the traffic off the memory model, the launch's counters.
#[derive(Debug, Clone)]
pub struct Gathered {
    /// Reflected radiance per query (zero where no query).
    pub radiance: Vec<[f32; 3]>,
    /// Summed over the queries.
    pub walk: Walk,
    /// Summed over the queries.
    pub traffic: Traffic,
    /// Everything the memory model counted.
    pub memory: crate::model::ModelStats,
    /// The launch.
    pub launch: LaunchStats,
}

/// Per tag name, the lanes that executed the tagged instruction on a tagged line of `pmgather.cu`.
pub fn line_counts(prog: &Program, stats: &LaunchStats) -> BTreeMap<String, u64> {
    tagged_counts(prog, &stats.profile, SOURCE_FILE, &count_tags(SOURCE), |c| c.pred_on)
}

/// One traversal launch on the emulator, observed by the gt200 memory model.
#[derive(Debug, Clone)]
pub(super) struct TraversalRun {
    /// The output buffer: four floats an item.
    pub out: Vec<f32>,
    /// Node (read-only path) and stack (local) bytes by the memory model.
    pub traffic: Traffic,
    /// Everything the memory model counted.
    pub memory: crate::model::ModelStats,
    /// The launch.
    pub launch: LaunchStats,
}

/// Uploads `buffers` (named for errors), launches `entry` of `module` over
/// `n` items (at most [`MAX_CTAS`] CTAs of [`THREADS`], the buffers then an
/// output of four floats an item as its arguments) under the gt200 memory
/// model, and reads back the output and the read-only and local traffic:
/// the launch the gather and scene-BVH kernels share.
pub(super) fn run_traversal(
    dev: &mut Device,
    module: &Module,
    entry: &str,
    buffers: &[(&[u8], &str)],
    n: usize,
) -> Result<TraversalRun, SimError> {
    let mut args = Vec::with_capacity(buffers.len() + 1);
    for (bytes, name) in buffers {
        args.push(Arg::Ptr(upload(dev, bytes, name)?));
    }
    let out = dev.alloc_zeroed::<f32>(4 * n.max(1));
    args.push(Arg::Ptr(out));
    let model = Model::new(Profile::Gt200, &module.prog);
    let ctas = (n.div_ceil(THREADS as usize) as u32).clamp(1, MAX_CTAS);
    let launch = dev.launch_observed(module, entry, LaunchConfig::linear(ctas, THREADS), &args, Some(&model))?;
    let memory = model.finish();
    let m = &memory.counters;
    let traffic = Traffic { nodes: m.texture.bytes, stack: m.local_ld.bytes + m.local_st.bytes };
    Ok(TraversalRun { out: dev.read::<f32>(out, 4 * n), traffic, memory, launch })
}

/// Loads the gather kernels' PTX on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/fabianowski2011/pmgather.ptx")
}

/// Runs the gather kernel of `layout` at `queries` on the emulator.
pub fn gather_kernel(
    dev: &mut Device,
    module: &Module,
    l: &Layouts,
    layout: Layout,
    queries: &[Option<Query>],
    shape: Shape,
) -> Result<Gathered, PhotonError> {
    let n = queries.len();
    if n > i32::MAX as usize {
        return Err(PhotonError::TooMany(n));
    }
    // an empty map: a root box no point is inside
    let root = if l.complete.is_empty() { [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]] } else { l.root };
    let mut params = to_bytes(&[root[0], root[1]].concat());
    params.extend(to_bytes(&[n as i32, shape.code()]));
    let q: Vec<f32> = queries.iter().flat_map(|q| Query::floats(q.as_ref())).collect();
    let (entry, nodes) = match layout {
        Layout::Complete => (COMPLETE, &l.complete),
        Layout::Compact => (COMPACT, &l.compact),
    };
    let buffers = [
        (&params[..], "params"),
        (&to_bytes(&nodes.concat())[..], "nodes"),
        (&to_bytes(&l.kernel_floats())[..], "kernels"),
        (&to_bytes(&q)[..], "queries"),
    ];
    let run = run_traversal(dev, module, entry, &buffers, n)?;
    let c = line_counts(&module.prog, &run.launch);
    let get = |k: &str| c.get(k).copied().unwrap_or(0);
    let walk = Walk {
        nodes: get("nodes") + 2 * get("pairs"),
        pushes: get("push"),
        pops: get("pop"),
        retrieved: get("retrieved"),
        contributed: get("contributed"),
    };
    let radiance = run.out.chunks_exact(4).map(|r| [r[0], r[1], r[2]]).collect();
    Ok(Gathered { radiance, walk, traffic: run.traffic, memory: run.memory, launch: run.launch })
}

/// The native gathers at `queries` (radiance per query, the walks summed).
pub fn gather_all(l: &Layouts, layout: Layout, queries: &[Option<Query>], shape: Shape) -> (Vec<[f32; 3]>, Walk) {
    use rayon::prelude::*;
    let each: Vec<([f32; 3], Walk)> = queries
        .par_iter()
        .map(|q| q.as_ref().map_or(([0.0; 3], Walk::default()), |q| gather(l, layout, q, shape)))
        .collect();
    let mut total = Walk::default();
    for (_, w) in &each {
        total.add(w);
    }
    (each.into_iter().map(|(r, _)| r).collect(), total)
}

/// `c` relative to `b` in percent.
pub(super) fn change(c: f64, b: f64) -> f64 {
    (c / b - 1.0) * 100.0
}

/// The six columns Tables 6.4 and 6.5 share after their counts: Bytes B,
/// Bytes C, Instr. B, Instr. C, FPS B and FPS C, with `digits` decimals for
/// the three absolute ones. Instr. B is shown, not compared: the thesis
/// counts `instr_whole`, ours the traversal kernel alone (`instr_ours`), so
/// only the relative Instr. C is the same quantity; the FPS are modelled by
/// the GTX 280 timing model on the emulator's counters, FPS B within
/// [`super::timing::FPS_TOLERANCE`], the relative FPS C within the ratio
/// tolerance.
pub(super) fn layout_columns(
    digits: [usize; 3],
    instr_whole: &str,
    instr_ours: &str,
) -> Vec<crate::repro::table::Column> {
    use crate::repro::compare::Tolerance;
    use crate::repro::table::{Column, Unit};
    let instr_why = format!("the thesis counts {instr_whole}, ours {instr_ours}: not the same quantity");
    let model = super::timing::MODEL;
    vec![
        Column::measured("Bytes B", Unit::Number(digits[0]), Tolerance::COUNT),
        Column::measured("Bytes C", Unit::Change, Tolerance::RATIO),
        Column::measured("Instr. B", Unit::Number(digits[1]), Tolerance::COUNT).uncompared(&instr_why),
        Column::measured("Instr. C", Unit::Change, Tolerance::RATIO),
        Column::modelled("FPS B", Unit::Number(digits[2]), model, Some(super::timing::FPS_TOLERANCE), None),
        Column::modelled("FPS C", Unit::Change, model, Some(Tolerance::RATIO), None),
    ]
}
