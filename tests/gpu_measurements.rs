//! warplight against two GPU measurements of `docs/gpu-measurements.md`
//! (an H200, CUDA 13.0):
//!
//! - FFMA contraction by ptxas (`tests/fixtures/gpu_fma_contraction.json`):
//!   every case kernel (f32, f64, f16) must give exactly the bits of ptxas's
//!   default build with contraction on (warplight's default), and of the
//!   `ptxas --fmad=false` build with it off.
//! - SFU approximations (`tests/fixtures/gpu_sfu_{approx,samples}.json`):
//!   warplight computes `rcp/rsqrt/sqrt/ex2.approx` correctly rounded; on the
//!   sampled inputs (exponent sweep, special values, the GPU's worst inputs) it
//!   must agree with the GPU on NaN-ness and lie within the largest distance
//!   the GPU showed from the correctly rounded result over all 2^32 inputs.

mod common;
use common::*;
use serde_json::Value;
use warplight::sim::sfu::SfuModel;
use warplight::sim::{Arg, Device, LaunchConfig, SimConfig};

fn json(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn words(v: &Value) -> Vec<u64> {
    v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect()
}

const HEADER: &str = ".version 8.0\n.target sm_90\n.address_size 64\n\n";

/// Runs every f32/f64 contraction case with contraction on or off and
/// returns the cases whose bits differ from the fixture's build `want`
/// (`default` or `fmad_false`), with the first differing word.
fn contraction_mismatches(fmad: bool, want: &str) -> (usize, Vec<String>) {
    let fx = json("tests/fixtures/gpu_fma_contraction.json");
    let cases = fx["cases"].as_array().unwrap();
    assert!(cases.len() >= 50);
    let mut dev = Device::with_config(SimConfig { threads: 1, fmad, ..SimConfig::default() });
    let mut mismatches = Vec::new();
    let mut run = 0;
    for c in cases {
        let name = c["name"].as_str().unwrap();
        let width = match c["type"].as_str().unwrap() {
            "f64" => 8,
            "f32" => 4,
            _ => 2,
        };
        let src = format!("{HEADER}{}", c["ptx"].as_str().unwrap());
        let m = dev.load_ptx(&src, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let rows = c["inputs"].as_array().unwrap();
        let n = rows.len();
        let input: Vec<u64> = rows.iter().flat_map(words).collect();
        let bytes: Vec<u8> = input.iter().flat_map(|x| x.to_le_bytes()[..width].to_vec()).collect();
        let (din, dout) = (dev.alloc_from(&bytes), dev.alloc_zeroed::<u8>(2 * n * width));
        dev.launch(&m, name, LaunchConfig::linear(1, n as u32), &[Arg::Ptr(din), Arg::Ptr(dout)])
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let got: Vec<u64> = dev
            .read::<u8>(dout, 2 * n * width)
            .chunks(width)
            .map(|b| b.iter().rev().fold(0u64, |v, x| v << 8 | *x as u64))
            .collect();
        let expected: Vec<u64> = c["results"][want].as_array().unwrap().iter().flat_map(words).collect();
        run += 1;
        if got != expected {
            let i = (0..got.len()).find(|&i| got[i] != expected[i]).unwrap();
            mismatches.push(format!("{name} word {i}: {want} {:#x}, warplight {:#x}", expected[i], got[i]));
        }
    }
    (run, mismatches)
}

/// With contraction on (the default) every case gives the bits of ptxas's
/// default build, bit for bit: the contraction rule of `warplight::sim::contract`.
#[test]
fn contraction_cases_equal_ptxas_default_build() {
    let (run, mismatches) = contraction_mismatches(true, "default");
    assert!(run >= 53, "{run} cases run");
    assert!(mismatches.is_empty(), "{} cases differ from ptxas:\n{}", mismatches.len(), mismatches.join("\n"));
}

/// With contraction off every case gives the bits of `ptxas --fmad=false`.
#[test]
fn contraction_off_equals_ptxas_fmad_false() {
    let (run, mismatches) = contraction_mismatches(false, "fmad_false");
    assert!(run >= 53, "{run} cases run");
    assert!(mismatches.is_empty(), "{} cases differ:\n{}", mismatches.len(), mismatches.join("\n"));
}

/// The two settings differ exactly in the cases ptxas contracts (the fixture
/// has inputs on which fused and unfused results differ on every thread).
#[test]
fn the_fixture_separates_fused_from_unfused() {
    let fx = json("tests/fixtures/gpu_fma_contraction.json");
    for c in fx["cases"].as_array().unwrap() {
        let differ = c["results"]["default"] != c["results"]["fmad_false"];
        assert_eq!(differ, c["contracted"].as_bool().unwrap(), "{}", c["name"]);
    }
}

/// The largest |ord(gpu) - ord(RN(exact))| in an instruction's histogram (bins of gpu_sfu_approx.json).
fn max_distance(op: &Value) -> i64 {
    let h = words(&op["hist"]);
    let mut m = 0i64;
    for (b, &count) in h.iter().enumerate().take(89) {
        if count == 0 {
            continue;
        }
        let d = match b {
            0..=32 => (b as i64 - 16).abs(),
            33..=60 => (1i64 << (b - 33 + 5)) - 1,
            _ => (1i64 << (b - 61 + 5)) - 1,
        };
        m = m.max(d);
    }
    m
}

fn ord(b: u32) -> i64 {
    if b & 0x8000_0000 != 0 { -((b & 0x7fff_ffff) as i64) } else { b as i64 }
}

fn is_nan(b: u32) -> bool {
    b & 0x7fff_ffff > 0x7f80_0000
}

#[test]
fn approx_instructions_lie_within_the_gpus_measured_distance() {
    let stats = json("tests/fixtures/gpu_sfu_approx.json");
    let samples = json("tests/fixtures/gpu_sfu_samples.json");
    let mut dev = device(1);
    let mut failures = Vec::new();
    let mut checked = 0;
    for (op, smp) in stats["ops"].as_array().unwrap().iter().zip(samples["ops"].as_array().unwrap()) {
        let name = op["name"].as_str().unwrap();
        assert_eq!(smp["name"], op["name"]);
        if !["rcp.", "rsqrt.", "sqrt.", "ex2."].iter().any(|p| name.starts_with(p)) {
            continue;
        }
        let bound = max_distance(op);
        assert!(bound <= 3, "{name}: the GPU's histogram reaches {bound}");
        let ptx = format!(
            "{HEADER}.visible .entry k(.param .u64 pin, .param .u64 pout)\n{{\n\
             .reg .b32 %r<4>;\n.reg .b64 %rd<6>;\n.reg .f32 %f<2>;\n\
             ld.param.u64 %rd0, [pin];\nld.param.u64 %rd1, [pout];\n\
             cvta.to.global.u64 %rd0, %rd0;\ncvta.to.global.u64 %rd1, %rd1;\n\
             mov.u32 %r0, %tid.x;\nmov.u32 %r1, %ctaid.x;\nmov.u32 %r2, %ntid.x;\nmad.lo.u32 %r3, %r1, %r2, %r0;\n\
             mul.wide.u32 %rd2, %r3, 4;\nadd.u64 %rd3, %rd0, %rd2;\nadd.u64 %rd4, %rd1, %rd2;\n\
             ld.global.f32 %f0, [%rd3];\n{name} %f1, %f0;\nst.global.f32 [%rd4], %f1;\nret;\n}}\n"
        );
        let m = dev.load_ptx(&ptx, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let x: Vec<u32> = words(&smp["x"]).into_iter().map(|v| v as u32).collect();
        let y: Vec<u32> = words(&smp["y"]).into_iter().map(|v| v as u32).collect();
        let ctas = x.len().div_ceil(256);
        let mut input = x.clone();
        input.resize(ctas * 256, 0);
        let (din, dout) = (dev.alloc_from(&input), dev.alloc_zeroed::<u32>(input.len()));
        dev.launch(&m, "k", LaunchConfig::linear(ctas as u32, 256), &[Arg::Ptr(din), Arg::Ptr(dout)])
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let got = dev.read::<u32>(dout, x.len());
        for i in 0..x.len() {
            checked += 1;
            let (g, w) = (y[i], got[i]);
            let ok = if is_nan(g) || is_nan(w) { is_nan(g) && is_nan(w) } else { (ord(g) - ord(w)).abs() <= bound };
            if !ok {
                failures.push(format!("{name}({:#010x}): gpu {g:#010x}, warplight {w:#010x} (bound {bound})", x[i]));
            }
        }
    }
    assert!(checked > 10_000, "{checked} samples checked");
    assert!(failures.is_empty(), "{} samples outside the bound:\n{}", failures.len(), failures.join("\n"));
}

fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// The H200's MUFU table model (`warplight::sim::sfu`, the default) gives the
/// GPU's bits on every sample of `rcp`, `rsqrt`, `sqrt` (`.approx`, both flush
/// modes), `div.approx` and `div.full`, run as PTX kernels; with the
/// correctly rounded model some samples differ (so the test can fail).
#[test]
fn mufu_table_model_equals_the_gpu_bit_for_bit() {
    let samples = json("tests/fixtures/gpu_sfu_samples.json");
    let run = |sfu: SfuModel| {
        let mut dev = Device::with_config(SimConfig { threads: 1, sfu, ..SimConfig::default() });
        let (mut checked, mut failures) = (0, Vec::new());
        for smp in samples["ops"].as_array().unwrap() {
            let name = smp["name"].as_str().unwrap();
            if !["rcp.", "rsqrt.", "sqrt.", "div."].iter().any(|p| name.starts_with(p)) {
                continue;
            }
            let div = name.starts_with("div.");
            let wide = smp["a_mode"].as_str() == Some("a = mix32(b)");
            let inst = if div { format!("{name} %f1, %f2, %f0;") } else { format!("{name} %f1, %f0;") };
            let ptx = format!(
                "{HEADER}.visible .entry k(.param .u64 pin, .param .u64 pa, .param .u64 pout)\n{{\n\
                 .reg .b32 %r<4>;\n.reg .b64 %rd<8>;\n.reg .f32 %f<3>;\n\
                 ld.param.u64 %rd0, [pin];\nld.param.u64 %rd1, [pout];\nld.param.u64 %rd5, [pa];\n\
                 mov.u32 %r0, %tid.x;\nmov.u32 %r1, %ctaid.x;\nmov.u32 %r2, %ntid.x;\nmad.lo.u32 %r3, %r1, %r2, %r0;\n\
                 mul.wide.u32 %rd2, %r3, 4;\nadd.u64 %rd3, %rd0, %rd2;\nadd.u64 %rd4, %rd1, %rd2;\nadd.u64 %rd6, %rd5, %rd2;\n\
                 ld.global.f32 %f0, [%rd3];\nld.global.f32 %f2, [%rd6];\n{inst}\nst.global.f32 [%rd4], %f1;\nret;\n}}\n"
            );
            let m = dev.load_ptx(&ptx, name).unwrap_or_else(|e| panic!("{name}: {e}"));
            let x: Vec<u32> = words(&smp["x"]).into_iter().map(|v| v as u32).collect();
            let y: Vec<u32> = words(&smp["y"]).into_iter().map(|v| v as u32).collect();
            let a: Vec<u32> =
                x.iter().map(|&b| if wide { mix32(b) } else { 0x3f80_0000 | (mix32(b) & 0x7f_ffff) }).collect();
            let ctas = x.len().div_ceil(256);
            let (mut xin, mut ain) = (x.clone(), a.clone());
            xin.resize(ctas * 256, 0);
            ain.resize(ctas * 256, 0);
            let (din, da, dout) = (dev.alloc_from(&xin), dev.alloc_from(&ain), dev.alloc_zeroed::<u32>(xin.len()));
            dev.launch(&m, "k", LaunchConfig::linear(ctas as u32, 256), &[Arg::Ptr(din), Arg::Ptr(da), Arg::Ptr(dout)])
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let got = dev.read::<u32>(dout, x.len());
            for i in 0..x.len() {
                checked += 1;
                if got[i] != y[i] {
                    failures.push(format!(
                        "{name}({:#010x}, a {:#010x}): gpu {:#010x}, warplight {:#010x}",
                        x[i], a[i], y[i], got[i]
                    ));
                }
            }
        }
        (checked, failures)
    };
    let (checked, failures) = run(SfuModel::Sm90);
    assert!(checked > 20_000, "{checked} samples checked");
    assert!(
        failures.is_empty(),
        "{} samples differ:\n{}",
        failures.len(),
        failures[..failures.len().min(20)].join("\n")
    );
    let (_, rounded) = run(SfuModel::CorrectlyRounded);
    assert!(rounded.len() > 1000, "the correctly rounded model differs on {} samples only", rounded.len());
}
