//! The emulated ray tracer against the native one (issue: within 20x): Sponza,
//! frame 0 of the flight at 512 x 512 (primary, shadow and reflection rays),
//! the `trace_stack` kernel with every GT200 counter against the native
//! caster, both on the same tree and on all host threads; and the emulator's
//! scaling from one host thread to two. Ratios are measured in one run (the
//! machines are shared and noisy) and printed before criterion's own timings.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use warplight::host::raycast::{Caster, render};
use warplight::host::rt_kernels::{self, Variant};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::model::Profile;
use warplight::sim::{Device, Fidelity};

fn setup() -> (Scene, KdTree, Camera) {
    let s = scene_file::load(Path::new("scenes/sponza.toml")).expect("scene");
    let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = s.flight.camera(&s.camera, 0);
    cam.resolution = [512, 512];
    (s, tree, cam)
}

fn native(s: &Scene, tree: &KdTree, cam: &Camera) -> u64 {
    let caster = Caster::new(s, tree);
    render(&caster, cam, s.flight.light_offset(0)).1.rays
}

fn emulated(s: &Scene, tree: &KdTree, cam: &Camera, threads: usize) -> u64 {
    emulated_at(s, tree, cam, threads, Fidelity::Caches).trace.rays
}

fn emulated_at(s: &Scene, tree: &KdTree, cam: &Camera, threads: usize, level: Fidelity) -> rt_kernels::KernelRender {
    let mut cfg = rt_kernels::sim_config(cam);
    cfg.threads = threads;
    cfg.fidelity = level;
    let mut dev = Device::with_config(cfg);
    let module = rt_kernels::load(&mut dev).expect("kernels");
    rt_kernels::render(&mut dev, &module, s, tree, cam, s.flight.light_offset(0), Variant::Stack, Profile::Gt200)
        .expect("render")
}

/// Speed against counter accuracy per fidelity level (`RAYTRACE_FIDELITY=out.json`):
/// the frame at 256 x 256 on one host thread; x: million warp instructions per
/// second, y: mean relative error (%) of the GT200 profiler counters against
/// the full model. Written as `warplight chart scatter` JSON.
fn fidelity_chart(out: &str) {
    let (s, tree, mut cam) = setup();
    cam.resolution = [256, 256];
    let full = emulated_at(&s, &tree, &cam, 1, Fidelity::Caches);
    let reference = full.memory.profiler_names(&full.launch.totals);
    let mut series = Vec::new();
    for level in Fidelity::ALL {
        let t = best(2, || {
            std::hint::black_box(emulated_at(&s, &tree, &cam, 1, level));
            0
        });
        let r = emulated_at(&s, &tree, &cam, 1, level);
        let got = r.memory.profiler_names(&r.launch.totals);
        let errs: Vec<f64> = reference
            .iter()
            .zip(&got)
            .filter(|(a, _)| a.1 > 0)
            .map(|(a, b)| (a.1 as f64 - b.1 as f64).abs() / a.1 as f64)
            .collect();
        let err = 100.0 * errs.iter().sum::<f64>() / errs.len().max(1) as f64;
        let speed = r.launch.totals.warp_instructions as f64 / t / 1e6;
        eprintln!("  {level:<12} {t:>7.3} s  {speed:>6.2} M warp-inst/s  counter error {err:>5.1} %");
        series.push(serde_json::json!({"name": level.name(), "points": [[speed, err]]}));
    }
    let chart = serde_json::json!({
        "title": "Emulated trace_stack, Sponza 256x256, 1 host thread: speed against GT200 counter error per fidelity level",
        "x_label": "million warp instructions per second",
        "y_label": "mean relative error of the GT200 profiler counters vs the full model (%)",
        "series": series,
    });
    std::fs::write(out, serde_json::to_string_pretty(&chart).expect("json")).expect("write chart data");
}

/// Best of `n` timings of `f`.
fn best(n: usize, mut f: impl FnMut() -> u64) -> f64 {
    (0..n)
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(f());
            t0.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn report() {
    let (s, tree, cam) = setup();
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get()).min(2);
    let tn = best(5, || native(&s, &tree, &cam));
    let te = best(3, || emulated(&s, &tree, &cam, threads));
    let t1 = best(2, || emulated(&s, &tree, &cam, 1));
    eprintln!("\nSponza 512 x 512, frame 0, SIROH tree, {threads} host threads (best of several runs):");
    eprintln!("  native caster            {tn:>8.3} s");
    eprintln!("  emulated trace_stack     {te:>8.3} s  (gt200 counters)");
    eprintln!("  emulated / native        {:>8.1} x   (target: <= 20 x)", te / tn);
    eprintln!(
        "  emulated, 1 thread       {t1:>8.3} s  -> {threads} threads scale {:.2} x (target: >= 1.8 x)\n",
        t1 / te
    );
}

fn bench(c: &mut Criterion) {
    // `RAYTRACE_ONCE=1`: one emulated frame on one host thread and nothing
    // else, for profiling (`perf record`).
    if let Some(out) = std::env::var_os("RAYTRACE_FIDELITY") {
        fidelity_chart(&out.to_string_lossy());
        return;
    }
    if std::env::var_os("RAYTRACE_ONCE").is_some() {
        let (s, tree, cam) = setup();
        let t0 = Instant::now();
        emulated(&s, &tree, &cam, 1);
        eprintln!("one emulated frame, 1 thread: {:.3} s", t0.elapsed().as_secs_f64());
        return;
    }
    report();
    let (s, tree, cam) = setup();
    let mut g = c.benchmark_group("sponza_512");
    g.sample_size(10);
    g.bench_function("native", |b| b.iter(|| native(&s, &tree, &cam)));
    g.bench_function("emulated_stack_gt200", |b| b.iter(|| emulated(&s, &tree, &cam, 0)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
