//! Seed 004's images (Fig. 7) on the emulator against the native mirror of
//! the per-pixel passes (`src/repro/purcell2003/native.rs`): the three
//! scenes with 100 times fewer photons at 24 pixels wide, query points,
//! shadow-ray light, the final kNN-grid states on both maps and the images
//! bit for bit alike; the shadow rays' direct light against a hand-derived
//! value.

use glam::Vec3;
use warplight::host::scene::{Light, Material, MaterialKind, Scene, Triangle};
use warplight::host::scene_file;
use warplight::repro::purcell2003::image;
use warplight::repro::purcell2003::native;
use warplight::repro::purcell2003::passes::Passes;
use warplight::repro::purcell2003::photons::{self, Geometry};
use warplight::repro::purcell2003::scenes::FIXTURES;

fn bits(v: &[[f32; 4]]) -> Vec<u32> {
    v.iter().flatten().map(|x| x.to_bits()).collect()
}

#[test]
fn emulated_and_native_images_of_the_three_scenes_are_bit_for_bit_alike() {
    for f in FIXTURES {
        let scene = scene_file::load(&scene_file::resolve(f.scene)).unwrap();
        let r = image::render(&scene, &f.reduced(100), 24).unwrap();
        assert!(r.finished.iter().all(|&x| x), "{}: the estimates finish", f.scene);
        let (q, direct, states) = image::native_passes(&scene, &r);
        assert_eq!(bits(&q.query), bits(&r.queries.query), "{}: query points", f.scene);
        assert_eq!(bits(&q.normal), bits(&r.queries.normal), "{}: normals", f.scene);
        assert_eq!(bits(&direct), bits(&r.direct), "{}: shadow rays", f.scene);
        for (m, (n, e)) in states.iter().zip(&r.states).enumerate() {
            assert_eq!(n, e, "{}: map {m}'s final states", f.scene);
        }
        let (e, n) = (image::images(&r), image::native_images(&scene, &r));
        for m in 0..2 {
            assert_eq!(e[m], n[m], "{}: image of map {m}", f.scene);
        }
        // the images are not black: direct light where the shadow rays see the light, and the estimate adds to it
        let lit = r.direct.iter().filter(|d| d[0] > 0.0).count();
        assert!(lit > 0, "{}: no directly lit pixel", f.scene);
        let found = r.states[0].iter().filter(|s| s.n > 0).count();
        assert!(found > 0, "{}: the map's estimate finds photons", f.scene);
    }
}

fn quad(a: Vec3, b: Vec3, c: Vec3, d: Vec3, m: u32) -> [Triangle; 2] {
    [Triangle { v: [a, b, c], material: m }, Triangle { v: [a, c, d], material: m }]
}

/// A diffuse floor (y = 0) under a point light at height 1 with a blocker
/// (a small quad at y = 0.5 over x in [0.4, 0.6]).
fn floor_and_blocker(albedo: f32, intensity: f32) -> Scene {
    let s = 2.0;
    let mut tris =
        quad(Vec3::new(-s, 0.0, -s), Vec3::new(-s, 0.0, s), Vec3::new(s, 0.0, s), Vec3::new(s, 0.0, -s), 0).to_vec();
    let (a, b) = (0.4, 0.6);
    tris.extend(quad(
        Vec3::new(a, 0.5, -0.1),
        Vec3::new(a, 0.5, 0.1),
        Vec3::new(b, 0.5, 0.1),
        Vec3::new(b, 0.5, -0.1),
        0,
    ));
    let m = Material { name: "floor".into(), kind: MaterialKind::Diffuse, color: [albedo; 3], emission: [0.0; 3] };
    let mut sc = Scene::assemble("floor", std::path::Path::new("floor"), tris, vec![m]);
    sc.lights.push(Light::Point { position: [0.0, 1.0, 0.0], intensity: [intensity; 3] });
    sc
}

/// Direct light from a point light, by hand: albedo / π · I cos θ / d²; zero in the blocker's shadow.
#[test]
fn shadow_rays_give_the_point_lights_direct_light_and_its_shadow() {
    let scene = floor_and_blocker(0.5, 2.0);
    let geo = Geometry::of(&scene);
    let mut p = Passes::new(None).unwrap();
    // query points on the floor: straight below the light, at x = 1 (lit), at x = 1 behind the blocker's shadow (x = 1 lies
    // in the shadow of x in [0.4, 0.6] at y = 0.5: the shadow spans x in [0.8, 1.2])
    let pts = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.5, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)];
    let mut q = native::QueryPoints { query: vec![], normal: vec![], albedo: vec![] };
    for x in pts {
        q.query.push([x.x, x.y, x.z, 1.0]);
        q.normal.push([0.0, 1.0, 0.0, 0.0]);
        q.albedo.push([0.5, 0.5, 0.5, 0.0]);
    }
    let mut up = |v: &Vec<[f32; 4]>| p.upload(&v.iter().flatten().copied().collect::<Vec<f32>>()).unwrap();
    let queries = photons::Queries {
        width: pts.len() as u32,
        height: 1,
        query: up(&q.query),
        normal: up(&q.normal),
        albedo: up(&q.albedo),
    };
    let d = photons::shadow_rays(&mut p, &geo, &queries, 1, 5).unwrap();
    let got: Vec<[f32; 4]> =
        p.dev.read::<f32>(d, 4 * pts.len()).chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    let want = |x: Vec3| {
        let to = Vec3::new(0.0, 1.0, 0.0) - x;
        let cos = to.y / to.length();
        0.5 / std::f32::consts::PI * 2.0 * cos / to.length_squared()
    };
    assert!((got[0][0] - want(pts[0])).abs() < 1e-6 * want(pts[0]) + 1e-7, "{:?}", got[0]);
    assert!((got[1][0] - want(pts[1])).abs() < 1e-5 * want(pts[1]), "{:?} vs {}", got[1], want(pts[1]));
    assert_eq!(got[2], [0.0; 4], "in the blocker's shadow");
    assert!((got[3][0] - want(pts[3])).abs() < 1e-5 * want(pts[3]));
    // the native mirror gives the same bits
    assert_eq!(bits(&native::shadow_rays(&geo, &q, 1, 5)), bits(&got));
}

/// Saturation against convergence (004:L182): with the display clamped at 1,
/// bright pixels show their final colour passes before their search ends,
/// and the displayed image is final before every pixel has finished.
#[test]
fn saturated_pixels_show_their_final_colour_before_they_finish() {
    let f = FIXTURES[0];
    let scene = scene_file::load(&scene_file::resolve(f.scene)).unwrap();
    let r = image::render_with(&scene, &f.reduced(100), 24, true).unwrap();
    let iters = r.params.iters as i32;
    for m in 0..2 {
        let frames = &r.progress[m];
        assert_eq!(frames.len(), r.finished_after[m].len(), "one running image per pass");
        let last = frames.last().unwrap();
        let shown: Vec<Vec<u8>> = frames.iter().map(|f| f.to_srgb8(0.0)).collect();
        let fin = &shown[shown.len() - 1];
        let (mut early, mut saturated) = (0, 0);
        let mut visual = 0;
        for (i, px) in last.pixels.iter().enumerate() {
            // the pass from which the displayed colour stays final
            let v = (0..shown.len()).rev().take_while(|&p| shown[p][3 * i..3 * i + 3] == fin[3 * i..3 * i + 3]).last();
            let v = v.map_or(shown.len(), |p| p + 1);
            visual = visual.max(v);
            let done = (r.states[m][i].used + iters - 1) / iters;
            if px.iter().any(|&c| c >= 1.0) && done > 1 {
                saturated += 1;
                if (v as i32) < done {
                    early += 1;
                }
            }
        }
        eprintln!(
            "map {m}: {early} of {saturated} saturated pixels final early; display final after pass {visual} of {}",
            frames.len()
        );
        assert!(saturated > 0, "map {m}: bright pixels saturate");
        assert!(early > 0, "map {m}: saturated pixels show their final colour before they finish");
        assert!(visual <= frames.len());
        let c = image::convergence(frames, &r.finished_after[m]);
        assert_eq!(c.last().unwrap().rel_rmse, 0.0);
        assert_eq!(c.last().unwrap().displayed_off, 0.0);
        assert!(c.iter().all(|p| (0.0..=1.0).contains(&p.displayed_off)));
    }
}
