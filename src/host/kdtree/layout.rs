//! The device layout of a kd-tree and its triangles, as byte buffers ready to
//! upload to the emulator's memory (thesis 000 §3.2.4, §4.3).
//!
//! - **Nodes**, 8 bytes: word 0 = split position (f32 bits); word 1 =
//!   `pair << 2 | axis`, where the children are nodes `2·pair + 1` (lower)
//!   and `2·pair + 2` (upper) — siblings are stored in pairs. **Leaves**
//!   (warplight's encoding; the thesis leaves it open): word 1 =
//!   `first << 2 | 3`, word 0 = the number of triangle references, which
//!   start at index `first` of the reference buffer.
//! - The top `heap_levels` levels are a complete binary tree in heap order
//!   (node i's children at 2i + 1, 2i + 2), holes filled with zero bytes,
//!   for the node caches (I: 10 levels = 1023 nodes; II: 8 levels = 255 nodes
//!   with a 24-byte AABB each in `aabbs`). Deeper pairs follow in order.
//! - **Triangle references**: u32 triangle indices.
//! - **Triangles**, 48 bytes, Wald's precomputed form (Alg. 3.2): three
//!   float4 `[n'_i, n'_j, n'_d, k]`, `[e'1, 0]`, `[e'2, 0]` with `k` stored as
//!   u32 bits; the first float4 is all the plane test needs.

use glam::Vec3;

use super::{Aabb, KdTree, Node};

/// The byte buffers of a laid-out tree.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceTree {
    /// 8-byte nodes.
    pub nodes: Vec<u8>,
    /// u32 triangle references.
    pub tri_refs: Vec<u8>,
    /// 48-byte triangles.
    pub triangles: Vec<u8>,
    /// 24-byte AABBs (lo, hi) of the heap-ordered nodes.
    pub aabbs: Vec<u8>,
    /// Nodes in the heap-ordered region.
    pub heap_nodes: u32,
    /// The scene's bounds.
    pub bounds: Aabb,
}

/// Bytes per node.
pub const NODE_BYTES: usize = 8;
/// Bytes per triangle.
pub const TRI_BYTES: usize = 48;
/// The axis value of a leaf.
pub const LEAF: u32 = 3;

/// Wald's precomputed triangle: k, n' (3), e'1 (3), e'2 (3).
pub fn wald(t: &[Vec3; 3]) -> (u32, [f32; 3], [f32; 3], [f32; 3]) {
    let (v0, e1, e2) = (t[0], t[1] - t[0], t[2] - t[0]);
    let n = e1.cross(e2);
    let a = n.abs();
    let k = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let np = [n[i] / n[k], n[j] / n[k], v0.dot(n) / n[k]];
    let d = e1[i] * e2[j] - e1[j] * e2[i];
    let e1p = [-e1[j] / d, e1[i] / d, (e1[j] * v0[i] - e1[i] * v0[j]) / d];
    let e2p = [e2[j] / d, -e2[i] / d, (e2[i] * v0[j] - e2[j] * v0[i]) / d];
    (k as u32, np, e1p, e2p)
}

fn put_f32(out: &mut Vec<u8>, v: f32) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// Lays out `tree` over `tris` with `heap_levels` heap-ordered levels.
pub fn layout(tree: &KdTree, tris: &[[Vec3; 3]], heap_levels: u32) -> DeviceTree {
    let heap_nodes = (1u32 << heap_levels) - 1;
    // position of each tree node in the device array, and the pair of each inner node
    let mut pos = vec![u32::MAX; tree.nodes.len()];
    // pairs p < heap_nodes / 2 are the heap's (children of heap node p); later pairs follow in order
    let mut next_pair = heap_nodes / 2;
    let mut pairs = vec![u32::MAX; tree.nodes.len()];
    pos[0] = 0;
    let mut queue = std::collections::VecDeque::from([0u32]);
    while let Some(n) = queue.pop_front() {
        if let Node::Inner { left, right, .. } = tree.nodes[n as usize] {
            let p = pos[n as usize];
            let pair = if 2 * p + 2 < heap_nodes {
                p
            } else {
                next_pair += 1;
                next_pair - 1
            };
            pairs[n as usize] = pair;
            pos[left as usize] = 2 * pair + 1;
            pos[right as usize] = 2 * pair + 2;
            queue.push_back(left);
            queue.push_back(right);
        }
    }
    let len = pos.iter().copied().max().unwrap_or(0) as usize + 1;
    // the padded top spans 2^levels slots, so a cache preload of 2^levels nodes stays in bounds
    let mut nodes = vec![0u8; len.max(heap_nodes as usize + (heap_levels > 0) as usize) * NODE_BYTES];
    for (i, n) in tree.nodes.iter().enumerate() {
        let (w0, w1) = match *n {
            Node::Inner { axis, split, .. } => (split.to_bits(), pairs[i] << 2 | axis as u32),
            Node::Leaf { first, count } => (count, first << 2 | LEAF),
        };
        let at = pos[i] as usize * NODE_BYTES;
        nodes[at..at + 4].copy_from_slice(&w0.to_le_bytes());
        nodes[at + 4..at + 8].copy_from_slice(&w1.to_le_bytes());
    }
    // AABBs of heap nodes
    let mut aabbs = vec![0u8; (heap_nodes as usize + (heap_levels > 0) as usize) * 24];
    let mut stack = vec![(0u32, tree.bounds)];
    while let Some((n, b)) = stack.pop() {
        let p = pos[n as usize] as usize;
        if p < heap_nodes as usize {
            let mut v = Vec::with_capacity(24);
            for x in [b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z] {
                put_f32(&mut v, x);
            }
            aabbs[p * 24..p * 24 + 24].copy_from_slice(&v);
        }
        if let Node::Inner { axis, split, left, right } = tree.nodes[n as usize] {
            let (mut lb, mut rb) = (b, b);
            lb.hi[axis as usize] = split;
            rb.lo[axis as usize] = split;
            stack.push((left, lb));
            stack.push((right, rb));
        }
    }
    let mut triangles = Vec::with_capacity(tris.len() * TRI_BYTES);
    for t in tris {
        let (k, np, e1, e2) = wald(t);
        for x in np {
            put_f32(&mut triangles, x);
        }
        triangles.extend_from_slice(&k.to_le_bytes());
        for e in [e1, e2] {
            for x in e {
                put_f32(&mut triangles, x);
            }
            put_f32(&mut triangles, 0.0);
        }
    }
    let tri_refs = tree.tri_refs.iter().flat_map(|r| r.to_le_bytes()).collect();
    DeviceTree { nodes, tri_refs, triangles, aabbs, heap_nodes, bounds: tree.bounds }
}

/// Reads the laid-out nodes back into a tree (for tests and tools).
pub fn decode(d: &DeviceTree) -> Vec<Node> {
    let word = |i: usize, w: usize| {
        let at = i * NODE_BYTES + 4 * w;
        u32::from_le_bytes(d.nodes[at..at + 4].try_into().expect("4 bytes"))
    };
    let mut out = Vec::new();
    let mut map = std::collections::HashMap::new();
    let mut queue = std::collections::VecDeque::from([0usize]);
    map.insert(0usize, 0u32);
    out.push(Node::Leaf { first: 0, count: 0 });
    while let Some(p) = queue.pop_front() {
        let (w0, w1) = (word(p, 0), word(p, 1));
        let me = map[&p] as usize;
        if w1 & 3 == LEAF {
            out[me] = Node::Leaf { first: w1 >> 2, count: w0 };
        } else {
            let pair = (w1 >> 2) as usize;
            let (l, r) = (2 * pair + 1, 2 * pair + 2);
            let li = out.len() as u32;
            out.push(Node::Leaf { first: 0, count: 0 });
            out.push(Node::Leaf { first: 0, count: 0 });
            map.insert(l, li);
            map.insert(r, li + 1);
            out[me] = Node::Inner { axis: (w1 & 3) as u8, split: f32::from_bits(w0), left: li, right: li + 1 };
            queue.push_back(l);
            queue.push_back(r);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::kdtree::{BuildParams, Heuristic, build};

    fn scene() -> Vec<[Vec3; 3]> {
        let mut v = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (x, z) = (i as f32 * 0.5, j as f32 * 0.5);
                v.push([
                    Vec3::new(x, (i * j % 7) as f32 * 0.1, z),
                    Vec3::new(x + 0.4, 0.2, z),
                    Vec3::new(x, 0.3, z + 0.4),
                ]);
            }
        }
        v
    }

    /// Same structure: compare by walking both trees in the same order.
    fn same(a: &[Node], ai: u32, b: &[Node], bi: u32, refs: &[u32]) {
        match (a[ai as usize], b[bi as usize]) {
            (
                Node::Inner { axis: x, split: s, left: l1, right: r1 },
                Node::Inner { axis: y, split: t, left: l2, right: r2 },
            ) => {
                assert_eq!((x, s.to_bits()), (y, t.to_bits()));
                same(a, l1, b, l2, refs);
                same(a, r1, b, r2, refs);
            }
            (Node::Leaf { first: f1, count: c1 }, Node::Leaf { first: f2, count: c2 }) => {
                assert_eq!((f1, c1), (f2, c2));
                assert!((f1 + c1) as usize <= refs.len());
            }
            (x, y) => panic!("{x:?} vs {y:?}"),
        }
    }

    #[test]
    fn layout_round_trips() {
        let s = scene();
        let t = build(&s, BuildParams::thesis(Heuristic::Sah));
        for levels in [0, 3, 10] {
            let d = layout(&t, &s, levels);
            let back = decode(&d);
            same(&t.nodes, 0, &back, 0, &t.tri_refs);
            assert_eq!(d.triangles.len(), s.len() * TRI_BYTES);
            assert_eq!(d.tri_refs.len(), t.tri_refs.len() * 4);
            assert_eq!(d.nodes.len() % NODE_BYTES, 0);
        }
    }

    #[test]
    fn heap_region_is_heap_ordered() {
        let s = scene();
        let t = build(&s, BuildParams::thesis(Heuristic::Sah));
        let d = layout(&t, &s, 4);
        // the root's children are nodes 1 and 2, pair 0
        let w1 = u32::from_le_bytes(d.nodes[4..8].try_into().unwrap());
        assert_eq!(w1 >> 2, 0);
        // the root's AABB is the scene's
        let lo_x = f32::from_le_bytes(d.aabbs[0..4].try_into().unwrap());
        assert_eq!(lo_x, t.bounds.lo.x);
    }

    #[test]
    fn wald_form_gives_barycentrics() {
        let t = [Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 1.0)];
        let (k, np, e1, e2) = wald(&t);
        let p = t[0] + 0.25 * (t[1] - t[0]) + 0.5 * (t[2] - t[0]);
        let (i, j) = (((k + 1) % 3) as usize, ((k + 2) % 3) as usize);
        let u = e2[0] * p[i] + e2[1] * p[j] + e2[2];
        let v = e1[0] * p[i] + e1[1] * p[j] + e1[2];
        assert!((u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6, "u {u} v {v}");
        // the plane: p_k + n'_i p_i + n'_j p_j = n'_d
        assert!((p[k as usize] + np[0] * p[i] + np[1] * p[j] - np[2]).abs() < 1e-5);
    }
}
