//! Thesis 000's top-down BVH construction by a cost metric over object
//! partitions, in its two uses:
//!
//! - the **VVH** photon map (§6.1.1, L2557–2579): C_P(L, R) = p_P·2C_T +
//!   p_L n_L C_I + p_R n_R C_I (eq. 6.2) with p_N = V(N)/V(S) (eq. 6.3), "a
//!   serial process with empirically determined C_T = 0, C_I = 1" (L2625),
//!   a leaf when n_P ≤ n_auto, and "the criterion min C_P(L, R) > p_P n_P C_I
//!   and a maximal recursion depth of 64 are additionally used" (L2619);
//! - the **scene BVH** of Table 6.5 (L2800): "the SAH with parameters tuned
//!   for maximal performance (C_T = 1, C_I = 3, recursive subdivision while
//!   n_P > 5 and min C_P(L, R) ≤ p_P n_P C_I)", the cost metric of eq. 3.12,
//!   C_P(L, R) = p_P C_T + p_L n_L C_I + p_R n_R C_I with p_N the surface area
//!   ratio (§3.2.3.1).
//!
//! The construction "is identical to that of a BVH over scene surfaces,
//! achieving O(n log n) complexity by sorting and then progressively
//! splitting lists of candidate splitting planes" (L2579): the primitives are
//! sorted by their AABB centroids once per axis; each node sweeps the three
//! lists for the cheapest partition into a prefix and a suffix, and the
//! lists are split stably into the children's. Ties go to the lowest axis,
//! then the smallest left part. Costs are summed in f64.

use super::pm_layout::{PmKind, PmNode, PmTree};

/// The probability measure of a node: its AABB's surface area (SAH) or volume (VVH).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Surface area (eq. 3.12 for rays).
    Area,
    /// Volume (eq. 6.3 for query points).
    Volume,
}

/// A construction's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// p_N's measure.
    pub metric: Metric,
    /// Traversal cost C_T.
    pub c_t: f64,
    /// Intersection (retrieval) cost C_I.
    pub c_i: f64,
    /// Children stored in pairs: visiting a parent costs 2C_T (eq. 6.2) instead of C_T (eq. 3.12).
    pub pairs: bool,
    /// Subdivide only while n_P exceeds this.
    pub leaf_size: usize,
    /// A node at this depth (the root: 1) is a leaf.
    pub max_depth: usize,
}

impl Params {
    /// Table 6.5's scene BVH (L2800).
    pub const SCENE: Params =
        Params { metric: Metric::Area, c_t: 1.0, c_i: 3.0, pairs: false, leaf_size: 5, max_depth: 128 };

    /// The VVH photon map with leaf threshold `n_auto` (L2619, L2625).
    pub fn vvh(n_auto: usize) -> Params {
        Params { metric: Metric::Volume, c_t: 0.0, c_i: 1.0, pairs: true, leaf_size: n_auto, max_depth: 64 }
    }
}

/// An AABB as two corners.
pub type Bounds = [[f32; 3]; 2];

fn union(a: &Bounds, b: &Bounds) -> Bounds {
    [std::array::from_fn(|c| a[0][c].min(b[0][c])), std::array::from_fn(|c| a[1][c].max(b[1][c]))]
}

const EMPTY: Bounds = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];

fn measure(m: Metric, b: &Bounds) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|c| (b[1][c] as f64 - b[0][c] as f64).max(0.0));
    match m {
        Metric::Area => 2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]),
        Metric::Volume => d[0] * d[1] * d[2],
    }
}

struct Builder<'a> {
    boxes: &'a [Bounds],
    p: Params,
    root_measure: f64,
    nodes: Vec<PmNode>,
    order: Vec<u32>,
    side: Vec<bool>,
}

/// Builds the BVH over `boxes` (primitive AABBs) with `p`.
pub fn build(boxes: &[Bounds], p: &Params) -> PmTree {
    if boxes.is_empty() {
        return PmTree::default();
    }
    let centre = |i: u32, c: usize| {
        let b = &boxes[i as usize];
        b[0][c] * 0.5 + b[1][c] * 0.5
    };
    let mut lists: [Vec<u32>; 3] = std::array::from_fn(|c| {
        let mut v: Vec<u32> = (0..boxes.len() as u32).collect();
        v.sort_by(|&a, &b| centre(a, c).total_cmp(&centre(b, c)).then(a.cmp(&b)));
        v
    });
    let root = boxes.iter().fold(EMPTY, |a, b| union(&a, b));
    let mut b = Builder {
        boxes,
        p: *p,
        root_measure: measure(p.metric, &root),
        nodes: vec![PmNode { lo: root[0], hi: root[1], kind: PmKind::Leaf { first: 0, count: 0 } }],
        order: Vec::with_capacity(boxes.len()),
        side: vec![false; boxes.len()],
    };
    let [l0, l1, l2] = &mut lists;
    b.node(0, [l0.as_mut_slice(), l1.as_mut_slice(), l2.as_mut_slice()], 1);
    PmTree { nodes: b.nodes, order: b.order }
}

impl Builder<'_> {
    fn prob(&self, b: &Bounds) -> f64 {
        if self.root_measure > 0.0 { measure(self.p.metric, b) / self.root_measure } else { 1.0 }
    }

    /// The cheapest partition: (cost, axis, left count).
    fn best_split(&self, lists: &[&mut [u32]; 3]) -> Option<(f64, usize, usize)> {
        let n = lists[0].len();
        let mut best: Option<(f64, usize, usize)> = None;
        let mut right = vec![EMPTY; n];
        for (axis, list) in lists.iter().enumerate() {
            let mut acc = EMPTY;
            for i in (1..n).rev() {
                acc = union(&acc, &self.boxes[list[i] as usize]);
                right[i] = acc;
            }
            let mut left = EMPTY;
            for i in 1..n {
                left = union(&left, &self.boxes[list[i - 1] as usize]);
                let c = self.p.c_i * (self.prob(&left) * i as f64 + self.prob(&right[i]) * (n - i) as f64);
                if best.is_none_or(|(b, _, _)| c < b) {
                    best = Some((c, axis, i));
                }
            }
        }
        best
    }

    fn node(&mut self, at: usize, mut lists: [&mut [u32]; 3], depth: usize) {
        let n = lists[0].len();
        let bounds = lists[0].iter().fold(EMPTY, |a, &i| union(&a, &self.boxes[i as usize]));
        self.nodes[at].lo = bounds[0];
        self.nodes[at].hi = bounds[1];
        let p_p = self.prob(&bounds);
        let split = if n > self.p.leaf_size && depth < self.p.max_depth { self.best_split(&lists) } else { None };
        let traverse = if self.p.pairs { 2.0 } else { 1.0 } * self.p.c_t * p_p;
        let Some((_, axis, k)) = split.filter(|&(c, _, _)| traverse + c <= p_p * n as f64 * self.p.c_i) else {
            let first = self.order.len() as u32;
            self.order.extend_from_slice(lists[0]);
            self.nodes[at].kind = PmKind::Leaf { first, count: n as u32 };
            return;
        };
        for (i, &prim) in lists[axis].iter().enumerate() {
            self.side[prim as usize] = i < k;
        }
        for (c, list) in lists.iter_mut().enumerate() {
            if c != axis {
                stable_partition(list, &self.side);
            }
        }
        let l = self.nodes.len();
        let leaf = PmNode { lo: [0.0; 3], hi: [0.0; 3], kind: PmKind::Leaf { first: 0, count: 0 } };
        self.nodes.extend([leaf, leaf]);
        self.nodes[at].kind = PmKind::Inner([l as u32, l as u32 + 1]);
        let [a, b, c] = lists;
        let (a0, a1) = a.split_at_mut(k);
        let (b0, b1) = b.split_at_mut(k);
        let (c0, c1) = c.split_at_mut(k);
        self.node(l, [a0, b0, c0], depth + 1);
        self.node(l + 1, [a1, b1, c1], depth + 1);
    }
}

/// Moves the entries whose `side` is true to the front, keeping both parts' order.
fn stable_partition(list: &mut [u32], side: &[bool]) {
    let (mut l, mut r): (Vec<u32>, Vec<u32>) = list.iter().partition(|&&i| side[i as usize]);
    l.append(&mut r);
    list.copy_from_slice(&l);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(x: f32) -> Bounds {
        [[x, 0.0, 0.0], [x + 1.0, 1.0, 1.0]]
    }

    #[test]
    fn two_clusters_split_between_them_and_small_sets_stay_leaves() {
        // six boxes near x = 0 and six near x = 100: the first split separates them
        let boxes: Vec<Bounds> =
            (0..6).map(|i| unit(i as f32 * 0.1)).chain((0..6).map(|i| unit(100.0 + i as f32 * 0.1))).collect();
        let t = build(&boxes, &Params::SCENE);
        let PmKind::Inner([l, r]) = t.nodes[0].kind else { panic!("root is a leaf") };
        assert!(t.nodes[l as usize].hi[0] < 2.0 && t.nodes[r as usize].lo[0] > 99.0);
        // each cluster holds 6 > 5 boxes, but overlapping unit boxes cannot be split for less than a leaf costs
        let s = t.stats();
        assert_eq!(s.leaves + s.inner, t.nodes.len());
        let mut all: Vec<u32> = t.order.clone();
        all.sort();
        assert_eq!(all, (0..12).collect::<Vec<u32>>());
        // five boxes: a leaf whatever the cost
        assert_eq!(build(&boxes[..5], &Params::SCENE).nodes.len(), 1);
    }

    #[test]
    fn vvh_stops_at_n_auto_and_depth_64() {
        let boxes: Vec<Bounds> = (0..64).map(|i| unit(i as f32 * 3.0)).collect();
        let t = build(&boxes, &Params::vvh(8));
        for n in &t.nodes {
            if let PmKind::Leaf { count, .. } = n.kind {
                assert!((1..=8).contains(&count));
            }
        }
        // C_T = 0: the cost test never stops a split, so disjoint boxes end in leaves of at most n_auto
        assert!(t.stats().leaves >= 8);
        let deep = Params { max_depth: 2, ..Params::vvh(1) };
        assert_eq!(build(&boxes, &deep).stats().depth, 2);
    }
}
