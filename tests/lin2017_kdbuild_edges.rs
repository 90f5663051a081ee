//! The GPU kd-tree build's limits (review 7, findings 2 and 8): the depth
//! limit and the forced split above 63 triangles are taken by the emulated
//! kernels exactly as by their serial twin (`gpu_build::twin`), node for
//! node; and a level the kernels cannot index in 32 bits is refused with a
//! typed error. `tests/lin2017_kdbuild.rs` compares the twin on the
//! fixtures' scenes, which reach neither branch (Cornell stops at depth 6 of
//! 14, Suzanne at 18 of 20, and no node is split by force).

use glam::Vec3;
use warplight::host::kdtree::{KdTree, Node};
use warplight::host::path::gpu_build::{self, GpuBuildError, GpuParams, MAX_LEVEL_REFS};
use warplight::host::scene_file;
use warplight::sim::Fidelity;

fn triangles(name: &str) -> Vec<[Vec3; 3]> {
    let s = scene_file::load(&scene_file::resolve(name)).unwrap_or_else(|e| panic!("scenes/{name}.toml: {e}"));
    s.triangles.iter().map(|t| t.v).collect()
}

/// The emulated build equals the twin node for node; returns the twin.
fn emulated_is_twin(what: &str, tris: &[[Vec3; 3]], p: &GpuParams) -> KdTree {
    let (mut dev, m) = gpu_build::device(Fidelity::Functional).expect("load PTX");
    let g = gpu_build::build(&mut dev, &m, tris, p).expect("build");
    let t = gpu_build::twin(tris, p).expect("twin");
    assert_eq!(g.tree.nodes, t.nodes, "{what}");
    assert_eq!(g.tree.tri_refs, t.tri_refs, "{what}");
    assert_eq!(g.tree.depth, t.depth, "{what}");
    t
}

#[test]
fn the_depth_limit_is_the_twins() {
    // kd_sah's and kd_decide's depth tests: with `>=` made `>` (and `<`
    // made `<=`) the kernels build a level deeper than the twin
    for name in ["cornell-lambert", "suzanne"] {
        let tris = triangles(name);
        for all_axes in [false, true] {
            let p = GpuParams { all_axes, max_depth: 4, ..GpuParams::thesis(tris.len()) };
            let t = emulated_is_twin(&format!("{name} all_axes {all_axes}"), &tris, &p);
            assert_eq!(t.depth, 4, "{name}: the limit is reached");
        }
    }
}

/// 70 long slivers along x, overlapping: triangle i spans x from a to 10 - a
/// (a = i / 700 < 0.1), y from 0 to 1 and z from 0 to 0.5 + i / 1000. No
/// plane makes the SAH split (hand-derived, box area A = 2 (10 + 0.569 +
/// 5.69)): on y there is no candidate inside the box; on x every plane
/// keeps all 70 on one side whose area is at least (1 - 0.0965 p) A, so the
/// cost is at least 15 + 20 * 70 (1 - 0.0965 * 0.1) > 1413 (and 15 + 20 * 70
/// in the middle, where all 70 are on both sides); on z the left side holds
/// all 70 in at least 0.95 A; K_I n = 1400. So the SAH alone makes a leaf.
fn slivers() -> Vec<[Vec3; 3]> {
    (0..70)
        .map(|i| {
            let a = i as f32 / 700.0;
            [Vec3::new(a, 0.0, 0.0), Vec3::new(10.0 - a, 0.0, 0.0), Vec3::new(5.0, 1.0, 0.5 + i as f32 / 1000.0)]
        })
        .collect()
}

#[test]
fn the_forced_split_above_63_triangles_is_the_twins() {
    let tris = slivers();
    for all_axes in [false, true] {
        let p = GpuParams { all_axes, max_depth: 3, ..GpuParams::thesis(tris.len()) };
        // without the forced split (leaves of any size) the SAH keeps one leaf
        let sah_only = gpu_build::twin(&tris, &GpuParams { max_leaf: 70, ..p }).expect("twin");
        assert_eq!(sah_only.nodes.len(), 1, "all_axes {all_axes}: {:?}", sah_only.nodes);
        // with it, the root and its children are split down to the depth limit
        // (kd_decide's `|| n > max_leaf` removed: one leaf, not the twin)
        let t = emulated_is_twin(&format!("slivers all_axes {all_axes}"), &tris, &p);
        assert!(matches!(t.nodes[0], Node::Inner { .. }), "all_axes {all_axes}: {:?}", t.nodes[0]);
        assert_eq!(t.depth, 3, "all_axes {all_axes}");
    }
}

#[test]
fn a_level_the_kernels_cannot_index_is_refused() {
    // 12 t < 2^32 (kd_event_flags / kd_event_scatter index 6 x 2 t entries in
    // u32) and 2 t < 2^30 (a node's event in the best key's 30 bits)
    assert_eq!(MAX_LEVEL_REFS, 357_913_941);
    const {
        assert!(12 * MAX_LEVEL_REFS as u64 <= u32::MAX as u64 && 12 * (MAX_LEVEL_REFS as u64 + 1) > u32::MAX as u64);
        assert!(2 * MAX_LEVEL_REFS < 1 << 30);
    };
    assert!(gpu_build::check_level(19, MAX_LEVEL_REFS).is_ok());
    let e = gpu_build::check_level(19, MAX_LEVEL_REFS + 1).unwrap_err();
    assert!(matches!(e, GpuBuildError::TooManyRefs { depth: 19, refs } if refs == MAX_LEVEL_REFS + 1), "{e:?}");
    assert!(e.to_string().contains("level 19") && e.to_string().contains("357913941"), "{e}");
}
