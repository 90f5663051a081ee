//! The GT200 and Maxwell profiles on real kernels, against counts derived by
//! hand from the CC 1.3 coalescing rules and 32-byte sectors.

use warplight::model::{Model, ModelStats, Profile};
use warplight::sim::{Arg, Device, LaunchConfig};

fn run(profile: Profile, kernel: &str, a: i32, grid: u32) -> (ModelStats, warplight::sim::Counters) {
    let mut dev = Device::new();
    let src = std::fs::read_to_string("kernels/micro/micro.ptx").unwrap();
    let m = dev.load_ptx(&src, "micro.ptx").unwrap();
    let out = dev.alloc_zeroed::<f32>(1 << 20);
    let inb = dev.alloc_zeroed::<f32>(1 << 20);
    let model = Model::new(profile, &m.prog);
    let s = dev
        .launch_observed(
            &m,
            kernel,
            LaunchConfig::linear(grid, 256),
            &[Arg::Ptr(out), Arg::Ptr(inb), Arg::I32(a), Arg::I32(0)],
            Some(&model),
        )
        .unwrap();
    (model.finish(), s.totals)
}

#[test]
fn gt200_coalescing_of_strided_loads() {
    // 4 CTAs x 8 warps = 32 warp instructions = 64 half-warps.
    let (s, _) = run(Profile::Gt200, "ld_stride", 1, 4);
    // stride 1: each half-warp reads 64 contiguous aligned bytes -> one 64-byte transaction
    assert_eq!((s.counters.global_ld.t32, s.counters.global_ld.t64, s.counters.global_ld.t128), (0, 64, 0));
    let (s, _) = run(Profile::Gt200, "ld_stride", 2, 4);
    // stride 2: 128 bytes spanned -> one 128-byte transaction
    assert_eq!((s.counters.global_ld.t64, s.counters.global_ld.t128), (0, 64));
    let (s, _) = run(Profile::Gt200, "ld_stride", 32, 4);
    // stride 32 floats = 128 bytes: every thread its own segment, 4 bytes used -> 32-byte transactions
    assert_eq!(s.counters.global_ld.t32, 64 * 16);
    let (s, _) = run(Profile::Gt200, "ld_stride", 0, 4);
    assert_eq!(s.counters.global_ld.t32, 64, "one word for all: one 32-byte transaction per half-warp");
    // the out[t] store is coalesced into one 64-byte transaction per half-warp
    assert_eq!(s.counters.global_st.t64, 64);
}

#[test]
fn gt200_vector_loads_and_texture_path() {
    let (s, _) = run(Profile::Gt200, "ld_v4", 1, 4);
    // 16 threads x 16 bytes = 256 bytes: two 128-byte segments per half-warp
    assert_eq!(s.counters.global_ld.t128, 128);
    let (s, _) = run(Profile::Gt200, "ldg_gather", 1, 4);
    // The texture path does not coalesce: one lookup per distinct 32-byte line and half-warp;
    // consecutive floats: 2 lines per half-warp; each line is new the first time.
    assert_eq!(s.counters.texture.sectors, 128);
    assert_eq!(s.counters.texture.misses, 128);
    assert_eq!(s.counters.global_ld.instructions, 0, "the only load goes through the texture path");
    assert_eq!(s.counters.texture.instructions, 32);
}

#[test]
fn gt200_shared_banks_per_half_warp() {
    let (s, _) = run(Profile::Gt200, "sh_stride", 2, 1);
    // stride 2 words with 16 banks: 2-way conflicts in each half-warp
    assert_eq!(s.counters.shared_ld.wavefronts, 8 * 2 * 2);
    assert_eq!(s.counters.shared_ld.bank_conflicts, 8 * 2);
    assert_eq!(s.counters.warp_serialize, 16, "every shared load and store serialized");
    let (s, _) = run(Profile::Gt200, "sh_stride", 1, 1);
    assert_eq!(s.counters.shared_ld.bank_conflicts, 0);
}

#[test]
fn maxwell_sectors_and_texture_cache() {
    let (s, c) = run(Profile::Maxwell, "ld_stride", 2, 4);
    assert_eq!(s.counters.global_ld.requests, 32);
    assert_eq!(s.counters.global_ld.sectors, 32 * 8);
    let (s, _) = run(Profile::Maxwell, "ldg_gather", 1, 4);
    // read-only loads go through the texture path in 32-byte sectors: 4 per warp
    assert_eq!(s.counters.texture.sectors, 32 * 4);
    assert!(s.counters.texture.hits == 0 && s.counters.texture.misses == 128);
    let names: Vec<&str> = s.profiler_names(&c).into_iter().map(|(n, _)| n).collect();
    assert!(names.contains(&"gld_transactions") && names.contains(&"tex_cache_hits"));
}

#[test]
fn gt200_texture_cache_is_shared_per_tpc() {
    // Every thread reads in[0] through the texture path: one 32-byte line per
    // half-warp lookup. CTAs 0-2 run on SMs 0-2, which share the texture cache of
    // cluster (TPC) 0; CTAs 3-5 share that of TPC 1. Each cluster misses once
    // and hits on the other 47 of its 48 half-warp lookups, for any number of host threads.
    for threads in [1, 2] {
        let mut dev = Device::with_config(warplight::sim::SimConfig { threads, ..Default::default() });
        let src = std::fs::read_to_string("kernels/micro/micro.ptx").unwrap();
        let m = dev.load_ptx(&src, "micro.ptx").unwrap();
        let out = dev.alloc_zeroed::<f32>(1 << 12);
        let inb = dev.alloc_zeroed::<f32>(1 << 16);
        let model = Model::new(Profile::Gt200, &m.prog);
        let args = [Arg::Ptr(out), Arg::Ptr(inb), Arg::I32(0), Arg::I32(0)];
        dev.launch_observed(&m, "ldg_gather", LaunchConfig::linear(6, 256), &args, Some(&model)).unwrap();
        let s = model.finish();
        assert_eq!(s.counters.texture.sectors, 6 * 16, "{threads} threads");
        assert_eq!((s.counters.texture.misses, s.counters.texture.hits), (2, 94), "{threads} threads");
    }
}
