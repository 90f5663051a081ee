//! Conversions: `cvt` between integer and float types, `cvta` between
//! generic and state-space addresses.

use super::opcode::Decoded;
use super::validate::one_type;
use super::{FnLower, LResult};
use crate::ptx::ast;
use crate::ptx::ir::*;
use crate::ptx::types::{Space, Ty};

impl FnLower<'_> {
    /// Lowers a validated `cvt`.
    pub(super) fn lower_cvt(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let (dty, sty) = (m.types[0], m.types[1]);
        let mode = FloatMode { rnd: m.rounding(), ftz: m.has("ftz"), sat: m.has("sat"), ..FloatMode::default() };
        if ops.len() == 3 {
            // cvt.rn.f16x2.f32 d, a, b (validated): two f32 into one packed pair
            return Ok(Kind::Arith {
                op: ArithOp::CvtPack,
                ty: dty,
                mode,
                d: self.dst(&ops[0], pos)?,
                a: self.src(&ops[1], Ty::F32, pos)?,
                b: self.src(&ops[2], Ty::F32, pos)?,
                c: Src::Imm(0),
            });
        }
        Ok(Kind::Cvt { dty, sty, mode, d: self.dst(&ops[0], pos)?, a: self.src(&ops[1], sty, pos)? })
    }

    /// Lowers a validated `cvta`.
    pub(super) fn lower_cvta(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let t = one_type(d, i)?;
        let space = match m.space {
            Some(Space::Global) => MemSpace::Global,
            Some(Space::Shared) => MemSpace::Shared,
            Some(Space::Local) => MemSpace::Local,
            Some(Space::Const) => MemSpace::Const,
            _ => MemSpace::KernelParam,
        };
        Ok(Kind::Cvta { to_generic: !m.has("to"), space, d: self.dst(&ops[0], pos)?, a: self.src(&ops[1], t, pos)? })
    }
}
