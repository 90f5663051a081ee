//! Thesis 003's path tracer, paths per second emulated against native: one
//! frame (4 paths per pixel, next-event estimation, at most 16 bounces) of
//! the Lambertian Cornell box and of Fig. 3's bunny&ball at 32 x 32, the
//! kernel `path_frame` at fidelity `functional` (and `instructions`, which
//! the Fig. 3 table runs at) against the native mirror, both on all host
//! threads; and on the box, a frame of the fixed-depth build (no Russian
//! roulette, `kernels/lin2017/path_fixed_depth.cu`) against the thesis'
//! build, natively and emulated (the speed-up 003:L269 claims for roulette),
//! and a frame of the stratified-pixel build (`path_stratified.cu`, 4 x 4
//! strata) against the thesis' tent filter (003:L225 compares them at equal
//! samples; the two should cost alike).
//! The ratios are measured in one run (the machines are shared and noisy)
//! and printed before criterion's own timings.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use warplight::host::camera::Camera;
use warplight::host::path::build::{self, Construction};
use warplight::host::path::layout::PathScene;
use warplight::host::path::{FrameParams, Integrator, PixelSampling, Termination, kernel, render_native};
use warplight::host::scene_file;
use warplight::sim::Fidelity;

const SIDE: u32 = 32;

fn setup(name: &str) -> (PathScene, Camera) {
    let s = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).expect("scene");
    let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build::build(&tris, &build::Params::fig3(Construction::Sah, tris.len()));
    let ps = PathScene::new(&s, &tree).expect("layout");
    (ps, Camera { resolution: [SIDE, SIDE], ..s.camera })
}

fn params() -> FrameParams {
    FrameParams::new(SIDE, SIDE, Integrator::Nee, 16, 0)
}

fn native(ps: &PathScene, cam: &Camera) -> f32 {
    native_with(ps, cam, params())
}

fn native_with(ps: &PathScene, cam: &Camera, p: FrameParams) -> f32 {
    render_native(ps, cam, p, 1, false, |_| {}).expect("render").accum[0]
}

fn emulated(ps: &PathScene, cam: &Camera, level: Fidelity) -> f32 {
    emulated_with(ps, cam, level, params())
}

/// One emulated frame of `p` on the build it needs.
fn emulated_with(ps: &PathScene, cam: &Camera, level: Fidelity, p: FrameParams) -> f32 {
    let (mut dev, module) = kernel::device(&p, level).expect("kernel");
    kernel::render(&mut dev, &module, ps, cam, p, 1, false, |_| {}).expect("render").image.accum[0]
}

/// Best of `n` timings of `f`.
fn best(n: usize, mut f: impl FnMut() -> f32) -> f64 {
    (0..n)
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(f());
            t0.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn report() {
    let paths = params().paths() as f64;
    for name in ["cornell-lambert", "bunny-ball"] {
        let (ps, cam) = setup(name);
        let tn = best(5, || native(&ps, &cam));
        let tf = best(2, || emulated(&ps, &cam, Fidelity::Functional));
        let ti = best(2, || emulated(&ps, &cam, Fidelity::Instructions));
        eprintln!("\n{name}, {SIDE} x {SIDE}, 1 frame ({paths} paths), NEE (best of several runs):");
        eprintln!("  native                  {:>10.0} paths/s", paths / tn);
        eprintln!("  emulated, functional    {:>10.0} paths/s   native / emulated {:>7.1} x", paths / tf, tf / tn);
        eprintln!("  emulated, instructions  {:>10.0} paths/s   native / emulated {:>7.1} x", paths / ti, ti / tn);
        if name == "cornell-lambert" {
            let fixed = FrameParams { termination: Termination::FixedDepth, ..params() };
            let stratified = FrameParams { pixels: PixelSampling::Stratified(4), ..params() };
            let progressive = FrameParams { pixels: PixelSampling::Progressive(4), ..params() };
            for (what, p) in [
                ("fixed depth / roulette", fixed),
                ("stratified 4x4 / tent", stratified),
                ("progressive 4x4 / tent", progressive),
            ] {
                let n = best(5, || native_with(&ps, &cam, p));
                let e = best(2, || emulated_with(&ps, &cam, Fidelity::Functional, p));
                eprintln!("  {what}: native {:.2} x, emulated (functional) {:.2} x", n / tn, e / tf);
            }
        }
    }
    eprintln!();
}

fn bench(c: &mut Criterion) {
    report();
    for name in ["cornell-lambert", "bunny-ball"] {
        let (ps, cam) = setup(name);
        let mut g = c.benchmark_group(format!("path_{name}_{SIDE}"));
        g.sample_size(10);
        g.throughput(criterion::Throughput::Elements(params().paths() as u64));
        g.bench_function("native", |b| b.iter(|| native(&ps, &cam)));
        g.bench_function("emulated_functional", |b| b.iter(|| emulated(&ps, &cam, Fidelity::Functional)));
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
