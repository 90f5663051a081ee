//! Memory instructions: `ld`, `st` (vectors, every state space, qualifiers
//! without effect on results) and `atom`/`red`.

use super::opcode::{Decoded, Opcode, atom_op_of};
use super::validate::one_type;
use super::{FnLower, LResult, invalid};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::*;

impl FnLower<'_> {
    /// Lowers a validated `ld` or `st`.
    pub(super) fn lower_ld_st(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let t = one_type(d, i)?;
        let (addr_op, val_op) = if d.op == Opcode::Ld { (&ops[1], &ops[0]) } else { (&ops[0], &ops[1]) };
        let (addr, sym_space) = self.address(addr_op, pos)?;
        let space = self.mem_space(m.space, sym_space, pos)?;
        let vals: Vec<&Operand> = match val_op {
            Operand::Vector(v) => v.iter().collect(),
            o => vec![o],
        };
        let volatile = m.has("volatile") || m.has("relaxed") || m.has("acquire") || m.has("release");
        if d.op == Opcode::Ld {
            let ds = vals.iter().map(|v| self.dst(v, pos)).collect::<LResult<Vec<_>>>()?;
            Ok(Kind::Ld { space, ty: t, ds, addr, nc: m.has("nc"), volatile })
        } else {
            let vs = vals.iter().map(|v| self.src(v, t, pos)).collect::<LResult<Vec<_>>>()?;
            Ok(Kind::St { space, ty: t, vals: vs, addr, volatile })
        }
    }

    /// Lowers a validated `atom` or `red` (`red` has no destination).
    pub(super) fn lower_atom(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let op = m.words.iter().rev().find_map(|w| atom_op_of(w)).expect("validated: an operation");
        let t = one_type(d, i)?;
        let k = usize::from(d.op == Opcode::Atom);
        let (addr, sym_space) = self.address(&ops[k], pos)?;
        let space = self.mem_space(m.space, sym_space, pos)?;
        if !matches!(space, MemSpace::Global | MemSpace::Shared | MemSpace::Generic) {
            return invalid(pos, "atomics work on global, shared or generic addresses only");
        }
        let b = self.src(&ops[k + 1], t, pos)?;
        let c = if op == AtomOp::Cas { self.src(&ops[k + 2], t, pos)? } else { Src::Imm(0) };
        let dst = if k == 1 { Some(self.dst(&ops[0], pos)?) } else { None };
        Ok(Kind::Atom { space, op, ty: t, d: dst, addr, b, c })
    }
}
