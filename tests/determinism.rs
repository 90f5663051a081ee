//! Results and every counter are bit-identical for 1, 2 and 4 host threads and
//! across runs, also for kernels whose CTAs communicate through global atomics.

#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use warplight::sim::{Arg, Device, LaunchConfig, SimConfig};

/// Runs `f` on devices with 1, 2 and 4 host threads (twice with 2) and checks
/// that outputs, totals and per-instruction profiles agree.
fn same_everywhere(f: impl Fn(&mut Device) -> (Vec<u8>, warplight::sim::LaunchStats)) {
    let mut first: Option<(Vec<u8>, warplight::sim::LaunchStats)> = None;
    for threads in [1, 2, 4, 2] {
        let mut dev = Device::with_config(SimConfig { threads, ..SimConfig::default() });
        let (out, stats) = f(&mut dev);
        match &first {
            None => first = Some((out, stats)),
            Some((o, s)) => {
                assert_eq!(o, &out, "outputs differ with {threads} threads");
                assert_eq!(s.totals, stats.totals, "totals differ with {threads} threads");
                assert_eq!(s.profile, stats.profile, "per-instruction counts differ with {threads} threads");
            }
        }
    }
}

fn bytes_of(dev: &Device, p: warplight::sim::DevicePtr, n: usize) -> Vec<u8> {
    dev.read::<u8>(p, n)
}

#[test]
fn job_queue_is_deterministic() {
    for d in BOTH {
        same_everywhere(|dev| {
            let m = load(dev, "atomics", d);
            let items = 20_000;
            let next = dev.alloc_zeroed::<u32>(1);
            let out = dev.alloc_zeroed::<i32>(items);
            let owner = dev.alloc_zeroed::<i32>(items);
            let s = dev
                .launch(
                    &m,
                    "job_queue",
                    LaunchConfig::linear(30, 256),
                    &[Arg::Ptr(next), Arg::Ptr(out), Arg::Ptr(owner), Arg::I32(items as i32)],
                )
                .unwrap();
            (bytes_of(dev, owner, items * 4), s)
        });
    }
}

#[test]
fn float_atomics_are_deterministic() {
    same_everywhere(|dev| {
        let m = load(dev, "atomics", Dialect::Clang);
        let vals: Vec<f32> = (0..8192).map(|i| ((i * 7919) % 1000) as f32 * 1e-3 - 0.4).collect();
        let inb = dev.alloc_from(&vals);
        let sum = dev.alloc_zeroed::<f32>(1);
        let s = dev.launch(&m, "float_sum", LaunchConfig::linear(64, 128), &[Arg::Ptr(sum), Arg::Ptr(inb)]).unwrap();
        (bytes_of(dev, sum, 4), s)
    });
}

#[test]
fn many_ctas_with_barriers_are_deterministic() {
    same_everywhere(|dev| {
        let m = load(dev, "shared", Dialect::Nvcc);
        let n = 64usize;
        let a: Vec<f32> = (0..n * n).map(|i| (i % 17) as f32 * 0.25).collect();
        let (ab, bb) = (dev.alloc_from(&a), dev.alloc_from(&a));
        let cb = dev.alloc_zeroed::<f32>(n * n);
        let cfg = LaunchConfig { grid: [4, 4, 1], block: [16, 16, 1], dynamic_shared: 0 };
        let s = dev
            .launch(&m, "matmul_tiled", cfg, &[Arg::Ptr(cb), Arg::Ptr(ab), Arg::Ptr(bb), Arg::I32(n as i32)])
            .unwrap();
        (bytes_of(dev, cb, n * n * 4), s)
    });
}

#[test]
fn more_ctas_than_resident_slots() {
    // 300 CTAs with 240 resident at a time: later CTAs start as earlier ones retire.
    same_everywhere(|dev| {
        let m = load(dev, "atomics", Dialect::Clang);
        let counter = dev.alloc_zeroed::<u32>(1);
        let seen = dev.alloc_zeroed::<u32>(300 * 64);
        let s =
            dev.launch(&m, "contention", LaunchConfig::linear(300, 64), &[Arg::Ptr(counter), Arg::Ptr(seen)]).unwrap();
        assert_eq!(s.totals.ctas, 300);
        (bytes_of(dev, seen, 300 * 64 * 4), s)
    });
}
