//! Half-precision `ex2.approx` and `tanh.approx` (`.f16 .bf16 .f16x2
//! .bf16x2`) against an H200 on all 2^16 inputs
//! (`tests/fixtures/gpu_half_sfu.bin.z`: the zlib-compressed results of
//! `ex2_f16`, `tanh_f16`, `ex2_bf16`, `tanh_bf16` of
//! `kernels/tests/half_sfu.cu`, 2^16 little-endian u16 each, made by
//! `tools/gpu/probe_tex_calls.sh`; the packed kernels gave the same halves).
//! warplight's model (`warplight::sim::half::sfu`) differs from the GPU on
//! exactly the counted inputs, and the kernels in both PTX dialects execute
//! the model.

// The loops index several tables by the input value itself.
#![allow(clippy::needless_range_loop)]

mod common;

use common::{BOTH, load};
use warplight::ptx::ir::ArithOp;
use warplight::sim::half::{sfu, to_f64};
use warplight::sim::{Arg, Device, LaunchConfig};

/// Kernel, operation, bfloat16, `.ftz` (as `half_sfu.cu` writes them).
const KERNELS: [(&str, ArithOp, bool, bool); 4] = [
    ("ex2_f16", ArithOp::Ex2, false, false),
    ("tanh_f16", ArithOp::Tanh, false, false),
    ("ex2_bf16", ArithOp::Ex2, true, true),
    ("tanh_bf16", ArithOp::Tanh, true, false),
];

fn gpu() -> Vec<Vec<u16>> {
    let z = std::fs::read("tests/fixtures/gpu_half_sfu.bin.z").unwrap();
    let raw = miniz_oxide::inflate::decompress_to_vec_zlib(&z).unwrap();
    raw.chunks(2 << 16).map(|t| t.chunks(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect()).collect()
}

#[test]
fn the_model_differs_from_the_h200_on_the_counted_inputs_only() {
    let g = gpu();
    // measured: inputs whose result differs from the H200's (NaN inputs excluded)
    let expected = [0, 324, 0, 38];
    for ((name, op, bf, ftz), (table, want)) in KERNELS.iter().zip(g.iter().zip(expected)) {
        let mut off = 0;
        for i in 0..=u16::MAX {
            let x = to_f64(i, *bf);
            if x.is_nan() {
                continue;
            }
            let m = sfu(*op, *bf, *ftz, x);
            if m != table[i as usize] {
                off += 1;
                // never more than one step of the half type
                assert_eq!((m as i32 - table[i as usize] as i32).abs(), 1, "{name} {i:#06x}");
            }
        }
        assert_eq!(off, want, "{name}");
    }
}

#[test]
fn the_kernels_execute_the_model_in_both_dialects() {
    let n = 1usize << 16;
    for d in BOTH {
        let mut dev = Device::new();
        let m = load(&mut dev, "half_sfu", d);
        for (name, op, bf, ftz) in KERNELS {
            let out = dev.alloc_zeroed::<u16>(n);
            dev.launch(&m, name, LaunchConfig::linear((n / 256) as u32, 256), &[Arg::Ptr(out), Arg::I32(n as i32)])
                .unwrap();
            let got: Vec<u16> = dev.read(out, n);
            for i in 0..n {
                let x = to_f64(i as u16, bf);
                let want = if x.is_nan() { 0x7fff } else { sfu(op, bf, ftz, x) };
                assert_eq!(got[i], want, "{name} ({d:?}) input {i:#06x}");
            }
            // the packed form: both halves as the scalar one
            let x2 = format!("{}x2", name);
            let out2 = dev.alloc_zeroed::<u32>(n);
            dev.launch(&m, &x2, LaunchConfig::linear((n / 256) as u32, 256), &[Arg::Ptr(out2), Arg::I32(n as i32)])
                .unwrap();
            let got2: Vec<u32> = dev.read(out2, n);
            for i in 0..n {
                assert_eq!(got2[i] & 0xffff, got[i] as u32, "{x2} ({d:?}) low {i:#06x}");
                assert_eq!(got2[i] >> 16, got[n - 1 - i] as u32, "{x2} ({d:?}) high {i:#06x}");
            }
        }
    }
}

/// The cases of `tests/fixtures/gpu_textures.json` named `name`.
fn probe_case(name: &str) -> serde_json::Value {
    let f: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("tests/fixtures/gpu_textures.json").unwrap()).unwrap();
    f["cases"].as_array().unwrap().iter().find(|c| c["name"] == name).unwrap().clone()
}

fn u32s(v: &serde_json::Value) -> Vec<u32> {
    v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as u32).collect()
}

#[test]
fn setp_on_packed_halves_equals_the_h200() {
    // 14 comparisons (eq ne lt le gt ge equ neu ltu leu gtu geu nan num) of
    // every pair of 11 values (zeros, ±1, ±inf, NaNs, a subnormal ...), two
    // predicates each
    for name in ["setp_f16x2", "setp_bf16x2"] {
        let c = probe_case(name);
        let (a, b, want) = (u32s(&c["a"]), u32s(&c["b"]), u32s(&c["out"]));
        for d in BOTH {
            let mut dev = Device::new();
            let m = load(&mut dev, "half_sfu", d);
            let (pa, pb) = (dev.alloc_from(&a), dev.alloc_from(&b));
            let out = dev.alloc_zeroed::<u32>(want.len());
            let n = want.len() as i32;
            dev.launch(
                &m,
                name,
                LaunchConfig::linear(1, 128),
                &[Arg::Ptr(pa), Arg::Ptr(pb), Arg::Ptr(out), Arg::I32(n)],
            )
            .unwrap();
            assert_eq!(dev.read::<u32>(out, want.len()), want, "{name} ({d:?})");
        }
    }
}

#[test]
fn tanh_approx_f32_is_within_the_measured_error() {
    // the H200's tanh.approx.f32 samples (tests/fixtures/gpu_sfu_samples.json):
    // warplight computes tanh correctly rounded; the GPU is within 134 ulp of it
    let f: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("tests/fixtures/gpu_sfu_samples.json").unwrap()).unwrap();
    let op = f["ops"].as_array().unwrap().iter().find(|o| o["name"] == "tanh.approx.f32").unwrap();
    let (x, y) = (u32s(&op["x"]), u32s(&op["y"]));
    for d in BOTH {
        let mut dev = Device::new();
        let m = load(&mut dev, "half_sfu", d);
        let (px, out) = (dev.alloc_from(&x), dev.alloc_zeroed::<u32>(x.len()));
        let n = x.len();
        dev.launch(
            &m,
            "tanh_f32",
            LaunchConfig::linear(n.div_ceil(128) as u32, 128),
            &[Arg::Ptr(px), Arg::Ptr(out), Arg::I32(n as i32)],
        )
        .unwrap();
        let got: Vec<u32> = dev.read(out, n);
        let ord = |v: u32| if v >> 31 == 1 { -((v & 0x7fff_ffff) as i64) } else { v as i64 };
        for i in 0..n {
            let (g, w) = (f32::from_bits(got[i]), f32::from_bits(y[i]));
            if g.is_nan() || w.is_nan() {
                assert_eq!(g.is_nan(), w.is_nan(), "tanh({:#x})", x[i]);
                continue;
            }
            assert!((ord(got[i]) - ord(y[i])).abs() <= 134, "tanh({:#x}): warplight {g}, H200 {w}", x[i]);
        }
    }
}
