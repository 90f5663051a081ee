//! Visit probabilities p_N of a node N in scene S: SAH (Eq. 4.2), SIROH
//! (Eq. 4.6) and the numerical 26-region approximation (Eq. 4.5).

use std::f32::consts::PI;

use glam::Vec3;

use super::Aabb;

/// Which estimate of the visit probability a build minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Heuristic {
    /// Surface area heuristic: p_N = SA(N)/SA(S).
    Sah,
    /// SIROH: ray origins inside the scene, incremental evaluation.
    Siroh,
    /// The numerical approximation of §4.1.2 (26 regions, solid angles).
    Numerical,
}

impl std::fmt::Display for Heuristic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Heuristic::Sah => "SAH",
            Heuristic::Siroh => "SIROH",
            Heuristic::Numerical => "numerical",
        })
    }
}

/// The probability of a node, with SIROH's components: `p0` = V(N)/V(S) and
/// one term per face (`faces[2k]` the low face on axis k, `faces[2k + 1]` the high one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prob {
    /// p_N.
    pub total: f32,
    /// V(N)/V(S) (SIROH only).
    pub p0: f32,
    /// Face terms (SIROH only).
    pub faces: [f32; 6],
}

/// The scene-dependent part of a heuristic.
#[derive(Debug, Clone, Copy)]
pub struct CostModel {
    /// The heuristic.
    pub heuristic: Heuristic,
    /// The scene's box.
    pub scene: Aabb,
    v_s: f32,
    sa_s: f32,
}

fn others(k: usize) -> (usize, usize) {
    ((k + 1) % 3, (k + 2) % 3)
}

impl CostModel {
    /// A model for `scene`.
    pub fn new(heuristic: Heuristic, scene: Aabb) -> Self {
        CostModel { heuristic, scene, v_s: scene.volume(), sa_s: scene.area() }
    }

    /// p of the root (the whole scene): 1.
    pub fn root(&self) -> Prob {
        Prob { total: 1.0, p0: 1.0, faces: [0.0; 6] }
    }

    /// p_N computed directly from the box (SIROH's components included).
    pub fn prob(&self, n: &Aabb) -> Prob {
        match self.heuristic {
            Heuristic::Sah => Prob { total: n.area() / self.sa_s, p0: 0.0, faces: [0.0; 6] },
            Heuristic::Siroh => self.siroh(n),
            Heuristic::Numerical => Prob { total: self.numerical(n), p0: 0.0, faces: [0.0; 6] },
        }
    }

    /// SIROH (Eq. 4.6) evaluated directly.
    pub fn siroh(&self, n: &Aabb) -> Prob {
        let (s, d) = (self.scene.size(), n.size());
        let p0 = n.volume() / self.v_s;
        let mut faces = [0.0f32; 6];
        for k in 0..3 {
            let (a, b) = others(k);
            let sa_sk = s[a] * s[b];
            let c_sk = 2.0 * (s[a] + s[b]);
            let sa_face = d[a] * d[b];
            for (side, t) in [(0, n.lo[k] - self.scene.lo[k]), (1, self.scene.hi[k] - n.hi[k])] {
                let t = t.max(0.0);
                faces[2 * k + side] = if t > 0.0 && sa_sk > 0.0 {
                    (t * sa_sk) / self.v_s * sa_face / (2.0 * sa_sk + t * c_sk)
                } else {
                    0.0
                };
            }
        }
        Prob { total: p0 + faces.iter().sum::<f32>(), p0, faces }
    }

    /// The numerical approximation (Eq. 4.5).
    pub fn numerical(&self, n: &Aabb) -> f32 {
        let s = &self.scene;
        let mut p = n.volume() / self.v_s;
        let iv = |k: usize, i: usize| match i {
            0 => (s.lo[k], n.lo[k]),
            1 => (n.lo[k], n.hi[k]),
            _ => (n.hi[k], s.hi[k]),
        };
        for ix in 0..3 {
            for iy in 0..3 {
                for iz in 0..3 {
                    if (ix, iy, iz) == (1, 1, 1) {
                        continue;
                    }
                    let (x, y, z) = (iv(0, ix), iv(1, iy), iv(2, iz));
                    let v = (x.1 - x.0).max(0.0) * (y.1 - y.0).max(0.0) * (z.1 - z.0).max(0.0);
                    if v <= 0.0 {
                        continue;
                    }
                    let c = Vec3::new((x.0 + x.1) * 0.5, (y.0 + y.1) * 0.5, (z.0 + z.1) * 0.5);
                    p += v / self.v_s * box_solid_angle(n, c) / (4.0 * PI);
                }
            }
        }
        p
    }

    /// Probabilities of the two children of `parent` split on `axis` at `s`.
    /// SIROH uses the incremental form c1 + c2·l + r/(c3 + c4·r).
    pub fn children(&self, parent: &Aabb, pp: &Prob, axis: usize, s: f32) -> (Prob, Prob) {
        let (mut l, mut r) = (*parent, *parent);
        l.hi[axis] = s;
        r.lo[axis] = s;
        match self.heuristic {
            Heuristic::Siroh => {
                let sw = SirohSweep::new(self, parent, pp, axis);
                (sw.left_components(pp, s), sw.right_components(pp, s))
            }
            _ => (self.prob(&l), self.prob(&r)),
        }
    }
}

/// Solid angle subtended by box `n` at outside point `c`: the faces facing `c`,
/// each as two triangles (Van Oosterom and Strackee).
fn box_solid_angle(n: &Aabb, c: Vec3) -> f32 {
    let mut total = 0.0;
    for k in 0..3 {
        let (a, b) = others(k);
        for (plane, visible) in [(n.lo[k], c[k] < n.lo[k]), (n.hi[k], c[k] > n.hi[k])] {
            if !visible {
                continue;
            }
            let corner = |u: f32, v: f32| {
                let mut p = Vec3::ZERO;
                p[k] = plane;
                p[a] = u;
                p[b] = v;
                p - c
            };
            let q = [
                corner(n.lo[a], n.lo[b]),
                corner(n.hi[a], n.lo[b]),
                corner(n.hi[a], n.hi[b]),
                corner(n.lo[a], n.hi[b]),
            ];
            total += triangle_solid_angle(q[0], q[1], q[2]) + triangle_solid_angle(q[0], q[2], q[3]);
        }
    }
    total
}

/// Ω = 2 atan(x_a·(x_b × x_c) / (|a||b||c| + |a|(b·c) + |b|(a·c) + |c|(a·b))), unsigned.
fn triangle_solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + la * b.dot(c) + lb * a.dot(c) + lc * a.dot(b);
    2.0 * num.atan2(den)
}

/// Constants of SIROH's incremental evaluation along one axis of a parent.
#[derive(Debug, Clone, Copy)]
pub struct SirohSweep {
    axis: usize,
    lo: f32,
    hi: f32,
    scene_lo: f32,
    scene_hi: f32,
    c2: f32,
    c3: f32,
    c4: f32,
    extent: f32,
}

impl SirohSweep {
    /// Precomputes c2, c3, c4 for splits of `parent` on `axis`.
    pub fn new(m: &CostModel, parent: &Aabb, pp: &Prob, axis: usize) -> Self {
        let (a, b) = others(axis);
        let (s, d) = (m.scene.size(), parent.size());
        let extent = d[axis];
        let rest = pp.p0 + pp.faces[2 * a] + pp.faces[2 * a + 1] + pp.faces[2 * b] + pp.faces[2 * b + 1];
        let c2 = if extent > 0.0 { rest / extent } else { 0.0 };
        let sa_l3 = d[a] * d[b];
        let sa_s3 = s[a] * s[b];
        let c_s3 = 2.0 * (s[a] + s[b]);
        let (c3, c4) = if sa_l3 > 0.0 && sa_s3 > 0.0 {
            (2.0 * m.v_s / sa_l3, m.v_s * c_s3 / (sa_s3 * sa_l3))
        } else {
            (f32::INFINITY, 0.0)
        };
        SirohSweep {
            axis,
            lo: parent.lo[axis],
            hi: parent.hi[axis],
            scene_lo: m.scene.lo[axis],
            scene_hi: m.scene.hi[axis],
            c2,
            c3,
            c4,
            extent,
        }
    }

    fn face(&self, r: f32) -> f32 {
        if r > 0.0 && self.c3.is_finite() { r / (self.c3 + self.c4 * r) } else { 0.0 }
    }

    /// p_L and p_R for a split at `s`: three additions, two multiplications and one division each.
    #[inline]
    pub fn eval(&self, pp: &Prob, s: f32) -> (f32, f32) {
        let k = self.axis;
        let pl = pp.faces[2 * k] + self.c2 * (s - self.lo) + self.face(self.scene_hi - s);
        let pr = pp.faces[2 * k + 1] + self.c2 * (self.hi - s) + self.face(s - self.scene_lo);
        (pl, pr)
    }

    fn scaled(&self, pp: &Prob, frac: f32) -> Prob {
        let mut c = *pp;
        c.p0 *= frac;
        for j in 0..3 {
            if j != self.axis {
                c.faces[2 * j] *= frac;
                c.faces[2 * j + 1] *= frac;
            }
        }
        c
    }

    /// The left child's components.
    pub fn left_components(&self, pp: &Prob, s: f32) -> Prob {
        let frac = if self.extent > 0.0 { (s - self.lo) / self.extent } else { 0.0 };
        let mut c = self.scaled(pp, frac);
        c.faces[2 * self.axis + 1] = self.face(self.scene_hi - s);
        c.total = c.p0 + c.faces.iter().sum::<f32>();
        c
    }

    /// The right child's components.
    pub fn right_components(&self, pp: &Prob, s: f32) -> Prob {
        let frac = if self.extent > 0.0 { (self.hi - s) / self.extent } else { 0.0 };
        let mut c = self.scaled(pp, frac);
        c.faces[2 * self.axis] = self.face(s - self.scene_lo);
        c.total = c.p0 + c.faces.iter().sum::<f32>();
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn scene() -> Aabb {
        Aabb { lo: Vec3::new(0.0, 0.0, 0.0), hi: Vec3::new(4.0, 2.0, 3.0) }
    }

    #[test]
    fn root_probability_is_one() {
        for h in [Heuristic::Sah, Heuristic::Siroh, Heuristic::Numerical] {
            let m = CostModel::new(h, scene());
            assert_relative_eq!(m.prob(&scene()).total, 1.0, epsilon = 1e-5);
        }
    }

    #[test]
    fn incremental_siroh_equals_direct() {
        let m = CostModel::new(Heuristic::Siroh, scene());
        let parent = Aabb { lo: Vec3::new(0.5, 0.2, 1.0), hi: Vec3::new(3.0, 1.5, 2.5) };
        let pp = m.siroh(&parent);
        for axis in 0..3 {
            let sw = SirohSweep::new(&m, &parent, &pp, axis);
            for f in [0.1f32, 0.37, 0.8] {
                let s = parent.lo[axis] + f * parent.size()[axis];
                let (mut l, mut r) = (parent, parent);
                l.hi[axis] = s;
                r.lo[axis] = s;
                let (pl, pr) = sw.eval(&pp, s);
                assert_relative_eq!(pl, m.siroh(&l).total, epsilon = 1e-5);
                assert_relative_eq!(pr, m.siroh(&r).total, epsilon = 1e-5);
                let (cl, cr) = m.children(&parent, &pp, axis, s);
                assert_relative_eq!(cl.total, pl, epsilon = 1e-5);
                assert_relative_eq!(cr.total, pr, epsilon = 1e-5);
                for i in 0..6 {
                    assert_relative_eq!(cl.faces[i], m.siroh(&l).faces[i], epsilon = 1e-5);
                }
            }
        }
    }

    #[test]
    fn solid_angle_of_a_face_seen_from_close_is_near_2pi() {
        let n = Aabb { lo: Vec3::splat(-1.0), hi: Vec3::splat(1.0) };
        let omega = box_solid_angle(&n, Vec3::new(0.0, 0.0, 1.001));
        assert!((omega - 2.0 * PI).abs() < 0.01, "{omega}");
        // from far away along an axis: about area / d^2
        let far = box_solid_angle(&n, Vec3::new(0.0, 0.0, 100.0));
        assert_relative_eq!(far, 4.0 / (99.0f32 * 99.0), epsilon = 1e-5);
    }

    #[test]
    fn heuristics_rank_inner_nodes_alike_and_bound_them() {
        let s = scene();
        let n = Aabb { lo: Vec3::new(1.0, 0.5, 1.0), hi: Vec3::new(2.0, 1.0, 2.0) };
        for h in [Heuristic::Sah, Heuristic::Siroh, Heuristic::Numerical] {
            let p = CostModel::new(h, s).prob(&n).total;
            assert!(p > 0.0 && p < 1.0, "{h}: {p}");
        }
    }
}
