//! Warp-level instructions: `vote` (all, any, uni, ballot), `activemask`
//! (a ballot of `true`), `shfl` (idx, up, down, bfly), `redux.sync` and
//! `match.sync`.

use super::opcode::Decoded;
use super::{FnLower, LResult};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

/// The member mask of a warp instruction without `.sync` (and of
/// `activemask`): the lanes that execute it. No 32-bit operand has this
/// value, so the simulator tells it from a `.sync` form's mask.
pub const NO_MEMBER_MASK: Src = Src::Imm(1 << 32);

impl FnLower<'_> {
    /// Lowers a validated `vote`.
    pub(super) fn lower_vote(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let mode = m.vote_mode().expect("validated: a mode");
        let membermask = if m.has("sync") { self.src(&ops[2], Ty::U32, pos)? } else { NO_MEMBER_MASK };
        let a = self.pred_src(&ops[1], pos)?;
        Ok(if mode == VoteMode::Ballot {
            Kind::Vote { mode, d: Some(self.dst(&ops[0], pos)?), p: PRED_FALSE, a, membermask }
        } else {
            Kind::Vote { mode, d: None, p: self.pred_dst(&ops[0], pos)?, a, membermask }
        })
    }

    /// Lowers `activemask d`: a ballot of `true` over the whole warp.
    pub(super) fn lower_activemask(&self, i: &ast::Instruction) -> LResult<Kind> {
        Ok(Kind::Vote {
            mode: VoteMode::Ballot,
            d: Some(self.dst(&i.operands[0], i.pos)?),
            p: PRED_FALSE,
            a: PredSrc { reg: PRED_TRUE, neg: false },
            membermask: NO_MEMBER_MASK,
        })
    }

    /// Lowers a validated `redux.sync`.
    pub(super) fn lower_redux(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let ty = m.types[0];
        let op = if m.has("add") {
            ReduxOp::Add
        } else if m.has("min") {
            ReduxOp::Min
        } else if m.has("max") {
            ReduxOp::Max
        } else if m.has("and") {
            ReduxOp::And
        } else if m.has("or") {
            ReduxOp::Or
        } else {
            ReduxOp::Xor
        };
        Ok(Kind::Redux {
            op,
            ty,
            d: self.dst(&ops[0], pos)?,
            a: self.src(&ops[1], ty, pos)?,
            membermask: self.src(&ops[2], Ty::U32, pos)?,
        })
    }

    /// Lowers a validated `match.sync`.
    pub(super) fn lower_match(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let ty = m.types[0];
        let (dst, p) = match &ops[0] {
            Operand::Pair(d, p) => (self.dst(&Operand::Name(d.clone()), pos)?, Some(self.pred_named(p, pos)?)),
            o => (self.dst(o, pos)?, None),
        };
        Ok(Kind::Match {
            all: m.has("all"),
            ty,
            d: dst,
            p,
            a: self.src(&ops[1], ty, pos)?,
            membermask: self.src(&ops[2], Ty::U32, pos)?,
        })
    }

    /// Lowers a validated `shfl`.
    pub(super) fn lower_shfl(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let mode = m.shfl_mode().expect("validated: a mode");
        let (dst, p) = match &ops[0] {
            Operand::Pair(d, p) => (self.dst(&Operand::Name(d.clone()), pos)?, Some(self.pred_named(p, pos)?)),
            o => (self.dst(o, pos)?, None),
        };
        Ok(Kind::Shfl {
            mode,
            d: dst,
            p,
            a: self.src(&ops[1], Ty::B32, pos)?,
            b: self.src(&ops[2], Ty::U32, pos)?,
            c: self.src(&ops[3], Ty::U32, pos)?,
            membermask: if m.has("sync") { self.src(&ops[4], Ty::U32, pos)? } else { NO_MEMBER_MASK },
        })
    }
}
