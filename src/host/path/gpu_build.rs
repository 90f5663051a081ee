//! Thesis 003's GPU full-SAH kd-tree construction (Lin 2017 §6.5,
//! 003:L548-587) on the emulator: the kernels of
//! `kernels/lin2017/kdbuild.cu`, launched level by level (breadth first)
//! from here, and [`twin`], the same algorithm serially in Rust.
//!
//! The root's events (a start and an end per triangle and dimension) are
//! sorted once by a merge sort; every level then costs each event's position
//! by the SAH (003:L560-562) with the counts from a scan of the end events,
//! takes each node's cheapest event by a 64-bit `atomicMin` (the thesis'
//! segmented reduction), decides split or leaf (003:L564), marks each
//! reference left, right or leaf in a bit array, scans it and compacts the
//! triangle list and the events into the next level's (003:L564-576).
//! Nodes are numbered level by level: the left children of a level's split
//! nodes, then the right children, in their parents' order.
//!
//! As the thesis describes it (003:L560, L576), a node's SAH evaluates the
//! events of **one axis**, the longest of its box; Wald and Havran's
//! construction, the thesis' CPU reference (Table 2), sweeps all three. The
//! kernels do either ([`GpuParams::all_axes`]), so that erratum 13 of the
//! extract (the "same tree" claim, 003:L578) can be measured
//! (`docs/reproduction-lin2017.md`). Per-node axes need no rotation of the
//! event arrays (003:L576): an event's thread reads its node's axis.
//!
//! Not stated by the thesis, ours: K_T, K_I, the depth limit and the leaf
//! rule are those of [`super::build::Params::fig3`] (leaf when no candidate,
//! at the depth limit, or when the best cost is not below K_I n while n fits
//! the node's 6-bit count); at one position the events sort flat triangles'
//! starts, their ends, the other ends, the other starts, so that a sweep
//! counts a flat triangle in the plane on the left (003:L562); the event
//! owner is read through the triangle list's owner array rather than kept
//! as a fourth array (the segments are the same, 003:L576).

use glam::Vec3;

use super::build::{self, Construction};
use super::layout::MAX_LEAF;
use crate::host::kdtree::{Aabb, Heuristic, KdTree, Node};
use crate::model::{Model, Profile};
use crate::sim::{Arg, Counters, Device, DevicePtr, Element, Fidelity, LaunchConfig, Module, SimConfig, SimError};

/// The kernels' PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/lin2017/kdbuild.ptx");
/// Threads per CTA of every launch (`KD_THREADS`).
pub const THREADS: u32 = 256;
/// Words of a level's node struct (`KdNode`).
pub const NODE_WORDS: usize = 16;
/// The split dimension of a leaf (`KD_LEAF`).
const LEAF: u32 = 3;
/// A node's best key before any candidate (`NO_SPLIT`).
const NO_SPLIT: u64 = u64::MAX;
/// Event flag: an end event (`EV_END`).
const EV_END: u32 = 1;
/// Event flag: the triangle is flat in the event's dimension (`EV_FLAT`).
const EV_FLAT: u32 = 2;
/// Triangles the event keys can address (30 bits).
pub const MAX_TRIANGLES: usize = 1 << 30;
/// The most triangle references a level may hold: the kernels index a
/// level's 6 x 2 t event-side entries (`kd_event_flags`, `kd_event_scatter`:
/// `6u * ev`, ev = 2 t) in 32 bits, so 12 t < 2^32; the best key keeps a
/// node's event (fewer than 2 t) in 30 bits, which this bound implies
/// (2 t < 2^30). A level holds more references than the build has triangles
/// (the bunny's level 19: 220,750 for 69,451).
pub const MAX_LEVEL_REFS: usize = (u32::MAX / 12) as usize;

/// Construction parameters (none stated by the thesis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuParams {
    /// Cost of a traversal step, K_T.
    pub k_t: f32,
    /// Cost of a triangle test, K_I.
    pub k_i: f32,
    /// Deepest level (the root is level 0).
    pub max_depth: u32,
    /// Nodes with more triangles are split even when splitting costs more.
    pub max_leaf: u32,
    /// Evaluate the events of all three axes (Wald and Havran) instead of the
    /// node's longest axis alone (the thesis, 003:L560).
    pub all_axes: bool,
}

impl GpuParams {
    /// The thesis' construction over `n` triangles with Fig. 3's fixtures
    /// ([`build::Params::fig3`]), one axis per node.
    pub fn thesis(n: usize) -> GpuParams {
        let p = build::Params::fig3(Construction::Sah, n);
        GpuParams { k_t: p.k_t, k_i: p.k_i, max_depth: p.max_depth, max_leaf: MAX_LEAF as u32, all_axes: false }
    }

    /// The serial CPU construction with the same fixtures, without clipping
    /// (Table 2's "full SAH without triangle clipping", 003:L578).
    pub fn serial(&self) -> build::Params {
        build::Params {
            construction: Construction::Sah,
            k_t: self.k_t,
            k_i: self.k_i,
            median_leaf: 8,
            max_depth: self.max_depth,
            clip: false,
        }
    }
}

/// Why a build failed.
#[derive(Debug, thiserror::Error)]
pub enum GpuBuildError {
    /// The emulator faulted.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// More triangles than the event keys address.
    #[error("{0} triangles: the GPU build's event keys address at most 2^30")]
    TooMany(usize),
    /// A level holds more references than the kernels index in 32 bits.
    #[error(
        "level {depth} of the GPU build holds {refs} triangle references: the kernels index 12 entries a reference in 32 bits, so at most {MAX_LEVEL_REFS}"
    )]
    TooManyRefs {
        /// The level (the root is 0).
        depth: u32,
        /// Its triangle references.
        refs: usize,
    },
    /// A count passed to a kernel does not fit its 32-bit parameter.
    #[error("a count of {0} does not fit the kernels' 32-bit parameters")]
    Count(usize),
}

/// Refuses a level of `refs` triangle references that the kernels cannot
/// index ([`MAX_LEVEL_REFS`]): the emulated build and its twin check each level.
pub fn check_level(depth: u32, refs: usize) -> Result<(), GpuBuildError> {
    if refs > MAX_LEVEL_REFS {
        return Err(GpuBuildError::TooManyRefs { depth, refs });
    }
    Ok(())
}

/// What one level (or the root's sort) cost on the emulator.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct LevelCost {
    /// Nodes of the level.
    pub nodes: u64,
    /// Of them split.
    pub splits: u64,
    /// Triangle references of the level.
    pub refs: u64,
    /// Kernel launches.
    pub launches: u64,
    /// Warp instructions issued.
    pub warp_instructions: u64,
    /// Thread instructions.
    pub thread_instructions: u64,
    /// Bytes of global memory moved: 32-byte sectors of the loads, stores and
    /// atomics on the hopper profile (fidelity `memory`; 0 below it).
    pub bytes: u64,
}

/// A build on the emulator.
#[derive(Debug, Clone)]
pub struct GpuBuild {
    /// The tree.
    pub tree: KdTree,
    /// The root's event sort (events, merge passes, unpacking).
    pub sort: LevelCost,
    /// Per level, the root first.
    pub levels: Vec<LevelCost>,
    /// Every launch's counters.
    pub totals: Counters,
}

impl GpuBuild {
    /// Launches, warp instructions and bytes of the whole build.
    pub fn total(&self) -> LevelCost {
        let mut t = self.sort.clone();
        for l in &self.levels {
            t.nodes += l.nodes;
            t.splits += l.splits;
            t.refs += l.refs;
            t.launches += l.launches;
            t.warp_instructions += l.warp_instructions;
            t.thread_instructions += l.thread_instructions;
            t.bytes += l.bytes;
        }
        t
    }
}

/// The bounds of `tris` (the root's box; a point at the origin when empty).
fn bounds_of(tris: &[[Vec3; 3]]) -> Aabb {
    let mut b = Aabb::EMPTY;
    for v in tris.iter().flatten() {
        b.grow(*v);
    }
    if tris.is_empty() { Aabb { lo: Vec3::ZERO, hi: Vec3::ZERO } } else { b }
}

/// The longest axis of `b`, ties to the lower axis (`longest` in the kernel).
fn longest(lo: [f32; 3], hi: [f32; 3]) -> u32 {
    let e = |k: usize| (hi[k] - lo[k]).max(0.0);
    let (x, y, z) = (e(0), e(1), e(2));
    if x >= y && x >= z {
        0
    } else if y >= z {
        1
    } else {
        2
    }
}

/// Surface area as [`Aabb::area`].
fn area(lo: [f32; 3], hi: [f32; 3]) -> f32 {
    Aabb { lo: Vec3::from(lo), hi: Vec3::from(hi) }.area()
}

/// A level's node, as `KdNode`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct LNode {
    lo: [f32; 3],
    hi: [f32; 3],
    tri_off: u32,
    n: u32,
    axis: u32,
    depth: u32,
    split_dim: u32,
    best_ev: u32,
    split: f32,
}

impl LNode {
    fn root(b: &Aabb, n: u32) -> LNode {
        let (lo, hi) = (b.lo.to_array(), b.hi.to_array());
        LNode { lo, hi, tri_off: 0, n, axis: longest(lo, hi), depth: 0, split_dim: LEAF, best_ev: 0, split: 0.0 }
    }

    fn words(&self) -> [u32; NODE_WORDS] {
        let f = f32::to_bits;
        let (l, h) = (self.lo, self.hi);
        [
            f(l[0]),
            f(l[1]),
            f(l[2]),
            f(h[0]),
            f(h[1]),
            f(h[2]),
            self.tri_off,
            self.n,
            self.axis,
            self.depth,
            self.split_dim,
            self.best_ev,
            f(self.split),
            0,
            0,
            0,
        ]
    }
}

/// Float order as unsigned order (`ord` in the kernel; -0 as +0).
fn ord(x: f32) -> u32 {
    let b = if x.to_bits() == 0x8000_0000 { 0 } else { x.to_bits() };
    if b & 0x8000_0000 != 0 { !b } else { b | 0x8000_0000 }
}

/// The root's sorted event keys of dimension `d` (`kd_init_events` and the sort).
fn root_keys(tris: &[[Vec3; 3]], d: usize) -> Vec<u64> {
    let mut keys = Vec::with_capacity(2 * tris.len());
    for (t, v) in tris.iter().enumerate() {
        let (a, b, c) = (v[0][d], v[1][d], v[2][d]);
        let (lo, hi) = (a.min(b.min(c)), a.max(b.max(c)));
        let flat = lo == hi;
        let class = |start: bool| -> u64 {
            match (flat, start) {
                (true, true) => 0,
                (true, false) => 1,
                (false, false) => 2,
                (false, true) => 3,
            }
        };
        keys.push((u64::from(ord(lo)) << 32) | (class(true) << 30) | t as u64);
        keys.push((u64::from(ord(hi)) << 32) | (class(false) << 30) | t as u64);
    }
    keys.sort_unstable();
    keys
}

/// A level's events, dimension-major (`kd_unpack`'s arrays).
struct Events {
    pos: Vec<f32>,
    flags: Vec<u32>,
    tri: Vec<u32>,
}

fn unpack(keys: &[u64]) -> Events {
    let mut e = Events { pos: Vec::new(), flags: Vec::new(), tri: Vec::new() };
    for &k in keys {
        let class = ((k >> 30) & 3) as u32;
        let u = (k >> 32) as u32;
        e.pos.push(f32::from_bits(if u & 0x8000_0000 != 0 { u & 0x7fff_ffff } else { !u }));
        e.flags.push(if class == 1 || class == 2 { EV_END } else { 0 } | if class <= 1 { EV_FLAT } else { 0 });
        e.tri.push((k & 0x3fff_ffff) as u32);
    }
    e
}

/// Exclusive prefix sums of `x != 0` with the total appended.
fn scan(x: impl Iterator<Item = bool>) -> Vec<u32> {
    let mut out = vec![0];
    let mut s = 0u32;
    for b in x {
        s += b as u32;
        out.push(s);
    }
    out
}

/// The tree from the levels' records (`kd_nodes`' 4 words a node) and the leaf triangles.
fn assemble(records: &[u32], leaf_tris: Vec<u32>, bounds: Aabb, depth: u32) -> KdTree {
    let nodes = records
        .chunks_exact(4)
        .map(|r| {
            if r[0] == LEAF {
                Node::Leaf { first: r[2], count: r[3] }
            } else {
                Node::Inner { axis: r[0] as u8, split: f32::from_bits(r[1]), left: r[2], right: r[3] }
            }
        })
        .collect();
    KdTree { nodes, tri_refs: leaf_tris, bounds, depth, heuristic: Heuristic::Sah, budget_hit: false }
}

/// The SAH cost of `tree` (f64): K_T SA(n)/SA(root) per inner node plus
/// K_I |T| SA(n)/SA(root) per leaf, with the boxes the splits give.
pub fn sah_cost(tree: &KdTree, k_t: f64, k_i: f64) -> f64 {
    let root = f64::from(tree.bounds.area());
    if root <= 0.0 || tree.nodes.is_empty() {
        return 0.0;
    }
    let mut sum = 0.0;
    let mut todo = vec![(0usize, tree.bounds)];
    while let Some((i, b)) = todo.pop() {
        let p = f64::from(b.area()) / root;
        match tree.nodes[i] {
            Node::Inner { axis, split, left, right } => {
                sum += k_t * p;
                let (mut l, mut r) = (b, b);
                l.hi[axis as usize] = split;
                r.lo[axis as usize] = split;
                todo.push((left as usize, l));
                todo.push((right as usize, r));
            }
            Node::Leaf { count, .. } => sum += k_i * f64::from(count) * p,
        }
    }
    sum
}

/// The construction serially, step for step as the kernels (the same float
/// operations, the same tie rules): the emulated build's native reference.
pub fn twin(tris: &[[Vec3; 3]], p: &GpuParams) -> Result<KdTree, GpuBuildError> {
    if tris.len() >= MAX_TRIANGLES {
        return Err(GpuBuildError::TooMany(tris.len()));
    }
    let bounds = bounds_of(tris);
    let mut t = tris.len();
    let mut keys = Vec::with_capacity(6 * t);
    for d in 0..3 {
        keys.extend(root_keys(tris, d));
    }
    let mut ev = unpack(&keys);
    let mut tri_list: Vec<u32> = (0..t as u32).collect();
    let mut tri_owner = vec![0u32; t];
    let mut nodes = vec![LNode::root(&bounds, t as u32)];
    let (mut records, mut leaf_tris) = (Vec::new(), Vec::new());
    let mut depth = 0;
    loop {
        check_level(depth, t)?;
        let e = 2 * t;
        let ends = scan(ev.flags.iter().map(|f| f & EV_END != 0));
        let mut best = vec![NO_SPLIT; nodes.len()];
        for g in 0..3 * e {
            let (d, ei) = (g / e, g % e);
            let o = tri_owner[ev.tri[g] as usize] as usize;
            let nd = &nodes[o];
            if nd.depth >= p.max_depth || (!p.all_axes && d as u32 != nd.axis) {
                continue;
            }
            let pos = ev.pos[g];
            if !(pos > nd.lo[d] && pos < nd.hi[d]) {
                continue;
            }
            let a = area(nd.lo, nd.hi);
            if a.is_nan() || a <= 0.0 {
                continue;
            }
            let off = 2 * nd.tri_off as usize;
            let rel = (ei - off) as u32;
            let is_end = ev.flags[g] & EV_END;
            let e_incl = ends[g] + is_end - ends[d * e + off];
            let (n_r, n_l) = (nd.n - e_incl, rel - e_incl + is_end);
            let (mut l_hi, mut r_lo) = (nd.hi, nd.lo);
            l_hi[d] = pos;
            r_lo[d] = pos;
            let cost = p.k_t + p.k_i * (area(nd.lo, l_hi) / a * n_l as f32 + area(r_lo, nd.hi) / a * n_r as f32);
            let key = (u64::from(cost.to_bits()) << 32) | ((d as u64) << 30) | u64::from(rel);
            best[o] = best[o].min(key);
        }
        let mut is_split = vec![false; nodes.len()];
        for (o, nd) in nodes.iter_mut().enumerate() {
            let b = best[o];
            let split = b != NO_SPLIT
                && nd.depth < p.max_depth
                && nd.n > 0
                && (f32::from_bits((b >> 32) as u32) < p.k_i * nd.n as f32 || nd.n > p.max_leaf);
            if split {
                let (d, rel) = (((b >> 30) & 3) as u32, (b & 0x3fff_ffff) as u32);
                nd.split_dim = d;
                nd.best_ev = rel;
                nd.split = ev.pos[d as usize * e + 2 * nd.tri_off as usize + rel as usize];
            } else {
                nd.split_dim = LEAF;
            }
            is_split[o] = split;
        }
        let rank = scan(is_split.iter().copied());
        let splits = rank[nodes.len()];
        let mut bits = vec![false; 3 * t];
        for g in 0..3 * e {
            let (d, ei) = (g / e, g % e);
            let a = ev.tri[g] as usize;
            let nd = &nodes[tri_owner[a] as usize];
            let f = ev.flags[g];
            if nd.split_dim == LEAF {
                if d == 0 && f & EV_END == 0 {
                    bits[2 * t + a] = true;
                }
                continue;
            }
            if d as u32 != nd.split_dim {
                continue;
            }
            let rel = (ei - 2 * nd.tri_off as usize) as u32;
            if f & EV_END == 0 && rel < nd.best_ev {
                bits[a] = true;
            }
            if f & EV_END != 0 && rel > nd.best_ev {
                bits[t + a] = true;
            }
            if f & EV_FLAT != 0 && ev.pos[g] == nd.split {
                bits[a] = true;
                bits[t + a] = true;
            }
        }
        let addr = scan(bits.iter().copied());
        let next_t = addr[2 * t] as usize;
        let level_base = (records.len() / 4) as u32;
        let leaf_base = leaf_tris.len() as u32;
        let mut next = vec![LNode::default(); 2 * splits as usize];
        for (o, nd) in nodes.iter().enumerate() {
            if nd.split_dim == LEAF {
                records.extend([LEAF, 0, leaf_base + addr[2 * t + nd.tri_off as usize] - addr[2 * t], nd.n]);
                continue;
            }
            let (d, r) = (nd.split_dim as usize, rank[o]);
            let next_base = level_base + nodes.len() as u32;
            records.extend([d as u32, nd.split.to_bits(), next_base + r, next_base + splits + r]);
            for side in 0..2usize {
                let (mut lo, mut hi) = (nd.lo, nd.hi);
                if side == 0 {
                    hi[d] = nd.split;
                } else {
                    lo[d] = nd.split;
                }
                let first = addr[side * t + nd.tri_off as usize];
                let n = addr[side * t + (nd.tri_off + nd.n) as usize] - first;
                let k = if side == 0 { r } else { splits + r } as usize;
                next[k] = LNode {
                    lo,
                    hi,
                    tri_off: first,
                    n,
                    axis: longest(lo, hi),
                    depth: nd.depth + 1,
                    split_dim: LEAF,
                    best_ev: 0,
                    split: 0.0,
                };
            }
        }
        let (mut next_list, mut next_owner) = (vec![0u32; next_t], vec![0u32; next_t]);
        for (k, _) in bits.iter().enumerate().filter(|(_, b)| **b) {
            let (side, a) = (k / t, k % t);
            if side == 2 {
                leaf_tris.push(tri_list[a]);
                continue;
            }
            let at = addr[k] as usize;
            next_list[at] = tri_list[a];
            next_owner[at] = if side == 0 { 0 } else { splits } + rank[tri_owner[a] as usize];
        }
        if splits == 0 {
            break;
        }
        let mut nev = Events { pos: Vec::new(), flags: Vec::new(), tri: Vec::new() };
        for d in 0..3 {
            for side in 0..2 {
                for ei in 0..e {
                    let g = d * e + ei;
                    let at = side * t + ev.tri[g] as usize;
                    if bits[at] {
                        nev.pos.push(ev.pos[g]);
                        nev.flags.push(ev.flags[g]);
                        nev.tri.push(addr[at]);
                    }
                }
            }
        }
        ev = nev;
        tri_list = next_list;
        tri_owner = next_owner;
        nodes = next;
        t = next_t;
        depth += 1;
    }
    Ok(assemble(&records, leaf_tris, bounds, depth))
}

/// A device buffer that grows (the emulator never frees; a larger one replaces it).
#[derive(Debug, Clone, Copy)]
struct Buf {
    ptr: DevicePtr,
    cap: usize,
}

impl Buf {
    fn new() -> Buf {
        Buf { ptr: DevicePtr(0), cap: 0 }
    }

    /// At least `n` elements of `T` (1 at least).
    fn ensure<T: Element>(&mut self, dev: &mut Device, n: usize) -> DevicePtr {
        if self.cap < n.max(1) {
            self.cap = n.max(1).max(2 * self.cap);
            self.ptr = dev.alloc_zeroed::<T>(self.cap);
        }
        self.ptr
    }
}

/// Launches and accounts one level's (or the sort's) kernels.
struct Launcher<'a> {
    dev: &'a mut Device,
    module: &'a Module,
    model: Option<Model>,
    cost: LevelCost,
    totals: Counters,
}

impl Launcher<'_> {
    fn launch(&mut self, kernel: &str, threads: usize, args: &[Arg]) -> Result<(), SimError> {
        let blocks = (threads.max(1)).div_ceil(THREADS as usize) as u32;
        self.launch_grid(kernel, blocks, args)
    }

    fn launch_grid(&mut self, kernel: &str, blocks: u32, args: &[Arg]) -> Result<(), SimError> {
        let cfg = LaunchConfig::linear(blocks, THREADS);
        let obs = self.model.as_ref().map(|m| m as &dyn crate::sim::ObserverFactory);
        let st = self.dev.launch_observed(self.module, kernel, cfg, args, obs)?;
        self.cost.launches += 1;
        self.cost.warp_instructions += st.totals.warp_instructions;
        self.cost.thread_instructions += st.totals.thread_instructions;
        self.totals.merge(&st.totals);
        Ok(())
    }

    /// Exclusive scan of `(input[j] & mask) != 0` for j < n into `out` (n + 1
    /// entries, the total last); returns the total.
    fn scan(&mut self, input: DevicePtr, mask: u32, n: usize, out: DevicePtr, sums: &mut Buf) -> Result<u32, SimError> {
        let blocks = n.div_ceil(THREADS as usize).max(1);
        let s = sums.ensure::<u32>(self.dev, blocks + 1);
        let (n32, b32) = (n as u32, blocks as u32);
        self.launch_grid(
            "kd_scan_blocks",
            b32,
            &[Arg::Ptr(input), Arg::U32(mask), Arg::U32(n32), Arg::Ptr(out), Arg::Ptr(s)],
        )?;
        self.launch_grid("kd_scan_sums", 1, &[Arg::Ptr(s), Arg::U32(b32)])?;
        self.launch("kd_scan_add", n + 1, &[Arg::Ptr(out), Arg::Ptr(s), Arg::U32(n32), Arg::U32(b32)])?;
        Ok(self.dev.try_read::<u32>(DevicePtr(out.0 + 4 * n as u64), 1)?[0])
    }

    /// Closes the account: the cost so far, and a fresh one.
    fn take(&mut self, nodes: u64, splits: u64, refs: u64) -> LevelCost {
        let mut c = std::mem::take(&mut self.cost);
        (c.nodes, c.splits, c.refs) = (nodes, splits, refs);
        if let Some(m) = &self.model {
            let s = m.finish().counters;
            let sectors = s.global_ld.sectors + s.global_st.sectors + s.global_atom.sectors + s.global_red.sectors;
            c.bytes = 32 * sectors;
            self.model = Some(Model::new(Profile::Hopper, &self.module.prog));
        }
        c
    }
}

/// Loads the kernels on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/lin2017/kdbuild.ptx")
}

/// A device for the build at `fidelity` (`memory` or above counts the bytes).
pub fn device(fidelity: Fidelity) -> Result<(Device, Module), SimError> {
    let mut dev = Device::with_config(SimConfig { fidelity, ..SimConfig::default() });
    let m = load(&mut dev)?;
    Ok((dev, m))
}

/// Builds the tree of `tris` on the emulator.
pub fn build(dev: &mut Device, module: &Module, tris: &[[Vec3; 3]], p: &GpuParams) -> Result<GpuBuild, GpuBuildError> {
    let n = tris.len();
    if n >= MAX_TRIANGLES {
        return Err(GpuBuildError::TooMany(n));
    }
    let bounds = bounds_of(tris);
    let counted = dev.config().fidelity >= Fidelity::Memory;
    let model = counted.then(|| Model::new(Profile::Hopper, &module.prog));
    let mut l = Launcher { dev, module, model, cost: LevelCost::default(), totals: Counters::default() };
    // the root's events: keys, merge passes, SoA
    let verts: Vec<f32> = tris.iter().flatten().flat_map(|v| v.to_array()).collect();
    let vbuf = l.dev.alloc_from(&verts);
    let m = 2 * n;
    let mut keys = [l.dev.alloc_zeroed::<u64>(3 * m), l.dev.alloc_zeroed::<u64>(3 * m)];
    let (mut pos, mut flags, mut tri) = (Buf::new(), Buf::new(), Buf::new());
    let (mut npos, mut nflags, mut ntri) = (Buf::new(), Buf::new(), Buf::new());
    if n > 0 {
        l.launch("kd_init_events", 3 * n, &[Arg::Ptr(vbuf), Arg::U32(n as u32), Arg::Ptr(keys[0])])?;
        let mut width = 1usize;
        while width < m {
            let args = [Arg::Ptr(keys[0]), Arg::Ptr(keys[1]), Arg::U32(m as u32), Arg::U32(3), Arg::U32(width as u32)];
            l.launch("kd_merge_pass", 3 * m, &args)?;
            keys.swap(0, 1);
            width *= 2;
        }
        let (p_, f_, t_) =
            (pos.ensure::<f32>(l.dev, 3 * m), flags.ensure::<u32>(l.dev, 3 * m), tri.ensure::<u32>(l.dev, 3 * m));
        l.launch(
            "kd_unpack",
            3 * m,
            &[Arg::Ptr(keys[0]), Arg::U32(3 * m as u32), Arg::Ptr(p_), Arg::Ptr(f_), Arg::Ptr(t_)],
        )?;
    }
    let sort = l.take(0, 0, n as u64);
    let ids: Vec<u32> = (0..n as u32).collect();
    let (mut tri_list, mut tri_owner) = (Buf::new(), Buf::new());
    let (mut next_list, mut next_owner) = (Buf::new(), Buf::new());
    let list0 = tri_list.ensure::<u32>(l.dev, n);
    l.dev.write(list0, &ids)?;
    tri_owner.ensure::<u32>(l.dev, n);
    let (mut nodes, mut best, mut next_nodes, mut next_best) = (Buf::new(), Buf::new(), Buf::new(), Buf::new());
    let (root, best0) = (nodes.ensure::<u32>(l.dev, NODE_WORDS), best.ensure::<u64>(l.dev, 1));
    l.dev.write(root, &LNode::root(&bounds, n as u32).words())?;
    l.dev.write(best0, &[NO_SPLIT])?;
    let (mut ends, mut sums, mut is_split, mut rank) = (Buf::new(), Buf::new(), Buf::new(), Buf::new());
    let (mut bits, mut addr, mut rec, mut leaf) = (Buf::new(), Buf::new(), Buf::new(), Buf::new());
    let (mut ev_bits, mut ev_addr) = (Buf::new(), Buf::new());
    let (mut records, mut leaf_tris, mut levels) = (Vec::new(), Vec::new(), Vec::new());
    let (mut t, mut count, mut depth) = (n, 1usize, 0u32);
    let t_ = |x: usize| u32::try_from(x).map(Arg::U32).map_err(|_| GpuBuildError::Count(x));
    let all = Arg::U32(p.all_axes as u32);
    loop {
        check_level(depth, t)?;
        let e = 2 * t;
        let end_scan = ends.ensure::<u32>(l.dev, 3 * e + 1);
        l.scan(flags.ptr, EV_END, 3 * e, end_scan, &mut sums)?;
        let ev_args = [Arg::Ptr(pos.ptr), Arg::Ptr(flags.ptr), Arg::Ptr(tri.ptr)];
        let mut args = vec![Arg::Ptr(nodes.ptr), Arg::Ptr(best.ptr)];
        args.extend(ev_args.iter().cloned());
        args.extend([Arg::Ptr(end_scan), Arg::Ptr(tri_owner.ptr), t_(e)?, all.clone(), Arg::U32(p.max_depth)]);
        args.extend([Arg::F32(p.k_t), Arg::F32(p.k_i)]);
        l.launch("kd_sah", 3 * e, &args)?;
        let flags_split = is_split.ensure::<u32>(l.dev, count);
        let args = [
            Arg::Ptr(nodes.ptr),
            Arg::Ptr(best.ptr),
            t_(count)?,
            Arg::Ptr(pos.ptr),
            t_(e)?,
            Arg::U32(p.max_depth),
            Arg::U32(p.max_leaf),
            Arg::F32(p.k_i),
            Arg::Ptr(flags_split),
        ];
        l.launch("kd_decide", count, &args)?;
        let ranks = rank.ensure::<u32>(l.dev, count + 1);
        let splits = l.scan(flags_split, 1, count, ranks, &mut sums)? as usize;
        let b = bits.ensure::<u32>(l.dev, 3 * t);
        l.launch("kd_clear", 3 * t, &[Arg::Ptr(b), t_(3 * t)?])?;
        let mut args = vec![Arg::Ptr(nodes.ptr)];
        args.extend(ev_args.iter().cloned());
        args.extend([Arg::Ptr(tri_owner.ptr), t_(e)?, t_(t)?, Arg::Ptr(b)]);
        l.launch("kd_assign", 3 * e, &args)?;
        let a = addr.ensure::<u32>(l.dev, 3 * t + 1);
        let total = l.scan(b, 1, 3 * t, a, &mut sums)? as usize;
        let next_t = l.dev.try_read::<u32>(DevicePtr(a.0 + 4 * 2 * t as u64), 1)?[0] as usize;
        let leaves_here = total - next_t;
        let level_base = records.len() / 4;
        let r = rec.ensure::<u32>(l.dev, 4 * count);
        let nn = next_nodes.ensure::<u32>(l.dev, NODE_WORDS * 2 * splits);
        let nb = next_best.ensure::<u64>(l.dev, 2 * splits);
        let args = [
            Arg::Ptr(nodes.ptr),
            t_(count)?,
            Arg::Ptr(ranks),
            t_(splits)?,
            Arg::Ptr(a),
            t_(t)?,
            t_(leaf_tris.len())?,
            t_(level_base)?,
            Arg::Ptr(r),
            Arg::Ptr(nn),
            Arg::Ptr(nb),
        ];
        l.launch("kd_nodes", count, &args)?;
        let (nl, no, lf) = (
            next_list.ensure::<u32>(l.dev, next_t),
            next_owner.ensure::<u32>(l.dev, next_t),
            leaf.ensure::<u32>(l.dev, leaves_here),
        );
        let args = [
            Arg::Ptr(tri_list.ptr),
            Arg::Ptr(tri_owner.ptr),
            Arg::Ptr(b),
            Arg::Ptr(a),
            t_(t)?,
            Arg::Ptr(ranks),
            t_(splits)?,
            Arg::Ptr(nl),
            Arg::Ptr(no),
            Arg::Ptr(lf),
        ];
        l.launch("kd_spawn_tris", 3 * t, &args)?;
        records.extend(l.dev.try_read::<u32>(r, 4 * count)?);
        leaf_tris.extend(l.dev.try_read::<u32>(lf, leaves_here)?);
        if splits > 0 {
            let eb = ev_bits.ensure::<u32>(l.dev, 6 * e);
            l.launch("kd_event_flags", 6 * e, &[Arg::Ptr(tri.ptr), t_(e)?, t_(t)?, Arg::Ptr(b), Arg::Ptr(eb)])?;
            let ea = ev_addr.ensure::<u32>(l.dev, 6 * e + 1);
            l.scan(eb, 1, 6 * e, ea, &mut sums)?;
            let next_e = 2 * next_t;
            let (np, nf, nt) = (
                npos.ensure::<f32>(l.dev, 3 * next_e),
                nflags.ensure::<u32>(l.dev, 3 * next_e),
                ntri.ensure::<u32>(l.dev, 3 * next_e),
            );
            let mut args = ev_args.to_vec();
            args.splice(3..3, [t_(e)?, t_(t)?, Arg::Ptr(eb), Arg::Ptr(ea), Arg::Ptr(a)]);
            args.extend([Arg::Ptr(np), Arg::Ptr(nf), Arg::Ptr(nt)]);
            l.launch("kd_event_scatter", 6 * e, &args)?;
        }
        levels.push(l.take(count as u64, splits as u64, t as u64));
        if splits == 0 {
            break;
        }
        std::mem::swap(&mut pos, &mut npos);
        std::mem::swap(&mut flags, &mut nflags);
        std::mem::swap(&mut tri, &mut ntri);
        std::mem::swap(&mut tri_list, &mut next_list);
        std::mem::swap(&mut tri_owner, &mut next_owner);
        std::mem::swap(&mut nodes, &mut next_nodes);
        std::mem::swap(&mut best, &mut next_best);
        t = next_t;
        count = 2 * splits;
        depth += 1;
    }
    let tree = assemble(&records, leaf_tris, bounds, depth);
    Ok(GpuBuild { tree, sort, levels, totals: l.totals })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn float_order_is_unsigned_order() {
        let xs = [-3.5f32, -1.0, -0.0, 0.0, 1e-30, 2.0, 7.25];
        for w in xs.windows(2) {
            assert!(ord(w[0]) <= ord(w[1]), "{} {}", w[0], w[1]);
        }
        assert_eq!(ord(-0.0), ord(0.0));
        let e = unpack(&[u64::from(ord(-3.5)) << 32 | 3 << 30 | 7]);
        assert_eq!((e.pos[0], e.flags[0], e.tri[0]), (-3.5, 0, 7));
    }

    #[test]
    fn two_separated_triangles_split_between_them_and_cut_off_empty_space() {
        // two small triangles far apart on x, box 10 x 1 x 0.5 (area 31). At
        // the root the end of the first (x = 1) and the start of the second
        // (x = 9) cost the same, 15 + 20 (4/31 + 28/31) = 35.6 < 20 * 2:
        // the lower event wins. The right child [1, 10] (area 28) splits
        // again at 9, 15 + 20 (4/28) = 17.9 < 20, cutting off empty space;
        // [0, 1] has no candidate inside on its longest axis (x).
        let tris = vec![
            [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.5)],
            [v(9.0, 0.0, 0.0), v(10.0, 0.0, 0.0), v(9.0, 1.0, 0.5)],
        ];
        let t = twin(&tris, &GpuParams::thesis(2)).unwrap();
        assert_eq!(
            t.nodes,
            [
                Node::Inner { axis: 0, split: 1.0, left: 1, right: 2 },
                Node::Leaf { first: 0, count: 1 },
                Node::Inner { axis: 0, split: 9.0, left: 3, right: 4 },
                Node::Leaf { first: 1, count: 0 },
                Node::Leaf { first: 1, count: 1 },
            ]
        );
        assert_eq!((t.tri_refs.as_slice(), t.depth), ([0u32, 1].as_slice(), 2));
    }
}
