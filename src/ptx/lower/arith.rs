//! Arithmetic, logic, shifts, bit fields and special functions: `add` … `copysign`
//! become [`Kind::Arith`], `bfi` [`Kind::Bfi`].

use super::opcode::{Decoded, Opcode};
use super::validate::{arith_shape, one_type};
use super::{FnLower, LResult};
use crate::ptx::ast;
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

/// The IR operation of a validated arithmetic instruction.
fn arith_op(d: &Decoded) -> ArithOp {
    use Opcode::*;
    let m = &d.mods;
    match d.op {
        Add => ArithOp::Add,
        Sub => ArithOp::Sub,
        Mul if m.has("hi") => ArithOp::MulHi,
        Mul if m.has("wide") => ArithOp::MulWide,
        Mul => ArithOp::Mul,
        Mad | Fma if m.has("hi") => ArithOp::MadHi,
        Mad | Fma if m.has("wide") => ArithOp::MadWide,
        Mad | Fma => ArithOp::Mad,
        Mul24 if m.has("hi") => ArithOp::Mul24Hi,
        Mul24 => ArithOp::Mul24Lo,
        Mad24 if m.has("hi") => ArithOp::Mad24Hi,
        Mad24 => ArithOp::Mad24Lo,
        Div => ArithOp::Div,
        Rem => ArithOp::Rem,
        Abs => ArithOp::Abs,
        Neg => ArithOp::Neg,
        Min => ArithOp::Min,
        Max => ArithOp::Max,
        And => ArithOp::And,
        Or => ArithOp::Or,
        Xor => ArithOp::Xor,
        Not => ArithOp::Not,
        Cnot => ArithOp::Cnot,
        Shl => ArithOp::Shl,
        Shr => ArithOp::Shr,
        Shf => match (m.has("l"), m.has("wrap")) {
            (true, true) => ArithOp::ShfLWrap,
            (true, false) => ArithOp::ShfLClamp,
            (false, true) => ArithOp::ShfRWrap,
            (false, false) => ArithOp::ShfRClamp,
        },
        Popc => ArithOp::Popc,
        Clz => ArithOp::Clz,
        Brev => ArithOp::Brev,
        Bfe => ArithOp::Bfe,
        Prmt if m.has("f4e") => ArithOp::PrmtF4e,
        Prmt if m.has("b4e") => ArithOp::PrmtB4e,
        Prmt if m.has("rc8") => ArithOp::PrmtRc8,
        Prmt if m.has("ecl") => ArithOp::PrmtEcl,
        Prmt if m.has("ecr") => ArithOp::PrmtEcr,
        Prmt if m.has("rc16") => ArithOp::PrmtRc16,
        Prmt => ArithOp::Prmt,
        Bfind if m.has("shiftamt") => ArithOp::BfindShiftamt,
        Bfind => ArithOp::Bfind,
        Dp4a | Dp2a => {
            let bs = m.types.get(1) == Some(&Ty::S32);
            match (d.op, m.has("hi"), bs) {
                (Dp4a, _, false) => ArithOp::Dp4aU,
                (Dp4a, _, true) => ArithOp::Dp4aS,
                (_, false, false) => ArithOp::Dp2aLoU,
                (_, false, true) => ArithOp::Dp2aLoS,
                (_, true, false) => ArithOp::Dp2aHiU,
                (_, true, true) => ArithOp::Dp2aHiS,
            }
        }
        Sqrt => ArithOp::Sqrt,
        Rsqrt => ArithOp::Rsqrt,
        Rcp => ArithOp::Rcp,
        Sin => ArithOp::Sin,
        Cos => ArithOp::Cos,
        Ex2 => ArithOp::Ex2,
        Lg2 => ArithOp::Lg2,
        Tanh => ArithOp::Tanh,
        Copysign => ArithOp::Copysign,
        other => unreachable!("{other:?} is not an arithmetic opcode"),
    }
}

/// The type source operand `k` of `op` on type `t` is read as.
fn src_ty(op: ArithOp, t: Ty, k: usize) -> Ty {
    use ArithOp::*;
    match (op, k) {
        (Shl | Shr, 1) => Ty::U32,
        (Bfe, 1 | 2) => Ty::U32,
        (ShfLWrap | ShfLClamp | ShfRWrap | ShfRClamp, 2) => Ty::U32,
        (MadWide, 2) => wide_of(t),
        (Prmt | PrmtF4e | PrmtB4e | PrmtRc8 | PrmtEcl | PrmtEcr | PrmtRc16, _) => Ty::B32,
        (Dp4aU | Dp4aS | Dp2aLoU | Dp2aLoS | Dp2aHiU | Dp2aHiS, 1) => Ty::B32,
        _ => t,
    }
}

/// The type twice as wide (for `mad.wide`'s addend).
fn wide_of(t: Ty) -> Ty {
    match t {
        Ty::S16 => Ty::S32,
        Ty::U16 => Ty::U32,
        Ty::S32 => Ty::S64,
        Ty::U32 => Ty::U64,
        o => o,
    }
}

impl FnLower<'_> {
    /// Lowers a validated arithmetic instruction.
    pub(super) fn lower_arith(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let dot = matches!(d.op, Opcode::Dp4a | Opcode::Dp2a);
        // dp4a/dp2a: the instruction type is a's (and c's and d's), b's decides the op
        let t = if dot { m.types[0] } else { one_type(d, i)? };
        let op = arith_op(d);
        let (nsrc, _) = if dot { (3, &[][..]) } else { arith_shape(d.op) };
        let mode = FloatMode {
            rnd: m.rounding(),
            ftz: m.has("ftz"),
            sat: m.has("sat"),
            approx: m.has("approx") || m.has("full"),
            full: m.has("full"),
        };
        let mut s = [Src::Imm(0); 3];
        for (k, s) in s.iter_mut().enumerate().take(nsrc) {
            *s = self.src(&ops[k + 1], src_ty(op, t, k), pos)?;
        }
        let dst = self.dst(&ops[0], pos)?;
        Ok(Kind::Arith { op, ty: t, mode, d: dst, a: s[0], b: s[1], c: s[2] })
    }

    /// Lowers a validated carry-chain instruction: `add.cc`, `addc[.cc]`,
    /// `sub.cc`, `subc[.cc]`, `mad{.lo,.hi}.cc`, `madc{.lo,.hi}[.cc]`.
    pub(super) fn lower_carry(&mut self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let t = one_type(d, i)?;
        let (op, cin) = match d.op {
            Opcode::Add => (CarryOp::Add, false),
            Opcode::Addc => (CarryOp::Add, true),
            Opcode::Sub => (CarryOp::Sub, false),
            Opcode::Subc => (CarryOp::Sub, true),
            Opcode::Mad | Opcode::Madc => {
                (if m.has("hi") { CarryOp::MadHi } else { CarryOp::MadLo }, d.op == Opcode::Madc)
            }
            other => unreachable!("{other:?} has no carry form"),
        };
        let nsrc = if matches!(op, CarryOp::MadLo | CarryOp::MadHi) { 3 } else { 2 };
        let mut s = [Src::Imm(0); 3];
        for (k, s) in s.iter_mut().enumerate().take(nsrc) {
            *s = self.src(&ops[k + 1], t, pos)?;
        }
        let dst = self.dst(&ops[0], pos)?;
        let cc = self.cc_reg();
        Ok(Kind::Carry { op, cin, cout: m.has("cc"), ty: t, d: dst, a: s[0], b: s[1], c: s[2], cc })
    }

    /// Lowers a validated `bfi`.
    pub(super) fn lower_bfi(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops) = (i.pos, &i.operands);
        let t = one_type(d, i)?;
        Ok(Kind::Bfi {
            ty: t,
            d: self.dst(&ops[0], pos)?,
            a: self.src(&ops[1], t, pos)?,
            b: self.src(&ops[2], t, pos)?,
            c: self.src(&ops[3], Ty::U32, pos)?,
            e: self.src(&ops[4], Ty::U32, pos)?,
        })
    }
}
