//! Stepping one warp instruction at a time: the SIMT stack, masks, registers and
//! shared memory are visible, and stepping to the end matches a normal launch.

#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use warplight::sim::{Arg, LaunchConfig};

#[test]
fn stepping_shows_divergence_and_reconvergence() {
    let mut dev = device(1);
    let m = load(&mut dev, "divergence", Dialect::Clang);
    let odd = dev.alloc_zeroed::<i32>(2048);
    let even = dev.alloc_zeroed::<i32>(2048);
    let args = [Arg::Ptr(odd), Arg::Ptr(even)];
    let mut st = dev.stepper(&m, "if_else", LaunchConfig::linear(1, 32), &args).unwrap();
    let first = st.step().unwrap().unwrap();
    assert_eq!((first.warp, first.pc, first.mask), (0, 0, u32::MAX));
    assert_eq!(first.opcode, "mov.u32");
    // Step until the branch has executed: then two paths sit on the stack.
    let ev = st.run_until(100, |_, e| e.opcode == "bra" && e.mask == u32::MAX).unwrap().unwrap();
    assert_eq!(ev.opcode, "bra");
    let w = st.warp(0, 0).unwrap();
    assert_eq!(w.stack.len(), 3, "reconvergence entry + two paths: {:?}", w.stack);
    assert_eq!(w.active, 0xAAAA_AAAA, "odd lanes (fall-through) run first");
    assert_eq!(w.stack[1].mask, 0x5555_5555);
    assert_eq!(w.stack[2].rpc, w.stack[1].rpc);
    // %r10 holds threadIdx.x
    let r = st.register(0, 0, "%r10").unwrap();
    assert_eq!(r[7], 7);
    assert!(st.register_names(0, 0).contains(&"%p4".to_string()));
    // Run on to the join: each path pops when it reaches it, so the next
    // instruction at the join's line is issued by the whole warp again.
    let join = w.stack[1].rpc;
    let line = m.prog.functions[0].info[join as usize].ptx_line;
    st.run_to_ptx_line(line, 100).unwrap();
    let w = st.warp(0, 0).unwrap();
    assert_eq!(w.next_pc, Some(join));
    assert_eq!(w.stack.len(), 1);
    assert_eq!(w.active, u32::MAX);
    assert_eq!(st.counters().reconvergences, 2);
    // Finish, and compare with a normal launch.
    while st.step().unwrap().is_some() {}
    assert!(st.finished());
    let stepped = st.counters();
    let normal = dev.launch(&m, "if_else", LaunchConfig::linear(1, 32), &args).unwrap();
    assert_eq!(stepped.warp_instructions, normal.totals.warp_instructions);
    assert_eq!(stepped.thread_instructions, normal.totals.thread_instructions);
    assert_eq!(stepped.divergent_branches, normal.totals.divergent_branches);
}

#[test]
fn stepping_shows_shared_memory_and_barriers() {
    let mut dev = device(1);
    let m = load(&mut dev, "shared", Dialect::Clang);
    let input: Vec<i32> = (0..256).collect();
    let inb = dev.alloc_from(&input);
    let out = dev.alloc_zeroed::<i32>(1);
    let mut st = dev.stepper(&m, "reduce_sum", LaunchConfig::linear(1, 256), &[Arg::Ptr(out), Arg::Ptr(inb)]).unwrap();
    assert_eq!(st.warps_per_cta(), 8);
    // Run until the last warp arrives at the first barrier.
    let ev = st.run_until(10_000, |_, e| e.opcode == "bar.sync" && e.warp == 7).unwrap().unwrap();
    assert_eq!(ev.warp, 7);
    let sh = st.shared(0).unwrap();
    let vals: Vec<i32> = sh[..1024].chunks(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(vals, input, "every thread stored its value before the barrier");
    while st.step().unwrap().is_some() {}
    assert_eq!(st.counters().barriers, 9);
}
