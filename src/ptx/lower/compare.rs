//! Comparisons and selection: `setp`, `set`, `selp`, and predicate logic
//! (`and or xor not cnot` on `.pred`, and `mov.pred` in [`super::data`]).

use super::opcode::{Decoded, Opcode, bool_of, cmp_of};
use super::validate::one_type;
use super::{FnLower, LResult};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

impl FnLower<'_> {
    /// Lowers a validated `setp` or `set`.
    pub(super) fn lower_setp(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let mut cmp = None;
        let mut comb = None;
        for w in &m.words {
            if let Some(c) = cmp_of(w).filter(|_| cmp.is_none()) {
                cmp = Some(c);
            } else if let Some(b) = bool_of(w) {
                comb = Some(b);
            }
        }
        let cmp = cmp.expect("validated: a comparison");
        let ftz = m.has("ftz");
        let (sty, dty) = match m.types.as_slice() {
            [d, s] => (*s, *d),
            _ => (one_type(d, i)?, Ty::Pred),
        };
        let comb = match comb {
            Some(b) => Some((b, self.pred_src(&ops[3], pos)?)),
            None => None,
        };
        let a = self.src(&ops[1], sty, pos)?;
        let b = self.src(&ops[2], sty, pos)?;
        if d.op == Opcode::Setp {
            let (p, q) = match &ops[0] {
                Operand::Pair(p, q) => (self.pred_named(p, pos)?, Some(self.pred_named(q, pos)?)),
                o => (self.pred_dst(o, pos)?, None),
            };
            Ok(Kind::Setp { cmp, ty: sty, p, q, a, b, comb, ftz })
        } else {
            Ok(Kind::Set { cmp, dty, sty, d: self.dst(&ops[0], pos)?, a, b, comb, ftz })
        }
    }

    /// Lowers a validated `selp`.
    pub(super) fn lower_selp(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops) = (i.pos, &i.operands);
        let t = one_type(d, i)?;
        Ok(Kind::Selp {
            d: self.dst(&ops[0], pos)?,
            a: self.src(&ops[1], t, pos)?,
            b: self.src(&ops[2], t, pos)?,
            p: self.pred_src(&ops[3], pos)?,
        })
    }

    /// Lowers validated predicate logic: `and/or/xor.pred d, a, b`, `not/cnot.pred d, a`.
    pub(super) fn lower_pred_logic(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops) = (i.pos, &i.operands);
        let op = match d.op {
            Opcode::And => Some(BoolOp::And),
            Opcode::Or => Some(BoolOp::Or),
            Opcode::Xor => Some(BoolOp::Xor),
            _ => None,
        };
        let dst = self.pred_dst(&ops[0], pos)?;
        let mut a = self.pred_src(&ops[1], pos)?;
        let b = if op.is_some() { self.pred_src(&ops[2], pos)? } else { PredSrc { reg: PRED_FALSE, neg: false } };
        if d.op == Opcode::Not {
            a.neg = !a.neg;
        }
        Ok(Kind::PredLogic { op, d: dst, a, b })
    }
}
