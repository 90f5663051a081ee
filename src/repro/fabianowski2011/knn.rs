//! Thesis 000 §5.2.3: the k-th nearest neighbour (kNN) density estimate, the
//! baseline VKDE is compared with (Fig. 5.3, k_kNN of Table 5.1), on the
//! emulator (`kernels/fabianowski2011/knn.cu`) and natively ([`estimate`]).
//!
//! The photon map is the original one of the thesis' background (§3.4.3.1,
//! L1383, [Jen95]): a left-balanced kd-tree with one interaction per node in
//! heap order ([`KdMap`]), split on the axis of the largest extent. A query
//! keeps the k nearest interactions whose normal faces the query's side in a
//! max-heap (in local memory on the device: the priority queue the thesis
//! says makes kNN slow in CUDA, L2171); the search radius starts at h_max and
//! shrinks to the k-th distance once k are found (L1399). The bandwidth is
//! h = ‖x − x_k‖ (L1299), or h_max when fewer than k lie within it; the
//! estimate is L_r = (ρ/π) Σ_j K(‖x − x_j‖/h) Φ_j / h² over the heap (eq. 3.16
//! with the kNN bandwidth), uniform or Epanechnikov K.

use std::cmp::Ordering::{Greater, Less};
use std::f32::consts::{FRAC_1_PI, FRAC_2_PI};

use super::photons::{Photon, PhotonError, dot};
use super::vkde::{ESTIMATE_FLOATS, Estimate, Query, Shape};
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, LaunchConfig, LaunchStats, Module, SimError};

/// The kernel's PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/fabianowski2011/knn.ptx");
/// Entry: kNN estimation, one thread per query.
pub const ESTIMATE: &str = "estimate_knn";
/// The largest k the kernel's heap holds (Table 5.1's largest k_kNN is 451).
pub const K_MAX: usize = 512;
/// Entries of the traversal stack (bounds the tree's depth).
pub const STACK: usize = 64;
/// Floats of a node on the device: [x, axis bits, Φ, 0, n, 0].
pub const NODE_FLOATS: usize = 12;

/// Why a kNN estimate cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum KnnError {
    /// k outside 1..=K_MAX.
    #[error("k = {0}: the kNN heap holds 1 to {K_MAX} interactions")]
    BadK(usize),
    /// The photon kernels or the emulator failed.
    #[error(transparent)]
    Photon(#[from] PhotonError),
}

impl From<SimError> for KnnError {
    fn from(e: SimError) -> Self {
        KnnError::Photon(PhotonError::Sim(e))
    }
}

/// An interaction in the kd-tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Position.
    pub x: [f32; 3],
    /// Split axis of its node (0, 1, 2).
    pub axis: u32,
    /// Flux Φ (RGB).
    pub flux: [f32; 3],
    /// Unit surface normal on the photon's side.
    pub normal: [f32; 3],
}

/// A left-balanced kd-tree over interactions, in heap order (children of node i at 2i + 1, 2i + 2).
#[derive(Debug, Clone, Default)]
pub struct KdMap {
    /// The nodes.
    pub nodes: Vec<Point>,
}

/// Nodes in the left subtree of a left-balanced tree of `n` nodes.
pub fn left_size(n: usize) -> usize {
    if n <= 1 {
        return 0;
    }
    let h = usize::BITS - 1 - n.leading_zeros(); // full levels below the root's: n in [2^h, 2^(h+1))
    let last = n - ((1usize << h) - 1); // nodes on the last level
    let half = 1usize << (h - 1); // the last level's capacity in the left subtree
    (half - 1) + last.min(half)
}

impl KdMap {
    /// Builds the tree over the stored interactions of `photons` (each photon's 2nd and 3rd).
    pub fn build(photons: &[[Option<Photon>; 2]]) -> KdMap {
        let pts: Vec<Point> = photons
            .iter()
            .flatten()
            .flatten()
            .map(|p| Point { x: p.z, axis: 0, flux: p.flux, normal: p.normal })
            .collect();
        KdMap::from_points(pts)
    }

    /// Builds the tree over `pts` (the axis fields are set here).
    pub fn from_points(mut pts: Vec<Point>) -> KdMap {
        let n = pts.len();
        let mut nodes = vec![Point { x: [0.0; 3], axis: 0, flux: [0.0; 3], normal: [0.0; 3] }; n];
        let mut idx: Vec<usize> = (0..n).collect();
        if n > 0 {
            balance(&mut pts, &mut idx, 0, &mut nodes);
        }
        KdMap { nodes }
    }

    /// The nodes as the kernel reads them.
    pub fn node_floats(&self) -> Vec<f32> {
        let mut v = Vec::with_capacity(NODE_FLOATS * self.nodes.len());
        for p in &self.nodes {
            v.extend_from_slice(&p.x);
            v.push(f32::from_bits(p.axis));
            v.extend_from_slice(&p.flux);
            v.push(0.0);
            v.extend_from_slice(&p.normal);
            v.push(0.0);
        }
        v
    }
}

fn balance(pts: &mut [Point], idx: &mut [usize], at: usize, out: &mut [Point]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for &i in idx.iter() {
        for c in 0..3 {
            lo[c] = lo[c].min(pts[i].x[c]);
            hi[c] = hi[c].max(pts[i].x[c]);
        }
    }
    let e = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let axis = if e[0] >= e[1] && e[0] >= e[2] {
        0
    } else if e[1] >= e[2] {
        1
    } else {
        2
    };
    idx.sort_by(|&a, &b| pts[a].x[axis].total_cmp(&pts[b].x[axis]).then(a.cmp(&b)));
    let m = left_size(idx.len());
    let mut p = pts[idx[m]];
    p.axis = axis as u32;
    out[at] = p;
    let (l, r) = idx.split_at_mut(m);
    if !l.is_empty() {
        balance(pts, l, 2 * at + 1, out);
    }
    if r.len() > 1 {
        balance(pts, &mut r[1..], 2 * at + 2, out);
    }
}

/// Sifts entry `i` of a max-heap on distance² up.
fn sift_up(d: &mut [f32], id: &mut [u32], mut i: usize) {
    while i > 0 {
        let p = (i - 1) / 2;
        if d[i].partial_cmp(&d[p]) != Some(Greater) {
            break;
        }
        d.swap(i, p);
        id.swap(i, p);
        i = p;
    }
}

/// Sifts the root of a max-heap of `n` entries down.
fn sift_down(d: &mut [f32], id: &mut [u32], n: usize) {
    let mut i = 0;
    loop {
        let l = 2 * i + 1;
        if l >= n {
            break;
        }
        let r = l + 1;
        let c = if r < n && d[r] > d[l] { r } else { l };
        if d[c].partial_cmp(&d[i]) != Some(Greater) {
            break;
        }
        d.swap(i, c);
        id.swap(i, c);
        i = c;
    }
}

/// The native kNN estimate at `q` with `k` neighbours (at most [`K_MAX`]) and
/// search radius `h_max` (the kernel's search, step for step).
pub fn estimate(map: &KdMap, q: &Query, k: usize, h_max: f32, shape: Shape) -> Estimate {
    let mut e = Estimate::default();
    let n = map.nodes.len();
    if n == 0 {
        return e;
    }
    let x = q.x;
    let hmax2 = h_max * h_max;
    let mut r2 = hmax2;
    let mut hd = vec![0.0f32; k];
    let mut hi = vec![0u32; k];
    let mut count = 0usize;
    let mut stack = [(0u32, 0.0f32); STACK];
    let mut size = 1;
    while size > 0 {
        size -= 1;
        let (mut i, plane) = stack[size];
        if plane.partial_cmp(&r2) != Some(Less) {
            continue;
        }
        loop {
            let p = &map.nodes[i as usize];
            e.nodes += 1;
            let d = [x[0] - p.x[0], x[1] - p.x[1], x[2] - p.x[2]];
            let d2 = dot(d, d);
            if d2 < r2 && dot(p.normal, q.n) > 0.0 {
                e.retrieved += 1;
                if count < k {
                    hd[count] = d2;
                    hi[count] = i;
                    sift_up(&mut hd, &mut hi, count);
                    count += 1;
                    if count == k {
                        r2 = hd[0];
                    }
                } else {
                    hd[0] = d2;
                    hi[0] = i;
                    sift_down(&mut hd, &mut hi, k);
                    r2 = hd[0];
                }
            }
            let left = 2 * i + 1;
            if left as usize >= n {
                break;
            }
            let dd = x[p.axis as usize] - p.x[p.axis as usize];
            let (near, far) = if dd < 0.0 { (left, left + 1) } else { (left + 1, left) };
            if (far as usize) < n {
                stack[size] = (far, dd * dd);
                size += 1;
            }
            if near as usize >= n {
                break;
            }
            i = near;
        }
    }
    let h2 = if count == k { hd[0] } else { hmax2 };
    if h2.partial_cmp(&0.0) != Some(Greater) {
        return e;
    }
    let mut sum = [0.0f32; 3];
    for j in 0..count {
        let w = match shape {
            Shape::Uniform => FRAC_1_PI,
            Shape::Epanechnikov => (1.0 - hd[j] / h2) * FRAC_2_PI,
        };
        let f = map.nodes[hi[j] as usize].flux;
        for c in 0..3 {
            sum[c] += w * f[c];
        }
    }
    e.contributions = count as u32;
    e.radiance = std::array::from_fn(|c| q.weight[c] * FRAC_1_PI * (sum[c] / h2));
    e
}

/// Loads the kNN kernel's PTX on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/fabianowski2011/knn.ptx")
}

/// Runs the kNN kernel at `queries` (`None`: estimate 0) with `k` neighbours.
pub fn estimate_kernel(
    dev: &mut Device,
    module: &Module,
    map: &KdMap,
    queries: &[Option<Query>],
    k: usize,
    h_max: f32,
    shape: Shape,
) -> Result<(Vec<Estimate>, LaunchStats), KnnError> {
    estimate_kernel_observed(dev, module, map, queries, (k, h_max, shape), None)
}

/// As [`estimate_kernel`] with (k, h_max, shape) in `search`, the launch
/// observed by `model` when given (a memory model for the timing model).
pub fn estimate_kernel_observed(
    dev: &mut Device,
    module: &Module,
    map: &KdMap,
    queries: &[Option<Query>],
    search: (usize, f32, Shape),
    model: Option<&crate::model::Model>,
) -> Result<(Vec<Estimate>, LaunchStats), KnnError> {
    let (k, h_max, shape) = search;
    if k == 0 || k > K_MAX {
        return Err(KnnError::BadK(k));
    }
    let n = queries.len();
    if n > i32::MAX as usize || map.nodes.len() > i32::MAX as usize {
        return Err(PhotonError::TooMany(n.max(map.nodes.len())).into());
    }
    let q: Vec<f32> = queries.iter().flat_map(|q| Query::floats(q.as_ref())).collect();
    let mut params = to_bytes(&[n as i32, shape.code(), map.nodes.len() as i32, k as i32]);
    params.extend(to_bytes(&[h_max]));
    let up = crate::host::rt_kernels::upload;
    let pp = up(dev, &params, "params")?;
    let nodes = up(dev, &to_bytes(&map.node_floats()), "nodes")?;
    let qb = up(dev, &to_bytes(&q), "queries")?;
    let out = dev.alloc_zeroed::<f32>(ESTIMATE_FLOATS * n.max(1));
    let args: Vec<Arg> = [pp, nodes, qb, out].into_iter().map(Arg::Ptr).collect();
    let ctas = (n.div_ceil(super::vkde::THREADS as usize) as u32).clamp(1, super::vkde::MAX_CTAS);
    let observer = model.map(|m| m as &dyn crate::sim::ObserverFactory);
    let launch =
        dev.launch_observed(module, ESTIMATE, LaunchConfig::linear(ctas, super::vkde::THREADS), &args, observer)?;
    let raw = dev.read::<f32>(out, ESTIMATE_FLOATS * n);
    Ok((raw.chunks_exact(ESTIMATE_FLOATS).map(Estimate::from_floats).collect(), launch))
}
