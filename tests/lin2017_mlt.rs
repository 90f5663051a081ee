//! Metropolis light transport (§4.8, `--integrator mlt`) against Mitsuba 3,
//! and the thesis' counted MLT memory, 40 k W H bytes (003:L328).
//!
//! MLT is consistent, not unbiased per pixel, and the frames of one render
//! are not independent (the chains go on from frame to frame), so a render's
//! frames cannot serve as the t-test's batches as the other integrators'
//! do. The batches here are **independent renders**: `RUNS` seeds, each with
//! its own bootstrap (b) and its own chains, each run's final image one
//! estimate. Their spread holds every error that differs between runs: the
//! chains' noise and correlation and the error of b, which scales a whole
//! image. The per-block Welch t-test under Holm's correction
//! (`lin2017_mitsuba`, 4 x 4 blocks x 3 channels, α = 0.01) then compares
//! the mean of the runs with Mitsuba's `path` reference of the Lambertian
//! Cornell box.
//!
//! What it catches: a block whose mean moves by more than the runs' spread
//! allows: a wrong brightness (a light 10 % too bright fails), a wrong
//! normalisation (b, the fixed point, the expected-value splat weights), a
//! wrong pixel mapping of the splats (blocks swap light). What it cannot
//! catch: a bias that every run shares and that is smaller than that
//! spread. Start-up bias is such a bias; it shrinks with the frames, and
//! the runs here are long enough (the chart in docs/reproduction-lin2017.md
//! measures it); nor errors inside a block.

mod lin2017_mitsuba;

use lin2017_mitsuba::{ALPHA, BLOCK, params, reference_of, scene_of};
use warplight::host::camera::Camera;
use warplight::host::image::FrameBuffer;
use warplight::host::path::layout::PathScene;
use warplight::host::path::stats::{Estimate, Outcome, from_frames, welch_holm};
use warplight::host::path::{FrameParams, Integrator, Traversal, kernel, mlt, render_native};
use warplight::host::scene::MaterialKind;
use warplight::sim::Device;

const FIXTURE: &str = "tests/fixtures/mitsuba/cornell-lambert-32";
/// Independent renders (seeds), the batches of the test.
const RUNS: u32 = 16;
/// Frames of a render (4 mutations a pixel each).
const FRAMES: u32 = 64;

/// The final images of `RUNS` independent MLT renders (seeds `seed`, `seed` + 1, ...).
fn runs(ps: &PathScene, cam: &Camera, size: u32, seed: u32) -> Vec<FrameBuffer> {
    (0..RUNS)
        .map(|r| render_native(ps, cam, params(size, Integrator::Mlt, seed + r), FRAMES, false, |_| {}).image())
        .collect()
}

fn outcome(ps: &PathScene, cam: &Camera, size: u32, seed: u32, reference: &Estimate) -> Outcome {
    let ours = from_frames(&runs(ps, cam, size, seed), BLOCK).expect("two runs or more");
    // each cell's relative difference, sorted: how far the blocks are off, beside the runs' spread
    let mut rel: Vec<(f64, usize, f64)> = (0..ours.mean.len())
        .map(|i| (ours.mean[i] / reference.mean[i] - 1.0, i, ours.var[i].sqrt() / reference.mean[i]))
        .collect();
    rel.sort_by(|x, y| x.0.total_cmp(&y.0));
    let q = |f: f64| rel[((rel.len() - 1) as f64 * f) as usize];
    eprintln!(
        "relative difference per cell (value, cell, runs' relative standard error): min {:?} q10 {:?} median {:?} q90 {:?} max {:?}",
        q(0.0),
        q(0.1),
        q(0.5),
        q(0.9),
        q(1.0)
    );
    welch_holm(&ours, reference, ALPHA).expect("same block grid")
}

/// FAILS at present (ignored): the light's blocks come out about 48 % too
/// dark and every other block about 71 % too bright, the image's total
/// within 1 % (b is right; the chains spend about half the time they should
/// on the directly seen light). The same with nee as the base integrator, so
/// the fault is in the chains, not in bdpt's heavy tail. Not yet found; see
/// docs/reproduction-lin2017.md, "Metropolis light transport".
#[test]
#[ignore = "MLT's per-block means disagree with Mitsuba (light blocks -48 %, the rest +71 %): an open bug"]
fn mlt_agrees_with_mitsuba_over_independent_runs() {
    let (reference, size, _) = reference_of(FIXTURE);
    let (_, ps, cam) = scene_of("cornell-lambert", size);
    let o = outcome(&ps, &cam, size, 500, &reference);
    eprintln!("mlt lambert ({RUNS} runs of {FRAMES} frames): {o:?}");
    assert!(o.passed(), "mlt disagrees with Mitsuba: {o:?}");
    assert!(o.mean_rel_diff.abs() < 0.02, "mlt: mean off by {:.3}", o.mean_rel_diff);
}

/// The test sees MLT's brightness: a light 10 % too bright fails. (While the
/// test above fails, this holds trivially; ignored with it.)
#[test]
#[ignore = "meaningful only once mlt_agrees_with_mitsuba_over_independent_runs passes"]
fn mlt_with_a_bright_light_fails() {
    let (reference, size, _) = reference_of(FIXTURE);
    let (scene, mut ps, cam) = scene_of("cornell-lambert", size);
    for (m, mat) in scene.materials.iter().enumerate() {
        if mat.kind == MaterialKind::Emitter {
            for c in 4..7 {
                ps.mats[m][c] *= 1.1;
            }
        }
    }
    let o = outcome(&ps, &cam, size, 600, &reference);
    eprintln!("mlt bright light: {o:?}");
    assert!(!o.passed(), "mlt with a light 10 % too bright passed: {o:?}");
}

/// 003:L328: "there will be 40k·W·H bytes in total for storing the MLT data"
/// (10 floats a path segment, k the longest path). The device allocation of
/// the chains' random numbers is the host's formula (checked as such; the
/// kernels' footprint: tests/lin2017_mlt_state.rs); measured on the
/// emulator: the global bytes `mlt_init` stores (counted by the Maxwell
/// memory model): every state float once, plus each chain's current sample
/// (16 bytes) and its bootstrap sum (4 bytes). At k = 30 (the thesis'
/// example, 29 bounces) and at the default k = 17.
#[test]
fn the_chains_keep_40_k_w_h_bytes() {
    use warplight::model::{Model, Profile};
    use warplight::sim::{Arg, LaunchConfig};
    let (scene, ps, _) = scene_of("cornell-lambert", 8);
    let (w, h) = (8u32, 6u32);
    let cam = Camera { resolution: [w, h], ..scene.camera };
    for max_bounces in [29u32, 16] {
        let k = max_bounces as u64 + 1;
        let p = FrameParams {
            width: w,
            height: h,
            integrator: Integrator::Mlt,
            max_bounces,
            seed: 1,
            traversal: Traversal::ShortStack,
        };
        let mut dev = Device::with_config(kernel::sim_config(&p));
        let module = kernel::load(&mut dev).expect("load PTX");
        let bufs = kernel::upload_scene(&mut dev, &ps, &cam, &p).expect("upload");
        let n = (w * h) as u64;
        let state = dev.alloc_bytes(mlt::state_bytes(w, h, max_bounces), mlt::STATE_BUFFER);
        let chains = dev.alloc_bytes(16 * n, "mlt chains");
        let ysum = dev.alloc_bytes(4 * n, "mlt bootstrap sums");
        let args: Vec<Arg> = bufs.scene_args().into_iter().chain([state, chains, ysum]).map(Arg::Ptr).collect();
        let model = Model::new(Profile::Maxwell, &module.prog);
        let cfg = LaunchConfig::linear(1, kernel::THREADS);
        dev.launch_observed(&module, mlt::INIT_KERNEL, cfg, &args, Some(&model)).expect("launch");
        let stored = model.finish().counters.global_st.bytes;
        let allocated =
            dev.memory().allocations().iter().find(|a| a.name == mlt::STATE_BUFFER).map(|a| a.len).expect("state");
        eprintln!("k = {k}, {w} x {h}: state {allocated} bytes allocated, mlt_init stored {stored} global bytes");
        // the host's formula (mlt::state_bytes); tests/lin2017_mlt_state.rs measures the kernels' footprint
        assert_eq!(allocated, 40 * k * n, "40 k W H allocated");
        assert_eq!(stored, 40 * k * n + 16 * n + 4 * n, "the state, the chains' current samples and their sums");
        // every state float was written: a uniform in [0, 1), not all zero
        let u = dev.read::<f32>(state, (10 * k * n) as usize);
        assert!(u.iter().all(|x| (0.0..1.0).contains(x)) && u.iter().filter(|&&x| x > 0.0).count() > u.len() * 9 / 10);
    }
    // the thesis' example, 1920 x 1080 at k = 30: 2,488,320,000 bytes (it prints "2.37G"; errata 8)
    assert_eq!(mlt::state_bytes(1920, 1080, 29), 2_488_320_000);
}
