//! The teaching views' speed: stepping a launch one warp instruction at a
//! time with memory accesses recorded (what `warplight step` and its step
//! back by replay do), and recording plus rendering an HTML trace. Besides
//! criterion's timings it prints stepped thread-instructions per second on
//! one core, and how long a step back takes at the end of each lesson.

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use warplight::model::Profile;
use warplight::teach::session::Session;
use warplight::teach::trace::{self, TraceOptions};

const SPECS: [&str; 3] =
    ["examples/lessons/divergence.toml", "examples/lessons/reduction.toml", "examples/lessons/stackless.toml"];

fn session(spec: &str) -> Session {
    Session::load(Path::new(spec)).expect("lesson spec")
}

/// Steps the whole launch; returns (warp instructions, thread instructions).
fn step_all(s: &Session) -> (u64, u64) {
    s.with_stepper(|st| {
        let mut n = 0u64;
        while st.step()?.is_some() {
            n += 1;
        }
        Ok((n, st.counters().thread_instructions))
    })
    .expect("steps")
}

fn trace_options() -> TraceOptions {
    TraceOptions { ctas: vec![0], warps: vec![], from: 1, to: u64::MAX, max_events: 20_000, profile: Profile::Hopper }
}

fn report() {
    eprintln!("\nstepping with memory accesses recorded (1 host core):");
    eprintln!("{:<36} {:>12} {:>16} {:>16}", "spec", "warp inst", "Mthread-inst/s", "step back (ms)");
    for spec in SPECS {
        let s = session(spec);
        let t0 = Instant::now();
        let (warps, threads) = step_all(&s);
        let secs = t0.elapsed().as_secs_f64();
        // a step back from the end replays everything but the last instruction
        eprintln!("{spec:<36} {warps:>12} {:>16.1} {:>16.2}", threads as f64 / secs / 1e6, secs * 1e3);
    }
}

fn bench(cr: &mut Criterion) {
    report();
    let mut g = cr.benchmark_group("teach");
    g.sample_size(10);
    for spec in SPECS {
        let s = session(spec);
        let name = Path::new(spec).file_stem().unwrap().to_string_lossy().to_string();
        let (_, threads) = step_all(&s);
        g.throughput(Throughput::Elements(threads));
        g.bench_function(format!("step/{name}"), |b| b.iter(|| step_all(&s)));
        g.bench_function(format!("trace/{name}"), |b| {
            b.iter(|| trace::html(&trace::record(&s, &trace_options()).unwrap()).unwrap().len())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
