//! Half-precision arithmetic: `.f16`, `.bf16` and their packed pairs
//! `.f16x2`, `.bf16x2` (the low half is the first element), and the
//! conversions between them and f32/f64, as an H200 computes them
//! (`sem_half` of tests/fixtures/gpu_semantics.json).
//!
//! Each operation is computed exactly (or rounded once in f64, which cannot
//! change the final rounding: 53 ≥ 2·11 + 2) and rounded once to the
//! half type. NaN results are the canonical `0x7fff`, `neg`/`abs` of a NaN
//! included; `min`/`max` return the other operand of one NaN and order −0
//! below +0; `.sat` maps NaN to +0; `.ftz` flushes subnormal inputs and
//! results of `.f16`. Converting an `.f16` NaN to f32 gives `0x7fffffff`, a
//! `.bf16` NaN keeps its bits (shifted left by 16).

use half::{bf16, f16};

use crate::ptx::ir::{ArithOp, FloatMode, Rounding};
use crate::ptx::types::Ty;

/// The canonical half NaN.
pub const NAN16: u16 = 0x7FFF;

/// Whether `ty` is one of the half types.
pub fn is_half(ty: Ty) -> bool {
    matches!(ty, Ty::F16 | Ty::BF16 | Ty::F16x2 | Ty::BF16x2)
}

/// The value of half bits `x` (bfloat16 when `bf`).
pub fn to_f64(x: u16, bf: bool) -> f64 {
    if bf { bf16::from_bits(x).to_f64() } else { f16::from_bits(x).to_f64() }
}

/// Whether `x` (`.bf16` bits when `bf`, else `.f16`) is subnormal.
pub(crate) fn is_subnormal(x: u16, bf: bool) -> bool {
    let exp = if bf { (x >> 7) & 0xFF } else { (x >> 10) & 0x1F };
    exp == 0 && x & 0x7FFF != 0
}

/// `x` rounded to the half type with `rnd` (round to nearest by default).
pub fn round(x: f64, bf: bool, rnd: Option<Rounding>) -> u16 {
    if x.is_nan() {
        return NAN16;
    }
    let rn = if bf { bf16::from_f64(x).to_bits() } else { f16::from_f64(x).to_bits() };
    let v = to_f64(rn, bf);
    let down = |b: u16| -> u16 {
        // one step toward zero in magnitude
        if b & 0x7FFF == 0 { b } else { b - 1 }
    };
    let up = |b: u16| -> u16 { b + 1 };
    let toward_zero = |b: u16| if v.abs() > x.abs() { down(b) } else { b };
    match rnd {
        Some(Rounding::Rz | Rounding::Rzi) => toward_zero(rn),
        Some(Rounding::Rm | Rounding::Rmi) if v > x => {
            if x >= 0.0 {
                down(rn)
            } else {
                up(rn)
            }
        }
        Some(Rounding::Rp | Rounding::Rpi) if v < x => {
            if x >= 0.0 {
                up(rn)
            } else {
                down(rn)
            }
        }
        _ => rn,
    }
}

/// `ex2.approx` and `tanh.approx` on a half type, as the H200 computes them
/// (`kernels/tests/half_sfu.cu`, all 2^16 inputs, `tests/gpu_half_sfu.rs`): the
/// special-function unit's f32 result truncated toward zero to the half type,
/// with overflow to infinity and `.ftz` flushing subnormal results; `tanh(x) = x` for |x| < 2^-8 and `ex2` of
/// (-2^-23, 0) is 1. The f32 result is the correctly rounded one here (the
/// unit's own differs by a few ulp): `ex2` equals the GPU on every input,
/// 324 of 63,490 `.f16` and 38 of 65,282 `.bf16` `tanh` results are one
/// step of the half type off.
pub fn sfu(op: ArithOp, bf: bool, ftz: bool, x: f64) -> u16 {
    if x.is_nan() {
        return NAN16;
    }
    let y = match op {
        ArithOp::Ex2 if x < 0.0 && x > -(2f64.powi(-23)) => 1.0,
        ArithOp::Ex2 => x.exp2(),
        _ if x.abs() < 2f64.powi(-8) => x,
        _ => x.tanh(),
    };
    let y = y as f32 as f64;
    if !bf && y.abs() >= 65536.0 {
        return if y > 0.0 { 0x7C00 } else { 0xFC00 };
    }
    let h = round(y, bf, Some(Rounding::Rz));
    // `.ftz` flushes subnormal results (`ex2.approx.ftz.bf16`)
    if ftz && is_subnormal(h, bf) { h & 0x8000 } else { h }
}

/// One half-precision lane of an arithmetic operation.
fn scalar(op: ArithOp, bf: bool, m: FloatMode, a: u16, b: u16, c: u16) -> u16 {
    let flush = |x: u16| if m.ftz && !bf && is_subnormal(x, bf) { x & 0x8000 } else { x };
    let (a, b, c) = (flush(a), flush(b), flush(c));
    let (x, y, z) = (to_f64(a, bf), to_f64(b, bf), to_f64(c, bf));
    let r = match op {
        ArithOp::Add => x + y,
        ArithOp::Sub => x - y,
        ArithOp::Mul => x * y,
        ArithOp::Mad => x.mul_add(y, z),
        ArithOp::Ex2 | ArithOp::Tanh => return sfu(op, bf, m.ftz, x),
        ArithOp::Neg if x.is_nan() => return NAN16,
        ArithOp::Neg => return flush(a ^ 0x8000),
        ArithOp::Abs if x.is_nan() => return NAN16,
        ArithOp::Abs => return flush(a & 0x7FFF),
        ArithOp::Min | ArithOp::Max => {
            let max = op == ArithOp::Max;
            return match (x.is_nan(), y.is_nan()) {
                (true, true) => NAN16,
                (true, false) => b,
                (false, true) => a,
                _ if x == y => {
                    if (a & 0x8000 != 0) != max {
                        a
                    } else {
                        b
                    }
                }
                _ if (x < y) != max => a,
                _ => b,
            };
        }
        _ => f64::NAN,
    };
    // an exact zero sum of opposite signs is +0 (round to nearest)
    let mut h = round(r, bf, m.rnd);
    if m.ftz && !bf && is_subnormal(h, bf) {
        h &= 0x8000;
    }
    if m.sat {
        let v = to_f64(h, bf);
        h = if v.is_nan() || v <= 0.0 {
            0
        } else if v >= 1.0 {
            round(1.0, bf, None)
        } else {
            h
        };
    }
    h
}

/// An arithmetic operation on a half type (`.x2`: both halves).
pub fn arith(op: ArithOp, ty: Ty, m: FloatMode, a: u64, b: u64, c: u64) -> u64 {
    let bf = matches!(ty, Ty::BF16 | Ty::BF16x2);
    if op == ArithOp::CvtPack {
        // cvt.rn.f16x2.f32 d, a, b: a into the upper half, b into the lower
        let one = |x: u64| {
            let f = f32::from_bits(x as u32) as f64;
            let f = if m.ftz && f.abs() < f32::MIN_POSITIVE as f64 { 0.0f64.copysign(f) } else { f };
            let mut h = round(f, bf, m.rnd);
            if m.sat {
                h = scalar(ArithOp::Max, bf, FloatMode::default(), h, 0, 0);
                h = scalar(ArithOp::Min, bf, FloatMode::default(), h, round(1.0, bf, None), 0);
                if to_f64(h, bf).is_nan() {
                    h = 0;
                }
            }
            h as u64
        };
        return one(a) << 16 | one(b);
    }
    let lane = |k: u32| scalar(op, bf, m, (a >> k) as u16, (b >> k) as u16, (c >> k) as u16) as u64;
    if matches!(ty, Ty::F16x2 | Ty::BF16x2) { lane(16) << 16 | lane(0) } else { lane(0) }
}

/// `cvt` between a half type (`.f16`, `.bf16`) and a float or integer type;
/// `None` when neither side is a half type.
pub fn cvt(dty: Ty, sty: Ty, m: FloatMode, a: u64) -> Option<u64> {
    let hs = matches!(sty, Ty::F16 | Ty::BF16);
    let hd = matches!(dty, Ty::F16 | Ty::BF16);
    if !hs && !hd {
        return None;
    }
    let x: f64 = if hs {
        let h = a as u16;
        if sty == Ty::BF16 && dty == Ty::F32 {
            // a bfloat16 is the upper half of an f32: NaNs keep their bits
            return Some((h as u64) << 16);
        }
        if m.ftz && sty == Ty::F16 && is_subnormal(h, false) {
            0.0f64.copysign(to_f64(h, false))
        } else {
            to_f64(h, sty == Ty::BF16)
        }
    } else if sty == Ty::F32 {
        let f = f32::from_bits(a as u32);
        (if m.ftz && f.is_subnormal() { 0.0f32.copysign(f) } else { f }) as f64
    } else if sty == Ty::F64 {
        f64::from_bits(a)
    } else if sty.is_signed() {
        sty.extend(a) as i64 as f64
    } else {
        (a & sty.mask()) as f64
    };
    if hd {
        let int_round = matches!(m.rnd, Some(Rounding::Rni | Rounding::Rzi | Rounding::Rmi | Rounding::Rpi));
        let x = if int_round {
            match m.rnd {
                Some(Rounding::Rzi) => x.trunc(),
                Some(Rounding::Rmi) => x.floor(),
                Some(Rounding::Rpi) => x.ceil(),
                _ => x.round_ties_even(),
            }
        } else {
            x
        };
        let mut h = round(x, dty == Ty::BF16, m.rnd);
        if m.sat {
            h = scalar(ArithOp::Add, dty == Ty::BF16, FloatMode { sat: true, ..FloatMode::default() }, h, 0x8000, 0);
        }
        return Some(h as u64);
    }
    // half → f32 / f64 / integer
    Some(match dty {
        Ty::F32 if x.is_nan() => crate::sim::alu::NAN32 as u64,
        Ty::F32 => {
            let f = x as f32;
            let f = if m.sat { if f.is_nan() || f <= 0.0 { 0.0 } else { f.min(1.0) } } else { f };
            f.to_bits() as u64
        }
        Ty::F64 if x.is_nan() => crate::sim::alu::NAN64,
        Ty::F64 => x.to_bits(),
        _ => crate::sim::alu::cvt(dty, Ty::F64, m, x.to_bits()),
    })
}

/// The value `set` writes for "true" into a destination of type `dty`: 1.0
/// in a float type (`.f16`, `.bf16` and each half of `.f16x2`/`.bf16x2`
/// included), all ones in an integer type (each 16-bit half of a packed
/// comparison into `.u32`/`.s32`).
pub fn set_true(dty: Ty, packed: bool) -> u64 {
    let one: u64 = match dty {
        Ty::F16 | Ty::F16x2 => 0x3C00,
        Ty::BF16 | Ty::BF16x2 => 0x3F80,
        Ty::F32 => 1.0f32.to_bits() as u64,
        Ty::F64 => 1.0f64.to_bits(),
        t if packed => t.mask() & 0xFFFF,
        t => t.mask(),
    };
    if packed { one | one << 16 } else { one }
}

/// `set.cmp[.bool].dty.f16x2 d, a, b[, c]` (and `.bf16x2`) in one lane: each
/// half of `d` is [`set_true`]'s half where that half of `a` compares true
/// with the same half of `b` (combined with `c` when `comb` is given), else 0.
pub fn set_x2(
    cmp: crate::ptx::ir::Cmp,
    dty: Ty,
    sty: Ty,
    ftz: bool,
    a: u64,
    b: u64,
    comb: Option<(crate::ptx::ir::BoolOp, bool)>,
) -> u64 {
    let half = if sty == Ty::BF16x2 { Ty::BF16 } else { Ty::F16 };
    let one = set_true(dty, true) & 0xFFFF;
    let mut d = 0;
    for k in [0, 16] {
        let mut t = crate::sim::alu::compare(cmp, half, ftz, a >> k & 0xFFFF, b >> k & 0xFFFF);
        if let Some((op, c)) = comb {
            t = match op {
                crate::ptx::ir::BoolOp::And => t & c,
                crate::ptx::ir::BoolOp::Or => t | c,
                crate::ptx::ir::BoolOp::Xor => t ^ c,
            };
        }
        if t {
            d |= one << k;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_modes() {
        // 1 + 2^-11 lies halfway between 1 and the next f16 (1 + 2^-10)
        let x = 1.0 + 2f64.powi(-11) + 2f64.powi(-20);
        assert_eq!(round(x, false, None), 0x3C01);
        assert_eq!(round(x, false, Some(Rounding::Rz)), 0x3C00);
        assert_eq!(round(-x, false, Some(Rounding::Rp)), 0xBC00);
        assert_eq!(round(-x, false, Some(Rounding::Rm)), 0xBC01);
        assert_eq!(round(1e6, false, Some(Rounding::Rz)), 0x7BFF);
        assert_eq!(round(1e6, false, None), 0x7C00);
        assert_eq!(round(f64::NAN, true, None), NAN16);
    }

    #[test]
    fn packed_pairs_work_on_both_halves() {
        let one = 0x3C00u64;
        let two = 0x4000u64;
        let m = FloatMode::default();
        assert_eq!(arith(ArithOp::Add, Ty::F16x2, m, one << 16 | two, two << 16 | one, 0), 0x4200_4200);
        assert_eq!(
            arith(ArithOp::CvtPack, Ty::BF16x2, m, 1.0f32.to_bits() as u64, 2.0f32.to_bits() as u64, 0),
            0x3F80_4000
        );
        assert_eq!(arith(ArithOp::Neg, Ty::F16, m, 0x7E00, 0, 0), NAN16 as u64);
        assert_eq!(arith(ArithOp::Min, Ty::F16, m, 0x7E00, one, 0), one);
    }
}
