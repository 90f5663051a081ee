//! `warplight render --method photon-map` (thesis 000 ch. 5, issue 13 item 5):
//! the emulated pipeline (photon tracing, kernel construction, estimation
//! kernels) makes the native pipeline's image bit for bit, for VKDE and kNN;
//! the estimator names parse as documented.

use std::path::Path;

use glam::Vec3;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::scene_file;
use warplight::repro::fabianowski2011::photon_image::{self, Estimator, Options, parse_estimator};
use warplight::repro::fabianowski2011::vkde::{self, Shape};

#[test]
fn the_emulated_photon_map_image_equals_the_native_one() {
    let scene = scene_file::load(Path::new("scenes/cornell-box.toml")).unwrap();
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = scene.camera;
    cam.resolution = [10, 10];
    for (estimator, shape) in [(Estimator::Vkde, Shape::Epanechnikov), (Estimator::Knn(16), Shape::Uniform)] {
        let o = Options { photons: 1024, spread: 4.0, h_max: vkde::H_MAX, estimator, shape, emulated: false };
        let native = photon_image::render(&scene, &tree, &cam, &o).unwrap();
        let emulated = photon_image::render(&scene, &tree, &cam, &Options { emulated: true, ..o }).unwrap();
        let bits = |f: &warplight::host::image::FrameBuffer| -> Vec<[u32; 3]> {
            f.pixels.iter().map(|p| p.map(f32::to_bits)).collect()
        };
        assert_eq!(bits(&emulated.indirect), bits(&native.indirect), "{estimator:?}");
        assert_eq!(emulated.contributions, native.contributions);
        // lit: most pixels see photon-mapped light
        let lit = native.indirect.pixels.iter().filter(|p| p[0] > 0.0).count();
        assert!(lit > 50, "{estimator:?}: {lit} lit pixels");
        assert!(emulated.launch.is_some() && native.launch.is_none());
    }
}

#[test]
fn estimator_names() {
    assert_eq!(parse_estimator("vkde", "x"), Some((Estimator::Vkde, Shape::Uniform)));
    assert_eq!(parse_estimator("vkde-epanechnikov", "x"), Some((Estimator::Vkde, Shape::Epanechnikov)));
    // Table 5.1's k_kNN for its scenes (Ring: 51), else 50
    assert_eq!(parse_estimator("knn", "ring"), Some((Estimator::Knn(51), Shape::Uniform)));
    assert_eq!(parse_estimator("knn", "cornell-box"), Some((Estimator::Knn(50), Shape::Uniform)));
    assert_eq!(parse_estimator("knn:7", "x"), Some((Estimator::Knn(7), Shape::Uniform)));
    assert_eq!(parse_estimator("knn:0", "x"), None);
    assert_eq!(parse_estimator("knn:x", "x"), None);
    assert_eq!(parse_estimator("kde", "x"), None);
    // Table 5.1's photons and spread for its scenes
    assert_eq!(photon_image::render_parameters("sponza"), (262144, 40.0));
    assert_eq!(photon_image::render_parameters("cornell-box"), (131072, 10.0));
}

/// The committed first frames of `render --method photon-map` (96 x 96,
/// native, Table 5.1's photons and s): two small scenes re-rendered match
/// within one 8-bit step a channel.
#[test]
fn photon_map_first_frames_match_their_references() {
    use warplight::host::image::FrameBuffer;
    for name in ["scene6", "ring"] {
        let scene = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).unwrap();
        let mut cam = scene.flight.camera(&scene.camera, 0);
        cam.resolution = [96, 96];
        for est in ["vkde", "knn"] {
            let (estimator, shape) = parse_estimator(est, name).unwrap();
            let (photons, spread) = photon_image::render_parameters(name);
            let o = Options { photons, spread, h_max: vkde::H_MAX, estimator, shape, emulated: false };
            let (image, _) = photon_image::render_scene(&scene, &cam, &o, Vec3::ZERO, None).unwrap();
            let got = image.to_srgb8(0.0);
            let path = format!("reference_images/fabianowski-{name}-{est}.png");
            let want = FrameBuffer::read_png(Path::new(&path)).unwrap().to_srgb8(0.0);
            assert_eq!(got.len(), want.len(), "{path}");
            let worst = got.iter().zip(&want).map(|(a, b)| (*a as i32 - *b as i32).abs()).max().unwrap();
            assert!(worst <= 1, "{path}: a channel differs by {worst} steps");
        }
    }
}

/// `render --method photon-map` runs the emulated kernels on the device it
/// is given: a device whose CTAs are too small for the kernels' launch fails.
#[test]
fn the_emulated_render_runs_on_the_device_given() {
    let scene = scene_file::load(Path::new("scenes/cornell-box.toml")).unwrap();
    let mut cam = scene.camera;
    cam.resolution = [4, 4];
    let o = Options {
        photons: 64,
        spread: 4.0,
        h_max: vkde::H_MAX,
        estimator: Estimator::Vkde,
        shape: Shape::Uniform,
        emulated: true,
    };
    let small = warplight::sim::SimConfig { max_threads_per_cta: 32, ..Default::default() };
    let dev = warplight::sim::Device::with_config(small);
    assert!(photon_image::render_scene(&scene, &cam, &o, Vec3::ZERO, Some(dev)).is_err());
    let (image, r) =
        photon_image::render_scene(&scene, &cam, &o, Vec3::ZERO, Some(warplight::sim::Device::new())).unwrap();
    assert!(r.launch.is_some() && image.pixels.len() == 16);
}

/// The photon-map branch checks the host memory it needs against the budget before any work.
#[test]
fn the_photon_map_render_checks_its_memory_first() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["render", "--scene", "cornell-box", "--method", "photon-map", "--resolution", "64x64", "-o"])
        .arg(std::env::temp_dir().join("warplight-photon-budget.png"))
        .env("WARPLIGHT_MEMORY_BUDGET", "64K")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("photon-mapped render of 64 x 64 pixels"), "{err}");
}
