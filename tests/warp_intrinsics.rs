//! The CUDA intrinsics that compile to the newer PTX instructions —
//! `__reduce_*_sync` (`redux.sync`), `__match_*_sync` (`match.sync`),
//! `__syncthreads_count/_or/_and` (`bar.red`), `__byte_perm` (`prmt`),
//! `__popcll`/`__clzll`/`__brevll` (64-bit) and `__activemask` — as clang-16
//! and nvcc emit them (`kernels/tests/intrinsics.cu`), against Rust references.

mod common;
use common::*;
use warplight::sim::{Arg, LaunchConfig};

const W: usize = 14;

fn mix(i: u32) -> u32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x5bd1_e995;
    x ^= x >> 15;
    x = x.wrapping_mul(0x2c1b_3c6d);
    x ^ (x >> 12)
}

/// What every thread of one 256-thread CTA must write, from CUDA's definitions.
fn reference(input: &[u32]) -> Vec<u32> {
    let n = input.len();
    let cnt = input.iter().filter(|&&x| x & 1 != 0).count() as u32;
    let any = input.iter().any(|&x| x % 97 == 0) as u32;
    let all = input.iter().all(|&x| x != 12345) as u32;
    let mut out = vec![0u32; n * W];
    for (i, &x) in input.iter().enumerate() {
        let warp = &input[i / 32 * 32..i / 32 * 32 + 32];
        let o = &mut out[i * W..i * W + W];
        o[0] = warp.iter().fold(0u32, |s, v| s.wrapping_add(*v));
        o[1] = *warp.iter().min().unwrap();
        o[2] = *warp.iter().map(|v| *v as i32).collect::<Vec<_>>().iter().max().unwrap() as u32;
        o[3] = warp.iter().fold(0, |s, v| s ^ v) | warp.iter().fold(u32::MAX, |s, v| s & (v | 0xff00));
        o[4] = (0..32).filter(|&k| warp[k] & 3 == x & 3).fold(0, |m, k| m | 1 << k);
        let key = |v: u32| if i < 128 { 7 } else { v & 1 };
        let agree = warp.iter().all(|v| key(*v) == key(warp[0]));
        o[5] = if agree { u32::MAX ^ 1 } else { 0 };
        o[6] = cnt;
        o[7] = any | all << 1;
        let bytes = ((!x as u64) << 32) | x as u64;
        let s = (x >> 16) & 0x7777;
        o[8] = (0..4).fold(0, |d, k| {
            let sel = (s >> (4 * k)) & 0xF;
            let b = (bytes >> ((sel & 7) * 8)) as u32 & 0xFF;
            let b = if sel & 8 != 0 { if b & 0x80 != 0 { 0xFF } else { 0 } } else { b };
            d | b << (8 * k)
        });
        let w = ((x as u64) << 32) | x.wrapping_mul(2_654_435_761) as u64;
        o[9] = w.count_ones();
        o[10] = (w >> (x & 63)).leading_zeros();
        let r = w.reverse_bits();
        o[11] = r as u32;
        o[12] = (r >> 32) as u32;
        o[13] = if x & 1 != 0 {
            warp.iter().enumerate().filter(|(_, v)| *v & 1 != 0).fold(0, |m, (k, _)| m | 1 << k)
        } else {
            0
        };
    }
    out
}

#[test]
fn intrinsics_equal_their_definitions_in_both_dialects() {
    let n = 256;
    let mut input: Vec<u32> = (0..n as u32).map(mix).collect();
    input[77] = 97 * 1000; // __syncthreads_or: one thread true
    input[200] = 12345; // __syncthreads_and: one thread false
    let want = reference(&input);
    assert!(want.chunks(W).any(|o| o[5] == 0) && want.chunks(W).any(|o| o[5] != 0), "match.all both ways");
    for d in BOTH {
        let mut dev = device(1);
        let m = load(&mut dev, "intrinsics", d);
        let (din, dout) = (dev.alloc_from(&input), dev.alloc_zeroed::<u32>(n * W));
        dev.launch(
            &m,
            "intrinsics",
            LaunchConfig::linear(1, n as u32),
            &[Arg::Ptr(dout), Arg::Ptr(din), Arg::I32(n as i32)],
        )
        .unwrap_or_else(|e| panic!("{d:?}: {e}"));
        let got = dev.read::<u32>(dout, n * W);
        for (i, (g, w)) in got.chunks(W).zip(want.chunks(W)).enumerate() {
            assert_eq!(g, w, "{d:?} thread {i} (x = {:#x})", input[i]);
        }
    }
}
