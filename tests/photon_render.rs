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
