//! Seed 004's images (Fig. 7) on the emulator against the native mirror of
//! the per-pixel passes (`src/repro/purcell2003/native.rs`): the three
//! scenes with 100 times fewer photons and grid cells (`Fixture::reduced`) at
//! 24 pixels wide, query points, shadow-ray light, the final kNN-grid states
//! on both maps and the images bit for bit alike; the shadow rays' direct
//! light against a hand-derived value; the progressive display's saturation.
//! Each render is made once and shared by the tests (`OnceLock`).

use std::sync::OnceLock;

use glam::Vec3;
use warplight::host::scene::{Light, Material, MaterialKind, Scene, Triangle};
use warplight::host::scene_file;
use warplight::repro::purcell2003::image;
use warplight::repro::purcell2003::native;
use warplight::repro::purcell2003::passes::Passes;
use warplight::repro::purcell2003::photons::{self, Geometry};
use warplight::repro::purcell2003::scenes::{FIXTURES, Fixture};

fn bits(v: &[[f32; 4]]) -> Vec<u32> {
    v.iter().flatten().map(|x| x.to_bits()).collect()
}

/// Photons (stored, pilot), photons sought and grid cells divided by this.
const DIV: u32 = 100;
/// Image width.
const WIDTH: u32 = 24;

/// The three scenes, each rendered once on the emulator.
fn renders() -> &'static [(Scene, image::Rendered)] {
    static R: OnceLock<Vec<(Scene, image::Rendered)>> = OnceLock::new();
    R.get_or_init(|| {
        FIXTURES
            .iter()
            .map(|f| {
                let scene = scene_file::load(&scene_file::resolve(f.scene)).unwrap();
                let r = image::render(&scene, &f.reduced(DIV), WIDTH).unwrap();
                (scene, r)
            })
            .collect()
    })
}

/// The glass ball with 100 times fewer photons in the stated 250 × 1 × 250
/// grid, with its running images: with the grid reduced too its estimate
/// ends in 6 passes, too few to watch a display settle; here it takes about
/// a hundred, most pixels searching empty cells out to r_max.
fn glass_ball_in_the_stated_grid() -> &'static image::Rendered {
    static R: OnceLock<image::Rendered> = OnceLock::new();
    R.get_or_init(|| {
        let f = FIXTURES[0];
        let scene = scene_file::load(&scene_file::resolve(f.scene)).unwrap();
        image::render_with(&scene, &Fixture { grid: f.grid, ..f.reduced(DIV) }, WIDTH, true).unwrap()
    })
}

#[test]
fn emulated_and_native_images_of_the_three_scenes_are_bit_for_bit_alike() {
    for (f, (scene, r)) in FIXTURES.iter().zip(renders()) {
        assert!(r.finished.iter().all(|&x| x), "{}: the estimates finish", f.scene);
        let (q, direct, states) = image::native_passes(scene, r);
        assert_eq!(bits(&q.query), bits(&r.queries.query), "{}: query points", f.scene);
        assert_eq!(bits(&q.normal), bits(&r.queries.normal), "{}: normals", f.scene);
        assert_eq!(bits(&direct), bits(&r.direct), "{}: shadow rays", f.scene);
        for (m, (n, e)) in states.iter().zip(&r.states).enumerate() {
            assert_eq!(n, e, "{}: map {m}'s final states", f.scene);
        }
        let (e, n) = (image::images(r), image::native_images(scene, r));
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
    let r = glass_ball_in_the_stated_grid();
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

/// Why the ring's images are dark: its point light (3.5, 3, 0) stands outside
/// the 2 m high mirror band of radius 1.5 m, so a ray from any floor point
/// inside the band to the light leaves the band at most 3 / 5 of the way up
/// (at most 2R = 3 m inside, at least 3.5 − 1.5 = 2 m outside), 1.8 m < 2 m:
/// the whole interior is in the band's shadow, lit only by the caustic the
/// band reflects onto it and by indirect light (the photon map), whatever the
/// renderer. The shadow rays see exactly that.
#[test]
fn the_rings_interior_is_in_the_bands_shadow_and_lit_by_the_photon_map() {
    let r = &renders()[1].1;
    assert_eq!(r.fixture.scene, "ring");
    let (mut inside, mut lit_by_map) = (0, 0);
    for (i, q) in r.queries.query.iter().enumerate() {
        let on_floor = q[3] != 0.0 && q[1].abs() < 1e-3;
        if on_floor && q[0] * q[0] + q[2] * q[2] < 1.45 * 1.45 {
            inside += 1;
            assert_eq!(r.direct[i], [0.0; 4], "pixel {i} inside the band sees the light: {q:?}");
            lit_by_map += usize::from(r.states[0][i].n > 0);
        }
    }
    assert!(inside > 20, "{inside} pixels of the floor inside the band");
    assert!(lit_by_map > 0, "the photon map lights the interior ({lit_by_map} of {inside} pixels)");
    // outside the band, on the light's side, the floor is lit directly
    let outside_lit = r
        .queries
        .query
        .iter()
        .zip(&r.direct)
        .filter(|(q, d)| q[3] != 0.0 && q[1].abs() < 1e-3 && q[0] > 1.6 && d[0] > 0.0)
        .count();
    assert!(outside_lit > 0, "the floor outside the band on the light's side is lit");
}

/// The pass from which the running image stays within `tol` (relative RMS
/// error) of the final one, from 1.
fn settles_at(c: &[image::PassError], tol: f64) -> u64 {
    c.iter().rev().take_while(|p| p.rel_rmse < tol).last().map_or(c.len() as u64 + 1, |p| p.pass)
}

/// Full against visual convergence (004:L182): on both maps the progressive
/// display settles (stays within 1 % of the final image) passes before every
/// pixel has finished, after changing at first (the first pass's image is
/// not the final one). Which map settles first is printed, not asserted: at
/// the stated photons on 96 × 72 pixels the stencil map does
/// (docs/reproduction-purcell2003.md).
#[test]
fn the_progressive_display_settles_before_the_estimate_finishes() {
    let r = glass_ball_in_the_stated_grid();
    for m in 0..2 {
        let c = image::convergence(&r.progress[m], &r.finished_after[m]);
        let passes = c.len() as u64;
        let at = settles_at(&c, 0.01);
        eprintln!("map {m}: within 1 % from pass {at} of {passes}");
        assert!(passes > 2, "map {m}: {passes} passes");
        assert!(at < passes, "map {m}: settles only at the last pass");
        assert!(c[0].rel_rmse > 0.0, "map {m}: the first pass's image is already final");
    }
}
