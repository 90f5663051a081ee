//! Thesis 003's SAH BVH and refit (§3.5-3.6, 003:L191-205): the binned-SAH
//! build holds every triangle once and each box bounds its subtree; the
//! traversal finds brute force's nearest hit although the back child may
//! hold it (the failure case of 003:L197-199); the emulated traversal equals
//! the native one bit for bit through the same counted events, and the
//! memory model moves exactly 4 bytes a stack push or pop; the emulated
//! refit with atomics leaves the boxes the serial refit computes, with
//! exactly two atomic arrivals per inner node; after a translation, the
//! refitted tree still finds every brute-force hit.

use std::path::Path;

use glam::Vec3;
use warplight::host::path::bvh::{self, Bvh, BvhRay, Walk};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::sim::Device;

fn scene() -> Scene {
    scene_file::load(Path::new("scenes/cornell-lambert.toml")).unwrap()
}

/// Object 1: the triangles off the walls with x < 0 (the tall box); object 0: the rest.
fn objects(s: &Scene) -> Vec<u32> {
    let (lo, hi) = s
        .triangles
        .iter()
        .flat_map(|t| t.v)
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    s.triangles
        .iter()
        .map(|t| {
            let inside = t.v.iter().all(|v| {
                (0..3).all(|k| v[k] > lo[k] + 0.05 * (hi[k] - lo[k]) && v[k] < hi[k] - 0.05 * (hi[k] - lo[k]))
            });
            (inside && t.v.iter().all(|v| v.x < 0.0)) as u32
        })
        .collect()
}

/// A counter-based uniform in [0, 1).
fn u(i: u32, d: u32) -> f32 {
    let mut h = i.wrapping_mul(0x9e37_79b9) ^ d.wrapping_mul(0x85eb_ca6b);
    for _ in 0..2 {
        h ^= h >> 16;
        h = h.wrapping_mul(0x7feb_352d);
        h ^= h >> 15;
        h = h.wrapping_mul(0x846c_a68b);
        h ^= h >> 16;
    }
    (h >> 8) as f32 / 16_777_216.0
}

/// Camera rays through a `side` x `side` grid, and as many rays from random
/// points inside the room in random directions (whose back children often
/// hold the nearer hit).
fn rays(s: &Scene, side: u32) -> Vec<BvhRay> {
    let cam = s.camera;
    let mut out = Vec::new();
    let (r, up, f) = cam.frame();
    let th = (cam.fov_y.to_radians() * 0.5).tan();
    for y in 0..side {
        for x in 0..side {
            let cx = ((x as f32 + 0.5) / side as f32 * 2.0 - 1.0) * th;
            let cy = (1.0 - (y as f32 + 0.5) / side as f32 * 2.0) * th;
            let d = (f + r * cx + up * cy).normalize();
            out.push(BvhRay { origin: cam.position, dir: d.into(), t_min: 1e-4, t_max: f32::INFINITY });
        }
    }
    for i in 0..side * side {
        let o = [-0.9 + 1.8 * u(i, 0), 0.1 + 1.8 * u(i, 1), -0.9 + 1.8 * u(i, 2)];
        let z = 1.0 - 2.0 * u(i, 3);
        let a = std::f32::consts::TAU * u(i, 4);
        let rr = (1.0 - z * z).max(0.0).sqrt();
        out.push(BvhRay { origin: o, dir: [rr * a.cos(), rr * a.sin(), z], t_min: 1e-4, t_max: f32::INFINITY });
    }
    out
}

fn build(s: &Scene) -> Bvh {
    let tris: Vec<[Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    Bvh::build(&tris, &objects(s)).unwrap()
}

const REST: [[f32; 4]; 2] = [[0.0; 4]; 2];
/// The tall box moved by (0.25, 0.125, -0.5): its leaves and their ancestors
/// grow and move.
const MOVED: [[f32; 4]; 2] = [[0.0; 4], [0.25, 0.125, -0.5, 0.0]];

#[test]
fn the_binned_sah_build_holds_every_triangle_once_and_every_box_bounds_its_subtree() {
    let s = scene();
    let b = build(&s);
    assert!(objects(&s).contains(&1), "a movable object");
    let mut seen = b.refs.clone();
    seen.sort();
    assert_eq!(seen, (0..s.triangles.len() as u32).collect::<Vec<_>>());
    assert_eq!(b.leaves.len(), b.inner() + 1, "a binary tree");
    for (i, n) in b.nodes.iter().enumerate() {
        let (lo, hi) = b.node_box(i);
        if n[3] >> 30 == bvh::LEAF {
            let first = (n[3] & 0x3fff_ffff) as usize;
            assert!(n[7] > 0, "node {i}: an empty leaf");
            for &t in &b.refs[first..first + n[7] as usize] {
                for v in &b.verts[t as usize] {
                    assert!((0..3).all(|k| lo[k] <= v[k] && v[k] <= hi[k]), "node {i}");
                }
            }
        } else {
            let (l, r) = (b.node_box(i + 1), b.node_box((n[3] & 0x3fff_ffff) as usize));
            for k in 0..3 {
                assert_eq!(lo[k], l.0[k].min(r.0[k]), "node {i}");
                assert_eq!(hi[k], l.1[k].max(r.1[k]), "node {i}");
            }
            assert_eq!(b.parents[i + 1] as usize, i);
        }
    }
}

#[test]
fn the_traversal_finds_brute_forces_nearest_hit_though_the_back_child_may_hold_it() {
    let s = scene();
    let mut b = build(&s);
    let rays = rays(&s, 24);
    for offsets in [&REST[..], &MOVED[..]] {
        b.refit(offsets).unwrap();
        let mut w = Walk::default();
        let mut hits = 0;
        for r in &rays {
            let got = b.trace(r, offsets, &mut w);
            let want = b.brute(r, offsets);
            assert_eq!(got.t.to_bits(), want.t.to_bits(), "{r:?}");
            assert_eq!(got.tri >= 0, want.tri >= 0, "{r:?}");
            hits += (got.tri >= 0) as u32;
        }
        assert!(hits as usize > rays.len() * 9 / 10, "the room encloses the rays: {hits} hits");
        // the search goes on past the first leaf hit: more leaves than rays
        assert!(w.leaves > w.rays && w.pops > 0, "{w:?}");
    }
    // the translation matters: some ray's hit moves with the tall box
    let mut w = Walk::default();
    b.refit(&REST).unwrap();
    let rest: Vec<_> = rays.iter().map(|r| b.trace(r, &REST, &mut w)).collect();
    b.refit(&MOVED).unwrap();
    let moved: Vec<_> = rays.iter().map(|r| b.trace(r, &MOVED, &mut w)).collect();
    assert!(rest.iter().zip(&moved).any(|(a, b)| !a.same(b)));
}

#[test]
fn the_emulated_traversal_equals_the_native_one_and_moves_4_bytes_a_stack_entry() {
    let s = scene();
    let mut b = build(&s);
    let rays = rays(&s, 8);
    let mut dev = Device::new();
    let module = bvh::load(&mut dev).unwrap();
    for offsets in [&REST[..], &MOVED[..]] {
        b.refit(offsets).unwrap();
        let mut walk = Walk::default();
        let native: Vec<_> = rays.iter().map(|r| b.trace(r, offsets, &mut walk)).collect();
        let t = bvh::trace_kernel(&mut dev, &module, &b, offsets, &rays).unwrap();
        for (i, (a, e)) in native.iter().zip(&t.hits).enumerate() {
            assert!(a.same(e), "ray {i}: native {a:?} emulated {e:?}");
        }
        assert_eq!(t.walk, Walk { leaves: 0, ..walk });
        assert_eq!(walk.rays, rays.len() as u64);
        // the stack lives in local memory: 4-byte entries, one store a push, one load a pop
        assert_eq!(t.stack_bytes, (bvh::STACK_ENTRY_BYTES * walk.pushes, bvh::STACK_ENTRY_BYTES * walk.pops));
        assert!(walk.pushes > 0 && walk.pops > 0);
    }
    // the node is fetched as two 16-byte loads: the tagged line holds one ld.global.v4.u32
    let ptx = bvh::PTX;
    assert!(ptx.contains("ld.global.v4.u32"), "the node's 16-byte loads");
}

#[test]
fn the_emulated_refit_with_atomics_equals_the_serial_refit_with_two_arrivals_per_inner_node() {
    let s = scene();
    let b = build(&s);
    let mut dev = Device::new();
    let module = bvh::load(&mut dev).unwrap();
    // at rest the refit reproduces the build's boxes
    let r = bvh::refit_kernel(&mut dev, &module, &b, &REST).unwrap();
    assert_eq!(r.nodes, b.nodes);
    // moved: the serial refit's boxes, bit for bit
    let mut moved = b.clone();
    moved.refit(&MOVED).unwrap();
    assert_ne!(moved.nodes, b.nodes);
    let r = bvh::refit_kernel(&mut dev, &module, &b, &MOVED).unwrap();
    assert_eq!(r.nodes, moved.nodes);
    // one arrival per child: every node but the root arrives at its parent once
    assert_eq!(r.arrivals, 2 * b.inner() as u64);
    // a wrong translation count is refused with the triangle named
    let e = bvh::refit_kernel(&mut dev, &module, &b, &REST[..1]).unwrap_err();
    assert!(e.to_string().contains("belongs to object 1"), "{e}");
}

/// Object ids number the objects densely from 0: a sparse id (`u32::MAX`,
/// which would ask for 2^32 translations) is a typed error naming the
/// triangle, not an abort.
#[test]
fn a_sparse_object_id_is_refused() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let e = Bvh::build(&[tri, tri], &[0, u32::MAX]).unwrap_err();
    assert!(matches!(e, bvh::BvhError::SparseObject { triangle: 1, object: u32::MAX, triangles: 2 }), "{e}");
    assert!(e.to_string().contains("triangle 1 belongs to object 4294967295"), "{e}");
    Bvh::build(&[tri, tri], &[1, 0]).unwrap();
}
