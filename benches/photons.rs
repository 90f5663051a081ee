//! Thesis 000 §5.1's photon tracing, photons traced per second emulated
//! against native (issue 13): Scene 6 (Table 5.1's first scene, 804
//! triangles, SIROH kd-tree), 2^15 photons from its point light traced to
//! the 3rd surface interaction with photon differentials. The kernel
//! `trace_photons` (`kernels/fabianowski2011/photons.cu`) runs on the
//! emulator at fidelity `functional` (what Table 5.1 counts at) and at
//! `caches` (the full model); the native reference (`photons::trace_one`,
//! the kernel's float operations in its order, bit for bit the kernel's
//! photons) runs on the same host threads through rayon. The ratios are
//! measured in one run (the machines are shared and noisy) and printed
//! before criterion's own timings.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rayon::prelude::*;
use warplight::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use warplight::host::raycast::Caster;
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::repro::fabianowski2011::photons::{self, Emission};
use warplight::sim::{Device, Fidelity, SimConfig};

/// Photons per run.
const PHOTONS: usize = 1 << 15;

fn setup() -> (Scene, KdTree, Emission) {
    let s = scene_file::load(Path::new("scenes/scene6.toml")).expect("scene");
    let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let e = Emission::of(&s, PHOTONS).expect("point light");
    (s, tree, e)
}

/// Stored interactions of the native trace on all host threads.
fn native(s: &Scene, tree: &KdTree, e: &Emission) -> usize {
    let caster = Caster::new(s, tree);
    (0..e.n as u32).into_par_iter().map(|i| photons::trace_one(&caster, e, i).iter().flatten().count()).sum()
}

/// Stored interactions of the emulated kernel at `level` on `threads` host threads (0: all).
fn emulated(s: &Scene, tree: &KdTree, e: &Emission, level: Fidelity, threads: usize) -> usize {
    let mut dev = Device::with_config(SimConfig { fidelity: level, threads, ..SimConfig::default() });
    let module = photons::load(&mut dev).expect("kernel");
    let k = photons::trace_kernel(&mut dev, &module, s, tree, e).expect("trace");
    k.photons.iter().flatten().flatten().count()
}

/// Best of `n` timings of `f`; checks every run stores `expect` interactions.
fn best(n: usize, expect: usize, mut f: impl FnMut() -> usize) -> f64 {
    (0..n)
        .map(|_| {
            let t0 = Instant::now();
            let got = std::hint::black_box(f());
            let t = t0.elapsed().as_secs_f64();
            assert_eq!(got, expect, "a run stored a different number of interactions");
            t
        })
        .fold(f64::INFINITY, f64::min)
}

fn report() {
    let (s, tree, e) = setup();
    let threads = rayon::current_num_threads();
    let stored = native(&s, &tree, &e);
    let tn = best(5, stored, || native(&s, &tree, &e));
    let tf = best(3, stored, || emulated(&s, &tree, &e, Fidelity::Functional, 0));
    let tc = best(2, stored, || emulated(&s, &tree, &e, Fidelity::Caches, 0));
    let rate = |t: f64| PHOTONS as f64 / t;
    eprintln!(
        "\nScene 6, {PHOTONS} photons ({stored} stored interactions), {threads} host threads (best of several runs):"
    );
    eprintln!("  native trace_one        {:>10.0} photons/s", rate(tn));
    eprintln!("  emulated, functional    {:>10.0} photons/s   emulated / native {:>7.1} x", rate(tf), tf / tn);
    eprintln!("  emulated, caches        {:>10.0} photons/s   emulated / native {:>7.1} x\n", rate(tc), tc / tn);
}

fn bench(c: &mut Criterion) {
    report();
    let (s, tree, e) = setup();
    let mut g = c.benchmark_group(format!("photons_scene6_{PHOTONS}"));
    g.sample_size(10);
    g.throughput(Throughput::Elements(PHOTONS as u64));
    g.bench_function("native", |b| b.iter(|| native(&s, &tree, &e)));
    g.bench_function("emulated_functional", |b| b.iter(|| emulated(&s, &tree, &e, Fidelity::Functional, 0)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
