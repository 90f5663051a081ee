//! Emulator throughput: an ALU-bound, a memory-bound and a divergent kernel, on
//! one and two host threads. Besides criterion's timings it prints warp and
//! thread instructions per second per core, and the two-thread speed-up.

use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use warplight::model::{Model, Profile};
use warplight::sim::{Arg, Device, LaunchConfig, Module, SimConfig};

struct Case {
    name: &'static str,
    grid: u32,
    block: u32,
    setup: fn(&mut Device) -> Vec<Arg>,
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "alu_loop",
            grid: 64,
            block: 256,
            setup: |d| vec![Arg::Ptr(d.alloc_zeroed::<f32>(16384)), Arg::I32(200)],
        },
        Case {
            name: "memory_stride",
            grid: 64,
            block: 256,
            setup: |d| {
                let n = 1 << 16;
                let input: Vec<f32> = (0..n).map(|i| i as f32).collect();
                let inb = d.alloc_from(&input);
                vec![Arg::Ptr(d.alloc_zeroed::<f32>(16384)), Arg::Ptr(inb), Arg::I32(n), Arg::I32(33), Arg::I32(64)]
            },
        },
        Case {
            name: "divergent",
            grid: 64,
            block: 256,
            setup: |d| vec![Arg::Ptr(d.alloc_zeroed::<i32>(16384)), Arg::I32(100)],
        },
    ]
}

fn device(threads: usize) -> (Device, Module) {
    let mut dev = Device::with_config(SimConfig { threads, ..SimConfig::default() });
    let src = std::fs::read_to_string("kernels/bench/throughput.ptx").expect("bench PTX");
    let m = dev.load_ptx(&src, "kernels/bench/throughput.ptx").expect("loads");
    (dev, m)
}

fn report() {
    eprintln!("\nwarplight throughput (counters on), per host core:");
    eprintln!("{:<14} {:>8} {:>14} {:>16} {:>10}", "kernel", "threads", "Mwarp-inst/s", "Mthread-inst/s", "speed-up");
    for c in cases() {
        let mut base = 0.0;
        for threads in [1usize, 2] {
            let (mut dev, m) = device(threads);
            let args = (c.setup)(&mut dev);
            let cfg = LaunchConfig::linear(c.grid, c.block);
            let s = dev.launch(&m, c.name, cfg, &args).unwrap();
            let reps = 5;
            let t0 = Instant::now();
            for _ in 0..reps {
                dev.launch(&m, c.name, cfg, &args).unwrap();
            }
            let secs = t0.elapsed().as_secs_f64() / reps as f64;
            let w = s.totals.warp_instructions as f64 / secs / 1e6;
            let t = s.totals.thread_instructions as f64 / secs / 1e6;
            if threads == 1 {
                base = secs;
            }
            eprintln!(
                "{:<14} {:>8} {:>14.2} {:>16.1} {:>10.2}",
                c.name,
                threads,
                w / threads as f64,
                t / threads as f64,
                base / secs
            );
        }
    }
}

/// Counters on (a device profile's memory model) against off.
fn report_model_cost() {
    eprintln!("\nmemory-model cost (1 host thread): time with the profile / time without");
    for c in cases() {
        let (mut dev, m) = device(1);
        let args = (c.setup)(&mut dev);
        let cfg = LaunchConfig::linear(c.grid, c.block);
        let time = |dev: &mut Device, profile: Option<Profile>| {
            let t0 = Instant::now();
            for _ in 0..3 {
                match profile {
                    None => {
                        dev.launch(&m, c.name, cfg, &args).unwrap();
                    }
                    Some(p) => {
                        let model = Model::new(p, &m.prog);
                        dev.launch_observed(&m, c.name, cfg, &args, Some(&model)).unwrap();
                    }
                }
            }
            t0.elapsed().as_secs_f64()
        };
        let off = time(&mut dev, None);
        let line: Vec<String> =
            Profile::ALL.iter().map(|p| format!("{} {:.2}x", p, time(&mut dev, Some(*p)) / off)).collect();
        eprintln!("{:<14} {}", c.name, line.join("   "));
    }
}

fn bench(cr: &mut Criterion) {
    report();
    report_model_cost();
    let mut g = cr.benchmark_group("emulator");
    g.sample_size(10);
    for c in cases() {
        for threads in [1usize, 2] {
            let (mut dev, m) = device(threads);
            let args = (c.setup)(&mut dev);
            let cfg = LaunchConfig::linear(c.grid, c.block);
            let s = dev.launch(&m, c.name, cfg, &args).unwrap();
            g.throughput(Throughput::Elements(s.totals.thread_instructions));
            g.bench_function(format!("{}/{}t", c.name, threads), |b| {
                b.iter(|| dev.launch(&m, c.name, cfg, &args).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
