//! Thesis 003's thread compaction (§6.3): the flag, scan and scatter kernels
//! of `kernels/lin2017/compact.cu` against a Rust stream compaction; the
//! wavefront form of the path tracer, with and without compaction, traces
//! the megakernel's paths bit for bit; Fig. 16's worked example (25 % of
//! the lanes useful before compaction, 75 % after) counted by the emulator.

use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::path::layout::PathScene;
use warplight::host::path::wavefront::{self, Compactor, Mode, PATH_ACTIVE, STATE_FLOATS};
use warplight::host::path::{FrameParams, Integrator, PixelSampling, Termination, Traversal, kernel};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::repro::lin2017::fig_16;
use warplight::sim::{Device, Fidelity};

fn cornell() -> (Scene, PathScene) {
    let scene = scene_file::load(&scene_file::resolve("cornell-lambert")).expect("scenes/cornell-lambert.toml");
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    let ps = PathScene::new(&scene, &tree).expect("layout");
    (scene, ps)
}

#[test]
fn flag_scan_scatter_is_a_stable_stream_compaction() {
    let mut dev = Device::with_config(Default::default());
    let module = wavefront::load_compact(&mut dev).expect("load compact.ptx");
    // more than 256 CTAs of 256, so the sums' scan carries across its chunks
    for n in [1usize, 255, 256, 1000, 256 * 257 + 5] {
        let mut x = 12345u32;
        let mut states = vec![0f32; n * STATE_FLOATS];
        let mut active = Vec::new();
        for j in 0..n {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let on = x.is_multiple_of(3);
            for k in 0..STATE_FLOATS - 1 {
                states[j * STATE_FLOATS + k] = (j * STATE_FLOATS + k) as f32;
            }
            states[j * STATE_FLOATS + 15] = f32::from_bits(if on { PATH_ACTIVE | 1 } else { 1 });
            if on {
                active.push(j);
            }
        }
        let from = dev.alloc_zeroed::<f32>(states.len());
        let to = dev.alloc_zeroed::<f32>(states.len());
        dev.write(from, &states).expect("write");
        let c = Compactor::new(&mut dev, n);
        let (k, counters) = c.compact(&mut dev, &module, from, to, n as u32).expect("compact");
        assert_eq!(k as usize, active.len(), "n = {n}");
        assert!(counters.warp_instructions > 0);
        let got = dev.read::<f32>(to, n * STATE_FLOATS);
        for (slot, &j) in active.iter().enumerate() {
            let (a, b) = (&got[slot * STATE_FLOATS..][..STATE_FLOATS], &states[j * STATE_FLOATS..][..STATE_FLOATS]);
            assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()), "n = {n}: slot {slot} is not state {j}");
        }
    }
}

#[test]
fn wavefront_with_and_without_compaction_traces_the_megakernels_paths() {
    let (scene, ps) = cornell();
    let (w, h) = (8, 6);
    let cam = Camera { resolution: [w, h], ..scene.camera };
    for integrator in [Integrator::Nee, Integrator::MisPower] {
        let params = FrameParams {
            width: w,
            height: h,
            integrator,
            max_bounces: 12,
            seed: 7,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        };
        let mut cfg = kernel::sim_config(&params);
        cfg.fidelity = Fidelity::Functional;
        let mut dev = Device::with_config(cfg);
        let module = kernel::load(&mut dev).expect("load PTX");
        let mega = kernel::render(&mut dev, &module, &ps, &cam, params, 2, true, |_| {}).expect("megakernel");
        let mut per_mode = Vec::new();
        for mode in Mode::ALL {
            let (mut dev, m, c) = wavefront::device(&params, Fidelity::Instructions).expect("device");
            let r = wavefront::render(&mut dev, &m, &c, &ps, &cam, params, 2, mode, true, |_| {}).expect("wavefront");
            let diff = r.image.accum.iter().zip(&mega.image.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
            assert_eq!(diff, 0, "{integrator:?} {mode:?}: {diff} values differ from the megakernel's");
            assert_eq!(r.image.frame_images, mega.image.frame_images, "{integrator:?} {mode:?}");
            assert_eq!(r.levels.len(), 13);
            // every path enters level 0, twice (two frames); then fewer
            assert_eq!(r.levels[0].active, 2 * params.paths() as u64);
            assert!(r.levels.windows(2).all(|l| l[1].active <= l[0].active), "{mode:?}: {:?}", r.levels);
            assert!(r.levels[3].active > 0 && r.levels[3].active < r.levels[0].active);
            match mode {
                Mode::Normal => {
                    assert!(r.levels.iter().all(|l| l.threads == 2 * params.paths() as u64));
                    assert_eq!(r.compaction.warp_instructions, 0);
                }
                Mode::Compacted => {
                    // a level launches the paths that survived the one before
                    assert!(r.levels.windows(2).all(|l| l[1].threads == l[1].active));
                    assert!(r.compaction.warp_instructions > 0);
                }
            }
            per_mode.push(r.levels.iter().map(|l| l.active).collect::<Vec<_>>());
        }
        assert_eq!(per_mode[0], per_mode[1], "{integrator:?}: active paths per level differ between the modes");
    }
}

#[test]
fn fig_16_worked_example_counts_25_then_75_percent_useful_lanes() {
    let f = fig_16::measure().expect("the worked example");
    // 4 warps launched; 3 of them hold 8 active lanes each (3 of 12 toy lanes, x 8)
    assert_eq!((f.before.warps, f.before.busy_warps, f.before.active), (4, 3, 24));
    assert_eq!(f.before.useful_fraction(), 0.25);
    // compacted: the 24 paths in one warp
    assert_eq!((f.after.warps, f.after.busy_warps, f.after.active), (1, 1, 24));
    assert_eq!(f.after.useful_fraction(), 0.75);
    assert_eq!(f.occupancy(), 0.75);
    // the compaction kept the paths: the same images either way
    assert!(f.same_radiance);
}
