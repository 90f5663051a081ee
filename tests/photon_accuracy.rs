//! Accuracy of the density estimators against a converged reference
//! (`warplight::repro::fabianowski2011::accuracy`, issue 13 item 6), on a
//! small Cornell box natively (the emulated kernels equal the native
//! references bit for bit, `tests/vkde.rs`): the structural claims the
//! docs' error charts rest on.

use std::path::Path;

use glam::Vec3;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::raycast::Caster;
use warplight::host::scene_file;
use warplight::repro::fabianowski2011::accuracy::{
    self, Method, estimate_native, mean_relative_error, native_maps, reference, rmse, trace_native,
};
use warplight::repro::fabianowski2011::photon_image;
use warplight::repro::fabianowski2011::photons::Emission;
use warplight::repro::fabianowski2011::vkde::{self, Settings};

/// The fixture: 12 x 12 pixels, spread 10, k = 50; renders of 1,024 and
/// 16,384 photons (indices from 0); a reference of 4 batches of 65,536.
const SIDE: u32 = 12;
const SPREAD: f32 = 10.0;
const K: usize = 50;
const FEW: usize = 1 << 10;
const MANY: usize = 1 << 14;
const BATCH: usize = 1 << 16;
const BATCHES: usize = 4;

#[test]
fn error_falls_with_photons_against_a_reference_quieter_than_the_renders() {
    let scene = scene_file::load(Path::new("scenes/cornell-box.toml")).unwrap();
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = scene.camera;
    cam.resolution = [SIDE, SIDE];
    let caster = Caster::new(&scene, &tree);
    let q = photon_image::queries(&caster, &cam);
    assert!(q.iter().flatten().count() > (SIDE * SIDE / 2) as usize, "most pixels see a diffuse surface");
    let refr = reference(&scene, &tree, &q, SPREAD, BATCH, BATCHES, accuracy::REFERENCE_FIRST, &mut |_| {}).unwrap();
    assert_eq!((refr.batches, refr.batch_photons), (BATCHES, BATCH));
    let render = |n: usize, m: Method| {
        let e = Emission::of(&scene, n).unwrap();
        let s = Settings { h_max: vkde::H_MAX, ..Settings::thesis(n, SPREAD) };
        let (_, bvh, kd) = native_maps(&trace_native(&caster, &e, 0), &s);
        let img: Vec<[f32; 3]> = estimate_native(&bvh, &kd, &q, m, K).iter().map(|e| e.radiance).collect();
        (rmse(&img, &refr.image), mean_relative_error(&img, &refr.image))
    };
    for m in Method::ALL {
        let (few, many) = (render(FEW, m), render(MANY, m));
        eprintln!("{m:?}: {FEW} photons {few:?}, {MANY} photons {many:?}, reference noise {}", refr.noise);
        // 16 times the photons: both errors fall
        assert!(many.0 < 0.8 * few.0, "{m:?}: RMSE {} at {MANY} photons, {} at {FEW}", many.0, few.0);
        assert!(many.1 < 0.8 * few.1, "{m:?}: relative error {} at {MANY} photons, {} at {FEW}", many.1, few.1);
        // the reference's own noise is well below the error it measures
        assert!(refr.noise < 0.5 * many.0, "{m:?}: reference noise {} against an error of {}", refr.noise, many.0);
    }
}
