//! Thesis 003's CPU kd-tree constructions (Lin 2017 §3.2-3.3, Fig. 3): the
//! SAH tree and the space-median tree the traversal comparison of Fig. 3
//! runs on (003:L181-189).
//!
//! - **SAH** (003:L135-141): at each node, over the three axes, every
//!   distinct bound of the node's triangles strictly inside the node is a
//!   candidate plane, costed
//!   C = K_T + K_I (SA(V_L)/SA(V) |T_L| + SA(V_R)/SA(V) |T_R|); the node stays
//!   a leaf when no candidate costs less than K_I |T| (not splitting,
//!   003:L141, L564). K_T = 15 and K_I = 20 are Wald and Havran's (2006), the
//!   construction the thesis cites as its CPU reference (003:L143); the
//!   thesis states neither (`docs/fixtures.md`).
//! - **Space median**: the node's box is halved on its longest axis until a
//!   node holds at most [`Params::median_leaf`] triangles.
//!
//! Both put a triangle lying in the split plane on **both** sides (003:L566),
//! so no node is ever of zero thickness and the stackless traversals
//! (kd-restart, kd-backtrack), which cannot return to a plane they crossed,
//! find it from either side. With [`Params::clip`] a triangle's extent in a
//! child is the bound of the triangle clipped to the child's box (§3.3,
//! 003:L145-167), not its box clamped to the child's; a triangle that only
//! overlaps a child's box with its bounding box is left out of the child.
//!
//! The result is the project's [`KdTree`], which [`super::layout::PathScene`]
//! flattens. Its `heuristic` field names thesis 000's heuristics; these
//! builds record `Sah` there whatever the [`Construction`].

use glam::{DVec3, Vec3};

use crate::host::kdtree::{Aabb, Heuristic, KdTree, Node};

/// How the split planes are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Construction {
    /// The surface area heuristic (003:L135-141).
    Sah,
    /// The middle of the node's longest axis.
    SpaceMedian,
}

impl Construction {
    /// Both, in Fig. 3's column order.
    pub const ALL: [Construction; 2] = [Construction::Sah, Construction::SpaceMedian];

    /// As Fig. 3 heads its columns.
    pub fn name(self) -> &'static str {
        match self {
            Construction::Sah => "SAH",
            Construction::SpaceMedian => "Space Median",
        }
    }

    /// A short key for measurements.
    pub fn key(self) -> &'static str {
        match self {
            Construction::Sah => "sah",
            Construction::SpaceMedian => "median",
        }
    }
}

/// Construction parameters (none stated by the thesis; `docs/fixtures.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Split-plane choice.
    pub construction: Construction,
    /// Cost of a traversal step, K_T.
    pub k_t: f32,
    /// Cost of a triangle test, K_I.
    pub k_i: f32,
    /// The space-median tree's leaf size: nodes of at most this many triangles are leaves.
    pub median_leaf: usize,
    /// Deepest level (the root is level 0); at most the kernel's 32 stack entries.
    pub max_depth: u32,
    /// Clip triangles to the child boxes (§3.3).
    pub clip: bool,
}

/// The longest leaf the thesis' node can hold (6-bit count, §6.1).
const MAX_LEAF: usize = super::layout::MAX_LEAF;

impl Params {
    /// The parameters of Fig. 3's trees over `n` triangles: K_T = 15,
    /// K_I = 20 (Wald and Havran 2006), median leaves of at most 8
    /// triangles, depth at most 8 + 1.3 log2 n (PBRT's rule; at most 32),
    /// clipping on (§3.3 is the thesis' CPU build).
    pub fn fig3(construction: Construction, n: usize) -> Params {
        let depth = 8.0 + 1.3 * (n.max(1) as f64).log2();
        Params { construction, k_t: 15.0, k_i: 20.0, median_leaf: 8, max_depth: (depth as u32).min(32), clip: true }
    }
}

/// A triangle in a node: its index and its extent there.
#[derive(Debug, Clone, Copy)]
struct Item {
    tri: u32,
    lo: Vec3,
    hi: Vec3,
}

/// `x` rounded to an f32 no greater than it.
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// `x` rounded to an f32 no less than it.
fn up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}

/// The bound of triangle `t` clipped to `b` (Sutherland-Hodgman against the
/// six planes, in f64, rounded outwards), or `None` when nothing is left.
pub fn clipped_bounds(t: &[Vec3; 3], b: &Aabb) -> Option<Aabb> {
    let mut poly: Vec<DVec3> = t.iter().map(|v| v.as_dvec3()).collect();
    for axis in 0..3 {
        for (plane, keep_above) in [(b.lo[axis] as f64, true), (b.hi[axis] as f64, false)] {
            let inside = |p: &DVec3| if keep_above { p[axis] >= plane } else { p[axis] <= plane };
            let mut out = Vec::with_capacity(poly.len() + 2);
            for i in 0..poly.len() {
                let (a, c) = (poly[i], poly[(i + 1) % poly.len()]);
                let (ia, ic) = (inside(&a), inside(&c));
                if ia {
                    out.push(a);
                }
                if ia != ic {
                    let s = (plane - a[axis]) / (c[axis] - a[axis]);
                    let mut p = a + (c - a) * s;
                    p[axis] = plane;
                    out.push(p);
                }
            }
            poly = out;
            if poly.is_empty() {
                return None;
            }
        }
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &poly {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let lo = Vec3::new(down(lo.x), down(lo.y), down(lo.z)).max(b.lo);
    let hi = Vec3::new(up(hi.x), up(hi.y), up(hi.z)).min(b.hi);
    Some(Aabb { lo, hi })
}

/// The extent of triangle `t` in box `b`: clipped, or its bounds clamped to `b`.
fn extent(t: &[Vec3; 3], b: &Aabb, clip: bool) -> Option<Aabb> {
    if clip {
        return clipped_bounds(t, b);
    }
    let mut tb = Aabb::EMPTY;
    for v in t {
        tb.grow(*v);
    }
    let c = tb.clamp(b);
    (c.lo.cmple(c.hi).all()).then_some(c)
}

/// A chosen plane.
#[derive(Debug, Clone, Copy)]
struct Split {
    axis: usize,
    pos: f32,
    cost: f32,
}

/// The cheapest SAH plane of `items` in `b`: candidates are the items' bounds
/// strictly inside `b`; ties go to the first in (axis, position) order.
fn sah_split(items: &[Item], b: &Aabb, p: &Params) -> Option<Split> {
    let area = b.area();
    if area <= 0.0 {
        return None;
    }
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        let (lo, hi) = (b.lo[axis], b.hi[axis]);
        if lo >= hi {
            continue;
        }
        let mut starts: Vec<f32> = items.iter().map(|i| i.lo[axis]).collect();
        let mut ends: Vec<f32> = items.iter().map(|i| i.hi[axis]).collect();
        let mut flats: Vec<f32> = items.iter().filter(|i| i.lo[axis] == i.hi[axis]).map(|i| i.lo[axis]).collect();
        starts.sort_by(f32::total_cmp);
        ends.sort_by(f32::total_cmp);
        flats.sort_by(f32::total_cmp);
        let mut cands: Vec<f32> = starts.iter().chain(&ends).copied().filter(|&x| x > lo && x < hi).collect();
        cands.sort_by(f32::total_cmp);
        cands.dedup();
        for pos in cands {
            let flat = flats.partition_point(|&x| x < pos)..flats.partition_point(|&x| x <= pos);
            let n_flat = flat.len();
            let n_l = starts.partition_point(|&x| x < pos) + n_flat;
            let n_r = ends.len() - ends.partition_point(|&x| x <= pos) + n_flat;
            let (mut bl, mut br) = (*b, *b);
            bl.hi[axis] = pos;
            br.lo[axis] = pos;
            let cost = p.k_t + p.k_i * (bl.area() / area * n_l as f32 + br.area() / area * n_r as f32);
            if best.is_none_or(|s| cost < s.cost) {
                best = Some(Split { axis, pos, cost });
            }
        }
    }
    best
}

/// The space-median plane of `b`: the middle of its longest axis, if strictly inside.
fn median_split(b: &Aabb) -> Option<Split> {
    let e = b.size();
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let pos = 0.5 * (b.lo[axis] + b.hi[axis]);
    (pos > b.lo[axis] && pos < b.hi[axis]).then_some(Split { axis, pos, cost: 0.0 })
}

/// Builds the tree of `tris` by `p`.
pub fn build(tris: &[[Vec3; 3]], p: &Params) -> KdTree {
    let mut bounds = Aabb::EMPTY;
    for t in tris {
        for v in t {
            bounds.grow(*v);
        }
    }
    if tris.is_empty() {
        bounds = Aabb { lo: Vec3::ZERO, hi: Vec3::ZERO };
    }
    let items: Vec<Item> = (0..tris.len() as u32)
        .filter_map(|i| extent(&tris[i as usize], &bounds, false).map(|e| Item { tri: i, lo: e.lo, hi: e.hi }))
        .collect();
    let mut tree = KdTree {
        nodes: vec![Node::Leaf { first: 0, count: 0 }],
        tri_refs: Vec::new(),
        bounds,
        depth: 0,
        heuristic: Heuristic::Sah,
        budget_hit: false,
    };
    // depth first, lower child first: (node slot, box, items, depth)
    let mut todo = vec![(0usize, bounds, items, 0u32)];
    while let Some((slot, b, items, depth)) = todo.pop() {
        tree.depth = tree.depth.max(depth);
        let n = items.len();
        let split = if depth >= p.max_depth || n == 0 {
            None
        } else {
            match p.construction {
                Construction::Sah => sah_split(&items, &b, p).filter(|s| s.cost < p.k_i * n as f32 || n > MAX_LEAF),
                Construction::SpaceMedian => (n > p.median_leaf).then(|| median_split(&b)).flatten(),
            }
        };
        let Some(s) = split else {
            let first = tree.tri_refs.len() as u32;
            tree.tri_refs.extend(items.iter().map(|i| i.tri));
            tree.nodes[slot] = Node::Leaf { first, count: n as u32 };
            continue;
        };
        let (mut bl, mut br) = (b, b);
        bl.hi[s.axis] = s.pos;
        br.lo[s.axis] = s.pos;
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for it in &items {
            let (a, c) = (it.lo[s.axis], it.hi[s.axis]);
            let flat_here = a == s.pos && c == s.pos;
            let t = &tris[it.tri as usize];
            if (a < s.pos || flat_here)
                && let Some(e) = extent(t, &bl, p.clip)
            {
                left.push(Item { tri: it.tri, lo: e.lo, hi: e.hi });
            }
            if (c > s.pos || flat_here)
                && let Some(e) = extent(t, &br, p.clip)
            {
                right.push(Item { tri: it.tri, lo: e.lo, hi: e.hi });
            }
        }
        let l = tree.nodes.len();
        tree.nodes.push(Node::Leaf { first: 0, count: 0 });
        tree.nodes.push(Node::Leaf { first: 0, count: 0 });
        tree.nodes[slot] = Node::Inner { axis: s.axis as u8, split: s.pos, left: l as u32, right: l as u32 + 1 };
        todo.push((l + 1, br, right, depth + 1));
        todo.push((l, bl, left, depth + 1));
    }
    tree
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn clipping_a_triangle_to_a_box_bounds_the_pentagon() {
        // Fig. 2: a triangle cut by one corner of a box; its clipped bound is
        // the box corner's share, tighter than its bounding box clamped.
        let t = [v(0.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(0.0, 4.0, 0.0)];
        let b = Aabb { lo: v(1.0, 1.0, -1.0), hi: v(5.0, 5.0, 1.0) };
        let c = clipped_bounds(&t, &b).unwrap();
        // the part in x >= 1, y >= 1 is the triangle (1,1) (3,1) (1,3)
        assert_eq!((c.lo, c.hi), (v(1.0, 1.0, 0.0), v(3.0, 3.0, 0.0)));
        let clamped = extent(&t, &b, false).unwrap();
        assert_eq!(clamped.hi, v(4.0, 4.0, 0.0));
        // a box the triangle's bounding box overlaps but the triangle misses
        let miss = Aabb { lo: v(3.0, 3.0, -1.0), hi: v(4.0, 4.0, 1.0) };
        assert!(clipped_bounds(&t, &miss).is_none());
        assert!(extent(&t, &miss, false).is_some());
    }

    #[test]
    fn a_flat_triangle_in_the_split_plane_goes_to_both_sides() {
        // a floor in y = 0 and a triangle spanning y in [-1, 1]: the box's
        // longest axis is y, whose middle is the floor's plane (003:L566)
        let tris = vec![
            [v(-0.5, 0.0, -0.5), v(0.5, 0.0, -0.5), v(-0.5, 0.0, 0.5)],
            [v(-0.5, -1.0, 0.0), v(0.5, 1.0, 0.0), v(-0.5, 1.0, 0.2)],
        ];
        let p = Params { median_leaf: 1, max_depth: 1, ..Params::fig3(Construction::SpaceMedian, 2) };
        let t = build(&tris, &p);
        let Node::Inner { axis, split, left, right } = t.nodes[0] else { panic!("root {:?}", t.nodes[0]) };
        assert_eq!((axis, split), (1, 0.0));
        for c in [left, right] {
            let Node::Leaf { first, count } = t.nodes[c as usize] else { panic!("depth 1 is leaves") };
            assert_eq!(&t.tri_refs[first as usize..(first + count) as usize], &[0, 1]);
        }
    }

    #[test]
    fn sah_costs_are_the_thesis_formula() {
        // in a 10 x 1 x 1 box: two triangles flat on the box's x faces, which
        // offer no candidate strictly inside, and one spanning x in [4, 6]
        let b = Aabb { lo: v(0.0, 0.0, 0.0), hi: v(10.0, 1.0, 1.0) };
        let item = |tri: u32, x0: f32, x1: f32| Item { tri, lo: v(x0, 0.0, 0.0), hi: v(x1, 1.0, 1.0) };
        let p = Params::fig3(Construction::Sah, 3);
        assert!(sah_split(&[item(0, 0.0, 0.0), item(1, 10.0, 10.0)], &b, &p).is_none());
        let items = [item(0, 0.0, 0.0), item(1, 10.0, 10.0), item(2, 4.0, 6.0)];
        let s = sah_split(&items, &b, &p).unwrap();
        // K_T + K_I (SA_L/SA |T_L| + SA_R/SA |T_R|) at x = 4: 1 left, 2 right
        let area = b.area();
        let left = Aabb { hi: v(4.0, 1.0, 1.0), ..b }.area();
        let right = Aabb { lo: v(4.0, 0.0, 0.0), ..b }.area();
        let at4 = p.k_t + p.k_i * (left / area * 1.0 + right / area * 2.0);
        assert_eq!((s.axis, s.pos, s.cost), (0, 4.0, at4));
    }

    #[test]
    fn every_triangle_is_in_a_leaf_that_holds_its_points() {
        // a grid of small tilted triangles: each triangle's centroid lies in
        // the box of some leaf that references it, in both trees, clipped or not
        let mut tris = Vec::new();
        for i in 0..12 {
            for j in 0..12 {
                let (x, z) = (i as f32, j as f32);
                tris.push([v(x, 0.1 * x, z), v(x + 0.9, 0.2 * z, z), v(x, 0.5, z + 0.9)]);
            }
        }
        for c in Construction::ALL {
            for clip in [false, true] {
                let p = Params { clip, ..Params::fig3(c, tris.len()) };
                let t = build(&tris, &p);
                assert!(t.nodes.len() > 20, "{c:?}");
                for (k, tri) in tris.iter().enumerate() {
                    let centroid = (tri[0] + tri[1] + tri[2]) / 3.0;
                    // descend to the leaf holding the centroid
                    let mut at = 0usize;
                    loop {
                        match t.nodes[at] {
                            Node::Inner { axis, split, left, right } => {
                                at = if centroid[axis as usize] <= split { left } else { right } as usize;
                            }
                            Node::Leaf { first, count } => {
                                let refs = &t.tri_refs[first as usize..(first + count) as usize];
                                assert!(refs.contains(&(k as u32)), "{c:?} clip {clip}: triangle {k}");
                                break;
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn clipping_keeps_fewer_references() {
        // long diagonal triangles: clamped boxes overlap many leaves, clipped ones fewer
        let mut tris = Vec::new();
        for i in 0..40 {
            let o = i as f32 * 0.5;
            tris.push([v(o, 0.0, 0.0), v(o + 10.0, 10.0, 0.3), v(o + 0.2, 0.1, 1.0)]);
        }
        // on the space-median tree, whose planes do not depend on the bounds
        // (the SAH finds other planes with tighter bounds and splits deeper)
        let p = Params::fig3(Construction::SpaceMedian, tris.len());
        let clipped = build(&tris, &p);
        let clamped = build(&tris, &Params { clip: false, ..p });
        assert!(
            clipped.tri_refs.len() < clamped.tri_refs.len(),
            "{} vs {}",
            clipped.tri_refs.len(),
            clamped.tri_refs.len()
        );
    }
}
