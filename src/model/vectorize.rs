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
//! - **Alignment** comes from a trailing-zero analysis of the registers (a
//!   register read where one unguarded definition reaches it in
//!   straight-line code — no branch target in between — has that
//!   definition's; otherwise the fewest of all its definitions): shared
//!   variables' offsets, immediates, `shl` by a constant, `mul`/`mad` (zeros
//!   add up), `add`/`sub`/`or` (the fewer), `and` (the more), `neg`, moves
//!   and conversions keep them; anything loaded or special is unaligned. A
//!   64-bit `sub` whose subtracted operand is not a constant (an immediate
//!   or a register only ever set to one), and a 64-bit `neg`, give no
//!   alignment; 32-bit ones keep it (ptxas 13.5: `arr - 64 tid` in 64 bits
//!   is two `LDS`, in 32 bits, or as `arr + (-64 tid)`, one `LDS.64`). A
//!   register stepped round a loop (`add`/`sub %r, %r, k`) is as aligned as
//!   its first value and its step (`kernels/validation/loop_stepped.cu`). A
//!   shared variable's symbol — as a `mov`/`cvta` source or as an address
//!   base, `[var+8]` — stands for its offset in ptxas's layout of the kernel
//!   ([`Program::kernel_shared_layout`]: the variables the kernel and its
//!   callees name, its own function-scope ones first, then module-scope,
//!   then its callees' function-scope ones, each at its `.align`), not in
//!   warplight's layout of the whole module; a number written in the PTX
//!   is itself ([`crate::ptx::ir::Function::shared_symbols`] tells them
//!   apart). The evidence (`docs/validation.md`, "Vectorisation: the
//!   alignment rule"): the rule was read off
//!   `tests/fixtures/validation/vectorize_probes.sass` (ptxas 13.5),
//!   `loop_stepped.*.sass` and the suite (ptxas 13.0, needleman_wunsch's
//!   `sub.s64` base: no `LDS.64`); `vectorize_heldout.sass` (its layout
//!   order refuted in two of eleven kernels, then corrected) and
//!   `vectorize_heldout2.sass` (five of five) were predicted before they
//!   were made.
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
use crate::ptx::ir::{Address, ArithOp, AtomOp, Dst, Function, Inst, Kind, MemSpace, PredSrc, RegId, Src};

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
        let places = shared_places(prog);
        Plan { actions: prog.functions.iter().zip(&places).map(|(f, p)| plan_function(f, p)).collect() }
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

/// Where a shared variable lies, as ptxas knows it when it compiles one
/// function: in the layout of every kernel that reaches the function
/// ([`Program::kernel_shared_layout`]) its offset agrees with `offset` in
/// the low `bits` bits (64: it is `offset` in all of them). ptxas compiles a
/// callee once per calling kernel (`$kernel$callee` in the SASS), in that
/// kernel's layout; warplight plans each function once, so a callee of
/// kernels whose layouts disagree is taken as aligned only as far as they
/// agree.
#[derive(Debug, Clone, Copy)]
struct Place {
    /// The variable's offset in warplight's (module-wide) layout: the value
    /// of its symbol in the IR.
    warplight: u64,
    /// Its offset in ptxas's layout (the low `bits` bits known).
    offset: u64,
    /// How many low bits of `offset` hold in every layout.
    bits: u32,
}

impl Place {
    /// Trailing zeros known of the variable's address.
    fn tz(&self) -> u32 {
        tz_imm(self.offset).min(self.bits)
    }
}

/// Per function of `prog`, the shared variables of the kernels that reach it
/// (a function no kernel calls: as if it were one).
fn shared_places(prog: &Program) -> Vec<Vec<Place>> {
    let n = prog.functions.len();
    let taken = prog.address_taken();
    let mut places: Vec<Vec<Place>> = vec![Vec::new(); n];
    let mut reached = vec![false; n];
    let mut add = |f: usize, layout: &[crate::ptx::ir::SharedPlace]| {
        for p in layout {
            let warplight = u64::from(prog.shared_vars[p.var].offset);
            let offset = u64::from(p.offset);
            match places[f].iter_mut().find(|x| x.warplight == warplight) {
                Some(x) => x.bits = x.bits.min(tz_imm(x.offset ^ offset)),
                None => places[f].push(Place { warplight, offset, bits: 64 }),
            }
        }
    };
    for k in (0..n as u32).filter(|&k| prog.functions[k as usize].is_entry) {
        let layout = prog.kernel_shared_layout(k);
        for f in prog.reachable(k, &taken) {
            reached[f as usize] = true;
            add(f as usize, &layout);
        }
    }
    for f in (0..n).filter(|&f| !reached[f]) {
        add(f, &prog.kernel_shared_layout(f as u32));
    }
    places
}

/// The place of the shared variable whose symbol instruction `pc` of `f`
/// names with value `v` (`None` for a number written in the PTX).
fn symbol_place(f: &Function, places: &[Place], pc: usize, v: u64) -> Option<Place> {
    if f.shared_symbols.binary_search(&(pc as u32)).is_err() {
        return None;
    }
    places.iter().find(|p| p.warplight == v).copied()
}

/// Known trailing zeros of the values of `f`'s data registers (see the
/// module comment): of each definition, and of each register over all of
/// them.
struct Zeros {
    /// Per instruction: of the value it writes (64 where it writes none).
    at_def: Vec<u32>,
    /// Per register: the fewest over all its definitions.
    reg: Vec<u32>,
}

impl Zeros {
    /// Trailing zeros of register `r` read where `reaching` stands: those of
    /// the one definition that reaches it in straight-line code, else the
    /// fewest of all its definitions (a loop's register: its first value and
    /// its steps).
    fn of(&self, r: RegId, reaching: &Reaching) -> u32 {
        match reaching.last.get(r as usize).copied().flatten() {
            Some(d) => self.at_def.get(d).copied().unwrap_or(0),
            None => self.reg.get(r as usize).copied().unwrap_or(0),
        }
    }
}

/// The definition of each register that reaches an instruction in
/// straight-line code: its last unguarded one, and none past a branch
/// target (where other paths join).
struct Reaching {
    last: Vec<Option<usize>>,
}

impl Reaching {
    fn new(f: &Function) -> Reaching {
        Reaching { last: vec![None; f.reg_masks.len()] }
    }

    /// Steps onto instruction `pc` (before its operands are read).
    fn enter(&mut self, pc: usize, target: &[bool]) {
        if target.get(pc).copied().unwrap_or(false) {
            self.last.fill(None);
        }
    }

    /// Records the registers instruction `pc` writes (after its operands were read).
    fn leave(&mut self, pc: usize, inst: &Inst) {
        for r in inst.kind.writes() {
            if let Some(x) = self.last.get_mut(r as usize) {
                *x = inst.guard.is_none().then_some(pc);
            }
        }
    }
}

/// Which instructions of `f` a branch may jump to.
fn branch_targets(f: &Function) -> Vec<bool> {
    let mut target = vec![false; f.insts.len() + 1];
    for (_, t) in &f.labels {
        if let Some(x) = target.get_mut(*t as usize) {
            *x = true;
        }
    }
    target
}

/// [`Zeros`] of `f`; `places`: [`shared_places`] of `f`.
fn trailing_zeros(f: &Function, places: &[Place], target: &[bool]) -> Zeros {
    let n = f.reg_masks.len();
    let mut z = Zeros { at_def: vec![64u32; f.insts.len()], reg: vec![64u32; n] };
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
        let mut reaching = Reaching::new(f);
        for (pc, inst) in f.insts.iter().enumerate() {
            reaching.enter(pc, target);
            let of = |s: &Src, z: &Zeros| match s {
                Src::Reg(r) => z.of(*r, &reaching),
                Src::Imm(v) => tz_imm(*v),
                _ => 0,
            };
            // a shared variable's symbol (an immediate in warplight's
            // layout) as aligned as ptxas knows it; a number as itself
            let var = |s: &Src, z: &Zeros| match s {
                Src::Imm(v) => symbol_place(f, places, pc, *v).map_or(tz_imm(*v), |p| p.tz()),
                _ => of(s, z),
            };
            let (regs, value): (Vec<RegId>, u32) = match &inst.kind {
                Kind::Mov { d, a } => (vec![d.reg], var(a, &z)),
                Kind::Cvt { d, a, dty, sty, .. } if !dty.is_float() && !sty.is_float() => (vec![d.reg], of(a, &z)),
                Kind::Cvta { d, a, .. } => (vec![d.reg], var(a, &z)),
                Kind::Selp { d, a, b, .. } => (vec![d.reg], of(a, &z).min(of(b, &z))),
                // ptxas 13.5 keeps no alignment through a 64-bit `sub` of a
                // non-constant or a 64-bit `neg` (32-bit ones keep it)
                Kind::Arith { op: ArithOp::Sub, d, b, ty, .. } if ty.bytes() == 8 && !is_constant(b) => {
                    (vec![d.reg], 0)
                }
                Kind::Arith { op: ArithOp::Neg, d, ty, .. } if ty.bytes() == 8 && !ty.is_float() => (vec![d.reg], 0),
                Kind::Arith { op, d, a, b, c, ty, .. } if !ty.is_float() => {
                    let (a, b, c) = (of(a, &z), of(b, &z), of(c, &z));
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
                if v < z.at_def[pc] {
                    z.at_def[pc] = v;
                    changed = true;
                }
                if v < z.reg[r as usize] {
                    z.reg[r as usize] = v;
                    changed = true;
                }
            }
            reaching.leave(pc, inst);
        }
        if !changed {
            return z;
        }
    }
}

/// The base of an address as the pass compares them: a register at one of its
/// definitions, a shared variable's symbol (by its warplight offset), or an
/// absolute shared address written as a number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Base {
    Reg(RegId, u32),
    Sym(u64),
    Abs,
}

/// A pending scalar shared access of a run.
#[derive(Debug, Clone, Copy)]
struct Pending {
    pc: usize,
    base: Base,
    /// Byte offset from the base (for [`Base::Sym`], from the start of
    /// ptxas's layout, the low bits its `tz` says; for [`Base::Abs`], the
    /// absolute address).
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

/// Plans one function; `places`: [`shared_places`] of `f`.
fn plan_function(f: &Function, places: &[Place]) -> Vec<Action> {
    let mut actions = vec![Action::Count; f.insts.len()];
    let target = branch_targets(f);
    let zeros = trailing_zeros(f, places, &target);
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
    // each register's definition count so far, and the predicate writes so far
    let mut version = vec![0u32; f.reg_masks.len()];
    let mut pred_epoch = 0u32;
    let mut loads: Vec<Pending> = Vec::new();
    let mut stores: Vec<Pending> = Vec::new();
    let mut reaching = Reaching::new(f);
    for (pc, inst) in f.insts.iter().enumerate() {
        reaching.enter(pc, &target);
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
                            zeros.of(r, &reaching),
                        ),
                        Src::Imm(v) => match symbol_place(f, places, pc, v) {
                            // in ptxas's layout: aligned as far as the layouts agree
                            Some(p) => (Base::Sym(v), addr.offset.wrapping_add(p.offset as i64), p.bits),
                            None => (Base::Abs, addr.offset.wrapping_add(v as i64), 64),
                        },
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
        reaching.leave(pc, inst);
    }
    settle(&mut loads, true, &mut actions);
    settle(&mut stores, false, &mut actions);
    actions
}
