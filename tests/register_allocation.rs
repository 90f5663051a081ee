//! Register compaction at decode time (`sim::regalloc`): a warp's frame holds
//! the live maximum of registers, not one row per PTX virtual register, and
//! nothing a kernel computes or counts changes. A launch runs the compacted
//! form; a stepper runs one row per register (`Module::stepping_code`), so
//! stepping to the end and launching compare the two.

mod common;
use common::*;
use warplight::host::rt_kernels;
use warplight::ptx::ir::RegId;
use warplight::sim::cfg::Cfg;
use warplight::sim::regalloc::{Allocation, Liveness};
use warplight::sim::{Arg, Device, LaunchConfig, Module, SimConfig};

/// Frame rows of `trace_stack` after compaction. It declares 686 data
/// registers (`%f<410>`, `%r<170>`, `%rd<100>`, `%SP`, `%SPL` and the
/// parameter temporaries); at most this many are live at once (or pinned).
/// A change to the allocator or the kernel's PTX that moves this figure
/// should be looked at, not just updated.
const TRACE_STACK_ROWS: usize = 92;

fn rt_module() -> (Device, Module) {
    let mut dev = Device::with_config(SimConfig::default());
    let m = rt_kernels::load(&mut dev).expect("ray-tracing kernels");
    (dev, m)
}

#[test]
fn trace_stack_frame_is_its_live_maximum() {
    let (_, m) = rt_module();
    let k = m.prog.kernel("trace_stack").expect("trace_stack") as usize;
    let declared = m.prog.functions[k].reg_masks.len();
    let rows = m.code.funcs[k].rows();
    eprintln!("trace_stack: {declared} virtual registers, {rows} frame rows");
    assert_eq!(rows, TRACE_STACK_ROWS, "trace_stack frame rows (of {declared} declared)");
    assert!(rows * 4 < declared, "compaction should shrink the frame at least 4x");
    // the stepper keeps one row per register
    assert_eq!(m.stepping_code().funcs[k].rows(), declared);
}

/// On every function of the ray-tracing kernels: registers live before the
/// same instruction, and a register an instruction writes and those live
/// after it, are in different slots; pinned registers share with nothing.
#[test]
fn no_two_live_registers_share_a_slot_in_the_ray_tracer() {
    let (_, m) = rt_module();
    for (fi, f) in m.prog.functions.iter().enumerate() {
        if f.insts.is_empty() {
            continue;
        }
        let cfg = Cfg::build(f);
        // the contracted instructions the module decoded with (none when contraction is off)
        let fused =
            &if m.code.funcs[fi].fused.is_empty() { Default::default() } else { warplight::sim::contract::contract(f) };
        let live = Liveness::of(f, &cfg, fused);
        let a: &Allocation = &m.code.funcs[fi].alloc;
        assert_eq!(a, &Allocation::compact(f, &cfg, fused), "the module's allocation is the analysis's");
        let mut slot_owner: Vec<Option<RegId>> = vec![None; a.rows as usize];
        for &p in &a.pinned {
            slot_owner[a.slot[p as usize] as usize] = Some(p);
        }
        for (pc, inst) in f.insts.iter().enumerate() {
            let mut regs: Vec<RegId> = live.live_in[pc].iter().collect();
            let mut k = inst.kind.clone();
            let mut defs = Vec::new();
            k.visit_regs_mut(&mut |r, _, w| {
                if w {
                    defs.push(*r)
                }
            });
            if !defs.is_empty() {
                regs.extend(defs);
                regs.extend(live.live_in.get(pc + 1).into_iter().flat_map(|s| s.iter()));
            }
            regs.sort_unstable();
            regs.dedup();
            let mut seen = vec![None; a.rows as usize];
            for r in regs {
                let s = a.slot[r as usize] as usize;
                if let Some(o) = seen[s] {
                    panic!(
                        "{}: {} and {} share slot {s} at pc {pc}",
                        f.name, f.reg_names[o as usize], f.reg_names[r as usize]
                    );
                }
                seen[s] = Some(r);
                if let Some(p) = slot_owner[s] {
                    assert_eq!(
                        p, r,
                        "{}: {} is in pinned {}'s slot",
                        f.name, f.reg_names[r as usize], f.reg_names[p as usize]
                    );
                }
            }
        }
    }
}

/// Launch (compacted frames) and stepping to the end (one row per register)
/// write the same memory and count the same, on kernels with divergent calls,
/// recursion, local arrays and shuffles.
#[test]
fn compacted_and_full_frames_compute_and_count_the_same() {
    let cases = [
        ("calls", "call_divergent", 64),
        ("calls", "recursive_fib", 64),
        ("warp_ops", "shuffles", 32),
        ("warp_ops", "votes", 64),
        ("divergence", "if_else", 64),
    ];
    for (file, kernel, n) in cases {
        for d in BOTH {
            let run = |step: bool| {
                let mut dev = device(1);
                let m = load(&mut dev, file, d);
                let out = dev.alloc_zeroed::<i32>(2048);
                let other = dev.alloc_from(&(0..2048).map(|x| x * 7 - 3).collect::<Vec<i32>>());
                let f = &m.prog.functions[m.prog.kernel(kernel).unwrap() as usize];
                let args: Vec<Arg> = f
                    .params
                    .iter()
                    .enumerate()
                    .map(|(i, p)| match (i, p.size) {
                        (0, 8) => Arg::Ptr(out),
                        (_, 8) => Arg::Ptr(other),
                        _ => Arg::I32(5 + i as i32),
                    })
                    .collect();
                let cfg = LaunchConfig::linear(1, n);
                let counters = if step {
                    let mut st = dev.stepper(&m, kernel, cfg, &args).unwrap();
                    while st.step().unwrap().is_some() {}
                    st.counters()
                } else {
                    dev.launch(&m, kernel, cfg, &args).unwrap().totals
                };
                (dev.read::<i32>(out, 2048), dev.read::<i32>(other, 2048), counters)
            };
            let (launched, stepped) = (run(false), run(true));
            assert_eq!(launched.0, stepped.0, "{kernel} ({d:?}): output");
            assert_eq!(launched.1, stepped.1, "{kernel} ({d:?}): second buffer");
            assert_eq!(launched.2, stepped.2, "{kernel} ({d:?}): counters");
        }
    }
}

/// Definitions that write fewer than the executing lanes, each the first
/// definition of its register after another register's range ended (whose
/// slot a killing definition would take): the lanes they leave alone read
/// the fresh frame's zeros, not the earlier register.
const PARTIAL_DEFS: &str = ".version 7.8\n.target sm_90\n.address_size 64\n\
    .visible .entry KERNEL(.param .u64 out)\n{\n.reg .pred %p<2>;\n.reg .b32 %r<12>;\n.reg .b64 %rd<5>;\n\
    ld.param.u64 %rd1, [out];\ncvta.to.global.u64 %rd1, %rd1;\nmov.u32 %r1, %tid.x;\nmul.wide.u32 %rd2, %r1, 4;\n\
    add.s64 %rd3, %rd1, %rd2;\nadd.u32 %r3, %r1, 7777;\nst.global.u32 [%rd3+128], %r3;\n\
    setp.lt.u32 %p1, %r1, 16;\nselp.b32 %r5, 0x0000FFFF, 0xFFFF0000, %p1;\n\
    and.b32 %r2, %r1, 3;\nadd.u32 %r6, %r1, 0x80000000;\nsetp.lt.u32 %p1, %r1, 8;\n\
    BODY\nst.global.u32 [%rd3], %r4;\nret;\n}\n";

/// Launch (compacted frames) and stepping to the end (one row per register)
/// of the definitions that do not kill: a guarded one, `redux` and `match`
/// (which write the member lanes: here lanes 0..15, the first lane's mask),
/// and a guarded `add.cc` read by two `addc` (which do not write the
/// condition code). Lanes 0..15 are worked by hand; all lanes agree.
#[test]
fn definitions_that_do_not_kill_keep_their_registers_live() {
    // (kernel, the definitions, the value of lane t)
    type Case = (&'static str, &'static str, fn(u32) -> u32);
    let cases: [Case; 4] = [
        ("guarded", "@%p1 mov.u32 %r4, 5;", |t| if t < 8 { 5 } else { 0 }),
        // lanes 0..15 hold t & 3: four each of 0, 1, 2, 3
        ("redux", "redux.sync.add.u32 %r4, %r2, %r5;", |t| if t < 16 { 24 } else { 0 }),
        ("match", "match.any.sync.b32 %r4, %r2, %r5;", |t| if t < 16 { 0x1111 << (t & 3) } else { 0 }),
        (
            "carry",
            "@%p1 add.cc.u32 %r7, %r6, %r6;\naddc.u32 %r8, 0, 0;\naddc.u32 %r9, %r8, 0;\nmad.lo.u32 %r4, %r8, 10, %r9;",
            // lanes 0..7: 2^31 + t doubled carries 1, read twice (addc leaves it): 1·10 + 2
            |t| if t < 8 { 12 } else { 0 },
        ),
    ];
    for (kernel, body, want) in cases {
        let src = PARTIAL_DEFS.replace("KERNEL", kernel).replace("BODY", body);
        let run = |step: bool| {
            let mut dev = device(1);
            let m = dev.load_ptx(&src, "partial.ptx").unwrap_or_else(|e| panic!("{kernel}: {e}"));
            let out = dev.alloc_zeroed::<u32>(64);
            let (cfg, args) = (LaunchConfig::linear(1, 32), [Arg::Ptr(out)]);
            let counters = if step {
                let mut st = dev.stepper(&m, kernel, cfg, &args).unwrap();
                while st.step().unwrap().is_some() {}
                st.counters()
            } else {
                dev.launch(&m, kernel, cfg, &args).unwrap().totals
            };
            let k = m.prog.kernel(kernel).unwrap() as usize;
            (dev.read::<u32>(out, 64), counters, m.code.funcs[k].rows(), m.prog.functions[k].reg_masks.len())
        };
        let (launched, stepped) = (run(false), run(true));
        let (rows, declared) = (launched.2, launched.3);
        assert!(rows < declared, "{kernel}: the launch's frame is compacted ({rows} of {declared} rows)");
        assert_eq!(launched.0, stepped.0, "{kernel}: compacted and full frames");
        assert_eq!(launched.1, stepped.1, "{kernel}: counters");
        for t in 0..32 {
            assert_eq!(launched.0[32 + t], 7777 + t as u32, "{kernel}: the earlier register, lane {t}");
            if t < 16 || kernel == "guarded" || kernel == "carry" {
                assert_eq!(launched.0[t], want(t as u32), "{kernel}: lane {t}");
            }
        }
    }
}
