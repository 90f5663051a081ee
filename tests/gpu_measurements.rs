//! warplight against two GPU measurements of `docs/gpu-measurements.md`
//! (an H200, CUDA 13.0):
//!
//! - FFMA contraction by ptxas (`tests/fixtures/gpu_fma_contraction.json`):
//!   every case kernel must give exactly the bits of the `ptxas --fmad=false`
//!   build (the f32 and f64 cases; f16 arithmetic is not supported yet),
//!   since warplight rounds each `mul`/`add` as written. Known
//!   difference: warplight does not model ptxas's default contraction, so
//!   precisely the cases that ptxas contracts differ from the default build.
//! - SFU approximations (`tests/fixtures/gpu_sfu_{approx,samples}.json`):
//!   warplight computes `rcp/rsqrt/sqrt/ex2.approx` correctly rounded; on the
//!   sampled inputs (exponent sweep, special values, the GPU's worst inputs) it
//!   must agree with the GPU on NaN-ness and lie within the largest distance
//!   the GPU showed from the correctly rounded result over all 2^32 inputs.

mod common;
use common::*;
use serde_json::Value;
use warplight::sim::{Arg, LaunchConfig};

fn json(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn words(v: &Value) -> Vec<u64> {
    v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect()
}

const HEADER: &str = ".version 8.0\n.target sm_90\n.address_size 64\n\n";

/// The fixture's kernels declare several registers in one `.reg` line
/// (`.reg .b32 %i, %n, %r<4>;`), which ptxas accepts and warplight's parser
/// does not yet; this splits such lines into one declaration per name.
fn one_name_per_reg(ptx: &str) -> String {
    let mut out = String::new();
    for line in ptx.lines() {
        let t = line.trim();
        match t.strip_prefix(".reg ").and_then(|r| r.strip_suffix(';')).and_then(|r| r.split_once(' ')) {
            Some((ty, names)) if names.contains(',') => {
                for n in names.split(',') {
                    out += &format!("    .reg {ty} {};\n", n.trim());
                }
            }
            _ => {
                out += line;
                out.push('\n');
            }
        }
    }
    out
}

#[test]
fn contraction_cases_equal_ptxas_fmad_false_and_differ_exactly_where_ptxas_contracts() {
    let fx = json("tests/fixtures/gpu_fma_contraction.json");
    let cases = fx["cases"].as_array().unwrap();
    assert!(cases.len() >= 40);
    let mut dev = device(1);
    let (mut mismatches, mut differ, mut contracted) = (Vec::new(), Vec::new(), Vec::new());
    for c in cases {
        let name = c["name"].as_str().unwrap();
        if c["type"] == "f16" {
            // Data for the f16 arithmetic still to come (issue 20, "Also"); same rule as f32.
            continue;
        }
        let src = format!("{HEADER}{}", one_name_per_reg(c["ptx"].as_str().unwrap()));
        let m = dev.load_ptx(&src, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let rows = c["inputs"].as_array().unwrap();
        let n = rows.len();
        let input: Vec<u64> = rows.iter().flat_map(words).collect();
        let f64_case = c["type"] == "f64";
        let (din, dout) = if f64_case {
            (dev.alloc_from(&input), dev.alloc_zeroed::<u64>(2 * n))
        } else {
            let v: Vec<u32> = input.iter().map(|&x| x as u32).collect();
            (dev.alloc_from(&v), dev.alloc_zeroed::<u32>(2 * n))
        };
        dev.launch(&m, name, LaunchConfig::linear(1, n as u32), &[Arg::Ptr(din), Arg::Ptr(dout)])
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let got: Vec<u64> = if f64_case {
            dev.read::<u64>(dout, 2 * n)
        } else {
            dev.read::<u32>(dout, 2 * n).into_iter().map(u64::from).collect()
        };
        let flat = |k: &str| -> Vec<u64> { c["results"][k].as_array().unwrap().iter().flat_map(words).collect() };
        let (unfused, default) = (flat("fmad_false"), flat("default"));
        if got != unfused {
            let i = (0..got.len()).find(|&i| got[i] != unfused[i]).unwrap();
            mismatches.push(format!("{name} word {i}: fmad=false {:#x}, warplight {:#x}", unfused[i], got[i]));
        }
        if got != default {
            differ.push(name);
        }
        if c["contracted"].as_bool().unwrap() {
            contracted.push(name);
        }
    }
    assert!(
        mismatches.is_empty(),
        "{} cases differ from ptxas --fmad=false:\n{}",
        mismatches.len(),
        mismatches.join("\n")
    );
    // Known difference (issue 20 item 4): no contraction is modelled yet.
    assert_eq!(differ, contracted, "cases where warplight differs from ptxas's default build");
    assert!(contracted.len() >= 20);
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
