//! Thesis 003's path tracer: the emulated kernel (`kernels/lin2017/path.cu`)
//! and the native mirror (`src/host/path/`) trace the same paths bit for bit;
//! the layout, traversal and estimators behave as derived by hand.

mod support;
use support::warplight;

use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::path::layout::PathScene;
use warplight::host::path::{FrameParams, Integrator, PixelSampling, Termination, Traversal, kernel, render_native};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::sim::Fidelity;

fn cornell() -> (Scene, PathScene) {
    load("cornell-lambert")
}

fn load(name: &str) -> (Scene, PathScene) {
    let scene = scene_file::load(&scene_file::resolve(name)).expect("a scene of scenes/");
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
    same_frames(cornell(), &Integrator::ALL);
}

/// The rough mirror (Cook-Torrance), rough glass (Walter), smooth mirror and
/// Lambertian kinds together: the kernel's shading equals the native one's
/// bit for bit, with light samples at the rough mirror (nee, mis-power) and
/// without (pt).
#[test]
fn every_material_kind_traces_the_same_bits_emulated_and_native() {
    let (scene, ps) = load("cornell-glossy");
    use warplight::host::path::layout::{KIND_CONDUCTOR, KIND_MIRROR, KIND_ROUGH_GLASS};
    let kinds: Vec<u32> = ps.mats.iter().map(|m| m[3].to_bits()).collect();
    for k in [KIND_CONDUCTOR, KIND_ROUGH_GLASS, KIND_MIRROR] {
        assert!(kinds.contains(&k), "cornell-glossy lacks kind {k}: {kinds:?}");
    }
    let alphas: Vec<f32> = ps.mats.iter().filter(|m| m[3].to_bits() == KIND_CONDUCTOR).map(|m| m[8]).collect();
    assert_eq!(alphas, [0.3], "the rough gold's alpha");
    same_frames((scene, ps), &[Integrator::Pt, Integrator::Nee, Integrator::MisPower]);
}

/// The anisotropic mirror (§5.1, the thesis' "Ward" lobe, path.cu's Aniso):
/// its sampling, D_aniso, the projected-roughness G and the light sample at
/// it trace the same bits emulated and native, under every integrator that
/// samples it (mlt's chains mutate its two random numbers too); and so does
/// the anisotropic rough glass (env-glass-anisotropic's frosted ball).
#[test]
fn the_anisotropic_mirror_traces_the_same_bits_emulated_and_native() {
    use warplight::host::path::layout::KIND_CONDUCTOR;
    let (scene, ps) = load("cornell-anisotropic");
    let lobes: Vec<[f32; 2]> =
        ps.mats.iter().filter(|m| m[3].to_bits() == KIND_CONDUCTOR).map(|m| [m[8], m[10]]).collect();
    assert_eq!(lobes, [[0.05, 0.4]], "the back wall's alpha_x and alpha_y");
    same_frames((scene, ps), &[Integrator::Pt, Integrator::Nee, Integrator::MisPower, Integrator::Mlt]);
    // and the anisotropic rough glass (Walter's refraction, the same sampling and G)
    use warplight::host::path::layout::KIND_ROUGH_GLASS;
    let (scene, ps) = load("env-glass-anisotropic");
    let lobes: Vec<[f32; 2]> =
        ps.mats.iter().filter(|m| m[3].to_bits() == KIND_ROUGH_GLASS).map(|m| [m[8], m[10]]).collect();
    assert_eq!(lobes, [[0.05, 0.4]], "the frosted ball's alpha_x and alpha_y");
    same_frames((scene, ps), &[Integrator::Pt, Integrator::MisPower]);
}

/// The thesis' coated diffuse (§4.5: the coat's Fresnel switch, Ashikhmin
/// and Shirley's lobe, its light sample; `scenes/cornell-coated.toml`):
/// the same bits emulated and native under every integrator (bdpt and mlt
/// connect through no coated vertex: it ends light subpaths, as a glossy one).
#[test]
fn the_coated_diffuse_traces_the_same_bits_emulated_and_native() {
    use warplight::host::path::layout::KIND_COATED;
    let (scene, ps) = load("cornell-coated");
    let iors: Vec<f32> = ps.mats.iter().filter(|m| m[3].to_bits() == KIND_COATED).map(|m| m[7]).collect();
    assert_eq!(iors, [1.5; 3], "the coats' IOR");
    let mut all = Integrator::ALL.to_vec();
    all.extend([Integrator::Bdpt, Integrator::Mlt]);
    same_frames((scene, ps), &all);
}

/// Bidirectional path tracing (`bdpt_frame`): the light subpath, the
/// connections and the uniform weights trace the same bits emulated and
/// native, on the Lambertian box and on the glossy one, whose mirror, glass
/// and rough metal end light subpaths and are never connected through
/// (delta and glossy BSDFs in connections): finite, non-negative values.
#[test]
fn bdpt_traces_the_same_bits_emulated_and_native() {
    same_frames(cornell(), &[Integrator::Bdpt]);
    same_frames(load("cornell-glossy"), &[Integrator::Bdpt]);
}

/// Metropolis light transport (`mlt_init`, `mlt_start`, `mlt_frame`): the chains' start,
/// b, every splat (64-bit fixed-point atomics) and each frame's image are the
/// same bits emulated and native, on the Lambertian box and on the glossy one,
/// at the default 16 bounces and at 3 (a shorter state, k = 4).
#[test]
fn mlt_traces_the_same_bits_emulated_and_native() {
    use warplight::host::path::mlt;
    same_frames(cornell(), &[Integrator::Mlt]);
    for (name, max_bounces) in [("cornell-lambert", 3), ("cornell-glossy", 16)] {
        let (scene, ps) = load(name);
        let (w, h) = (12, 10);
        let cam = camera(&scene, w, h);
        let p = FrameParams {
            width: w,
            height: h,
            integrator: Integrator::Mlt,
            max_bounces,
            seed: 4,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        };
        let native = mlt::render_native(&ps, &cam, p, 2, true, |_| {}).expect("settings");
        let (mut dev, module) = kernel::device(&p, Fidelity::Functional).expect("load PTX");
        let emu = mlt::render_emulated(&mut dev, &module, &ps, &cam, p, 2, true, |_| {}).expect("launch");
        assert!(native.b > 0.0, "{name}: b = {}", native.b);
        assert_eq!(native.b.to_bits(), emu.b.to_bits(), "{name}: b");
        assert_eq!(native.fixed, emu.fixed, "{name}: the fixed-point image");
        assert_eq!(native.image.frame_images, emu.image.frame_images, "{name}: the frames");
        assert!(native.fixed.iter().filter(|&&v| v > 0).count() > native.fixed.len() / 2, "{name}: splats missing");
        // the allocation's size: the host's formula (the kernels' footprint: tests/lin2017_mlt_state.rs)
        assert_eq!(emu.state_bytes, 40 * (max_bounces as u64 + 1) * (w * h) as u64, "{name}: 40 k W H allocated");
    }
}

/// bdpt at most 1 bounce is direct light only, whose techniques are the eye
/// path hitting the light (weight 1/2 after a Lambertian bounce) and the
/// connection to the light point y0 (1/2); the same pixels at 0 bounces see
/// only the light itself, weight 1, as every other integrator. The means
/// show unbiasedness only (any split has nee's mean); the 1/2 + 1/2 split
/// is checked by the variance in `tests/bdpt_weights.rs`.
#[test]
fn bdpt_weights_a_direct_path_by_its_two_techniques() {
    let (scene, ps) = cornell();
    let (w, h) = (12, 10);
    let cam = camera(&scene, w, h);
    let run = |integrator, max_bounces, seed| {
        let p = FrameParams::new(w, h, integrator, max_bounces, seed);
        render_native(&ps, &cam, p, 1, false, |_| {}).expect("render").accum
    };
    assert_eq!(run(Integrator::Bdpt, 0, 5), run(Integrator::Pt, 0, 5), "0 bounces: the light seen directly");
    // 1 bounce, many frames: bdpt's mean equals nee's (both unbiased for direct light)
    let mean = |integrator| {
        let p = FrameParams {
            width: w,
            height: h,
            integrator,
            max_bounces: 1,
            seed: 9,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        };
        let r = render_native(&ps, &cam, p, 64, false, |_| {}).expect("render");
        r.accum.iter().map(|&v| v as f64).sum::<f64>() / 64.0
    };
    let (b, n) = (mean(Integrator::Bdpt), mean(Integrator::Nee));
    assert!((b / n - 1.0).abs() < 0.02, "direct light: bdpt {b} vs nee {n}");
}

/// The environment-lit scene (no area light; a diffuse and a mirror ball
/// under the forest map): the kernel's lookup of the map equals the native
/// one's bit for bit, whatever the integrator (none samples the map).
#[test]
fn the_environment_map_traces_the_same_bits_emulated_and_native() {
    let (scene, ps) = load("env-spheres");
    let env = ps.env.as_ref().expect("env-spheres has an environment");
    assert_eq!((env.width, env.height, ps.lights.len()), (128, 64, 0));
    same_frames((scene, ps), &[Integrator::Pt, Integrator::MisPower]);
}

/// Glass with the exact Fresnel equations (`fresnel = "exact"`), rough and
/// smooth, under the environment: emulated and native agree bit for bit.
#[test]
fn exact_fresnel_glass_traces_the_same_bits_emulated_and_native() {
    let (scene, ps) = load("env-glass");
    assert_eq!(ps.mats.iter().filter(|m| m[9] > 0.0).count(), 2, "two exact-Fresnel glasses");
    same_frames((scene, ps), &[Integrator::Pt, Integrator::MisPower]);
}

fn same_frames((scene, ps): (Scene, PathScene), integrators: &[Integrator]) {
    let (w, h) = (12, 10);
    let cam = camera(&scene, w, h);
    for &integrator in integrators {
        let params = FrameParams {
            width: w,
            height: h,
            integrator,
            max_bounces: 16,
            seed: 3,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        };
        let native = render_native(&ps, &cam, params, 2, true, |_| {}).expect("render");
        let (mut dev, module) = kernel::device(&params, Fidelity::Functional).expect("load PTX");
        let emu = kernel::render(&mut dev, &module, &ps, &cam, params, 2, true, |_| {}).expect("launch");
        let diff = native.accum.iter().zip(&emu.image.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        assert_eq!(diff, 0, "{integrator:?}: {diff} of {} accumulated values differ", native.accum.len());
        assert_eq!(native.frame_images, emu.image.frame_images, "{integrator:?}");
        let sum: f32 = native.accum.iter().sum();
        assert!(sum > 0.0, "{integrator:?}: a black image");
        let bad = native.accum.iter().filter(|v| !v.is_finite() || **v < 0.0).count();
        assert_eq!(bad, 0, "{integrator:?}: {bad} values NaN, infinite or negative");
    }
}

/// `warplight render --method path --scene cornell-lambert --resolution 8x6` and `extra`.
fn render_path(extra: &[&str]) -> (bool, String, String) {
    let mut args = vec!["render", "--method", "path", "--scene", "cornell-lambert", "--resolution", "8x6"];
    args.extend_from_slice(extra);
    warplight(&args)
}

#[test]
fn render_takes_each_traversal_and_names_a_wrong_one() {
    let dir = std::env::temp_dir().join(format!("warplight-lin2017-traversal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    for t in ["stack", "restart", "backtrack"] {
        let out = dir.join(format!("{t}.exr"));
        let (ok, stdout, stderr) =
            render_path(&["--spp", "4", "--traversal", t, "-o", out.to_str().expect("utf-8 path")]);
        assert!(ok, "--traversal {t}: {stderr}");
        let name = if t == "stack" { "short-stack" } else { t };
        assert!(stdout.contains(&format!("({name} traversal, roulette)")), "--traversal {t}: {stdout}");
        assert!(out.exists(), "--traversal {t}: no image");
    }
    let (ok, _, stderr) = render_path(&["--traversal", "bvh"]);
    assert!(!ok && stderr.contains("unknown traversal `bvh`"), "{stderr}");
    let out = dir.join("bdpt.exr");
    let (ok, stdout, stderr) =
        render_path(&["--spp", "4", "--integrator", "bdpt", "-o", out.to_str().expect("utf-8 path")]);
    assert!(ok && stdout.contains("path tracer bdpt") && out.exists(), "--integrator bdpt: {stdout} {stderr}");
    let out = dir.join("mlt.exr");
    let (ok, stdout, stderr) =
        render_path(&["--spp", "4", "--integrator", "mlt", "-o", out.to_str().expect("utf-8 path")]);
    assert!(ok && stdout.contains("path tracer mlt") && out.exists(), "--integrator mlt: {stdout} {stderr}");
    let (ok, _, stderr) = render_path(&["--integrator", "metropolis"]);
    assert!(!ok && stderr.contains("unknown integrator `metropolis`") && stderr.contains("mlt"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The path tracer's scene keys are checked: `fresnel` only on glass and
/// only "schlick" or "exact", `environment` an existing file, and a scene
/// with neither an area light nor an environment is refused by the layout.
#[test]
fn environment_and_fresnel_keys_are_checked() {
    let dir = std::env::temp_dir().join(format!("warplight-lin2017-keys-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(dir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("obj");
    let scene = |extra: &str, mat: &str| {
        let f = dir.join("t.toml");
        std::fs::write(&f, format!("obj = \"t.obj\"\n{extra}\n[[material]]\nname = \"m\"\n{mat}\n")).expect("toml");
        scene_file::load(&f)
    };
    let err = |r: Result<Scene, scene_file::SceneError>| r.err().map(|e| e.to_string()).unwrap_or_default();
    let e = err(scene("", "kind = \"diffuse\"\nfresnel = \"exact\""));
    assert!(e.contains("material[0].fresnel") && e.contains("only glass"), "{e}");
    let e = err(scene("", "kind = \"glass\"\nfresnel = \"fast\""));
    assert!(e.contains("expected \"schlick\" or \"exact\""), "{e}");
    let e = err(scene("environment = \"nowhere.exr\"", "kind = \"diffuse\""));
    assert!(e.contains("environment") && e.contains("no such file"), "{e}");
    let s = scene("", "kind = \"glass\"\nfresnel = \"exact\"").expect("an exact glass");
    assert_eq!(s.exact_fresnel, [true]);
    let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    let e = PathScene::new(&s, &tree).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e.contains("no emitting triangle and no environment"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Fig. 8 (003:L305): the light turned to the ceiling (`cornell-inverted`),
/// 100 frames: bdpt's noise is well below nee's. Noise is measured without a
/// reference (every estimator is heavy-tailed here: 2,000-frame means of one
/// integrator differ by 3x between seeds for nee): the RMS difference of two
/// independent renders (√2 σ), relative to their mean.
#[test]
fn fig_8_bdpt_beats_nee_under_the_inverted_light() {
    let (scene, ps) = load("cornell-inverted");
    let (w, h) = (16, 16);
    let cam = camera(&scene, w, h);
    let image = |integrator, seed| {
        let p = FrameParams {
            width: w,
            height: h,
            integrator,
            max_bounces: 16,
            seed,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        };
        render_native(&ps, &cam, p, 100, false, |_| {}).expect("render").image().pixels
    };
    let spread = |integrator| {
        let (a, b) = (image(integrator, 1), image(integrator, 2));
        let n = (3 * a.len()) as f64;
        let d: f64 = a.iter().zip(&b).flat_map(|(x, y)| (0..3).map(move |c| (x[c] as f64 - y[c] as f64).powi(2))).sum();
        let m: f64 = a.iter().chain(&b).flatten().map(|&v| v as f64).sum::<f64>() / (2.0 * n);
        ((d / n).sqrt() / m, m)
    };
    let ((eb, mb), (en, mn)) = (spread(Integrator::Bdpt), spread(Integrator::Nee));
    eprintln!(
        "fig 8: relative rms difference of two 100-frame renders: bdpt {eb:.4} (mean {mb:.5}), nee {en:.4} (mean {mn:.5})"
    );
    assert!(eb < 0.75 * en, "bdpt {eb} not below nee {en}");
}
