//! Thesis 000 §6.1.2–6.1.3: the linear BVH (LBVH) photon map, built by
//! kernels (`kernels/fabianowski2011/lbvh.cu`) with the dual "merge"
//! construction, and natively by the same steps.
//!
//! Steps (extract §3.3, L2581–2619): a 30-bit Morton code per interaction (its
//! kernel's centre quantised to 10 bits per axis within the centres' bounds,
//! L2625); the references radix-sorted by code ("radix-sort references
//! (code, primitive index) by code", L2589; [`sort_kernel`]: a stable LSD
//! radix sort of 4 bits a pass, as kernels); runs of identical codes
//! pre-merged (S at both ends, the run's AABB at its first index); a merge
//! point between every two neighbouring runs at the level of their codes'
//! first differing bit; the merge points radix-sorted by level, deepest
//! first (Fig. 6.1(b)); then one
//! launch per level, deepest first, every merge point of the level in
//! parallel: an inner node is made only if S\[i\] + S\[i+1\] > n_auto (the dual
//! termination criterion, L2611), its children being the intervals' nodes or
//! leaves made on the spot (a null pointer, L2607).
//!
//! **n_auto** (§6.1.3, L2613–2619): c · Σ π‖M × m1‖ / Σ A(T) with c = 8,
//! clamped to at least 5; the sums are taken on the host (f64) and rounded to
//! the nearest integer (the thesis prints integers, Table 6.1).
//!
//! Node ids are deterministic: merge point t of a level gets id
//! (merge points of deeper levels) + t, whether or not it makes a node, so
//! the emulated build equals the native one bit for bit (`tests/photon_bvh.rs`).

use super::photons::PhotonError;
use super::pm_layout::{PmKind, PmNode, PmTree};
use super::vkde::Kernel;
use crate::host::scene::Scene;
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, DevicePtr, LaunchConfig, LaunchStats, Module, SimError};

/// The kernels' PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/fabianowski2011/lbvh.ptx");
/// Morton codes of the kernels' centres.
pub const CODES: &str = "lbvh_codes";
/// Runs of identical codes.
pub const RUNS: &str = "lbvh_runs";
/// Merge points' levels.
pub const LEVELS: &str = "lbvh_levels";
/// The merge pass of one level.
pub const MERGE: &str = "lbvh_merge";
/// The sorted references' AABBs.
pub const GATHER: &str = "lbvh_gather";
/// The merge points' sort keys (29 − level; 31 for equal codes).
pub const LEVEL_KEYS: &str = "lbvh_level_keys";
/// Radix sort: per-tile digit counts.
pub const RADIX_COUNT: &str = "radix_count";
/// Radix sort: the exclusive scan of the counts (one CTA).
pub const RADIX_SCAN: &str = "radix_scan";
/// Radix sort: the stable scatter.
pub const RADIX_SCATTER: &str = "radix_scatter";
/// Bits of a radix-sort digit (one pass each).
pub const RADIX_BITS: u32 = 4;
/// Key bits of the merge points' sort by level (keys 0..=31).
pub const LEVEL_KEY_BITS: u32 = 5;
/// Elements per radix-sort tile (the kernels' CTA size).
const SORT_THREADS: usize = 256;
/// The constant c of n_auto (L2617: "c = 8").
pub const C_AUTO: f64 = 8.0;
/// The smallest n_auto (L2617: "clamped to a minimum of 5").
pub const N_AUTO_MIN: u32 = 5;
/// Bits of a Morton code (L2625: "30-bit Morton codes").
pub const CODE_BITS: u32 = 30;
/// A leaf reference in a node record.
pub const LEAF_REF: u32 = 0x8000_0000;
/// Words of a node record: left ref, left count, right ref, right count, left box, right box.
pub const NODE_WORDS: usize = 16;
const THREADS: u32 = 256;
const MAX_CTAS: u32 = 30;

/// n_auto = max(5, round(c Σ π‖M × m1‖ / Σ A(T))) for `kernels` in `scene`.
pub fn n_auto(kernels: &[Kernel], scene: &Scene) -> u32 {
    let cut: f64 = kernels.iter().map(|k| std::f64::consts::PI * k.area as f64).sum();
    let surface: f64 = scene.triangles.iter().map(|t| 0.5 * t.double_area() as f64).sum();
    if surface <= 0.0 {
        return N_AUTO_MIN;
    }
    ((C_AUTO * cut / surface).round() as u32).max(N_AUTO_MIN)
}

/// Spreads the low 10 bits of `v` to every third bit.
pub fn expand10(v: u32) -> u32 {
    let mut v = v.wrapping_mul(0x0001_0001) & 0xFF00_00FF;
    v = v.wrapping_mul(0x0000_0101) & 0x0F00_F00F;
    v = v.wrapping_mul(0x0000_0011) & 0xC30C_30C3;
    v.wrapping_mul(0x0000_0005) & 0x4924_9249
}

/// The quantisation box: the kernels' centres' bounds, 1024 cells per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantiser {
    /// Lower corner.
    pub lo: [f32; 3],
    /// Cells per unit length (0 on a flat axis).
    pub scale: [f32; 3],
}

impl Quantiser {
    /// Over the centres of `kernels`.
    pub fn of(kernels: &[Kernel]) -> Quantiser {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for k in kernels {
            for c in 0..3 {
                lo[c] = lo[c].min(k.z[c]);
                hi[c] = hi[c].max(k.z[c]);
            }
        }
        let scale = std::array::from_fn(|c| if hi[c] > lo[c] { 1024.0 / (hi[c] - lo[c]) } else { 0.0 });
        Quantiser { lo: if kernels.is_empty() { [0.0; 3] } else { lo }, scale }
    }

    fn cell(&self, z: f32, c: usize) -> u32 {
        let t = (z - self.lo[c]) * self.scale[c];
        let q = if t > 0.0 { t as i32 } else { 0 };
        q.min(1023) as u32
    }

    /// The Morton code of `z` (x in the highest of each three bits).
    pub fn code(&self, z: [f32; 3]) -> u32 {
        (expand10(self.cell(z[0], 0)) << 2) | (expand10(self.cell(z[1], 1)) << 1) | expand10(self.cell(z[2], 2))
    }
}

/// The level of the merge point between codes `a` and `b` (their common
/// leading bits among [`CODE_BITS`]), or `None` when they are equal.
pub fn level(a: u32, b: u32) -> Option<u32> {
    let x = a ^ b;
    (x != 0).then(|| x.leading_zeros() - (32 - CODE_BITS))
}

/// An LBVH as the merge passes leave it.
#[derive(Debug, Clone, PartialEq)]
pub struct Lbvh {
    /// Sorted position → kernel index.
    pub order: Vec<u32>,
    /// The sorted codes.
    pub codes: Vec<u32>,
    /// n_auto used.
    pub n_auto: u32,
    /// Node records by id ([`NODE_WORDS`] words; unused ids all zero).
    pub nodes: Vec<[u32; NODE_WORDS]>,
    /// The root: an inner node's id + 1, or 0 for a single leaf over everything.
    pub root: u32,
    /// The root's AABB (lo, hi).
    pub root_box: [f32; 6],
}

/// The merge points per level (0..30), ascending positions.
pub fn merge_points(codes: &[u32]) -> Vec<Vec<u32>> {
    let mut by_level = vec![Vec::new(); CODE_BITS as usize];
    for i in 0..codes.len().saturating_sub(1) {
        if let Some(l) = level(codes[i], codes[i + 1]) {
            by_level[l as usize].push(i as u32);
        }
    }
    by_level
}

fn lower(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

fn upper(a: f32, b: f32) -> f32 {
    if b > a { b } else { a }
}

/// The native dual merge over sorted `codes` with the references' `boxes`
/// (lo, hi), the kernels' steps one by one.
pub fn merge(codes: &[u32], boxes: &[[f32; 6]], n_auto: u32) -> (Vec<[u32; NODE_WORDS]>, u32, [f32; 6]) {
    let n = codes.len();
    if n == 0 {
        return (Vec::new(), 0, [0.0; 6]);
    }
    let mut size = vec![0u32; n];
    let mut bx = vec![[0.0f32; 6]; n];
    // runs of identical codes
    let mut i = 0;
    while i < n {
        let mut b = boxes[i];
        let mut k = i;
        while k + 1 < n && codes[k + 1] == codes[i] {
            k += 1;
            for a in 0..3 {
                b[a] = lower(b[a], boxes[k][a]);
                b[a + 3] = upper(b[a + 3], boxes[k][a + 3]);
            }
        }
        size[i] = (k - i + 1) as u32;
        size[k] = (k - i + 1) as u32;
        bx[i] = b;
        i = k + 1;
    }
    let levels = merge_points(codes);
    let total: usize = levels.iter().map(Vec::len).sum();
    let mut nodes = vec![[0u32; NODE_WORDS]; total];
    let mut node_of = vec![0u32; n];
    let mut first = 0u32;
    for points in levels.iter().rev() {
        for (t, &i) in points.iter().enumerate() {
            let i = i as usize;
            let (sl, sr) = (size[i], size[i + 1]);
            let a = i + 1 - sl as usize;
            let b = i + sr as usize;
            if sl + sr > n_auto {
                let id = first + t as u32;
                let (nl, nr) = (node_of[a], node_of[i + 1]);
                let o = &mut nodes[id as usize];
                o[0] = if nl != 0 { nl - 1 } else { LEAF_REF | a as u32 };
                o[1] = if nl != 0 { 0 } else { sl };
                o[2] = if nr != 0 { nr - 1 } else { LEAF_REF | (i + 1) as u32 };
                o[3] = if nr != 0 { 0 } else { sr };
                for k in 0..6 {
                    o[4 + k] = bx[a][k].to_bits();
                    o[10 + k] = bx[i + 1][k].to_bits();
                }
                node_of[a] = id + 1;
            }
            size[a] = sl + sr;
            size[b] = sl + sr;
            let r = bx[i + 1];
            for k in 0..3 {
                bx[a][k] = lower(bx[a][k], r[k]);
                bx[a][k + 3] = upper(bx[a][k + 3], r[k + 3]);
            }
        }
        first += points.len() as u32;
    }
    (nodes, node_of[0], bx[0])
}

/// The references of `kernels` sorted by code (stable): (order, sorted codes, sorted boxes).
pub fn sorted(codes: &[u32], kernels: &[Kernel]) -> (Vec<u32>, Vec<u32>, Vec<[f32; 6]>) {
    let mut order: Vec<u32> = (0..codes.len() as u32).collect();
    order.sort_by_key(|&i| codes[i as usize]);
    let c = order.iter().map(|&i| codes[i as usize]).collect();
    let b = order
        .iter()
        .map(|&i| {
            let k = &kernels[i as usize];
            [k.lo[0], k.lo[1], k.lo[2], k.hi[0], k.hi[1], k.hi[2]]
        })
        .collect();
    (order, c, b)
}

/// Builds the LBVH of `kernels` natively.
pub fn build(kernels: &[Kernel], n_auto: u32) -> Lbvh {
    let q = Quantiser::of(kernels);
    let codes: Vec<u32> = kernels.iter().map(|k| q.code(k.z)).collect();
    let (order, codes, boxes) = sorted(&codes, kernels);
    let (nodes, root, root_box) = merge(&codes, &boxes, n_auto);
    Lbvh { order, codes, n_auto, nodes, root, root_box }
}

/// Loads the LBVH kernels' PTX on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/fabianowski2011/lbvh.ptx")
}

fn ctas(n: usize) -> u32 {
    (n.div_ceil(THREADS as usize) as u32).clamp(1, MAX_CTAS)
}

fn params(count: usize, n_auto: u32, merges: usize, first: u32) -> Vec<u8> {
    to_bytes(&[count as i32, n_auto as i32, merges as i32, first as i32])
}

/// Builds the LBVH of `kernels` on the emulator (codes, the radix sort by
/// code, the sorted AABBs, runs, levels, the radix sort by level and one merge
/// launch per level). Returns the launches' counters too.
pub fn build_kernel(
    dev: &mut Device,
    module: &Module,
    kernels: &[Kernel],
    n_auto: u32,
) -> Result<(Lbvh, Vec<LaunchStats>), PhotonError> {
    build_kernel_observed(dev, module, kernels, n_auto, None)
}

/// As [`build_kernel`], every launch observed by `model` when given (its
/// counters the sum over the launches).
pub fn build_kernel_observed(
    dev: &mut Device,
    module: &Module,
    kernels: &[Kernel],
    n_auto: u32,
    model: Option<&crate::model::Model>,
) -> Result<(Lbvh, Vec<LaunchStats>), PhotonError> {
    let mut l = Launcher { shared: model, own: None, launches: Vec::new() };
    let lbvh = build_launches(dev, module, kernels, n_auto, &mut l)?;
    Ok((lbvh, l.launches.into_iter().map(|o| o.stats).collect()))
}

/// One launch of the build: its grid, its counters and, from
/// [`build_kernel_per_launch`], the memory traffic its own model counted.
#[derive(Debug, Clone)]
pub struct ObservedLaunch {
    /// The launch's grid and CTA shape.
    pub config: LaunchConfig,
    /// Its counters.
    pub stats: LaunchStats,
    /// What a memory model of its own counted (`None` unless asked for).
    pub memory: Option<crate::model::ModelStats>,
}

/// As [`build_kernel`], each launch observed by a memory model of `profile`
/// of its own and returned with its grid, so that a timing model can take
/// every launch at its real grid (the radix sort's one-CTA scan as one CTA).
pub fn build_kernel_per_launch(
    dev: &mut Device,
    module: &Module,
    kernels: &[Kernel],
    n_auto: u32,
    profile: crate::model::Profile,
) -> Result<(Lbvh, Vec<ObservedLaunch>), PhotonError> {
    let mut l = Launcher { shared: None, own: Some(profile), launches: Vec::new() };
    let lbvh = build_launches(dev, module, kernels, n_auto, &mut l)?;
    Ok((lbvh, l.launches))
}

/// Runs the build's launches: observed by one shared model, or each by a
/// model of its own (`own`), recorded in order.
struct Launcher<'m> {
    shared: Option<&'m crate::model::Model>,
    own: Option<crate::model::Profile>,
    launches: Vec<ObservedLaunch>,
}

impl Launcher<'_> {
    fn run(
        &mut self,
        dev: &mut Device,
        module: &Module,
        kernel: &str,
        config: LaunchConfig,
        args: &[Arg],
    ) -> Result<(), SimError> {
        let own = self.own.map(|p| crate::model::Model::new(p, &module.prog));
        let observer = match &own {
            Some(m) => Some(m as &dyn crate::sim::ObserverFactory),
            None => self.shared.map(|m| m as &dyn crate::sim::ObserverFactory),
        };
        let stats = dev.launch_observed(module, kernel, config, args, observer)?;
        self.launches.push(ObservedLaunch { config, stats, memory: own.map(|m| m.finish()) });
        Ok(())
    }
}

fn build_launches(
    dev: &mut Device,
    module: &Module,
    kernels: &[Kernel],
    n_auto: u32,
    launcher: &mut Launcher,
) -> Result<Lbvh, PhotonError> {
    let n = kernels.len();
    if n > (LEAF_REF - 1) as usize {
        return Err(PhotonError::TooMany(n));
    }
    if n == 0 {
        return Ok(build(kernels, n_auto));
    }
    let up = crate::host::rt_kernels::upload;
    let q = Quantiser::of(kernels);
    let mut p = to_bytes(&[q.lo[0], q.lo[1], q.lo[2], q.scale[0], q.scale[1], q.scale[2]]);
    p.extend_from_slice(&(n as i32).to_le_bytes());
    let pp = up(dev, &p, "params")?;
    let centres: Vec<f32> = kernels.iter().flat_map(|k| k.z).collect();
    let cb = up(dev, &to_bytes(&centres), "centres")?;
    let codes_out = dev.alloc_zeroed::<u32>(n);
    let args = [Arg::Ptr(pp), Arg::Ptr(cb), Arg::Ptr(codes_out)];
    launcher.run(dev, module, CODES, LaunchConfig::linear(ctas(n), THREADS), &args)?;
    // the references radix-sorted by code, their AABBs gathered in that order
    let (codes_dev, order_dev) = radix_sort(dev, module, codes_out, n, CODE_BITS, launcher)?;
    let kernel_boxes: Vec<f32> =
        kernels.iter().flat_map(|k| [k.lo[0], k.lo[1], k.lo[2], k.hi[0], k.hi[1], k.hi[2]]).collect();
    let kb = up(dev, &to_bytes(&kernel_boxes), "kernel boxes")?;
    let bb = dev.alloc_zeroed::<f32>(6 * n);
    let pp = up(dev, &params(n, n_auto, 0, 0), "params")?;
    let args = [Arg::Ptr(pp), Arg::Ptr(order_dev), Arg::Ptr(kb), Arg::Ptr(bb)];
    launcher.run(dev, module, GATHER, LaunchConfig::linear(ctas(n), THREADS), &args)?;
    let cb = codes_dev;
    let size = dev.alloc_zeroed::<u32>(n);
    let bx = dev.alloc_zeroed::<f32>(6 * n);
    let args = [Arg::Ptr(pp), Arg::Ptr(cb), Arg::Ptr(bb), Arg::Ptr(size), Arg::Ptr(bx)];
    launcher.run(dev, module, RUNS, LaunchConfig::linear(ctas(n), THREADS), &args)?;
    let lv = dev.alloc_zeroed::<u32>(n);
    let args = [Arg::Ptr(pp), Arg::Ptr(cb), Arg::Ptr(lv)];
    launcher.run(dev, module, LEVELS, LaunchConfig::linear(ctas(n), THREADS), &args)?;
    // the merge points radix-sorted by level, deepest first, ascending positions within a level
    let keys = dev.alloc_zeroed::<u32>(n);
    let args = [Arg::Ptr(pp), Arg::Ptr(lv), Arg::Ptr(keys)];
    launcher.run(dev, module, LEVEL_KEYS, LaunchConfig::linear(ctas(n), THREADS), &args)?;
    let (keys, points) = radix_sort(dev, module, keys, n - 1, LEVEL_KEY_BITS, launcher)?;
    // the launches per level: the sorted keys' runs (a point's place is its node id)
    let keys = dev.read::<u32>(keys, n - 1);
    let total = keys.iter().take_while(|&&k| k < CODE_BITS).count();
    let nodes = dev.alloc_zeroed::<u32>(NODE_WORDS * total.max(1));
    let node_of = dev.alloc_zeroed::<u32>(n);
    let mut first = 0usize;
    while first < total {
        let len = keys[first..total].iter().take_while(|&&k| k == keys[first]).count();
        let pp = up(dev, &params(n, n_auto, len, first as u32), "params")?;
        let args = [Arg::Ptr(pp), Arg::Ptr(points), Arg::Ptr(size), Arg::Ptr(bx), Arg::Ptr(node_of), Arg::Ptr(nodes)];
        launcher.run(dev, module, MERGE, LaunchConfig::linear(ctas(len), THREADS), &args)?;
        first += len;
    }
    let order = dev.read::<u32>(order_dev, n);
    let codes = dev.read::<u32>(codes_dev, n);
    let raw = dev.read::<u32>(nodes, NODE_WORDS * total);
    let nodes = raw.chunks_exact(NODE_WORDS).map(|c| std::array::from_fn(|k| c[k])).collect();
    let root = dev.read::<u32>(node_of, 1)[0];
    let b = dev.read::<f32>(bx, 6);
    let root_box = std::array::from_fn(|k| b[k]);
    Ok(Lbvh { order, codes, n_auto, nodes, root, root_box })
}

/// Radix-sorts the `n` keys at `keys` (their low `bits` bits) on the
/// emulator, stably, with the indices 0..n as values: three launches a pass
/// of [`RADIX_BITS`] bits (counts, scan on one CTA, scatter), run by `launcher`.
/// Returns the device buffers of the sorted keys and of their values.
fn radix_sort(
    dev: &mut Device,
    module: &Module,
    keys: DevicePtr,
    n: usize,
    bits: u32,
    launcher: &mut Launcher,
) -> Result<(DevicePtr, DevicePtr), PhotonError> {
    if n > i32::MAX as usize {
        return Err(PhotonError::TooMany(n));
    }
    let tiles = n.div_ceil(SORT_THREADS);
    let grid = (tiles as u32).clamp(1, MAX_CTAS);
    let counts = dev.alloc_zeroed::<u32>((1usize << RADIX_BITS) * tiles.max(1));
    let (mut k_in, mut v_in) = (keys, dev.alloc_zeroed::<u32>(n.max(1)));
    let (mut k_out, mut v_out) = (dev.alloc_zeroed::<u32>(n.max(1)), dev.alloc_zeroed::<u32>(n.max(1)));
    for pass in 0..bits.div_ceil(RADIX_BITS) {
        let p = [n as i32, tiles as i32, (pass * RADIX_BITS) as i32, (pass == 0) as i32];
        let pp = crate::host::rt_kernels::upload(dev, &to_bytes(&p), "sort params")?;
        let cfg = LaunchConfig::linear(grid, SORT_THREADS as u32);
        let args = [Arg::Ptr(pp), Arg::Ptr(k_in), Arg::Ptr(counts)];
        launcher.run(dev, module, RADIX_COUNT, cfg, &args)?;
        let args = [Arg::Ptr(pp), Arg::Ptr(counts)];
        launcher.run(dev, module, RADIX_SCAN, LaunchConfig::linear(1, SORT_THREADS as u32), &args)?;
        let args = [Arg::Ptr(pp), Arg::Ptr(counts), Arg::Ptr(k_in), Arg::Ptr(v_in), Arg::Ptr(k_out), Arg::Ptr(v_out)];
        launcher.run(dev, module, RADIX_SCATTER, cfg, &args)?;
        std::mem::swap(&mut k_in, &mut k_out);
        std::mem::swap(&mut v_in, &mut v_out);
    }
    if bits == 0 {
        // no pass: the values are still to be made
        let iota: Vec<u32> = (0..n as u32).collect();
        dev.write(v_in, &iota)?;
    }
    Ok((k_in, v_in))
}

/// What [`sort_kernel`] returns.
#[derive(Debug, Clone)]
pub struct Sorted {
    /// The keys in sorted order.
    pub keys: Vec<u32>,
    /// The permutation: sorted position → original index.
    pub order: Vec<u32>,
    /// The sort's launches (three a pass).
    pub launches: Vec<LaunchStats>,
}

/// Radix-sorts `keys` (their low `bits` bits) on the emulator, stably, as the
/// LBVH build does.
pub fn sort_kernel(dev: &mut Device, module: &Module, keys: &[u32], bits: u32) -> Result<Sorted, PhotonError> {
    let n = keys.len();
    let kb = crate::host::rt_kernels::upload(dev, &to_bytes(keys), "keys")?;
    let mut l = Launcher { shared: None, own: None, launches: Vec::new() };
    let (k, v) = radix_sort(dev, module, kb, n, bits, &mut l)?;
    let launches = l.launches.into_iter().map(|o| o.stats).collect();
    Ok(Sorted { keys: dev.read::<u32>(k, n), order: dev.read::<u32>(v, n), launches })
}

fn word_box(w: &[u32]) -> ([f32; 3], [f32; 3]) {
    let f = |k: usize| f32::from_bits(w[k]);
    ([f(0), f(1), f(2)], [f(3), f(4), f(5)])
}

impl Lbvh {
    /// The tree the layouts are made from (nodes in depth-first order, the root first).
    pub fn tree(&self) -> PmTree {
        let mut t = PmTree { nodes: Vec::new(), order: self.order.clone() };
        let n = self.order.len() as u32;
        if n == 0 {
            return t;
        }
        let (lo, hi) = word_box(&self.root_box.map(f32::to_bits));
        if self.root == 0 {
            t.nodes.push(PmNode { lo, hi, kind: PmKind::Leaf { first: 0, count: n } });
            return t;
        }
        self.convert(&mut t, self.root - 1, lo, hi);
        t
    }

    fn convert(&self, t: &mut PmTree, id: u32, lo: [f32; 3], hi: [f32; 3]) -> u32 {
        let me = t.nodes.len() as u32;
        t.nodes.push(PmNode { lo, hi, kind: PmKind::Inner([0, 0]) });
        let w = &self.nodes[id as usize];
        let mut kids = [0u32; 2];
        for (side, kid) in kids.iter_mut().enumerate() {
            let (r, count) = (w[2 * side], w[2 * side + 1]);
            let (clo, chi) = word_box(&w[4 + 6 * side..10 + 6 * side]);
            *kid = if r & LEAF_REF != 0 {
                let k = t.nodes.len() as u32;
                t.nodes.push(PmNode { lo: clo, hi: chi, kind: PmKind::Leaf { first: r & !LEAF_REF, count } });
                k
            } else {
                self.convert(t, r, clo, chi)
            };
        }
        t.nodes[me as usize].kind = PmKind::Inner(kids);
        me
    }
}
