//! Thesis 003's kd-tree traversals (Fig. 3): the 8-byte short stack,
//! kd-restart and kd-backtrack in `kernels/lin2017/path.cu` on trees of
//! thesis 003's constructions (`host::path::build`). Emulated and native
//! frames agree bit for bit for every traversal; the counts the emulator
//! reads off the kernel's `@count` lines equal the native mirror's, event for
//! event; the stackless traversals visit the same leaves; all three find
//! the same hits.

use warplight::host::camera::Camera;
use warplight::host::path::build::{self, Construction};
use warplight::host::path::counts::{self, Counts};
use warplight::host::path::layout::PathScene;
use warplight::host::path::{
    FrameParams, Integrator, PixelSampling, Progressive, Termination, Traversal, kernel, render_native,
};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::sim::{Device, Fidelity};

fn scene(name: &str) -> Scene {
    scene_file::load(&scene_file::resolve(name)).unwrap_or_else(|e| panic!("scenes/{name}.toml: {e}"))
}

fn layout(scene: &Scene, c: Construction) -> PathScene {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build::build(&tris, &build::Params::fig3(c, tris.len()));
    PathScene::new(scene, &tree).expect("layout")
}

fn params(w: u32, h: u32, traversal: Traversal) -> FrameParams {
    FrameParams {
        width: w,
        height: h,
        integrator: Integrator::Nee,
        max_bounces: 16,
        seed: 5,
        traversal,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    }
}

fn emulate(ps: &PathScene, cam: &Camera, p: FrameParams) -> (Progressive, Counts) {
    let mut cfg = kernel::sim_config(&p);
    cfg.fidelity = Fidelity::Instructions;
    let mut dev = Device::with_config(cfg);
    let module = kernel::load(&mut dev).expect("load PTX");
    let r = kernel::render(&mut dev, &module, ps, cam, p, 1, false, |_| {}).expect("launch");
    (r.image, r.counts.expect("counted at fidelity instructions"))
}

#[test]
fn every_tag_names_an_instruction_of_its_line() {
    let tags = counts::tags();
    let names: Vec<&str> = tags.iter().map(|t| t.name.as_str()).collect();
    for n in ["rays", "inner", "leaves", "tri_tests", "push", "pop", "ascents"] {
        assert!(names.contains(&n), "no @count tag {n}");
    }
    // each tag's opcode appears in the PTX on its line (a recompile that
    // moved or renamed the instruction would silently count nothing)
    let ptx = kernel::PTX;
    for t in &tags {
        let mut on_line = false;
        let mut found = false;
        for l in ptx.lines().map(str::trim) {
            if let Some(loc) = l.strip_prefix(".loc") {
                let w: Vec<&str> = loc.split_whitespace().collect();
                on_line = w.len() >= 2 && w[0] == "1" && w[1] == t.line.to_string();
            } else if on_line && l.split_whitespace().next() == Some(t.opcode.as_str()) {
                found = true;
            }
        }
        assert!(found, "@count {} {}: no such instruction on line {}", t.name, t.opcode, t.line);
    }
}

#[test]
fn emulated_traversals_equal_native_bit_for_bit_and_count_for_count() {
    let s = scene("cornell-lambert");
    let cam = Camera { resolution: [8, 6], ..s.camera };
    for c in Construction::ALL {
        let ps = layout(&s, c);
        for t in Traversal::ALL {
            let p = params(8, 6, t);
            let native = render_native(&ps, &cam, p, 1, false, |_| {}).expect("render");
            let (emu, counted) = emulate(&ps, &cam, p);
            let diff = native.accum.iter().zip(&emu.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
            assert_eq!(diff, 0, "{c:?} {t:?}: {diff} values differ");
            assert_eq!(counted, native.counts, "{c:?} {t:?}: emulator's tagged counts vs native");
            assert!(native.accum.iter().sum::<f32>() > 0.0, "{c:?} {t:?}: black");
            let k = native.counts;
            assert!(k.rays > 0 && k.inner > 0 && k.leaves > 0 && k.tri_tests > 0, "{c:?} {t:?}: {k:?}");
            match t {
                Traversal::ShortStack => assert!(k.pushes > 0 && k.ascents == 0, "{k:?}"),
                Traversal::Restart => assert!(k.pushes == 0 && k.pops == 0 && k.ascents == 0, "{k:?}"),
                Traversal::Backtrack => assert!(k.pushes == 0 && k.ascents > 0, "{k:?}"),
                Traversal::FullStack => unreachable!("not a row of Fig. 3"),
            }
        }
    }
}

#[test]
fn stackless_traversals_visit_the_same_leaves_and_every_traversal_finds_the_same_hits() {
    // the bunny&ball of Fig. 3 (70,735 triangles), both trees, natively
    let s = scene("bunny-ball");
    let (w, h) = (24, 24);
    let cam = Camera { resolution: [w, h], ..s.camera };
    for c in Construction::ALL {
        let ps = layout(&s, c);
        let runs: Vec<(Traversal, Progressive)> = Traversal::ALL
            .iter()
            .map(|&t| (t, render_native(&ps, &cam, params(w, h, t), 1, false, |_| {}).expect("render")))
            .collect();
        let (restart, backtrack) = (&runs[1].1.counts, &runs[2].1.counts);
        // the same leaves in the same order: the same leaf visits and triangle tests
        assert_eq!((restart.leaves, restart.tri_tests), (backtrack.leaves, backtrack.tri_tests), "{c:?}");
        // kd-backtrack resumes below the root: fewer inner-node steps
        assert!(backtrack.inner < restart.inner, "{c:?}: {backtrack:?} vs {restart:?}");
        // the short stack re-descends nothing: fewest inner steps
        assert!(runs[0].1.counts.inner < backtrack.inner, "{c:?}");
        // the same hits, hence the same image, with all three
        for (t, r) in &runs[1..] {
            let diff = r.accum.iter().zip(&runs[0].1.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
            assert_eq!(diff, 0, "{c:?} {t:?}: {diff} values differ from the short stack's");
        }
        assert_eq!(runs[0].1.counts.rays, restart.rays, "{c:?}: the same rays traced");
    }
}

/// One frame of `p` on the emulator with the Maxwell memory model watching:
/// the accumulation buffer, the tagged counts and the local-memory bytes
/// (stored, loaded).
fn emulate_local(ps: &PathScene, cam: &Camera, p: FrameParams) -> (Vec<f32>, Counts, (u64, u64)) {
    use warplight::model::{Model, Profile};
    use warplight::sim::{Arg, LaunchConfig};
    // the default fidelity: the memory model sees the accesses
    let mut dev = Device::with_config(kernel::sim_config(&p));
    let module = kernel::load(&mut dev).expect("load PTX");
    let bufs = kernel::upload_scene(&mut dev, ps, cam, &p).expect("upload");
    let n = p.paths() * 3;
    let accum = dev.alloc_zeroed::<f32>(n);
    let last = dev.alloc_zeroed::<f32>(n);
    let args: Vec<Arg> = bufs.scene_args().into_iter().chain([accum, last]).map(Arg::Ptr).collect();
    let model = Model::new(Profile::Maxwell, &module.prog);
    let ctas = p.paths().div_ceil(kernel::THREADS as usize) as u32;
    let st = dev
        .launch_observed(&module, kernel::KERNEL, LaunchConfig::linear(ctas, kernel::THREADS), &args, Some(&model))
        .expect("launch");
    let c = Counts::from_tags(&counts::tagged(&module.prog, &st.profile, &counts::tags()));
    let m = model.finish().counters;
    (dev.read::<f32>(accum, n), c, (m.local_st.bytes, m.local_ld.bytes))
}

#[test]
fn the_short_stacks_entries_move_8_bytes_and_the_standard_stacks_12() {
    // 003:L175: a standard entry {node, tnear, tfar} is 12 bytes; Santos et
    // al. derive tnear on a pop, so an entry is {node, tfar}, 8 bytes. Both
    // stacks trace the same paths; kd-restart (no stack) stores only the rest
    // of the kernel's local bytes (the arguments it passes through local
    // memory), so the stacks' stored bytes are exact differences.
    let s = scene("cornell-lambert");
    let cam = Camera { resolution: [8, 6], ..s.camera };
    let ps = layout(&s, Construction::Sah);
    let (base_img, _, base) = emulate_local(&ps, &cam, params(8, 6, Traversal::Restart));
    let (short_img, short, short_bytes) = emulate_local(&ps, &cam, params(8, 6, Traversal::ShortStack));
    let (full_img, full, full_bytes) = emulate_local(&ps, &cam, params(8, 6, Traversal::FullStack));
    assert!(short.pushes > 0 && short.pops > 0);
    assert_eq!(full, short, "the same walk");
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    assert!(same(&short_img, &full_img) && same(&short_img, &base_img), "the same image");
    // a push stores the whole entry
    assert_eq!(short_bytes.0, base.0 + 8 * short.pushes, "8-byte entries");
    assert_eq!(full_bytes.0, base.0 + 12 * full.pushes, "12-byte entries");
    // (a pop's loads are not compared: kd-restart's own local loads differ
    // from the stacks' non-stack loads, so they are no baseline)
    // natively too: the same image and walk
    let native = render_native(&ps, &cam, params(8, 6, Traversal::FullStack), 1, false, |_| {}).expect("render");
    assert!(same(&native.accum, &full_img));
    assert_eq!(native.counts, full);
    assert_eq!(Traversal::parse("stack12"), Some(Traversal::FullStack));
}
