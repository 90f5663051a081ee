//! Operands: names resolved to registers, predicates, special registers,
//! immediates of the instruction's type and addresses in a state space.

use super::{FnLower, LResult, Sym, invalid, unsupported};
use crate::ptx::ast::{Literal, Operand};
use crate::ptx::error::Pos;
use crate::ptx::ir::*;
use crate::ptx::types::{Space, Ty};

/// The bits of literal `l` as a value of type `ty`.
pub(super) fn lit_bits(l: Literal, ty: Ty, pos: Pos) -> LResult<u64> {
    Ok(match (l, ty) {
        (Literal::Int(v), Ty::F32) => ((v as i64) as f32).to_bits() as u64,
        (Literal::Int(v), Ty::F64) => ((v as i64) as f64).to_bits(),
        (Literal::Int(v), t) => v & t.mask(),
        (Literal::F32(b), Ty::F64) => (f32::from_bits(b) as f64).to_bits(),
        (Literal::F32(b), t) => b as u64 & t.mask(),
        (Literal::F64(b), Ty::F32) => (f64::from_bits(b) as f32).to_bits() as u64,
        (Literal::F64(b), t) => b & t.mask(),
        (Literal::Float(x), Ty::F32) => (x as f32).to_bits() as u64,
        (Literal::Float(x), Ty::F64) => x.to_bits(),
        (Literal::Float(_), t) => return invalid(pos, format!("float literal used as .{t}")),
    })
}

/// A special register by its PTX name (`%tid.x`, `%laneid`...).
fn special_reg(name: &str) -> Option<SpecialReg> {
    let dim = |c: &str| match c {
        "x" => Some(0u8),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    };
    if let Some((base, comp)) = name.split_once('.') {
        let d = dim(comp)?;
        return Some(match base {
            "%tid" => SpecialReg::Tid(d),
            "%ntid" => SpecialReg::Ntid(d),
            "%ctaid" => SpecialReg::Ctaid(d),
            "%nctaid" => SpecialReg::Nctaid(d),
            _ => return None,
        });
    }
    Some(match name {
        "%laneid" => SpecialReg::LaneId,
        "%warpid" => SpecialReg::WarpId,
        "%nwarpid" => SpecialReg::NWarpId,
        "%smid" => SpecialReg::SmId,
        "%nsmid" => SpecialReg::NSmId,
        "%gridid" => SpecialReg::GridId,
        "%lanemask_eq" => SpecialReg::LaneMaskEq,
        "%lanemask_le" => SpecialReg::LaneMaskLe,
        "%lanemask_lt" => SpecialReg::LaneMaskLt,
        "%lanemask_ge" => SpecialReg::LaneMaskGe,
        "%lanemask_gt" => SpecialReg::LaneMaskGt,
        "%clock" => SpecialReg::Clock,
        "%clock64" => SpecialReg::Clock64,
        // deterministic, as %clock64 (docs/ptx-support.md); a 32-bit read keeps the low half
        "%globaltimer" | "%globaltimer_lo" => SpecialReg::Clock64,
        "%globaltimer_hi" => SpecialReg::GlobalTimerHi,
        _ => return None,
    })
}

impl FnLower<'_> {
    /// A destination data register (`_` is the sink).
    pub(super) fn dst(&self, op: &Operand, pos: Pos) -> LResult<Dst> {
        match op {
            Operand::Name(n) if n == "_" => Ok(Dst { reg: Dst::SINK, mask: u64::MAX }),
            Operand::Name(n) => match self.lookup(n) {
                Some(Sym::Reg(id)) => Ok(Dst { reg: id, mask: self.out.reg_masks[id as usize] }),
                Some(_) => invalid(pos, format!("`{n}` is not a data register")),
                None => invalid(pos, format!("undeclared register `{n}`")),
            },
            _ => invalid(pos, "destination must be a register"),
        }
    }

    /// A destination predicate register (`_` writes the constant `false`, i.e. nothing).
    pub(super) fn pred_dst(&self, op: &Operand, pos: Pos) -> LResult<PredId> {
        match op {
            Operand::Name(n) if n == "_" => Ok(PRED_FALSE),
            Operand::Name(n) => match self.lookup(n) {
                Some(Sym::Pred(id)) => Ok(id),
                Some(_) => invalid(pos, format!("`{n}` is not a predicate register")),
                None => invalid(pos, format!("undeclared predicate `{n}`")),
            },
            _ => invalid(pos, "destination must be a predicate register"),
        }
    }

    /// A named predicate register as a destination.
    pub(super) fn pred_named(&self, n: &str, pos: Pos) -> LResult<PredId> {
        self.pred_dst(&Operand::Name(n.to_string()), pos)
    }

    /// A predicate source: `%p`, `!%p`, or a literal 0/1.
    pub(super) fn pred_src(&self, op: &Operand, pos: Pos) -> LResult<PredSrc> {
        match op {
            Operand::Not(n) => Ok(PredSrc { reg: self.pred_named(n, pos)?, neg: true }),
            Operand::Name(_) => Ok(PredSrc { reg: self.pred_dst(op, pos)?, neg: false }),
            Operand::Lit(Literal::Int(v)) => {
                Ok(PredSrc { reg: if *v != 0 { PRED_TRUE } else { PRED_FALSE }, neg: false })
            }
            _ => invalid(pos, "expected a predicate"),
        }
    }

    /// A source value read as type `ty`.
    pub(super) fn src(&self, op: &Operand, ty: Ty, pos: Pos) -> LResult<Src> {
        match op {
            Operand::Lit(l) => Ok(Src::Imm(lit_bits(*l, ty, pos)?)),
            Operand::Name(n) => match self.lookup(n) {
                Some(Sym::Reg(id)) => Ok(Src::Reg(id)),
                Some(Sym::Shared(o))
                | Some(Sym::Const(o))
                | Some(Sym::KernelParam(o))
                | Some(Sym::FrameParam(o, _)) => Ok(Src::Imm(o as u64)),
                Some(Sym::Local(o)) => Ok(Src::LocalAddr(o)),
                Some(Sym::Global(g)) => Ok(Src::GlobalAddr(g, 0)),
                Some(Sym::Pred(_)) => invalid(pos, format!("predicate `{n}` used as a value")),
                // a function pointer: an address outside memory that indirect calls resolve
                Some(Sym::Func(f)) => Ok(Src::Imm(func_addr(f))),
                None => match special_reg(n) {
                    Some(s) => Ok(Src::Special(s)),
                    // PTX's predefined constant (nvcc writes it for `warpSize`)
                    None if n == "WARP_SZ" => Ok(Src::Imm(32)),
                    None if n.starts_with('%') => invalid(pos, format!("undeclared register `{n}`")),
                    None => invalid(pos, format!("undeclared name `{n}`")),
                },
            },
            Operand::Offset(n, off) => self.offset_address(n, *off, pos),
            Operand::Not(_) => invalid(pos, "`!` applies to predicates only"),
            _ => invalid(pos, "expected a register or literal"),
        }
    }

    /// The value of the address expression `n+off`: variable `n`'s address
    /// plus `off` bytes (kernel and frame parameters, shared, constant and
    /// local variables by their offset in their space, globals by their
    /// address). Registers, predicates, functions and negative or
    /// overflowing offsets are errors that name the expression.
    fn offset_address(&self, n: &str, off: i64, pos: Pos) -> LResult<Src> {
        let text = if off < 0 { format!("{n}{off}") } else { format!("{n}+{off}") };
        let Ok(off) = u32::try_from(off) else {
            return invalid(pos, format!("`{text}`: an offset before the variable's start is not supported"));
        };
        let plus = |base: u32| match base.checked_add(off) {
            Some(a) => Ok(a),
            None => invalid(pos, format!("`{text}`: the address overflows 32 bits of the variable's space")),
        };
        match self.lookup(n) {
            Some(Sym::Shared(o)) | Some(Sym::Const(o)) | Some(Sym::KernelParam(o)) | Some(Sym::FrameParam(o, _)) => {
                Ok(Src::Imm(plus(o)? as u64))
            }
            Some(Sym::Local(o)) => Ok(Src::LocalAddr(plus(o)?)),
            Some(Sym::Global(g)) => Ok(Src::GlobalAddr(g, off)),
            Some(Sym::Reg(_)) | Some(Sym::Pred(_)) => invalid(
                pos,
                format!("`{text}`: only a variable's address takes an offset; `{n}` is a register (use `add`)"),
            ),
            Some(Sym::Func(_)) => invalid(pos, format!("`{text}`: `{n}` is a function, not a variable")),
            None if n.starts_with('%') => invalid(pos, format!("`{text}`: undeclared register `{n}`")),
            None => invalid(pos, format!("`{text}`: undeclared name `{n}`")),
        }
    }

    /// An address operand and the space its symbol lives in (if a symbol).
    pub(super) fn address(&self, op: &Operand, pos: Pos) -> LResult<(Address, Option<MemSpace>)> {
        let Operand::Addr(base, off) = op else {
            return invalid(pos, "expected an address `[...]`");
        };
        let Some(name) = base else {
            return Ok((Address { base: Src::Imm(0), offset: *off, wide: true }, None));
        };
        let (b, space) = match self.lookup(name) {
            Some(Sym::Reg(id)) => (Src::Reg(id), None),
            Some(Sym::Shared(o)) => (Src::Imm(o as u64), Some(MemSpace::Shared)),
            Some(Sym::Const(o)) => (Src::Imm(o as u64), Some(MemSpace::Const)),
            Some(Sym::KernelParam(o)) => (Src::Imm(o as u64), Some(MemSpace::KernelParam)),
            Some(Sym::FrameParam(o, _)) => (Src::Imm(o as u64), Some(MemSpace::FrameParam)),
            Some(Sym::Local(o)) => (Src::LocalAddr(o), Some(MemSpace::Local)),
            Some(Sym::Global(g)) => (Src::GlobalAddr(g, 0), Some(MemSpace::Global)),
            Some(Sym::Pred(_)) | Some(Sym::Func(_)) => {
                return invalid(pos, format!("`{name}` is not an address"));
            }
            None => return invalid(pos, format!("undeclared name `{name}`")),
        };
        // a 32-bit register base is added to the offset in 32 bits (nvcc's `[%r4+68]` with
        // %r4 = 0xFFFFFFC0 addresses 4), then widened
        let wide = match b {
            Src::Reg(id) => self.out.reg_masks.get(id as usize).is_none_or(|m| *m > u32::MAX as u64),
            _ => true,
        };
        Ok((Address { base: b, offset: *off, wide }, space))
    }

    /// The memory space of an access written with state space `space` to an
    /// address whose symbol (if any) lives in `sym_space`.
    pub(super) fn mem_space(&self, space: Option<Space>, sym_space: Option<MemSpace>, pos: Pos) -> LResult<MemSpace> {
        let declared = match space {
            None => MemSpace::Generic,
            Some(Space::Global) => MemSpace::Global,
            Some(Space::Shared) => MemSpace::Shared,
            Some(Space::Local) => MemSpace::Local,
            Some(Space::Const) => MemSpace::Const,
            Some(Space::Param) => {
                if self.sigs[self.me].is_entry {
                    MemSpace::KernelParam
                } else {
                    MemSpace::FrameParam
                }
            }
            Some(s) => return unsupported(pos, format!("state space .{s}")),
        };
        Ok(match (declared, sym_space) {
            (MemSpace::KernelParam, Some(MemSpace::FrameParam)) => MemSpace::FrameParam,
            (MemSpace::Generic, Some(s)) => s,
            (d, Some(s)) if d != s && !(d == MemSpace::FrameParam && s == MemSpace::KernelParam) => {
                return invalid(pos, format!("symbol of the {s:?} space used with a {d:?} access"));
            }
            (d, _) => d,
        })
    }
}
