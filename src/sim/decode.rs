//! The executable form of a module, decoded once when it is loaded: for every
//! instruction, what the executor would otherwise work out on every issue —
//! its counter class and, for arithmetic, the 32-lane function that the
//! `(operation, type, rounding)` triple selects. The executor looks the
//! instruction's [`Op`] up by PC and dispatches on it. Operands come from a
//! copy of the IR instructions whose registers are renamed to frame slots
//! ([`regalloc`](super::regalloc): a frame holds the live maximum of rows,
//! not one per virtual register).

use std::collections::HashMap;

use crate::ptx::ir::{ArithOp, FloatMode, Inst, InstClass, Kind, Program, RegId, Rounding, Src};
use crate::ptx::types::Ty;

use super::alu;
use super::cfg::Cfg;
use super::contract::{self, Fused};
use super::regalloc::Allocation;
use super::sfu::{self, SfuModel};

/// 32 lanes of register bits.
pub type Lanes = [u64; 32];

/// An arithmetic operation over 32 lanes with its type and modifiers resolved:
/// `f(a, b, c, out)` writes every lane of `out`.
pub type LaneFn = fn(&Lanes, &Lanes, &Lanes, &mut Lanes);

/// One decoded instruction (16 bytes: guarded by a test).
#[derive(Debug, Clone, Copy)]
pub struct Op {
    /// For arithmetic: the resolved 32-lane function; `None`: interpreted
    /// from the IR instruction.
    pub lanes: Option<LaneFn>,
    /// Whether `lanes` reads operand `c`.
    pub reads_c: bool,
    /// Its class, for the class counters.
    pub class: InstClass,
    /// An `add`/`sub` that executes fused with a `mul` ([`FnCode::fused`]).
    pub fused: bool,
}

/// A function's decoded instructions, parallel to its IR instructions.
#[derive(Debug, Clone)]
pub struct FnCode {
    /// One per instruction.
    pub ops: Vec<Op>,
    /// The IR instructions with every data register renamed to its frame
    /// slot ([`FnCode::alloc`]): what the executor reads operands from.
    pub insts: Vec<Inst>,
    /// The `add`/`sub` instructions ptxas would contract with a `mul`, by
    /// index ([`contract`]), operands renamed to slots; empty when
    /// contraction is off.
    pub fused: HashMap<u32, Fused>,
    /// Where each virtual register lives in a frame.
    pub alloc: Allocation,
}

impl FnCode {
    /// Rows of a register frame of this function.
    #[inline]
    pub fn rows(&self) -> usize {
        self.alloc.rows as usize
    }

    /// The frame row of virtual register `r` (the IR's numbering).
    #[inline]
    pub fn slot(&self, r: RegId) -> usize {
        self.alloc.slot[r as usize] as usize
    }
}

/// What the executable form models of the toolchain and the GPU's arithmetic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FloatOptions {
    /// ptxas's FFMA contraction of unrounded `mul` + `add`/`sub` ([`contract`]).
    pub fmad: bool,
    /// How approximate special functions are computed.
    pub sfu: SfuModel,
}

impl Default for FloatOptions {
    /// The H200's: contraction on, the MUFU table model.
    fn default() -> Self {
        FloatOptions { fmad: true, sfu: SfuModel::Sm90 }
    }
}

/// A decoded module.
#[derive(Debug, Clone, Default)]
pub struct Code {
    /// One per function of the program.
    pub funcs: Vec<FnCode>,
}

impl Code {
    /// Decodes every function of `prog`, with `opts` deciding contraction and
    /// the special functions, and registers compacted to their live maximum.
    pub fn decode(prog: &Program, opts: FloatOptions) -> Code {
        Code::decode_with(prog, opts, true)
    }

    /// As [`Code::decode`]; `compact: false` keeps one frame row per virtual
    /// register (every register keeps its last value, for inspection).
    pub fn decode_with(prog: &Program, opts: FloatOptions, compact: bool) -> Code {
        let funcs = prog
            .functions
            .iter()
            .map(|f| {
                let mut fused = if opts.fmad { contract::contract(f) } else { HashMap::new() };
                let alloc =
                    if compact { Allocation::compact(f, &Cfg::build(f), &fused) } else { Allocation::identity(f) };
                let mut insts = f.insts.clone();
                for i in &mut insts {
                    i.kind.visit_regs_mut(&mut |r, _, _| *r = alloc.slot[*r as usize]);
                }
                let rename = |s: &mut Src| {
                    if let Src::Reg(r) = s {
                        *r = alloc.slot[*r as usize];
                    }
                };
                for fz in fused.values_mut() {
                    rename(&mut fz.a);
                    rename(&mut fz.b);
                    rename(&mut fz.c);
                }
                let ops = f
                    .insts
                    .iter()
                    .zip(&f.info)
                    .enumerate()
                    .map(|(k, (i, info))| {
                        let is_fused = fused.contains_key(&(k as u32));
                        let r = match i.kind {
                            Kind::Arith { op, ty, mode, .. } if !is_fused => resolve_arith(op, ty, mode, opts.sfu),
                            _ => None,
                        };
                        Op {
                            lanes: r.map(|r| r.0),
                            reads_c: r.is_some_and(|r| r.1),
                            class: info.class,
                            fused: is_fused,
                        }
                    })
                    .collect();
                FnCode { ops, insts, fused, alloc }
            })
            .collect();
        Code { funcs }
    }
}

#[inline(always)]
fn map2(a: &Lanes, b: &Lanes, out: &mut Lanes, f: impl Fn(u64, u64) -> u64) {
    for l in 0..32 {
        out[l] = f(a[l], b[l]);
    }
}

#[inline(always)]
fn map3(a: &Lanes, b: &Lanes, c: &Lanes, out: &mut Lanes, f: impl Fn(u64, u64, u64) -> u64) {
    for l in 0..32 {
        out[l] = f(a[l], b[l], c[l]);
    }
}

#[inline(always)]
fn f32of(x: u64) -> f32 {
    f32::from_bits(x as u32)
}

/// An f32 result's bits, NaN made canonical (as `alu` does).
#[inline(always)]
pub fn canon32(x: f32) -> u64 {
    if x.is_nan() { alu::NAN32 as u64 } else { x.to_bits() as u64 }
}

/// `min`/`max` of f32 as `alu::arith` defines them (NaN operands ignored,
/// -0 below +0).
#[inline(always)]
fn minmax32(a: u64, b: u64, max: bool) -> u64 {
    let (x, y) = (f32of(a), f32of(b));
    let r = match (x.is_nan(), y.is_nan()) {
        (true, true) => f32::NAN,
        (true, false) => y,
        (false, true) => x,
        _ if x == y => {
            if (x.is_sign_negative() && !max) || (x.is_sign_positive() && max) {
                x
            } else {
                y
            }
        }
        _ if (x < y) != max => x,
        _ => y,
    };
    canon32(r)
}

macro_rules! lanefn2 {
    ($name:ident, |$x:ident, $y:ident| $e:expr) => {
        fn $name(a: &Lanes, b: &Lanes, _c: &Lanes, out: &mut Lanes) {
            map2(a, b, out, |$x, $y| $e)
        }
    };
}

macro_rules! lanefn3 {
    ($name:ident, |$x:ident, $y:ident, $z:ident| $e:expr) => {
        fn $name(a: &Lanes, b: &Lanes, c: &Lanes, out: &mut Lanes) {
            map3(a, b, c, out, |$x, $y, $z| $e)
        }
    };
}

lanefn2!(add32, |x, y| (x as u32).wrapping_add(y as u32) as u64);
lanefn2!(add64, |x, y| x.wrapping_add(y));
lanefn2!(sub32, |x, y| (x as u32).wrapping_sub(y as u32) as u64);
lanefn2!(sub64, |x, y| x.wrapping_sub(y));
lanefn2!(mul32, |x, y| (x as u32).wrapping_mul(y as u32) as u64);
lanefn2!(mul64, |x, y| x.wrapping_mul(y));
lanefn2!(and32, |x, y| x & y & 0xFFFF_FFFF);
lanefn2!(or32, |x, y| (x | y) & 0xFFFF_FFFF);
lanefn2!(xor32, |x, y| (x ^ y) & 0xFFFF_FFFF);
lanefn2!(and64, |x, y| x & y);
lanefn2!(or64, |x, y| x | y);
lanefn2!(xor64, |x, y| x ^ y);
lanefn2!(shl32, |x, s| if (s as u32) >= 32 { 0 } else { ((x as u32) << s) as u64 });
lanefn2!(shl64, |x, s| if (s as u32) >= 64 { 0 } else { x << s });
lanefn2!(shr_u32, |x, s| if (s as u32) >= 32 { 0 } else { ((x as u32) >> s) as u64 });
lanefn2!(shr_u64, |x, s| if (s as u32) >= 64 { 0 } else { x >> s });
lanefn2!(shr_s32, |x, s| ((x as i32) >> (s as u32).min(31)) as u32 as u64);
lanefn2!(mul_wide_s32, |x, y| ((x as i32 as i64) * (y as i32 as i64)) as u64);
lanefn2!(mul_wide_u32, |x, y| (x & 0xFFFF_FFFF) * (y & 0xFFFF_FFFF));
lanefn2!(min_s32, |x, y| (x as i32).min(y as i32) as u32 as u64);
lanefn2!(max_s32, |x, y| (x as i32).max(y as i32) as u32 as u64);
lanefn2!(min_u32, |x, y| (x as u32).min(y as u32) as u64);
lanefn2!(max_u32, |x, y| (x as u32).max(y as u32) as u64);
lanefn3!(mad32, |x, y, z| (x as u32).wrapping_mul(y as u32).wrapping_add(z as u32) as u64);
lanefn2!(fadd, |x, y| canon32(f32of(x) + f32of(y)));
lanefn2!(fsub, |x, y| canon32(f32of(x) - f32of(y)));
lanefn2!(fmul, |x, y| canon32(f32of(x) * f32of(y)));
lanefn2!(fdiv, |x, y| canon32(f32of(x) / f32of(y)));
lanefn2!(fmin, |x, y| minmax32(x, y, false));
lanefn2!(fmax, |x, y| minmax32(x, y, true));
lanefn2!(fneg, |x, _y| canon32(-f32of(x)));
lanefn2!(fabs, |x, _y| canon32(f32of(x).abs()));
lanefn2!(frcp, |x, _y| canon32(1.0 / f32of(x)));
lanefn2!(fsqrt, |x, _y| canon32(f32of(x).sqrt()));
lanefn3!(ffma, |x, y, z| canon32(f32of(x).mul_add(f32of(y), f32of(z))));
lanefn2!(mufu_rcp, |x, _y| sfu::rcp(x as u32, false) as u64);
lanefn2!(mufu_rcp_ftz, |x, _y| sfu::rcp(x as u32, true) as u64);
lanefn2!(mufu_rsq, |x, _y| sfu::rsq(x as u32, false, false) as u64);
lanefn2!(mufu_rsq_ftz, |x, _y| sfu::rsq(x as u32, false, true) as u64);
lanefn2!(mufu_sqrt, |x, _y| sfu::rsq(x as u32, true, false) as u64);
lanefn2!(mufu_sqrt_ftz, |x, _y| sfu::rsq(x as u32, true, true) as u64);
lanefn2!(div_approx, |x, y| sfu::div_approx(x as u32, y as u32, false) as u64);
lanefn2!(div_approx_ftz, |x, y| sfu::div_approx(x as u32, y as u32, true) as u64);
lanefn2!(div_full, |x, y| sfu::div_full(x as u32, y as u32, false) as u64);
lanefn2!(div_full_ftz, |x, y| sfu::div_full(x as u32, y as u32, true) as u64);

/// The H200 table model's function of an f32 approximation, when `sfu` asks
/// for it and the form has one (no `.sat`, no rounding modifier).
fn resolve_sfu(op: ArithOp, ty: Ty, mode: FloatMode, sfu: SfuModel) -> Option<LaneFn> {
    if sfu != SfuModel::Sm90 || ty != Ty::F32 || !mode.approx || mode.sat || mode.rnd.is_some() {
        return None;
    }
    Some(match (op, mode.ftz, mode.full) {
        (ArithOp::Rcp, false, _) => mufu_rcp,
        (ArithOp::Rcp, true, _) => mufu_rcp_ftz,
        (ArithOp::Rsqrt, false, _) => mufu_rsq,
        (ArithOp::Rsqrt, true, _) => mufu_rsq_ftz,
        (ArithOp::Sqrt, false, _) => mufu_sqrt,
        (ArithOp::Sqrt, true, _) => mufu_sqrt_ftz,
        (ArithOp::Div, false, false) => div_approx,
        (ArithOp::Div, true, false) => div_approx_ftz,
        (ArithOp::Div, false, true) => div_full,
        (ArithOp::Div, true, true) => div_full_ftz,
        _ => return None,
    })
}

/// The 32-lane function of an arithmetic instruction whose semantics
/// (`alu::arith`) reduce to a plain operation, and whether it reads `c`;
/// `None` for the other forms, which the executor evaluates lane by lane.
pub fn resolve_arith(op: ArithOp, ty: Ty, mode: FloatMode, sfu: SfuModel) -> Option<(LaneFn, bool)> {
    use ArithOp as A;
    use Ty as T;
    if let Some(f) = resolve_sfu(op, ty, mode, sfu) {
        return Some((f, false));
    }
    // Round-to-nearest is IEEE's default, so `.rn` and no rounding agree.
    let nearest = matches!(mode.rnd, None | Some(Rounding::Rn)) && !mode.ftz && !mode.sat;
    let int = !mode.sat;
    let f: LaneFn = match (op, ty) {
        (A::Add, T::S32 | T::U32 | T::B32) if int => add32,
        (A::Add, T::S64 | T::U64 | T::B64) if int => add64,
        (A::Sub, T::S32 | T::U32 | T::B32) if int => sub32,
        (A::Sub, T::S64 | T::U64 | T::B64) if int => sub64,
        (A::Mul, T::S32 | T::U32 | T::B32) => mul32,
        (A::Mul, T::S64 | T::U64 | T::B64) => mul64,
        (A::And, T::B32 | T::U32 | T::S32) => and32,
        (A::Or, T::B32 | T::U32 | T::S32) => or32,
        (A::Xor, T::B32 | T::U32 | T::S32) => xor32,
        (A::And, T::B64 | T::U64 | T::S64) => and64,
        (A::Or, T::B64 | T::U64 | T::S64) => or64,
        (A::Xor, T::B64 | T::U64 | T::S64) => xor64,
        (A::Shl, T::B32 | T::U32 | T::S32) => shl32,
        (A::Shl, T::B64 | T::U64 | T::S64) => shl64,
        (A::Shr, T::B32 | T::U32) => shr_u32,
        (A::Shr, T::B64 | T::U64) => shr_u64,
        (A::Shr, T::S32) => shr_s32,
        (A::MulWide, T::S32) => mul_wide_s32,
        (A::MulWide, T::U32) => mul_wide_u32,
        (A::Min, T::S32) => min_s32,
        (A::Max, T::S32) => max_s32,
        (A::Min, T::U32) => min_u32,
        (A::Max, T::U32) => max_u32,
        (A::Mad, T::S32 | T::U32 | T::B32) => return Some((mad32, true)),
        (A::Add, T::F32) if nearest => fadd,
        (A::Sub, T::F32) if nearest => fsub,
        (A::Mul, T::F32) if nearest => fmul,
        (A::Div, T::F32) if nearest => fdiv,
        (A::Rcp, T::F32) if nearest => frcp,
        (A::Sqrt, T::F32) if nearest && !mode.approx => fsqrt,
        (A::Min, T::F32) if !mode.ftz && !mode.sat => fmin,
        (A::Max, T::F32) if !mode.ftz && !mode.sat => fmax,
        (A::Neg, T::F32) if !mode.ftz && !mode.sat => fneg,
        (A::Abs, T::F32) if !mode.ftz && !mode.sat => fabs,
        (A::Mad, T::F32) if nearest => return Some((ffma, true)),
        _ => return None,
    };
    Some((f, false))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_decoded_instruction_is_16_bytes() {
        assert_eq!(std::mem::size_of::<Op>(), 16);
    }

    /// Every resolved function computes what `alu::arith` computes, on
    /// operands chosen to hit the edge cases (NaN, signed zeros, infinities,
    /// subnormals, shifts past the width, sign bits).
    #[test]
    fn resolved_functions_agree_with_the_lane_semantics() {
        let f = |x: f32| x.to_bits() as u64;
        let vals: Vec<u64> = vec![
            0,
            1,
            2,
            31,
            32,
            33,
            63,
            64,
            0xFFFF_FFFF,
            0x8000_0000,
            0x7FFF_FFFF,
            u64::MAX,
            0x1234_5678_9ABC_DEF0,
            f(1.5),
            f(-2.25),
            f(0.0),
            f(-0.0),
            f(f32::NAN),
            f(-f32::NAN),
            f(f32::INFINITY),
            f(f32::NEG_INFINITY),
            f(1e-40),
            f(-1e-40),
            f(3.0e38),
            f(1.0 / 3.0),
        ];
        let modes = [
            FloatMode::default(),
            FloatMode { rnd: Some(Rounding::Rn), ..FloatMode::default() },
            FloatMode { rnd: Some(Rounding::Rz), ..FloatMode::default() },
            FloatMode { ftz: true, ..FloatMode::default() },
            FloatMode { sat: true, ..FloatMode::default() },
            FloatMode { approx: true, ..FloatMode::default() },
        ];
        let ops = [
            ArithOp::Add,
            ArithOp::Sub,
            ArithOp::Mul,
            ArithOp::MulWide,
            ArithOp::Mad,
            ArithOp::Div,
            ArithOp::Rcp,
            ArithOp::Sqrt,
            ArithOp::Min,
            ArithOp::Max,
            ArithOp::Neg,
            ArithOp::Abs,
            ArithOp::And,
            ArithOp::Or,
            ArithOp::Xor,
            ArithOp::Shl,
            ArithOp::Shr,
        ];
        let tys = [Ty::S32, Ty::U32, Ty::B32, Ty::S64, Ty::U64, Ty::B64, Ty::F32];
        let mut resolved = 0;
        for op in ops {
            for ty in tys {
                for mode in modes {
                    let Some((func, _)) = resolve_arith(op, ty, mode, SfuModel::CorrectlyRounded) else { continue };
                    resolved += 1;
                    for (i, &x) in vals.iter().enumerate() {
                        // 32 lanes: x against every value, c rotating
                        let a: Lanes = [x; 32];
                        let b: Lanes = std::array::from_fn(|l| vals[l % vals.len()]);
                        let c: Lanes = std::array::from_fn(|l| vals[(l + i) % vals.len()]);
                        let mut out = [0; 32];
                        func(&a, &b, &c, &mut out);
                        for l in 0..32 {
                            let want = alu::arith(op, ty, mode, a[l], b[l], c[l]);
                            assert_eq!(
                                out[l], want,
                                "{op:?}.{ty:?} {mode:?} a={:#x} b={:#x} c={:#x}",
                                a[l], b[l], c[l]
                            );
                        }
                    }
                }
            }
        }
        assert!(resolved > 40, "only {resolved} forms resolved");
    }
}
