//! Thesis 003's own material model (§4.5, 003:L255-263): a smooth
//! dielectric coat whose Schlick reflectance R at the viewer's cosine picks
//! the coat's mirror reflection, else Ashikhmin and Shirley's coupled diffuse
//! lobe
//!
//!   f = 28/23 · C/π · (1 − R0) · (1 − (1 − n·ω_in/2)^5) · (1 − (1 − n·ω_out/2)^5).
//!
//! Mitsuba 3 has no such BSDF, so the checks are analytic. Since
//! ∫ (1 − (1 − cos θ/2)^5) cos θ dω = 23π/28 over the hemisphere (the
//! reason for the 28/23), a coated plate under a sky of radiance 1 reflects
//! exactly R(c) + C (1 − R0) (1 − (1 − c/2)^5) towards a viewer at cosine c:
//! the native and the emulated renders pass a per-block Welch test against
//! that image, and fail against the coated Lambertian R + (1 − R) C. Under a
//! sky cap (radiance 1 within 60° of the zenith) the lobe's shape shows: ours
//! passes, a lobe of the same albedo shaped as Lambert's fails. In the
//! Cornell box (`scenes/cornell-coated.toml`) the light sample's f and pdf
//! agree with BSDF sampling: pt, nee and both heuristics of mis estimate the
//! same image. (That the emulated kernel traces the native bits under every
//! integrator is tests/lin2017.rs'.)

mod lin2017_mitsuba;

use std::path::PathBuf;

use glam::Vec3;
use lin2017_mitsuba::{ALPHA, BLOCK, params, scene_of};
use warplight::host::camera::Camera;
use warplight::host::image::FrameBuffer;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::path::layout::{KIND_COATED, PathScene};
use warplight::host::path::native::{as_factor, coat_r0, schlick};
use warplight::host::path::stats::{Estimate, from_frames, welch_holm};
use warplight::host::path::{Integrator, kernel, render_native};
use warplight::host::scene::{Material, MaterialKind, Scene, Triangle};
use warplight::sim::{Device, Fidelity};

/// The plate's colour (distinct channels, so a lobe that ignores C fails in two of them).
const COLOR: [f32; 3] = [0.8, 0.5, 0.2];
/// The coat's IOR: R0 = 0.04.
const IOR: f32 = 1.5;
/// The furnace image's side.
const SIZE: u32 = 32;

#[test]
fn the_lobe_integrates_to_its_normalisation() {
    // ∫ g(cos θ) cos θ dω over the hemisphere, g = 1 − (1 − c/2)^5, by the
    // midpoint rule in c (dω = 2π dc): 23π/28, the reason for 28/23.
    let n = 100_000;
    let s: f64 = (0..n).map(|k| (k as f64 + 0.5) / n as f64).map(|c| as_factor(c as f32) as f64 * c).sum();
    let integral = 2.0 * std::f64::consts::PI * s / n as f64;
    assert!((integral - 23.0 * std::f64::consts::PI / 28.0).abs() < 1e-5, "{integral}");
    // the albedo at normal incidence: 31/32 of C (1 - R0); R0 of IOR 1.5 is 0.04
    assert!((as_factor(1.0) - 31.0 / 32.0).abs() < 1e-7);
    assert!((coat_r0(IOR) - 0.04).abs() < 1e-7);
    // the diffuse branch's mask f cos / (p (1 - R)) at normal incidence, per unit of colour:
    // 28/23 (31/32)^2 = 1.1425, above the 1 the thesis' roulette expects (003:L267-269)
    let fr = schlick(coat_r0(IOR), 1.0);
    let k = 28.0 / 23.0 * (1.0 - coat_r0(IOR)) * as_factor(1.0) * as_factor(1.0) / (1.0 - fr);
    assert!((k - 28.0 / 23.0 * (31.0f32 / 32.0).powi(2)).abs() < 1e-6 && k > 1.14, "{k}");
}

/// A sky whose radiance depends on the elevation alone: a 4 x `h` OpenEXR
/// map, row r (v = r / (h − 1) = acos(y) / π) of radiance `row(r)`, in a
/// fresh folder of its own (removed by [`plate`] once laid out).
fn sky(name: &str, h: u32, row: impl Fn(u32) -> f32) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("warplight-coated-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp folder");
    let path = dir.join(format!("{name}.exr"));
    let pixels = (0..h).flat_map(|r| [[row(r); 3]; 4]).collect();
    FrameBuffer { width: 4, height: h, pixels }.write_exr(&path).expect("write the sky");
    path
}

/// The cap sky's rows: radiance 1 down to 60° from the zenith (v = 1/3, row
/// 100 of 301), 0 below; the lookup's bilinear ramp reaches 0 at row 101.
const CAP_ROWS: u32 = 301;
fn cap_row(r: u32) -> f32 {
    if r <= 100 { 1.0 } else { 0.0 }
}

/// The cap sky's radiance towards elevation cosine c, as the lookup
/// interpolates its rows.
fn cap_radiance(c: f64) -> f64 {
    let x = c.clamp(-1.0, 1.0).acos() / std::f64::consts::PI * (CAP_ROWS - 1) as f64;
    let (r, t) = (x.floor(), x - x.floor());
    cap_row(r as u32) as f64 * (1.0 - t) + cap_row(r as u32 + 1) as f64 * t
}

/// The plane y = 0 (±50, normal +y) in material 0, coated (IOR `IOR`, colour
/// `COLOR`), under `sky`, seen from 1 above it looking 26.6° down
/// with a 40° field: viewer cosines from about 0.12 to 0.73, the horizon
/// above the top row.
fn plate(sky: PathBuf) -> (PathScene, Camera) {
    let l = 50.0;
    let p = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    let tris = vec![
        Triangle { v: [p(-l, -l), p(-l, l), p(l, l)], material: 0 },
        Triangle { v: [p(-l, -l), p(l, l), p(l, -l)], material: 0 },
    ];
    let m = Material { name: "coated".into(), kind: MaterialKind::Diffuse, color: COLOR, emission: [0.0; 3] };
    let mut scene = Scene::assemble("coated-plate", std::path::Path::new("coated-plate"), tris, vec![m]);
    scene.coat = vec![Some(IOR)];
    scene.environment = Some(sky);
    let v: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let ps = PathScene::new(&scene, &build(&v, BuildParams::thesis(Heuristic::Sah))).expect("layout");
    assert_eq!(ps.mats[0][3].to_bits(), KIND_COATED);
    // the layout holds the map's texels: its folder (the sky's alone) can go
    if let Some(dir) = scene.environment.as_deref().and_then(|p| p.parent()) {
        let _ = std::fs::remove_dir_all(dir);
    }
    let cam = Camera {
        position: [0.0, 1.0, 0.0],
        direction: [0.0, -0.5, -1.0],
        up: [0.0, 1.0, 0.0],
        fov_y: 40.0,
        resolution: [SIZE, SIZE],
    };
    (ps, cam)
}

/// smallpt's tent warp (the kernel's `tent`), in f64.
fn tent(y: f64) -> f64 {
    let r = 2.0 * y;
    if r < 1.0 { r.sqrt() - 1.0 } else { 1.0 - (2.0 - r).sqrt() }
}

/// The expected image of the plate under the white sky: per pixel, the mean
/// over the 4 subpixels' tent-filtered footprints (16 x 16 points of the
/// tent's quantiles each) of `albedo(c)` at the viewer cosine c of the plate
/// where the ray meets it, 1 where it sees the sky.
fn expected(cam: &Camera, albedo: impl Fn(f64) -> [f64; 3]) -> Estimate {
    let (r, u, f) = cam.frame();
    let (r, u, f) = (r.as_dvec3(), u.as_dvec3(), f.as_dvec3());
    let tan = (cam.fov_y as f64).to_radians().mul_add(0.5, 0.0).tan();
    let n = 16;
    let mut img = FrameBuffer { width: SIZE, height: SIZE, pixels: vec![[0.0; 3]; (SIZE * SIZE) as usize] };
    for y in 0..SIZE {
        for x in 0..SIZE {
            let mut sum = [0.0f64; 3];
            for sub in 0..4 {
                for a in 0..n {
                    for b in 0..n {
                        let px = x as f64 + ((sub & 1) as f64 + 0.5 + tent((a as f64 + 0.5) / n as f64)) * 0.5;
                        let py = y as f64 + ((sub >> 1) as f64 + 0.5 + tent((b as f64 + 0.5) / n as f64)) * 0.5;
                        let cx = (px / SIZE as f64 * 2.0 - 1.0) * tan;
                        let cy = (1.0 - py / SIZE as f64 * 2.0) * tan;
                        let d = (f + r * cx + u * cy).normalize();
                        let v = if d.y < 0.0 { albedo(-d.y) } else { [1.0; 3] };
                        for c in 0..3 {
                            sum[c] += v[c];
                        }
                    }
                }
            }
            let k = (4 * n * n) as f64;
            img.pixels[(y * SIZE + x) as usize] = sum.map(|s| (s / k) as f32);
        }
    }
    // an exact reference: no variance, and degrees of freedom that leave the test to ours
    let e = from_frames(&[img.clone(), img], BLOCK).expect("two frames");
    Estimate { var: vec![0.0; e.var.len()], dof: 1e12, ..e }
}

/// The thesis' lobe under its coat: R(c) + C (1 − R0) g(c), Schlick's R with R0 of `IOR`.
fn coated_albedo(c: f64) -> [f64; 3] {
    let r0 = coat_r0(IOR) as f64;
    let fr = r0 + (1.0 - r0) * (1.0 - c).powi(5);
    let g = 1.0 - (1.0 - 0.5 * c).powi(5);
    COLOR.map(|k| fr + k as f64 * (1.0 - r0) * g)
}

/// The coated Lambertian: R(c) + (1 − R(c)) C.
fn lambert_albedo(c: f64) -> [f64; 3] {
    let r0 = coat_r0(IOR) as f64;
    let fr = r0 + (1.0 - r0) * (1.0 - c).powi(5);
    COLOR.map(|k| fr + (1.0 - fr) * k as f64)
}

#[test]
fn a_coated_plate_under_a_white_sky_reflects_the_analytic_albedo() {
    let (ps, cam) = plate(sky("white", 4, |_| 1.0));
    let exact = expected(&cam, coated_albedo);
    let lambert = expected(&cam, lambert_albedo);
    // the sky has no light sample, so every integrator is BSDF sampling here: pt
    let r = render_native(&ps, &cam, params(SIZE, Integrator::Pt, 11), 64, true, |_| {}).expect("render");
    let ours = from_frames(&r.frame_images, BLOCK).expect("frames");
    let o = welch_holm(&ours, &exact, ALPHA).expect("same grid");
    eprintln!("native against the analytic albedo: {o:?}");
    assert!(o.passed(), "the coated plate disagrees with its analytic albedo: {o:?}");
    assert!(o.mean_rel_diff.abs() < 0.005, "mean off by {}", o.mean_rel_diff);
    let wrong = welch_holm(&ours, &lambert, ALPHA).expect("same grid");
    eprintln!("native against the coated Lambertian: {wrong:?}");
    assert!(wrong.rejected > 50, "the coated Lambertian's albedo passed: {wrong:?}");
    // the emulated kernel, 8 frames
    let p = params(SIZE, Integrator::Pt, 12);
    let mut cfg = kernel::sim_config(&p);
    cfg.fidelity = Fidelity::Functional;
    let mut dev = Device::with_config(cfg);
    let module = kernel::load_for(&mut dev, kernel::KernelBuild::of(&p)).expect("load PTX");
    let r = kernel::render(&mut dev, &module, &ps, &cam, p, 8, true, |_| {}).expect("launch");
    let ours = from_frames(&r.image.frame_images, BLOCK).expect("frames");
    let o = welch_holm(&ours, &exact, ALPHA).expect("same grid");
    eprintln!("emulated against the analytic albedo: {o:?}");
    assert!(o.passed(), "the emulated coated plate disagrees with its analytic albedo: {o:?}");
}

fn cornell_coated(size: u32) -> (PathScene, Camera) {
    let (_, ps, cam) = scene_of("cornell-coated", size);
    let coated = ps.mats.iter().filter(|m| m[3].to_bits() == KIND_COATED).count();
    assert_eq!(coated, 3, "cornell-coated's white, red and green");
    (ps, cam)
}

/// nee's and mis' light samples evaluate the lobe and its pdf; pt samples it
/// only: the same image in expectation (pt's emission after a coat's mirror
/// reflection, a delta, counts in full under each).
#[test]
fn light_samples_and_bsdf_samples_of_the_lobe_agree() {
    let size = 16;
    let (ps, cam) = cornell_coated(size);
    let run = |integrator, seed, frames| {
        let r = render_native(&ps, &cam, params(size, integrator, seed), frames, true, |_| {}).expect("render");
        from_frames(&r.frame_images, BLOCK).expect("frames")
    };
    let pt = run(Integrator::Pt, 21, 768);
    for (integrator, seed) in [(Integrator::Nee, 22), (Integrator::MisBalance, 23), (Integrator::MisPower, 24)] {
        let o = welch_holm(&run(integrator, seed, 384), &pt, ALPHA).expect("same grid");
        eprintln!("{integrator:?} against pt: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with pt on the coated box: {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?}: mean off by {}", o.mean_rel_diff);
    }
}

/// The lobe's shape, not only its albedo: under a sky of radiance 1 within
/// 60° of the zenith and 0 below, the plate reflects R(c) L(c) (the coat's
/// mirror direction has the viewer's elevation) plus C (1 − R0) g(c) · 28/23
/// · 2 ∫ g(c') c' L(c') dc' (the lobe's g(cos_in) weighs the cap), 0.829 of
/// C (1 − R0) g(c) where a lobe of the same albedo shaped as Lambert's gives
/// 2 ∫ c' L dc' = 0.755 (a sharp cap: 0.824 and 0.75; the lookup's bilinear
/// ramp adds the rest). Ours passes the block test natively; the Lambert
/// shape fails it.
#[test]
fn under_a_sky_cap_the_lobe_weighs_the_incoming_cosine() {
    let (ps, cam) = plate(sky("cap", CAP_ROWS, cap_row));
    let n = 200_000;
    let quad = |f: &dyn Fn(f64) -> f64| (0..n).map(|k| f((k as f64 + 0.5) / n as f64)).sum::<f64>() / n as f64;
    let g = |c: f64| 1.0 - (1.0 - 0.5 * c).powi(5);
    let thesis = 28.0 / 23.0 * 2.0 * quad(&|c| g(c) * c * cap_radiance(c));
    let lambert = 2.0 * quad(&|c| c * cap_radiance(c));
    eprintln!("the cap's weight: the thesis' lobe {thesis:.4}, a Lambert-shaped one {lambert:.4}");
    // the sharp cap's 0.8244 and 0.75, plus the lookup's ramp below it (0.49 < c < 0.5)
    assert!((thesis - 0.8244).abs() < 6e-3 && (lambert - 0.75).abs() < 6e-3, "{thesis} {lambert}");
    let r0 = coat_r0(IOR) as f64;
    let albedo = |k: f64| {
        move |c: f64| {
            let fr = r0 + (1.0 - r0) * (1.0 - c).powi(5);
            COLOR.map(|x| fr * cap_radiance(c) + x as f64 * (1.0 - r0) * g(c) * k)
        }
    };
    let r = render_native(&ps, &cam, params(SIZE, Integrator::Pt, 13), 64, true, |_| {}).expect("render");
    let ours = from_frames(&r.frame_images, BLOCK).expect("frames");
    let o = welch_holm(&ours, &expected(&cam, albedo(thesis)), ALPHA).expect("same grid");
    eprintln!("native against the thesis' lobe under the cap: {o:?}");
    assert!(o.passed(), "the coated plate disagrees with its lobe under the cap: {o:?}");
    let wrong = welch_holm(&ours, &expected(&cam, albedo(lambert)), ALPHA).expect("same grid");
    eprintln!("native against a Lambert-shaped lobe of the same albedo: {wrong:?}");
    assert!(wrong.rejected > 20, "a Lambert-shaped lobe passed: {wrong:?}");
}
