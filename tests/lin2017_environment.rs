//! Thesis 003's environment map (§5.4) against Mitsuba 3: `scenes/env-spheres.toml`
//! (a diffuse and a mirror ball on a floor, lit only by the 128 x 64 forest
//! map) rendered by Mitsuba's `path` with its `envmap` emitter
//! (`tests/fixtures/mitsuba/env-spheres-32`, made by `tools/mitsuba/reference.py`,
//! which first checks that warplight's lookup is Mitsuba's). The same
//! per-block Welch t-test under Holm's correction as `lin2017_reference.rs`:
//! every integrator natively and the emulated kernel pass; the map turned by
//! 90 degrees about the vertical fails, and so does the map mirrored left to
//! right (the orientation conventions the test holds).
//!
//! Glass against Mitsuba: `scenes/env-glass.toml`, the same balls as glass
//! with the exact dielectric Fresnel equations (`fresnel = "exact"`), one
//! rough (Walter et al., Beckmann α 0.2) and one smooth, against Mitsuba's
//! `roughdielectric` and `dielectric` (`env-glass-32`), natively; an IOR of
//! 1.33 instead of 1.5 fails.

mod lin2017_mitsuba;

use lin2017_mitsuba::{emulated_frames_outcome, params, reference_of, reference_samples, scene_of};
use warplight::host::camera::Camera;
use warplight::host::path::layout::{KIND_GLASS, KIND_ROUGH_GLASS, PathScene};
use warplight::host::path::stats::{Estimate, Outcome};
use warplight::host::path::{FrameParams, Integrator, SAMPLES_PER_FRAME};

const FIXTURE: &str = "tests/fixtures/mitsuba/env-spheres-32";
const GLASS_FIXTURE: &str = "tests/fixtures/mitsuba/env-glass-32";
/// env-glass with the frosted ball's roughness anisotropic (α 0.05 x 0.4).
const ANISO_GLASS_FIXTURE: &str = "tests/fixtures/mitsuba/env-glass-anisotropic-32";
/// Frames of a native render (4 paths a pixel each).
const FRAMES: u32 = 256;
/// Frames of an emulated render. A block whose frames all miss its rare
/// bright paths looks certain of a low mean from its batch variance alone
/// (t = -37 at 16 frames, -38 at 4); the emulated runs therefore floor each
/// cell's variance at the reference's at the same sample count
/// ([`emulated_floor`]).
const EMULATED_FRAMES: u32 = 16;

/// An environment-lit reference: its estimate, size and samples per pixel,
/// once its JSON shows the lookup was checked against Mitsuba's envmap.
fn reference_at(fixture: &str) -> (Estimate, u32, f64) {
    let (e, size, meta) = reference_of(fixture);
    let check = meta["envmap_check_max_rel_diff"].as_f64().expect("the lookup was checked against Mitsuba's");
    assert!(check < 1e-4, "the reference's lookup check: {check}");
    (e, size, reference_samples(&meta))
}

fn reference() -> (Estimate, u32, f64) {
    reference_at(FIXTURE)
}

/// The variance floor of an emulated run against a reference of
/// `reference_samples` per pixel: their ratio of samples per pixel (the
/// reference's variance of the mean scaled to the run's sample count;
/// `stats::welch_holm_floored`).
fn emulated_floor(reference_samples: f64) -> f64 {
    reference_samples / (SAMPLES_PER_FRAME * EMULATED_FRAMES) as f64
}

fn scene(size: u32) -> (PathScene, Camera) {
    scene_at("env-spheres", size)
}

fn scene_at(name: &str, size: u32) -> (PathScene, Camera) {
    let (_, ps, cam) = scene_of(name, size);
    (ps, cam)
}

fn native_outcome(ps: &PathScene, cam: &Camera, p: FrameParams, reference: &Estimate) -> Outcome {
    lin2017_mitsuba::native_outcome(ps, cam, p, FRAMES, reference)
}

/// Turns the map's columns by `k` texels (k / width of a turn about y), or mirrors them.
fn edit_map(ps: &mut PathScene, k: usize, mirror: bool) {
    let env = ps.env.as_mut().expect("an environment");
    let w = env.width as usize;
    for row in env.texels.chunks_mut(w) {
        if mirror {
            row.reverse();
        } else {
            row.rotate_left(k);
        }
    }
}

#[test]
fn the_environment_lit_scene_agrees_with_mitsuba() {
    let (reference, size, samples) = reference();
    let (ps, cam) = scene(size);
    for (k, integrator) in [Integrator::Pt, Integrator::MisPower].into_iter().enumerate() {
        let o = native_outcome(&ps, &cam, params(size, integrator, 300 + k as u32), &reference);
        eprintln!("environment {integrator:?}: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with Mitsuba under the environment: {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?}: mean off by {:.3}", o.mean_rel_diff);
    }
    let p = params(size, Integrator::Nee, 31);
    let o = emulated_frames_outcome(&ps, &cam, p, EMULATED_FRAMES, &reference, emulated_floor(samples));
    eprintln!("environment emulated: {o:?}");
    assert!(o.passed(), "the emulated kernel disagrees with Mitsuba under the environment: {o:?}");
}

/// Rough and smooth glass with the exact Fresnel equations agree with
/// Mitsuba's `roughdielectric` and `dielectric`, natively and emulated (16
/// frames, seed 51, the variance floored; unfloored, a block whose frames
/// missed its rare bright paths was rejected at t = -37: see
/// docs/reproduction-lin2017.md).
#[test]
fn exact_fresnel_glass_agrees_with_mitsuba() {
    let (reference, size, samples) = reference_at(GLASS_FIXTURE);
    let (ps, cam) = scene_at("env-glass", size);
    let exact: Vec<(u32, f32)> = ps.mats.iter().filter(|m| m[9] > 0.0).map(|m| (m[3].to_bits(), m[8])).collect();
    assert_eq!(exact, [(KIND_ROUGH_GLASS, 0.2), (KIND_GLASS, 0.0)], "the exact-Fresnel glasses");
    for (k, integrator) in [Integrator::Pt, Integrator::MisPower].into_iter().enumerate() {
        let o = native_outcome(&ps, &cam, params(size, integrator, 500 + k as u32), &reference);
        eprintln!("glass {integrator:?}: {o:?}");
        assert!(o.passed(), "{integrator:?} disagrees with Mitsuba on exact-Fresnel glass: {o:?}");
        assert!(o.mean_rel_diff.abs() < 0.02, "{integrator:?}: mean off by {:.3}", o.mean_rel_diff);
    }
    let p = params(size, Integrator::MisPower, 51);
    let o = emulated_frames_outcome(&ps, &cam, p, EMULATED_FRAMES, &reference, emulated_floor(samples));
    eprintln!("glass emulated: {o:?}");
    assert!(o.passed(), "the emulated kernel disagrees with Mitsuba on exact-Fresnel glass: {o:?}");
}

/// The anisotropic rough glass (`env-glass-anisotropic`: the frosted ball α
/// 0.05 x 0.4 along Duff's b1, b2 of each triangle) agrees with Mitsuba's
/// anisotropic `roughdielectric` natively at 384 frames (the scene has no
/// area light, so every integrator traces pt's paths; at 96 frames this seed
/// rejected one block at p 3.9e-5, seeds 530-532 none: docs); the alphas
/// swapped (the lobe turned a quarter) fail.
#[test]
fn anisotropic_rough_glass_agrees_with_mitsuba() {
    let (reference, size, _) = reference_at(ANISO_GLASS_FIXTURE);
    let (ps, cam) = scene_at("env-glass-anisotropic", size);
    let o = lin2017_mitsuba::native_outcome(&ps, &cam, params(size, Integrator::Pt, 520), 4 * FRAMES, &reference);
    eprintln!("anisotropic glass: {o:?}");
    assert!(o.passed(), "pt disagrees with Mitsuba on anisotropic glass: {o:?}");
    assert!(o.mean_rel_diff.abs() < 0.02, "mean off by {:.3}", o.mean_rel_diff);
    let mut turned = ps.clone();
    for m in turned.mats.iter_mut().filter(|m| m[3].to_bits() == KIND_ROUGH_GLASS) {
        m.swap(8, 10);
    }
    let o = native_outcome(&turned, &cam, params(size, Integrator::MisPower, 527), &reference);
    eprintln!("anisotropic glass turned a quarter: {o:?}");
    assert!(!o.passed(), "the glass's lobe turned a quarter passed: {o:?}");
}

/// The test sees the glass: an IOR of 1.33 instead of 1.5 fails. (Schlick's
/// Fresnel in place of the exact one is printed beside it, not asserted:
/// see docs/reproduction-lin2017.md.)
#[test]
fn glass_of_the_wrong_ior_fails() {
    let (reference, size, _) = reference_at(GLASS_FIXTURE);
    let (mut ps, cam) = scene_at("env-glass", size);
    let mut schlick = ps.clone();
    for m in schlick.mats.iter_mut() {
        m[9] = 0.0;
    }
    let o = native_outcome(&schlick, &cam, params(size, Integrator::MisPower, 61), &reference);
    eprintln!("glass with Schlick's Fresnel: {o:?}");
    for m in ps.mats.iter_mut().filter(|m| matches!(m[3].to_bits(), KIND_GLASS | KIND_ROUGH_GLASS)) {
        m[7] = 1.33;
    }
    let o = native_outcome(&ps, &cam, params(size, Integrator::MisPower, 61), &reference);
    eprintln!("glass of IOR 1.33: {o:?}");
    assert!(!o.passed(), "glass of IOR 1.33 passed against 1.5: {o:?}");
}

/// The test sees the map's orientation: turned a quarter about the vertical
/// (32 of 128 columns), or mirrored left to right, it fails.
#[test]
fn a_turned_or_mirrored_map_fails() {
    let (reference, size, _) = reference();
    for (name, k, mirror) in [("turned 90 degrees", 32, false), ("mirrored", 0, true)] {
        let (mut ps, cam) = scene(size);
        edit_map(&mut ps, k, mirror);
        let o = native_outcome(&ps, &cam, params(size, Integrator::MisPower, 41), &reference);
        eprintln!("map {name}: {o:?}");
        assert!(!o.passed(), "the map {name} passed: {o:?}");
    }
}
