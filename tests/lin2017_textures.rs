//! Thesis 003's texture maps (§5.4, Fig. 13 lower): albedo, roughness and
//! metalness maps on the Cornell box's back wall (`scenes/cornell-scratched.toml`,
//! the generated maps of `scenes/scratched-metal/`), shaded by the metalness
//! workflow (`texture_hit` in `kernels/lin2017/path.cu`). The emulated
//! `texture_frame` and the native mirror trace the same bits; the loader's
//! errors name the file and line; against Mitsuba 3 (`blendbsdf` of
//! `diffuse` and `roughconductor` over nearest `bitmap`s,
//! `tests/fixtures/mitsuba/cornell-scratched-white-32`, the metal white so that
//! Schlick's F is Mitsuba's) native and emulated renders pass the per-block
//! Welch t-test under Holm's correction, and the maps mirrored or shifted fail it.

mod lin2017_mitsuba;

use lin2017_mitsuba::{emulated_frames_outcome, native_outcome, params, reference_of, reference_samples, scene_of};
use warplight::host::camera::Camera;
use warplight::host::path::layout::{KIND_CONDUCTOR, KIND_DIFFUSE, KIND_TEXTURED, PathScene, ROUGHNESS_LEVELS};
use warplight::host::path::{
    FrameParams, Integrator, PixelSampling, SAMPLES_PER_FRAME, Termination, Traversal, kernel, render_native,
};
use warplight::host::scene_file;
use warplight::sim::{Device, Fidelity};

const FIXTURE: &str = "tests/fixtures/mitsuba/cornell-scratched-white-32";
/// Frames of a native render against the reference (4 paths a pixel each).
const FRAMES: u32 = 256;
/// Frames of the emulated render against the reference.
const EMULATED_FRAMES: u32 = 16;

/// The general metalness workflow (coloured metal: R0 = lerp(white, albedo, m)
/// below 1): pt, nee and mis-power trace the same bits emulated and native
/// (12 x 10 pixels, 2 frames), and the maps change the image.
#[test]
fn textured_frames_equal_native_frames_bit_for_bit() {
    let (scene, ps, _) = scene_of("cornell-scratched", 12);
    let m = scene.materials.iter().position(|m| m.name == "scratched").expect("the wall's material");
    assert_eq!(ps.mats[m][3].to_bits(), KIND_TEXTURED);
    let t = ps.textures.as_ref().expect("maps");
    let rows = t.mats[m][3] as usize;
    assert_eq!(ps.mats.len(), rows + ROUGHNESS_LEVELS, "one conductor row per roughness level");
    assert_eq!((ps.mats[rows][8], ps.mats[rows + 51][8], ps.mats[rows + 255][8]), (1e-4, 0.2, 1.0));
    assert!(ps.mats[rows..].iter().all(|r| r[3].to_bits() == KIND_CONDUCTOR));
    let cam = Camera { resolution: [12, 10], ..scene.camera };
    for integrator in [Integrator::Pt, Integrator::Nee, Integrator::MisPower] {
        let p = FrameParams {
            width: 12,
            height: 10,
            integrator,
            max_bounces: 16,
            seed: 3,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        };
        let native = render_native(&ps, &cam, p, 2, true, |_| {}).unwrap();
        let mut cfg = kernel::sim_config(&p);
        cfg.fidelity = Fidelity::Functional;
        let mut dev = Device::with_config(cfg);
        let module = kernel::load(&mut dev).expect("load PTX");
        assert_eq!(kernel::entry_for(&ps, integrator), kernel::TEXTURE_KERNEL);
        let emu = kernel::render(&mut dev, &module, &ps, &cam, p, 2, true, |_| {}).expect("launch");
        let diff = native.accum.iter().zip(&emu.image.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        assert_eq!(diff, 0, "{integrator:?}: {diff} of {} accumulated values differ", native.accum.len());
        assert_eq!(native.frame_images, emu.image.frame_images, "{integrator:?}");
        assert!(native.accum.iter().all(|v| v.is_finite() && *v >= 0.0), "{integrator:?}: NaN or negative");
        assert!(native.accum.iter().sum::<f32>() > 0.0, "{integrator:?}: black");
    }
    // the maps change the image: the same box with the wall untextured differs
    let mut plain = ps.clone();
    plain.mats[m][3] = f32::from_bits(KIND_DIFFUSE);
    let p = FrameParams {
        width: 12,
        height: 10,
        integrator: Integrator::Nee,
        max_bounces: 16,
        seed: 3,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    };
    let (a, b) = (
        render_native(&ps, &cam, p, 2, false, |_| {}).unwrap(),
        render_native(&plain, &cam, p, 2, false, |_| {}).unwrap(),
    );
    assert_ne!(a.accum, b.accum);
}

/// The planar mapping puts the wall's corners at the mapping's (u, v): hand-derived
/// from the OBJ's back wall (x from -0.99 to 1.00 and y from 0 to 1.99 at z = -1.04).
#[test]
fn the_planar_mapping_spans_the_wall() {
    let scene = scene_file::load(&scene_file::resolve("cornell-scratched")).expect("scene");
    let m = scene.materials.iter().position(|m| m.name == "scratched").expect("material") as u32;
    let s = scene.surface(m);
    assert!(s.texture.is_some() && s.roughness_map.is_some() && s.metalness_map.is_some());
    assert_eq!(scene.uvs.len(), scene.triangles.len());
    let mut corners = Vec::new();
    for (k, t) in scene.triangles.iter().enumerate().filter(|(_, t)| t.material == m) {
        for (v, uv) in t.v.iter().zip(scene.uv(k as u32)) {
            let want = [(v.x + 1.02) * 0.495, v.y * 0.5025];
            assert!((uv[0] - want[0]).abs() < 1e-6 && (uv[1] - want[1]).abs() < 1e-6, "{v:?}: {uv:?}");
            corners.push(uv);
        }
    }
    assert_eq!(corners.len(), 6, "the wall's two triangles");
    assert!(corners.iter().all(|c| (0.0..=1.0).contains(&c[0]) && (0.0..=1.0).contains(&c[1])));
    // the albedo texel of the wall's lower left corner is thesis 000's lookup of the same map
    let tex = &scene.textures[s.texture.expect("albedo") as usize];
    assert_eq!((tex.width, tex.height), (256, 256));
    assert_eq!(tex.texel(0.01, 0.01), tex.texels[253 * 256 + 2]);
}

fn write_scene(name: &str, body: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("warplight-textures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let f = dir.join(format!("{name}.toml"));
    let text = body.replace("SCENES", &scenes.display().to_string());
    std::fs::write(&f, text).expect("write scene");
    f
}

/// A missing map, a textured material without texture coordinates and a
/// roughness map without the metal lobe are typed errors naming the file,
/// the key and its line; bdpt and mlt refuse a textured scene.
#[test]
fn map_errors_name_the_file_and_line() {
    let head = "name = \"t\"\nobj = \"SCENES/cornell-box/CornellBox-Original.obj\"\n[[light]]\nkind = \"area\"\n";
    let mat = |extra: &str| {
        format!(
            "{head}[[material]]\nname = \"wall\"\nkind = \"diffuse\"\n{extra}[[override]]\ngroup = \"backWall\"\nmaterial = \"wall\"\n"
        )
    };
    let planar = "planar = { origin = [0, 0, 0], u = [1, 0, 0], v = [0, 1, 0] }\n";
    let cases = [
        (
            "missing",
            mat(&format!("albedo_map = \"no-such-map.png\"\n{planar}")),
            "material[0].albedo_map (line 8)",
            "no-such-map.png",
        ),
        (
            "no-uv",
            mat("albedo_map = \"SCENES/scratched-metal/albedo.png\"\n"),
            "material[0] (line 6)",
            "no texture coordinates",
        ),
        (
            "rough-only",
            mat(&format!("roughness_map = \"SCENES/scratched-metal/roughness.png\"\n{planar}")),
            "material[0].roughness_map",
            "metalness_map",
        ),
        (
            "no-alpha",
            mat(&format!("metalness_map = \"SCENES/scratched-metal/metalness.png\"\n{planar}")),
            "material[0].metalness_map",
            "roughness",
        ),
    ];
    for (name, body, key, what) in cases {
        let f = write_scene(name, &body);
        let e = scene_file::load(&f).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains(&f.display().to_string()) && e.contains(key) && e.contains(what), "{name}: {e}");
    }
    let (_, ps, _) = scene_of("cornell-scratched", 8);
    for i in [Integrator::Bdpt, Integrator::Mlt] {
        let e = ps.check_integrator("cornell-scratched", i).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("texture maps") && e.contains(i.name()), "{e}");
    }
    assert!(ps.check_integrator("cornell-scratched", Integrator::MisPower).is_ok());
}

fn reference() -> (warplight::host::path::stats::Estimate, u32, f64) {
    let (e, size, meta) = reference_of(FIXTURE);
    let checks = meta["bitmap_check_max_diff"].as_object().expect("the maps were checked against Mitsuba's bitmaps");
    assert_eq!(checks.len(), 3);
    assert!(checks.values().all(|v| v.as_f64().is_some_and(|d| d < 1e-6)), "{checks:?}");
    (e, size, reference_samples(&meta))
}

#[test]
fn the_textured_box_agrees_with_mitsuba() {
    let (reference, size, samples) = reference();
    let (_, ps, cam) = scene_of("cornell-scratched-white", size);
    for (k, integrator) in [Integrator::Pt, Integrator::MisPower].into_iter().enumerate() {
        let o = native_outcome(&ps, &cam, params(size, integrator, 700 + k as u32), FRAMES, &reference);
        eprintln!("textures {integrator:?}: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with Mitsuba on the textured box: {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?}: mean off by {:.3}", o.mean_rel_diff);
    }
    let floor = samples / (SAMPLES_PER_FRAME * EMULATED_FRAMES) as f64;
    let o = emulated_frames_outcome(&ps, &cam, params(size, Integrator::Nee, 71), EMULATED_FRAMES, &reference, floor);
    eprintln!("textures emulated: {o:?}");
    assert!(o.passed(), "the emulated kernel disagrees with Mitsuba on the textured box: {o:?}");
}

/// Mirrors every map left to right, or shifts its columns by `k` texels.
fn edit_maps(ps: &mut PathScene, k: usize, mirror: bool) {
    let t = ps.textures.as_mut().expect("maps");
    for m in t.info.chunks(4) {
        let (first, w, h) = (m[0] as usize, m[1] as usize, m[2] as usize);
        for row in t.texels[first..first + w * h].chunks_mut(w) {
            if mirror {
                row.reverse();
            } else {
                row.rotate_left(k);
            }
        }
    }
}

/// The test sees the maps: mirrored left to right, or shifted by a quarter of
/// the wall (64 of 256 texels), they fail.
#[test]
fn a_mirrored_or_shifted_texture_fails() {
    let (reference, size, _) = reference();
    for (name, k, mirror) in [("mirrored", 0, true), ("shifted a quarter", 64, false)] {
        let (_, mut ps, cam) = scene_of("cornell-scratched-white", size);
        edit_maps(&mut ps, k, mirror);
        let o = native_outcome(&ps, &cam, params(size, Integrator::MisPower, 81), FRAMES, &reference);
        eprintln!("maps {name}: {o:?}");
        assert!(!o.passed(), "the maps {name} passed: {o:?}");
    }
}
