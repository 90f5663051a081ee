//! The O(n log n) kd-tree builder: split candidates are the start, end and
//! planar events of the triangles' bounds (clamped to the node), sorted once
//! per axis at the root and kept sorted while nodes split (Wald and Havran 2006).
//!
//! Deterministic tie rules (`docs/kdtree.md`): among candidates of equal cost
//! the first in (axis, position) order wins; triangles lying in the split
//! plane go left unless right is strictly cheaper; events at one position are
//! ordered end, planar, start, then by triangle index.

use glam::Vec3;

use super::cost::{CostModel, Heuristic, Prob, SirohSweep};
use super::{Aabb, KdTree, Node};

/// Construction parameters (thesis 000 §4.1.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildParams {
    /// The visit-probability estimate.
    pub heuristic: Heuristic,
    /// Cost of traversing an inner node, C_T.
    pub c_t: f32,
    /// Cost of intersecting a triangle, C_I.
    pub c_i: f32,
    /// Subdivide only nodes with more triangles than this.
    pub leaf_max: usize,
    /// Cost factor of a candidate with a large empty child.
    pub empty_bias: f32,
    /// Volume fraction above which an empty child earns the bias.
    pub empty_volume: f32,
    /// Maximum depth (the root has depth 0).
    pub max_depth: u32,
    /// Most triangle references per triangle of the scene: a split that
    /// would take the tree past `max_refs_per_triangle · n` references makes
    /// a leaf instead. Not a thesis parameter: a bound for scenes whose
    /// bounding boxes overlap without end, as in a flat fan of triangles
    /// (`docs/kdtree.md#the-reference-budget`); the scenes of the thesis stay
    /// below 6.
    pub max_refs_per_triangle: u32,
}

/// The default reference budget per triangle ([`BuildParams::max_refs_per_triangle`]).
pub const MAX_REFS_PER_TRIANGLE: u32 = 32;

impl BuildParams {
    /// Thesis 000's parameters with heuristic `h`.
    pub fn thesis(h: Heuristic) -> Self {
        BuildParams {
            heuristic: h,
            c_t: 1.0,
            c_i: 3.0,
            leaf_max: 4,
            empty_bias: 0.8,
            empty_volume: 0.3,
            max_depth: 32,
            max_refs_per_triangle: MAX_REFS_PER_TRIANGLE,
        }
    }
}

const END: u8 = 0;
const PLANAR: u8 = 1;
const START: u8 = 2;

#[derive(Debug, Clone, Copy)]
struct Event {
    pos: f32,
    kind: u8,
    tri: u32,
}

fn ev_cmp(a: &Event, b: &Event) -> std::cmp::Ordering {
    a.pos.total_cmp(&b.pos).then(a.kind.cmp(&b.kind)).then(a.tri.cmp(&b.tri))
}

fn events_of(b: &Aabb, tri: u32, axis: usize, out: &mut Vec<Event>) {
    if b.lo[axis] == b.hi[axis] {
        out.push(Event { pos: b.lo[axis], kind: PLANAR, tri });
    } else {
        out.push(Event { pos: b.lo[axis], kind: START, tri });
        out.push(Event { pos: b.hi[axis], kind: END, tri });
    }
}

fn merge(a: Vec<Event>, b: Vec<Event>) -> Vec<Event> {
    if b.is_empty() {
        return a;
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if ev_cmp(&a[i], &b[j]).is_le() {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

#[derive(Debug, Clone, Copy)]
struct Split {
    cost: f32,
    axis: usize,
    pos: f32,
    planar_left: bool,
}

const LEFT: u8 = 1;
const RIGHT: u8 = 2;
const BOTH: u8 = 3;

struct Builder<'a> {
    p: BuildParams,
    model: CostModel,
    boxes: &'a [Aabb],
    side: Vec<u8>,
    nodes: Vec<Node>,
    refs: Vec<u32>,
    depth: u32,
    /// References the tree will hold: those of its leaves plus the
    /// triangles of the nodes still to be built.
    planned: u64,
    /// The most references the tree may hold.
    budget: u64,
    /// True when the budget turned a node that would have split into a leaf.
    budget_hit: bool,
}

/// Builds a kd-tree over triangles (each three vertices).
pub fn build(tris: &[[Vec3; 3]], p: BuildParams) -> KdTree {
    let boxes: Vec<Aabb> = tris
        .iter()
        .map(|t| {
            let mut b = Aabb::EMPTY;
            t.iter().for_each(|v| b.grow(*v));
            b
        })
        .collect();
    let mut bounds = Aabb::EMPTY;
    for b in &boxes {
        bounds.grow(b.lo);
        bounds.grow(b.hi);
    }
    if tris.is_empty() {
        bounds = Aabb { lo: Vec3::ZERO, hi: Vec3::ZERO };
    }
    let model = CostModel::new(p.heuristic, bounds);
    let mut events: [Vec<Event>; 3] = Default::default();
    for (axis, ev) in events.iter_mut().enumerate() {
        ev.reserve(2 * tris.len());
        for (i, b) in boxes.iter().enumerate() {
            events_of(b, i as u32, axis, ev);
        }
        ev.sort_unstable_by(ev_cmp);
    }
    let n = tris.len() as u64;
    let mut b = Builder {
        p,
        model,
        boxes: &boxes,
        side: vec![0; tris.len()],
        nodes: Vec::new(),
        refs: Vec::new(),
        depth: 0,
        planned: n,
        budget: n.saturating_mul(p.max_refs_per_triangle.max(1) as u64),
        budget_hit: false,
    };
    let all: Vec<u32> = (0..tris.len() as u32).collect();
    let root = model.root();
    b.node(bounds, root, all, events, 0);
    KdTree {
        nodes: b.nodes,
        tri_refs: b.refs,
        bounds,
        depth: b.depth,
        heuristic: p.heuristic,
        budget_hit: b.budget_hit,
    }
}

impl Builder<'_> {
    fn leaf(&mut self, at: usize, tris: &[u32]) {
        self.nodes[at] = Node::Leaf { first: self.refs.len() as u32, count: tris.len() as u32 };
        self.refs.extend_from_slice(tris);
    }

    fn node(&mut self, bounds: Aabb, prob: Prob, tris: Vec<u32>, events: [Vec<Event>; 3], depth: u32) -> u32 {
        let at = self.nodes.len();
        self.nodes.push(Node::Leaf { first: 0, count: 0 });
        self.depth = self.depth.max(depth);
        let n = tris.len();
        if n <= self.p.leaf_max || depth >= self.p.max_depth {
            self.leaf(at, &tris);
            return at as u32;
        }
        let best = self.find_split(&bounds, &prob, n, &events);
        let leaf_cost = prob.total * n as f32 * self.p.c_i;
        let Some(best) = best.filter(|b| b.cost <= leaf_cost) else {
            self.leaf(at, &tris);
            return at as u32;
        };
        let (k, s) = (best.axis, best.pos);
        let (mut lb, mut rb) = (bounds, bounds);
        lb.hi[k] = s;
        rb.lo[k] = s;
        // classify
        let (mut lt, mut rt, mut both) = (Vec::new(), Vec::new(), Vec::new());
        for &t in &tris {
            let b = self.boxes[t as usize].clamp(&bounds);
            let side = if b.lo[k] == s && b.hi[k] == s {
                if best.planar_left { LEFT } else { RIGHT }
            } else if b.hi[k] <= s {
                LEFT
            } else if b.lo[k] >= s {
                RIGHT
            } else {
                BOTH
            };
            self.side[t as usize] = side;
            match side {
                LEFT => lt.push(t),
                RIGHT => rt.push(t),
                _ => {
                    lt.push(t);
                    rt.push(t);
                    both.push(t);
                }
            }
        }
        // the straddlers are referenced twice: within the budget, or a leaf
        if self.planned + both.len() as u64 > self.budget {
            for &t in &tris {
                self.side[t as usize] = 0;
            }
            self.budget_hit = true;
            self.leaf(at, &tris);
            return at as u32;
        }
        self.planned += both.len() as u64;
        // split the sorted event lists; regenerate the straddlers' events in each child
        let mut le: [Vec<Event>; 3] = Default::default();
        let mut re: [Vec<Event>; 3] = Default::default();
        for (j, ev) in events.into_iter().enumerate() {
            let (mut l, mut r) = (Vec::with_capacity(ev.len()), Vec::with_capacity(ev.len()));
            for e in ev {
                match self.side[e.tri as usize] {
                    LEFT => l.push(e),
                    RIGHT => r.push(e),
                    _ => {}
                }
            }
            let (mut nl, mut nr) = (Vec::new(), Vec::new());
            for &t in &both {
                events_of(&self.boxes[t as usize].clamp(&lb), t, j, &mut nl);
                events_of(&self.boxes[t as usize].clamp(&rb), t, j, &mut nr);
            }
            nl.sort_unstable_by(ev_cmp);
            nr.sort_unstable_by(ev_cmp);
            le[j] = merge(l, nl);
            re[j] = merge(r, nr);
        }
        for &t in &tris {
            self.side[t as usize] = 0;
        }
        drop(tris);
        let (pl, pr) = self.model.children(&bounds, &prob, k, s);
        let left = self.node(lb, pl, lt, le, depth + 1);
        let right = self.node(rb, pr, rt, re, depth + 1);
        self.nodes[at] = Node::Inner { axis: k as u8, split: s, left, right };
        at as u32
    }

    fn find_split(&self, bounds: &Aabb, prob: &Prob, n: usize, events: &[Vec<Event>; 3]) -> Option<Split> {
        let mut best: Option<Split> = None;
        let size = bounds.size();
        for (k, ev) in events.iter().enumerate() {
            if size[k] <= 0.0 {
                continue;
            }
            let siroh = (self.p.heuristic == Heuristic::Siroh).then(|| SirohSweep::new(&self.model, bounds, prob, k));
            let (mut nl, mut nr) = (0usize, n);
            let mut i = 0;
            while i < ev.len() {
                let pos = ev[i].pos;
                let (mut pe, mut pp, mut ps) = (0, 0, 0);
                while i < ev.len() && ev[i].pos == pos && ev[i].kind == END {
                    pe += 1;
                    i += 1;
                }
                while i < ev.len() && ev[i].pos == pos && ev[i].kind == PLANAR {
                    pp += 1;
                    i += 1;
                }
                while i < ev.len() && ev[i].pos == pos && ev[i].kind == START {
                    ps += 1;
                    i += 1;
                }
                nr -= pp + pe;
                if pos >= bounds.lo[k] && pos <= bounds.hi[k] {
                    let (pl, pr) = match &siroh {
                        Some(sw) => sw.eval(prob, pos),
                        None => {
                            let (mut l, mut r) = (*bounds, *bounds);
                            l.hi[k] = pos;
                            r.lo[k] = pos;
                            (self.model.prob(&l).total, self.model.prob(&r).total)
                        }
                    };
                    let frac = (pos - bounds.lo[k]) / size[k];
                    for planar_left in [true, false] {
                        let (cl, cr) = if planar_left { (nl + pp, nr) } else { (nl, nr + pp) };
                        let mut cost = self.p.c_t * prob.total + self.p.c_i * (pl * cl as f32 + pr * cr as f32);
                        if (cl == 0 && frac > self.p.empty_volume) || (cr == 0 && 1.0 - frac > self.p.empty_volume) {
                            cost *= self.p.empty_bias;
                        }
                        if best.is_none_or(|b| cost < b.cost) {
                            best = Some(Split { cost, axis: k, pos, planar_left });
                        }
                    }
                }
                nl += ps + pp;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [Vec3; 3] {
        [Vec3::from(a), Vec3::from(b), Vec3::from(c)]
    }

    /// Every triangle is reachable from the leaves whose boxes it overlaps.
    fn check(tree: &KdTree, tris: &[[Vec3; 3]]) {
        let mut seen = vec![false; tris.len()];
        let mut stack = vec![(0u32, tree.bounds)];
        while let Some((n, b)) = stack.pop() {
            match tree.nodes[n as usize] {
                Node::Inner { axis, split, left, right } => {
                    assert!(split >= b.lo[axis as usize] && split <= b.hi[axis as usize]);
                    let (mut lb, mut rb) = (b, b);
                    lb.hi[axis as usize] = split;
                    rb.lo[axis as usize] = split;
                    stack.push((left, lb));
                    stack.push((right, rb));
                }
                Node::Leaf { first, count } => {
                    for &t in &tree.tri_refs[first as usize..(first + count) as usize] {
                        seen[t as usize] = true;
                    }
                }
            }
        }
        assert!(seen.iter().all(|&s| s), "every triangle is referenced");
    }

    fn grid_scene(n: usize) -> Vec<[Vec3; 3]> {
        let mut v = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, z) = (i as f32, j as f32);
                v.push(tri([x, 0.0, z], [x + 0.9, 0.0, z], [x, 0.5, z + 0.9]));
            }
        }
        v
    }

    #[test]
    fn small_nodes_are_leaves() {
        let t = build(&grid_scene(2), BuildParams::thesis(Heuristic::Sah));
        assert_eq!(t.nodes.len(), 1);
        assert_eq!(t.stats().tri_refs, 4);
    }

    #[test]
    fn trees_reference_every_triangle() {
        let s = grid_scene(12);
        for h in [Heuristic::Sah, Heuristic::Siroh, Heuristic::Numerical] {
            let t = build(&s, BuildParams::thesis(h));
            check(&t, &s);
            let st = t.stats();
            assert!(st.inner_nodes > 10, "{h}: {st:?}");
            assert!(st.tri_refs >= 144);
            assert!(t.depth <= 32);
        }
    }

    #[test]
    fn planar_triangles_in_a_plane_are_shaved_off() {
        // a floor of 64 flat triangles plus a cloud above it
        let mut s = Vec::new();
        for i in 0..8 {
            for j in 0..8 {
                let (x, z) = (i as f32, j as f32);
                s.push(tri([x, 0.0, z], [x + 1.0, 0.0, z], [x, 0.0, z + 1.0]));
                s.push(tri([x, 10.0 + 0.05 * i as f32, z], [x + 0.5, 10.5, z], [x, 10.2, z + 0.5]));
            }
        }
        let t = build(&s, BuildParams::thesis(Heuristic::Sah));
        check(&t, &s);
        // the root cuts the empty space between the floor and the cloud on y
        match t.nodes[0] {
            Node::Inner { axis, split, .. } => assert!(axis == 1 && split <= 10.0, "root splits y at {split}"),
            n => panic!("root is {n:?}"),
        }
    }

    #[test]
    fn builds_are_deterministic() {
        let s = grid_scene(10);
        let a = build(&s, BuildParams::thesis(Heuristic::Siroh));
        let b = build(&s, BuildParams::thesis(Heuristic::Siroh));
        assert_eq!(a.nodes, b.nodes);
        assert_eq!(a.tri_refs, b.tri_refs);
    }

    /// A flat disc: `n` thin triangles fanned around the origin in y = 0.
    fn disc(n: usize) -> Vec<[Vec3; 3]> {
        let rim = |i: usize| {
            let a = std::f32::consts::TAU * (i % n) as f32 / n as f32;
            Vec3::new(a.cos(), 0.0, a.sin())
        };
        (0..n).map(|i| [Vec3::ZERO, rim(i), rim(i + 1)]).collect()
    }

    #[test]
    fn a_flat_disc_blows_up_without_the_reference_budget() {
        // In a flat node the children's surface areas add up to the parent's,
        // so the SAH charges nothing for straddlers, and the fan's boxes
        // overlap: the tree refines to the cells of the boxes' edges.
        let s = disc(200);
        let unbounded = BuildParams { max_refs_per_triangle: u32::MAX, ..BuildParams::thesis(Heuristic::Sah) };
        let t = build(&s, unbounded);
        assert!(!t.budget_hit);
        assert!(t.stats().tri_refs > 200 * 200, "{:?}", t.stats());
    }

    #[test]
    fn the_reference_budget_bounds_a_flat_disc() {
        // issue 17's case: 1,998 triangles took 33 s and 667 MB
        let s = disc(1998);
        for h in [Heuristic::Sah, Heuristic::Siroh] {
            let t = build(&s, BuildParams::thesis(h));
            check(&t, &s);
            let st = t.stats();
            assert!(t.budget_hit, "{h}");
            assert!(st.tri_refs <= 1998 * MAX_REFS_PER_TRIANGLE as u64, "{h}: {st:?}");
            assert!(st.tri_refs > 1998 * 8, "{h}: the budget is used, not a single leaf: {st:?}");
        }
        // a scene in three dimensions never meets it
        let s = grid_scene(12);
        for h in [Heuristic::Sah, Heuristic::Siroh, Heuristic::Numerical] {
            let t = build(&s, BuildParams::thesis(h));
            assert!(!t.budget_hit, "{h}");
        }
    }
}
