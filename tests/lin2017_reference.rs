//! Thesis 003's path tracer against an independent renderer: Mitsuba 3's
//! reference of the all-Lambertian Cornell box (`tests/fixtures/mitsuba/`,
//! made by `tools/mitsuba/reference.py`; the command is in its JSON). The
//! test is statistical, as Mitsuba's own render tests are: per 4 x 4-pixel
//! block and channel a Welch t-test of the two mean estimates with their
//! variances (ours from the frames' batch means, Mitsuba's from its 16
//! batches), the 192 tests controlled by Holm's procedure at α = 0.01.
//! Every integrator passes natively, the emulated kernel passes at a few
//! frames, and a renderer whose light is 10 % too bright fails.
//!
//! The same for the Cornell box with a rough-mirror back wall (Figs. 6 and
//! 7's scene; Cook-Torrance with Beckmann α 0.2 against Mitsuba's
//! `roughconductor`, `cornell-rough-32`), where a mirror of α 0.3 fails.
//!
//! The anisotropic mirror (§5.1; `cornell-anisotropic-32`, Mitsuba's
//! `roughconductor` with `alpha_u` and `alpha_v`), where the lobe turned a
//! quarter, or made isotropic, fails.
//!
//! Fig. 8's scene (the light turned to the ceiling): pt passes against
//! Mitsuba's path tracer (`cornell-inverted-path-32`), bdpt's image mean
//! agrees (its blocks are heavy-tailed there), and Mitsuba's particle tracer
//! (`cornell-inverted-32`) is darker than its path tracer.

mod lin2017_mitsuba;

use lin2017_mitsuba::{ALPHA, BLOCK, emulated_outcome, native_outcome, params, reference_of, scene_of};
use warplight::host::camera::Camera;
use warplight::host::path::layout::PathScene;
use warplight::host::path::stats::{Estimate, from_frames, welch_holm};
use warplight::host::path::{Integrator, kernel, render_native};
use warplight::host::scene::{MaterialKind, Scene};
use warplight::sim::{Device, Fidelity};

const FIXTURE: &str = "tests/fixtures/mitsuba/cornell-lambert-32";
const ROUGH_FIXTURE: &str = "tests/fixtures/mitsuba/cornell-rough-32";
/// The anisotropic mirror's box (`cornell-anisotropic`: the back wall α 0.05 x 0.4).
const ANISO_FIXTURE: &str = "tests/fixtures/mitsuba/cornell-anisotropic-32";
/// Fig. 8's scene by Mitsuba's particle tracer (`ptracer`).
const INVERTED_PTRACER: &str = "tests/fixtures/mitsuba/cornell-inverted-32";
/// Fig. 8's scene by Mitsuba's path tracer (`path`: next-event estimation and BSDF sampling under MIS).
const INVERTED_PATH: &str = "tests/fixtures/mitsuba/cornell-inverted-path-32";
/// The large-step study's caustic box (the tall box smooth glass, exact Fresnel).
const CAUSTIC: &str = "tests/fixtures/mitsuba/cornell-caustic-32";

fn reference() -> (Estimate, u32) {
    let (e, size, _) = reference_of(FIXTURE);
    (e, size)
}

fn cornell(size: u32) -> (Scene, PathScene, Camera) {
    scene_of("cornell-lambert", size)
}

#[test]
fn every_integrator_natively_agrees_with_mitsuba() {
    let (reference, size) = reference();
    let (_, ps, cam) = cornell(size);
    for (k, integrator) in Integrator::ALL.into_iter().enumerate() {
        let o = native_outcome(&ps, &cam, params(size, integrator, 100 + k as u32), 96, &reference);
        eprintln!("{integrator:?}: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with Mitsuba: {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?}: mean off by {:.3}", o.mean_rel_diff);
    }
}

#[test]
fn a_light_ten_percent_too_bright_fails() {
    let (reference, size) = reference();
    let (scene, mut ps, cam) = cornell(size);
    for (m, mat) in scene.materials.iter().enumerate() {
        if mat.kind == MaterialKind::Emitter {
            for c in 4..7 {
                ps.mats[m][c] *= 1.1;
            }
        }
    }
    let o = native_outcome(&ps, &cam, params(size, Integrator::Nee, 7), 96, &reference);
    eprintln!("bright light: {o:?}");
    assert!(!o.passed(), "a light 10 % too bright passed: {o:?}");
}

#[test]
fn the_emulated_kernel_agrees_with_mitsuba() {
    let (reference, size) = reference();
    let (_, ps, cam) = cornell(size);
    let o = emulated_outcome(&ps, &cam, params(size, Integrator::Nee, 11), &reference);
    eprintln!("emulated: {o:?}");
    assert!(o.passed(), "the emulated kernel disagrees with Mitsuba: {o:?}");
}

/// The rough-mirror back wall: every integrator natively (light samples at
/// the rough mirror for nee and mis) and the emulated kernel agree with
/// Mitsuba's `roughconductor` (Beckmann α 0.2, F = 1).
#[test]
fn the_rough_mirror_box_agrees_with_mitsuba() {
    let (reference, size, _) = reference_of(ROUGH_FIXTURE);
    let (_, ps, cam) = scene_of("cornell-rough", size);
    let kinds: Vec<u32> = ps.mats.iter().map(|m| m[3].to_bits()).collect();
    assert!(kinds.contains(&warplight::host::path::layout::KIND_CONDUCTOR), "no rough mirror: {kinds:?}");
    every_integrator_and_the_emulated_kernel_agree(&ps, &cam, &reference, size, "rough", (200, 13));
}

/// Every integrator natively (96 frames, seeds `seeds.0 + k`) and the emulated
/// kernel (mis-power, 4 frames, seed `seeds.1`) pass the Welch-Holm test
/// against `reference`; the native means lie within 2 %.
fn every_integrator_and_the_emulated_kernel_agree(
    ps: &PathScene,
    cam: &Camera,
    reference: &Estimate,
    size: u32,
    what: &str,
    seeds: (u32, u32),
) {
    for (k, integrator) in Integrator::ALL.into_iter().enumerate() {
        let o = native_outcome(ps, cam, params(size, integrator, seeds.0 + k as u32), 96, reference);
        eprintln!("{what} {integrator:?}: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with Mitsuba ({what}): {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?} ({what}): mean off by {:.3}", o.mean_rel_diff);
    }
    let o = emulated_outcome(ps, cam, params(size, Integrator::MisPower, seeds.1), reference);
    eprintln!("{what} emulated: {o:?}");
    assert!(o.passed(), "the emulated kernel disagrees with Mitsuba ({what}): {o:?}");
}

/// The test sees the BSDF: the back wall with α 0.3 instead of 0.2 fails.
#[test]
fn a_rougher_mirror_fails() {
    let (reference, size, _) = reference_of(ROUGH_FIXTURE);
    let (_, mut ps, cam) = scene_of("cornell-rough", size);
    for m in ps.mats.iter_mut() {
        if m[3].to_bits() == warplight::host::path::layout::KIND_CONDUCTOR {
            m[8] = 0.3;
        }
    }
    let o = native_outcome(&ps, &cam, params(size, Integrator::MisPower, 17), 96, &reference);
    eprintln!("rougher mirror: {o:?}");
    assert!(!o.passed(), "a mirror of alpha 0.3 passed against alpha 0.2: {o:?}");
}

/// The anisotropic mirror (§5.1, 003:L346-352): the back wall brushed, α_x
/// 0.05 along the tangent b1 and α_y 0.4 along b2, against Mitsuba's
/// anisotropic `roughconductor` (`alpha_u`, `alpha_v`, its tangent checked to
/// be b1 by the tool): every integrator natively, and the emulated kernel.
#[test]
fn the_anisotropic_mirror_box_agrees_with_mitsuba() {
    let (reference, size, _) = reference_of(ANISO_FIXTURE);
    let (_, ps, cam) = scene_of("cornell-anisotropic", size);
    every_integrator_and_the_emulated_kernel_agree(&ps, &cam, &reference, size, "anisotropic", (220, 23));
}

/// The test sees the lobe's orientation: the same alphas swapped (the lobe
/// turned a quarter about the normal) fail, and so does the isotropic lobe
/// of their mean.
#[test]
fn the_anisotropic_lobe_turned_or_made_isotropic_fails() {
    let (reference, size, _) = reference_of(ANISO_FIXTURE);
    let (_, ps, cam) = scene_of("cornell-anisotropic", size);
    let mutate = |f: &dyn Fn(&mut [f32; 12])| {
        let mut ps = ps.clone();
        for m in ps.mats.iter_mut().filter(|m| m[3].to_bits() == warplight::host::path::layout::KIND_CONDUCTOR) {
            f(m);
        }
        ps
    };
    let turned = mutate(&|m| m.swap(8, 10));
    let o = native_outcome(&turned, &cam, params(size, Integrator::MisPower, 27), 96, &reference);
    eprintln!("turned a quarter: {o:?}");
    assert!(!o.passed(), "the lobe turned a quarter passed: {o:?}");
    let iso = mutate(&|m| {
        m[8] = 0.5 * (m[8] + m[10]);
        m[10] = 0.0;
    });
    let o = native_outcome(&iso, &cam, params(size, Integrator::MisPower, 29), 96, &reference);
    eprintln!("isotropic of the mean alpha: {o:?}");
    assert!(!o.passed(), "the isotropic lobe passed: {o:?}");
}

/// Bidirectional path tracing (the thesis' uniform weights over the
/// combinations that can make a path) is unbiased: natively it agrees with
/// Mitsuba's path-traced references of the Lambertian box and of the
/// rough-mirror box (the rough mirror is reached by eye-subpath sampling
/// only); the emulated kernel's frames equal the native ones there.
#[test]
fn bdpt_agrees_with_mitsuba() {
    let (reference, size) = reference();
    let (_, ps, cam) = cornell(size);
    // 384 frames and a 1 % bound on the mean: at 96 frames the whole image's
    // mean varies by about ±1 % between seeds, and a light subpath whose
    // roulette forgets to divide by q (about -2 %) passed (review 6, finding 4)
    let o = native_outcome(&ps, &cam, params(size, Integrator::Bdpt, 300), 384, &reference);
    eprintln!("bdpt lambert: {o:?}");
    assert!(o.passed(), "bdpt disagrees with Mitsuba: {o:?}");
    assert!(o.mean_rel_diff.abs() < 0.01, "bdpt: mean off by {:.3}", o.mean_rel_diff);
    // The emulated kernel: its 4 frames equal the native ones bit for bit, so
    // the native pass above covers it. Its own t-test at 4 or 16 frames is not
    // asserted: uniform weights leave short connections (G ~ 1 / d^2) their
    // heavy tail, and a few frames underestimate a block's variance
    // (docs/reproduction-lin2017.md, "Bidirectional path tracing").
    let p = params(size, Integrator::Bdpt, 301);
    let native = render_native(&ps, &cam, p, 4, false, |_| {}).expect("render");
    let mut cfg = kernel::sim_config(&p);
    cfg.fidelity = Fidelity::Functional;
    let mut dev = Device::with_config(cfg);
    let module = kernel::load(&mut dev).expect("load PTX");
    let emu = kernel::render(&mut dev, &module, &ps, &cam, p, 4, false, |_| {}).expect("launch");
    let diff = native.accum.iter().zip(&emu.image.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
    assert_eq!(diff, 0, "bdpt at 32 x 32: {diff} values differ emulated and native");
    let (reference, size, _) = reference_of(ROUGH_FIXTURE);
    let (_, ps, cam) = scene_of("cornell-rough", size);
    // 384 frames: the mirror's image of the light comes from eye subpaths alone
    // (as pt's), a rare, bright event; at 96 frames seed 302 rejected 3 blocks
    // there (mean -1.6 %), seed 400 none (+0.5 %), as pt's own runs vary
    let o = native_outcome(&ps, &cam, params(size, Integrator::Bdpt, 302), 384, &reference);
    eprintln!("bdpt rough: {o:?}");
    assert!(o.passed(), "bdpt disagrees with Mitsuba on the rough mirror: {o:?}");
    assert!(o.mean_rel_diff.abs() < 0.02, "bdpt rough: mean off by {:.3}", o.mean_rel_diff);
}

/// The test sees bdpt's brightness: its render of a light 10 % too dim
/// fails (a weighting that divided by impossible combinations too, as the
/// literal count of 003:L303 would, darkens the image by more).
#[test]
fn bdpt_with_a_dim_light_fails() {
    let (reference, size) = reference();
    let (scene, mut ps, cam) = cornell(size);
    for (m, mat) in scene.materials.iter().enumerate() {
        if mat.kind == MaterialKind::Emitter {
            for c in 4..7 {
                ps.mats[m][c] *= 0.9;
            }
        }
    }
    let o = native_outcome(&ps, &cam, params(size, Integrator::Bdpt, 303), 96, &reference);
    eprintln!("bdpt dim light: {o:?}");
    assert!(!o.passed(), "bdpt with a light 10 % too dim passed: {o:?}");
}

/// Fig. 8's scene (003:L305, the light turned to the ceiling,
/// `cornell-inverted`) against Mitsuba's path tracer: pt, the control,
/// passes the block test at 6,144 frames.
#[test]
fn fig_8_pt_agrees_with_mitsuba_under_the_inverted_light() {
    let (reference, size, meta) = reference_of(INVERTED_PATH);
    assert_eq!(meta["integrator"].as_str(), Some("path"));
    let (_, ps, cam) = scene_of("cornell-inverted", size);
    let o = native_outcome(&ps, &cam, params(size, Integrator::Pt, 510), 6144, &reference);
    eprintln!("fig 8, pt: {o:?}");
    assert!(o.passed(), "pt disagrees with Mitsuba under the inverted light: {o:?}");
    assert!(o.mean_rel_diff.abs() < 0.02, "pt: mean off by {:.3}", o.mean_rel_diff);
}

/// The caustic box (`scenes/cornell-caustic.toml`: the tall box smooth
/// glass with the exact Fresnel equations, Mitsuba's `dielectric`): pt and
/// bdpt (over which the large-step study runs MLT) agree with Mitsuba's path
/// tracer block by block at 384 frames.
#[test]
fn the_caustic_box_agrees_with_mitsuba() {
    let (reference, size, _) = reference_of(CAUSTIC);
    let (_, ps, cam) = scene_of("cornell-caustic", size);
    for (integrator, seed, frames) in [(Integrator::Pt, 520, 384), (Integrator::Bdpt, 521, 384)] {
        let o = native_outcome(&ps, &cam, params(size, integrator, seed), frames, &reference);
        eprintln!("caustic box, {integrator:?}: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with Mitsuba on the caustic box: {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?}: mean off by {:.3}", o.mean_rel_diff);
    }
}

/// bdpt under the inverted light: its image mean agrees with Mitsuba's path
/// tracer within 3 of its frames' standard errors at 6,144 frames. The
/// block test is reported, not asserted: bdpt's uniform weights (003:L303)
/// keep 1 / c of next-event estimation's 1 / d^2 spikes at eye vertices in
/// the 1 cm crevice, single frames hold up to a third of a block's sum, and
/// blocks that have not drawn their share come out below with too small a
/// variance (6 to 14 of 192 cells rejected at 6,144 and 24,576 frames, all
/// ours below; docs/reproduction-lin2017.md, "Bidirectional path tracing").
#[test]
fn fig_8_bdpt_under_the_inverted_light_agrees_in_the_mean() {
    let (reference, size, _) = reference_of(INVERTED_PATH);
    let (_, ps, cam) = scene_of("cornell-inverted", size);
    let r = render_native(&ps, &cam, params(size, Integrator::Bdpt, 511), 6144, true, |_| {}).expect("render");
    let sums: Vec<f64> = r
        .frame_images
        .iter()
        .map(|im| {
            let mut t = 0.0f64;
            for y in 0..size {
                for x in 0..size {
                    t += im.get(x, y).iter().map(|&v| v as f64).sum::<f64>();
                }
            }
            t
        })
        .collect();
    let n = sums.len() as f64;
    let mean = sums.iter().sum::<f64>() / n;
    let se = (sums.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let target = reference.mean.iter().sum::<f64>() * f64::from(BLOCK * BLOCK);
    let ours = from_frames(&r.frame_images, BLOCK).expect("frames");
    let o = welch_holm(&ours, &reference, ALPHA).expect("same block grid");
    eprintln!(
        "fig 8, bdpt: image mean {:+.2} % +- {:.2} % of Mitsuba's; block test (not asserted) {o:?}",
        100.0 * (mean / target - 1.0),
        100.0 * se / target
    );
    assert!((mean - target).abs() < 3.0 * se, "bdpt's image mean {mean} against {target} +- {se}");
    assert!(se / target < 0.05, "bdpt's image mean too uncertain to say anything: {se} of {target}");
}

/// The committed particle-tracer reference of Fig. 8's scene is darker than
/// Mitsuba's path tracer's by about 2.5 % over the whole image, many
/// standard errors; in the Lambertian box the two agree inside the image
/// (docs). The bdpt test therefore uses the path tracer's reference.
#[test]
fn the_particle_tracer_reference_of_fig_8_is_darker_than_the_path_tracers() {
    let sum = |fixture: &str| {
        let (e, _, _) = reference_of(fixture);
        let m: f64 = e.mean.iter().sum();
        let v: f64 = e.var.iter().sum();
        (m, v)
    };
    let ((mp, vp), (mt, vt)) = (sum(INVERTED_PATH), sum(INVERTED_PTRACER));
    let z = (mp - mt) / (vp + vt).sqrt();
    eprintln!("fig 8: path / ptracer = {:.4}, z = {z:.1}", mp / mt);
    assert!(z > 5.0 && (mp / mt - 1.0) > 0.01, "path / ptracer = {:.4}, z = {z:.1}", mp / mt);
}
