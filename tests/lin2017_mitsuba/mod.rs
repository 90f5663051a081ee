//! What the path tracer's tests against Mitsuba 3 share: the committed
//! references (`tests/fixtures/mitsuba/`, made by `tools/mitsuba/reference.py`),
//! the scenes laid out as the renderer does, and the per-block Welch t-test
//! under Holm's correction of a native or emulated render against them.

use std::path::Path;

use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::path::layout::PathScene;
use warplight::host::path::stats::{
    Estimate, Outcome, from_frames, from_reference, read_exr, welch_holm, welch_holm_floored,
};
use warplight::host::path::{FrameParams, Integrator, PixelSampling, Termination, Traversal, kernel, render_native};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::sim::{Device, Fidelity};

/// Pixels a block's side.
pub const BLOCK: u32 = 4;
/// The family-wise level of Holm's procedure.
pub const ALPHA: f64 = 0.01;

/// A reference's estimate, its image size and its metadata.
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn reference_of(fixture: &str) -> (Estimate, u32, serde_json::Value) {
    reference_in_blocks(fixture, BLOCK)
}

/// [`reference_of`] in blocks of `block` x `block` pixels.
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn reference_in_blocks(fixture: &str, block: u32) -> (Estimate, u32, serde_json::Value) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mean = read_exr(&root.join(format!("{fixture}.exr"))).expect("reference mean");
    let var = read_exr(&root.join(format!("{fixture}-var.exr"))).expect("reference variance");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join(format!("{fixture}.json"))).expect("reference json"))
            .expect("json");
    let batches = meta["batches"].as_u64().expect("batches") as u32;
    assert_eq!(meta["size"].as_u64(), Some(mean.width as u64));
    (from_reference(&mean, &var, block, batches), mean.width, meta)
}

/// Scene `name` of `scenes/`, laid out, and its camera at `size` x `size` pixels.
pub fn scene_of(name: &str, size: u32) -> (Scene, PathScene, Camera) {
    let scene = scene_file::load(&scene_file::resolve(name)).expect("a scene of scenes/");
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    let ps = PathScene::new(&scene, &tree).expect("layout");
    let cam = Camera { resolution: [size, size], ..scene.camera };
    (scene, ps, cam)
}

/// Frames of `size` x `size` pixels, 16 bounces, the short stack.
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn params(size: u32, integrator: Integrator, seed: u32) -> FrameParams {
    FrameParams {
        width: size,
        height: size,
        integrator,
        max_bounces: 16,
        seed,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    }
}

/// A native render of `frames` frames against `reference`.
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn native_outcome(ps: &PathScene, cam: &Camera, p: FrameParams, frames: u32, reference: &Estimate) -> Outcome {
    native_outcome_in_blocks(ps, cam, p, frames, reference, BLOCK)
}

/// [`native_outcome`] in blocks of `block` x `block` pixels (`reference`
/// made with the same, [`reference_in_blocks`]).
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn native_outcome_in_blocks(
    ps: &PathScene,
    cam: &Camera,
    p: FrameParams,
    frames: u32,
    reference: &Estimate,
    block: u32,
) -> Outcome {
    let r = render_native(ps, cam, p, frames, true, |_| {}).expect("render");
    let ours = from_frames(&r.frame_images, block).expect("two frames or more");
    welch_holm(&ours, reference, ALPHA).expect("same block grid")
}

/// The emulated kernel's 4 frames (functional fidelity) against `reference`.
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn emulated_outcome(ps: &PathScene, cam: &Camera, p: FrameParams, reference: &Estimate) -> Outcome {
    emulated_frames_outcome(ps, cam, p, 4, reference, 0.0)
}

/// Samples per pixel behind a reference (its metadata): 2 x 2 subpixels x
/// spp per subpixel per batch x batches.
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn reference_samples(meta: &serde_json::Value) -> f64 {
    let spp = meta["spp_per_subpixel_per_batch"].as_f64().expect("spp_per_subpixel_per_batch");
    4.0 * spp * meta["batches"].as_f64().expect("batches")
}

/// The emulated kernel's `frames` frames (functional fidelity) against
/// `reference`, each cell's variance floored at `floor` times the
/// reference's ([`welch_holm_floored`]; 0: none).
pub fn emulated_frames_outcome(
    ps: &PathScene,
    cam: &Camera,
    p: FrameParams,
    frames: u32,
    reference: &Estimate,
    floor: f64,
) -> Outcome {
    let mut cfg = kernel::sim_config(&p);
    cfg.fidelity = Fidelity::Functional;
    let mut dev = Device::with_config(cfg);
    let module = kernel::load_for(&mut dev, kernel::KernelBuild::of(&p)).expect("load PTX");
    let r = kernel::render(&mut dev, &module, ps, cam, p, frames, true, |_| {}).expect("launch");
    let ours = from_frames(&r.image.frame_images, BLOCK).expect("frames");
    welch_holm_floored(&ours, reference, ALPHA, floor).expect("same block grid")
}

/// `e` without the cells of `blocks` ((x, y) of the block grid), as one row
/// of the remaining blocks: the test of [`welch_holm`] over the others (both
/// estimates cut alike).
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn without_blocks(e: &Estimate, blocks: &[(u32, u32)]) -> Estimate {
    let keep = |i: usize| {
        let b = (i / 3) as u32;
        !blocks.contains(&(b % e.blocks_x, b / e.blocks_x))
    };
    let mean: Vec<f64> = e.mean.iter().enumerate().filter(|(i, _)| keep(*i)).map(|(_, v)| *v).collect();
    let var: Vec<f64> = e.var.iter().enumerate().filter(|(i, _)| keep(*i)).map(|(_, v)| *v).collect();
    Estimate { blocks_x: (mean.len() / 3) as u32, blocks_y: 1, mean, var, dof: e.dof }
}

/// A native render of `frames` frames against `reference`, both without
/// the cells of `blocks` ([`without_blocks`]).
// each test crate that includes this module uses a part of it
#[allow(dead_code)]
pub fn native_outcome_without(
    ps: &PathScene,
    cam: &Camera,
    p: FrameParams,
    frames: u32,
    reference: &Estimate,
    blocks: &[(u32, u32)],
) -> (Outcome, Outcome) {
    let r = render_native(ps, cam, p, frames, true, |_| {}).expect("render");
    let ours = from_frames(&r.frame_images, BLOCK).expect("two frames or more");
    let all = welch_holm(&ours, reference, ALPHA).expect("same block grid");
    let rest =
        welch_holm(&without_blocks(&ours, blocks), &without_blocks(reference, blocks), ALPHA).expect("same block grid");
    (all, rest)
}

#[path = "../support/mod.rs"]
mod support;
/// Runs the `warplight` binary with `args`: (success, stdout, stderr).
#[allow(unused_imports)]
pub use support::warplight;
