//! Host-side speed: SAH and SIROH kd-tree construction per scene, and the
//! native reference ray caster's rays per second.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::raycast::{Caster, render};
use warplight::host::scene_file;

const SCENES: [&str; 5] = ["scene6", "ring", "sponza", "sibenik", "conference"];

fn report() {
    eprintln!("\n{:<12} {:>10} {:>10} {:>10} {:>12}", "scene", "SAH s", "SIROH s", "ratio", "M rays/s");
    for name in SCENES {
        let s = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).expect("scene");
        let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
        let time = |h| {
            let t0 = Instant::now();
            let t = build(&tris, BuildParams::thesis(h));
            (t0.elapsed().as_secs_f64(), t)
        };
        let (ts, tree) = time(Heuristic::Sah);
        let (tr, _) = time(Heuristic::Siroh);
        let caster = Caster::new(&s, &tree);
        let mut cam = s.camera;
        cam.resolution = [256, 256];
        let t0 = Instant::now();
        let (_, st) = render(&caster, &cam, glam::Vec3::ZERO);
        let rps = st.rays as f64 / t0.elapsed().as_secs_f64() / 1e6;
        eprintln!("{name:<12} {ts:>10.4} {tr:>10.4} {:>10.3} {rps:>12.2}", tr / ts);
    }
}

/// Emulated rays per second of the kernel variants beside the native caster (same scene, same view).
fn report_emulated() {
    use warplight::host::rt_kernels::{self, Variant};
    eprintln!("\n{:<10} {:<28} {:>14}", "scene", "renderer (64x64)", "rays/s");
    for name in ["scene6", "sponza"] {
        let s = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).expect("scene");
        let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
        let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
        let mut cam = s.camera;
        cam.resolution = [64, 64];
        let caster = Caster::new(&s, &tree);
        let t0 = Instant::now();
        let (_, st) = render(&caster, &cam, glam::Vec3::ZERO);
        eprintln!("{name:<10} {:<28} {:>14.0}", "native", st.rays as f64 / t0.elapsed().as_secs_f64());
        for v in [Variant::Stack, Variant::Stackless, Variant::ShortStack, Variant::NodeCache1StackCache1] {
            let mut dev = warplight::sim::Device::new();
            let module = rt_kernels::load(&mut dev).expect("kernels");
            let t0 = Instant::now();
            let k = rt_kernels::render(
                &mut dev,
                &module,
                &s,
                &tree,
                &cam,
                glam::Vec3::ZERO,
                v,
                warplight::model::Profile::Gt200,
            )
            .expect("render");
            eprintln!(
                "{name:<10} {:<28} {:>14.0}",
                format!("emulated {}", v.name()),
                k.trace.rays as f64 / t0.elapsed().as_secs_f64()
            );
        }
    }
}

fn bench(c: &mut Criterion) {
    report();
    report_emulated();
    let mut g = c.benchmark_group("host");
    g.sample_size(10);
    for name in ["scene6", "sponza"] {
        let s = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).expect("scene");
        let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
        for h in [Heuristic::Sah, Heuristic::Siroh] {
            g.bench_function(format!("build/{name}/{h}"), |b| b.iter(|| build(&tris, BuildParams::thesis(h))));
        }
        let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
        let caster = Caster::new(&s, &tree);
        let mut cam = s.camera;
        cam.resolution = [128, 128];
        g.bench_function(format!("native_render/{name}/128x128"), |b| {
            b.iter(|| render(&caster, &cam, glam::Vec3::ZERO))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
