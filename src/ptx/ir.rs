//! The typed, validated intermediate representation that the simulator executes.
//!
//! Names are resolved to indices, literals to bit patterns of the instruction's
//! type, labels to instruction indices, parameters and variables to offsets in
//! their state space. Nothing here knows how instructions execute.

use super::error::PtxError;
use super::types::Ty;

/// Index of a data register in a function's register file.
pub type RegId = u16;

/// Index of a predicate register. 0 is the constant `false`, 1 the constant `true`.
pub type PredId = u16;

/// The predicate register that always holds false.
pub const PRED_FALSE: PredId = 0;
/// The predicate register that always holds true.
pub const PRED_TRUE: PredId = 1;

/// A special (read-only) register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum SpecialReg {
    Tid(u8),
    Ntid(u8),
    Ctaid(u8),
    Nctaid(u8),
    LaneId,
    WarpId,
    NWarpId,
    SmId,
    NSmId,
    GridId,
    LaneMaskEq,
    LaneMaskLe,
    LaneMaskLt,
    LaneMaskGe,
    LaneMaskGt,
    Clock,
    Clock64,
    /// `%globaltimer_hi`: the upper 32 bits of the deterministic clock.
    GlobalTimerHi,
}

/// The value a function's address has (`mov.u64 %rd, f;`, `.u64 t[] = {f}`):
/// function `i` is at `FUNC_ADDR_BASE + 16 i`, outside every memory window.
pub const FUNC_ADDR_BASE: u64 = 0xF0F0_0000_0000_0000;

/// The address of function `idx`.
pub fn func_addr(idx: u32) -> u64 {
    FUNC_ADDR_BASE + 16 * idx as u64
}

/// The function at address `a`, when `a` is one of [`func_addr`]'s values.
pub fn func_at(a: u64, functions: usize) -> Option<u32> {
    let off = a.checked_sub(FUNC_ADDR_BASE)?;
    (off % 16 == 0 && off / 16 < functions as u64).then_some((off / 16) as u32)
}

/// The dimensionality of a texture or surface access (`.1d .2d .3d`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum TexGeom {
    D1,
    D2,
    D3,
}

impl TexGeom {
    /// Coordinates it uses.
    pub fn dims(self) -> usize {
        match self {
            TexGeom::D1 => 1,
            TexGeom::D2 => 2,
            TexGeom::D3 => 3,
        }
    }
}

/// What `txq` asks of a texture object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum TxqQuery {
    Width,
    Height,
    Depth,
    ChannelDataType,
    ChannelOrder,
    NormalizedCoords,
    FilterMode,
    AddrMode0,
    AddrMode1,
    AddrMode2,
    ArraySize,
    NumMipmapLevels,
    NumSamples,
}

/// What a surface access out of range does (`.trap .clamp .zero`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum SurfClamp {
    Trap,
    Clamp,
    Zero,
}

/// A source operand.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Src {
    /// A data register.
    Reg(RegId),
    /// An immediate, as the bits of the instruction's type.
    Imm(u64),
    /// A special register.
    Special(SpecialReg),
    /// The local-space address of the current frame's local area plus an offset.
    LocalAddr(u32),
    /// The global address of a module variable (index into [`Program::globals`]) plus an offset.
    GlobalAddr(u32, u32),
}

/// A destination data register. `mask` is the register's width mask: results are truncated to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dst {
    /// The register; [`Dst::SINK`] discards the value (`_`).
    pub reg: RegId,
    /// All-ones in the register's declared width.
    pub mask: u64,
}

impl Dst {
    /// Register index used for the `_` sink.
    pub const SINK: RegId = RegId::MAX;
}

/// A predicate source, possibly negated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PredSrc {
    /// Predicate register.
    pub reg: PredId,
    /// `!p`
    pub neg: bool,
}

/// A memory state space as the simulator distinguishes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[allow(missing_docs)]
pub enum MemSpace {
    Global,
    Shared,
    Local,
    Const,
    /// Kernel parameters (uniform across the grid).
    KernelParam,
    /// Per-thread parameter area of a function frame (call arguments, returns).
    FrameParam,
    /// A generic address resolved per lane at run time.
    Generic,
}

/// A memory address: base plus byte offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Address {
    /// Base value (`Imm(0)` for an absolute address).
    pub base: Src,
    /// Byte offset added to the base.
    pub offset: i64,
    /// Whether the base is 64 bits wide; a 32-bit register base is added to
    /// the offset modulo 2^32 and then zero-extended.
    pub wide: bool,
}

/// Floating-point rounding modes, and integer rounding of floats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Rounding {
    Rn,
    Rz,
    Rm,
    Rp,
    /// Round to nearest integer, ties to even.
    Rni,
    Rzi,
    Rmi,
    Rpi,
}

/// Comparison operators of `setp`/`set`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Cmp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Lo,
    Ls,
    Hi,
    Hs,
    Equ,
    Neu,
    Ltu,
    Leu,
    Gtu,
    Geu,
    Num,
    Nan,
}

/// Boolean combiners of `setp.CMP.BOOL` and predicate logic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum BoolOp {
    And,
    Or,
    Xor,
}

/// Arithmetic and logic operations with up to three sources.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ArithOp {
    Add,
    Sub,
    /// `mul.lo` (and float `mul`).
    Mul,
    MulHi,
    /// `mul.wide`: the instruction type is the source type; the result has twice the width.
    MulWide,
    /// `mad.lo` / float `mad`, `fma`.
    Mad,
    MadHi,
    MadWide,
    Mul24Lo,
    Mul24Hi,
    Mad24Lo,
    Mad24Hi,
    Div,
    Rem,
    Abs,
    Neg,
    Min,
    Max,
    And,
    Or,
    Xor,
    Not,
    Cnot,
    Shl,
    Shr,
    Popc,
    Clz,
    Brev,
    Bfe,
    Prmt,
    /// `shf.l.wrap`: funnel shift left of {b:a}, upper word.
    ShfLWrap,
    ShfLClamp,
    /// `shf.r.wrap`: funnel shift right of {b:a}, lower word.
    ShfRWrap,
    ShfRClamp,
    Sqrt,
    Rsqrt,
    Rcp,
    Sin,
    Cos,
    Ex2,
    Lg2,
    /// `tanh.approx`.
    Tanh,
    Copysign,
    /// `bfind`: the bit position of the most significant non-sign bit (all
    /// ones when none).
    Bfind,
    /// `bfind.shiftamt`: the left shift that brings that bit to the top.
    BfindShiftamt,
    /// `prmt.b32.f4e` (forward 4 extract), and the other `prmt` modes.
    PrmtF4e,
    PrmtB4e,
    PrmtRc8,
    PrmtEcl,
    PrmtEcr,
    PrmtRc16,
    /// `dp4a.atype.u32`: four byte products summed into `c`; the instruction
    /// type is `a`'s, `b`'s bytes are unsigned.
    Dp4aU,
    /// `dp4a.atype.s32`: `b`'s bytes signed.
    Dp4aS,
    /// `dp2a.lo.atype.u32`: two 16-bit by 8-bit products (bytes 0, 1 of `b`).
    Dp2aLoU,
    Dp2aLoS,
    /// `dp2a.hi`: bytes 2, 3 of `b`.
    Dp2aHiU,
    Dp2aHiS,
    /// `cvt.rn.f16x2.f32 d, a, b` (and `.bf16x2`): `a` into the upper half, `b` the lower.
    CvtPack,
}

/// `redux.sync` operations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ReduxOp {
    Add,
    Min,
    Max,
    And,
    Or,
    Xor,
}

/// `bar.red` reductions (`__syncthreads_count`, `_and`, `_or`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum BarRedOp {
    Popc,
    And,
    Or,
}

/// Carry-chain operations: `add.cc/addc`, `sub.cc/subc`, `mad.lo.cc/madc.lo`, `mad.hi.cc/madc.hi`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum CarryOp {
    Add,
    Sub,
    MadLo,
    MadHi,
}

/// Floating-point and saturation modifiers of an arithmetic instruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FloatMode {
    /// Rounding mode (`None`: the instruction's default).
    pub rnd: Option<Rounding>,
    /// `.ftz`: flush subnormal inputs and results to zero.
    pub ftz: bool,
    /// `.sat`: clamp floats to [0, 1] (integers to their range).
    pub sat: bool,
    /// `.approx` (or `.full` for `div`): an approximation, not correctly rounded.
    pub approx: bool,
    /// `div.full` (also sets `approx`): the division that rescales huge and
    /// tiny divisors around the approximate reciprocal.
    pub full: bool,
}

/// Atomic operations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[allow(missing_docs)]
pub enum AtomOp {
    Add,
    Min,
    Max,
    Inc,
    Dec,
    Exch,
    Cas,
    And,
    Or,
    Xor,
}

/// `vote.sync` modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum VoteMode {
    All,
    Any,
    Uni,
    Ballot,
}

/// `shfl.sync` modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ShflMode {
    Up,
    Down,
    Bfly,
    Idx,
}

/// Broad instruction classes, for counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum InstClass {
    /// Integer, logic, moves, conversions and float add/mul/fma.
    Alu,
    /// Special-function unit: transcendental approximations, reciprocals, square roots.
    Sfu,
    /// Loads, stores and atomics.
    Memory,
    /// Branches, calls, returns, exits, barriers.
    Control,
    /// Warp-level communication: votes and shuffles.
    Warp,
}

/// One decoded instruction. Operand names follow PTX: `d` destination, `a`, `b`, `c`
/// sources in order, `p`/`q` predicate destinations.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub enum Kind {
    /// `mov` of data (also `cvta` between equal windows is not this).
    Mov { d: Dst, a: Src },
    /// `mov.bN d, {a, b, ...}`: concatenate `parts` of `part_bits` each, lowest first.
    Pack { d: Dst, parts: Vec<Src>, part_bits: u32 },
    /// `mov.bN {a, b, ...}, s`: split.
    Unpack { ds: Vec<Dst>, a: Src, part_bits: u32 },
    /// Arithmetic on `ty`.
    Arith { op: ArithOp, ty: Ty, mode: FloatMode, d: Dst, a: Src, b: Src, c: Src },
    /// `setp.cmp[.bool].ty p[|q], a, b[, c]`.
    Setp { cmp: Cmp, ty: Ty, p: PredId, q: Option<PredId>, a: Src, b: Src, comb: Option<(BoolOp, PredSrc)>, ftz: bool },
    /// `set.cmp[.bool].dty.sty d, a, b[, c]`.
    Set { cmp: Cmp, dty: Ty, sty: Ty, d: Dst, a: Src, b: Src, comb: Option<(BoolOp, PredSrc)>, ftz: bool },
    /// `bfi.ty d, a, b, c, e`: insert `e` bits of `a` into `b` at position `c`.
    Bfi { ty: Ty, d: Dst, a: Src, b: Src, c: Src, e: Src },
    /// `selp.ty d, a, b, p`.
    Selp { d: Dst, a: Src, b: Src, p: PredSrc },
    /// Predicate logic: `and/or/xor.pred d, a, b` (`op = None` with `b` ignored is `mov`/`not`).
    PredLogic { op: Option<BoolOp>, d: PredId, a: PredSrc, b: PredSrc },
    /// `cvt.[rnd][.ftz][.sat].dty.sty d, a`.
    Cvt { dty: Ty, sty: Ty, mode: FloatMode, d: Dst, a: Src },
    /// `cvta[.to].space.size d, a`.
    Cvta { to_generic: bool, space: MemSpace, d: Dst, a: Src },
    /// `ld`: `vec` elements of `ty` into `ds`.
    Ld { space: MemSpace, ty: Ty, ds: Vec<Dst>, addr: Address, nc: bool, volatile: bool },
    /// `st`: `vals` of `ty`.
    St { space: MemSpace, ty: Ty, vals: Vec<Src>, addr: Address, volatile: bool },
    /// `atom`/`red` (`d == None` for `red`).
    Atom { space: MemSpace, op: AtomOp, ty: Ty, d: Option<Dst>, addr: Address, b: Src, c: Src },
    /// `bra target` (an instruction index); `uni` as written.
    Bra { target: u32, uni: bool },
    /// `call` of a function: copy `args` (caller offset → callee offset, size) in, `rets` back.
    Call { func: u32, args: Vec<(u32, u32, u32)>, rets: Vec<(u32, u32, u32)> },
    /// `call` through a register holding a function's address ([`func_addr`]),
    /// with a `.callprototype`: `args` (caller offset, size) are copied into the
    /// called function's parameters in order, its return parameters into `rets`.
    CallIndirect { target: Src, args: Vec<(u32, u32)>, rets: Vec<(u32, u32)> },
    /// `tex.geom.v4.dty.cty d, [handle, {coords}]`, or with `gather` the
    /// component of `tld4.comp.2d` (0 r, 1 g, 2 b, 3 a).
    Tex { geom: TexGeom, gather: Option<u8>, dty: Ty, cty: Ty, ds: Vec<Dst>, handle: Src, coords: Vec<Src> },
    /// `txq.query.b32 d, [handle]`.
    Txq { query: TxqQuery, d: Dst, handle: Src },
    /// `suld.b.geom[.vec].ty.clamp d, [handle, {coords}]` (x in bytes).
    Suld { geom: TexGeom, ty: Ty, ds: Vec<Dst>, handle: Src, coords: Vec<Src>, clamp: SurfClamp },
    /// `sust.b.geom[.vec].ty.clamp [handle, {coords}], vals`; with `red`,
    /// `sured.b.op.geom.ty.clamp [handle, {coords}], val`: the operation on
    /// the element in place (a global atomic without a result).
    Sust { geom: TexGeom, ty: Ty, vals: Vec<Src>, handle: Src, coords: Vec<Src>, clamp: SurfClamp, red: Option<AtomOp> },
    /// `ret`
    Ret,
    /// `exit`
    Exit,
    /// `bar.sync id[, count]` / `barrier.sync`.
    Bar { id: Src, count: Option<Src> },
    /// `bar.warp.sync membermask`: the member lanes of the warp synchronise;
    /// what they did before it happens before what they do after (PTX orders
    /// their memory accesses). The emulator's lanes already run together, so
    /// it only tells the race checker.
    WarpSync { membermask: Src },
    /// `bar.red.op id[, count], a`: a barrier that also reduces predicate `a`
    /// over the CTA's arriving threads; `.popc` writes the count to `d`,
    /// `.and`/`.or` write predicate `p`.
    BarRed { op: BarRedOp, d: Option<Dst>, p: PredId, id: Src, count: Option<Src>, a: PredSrc },
    /// `vote.sync.mode`: a ballot writes `d`, the others write predicate `p`.
    Vote { mode: VoteMode, d: Option<Dst>, p: PredId, a: PredSrc, membermask: Src },
    /// `shfl.sync.mode.b32 d[|p], a, b, c, membermask`.
    Shfl { mode: ShflMode, d: Dst, p: Option<PredId>, a: Src, b: Src, c: Src, membermask: Src },
    /// `redux.sync.op.ty d, a, membermask`: the operation over the member lanes' `a`.
    Redux { op: ReduxOp, ty: Ty, d: Dst, a: Src, membermask: Src },
    /// `match.any.sync.ty d, a, membermask` (the lanes holding the same
    /// value), or `match.all` (all members or none; `p`: whether all agree).
    Match { all: bool, ty: Ty, d: Dst, p: Option<PredId>, a: Src, membermask: Src },
    /// A carry-chain instruction: `cin` reads the condition code `cc` (a
    /// register the front end adds), `cout` writes it.
    Carry { op: CarryOp, cin: bool, cout: bool, ty: Ty, d: Dst, a: Src, b: Src, c: Src, cc: RegId },
    /// `membar` / `fence`.
    Membar,
    /// An instruction with no effect in the model (`prefetch`, `pmevent`...).
    Nop,
    /// `trap`: a fault.
    Trap,
}

impl Kind {
    /// The data registers the instruction reads (its sources, address bases,
    /// member masks and carry flag), in operand order; predicates are not data.
    /// Taken from [`Kind::visit_regs_mut`], the one list of every
    /// instruction's register fields.
    pub fn reads(&self) -> Vec<RegId> {
        let mut v = Vec::new();
        self.clone().visit_regs_mut(&mut |r, read, _| {
            if read {
                v.push(*r)
            }
        });
        v
    }

    /// The data registers the instruction writes (destinations, and the
    /// condition code of a carry-out), in operand order; the `_` sink is not
    /// one. Taken from [`Kind::visit_regs_mut`].
    pub fn writes(&self) -> Vec<RegId> {
        let mut v = Vec::new();
        self.clone().visit_regs_mut(&mut |r, _, written| {
            if written {
                v.push(*r)
            }
        });
        v
    }

    /// The predicate registers the instruction writes (`setp`'s `p` and `q`,
    /// predicate logic, `vote`'s and `bar.red`'s predicate, `shfl`'s and
    /// `match.all`'s `p`; not the constant predicates, which stand for an
    /// absent one). Predicates are not data registers, so
    /// [`Kind::visit_regs_mut`] does not visit them; this is their one list.
    pub fn pred_writes(&self) -> Vec<PredId> {
        let written: Vec<PredId> = match self {
            Kind::Setp { p, q, .. } => std::iter::once(*p).chain(*q).collect(),
            Kind::PredLogic { d, .. } => vec![*d],
            Kind::Vote { p, .. } | Kind::BarRed { p, .. } => vec![*p],
            Kind::Shfl { p, .. } | Kind::Match { p, .. } => p.iter().copied().collect(),
            Kind::Mov { .. }
            | Kind::Pack { .. }
            | Kind::Unpack { .. }
            | Kind::Arith { .. }
            | Kind::Set { .. }
            | Kind::Bfi { .. }
            | Kind::Selp { .. }
            | Kind::Cvt { .. }
            | Kind::Cvta { .. }
            | Kind::Ld { .. }
            | Kind::St { .. }
            | Kind::Atom { .. }
            | Kind::Bra { .. }
            | Kind::Call { .. }
            | Kind::CallIndirect { .. }
            | Kind::Tex { .. }
            | Kind::Txq { .. }
            | Kind::Suld { .. }
            | Kind::Sust { .. }
            | Kind::Ret
            | Kind::Exit
            | Kind::Bar { .. }
            | Kind::WarpSync { .. }
            | Kind::Redux { .. }
            | Kind::Carry { .. }
            | Kind::Membar
            | Kind::Nop
            | Kind::Trap => Vec::new(),
        };
        // the constants `false`/`true` stand for an absent predicate (a sink)
        written.into_iter().filter(|&p| p != PRED_FALSE && p != PRED_TRUE).collect()
    }

    /// Calls `f(reg, read, written)` exactly once for every data-register
    /// field of the instruction: sources, address bases, member masks,
    /// destinations and the carry flag (read as [`Kind::reads`] counts it,
    /// written when the instruction sets it). The `_` sink is not a register
    /// and is not visited. Register allocation renames registers through it
    /// and takes the instruction's uses and definitions from it.
    pub fn visit_regs_mut(&mut self, f: &mut dyn FnMut(&mut RegId, bool, bool)) {
        let s = |x: &mut Src, f: &mut dyn FnMut(&mut RegId, bool, bool)| {
            if let Src::Reg(r) = x {
                f(r, true, false)
            }
        };
        let d = |x: &mut Dst, f: &mut dyn FnMut(&mut RegId, bool, bool)| {
            if x.reg != Dst::SINK {
                f(&mut x.reg, false, true)
            }
        };
        match self {
            Kind::Mov { d: x, a } | Kind::Cvt { d: x, a, .. } | Kind::Cvta { d: x, a, .. } => {
                s(a, f);
                d(x, f)
            }
            Kind::Pack { d: x, parts, .. } => {
                parts.iter_mut().for_each(|p| s(p, f));
                d(x, f)
            }
            Kind::Unpack { ds, a, .. } => {
                s(a, f);
                ds.iter_mut().for_each(|x| d(x, f))
            }
            Kind::Arith { d: x, a, b, c, .. } => {
                [a, b, c].into_iter().for_each(|y| s(y, f));
                d(x, f)
            }
            Kind::Setp { a, b, .. } => [a, b].into_iter().for_each(|y| s(y, f)),
            Kind::Set { d: x, a, b, .. } | Kind::Selp { d: x, a, b, .. } => {
                [a, b].into_iter().for_each(|y| s(y, f));
                d(x, f)
            }
            Kind::Bfi { d: x, a, b, c, e, .. } => {
                [a, b, c, e].into_iter().for_each(|y| s(y, f));
                d(x, f)
            }
            Kind::Ld { ds, addr, .. } => {
                s(&mut addr.base, f);
                ds.iter_mut().for_each(|x| d(x, f))
            }
            Kind::St { vals, addr, .. } => {
                vals.iter_mut().for_each(|v| s(v, f));
                s(&mut addr.base, f)
            }
            Kind::Atom { d: x, addr, b, c, .. } => {
                [&mut addr.base, b, c].into_iter().for_each(|y| s(y, f));
                x.iter_mut().for_each(|x| d(x, f))
            }
            Kind::Bar { id, count } => {
                s(id, f);
                count.iter_mut().for_each(|c| s(c, f))
            }
            Kind::BarRed { d: x, id, count, .. } => {
                s(id, f);
                count.iter_mut().for_each(|c| s(c, f));
                x.iter_mut().for_each(|x| d(x, f))
            }
            Kind::Vote { d: x, membermask, .. } => {
                s(membermask, f);
                x.iter_mut().for_each(|x| d(x, f))
            }
            Kind::WarpSync { membermask } => s(membermask, f),
            Kind::Shfl { d: x, a, b, c, membermask, .. } => {
                [a, b, c, membermask].into_iter().for_each(|y| s(y, f));
                d(x, f)
            }
            Kind::Redux { d: x, a, membermask, .. } | Kind::Match { d: x, a, membermask, .. } => {
                [a, membermask].into_iter().for_each(|y| s(y, f));
                d(x, f)
            }
            Kind::Carry { d: x, a, b, c, cc, cout, .. } => {
                [a, b, c].into_iter().for_each(|y| s(y, f));
                d(x, f);
                f(cc, true, *cout)
            }
            Kind::CallIndirect { target, .. } => s(target, f),
            Kind::Tex { ds, handle, coords, .. } | Kind::Suld { ds, handle, coords, .. } => {
                s(handle, f);
                coords.iter_mut().for_each(|c| s(c, f));
                ds.iter_mut().for_each(|x| d(x, f))
            }
            Kind::Txq { d: x, handle, .. } => {
                s(handle, f);
                d(x, f)
            }
            Kind::Sust { vals, handle, coords, .. } => {
                s(handle, f);
                coords.iter_mut().for_each(|c| s(c, f));
                vals.iter_mut().for_each(|v| s(v, f))
            }
            Kind::PredLogic { .. }
            | Kind::Bra { .. }
            | Kind::Call { .. }
            | Kind::Ret
            | Kind::Exit
            | Kind::Membar
            | Kind::Nop
            | Kind::Trap => {}
        }
    }
}

/// One instruction with its guard.
#[derive(Debug, Clone, PartialEq)]
pub struct Inst {
    /// `@p` / `@!p`; `None` when unguarded.
    pub guard: Option<PredSrc>,
    /// What it does.
    pub kind: Kind,
}

/// A CUDA source position from `.loc`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub struct SrcLoc {
    /// Index into [`Program::files`].
    pub file: u32,
    /// 1-based line (0 = compiler-generated).
    pub line: u32,
    /// 1-based column.
    pub col: u32,
}

/// Where an instruction came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstInfo {
    /// Line in the PTX file.
    pub ptx_line: u32,
    /// Column in the PTX file.
    pub ptx_col: u32,
    /// CUDA source position from the last `.loc`.
    pub src: Option<SrcLoc>,
    /// The opcode as written, e.g. `ld.global.nc.f32`.
    pub opcode: String,
    /// Its class, for counters.
    pub class: InstClass,
}

/// A kernel parameter or function parameter.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Param {
    /// Its name.
    pub name: String,
    /// Its type (`.b8` arrays keep `B8` with `size` > 1).
    pub ty: Ty,
    /// Byte offset in the parameter area.
    pub offset: u32,
    /// Size in bytes.
    pub size: u32,
}

/// A lowered function or kernel.
#[derive(Debug, Clone)]
pub struct Function {
    /// Its name.
    pub name: String,
    /// True for `.entry`.
    pub is_entry: bool,
    /// Parameters with offsets (kernel param area for entries, frame area otherwise).
    pub params: Vec<Param>,
    /// Return parameters (frame area).
    pub returns: Vec<Param>,
    /// Size of the per-thread frame parameter area (formals, returns, call arguments).
    pub frame_param_size: u32,
    /// Size of the kernel parameter area (entries only).
    pub kernel_param_size: u32,
    /// Bytes of local memory of one frame.
    pub local_size: u32,
    /// Alignment of the local frame.
    pub local_align: u32,
    /// Width mask of each data register.
    pub reg_masks: Vec<u64>,
    /// Register names, for inspection.
    pub reg_names: Vec<String>,
    /// Number of predicate registers including the two constants.
    pub num_preds: u16,
    /// Predicate register names (index 0, 1 are `false`, `true`).
    pub pred_names: Vec<String>,
    /// The instructions.
    pub insts: Vec<Inst>,
    /// Source information, parallel to `insts`.
    pub info: Vec<InstInfo>,
    /// Labels and their instruction indices.
    pub labels: Vec<(String, u32)>,
    /// 32-bit registers the PTX declares (a `.b64` counts two), for occupancy.
    pub declared_reg_words: u32,
    /// Offsets of the shared variables the function names itself (callees not included).
    pub shared_refs: Vec<u32>,
    /// The instructions (ascending) whose moved value (`mov`, `cvta`) or
    /// address base is a shared variable's name: their [`Src::Imm`] is that
    /// variable's offset in warplight's layout, not a number written in the
    /// PTX (which the IR does not tell apart).
    pub shared_symbols: Vec<u32>,
    /// Why the function cannot run, when it (or a function it calls) holds an
    /// instruction warplight does not execute: the module still loads, and only
    /// a launch of this kernel fails, with this error (file, line, instruction).
    /// In the body a `trap` stands in place of each unsupported instruction.
    pub unsupported: Option<PtxError>,
}

/// A module-scope `.global` variable.
#[derive(Debug, Clone)]
pub struct GlobalVar {
    /// Its name.
    pub name: String,
    /// Size in bytes.
    pub size: u64,
    /// Alignment.
    pub align: u32,
    /// Initial contents (zeros when absent).
    pub init: Vec<u8>,
}

/// A shared variable's placement.
#[derive(Debug, Clone)]
pub struct SharedVar {
    /// Its name.
    pub name: String,
    /// Offset in the CTA's shared memory.
    pub offset: u32,
    /// Size in bytes (0 for the dynamic `extern` array).
    pub size: u32,
    /// Alignment in bytes (`.align`, else the element size).
    pub align: u32,
    /// The function whose body declares it (index into
    /// [`Program::functions`]); `None` at module scope.
    pub scope: Option<u32>,
}

/// A shared variable in ptxas's layout of one kernel
/// ([`Program::kernel_shared_layout`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SharedPlace {
    /// The variable (index into [`Program::shared_vars`]).
    pub var: usize,
    /// Its offset in the kernel's layout (warplight's own is [`SharedVar::offset`]).
    pub offset: u32,
}

/// A complete validated module.
#[derive(Debug, Clone)]
pub struct Program {
    /// Name of the PTX file it came from.
    pub source_name: String,
    /// The PTX source lines, for listings.
    pub ptx_lines: Vec<String>,
    /// `.target` words.
    pub target: Vec<String>,
    /// `.version`.
    pub version: String,
    /// Files of `.loc` (index = [`SrcLoc::file`]).
    pub files: Vec<String>,
    /// Functions and kernels.
    pub functions: Vec<Function>,
    /// Module `.global` variables.
    pub globals: Vec<GlobalVar>,
    /// The `.const` bank image.
    pub const_bank: Vec<u8>,
    /// Module `.const` variables: name, offset in the bank and size in bytes.
    pub const_vars: Vec<(String, u32, u32)>,
    /// Shared variables with offsets.
    pub shared_vars: Vec<SharedVar>,
    /// Static shared memory per CTA in bytes (dynamic shared starts here, 16-aligned).
    pub static_shared_size: u32,
}

impl Program {
    /// Finds a kernel (an `.entry`) by name.
    pub fn kernel(&self, name: &str) -> Option<u32> {
        let exact = self.functions.iter().position(|f| f.is_entry && f.name == name);
        // a C++ kernel by its plain name (`saxpy` for `_Z5saxpyifPfS_`), when only one has it
        let plain = || {
            let mut m = self
                .functions
                .iter()
                .enumerate()
                .filter(|(_, f)| f.is_entry && demangle(&f.name).as_deref() == Some(name));
            match (m.next(), m.next()) {
                (Some((i, _)), None) => Some(i),
                _ => None,
            }
        };
        exact.or_else(plain).map(|i| i as u32)
    }

    /// The instructions that `.loc` places in the CUDA source `source_file`
    /// (a suffix of a `.file` path, the first file that has it), in function
    /// and pc order: (function index, pc, the instruction's info, its source
    /// line). Nothing when no file has the suffix.
    pub fn located_in<'a>(&'a self, source_file: &str) -> impl Iterator<Item = (usize, usize, &'a InstInfo, u32)> + 'a {
        let file = self.files.iter().position(|f| f.ends_with(source_file));
        self.functions.iter().enumerate().flat_map(move |(f, func)| {
            func.info.iter().enumerate().filter_map(move |(pc, info)| {
                let s = info.src?;
                (Some(s.file as usize) == file).then_some((f, pc, info, s.line))
            })
        })
    }

    /// Static shared memory `kernel` itself needs in bytes: the end of its
    /// layout ([`Program::kernel_shared_layout`]). The emulator still gives
    /// every CTA the whole module layout ([`Program::static_shared_size`]);
    /// this is the figure for occupancy.
    pub fn kernel_shared_size(&self, kernel: u32) -> u32 {
        let layout = self.kernel_shared_layout(kernel);
        layout.iter().map(|p| p.offset.saturating_add(self.shared_vars[p.var].size)).max().unwrap_or(0)
    }

    /// ptxas's layout of `kernel`'s static shared memory: only the variables
    /// it or a function it calls (transitively) names, each at its own
    /// alignment from 0, in this order: the kernel's own function-scope
    /// variables, then the module-scope ones, then its callees'
    /// function-scope ones, each group in declaration order. ptxas 13.5
    /// (`-arch=sm_90`) knows these offsets when it vectorises
    /// (`src/model/vectorize.rs`; `tests/fixtures/validation/vectorize_*.sass`,
    /// `docs/validation.md`, "Vectorisation: the alignment rule").
    pub fn kernel_shared_layout(&self, kernel: u32) -> Vec<SharedPlace> {
        let taken = self.address_taken();
        let mut offsets = std::collections::BTreeSet::new();
        for f in self.reachable(kernel, &taken) {
            offsets.extend(self.functions[f as usize].shared_refs.iter().copied());
        }
        let group = |v: &SharedVar| match v.scope {
            Some(f) if f == kernel => 0,
            None => 1,
            Some(_) => 2,
        };
        let mut used: Vec<usize> = (0..self.shared_vars.len())
            .filter(|&i| self.shared_vars[i].size > 0 && offsets.contains(&self.shared_vars[i].offset))
            .collect();
        // stable: declaration order within each group
        used.sort_by_key(|&i| group(&self.shared_vars[i]));
        let mut end = 0u32;
        used.into_iter()
            .map(|var| {
                let v = &self.shared_vars[var];
                let offset = end.div_ceil(v.align.max(1)).saturating_mul(v.align.max(1));
                end = offset.saturating_add(v.size);
                SharedPlace { var, offset }
            })
            .collect()
    }

    /// `f` and every function it calls, transitively (ascending);
    /// `address_taken`: [`Program::address_taken`].
    pub fn reachable(&self, f: u32, address_taken: &[u32]) -> Vec<u32> {
        let mut seen = vec![false; self.functions.len()];
        let mut todo = vec![f as usize];
        while let Some(g) = todo.pop() {
            if g >= seen.len() || std::mem::replace(&mut seen[g], true) {
                continue;
            }
            todo.extend(self.callees(g as u32, address_taken).into_iter().map(|c| c as usize));
        }
        (0..seen.len() as u32).filter(|&g| seen[g as usize]).collect()
    }

    /// The functions whose address the module takes (`mov.u64 %rd, f;`, or a
    /// function's name in a variable's initializer): those an indirect call
    /// may reach. Found from the values themselves ([`func_at`]): every
    /// immediate operand, and every 8 bytes of the module variables' and the
    /// constant bank's initial values.
    pub fn address_taken(&self) -> Vec<u32> {
        let n = self.functions.len();
        let mut taken = vec![false; n];
        let mut see = |v: u64| {
            if let Some(f) = func_at(v, n) {
                taken[f as usize] = true;
            }
        };
        for f in &self.functions {
            for i in &f.insts {
                let mut imm = |s: &Src| {
                    if let Src::Imm(v) = s {
                        see(*v)
                    }
                };
                match &i.kind {
                    Kind::Mov { a, .. } | Kind::Cvt { a, .. } | Kind::Cvta { a, .. } => imm(a),
                    Kind::Selp { a, b, .. } => [a, b].into_iter().for_each(imm),
                    Kind::Arith { a, b, c, .. } => [a, b, c].into_iter().for_each(imm),
                    Kind::St { vals, .. } => vals.iter().for_each(imm),
                    Kind::Pack { parts, .. } => parts.iter().for_each(imm),
                    Kind::CallIndirect { target, .. } => imm(target),
                    _ => {}
                }
            }
        }
        for bytes in self.globals.iter().map(|g| &g.init[..]).chain([&self.const_bank[..]]) {
            for w in bytes.windows(8) {
                see(u64::from_le_bytes(w.try_into().expect("8 bytes")));
            }
        }
        (0..n as u32).filter(|&f| taken[f as usize]).collect()
    }

    /// The functions `f` may call: its direct calls' targets and, when it
    /// makes an indirect call, every function in `address_taken`
    /// ([`Program::address_taken`]) — which of them a register holds is
    /// known only at run time, so each is assumed reachable.
    pub fn callees(&self, f: u32, address_taken: &[u32]) -> Vec<u32> {
        let Some(func) = self.functions.get(f as usize) else { return Vec::new() };
        let mut out: Vec<u32> = Vec::new();
        let mut indirect = false;
        for i in &func.insts {
            match i.kind {
                Kind::Call { func, .. } => out.push(func),
                Kind::CallIndirect { .. } => indirect = true,
                _ => {}
            }
        }
        if indirect {
            out.extend_from_slice(address_taken);
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Why kernel (or function) `k` cannot run, when it needs an instruction
    /// warplight does not execute; `None` when it can.
    pub fn kernel_error(&self, k: u32) -> Option<&super::error::PtxError> {
        self.functions.get(k as usize).and_then(|f| f.unsupported.as_ref())
    }

    /// The function that holds the instruction kernel `k` cannot run (`k`
    /// itself, or a function it calls), when there is one.
    pub fn unsupported_in(&self, k: u32) -> Option<&str> {
        let e = self.kernel_error(k)?;
        let holds = |f: &&Function| {
            f.unsupported.as_ref() == Some(e)
                && f.insts.iter().zip(&f.info).any(|(i, inf)| i.kind == Kind::Trap && inf.ptx_line == e.pos.line)
        };
        let own = self.functions.get(k as usize).filter(holds);
        own.or_else(|| self.functions.iter().find(holds)).map(|f| f.name.as_str())
    }

    /// Names of all kernels (as in the PTX; C++ kernels mangled).
    pub fn kernel_names(&self) -> Vec<&str> {
        self.functions.iter().filter(|f| f.is_entry).map(|f| f.name.as_str()).collect()
    }
}

/// The plain name of an Itanium-mangled function name (`_Z5saxpyifPfS_` →
/// `saxpy`), or `None` for names that are not mangled (`extern "C"` kernels).
pub fn demangle(name: &str) -> Option<String> {
    let rest = name.strip_prefix("_Z")?;
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    let n: usize = digits.parse().ok()?;
    rest.get(digits.len()..digits.len() + n).map(str::to_string)
}
