//! Which registers of a function hold the same value in every lane of a warp,
//! as far as a static look at the PTX can tell — the values ptxas can prove
//! warp-uniform. The ptxas plan ([`super::vectorize`]) uses it to find the
//! global atomics ptxas merges into one lane's operation per warp.
//!
//! Uniform are: immediates, module variables' addresses, `%ntid %ctaid
//! %nctaid %gridid`, a kernel's parameters (`ld.param` of a kernel at a
//! uniform address), and loads of global, constant or shared memory at a
//! uniform address (not `.volatile`; one warp-level load reads one value);
//! then whatever `mov cvt cvta` and arithmetic, comparisons, `selp` and
//! predicate logic compute from uniform operands alone under a uniform guard
//! (or none). Everything else — `%tid %laneid` and the other special
//! registers, atomics' and warp operations' results, local memory, a called
//! function's parameters and results, generic loads — is taken as varying;
//! so are global and shared loads in a function with divergent control flow
//! (below): a load in a loop the lanes leave at different iterations runs at
//! different times for different lanes.
//!
//! Divergent control flow: where some branch of the function is guarded by a
//! varying predicate, lanes may reach a register's definitions along
//! different paths, so a register (or predicate) written by more than one
//! instruction is varying; one written once is uniform when that
//! instruction's operands are. Without such a branch, every definition with
//! uniform operands keeps the register uniform (a loop counter of a uniform
//! loop, say). The analysis is an optimistic fixed point: everything starts
//! uniform and is made varying until nothing changes.

use crate::ptx::ir::{Function, Kind, MemSpace, PRED_FALSE, PRED_TRUE, PredId, PredSrc, RegId, SpecialReg, Src};

/// The uniform registers and predicates of one function.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Uniformity {
    /// Per data register: uniform.
    pub regs: Vec<bool>,
    /// Per predicate register: uniform.
    pub preds: Vec<bool>,
}

impl Uniformity {
    /// Whether `s` has the same value in every lane.
    pub fn src(&self, s: &Src) -> bool {
        match s {
            Src::Reg(r) => self.regs.get(*r as usize).copied().unwrap_or(false),
            Src::Imm(_) | Src::GlobalAddr(..) => true,
            Src::Special(sr) => {
                matches!(sr, SpecialReg::Ntid(_) | SpecialReg::Ctaid(_) | SpecialReg::Nctaid(_) | SpecialReg::GridId)
            }
            Src::LocalAddr(_) => false,
        }
    }

    /// Whether predicate `p` has the same value in every lane.
    pub fn pred(&self, p: PredSrc) -> bool {
        self.pred_id(p.reg)
    }

    fn pred_id(&self, p: PredId) -> bool {
        p == PRED_TRUE || p == PRED_FALSE || self.preds.get(p as usize).copied().unwrap_or(false)
    }
}

/// What an instruction writes: data registers, predicates.
fn defs(k: &Kind) -> (Vec<RegId>, Vec<PredId>) {
    (k.writes(), k.pred_writes())
}

/// Whether the values `k` computes are uniform, given `u` (the guard aside);
/// `divergent`: the function branches on a varying predicate, so one load
/// may run at different times for different lanes (a loop they leave at
/// different iterations) and only read-only memory reads one value.
fn computes_uniform(k: &Kind, u: &Uniformity, is_entry: bool, divergent: bool) -> bool {
    let all = |ss: &[&Src]| ss.iter().all(|s| u.src(s));
    match k {
        Kind::Mov { a, .. } | Kind::Unpack { a, .. } | Kind::Cvt { a, .. } | Kind::Cvta { a, .. } => u.src(a),
        Kind::Pack { parts, .. } => parts.iter().all(|s| u.src(s)),
        Kind::Arith { a, b, c, .. } => all(&[a, b, c]),
        Kind::Setp { a, b, comb, .. } | Kind::Set { a, b, comb, .. } => {
            all(&[a, b]) && comb.is_none_or(|(_, c)| u.pred(c))
        }
        Kind::Bfi { a, b, c, e, .. } => all(&[a, b, c, e]),
        Kind::Selp { a, b, p, .. } => all(&[a, b]) && u.pred(*p),
        Kind::PredLogic { a, b, .. } => u.pred(*a) && u.pred(*b),
        Kind::Carry { a, b, c, cc, cin, .. } => all(&[a, b, c]) && (!cin || u.src(&Src::Reg(*cc))),
        Kind::Ld { space, addr, volatile, .. } => {
            let space_ok = match space {
                MemSpace::Const => true,
                MemSpace::Global | MemSpace::Shared => !divergent,
                MemSpace::KernelParam => is_entry,
                MemSpace::Local | MemSpace::FrameParam | MemSpace::Generic => false,
            };
            space_ok && !volatile && u.src(&addr.base)
        }
        _ => false,
    }
}

/// The uniform registers and predicates of `f` (see the module comment).
pub fn analyse(f: &Function) -> Uniformity {
    let mut u = Uniformity { regs: vec![true; f.reg_masks.len()], preds: vec![true; f.num_preds as usize] };
    let mut reg_defs = vec![0u32; f.reg_masks.len()];
    let mut pred_defs = vec![0u32; f.num_preds as usize];
    let all_defs: Vec<(Vec<RegId>, Vec<PredId>)> = f.insts.iter().map(|i| defs(&i.kind)).collect();
    for (rs, ps) in &all_defs {
        for &r in rs {
            if let Some(n) = reg_defs.get_mut(r as usize) {
                *n += 1;
            }
        }
        for &p in ps {
            if let Some(n) = pred_defs.get_mut(p as usize) {
                *n += 1;
            }
        }
    }
    loop {
        let mut changed = false;
        let divergent =
            f.insts.iter().any(|i| matches!(i.kind, Kind::Bra { .. }) && i.guard.is_some_and(|g| !u.pred(g)));
        for (inst, (rs, ps)) in f.insts.iter().zip(&all_defs) {
            let uniform =
                inst.guard.is_none_or(|g| u.pred(g)) && computes_uniform(&inst.kind, &u, f.is_entry, divergent);
            for &r in rs {
                let many = divergent && reg_defs.get(r as usize).is_some_and(|&n| n > 1);
                if let Some(x) = u.regs.get_mut(r as usize)
                    && *x
                    && (!uniform || many)
                {
                    *x = false;
                    changed = true;
                }
            }
            for &p in ps {
                let many = divergent && pred_defs.get(p as usize).is_some_and(|&n| n > 1);
                if p != PRED_TRUE
                    && p != PRED_FALSE
                    && let Some(x) = u.preds.get_mut(p as usize)
                    && *x
                    && (!uniform || many)
                {
                    *x = false;
                    changed = true;
                }
            }
        }
        if !changed {
            return u;
        }
    }
}
