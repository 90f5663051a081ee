//! Control: branches (resolved once all labels are known), calls of device
//! functions through `.param` variables, `ret`/`exit`/`trap`, barriers, fences
//! and the instructions without effect in the model.

use super::opcode::{Decoded, Opcode};
use super::{FnLower, LResult, Sym, invalid, unsupported};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

impl FnLower<'_> {
    /// Lowers a validated control instruction.
    pub(super) fn lower_control(&mut self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        use Opcode::*;
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        Ok(match d.op {
            Bra => {
                let Operand::Name(l) = &ops[0] else { unreachable!("validated: a label") };
                self.fixups.push((self.out.insts.len(), l.clone(), pos));
                Kind::Bra { target: u32::MAX, uni: m.has("uni") }
            }
            Call => self.call(i)?,
            Ret if self.sigs[self.me].is_entry => Kind::Exit,
            Ret => Kind::Ret,
            Exit => Kind::Exit,
            Trap => Kind::Trap,
            Bar | Barrier if m.has("warp") => Kind::WarpSync { membermask: self.src(&ops[0], Ty::U32, pos)? },
            Bar | Barrier if m.has("red") => {
                let op = if m.has("popc") {
                    BarRedOp::Popc
                } else if m.has("and") {
                    BarRedOp::And
                } else {
                    BarRedOp::Or
                };
                let (d, p) = if op == BarRedOp::Popc {
                    (Some(self.dst(&ops[0], pos)?), PRED_FALSE)
                } else {
                    (None, self.pred_dst(&ops[0], pos)?)
                };
                let id = self.src(&ops[1], Ty::U32, pos)?;
                let count = if ops.len() == 4 { Some(self.src(&ops[2], Ty::U32, pos)?) } else { None };
                let a = self.pred_src(&ops[ops.len() - 1], pos)?;
                Kind::BarRed { op, d, p, id, count, a }
            }
            Bar | Barrier => {
                let id = self.src(&ops[0], Ty::U32, pos)?;
                let count = if ops.len() == 2 { Some(self.src(&ops[1], Ty::U32, pos)?) } else { None };
                Kind::Bar { id, count }
            }
            Membar | Fence => Kind::Membar,
            Prefetch | Prefetchu | Pmevent | Nanosleep | Brkpt | Nop => Kind::Nop,
            other => unreachable!("{other:?} is not a control opcode"),
        })
    }

    /// A direct call: arguments and return values are `.param` variables,
    /// copied into and out of the callee's frame.
    fn call(&mut self, i: &ast::Instruction) -> LResult<Kind> {
        let pos = i.pos;
        let ops = &i.operands;
        let mut k = 0;
        let mut rets: &[Operand] = &[];
        if let Some(Operand::List(r)) = ops.first() {
            rets = r;
            k = 1;
        }
        let Some(Operand::Name(fname)) = ops.get(k) else {
            return invalid(pos, "`call` needs a function name");
        };
        let args: &[Operand] = match ops.get(k + 1) {
            Some(Operand::List(a)) => a,
            None => &[],
            // `call (r), %rd, prototype;` with no arguments
            Some(Operand::Name(_)) if ops.len() == k + 2 => &[],
            Some(_) => return invalid(pos, "`call` arguments must be a list `(...)`"),
        };
        let fidx = match self.lookup(fname) {
            Some(Sym::Func(f)) => f as usize,
            Some(Sym::Reg(_)) => return self.call_indirect(i, fname, rets, args),
            _ => return invalid(pos, format!("call of undeclared function `{fname}`")),
        };
        if ops.len() > k + 2 {
            return invalid(pos, "a direct `call` takes no prototype");
        }
        let callee = &self.sigs[fidx];
        if callee.is_entry {
            return invalid(pos, format!("`{fname}` is a kernel and cannot be called"));
        }
        // `vprintf` (what `printf` becomes) is executed by the simulator itself (`crate::sim::printf`)
        if !callee.has_body && callee.name != "vprintf" {
            return unsupported(pos, format!("call of `{fname}`, which has no body in this module"));
        }
        if args.len() != callee.params.len() || rets.len() != callee.returns.len() {
            return invalid(
                pos,
                format!(
                    "`{}` takes {} argument(s) and {} return value(s); the call passes {} and {}",
                    callee.name,
                    callee.params.len(),
                    callee.returns.len(),
                    args.len(),
                    rets.len()
                ),
            );
        }
        let param_var = |o: &Operand| -> LResult<(u32, u32)> {
            match o {
                Operand::Name(n) => match self.lookup(n) {
                    Some(Sym::FrameParam(off, size)) => Ok((off, size)),
                    _ => unsupported(pos, format!("call argument `{n}` that is not a .param variable")),
                },
                _ => unsupported(pos, "call argument that is not a .param variable"),
            }
        };
        // each argument and return value as large as the callee's parameter:
        // PTX passes `.param` variables whole, so a difference is an error,
        // never a copy silently shortened
        let sized = |what: &str, k: usize, o: &Operand, want: u32| -> LResult<(u32, u32)> {
            let (off, size) = param_var(o)?;
            if size != want {
                return invalid(
                    pos,
                    format!(
                        "{what} {} of the call of `{}` has {size} byte(s); the function's has {want}",
                        k + 1,
                        callee.name
                    ),
                );
            }
            Ok((off, size))
        };
        let mut a = Vec::new();
        for (k, (o, p)) in args.iter().zip(&callee.params).enumerate() {
            let (off, size) = sized("argument", k, o, p.size)?;
            a.push((off, p.offset, size));
        }
        let mut r = Vec::new();
        for (k, (o, p)) in rets.iter().zip(&callee.returns).enumerate() {
            let (off, size) = sized("return value", k, o, p.size)?;
            r.push((p.offset, off, size));
        }
        Ok(Kind::Call { func: fidx as u32, args: a, rets: r })
    }

    /// An indirect call: `call (rets), %reg, (args), prototype;`. The called
    /// function is known only at run time; its signature is checked then
    /// against the arguments (`.param` variables: offset and size).
    fn call_indirect(&self, i: &ast::Instruction, reg: &str, rets: &[Operand], args: &[Operand]) -> LResult<Kind> {
        let pos = i.pos;
        let param_var = |o: &Operand| -> LResult<(u32, u32)> {
            match o {
                Operand::Name(n) => match self.lookup(n) {
                    Some(Sym::FrameParam(off, size)) => Ok((off, size)),
                    _ => unsupported(pos, format!("call argument `{n}` that is not a .param variable")),
                },
                _ => unsupported(pos, "call argument that is not a .param variable"),
            }
        };
        let target = self.src(&Operand::Name(reg.to_string()), Ty::U64, pos)?;
        Ok(Kind::CallIndirect {
            target,
            args: args.iter().map(param_var).collect::<LResult<_>>()?,
            rets: rets.iter().map(param_var).collect::<LResult<_>>()?,
        })
    }
}
