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
/// should be looked at, not just updated. (92 with one pool of rows; the
/// two classes of rows, wide and narrow, cost 4 more.)
const TRACE_STACK_ROWS: usize = 96;

/// Of them, rows of 64-bit lanes and rows of 32-bit lanes (16 000 bytes a
/// warp, against 23 552 for 92 wide rows).
const TRACE_STACK_WIDE_NARROW: (usize, usize) = (29, 67);

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
    let (wide, narrow) = m.code.funcs[k].frame_rows();
    eprintln!("trace_stack: {declared} virtual registers, {rows} frame rows ({wide} wide, {narrow} narrow)");
    assert_eq!(rows, TRACE_STACK_ROWS, "trace_stack frame rows (of {declared} declared)");
    // most of its registers are of 32 bits (`%f`, `%r`): most rows are narrow
    assert_eq!((wide, narrow), TRACE_STACK_WIDE_NARROW, "trace_stack's wide and narrow rows");
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

/// Registers of 32 bits or fewer live in narrow rows of 32-bit lanes when a
/// kernel is launched (`Allocation::wide`), and the frequent forms on them
/// run as narrow lane functions (`Exec::Lanes32`, `Mov32`, `Selp32`,
/// `Setp32`); a stepper's frame keeps every register in a wide row and runs
/// the wide forms. Both write the same memory and count the same on edge
/// values (negative constants, sign extension from 8, 16 and 32 bits, shifts
/// past the width, signed and unsigned comparisons, f32 conversions),
/// guarded instructions, and partial masks of more and of fewer than 16
/// lanes; some results are checked against Rust too.
#[test]
fn narrow_rows_compute_what_wide_rows_compute() {
    let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry narrow(.param .u64 out, .param .u64 inp)\n{\n\
        .reg .pred %p<5>;\n.reg .b16 %h<6>;\n.reg .b32 %r<40>;\n.reg .f32 %f<10>;\n.reg .b64 %rd<10>;\n\
        ld.param.u64 %rd1, [out];\nld.param.u64 %rd2, [inp];\n\
        cvta.to.global.u64 %rd1, %rd1;\ncvta.to.global.u64 %rd2, %rd2;\n\
        mov.u32 %r1, %tid.x;\nmul.wide.u32 %rd3, %r1, 4;\nadd.s64 %rd4, %rd2, %rd3;\nadd.s64 %rd6, %rd1, %rd3;\n\
        ld.global.u32 %r2, [%rd4];\nld.global.s8 %r3, [%rd4];\nld.global.s16 %h1, [%rd4+2];\n\
        cvt.s32.s16 %r4, %h1;\n\
        add.s32 %r5, %r2, -1;\nsub.s32 %r6, -7, %r2;\nmul.lo.s32 %r7, %r2, -3;\nmad.lo.s32 %r8, %r2, %r3, -5;\n\
        shr.s32 %r9, %r2, 3;\nshr.u32 %r10, %r2, %r1;\nshl.b32 %r11, %r2, 33;\nmin.s32 %r12, %r2, %r3;\n\
        max.u32 %r13, %r2, %r3;\nand.b32 %r14, %r2, 0xFFFF00FF;\nxor.b32 %r15, %r2, -1;\n\
        setp.lt.s32 %p1, %r2, -100;\nselp.b32 %r16, %r5, %r6, %p1;\n\
        setp.lt.s16 %p2, %h1, 0;\n@%p2 add.s32 %r16, %r16, 1000;\n\
        mov.u16 %h2, 5;\nadd.u16 %h3, %h1, %h2;\ncvt.u32.u16 %r17, %h3;\n\
        cvt.rn.f32.s32 %f1, %r2;\nmul.f32 %f2, %f1, 0f3F000000;\nfma.rn.f32 %f3, %f2, %f1, 0fBF800000;\n\
        setp.gtu.f32 %p3, %f3, %f2;\nselp.f32 %f4, %f3, %f2, %p3;\ncvt.rzi.s32.f32 %r18, %f4;\n\
        cvt.s64.s32 %rd5, %r7;\ncvt.u32.u64 %r19, %rd5;\nmov.b64 {%r20, %r21}, %rd5;\nmov.b64 %rd7, {%r6, %r5};\n\
        setp.hi.u32 %p4, %r2, %r3;\nselp.u32 %r22, 1, 0, %p4;\n\
        mov.u32 %r23, 0;\nmov.u32 %r24, 0;\n\
        setp.lt.u32 %p1, %r1, 11;\n@%p1 bra SKIP1;\nadd.s32 %r23, %r2, %r1;\nmul.lo.s32 %r24, %r3, %r3;\nSKIP1:\n\
        setp.lt.u32 %p1, %r1, 27;\n@%p1 bra SKIP2;\nsub.s32 %r23, %r23, %r9;\nselp.b32 %r24, %r4, -9, %p2;\nSKIP2:\n\
        st.global.u32 [%rd6], %r3;\nst.global.u32 [%rd6+128], %r4;\nst.global.u32 [%rd6+256], %r5;\n\
        st.global.u32 [%rd6+384], %r6;\nst.global.u32 [%rd6+512], %r7;\nst.global.u32 [%rd6+640], %r8;\n\
        st.global.u32 [%rd6+768], %r9;\nst.global.u32 [%rd6+896], %r10;\nst.global.u32 [%rd6+1024], %r11;\n\
        st.global.u32 [%rd6+1152], %r12;\nst.global.u32 [%rd6+1280], %r13;\nst.global.u32 [%rd6+1408], %r14;\n\
        st.global.u32 [%rd6+1536], %r15;\nst.global.u32 [%rd6+1664], %r16;\nst.global.u32 [%rd6+1792], %r17;\n\
        st.global.u32 [%rd6+1920], %r18;\nst.global.u32 [%rd6+2048], %r19;\nst.global.u32 [%rd6+2176], %r20;\n\
        st.global.u32 [%rd6+2304], %r21;\nst.global.u32 [%rd6+2432], %r22;\nst.global.u32 [%rd6+2560], %r23;\n\
        st.global.u32 [%rd6+2688], %r24;\nst.global.f32 [%rd6+2816], %f4;\nst.global.u16 [%rd6+2944], %h3;\n\
        mul.wide.u32 %rd8, %r1, 8;\nadd.s64 %rd9, %rd1, %rd8;\nst.global.u64 [%rd9+3072], %rd7;\nret;\n}\n";
    let inputs: [u32; 32] = [
        0,
        1,
        u32::MAX,
        0x7FFF_FFFF,
        0x8000_0000,
        -100i32 as u32,
        -101i32 as u32,
        0x1234_8765,
        0xFFFF_0080,
        0x0000_7F7F,
        0x8000_FFFF,
        3,
        -3i32 as u32,
        0x00FF_FF00,
        16_777_217,
        0xDEAD_BEEF,
        7,
        -8i32 as u32,
        0x7F80_0000,
        100,
        0x0001_0000,
        0xFFFF_FFFE,
        0x4000_0000,
        0xC000_0000,
        12345,
        -12345i32 as u32,
        0x80,
        0x8000,
        0xFF,
        0xFFFF,
        31,
        -99i32 as u32,
    ];
    let run = |step: bool| {
        let mut dev = device(1);
        let m = dev.load_ptx(src, "narrow.ptx").unwrap();
        let out = dev.alloc_zeroed::<u32>(32 * 40);
        let inp = dev.alloc_from(&inputs);
        let (cfg, args) = (LaunchConfig::linear(1, 32), [Arg::Ptr(out), Arg::Ptr(inp)]);
        let counters = if step {
            let mut st = dev.stepper(&m, "narrow", cfg, &args).unwrap();
            while st.step().unwrap().is_some() {}
            st.counters()
        } else {
            dev.launch(&m, "narrow", cfg, &args).unwrap().totals
        };
        let k = m.prog.kernel("narrow").unwrap() as usize;
        let narrow = |code: &warplight::sim::decode::Code| code.funcs[k].frame_rows().1;
        (dev.read::<u32>(out, 32 * 40), counters, narrow(&m.code), narrow(m.stepping_code()))
    };
    let (launched, stepped) = (run(false), run(true));
    assert!(launched.2 > 0 && stepped.3 == 0, "narrow rows: launch {}, stepper {}", launched.2, stepped.3);
    assert_eq!(launched.1, stepped.1, "counters");
    let at = |v: &Vec<u32>, slot: usize, t: usize| v[slot * 32 + t];
    for slot in 0..40 {
        for t in 0..32 {
            assert_eq!(at(&launched.0, slot, t), at(&stepped.0, slot, t), "result {slot}, lane {t}");
        }
    }
    // some results by Rust
    let o = &launched.0;
    for (t, &x) in inputs.iter().enumerate() {
        let (s8, s16) = (x as u8 as i8 as i32, (x >> 16) as u16 as i16 as i32);
        assert_eq!(at(o, 0, t), s8 as u32, "ld.s8, lane {t}");
        assert_eq!(at(o, 1, t), s16 as u32, "ld.s16 + cvt.s32.s16, lane {t}");
        assert_eq!(at(o, 2, t), x.wrapping_sub(1), "add -1, lane {t}");
        assert_eq!(at(o, 5, t), (x as i32).wrapping_mul(s8).wrapping_sub(5) as u32, "mad, lane {t}");
        assert_eq!(at(o, 6, t), ((x as i32) >> 3) as u32, "shr.s32, lane {t}");
        assert_eq!(at(o, 8, t), 0, "shl by 33, lane {t}");
        assert_eq!(at(o, 9, t), (x as i32).min(s8) as u32, "min.s32, lane {t}");
        let p2 = s16 < 0;
        let sel = if (x as i32) < -100 { x.wrapping_sub(1) } else { (-7i32).wrapping_sub(x as i32) as u32 };
        assert_eq!(at(o, 13, t), sel.wrapping_add(if p2 { 1000 } else { 0 }), "selp + guarded add, lane {t}");
        let m3 = (x as i32).wrapping_mul(-3);
        assert_eq!(at(o, 16, t), m3 as u32, "cvt.u32.u64 of cvt.s64.s32, lane {t}");
        assert_eq!(at(o, 18, t), (m3 as i64 >> 32) as u32, "unpack's high half, lane {t}");
        let r23 = if t < 11 { 0 } else { x.wrapping_add(t as u32) };
        let r23 = if t < 27 { r23 } else { r23.wrapping_sub(((x as i32) >> 3) as u32) };
        assert_eq!(at(o, 20, t), r23, "partial masks, lane {t}");
        let r24 = if t < 11 { 0 } else { s8.wrapping_mul(s8) as u32 };
        let r24 = if t < 27 {
            r24
        } else if p2 {
            s16 as u32
        } else {
            -9i32 as u32
        };
        assert_eq!(at(o, 21, t), r24, "partial masks, lane {t}");
    }
}

/// The forms of step 28's narrow rows that `narrow_rows_compute_what_wide_rows_compute`
/// does not reach: a vector load into four narrow registers, atomics'
/// old values written into narrow rows (on every lane and under a partial
/// mask), `mul.hi` (interpreted, reading narrow operands zero-extended),
/// `vote.ballot` and `shfl` (with its predicate) into narrow rows. Launched
/// (narrow rows) and stepped (wide rows) write the same memory and count
/// the same; the values are checked against Rust.
#[test]
fn narrow_rows_take_vector_loads_atomics_shuffles_and_high_products() {
    let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry narrow_mem(.param .u64 out, .param .u64 inp, .param .u64 ctr)\n{\n\
        .reg .pred %p<3>;\n.reg .b32 %r<20>;\n.reg .b64 %rd<12>;\n\
        ld.param.u64 %rd1, [out];\nld.param.u64 %rd2, [inp];\nld.param.u64 %rd3, [ctr];\n\
        cvta.to.global.u64 %rd1, %rd1;\ncvta.to.global.u64 %rd2, %rd2;\ncvta.to.global.u64 %rd3, %rd3;\n\
        mov.u32 %r1, %tid.x;\nmul.wide.u32 %rd4, %r1, 16;\nadd.s64 %rd5, %rd2, %rd4;\n\
        ld.global.v4.u32 {%r2, %r3, %r4, %r5}, [%rd5];\n\
        mul.wide.u32 %rd6, %r1, 4;\nadd.s64 %rd7, %rd3, %rd6;\n\
        atom.global.add.u32 %r6, [%rd7], %r2;\natom.global.cas.b32 %r7, [%rd7], %r3, %r4;\n\
        mul.hi.s32 %r8, %r2, %r3;\nmul.hi.u32 %r9, %r2, %r3;\nmul.hi.s32 %r10, %r2, 715827883;\n\
        setp.lt.s32 %p1, %r2, 0;\nvote.sync.ballot.b32 %r11, %p1, -1;\n\
        shfl.sync.idx.b32 %r12, %r4, 3, 31, -1;\nshfl.sync.down.b32 %r13|%p2, %r5, 2, 31, -1;\n\
        selp.u32 %r14, 1, 0, %p2;\nmov.u32 %r15, 7;\n\
        @%p1 bra SKIP;\natom.global.exch.b32 %r15, [%rd7], %r5;\nSKIP:\n\
        add.s64 %rd8, %rd1, %rd6;\n\
        st.global.u32 [%rd8], %r2;\nst.global.u32 [%rd8+128], %r3;\nst.global.u32 [%rd8+256], %r4;\n\
        st.global.u32 [%rd8+384], %r5;\nst.global.u32 [%rd8+512], %r6;\nst.global.u32 [%rd8+640], %r7;\n\
        st.global.u32 [%rd8+768], %r8;\nst.global.u32 [%rd8+896], %r9;\nst.global.u32 [%rd8+1024], %r10;\n\
        st.global.u32 [%rd8+1152], %r11;\nst.global.u32 [%rd8+1280], %r12;\nst.global.u32 [%rd8+1408], %r13;\n\
        st.global.u32 [%rd8+1536], %r14;\nst.global.u32 [%rd8+1664], %r15;\nret;\n}\n";
    let xs: [u32; 32] = std::array::from_fn(|t| match t % 8 {
        0 => t as u32,
        1 => u32::MAX - t as u32,
        2 => 0x8000_0000 | t as u32,
        3 => 0x7FFF_FFF0 + t as u32,
        4 => (-(100 * t as i32)) as u32,
        5 => 0xDEAD_BEEF ^ t as u32,
        6 => 0x0001_0000 * t as u32,
        _ => 0xFFFF_0000 + t as u32,
    });
    let lane = |t: usize| -> [u32; 4] {
        [xs[t], xs[(t * 7 + 3) % 32], xs[(t * 5 + 1) % 32], 0x0101_0101u32.wrapping_mul(t as u32)]
    };
    let inputs: Vec<u32> = (0..32).flat_map(lane).collect();
    let ctr0: Vec<u32> = (0..32).map(|t| 1000 * t + 17).collect();
    let run = |step: bool| {
        let mut dev = device(1);
        let m = dev.load_ptx(src, "narrow_mem.ptx").unwrap();
        let out = dev.alloc_zeroed::<u32>(32 * 14);
        let inp = dev.alloc_from(&inputs);
        let ctr = dev.alloc_from(&ctr0);
        let (cfg, args) = (LaunchConfig::linear(1, 32), [Arg::Ptr(out), Arg::Ptr(inp), Arg::Ptr(ctr)]);
        let counters = if step {
            let mut st = dev.stepper(&m, "narrow_mem", cfg, &args).unwrap();
            while st.step().unwrap().is_some() {}
            st.counters()
        } else {
            dev.launch(&m, "narrow_mem", cfg, &args).unwrap().totals
        };
        let k = m.prog.kernel("narrow_mem").unwrap() as usize;
        let narrow = |code: &warplight::sim::decode::Code| code.funcs[k].frame_rows().1;
        (dev.read::<u32>(out, 32 * 14), dev.read::<u32>(ctr, 32), counters, narrow(&m.code), narrow(m.stepping_code()))
    };
    let (launched, stepped) = (run(false), run(true));
    assert!(launched.3 > 0 && stepped.4 == 0, "narrow rows: launch {}, stepper {}", launched.3, stepped.4);
    assert_eq!(launched.2, stepped.2, "counters");
    assert_eq!(launched.1, stepped.1, "the counters' memory");
    let at = |v: &Vec<u32>, slot: usize, t: usize| v[slot * 32 + t];
    for slot in 0..14 {
        for t in 0..32 {
            assert_eq!(at(&launched.0, slot, t), at(&stepped.0, slot, t), "result {slot}, lane {t}");
        }
    }
    let o = &launched.0;
    let ballot = (0..32).filter(|&t| (xs[t] as i32) < 0).fold(0u32, |b, t| b | 1 << t);
    for (t, &c0) in ctr0.iter().enumerate() {
        let [x, y, z, w] = lane(t);
        for (k, v) in [x, y, z, w].into_iter().enumerate() {
            assert_eq!(at(o, k, t), v, "ld.v4 component {k}, lane {t}");
        }
        assert_eq!(at(o, 4, t), c0, "atom.add's old value, lane {t}");
        assert_eq!(at(o, 5, t), c0.wrapping_add(x), "atom.cas's old value, lane {t}");
        assert_eq!(at(o, 6, t), ((x as i32 as i64 * y as i32 as i64) >> 32) as u32, "mul.hi.s32, lane {t}");
        assert_eq!(at(o, 7, t), ((x as u64 * y as u64) >> 32) as u32, "mul.hi.u32, lane {t}");
        assert_eq!(at(o, 8, t), ((x as i32 as i64 * 715_827_883) >> 32) as u32, "mul.hi.s32 by a constant, lane {t}");
        assert_eq!(at(o, 9, t), ballot, "vote.ballot, lane {t}");
        assert_eq!(at(o, 10, t), lane(3)[2], "shfl.idx, lane {t}");
        let down = if t + 2 < 32 { (lane(t + 2)[3], 1) } else { (w, 0) };
        assert_eq!((at(o, 11, t), at(o, 12, t)), down, "shfl.down and its predicate, lane {t}");
        let cas = c0.wrapping_add(x);
        let after_cas = if cas == y { z } else { cas };
        let exch = if (x as i32) < 0 { 7 } else { after_cas };
        assert_eq!(at(o, 13, t), exch, "atom.exch's old value under a partial mask, lane {t}");
        assert_eq!(launched.1[t], if (x as i32) < 0 { after_cas } else { w }, "the counter, lane {t}");
    }
    assert!(ballot != 0 && ballot != u32::MAX, "a partial mask: {ballot:#x}");
}
