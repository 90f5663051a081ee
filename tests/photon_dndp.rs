//! Eqs. 5.12–5.21 (seed 000: the interpolated normal's derivative ∂n/∂p
//! through Wald's projection) on every projection axis (review 6, finding 3).
//! `ShadingTriangle::normal_at` picks k = argmax |n_geo,k| and places ∂λ/∂z's
//! entries at the rows i, j = k + 1, k + 2 (mod 3); `tests/photons.rs` and
//! `tests/photon_stability.rs` use triangles in z = 0 only (k = 2). Here the
//! same concave patch has its coordinates permuted (all six orders), so that
//! k = 0, 1 and 2 each occur, with both windings: the derivative must match
//! central differences of n(λ) and the curved mirror must focus a parallel
//! beam at half its radius on every axis.

use glam::Vec3;
use warplight::repro::fabianowski2011::photons::{self, Differentials, propagate, reflect};

/// The six orders of the three axes.
const PERMS: [[usize; 3]; 6] = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [1, 0, 2], [0, 2, 1], [2, 1, 0]];

/// `a` with coordinate c moved to axis `perm[c]`.
fn permute(perm: [usize; 3], a: [f32; 3]) -> [f32; 3] {
    let mut r = [0.0; 3];
    for c in 0..3 {
        r[perm[c]] = a[c];
    }
    r
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
}

/// tests/photons.rs's sphere patch (the plane z = 0, vertex normals toward
/// the centre (0, 0, r) of a sphere of radius r), its coordinates permuted.
fn patch(perm: [usize; 3], r: f32) -> photons::ShadingTriangle {
    let v = [[-0.2, -0.2, 0.0], [0.3, -0.1, 0.0], [-0.05, 0.35, 0.0]];
    let n = v.map(|p: [f32; 3]| (Vec3::new(0.0, 0.0, r) - v3(p)).normalize().to_array());
    photons::ShadingTriangle { v: v.map(|p| permute(perm, p)), n: n.map(|p| permute(perm, p)) }
}

/// The projection axis `normal_at` takes: the geometric normal's largest component.
fn axis(t: &photons::ShadingTriangle) -> usize {
    let [v0, v1, v2] = t.v.map(v3);
    let g = (v1 - v0).cross(v2 - v0).abs();
    (0..3).max_by(|&a, &b| g[a].total_cmp(&g[b])).unwrap()
}

#[test]
fn the_permuted_patches_project_on_every_axis() {
    let mut seen = [0; 3];
    for perm in PERMS {
        seen[axis(&patch(perm, 2.0))] += 1;
    }
    assert_eq!(seen, [2, 2, 2]);
}

#[test]
fn the_normal_derivative_matches_finite_differences_on_every_axis() {
    let r = 2.0;
    for perm in PERMS {
        let t = patch(perm, r);
        let z = permute(perm, [0.0, 0.05, 0.0]);
        let s = t.normal_at(z).unwrap();
        let n_at = |p: Vec3| v3(t.normal_at(p.to_array()).unwrap().n);
        for d in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.6, -0.8, 0.0]] {
            let d = v3(permute(perm, d));
            let h = 1e-2;
            let fd = (n_at(v3(z) + d * h) - n_at(v3(z) - d * h)) / (2.0 * h);
            let an = v3(s.dn_dp(d.to_array()));
            assert!((fd - an).length() < 2e-3 * an.length().max(1e-3), "{perm:?} d {d}: {fd} vs {an}");
            // inside the sphere ∂n/∂z ≈ −d / r
            assert!((an + d / r).length() < 0.05, "{perm:?}: {an}");
        }
        // (u, v) are the weights of v1 and v2: at v1 the normal is n1, at v2 n2
        for k in 1..3 {
            assert!((v3(t.normal_at(t.v[k]).unwrap().n) - v3(t.n[k]).normalize()).length() < 1e-6, "{perm:?}");
        }
    }
}

#[test]
fn a_curved_mirror_focuses_a_parallel_beam_at_half_its_radius_on_every_axis() {
    let r = 2.0;
    for perm in PERMS {
        let t = patch(perm, r);
        let up = permute(perm, [0.0, 0.0, 1.0]);
        let (x, y) = (v3(permute(perm, [1.0, 0.0, 0.0])), v3(permute(perm, [0.0, 1.0, 0.0])));
        let mut p = Differentials {
            z: permute(perm, [0.0, 0.05, 1.0]),
            w: permute(perm, [0.0, 0.0, -1.0]),
            dz: [x.to_array(), y.to_array()],
            dw: [[0.0; 3]; 2],
        };
        propagate(&mut p, 1.0, up);
        let s = t.normal_at(p.z).unwrap();
        let mut flat = p;
        photons::reflect_curved(&mut p, Some(&s), up);
        reflect(&mut flat, up);
        assert_eq!(flat.dw, [[0.0; 3]; 2]);
        assert!(v3(p.w).dot(v3(up)) > 0.99, "{perm:?}: {:?}", p.w);
        for (i, a) in [x, y].into_iter().enumerate() {
            let dw = v3(p.dw[i]);
            assert!((dw + a * (2.0 / r)).length() < 0.05 * (2.0 / r), "{perm:?} {i}: {dw}");
            let focus = v3(p.dz[i]) + dw * (r / 2.0);
            assert!(focus.length() < 0.06, "{perm:?} {i}: {focus}");
        }
    }
}
