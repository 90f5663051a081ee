//! CUDA's math library (libdevice, linked by `warplight compile`) in the
//! emulator against an H200: `tools/device/mathlib.cu` over 2,048 inputs
//! (`tests/fixtures/mathlib/inputs.bin`), compiled by clang-16 with libdevice
//! into `tests/fixtures/mathlib/mathlib.ptx`; the same PTX ran on the GPU
//! through the driver (`tools/device/mathlib.sh`), its outputs are
//! `h200_clang.f32.bin` / `.f64.bin`.
//!
//! Functions whose libdevice code uses no `.approx` instruction must match
//! bit for bit. The others reach the GPU's SFU (`ex2`, `lg2`, `sin`, `cos`,
//! `rsqrt`, `rcp` approximations), which warplight computes correctly rounded
//! (`docs/semantics.md`): they must stay within 2 ulp, and the `__expf`-style
//! intrinsics (a single SFU instruction or two) within 2^-20 relative to
//! max(1, |result|) on |x| ≤ 4. `docs/prelude.md` has the measured table.

use std::cmp::Ordering;

use warplight::sim::{Arg, Device, LaunchConfig};

const N: usize = 2048;

/// The rows of `out` in `mathlib.cu`'s order, and how each is compared.
const F32_ROWS: [(&str, Cmp); 45] = {
    use Cmp::*;
    [
        ("expf", Ulp(2)),
        ("exp2f", Ulp(2)),
        ("exp10f", Ulp(2)),
        ("expm1f", Exact),
        ("logf", Exact),
        ("log2f", Exact),
        ("log10f", Exact),
        ("log1pf", Exact),
        ("sinf", Exact),
        ("cosf", Exact),
        ("tanf", Ulp(2)),
        ("asinf", Ulp(2)),
        ("acosf", Exact),
        ("atanf", Ulp(2)),
        ("atan2f", Exact),
        ("sinhf", Ulp(2)),
        ("coshf", Ulp(2)),
        ("tanhf", Ulp(2)),
        ("powf", Exact),
        ("sqrtf", Exact),
        ("rsqrtf", Ulp(2)),
        ("cbrtf", Ulp(2)),
        ("floorf", Exact),
        ("ceilf", Exact),
        ("roundf", Exact),
        ("truncf", Exact),
        ("fabsf", Exact),
        ("fminf", Exact),
        ("fmaxf", Exact),
        ("fmodf", Exact),
        ("hypotf", Ulp(2)),
        ("erff", Ulp(2)),
        ("a / b", Exact),
        ("min(float)", Exact),
        ("max(float)", Exact),
        ("abs(float)", Exact),
        ("__expf", Sfu),
        ("__logf", Sfu),
        ("__sinf", Sfu),
        ("__cosf", Sfu),
        ("__powf", Sfu),
        ("__fdividef", Sfu),
        ("min(int)", Exact),
        ("max(int)", Exact),
        ("abs(int)", Exact),
    ]
};

/// The rows of `outd` (double precision; none uses an approximation).
const F64_ROWS: [&str; 5] = ["exp", "log", "atan2", "pow", "sqrt"];

#[derive(Debug, Clone, Copy)]
enum Cmp {
    /// Bit for bit (NaNs of any payload are equal).
    Exact,
    /// Within this many units in the last place.
    Ulp(u32),
    /// A single SFU approximation: within 2^-20 · max(1, |gpu|) on small inputs.
    Sfu,
}

fn read_f32(path: &str) -> Vec<u32> {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    b.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect()
}

fn read_f64(path: &str) -> Vec<u64> {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    b.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().unwrap())).collect()
}

/// Distance in representable f32 values: 0 for equal bits or two NaNs (and
/// for -0 and +0, which `Exact` tells apart), `u64::MAX` for a NaN and a number.
fn ulps(a: u32, b: u32) -> u64 {
    let nan = |v: u32| f32::from_bits(v).is_nan();
    if nan(a) && nan(b) {
        return 0;
    }
    if nan(a) != nan(b) {
        return u64::MAX;
    }
    let key = |v: u32| if v >> 31 == 1 { 0x8000_0000u64 - (v & 0x7fff_ffff) as u64 } else { 0x8000_0000u64 + v as u64 };
    key(a).abs_diff(key(b))
}

fn same64(a: u64, b: u64) -> bool {
    a == b || (f64::from_bits(a).is_nan() && f64::from_bits(b).is_nan())
}

#[test]
fn libdevice_in_the_emulator_matches_the_gpu() {
    let dir = "tests/fixtures/mathlib";
    let inputs = read_f32(&format!("{dir}/inputs.bin"));
    let (x, y) = inputs.split_at(N);
    let ptx = std::fs::read_to_string(format!("{dir}/mathlib.ptx")).unwrap();
    let mut dev = Device::new();
    let m = dev.load_ptx(&ptx, "mathlib.ptx").unwrap_or_else(|e| panic!("{e}"));
    let xs: Vec<f32> = x.iter().map(|b| f32::from_bits(*b)).collect();
    let ys: Vec<f32> = y.iter().map(|b| f32::from_bits(*b)).collect();
    let (px, py) = (dev.alloc_from(&xs), dev.alloc_from(&ys));
    let out = dev.alloc_zeroed::<u32>(F32_ROWS.len() * N);
    let outd = dev.alloc_zeroed::<u64>(F64_ROWS.len() * N);
    let args = [Arg::Ptr(px), Arg::Ptr(py), Arg::Ptr(out), Arg::Ptr(outd), Arg::I32(N as i32)];
    dev.launch(&m, "mathlib", LaunchConfig::linear((N / 128) as u32, 128), &args).unwrap_or_else(|e| panic!("{e}"));
    let emu = dev.read::<u32>(out, F32_ROWS.len() * N);
    let emud = dev.read::<u64>(outd, F64_ROWS.len() * N);
    let gpu = read_f32(&format!("{dir}/h200_clang.f32.bin"));
    let gpud = read_f64(&format!("{dir}/h200_clang.f64.bin"));
    assert_eq!((gpu.len(), gpud.len()), (emu.len(), emud.len()));

    let mut failures = Vec::new();
    let mut exact_rows = 0;
    for (k, (name, cmp)) in F32_ROWS.iter().enumerate() {
        let row = k * N..(k + 1) * N;
        let (e, g) = (&emu[row.clone()], &gpu[row]);
        let bad: Vec<usize> = (0..N)
            .filter(|&i| match cmp {
                Cmp::Exact => e[i] != g[i] && !(f32::from_bits(e[i]).is_nan() && f32::from_bits(g[i]).is_nan()),
                Cmp::Ulp(n) => ulps(e[i], g[i]) > *n as u64,
                Cmp::Sfu => {
                    let (a, b) = (f32::from_bits(x[i]).abs(), f32::from_bits(y[i]).abs());
                    let domain = a <= 4.0
                        && (0.0625..=4.0).contains(&b)
                        && (!matches!(*name, "__logf" | "__powf") || f32::from_bits(x[i]) > 0.0625);
                    let (ve, vg) = (f32::from_bits(e[i]) as f64, f32::from_bits(g[i]) as f64);
                    {
                        // NaN on one side only is a difference too
                        let within = (ve - vg).abs().partial_cmp(&(2f64.powi(-20) * vg.abs().max(1.0)));
                        domain && ulps(e[i], g[i]) != 0 && !matches!(within, Some(Ordering::Less | Ordering::Equal))
                    }
                }
            })
            .collect();
        if matches!(cmp, Cmp::Exact) {
            exact_rows += 1;
        }
        if let Some(&i) = bad.first() {
            failures.push(format!(
                "{name} ({cmp:?}): {} inputs differ, first x = {:e}, y = {:e}: emulator {:#010x}, H200 {:#010x}",
                bad.len(),
                f32::from_bits(x[i]),
                f32::from_bits(y[i]),
                e[i],
                g[i]
            ));
        }
    }
    for (k, name) in F64_ROWS.iter().enumerate() {
        let bad = (k * N..(k + 1) * N).filter(|&i| !same64(emud[i], gpud[i])).count();
        if bad > 0 {
            failures.push(format!("{name} (double, Exact): {bad} inputs differ"));
        }
    }
    assert_eq!(exact_rows, 26, "26 of the 45 single-precision rows are compared bit for bit");
    assert!(failures.is_empty(), "the emulator differs from the H200:\n{}", failures.join("\n"));
}

#[test]
fn the_inputs_cover_special_values_and_every_magnitude() {
    // guards the fixture against a regenerated, narrower sample
    let x: Vec<f32> = read_f32("tests/fixtures/mathlib/inputs.bin")[..N].iter().map(|b| f32::from_bits(*b)).collect();
    assert!(x.iter().any(|v| v.is_nan()) && x.contains(&f32::INFINITY) && x.contains(&f32::NEG_INFINITY));
    assert!(x.iter().any(|v| *v == 0.0 && v.is_sign_negative()) && x.iter().any(|v| v.is_subnormal()));
    for e in -40..40 {
        let (lo, hi) = (2f32.powi(e), 2f32.powi(e + 1));
        assert!(x.iter().any(|v| (lo..hi).contains(&v.abs())), "no input with |x| in [2^{e}, 2^{})", e + 1);
    }
}

/// libdevice's double `sin`, `cos` and `tan` (`tools/device/trig64.cu`): no
/// `.approx` instruction, so bit for bit; arguments past 2^20 or so take the
/// long (Payne-Hanek) reduction, an inline-assembly carry chain
/// (`mad.lo.cc`/`madc.hi.cc`/`addc`, `sub.cc`/`subc`) that warplight runs as
/// clang wrote it. The same PTX ran on an H200 (`tools/device/trig64.sh`).
#[test]
fn double_sin_cos_tan_match_the_gpu_through_the_carry_chains() {
    const N: usize = 2560;
    let dir = "tests/fixtures/mathlib";
    let x: Vec<f64> = read_f64(&format!("{dir}/trig64_inputs.bin")).into_iter().map(f64::from_bits).collect();
    assert_eq!(x.len(), N);
    assert!(x.iter().filter(|v| v.abs() > 1e300).count() >= 5, "the sample reaches the largest exponents");
    let ptx = std::fs::read_to_string(format!("{dir}/trig64.ptx")).unwrap();
    for chain in ["mad.lo.cc.u32", "madc.hi.cc.u32", "addc.u32", "sub.cc.u32", "subc.cc.u32"] {
        assert!(ptx.contains(chain), "the fixture's PTX runs the carry chain ({chain}) itself");
    }
    let mut dev = Device::new();
    let m = dev.load_ptx(&ptx, "trig64.ptx").unwrap_or_else(|e| panic!("{e}"));
    let px = dev.alloc_from(&x);
    let out = dev.alloc_zeroed::<u64>(3 * N);
    let args = [Arg::Ptr(px), Arg::Ptr(out), Arg::I32(N as i32)];
    dev.launch(&m, "trig64", LaunchConfig::linear((N / 128) as u32, 128), &args).unwrap_or_else(|e| panic!("{e}"));
    let emu = dev.read::<u64>(out, 3 * N);
    let gpu = read_f64(&format!("{dir}/h200_trig64_clang.f64.bin"));
    assert_eq!(gpu.len(), emu.len());
    let mut failures = Vec::new();
    for (k, name) in ["sin", "cos", "tan"].iter().enumerate() {
        let bad: Vec<usize> = (0..N).filter(|&i| !same64(emu[k * N + i], gpu[k * N + i])).collect();
        if let Some(&i) = bad.first() {
            failures.push(format!(
                "{name}: {} inputs differ, first x = {:e}: emulator {:e}, H200 {:e}",
                bad.len(),
                x[i],
                f64::from_bits(emu[k * N + i]),
                f64::from_bits(gpu[k * N + i])
            ));
        }
    }
    assert!(failures.is_empty(), "the emulator differs from the H200:\n{}", failures.join("\n"));
}
