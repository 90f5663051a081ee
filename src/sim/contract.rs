//! ptxas's FFMA contraction: which unrounded `mul` + `add`/`sub` pairs of a
//! function execute as one fused multiply-add.
//!
//! ptxas (default `--fmad=true`, and the driver's JIT alike) fuses a `mul`
//! into the `add`/`sub` instructions that use its product; the GPU then
//! rounds once. The rule, measured on an H200 with ptxas 13.0 over the 53
//! cases of `tests/fixtures/gpu_fma_contraction.json` (docs/gpu-measurements.md,
//! docs/semantics.md):
//!
//! 1. neither instruction has a rounding modifier, both have the same `.ftz`,
//!    the `mul` has no `.sat` (the add's `.sat` is kept) and both have the
//!    same type (`.f32`, `.f64`, `.f16`);
//! 2. *every* use of the product (through `mov` copies and `neg`, which
//!    folds into the sign of the product) is such an `add`/`sub`, in the same
//!    basic block as the `mul`; one other use blocks all of them. Each
//!    qualifying use becomes its own FMA;
//! 3. `add p, c` / `add c, p` → fma(a, b, c); `sub p, c` → fma(a, b, −c);
//!    `sub c, p` → fma(−a, b, c);
//! 4. when both operands of an add are contractible products the first is
//!    fused and the second read rounded (the second is fused when the first
//!    is not contractible).
//!
//! "The same basic block" is the PTX block, with one extension that ptxas's
//! optimiser makes: a loop between the two that computes nothing used
//! elsewhere (no store, its registers read nowhere else) is deleted, so the
//! `mul` and the `add` meet (`across_loop`). The pass works on definitions:
//! a later assignment to the product's register is not a use.
//!
//! Two limits, both outside the measured shapes: a pair is not fused when a
//! register the `mul` reads is assigned between the `mul` and the `add` (the
//! emulator reads the factors again at the add), nor when the `mul` is
//! predicated. The `mul` itself still executes (its register is read by
//! nothing else) and every instruction is still counted as written (PTX
//! instructions, not SASS: ncu would count one FFMA for the pair).

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::ptx::ir::*;
use crate::ptx::types::Ty;

static DEFAULT: AtomicBool = AtomicBool::new(true);

/// Whether contraction is on in [`crate::sim::SimConfig::default`]: on
/// (ptxas's default) unless [`set_default`] turned it off (`tables --fmad=false`).
pub fn default_on() -> bool {
    DEFAULT.load(Ordering::Relaxed)
}

/// Sets [`default_on`] for this process.
pub fn set_default(on: bool) {
    DEFAULT.store(on, Ordering::Relaxed)
}

/// An `add`/`sub` that executes as fma(±a, b, ±c).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fused {
    /// Index of the `mul` whose product is fused.
    pub mul: u32,
    /// The multiplication's first factor.
    pub a: Src,
    /// Its second factor.
    pub b: Src,
    /// The addend: the add's other operand.
    pub c: Src,
    /// The product enters negated (`sub c, p`, or through a `neg`).
    pub neg_product: bool,
    /// The addend enters negated (`sub p, c`).
    pub neg_c: bool,
}

/// The predicate registers an instruction (guard included) reads and writes.
fn preds(i: &Inst) -> (Vec<PredId>, Vec<PredId>) {
    let mut r: Vec<PredId> = i.guard.iter().map(|g| g.reg).collect();
    let mut w = Vec::new();
    match &i.kind {
        Kind::Setp { p, q, comb, .. } => {
            w.push(*p);
            w.extend(q);
            r.extend(comb.iter().map(|c| c.1.reg));
        }
        Kind::Set { comb, .. } => r.extend(comb.iter().map(|c| c.1.reg)),
        Kind::Selp { p, .. } => r.push(p.reg),
        Kind::PredLogic { d, a, b, .. } => {
            w.push(*d);
            r.extend([a.reg, b.reg]);
        }
        Kind::Vote { p, a, .. } | Kind::BarRed { p, a, .. } => {
            w.push(*p);
            r.push(a.reg);
        }
        Kind::Shfl { p, .. } | Kind::Match { p, .. } => w.extend(p),
        _ => {}
    }
    (r, w)
}

/// The function's instructions with what the rule needs to know of them.
struct Facts<'a> {
    insts: &'a [Inst],
    reads: Vec<Vec<RegId>>,
    writes: Vec<Vec<RegId>>,
    /// Number of instructions writing each register.
    defs: HashMap<RegId, usize>,
    /// For each instruction index, the branches that jump to it.
    into: HashMap<u32, Vec<u32>>,
}

impl<'a> Facts<'a> {
    fn new(f: &'a Function) -> Self {
        let reads: Vec<_> = f.insts.iter().map(|i| i.kind.reads()).collect();
        let writes: Vec<_> = f.insts.iter().map(|i| i.kind.writes()).collect();
        let mut defs = HashMap::new();
        for w in writes.iter().flatten() {
            *defs.entry(*w).or_insert(0) += 1;
        }
        let mut into: HashMap<u32, Vec<u32>> = HashMap::new();
        for (k, i) in f.insts.iter().enumerate() {
            if let Kind::Bra { target, .. } = i.kind {
                into.entry(target).or_default().push(k as u32);
            }
        }
        Facts { insts: &f.insts, reads, writes, defs, into }
    }

    /// The instructions that read the value instruction `i` writes into
    /// register `r`; `None` when that cannot be decided simply.
    fn uses(&self, i: usize, r: RegId) -> Option<Vec<usize>> {
        if self.defs.get(&r) == Some(&1) {
            return Some((0..self.insts.len()).filter(|&k| k != i && self.reads[k].contains(&r)).collect());
        }
        // several definitions: follow the straight line to the next one
        let mut out = Vec::new();
        for k in i + 1..self.insts.len() {
            if self.into.contains_key(&(k as u32)) {
                return None; // another path joins: other definitions may reach too
            }
            if self.reads[k].contains(&r) {
                out.push(k);
            }
            let inst = &self.insts[k];
            let unguarded = inst.guard.is_none();
            match inst.kind {
                Kind::Bra { .. } | Kind::Call { .. } | Kind::CallIndirect { .. } => return None,
                Kind::Ret | Kind::Exit if unguarded => return Some(out),
                _ => {}
            }
            if unguarded && self.writes[k].contains(&r) {
                return Some(out);
            }
        }
        Some(out)
    }

    /// Whether the code from `i` to `j` (`i < j`) is one basic block once
    /// ptxas deletes loops that compute nothing used elsewhere: no branch
    /// enters it from outside or leaves it, no call, return or exit, and if it
    /// has branches, no store, atomic, barrier or warp instruction and no
    /// register or predicate written in it read outside it.
    fn one_block(&self, i: usize, j: usize) -> bool {
        let inside = |k: u32| (i as u32) < k && k < j as u32;
        let mut branchy = false;
        for k in i + 1..=j {
            if let Some(srcs) = self.into.get(&(k as u32))
                && srcs.iter().any(|&s| !inside(s))
            {
                return false;
            }
            if k == j {
                break;
            }
            match self.insts[k].kind {
                Kind::Bra { target, .. } => {
                    if !(inside(target) || target == j as u32) {
                        return false;
                    }
                    branchy = true;
                }
                Kind::Call { .. } | Kind::CallIndirect { .. } | Kind::Ret | Kind::Exit | Kind::Trap => return false,
                _ => {}
            }
        }
        if !branchy {
            return true;
        }
        let mut regs = Vec::new();
        let mut prds = Vec::new();
        for k in i + 1..j {
            if matches!(
                self.insts[k].kind,
                Kind::St { .. }
                    | Kind::Atom { .. }
                    | Kind::Bar { .. }
                    | Kind::BarRed { .. }
                    | Kind::Vote { .. }
                    | Kind::Shfl { .. }
                    | Kind::Redux { .. }
                    | Kind::Match { .. }
            ) {
                return false;
            }
            regs.extend(&self.writes[k]);
            prds.extend(preds(&self.insts[k]).1);
        }
        (0..self.insts.len()).filter(|&k| !inside(k as u32)).all(|k| {
            !self.reads[k].iter().any(|r| regs.contains(r)) && !preds(&self.insts[k]).0.iter().any(|p| prds.contains(p))
        })
    }

    /// The `add`/`sub` instructions the product `r` written at `i` reaches
    /// through `mov` and `neg` (with the product's sign), when every use is
    /// one of them; `None` when another use blocks the contraction.
    fn add_uses(&self, i: usize, r: RegId, ty: Ty, ftz: bool, neg: bool, out: &mut Vec<(usize, RegId, bool)>) -> bool {
        let Some(uses) = self.uses(i, r) else { return false };
        for u in uses {
            if u <= i || out.len() > 64 {
                return false;
            }
            let inst = &self.insts[u];
            match inst.kind {
                Kind::Mov { d, a: Src::Reg(x) } if x == r && inst.guard.is_none() && d.reg != Dst::SINK => {
                    if !self.add_uses(u, d.reg, ty, ftz, neg, out) {
                        return false;
                    }
                }
                Kind::Arith { op: ArithOp::Neg, ty: t, mode, d, .. }
                    if t == ty && mode == FloatMode::default() && inst.guard.is_none() && d.reg != Dst::SINK =>
                {
                    if !self.add_uses(u, d.reg, ty, ftz, !neg, out) {
                        return false;
                    }
                }
                Kind::Arith { op: ArithOp::Add | ArithOp::Sub, ty: t, mode, .. }
                    if t == ty && mode.rnd.is_none() && mode.ftz == ftz && !mode.approx =>
                {
                    out.push((u, r, neg));
                }
                _ => return false,
            }
        }
        true
    }
}

/// Whether `ty` has an FMA that ptxas contracts into.
fn fusable(ty: Ty) -> bool {
    matches!(ty, Ty::F32 | Ty::F64 | Ty::F16)
}

/// The `add`/`sub` instructions of `f` that ptxas fuses with a `mul`, by index.
pub fn contract(f: &Function) -> HashMap<u32, Fused> {
    let facts = Facts::new(f);
    // (add index, register it reads) → (mul index, product negated)
    let mut feeds: HashMap<(usize, RegId), (usize, bool)> = HashMap::new();
    for (i, inst) in f.insts.iter().enumerate() {
        let Kind::Arith { op: ArithOp::Mul, ty, mode, d, a, b, .. } = inst.kind else { continue };
        if !fusable(ty) || mode.rnd.is_some() || mode.sat || inst.guard.is_some() || d.reg == Dst::SINK {
            continue;
        }
        let factors: Vec<RegId> = [a, b]
            .iter()
            .filter_map(|s| match s {
                Src::Reg(r) => Some(*r),
                _ => None,
            })
            .collect();
        if factors.contains(&d.reg) {
            continue;
        }
        let mut adds = Vec::new();
        if !facts.add_uses(i, d.reg, ty, mode.ftz, false, &mut adds) || adds.is_empty() {
            continue;
        }
        let ok = adds.iter().all(|&(u, _, _)| {
            facts.one_block(i, u) && (i + 1..u).all(|k| !facts.writes[k].iter().any(|w| factors.contains(w)))
        });
        if ok {
            for (u, r, neg) in adds {
                feeds.insert((u, r), (i, neg));
            }
        }
    }
    let mut out = HashMap::new();
    for (u, inst) in f.insts.iter().enumerate() {
        let Kind::Arith { op: op @ (ArithOp::Add | ArithOp::Sub), a, b, .. } = inst.kind else { continue };
        let fed = |s: Src| match s {
            Src::Reg(r) => feeds.get(&(u, r)).copied(),
            _ => None,
        };
        let sub = op == ArithOp::Sub;
        // the first operand's product wins; the other operand is read rounded
        let (mul, neg, c, neg_c) = match (fed(a), fed(b)) {
            (Some((m, n)), _) => (m, n, b, sub),
            (None, Some((m, n))) => (m, n ^ sub, a, false),
            (None, None) => continue,
        };
        let Kind::Arith { a: fa, b: fb, .. } = f.insts[mul].kind else { unreachable!("a mul") };
        out.insert(u as u32, Fused { mul: mul as u32, a: fa, b: fb, c, neg_product: neg, neg_c });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The indices of the fused adds of kernel `k` whose body is `body`.
    fn fused(body: &str) -> Vec<u32> {
        let src = format!(
            ".version 8.0\n.target sm_90\n.address_size 64\n.visible .entry k()\n{{\n\
             .reg .pred %p<2>;\n.reg .f32 %f<8>;\n{body}\nret;\n}}\n"
        );
        let prog = crate::ptx::load(&src, "c.ptx").unwrap();
        let mut v: Vec<u32> = contract(&prog.functions[0]).into_keys().collect();
        v.sort_unstable();
        v
    }

    #[test]
    fn carries_write_the_condition_code_only_with_cc() {
        let src = ".version 8.0\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n.reg .b32 %r<8>;\n\
                   add.cc.u32 %r1, %r2, %r3;\naddc.u32 %r4, %r2, %r3;\naddc.cc.u32 %r5, %r2, %r3;\nret;\n}\n";
        let prog = crate::ptx::load(src, "c.ptx").unwrap();
        let w: Vec<usize> = prog.functions[0].insts[..3].iter().map(|i| i.kind.writes().len()).collect();
        assert_eq!(w, [2, 1, 2], "add.cc, addc, addc.cc");
    }

    #[test]
    fn a_single_add_use_is_fused_with_the_product_sign() {
        let f = fused("mul.f32 %f3, %f1, %f2;\nsub.f32 %f4, %f5, %f3;");
        assert_eq!(f, vec![1]);
        let src = ".version 8.0\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n.reg .f32 %f<8>;\n\
                   mul.f32 %f3, %f1, %f2;\nsub.f32 %f4, %f5, %f3;\nret;\n}\n";
        let prog = crate::ptx::load(src, "c.ptx").unwrap();
        let fz = contract(&prog.functions[0])[&1];
        assert_eq!((fz.mul, fz.neg_product, fz.neg_c, fz.c), (0, true, false, Src::Reg(5)));
    }

    #[test]
    fn other_uses_rounding_and_flush_modes_block_it() {
        assert!(fused("mul.f32 %f3, %f1, %f2;\nadd.f32 %f4, %f3, %f5;\nsetp.lt.f32 %p1, %f3, %f5;").is_empty());
        assert!(fused("mul.rn.f32 %f3, %f1, %f2;\nadd.f32 %f4, %f3, %f5;").is_empty());
        assert!(fused("mul.f32 %f3, %f1, %f2;\nadd.rz.f32 %f4, %f3, %f5;").is_empty());
        assert!(fused("mul.ftz.f32 %f3, %f1, %f2;\nadd.f32 %f4, %f3, %f5;").is_empty());
        assert!(fused("mul.f32 %f3, %f1, %f2;\nabs.f32 %f6, %f3;\nadd.f32 %f4, %f6, %f5;").is_empty());
    }

    #[test]
    fn a_use_in_another_block_blocks_it() {
        let body = "mul.f32 %f3, %f1, %f2;\n@%p1 bra L;\nadd.f32 %f4, %f3, %f5;\nL:\nadd.f32 %f6, %f3, %f5;";
        assert!(fused(body).is_empty());
    }

    /// The two limits outside the measured shapes: a predicated `mul`, and a
    /// factor register assigned between the `mul` and the add.
    #[test]
    fn documented_limits_are_not_fused() {
        assert!(fused("@%p1 mul.f32 %f3, %f1, %f2;\nadd.f32 %f4, %f3, %f5;").is_empty());
        assert!(fused("mul.f32 %f3, %f1, %f2;\nmov.f32 %f1, %f5;\nadd.f32 %f4, %f3, %f5;").is_empty());
    }

    #[test]
    fn through_mov_and_neg_each_add_is_fused() {
        let body = "mul.f32 %f3, %f1, %f2;\nmov.f32 %f6, %f3;\nneg.f32 %f7, %f3;\nadd.f32 %f4, %f6, %f5;\nadd.f32 %f5, %f7, %f4;";
        assert_eq!(fused(body), vec![3, 4]);
    }
}
