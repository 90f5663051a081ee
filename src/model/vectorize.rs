//! What ptxas makes of a kernel's shared-memory accesses before the GPU counts
//! them (issue 20, items 6, 7 and 11): a static pass over each PTX function
//! that decides, per instruction, how the Maxwell and Hopper counter models
//! count its warp-level accesses. Values are never changed — the simulator
//! executes the PTX as written — only the counts.
//!
//! - **Vectorisation.** Scalar `ld.shared`/`st.shared` of 4 or 8 bytes at
//!   offsets `o, o+e, …` from one base register, in one straight-line run,
//!   under one guard, with the base not redefined in between and the start
//!   provably aligned to the merged width, become one 8- or 16-byte access
//!   (`LDS.64`/`LDS.128`/`STS.64`/`STS.128`): counted once, at the first
//!   member's execution, with the merged width. Loads may be separated by
//!   loads of other spaces and bases and by non-memory instructions; a shared
//!   or generic store, an atomic, a barrier, a fence, a call or a branch ends
//!   the run. Stores must follow one another (non-memory instructions between
//!   are allowed). Greedy from the lowest offset: 16 bytes where the start is
//!   16-byte aligned, else 8 where 8-byte aligned.
//! - **Alignment** comes from a trailing-zero analysis of the registers
//!   (flow-insensitive, every definition of a register considered): shared
//!   variables' offsets, immediates, `shl` by a constant, `mul`/`mad` (zeros
//!   add up), `add`/`sub`/`or` (the fewer), `and` (the more), `neg`, moves
//!   and conversions keep them; anything loaded or special is unaligned. A
//!   64-bit `sub` whose subtracted operand is not a constant (an immediate
//!   or a register only ever set to one), and a 64-bit `neg`, give no
//!   alignment; 32-bit ones keep it (ptxas 13.5: `arr - 64 tid` in 64 bits
//!   is two `LDS`, in 32 bits, or as `arr + (-64 tid)`, one `LDS.64`). A
//!   register stepped round a loop (`add`/`sub %r, %r, k`) is as aligned as
//!   its first value and its step (`kernels/validation/loop_stepped.cu`). A
//!   shared variable is as aligned as its offset in ptxas's layout of the
//!   kernel: the variables the function names, in declaration order, each at
//!   its `.align` (not warplight's layout of the whole module). The evidence
//!   (`docs/validation.md`, "Vectorisation: the alignment rule"):
//!   `tests/fixtures/validation/vectorize_probes.sass` (ptxas 13.5),
//!   `loop_stepped.*.sass` and the suite (ptxas 13.0, needleman_wunsch's
//!   `sub.s64` base: no `LDS.64`).
//! - **Repeated loads.** A shared load of the same base register (same
//!   definition), offset and width as an earlier load of the same run is
//!   dropped (ptxas reuses the register): not counted.
//! - **Reductions.** A `.global` `atom` whose destination register no
//!   instruction of the function reads is executed as `RED` (add, min, max,
//!   inc, dec, and, or, xor; not exch or cas) — counted as a reduction on the
//!   hopper profile. A generic `atom` stays `ATOM` (clang's generic
//!   `atom.inc`: `ATOM.E.INC` on the H200).
//! - **Warp-uniform atomics.** A global or generic 32-bit integer atomic
//!   whose address is warp-uniform ([`super::uniform`]) is done once per warp
//!   by one lane (`VOTEU.ANY`, then `POPC` or `REDUX` of the operands, then
//!   one lane's `RED`/`ATOM`; the old value handed back by `SHFL`): `add`,
//!   `min`, `max`, `and`, `or`, `xor` whose result is unused, in any lanes;
//!   `add` whose result is used, in any lanes when its operand is uniform,
//!   and only in a full warp when it varies. A 64-bit one (`REDUX` has no
//!   64-bit form) only when it is an `add` of a uniform operand, its result
//!   used or not (`kernels/validation/uniform_atomics64.cu`). Not merged:
//!   floats, `inc`/`dec`, `exch`, `cas`, `min`/`max`/logic whose result is
//!   used, 64-bit operations on a varying operand. Counted as one lane's
//!   access on the hopper profile (1 L1 sector instead of 1 per lane).
//!
//! The rules were read off the SASS that ptxas 13.0 makes for sm_90 of the
//! validation suite (`kernels/validation/suite.cu`, `docs/validation.md`):
//! the unrolled tiled matrix product's `As[ty][k..k+3]` become `LDS.128`,
//! the sorting network's eight adjacent words two `LDS.128`/`STS.128`, and
//! the bitonic sort's stride-1 steps (`pos = 2 * tid`) `LDS.64`/`STS.64`.
//! Switch the pass off with `--no-ptxas-vectorize`
//! ([`set_default`], or [`crate::model::Model::with_vectorize`]).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::ptx::Program;
use crate::ptx::ir::{Address, ArithOp, AtomOp, Dst, Function, Kind, MemSpace, PredSrc, RegId, Src};

/// How the counter model counts one instruction's accesses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Action {
    /// As the PTX says.
    #[default]
    Count,
    /// Not at all: merged into another instruction's access, or a repeated load.
    Skip,
    /// As one access of `bytes` per lane starting `shift` bytes from this
    /// instruction's addresses (the first instruction of a merged group).
    Widen {
        /// Bytes per lane of the merged access (8 or 16).
        bytes: u32,
        /// Offset of the merged access's start from this instruction's address.
        shift: i64,
    },
    /// A global atomic whose result is unused: a reduction.
    Red,
    /// A global or generic atomic whose address ptxas proves warp-uniform
    /// ([`super::uniform`]): one lane does it for the whole warp, with the
    /// warp's combined operand — as a reduction when `red` — and, when
    /// `full_warp_only`, only where all 32 lanes take part (otherwise each
    /// lane does its own, as written).
    Uniform {
        /// Executed as `RED` (a `.global` atom whose result is unused).
        red: bool,
        /// Merged only when the whole warp is active.
        full_warp_only: bool,
    },
}

/// The pass's decisions: `actions[function][pc]`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Plan {
    /// Per function, per instruction.
    pub actions: Vec<Vec<Action>>,
}

impl Plan {
    /// The action for instruction `pc` of function `func` ([`Action::Count`] when unknown).
    pub fn action(&self, func: u32, pc: u32) -> Action {
        self.actions.get(func as usize).and_then(|f| f.get(pc as usize)).copied().unwrap_or_default()
    }

    /// Plans every function of `prog`.
    pub fn new(prog: &Program) -> Plan {
        Plan { actions: prog.functions.iter().map(|f| plan_function(f, &shared_var_alignment(prog, f))).collect() }
    }
}

static DEFAULT_ON: AtomicBool = AtomicBool::new(true);

/// Whether models made by [`crate::model::Model::new`] apply the pass (on unless
/// switched off, e.g. by `--no-ptxas-vectorize`).
pub fn default_on() -> bool {
    DEFAULT_ON.load(Ordering::Relaxed)
}

/// Switches the pass on or off for models made from now on by [`crate::model::Model::new`].
pub fn set_default(on: bool) {
    DEFAULT_ON.store(on, Ordering::Relaxed);
}

/// What an instruction means for the pass.
enum Effect {
    /// Writes these data registers (and nothing the pass must stop at).
    Writes(Vec<RegId>),
    /// Writes predicates (guards of pending accesses may change).
    WritesPred(Vec<RegId>),
    /// A load or store the pass looks at.
    Access,
    /// Ends every run: control flow, barriers, fences, calls.
    Boundary,
    /// Any other instruction (textures, surfaces): ends every run as a
    /// boundary does.
    Unknown,
}

fn dst_regs(ds: impl IntoIterator<Item = RegId>) -> Vec<RegId> {
    ds.into_iter().filter(|&r| r != Dst::SINK).collect()
}

fn effect(k: &Kind) -> Effect {
    match k {
        Kind::Mov { d, .. }
        | Kind::Pack { d, .. }
        | Kind::Arith { d, .. }
        | Kind::Set { d, .. }
        | Kind::Bfi { d, .. }
        | Kind::Selp { d, .. }
        | Kind::Cvt { d, .. }
        | Kind::Cvta { d, .. } => Effect::Writes(dst_regs([d.reg])),
        Kind::Unpack { ds, .. } => Effect::Writes(dst_regs(ds.iter().map(|d| d.reg))),
        // warp reductions and carry arithmetic touch no memory (REDUX,
        // MATCH, IADD3 with a carry)
        Kind::Redux { .. } | Kind::Carry { .. } => Effect::Writes(k.writes()),
        Kind::Match { .. } => Effect::WritesPred(k.writes()),
        Kind::Setp { .. } | Kind::PredLogic { .. } => Effect::WritesPred(Vec::new()),
        Kind::Vote { d, .. } => Effect::WritesPred(dst_regs(d.iter().map(|d| d.reg))),
        Kind::Shfl { d, .. } => Effect::WritesPred(dst_regs([d.reg])),
        Kind::Ld { .. } | Kind::St { .. } | Kind::Atom { .. } => Effect::Access,
        Kind::Nop => Effect::Writes(Vec::new()),
        Kind::Bra { .. }
        | Kind::Call { .. }
        | Kind::CallIndirect { .. }
        | Kind::Ret
        | Kind::Exit
        | Kind::Bar { .. }
        | Kind::BarRed { .. }
        | Kind::WarpSync { .. }
        | Kind::Membar
        | Kind::Trap => Effect::Boundary,
        _ => Effect::Unknown,
    }
}

/// Trailing zero bits of an immediate (64 for 0).
fn tz_imm(v: u64) -> u32 {
    v.trailing_zeros()
}

/// The shared variables `f` names, with the alignment ptxas knows their
/// addresses by: (warplight's offset, trailing zeros of the offset in
/// ptxas's layout). ptxas lays out only the variables a kernel uses, in
/// declaration order, each at its `.align`, from a base aligned far beyond
/// 16 bytes, and knows the offsets (ptxas 13.5: an unused 4-byte array
/// declared first takes no room; a `.align 4` array of 1,024 bytes after
/// one of 1,156 sits at 0x484 and is not read as `LDS.64`; a `.align 4`
/// array of 1,156 bytes first is;
/// `tests/fixtures/validation/vectorize_probes.sass`). Warplight's own
/// layout holds every variable of the module, so its offsets can be
/// aligned otherwise.
fn shared_var_alignment(prog: &Program, f: &Function) -> Vec<(u64, u32)> {
    let mut off: u64 = 0;
    let mut out = Vec::new();
    for v in prog.shared_vars.iter().filter(|v| v.size > 0 && f.shared_refs.contains(&v.offset)) {
        let align = u64::from(v.align.max(1));
        off = off.div_ceil(align).saturating_mul(align);
        out.push((u64::from(v.offset), tz_imm(off)));
        off = off.saturating_add(u64::from(v.size));
    }
    out
}

/// Known trailing zeros of every data register of `f` (see the module
/// comment); `vars`: [`shared_var_alignment`].
fn trailing_zeros(f: &Function, vars: &[(u64, u32)]) -> Vec<u32> {
    let n = f.reg_masks.len();
    let mut tz = vec![64u32; n];
    let width = |r: RegId| f.reg_masks.get(r as usize).map_or(64, |m| m.count_ones());
    // registers every definition of which moves an immediate into them
    let mut constant = vec![true; n];
    for inst in &f.insts {
        let imm = matches!(inst.kind, Kind::Mov { a: Src::Imm(_), .. });
        for r in inst.kind.writes() {
            if let Some(c) = constant.get_mut(r as usize) {
                *c &= imm;
            }
        }
    }
    let is_constant = |s: &Src| match s {
        Src::Imm(_) => true,
        Src::Reg(r) => constant.get(*r as usize).copied().unwrap_or(false),
        _ => false,
    };
    loop {
        let mut changed = false;
        for inst in &f.insts {
            let of = |s: &Src, tz: &[u32]| match s {
                Src::Reg(r) => tz.get(*r as usize).copied().unwrap_or(0),
                Src::Imm(v) => tz_imm(*v),
                _ => 0,
            };
            // a shared variable's address (an immediate in warplight's
            // layout) as aligned as ptxas knows it
            let var = |s: &Src, tz: &[u32]| match s {
                Src::Imm(v) => vars.iter().find(|x| x.0 == *v).map_or(tz_imm(*v), |x| x.1),
                _ => of(s, tz),
            };
            let (regs, value): (Vec<RegId>, u32) = match &inst.kind {
                Kind::Mov { d, a } => (vec![d.reg], var(a, &tz)),
                Kind::Cvt { d, a, dty, sty, .. } if !dty.is_float() && !sty.is_float() => (vec![d.reg], of(a, &tz)),
                Kind::Cvta { d, a, .. } => (vec![d.reg], var(a, &tz)),
                Kind::Selp { d, a, b, .. } => (vec![d.reg], of(a, &tz).min(of(b, &tz))),
                // ptxas 13.5 keeps no alignment through a 64-bit `sub` of a
                // non-constant or a 64-bit `neg` (32-bit ones keep it)
                Kind::Arith { op: ArithOp::Sub, d, b, ty, .. } if ty.bytes() == 8 && !is_constant(b) => {
                    (vec![d.reg], 0)
                }
                Kind::Arith { op: ArithOp::Neg, d, ty, .. } if ty.bytes() == 8 && !ty.is_float() => (vec![d.reg], 0),
                Kind::Arith { op, d, a, b, c, ty, .. } if !ty.is_float() => {
                    let (a, b, c) = (of(a, &tz), of(b, &tz), of(c, &tz));
                    let v = match op {
                        ArithOp::Add | ArithOp::Sub | ArithOp::Or | ArithOp::Xor => a.min(b),
                        ArithOp::And => a.max(b),
                        ArithOp::Mul | ArithOp::MulWide => a.saturating_add(b),
                        ArithOp::Mad | ArithOp::MadWide => a.saturating_add(b).min(c),
                        ArithOp::Neg => a,
                        ArithOp::Shl => match &inst.kind {
                            Kind::Arith { b: Src::Imm(k), .. } => a.saturating_add(*k as u32),
                            _ => 0,
                        },
                        _ => 0,
                    };
                    (vec![d.reg], v)
                }
                // anything else: what it writes is unaligned as far as the
                // pass knows
                k => (k.writes(), 0),
            };
            for r in regs {
                if r == Dst::SINK || r as usize >= n {
                    continue;
                }
                let v = value.min(width(r));
                if v < tz[r as usize] {
                    tz[r as usize] = v;
                    changed = true;
                }
            }
        }
        if !changed {
            return tz;
        }
    }
}

/// The base of an address as the pass compares them: a register at one of its
/// definitions, or an absolute shared offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Base {
    Reg(RegId, u32),
    Abs,
}

/// A pending scalar shared access of a run.
#[derive(Debug, Clone, Copy)]
struct Pending {
    pc: usize,
    base: Base,
    /// Byte offset from the base (absolute offset for [`Base::Abs`]).
    off: i64,
    /// Bytes of the access (4 or 8).
    bytes: u32,
    /// The guard, with the number of predicate writes before it (a guard
    /// predicate written in between makes another guard).
    guard: Option<(PredSrc, u32)>,
    /// Trailing zeros known of the base.
    tz: u32,
}

/// The scalar shared access of `k`, if it is one the pass may merge: (is a load, address, bytes).
fn scalar_shared(k: &Kind) -> Option<(bool, Address, u32)> {
    match k {
        Kind::Ld { space: MemSpace::Shared, ty, ds, addr, volatile: false, .. } if ds.len() == 1 => {
            Some((true, *addr, ty.bytes()))
        }
        Kind::St { space: MemSpace::Shared, ty, vals, addr, volatile: false } if vals.len() == 1 => {
            Some((false, *addr, ty.bytes()))
        }
        _ => None,
    }
}

/// Groups a run's pending accesses (all loads or all stores) into `actions`.
fn settle(run: &mut Vec<Pending>, loads: bool, actions: &mut [Action]) {
    // same base (definition), width and guard
    while let Some(first) = run.first().copied() {
        let key = (first.base, first.bytes, first.guard);
        let mut group: Vec<Pending> = run.iter().filter(|p| (p.base, p.bytes, p.guard) == key).copied().collect();
        run.retain(|p| (p.base, p.bytes, p.guard) != key);
        // repeated loads: the first of each offset stays
        if loads {
            group.sort_by_key(|p| (p.off, p.pc));
            let mut kept: Vec<Pending> = Vec::new();
            for p in group {
                if kept.last().is_some_and(|k| k.off == p.off) {
                    actions[p.pc] = Action::Skip;
                } else {
                    kept.push(p);
                }
            }
            group = kept;
        } else {
            // a store written twice at one offset is left alone
            group.sort_by_key(|p| (p.off, p.pc));
            group.dedup_by_key(|p| p.off);
        }
        let e = key.1 as i64;
        let tz = group.first().map_or(0, |p| p.tz);
        let aligned = |off: i64, width: i64| {
            let k = width.trailing_zeros();
            tz >= k && off.rem_euclid(width) == 0
        };
        let mut taken = vec![false; group.len()];
        for s in 0..group.len() {
            if taken[s] {
                continue;
            }
            let start = group[s].off;
            for width in [16i64, 8] {
                let n = (width / e) as usize;
                if n < 2 || !aligned(start, width) {
                    continue;
                }
                let members: Option<Vec<usize>> = (0..n)
                    .map(|j| (s..group.len()).find(|&x| !taken[x] && group[x].off == start + j as i64 * e))
                    .collect();
                let Some(members) = members else { continue };
                let Some(&leader) = members.iter().min_by_key(|&&x| group[x].pc) else { continue };
                for &m in &members {
                    taken[m] = true;
                    actions[group[m].pc] = Action::Skip;
                }
                actions[group[leader].pc] = Action::Widen { bytes: width as u32, shift: start - group[leader].off };
                break;
            }
        }
    }
}

/// Plans one function.
fn plan_function(f: &Function, vars: &[(u64, u32)]) -> Vec<Action> {
    let mut actions = vec![Action::Count; f.insts.len()];
    let tz = trailing_zeros(f, vars);
    // registers some instruction reads (for atomics without a used result)
    let mut read = vec![false; f.reg_masks.len()];
    for inst in &f.insts {
        for r in inst.kind.reads() {
            if let Some(x) = read.get_mut(r as usize) {
                *x = true;
            }
        }
    }
    for (pc, inst) in f.insts.iter().enumerate() {
        if let Kind::Atom { space: MemSpace::Global | MemSpace::Generic, op, d, .. } = &inst.kind {
            let reducible = !matches!(op, AtomOp::Exch | AtomOp::Cas);
            let unused = d.is_none_or(|d| d.reg == Dst::SINK || !read.get(d.reg as usize).copied().unwrap_or(true));
            let global = matches!(inst.kind, Kind::Atom { space: MemSpace::Global, .. });
            if reducible && unused && global {
                actions[pc] = Action::Red;
            }
        }
    }
    let uniform = super::uniform::analyse(f);
    for (pc, inst) in f.insts.iter().enumerate() {
        if let Kind::Atom { space: space @ (MemSpace::Global | MemSpace::Generic), op, ty, d, addr, b, .. } = &inst.kind
        {
            if !ty.is_int() || !matches!(ty.bits(), 32 | 64) || !uniform.src(&addr.base) {
                continue;
            }
            let unused = d.is_none_or(|d| d.reg == Dst::SINK || !read.get(d.reg as usize).copied().unwrap_or(true));
            let red = unused && *space == MemSpace::Global;
            actions[pc] = match (op, unused, ty.bits()) {
                (AtomOp::Add | AtomOp::Min | AtomOp::Max | AtomOp::And | AtomOp::Or | AtomOp::Xor, true, 32) => {
                    Action::Uniform { red, full_warp_only: false }
                }
                (AtomOp::Add, false, 32) => Action::Uniform { red, full_warp_only: !uniform.src(b) },
                // 64 bits: no REDUX, so only an add of a uniform operand
                // (`UPOPC` × operand), its result used or not
                (AtomOp::Add, _, 64) if uniform.src(b) => Action::Uniform { red, full_warp_only: false },
                _ => continue,
            };
        }
    }
    let mut target = vec![false; f.insts.len() + 1];
    for (_, t) in &f.labels {
        if let Some(x) = target.get_mut(*t as usize) {
            *x = true;
        }
    }
    // each register's definition count so far, and the predicate writes so far
    let mut version = vec![0u32; f.reg_masks.len()];
    let mut pred_epoch = 0u32;
    let mut loads: Vec<Pending> = Vec::new();
    let mut stores: Vec<Pending> = Vec::new();
    for (pc, inst) in f.insts.iter().enumerate() {
        if target[pc] {
            settle(&mut loads, true, &mut actions);
            settle(&mut stores, false, &mut actions);
        }
        let written: Vec<RegId> = match effect(&inst.kind) {
            Effect::Boundary | Effect::Unknown => {
                settle(&mut loads, true, &mut actions);
                settle(&mut stores, false, &mut actions);
                inst.kind.writes()
            }
            Effect::WritesPred(ds) => {
                pred_epoch += 1;
                ds
            }
            Effect::Writes(ds) => ds,
            Effect::Access => {
                let scalar = scalar_shared(&inst.kind);
                let (is_load, space) = match &inst.kind {
                    Kind::Ld { space, .. } => (true, *space),
                    Kind::St { space, .. } => (false, *space),
                    Kind::Atom { space, .. } => (false, *space),
                    _ => (false, MemSpace::Generic),
                };
                let shared_or_generic = matches!(space, MemSpace::Shared | MemSpace::Generic);
                let based = scalar.and_then(|(load, addr, bytes)| {
                    let (base, off, tzb) = match addr.base {
                        Src::Reg(r) => (
                            Base::Reg(r, version.get(r as usize).copied().unwrap_or(0)),
                            addr.offset,
                            tz.get(r as usize).copied().unwrap_or(0),
                        ),
                        Src::Imm(v) => (Base::Abs, addr.offset.wrapping_add(v as i64), 64),
                        _ => return None,
                    };
                    (bytes == 4 || bytes == 8).then_some((load, base, off, bytes, tzb))
                });
                // a shared or generic load ends the store run; a shared or
                // generic store or atomic ends both, except that a scalar
                // shared store joins the store run
                match based {
                    Some((load, base, off, bytes, tzb)) => {
                        let p = Pending { pc, base, off, bytes, guard: inst.guard.map(|g| (g, pred_epoch)), tz: tzb };
                        if load {
                            settle(&mut stores, false, &mut actions);
                            loads.push(p);
                        } else {
                            settle(&mut loads, true, &mut actions);
                            stores.push(p);
                        }
                    }
                    None if shared_or_generic => {
                        settle(&mut stores, false, &mut actions);
                        if !is_load {
                            settle(&mut loads, true, &mut actions);
                        }
                    }
                    None => {}
                }
                match &inst.kind {
                    Kind::Ld { ds, .. } => dst_regs(ds.iter().map(|d| d.reg)),
                    Kind::Atom { d: Some(d), .. } => dst_regs([d.reg]),
                    _ => Vec::new(),
                }
            }
        };
        for r in written {
            if let Some(v) = version.get_mut(r as usize) {
                *v += 1;
            }
        }
    }
    settle(&mut loads, true, &mut actions);
    settle(&mut stores, false, &mut actions);
    actions
}
