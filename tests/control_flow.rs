//! Divergence, reconvergence, loops, early exits, calls and recursion: results
//! against Rust references, counters against hand-derived numbers.

#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use warplight::sim::{Arg, LaunchConfig};

/// if/else on `threadIdx.x % 2`, clang's PTX, counted by hand from the listing
/// in `kernels/tests/divergence.ptx`:
/// - 12 instructions before the branch (all 32 lanes),
/// - odd lanes: `bra.uni` + 5 instructions (16 lanes),
/// - even lanes: 7 instructions (16 lanes),
/// - 3 after the join (32 lanes).
///   Per warp: 28 warp instructions, 12*32 + 6*16 + 7*16 + 3*32 = 688 thread
///   instructions, 3 branches of which 1 divergent, 2 reconvergences.
#[test]
fn if_else_counts_match_hand_derivation() {
    let mut dev = device(2);
    let m = load(&mut dev, "divergence", Dialect::Clang);
    let odd = dev.alloc_zeroed::<i32>(2048);
    let even = dev.alloc_zeroed::<i32>(2048);
    let s = dev.launch(&m, "if_else", LaunchConfig::linear(1, 64), &[Arg::Ptr(odd), Arg::Ptr(even)]).unwrap();
    let c = &s.totals;
    assert_eq!(c.warp_instructions, 2 * 28);
    assert_eq!(c.thread_instructions, 2 * 688);
    assert_eq!(c.branches, 2 * 3);
    assert_eq!(c.divergent_branches, 2);
    assert_eq!(c.reconvergences, 2 * 2);
    let (o, e) = (dev.read::<i32>(odd, 2048), dev.read::<i32>(even, 2048));
    for t in 0..64 {
        if t % 2 == 1 {
            assert_eq!((o[t], o[t + 1024]), (t as i32 * 3, t as i32));
        } else {
            assert_eq!((e[t], e[t + 1024]), (t as i32 + 100, -(t as i32)));
        }
    }
}

/// Both sides of the if/else issue once per warp with half the lanes active,
/// in either dialect: the first statement of each side runs with 16 lanes.
#[test]
fn if_else_sides_issue_once_per_warp_with_half_the_lanes() {
    for d in BOTH {
        let mut dev = device(1);
        let m = load(&mut dev, "divergence", d);
        let odd = dev.alloc_zeroed::<i32>(4096);
        let even = dev.alloc_zeroed::<i32>(4096);
        let warps = 8;
        let s = dev.launch(&m, "if_else", LaunchConfig::linear(2, 128), &[Arg::Ptr(odd), Arg::Ptr(even)]).unwrap();
        assert_eq!(s.totals.divergent_branches, warps, "{d:?}");
        for needle in ["odd[i] = t * 3", "even[i] = t + 100"] {
            let l = source_line(&s, &m.prog, "divergence", cu_line("divergence", needle));
            assert!(l.counts.warp_instructions > 0);
            assert_eq!(l.counts.warp_instructions % warps, 0, "{d:?} {needle}: once per warp");
            assert_eq!(l.counts.thread_instructions, 16 * l.counts.warp_instructions, "{d:?} {needle}");
        }
    }
}

#[test]
fn nested_if_results_and_lane_counts() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "divergence", d);
        let bufs: Vec<_> = (0..3).map(|_| dev.alloc_zeroed::<i32>(2048)).collect();
        let args: Vec<Arg> = bufs.iter().map(|b| Arg::Ptr(*b)).collect();
        let s = dev.launch(&m, "nested_if", LaunchConfig::linear(1, 96), &args).unwrap();
        let (a, b, c) =
            (dev.read::<i32>(bufs[0], 2048), dev.read::<i32>(bufs[1], 2048), dev.read::<i32>(bufs[2], 2048));
        for t in 0..96usize {
            let ti = t as i32;
            assert_eq!(a[t], if t & 1 == 1 { 1 } else { 0 }, "{d:?} t={t}");
            assert_eq!(b[t], if t & 3 == 3 { 3 } else { 0 });
            assert_eq!(c[t], if t & 3 == 1 { 5 } else { 0 });
            if t & 1 == 1 {
                assert_eq!(a[t + 1024], ti);
            }
        }
        // The outer branch splits every warp (3 warps); the innermost statements run
        // with a quarter of the lanes.
        assert!(s.totals.divergent_branches >= 3, "{d:?}");
        let outer = source_line(&s, &m.prog, "divergence", cu_line("divergence", "a[i] = 1;"));
        assert_eq!(outer.counts.thread_instructions, 16 * outer.counts.warp_instructions);
    }
}

fn loop_reference(limit: i32) -> i32 {
    let mut s = 0;
    for k in 0..limit {
        if k % 2 == 0 {
            continue;
        }
        if k > 20 {
            break;
        }
        s += k;
    }
    s
}

#[test]
fn loop_with_break_and_continue() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "divergence", d);
        let limits: Vec<i32> = (0..64).map(|t| (t * 7) % 40).collect();
        let lim = dev.alloc_from(&limits);
        let out = dev.alloc_zeroed::<i32>(64);
        let s = dev
            .launch(&m, "loop_break_continue", LaunchConfig::linear(1, 64), &[Arg::Ptr(out), Arg::Ptr(lim)])
            .unwrap();
        let got = dev.read::<i32>(out, 64);
        for t in 0..64 {
            assert_eq!(got[t], loop_reference(limits[t]), "{d:?} t={t}");
        }
        // Lanes leave the loop at different trip counts: it must diverge, and every
        // divergence is matched by reconvergences.
        assert!(s.totals.divergent_branches > 0);
        assert!(s.totals.reconvergences >= s.totals.divergent_branches);
        assert!(s.totals.thread_instructions < 32 * s.totals.warp_instructions);
    }
}

#[test]
fn early_return_writes_only_live_threads() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "divergence", d);
        let out = dev.alloc_from(&vec![-1i32; 128]);
        dev.launch(&m, "early_return", LaunchConfig::linear(2, 64), &[Arg::Ptr(out), Arg::I32(70)]).unwrap();
        let got = dev.read::<i32>(out, 128);
        for (t, v) in got.iter().enumerate() {
            assert_eq!(*v, if t < 70 { (t * t) as i32 } else { -1 }, "{d:?} t={t}");
        }
    }
}

#[test]
fn uniform_branch_never_diverges() {
    for d in BOTH {
        for flag in [0, 1] {
            let mut dev = device(1);
            let m = load(&mut dev, "divergence", d);
            let yes = dev.alloc_zeroed::<i32>(2048);
            let no = dev.alloc_zeroed::<i32>(2048);
            let s = dev
                .launch(
                    &m,
                    "uniform_branch",
                    LaunchConfig::linear(2, 64),
                    &[Arg::Ptr(yes), Arg::Ptr(no), Arg::I32(flag)],
                )
                .unwrap();
            assert_eq!(s.totals.divergent_branches, 0);
            assert_eq!(s.totals.thread_instructions, 32 * s.totals.warp_instructions, "all lanes always active");
            let target = if flag == 1 { dev.read::<i32>(yes, 128) } else { dev.read::<i32>(no, 128) };
            assert!(target.iter().all(|&v| v == if flag == 1 { 1 } else { 2 }));
        }
    }
}

#[test]
fn grid_2d_indices() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "divergence", d);
        let (w, h) = (48usize, 20usize);
        let out = dev.alloc_zeroed::<i32>(w * h);
        let cfg = LaunchConfig { grid: [3, 5, 1], block: [16, 4, 1], dynamic_shared: 0 };
        dev.launch(&m, "grid_2d", cfg, &[Arg::Ptr(out), Arg::I32(w as i32)]).unwrap();
        let got = dev.read::<i32>(out, w * h);
        for y in 0..h {
            for x in 0..w {
                assert_eq!(got[y * w + x], ((y << 16) | x) as i32);
            }
        }
    }
}

fn collatz(mut x: i32) -> i32 {
    let mut n = 0;
    while x != 1 {
        x = if x & 1 == 1 { 3 * x + 1 } else { x / 2 };
        n += 1;
    }
    n
}

fn fib(n: i32) -> i32 {
    if n < 2 { n } else { fib(n - 1) + fib(n - 2) }
}

#[test]
fn divergent_device_call() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "calls", d);
        let out = dev.alloc_zeroed::<i32>(96);
        let s = dev.launch(&m, "call_divergent", LaunchConfig::linear(1, 96), &[Arg::Ptr(out)]).unwrap();
        let got = dev.read::<i32>(out, 96);
        for t in 0..96 {
            assert_eq!(got[t], if t % 3 == 0 { collatz(t as i32 + 1) } else { -1 }, "{d:?} t={t}");
        }
        assert_eq!(s.totals.calls, 3, "one call per warp");
    }
}

#[test]
fn recursion() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "calls", d);
        let out = dev.alloc_zeroed::<i32>(64);
        let s = dev.launch(&m, "recursive_fib", LaunchConfig::linear(2, 32), &[Arg::Ptr(out)]).unwrap();
        let got = dev.read::<i32>(out, 64);
        for t in 0..64 {
            assert_eq!(got[t], fib(t as i32 % 12), "{d:?} t={t}");
        }
        assert!(s.totals.calls > 100, "recursive calls are counted: {}", s.totals.calls);
    }
}

#[test]
fn local_array_per_thread() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "calls", d);
        let idx: Vec<i32> = (0..64).map(|t| (t * 5 + 3) % 23).collect();
        let ib = dev.alloc_from(&idx);
        let out = dev.alloc_zeroed::<i32>(64);
        let s = dev.launch(&m, "local_array", LaunchConfig::linear(2, 32), &[Arg::Ptr(out), Arg::Ptr(ib)]).unwrap();
        let got = dev.read::<i32>(out, 64);
        for t in 0..64 {
            let i = idx[t];
            let exp = t as i32 * (i & 15) + t as i32 * ((i + 5) & 15);
            assert_eq!(got[t], exp, "{d:?} t={t}");
        }
        assert!(s.totals.loads.local + s.totals.stores.local > 0, "{d:?}: the array lives in local memory");
    }
}

/// Even lanes call `fa`, odd lanes `fb`, through one indirect `call`
/// preceded by an `st.param` (as clang emits it).
const ICALL: &str = include_str!("fixtures/icall_divergent.ptx");

/// A divergent indirect call issues the `call` once per target group. Each
/// issue is counted on the `call`'s line (32 lanes, then the 16 that call
/// the other target), so the per-line counts add up to the totals.
#[test]
fn divergent_indirect_call_counts_every_issue_per_line() {
    let mut dev = device(2);
    let m = dev.load_ptx(ICALL, "icall.ptx").unwrap_or_else(|e| panic!("{e}"));
    let out = dev.alloc_zeroed::<i32>(32);
    let s = dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap();
    let got = dev.read::<i32>(out, 32);
    for t in 0..32 {
        assert_eq!(got[t], t as i32 + if t % 2 == 0 { 1 } else { 2 }, "t={t}");
    }
    let lines = s.per_ptx_line(&m.prog);
    let warp: u64 = lines.iter().map(|l| l.counts.warp_instructions).sum();
    let thread: u64 = lines.iter().map(|l| l.counts.thread_instructions).sum();
    assert_eq!((warp, thread), (s.totals.warp_instructions, s.totals.thread_instructions));
    let call_line = ICALL.lines().position(|l| l.starts_with("call ")).unwrap() as u32 + 1;
    let call = lines.iter().find(|l| l.line == call_line).expect("the call is counted");
    assert_eq!((call.counts.warp_instructions, call.counts.thread_instructions), (2, 48));
}

/// The per-PTX-line warp and thread counts add up to the launch's totals.
fn assert_lines_add_up(s: &warplight::sim::LaunchStats, m: &warplight::sim::Module, what: &str) {
    let lines = s.per_ptx_line(&m.prog);
    let warp: u64 = lines.iter().map(|l| l.counts.warp_instructions).sum();
    let thread: u64 = lines.iter().map(|l| l.counts.thread_instructions).sum();
    let pred_on: u64 = lines.iter().map(|l| l.counts.thread_instructions_pred_on).sum();
    let t = &s.totals;
    assert_eq!(
        (warp, thread, pred_on),
        (t.warp_instructions, t.thread_instructions, t.thread_instructions_pred_on),
        "{what}"
    );
}

/// Over the control-flow kernels in both dialects (divergence, early
/// returns, loops, direct, recursive and indirect calls with lanes calling
/// different functions), every issued instruction is on some line.
#[test]
fn per_line_counts_add_up_to_the_totals() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "divergence", d);
        let [a, b, c] = [0; 3].map(|_| dev.alloc_zeroed::<i32>(2048));
        let lim = dev.alloc_from(&(0..64).map(|i| i % 9).collect::<Vec<i32>>());
        for (k, args) in [
            ("if_else", vec![Arg::Ptr(a), Arg::Ptr(b)]),
            ("nested_if", vec![Arg::Ptr(a), Arg::Ptr(b), Arg::Ptr(c)]),
            ("loop_break_continue", vec![Arg::Ptr(a), Arg::Ptr(lim)]),
            ("early_return", vec![Arg::Ptr(a), Arg::I32(70)]),
        ] {
            let s = dev.launch(&m, k, LaunchConfig::linear(2, 64), &args).unwrap();
            assert_lines_add_up(&s, &m, &format!("{k} {d:?}"));
        }
        let m = load(&mut dev, "calls", d);
        for k in ["call_divergent", "recursive_fib"] {
            let s = dev.launch(&m, k, LaunchConfig::linear(2, 32), &[Arg::Ptr(a)]).unwrap();
            assert_lines_add_up(&s, &m, &format!("{k} {d:?}"));
        }
        let m = load(&mut dev, "indirect", d);
        let x = dev.alloc_from(&(0..64).map(|i| i as f32 * 0.5).collect::<Vec<f32>>());
        let out = dev.alloc_zeroed::<f32>(64);
        for (k, args) in [
            ("call_table", vec![Arg::Ptr(x), Arg::Ptr(x), Arg::Ptr(out), Arg::I32(64)]),
            ("call_select", vec![Arg::Ptr(x), Arg::Ptr(out), Arg::I32(64)]),
            ("call_virtual", vec![Arg::Ptr(x), Arg::Ptr(out), Arg::I32(64)]),
        ] {
            let s = dev.launch(&m, k, LaunchConfig::linear(2, 32), &args).unwrap();
            assert!(s.totals.calls > 2, "{k}: lanes call different functions");
            assert_lines_add_up(&s, &m, &format!("{k} {d:?}"));
        }
    }
}
