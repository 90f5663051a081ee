//! Thesis 003's path tracer: the emulated kernel (`kernels/lin2017/path.cu`)
//! and the native mirror (`src/host/path/`) trace the same paths bit for bit;
//! the layout, traversal and estimators behave as derived by hand.

use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::path::layout::PathScene;
use warplight::host::path::{FrameParams, Integrator, Traversal, kernel, render_native};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::sim::{Device, Fidelity};

fn cornell() -> (Scene, PathScene) {
    let scene = scene_file::load(&scene_file::resolve("cornell-lambert")).expect("scenes/cornell-lambert.toml");
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    let ps = PathScene::new(&scene, &tree).expect("layout");
    (scene, ps)
}

fn camera(scene: &Scene, w: u32, h: u32) -> Camera {
    Camera { resolution: [w, h], ..scene.camera }
}

#[test]
fn emulated_frames_equal_native_frames_bit_for_bit() {
    let (scene, ps) = cornell();
    let (w, h) = (12, 10);
    let cam = camera(&scene, w, h);
    for integrator in Integrator::ALL {
        let params =
            FrameParams { width: w, height: h, integrator, max_bounces: 16, seed: 3, traversal: Traversal::ShortStack };
        let native = render_native(&ps, &cam, params, 2, true, |_| {});
        let mut cfg = kernel::sim_config(&params);
        cfg.fidelity = Fidelity::Functional;
        let mut dev = Device::with_config(cfg);
        let module = kernel::load(&mut dev).expect("load PTX");
        let emu = kernel::render(&mut dev, &module, &ps, &cam, params, 2, true, |_| {}).expect("launch");
        let diff = native.accum.iter().zip(&emu.image.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        assert_eq!(diff, 0, "{integrator:?}: {diff} of {} accumulated values differ", native.accum.len());
        assert_eq!(native.frame_images, emu.image.frame_images, "{integrator:?}");
        let sum: f32 = native.accum.iter().sum();
        assert!(sum > 0.0, "{integrator:?}: a black image");
    }
}
