//! Executes one warp instruction: fetch from the SIMT stack's top path,
//! evaluate the guard, count, apply the instruction to the active lanes
//! (registers as 32-lane arrays), and move the PC or the stack.
//!
//! This file holds the launch context ([`Ctx`], [`CtaMut`]), operand access
//! and the dispatch; the instruction families live in [`arith`] (data and
//! lane exchange), [`memory`] (loads, stores, address spaces, observer
//! events), [`atomic`], [`control`] (branches, exit, barriers) and [`call`].

mod arith;
mod atomic;
mod call;
mod control;
mod memory;
mod texture;

pub use atomic::{PendingAtomic, apply_pending};
pub use call::call_chain;

use super::cfg::Cfg;
use super::counters::{Counters, InstProfile};
use super::decode::{CONST, Code, Dest, Exec, Lanes32, Opnd, Word};
use super::fault::FaultKind;
use super::memory::DeviceMemory;
use super::observer::{MemObserver, ObserverFactory};
use super::simt_stack::SimtEntry;
use super::warp::{BarRedWait, Frame, Warp};
use crate::ptx::ir::*;

/// Everything an instruction may read that is shared by all CTAs of a launch.
pub struct Ctx<'a> {
    /// The program.
    pub prog: &'a Program,
    /// Its decoded form.
    pub code: &'a Code,
    /// CFG (reconvergence points) of each function.
    pub cfgs: &'a [Cfg],
    /// Device memory.
    pub mem: &'a DeviceMemory,
    /// Kernel parameter bytes.
    pub kparams: Vec<u8>,
    /// Addresses of the module's `.global` variables.
    pub global_addrs: &'a [u64],
    /// Grid size in CTAs.
    pub grid: [u32; 3],
    /// CTA size in threads.
    pub block: [u32; 3],
    /// Simulated SM count (for `%smid`, `%nsmid`).
    pub num_sms: u32,
    /// Per-thread local memory limit in bytes.
    pub local_limit: u32,
    /// Most device-function frames on a warp's call stack.
    pub max_call_depth: u32,
    /// Makes the per-CTA memory observers (counter models), if any.
    pub observers: Option<&'a dyn ObserverFactory>,
    /// Count per instruction (fidelity `instructions` and up).
    pub per_inst: bool,
    /// Where `printf` output goes.
    pub printf: super::printf::PrintfTarget<'a>,
    /// The device's texture and surface objects (handle = index + 1).
    pub textures: &'a [super::texture::Object],
}

/// The CTA-owned state an instruction may change besides its warp.
pub struct CtaMut<'a> {
    /// CTA index.
    pub cta_id: [u32; 3],
    /// Linear CTA index.
    pub cta_linear: u32,
    /// Shared memory.
    pub shared: &'a mut Vec<u8>,
    /// Counters.
    pub counters: &'a mut Counters,
    /// Per-instruction counts.
    pub profile: &'a mut InstProfile,
    /// Global atomics waiting for the round's end.
    pub pending: &'a mut Vec<PendingAtomic>,
    /// The CTA's memory observer.
    pub observer: Option<&'a mut Box<dyn MemObserver>>,
}

/// A fault raised by an instruction (the caller adds where).
#[derive(Debug, Clone)]
pub struct ExecFault {
    /// What happened.
    pub kind: FaultKind,
    /// The first faulting lane, if per lane.
    pub lane: Option<u32>,
}

/// A fault, boxed: instructions return it rarely, and a small `Result` keeps
/// the common path cheap.
fn fault(kind: FaultKind, lane: Option<usize>) -> Box<ExecFault> {
    Box::new(ExecFault { kind, lane: lane.map(|l| l as u32) })
}

/// What the executed instruction did to the warp's schedulability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    /// The warp can continue.
    Continue,
    /// The warp blocked (barrier, atomic) or finished.
    Blocked,
}

/// 32 lanes of register bits.
pub(crate) type Lanes = [u64; 32];

#[inline(always)]
fn map1(a: &Lanes, f: impl Fn(u64) -> u64) -> Lanes {
    std::array::from_fn(|l| f(a[l]))
}

#[inline(always)]
fn map3(a: &Lanes, b: &Lanes, c: &Lanes, f: impl Fn(u64, u64, u64) -> u64) -> Lanes {
    std::array::from_fn(|l| f(a[l], b[l], c[l]))
}

#[inline(always)]
fn write(frame: &mut Frame, d: Dst, v: &Lanes, mask: u32) {
    if d.reg == Dst::SINK {
        return;
    }
    store_slot(frame, d.reg as usize, d.mask, v, mask);
}

/// Writes `v & width` into the lanes of the frame's row `slot` (wide or
/// narrow) that `exec` names.
#[inline(always)]
fn store_slot(fr: &mut Frame, slot: usize, width: u64, v: &Lanes, exec: u32) {
    let nw = fr.regs.len();
    if slot < nw {
        store_row(&mut fr.regs[slot], width, v, exec);
    } else {
        store_row(&mut fr.regs32[slot - nw], width as u32, v, exec);
    }
}

/// All-ones or all-zeros lane masks of four lanes of type `$t`, for each
/// 4-bit group of a lane bitmask.
macro_rules! nibble_masks {
    ($t:ty) => {{
        let mut t = [[0 as $t; 4]; 16];
        let mut n = 0;
        while n < 16 {
            let mut l = 0;
            while l < 4 {
                if n >> l & 1 != 0 {
                    t[n][l] = <$t>::MAX;
                }
                l += 1;
            }
            n += 1;
        }
        t
    }};
}

static NIBBLE_MASKS: [[u64; 4]; 16] = nibble_masks!(u64);
static NIBBLE_MASKS32: [[u32; 4]; 16] = nibble_masks!(u32);

/// A register row's lane word, with what [`store_row`] and [`lane_masks`]
/// need of it.
trait RowWord: Word + 'static {
    /// Active lanes up to which [`store_row`] writes lane by lane: about 6
    /// host instructions per active lane, against about 130 for the
    /// branch-free select of 32 wide lanes and about half that of 32 narrow
    /// ones (the ray-tracing kernels' warps average 13–14 active lanes).
    const SPARSE_LANES: u32;
    /// The lane masks of a 4-bit group.
    fn nibble(n: u32) -> &'static [Self; 4];
}

impl RowWord for u64 {
    const SPARSE_LANES: u32 = 16;
    #[inline(always)]
    fn nibble(n: u32) -> &'static [u64; 4] {
        &NIBBLE_MASKS[n as usize]
    }
}

impl RowWord for u32 {
    const SPARSE_LANES: u32 = 10;
    #[inline(always)]
    fn nibble(n: u32) -> &'static [u32; 4] {
        &NIBBLE_MASKS32[n as usize]
    }
}

/// Lane `l` all ones where bit `l` of `bits` is set, else zero: selecting by
/// a lane bitmask through it is branch-free and vectorises (a loop testing
/// each bit compiles to a branch per lane, mispredicted when warps diverge).
#[inline(always)]
fn lane_masks<W: RowWord>(bits: u32) -> [W; 32] {
    let mut m = [W::default(); 32];
    for k in 0..8 {
        m[k * 4..k * 4 + 4].copy_from_slice(W::nibble(bits >> (4 * k) & 0xF));
    }
    m
}

/// `a` where the lane's mask is set, else `b`.
#[inline(always)]
fn select<W: Word>(m: &[W; 32], a: &[W; 32], b: &[W; 32], out: &mut [W; 32]) {
    for l in 0..32 {
        out[l] = (a[l] & m[l]) | (b[l] & !m[l]);
    }
}

/// Writes `v & width` into the lanes of `row` that `exec` names (a wide
/// value truncated to a narrow row's lanes, `width` of 32 bits or fewer
/// then).
#[inline(always)]
fn store_row<T: RowWord, S: Word>(row: &mut [T; 32], width: T, v: &[S; 32], exec: u32) {
    if exec == u32::MAX {
        for l in 0..32 {
            row[l] = T::of(v[l].wide()) & width;
        }
    } else if exec.count_ones() <= T::SPARSE_LANES {
        let mut m = exec;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            row[l] = T::of(v[l].wide()) & width;
        }
    } else {
        let e = lane_masks::<T>(exec);
        for l in 0..32 {
            row[l] = (T::of(v[l].wide()) & width & e[l]) | (row[l] & !e[l]);
        }
    }
}

/// Writes a compact instruction's result (a wide row or a narrow one).
#[inline(always)]
fn put(fr: &mut Frame, d: Dest, v: &Lanes, exec: u32) {
    if d.slot != Dest::SINK {
        store_slot(fr, d.slot as usize, d.mask(), v, exec);
    }
}

/// Writes a narrow form's result (`d.slot`: the narrow row's index).
#[inline(always)]
fn put32(fr: &mut Frame, d: Dest, v: &Lanes32, exec: u32) {
    store_row(&mut fr.regs32[d.slot as usize], d.mask() as u32, v, exec);
}

/// Row `slot` of a frame as 64-bit lanes: a wide row borrowed, a narrow one
/// zero-extended.
#[inline(always)]
fn row(fr: &Frame, slot: usize) -> Operand<'_> {
    match fr.regs.get(slot) {
        Some(r) => Operand::Reg(r),
        None => {
            let n = &fr.regs32[slot - fr.regs.len()];
            Operand::Value(std::array::from_fn(|l| n[l] as u64))
        }
    }
}

/// A compact instruction's operand: a register row or a constant row.
#[inline(always)]
fn opnd<'a>(fr: &'a Frame, consts: &'a [Lanes], o: Opnd) -> Operand<'a> {
    if o < CONST { row(fr, o as usize) } else { Operand::Reg(&consts[(o - CONST) as usize]) }
}

/// A narrow form's operand: a narrow row or a narrow constant row.
#[inline(always)]
fn opnd32<'a>(regs32: &'a [Lanes32], consts32: &'a [Lanes32], o: Opnd) -> &'a Lanes32 {
    if o < CONST { &regs32[o as usize] } else { &consts32[(o - CONST) as usize] }
}

/// A compact memory instruction's addresses: base plus offset (32-bit bases
/// wrap, then zero-extend).
#[inline(always)]
fn compact_addresses(fr: &Frame, consts: &[Lanes], base: Opnd, offset: i32, wide: bool) -> Lanes {
    let b = &*opnd(fr, consts, base);
    if wide {
        map1(b, |x| x.wrapping_add(offset as i64 as u64))
    } else {
        map1(b, |x| (x as u32).wrapping_add(offset as u32) as u64)
    }
}

#[inline(always)]
fn pred_bits(frame: &Frame, p: PredSrc) -> u32 {
    let v = frame.preds[p.reg as usize];
    if p.neg { !v } else { v }
}

#[inline(always)]
fn set_pred(frame: &mut Frame, p: PredId, value: u32, mask: u32) {
    if p > PRED_TRUE {
        let r = &mut frame.preds[p as usize];
        *r = (*r & !mask) | (value & mask);
    }
}

fn combine(op: BoolOp, a: u32, b: u32) -> u32 {
    match op {
        BoolOp::And => a & b,
        BoolOp::Or => a | b,
        BoolOp::Xor => a ^ b,
    }
}

fn lane_of_mask(m: u32) -> Option<usize> {
    (m != 0).then(|| m.trailing_zeros() as usize)
}

/// Reads a source operand for all lanes.
#[inline]
fn read(ctx: &Ctx, w: &Warp, cta: &CtaMut, s: Src) -> Lanes {
    let f = w.frame();
    match s {
        Src::Reg(r) => *row(f, r as usize),
        Src::Imm(v) => [v; 32],
        Src::LocalAddr(o) => [(f.local_base + o) as u64; 32],
        Src::GlobalAddr(g, o) => [ctx.global_addrs[g as usize] + o as u64; 32],
        Src::Special(sr) => special(ctx, w, cta, sr),
    }
}

/// An operand's lanes: a register borrowed from the frame, or a value built
/// for any other source. Saves copying 256 bytes per register operand.
// Boxing the value would allocate per operand; the enum lives on the stack
// for one instruction.
#[allow(clippy::large_enum_variant)]
enum Operand<'a> {
    Reg(&'a Lanes),
    Value(Lanes),
}

impl std::ops::Deref for Operand<'_> {
    type Target = Lanes;
    #[inline]
    fn deref(&self) -> &Lanes {
        match self {
            Operand::Reg(r) => r,
            Operand::Value(v) => v,
        }
    }
}

#[inline]
fn operand<'a>(ctx: &Ctx, w: &'a Warp, cta: &CtaMut, s: Src) -> Operand<'a> {
    match s {
        Src::Reg(r) => row(w.frame(), r as usize),
        other => Operand::Value(read(ctx, w, cta, other)),
    }
}

fn special(ctx: &Ctx, w: &Warp, cta: &CtaMut, sr: SpecialReg) -> Lanes {
    let [bx, by, _] = ctx.block;
    let tid = |l: usize, d: u8| -> u64 {
        let lin = w.id * 32 + l as u32;
        (match d {
            0 => lin % bx,
            1 => (lin / bx) % by,
            _ => lin / (bx * by),
        }) as u64
    };
    match sr {
        SpecialReg::Tid(d) => std::array::from_fn(|l| tid(l, d)),
        SpecialReg::Ntid(d) => [ctx.block[d as usize] as u64; 32],
        SpecialReg::Ctaid(d) => [cta.cta_id[d as usize] as u64; 32],
        SpecialReg::Nctaid(d) => [ctx.grid[d as usize] as u64; 32],
        SpecialReg::LaneId => std::array::from_fn(|l| l as u64),
        SpecialReg::WarpId => [w.id as u64; 32],
        SpecialReg::NWarpId => [(bx * ctx.block[1] * ctx.block[2]).div_ceil(32) as u64; 32],
        SpecialReg::SmId => [(cta.cta_linear % ctx.num_sms) as u64; 32],
        SpecialReg::NSmId => [ctx.num_sms as u64; 32],
        SpecialReg::GridId => [0; 32],
        SpecialReg::LaneMaskEq => std::array::from_fn(|l| 1u64 << l),
        SpecialReg::LaneMaskLe => std::array::from_fn(|l| ((1u64 << (l + 1)) - 1) & 0xFFFF_FFFF),
        SpecialReg::LaneMaskLt => std::array::from_fn(|l| (1u64 << l) - 1),
        SpecialReg::LaneMaskGe => std::array::from_fn(|l| (0xFFFF_FFFFu64 << l) & 0xFFFF_FFFF),
        SpecialReg::LaneMaskGt => std::array::from_fn(|l| (0xFFFF_FFFFu64 << (l + 1)) & 0xFFFF_FFFF),
        // A deterministic clock: the CTA's issued warp instructions.
        SpecialReg::Clock | SpecialReg::Clock64 => [cta.counters.warp_instructions; 32],
        SpecialReg::GlobalTimerHi => [cta.counters.warp_instructions >> 32; 32],
    }
}

/// Executes the next instruction of warp `w`. Returns its function and PC (for
/// fault reports and stepping) and its effect.
///
/// Reconvergence is checked once per instruction, after it, and only when the
/// running path stands at its reconvergence point. Both are the same as
/// popping before and after every instruction:
/// - `SimtStack::reconverge` pops nothing unless the top entry's `pc` equals
///   its `rpc` (its loop stops at the first entry where they differ), so
///   testing that first changes nothing.
/// - Before an instruction there is nothing to pop: the stack and the frames
///   of a warp change only inside this function (branches, exits, calls and
///   returns; barriers, atomics and the scheduler change the warp's state and
///   registers, not its stack), and the previous instruction of the warp
///   ended with the check below, which pops until the top entry is not at
///   its reconvergence point or is its frame's first; a warp starts with one
///   entry. `stepper::tests::the_stack_between_instructions_is_reconverged`
///   checks this between every two instructions of divergent kernels.
pub fn step(ctx: &Ctx, w: &mut Warp, cta: &mut CtaMut) -> (u32, u32, Result<Effect, Box<ExecFault>>) {
    let top = *w.stack.top().expect("running warp has a path");
    let func = w.frame().func;
    let pc = top.pc;
    let r = exec(ctx, w, cta, func, top);
    // Pop paths that reached their reconvergence point now, so that the stack
    // seen between instructions is the one the next instruction runs on.
    if let Some(t) = w.stack.top()
        && t.pc == t.rpc
    {
        let base = w.frame().stack_base;
        cta.counters.reconvergences += w.stack.reconverge(base) as u64;
    }
    (func, pc, r)
}

/// Moves the running path to the next instruction.
#[inline(always)]
fn advance(w: &mut Warp, pc: u32) {
    w.stack.top_mut().expect("top").pc = pc + 1;
}

// inlined into `step`, as it was before the narrow forms made it larger
#[inline(always)]
fn exec(ctx: &Ctx, w: &mut Warp, cta: &mut CtaMut, func: u32, top: SimtEntry) -> Result<Effect, Box<ExecFault>> {
    let pc = top.pc;
    let code = &ctx.code.funcs[func as usize];
    let Some(op) = code.ops.get(pc as usize) else {
        let name = &ctx.prog.functions[func as usize].name;
        return Err(fault(FaultKind::Unsupported(format!("execution ran past the end of `{name}`")), None));
    };
    let mask = top.mask;
    // an unguarded instruction's guard is the always-true predicate
    let exec = mask & pred_bits(w.frame(), op.guard);
    // counting
    let c = &mut *cta.counters;
    c.warp_instructions += 1;
    c.thread_instructions += mask.count_ones() as u64;
    c.thread_instructions_pred_on += exec.count_ones() as u64;
    c.by_class.add(op.class);
    if ctx.per_inst {
        // per counting block: warp and thread counts once per block entry,
        // `pred_on` where a guard makes it differ (`InstProfile::expand_blocks`)
        let counts = &mut cta.profile.per_fn[func as usize];
        if op.leader {
            let ic = &mut counts[pc as usize];
            ic.warp += 1;
            ic.thread += mask.count_ones() as u64;
        }
        if op.guarded() {
            counts[pc as usize].pred_on += exec.count_ones() as u64;
        }
    }

    match op.exec {
        // control transfers move the stack themselves (and run with no lane active too)
        Exec::Bra { target } => return Ok(control::branch(ctx, w, cta, func, pc, target, exec)),
        Exec::Ir => return exec_ir(ctx, w, cta, func, pc, &code.insts[pc as usize], exec),
        _ => {}
    }
    advance(w, pc);
    if exec == 0 {
        // Predicated off for every lane: issued, no effect.
        return Ok(Effect::Continue);
    }
    let consts = &code.consts[..];
    let consts32 = &code.consts32[..];
    match op.exec {
        Exec::Lanes32 { f, d, a, b, c } => {
            let fr = w.frames.last_mut().expect("frame");
            let mut r = [0u32; 32];
            let n = &fr.regs32;
            f(opnd32(n, consts32, a), opnd32(n, consts32, b), opnd32(n, consts32, c), &mut r);
            put32(fr, d, &r, exec);
        }
        Exec::Mov32 { d, a } => {
            let fr = w.frames.last_mut().expect("frame");
            let r = *opnd32(&fr.regs32, consts32, a);
            put32(fr, d, &r, exec);
        }
        Exec::Selp32 { d, a, b, p } => {
            let fr = w.frames.last_mut().expect("frame");
            let m = lane_masks(pred_bits(fr, p));
            let mut r = [0u32; 32];
            select(&m, opnd32(&fr.regs32, consts32, a), opnd32(&fr.regs32, consts32, b), &mut r);
            put32(fr, d, &r, exec);
        }
        Exec::Setp32 { cmp, ty, ftz, p, q, a, b } => {
            let fr = w.frames.last_mut().expect("frame");
            let n = &fr.regs32;
            let t = super::alu::compare_lanes(cmp, ty, ftz, opnd32(n, consts32, a), opnd32(n, consts32, b));
            set_pred(fr, p, t, exec);
            // `q` is PRED_FALSE, never written, when absent
            set_pred(fr, q, !t, exec);
        }
        Exec::Lanes { f, d, a, b, c } => {
            let fr = w.frames.last_mut().expect("frame");
            let mut r = [0u64; 32];
            f(&opnd(fr, consts, a), &opnd(fr, consts, b), &opnd(fr, consts, c), &mut r);
            put(fr, d, &r, exec);
        }
        Exec::Mov { d, a } => {
            let fr = w.frames.last_mut().expect("frame");
            let r = *opnd(fr, consts, a);
            put(fr, d, &r, exec);
        }
        Exec::Selp { d, a, b, p } => {
            let fr = w.frames.last_mut().expect("frame");
            let m = lane_masks(pred_bits(fr, p));
            let mut r = [0u64; 32];
            select(&m, &opnd(fr, consts, a), &opnd(fr, consts, b), &mut r);
            put(fr, d, &r, exec);
        }
        Exec::Setp { cmp, ty, ftz, p, q, a, b } => {
            let fr = w.frames.last_mut().expect("frame");
            let t = super::alu::compare_lanes(cmp, ty, ftz, &opnd(fr, consts, a), &opnd(fr, consts, b));
            set_pred(fr, p, t, exec);
            // `q` is PRED_FALSE, never written, when absent
            set_pred(fr, q, !t, exec);
        }
        Exec::Fused => {
            let (Kind::Arith { ty, mode, d, .. }, Some(fz)) = (&code.insts[pc as usize].kind, code.fused.get(&pc))
            else {
                unreachable!("a contracted instruction is an arithmetic one with its contraction")
            };
            arith::fused(ctx, w, cta, (*ty, *mode), *d, fz, exec);
        }
        Exec::Ld { space, ty, n, nc, wide, bits, base, offset, ds } => {
            let addrs = compact_addresses(w.frame(), consts, base, offset, wide);
            // a scalar load needs one lane array, not four
            let mut one = [[0u64; 32]; 1];
            let mut four;
            let vals: &mut [Lanes] = if n == 1 {
                &mut one
            } else {
                four = [[0u64; 32]; 4];
                &mut four[..n as usize]
            };
            memory::transfer(ctx, w, cta, (func, pc), space, ty, &addrs, false, nc, exec, vals)?;
            let fr = w.frames.last_mut().expect("frame");
            for (v, &slot) in vals.iter().zip(&ds) {
                put(fr, Dest { slot, bits }, v, exec);
            }
        }
        Exec::St { space, ty, n, wide, base, offset, vals } => {
            let fr = w.frame();
            let addrs = compact_addresses(fr, consts, base, offset, wide);
            let mut vs = [[0u64; 32]; 4];
            for (v, &o) in vs.iter_mut().zip(&vals[..n as usize]) {
                *v = *opnd(fr, consts, o);
            }
            memory::transfer(ctx, w, cta, (func, pc), space, ty, &addrs, true, false, exec, &mut vs[..n as usize])?;
        }
        Exec::Bra { .. } | Exec::Ir => unreachable!("handled above"),
    }
    Ok(Effect::Continue)
}

/// Executes an instruction without a compact form, from its IR (registers
/// renamed to frame slots), once counted.
fn exec_ir(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    func: u32,
    pc: u32,
    inst: &Inst,
    exec: u32,
) -> Result<Effect, Box<ExecFault>> {
    // Control transfers move the stack themselves (and run with no lane active too).
    // (`bra` always has a compact form: `exec` runs it)
    match &inst.kind {
        // `ret` in the kernel's own frame (no caller to return to) ends the
        // thread, as `exit` does; the front end already lowers a kernel's
        // `ret` to `exit`, this covers hand-built programs.
        Kind::Exit | Kind::Ret if matches!(inst.kind, Kind::Exit) || w.frames.len() == 1 => {
            advance(w, pc);
            return Ok(control::exit(ctx, w, exec));
        }
        Kind::Ret => {
            advance(w, pc);
            return Ok(call::ret(ctx, w, exec));
        }
        Kind::Call { func: callee, args, .. } => {
            advance(w, pc);
            return call::call(ctx, w, cta, pc, *callee, args, exec);
        }
        Kind::CallIndirect { target, args, .. } => {
            advance(w, pc);
            return call::call_indirect(ctx, w, cta, pc, *target, args, exec);
        }
        _ => {}
    }

    advance(w, pc);
    if exec == 0 {
        // Predicated off for every lane: issued, no effect.
        return Ok(Effect::Continue);
    }

    match &inst.kind {
        Kind::Mov { d, a } => arith::mov(ctx, w, cta, *d, *a, exec),
        Kind::Pack { d, parts, part_bits } => arith::pack(ctx, w, cta, *d, parts, *part_bits, exec),
        Kind::Unpack { ds, a, part_bits } => arith::unpack(ctx, w, cta, ds, *a, *part_bits, exec),
        Kind::Arith { op, ty, mode, d, a, b, c } => {
            arith::arith(ctx, w, cta, (*op, *ty, *mode), *d, [*a, *b, *c], exec)
        }
        Kind::Bfi { ty, d, a, b, c, e } => arith::bfi(ctx, w, cta, *ty, *d, [*a, *b, *c, *e], exec),
        Kind::Setp { .. } => arith::setp(ctx, w, cta, &inst.kind, exec),
        Kind::Set { .. } => arith::set(ctx, w, cta, &inst.kind, exec),
        Kind::Selp { d, a, b, p } => arith::selp(ctx, w, cta, *d, *a, *b, *p, exec),
        Kind::PredLogic { op, d, a, b } => arith::pred_logic(w, *op, *d, *a, *b, exec),
        Kind::Cvt { dty, sty, mode, d, a } => arith::cvt(ctx, w, cta, (*dty, *sty, *mode), *d, *a, exec),
        Kind::Cvta { to_generic, space, d, a } => memory::cvta(ctx, w, cta, *to_generic, *space, *d, *a, exec),
        Kind::Ld { space, ty, ds, addr, nc, .. } => {
            memory::load(ctx, w, cta, (func, pc), *space, *ty, ds, addr, *nc, exec)?
        }
        Kind::St { space, ty, vals, addr, .. } => {
            memory::store(ctx, w, cta, (func, pc), *space, *ty, vals, addr, exec)?
        }
        Kind::Atom { space, op, ty, d, addr, b, c } => {
            return atomic::atomic(ctx, w, cta, (func, pc), *space, *op, *ty, *d, addr, *b, *c, exec);
        }
        Kind::Bar { id, count } => return control::bar(ctx, w, cta, *id, *count, exec),
        Kind::Vote { mode, d, p, a, membermask } => {
            control::member_mask(ctx, w, cta, *membermask, exec)?;
            for members in control::member_groups(ctx, w, cta, *membermask, exec)? {
                arith::vote(w, *mode, *d, *p, *a, members)
            }
        }
        Kind::Shfl { mode, d, p, a, b, c, membermask } => {
            control::member_mask(ctx, w, cta, *membermask, exec)?;
            control::member_groups(ctx, w, cta, *membermask, exec)?;
            arith::shfl(ctx, w, cta, *mode, *d, *p, [*a, *b, *c], exec)
        }
        Kind::BarRed { op, d, p, id, count, a } => {
            let bits = pred_bits(w.frame(), *a) & exec;
            w.bar_red = Some(BarRedWait { op: *op, lanes: exec, bits, d: *d, p: *p });
            return control::bar(ctx, w, cta, *id, *count, exec);
        }
        Kind::Redux { op, ty, d, a, membermask } => {
            control::member_mask(ctx, w, cta, *membermask, exec)?;
            for members in control::member_groups(ctx, w, cta, *membermask, exec)? {
                arith::redux(ctx, w, cta, *op, *ty, *d, *a, members)
            }
        }
        Kind::Match { all, ty, d, p, a, membermask } => {
            control::member_mask(ctx, w, cta, *membermask, exec)?;
            for members in control::member_groups(ctx, w, cta, *membermask, exec)? {
                arith::match_sync(ctx, w, cta, *all, *ty, *d, *p, *a, members)
            }
        }
        Kind::Carry { op, cin, cout, ty, d, a, b, c, cc } => {
            arith::carry(ctx, w, cta, (*op, *cin, *cout, *ty), *d, [*a, *b, *c], *cc, exec)
        }
        Kind::Tex { geom, gather, cty, ds, handle, coords, .. } => {
            texture::tex(ctx, w, cta, (func, pc), *geom, *gather, *cty, ds, *handle, coords, exec)?
        }
        Kind::Txq { query, d, handle } => texture::txq(ctx, w, cta, *query, *d, *handle, exec)?,
        Kind::Suld { geom, ty, ds, handle, coords, clamp } => {
            texture::suld(ctx, w, cta, (func, pc), *geom, *ty, ds, *handle, coords, *clamp, exec)?
        }
        Kind::Sust { geom, ty, vals, handle, coords, clamp, red } => {
            texture::sust(ctx, w, cta, (func, pc), (*geom, *ty, *red), vals, *handle, coords, *clamp, exec)?
        }
        Kind::WarpSync { membermask } => control::warp_sync(ctx, w, cta, *membermask, exec)?,
        Kind::Membar => return Ok(control::membar(w, cta)),
        Kind::Nop => {}
        Kind::Trap => return Err(fault(FaultKind::Trap, lane_of_mask(exec))),
        Kind::Bra { .. } | Kind::Exit | Kind::Ret | Kind::Call { .. } | Kind::CallIndirect { .. } => {
            unreachable!("handled above")
        }
    }
    Ok(Effect::Continue)
}

#[cfg(test)]
mod tests {
    use super::{Lanes, RowWord, store_row};

    /// `store_row` writes `v & width` into exactly the lanes `exec` names
    /// and leaves the others, whether it goes lane by lane (few lanes), by
    /// the branch-free select (many) or writes the whole row (all 32).
    #[test]
    fn store_row_writes_exactly_the_named_lanes() {
        let v: Lanes = std::array::from_fn(|l| 0x1234_5678_9ABC_DEF0u64.rotate_left(l as u32) | 1);
        let old: Lanes = std::array::from_fn(|l| 0xF00D_0000_0000_0000 + l as u64);
        let mut x = 0x9E37_79B9u32;
        let mut masks = vec![0u32, 1, 1 << 31, u32::MAX, u32::MAX >> 1, 0x5555_5555, 0xFFFF, 0xFFFF_0000];
        for _ in 0..200 {
            // masks of every density around the threshold
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            masks.push(x & x.rotate_left(7) | (x >> (x % 29)));
            masks.push(x);
        }
        let mut counts = [0usize; 33];
        for &exec in &masks {
            counts[exec.count_ones() as usize] += 1;
            for width in [u64::MAX, 0xFFFF_FFFF, 0xFFFF, 1] {
                let mut row = old;
                store_row(&mut row, width, &v, exec);
                for l in 0..32 {
                    let want = if exec >> l & 1 != 0 { v[l] & width } else { old[l] };
                    assert_eq!(row[l], want, "exec {exec:#x}, width {width:#x}, lane {l}");
                }
            }
        }
        // narrow rows: the same lanes, of the values truncated
        for &exec in &masks {
            let old32: [u32; 32] = std::array::from_fn(|l| old[l] as u32);
            for width in [0xFFFF_FFFFu32, 0xFFFF, 0xFF] {
                let (mut row, mut row_of_narrow) = (old32, old32);
                let v32: [u32; 32] = std::array::from_fn(|l| v[l] as u32);
                store_row(&mut row, width, &v, exec);
                store_row(&mut row_of_narrow, width, &v32, exec);
                for l in 0..32 {
                    let want = if exec >> l & 1 != 0 { v[l] as u32 & width } else { old32[l] };
                    assert_eq!((row[l], row_of_narrow[l]), (want, want), "exec {exec:#x}, width {width:#x}, lane {l}");
                }
            }
        }
        // both sides of the lane-by-lane threshold were exercised
        for n in [<u64 as RowWord>::SPARSE_LANES as usize, <u32 as RowWord>::SPARSE_LANES as usize] {
            assert!(
                counts[1..=n].iter().sum::<usize>() > 20 && counts[n + 1..32].iter().sum::<usize>() > 20,
                "{counts:?}"
            );
        }
    }
}
