//! The executable form of a module, decoded once when it is loaded: for every
//! instruction, what the executor would otherwise work out on every issue —
//! its guard, its counter class and, for the frequent forms, the operation
//! with its operands resolved to frame slots and constants (an [`Exec`]):
//! arithmetic as the 32-lane function that the `(operation, type, rounding)`
//! triple selects, `mov`, `selp`, `setp`, `bra`, `ld` and `st`. The executor
//! looks the instruction's [`Op`] (32 bytes, no `Vec`: a test guards the
//! size) up by PC and dispatches on it; the other forms ([`Exec::Ir`]) are
//! interpreted from a copy of the IR instructions whose registers are renamed
//! to frame slots ([`regalloc`](super::regalloc): a frame holds the live
//! maximum of rows, not one per virtual register).
//!
//! Registers of 32 bits or fewer live in narrow rows of 32-bit lanes. An
//! arithmetic, `cvt`, `mov`, `selp` or `setp` whose destination and register
//! operands are all narrow gets a narrow form ([`Exec::Lanes32`],
//! [`Exec::Mov32`], [`Exec::Selp32`], [`Exec::Setp32`]), which reads and
//! writes 32-bit lanes (half the bytes); the others read a narrow operand
//! zero-extended and truncate a narrow result, which is what a wide row
//! would have held.

use std::collections::HashMap;

use crate::ptx::ir::{
    Address, ArithOp, Cmp, Dst, FloatMode, Inst, InstClass, Kind, MemSpace, PRED_FALSE, PRED_TRUE, PredId, PredSrc,
    Program, RegId, Rounding, Src,
};
use crate::ptx::types::Ty;

use super::alu;
use super::cfg::Cfg;
use super::contract::{self, Fused};
use super::regalloc::Allocation;
use super::sfu::{self, SfuModel};

/// 32 lanes of register bits.
pub type Lanes = [u64; 32];

/// 32 lanes of a narrow row (registers of 32 bits or fewer).
pub type Lanes32 = [u32; 32];

/// A lane's word: `u64` in wide rows, `u32` in narrow ones. A narrow row
/// holds what a wide one would, truncated: register values of 32 bits or
/// fewer are zero-extended in wide rows.
pub trait Word:
    Copy + Default + std::ops::BitAnd<Output = Self> + std::ops::BitOr<Output = Self> + std::ops::Not<Output = Self>
{
    /// Lane functions of 64-bit results exist for this word.
    const WIDE: bool;
    /// `x` truncated to the word.
    fn of(x: u64) -> Self;
    /// The word zero-extended.
    fn wide(self) -> u64;
}

impl Word for u64 {
    const WIDE: bool = true;
    #[inline(always)]
    fn of(x: u64) -> u64 {
        x
    }
    #[inline(always)]
    fn wide(self) -> u64 {
        self
    }
}

impl Word for u32 {
    const WIDE: bool = false;
    #[inline(always)]
    fn of(x: u64) -> u32 {
        x as u32
    }
    #[inline(always)]
    fn wide(self) -> u64 {
        self as u64
    }
}

/// An arithmetic operation over 32 lanes of words `W` with its type and
/// modifiers resolved: `f(a, b, c, out)` writes every lane of `out`.
pub type LaneFnOf<W> = fn(&[W; 32], &[W; 32], &[W; 32], &mut [W; 32]);

/// A lane function over wide rows.
pub type LaneFn = LaneFnOf<u64>;

/// A lane function over narrow rows: the wide function's result truncated
/// to 32 bits, for operands zero-extended from 32 bits (registers) or
/// truncated to them (constants: every narrow function reads only its
/// operands' low 32 bits).
pub type LaneFn32 = LaneFnOf<u32>;

/// A source operand of a compact instruction: a frame slot (below
/// [`CONST`]), or row `o - CONST` of the function's constant table
/// ([`FnCode::consts`]: an immediate broadcast to 32 lanes, so that reading
/// it borrows a row as reading a register does).
pub type Opnd = u16;

/// The first constant operand.
pub const CONST: Opnd = 0x8000;

/// A destination of a compact instruction: a frame slot ([`Dest::SINK`]
/// discards the value) and the register's width in bits (results are
/// truncated to it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dest {
    /// Frame slot.
    pub slot: u16,
    /// Declared width.
    pub bits: u8,
}

impl Dest {
    /// The `_` sink.
    pub const SINK: u16 = u16::MAX;

    /// All-ones in the register's width.
    #[inline(always)]
    pub fn mask(self) -> u64 {
        width_mask(self.bits)
    }

    /// The compact form of `d`, when its mask is a width's.
    fn of(d: Dst) -> Option<Dest> {
        let bits = (64 - d.mask.leading_zeros()) as u8;
        if width_mask(bits) != d.mask {
            return None;
        }
        let slot = if d.reg == Dst::SINK { Dest::SINK } else { Some(d.reg).filter(|&s| s < CONST)? };
        Some(Dest { slot, bits })
    }
}

#[inline(always)]
fn width_mask(bits: u8) -> u64 {
    if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 }
}

/// What an instruction does, with operands resolved (24 bytes).
#[derive(Debug, Clone, Copy)]
pub enum Exec {
    /// Interpreted from the IR instruction ([`FnCode::insts`]).
    Ir,
    /// An `add`/`sub` contracted with a `mul` that no lane function
    /// covers: interpreted from [`FnCode::fused`].
    Fused,
    /// `d = f(a, b, c)`: arithmetic, and `add`/`sub` contracted with a `mul`
    /// (an FMA with the signs folded in). `c` is `a` when `f` does not read it.
    Lanes {
        /// The 32-lane function.
        f: LaneFn,
        /// Destination.
        d: Dest,
        /// Sources.
        a: Opnd,
        /// Sources.
        b: Opnd,
        /// Sources.
        c: Opnd,
    },
    /// `mov d, a`.
    Mov {
        /// Destination.
        d: Dest,
        /// Source.
        a: Opnd,
    },
    /// `selp d, a, b, p`.
    Selp {
        /// Destination.
        d: Dest,
        /// Where `p` holds.
        a: Opnd,
        /// Where it does not.
        b: Opnd,
        /// The selector.
        p: PredSrc,
    },
    /// `setp.cmp.ty p|q, a, b` (no combining predicate, not a half pair);
    /// `q` is [`PRED_FALSE`] (never written) when absent.
    Setp {
        /// Comparison.
        cmp: Cmp,
        /// Operand type.
        ty: Ty,
        /// `.ftz`.
        ftz: bool,
        /// Where the comparison goes.
        p: PredId,
        /// Where its negation goes.
        q: PredId,
        /// Sources.
        a: Opnd,
        /// Sources.
        b: Opnd,
    },
    /// `d = f(a, b, c)` on narrow rows: `d` and the register operands are
    /// narrow rows (by index among them), the constants rows of
    /// [`FnCode::consts32`].
    Lanes32 {
        /// The 32-lane function.
        f: LaneFn32,
        /// Destination (narrow index).
        d: Dest,
        /// Sources.
        a: Opnd,
        /// Sources.
        b: Opnd,
        /// Sources.
        c: Opnd,
    },
    /// `mov d, a` on narrow rows.
    Mov32 {
        /// Destination (narrow index).
        d: Dest,
        /// Source.
        a: Opnd,
    },
    /// `selp d, a, b, p` on narrow rows.
    Selp32 {
        /// Destination (narrow index).
        d: Dest,
        /// Where `p` holds.
        a: Opnd,
        /// Where it does not.
        b: Opnd,
        /// The selector.
        p: PredSrc,
    },
    /// `setp` on narrow rows, of a type of 32 bits or fewer.
    Setp32 {
        /// Comparison.
        cmp: Cmp,
        /// Operand type.
        ty: Ty,
        /// `.ftz`.
        ftz: bool,
        /// Where the comparison goes.
        p: PredId,
        /// Where its negation goes.
        q: PredId,
        /// Sources.
        a: Opnd,
        /// Sources.
        b: Opnd,
    },
    /// `bra target`.
    Bra {
        /// Instruction index.
        target: u32,
    },
    /// `ld.space.ty {ds}, [base + offset]`: `n` elements, into destinations
    /// of one width.
    Ld {
        /// Space as written.
        space: MemSpace,
        /// Element type.
        ty: Ty,
        /// Elements (1, 2 or 4).
        n: u8,
        /// `.nc`.
        nc: bool,
        /// 64-bit base.
        wide: bool,
        /// Width of the destinations.
        bits: u8,
        /// Address base.
        base: Opnd,
        /// Byte offset.
        offset: i32,
        /// Destination slots ([`Dest::SINK`] discards).
        ds: [u16; 4],
    },
    /// `st.space.ty [base + offset], {vals}`.
    St {
        /// Space as written.
        space: MemSpace,
        /// Element type.
        ty: Ty,
        /// Elements (1, 2 or 4).
        n: u8,
        /// 64-bit base.
        wide: bool,
        /// Address base.
        base: Opnd,
        /// Byte offset.
        offset: i32,
        /// Values.
        vals: [Opnd; 4],
    },
}

/// One decoded instruction (32 bytes: guarded by a test).
#[derive(Debug, Clone, Copy)]
pub struct Op {
    /// What it does.
    pub exec: Exec,
    /// Its guard; an unguarded instruction has the always-true predicate
    /// ([`PRED_TRUE`]), so the executor evaluates every guard alike.
    pub guard: PredSrc,
    /// Its class, for the class counters.
    pub class: InstClass,
    /// First instruction of a counting block ([`counting_leaders`]): the
    /// executor adds the block's warp and thread counts here, once per entry.
    pub leader: bool,
}

impl Op {
    /// True when the instruction has a guard other than the always-true
    /// predicate (its `pred_on` count differs from its thread count).
    #[inline(always)]
    pub fn guarded(&self) -> bool {
        self.guard.reg != PRED_TRUE || self.guard.neg
    }
}

/// The instructions that start a *counting block*: a run of instructions
/// that a warp, once it issued the first, issues in order with the same
/// active lanes. They are the CFG's leaders (the first instruction, branch
/// targets, the instruction after a branch, `ret`, `exit` or `trap`; every
/// reconvergence point is a branch target's or a fall-through's block), and
/// also the instruction after a `call`, where a callee's `exit` may have
/// removed lanes. Every indirect `call` starts a block too: lanes whose
/// target differs issue it again, each group as its own block entry.
/// Nothing else changes a running path's lanes: divergence
/// and reconvergence happen at branches and at block starts.
pub fn counting_leaders(insts: &[Inst]) -> Vec<bool> {
    let n = insts.len();
    let mut leader = vec![false; n + 1];
    if n > 0 {
        leader[0] = true;
    }
    for (pc, i) in insts.iter().enumerate() {
        match &i.kind {
            Kind::Bra { target, .. } => {
                if let Some(l) = leader.get_mut(*target as usize) {
                    *l = true;
                }
                leader[pc + 1] = true;
            }
            Kind::Ret | Kind::Exit | Kind::Trap | Kind::Call { .. } => leader[pc + 1] = true,
            // lanes calling other targets issue the call again (`call_indirect`)
            Kind::CallIndirect { .. } => {
                leader[pc] = true;
                leader[pc + 1] = true;
            }
            _ => {}
        }
    }
    leader.truncate(n);
    leader
}

/// A function's decoded instructions, parallel to its IR instructions.
#[derive(Debug, Clone)]
pub struct FnCode {
    /// One per instruction.
    pub ops: Vec<Op>,
    /// The IR instructions with every data register renamed to its frame
    /// slot ([`FnCode::alloc`]): what the executor interprets [`Exec::Ir`]
    /// instructions from.
    pub insts: Vec<Inst>,
    /// The constants compact instructions read ([`Opnd`]).
    pub consts: Vec<Lanes>,
    /// The constants the narrow forms read, truncated to 32 bits.
    pub consts32: Vec<Lanes32>,
    /// The `add`/`sub` instructions ptxas would contract with a `mul`, by
    /// index ([`contract`]), operands renamed to slots; empty when
    /// contraction is off.
    pub fused: HashMap<u32, Fused>,
    /// Where each virtual register lives in a frame.
    pub alloc: Allocation,
}

impl FnCode {
    /// Rows of a register frame of this function.
    #[inline]
    pub fn rows(&self) -> usize {
        self.alloc.rows as usize
    }

    /// The (wide, narrow) rows of a register frame of this function.
    #[inline]
    pub fn frame_rows(&self) -> (usize, usize) {
        (self.alloc.wide as usize, (self.alloc.rows - self.alloc.wide) as usize)
    }

    /// The frame row of virtual register `r` (the IR's numbering).
    #[inline]
    pub fn slot(&self, r: RegId) -> usize {
        self.alloc.slot[r as usize] as usize
    }
}

/// Builds a function's constant tables while its instructions are compacted.
#[derive(Default)]
struct Consts {
    rows: Vec<Lanes>,
    index: HashMap<u64, Opnd>,
    rows32: Vec<Lanes32>,
    index32: HashMap<u32, Opnd>,
    /// The first narrow slot ([`Allocation::wide`]).
    wide: u16,
}

impl Consts {
    /// The narrow form's operand of `s` (renamed): a narrow row's index or a
    /// constant truncated to 32 bits; `None` for a wide register and what
    /// [`Consts::opnd`] leaves out.
    fn opnd32(&mut self, s: Src) -> Option<Opnd> {
        match s {
            Src::Reg(r) => Some(r).filter(|&r| r >= self.wide && r < CONST).map(|r| r - self.wide),
            Src::Imm(v) => {
                let v = v as u32;
                if let Some(&o) = self.index32.get(&v) {
                    return Some(o);
                }
                let o = CONST.checked_add(u16::try_from(self.rows32.len()).ok().filter(|&n| n < 0x7FFF)?)?;
                self.rows32.push([v; 32]);
                self.index32.insert(v, o);
                Some(o)
            }
            _ => None,
        }
    }

    /// The narrow form's destination of `d`: a narrow row (by index), not
    /// the sink.
    fn dest32(&self, d: Dst) -> Option<Dest> {
        let d = Dest::of(d)?;
        (d.slot != Dest::SINK && d.slot >= self.wide).then(|| Dest { slot: d.slot - self.wide, bits: d.bits })
    }

    /// The compact operand of `s` (renamed): a slot or a constant row;
    /// `None` for special registers and addresses of variables, which are
    /// interpreted.
    fn opnd(&mut self, s: Src) -> Option<Opnd> {
        match s {
            Src::Reg(r) => Some(r).filter(|&r| r < CONST),
            Src::Imm(v) => {
                if let Some(&o) = self.index.get(&v) {
                    return Some(o);
                }
                let o = CONST.checked_add(u16::try_from(self.rows.len()).ok().filter(|&n| n < 0x7FFF)?)?;
                self.rows.push([v; 32]);
                self.index.insert(v, o);
                Some(o)
            }
            _ => None,
        }
    }
}

/// What the executable form models of the toolchain and the GPU's arithmetic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FloatOptions {
    /// ptxas's FFMA contraction of unrounded `mul` + `add`/`sub` ([`contract`]).
    pub fmad: bool,
    /// How approximate special functions are computed.
    pub sfu: SfuModel,
}

impl Default for FloatOptions {
    /// The H200's: contraction on, the MUFU table model.
    fn default() -> Self {
        FloatOptions { fmad: true, sfu: SfuModel::Sm90 }
    }
}

/// A decoded module.
#[derive(Debug, Clone, Default)]
pub struct Code {
    /// One per function of the program.
    pub funcs: Vec<FnCode>,
    /// How the special functions are computed (interpreted instructions too).
    pub sfu: SfuModel,
}

impl Code {
    /// Decodes every function of `prog`, with `opts` deciding contraction and
    /// the special functions, and registers compacted to their live maximum.
    pub fn decode(prog: &Program, opts: FloatOptions) -> Code {
        Code::decode_with(prog, opts, true)
    }

    /// As [`Code::decode`]; `compact: false` keeps one frame row per virtual
    /// register (every register keeps its last value, for inspection).
    pub fn decode_with(prog: &Program, opts: FloatOptions, compact: bool) -> Code {
        let funcs = prog
            .functions
            .iter()
            .map(|f| {
                let mut fused = if opts.fmad { contract::contract(f) } else { HashMap::new() };
                let alloc =
                    if compact { Allocation::compact(f, &Cfg::build(f), &fused) } else { Allocation::identity(f) };
                let mut insts = f.insts.clone();
                for i in &mut insts {
                    i.kind.visit_regs_mut(&mut |r, _, _| *r = alloc.slot[*r as usize]);
                }
                let rename = |s: &mut Src| {
                    if let Src::Reg(r) = s {
                        *r = alloc.slot[*r as usize];
                    }
                };
                for fz in fused.values_mut() {
                    rename(&mut fz.a);
                    rename(&mut fz.b);
                    rename(&mut fz.c);
                }
                let wide = u16::try_from(alloc.wide).unwrap_or(CONST);
                let mut consts = Consts { wide, ..Consts::default() };
                let leaders = counting_leaders(&insts);
                let ops = insts
                    .iter()
                    .zip(&f.info)
                    .zip(&leaders)
                    .enumerate()
                    .map(|(k, ((i, info), &leader))| {
                        let fz = fused.get(&(k as u32));
                        let exec = narrow_form(i, fz, opts.sfu, &mut consts)
                            .or_else(|| compact_form(i, fz, opts.sfu, &mut consts))
                            .unwrap_or(if fz.is_some() { Exec::Fused } else { Exec::Ir });
                        let guard = i.guard.unwrap_or(PredSrc { reg: PRED_TRUE, neg: false });
                        Op { exec, guard, class: info.class, leader }
                    })
                    .collect();
                FnCode { ops, insts, consts: consts.rows, consts32: consts.rows32, fused, alloc }
            })
            .collect();
        Code { funcs, sfu: opts.sfu }
    }
}

/// The compact form of instruction `i` (registers renamed; `fz`: its
/// contraction with a `mul`, if any), or `None` when it is interpreted.
fn compact_form(i: &Inst, fz: Option<&Fused>, sfu: SfuModel, consts: &mut Consts) -> Option<Exec> {
    Some(match &i.kind {
        Kind::Arith { ty, mode, d, .. } if fz.is_some() => {
            let fz = fz.expect("fused");
            // fma(±a, b, ±c) with the add's modifiers: a lane function for
            // the IEEE default on f32 (`arith::fused` computes the rest)
            if *ty != Ty::F32 || mode.ftz || mode.sat {
                return None;
            }
            let f = fused_fma(fz)?;
            Exec::Lanes { f, d: Dest::of(*d)?, a: consts.opnd(fz.a)?, b: consts.opnd(fz.b)?, c: consts.opnd(fz.c)? }
        }
        Kind::Arith { op, ty, mode, d, a, b, c } => {
            let (f, reads_c) = resolve_arith(*op, *ty, *mode, sfu)?;
            let (d, a, b) = (Dest::of(*d)?, consts.opnd(*a)?, consts.opnd(*b)?);
            Exec::Lanes { f, d, a, b, c: if reads_c { consts.opnd(*c)? } else { a } }
        }
        Kind::Cvt { dty, sty, mode, d, a } => {
            let f = resolve_cvt(*dty, *sty, *mode)?;
            let a = consts.opnd(*a)?;
            Exec::Lanes { f, d: Dest::of(*d)?, a, b: a, c: a }
        }
        Kind::Mov { d, a } => Exec::Mov { d: Dest::of(*d)?, a: consts.opnd(*a)? },
        Kind::Selp { d, a, b, p } => Exec::Selp { d: Dest::of(*d)?, a: consts.opnd(*a)?, b: consts.opnd(*b)?, p: *p },
        Kind::Setp { cmp, ty, p, q, a, b, comb: None, ftz } if !matches!(ty, Ty::F16x2 | Ty::BF16x2) => Exec::Setp {
            cmp: *cmp,
            ty: *ty,
            ftz: *ftz,
            p: *p,
            q: q.unwrap_or(PRED_FALSE),
            a: consts.opnd(*a)?,
            b: consts.opnd(*b)?,
        },
        Kind::Bra { target, .. } => Exec::Bra { target: *target },
        Kind::Ld { space, ty, ds, addr, nc, .. } if matches!(ds.len(), 1 | 2 | 4) => {
            let (base, offset) = address(addr, consts)?;
            let d0 = Dest::of(ds[0])?;
            let mut slots = [Dest::SINK; 4];
            for (s, d) in slots.iter_mut().zip(ds) {
                let d = Dest::of(*d)?;
                if d.bits != d0.bits {
                    return None;
                }
                *s = d.slot;
            }
            Exec::Ld {
                space: *space,
                ty: *ty,
                n: ds.len() as u8,
                nc: *nc,
                wide: addr.wide,
                bits: d0.bits,
                base,
                offset,
                ds: slots,
            }
        }
        Kind::St { space, ty, vals, addr, .. } if matches!(vals.len(), 1 | 2 | 4) => {
            let (base, offset) = address(addr, consts)?;
            let mut vs = [0; 4];
            for (o, v) in vs.iter_mut().zip(vals) {
                *o = consts.opnd(*v)?;
            }
            Exec::St { space: *space, ty: *ty, n: vals.len() as u8, wide: addr.wide, base, offset, vals: vs }
        }
        _ => return None,
    })
}

/// The fma lane function of an `add`/`sub` contracted with a `mul`: signs
/// folded in as `arith::fused` folds them.
fn fused_fma<W: Word>(fz: &Fused) -> Option<LaneFnOf<W>> {
    Some(match (fz.neg_product, fz.neg_c) {
        (false, false) => ffma::<W>,
        (true, false) => ffma_neg_ab::<W>,
        (false, true) => ffma_neg_c::<W>,
        (true, true) => ffma_neg_ab_c::<W>,
    })
}

/// The narrow form of instruction `i` (registers renamed): when its
/// destination and register operands are all narrow rows and the operation
/// has a narrow lane function (which reads its operands' low 32 bits only,
/// so constants may be truncated). `None` otherwise ([`compact_form`]).
fn narrow_form(i: &Inst, fz: Option<&Fused>, sfu: SfuModel, consts: &mut Consts) -> Option<Exec> {
    Some(match &i.kind {
        Kind::Arith { ty, mode, d, .. } if fz.is_some() => {
            let fz = fz.expect("fused");
            if *ty != Ty::F32 || mode.ftz || mode.sat {
                return None;
            }
            let d = consts.dest32(*d)?;
            Exec::Lanes32 {
                f: fused_fma(fz)?,
                d,
                a: consts.opnd32(fz.a)?,
                b: consts.opnd32(fz.b)?,
                c: consts.opnd32(fz.c)?,
            }
        }
        Kind::Arith { op, ty, mode, d, a, b, c } => {
            let (f, reads_c) = resolve_arith_of::<u32>(*op, *ty, *mode, sfu)?;
            let (d, a, b) = (consts.dest32(*d)?, consts.opnd32(*a)?, consts.opnd32(*b)?);
            Exec::Lanes32 { f, d, a, b, c: if reads_c { consts.opnd32(*c)? } else { a } }
        }
        Kind::Cvt { dty, sty, mode, d, a } => {
            let f = resolve_cvt_of::<u32>(*dty, *sty, *mode)?;
            let (d, a) = (consts.dest32(*d)?, consts.opnd32(*a)?);
            Exec::Lanes32 { f, d, a, b: a, c: a }
        }
        Kind::Mov { d, a } => Exec::Mov32 { d: consts.dest32(*d)?, a: consts.opnd32(*a)? },
        Kind::Selp { d, a, b, p } => {
            Exec::Selp32 { d: consts.dest32(*d)?, a: consts.opnd32(*a)?, b: consts.opnd32(*b)?, p: *p }
        }
        // integers and f32 compare their low `bits` bits only
        Kind::Setp { cmp, ty, p, q, a, b, comb: None, ftz }
            if ty.bits() <= 32 && (*ty == Ty::F32 || !ty.is_float()) && !matches!(ty, Ty::Pred) =>
        {
            Exec::Setp32 {
                cmp: *cmp,
                ty: *ty,
                ftz: *ftz,
                p: *p,
                q: q.unwrap_or(PRED_FALSE),
                a: consts.opnd32(*a)?,
                b: consts.opnd32(*b)?,
            }
        }
        _ => return None,
    })
}

/// An address's base operand and its offset, when the offset fits 32 bits.
fn address(a: &Address, consts: &mut Consts) -> Option<(Opnd, i32)> {
    Some((consts.opnd(a.base)?, i32::try_from(a.offset).ok()?))
}

#[inline(always)]
fn map2<W: Word>(a: &[W; 32], b: &[W; 32], out: &mut [W; 32], f: impl Fn(u64, u64) -> u64) {
    for l in 0..32 {
        out[l] = W::of(f(a[l].wide(), b[l].wide()));
    }
}

#[inline(always)]
fn map3<W: Word>(a: &[W; 32], b: &[W; 32], c: &[W; 32], out: &mut [W; 32], f: impl Fn(u64, u64, u64) -> u64) {
    for l in 0..32 {
        out[l] = W::of(f(a[l].wide(), b[l].wide(), c[l].wide()));
    }
}

#[inline(always)]
fn f32of(x: u64) -> f32 {
    f32::from_bits(x as u32)
}

/// An f32 result's bits, NaN made canonical (as `alu` does).
#[inline(always)]
pub fn canon32(x: f32) -> u64 {
    if x.is_nan() { alu::NAN32 as u64 } else { x.to_bits() as u64 }
}

/// `min`/`max` of f32 as `alu::arith` defines them (NaN operands ignored,
/// -0 below +0).
#[inline(always)]
fn minmax32(a: u64, b: u64, max: bool) -> u64 {
    let (x, y) = (f32of(a), f32of(b));
    let r = match (x.is_nan(), y.is_nan()) {
        (true, true) => f32::NAN,
        (true, false) => y,
        (false, true) => x,
        _ if x == y => {
            if (x.is_sign_negative() && !max) || (x.is_sign_positive() && max) {
                x
            } else {
                y
            }
        }
        _ if (x < y) != max => x,
        _ => y,
    };
    canon32(r)
}

macro_rules! lanefn2 {
    ($name:ident, |$x:ident, $y:ident| $e:expr) => {
        fn $name<W: Word>(a: &[W; 32], b: &[W; 32], _c: &[W; 32], out: &mut [W; 32]) {
            map2(a, b, out, |$x, $y| $e)
        }
    };
}

macro_rules! lanefn3 {
    ($name:ident, |$x:ident, $y:ident, $z:ident| $e:expr) => {
        fn $name<W: Word>(a: &[W; 32], b: &[W; 32], c: &[W; 32], out: &mut [W; 32]) {
            map3(a, b, c, out, |$x, $y, $z| $e)
        }
    };
}

lanefn2!(add32, |x, y| (x as u32).wrapping_add(y as u32) as u64);
lanefn2!(add64, |x, y| x.wrapping_add(y));
lanefn2!(sub32, |x, y| (x as u32).wrapping_sub(y as u32) as u64);
lanefn2!(sub64, |x, y| x.wrapping_sub(y));
lanefn2!(mul32, |x, y| (x as u32).wrapping_mul(y as u32) as u64);
lanefn2!(mul64, |x, y| x.wrapping_mul(y));
lanefn2!(and32, |x, y| x & y & 0xFFFF_FFFF);
lanefn2!(or32, |x, y| (x | y) & 0xFFFF_FFFF);
lanefn2!(xor32, |x, y| (x ^ y) & 0xFFFF_FFFF);
lanefn2!(and64, |x, y| x & y);
lanefn2!(or64, |x, y| x | y);
lanefn2!(xor64, |x, y| x ^ y);
lanefn2!(shl32, |x, s| if (s as u32) >= 32 { 0 } else { ((x as u32) << s) as u64 });
lanefn2!(shl64, |x, s| if (s as u32) >= 64 { 0 } else { x << s });
lanefn2!(shr_u32, |x, s| if (s as u32) >= 32 { 0 } else { ((x as u32) >> s) as u64 });
lanefn2!(shr_u64, |x, s| if (s as u32) >= 64 { 0 } else { x >> s });
lanefn2!(shr_s32, |x, s| ((x as i32) >> (s as u32).min(31)) as u32 as u64);
lanefn2!(mul_wide_s32, |x, y| ((x as i32 as i64) * (y as i32 as i64)) as u64);
lanefn2!(mul_wide_u32, |x, y| (x & 0xFFFF_FFFF) * (y & 0xFFFF_FFFF));
lanefn2!(min_s32, |x, y| (x as i32).min(y as i32) as u32 as u64);
lanefn2!(max_s32, |x, y| (x as i32).max(y as i32) as u32 as u64);
lanefn2!(min_u32, |x, y| (x as u32).min(y as u32) as u64);
lanefn2!(max_u32, |x, y| (x as u32).max(y as u32) as u64);
lanefn3!(mad32, |x, y, z| (x as u32).wrapping_mul(y as u32).wrapping_add(z as u32) as u64);
lanefn2!(fadd, |x, y| canon32(f32of(x) + f32of(y)));
lanefn2!(fsub, |x, y| canon32(f32of(x) - f32of(y)));
lanefn2!(fmul, |x, y| canon32(f32of(x) * f32of(y)));
lanefn2!(fdiv, |x, y| canon32(f32of(x) / f32of(y)));
lanefn2!(fmin, |x, y| minmax32(x, y, false));
lanefn2!(fmax, |x, y| minmax32(x, y, true));
lanefn2!(fneg, |x, _y| canon32(-f32of(x)));
lanefn2!(fabs, |x, _y| canon32(f32of(x).abs()));
lanefn2!(frcp, |x, _y| canon32(1.0 / f32of(x)));
lanefn2!(fsqrt, |x, _y| canon32(f32of(x).sqrt()));
lanefn3!(ffma, |x, y, z| canon32(f32of(x).mul_add(f32of(y), f32of(z))));
// an `add`/`sub` contracted with a `mul`: fma with the product's and the
// addend's signs flipped as `arith::fused` flips them
const SIGN32: u64 = 1 << 31;
lanefn3!(ffma_neg_ab, |x, y, z| canon32(f32of(x ^ SIGN32).mul_add(f32of(y), f32of(z))));
lanefn3!(ffma_neg_c, |x, y, z| canon32(f32of(x).mul_add(f32of(y), f32of(z ^ SIGN32))));
lanefn3!(ffma_neg_ab_c, |x, y, z| canon32(f32of(x ^ SIGN32).mul_add(f32of(y), f32of(z ^ SIGN32))));
lanefn2!(mufu_rcp, |x, _y| sfu::rcp(x as u32, false) as u64);
lanefn2!(mufu_rcp_ftz, |x, _y| sfu::rcp(x as u32, true) as u64);
lanefn2!(mufu_rsq, |x, _y| sfu::rsq(x as u32, false, false) as u64);
lanefn2!(mufu_rsq_ftz, |x, _y| sfu::rsq(x as u32, false, true) as u64);
lanefn2!(mufu_sqrt, |x, _y| sfu::rsq(x as u32, true, false) as u64);
lanefn2!(mufu_sqrt_ftz, |x, _y| sfu::rsq(x as u32, true, true) as u64);
lanefn2!(div_approx, |x, y| sfu::div_approx(x as u32, y as u32, false) as u64);
lanefn2!(div_approx_ftz, |x, y| sfu::div_approx(x as u32, y as u32, true) as u64);
lanefn2!(div_full, |x, y| sfu::div_full(x as u32, y as u32, false) as u64);
lanefn2!(div_full_ftz, |x, y| sfu::div_full(x as u32, y as u32, true) as u64);

/// The H200 table model's function of an f32 approximation, when `sfu` asks
/// for it and the form has one (no `.sat`, no rounding modifier).
pub fn resolve_sfu(op: ArithOp, ty: Ty, mode: FloatMode, sfu: SfuModel) -> Option<LaneFn> {
    resolve_sfu_of::<u64>(op, ty, mode, sfu)
}

/// [`resolve_sfu`] over words `W`.
fn resolve_sfu_of<W: Word>(op: ArithOp, ty: Ty, mode: FloatMode, sfu: SfuModel) -> Option<LaneFnOf<W>> {
    if sfu != SfuModel::Sm90 || ty != Ty::F32 || !mode.approx || mode.sat || mode.rnd.is_some() {
        return None;
    }
    Some(match (op, mode.ftz, mode.full) {
        (ArithOp::Rcp, false, _) => mufu_rcp::<W>,
        (ArithOp::Rcp, true, _) => mufu_rcp_ftz::<W>,
        (ArithOp::Rsqrt, false, _) => mufu_rsq::<W>,
        (ArithOp::Rsqrt, true, _) => mufu_rsq_ftz::<W>,
        (ArithOp::Sqrt, false, _) => mufu_sqrt::<W>,
        (ArithOp::Sqrt, true, _) => mufu_sqrt_ftz::<W>,
        (ArithOp::Div, false, false) => div_approx::<W>,
        (ArithOp::Div, true, false) => div_approx_ftz::<W>,
        (ArithOp::Div, false, true) => div_full::<W>,
        (ArithOp::Div, true, true) => div_full_ftz::<W>,
        _ => return None,
    })
}

/// The 32-lane function of an arithmetic instruction whose semantics
/// (`alu::arith`) reduce to a plain operation, and whether it reads `c`;
/// `None` for the other forms, which the executor evaluates lane by lane.
pub fn resolve_arith(op: ArithOp, ty: Ty, mode: FloatMode, sfu: SfuModel) -> Option<(LaneFn, bool)> {
    resolve_arith_of::<u64>(op, ty, mode, sfu)
}

/// [`resolve_arith`] over words `W`: over narrow rows (`u32`) only the
/// forms of 32-bit results, every one of which reads its operands' low 32
/// bits only.
pub fn resolve_arith_of<W: Word>(op: ArithOp, ty: Ty, mode: FloatMode, sfu: SfuModel) -> Option<(LaneFnOf<W>, bool)> {
    use ArithOp as A;
    use Ty as T;
    if let Some(f) = resolve_sfu_of::<W>(op, ty, mode, sfu) {
        return Some((f, false));
    }
    // Round-to-nearest is IEEE's default, so `.rn` and no rounding agree.
    let nearest = matches!(mode.rnd, None | Some(Rounding::Rn)) && !mode.ftz && !mode.sat;
    let int = !mode.sat;
    let wide = W::WIDE;
    let f: LaneFnOf<W> = match (op, ty) {
        (A::Add, T::S32 | T::U32 | T::B32) if int => add32::<W>,
        (A::Add, T::S64 | T::U64 | T::B64) if int && wide => add64::<W>,
        (A::Sub, T::S32 | T::U32 | T::B32) if int => sub32::<W>,
        (A::Sub, T::S64 | T::U64 | T::B64) if int && wide => sub64::<W>,
        (A::Mul, T::S32 | T::U32 | T::B32) => mul32::<W>,
        (A::Mul, T::S64 | T::U64 | T::B64) if wide => mul64::<W>,
        (A::And, T::B32 | T::U32 | T::S32) => and32::<W>,
        (A::Or, T::B32 | T::U32 | T::S32) => or32::<W>,
        (A::Xor, T::B32 | T::U32 | T::S32) => xor32::<W>,
        (A::And, T::B64 | T::U64 | T::S64) if wide => and64::<W>,
        (A::Or, T::B64 | T::U64 | T::S64) if wide => or64::<W>,
        (A::Xor, T::B64 | T::U64 | T::S64) if wide => xor64::<W>,
        (A::Shl, T::B32 | T::U32 | T::S32) => shl32::<W>,
        (A::Shl, T::B64 | T::U64 | T::S64) if wide => shl64::<W>,
        (A::Shr, T::B32 | T::U32) => shr_u32::<W>,
        (A::Shr, T::B64 | T::U64) if wide => shr_u64::<W>,
        (A::Shr, T::S32) => shr_s32::<W>,
        (A::MulWide, T::S32) if wide => mul_wide_s32::<W>,
        (A::MulWide, T::U32) if wide => mul_wide_u32::<W>,
        (A::Min, T::S32) => min_s32::<W>,
        (A::Max, T::S32) => max_s32::<W>,
        (A::Min, T::U32) => min_u32::<W>,
        (A::Max, T::U32) => max_u32::<W>,
        (A::Mad, T::S32 | T::U32 | T::B32) => return Some((mad32::<W>, true)),
        (A::Add, T::F32) if nearest => fadd::<W>,
        (A::Sub, T::F32) if nearest => fsub::<W>,
        (A::Mul, T::F32) if nearest => fmul::<W>,
        (A::Div, T::F32) if nearest => fdiv::<W>,
        (A::Rcp, T::F32) if nearest => frcp::<W>,
        (A::Sqrt, T::F32) if nearest && !mode.approx => fsqrt::<W>,
        (A::Min, T::F32) if !mode.ftz && !mode.sat => fmin::<W>,
        (A::Max, T::F32) if !mode.ftz && !mode.sat => fmax::<W>,
        (A::Neg, T::F32) if !mode.ftz && !mode.sat => fneg::<W>,
        (A::Abs, T::F32) if !mode.ftz && !mode.sat => fabs::<W>,
        (A::Mad, T::F32) if nearest => return Some((ffma::<W>, true)),
        _ => return None,
    };
    Some((f, false))
}

lanefn2!(zext32, |x, _y| x & 0xFFFF_FFFF);
lanefn2!(sext32, |x, _y| x as u32 as i32 as i64 as u64);
lanefn2!(f32_from_s32, |x, _y| (x as u32 as i32 as f32).to_bits() as u64);
lanefn2!(f32_from_u32, |x, _y| (x as u32 as f32).to_bits() as u64);
// `as` truncates toward zero and saturates, NaN to 0: `cvt`'s rules
lanefn2!(s32_floor_f32, |x, _y| f32::from_bits(x as u32).floor() as i32 as i64 as u64);
lanefn2!(s32_trunc_f32, |x, _y| f32::from_bits(x as u32) as i32 as i64 as u64);

/// The 32-lane function of the frequent `cvt` forms (the kernels' index
/// widening and narrowing, integer to float, float to integer rounding
/// down or toward zero): `dty.extend(alu::cvt(dty, sty, mode, a))` per lane,
/// the value the interpreted `cvt` writes. `None` for the rest
/// (saturation, `.ftz`, other types and roundings: interpreted).
pub fn resolve_cvt(dty: Ty, sty: Ty, mode: FloatMode) -> Option<LaneFn> {
    resolve_cvt_of::<u64>(dty, sty, mode)
}

/// [`resolve_cvt`] over words `W`: over narrow rows only the forms of
/// 32-bit results.
pub fn resolve_cvt_of<W: Word>(dty: Ty, sty: Ty, mode: FloatMode) -> Option<LaneFnOf<W>> {
    use Ty as T;
    if mode.sat || mode.ftz {
        return None;
    }
    let int = mode.rnd.is_none();
    let nearest = matches!(mode.rnd, None | Some(Rounding::Rn));
    Some(match (dty, sty) {
        (T::U64 | T::S64 | T::B64, T::U32 | T::B32) if int && W::WIDE => zext32::<W>,
        (T::U64 | T::S64 | T::B64, T::S32) if int && W::WIDE => sext32::<W>,
        (T::U32 | T::B32, T::U64 | T::S64 | T::B64 | T::U32 | T::S32 | T::B32) if int => zext32::<W>,
        (T::S32, T::U64 | T::S64 | T::B64 | T::U32 | T::S32 | T::B32) if int => sext32::<W>,
        (T::F32, T::S32) if nearest => f32_from_s32::<W>,
        (T::F32, T::U32) if nearest => f32_from_u32::<W>,
        (T::S32, T::F32) if mode.rnd == Some(Rounding::Rmi) => s32_floor_f32::<W>,
        (T::S32, T::F32) if mode.rnd == Some(Rounding::Rzi) => s32_trunc_f32::<W>,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f32 operands at the edges, as lane values: signed zeros, NaNs of
    /// both signs, infinities, subnormals of both signs.
    const FLOAT_EDGES: [u64; 8] = [
        0,
        0x8000_0000,
        0x7FC0_0000,
        0xFFC0_0000,
        0x7F80_0000,
        0xFF80_0000,
        0x0001_16C2, // 1e-40
        0x8001_16C2, // -1e-40
    ];

    #[test]
    fn a_decoded_instruction_is_32_bytes() {
        assert_eq!(std::mem::size_of::<Exec>(), 24);
        assert_eq!(std::mem::size_of::<Op>(), 32);
    }

    /// Every resolved function computes what `alu::arith` computes, on
    /// operands chosen to hit the edge cases (NaN, signed zeros, infinities,
    /// subnormals, shifts past the width, sign bits).
    #[test]
    fn resolved_functions_agree_with_the_lane_semantics() {
        let f = |x: f32| x.to_bits() as u64;
        let mut vals: Vec<u64> = vec![
            0,
            1,
            2,
            31,
            32,
            33,
            63,
            64,
            0xFFFF_FFFF,
            0x8000_0000,
            0x7FFF_FFFF,
            u64::MAX,
            0x1234_5678_9ABC_DEF0,
            f(1.5),
            f(-2.25),
            f(3.0e38),
            f(1.0 / 3.0),
        ];
        vals.extend(FLOAT_EDGES);
        let modes = [
            FloatMode::default(),
            FloatMode { rnd: Some(Rounding::Rn), ..FloatMode::default() },
            FloatMode { rnd: Some(Rounding::Rz), ..FloatMode::default() },
            FloatMode { ftz: true, ..FloatMode::default() },
            FloatMode { sat: true, ..FloatMode::default() },
            FloatMode { approx: true, ..FloatMode::default() },
        ];
        let ops = [
            ArithOp::Add,
            ArithOp::Sub,
            ArithOp::Mul,
            ArithOp::MulWide,
            ArithOp::Mad,
            ArithOp::Div,
            ArithOp::Rcp,
            ArithOp::Sqrt,
            ArithOp::Min,
            ArithOp::Max,
            ArithOp::Neg,
            ArithOp::Abs,
            ArithOp::And,
            ArithOp::Or,
            ArithOp::Xor,
            ArithOp::Shl,
            ArithOp::Shr,
        ];
        let tys = [Ty::S32, Ty::U32, Ty::B32, Ty::S64, Ty::U64, Ty::B64, Ty::F32];
        let mut resolved = 0;
        for op in ops {
            for ty in tys {
                for mode in modes {
                    let Some((func, _)) = resolve_arith(op, ty, mode, SfuModel::CorrectlyRounded) else { continue };
                    resolved += 1;
                    for (i, &x) in vals.iter().enumerate() {
                        // 32 lanes: x against every value, c rotating
                        let a: Lanes = [x; 32];
                        let b: Lanes = std::array::from_fn(|l| vals[l % vals.len()]);
                        let c: Lanes = std::array::from_fn(|l| vals[(l + i) % vals.len()]);
                        let mut out = [0; 32];
                        func(&a, &b, &c, &mut out);
                        for l in 0..32 {
                            let want = alu::arith(op, ty, mode, a[l], b[l], c[l]);
                            assert_eq!(
                                out[l], want,
                                "{op:?}.{ty:?} {mode:?} a={:#x} b={:#x} c={:#x}",
                                a[l], b[l], c[l]
                            );
                        }
                    }
                }
            }
        }
        assert!(resolved > 40, "only {resolved} forms resolved");
    }

    /// Every resolved `cvt` form computes what the interpreted `cvt` writes
    /// (`dty.extend(alu::cvt(..))`), on integers at the 32-bit boundaries
    /// with garbage above them and floats at the edges (NaN, infinities,
    /// signed zeros, subnormals, halves, out of the integer range); the
    /// index widening of the ray-tracing kernels is among the forms.
    #[test]
    fn resolved_conversions_agree_with_the_interpreted_cvt() {
        let f = |x: f32| x.to_bits() as u64;
        let vals = [
            0,
            1,
            0x7FFF_FFFF,
            0x8000_0000,
            0xFFFF_FFFF,
            0x1_0000_0000,
            0xDEAD_BEEF_8000_0001,
            u64::MAX,
            16_777_217,
            0x8000_0001,
            f(1.5),
            f(-1.5),
            f(2.5),
            f(-0.5),
            f(3.0e9),
            f(-3.0e9),
            f(2147483520.0),
            f(-2147483648.0),
        ]
        .into_iter()
        .chain(FLOAT_EDGES)
        .collect::<Vec<_>>();
        let tys = [Ty::U32, Ty::S32, Ty::B32, Ty::U64, Ty::S64, Ty::B64, Ty::F32, Ty::F64, Ty::U16, Ty::S16];
        let mut modes = vec![FloatMode::default(), FloatMode { sat: true, ..FloatMode::default() }];
        for r in [
            Rounding::Rn,
            Rounding::Rz,
            Rounding::Rm,
            Rounding::Rp,
            Rounding::Rni,
            Rounding::Rzi,
            Rounding::Rmi,
            Rounding::Rpi,
        ] {
            modes.push(FloatMode { rnd: Some(r), ..FloatMode::default() });
            modes.push(FloatMode { rnd: Some(r), ftz: true, ..FloatMode::default() });
        }
        let mut resolved = vec![];
        for dty in tys {
            for sty in tys {
                for mode in &modes {
                    let Some(func) = resolve_cvt(dty, sty, *mode) else { continue };
                    resolved.push((dty, sty, mode.rnd));
                    let a: Lanes = std::array::from_fn(|l| vals[l % vals.len()]);
                    let b: Lanes = std::array::from_fn(|l| vals[(l + 7) % vals.len()]);
                    for a in [a, b] {
                        let mut out = [0; 32];
                        func(&a, &a, &a, &mut out);
                        for l in 0..32 {
                            let want = dty.extend(alu::cvt(dty, sty, *mode, a[l]));
                            assert_eq!(out[l], want, "cvt{:?}.{dty:?}.{sty:?} a={:#x}", mode.rnd, a[l]);
                        }
                    }
                }
            }
        }
        for form in
            [(Ty::U64, Ty::U32, None), (Ty::F32, Ty::S32, Some(Rounding::Rn)), (Ty::S32, Ty::F32, Some(Rounding::Rmi))]
        {
            assert!(resolved.contains(&form), "{form:?} not resolved");
        }
    }

    /// The lane functions of an `add`/`sub` contracted with a `mul` compute
    /// what the interpreted contraction (`arith::fused`) computes: the f32
    /// fma of `alu::arith` with the product's and the addend's signs flipped.
    #[test]
    fn contracted_lane_functions_agree_with_the_fma_semantics() {
        let f = |x: f32| x.to_bits() as u64;
        let vals = [
            f(1.5),
            f(-2.25),
            f(0.0),
            f(-0.0),
            f(f32::NAN),
            f(f32::INFINITY),
            f(f32::NEG_INFINITY),
            f(1e-40),
            f(3.0e38),
            f(1.0 / 3.0),
            f(-7.0),
        ];
        let sign = 1u64 << 31;
        let forms: [(LaneFn, bool, bool); 4] = [
            (ffma::<u64>, false, false),
            (ffma_neg_ab::<u64>, true, false),
            (ffma_neg_c::<u64>, false, true),
            (ffma_neg_ab_c::<u64>, true, true),
        ];
        for (func, na, nc) in forms {
            for (i, &x) in vals.iter().enumerate() {
                let a: Lanes = [x; 32];
                let b: Lanes = std::array::from_fn(|l| vals[l % vals.len()]);
                let c: Lanes = std::array::from_fn(|l| vals[(l * 3 + i) % vals.len()]);
                let mut out = [0; 32];
                func(&a, &b, &c, &mut out);
                for l in 0..32 {
                    let (x, z) = (a[l] ^ if na { sign } else { 0 }, c[l] ^ if nc { sign } else { 0 });
                    let want = alu::arith(ArithOp::Mad, Ty::F32, FloatMode::default(), x, b[l], z);
                    assert_eq!(out[l], want, "neg_ab={na} neg_c={nc} a={:#x} b={:#x} c={:#x}", a[l], b[l], c[l]);
                }
            }
        }
    }

    /// Integers with bits above 32 (constants keep them; narrow rows never
    /// do), at the 8-, 16- and 32-bit sign boundaries, and f32 edges.
    fn narrow_edge_values() -> Vec<u64> {
        let f = |x: f32| x.to_bits() as u64;
        let mut v = vec![
            0,
            1,
            2,
            31,
            32,
            33,
            0x7F,
            0x80,
            0xFF,
            0x7FFF,
            0x8000,
            0xFFFF,
            0x7FFF_FFFF,
            0x8000_0000,
            0xFFFF_FFFF,
            0xFFFF_FF9C, // -100
            0x1_0000_0001,
            0xDEAD_BEEF_8000_0001,
            u64::MAX,
            f(1.5),
            f(-2.25),
            f(3.0e38),
            f(-3.0e9),
            f(1.0 / 3.0),
        ];
        v.extend(FLOAT_EDGES);
        v
    }

    /// Every narrow lane function (registers of 32 bits or fewer in rows of
    /// 32-bit lanes) gives the low 32 bits of its wide twin's result, for
    /// operands truncated to 32 bits: register values (which fit) and
    /// constants with bits above 32 (which the narrow forms truncate). The
    /// 64-bit forms have no narrow twin.
    #[test]
    fn narrow_lane_functions_are_the_wide_ones_truncated() {
        let vals = narrow_edge_values();
        let check = |name: &str, wide: LaneFn, narrow: LaneFn32| {
            for i in 0..vals.len() {
                let a: Lanes = [vals[i]; 32];
                let b: Lanes = std::array::from_fn(|l| vals[l % vals.len()]);
                let c: Lanes = std::array::from_fn(|l| vals[(l * 5 + i) % vals.len()]);
                let t = |x: &Lanes| -> Lanes32 { std::array::from_fn(|l| x[l] as u32) };
                let (mut w, mut n) = ([0u64; 32], [0u32; 32]);
                wide(&a, &b, &c, &mut w);
                narrow(&t(&a), &t(&b), &t(&c), &mut n);
                for l in 0..32 {
                    assert_eq!(n[l], w[l] as u32, "{name}: a={:#x} b={:#x} c={:#x}", a[l], b[l], c[l]);
                }
            }
        };
        let modes = [
            FloatMode::default(),
            FloatMode { rnd: Some(Rounding::Rn), ..FloatMode::default() },
            FloatMode { ftz: true, ..FloatMode::default() },
            FloatMode { approx: true, ..FloatMode::default() },
            FloatMode { approx: true, ftz: true, ..FloatMode::default() },
            FloatMode { approx: true, full: true, ..FloatMode::default() },
        ];
        let ops = [
            ArithOp::Add,
            ArithOp::Sub,
            ArithOp::Mul,
            ArithOp::MulWide,
            ArithOp::Mad,
            ArithOp::Div,
            ArithOp::Rcp,
            ArithOp::Sqrt,
            ArithOp::Rsqrt,
            ArithOp::Min,
            ArithOp::Max,
            ArithOp::Neg,
            ArithOp::Abs,
            ArithOp::And,
            ArithOp::Or,
            ArithOp::Xor,
            ArithOp::Shl,
            ArithOp::Shr,
        ];
        let tys = [Ty::S32, Ty::U32, Ty::B32, Ty::S64, Ty::U64, Ty::B64, Ty::F32, Ty::S16, Ty::U16];
        let mut narrow = 0;
        for op in ops {
            for ty in tys {
                for mode in modes {
                    for sfu in [SfuModel::Sm90, SfuModel::CorrectlyRounded] {
                        let Some((n, nc)) = resolve_arith_of::<u32>(op, ty, mode, sfu) else { continue };
                        let (w, wc) = resolve_arith(op, ty, mode, sfu).expect("a narrow form has a wide one");
                        assert_eq!(nc, wc);
                        assert!(ty.bits() <= 32, "{op:?}.{ty:?} has a narrow form");
                        check(&format!("{op:?}.{ty:?} {mode:?}"), w, n);
                        narrow += 1;
                    }
                }
            }
        }
        assert!(narrow > 40, "only {narrow} narrow forms");
        for dty in tys {
            for sty in tys {
                for rnd in [None, Some(Rounding::Rn), Some(Rounding::Rmi), Some(Rounding::Rzi)] {
                    let mode = FloatMode { rnd, ..FloatMode::default() };
                    let Some(n) = resolve_cvt_of::<u32>(dty, sty, mode) else { continue };
                    assert!(dty.bits() <= 32, "cvt.{dty:?}.{sty:?} has a narrow form");
                    check(&format!("cvt.{dty:?}.{sty:?} {rnd:?}"), resolve_cvt(dty, sty, mode).unwrap(), n);
                }
            }
        }
        for (na, nc) in [(false, false), (true, false), (false, true), (true, true)] {
            let fz = Fused { mul: 0, neg_product: na, neg_c: nc, a: Src::Imm(0), b: Src::Imm(0), c: Src::Imm(0) };
            check("fused fma", fused_fma::<u64>(&fz).unwrap(), fused_fma::<u32>(&fz).unwrap());
        }
    }

    /// `setp` on narrow rows (integers of 32 bits or fewer, f32, with and
    /// without `.ftz`) gives what it gives on wide rows, for every
    /// comparison, operands with bits above the type's width included
    /// (constants).
    #[test]
    fn narrow_comparisons_agree_with_the_wide_ones() {
        let vals = narrow_edge_values();
        let a: Lanes = std::array::from_fn(|l| vals[l % vals.len()]);
        let cmps = alu::ALL_CMPS;
        let tys = [Ty::S32, Ty::U32, Ty::B32, Ty::S16, Ty::U16, Ty::B16, Ty::S8, Ty::U8, Ty::F32];
        for i in 0..vals.len() {
            let b: Lanes = std::array::from_fn(|l| vals[(l + i) % vals.len()]);
            let t = |x: &Lanes| -> Lanes32 { std::array::from_fn(|l| x[l] as u32) };
            for ty in tys {
                for cmp in cmps {
                    for ftz in [false, true] {
                        let w = alu::compare_lanes(cmp, ty, ftz, &a, &b);
                        let n = alu::compare_lanes(cmp, ty, ftz, &t(&a), &t(&b));
                        assert_eq!(n, w, "setp.{cmp:?}.{ty:?} ftz={ftz}, b from {i}");
                    }
                }
            }
        }
    }

    fn decode_body(body: &str) -> (Program, Code) {
        let src = format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n.entry k(.param .u64 out)\n{{\n.reg .pred %p<3>;\n.reg .b32 %r<8>;\n.reg .f32 %f<8>;\n.reg .b64 %rd<4>;\n{body}\n}}\n"
        );
        let p = crate::ptx::load(&src, "t.ptx").unwrap();
        let code = Code::decode(&p, FloatOptions::default());
        (p, code)
    }

    /// The frequent forms get compact instructions with operands resolved to
    /// frame slots and constant rows; the others stay interpreted.
    #[test]
    fn frequent_forms_are_compact_with_resolved_operands() {
        let (_, code) = decode_body(
            "ld.param.u64 %rd1, [out];\n\
             cvta.to.global.u64 %rd2, %rd1;\n\
             mov.u32 %r1, %tid.x;\n\
             mul.wide.u32 %rd3, %r1, 4;\n\
             add.s64 %rd2, %rd2, %rd3;\n\
             ld.global.f32 %f1, [%rd2+8];\n\
             add.rn.f32 %f2, %f1, 0f3F800000;\n\
             setp.lt.f32 %p1, %f2, %f1;\n\
             selp.f32 %f3, %f2, %f1, %p1;\n\
             @%p1 bra DONE;\n\
             mov.f32 %f3, 0f40000000;\n\
             DONE:\n\
             st.global.f32 [%rd2], %f3;\n\
             ret;",
        );
        let fc = &code.funcs[0];
        let ops = &fc.ops;
        assert!(matches!(ops[0].exec, Exec::Ld { space: MemSpace::KernelParam, n: 1, .. }));
        assert!(matches!(ops[1].exec, Exec::Ir), "cvta is interpreted");
        assert!(matches!(ops[2].exec, Exec::Ir), "a special-register source is interpreted");
        let Exec::Lanes { b, .. } = ops[3].exec else { panic!("mul.wide: {:?}", ops[3].exec) };
        assert!(b >= CONST && fc.consts[(b - CONST) as usize] == [4; 32], "the immediate is a constant row");
        let Exec::Ld { space: MemSpace::Global, offset: 8, wide: true, bits: 32, n: 1, .. } = ops[5].exec else {
            panic!("ld: {:?}", ops[5].exec)
        };
        // 32-bit registers in narrow rows: the narrow forms, narrow constants
        let Exec::Lanes32 { d, a, b, c, .. } = ops[6].exec else { panic!("add.rn.f32: {:?}", ops[6].exec) };
        assert!(d.slot < CONST && a < CONST && b >= CONST && c == a && d.bits == 32);
        assert_eq!(fc.consts32[(b - CONST) as usize], [0x3F80_0000; 32]);
        assert!(matches!(ops[7].exec, Exec::Setp32 { q: PRED_FALSE, .. }));
        assert!(matches!(ops[8].exec, Exec::Selp32 { .. }));
        assert!(matches!(ops[9].exec, Exec::Bra { target: 11 }));
        assert!(ops[9].guard.reg > PRED_TRUE && !ops[9].guard.neg);
        assert_eq!(ops[8].guard, PredSrc { reg: PRED_TRUE, neg: false }, "unguarded: always true");
        assert!(matches!(ops[10].exec, Exec::Mov32 { .. }));
        assert!(matches!(ops[11].exec, Exec::St { space: MemSpace::Global, n: 1, .. }));
        assert!(matches!(ops[12].exec, Exec::Ir));
        // one row per distinct immediate
        let (_, code) = decode_body("mov.u32 %r1, 5;\nadd.s32 %r2, %r1, 5;\nadd.s32 %r3, %r2, 6;\nret;");
        assert_eq!((code.funcs[0].consts.len(), code.funcs[0].consts32.len()), (0, 2));
        // a 64-bit destination of 32-bit sources: the wide form, its operands widened when read
        let (_, code) = decode_body("mov.u32 %r1, 5;\nmul.wide.s32 %rd1, %r1, -3;\ncvt.u32.u64 %r2, %rd1;\nret;");
        let ops = &code.funcs[0].ops;
        assert!(matches!(ops[1].exec, Exec::Lanes { .. }) && matches!(ops[2].exec, Exec::Lanes { .. }));
        assert_eq!(code.funcs[0].consts, [[-3i32 as u32 as u64; 32]]);
    }

    /// Counting blocks start at the first instruction, at branch targets and
    /// after branches, `exit`, `ret` and `call`; nowhere else.
    #[test]
    fn counting_blocks_start_where_a_paths_lanes_may_change() {
        let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
            .func f()\n{\nret;\n}\n\
            .entry k(.param .u64 out)\n{\n.reg .pred %p<3>;\n.reg .b32 %r<8>;\n\
            mov.u32 %r1, %tid.x;\n\
            setp.lt.u32 %p1, %r1, 5;\n\
            @%p1 bra SKIP;\n\
            add.s32 %r2, %r1, 1;\n\
            call f;\n\
            add.s32 %r2, %r2, 1;\n\
            @%p1 exit;\n\
            add.s32 %r2, %r2, 1;\n\
            SKIP:\n\
            add.s32 %r3, %r1, 2;\n\
            ret;\n}\n";
        let p = crate::ptx::load(src, "t.ptx").unwrap();
        let code = Code::decode(&p, FloatOptions::default());
        let k = p.functions.iter().position(|f| f.name == "k").unwrap();
        let leaders: Vec<bool> = code.funcs[k].ops.iter().map(|o| o.leader).collect();
        //           mov   setp   bra    add   call   add   exit   add   SKIP: add  ret
        assert_eq!(leaders, [true, false, false, true, false, true, false, true, true, false]);
        assert!(code.funcs[k].ops[2].guarded() && !code.funcs[k].ops[3].guarded());
    }

    /// A `mul` feeding an `add` (contraction on) executes as one fma lane
    /// function with the signs folded in.
    #[test]
    fn a_contracted_add_is_a_compact_fma() {
        let (_, code) = decode_body(
            "ld.param.u64 %rd1, [out];\n\
             ld.global.f32 %f1, [%rd1];\n\
             ld.global.f32 %f2, [%rd1+4];\n\
             mul.f32 %f3, %f1, %f2;\n\
             sub.f32 %f4, %f1, %f3;\n\
             st.global.f32 [%rd1], %f4;\n\
             ret;",
        );
        // f32 registers: the narrow form
        let Exec::Lanes32 { f, .. } = code.funcs[0].ops[4].exec else { panic!("{:?}", code.funcs[0].ops[4].exec) };
        // fma(-2, 3, 1) = -5; the other sign foldings give 7, 5 and -7
        let (a, b, c) = ([2f32.to_bits(); 32], [3f32.to_bits(); 32], [1f32.to_bits(); 32]);
        let mut out = [0; 32];
        f(&a, &b, &c, &mut out);
        assert_eq!(out, [(-5f32).to_bits(); 32], "c - a*b is fma(-a, b, c)");
    }
}
