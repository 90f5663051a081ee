//! Table 2's instruction classes read off the PTX by data flow: texture
//! fetches (TEX), address arithmetic (Addr) and bit packing (Pack), the
//! categories Cg 1.1's fp30 counts were given in (004:L190–197, L199–203).
//!
//! The rules, per function, over the lowered instructions:
//! - **TEX**: a load from global (or generic) memory, the fetch of a
//!   fragment program.
//! - **Addr**: an instruction (not a memory access, not control) whose
//!   results feed memory addresses *only*: every use of every register it
//!   writes is the address of a load, store or atomic, or an instruction that
//!   is itself Addr, and at least one such chain ends at an address. An index
//!   that also feeds anything else (a comparison, a stored value, the loop's
//!   state) is not address arithmetic. Data flow passes through data
//!   registers and through predicates into `selp` / `set` / `setp`'s combiner
//!   (a clamp of an index is address arithmetic); guards and branches
//!   (control dependence) are uses of another kind.
//! - **Pack**: a bit-level instruction that is not Addr: `mov` into or out of
//!   a vector of parts, `bfe`, `bfi`, `prmt`, `and`, `or`, `xor`, `not`,
//!   `shl`, `shr`, and conversions to or from 16-bit floats (`cvt` with an
//!   `f16` / `bf16` side, `cvt.rn.f16x2.f32`): what packing state into a
//!   128-bit output and unpacking it again costs.
//! - everything else is **Other**.
//!
//! Registers are treated flow-insensitively (every write of a register
//! reaches every read of it), which is exact for the single-assignment PTX
//! compilers emit apart from loop-carried moves, and errs only towards "not
//! address-only" there.

use crate::ptx::ir::{ArithOp, Function, Kind, MemSpace, Program, Src};
use crate::ptx::types::Ty;
use crate::sim::{LaunchStats, Module};

/// The class of one instruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// A global-memory load: a texture fetch.
    Tex,
    /// Address arithmetic.
    Addr,
    /// Bit packing.
    Pack,
    /// Anything else.
    Other,
}

/// A value an instruction writes or reads: a data register or a predicate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Var {
    R(u16),
    P(u16),
}

/// How an instruction uses a value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Use {
    /// As the address of a memory access.
    Address,
    /// As a data operand (flows on to the instruction's results).
    Data,
    /// As anything else: a stored value, a guard, a branch condition.
    Sink,
}

fn is_memory(space: MemSpace) -> bool {
    !matches!(space, MemSpace::KernelParam | MemSpace::FrameParam)
}

/// The values an instruction writes ([`Kind::writes`], [`Kind::pred_writes`]).
fn writes(k: &Kind) -> Vec<Var> {
    k.writes().into_iter().map(Var::R).chain(k.pred_writes().into_iter().map(Var::P)).collect()
}

/// The values an instruction reads, with how it uses each.
fn uses(inst: &crate::ptx::ir::Inst) -> Vec<(Var, Use)> {
    let mut v = Vec::new();
    if let Some(g) = inst.guard {
        v.push((Var::P(g.reg), Use::Sink));
    }
    let reg = |s: &Src| if let Src::Reg(r) = s { Some(Var::R(*r)) } else { None };
    match &inst.kind {
        Kind::Ld { space, addr, .. } => {
            let u = if is_memory(*space) { Use::Address } else { Use::Sink };
            v.extend(reg(&addr.base).map(|x| (x, u)));
        }
        Kind::St { space, vals, addr, .. } => {
            v.extend(vals.iter().filter_map(reg).map(|x| (x, Use::Sink)));
            let u = if is_memory(*space) { Use::Address } else { Use::Sink };
            v.extend(reg(&addr.base).map(|x| (x, u)));
        }
        Kind::Atom { space, addr, b, c, .. } => {
            v.extend([b, c].into_iter().filter_map(reg).map(|x| (x, Use::Sink)));
            let u = if is_memory(*space) { Use::Address } else { Use::Sink };
            v.extend(reg(&addr.base).map(|x| (x, u)));
        }
        // a texture or surface access: its handle and coordinates address memory
        Kind::Tex { handle, coords, .. } | Kind::Suld { handle, coords, .. } => {
            v.extend(std::iter::once(handle).chain(coords.iter()).filter_map(reg).map(|x| (x, Use::Address)));
        }
        Kind::Txq { handle, .. } => v.extend(reg(handle).map(|x| (x, Use::Address))),
        Kind::Sust { vals, handle, coords, .. } => {
            v.extend(vals.iter().filter_map(reg).map(|x| (x, Use::Sink)));
            v.extend(std::iter::once(handle).chain(coords.iter()).filter_map(reg).map(|x| (x, Use::Address)));
        }
        k => {
            // every other instruction: its data sources flow into its results
            let flows =
                !writes(k).is_empty() && !matches!(k, Kind::Shfl { .. } | Kind::Redux { .. } | Kind::Vote { .. });
            let u = if flows { Use::Data } else { Use::Sink };
            v.extend(k.reads().into_iter().map(|r| (Var::R(r), u)));
            match k {
                Kind::Selp { p, .. } => v.push((Var::P(p.reg), Use::Data)),
                Kind::Setp { comb: Some((_, p)), .. } | Kind::Set { comb: Some((_, p)), .. } => {
                    v.push((Var::P(p.reg), Use::Data))
                }
                Kind::PredLogic { a, b, .. } => {
                    v.push((Var::P(a.reg), Use::Data));
                    v.push((Var::P(b.reg), Use::Data));
                }
                Kind::Vote { a, .. } | Kind::BarRed { a, .. } => v.push((Var::P(a.reg), Use::Sink)),
                _ => {}
            }
        }
    }
    v
}

/// Whether an instruction can be address arithmetic: it computes values
/// (not a memory access, control, or a warp-wide operation).
fn computes(k: &Kind) -> bool {
    matches!(
        k,
        Kind::Mov { .. }
            | Kind::Pack { .. }
            | Kind::Unpack { .. }
            | Kind::Arith { .. }
            | Kind::Setp { .. }
            | Kind::Set { .. }
            | Kind::Bfi { .. }
            | Kind::Selp { .. }
            | Kind::PredLogic { .. }
            | Kind::Cvt { .. }
            | Kind::Cvta { .. }
            | Kind::Carry { .. }
    )
}

/// Whether an instruction manipulates bits (packing or unpacking).
fn is_bit_op(k: &Kind) -> bool {
    let half = |t: Ty| matches!(t, Ty::F16 | Ty::BF16 | Ty::F16x2 | Ty::BF16x2);
    match k {
        Kind::Pack { .. } | Kind::Unpack { .. } | Kind::Bfi { .. } => true,
        Kind::Arith { op, .. } => matches!(
            op,
            ArithOp::And
                | ArithOp::Or
                | ArithOp::Xor
                | ArithOp::Not
                | ArithOp::Shl
                | ArithOp::Shr
                | ArithOp::Bfe
                | ArithOp::Prmt
                | ArithOp::PrmtF4e
                | ArithOp::PrmtB4e
                | ArithOp::PrmtRc8
                | ArithOp::PrmtEcl
                | ArithOp::PrmtEcr
                | ArithOp::PrmtRc16
                | ArithOp::ShfLWrap
                | ArithOp::ShfLClamp
                | ArithOp::ShfRWrap
                | ArithOp::ShfRClamp
                | ArithOp::CvtPack
        ),
        Kind::Cvt { dty, sty, .. } => half(*dty) || half(*sty),
        _ => false,
    }
}

/// The class of every instruction of `f`.
pub fn classify(f: &Function) -> Vec<Class> {
    let n = f.insts.len();
    let mut users: std::collections::HashMap<Var, Vec<(usize, Use)>> = std::collections::HashMap::new();
    for (i, inst) in f.insts.iter().enumerate() {
        for (var, u) in uses(inst) {
            users.entry(var).or_default().push((i, u));
        }
    }
    let outs: Vec<Vec<Var>> = f.insts.iter().map(|i| writes(&i.kind)).collect();
    let uses_of = |i: usize| outs[i].iter().flat_map(|v| users.get(v).into_iter().flatten().copied());
    // greatest set of instructions whose every use is an address or another member
    let mut addr: Vec<bool> = (0..n).map(|i| computes(&f.insts[i].kind) && uses_of(i).next().is_some()).collect();
    let mut changed = true;
    while changed {
        changed = false;
        for i in 0..n {
            if addr[i] && !uses_of(i).all(|(j, u)| u == Use::Address || (u == Use::Data && addr[j])) {
                addr[i] = false;
                changed = true;
            }
        }
    }
    // of those, the ones whose chains end at an address (not a closed cycle)
    let mut reach: Vec<bool> = (0..n).map(|i| addr[i] && uses_of(i).any(|(_, u)| u == Use::Address)).collect();
    changed = true;
    while changed {
        changed = false;
        for i in 0..n {
            if addr[i] && !reach[i] && uses_of(i).any(|(j, _)| reach[j]) {
                reach[i] = true;
                changed = true;
            }
        }
    }
    f.insts
        .iter()
        .enumerate()
        .map(|(i, inst)| match &inst.kind {
            Kind::Ld { space: MemSpace::Global | MemSpace::Generic, .. } => Class::Tex,
            _ if reach[i] => Class::Addr,
            k if is_bit_op(k) => Class::Pack,
            _ => Class::Other,
        })
        .collect()
}

/// The classes of every function of `prog` (indexed as `prog.functions`).
pub fn classify_program(prog: &Program) -> Vec<Vec<Class>> {
    prog.functions.iter().map(classify).collect()
}

/// Thread instructions of one launch by class (lanes active at each
/// instruction, summed; TEX counts the guard-true lanes, as the loads do).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClassCounts {
    /// Lane-level global loads.
    pub tex: u64,
    /// Thread instructions of address arithmetic.
    pub addr: u64,
    /// Thread instructions of bit packing.
    pub pack: u64,
}

impl ClassCounts {
    /// Adds another's counts.
    pub fn merge(&mut self, o: &ClassCounts) {
        self.tex += o.tex;
        self.addr += o.addr;
        self.pack += o.pack;
    }
}

/// The counts of a launch of `module` whose instructions are classed `classes`
/// (from [`classify_program`] of the module's program), from the emulator's
/// per-instruction profile.
pub fn count(classes: &[Vec<Class>], s: &LaunchStats) -> ClassCounts {
    let mut c = ClassCounts::default();
    for (f, counts) in s.profile.per_fn.iter().enumerate() {
        let Some(cl) = classes.get(f) else { continue };
        for (pc, ic) in counts.iter().enumerate() {
            match cl.get(pc) {
                Some(Class::Tex) => c.tex += ic.pred_on,
                Some(Class::Addr) => c.addr += ic.thread,
                Some(Class::Pack) => c.pack += ic.thread,
                _ => {}
            }
        }
    }
    c
}

/// The static class counts of kernel `name` of `module` (instructions in its
/// body, each once): (instructions, TEX, Addr, Pack).
pub fn static_counts(module: &Module, name: &str) -> Option<(usize, usize, usize, usize)> {
    let f = module.prog.functions.iter().find(|f| f.name == name)?;
    let cl = classify(f);
    let k = |c: Class| cl.iter().filter(|&&x| x == c).count();
    Some((cl.len(), k(Class::Tex), k(Class::Addr), k(Class::Pack)))
}
