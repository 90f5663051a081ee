//! Thesis 000 Table 6.6's pipeline (§6.3) on a small fixture (the Cornell
//! box, 2048 photons, 8 x 8 pixels): each frame's photons leave the moved
//! light and are bit for bit the native tracer's, the emulated gather through
//! the LBVH photon map equals the native one (radiance, and k as the lanes
//! through its `@count contributed` line), and every stage yields counters
//! the GTX 280 timing model turns into a positive time.

use std::path::Path;

use glam::Vec3;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::scene_file;
use warplight::repro::fabianowski2011::photons::{self, Emission};
use warplight::repro::fabianowski2011::pm_layout::{self, Layout, Layouts};
use warplight::repro::fabianowski2011::table_6_6::{self, Kernels};
use warplight::repro::fabianowski2011::vkde::{self, Constructed, Settings, Shape};
use warplight::repro::fabianowski2011::{lbvh, photon_image};

#[test]
fn each_frame_retraces_from_the_moved_light_and_every_stage_is_timed() {
    let scene = scene_file::load(Path::new("scenes/cornell-box.toml")).unwrap();
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = scene.camera;
    cam.resolution = [8, 8];
    let (n, spread) = (2048, 4.0);
    let mut k = Kernels::load().unwrap();
    let shapes = [Shape::Uniform, Shape::Epanechnikov];
    let mut lights = Vec::new();
    for f in 0..2 {
        let offset = table_6_6::light_offset(&scene, f);
        assert_eq!(offset, scene.flight.light_step.map(|s| s * f as f32));
        let fr = table_6_6::frame(&mut k, &scene, &tree, &cam, n, spread, offset, &shapes).unwrap();
        // the photons of the moved light, as the native tracer and construction make them
        let e = Emission::of(&scene, n).unwrap().moved(offset);
        assert_eq!(fr.light, e.position);
        let native = photons::reference(&scene, &tree, &e);
        let s = Settings { h_max: vkde::H_MAX, ..Settings::thesis(n, spread) };
        let c = Constructed::collect(vkde::construct_all(&native, &s).iter());
        // Interactions (every photon on the emulator) agree with the native tracer and construction
        assert_eq!((fr.interactions, fr.kernels), (c.interactions, c.kernels.len()));
        assert_eq!(fr.sample, n);
        assert!(fr.kernels > 100, "{} kernels", fr.kernels);
        assert_eq!(fr.n_auto, lbvh::n_auto(&c.kernels, &scene));
        // the emulated gathers equal the native walk through the same LBVH
        let layouts = Layouts::new(&lbvh::build(&c.kernels, fr.n_auto).tree(), &c.kernels);
        let q = photon_image::queries(&warplight::host::raycast::Caster::new(&scene, &tree), &cam);
        assert_eq!(fr.queries, q.iter().flatten().count());
        for (i, &shape) in shapes.iter().enumerate() {
            let (radiance, _) = pm_layout::gather_all(&layouts, Layout::Complete, &q, shape);
            let bits = |v: &[[f32; 3]]| v.iter().map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
            assert_eq!(bits(&fr.radiance[i]), bits(&radiance), "{shape:?}");
            // k: the emulated gather's `@count contributed` lanes are the native VKDE's contributions
            let map = vkde::PhotonMap::build(&c.kernels);
            let k: u64 = q.iter().flatten().map(|x| vkde::estimate(&map, x, shape).contributions as u64).sum();
            assert_eq!(fr.contributions[i], k, "{shape:?}");
            assert!(k > 0);
        }
        // every stage ran and has a positive modelled time
        for c in [&fr.trace, &fr.render[0], &fr.render[1]] {
            assert!(c.warp_instructions > 0.0 && c.dram_bytes > 0.0, "{c:?}");
            let ms = table_6_6::predicted_ms(c).unwrap();
            assert!(ms > 0.0 && ms.is_finite(), "{ms}");
        }
        // the LBVH by grid: the radix sorts' scans on one CTA, the sorts' other launches on
        // ceil(kernels / 256) CTAs (at most 30), each shape with its own positive time
        let grids: Vec<u32> = fr.lbvh.iter().map(|(s, _)| s.ctas).collect();
        let tiles = fr.kernels.div_ceil(256).min(30) as u32;
        assert!(grids.contains(&1) && grids.contains(&tiles), "{grids:?}, {tiles} tiles");
        for (shape, c) in &fr.lbvh {
            assert!(c.warp_instructions > 0.0, "{shape:?}: {c:?}");
            let ms = table_6_6::predicted_ms_at(c, *shape).unwrap();
            assert!(ms > 0.0 && ms.is_finite(), "{shape:?}: {ms}");
        }
        assert!(table_6_6::grid_ms(&fr.lbvh).unwrap() > 0.0);
        lights.push(fr.light);
    }
    // the light moved between the frames (3 cm along each axis by default)
    assert!((0..3).all(|c| lights[1][c] > lights[0][c]), "{lights:?}");
}
