//! Shared memory with barriers, atomics (including a persistent-threads job
//! queue), warp votes and shuffles, memory spaces and widths.

#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use warplight::sim::{Arg, LaunchConfig};

#[test]
fn shared_reduction_with_barriers() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "shared", d);
        let input: Vec<i32> = (0..4 * 256).map(|i| (i * 37 % 101) - 50).collect();
        let inb = dev.alloc_from(&input);
        let out = dev.alloc_zeroed::<i32>(4);
        let s = dev.launch(&m, "reduce_sum", LaunchConfig::linear(4, 256), &[Arg::Ptr(out), Arg::Ptr(inb)]).unwrap();
        let got = dev.read::<i32>(out, 4);
        for b in 0..4 {
            assert_eq!(got[b], input[b * 256..(b + 1) * 256].iter().sum::<i32>(), "{d:?}");
        }
        // 1 barrier after the load + 8 in the loop (strides 128..1), per CTA.
        assert_eq!(s.totals.barriers, 4 * 9, "{d:?}");
        assert_eq!(s.totals.barrier_warp_arrivals, 4 * 9 * 8, "{d:?}: 8 warps arrive at each");
    }
}

#[test]
fn tiled_matmul() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "shared", d);
        let n = 32usize;
        let a: Vec<f32> = (0..n * n).map(|i| ((i * 7) % 13) as f32 - 6.0).collect();
        let b: Vec<f32> = (0..n * n).map(|i| ((i * 5) % 11) as f32 * 0.5).collect();
        let (ab, bb) = (dev.alloc_from(&a), dev.alloc_from(&b));
        let cb = dev.alloc_zeroed::<f32>(n * n);
        let cfg = LaunchConfig { grid: [2, 2, 1], block: [16, 16, 1], dynamic_shared: 0 };
        dev.launch(&m, "matmul_tiled", cfg, &[Arg::Ptr(cb), Arg::Ptr(ab), Arg::Ptr(bb), Arg::I32(n as i32)]).unwrap();
        let c = dev.read::<f32>(cb, n * n);
        for r in 0..n {
            for col in 0..n {
                let mut acc = 0f32;
                for k in 0..n {
                    acc = a[r * n + k].mul_add(b[k * n + col], acc);
                }
                assert_eq!(c[r * n + col], acc, "{d:?} ({r},{col})");
            }
        }
    }
}

#[test]
fn dynamic_shared_memory() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "shared", d);
        let input: Vec<i32> = (0..3 * 96).collect();
        let inb = dev.alloc_from(&input);
        let out = dev.alloc_zeroed::<i32>(3 * 96);
        let cfg = LaunchConfig { grid: [3, 1, 1], block: [96, 1, 1], dynamic_shared: 96 * 4 };
        dev.launch(&m, "reverse_dynamic", cfg, &[Arg::Ptr(out), Arg::Ptr(inb)]).unwrap();
        let got = dev.read::<i32>(out, 3 * 96);
        for b in 0..3 {
            for t in 0..96 {
                assert_eq!(got[b * 96 + t], input[b * 96 + 95 - t]);
            }
        }
    }
}

#[test]
fn histogram_with_shared_and_global_atomics() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "shared", d);
        let data: Vec<u32> = (0..5000u32).map(|i| i.wrapping_mul(2654435761) >> 7).collect();
        let db = dev.alloc_from(&data);
        let bins = dev.alloc_zeroed::<u32>(16);
        let s = dev
            .launch(&m, "histogram", LaunchConfig::linear(4, 128), &[Arg::Ptr(bins), Arg::Ptr(db), Arg::I32(5000)])
            .unwrap();
        let mut exp = [0u32; 16];
        for v in &data {
            exp[(v & 15) as usize] += 1;
        }
        assert_eq!(dev.read::<u32>(bins, 16), exp.to_vec(), "{d:?}");
        assert_eq!(s.totals.atomic_lane_ops, 5000 + 4 * 16);
        assert_eq!(s.totals.atomics.global, 4, "{d:?}: one global atomic instruction per CTA (warp 0, 16 lanes)");
    }
}

#[test]
fn votes_act_per_warp() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "warp_ops", d);
        let out = dev.alloc_zeroed::<u32>(3 * 128);
        // all(t < 40): true in warp 0, false in warp 1 (lanes 40..63), false after.
        // any(t == 70): true in warp 2 only.
        dev.launch(&m, "votes", LaunchConfig::linear(1, 128), &[Arg::Ptr(out), Arg::I32(40), Arg::I32(70)]).unwrap();
        let got = dev.read::<u32>(out, 3 * 128);
        for t in 0..128usize {
            let w = t / 32;
            let ballot: u32 = (0..32).filter(|l| (w * 32 + l) % 3 == 0).fold(0, |m, l| m | 1 << l);
            assert_eq!(got[3 * t], ballot, "{d:?} ballot t={t}");
            assert_eq!(got[3 * t + 1], (w == 0) as u32, "{d:?} all t={t}");
            assert_eq!(got[3 * t + 2], (w == 2) as u32, "{d:?} any t={t}");
        }
    }
}

#[test]
fn shuffles() {
    for d in BOTH {
        let mut dev = device(1);
        let m = load(&mut dev, "warp_ops", d);
        let input: Vec<i32> = (0..64).map(|i| i * i - 100).collect();
        let inb = dev.alloc_from(&input);
        let out = dev.alloc_zeroed::<i32>(5 * 64);
        dev.launch(&m, "shuffles", LaunchConfig::linear(1, 64), &[Arg::Ptr(out), Arg::Ptr(inb)]).unwrap();
        let got = dev.read::<i32>(out, 5 * 64);
        for t in 0..64usize {
            let (w, l) = (t / 32 * 32, t % 32);
            assert_eq!(got[5 * t], input[w + 5], "{d:?} idx");
            assert_eq!(got[5 * t + 1], if l >= 1 { input[t - 1] } else { input[t] }, "{d:?} up t={t}");
            assert_eq!(got[5 * t + 2], if l + 2 < 32 { input[t + 2] } else { input[t] }, "{d:?} down t={t}");
            assert_eq!(got[5 * t + 3], input[w + (l ^ 1)], "{d:?} xor");
            assert_eq!(got[5 * t + 4], input[w..w + 32].iter().sum::<i32>(), "{d:?} warp sum");
        }
    }
}

#[test]
fn ballot_in_divergent_code_sees_active_lanes_only() {
    for d in BOTH {
        let mut dev = device(1);
        let m = load(&mut dev, "warp_ops", d);
        let out = dev.alloc_zeroed::<u32>(32);
        dev.launch(&m, "ballot_divergent", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap();
        let got = dev.read::<u32>(out, 32);
        for t in 0..32 {
            assert_eq!(got[t], if t & 1 == 1 { 0xAAAA_AAAA } else { 0 }, "{d:?} t={t}");
        }
    }
}

#[test]
fn atomic_contention_hands_out_every_value_once() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "atomics", d);
        let counter = dev.alloc_zeroed::<u32>(1);
        let seen = dev.alloc_zeroed::<u32>(1024);
        let s =
            dev.launch(&m, "contention", LaunchConfig::linear(8, 128), &[Arg::Ptr(counter), Arg::Ptr(seen)]).unwrap();
        assert_eq!(dev.read::<u32>(counter, 1)[0], 1024);
        let mut v = dev.read::<u32>(seen, 1024);
        // Deterministic order: CTA by CTA, warp by warp, lane by lane.
        assert_eq!(v, (0..1024).collect::<Vec<_>>(), "{d:?}");
        v.sort();
        assert_eq!(s.totals.atomics.global, 32);
        assert_eq!(s.totals.atomic_lane_ops, 1024);
    }
}

#[test]
fn every_atomic_operation() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "atomics", d);
        let init = [0i32, 1_000_000, -5, 0, 3, 7, -1, -1, 0, 0];
        let cells = dev.alloc_from(&init);
        let old = dev.alloc_zeroed::<i32>(10 * 64);
        dev.launch(&m, "all_ops", LaunchConfig::linear(2, 32), &[Arg::Ptr(cells), Arg::Ptr(old)]).unwrap();
        // Reference: apply in thread order (the order warplight defines).
        let mut c = init;
        let mut exp_old = vec![0i32; 640];
        for t in 0..64i32 {
            let o = &mut exp_old[10 * t as usize..10 * t as usize + 10];
            o[0] = c[0];
            c[0] = c[0].wrapping_add(t);
            o[1] = c[1];
            c[1] = c[1].min(1000 - t);
            o[2] = c[2];
            c[2] = c[2].max(t);
            o[3] = c[3];
            c[3] = if (c[3] as u32) >= 7 { 0 } else { c[3] + 1 };
            o[4] = c[4];
            c[4] = if c[4] == 0 || (c[4] as u32) > 5 { 5 } else { c[4] - 1 };
            o[5] = c[5];
            c[5] = t;
            o[6] = c[6];
            if c[6] == t - 1 {
                c[6] = t;
            }
            o[7] = c[7];
            c[7] &= !(1 << (t & 31));
            o[8] = c[8];
            c[8] |= 1 << (t & 31);
            o[9] = c[9];
            c[9] ^= t;
        }
        assert_eq!(dev.read::<i32>(cells, 10), c.to_vec(), "{d:?}");
        assert_eq!(dev.read::<i32>(old, 640), exp_old, "{d:?}");
    }
}

#[test]
fn float_atomic_sum_is_reproducible() {
    for d in BOTH {
        let mut results = Vec::new();
        for threads in [1, 2, 4] {
            let mut dev = device(threads);
            let m = load(&mut dev, "atomics", d);
            let vals: Vec<f32> =
                (0..2048).map(|i| 1.0 / (i as f32 + 1.0) * if i % 3 == 0 { -1e3 } else { 1.0 }).collect();
            let inb = dev.alloc_from(&vals);
            let sum = dev.alloc_zeroed::<f32>(1);
            dev.launch(&m, "float_sum", LaunchConfig::linear(16, 128), &[Arg::Ptr(sum), Arg::Ptr(inb)]).unwrap();
            let got = dev.read::<f32>(sum, 1)[0];
            // the defined order is thread order
            let exp = vals.iter().fold(0f32, |a, v| a + v);
            assert_eq!(got.to_bits(), exp.to_bits(), "{d:?}");
            results.push(got.to_bits());
        }
        assert!(results.windows(2).all(|w| w[0] == w[1]));
    }
}

#[test]
fn persistent_threads_job_queue() {
    for d in BOTH {
        let mut reference = None;
        for threads in [1, 2, 3] {
            let mut dev = device(threads);
            let m = load(&mut dev, "atomics", d);
            let items = 5000;
            let next = dev.alloc_zeroed::<u32>(1);
            let out = dev.alloc_from(&vec![-1i32; items]);
            let owner = dev.alloc_from(&vec![-1i32; items]);
            let s = dev
                .launch(
                    &m,
                    "job_queue",
                    LaunchConfig::linear(4, 128),
                    &[Arg::Ptr(next), Arg::Ptr(out), Arg::Ptr(owner), Arg::I32(items as i32)],
                )
                .unwrap();
            let got = dev.read::<i32>(out, items);
            for (i, v) in got.iter().enumerate() {
                assert_eq!(*v, (i * i) as i32, "{d:?}");
            }
            let owners = dev.read::<i32>(owner, items);
            assert!(owners.iter().all(|&o| (0..16).contains(&o)));
            // The same warp takes the same blocks and counts are identical, whatever the host threads.
            let key = (owners, s.totals.clone());
            match &reference {
                None => reference = Some(key),
                Some(r) => assert_eq!(r, &key, "{d:?} with {threads} threads"),
            }
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy)]
struct F4([f32; 4]);

#[test]
fn vector_loads_and_stores() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "memory", d);
        let input: Vec<f32> = (0..256).map(|i| i as f32 * 0.25).collect();
        let inb = dev.alloc_from(&input);
        let out = dev.alloc_zeroed::<f32>(256);
        let s = dev.launch(&m, "vec4_swizzle", LaunchConfig::linear(2, 32), &[Arg::Ptr(out), Arg::Ptr(inb)]).unwrap();
        let got = dev.read::<f32>(out, 256);
        for i in 0..64 {
            for k in 0..4 {
                assert_eq!(got[4 * i + k], input[4 * i + 3 - k]);
            }
        }
        assert_eq!(s.totals.loads.global, 2, "{d:?}: one v4 load per warp");
        assert_eq!(s.totals.stores.global, 2, "{d:?}: one v4 store per warp");
        let _ = F4([0.0; 4]);
    }
}

#[test]
fn constant_table_and_global_variable() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "memory", d);
        let out = dev.alloc_zeroed::<i32>(64);
        dev.launch(&m, "const_and_global", LaunchConfig::linear(2, 32), &[Arg::Ptr(out)]).unwrap();
        let lut = [1, 1, 2, 6, 24, 120, 720, 5040];
        let got = dev.read::<i32>(out, 64);
        for t in 0..64 {
            assert_eq!(got[t], lut[t & 7] + 1000, "{d:?}");
        }
        let bias = m.global("bias").expect("the module's global variable");
        assert_eq!(dev.read::<i32>(bias, 1)[0], 1000);
    }
}

#[test]
fn double_precision() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "memory", d);
        let x: Vec<f64> = (0..64).map(|i| i as f64 * 0.37 - 7.0).collect();
        let xb = dev.alloc_from(&x);
        let out = dev.alloc_zeroed::<f64>(64);
        dev.launch(&m, "fp64_poly", LaunchConfig::linear(2, 32), &[Arg::Ptr(out), Arg::Ptr(xb)]).unwrap();
        let got = dev.read::<f64>(out, 64);
        for i in 0..64 {
            let v = x[i];
            let exp = v.mul_add(v, -2.0).mul_add(v, 0.5) / 3.0 + (v * v + 1.0).sqrt();
            assert_eq!(got[i].to_bits(), exp.to_bits(), "{d:?} i={i}");
        }
    }
}

#[test]
fn partial_last_warp() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "memory", d);
        let out = dev.alloc_from(&vec![-1i32; 3 * 50]);
        let s = dev.launch(&m, "partial_warp", LaunchConfig::linear(3, 50), &[Arg::Ptr(out)]).unwrap();
        let got = dev.read::<i32>(out, 150);
        for i in 0..150 {
            assert_eq!(got[i], (i % 50) as i32 + 7);
        }
        assert_eq!(s.totals.warps, 6);
        // each warp issues the same instructions; the second warp of a CTA has 18 lanes.
        assert_eq!(s.totals.thread_instructions * 64, s.totals.warp_instructions * (32 + 18) * 32);
    }
}

#[test]
fn read_only_path_gather() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "memory", d);
        let input: Vec<f32> = (0..100).map(|i| i as f32 + 0.5).collect();
        let idx: Vec<i32> = (0..64).map(|t| (t * 13) % 100).collect();
        let (ib, xb) = (dev.alloc_from(&input), dev.alloc_from(&idx));
        let out = dev.alloc_zeroed::<f32>(64);
        dev.launch(&m, "ldg_gather", LaunchConfig::linear(2, 32), &[Arg::Ptr(out), Arg::Ptr(ib), Arg::Ptr(xb)])
            .unwrap();
        let got = dev.read::<f32>(out, 64);
        for t in 0..64 {
            assert_eq!(got[t], input[idx[t] as usize]);
        }
    }
}

#[test]
fn each_kernel_counts_only_the_shared_memory_it_names() {
    use warplight::model::{Profile, occupancy::occupancy};
    for d in BOTH {
        let mut dev = device(1);
        let m = load(&mut dev, "shared", d);
        let p = &m.prog;
        let size = |k: &str| p.kernel_shared_size(p.kernel(k).unwrap());
        // The module lays out all five kernels' arrays (1024 + 2*1024 + 64 + 256 bytes) ...
        assert!(p.static_shared_size >= 1024 + 2048 + 64 + 256, "{d:?}");
        // ... but each kernel needs only its own.
        assert_eq!(size("reduce_sum"), 256 * 4, "{d:?}");
        assert_eq!(size("matmul_tiled"), 2 * 16 * 16 * 4, "{d:?}");
        assert_eq!(size("histogram"), 16 * 4, "{d:?}");
        assert_eq!(size("reverse_dynamic"), 0, "{d:?}");
        assert_eq!(size("divergent_barrier"), 64 * 4, "{d:?}");
        let o = occupancy(Profile::Gt200, p, p.kernel("histogram").unwrap(), 256, 0);
        assert_eq!(o.shared_per_cta, 64, "{d:?}");
    }
}

/// `mov` of a variable's address plus an offset (PTX's address expression
/// `g+8`): the value is the variable's address plus 8 in the global, shared
/// and local spaces, and a store through it writes the variable's third word.
/// A register plus an offset, or a negative offset, is a load error naming
/// the expression and the line.
#[test]
fn a_symbol_plus_an_offset_is_its_address_plus_the_offset() {
    let head = ".version 7.8\n.target sm_90\n.address_size 64\n.global .align 4 .u32 g[4];\n\
        .visible .entry k(.param .u64 out)\n{\n.reg .b32 %r<12>;\n.reg .b64 %rd<8>;\n\
        .shared .align 4 .u32 s[4];\n.local .align 4 .u32 l[4];\n";
    let body = "ld.param.u64 %rd1, [out];\ncvta.to.global.u64 %rd1, %rd1;\n\
        mov.u64 %rd2, g+8;\nst.global.u64 [%rd1], %rd2;\nst.global.u32 [%rd2], 77;\n\
        mov.u32 %r1, s;\nmov.u32 %r2, s+8;\nsub.s32 %r3, %r2, %r1;\nst.global.u32 [%rd1+8], %r3;\n\
        st.shared.u32 [%r2], 55;\nld.shared.u32 %r4, [s+8];\nst.global.u32 [%rd1+12], %r4;\n\
        mov.u64 %rd3, l;\nmov.u64 %rd4, l+12;\nsub.s64 %rd5, %rd4, %rd3;\nst.global.u64 [%rd1+16], %rd5;\n\
        st.local.u32 [%rd4], 33;\nld.local.u32 %r5, [l+12];\nst.global.u32 [%rd1+24], %r5;\nret;\n}\n";
    let mut dev = warplight::sim::Device::new();
    let m = dev.load_ptx(&format!("{head}{body}"), "offset.ptx").unwrap_or_else(|e| panic!("{e}"));
    let out = dev.alloc_zeroed::<u32>(7);
    dev.launch(&m, "k", LaunchConfig::linear(1, 1), &[Arg::Ptr(out)]).unwrap();
    let got = dev.read::<u32>(out, 7);
    let g = m.global("g").expect("g is a module variable");
    assert_eq!(got[0] as u64 | (got[1] as u64) << 32, g.0 + 8, "g+8 is g's address plus 8");
    assert_eq!(dev.read::<u32>(g, 4), [0, 0, 77, 0], "the store through g+8 wrote g[2]");
    assert_eq!(got[2..7], [8, 55, 12, 0, 33], "shared s+8 and local l+12");
    for (line, want) in [
        ("mov.u32 %r1, %r2+8;", "`%r2+8`: only a variable's address takes an offset"),
        ("mov.u64 %rd2, g-4;", "`g-4`: an offset before the variable's start"),
        ("mov.u32 %r1, nothing+4;", "`nothing+4`: undeclared name"),
    ] {
        let err = dev.load_ptx(&format!("{head}{line}\nret;\n}}\n"), "bad.ptx").unwrap_err().to_string();
        assert!(err.contains(want) && err.contains("bad.ptx:11"), "{line}: {err}");
    }
}
