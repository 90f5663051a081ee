//! Validation of an instruction's shape before it is lowered: the modifiers
//! its opcode accepts, its types, its operand count and operand forms. What
//! passes here is lowered by the family files without re-checking; what is
//! refused is an error at the instruction — `unsupported` for valid PTX that
//! warplight does not execute, `invalid` for PTX that breaks a rule.

use super::opcode::{Decoded, Opcode, atom_op_of, bool_of, cmp_of};
use super::{LResult, invalid, unsupported};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::Rounding;
use crate::ptx::types::Ty;

/// Rounding-mode words.
pub const ROUNDINGS: &[&str] = &["rn", "rz", "rm", "rp", "rni", "rzi", "rmi", "rpi"];

/// Qualifiers `ld` and `st` accept (caching, ordering and scope have no effect on results).
const LD_ST_WORDS: &[&str] = &[
    "v2",
    "v4",
    "nc",
    "volatile",
    "weak",
    "relaxed",
    "acquire",
    "release",
    "ca",
    "cg",
    "cs",
    "lu",
    "cv",
    "wb",
    "wt",
    "cta",
    "gpu",
    "sys",
    "L1::evict_normal",
    "L1::evict_unchanged",
    "L1::evict_first",
    "L1::evict_last",
    "L1::no_allocate",
    "L2::64B",
    "L2::128B",
    "L2::256B",
    "L2::evict_first",
    "L2::evict_last",
    "L2::evict_normal",
];

/// Ordering, scope and `.noftz` words of atomics (no effect in the model).
const ATOM_IGNORED: &[&str] = &["relaxed", "acquire", "release", "acq_rel", "cta", "gpu", "sys", "noftz"];

/// Fails for a constant barrier id past 15 or a constant thread count that
/// is not a positive multiple of the warp size up to a CTA's 1024 threads (as
/// ptxas refuses them); ids and counts in registers are checked when they
/// execute (a fault).
fn constant_barrier(pos: crate::ptx::error::Pos, id: &Operand, count: Option<&Operand>) -> LResult<()> {
    if let Operand::Lit(ast::Literal::Int(v)) = id
        && *v > 15
    {
        return invalid(pos, format!("barrier id {} is out of range (a CTA has barriers 0 to 15)", *v as i64));
    }
    if let Some(Operand::Lit(ast::Literal::Int(c))) = count
        && (*c == 0 || c % 32 != 0 || *c > 1024)
    {
        return invalid(
            pos,
            format!(
                "a barrier thread count of {}: it must be a positive multiple of 32 (the warp size), at most 1024 (a CTA's threads)",
                *c as i64
            ),
        );
    }
    Ok(())
}

/// Fails when a modifier word of `d` is not in `allowed`.
fn only(d: &Decoded, allowed: &[&str], i: &ast::Instruction) -> LResult<()> {
    for w in &d.mods.words {
        if !allowed.contains(&w.as_str()) {
            return unsupported(i.pos, format!("{} (modifier .{w})", d.full));
        }
    }
    Ok(())
}

/// Fails unless `i` has `n` operands.
pub fn operands(i: &ast::Instruction, n: usize) -> LResult<()> {
    if i.operands.len() != n {
        return invalid(i.pos, format!("`{}` takes {n} operands, found {}", i.full_opcode(), i.operands.len()));
    }
    Ok(())
}

/// The single type of `d`.
pub fn one_type(d: &Decoded, i: &ast::Instruction) -> LResult<Ty> {
    match d.mods.types.as_slice() {
        [t] => Ok(*t),
        [] => invalid(i.pos, format!("`{}` needs a type", d.full)),
        _ => invalid(i.pos, format!("`{}` has more than one type", d.full)),
    }
}

/// The source operand count and extra modifier words of an arithmetic opcode.
pub fn arith_shape(op: Opcode) -> (usize, &'static [&'static str]) {
    use Opcode::*;
    match op {
        Mul => (2, &["lo", "hi", "wide"]),
        Mad | Fma => (3, &["lo", "hi", "wide"]),
        Mul24 => (2, &["lo", "hi"]),
        Mad24 => (3, &["lo", "hi"]),
        Shf => (3, &["l", "r", "wrap", "clamp"]),
        Bfe => (3, &[]),
        Prmt => (3, &["f4e", "b4e", "rc8", "ecl", "ecr", "rc16"]),
        Bfind => (1, &["shiftamt"]),
        Addc | Subc => (2, &["cc"]),
        Madc => (3, &["lo", "hi", "cc"]),
        Abs | Neg | Not | Cnot | Popc | Clz | Brev | Sqrt | Rsqrt | Rcp | Sin | Cos | Ex2 | Lg2 | Tanh => (1, &[]),
        _ => (2, &[]),
    }
}

/// Width of each part of a `mov` vector operand of `parts` parts of a `bits`-wide type.
pub fn part_bits(bits: u32, parts: usize, i: &ast::Instruction) -> LResult<u32> {
    let b = if parts == 0 { 0 } else { bits / parts as u32 };
    if !matches!(b, 8 | 16 | 32) {
        return invalid(i.pos, "vector move parts must be 8, 16 or 32 bits");
    }
    Ok(b)
}

/// Checks the shape of `i` (decoded as `d`).
pub fn validate(d: &Decoded, i: &ast::Instruction) -> LResult<()> {
    use Opcode::*;
    let pos = i.pos;
    let m = &d.mods;
    let n_ops = i.operands.len();
    match d.op {
        Mov => {
            operands(i, 2)?;
            only(d, &[], i)?;
            let t = one_type(d, i)?;
            if t != Ty::Pred {
                match (&i.operands[0], &i.operands[1]) {
                    (_, Operand::Vector(p)) | (Operand::Vector(p), _) => {
                        part_bits(t.bits(), p.len(), i)?;
                    }
                    _ => {}
                }
            }
        }
        And | Or | Xor | Not | Cnot if m.types.first() == Some(&Ty::Pred) => {
            operands(i, if matches!(d.op, Not | Cnot) { 2 } else { 3 })?;
        }
        Bfi => {
            operands(i, 5)?;
            only(d, &[], i)?;
            one_type(d, i)?;
        }
        Setp | Set => {
            let mut cmp = None;
            let mut comb = false;
            for w in &m.words {
                if let Some(c) = cmp_of(w).filter(|_| cmp.is_none()) {
                    cmp = Some(c);
                } else if bool_of(w).is_some() {
                    comb = true;
                } else if w != "ftz" {
                    return unsupported(pos, format!("{} (modifier .{w})", d.full));
                }
            }
            if cmp.is_none() {
                return invalid(pos, format!("`{}` needs a comparison", d.full));
            }
            operands(i, if comb { 4 } else { 3 })?;
            let packed = m.types.iter().any(|t| matches!(t, Ty::F16x2 | Ty::BF16x2));
            if packed && d.op == Setp && !matches!(i.operands[0], Operand::Pair(..)) {
                // `setp` on packed halves writes two predicates: `p|q`
                return unsupported(pos, format!("{} (packed halves)", d.full));
            }
            if d.op == Setp {
                one_type(d, i)?;
            } else if m.types.len() != 2 {
                return invalid(pos, "`set` needs a destination and a source type");
            } else if packed {
                // `set.dty.f16x2`: dty `.f16x2 .u32 .s32`; `set.dty.bf16x2`: `.bf16x2 .u32 .s32`
                let (dty, sty) = (m.types[0], m.types[1]);
                let ok = matches!(sty, Ty::F16x2 | Ty::BF16x2) && (dty == sty || matches!(dty, Ty::U32 | Ty::S32));
                if !ok {
                    return invalid(pos, format!("`{}`: packed halves compare into .{sty}, .u32 or .s32 only", d.full));
                }
            }
        }
        Selp => {
            operands(i, 4)?;
            only(d, &[], i)?;
            one_type(d, i)?;
        }
        Cvt => {
            let pack = matches!(m.types.first(), Some(Ty::F16x2 | Ty::BF16x2));
            operands(i, if pack { 3 } else { 2 })?;
            if pack && m.types.get(1) != Some(&Ty::F32) {
                return unsupported(pos, d.full.clone());
            }
            let mut allowed = ROUNDINGS.to_vec();
            allowed.extend(["ftz", "sat"]);
            only(d, &allowed, i)?;
            let [dty, sty] = m.types.as_slice() else {
                return invalid(pos, "`cvt` needs a destination and a source type");
            };
            if (matches!(dty, Ty::F16x2 | Ty::BF16x2) && *sty != Ty::F32) || matches!(sty, Ty::F16x2 | Ty::BF16x2) {
                return unsupported(pos, format!("{} (packed halves)", d.full));
            }
            if dty.is_float()
                && sty.is_int()
                && matches!(m.rounding(), Some(Rounding::Rni | Rounding::Rzi | Rounding::Rmi | Rounding::Rpi))
            {
                return invalid(pos, "integer rounding modifier on an int-to-float conversion");
            }
        }
        Cvta => {
            operands(i, 2)?;
            only(d, &["to"], i)?;
            one_type(d, i)?;
            if m.space.is_none() {
                return invalid(pos, "`cvta` needs a state space");
            }
        }
        Ld | St => {
            operands(i, 2)?;
            only(d, LD_ST_WORDS, i)?;
            one_type(d, i)?;
            let vals = if d.op == Ld { &i.operands[0] } else { &i.operands[1] };
            let n = match vals {
                Operand::Vector(v) => v.len(),
                _ => 1,
            };
            if n != m.vec() as usize {
                return invalid(pos, format!("`{}` moves {} value(s), found {n}", d.full, m.vec()));
            }
        }
        Atom | Red => {
            let mut op = None;
            for w in &m.words {
                match atom_op_of(w) {
                    Some(o) => op = Some(o),
                    None if ATOM_IGNORED.contains(&w.as_str()) => {}
                    None => return unsupported(pos, format!("{} (modifier .{w})", d.full)),
                }
            }
            let Some(op) = op else {
                return invalid(pos, format!("`{}` needs an operation", d.full));
            };
            let t = one_type(d, i)?;
            if t.bits() < 32 || t == Ty::F16 {
                return unsupported(pos, format!("{} (types narrower than 32 bits)", d.full));
            }
            let has_d = d.op == Atom;
            operands(i, usize::from(has_d) + 2 + usize::from(op == crate::ptx::ir::AtomOp::Cas))?;
        }
        Bra => {
            operands(i, 1)?;
            only(d, &["uni"], i)?;
            if !matches!(i.operands[0], Operand::Name(_)) {
                return invalid(pos, "`bra` needs a label");
            }
        }
        Call | Ret => only(d, &["uni"], i)?,
        Bar | Barrier if m.has("warp") => {
            // bar.warp.sync membermask
            only(d, &["warp", "sync"], i)?;
            operands(i, 1)?;
        }
        Bar | Barrier if m.has("red") => {
            only(d, &["red", "popc", "and", "or", "aligned", "sync"], i)?;
            let t = one_type(d, i)?;
            let ok = if m.has("popc") { t == Ty::U32 } else { (m.has("and") || m.has("or")) && t == Ty::Pred };
            if !ok {
                return invalid(pos, format!("`{}` needs .popc.u32, .and.pred or .or.pred", d.full));
            }
            if n_ops != 3 && n_ops != 4 {
                return invalid(
                    pos,
                    format!("`{}` takes a destination, a barrier id, an optional count and a predicate", d.full),
                );
            }
            constant_barrier(pos, &i.operands[1], (n_ops == 4).then(|| &i.operands[2]))?;
        }
        Bar | Barrier => {
            only(d, &["sync", "aligned"], i)?;
            if !m.has("sync") && d.op == Bar && !m.words.is_empty() {
                return unsupported(pos, d.full.clone());
            }
            if n_ops == 0 || n_ops > 2 {
                return invalid(pos, format!("`{}` takes a barrier id and an optional thread count", d.full));
            }
            constant_barrier(pos, &i.operands[0], i.operands.get(1))?;
        }
        Vote => {
            only(d, &["sync", "all", "any", "uni", "ballot"], i)?;
            if m.vote_mode().is_none() {
                return invalid(pos, "`vote` needs a mode");
            }
            operands(i, if m.has("sync") { 3 } else { 2 })?;
        }
        Activemask => operands(i, 1)?,
        Redux => {
            only(d, &["sync", "add", "min", "max", "and", "or", "xor"], i)?;
            operands(i, 3)?;
            let t = one_type(d, i)?;
            if !matches!(t, Ty::U32 | Ty::S32 | Ty::B32) {
                return unsupported(pos, format!("{} (.{t})", d.full));
            }
            if m.words.iter().filter(|w| *w != "sync").count() != 1 {
                return invalid(pos, format!("`{}` needs one operation", d.full));
            }
        }
        Match => {
            only(d, &["sync", "any", "all"], i)?;
            operands(i, 3)?;
            if !matches!(one_type(d, i)?, Ty::B32 | Ty::B64) {
                return invalid(pos, format!("`{}` takes .b32 or .b64", d.full));
            }
            if m.has("any") == m.has("all") {
                return invalid(pos, format!("`{}` needs .any or .all", d.full));
            }
        }
        Dp4a | Dp2a => {
            only(d, &["lo", "hi"], i)?;
            operands(i, 4)?;
            if m.types.len() != 2 || m.types.iter().any(|t| !matches!(t, Ty::U32 | Ty::S32)) {
                return invalid(pos, format!("`{}` needs two types, each .u32 or .s32", d.full));
            }
            if d.op == Dp2a && m.has("lo") == m.has("hi") {
                return invalid(pos, format!("`{}` needs .lo or .hi", d.full));
            }
        }
        Shfl => {
            only(d, &["sync", "up", "down", "bfly", "idx"], i)?;
            if m.shfl_mode().is_none() {
                return invalid(pos, "`shfl` needs a mode");
            }
            operands(i, if m.has("sync") { 5 } else { 4 })?;
        }
        Exit | Trap | Membar | Fence | Prefetch | Prefetchu | Pmevent | Nanosleep | Brkpt | Nop => {}
        Tex | Tld4 | Txq | Suld | Sust | Sured => super::texture::validate(d, i)?,
        // the arithmetic opcodes
        _ => {
            let t = one_type(d, i)?;
            let carry = m.has("cc") || matches!(d.op, Addc | Subc | Madc);
            if carry && (!matches!(d.op, Add | Sub | Mad | Addc | Subc | Madc) || m.has("wide")) {
                return invalid(pos, format!("`{}`: no carry-chain form", d.full));
            }
            if carry && !matches!(t, Ty::U32 | Ty::S32 | Ty::U64 | Ty::S64) {
                return invalid(pos, format!("`{}`: carry chains take .u32 .s32 .u64 .s64", d.full));
            }
            let (nsrc, extra) = arith_shape(d.op);
            let mut allowed: Vec<&str> = vec!["ftz", "sat", "approx", "full", "cc"];
            allowed.extend(ROUNDINGS);
            allowed.extend(extra);
            only(d, &allowed, i)?;
            operands(i, nsrc + 1)?;
            // ex2 and tanh on halves: `.approx` only, as PTX defines them
            let half_sfu = matches!(d.op, Ex2 | Tanh) && m.has("approx");
            let half_ok = matches!(d.op, Add | Sub | Mul | Mad | Fma | Neg | Abs | Min | Max) || half_sfu;
            if t.is_float() && t != Ty::F32 && t != Ty::F64 && !half_ok {
                return unsupported(pos, format!("{} (.{t})", d.full));
            }
            if d.op == Tanh && (!m.has("approx") || t == Ty::F64) {
                return invalid(pos, format!("`{}`: tanh is .approx on .f32 and halves", d.full));
            }
            if t.is_float() && matches!(d.op, Mul | Mad | Fma) && (m.has("hi") || m.has("wide")) {
                return invalid(pos, format!("`{}`: .hi/.wide apply to integers", d.full));
            }
        }
    }
    Ok(())
}
