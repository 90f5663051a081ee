//! kd-trees as thesis 000 builds them on the CPU: greedy top-down subdivision
//! minimising Eq. 4.1 with one of three visit-probability estimates — the
//! SAH (Eq. 4.2), SIROH (Eq. 4.6, evaluated incrementally as
//! c1 + c2·l + r/(c3 + c4·r)) and the numerical 26-region approximation of
//! §4.1.2 — over sorted split-candidate events in O(n log n) (`build.rs`),
//! then laid out for the kernels (`layout.rs`).
//!
//! Parameters (thesis 000 §4.1.4): C_T = 1, C_I = 3; subdivide while n > 4 and
//! the best split costs no more than a leaf; a candidate with an empty child
//! of more than 30 % of the parent's volume costs 20 % less; triangle bounds
//! are clamped to the node but not clipped. Depth is limited to 32 levels (the
//! stackless traversal's flags register). Tie rules: `docs/kdtree.md`.
//! A reference budget (32 per triangle, not a thesis parameter) bounds the
//! trees of scenes whose triangles' boxes overlap without end.

pub mod build;
pub mod cost;
pub mod layout;

use glam::Vec3;

pub use build::{BuildParams, build};
pub use cost::Heuristic;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub lo: Vec3,
    /// Maximum corner.
    pub hi: Vec3,
}

impl Aabb {
    /// The empty box.
    pub const EMPTY: Aabb = Aabb { lo: Vec3::splat(f32::INFINITY), hi: Vec3::splat(f32::NEG_INFINITY) };

    /// Grows the box to contain `p`.
    pub fn grow(&mut self, p: Vec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// Extent per axis.
    pub fn size(&self) -> Vec3 {
        (self.hi - self.lo).max(Vec3::ZERO)
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        let d = self.size();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Volume.
    pub fn volume(&self) -> f32 {
        let d = self.size();
        d.x * d.y * d.z
    }

    /// The intersection with `o`.
    pub fn clamp(&self, o: &Aabb) -> Aabb {
        Aabb { lo: self.lo.max(o.lo), hi: self.hi.min(o.hi) }
    }
}

/// A node of a built tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Node {
    /// An inner node splitting `axis` at `split`; children are `left` and `right` (indices into [`KdTree::nodes`]).
    Inner {
        /// Split axis (0 = x, 1 = y, 2 = z).
        axis: u8,
        /// Split position.
        split: f32,
        /// Left (lower) child.
        left: u32,
        /// Right (upper) child.
        right: u32,
    },
    /// A leaf referencing `count` triangles at `first` in [`KdTree::tri_refs`].
    Leaf {
        /// First reference.
        first: u32,
        /// Number of references.
        count: u32,
    },
}

/// A built kd-tree.
#[derive(Debug, Clone)]
pub struct KdTree {
    /// Nodes; the root is node 0.
    pub nodes: Vec<Node>,
    /// Triangle references of the leaves.
    pub tri_refs: Vec<u32>,
    /// Bounds of the scene (the root's box).
    pub bounds: Aabb,
    /// Depth of the deepest leaf (the root has depth 0).
    pub depth: u32,
    /// The heuristic used.
    pub heuristic: Heuristic,
    /// True when the reference budget ([`BuildParams::max_refs_per_triangle`])
    /// made leaves of nodes the heuristic would have split.
    pub budget_hit: bool,
}

/// Counts of Table 4.4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct TreeStats {
    /// Inner nodes.
    pub inner_nodes: u64,
    /// Leaves.
    pub leaves: u64,
    /// Empty leaves.
    pub empty_leaves: u64,
    /// Triangle references in leaves.
    pub tri_refs: u64,
    /// Maximum depth.
    pub depth: u32,
}

impl KdTree {
    /// Node and reference counts.
    pub fn stats(&self) -> TreeStats {
        let mut s = TreeStats {
            inner_nodes: 0,
            leaves: 0,
            empty_leaves: 0,
            tri_refs: self.tri_refs.len() as u64,
            depth: self.depth,
        };
        for n in &self.nodes {
            match n {
                Node::Inner { .. } => s.inner_nodes += 1,
                Node::Leaf { count, .. } => {
                    s.leaves += 1;
                    if *count == 0 {
                        s.empty_leaves += 1;
                    }
                }
            }
        }
        s
    }
}
