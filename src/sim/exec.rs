//! Executes one warp instruction: fetch from the SIMT stack's top path,
//! evaluate the guard, apply the instruction to the active lanes (registers as
//! 32-lane arrays), move the PC or the stack, and count.

use super::alu;
use super::cfg::{Cfg, EXIT_PC};
use super::counters::{Counters, InstProfile};
use super::fault::FaultKind;
use super::memory::{
    CONST_WINDOW, DeviceMemory, GenericTarget, LOCAL_WINDOW, PARAM_WINDOW, SHARED_WINDOW, decode_generic,
};
use super::observer::{MemEvent, MemObserver, MemOp, ObserverFactory};
use super::simt_stack::{BranchOutcome, SimtEntry};
use super::warp::{Frame, Warp, WarpState};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

/// Everything an instruction may read that is shared by all CTAs of a launch.
pub struct Ctx<'a> {
    /// The program.
    pub prog: &'a Program,
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

/// A warp's global atomic operations, applied in order when the round ends.
#[derive(Debug, Clone)]
pub struct PendingAtomic {
    /// Issuing warp.
    pub warp: u32,
    /// Operation.
    pub op: AtomOp,
    /// Type.
    pub ty: Ty,
    /// Destination register (in the warp's current frame).
    pub d: Option<Dst>,
    /// (lane, address, b, c) in lane order.
    pub lanes: Vec<(u8, u64, u64, u64)>,
}

/// A fault raised by an instruction (the caller adds where).
#[derive(Debug, Clone)]
pub struct ExecFault {
    /// What happened.
    pub kind: FaultKind,
    /// The first faulting lane, if per lane.
    pub lane: Option<u32>,
}

fn fault(kind: FaultKind, lane: Option<usize>) -> ExecFault {
    ExecFault { kind, lane: lane.map(|l| l as u32) }
}

/// What the executed instruction did to the warp's schedulability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    /// The warp can continue.
    Continue,
    /// The warp blocked (barrier, atomic) or finished.
    Blocked,
}

type Lanes = [u64; 32];

#[inline(always)]
fn map1(a: &Lanes, f: impl Fn(u64) -> u64) -> Lanes {
    std::array::from_fn(|l| f(a[l]))
}

#[inline(always)]
fn map2(a: &Lanes, b: &Lanes, f: impl Fn(u64, u64) -> u64) -> Lanes {
    std::array::from_fn(|l| f(a[l], b[l]))
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
    let r = &mut frame.regs[d.reg as usize];
    if mask == u32::MAX {
        for l in 0..32 {
            r[l] = v[l] & d.mask;
        }
    } else {
        for l in 0..32 {
            if mask >> l & 1 != 0 {
                r[l] = v[l] & d.mask;
            }
        }
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
        Src::Reg(r) => f.regs[r as usize],
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
        Src::Reg(r) => Operand::Reg(&w.frame().regs[r as usize]),
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
    }
}

/// A memory space as resolved for one lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Resolved {
    Global(u64),
    Shared(u64),
    Local(u64),
    Const(u64),
    KParam(u64),
    FParam(u64),
}

impl Resolved {
    fn space(self) -> MemSpace {
        match self {
            Resolved::Global(_) => MemSpace::Global,
            Resolved::Shared(_) => MemSpace::Shared,
            Resolved::Local(_) => MemSpace::Local,
            Resolved::Const(_) => MemSpace::Const,
            Resolved::KParam(_) => MemSpace::KernelParam,
            Resolved::FParam(_) => MemSpace::FrameParam,
        }
    }
    fn addr(self) -> u64 {
        match self {
            Resolved::Global(a)
            | Resolved::Shared(a)
            | Resolved::Local(a)
            | Resolved::Const(a)
            | Resolved::KParam(a)
            | Resolved::FParam(a) => a,
        }
    }
}

#[inline]
fn resolve(space: MemSpace, addr: u64) -> Resolved {
    match space {
        MemSpace::Global => Resolved::Global(addr),
        MemSpace::Shared => Resolved::Shared(addr),
        MemSpace::Local => Resolved::Local(addr),
        MemSpace::Const => Resolved::Const(addr),
        MemSpace::KernelParam => Resolved::KParam(addr),
        MemSpace::FrameParam => Resolved::FParam(addr),
        MemSpace::Generic => match decode_generic(addr) {
            GenericTarget::Global(a) => Resolved::Global(a),
            GenericTarget::Shared(a) => Resolved::Shared(a),
            GenericTarget::Local(a) => Resolved::Local(a),
            GenericTarget::Const(a) => Resolved::Const(a),
            GenericTarget::Param(a) => Resolved::KParam(a),
        },
    }
}

fn bytes_load(buf: &[u8], off: u64, size: u32) -> Option<u64> {
    let o = off as usize;
    let s = buf.get(o..o.checked_add(size as usize)?)?;
    let mut b = [0u8; 8];
    b[..size as usize].copy_from_slice(s);
    Some(u64::from_le_bytes(b))
}

fn bytes_store(buf: &mut [u8], off: u64, size: u32, v: u64) -> Option<()> {
    let o = off as usize;
    let s = buf.get_mut(o..o.checked_add(size as usize)?)?;
    s.copy_from_slice(&v.to_le_bytes()[..size as usize]);
    Some(())
}

/// One lane's access. `store = Some(v)` writes; returns the loaded value otherwise.
#[allow(clippy::too_many_arguments)]
#[inline]
fn access(
    ctx: &Ctx,
    w: &mut Warp,
    shared: &mut [u8],
    r: Resolved,
    lane: usize,
    size: u32,
    align: u32,
    store: Option<u64>,
) -> Result<u64, ExecFault> {
    let a = r.addr();
    let oob = || fault(FaultKind::OutOfBounds { space: r.space(), addr: a, size }, Some(lane));
    if !a.is_multiple_of(align as u64) {
        return Err(fault(FaultKind::Misaligned { space: r.space(), addr: a, size: align }, Some(lane)));
    }
    match r {
        Resolved::Global(addr) => {
            let (al, off) = ctx.mem.find(addr, size as u64).ok_or_else(oob)?;
            Ok(match store {
                Some(v) => {
                    al.store(off, size, v);
                    0
                }
                None => al.load(off, size),
            })
        }
        Resolved::Shared(off) => match store {
            Some(v) => bytes_store(shared, off, size, v).map(|_| 0).ok_or_else(oob),
            None => bytes_load(shared, off, size).ok_or_else(oob),
        },
        Resolved::Local(off) => {
            if off.checked_add(size as u64).is_none_or(|e| e > w.local_top as u64) {
                return Err(oob());
            }
            Ok(match store {
                Some(v) => {
                    w.local_store(lane, off, size, v);
                    0
                }
                None => w.local_load(lane, off, size),
            })
        }
        Resolved::Const(off) => match store {
            Some(_) => Err(fault(FaultKind::ReadOnly { space: MemSpace::Const }, Some(lane))),
            None => bytes_load(&ctx.prog.const_bank, off, size).ok_or_else(oob),
        },
        Resolved::KParam(off) => match store {
            Some(_) => Err(fault(FaultKind::ReadOnly { space: MemSpace::KernelParam }, Some(lane))),
            None => bytes_load(&ctx.kparams, off, size).ok_or_else(oob),
        },
        Resolved::FParam(off) => {
            let f = w.frames.last_mut().expect("frame");
            let ps = f.param_size as u64;
            if off.checked_add(size as u64).is_none_or(|e| e > ps) {
                return Err(oob());
            }
            let base = lane as u64 * ps + off;
            match store {
                Some(v) => bytes_store(&mut f.params, base, size, v).map(|_| 0).ok_or_else(oob),
                None => bytes_load(&f.params, base, size).ok_or_else(oob),
            }
        }
    }
}

/// Per-lane resolved accesses of one instruction, for observers.
struct Touched {
    space: [Option<MemSpace>; 32],
    addr: [u64; 32],
}

impl Touched {
    fn new() -> Self {
        Touched { space: [None; 32], addr: [0; 32] }
    }
    fn set(&mut self, lane: usize, r: Resolved) {
        self.space[lane] = Some(r.space());
        self.addr[lane] = r.addr();
    }
}

/// Sends one event per space the lanes touched.
#[allow(clippy::too_many_arguments)]
fn emit(cta: &mut CtaMut, w: &Warp, func: u32, pc: u32, op: MemOp, nc: bool, elem: u32, n: u32, t: &Touched) {
    let (cta_linear, warp) = (cta.cta_linear, w.id);
    let Some(obs) = cta.observer.as_deref_mut() else { return };
    let mut done = 0u32;
    for l in 0..32 {
        let Some(space) = t.space[l] else { continue };
        if done >> l & 1 != 0 {
            continue;
        }
        let mask = (0..32).filter(|&k| t.space[k] == Some(space)).fold(0u32, |m, k| m | 1 << k);
        done |= mask;
        obs.access(&MemEvent {
            func,
            pc,
            op,
            space,
            nc,
            bytes: elem * n,
            elem_bytes: elem,
            mask,
            addrs: &t.addr,
            cta: cta_linear,
            warp,
        });
    }
}

/// Loads (`store` = None) or stores `n` consecutive elements of `ty` for every
/// active lane. Returns the loaded values, the first lane's resolved space (for
/// counting) and what every lane touched (for observers).
#[allow(clippy::too_many_arguments)]
fn vector_access(
    ctx: &Ctx,
    w: &mut Warp,
    shared: &mut [u8],
    space: MemSpace,
    ty: Ty,
    n: u32,
    addrs: &Lanes,
    exec: u32,
    store: Option<&[Lanes; 4]>,
) -> Result<([Lanes; 4], Option<Resolved>, Touched), ExecFault> {
    let size = ty.bytes();
    let mut vals = [[0u64; 32]; 4];
    let mut first = None;
    let mut touched = Touched::new();
    for l in 0..32 {
        if exec >> l & 1 == 0 {
            continue;
        }
        let r = resolve(space, addrs[l]);
        first.get_or_insert(r);
        touched.set(l, r);
        check_vector_align(r, l, size * n)?;
        for k in 0..n as usize {
            let rk = resolve(space, addrs[l].wrapping_add((k as u32 * size) as u64));
            match store {
                None => vals[k][l] = ty.extend(access(ctx, w, shared, rk, l, size, size, None)?),
                Some(v) => {
                    access(ctx, w, shared, rk, l, size, size, Some(v[k][l] & ty.mask()))?;
                }
            }
        }
    }
    Ok((vals, first, touched))
}

/// Vector accesses must be aligned to their whole size.
fn check_vector_align(r: Resolved, lane: usize, total: u32) -> Result<(), ExecFault> {
    if !r.addr().is_multiple_of(total as u64) {
        return Err(fault(FaultKind::Misaligned { space: r.space(), addr: r.addr(), size: total }, Some(lane)));
    }
    Ok(())
}

fn count_space(c: &mut super::counters::SpaceCounts, r: Resolved) {
    match r {
        Resolved::Global(_) => c.global += 1,
        Resolved::Shared(_) => c.shared += 1,
        Resolved::Local(_) => c.local += 1,
        Resolved::Const(_) => c.constant += 1,
        Resolved::KParam(_) | Resolved::FParam(_) => c.param += 1,
    }
}

fn addresses(ctx: &Ctx, w: &Warp, cta: &CtaMut, a: &Address) -> Lanes {
    let base = operand(ctx, w, cta, a.base);
    if a.wide {
        map1(&base, |b| b.wrapping_add(a.offset as u64))
    } else {
        map1(&base, |b| (b as u32).wrapping_add(a.offset as u32) as u64)
    }
}

/// Executes the next instruction of warp `w`. Returns its function and PC (for
/// fault reports and stepping) and its effect.
pub fn step(ctx: &Ctx, w: &mut Warp, cta: &mut CtaMut) -> (u32, u32, Result<Effect, ExecFault>) {
    let base = w.frame().stack_base;
    cta.counters.reconvergences += w.stack.reconverge(base) as u64;
    let top = *w.stack.top().expect("running warp has a path");
    let func = w.frame().func;
    let pc = top.pc;
    let r = exec(ctx, w, cta, func, top);
    // Pop paths that reached their reconvergence point now, so that the stack
    // seen between instructions is the one the next instruction runs on.
    if !w.stack.entries.is_empty() {
        let base = w.frame().stack_base;
        cta.counters.reconvergences += w.stack.reconverge(base) as u64;
    }
    (func, pc, r)
}

fn exec(ctx: &Ctx, w: &mut Warp, cta: &mut CtaMut, func: u32, top: SimtEntry) -> Result<Effect, ExecFault> {
    let f = &ctx.prog.functions[func as usize];
    let pc = top.pc;
    let Some(inst) = f.insts.get(pc as usize) else {
        return Err(fault(FaultKind::Unsupported(format!("execution ran past the end of `{}`", f.name)), None));
    };
    let mask = top.mask;
    let exec = match inst.guard {
        None => mask,
        Some(p) => mask & pred_bits(w.frame(), p),
    };
    // counting
    let c = &mut *cta.counters;
    c.warp_instructions += 1;
    c.thread_instructions += mask.count_ones() as u64;
    c.thread_instructions_pred_on += exec.count_ones() as u64;
    c.by_class.add(f.info[pc as usize].class);
    let ic = &mut cta.profile.per_fn[func as usize][pc as usize];
    ic.warp += 1;
    ic.thread += mask.count_ones() as u64;
    ic.pred_on += exec.count_ones() as u64;

    let advance = |w: &mut Warp| {
        w.stack.top_mut().expect("top").pc = pc + 1;
    };

    match &inst.kind {
        Kind::Bra { target, .. } => {
            cta.counters.branches += 1;
            let rpc = ctx.cfgs[func as usize].reconv[pc as usize];
            if w.stack.branch(exec, *target, pc + 1, rpc) == BranchOutcome::Diverged {
                cta.counters.divergent_branches += 1;
                cta.profile.per_fn[func as usize][pc as usize].divergent += 1;
            }
            return Ok(Effect::Continue);
        }
        // `ret` in the kernel's own frame (no caller to return to) ends the
        // thread, as `exit` does; the front end already lowers a kernel's
        // `ret` to `exit`, this covers hand-built programs.
        Kind::Exit | Kind::Ret if matches!(inst.kind, Kind::Exit) || w.frames.len() == 1 => {
            advance(w);
            if exec == 0 {
                return Ok(Effect::Continue);
            }
            w.live &= !exec;
            w.stack.retire_lanes(0, exec);
            pop_empty_frames(ctx, w);
            if w.stack.entries.is_empty() {
                w.state = WarpState::Done;
                return Ok(Effect::Blocked);
            }
            return Ok(Effect::Continue);
        }
        Kind::Ret => {
            advance(w);
            if exec == 0 {
                return Ok(Effect::Continue);
            }
            let fr = w.frames.last_mut().expect("frame");
            fr.returned |= exec;
            let base = fr.stack_base;
            if w.stack.retire_lanes(base, exec) {
                return_from_call(ctx, w);
            }
            if w.stack.entries.is_empty() {
                w.state = WarpState::Done;
                return Ok(Effect::Blocked);
            }
            return Ok(Effect::Continue);
        }
        Kind::Call { func: callee, args, rets: _ } => {
            advance(w);
            if exec == 0 {
                return Ok(Effect::Continue);
            }
            cta.counters.calls += 1;
            let cf = &ctx.prog.functions[*callee as usize];
            // Device-function frames on the stack after this call (the kernel's is not one).
            let depth = w.frames.len() as u64;
            if depth > ctx.max_call_depth as u64 {
                let names = w.frames.iter().map(|fr| ctx.prog.functions[fr.func as usize].name.as_str());
                return Err(fault(
                    FaultKind::CallDepth {
                        limit: ctx.max_call_depth,
                        callee: cf.name.clone(),
                        chain: call_chain(names),
                    },
                    lane_of_mask(exec),
                ));
            }
            let caller = w.frame();
            let caller_fn = &ctx.prog.functions[caller.func as usize];
            let lb = (caller.local_base + caller_fn.local_size).div_ceil(cf.local_align) * cf.local_align;
            let need = lb as u64 + cf.local_size as u64;
            if need > ctx.local_limit as u64 {
                return Err(fault(FaultKind::LocalStackOverflow { needed: need, limit: ctx.local_limit as u64 }, None));
            }
            let (caller_func, caller_ps) = (caller.func, caller.param_size);
            let mut nf = w.take_frame(*callee, cf, lb, w.stack.entries.len(), pc);
            let caller = w.frames.last().expect("caller");
            debug_assert_eq!(caller.func, caller_func);
            let ps_c = caller_ps as usize;
            let ps_n = nf.param_size as usize;
            for l in 0..32 {
                if exec >> l & 1 == 0 {
                    continue;
                }
                for &(src, dst, size) in args {
                    let (s, d, n) = (src as usize, dst as usize, size as usize);
                    nf.params[l * ps_n + d..l * ps_n + d + n]
                        .copy_from_slice(&caller.params[l * ps_c + s..l * ps_c + s + n]);
                }
            }
            w.ensure_local(need as u32);
            w.local_top = need as u32;
            w.stack.push(SimtEntry { pc: 0, rpc: EXIT_PC, mask: exec });
            w.frames.push(nf);
            return Ok(Effect::Continue);
        }
        _ => {}
    }

    advance(w);
    if exec == 0 {
        // Predicated off for every lane: issued, no effect.
        return Ok(Effect::Continue);
    }

    match &inst.kind {
        Kind::Mov { d, a } => {
            let v = read(ctx, w, cta, *a);
            write(w.frames.last_mut().expect("frame"), *d, &v, exec);
        }
        Kind::Pack { d, parts, part_bits } => {
            let mut acc = [0u64; 32];
            let pm = (1u64 << part_bits) - 1;
            for (k, p) in parts.iter().enumerate() {
                let v = read(ctx, w, cta, *p);
                for l in 0..32 {
                    acc[l] |= (v[l] & pm) << (k as u32 * part_bits);
                }
            }
            write(w.frames.last_mut().expect("frame"), *d, &acc, exec);
        }
        Kind::Unpack { ds, a, part_bits } => {
            let v = read(ctx, w, cta, *a);
            let pm = (1u64 << part_bits) - 1;
            let fr = w.frames.last_mut().expect("frame");
            for (k, d) in ds.iter().enumerate() {
                let part = map1(&v, |x| (x >> (k as u32 * part_bits)) & pm);
                write(fr, *d, &part, exec);
            }
        }
        Kind::Arith { op, ty, mode, d, a, b, c } => {
            let (va, vb) = (operand(ctx, w, cta, *a), operand(ctx, w, cta, *b));
            let r = arith_lanes(*op, *ty, *mode, &va, &vb, || read(ctx, w, cta, *c));
            write(w.frames.last_mut().expect("frame"), *d, &r, exec);
        }
        Kind::Bfi { ty, d, a, b, c, e } => {
            let (va, vb, vc, ve) =
                (read(ctx, w, cta, *a), read(ctx, w, cta, *b), read(ctx, w, cta, *c), read(ctx, w, cta, *e));
            let r: Lanes = std::array::from_fn(|l| alu::bfi(*ty, va[l], vb[l], vc[l], ve[l]));
            write(w.frames.last_mut().expect("frame"), *d, &r, exec);
        }
        Kind::Setp { cmp, ty, p, q, a, b, comb, ftz } => {
            let (va, vb) = (operand(ctx, w, cta, *a), operand(ctx, w, cta, *b));
            let t = alu::compare_lanes(*cmp, *ty, *ftz, &va, &vb);
            let fr = w.frames.last_mut().expect("frame");
            let (pv, qv) = match comb {
                Some((op, c)) => {
                    let cv = pred_bits(fr, *c);
                    (combine(*op, t, cv), combine(*op, !t, cv))
                }
                None => (t, !t),
            };
            set_pred(fr, *p, pv, exec);
            if let Some(q) = q {
                set_pred(fr, *q, qv, exec);
            }
        }
        Kind::Set { cmp, dty, sty, d, a, b, comb, ftz } => {
            let (va, vb) = (read(ctx, w, cta, *a), read(ctx, w, cta, *b));
            let fr = w.frames.last_mut().expect("frame");
            let cv = comb.map(|(op, c)| (op, pred_bits(fr, c)));
            let one = match dty {
                Ty::F32 => 1.0f32.to_bits() as u64,
                Ty::F64 => 1.0f64.to_bits(),
                t => t.mask(),
            };
            let r: Lanes = std::array::from_fn(|l| {
                let mut t = alu::compare(*cmp, *sty, *ftz, va[l], vb[l]);
                if let Some((op, c)) = cv {
                    t = combine(op, t as u32, c >> l & 1) & 1 != 0;
                }
                if t { one } else { 0 }
            });
            write(fr, *d, &r, exec);
        }
        Kind::Selp { d, a, b, p } => {
            let (va, vb) = (operand(ctx, w, cta, *a), operand(ctx, w, cta, *b));
            let pv = pred_bits(w.frame(), *p);
            let r: Lanes = std::array::from_fn(|l| if pv >> l & 1 != 0 { va[l] } else { vb[l] });
            write(w.frames.last_mut().expect("frame"), *d, &r, exec);
        }
        Kind::PredLogic { op, d, a, b } => {
            let fr = w.frames.last_mut().expect("frame");
            let av = pred_bits(fr, *a);
            let v = match op {
                None => av,
                Some(o) => combine(*o, av, pred_bits(fr, *b)),
            };
            set_pred(fr, *d, v, exec);
        }
        Kind::Cvt { dty, sty, mode, d, a } => {
            let va = read(ctx, w, cta, *a);
            // A destination register wider than the type gets the value sign- or zero-extended.
            let r = map1(&va, |x| dty.extend(alu::cvt(*dty, *sty, *mode, x)));
            write(w.frames.last_mut().expect("frame"), *d, &r, exec);
        }
        Kind::Cvta { to_generic, space, d, a } => {
            let va = read(ctx, w, cta, *a);
            let win = match space {
                MemSpace::Shared => SHARED_WINDOW,
                MemSpace::Local => LOCAL_WINDOW,
                MemSpace::Const => CONST_WINDOW,
                MemSpace::KernelParam => PARAM_WINDOW,
                _ => 0,
            };
            let r = if *to_generic { map1(&va, |x| x.wrapping_add(win)) } else { map1(&va, |x| x.wrapping_sub(win)) };
            write(w.frames.last_mut().expect("frame"), *d, &r, exec);
        }
        Kind::Ld { space, ty, ds, addr, nc, .. } => {
            let addrs = addresses(ctx, w, cta, addr);
            let n = ds.len() as u32;
            let (vals, first, touched) = vector_access(ctx, w, cta.shared, *space, *ty, n, &addrs, exec, None)?;
            if let Some(r) = first {
                count_space(&mut cta.counters.loads, r);
            }
            emit(cta, w, func, pc, MemOp::Load, *nc, ty.bytes(), n, &touched);
            let fr = w.frames.last_mut().expect("frame");
            for (k, d) in ds.iter().enumerate() {
                write(fr, *d, &vals[k], exec);
            }
        }
        Kind::St { space, ty, vals, addr, .. } => {
            let addrs = addresses(ctx, w, cta, addr);
            let n = vals.len() as u32;
            let mut vs = [[0u64; 32]; 4];
            for (k, v) in vals.iter().enumerate() {
                vs[k] = read(ctx, w, cta, *v);
            }
            let (_, first, touched) = vector_access(ctx, w, cta.shared, *space, *ty, n, &addrs, exec, Some(&vs))?;
            if let Some(r) = first {
                count_space(&mut cta.counters.stores, r);
            }
            emit(cta, w, func, pc, MemOp::Store, false, ty.bytes(), n, &touched);
        }
        Kind::Atom { space, op, ty, d, addr, b, c } => {
            return atomic(ctx, w, cta, (func, pc), *space, *op, *ty, *d, addr, *b, *c, exec);
        }
        Kind::Bar { id, count } => {
            if exec != w.live {
                return Err(fault(FaultKind::DivergentBarrier { active: exec, live: w.live }, None));
            }
            let idv = read(ctx, w, cta, *id)[lane_of_mask(exec).unwrap_or(0)] as u32;
            let cnt = count.map(|c| read(ctx, w, cta, c)[lane_of_mask(exec).unwrap_or(0)] as u32);
            cta.counters.barrier_warp_arrivals += 1;
            w.state = WarpState::Barrier { id: idv, count: cnt };
            return Ok(Effect::Blocked);
        }
        Kind::Vote { mode, d, p, a, .. } => {
            let fr = w.frames.last_mut().expect("frame");
            let pv = pred_bits(fr, *a) & exec;
            match mode {
                VoteMode::Ballot => {
                    if let Some(d) = d {
                        write(fr, *d, &[pv as u64; 32], exec);
                    }
                }
                VoteMode::All => set_pred(fr, *p, if pv == exec { u32::MAX } else { 0 }, exec),
                VoteMode::Any => set_pred(fr, *p, if pv != 0 { u32::MAX } else { 0 }, exec),
                VoteMode::Uni => set_pred(fr, *p, if pv == 0 || pv == exec { u32::MAX } else { 0 }, exec),
            }
        }
        Kind::Shfl { mode, d, p, a, b, c, .. } => {
            let (va, vb, vc) = (read(ctx, w, cta, *a), read(ctx, w, cta, *b), read(ctx, w, cta, *c));
            let mut r = [0u64; 32];
            let mut pv = 0u32;
            for lane in 0..32u32 {
                let bval = (vb[lane as usize] & 0x1F) as u32;
                let cval = (vc[lane as usize] & 0x1F) as u32;
                let segmask = ((vc[lane as usize] >> 8) & 0x1F) as u32;
                let max_lane = (lane & segmask) | (cval & !segmask);
                let min_lane = lane & segmask;
                let (j, ok) = match mode {
                    ShflMode::Up => {
                        let j = lane as i32 - bval as i32;
                        (j, j >= max_lane as i32)
                    }
                    ShflMode::Down => {
                        let j = (lane + bval) as i32;
                        (j, j <= max_lane as i32)
                    }
                    ShflMode::Bfly => {
                        let j = (lane ^ bval) as i32;
                        (j, j <= max_lane as i32)
                    }
                    ShflMode::Idx => {
                        let j = (min_lane | (bval & !segmask)) as i32;
                        (j, j <= max_lane as i32)
                    }
                };
                let src = if ok { j as usize } else { lane as usize };
                r[lane as usize] = va[src & 31];
                if ok {
                    pv |= 1 << lane;
                }
            }
            let fr = w.frames.last_mut().expect("frame");
            write(fr, *d, &r, exec);
            if let Some(p) = p {
                set_pred(fr, *p, pv, exec);
            }
        }
        Kind::Membar => {
            if !cta.pending.is_empty() {
                // A fence waits for this CTA's outstanding global atomics.
                w.state = WarpState::WaitAtomic;
                return Ok(Effect::Blocked);
            }
        }
        Kind::Nop => {}
        Kind::Trap => return Err(fault(FaultKind::Trap, lane_of_mask(exec))),
        Kind::Bra { .. } | Kind::Exit | Kind::Ret | Kind::Call { .. } => {
            unreachable!("handled above")
        }
    }
    Ok(Effect::Continue)
}

/// Evaluates an arithmetic instruction over 32 lanes, with fast paths for the
/// hottest integer and f32 forms.
#[inline]
fn arith_lanes(op: ArithOp, ty: Ty, mode: FloatMode, a: &Lanes, b: &Lanes, c: impl FnOnce() -> Lanes) -> Lanes {
    let plain = mode == FloatMode::default();
    match (op, ty) {
        (ArithOp::Add, Ty::S32 | Ty::U32 | Ty::B32) if plain => {
            map2(a, b, |x, y| (x as u32).wrapping_add(y as u32) as u64)
        }
        (ArithOp::Add, Ty::S64 | Ty::U64 | Ty::B64) if plain => map2(a, b, |x, y| x.wrapping_add(y)),
        (ArithOp::Sub, Ty::S32 | Ty::U32 | Ty::B32) if plain => {
            map2(a, b, |x, y| (x as u32).wrapping_sub(y as u32) as u64)
        }
        (ArithOp::Mul, Ty::S32 | Ty::U32 | Ty::B32) => map2(a, b, |x, y| (x as u32).wrapping_mul(y as u32) as u64),
        (ArithOp::And, _) => map2(a, b, |x, y| x & y),
        (ArithOp::Or, _) => map2(a, b, |x, y| x | y),
        (ArithOp::Xor, _) => map2(a, b, |x, y| x ^ y),
        (ArithOp::Shl, Ty::B32 | Ty::U32 | Ty::S32) => {
            map2(a, b, |x, s| if (s as u32) >= 32 { 0 } else { ((x as u32) << s) as u64 })
        }
        (ArithOp::Shr, Ty::B32 | Ty::U32) => {
            map2(a, b, |x, s| if (s as u32) >= 32 { 0 } else { ((x as u32) >> s) as u64 })
        }
        (ArithOp::MulWide, Ty::S32) => map2(a, b, |x, y| ((x as i32 as i64) * (y as i32 as i64)) as u64),
        (ArithOp::MulWide, Ty::U32) => map2(a, b, |x, y| (x & 0xFFFF_FFFF) * (y & 0xFFFF_FFFF)),
        (ArithOp::Mad, Ty::S32 | Ty::U32 | Ty::B32) => {
            let c = c();
            map3(a, b, &c, |x, y, z| (x as u32).wrapping_mul(y as u32).wrapping_add(z as u32) as u64)
        }
        (ArithOp::Add, Ty::F32) if plain => {
            map2(a, b, |x, y| canon32(f32::from_bits(x as u32) + f32::from_bits(y as u32)))
        }
        (ArithOp::Mul, Ty::F32) if plain => {
            map2(a, b, |x, y| canon32(f32::from_bits(x as u32) * f32::from_bits(y as u32)))
        }
        (ArithOp::Mad, Ty::F32) if plain || mode == (FloatMode { rnd: Some(Rounding::Rn), ..FloatMode::default() }) => {
            let c = c();
            map3(a, b, &c, |x, y, z| {
                canon32(f32::from_bits(x as u32).mul_add(f32::from_bits(y as u32), f32::from_bits(z as u32)))
            })
        }
        _ => {
            let c = if matches!(
                op,
                ArithOp::Mad
                    | ArithOp::MadHi
                    | ArithOp::MadWide
                    | ArithOp::Mad24Lo
                    | ArithOp::Mad24Hi
                    | ArithOp::Bfe
                    | ArithOp::Prmt
                    | ArithOp::ShfLWrap
                    | ArithOp::ShfLClamp
                    | ArithOp::ShfRWrap
                    | ArithOp::ShfRClamp
            ) {
                c()
            } else {
                [0; 32]
            };
            map3(a, b, &c, |x, y, z| alu::arith(op, ty, mode, x, y, z))
        }
    }
}

#[inline(always)]
fn canon32(x: f32) -> u64 {
    if x.is_nan() { alu::NAN32 as u64 } else { x.to_bits() as u64 }
}

#[allow(clippy::too_many_arguments)]
fn atomic(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    (func, pc): (u32, u32),
    space: MemSpace,
    op: AtomOp,
    ty: Ty,
    d: Option<Dst>,
    addr: &Address,
    b: Src,
    c: Src,
    exec: u32,
) -> Result<Effect, ExecFault> {
    let addrs = addresses(ctx, w, cta, addr);
    let (vb, vc) = (read(ctx, w, cta, b), read(ctx, w, cta, c));
    let size = ty.bytes();
    let mut old = [0u64; 32];
    let mut global = Vec::new();
    let mut first = None;
    let mut touched = Touched::new();
    for l in 0..32 {
        if exec >> l & 1 == 0 {
            continue;
        }
        let r = resolve(space, addrs[l]);
        first.get_or_insert(r);
        touched.set(l, r);
        cta.counters.atomic_lane_ops += 1;
        match r {
            Resolved::Shared(_) => {
                let o = access(ctx, w, cta.shared, r, l, size, size, None)?;
                let n = alu::atom(op, ty, o, vb[l], vc[l]);
                access(ctx, w, cta.shared, r, l, size, size, Some(n))?;
                old[l] = o;
            }
            Resolved::Global(a) => {
                // Check now so the fault names this instruction; apply at the round's end.
                if a % size as u64 != 0 {
                    return Err(fault(FaultKind::Misaligned { space: MemSpace::Global, addr: a, size }, Some(l)));
                }
                if ctx.mem.find(a, size as u64).is_none() {
                    return Err(fault(FaultKind::OutOfBounds { space: MemSpace::Global, addr: a, size }, Some(l)));
                }
                global.push((l as u8, a, vb[l], vc[l]));
            }
            other => {
                return Err(fault(FaultKind::Unsupported(format!("atomic on the {:?} space", other.space())), Some(l)));
            }
        }
    }
    if let Some(r) = first {
        count_space(&mut cta.counters.atomics, r);
    }
    let mop = if d.is_some() { MemOp::Atomic } else { MemOp::Reduction };
    emit(cta, w, func, pc, mop, false, size, 1, &touched);
    if let Some(d) = d {
        let shared_lanes = exec & !global.iter().fold(0u32, |m, g| m | 1 << g.0);
        write(w.frames.last_mut().expect("frame"), d, &old, shared_lanes);
    }
    if global.is_empty() {
        return Ok(Effect::Continue);
    }
    cta.pending.push(PendingAtomic { warp: w.id, op, ty, d, lanes: global });
    if d.is_some() {
        w.state = WarpState::WaitAtomic;
        return Ok(Effect::Blocked);
    }
    Ok(Effect::Continue)
}

/// Function names of a call stack (outermost first), consecutive repeats
/// counted: `k, f, f, f` becomes `[(k, 1), (f, 3)]`.
pub fn call_chain<'a>(names: impl Iterator<Item = &'a str>) -> Vec<(String, u32)> {
    let mut out: Vec<(String, u32)> = Vec::new();
    for n in names {
        match out.last_mut() {
            Some((last, k)) if last == n => *k += 1,
            _ => out.push((n.to_string(), 1)),
        }
    }
    out
}

/// Pops callee frames whose paths are all gone (their lanes exited).
fn pop_empty_frames(ctx: &Ctx, w: &mut Warp) {
    while w.frames.len() > 1 && w.stack.entries.len() <= w.frame().stack_base {
        let done = w.frames.pop().expect("callee frame");
        w.recycle(done);
        let f = w.frame();
        w.local_top = f.local_base + ctx.prog.functions[f.func as usize].local_size;
    }
}

/// All of a callee's paths returned: copy return values back and pop the frame.
fn return_from_call(ctx: &Ctx, w: &mut Warp) {
    let callee = w.frames.pop().expect("callee frame");
    let caller = w.frames.last_mut().expect("caller frame");
    let Kind::Call { rets, .. } = &ctx.prog.functions[caller.func as usize].insts[callee.call_pc as usize].kind else {
        unreachable!("call_pc names a call");
    };
    let (ps_n, ps_c) = (callee.param_size as usize, caller.param_size as usize);
    for l in 0..32 {
        if callee.returned >> l & 1 == 0 {
            continue;
        }
        for &(src, dst, size) in rets {
            let (s, d, n) = (src as usize, dst as usize, size as usize);
            caller.params[l * ps_c + d..l * ps_c + d + n]
                .copy_from_slice(&callee.params[l * ps_n + s..l * ps_n + s + n]);
        }
    }
    let cf = &ctx.prog.functions[caller.func as usize];
    w.local_top = caller.local_base + cf.local_size;
    w.recycle(callee);
}

/// Applies a CTA's pending global atomics in order and wakes the waiting warps.
pub fn apply_pending(ctx: &Ctx, warps: &mut [Warp], pending: &mut Vec<PendingAtomic>) {
    for p in pending.drain(..) {
        let size = p.ty.bytes();
        let w = &mut warps[p.warp as usize];
        for &(l, a, b, c) in &p.lanes {
            let (al, off) = ctx.mem.find(a, size as u64).expect("checked at issue");
            let old = al.load(off, size);
            al.store(off, size, alu::atom(p.op, p.ty, old, b, c));
            if let Some(d) = p.d
                && d.reg != Dst::SINK
            {
                w.frames.last_mut().expect("frame").regs[d.reg as usize][l as usize] = old & d.mask;
            }
        }
    }
    for w in warps.iter_mut() {
        if w.state == WarpState::WaitAtomic {
            w.state = WarpState::Ready;
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn call_chain_counts_consecutive_repeats() {
        let names = ["k", "f", "f", "g", "f"];
        let c = super::call_chain(names.into_iter());
        let want: Vec<(String, u32)> =
            [("k", 1), ("f", 2), ("g", 1), ("f", 1)].map(|(n, k)| (n.to_string(), k)).to_vec();
        assert_eq!(c, want);
    }
}
