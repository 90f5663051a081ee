//! `mov`: registers, immediates, special registers and symbol addresses;
//! vector operands pack (`mov.b64 %rd, {%r1, %r2}`) and unpack.

use super::opcode::Decoded;
use super::validate::{one_type, part_bits};
use super::{FnLower, LResult};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

impl FnLower<'_> {
    /// Lowers a validated `mov`.
    pub(super) fn lower_mov(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops) = (i.pos, &i.operands);
        let t = one_type(d, i)?;
        Ok(if t == Ty::Pred {
            Kind::PredLogic {
                op: None,
                d: self.pred_dst(&ops[0], pos)?,
                a: self.pred_src(&ops[1], pos)?,
                b: PredSrc { reg: PRED_FALSE, neg: false },
            }
        } else if let Operand::Vector(parts) = &ops[1] {
            let part_bits = part_bits(t.bits(), parts.len(), i)?;
            let pt = part_ty(part_bits);
            let parts = parts.iter().map(|p| self.src(p, pt, pos)).collect::<LResult<Vec<_>>>()?;
            Kind::Pack { d: self.dst(&ops[0], pos)?, parts, part_bits }
        } else if let Operand::Vector(ds) = &ops[0] {
            let part_bits = part_bits(t.bits(), ds.len(), i)?;
            let ds = ds.iter().map(|d| self.dst(d, pos)).collect::<LResult<Vec<_>>>()?;
            Kind::Unpack { ds, a: self.src(&ops[1], t, pos)?, part_bits }
        } else {
            Kind::Mov { d: self.dst(&ops[0], pos)?, a: self.src(&ops[1], t, pos)? }
        })
    }
}

/// The bit type of a validated part width (8, 16 or 32).
fn part_ty(bits: u32) -> Ty {
    match bits {
        8 => Ty::B8,
        16 => Ty::B16,
        _ => Ty::B32,
    }
}
