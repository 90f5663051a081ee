//! Hostile and careless input (issue 17): a regression corpus of small PTX
//! modules and launch specs that once panicked, hung or aborted. Each must
//! give a clear error or documented behaviour: never a panic, an abort or an
//! endless run.

mod support;
use support::warplight_code;

use std::path::{Path, PathBuf};

use warplight::ptx::ir::Kind;
use warplight::ptx::{PtxErrorKind, parser::MAX_NESTING};
use warplight::sim::device::{
    DEFAULT_MAX_CALL_DEPTH, DEFAULT_MAX_WARP_INSTRUCTIONS, MAX_HOST_THREADS, cap_host_threads,
};
use warplight::sim::{Arg, Device, FaultKind, LaunchConfig, LaunchStats, SimConfig, SimError};

const HEADER: &str = ".version 7.8\n.target sm_90\n.address_size 64\n";

fn module(body: &str) -> String {
    format!("{HEADER}{body}")
}

fn device(f: impl FnOnce(&mut SimConfig)) -> Device {
    let mut c = SimConfig { threads: 1, ..SimConfig::default() };
    f(&mut c);
    Device::with_config(c)
}

fn fault_of(r: Result<LaunchStats, SimError>) -> Box<warplight::sim::Fault> {
    match r {
        Err(SimError::Fault(f)) => f,
        other => panic!("expected a fault, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------
// 1. Kernels that reach the end of their body.

/// Kernels whose last instruction is not an unconditional `ret`/`exit`: each
/// stores `%tid.x + 1` where it can, so that the test sees every thread ran.
const FALLS_OFF_THE_END: &[(&str, &str)] = &[
    ("empty kernel", ".visible .entry k(.param .u64 out)\n{\n}\n"),
    (
        "no final ret",
        ".visible .entry k(.param .u64 out)\n{\n .reg .b32 %r<3>;\n .reg .b64 %rd<4>;\n\
         ld.param.u64 %rd1, [out];\n mov.u32 %r1, %tid.x;\n add.u32 %r2, %r1, 1;\n\
         mul.wide.u32 %rd2, %r1, 4;\n add.s64 %rd3, %rd1, %rd2;\n st.global.u32 [%rd3], %r2;\n}\n",
    ),
    (
        "guarded ret as the last line",
        ".visible .entry k(.param .u64 out)\n{\n .reg .b32 %r<3>;\n .reg .b64 %rd<4>;\n .reg .pred %p<2>;\n\
         ld.param.u64 %rd1, [out];\n mov.u32 %r1, %tid.x;\n add.u32 %r2, %r1, 1;\n\
         mul.wide.u32 %rd2, %r1, 4;\n add.s64 %rd3, %rd1, %rd2;\n st.global.u32 [%rd3], %r2;\n\
         setp.lt.u32 %p1, %r1, 5;\n @%p1 ret;\n}\n",
    ),
    (
        "label at the end",
        ".visible .entry k(.param .u64 out)\n{\n .reg .b32 %r<3>;\n .reg .b64 %rd<4>;\n .reg .pred %p<2>;\n\
         ld.param.u64 %rd1, [out];\n mov.u32 %r1, %tid.x;\n add.u32 %r2, %r1, 1;\n\
         setp.lt.u32 %p1, %r1, 7;\n @%p1 bra END;\n\
         mul.wide.u32 %rd2, %r1, 4;\n add.s64 %rd3, %rd1, %rd2;\n st.global.u32 [%rd3], %r2;\nEND:\n}\n",
    ),
    (
        "guarded exit in a device function, then falling off both ends",
        ".func f()\n{\n .reg .b32 %r<2>;\n .reg .pred %p<2>;\n mov.u32 %r1, %tid.x;\n\
         setp.eq.u32 %p1, %r1, 3;\n @%p1 exit;\n}\n\
         .visible .entry k(.param .u64 out)\n{\n call.uni f, ();\n}\n",
    ),
];

#[test]
fn kernels_that_fall_off_their_end_exit_every_thread() {
    for (name, body) in FALLS_OFF_THE_END {
        let src = module(body);
        warplight::ptx::load(&src, "end.ptx").unwrap_or_else(|e| panic!("{name}: {e}"));
        for block in [1, 32, 45] {
            let mut dev = device(|_| {});
            let m = dev.load_ptx(&src, "end.ptx").unwrap();
            let out = dev.alloc_zeroed::<u32>(64);
            let stats = dev
                .launch(&m, "k", LaunchConfig::linear(2, block), &[Arg::Ptr(out)])
                .unwrap_or_else(|e| panic!("{name}, block {block}: {e}"));
            assert_eq!(stats.totals.ctas, 2, "{name}");
            let got = dev.read::<u32>(out, block as usize);
            if name.contains("no final ret") || name.contains("guarded ret") {
                assert_eq!(got, (1..=block).collect::<Vec<_>>(), "{name}, block {block}");
            }
            if name.contains("label at the end") {
                let exp: Vec<u32> = (0..block).map(|t| if t < 7 { 0 } else { t + 1 }).collect();
                assert_eq!(got, exp, "{name}, block {block}");
            }
            // Stepping runs the same launch to its end, one instruction at a time.
            let mut dev = device(|_| {});
            let m = dev.load_ptx(&src, "end.ptx").unwrap();
            let out = dev.alloc_zeroed::<u32>(64);
            let mut st = dev.stepper(&m, "k", LaunchConfig::linear(2, block), &[Arg::Ptr(out)]).unwrap();
            let mut steps = 0;
            while st.step().unwrap_or_else(|f| panic!("{name}: {f}")).is_some() {
                steps += 1;
                assert!(steps < 10_000, "{name}: stepping does not end");
            }
            assert_eq!(steps, stats.totals.warp_instructions, "{name}, block {block}");
        }
    }
}

#[test]
fn the_implicit_end_of_a_kernel_is_an_exit_and_of_a_function_a_return() {
    let src = module(FALLS_OFF_THE_END[4].1);
    let prog = warplight::ptx::load(&src, "end.ptx").unwrap();
    let f = &prog.functions[prog.kernel("k").unwrap() as usize];
    assert!(matches!(f.insts.last().unwrap().kind, Kind::Exit), "{:?}", f.insts.last());
    let d = prog.functions.iter().find(|f| f.name == "f").unwrap();
    assert!(matches!(d.insts.last().unwrap().kind, Kind::Ret), "{:?}", d.insts.last());
}

#[test]
fn a_kernel_without_a_body_is_a_launch_error() {
    let src = module(".visible .entry k(.param .u64 out);\n");
    let mut dev = device(|_| {});
    let m = dev.load_ptx(&src, "decl.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(1);
    let e = dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap_err();
    assert!(matches!(e, SimError::BadLaunch(_)), "{e}");
    assert!(e.to_string().contains("kernel `k` is declared without a body in decl.ptx"), "{e}");
    let e = dev.stepper(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).err().expect("an error");
    assert!(matches!(e, SimError::BadLaunch(_)), "{e}");
}

#[test]
fn ret_in_the_kernel_frame_exits_even_in_hand_built_ir() {
    // A program built without the front end may end a kernel with `Ret`.
    let src = module(FALLS_OFF_THE_END[1].1);
    let mut prog = warplight::ptx::load(&src, "ret.ptx").unwrap();
    let k = prog.kernel("k").unwrap() as usize;
    let last = prog.functions[k].insts.last_mut().unwrap();
    assert!(matches!(last.kind, Kind::Exit));
    last.kind = Kind::Ret;
    let mut dev = device(|_| {});
    let m = dev.load(prog);
    let out = dev.alloc_zeroed::<u32>(32);
    dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap();
    assert_eq!(dev.read::<u32>(out, 32), (1..=32).collect::<Vec<_>>());
}

// ---------------------------------------------------------------------------
// 2. Recursion without `.local` frames.

/// `down(n)` calls `down(n - 1)` until `n == base` (never, for a base above n).
fn recursion(base: i32) -> String {
    module(&format!(
        ".func (.param .b32 r) down(.param .b32 n)\n{{\n .reg .b32 %r<4>;\n .reg .pred %p<2>;\n\
         ld.param.u32 %r1, [n];\n setp.eq.s32 %p1, %r1, {base};\n @%p1 bra BASE;\n sub.s32 %r2, %r1, 1;\n\
         {{\n .param .b32 a;\n .param .b32 b;\n st.param.b32 [a], %r2;\n call.uni (b), down, (a);\n\
         ld.param.b32 %r3, [b];\n }}\n add.s32 %r3, %r3, 1;\n st.param.b32 [r], %r3;\n ret;\n\
         BASE:\n st.param.b32 [r], 0;\n ret;\n}}\n\
         .visible .entry k(.param .u64 out, .param .u32 n)\n{{\n .reg .b32 %r<3>;\n .reg .b64 %rd<2>;\n\
         ld.param.u32 %r1, [n];\n {{\n .param .b32 a;\n .param .b32 b;\n st.param.b32 [a], %r1;\n\
         call.uni (b), down, (a);\n ld.param.b32 %r2, [b];\n }}\n ld.param.u64 %rd1, [out];\n\
         st.global.u32 [%rd1], %r2;\n ret;\n}}\n"
    ))
}

fn run_recursion(base: i32, n: u32, max_depth: Option<u32>) -> (Result<LaunchStats, SimError>, u32) {
    let mut dev = device(|c| {
        if let Some(d) = max_depth {
            c.max_call_depth = d;
        }
    });
    let m = dev.load_ptx(&recursion(base), "rec.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(1);
    let r = dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(out), Arg::U32(n)]);
    (r, dev.read::<u32>(out, 1)[0])
}

#[test]
fn unbounded_recursion_faults_with_the_call_chain_and_line() {
    assert_eq!(SimConfig::default().max_call_depth, DEFAULT_MAX_CALL_DEPTH);
    assert_eq!(DEFAULT_MAX_CALL_DEPTH, 1024);
    let (r, _) = run_recursion(1_000_000, 10, None);
    let f = fault_of(r);
    match &f.kind {
        FaultKind::CallDepth { limit, callee, chain } => {
            assert_eq!(*limit, 1024);
            assert_eq!(callee, "down");
            assert_eq!(chain, &vec![("k".to_string(), 1), ("down".to_string(), 1024)]);
        }
        k => panic!("expected CallDepth, got {k}"),
    }
    assert_eq!(f.function, "down");
    assert!(f.ptx_text.contains("call.uni (b), down, (a);"), "{}", f.ptx_text);
    let msg = f.to_string();
    assert!(msg.contains("call stack overflow") && msg.contains("more than 1024"), "{msg}");
    assert!(msg.contains("call chain: k → down ×1024"), "{msg}");
    assert!(msg.contains(&format!("rec.ptx:{}:", f.ptx_line)), "{msg}");
}

#[test]
fn the_call_depth_limit_is_exact_and_configurable() {
    // Depth n: the kernel calls down(n), which recurses n more times to down(0).
    let (r, v) = run_recursion(0, 4, Some(5));
    r.unwrap();
    assert_eq!(v, 4);
    let (r, _) = run_recursion(0, 5, Some(5));
    let f = fault_of(r);
    assert!(matches!(&f.kind, FaultKind::CallDepth { limit: 5, chain, .. } if chain[1].1 == 5), "{f}");
    // Deep but bounded recursion is fine under the default.
    let (r, v) = run_recursion(0, 900, None);
    r.unwrap();
    assert_eq!(v, 900);
}

#[test]
fn mutual_recursion_names_a_shortened_chain() {
    let src = module(
        ".func a()\n{\n call.uni b, ();\n ret;\n}\n.func b()\n{\n call.uni a, ();\n ret;\n}\n\
         .visible .entry k()\n{\n call.uni a, ();\n ret;\n}\n",
    );
    let mut dev = device(|c| c.max_call_depth = 40);
    let m = dev.load_ptx(&src, "mutual.ptx").unwrap();
    let f = fault_of(dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[]));
    let FaultKind::CallDepth { chain, .. } = &f.kind else { panic!("{f}") };
    assert_eq!(chain.len(), 41);
    let msg = f.to_string();
    assert!(msg.contains("call chain: k → a → b → a → … 31 more … → a → b"), "{msg}");
}

// ---------------------------------------------------------------------------
// 3. The watchdog.

const ALU_SPIN: &str = ".visible .entry k()\n{\n .reg .b32 %r<3>;\n .reg .pred %p<2>;\n mov.u32 %r1, 0;\n\
L:\n add.s32 %r1, %r1, 1;\n setp.ne.s32 %p1, %r1, 0;\n @%p1 bra L;\n ret;\n}\n";

/// A per-thread spinlock: the lane that wins the CAS leaves the loop and
/// waits at the loop's exit (its reconvergence point) for the lanes still
/// spinning, which wait for it to release the lock: a livelock.
const SPINLOCK: &str = ".visible .entry lock(.param .u64 p)\n{\n .reg .b32 %r<4>;\n .reg .b64 %rd<2>;\n\
 .reg .pred %p<2>;\n ld.param.u64 %rd1, [p];\nSPIN:\n atom.global.cas.b32 %r1, [%rd1], 0, 1;\n\
 setp.ne.s32 %p1, %r1, 0;\n @%p1 bra SPIN;\n atom.global.exch.b32 %r2, [%rd1], 0;\n ret;\n}\n";

#[test]
fn the_default_watchdog_is_2_to_the_32() {
    assert_eq!(DEFAULT_MAX_WARP_INSTRUCTIONS, 1 << 32);
    assert_eq!(SimConfig::default().schedule.max_warp_instructions, 1 << 32);
}

#[test]
fn the_watchdog_names_the_hot_loop() {
    let src = module(ALU_SPIN);
    let mut dev = device(|c| {
        c.schedule.max_warp_instructions = 200_000;
    });
    let m = dev.load_ptx(&src, "spin.ptx").unwrap();
    let f = fault_of(dev.launch(&m, "k", LaunchConfig::linear(3, 64), &[]));
    let FaultKind::Runaway { budget, hot } = &f.kind else { panic!("{f}") };
    assert_eq!(*budget, 200_000);
    let lines: Vec<u32> = hot.iter().map(|h| h.ptx_line).collect();
    // The loop body (lines 10 to 12 of the module), nothing else.
    assert_eq!(lines, vec![10, 11, 12], "{f}");
    assert!(hot.iter().all(|h| (32..=34).contains(&h.share_pct)), "{hot:?}");
    assert_eq!(hot.iter().map(|h| h.warps_here).sum::<u32>(), 6, "every warp of the 3 CTAs is in the loop");
    let msg = f.to_string();
    assert!(msg.contains("--max-instructions") && msg.contains("max_instructions"), "{msg}");
    assert!(msg.contains("hot loop") && msg.contains("spin.ptx:10") && msg.contains("add.s32 %r1, %r1, 1;"), "{msg}");
}

#[test]
fn a_per_thread_spinlock_livelocks_and_the_watchdog_fires() {
    let src = module(SPINLOCK);
    let mut dev = device(|c| c.schedule.max_warp_instructions = 30_000);
    let m = dev.load_ptx(&src, "lock.ptx").unwrap();
    let lock = dev.alloc_zeroed::<u32>(1);
    let f = fault_of(dev.launch(&m, "lock", LaunchConfig::linear(1, 32), &[Arg::Ptr(lock)]));
    let FaultKind::Runaway { hot, .. } = &f.kind else { panic!("{f}") };
    assert!(hot.iter().any(|h| h.ptx_text.contains("atom.global.cas")), "{f}");
    // Lane 0 holds the lock and never released it.
    assert_eq!(dev.read::<u32>(lock, 1), vec![1]);
    // One thread per warp takes the lock and releases it: no livelock.
    let out = dev.alloc_zeroed::<u32>(1);
    dev.launch(&m, "lock", LaunchConfig::linear(4, 1), &[Arg::Ptr(out)]).unwrap();
    assert_eq!(dev.read::<u32>(out, 1), vec![0]);
}

// ---------------------------------------------------------------------------
// 4. Nesting.

fn nested_blocks(n: usize) -> String {
    module(&format!(".visible .entry k()\n{{\n{}{}ret;\n}}\n", "{\n".repeat(n), "}\n".repeat(n)))
}

#[test]
fn deep_nesting_is_an_error_naming_the_line_not_a_stack_overflow() {
    // Within the limit: fine.
    warplight::ptx::load(&nested_blocks(MAX_NESTING as usize), "ok.ptx").unwrap();
    // One deeper: the brace that goes too deep is named.
    let e = warplight::ptx::load(&nested_blocks(MAX_NESTING as usize + 1), "deep.ptx").unwrap_err();
    assert!(matches!(e.kind, PtxErrorKind::Limit(_)), "{e}");
    assert_eq!(e.pos.line, 4 + 2 + MAX_NESTING, "{e}");
    assert!(e.to_string().contains("nested more than 256 deep"), "{e}");
    // 20,000 levels (40 KB) of blocks, initializer braces and operand lists.
    let n = 20_000;
    let e = warplight::ptx::load(&nested_blocks(n), "blocks.ptx").unwrap_err();
    assert!(matches!(e.kind, PtxErrorKind::Limit(_)), "{e}");
    let src = module(&format!(".global .u32 g[1] = {}1{};\n", "{".repeat(n), "}".repeat(n)));
    let e = warplight::ptx::load(&src, "init.ptx").unwrap_err();
    assert!(matches!(e.kind, PtxErrorKind::Limit(_)) && e.pos.line == 4, "{e}");
    let src = module(&format!(".visible .entry k()\n{{\n mov.u32 %r1, {}1{};\n}}\n", "(".repeat(n), ")".repeat(n)));
    let e = warplight::ptx::load(&src, "ops.ptx").unwrap_err();
    assert!(matches!(e.kind, PtxErrorKind::Limit(_)) && e.pos.line == 6, "{e}");
    // The message quotes a bounded part of the 40 KB line.
    let msg = e.to_string();
    assert!(msg.len() < 1000 && msg.ends_with('…'), "{} bytes: {msg:.200}", msg.len());
}

// ---------------------------------------------------------------------------
// 5. Host threads.

#[test]
fn host_threads_are_capped() {
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let cap = (4 * cores).min(MAX_HOST_THREADS);
    assert_eq!(cap_host_threads(0), (0, None), "0 = all cores");
    assert_eq!(cap_host_threads(1), (1, None));
    assert_eq!(cap_host_threads(cap), (cap, None));
    let (n, why) = cap_host_threads(100_000);
    assert_eq!(n, cap);
    let why = why.expect("a message");
    assert!(why.contains(&format!("using {cap} host threads instead of 100000")), "{why}");
    // A device asked for too many threads still works (with the cap).
    let mut dev = Device::with_config(SimConfig { threads: 100_000, ..SimConfig::default() });
    let m = dev.load_ptx(&module(FALLS_OFF_THE_END[1].1), "t.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(64);
    dev.launch(&m, "k", LaunchConfig::linear(2, 32), &[Arg::Ptr(out)]).unwrap();
}

// ---------------------------------------------------------------------------
// The binary: launch, step and trace.

fn tempdir() -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    let d = std::env::temp_dir().join(format!(
        "warplight-hostile-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `ptx` and a spec for kernel `kernel` with one u32 buffer `buf` (as
/// its argument when `arg`) plus `extra` spec lines; returns the spec's path.
fn spec(dir: &Path, ptx: &str, kernel: &str, block: u32, arg: bool, extra: &str) -> String {
    std::fs::write(dir.join("k.ptx"), ptx).unwrap();
    let args = if arg { "args = [\"buf\"]\n" } else { "" };
    let s = format!(
        "ptx = \"k.ptx\"\nkernel = \"{kernel}\"\ngrid = 2\nblock = {block}\n{args}{extra}\n\
         [[buffer]]\nname = \"buf\"\ntype = \"u32\"\nlen = 64\n"
    );
    let p = dir.join("k.toml");
    std::fs::write(&p, s).unwrap();
    p.display().to_string()
}

#[test]
fn launch_step_and_trace_run_kernels_that_fall_off_their_end() {
    for (name, body) in FALLS_OFF_THE_END {
        let dir = tempdir();
        let s = spec(&dir, &module(body), "k", 40, true, "");
        let html = dir.join("t.html").display().to_string();
        let (code, _, err) = warplight_code(&["check", &dir.join("k.ptx").display().to_string()]);
        assert_eq!(code, Some(0), "{name}: check: {err}");
        for args in [
            vec!["launch", s.as_str()],
            vec!["step", s.as_str(), "--log"],
            vec!["trace", s.as_str(), "-o", html.as_str()],
        ] {
            let (code, out, err) = warplight_code(&args);
            assert_eq!(code, Some(0), "{name}: {args:?}: {out}{err}");
            assert!(!err.contains("panicked"), "{name}: {args:?}: {err}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}

#[test]
fn max_instructions_flag_and_spec_key_stop_a_runaway() {
    let dir = tempdir();
    let html = dir.join("t.html").display().to_string();
    // The flag, on each command.
    let s = spec(&dir, &module(ALU_SPIN), "k", 32, false, "");
    for args in [
        vec!["launch", s.as_str(), "--max-instructions", "50000"],
        vec!["step", s.as_str(), "--log", "--max-steps", "10000000", "--max-instructions", "50000"],
        vec!["trace", s.as_str(), "-o", html.as_str(), "--cta", "7", "--max-instructions", "50000"],
    ] {
        let (code, out, err) = warplight_code(&args);
        assert_eq!(code, Some(1), "{args:?}: {out}{err}");
        let all = format!("{out}{err}");
        assert!(all.contains("runaway kernel: more than 50000 warp instructions"), "{args:?}: {all}");
        assert!(all.contains("k.ptx:10") && all.contains("hot loop"), "{args:?}: {all}");
    }
    assert!(!Path::new(&html).exists(), "no page for a failed recording");
    // The spec key; the flag wins over it.
    let s = spec(&dir, &module(ALU_SPIN), "k", 32, false, "max_instructions = 40000");
    let (code, _, err) = warplight_code(&["launch", &s]);
    assert_eq!(code, Some(1));
    assert!(err.contains("more than 40000 warp instructions"), "{err}");
    let (code, _, err) = warplight_code(&["launch", &s, "--max-instructions", "30000"]);
    assert_eq!(code, Some(1));
    assert!(err.contains("more than 30000 warp instructions"), "{err}");
    // Nonsense values.
    let (code, _, err) = warplight_code(&["launch", &s, "--max-instructions", "0"]);
    assert_eq!(code, Some(2), "{err}");
    for bad in ["max_instructions = 0", "max_instructions = -5", "max_instructions = \"lots\"", "max_call_depth = 0"] {
        let s = spec(&dir, &module(ALU_SPIN), "k", 32, false, bad);
        let (code, _, err) = warplight_code(&["launch", &s]);
        assert_eq!(code, Some(1), "{bad}: {err}");
        let key = bad.split(' ').next().unwrap();
        assert!(err.contains(&format!("`{key}`: expected an integer from 1 to")), "{bad}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn max_call_depth_spec_key_bounds_recursion() {
    let dir = tempdir();
    let s = spec(&dir, &recursion(1_000_000), "k", 32, false, "max_call_depth = 16\nargs = [\"buf\", 3]");
    let (code, _, err) = warplight_code(&["launch", &s]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("more than 16 device-function calls") && err.contains("call chain: k → down ×16"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn too_many_host_threads_are_capped_with_a_warning() {
    let dir = tempdir();
    let s = spec(&dir, &module(FALLS_OFF_THE_END[1].1), "k", 32, true, "");
    let (code, _, err) = warplight_code(&["launch", &s, "--threads", "100000"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning: --threads 100000: using") && err.contains("host threads instead of 100000"),
        "{err}"
    );
    let (code, _, err) = warplight_code(&["launch", &s, "--threads", "2"]);
    assert_eq!(code, Some(0));
    assert!(!err.contains("warning"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `.reg %r<N>` with a huge N is an error before any register is made (it was an abort).
#[test]
fn a_huge_register_range_is_an_error_not_an_abort() {
    let ptx =
        ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n.reg .b32 %r<4294967295>;\nret;\n}\n";
    let e = warplight::ptx::load(ptx, "big.ptx").unwrap_err().to_string();
    assert!(e.contains("big.ptx:6:1") && e.contains("more registers than a function can have"), "{e}");
    let p = ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n.reg .pred %p<70000>;\nret;\n}\n";
    assert!(warplight::ptx::load(p, "p.ptx").is_err());
}

/// A function address in the initializer of a zero-length array (the last
/// `.global` or `.const` variable) is an error naming the line; the loader
/// wrote the address into no bytes at all and panicked.
#[test]
fn a_function_address_in_a_zero_length_array_is_an_error_not_a_panic() {
    for space in ["global", "const"] {
        let ptx = module(&format!(
            ".func f()\n{{\nret;\n}}\n.{space} .u64 t[0] = {{f}};\n.visible .entry k()\n{{\nret;\n}}\n"
        ));
        let e = warplight::ptx::load(&ptx, "zero.ptx").unwrap_err();
        assert_eq!(e.pos.line, 8, "{e}");
        let msg = e.to_string();
        assert!(msg.starts_with("zero.ptx:8:") && msg.contains("more elements than the array"), "{msg}");
        // one element holds it
        let ok = ptx.replace("t[0]", "t[1]");
        assert!(warplight::ptx::load(&ok, "one.ptx").is_ok(), "{space}");
    }
    // a zero-length array with no initializer, or an empty one, still loads
    let ptx = module(".global .u64 t[0];\n.const .u32 c[0] = {};\n.visible .entry k()\n{\nret;\n}\n");
    warplight::ptx::load(&ptx, "empty.ptx").unwrap();
}

/// An unsized first dimension of a multi-dimensional array takes its size
/// from the initializer, as a one-dimensional `t[]` does (the last row filled
/// with zeros); it was refused as "more elements than the array".
#[test]
fn an_unsized_first_dimension_comes_from_the_initializer() {
    let ptx = module(
        ".global .u32 t[][2] = {1, 2, 3, 4, 5};\n.global .u16 u[][2][2] = {{{1, 2}, {3, 4}}};\n\
         .visible .entry k()\n{\nret;\n}\n",
    );
    let p = warplight::ptx::load(&ptx, "unsized.ptx").unwrap();
    let t = p.globals.iter().find(|g| g.name == "t").unwrap();
    let words: Vec<u32> = t.init.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().unwrap())).collect();
    assert_eq!((t.size, words), (24, vec![1, 2, 3, 4, 5, 0]));
    let u = p.globals.iter().find(|g| g.name == "u").unwrap();
    assert_eq!((u.size, &u.init[..]), (8, &[1u8, 0, 2, 0, 3, 0, 4, 0][..]));
}

/// Nested braces with fewer elements than their row are padded with zeros
/// row by row, as C pads them (`t[2][2] = {{1},{2}}` is `{1, 0, 2, 0}`),
/// also under an unsized first dimension; a row with more elements than it
/// holds is an error naming the variable, not a reshape.
#[test]
fn nested_initializer_braces_are_padded_per_row() {
    let ptx = module(
        ".global .u32 t[2][2] = {{1},{2}};\n.global .u32 s[][2] = {{1},{2}};\n\
         .global .u16 u[2][2][2] = {{{1}, {2, 3}}, {{4}}};\n.global .f32 f[2][2] = {{1.0}, {2.0}};\n\
         .visible .entry k()\n{\nret;\n}\n",
    );
    let p = warplight::ptx::load(&ptx, "nested.ptx").unwrap();
    let words = |name: &str| {
        let g = p.globals.iter().find(|g| g.name == name).unwrap();
        (g.size, g.init.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().unwrap())).collect::<Vec<u32>>())
    };
    assert_eq!(words("t"), (16, vec![1, 0, 2, 0]));
    assert_eq!(words("s"), (16, vec![1, 0, 2, 0]));
    assert_eq!(words("f"), (16, vec![1.0f32.to_bits(), 0, 2.0f32.to_bits(), 0]));
    let u = p.globals.iter().find(|g| g.name == "u").unwrap();
    let halves: Vec<u16> = u.init.chunks_exact(2).map(|b| u16::from_le_bytes(b.try_into().unwrap())).collect();
    assert_eq!((u.size, halves), (16, vec![1, 0, 2, 3, 4, 0, 0, 0]));
    let bad = module(".global .u32 t[2][2] = {{1, 2, 3}, {4}};\n.visible .entry k()\n{\nret;\n}\n");
    let e = warplight::ptx::load(&bad, "bad.ptx").unwrap_err().to_string();
    assert!(e.contains("`t` holds 3 elements; it has room for 2"), "{e}");
}
