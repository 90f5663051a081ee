//! Half-precision `ex2.approx` and `tanh.approx` (`.f16 .bf16 .f16x2
//! .bf16x2`) against an H200 on all 2^16 inputs
//! (`tests/fixtures/gpu_half_sfu.bin.z`: the zlib-compressed results of
//! `ex2_f16`, `tanh_f16`, `ex2_bf16`, `tanh_bf16` of
//! `kernels/tests/half_sfu.cu`, 2^16 little-endian u16 each, made by
//! `tools/gpu/probe_tex_calls.sh`; the packed kernels gave the same halves).
//! warplight's model (`warplight::sim::half::sfu`) differs from the GPU on
//! exactly the counted inputs, and the kernels in both PTX dialects execute
//! the model.

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
