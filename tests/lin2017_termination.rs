//! The path tracer's two endings (§4.5, 003:L267-271): the thesis' Russian
//! roulette (`kernels/lin2017/path.cu`) and the fixed depth that 003:L269
//! compares it with (`kernels/lin2017/path_fixed_depth.cu`, the same source
//! built with `PATH_FIXED_DEPTH`). The fixed-depth build runs bit for bit
//! as its native twin, traces exactly max bounces + 1 rays a path in a closed
//! box of mirrors, is unbiased against Mitsuba 3, and a module of the other
//! build is refused rather than silently rendering the wrong ending.

#[allow(dead_code)]
mod lin2017_mitsuba;

use std::path::Path;

use lin2017_mitsuba::{native_outcome, params, reference_of, scene_of, warplight};
use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::path::kernel::KernelBuild;
use warplight::host::path::layout::PathScene;
use warplight::host::path::{
    FrameParams, Integrator, PixelSampling, Termination, kernel, regroup, render_native, wavefront,
};
use warplight::repro::lin2017::runs;
use warplight::sim::{Device, Fidelity};

fn fixed(p: FrameParams) -> FrameParams {
    FrameParams { termination: Termination::FixedDepth, ..p }
}

#[test]
fn the_fixed_depth_build_runs_as_its_native_twin() {
    let (_, ps, cam) = scene_of("cornell-lambert", 8);
    for integrator in [Integrator::Pt, Integrator::Nee, Integrator::MisPower, Integrator::Bdpt] {
        let p = fixed(params(8, integrator, 5));
        let t = runs::emulate_twin(&ps, &cam, p, 2).expect("render");
        assert!(t.same, "{integrator:?}: the fixed-depth build differs from its native twin");
        // the roulette's random numbers are drawn by neither: where no roulette runs, the builds agree
        let no_bounce = |t| {
            let p = FrameParams { max_bounces: 0, termination: t, ..params(8, integrator, 5) };
            render_native(&ps, &cam, p, 1, false, |_| {}).expect("render").accum
        };
        assert_eq!(no_bounce(Termination::Roulette), no_bounce(Termination::FixedDepth), "{integrator:?}");
        let roulette = render_native(&ps, &cam, params(8, integrator, 5), 2, false, |_| {}).expect("render");
        assert_ne!(roulette.accum, t.emulated.image.accum, "{integrator:?}: the two builds made the same image");
    }
    // the other entry points: the march through a medium, the translucent
    // walk, the textures (nee), and MLT's chains
    for (scene, integrator) in [
        ("fog-box", Integrator::Nee),
        ("sss-balls", Integrator::Nee),
        ("cornell-scratched", Integrator::Nee),
        ("cornell-lambert", Integrator::Mlt),
    ] {
        let (_, ps, cam) = scene_of(scene, 4);
        let p = fixed(params(4, integrator, 6));
        let t = runs::emulate_twin(&ps, &cam, p, 2).expect("render");
        assert!(t.same, "{scene} {integrator:?}: the fixed-depth build differs from its native twin");
        let roulette = render_native(&ps, &cam, params(4, integrator, 6), 2, false, |_| {}).expect("render");
        assert_ne!(
            roulette.accum, t.emulated.image.accum,
            "{scene} {integrator:?}: the two builds made the same image"
        );
    }
}

#[test]
fn fixed_depth_paths_cost_more_warp_instructions() {
    let (_, ps, cam) = scene_of("cornell-lambert", 8);
    let warps = |p: FrameParams| runs::emulate_twin(&ps, &cam, p, 1).expect("render").emulated.totals.warp_instructions;
    let (r, f) = (warps(params(8, Integrator::Nee, 3)), warps(fixed(params(8, Integrator::Nee, 3))));
    // the box's albedo is at most 0.725: a roulette path of nee ends after a few bounces, not 16
    assert!(f > 2 * r, "fixed depth {f} warp instructions against roulette's {r}");
}

/// A closed cube of 12 inward-facing triangles, all one material, and
/// outside it a lamp (the layout wants a light) that no path inside can reach.
const CUBE: &str = "g lamp
v 3 3 3
v 4 3 3
v 3 4 3
f 1 2 3
g walls
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 4 5 6
f 4 6 7
f 8 11 10
f 8 10 9
f 4 8 9
f 4 9 5
f 7 6 10
f 7 10 11
f 4 7 11
f 4 11 8
f 5 9 10
f 5 10 6
";

fn mirror_cube(dir: &Path, color: f32) -> (PathScene, Camera) {
    std::fs::create_dir_all(dir).expect("temp dir");
    std::fs::write(dir.join("cube.obj"), CUBE).expect("write obj");
    let toml = format!(
        "name = \"mirror-cube\"\nobj = \"cube.obj\"\n[[material]]\nname = \"m\"\nkind = \"mirror\"\n\
         color = [{color}, {color}, {color}]\n[[override]]\ngroup = \"walls\"\nmaterial = \"m\"\n\
         [[material]]\nname = \"lamp\"\nkind = \"emitter\"\ncolor = [1.0, 1.0, 1.0]\nemission = [1.0, 1.0, 1.0]\n\
         [[override]]\ngroup = \"lamp\"\nmaterial = \"lamp\"\n[[light]]\nkind = \"area\"\n[camera]\nposition = [0.1, 0.2, 0.3]\ndirection = [0.3, -0.2, -1.0]\nfov = 60.0\nresolution = [4, 4]\n"
    );
    let file = dir.join("mirror-cube.toml");
    std::fs::write(&file, toml).expect("write scene");
    let scene = warplight::host::scene_file::load(&file).expect("the cube loads");
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    (PathScene::new(&scene, &tree).expect("layout"), scene.camera)
}

#[test]
fn in_a_closed_box_of_mirrors_every_fixed_depth_path_traces_max_bounces_plus_one_rays() {
    let dir = std::env::temp_dir().join(format!("warplight-termination-{}", std::process::id()));
    let max_bounces = 9;
    let rays = |ps: &PathScene, cam: &Camera, t: Termination| {
        let p = FrameParams { max_bounces, termination: t, ..params(4, Integrator::Pt, 2) };
        let r = render_native(ps, cam, p, 1, false, |_| {}).expect("render");
        (r.counts.rays, p.paths() as u64)
    };
    // half-silvered walls: roulette ends some paths (q = 0.5), the fixed depth none
    let (ps, cam) = mirror_cube(&dir.join("half"), 0.5);
    let (r, paths) = rays(&ps, &cam, Termination::Roulette);
    let (f, _) = rays(&ps, &cam, Termination::FixedDepth);
    assert_eq!(f, paths * (max_bounces as u64 + 1), "fixed depth");
    assert!(r < paths * 3, "roulette at q = 0.5 traced {r} rays for {paths} paths (about 2 a path expected)");
    // the emulated kernel's `@count` lines count as many
    let p = FrameParams { max_bounces, termination: Termination::FixedDepth, ..params(4, Integrator::Pt, 2) };
    let (mut dev, module) = kernel::device(&p, Fidelity::Instructions).expect("load PTX");
    let k = kernel::render(&mut dev, &module, &ps, &cam, p, 1, false, |_| {}).expect("launch");
    assert_eq!(k.counts.expect("counted").rays, f);
    // perfect mirrors: q = 1, so the roulette never ends a path either
    let (ps, cam) = mirror_cube(&dir.join("perfect"), 1.0);
    assert_eq!(rays(&ps, &cam, Termination::Roulette).0, paths * (max_bounces as u64 + 1), "roulette, q = 1");
    std::fs::remove_dir_all(&dir).ok();
}

/// Russian roulette's tests as the emulator counts them (`@count` on
/// `roulette()`'s two tests; `counts::Roulettes`), against hand-derived
/// truths: in a closed box of perfect mirrors every path tests 9 times at 9
/// bounces, always with q = 1 (none below one); with half-silvered walls every
/// test has q = 0.5, and each survivor traces one more ray, so the tests lie
/// between the bounce rays and all rays; the fixed-depth build has none; the
/// Lambertian box (albedos below 1) has no q of 1 or more, the rough-mirror
/// box has (003:L269's "always less than or equal to 1" fails there), and so
/// has the coated box (its coat's mirror branch, q = 1).
#[test]
fn the_emulator_counts_roulettes_tests_and_the_masks_of_one_or_more() {
    use warplight::host::path::counts::Roulettes;
    let dir = std::env::temp_dir().join(format!("warplight-roulettes-{}", std::process::id()));
    let max_bounces = 9;
    let emulate = |ps: &PathScene, cam: &Camera, p: FrameParams| {
        let (mut dev, module) = kernel::device(&p, Fidelity::Instructions).expect("load PTX");
        let k = kernel::render(&mut dev, &module, ps, cam, p, 1, false, |_| {}).expect("launch");
        (k.roulettes.expect("counted"), k.counts.expect("counted").rays)
    };
    let p = FrameParams { max_bounces, ..params(4, Integrator::Pt, 2) };
    let paths = p.paths() as u64;
    let (ps, cam) = mirror_cube(&dir.join("perfect"), 1.0);
    let (q, _) = emulate(&ps, &cam, p);
    assert_eq!(q, Roulettes { tests: paths * max_bounces as u64, below_one: 0 }, "perfect mirrors");
    let (q, _) = emulate(&ps, &cam, fixed(p));
    assert_eq!(q.tests, 0, "the fixed-depth build has no roulette");
    let (ps, cam) = mirror_cube(&dir.join("half"), 0.5);
    let (q, rays) = emulate(&ps, &cam, p);
    assert_eq!(q.at_or_above_one(), 0, "q = 0.5");
    assert!(rays - paths <= q.tests && q.tests <= rays && q.tests > 0, "{q:?}, {rays} rays of {paths} paths");
    std::fs::remove_dir_all(&dir).ok();
    // the coated box: its coat's mirror reflection has q = 1 (as a perfect mirror)
    for (scene, above) in [("cornell-lambert", false), ("cornell-rough", true), ("cornell-coated", true)] {
        let (_, ps, cam) = scene_of(scene, 16);
        let (q, _) = emulate(&ps, &cam, params(16, Integrator::Nee, 3));
        eprintln!("{scene}: {q:?}");
        assert!(q.tests > 1000 && (q.at_or_above_one() > q.tests / 50) == above, "{scene}: {q:?}");
        if !above {
            assert_eq!(q.at_or_above_one(), 0, "{scene}: every albedo is below 1");
        }
    }
}

/// Every build of the kernel refuses frames that need another (the thesis',
/// the fixed depth, stratified pixels), in each entry point that takes the
/// module as given: the megakernel, the wavefront form and the regroup.
#[test]
fn a_module_of_another_build_is_refused() {
    let (_, ps, cam) = scene_of("cornell-lambert", 4);
    let params_for = |b: KernelBuild| {
        let p = params(4, Integrator::Nee, 1);
        match b {
            KernelBuild::Thesis => p,
            KernelBuild::FixedDepth => FrameParams { termination: Termination::FixedDepth, ..p },
            KernelBuild::Stratified => FrameParams { pixels: PixelSampling::Stratified(2), ..p },
        }
    };
    for loaded in KernelBuild::ALL {
        for asked in KernelBuild::ALL.into_iter().filter(|&b| b != loaded) {
            let p = params_for(asked);
            assert_eq!(KernelBuild::of(&p), asked);
            let mut dev = Device::with_config(kernel::sim_config(&p));
            let module = kernel::load_for(&mut dev, loaded).expect("load PTX");
            assert_eq!(KernelBuild::of_module(&module), loaded);
            let e = kernel::render(&mut dev, &module, &ps, &cam, p, 1, false, |_| {}).expect_err("refused");
            assert!(e.to_string().contains(asked.name()) && e.to_string().contains(loaded.name()), "{e}");
            // the wavefront form and the regroup, which take the module as given
            let (mut dev, _, compact) = wavefront::device(&p, Fidelity::Functional).expect("load PTX");
            let other = kernel::load_for(&mut dev, loaded).expect("load PTX");
            let e =
                wavefront::render(&mut dev, &other, &compact, &ps, &cam, p, 1, wavefront::Mode::Normal, false, |_| {})
                    .expect_err("refused");
            assert!(e.to_string().contains(asked.name()), "{e}");
            let e = regroup::render(&mut dev, &other, &compact, &ps, &cam, p, 1, regroup::Mode::Normal, false, |_| {})
                .expect_err("refused");
            assert!(e.to_string().contains(asked.name()), "{e}");
        }
    }
}

/// Both endings are unbiased: the fixed depth agrees with Mitsuba 3 (the
/// per-block Welch test under Holm) as the roulette does
/// (`tests/lin2017_reference.rs`, which also shows that a ten percent
/// brighter light fails the same test).
#[test]
fn the_fixed_depth_agrees_with_mitsuba() {
    let (reference, size, _) = reference_of("tests/fixtures/mitsuba/cornell-lambert-32");
    let (_, ps, cam) = scene_of("cornell-lambert", size);
    for (k, integrator) in [Integrator::Pt, Integrator::Nee].into_iter().enumerate() {
        let o = native_outcome(&ps, &cam, fixed(params(size, integrator, 600 + k as u32)), 96, &reference);
        eprintln!("{integrator:?} fixed depth: {o:?}");
        assert!(o.passed(), "{integrator:?} at a fixed depth disagrees with Mitsuba: {o:?}");
    }
}

#[test]
fn render_takes_a_termination_and_names_a_wrong_one() {
    let out = std::env::temp_dir().join(format!("warplight-termination-{}.exr", std::process::id()));
    let o = out.to_str().expect("utf-8 path");
    let base = ["render", "--method", "path", "--scene", "cornell-lambert", "--resolution", "8x6", "--spp", "4"];
    for variant in ["native", "emulated"] {
        let mut args = base.to_vec();
        args.extend(["--termination", "fixed-depth", "--variant", variant, "-o", o]);
        let (ok, stdout, stderr) = warplight(&args);
        assert!(ok, "{variant}: {stderr}");
        assert!(stdout.contains("(short-stack traversal, fixed-depth)"), "{variant}: {stdout}");
        assert!(out.exists(), "{variant}: no image");
        std::fs::remove_file(&out).ok();
    }
    let mut args = base.to_vec();
    args.extend(["--termination", "never", "-o", o]);
    let (ok, _, stderr) = warplight(&args);
    assert!(!ok && stderr.contains("unknown termination `never`"), "{stderr}");
    let (ok, _, stderr) = warplight(&["render", "--scene", "cornell-lambert", "--termination", "fixed-depth", "-o", o]);
    assert!(!ok && stderr.contains("--termination applies to --method path only"), "{stderr}");
    assert!(!out.exists());
}

/// `render --variant emulated` prints the roulette's tests when the fidelity
/// counts instructions (the default), and not at `functional`.
#[test]
fn render_prints_the_roulettes_tests() {
    let out = std::env::temp_dir().join(format!("warplight-roulette-line-{}.exr", std::process::id()));
    let o = out.to_str().expect("utf-8 path");
    let base = ["render", "--method", "path", "--variant", "emulated", "--scene", "cornell-rough"];
    let mut args = base.to_vec();
    args.extend(["--resolution", "8x8", "--spp", "4", "-o", o]);
    let (ok, stdout, stderr) = warplight(&args);
    assert!(ok, "{stderr}");
    let line = stdout.lines().find(|l| l.contains("Russian roulette: ")).unwrap_or_else(|| panic!("{stdout}"));
    assert!(line.contains(" tests, ") && line.contains("1 or more") && line.contains("003:L269"), "{line}");
    args.extend(["--fidelity", "functional"]);
    let (ok, stdout, stderr) = warplight(&args);
    assert!(ok, "{stderr}");
    assert!(!stdout.contains("Russian roulette"), "{stdout}");
    std::fs::remove_file(&out).ok();
}

/// At a fixed depth every path runs to the longest path, so the emulator's
/// watchdog grows with the bounces past the default 16 (a long fixed-depth
/// render is not stopped as runaway); the roulette build's stays.
#[test]
fn the_watchdog_grows_with_a_fixed_depth() {
    let budget = |t, max_bounces| {
        // 512 x 512: a budget past the simulator's default one
        let p = FrameParams { max_bounces, termination: t, ..params(512, Integrator::Nee, 1) };
        kernel::sim_config(&p).schedule.max_warp_instructions
    };
    assert_eq!(budget(Termination::FixedDepth, 16), budget(Termination::Roulette, 16));
    assert_eq!(budget(Termination::Roulette, 200), budget(Termination::Roulette, 16));
    assert_eq!(budget(Termination::FixedDepth, 200), 12 * budget(Termination::Roulette, 200));
    // and such a render runs: 100 bounces in the closed cube of mirrors
    let dir = std::env::temp_dir().join(format!("warplight-termination-watchdog-{}", std::process::id()));
    let (ps, cam) = mirror_cube(&dir, 1.0);
    let p = FrameParams { max_bounces: 100, termination: Termination::FixedDepth, ..params(4, Integrator::Pt, 2) };
    let t = runs::emulate_twin(&ps, &cam, p, 1).expect("not stopped by the watchdog");
    assert!(t.same);
    std::fs::remove_dir_all(&dir).ok();
}
