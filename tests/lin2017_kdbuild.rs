//! Thesis 003's GPU full-SAH kd-tree construction (§6.5, 003:L548-587):
//! the kernels of `kernels/lin2017/kdbuild.cu` on the emulator build the
//! same tree as their serial twin (`host::path::gpu_build::twin`), node for
//! node and reference for reference, in both forms (one axis per node as
//! the thesis describes it, and all three axes), from clang's PTX and from
//! nvcc's. Against the serial CPU construction (`host::path::build`, Wald
//! and Havran's sweep over three axes, no clipping) the statistics are
//! recorded as they are: the thesis' "same tree" claim (003:L578) fails for
//! the one-axis form; the three-axis form parts from the serial tree only
//! where flat triangles lie in a candidate plane (erratum 13;
//! docs/reproduction-lin2017.md). Table 1 and 2's committed quick run keeps
//! its recorded verdicts and counts.

use warplight::host::kdtree::{KdTree, TreeStats};
use warplight::host::path::build;
use warplight::host::path::gpu_build::{self, GpuParams};
use warplight::host::scene_file;
use warplight::repro::baseline::Baseline;
use warplight::repro::lin2017::table_2;
use warplight::repro::registry::{Workspace, resolve};
use warplight::repro::results::Results;
use warplight::sim::Fidelity;

fn triangles(name: &str) -> Vec<[glam::Vec3; 3]> {
    let s = scene_file::load(&scene_file::resolve(name)).unwrap_or_else(|e| panic!("scenes/{name}.toml: {e}"));
    s.triangles.iter().map(|t| t.v).collect()
}

fn emulated(tris: &[[glam::Vec3; 3]], p: &GpuParams) -> gpu_build::GpuBuild {
    let (mut dev, m) = gpu_build::device(Fidelity::Functional).expect("load PTX");
    gpu_build::build(&mut dev, &m, tris, p).expect("build")
}

fn summary(t: &KdTree, p: &GpuParams) -> (TreeStats, f64) {
    (t.stats(), gpu_build::sah_cost(t, p.k_t as f64, p.k_i as f64))
}

#[test]
fn the_emulated_build_is_its_twin_node_for_node() {
    for name in ["cornell-lambert", "suzanne"] {
        let tris = triangles(name);
        for all_axes in [false, true] {
            let p = GpuParams { all_axes, ..GpuParams::thesis(tris.len()) };
            let g = emulated(&tris, &p);
            let t = gpu_build::twin(&tris, &p).expect("twin");
            assert_eq!(g.tree.nodes, t.nodes, "{name} all_axes {all_axes}");
            assert_eq!(g.tree.tri_refs, t.tri_refs, "{name} all_axes {all_axes}");
            assert_eq!(g.tree.depth, t.depth, "{name} all_axes {all_axes}");
            assert_eq!(g.levels.len() as u32, t.depth + 1);
        }
    }
}

/// (inner nodes, leaves, references, depth, SAH cost) of a tree.
fn stats(t: &KdTree, p: &GpuParams) -> (u64, u64, u64, u32, f64) {
    let (s, sah) = summary(t, p);
    (s.inner_nodes, s.leaves, s.tri_refs, s.depth, (sah * 100.0).round() / 100.0)
}

#[test]
fn the_serial_build_is_not_the_one_axis_tree_and_almost_the_three_axis_one() {
    // recorded (docs/reproduction-lin2017.md, Table 2): the thesis' one-axis
    // form builds smaller trees of higher SAH cost than the serial sweep over
    // three axes; the three-axis form differs from it only where flat
    // triangles lie in a plane (counted on one side here, on both there)
    let cases = [
        ("cornell-lambert", (18, 19, 119, 6, 457.47), (20, 21, 109, 8, 396.99), (19, 20, 107, 8, 396.29)),
        ("suzanne", (1248, 1249, 4156, 18, 645.85), (1567, 1568, 4504, 19, 601.97), (1563, 1564, 4490, 19, 601.92)),
    ];
    for (name, one, three, serial) in cases {
        let tris = triangles(name);
        let p = GpuParams::thesis(tris.len());
        let p3 = GpuParams { all_axes: true, ..p };
        assert_eq!(stats(&gpu_build::twin(&tris, &p).expect("twin"), &p), one, "{name} one axis");
        assert_eq!(stats(&gpu_build::twin(&tris, &p3).expect("twin"), &p), three, "{name} three axes");
        assert_eq!(stats(&build::build(&tris, &p.serial()), &p), serial, "{name} serial");
    }
}

/// The first node (depth first, lower child first) where two trees part:
/// its depth, and the two nodes there (a leaf's references compared as a set).
fn first_difference(a: &KdTree, b: &KdTree) -> Option<(u32, String, String)> {
    use warplight::host::kdtree::Node;
    let mut todo = vec![(0usize, 0usize, 0u32)];
    while let Some((i, j, d)) = todo.pop() {
        match (a.nodes[i], b.nodes[j]) {
            (Node::Inner { axis, split, left, right }, Node::Inner { axis: x2, split: s2, left: l2, right: r2 })
                if axis == x2 && split == s2 =>
            {
                todo.push((right as usize, r2 as usize, d + 1));
                todo.push((left as usize, l2 as usize, d + 1));
            }
            (Node::Leaf { first, count }, Node::Leaf { first: f2, count: c2 })
                if sorted(&a.tri_refs[first as usize..(first + count) as usize])
                    == sorted(&b.tri_refs[f2 as usize..(f2 + c2) as usize]) => {}
            (x, y) => {
                let refs = |t: &KdTree, n: Node| match n {
                    Node::Leaf { first, count } => {
                        format!("{:?}", &t.tri_refs[first as usize..(first + count) as usize])
                    }
                    _ => String::new(),
                };
                return Some((d, format!("{x:?} {}", refs(a, x)), format!("{y:?} {}", refs(b, y))));
            }
        }
    }
    None
}

fn sorted(refs: &[u32]) -> Vec<u32> {
    let mut v = refs.to_vec();
    v.sort_unstable();
    v
}

/// Table 2's bunny check compares four statistics; the trees themselves:
/// the kernels' three-axis twin builds the serial tree node for node (split
/// axes and positions, leaf sets) on the bunny (review 7, finding 7).
#[test]
fn the_three_axis_twin_is_the_serial_tree_on_the_bunny() {
    let tris = triangles("stanford-bunny");
    let p = GpuParams { all_axes: true, ..GpuParams::thesis(tris.len()) };
    let t = gpu_build::twin(&tris, &p).expect("twin");
    let serial = build::build(&tris, &p.serial());
    assert_eq!(first_difference(&t, &serial), None);
    assert_eq!(t.stats().inner_nodes, 224_763);
}

#[test]
fn where_the_three_axis_form_parts_from_the_serial_build() {
    for name in ["cornell-lambert", "suzanne"] {
        let tris = triangles(name);
        let p = GpuParams { all_axes: true, ..GpuParams::thesis(tris.len()) };
        let t = gpu_build::twin(&tris, &p).expect("twin");
        let serial = build::build(&tris, &p.serial());
        let (depth, ours, theirs) = first_difference(&t, &serial).expect("the trees differ");
        eprintln!("{name}: depth {depth}: {ours} / {theirs}");
        // Cornell: a plane through the top of the short box (flat quads) is
        // cheaper when they count on one side; Suzanne: triangles 254 and 255
        // lie flat in z = 4.838267, where the three-axis form splits a node
        // the serial build keeps as a leaf
        let expected = if name == "suzanne" {
            (12, "Inner { axis: 2, split: 4.838267")
        } else {
            (3, "Inner { axis: 1, split: 0.6")
        };
        assert_eq!(depth, expected.0, "{name}");
        assert!(ours.starts_with(expected.1), "{name}: {ours}");
    }
}

#[test]
#[ignore = "minutes: the bunny's build on the emulator at fidelity memory"]
fn bunny_timing() {
    let tris = triangles("stanford-bunny");
    let p = GpuParams::thesis(tris.len());
    let t0 = std::time::Instant::now();
    let (mut dev, m) = gpu_build::device(Fidelity::Memory).expect("load PTX");
    let g = gpu_build::build(&mut dev, &m, &tris, &p).expect("build");
    eprintln!("bunny: {:.1} s, {:?}, {:?}", t0.elapsed().as_secs_f64(), g.tree.stats(), g.total());
}

fn root() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The committed quick run's raw results (`warplight tables lin:1 lin:2 --out`).
const QUICK: &str = "docs/results/lin-quick.json";
/// Its verdicts (`--write-baseline`).
const QUICK_BASELINE: &str = "docs/results/lin-quick.baseline.json";

#[test]
fn the_committed_run_renders_the_recorded_verdicts() {
    // every compared cell and check of lin:1 and lin:2 gives the verdict the
    // baseline records, either way (a verdict that moves fails until the
    // baseline is re-recorded: warplight tables lin:1 lin:2 --protocol quick
    // --out docs/results/lin-quick.json --write-baseline docs/results/lin-quick.baseline.json)
    let r = Results::read(&root().join(QUICK)).expect("committed results");
    let mut tables = Vec::new();
    for e in resolve(&["lin:1".into(), "lin:2".into()]).expect("registered") {
        tables.extend((e.table.render.expect("rendered"))(&e, &r));
    }
    let scenes: Vec<String> = r.scenes.iter().map(|s| s.name.clone()).collect();
    let now = Baseline::record(&r.protocol.describe(), &scenes, &tables);
    let base: Baseline =
        serde_json::from_str(&std::fs::read_to_string(root().join(QUICK_BASELINE)).expect("baseline")).expect("json");
    assert_eq!(now, base);
    // lin:2: only the bunny's three-axis check; the face counts (inputs) are not compared
    let lin2 = &base.tables["lin:2"];
    assert_eq!(lin2.values().filter(|v| *v == "within").count(), 1, "{lin2:?}");
    assert!(!lin2.keys().any(|k| k.contains("Face Count")), "{lin2:?}");
    // lin:1: the two checks; the modelled speedups (+12.6 %, +11.0 %) are not
    // the printed 7.3 % and 9.1 % within half their printed precision
    // (review 7, finding 3: the factor tolerance called them within)
    let lin1 = &base.tables["lin:1"];
    assert_eq!(lin1.values().filter(|v| *v == "within").count(), 2, "{lin1:?}");
    for row in ["Suzzane (suzanne) / Speedup", "Stanford Bunny (stanford-bunny) / Speedup"] {
        assert_eq!(lin1[row], "outside", "{row}");
    }
    // the tolerance cannot pass no speedup at all, nor the model's
    use warplight::repro::compare::Verdict;
    use warplight::repro::lin2017::table_1::SPEEDUP_TOLERANCE;
    for (ours, thesis, v) in [(0.0, 7.3, Verdict::Outside), (12.6, 7.3, Verdict::Outside), (7.34, 7.3, Verdict::Within)]
    {
        assert_eq!(SPEEDUP_TOLERANCE.verdict(ours, thesis), v, "{ours} vs {thesis}");
    }
}

#[test]
fn a_fresh_build_counts_what_the_committed_run_recorded() {
    // the GPU build is deterministic: launches, instructions, bytes and tree
    // statistics of Cornell and Suzanne equal the committed quick run's
    let r = Results::read(&root().join(QUICK)).expect("committed results");
    for name in ["cornell-lambert", "suzanne"] {
        let scene = scene_file::load(&scene_file::resolve(name)).expect("scene");
        let mut ws = Workspace::new(&scene, 0..1, 32);
        let fresh = table_2::measure(&mut ws, &mut |_| {}).expect("measure");
        assert!(fresh.len() > 3, "{name}");
        for s in fresh {
            let old = r.samples.iter().find(|o| o.group == s.group && o.scene == s.scene && o.variant == s.variant);
            let old = old.unwrap_or_else(|| panic!("{name} {}: not in {QUICK}", s.variant));
            for (k, v) in &s.counters {
                // the SAH costs pass through JSON's shortest decimal form
                let was = old.counters.get(k).copied().unwrap_or(f64::NAN);
                if k != "serial_seconds" {
                    assert!((v - was).abs() <= 1e-12 * v.abs(), "{name} {} {k}: {v} vs {was}", s.variant);
                }
            }
        }
    }
}

#[test]
fn nvccs_ptx_builds_the_same_tree() {
    // the second dialect (kernels/lin2017/kdbuild.nvcc.ptx) on the emulator
    let tris = triangles("suzanne");
    let p = GpuParams::thesis(tris.len());
    let (mut dev, _) = gpu_build::device(Fidelity::Functional).expect("load PTX");
    let text = std::fs::read_to_string(root().join("kernels/lin2017/kdbuild.nvcc.ptx")).expect("nvcc PTX");
    let m = dev.load_ptx(&text, "kernels/lin2017/kdbuild.nvcc.ptx").expect("load nvcc PTX");
    let g = gpu_build::build(&mut dev, &m, &tris, &p).expect("build");
    let t = gpu_build::twin(&tris, &p).expect("twin");
    assert_eq!((g.tree.nodes, g.tree.tri_refs), (t.nodes, t.tri_refs));
}
