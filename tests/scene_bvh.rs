//! The scene BVH of thesis 000 Table 6.5: the SAH build holds every triangle
//! once; both layouts ([AL09]'s complete pairs, B, and the compact pairs with
//! Algorithm 6.1, C) find the closest hit brute force finds (any hit for
//! shadow rays); the emulated traversals equal the native ones bit for bit,
//! through the same counted steps; and the emulator's memory counters obey
//! the byte model exactly: B 28 bytes a node access and 4 a stack push or
//! pop, C 16 and 12.

use std::path::Path;

use glam::Vec3;
use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::raycast::Caster;
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::repro::fabianowski2011::pm_layout::{Layout, PmKind};
use warplight::repro::fabianowski2011::scene_bvh::{self, Best, SceneBvh, TraceRay};
use warplight::sim::Device;

fn scene(name: &str) -> Scene {
    scene_file::load(Path::new(&format!("scenes/{name}.toml"))).unwrap()
}

fn rays(s: &Scene, side: u32) -> Vec<TraceRay> {
    let tris: Vec<[Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam: Camera = s.camera;
    cam.resolution = [side, side];
    scene_bvh::frame_rays(&Caster::new(s, &tree), &cam, scene_bvh::Rays::WithReflections).rays
}

/// The closest hit over all triangles (Alg. 3.3 as the kernels run it), or
/// whether any triangle is hit for a shadow ray.
fn brute(b: &SceneBvh, r: &TraceRay) -> Option<(f32, u32)> {
    let mut best: Option<(f32, u32)> = None;
    for w in &b.tris {
        let k = w[0] as usize;
        let (a, c) = ((k + 1) % 3, (k + 2) % 3);
        let f = |i: usize| f32::from_bits(w[i]);
        let (o, d) = (r.origin, r.dir);
        let t = (f(3) - o[k] - f(1) * o[a] - f(2) * o[c]) / (d[k] + f(1) * d[a] + f(2) * d[c]);
        let bound = best.map_or(r.t_max, |x| x.0);
        if !(t >= r.t_min && t <= bound) {
            continue;
        }
        let (hx, hy) = (o[a] + t * d[a], o[c] + t * d[c]);
        let u = f(7) * hx + f(8) * hy + f(9);
        let v = f(4) * hx + f(5) * hy + f(6);
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            continue;
        }
        if best.is_none_or(|x| t < x.0) {
            best = Some((t, w[10]));
        }
    }
    best
}

#[test]
fn the_sah_build_holds_every_triangle_once_in_leaves_of_at_most_five_where_splitting_pays() {
    let s = scene("cornell-box");
    let b = SceneBvh::build(&s);
    let mut seen: Vec<u32> = b.tris.iter().map(|w| w[10]).collect();
    seen.sort();
    assert_eq!(seen, (0..s.triangles.len() as u32).collect::<Vec<_>>());
    // the end flags close every leaf; B and C have one pair per inner node
    let leaves = b.tree.nodes.iter().filter(|n| matches!(n.kind, PmKind::Leaf { .. })).count();
    assert_eq!(b.tris.iter().filter(|w| w[11] != 0).count(), leaves);
    assert_eq!(b.complete.len(), b.tree.nodes.len() - leaves);
    assert_eq!(b.compact.len(), b.complete.len());
    // each inner node's box is the union of its children's
    for n in &b.tree.nodes {
        if let PmKind::Inner([l, r]) = n.kind {
            let (l, r) = (&b.tree.nodes[l as usize], &b.tree.nodes[r as usize]);
            for c in 0..3 {
                assert_eq!(n.lo[c], l.lo[c].min(r.lo[c]));
                assert_eq!(n.hi[c], l.hi[c].max(r.hi[c]));
            }
        }
    }
}

#[test]
fn both_layouts_find_the_brute_force_hit_and_c_skips_only_entries_beyond_the_hit() {
    let s = scene("cornell-box");
    let b = SceneBvh::build(&s);
    let rays = rays(&s, 24);
    assert!(rays.iter().any(|r| r.any) && rays.iter().any(|r| !r.any));
    let (hb, wb) = scene_bvh::trace_all(&b, Layout::Complete, &rays);
    let (hc, wc) = scene_bvh::trace_all(&b, Layout::Compact, &rays);
    for ((r, x), y) in rays.iter().zip(&hb).zip(&hc) {
        let want = brute(&b, r);
        for h in [x, y] {
            if r.any {
                assert_eq!(h.tri != u32::MAX, want.is_some(), "{r:?}");
            } else {
                assert_eq!(want.map(|w| w.0), (h.tri != u32::MAX).then_some(h.t), "{r:?}");
            }
        }
    }
    // both visit the same pairs but for C's skipped pops (t_a > t_max): C never visits more
    assert!(wc.nodes <= wb.nodes && wc.nodes > 0, "B {wb:?} C {wc:?}");
    assert!(wc.pushes <= wb.pushes, "B {wb:?} C {wc:?}");
}

#[test]
fn the_emulated_traversals_equal_the_native_ones_and_the_byte_model_holds_on_the_emulators_counters() {
    let s = scene("cornell-box");
    let b = SceneBvh::build(&s);
    let rays = rays(&s, 16);
    let mut dev = Device::new();
    let module = scene_bvh::load(&mut dev).unwrap();
    for layout in [Layout::Complete, Layout::Compact] {
        let (native, walk) = scene_bvh::trace_all(&b, layout, &rays);
        let t = scene_bvh::trace_kernel(&mut dev, &module, &b, layout, &rays).unwrap();
        assert!(native.iter().zip(&t.hits).all(|(a, b): (&Best, &Best)| a.same(b)), "{layout:?}");
        assert_eq!(t.walk, walk, "{layout:?}");
        let (nodes, stack) = scene_bvh::model_bytes(layout, &walk);
        assert_eq!((t.traffic.nodes, t.traffic.stack), (nodes, stack), "{layout:?} {walk:?}");
        assert!(walk.pushes > 0 && walk.pops > 0);
    }
}

/// Table 6.5 (a)'s baseline: closest-hit rays stack t_a with the pair (8
/// bytes) and skip entries beyond the hit, shadow rays stack the pair (4
/// bytes); the emulated kernel equals the native traversal, finds the
/// brute-force hits, and its local bytes are 4 per push or pop plus 4 per
/// t_a word, the t_a words being the closest-hit rays' pushes and pops.
#[test]
fn part_a_baseline_stacks_t_a_for_primary_rays_only_and_its_bytes_follow() {
    use scene_bvh::Traversal;
    let s = scene("cornell-box");
    let b = SceneBvh::build(&s);
    let tris: Vec<[Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam: Camera = s.camera;
    cam.resolution = [16, 16];
    let fr = scene_bvh::frame_rays(&Caster::new(&s, &tree), &cam, scene_bvh::Rays::PrimaryShadow);
    // one primary ray a pixel, at most one shadow ray (one point light), no reflection rays
    assert_eq!(fr.stats.primary, 256);
    assert_eq!(fr.stats.reflection, 0);
    assert!(fr.stats.shadow > 0 && fr.stats.shadow <= 256);
    assert_eq!(fr.rays.len() as u64, fr.stats.primary + fr.stats.shadow);
    let mut dev = Device::new();
    let module = scene_bvh::load(&mut dev).unwrap();
    let t = scene_bvh::trace_kernel_with(&mut dev, &module, &b, Traversal::CompleteTa, &fr.rays).unwrap();
    let (mut walk, mut ta) = (warplight::repro::fabianowski2011::pm_layout::Walk::default(), 0u64);
    for (r, h) in fr.rays.iter().zip(&t.hits) {
        let (n, w) = scene_bvh::trace_with(&b, Traversal::CompleteTa, r);
        assert!(n.same(h), "{r:?}");
        let want = brute(&b, r);
        if r.any {
            assert_eq!(h.tri != u32::MAX, want.is_some(), "{r:?}");
        } else {
            assert_eq!(want.map(|w| w.0), (h.tri != u32::MAX).then_some(h.t), "{r:?}");
            ta += w.pushes + w.pops;
        }
        walk.add(&w);
    }
    assert_eq!(t.walk, walk);
    assert!(ta > 0 && t.ta_words == ta, "t_a words {} vs closest-hit pushes + pops {ta}", t.ta_words);
    assert_eq!(t.traffic.nodes, 28 * walk.nodes);
    assert_eq!(t.traffic.stack, 4 * (walk.pushes + walk.pops) + 4 * ta);
    // the t_a check skips entries: never more nodes than (b)'s baseline on the same rays
    let b_walk = scene_bvh::trace_all(&b, Layout::Complete, &fr.rays).1;
    assert!(walk.nodes <= b_walk.nodes && walk.pops <= b_walk.pops, "{walk:?} vs {b_walk:?}");
}

/// Table 6.5's frame rates through the GTX 280 timing model on a quick run
/// (Scene 6, one frame at 16 x 16): both parts get finite modelled FPS B and
/// FPS C cells with verdicts; part (b)'s FPS B is the model's prediction on
/// the recorded traversal counters by hand (scaled to 512 x 512, 61
/// registers), and part (b)'s FPS C is negative (the thesis' sign: more
/// instructions for fewer bytes); and a results file without the timing
/// counters gives empty cells and says so.
#[test]
fn table_6_5s_frame_rates_are_modelled_on_the_recorded_counters() {
    use warplight::repro::fabianowski2011::table_6_5::{self, FRAME, REGISTERS_B, SCENE_BVH, SCENE_BVH_A};
    use warplight::repro::protocol::Protocol;
    use warplight::repro::registry::{Workspace, resolve};
    use warplight::repro::results::Results;
    use warplight::timing::{GTX_280, KernelCounts, Launch, LaunchShape, predict};
    let s = scene("scene6");
    let side = 16;
    let mut ws = Workspace::new(&s, 0..1, side);
    let protocol = Protocol { name: "custom".into(), frames: 1, resolution: side };
    let groups = vec![SCENE_BVH.into(), SCENE_BVH_A.into()];
    let mut r = Results::new("test", protocol, vec!["fabianowski:6.5".into()], groups);
    r.samples = table_6_5::measure(&mut ws, &mut |_| {}).unwrap();
    r.samples.extend(table_6_5::measure_a(&mut ws, &mut |_| {}).unwrap());
    let e = resolve(&["fabianowski:6.5".into()]).unwrap().remove(0);
    let render = e.table.render.unwrap();
    let tables = render(&e, &r);
    assert_eq!(tables.len(), 2);
    for t in &tables {
        let col = |n: &str| t.columns.iter().position(|c| c.name == n).unwrap();
        let row = t.rows.iter().find(|x| x.label == "scene6").unwrap();
        for c in [col("FPS B"), col("FPS C")] {
            assert!(row.cells[c].ours.is_some_and(f64::is_finite), "{}: {:?}", t.heading, row.cells[c]);
            assert!(row.cells[c].verdict.is_some());
        }
        assert!(row.cells[col("FPS B")].ours.unwrap() > 0.0);
        let per_cell = |n: &&String| n.starts_with("Per-cell error (ours - thesis): scene6:");
        assert!(t.notes.iter().find(per_cell).is_some_and(|n| n.contains("FPS B ") && n.contains("FPS C ")));
    }
    // by hand: part (b)'s B, the recorded counters scaled to 512 x 512, one persistent launch at 61 registers
    let b = table_6_5::frame_rates(&r, "scene6")[0];
    let counts = KernelCounts::from_counters(|n| r.sum(SCENE_BVH, "scene6", "B", &format!("{FRAME}.{n}")))
        .unwrap()
        .scaled((512.0 / side as f64).powi(2));
    let shape = LaunchShape { ctas: 30, threads_per_cta: 256, registers_per_thread: REGISTERS_B, shared_per_cta: 0 };
    let p = predict(&GTX_280, &Launch { counts, shape }).unwrap();
    assert!((p.fps() / b - 1.0).abs() < 1e-9, "{} against {b}", p.fps());
    let tb = &tables[1];
    let fb = tb.columns.iter().position(|c| c.name == "FPS B").unwrap();
    assert_eq!(tb.rows.iter().find(|x| x.label == "scene6").unwrap().cells[fb].ours, Some(b));
    // (b): C executes more instructions for fewer bytes, and the model makes it slower, as the thesis prints
    let c = |n: &str| {
        tb.rows.iter().find(|x| x.label == "scene6").unwrap().cells
            [tb.columns.iter().position(|c| c.name == n).unwrap()]
        .ours
        .unwrap()
    };
    assert!(c("Instr. C") > 0.0 && c("Bytes C") < 0.0);
    assert!(c("FPS C") < 0.0, "FPS C {:+.2}%", c("FPS C"));
    // without the timing counters: no frame rates, and a note says why
    for x in &mut r.samples {
        x.counters.retain(|k, _| !k.starts_with(&format!("{FRAME}.")));
    }
    for t in render(&e, &r) {
        let row = t.rows.iter().find(|x| x.label == "scene6").unwrap();
        let n = t.columns.len();
        assert!(row.cells[n - 2].ours.is_none() && row.cells[n - 1].ours.is_none());
        assert!(row.cells[n - 2].verdict.is_none() && row.cells[n - 1].verdict.is_none());
        assert!(t.notes.iter().any(|x| x.starts_with("Frame rates not measured for scene6")), "{:?}", t.notes);
        assert!(!t.markdown().contains("NaN"));
    }
}
