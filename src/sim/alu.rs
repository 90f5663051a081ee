//! Scalar semantics of every arithmetic, comparison, conversion and atomic
//! operation, one lane at a time, exactly as PTX defines them.
//!
//! Conventions worth knowing (each has a test):
//! - f32 results that are NaN are the canonical NaN `0x7fffffff`, `abs` and
//!   `neg` included, as an H100 produces (tests/fixtures/gpu_semantics.json).
//!   f64 arithmetic propagates a NaN operand (quieted); a NaN made from
//!   non-NaN f64 operands is `0xfff8000000000000`. Conversions between f32
//!   and f64 keep a NaN's sign and payload. `copysign` and `mov` are bit operations.
//! - Directed rounding (`.rz .rm .rp`) is exact: the round-to-nearest result is
//!   corrected by the sign of the exact error (error-free transformations).
//! - `.approx` transcendental functions are computed in f64 and rounded to f32
//!   (the correctly rounded value; the GPU's errors are in docs/semantics.md).
//!   Under the hopper profile `rcp`, `rsqrt`, `sqrt` and the f32 divisions
//!   take the H200's bits from `super::sfu` instead (chosen when decoded).
//! - Half types (`.f16 .bf16` and pairs) are computed by `super::half`.
//! - Integer `div` and `rem` by zero give all ones, signed or not, as an H100
//!   does; `INT_MIN / -1` wraps to `INT_MIN` and `INT_MIN % -1` is 0.
//! - `.sat` maps NaN and -0 to +0. With `.rm`, an exact zero sum is -0.
//! - Shifts by at least the width give 0 (or the sign fill for `shr.s`).
//! - Float → integer conversions saturate and map NaN to 0.

use std::cmp::Ordering;

use crate::ptx::ir::{ArithOp, AtomOp, CarryOp, Cmp, FloatMode, Rounding};
use crate::ptx::types::Ty;
use crate::sim::decode::Word;
use crate::sim::half;

/// The canonical f32 NaN of NVIDIA GPUs.
pub const NAN32: u32 = 0x7FFF_FFFF;
/// The f64 NaN an H100 creates from non-NaN operands (e.g. inf * 0).
pub const NAN64: u64 = 0xFFF8_0000_0000_0000;
/// The quiet bit of an f64 NaN.
const QUIET64: u64 = 1 << 51;

#[inline]
fn f32of(x: u64) -> f32 {
    f32::from_bits(x as u32)
}

#[inline]
fn ftz32(x: f32) -> f32 {
    if x.is_subnormal() { 0.0f32.copysign(x) } else { x }
}

#[inline]
fn ftz64(x: f64) -> f64 {
    if x.is_subnormal() { 0.0f64.copysign(x) } else { x }
}

#[inline]
fn in32(x: u64, ftz: bool) -> f32 {
    let f = f32of(x);
    if ftz { ftz32(f) } else { f }
}

#[inline]
fn out32(x: f32, m: FloatMode) -> u64 {
    let mut x = if m.ftz { ftz32(x) } else { x };
    if m.sat {
        // NaN and -0 saturate to +0
        x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    }
    if x.is_nan() { NAN32 as u64 } else { x.to_bits() as u64 }
}

#[inline]
fn out64(x: f64, m: FloatMode) -> u64 {
    let mut x = if m.ftz { ftz64(x) } else { x };
    if m.sat {
        x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    }
    if x.is_nan() { NAN64 } else { x.to_bits() }
}

/// Corrects a round-to-nearest f32 result `r` for a directed rounding mode,
/// given the sign of (exact − r).
fn direct32(r: f32, err: Ordering, rnd: Option<Rounding>) -> f32 {
    if r.is_nan() || err == Ordering::Equal {
        return r;
    }
    match rnd {
        Some(Rounding::Rz) | Some(Rounding::Rzi) => {
            if err == Ordering::Less && r > 0.0 || r == f32::INFINITY {
                r.next_down()
            } else if err == Ordering::Greater && r < 0.0 || r == f32::NEG_INFINITY {
                r.next_up()
            } else {
                r
            }
        }
        Some(Rounding::Rm) | Some(Rounding::Rmi) if err == Ordering::Less => r.next_down(),
        Some(Rounding::Rp) | Some(Rounding::Rpi) if err == Ordering::Greater => r.next_up(),
        _ => r,
    }
}

/// As [`direct32`] for f64.
fn direct64(r: f64, err: Ordering, rnd: Option<Rounding>) -> f64 {
    if r.is_nan() || err == Ordering::Equal {
        return r;
    }
    match rnd {
        Some(Rounding::Rz) | Some(Rounding::Rzi) => {
            if err == Ordering::Less && r > 0.0 || r == f64::INFINITY {
                r.next_down()
            } else if err == Ordering::Greater && r < 0.0 || r == f64::NEG_INFINITY {
                r.next_up()
            } else {
                r
            }
        }
        Some(Rounding::Rm) | Some(Rounding::Rmi) if err == Ordering::Less => r.next_down(),
        Some(Rounding::Rp) | Some(Rounding::Rpi) if err == Ordering::Greater => r.next_up(),
        _ => r,
    }
}

fn sign(x: f64) -> Ordering {
    x.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// Error-free sum: `a + b = s + e` exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Sign of (exact − r) where exact = s + e (error-free pair) and r an f32 result.
fn err_vs(s: f64, e: f64, r: f32) -> Ordering {
    if !r.is_finite() {
        return if r.is_nan() {
            Ordering::Equal
        } else if r > 0.0 {
            Ordering::Less
        } else {
            Ordering::Greater
        };
    }
    let d = s - r as f64;
    if d != 0.0 { sign(d) } else { sign(e) }
}

fn directed(rnd: Option<Rounding>) -> bool {
    matches!(rnd, Some(Rounding::Rz | Rounding::Rm | Rounding::Rp))
}

/// IEEE 754: an exact zero sum of operands of opposite signs (or of two zeros
/// with a negative one) is -0 when rounding toward negative infinity.
fn zero_sign_rm<T: Into<f64> + Copy>(r: f64, a: T, b: T, rnd: Option<Rounding>) -> bool {
    let (a, b) = (a.into(), b.into());
    r == 0.0 && rnd == Some(Rounding::Rm) && !(a == 0.0 && b == 0.0 && a.is_sign_positive() && b.is_sign_positive())
}

fn add32(a: f32, b: f32, rnd: Option<Rounding>) -> f32 {
    let r = a + b;
    if zero_sign_rm(r as f64, a, b, rnd) {
        return -0.0;
    }
    if !directed(rnd) || !(r.is_finite() || a.is_finite() && b.is_finite()) {
        return r;
    }
    let (s, e) = two_sum(a as f64, b as f64);
    direct32(r, err_vs(s, e, r), rnd)
}

fn mul32(a: f32, b: f32, rnd: Option<Rounding>) -> f32 {
    let r = a * b;
    if !(directed(rnd) && a.is_finite() && b.is_finite()) {
        return r;
    }
    let p = a as f64 * b as f64; // exact: 48-bit significand
    direct32(r, err_vs(p, 0.0, r), rnd)
}

fn fma32(a: f32, b: f32, c: f32, rnd: Option<Rounding>) -> f32 {
    let r = a.mul_add(b, c);
    if !(directed(rnd) && a.is_finite() && b.is_finite() && c.is_finite()) {
        return r;
    }
    let p = a as f64 * b as f64;
    let (s, e) = two_sum(p, c as f64);
    direct32(r, err_vs(s, e, r), rnd)
}

fn div32(a: f32, b: f32, rnd: Option<Rounding>) -> f32 {
    let r = a / b;
    if !(directed(rnd) && r.is_finite() && a.is_finite() && b.is_finite() && b != 0.0) {
        return r;
    }
    // a - r*b is exact in f64; its sign times b's sign is the sign of (a/b − r).
    let rem = a as f64 - r as f64 * b as f64;
    let err = if b > 0.0 { sign(rem) } else { sign(rem).reverse() };
    direct32(r, err, rnd)
}

fn sqrt32(a: f32, rnd: Option<Rounding>) -> f32 {
    let r = a.sqrt();
    if !directed(rnd) || !r.is_finite() || r == 0.0 {
        return r;
    }
    let rem = a as f64 - r as f64 * r as f64;
    direct32(r, sign(rem), rnd)
}

fn add64(a: f64, b: f64, rnd: Option<Rounding>) -> f64 {
    let (s, e) = two_sum(a, b);
    if zero_sign_rm(s, a, b, rnd) {
        return -0.0;
    }
    if !directed(rnd) || !s.is_finite() {
        return s;
    }
    direct64(s, sign(e), rnd)
}

fn mul64(a: f64, b: f64, rnd: Option<Rounding>) -> f64 {
    let p = a * b;
    if !directed(rnd) || !p.is_finite() {
        return p;
    }
    direct64(p, sign(a.mul_add(b, -p)), rnd)
}

fn fma64(a: f64, b: f64, c: f64, rnd: Option<Rounding>) -> f64 {
    let r = a.mul_add(b, c);
    if !directed(rnd) || !r.is_finite() {
        return r;
    }
    let p = a * b;
    let pe = a.mul_add(b, -p);
    let (s, e1) = two_sum(p, c);
    // exact = s + e1 + pe; r is its correct rounding, so compare against r.
    let d = (s - r) + (e1 + pe);
    direct64(r, sign(d), rnd)
}

fn div64(a: f64, b: f64, rnd: Option<Rounding>) -> f64 {
    let r = a / b;
    if !directed(rnd) || !r.is_finite() || b == 0.0 {
        return r;
    }
    let rem = (-r).mul_add(b, a);
    direct64(r, if b > 0.0 { sign(rem) } else { sign(rem).reverse() }, rnd)
}

fn sqrt64(a: f64, rnd: Option<Rounding>) -> f64 {
    let r = a.sqrt();
    if !directed(rnd) || !r.is_finite() || r == 0.0 {
        return r;
    }
    direct64(r, sign((-r).mul_add(r, a)), rnd)
}

/// PTX `min`/`max`: a NaN operand yields the other operand, two NaNs a NaN,
/// and -0 counts as less than +0. (f32 values convert to f64 exactly.)
fn min_max(a: f64, b: f64, max: bool) -> f64 {
    match (a.is_nan(), b.is_nan()) {
        (true, true) => f64::NAN,
        (true, false) => b,
        (false, true) => a,
        _ if a == b => {
            // equal values differ only in the sign of zero
            if (a.is_sign_negative() && !max) || (a.is_sign_positive() && max) { a } else { b }
        }
        _ if (a < b) != max => a,
        _ => b,
    }
}

fn f32op(op: ArithOp, m: FloatMode, a: u64, b: u64, c: u64) -> u64 {
    let (fa, fb, fc) = (in32(a, m.ftz), in32(b, m.ftz), in32(c, m.ftz));
    let r = match op {
        ArithOp::Add => add32(fa, fb, m.rnd),
        ArithOp::Sub => add32(fa, -fb, m.rnd),
        ArithOp::Mul => mul32(fa, fb, m.rnd),
        ArithOp::Mad => fma32(fa, fb, fc, m.rnd),
        ArithOp::Div => div32(fa, fb, m.rnd),
        ArithOp::Abs => fa.abs(),
        ArithOp::Neg => -fa,
        ArithOp::Copysign => return (fb.abs().to_bits() | (fa.to_bits() & 0x8000_0000)) as u64,
        ArithOp::Min | ArithOp::Max => min_max(fa as f64, fb as f64, op == ArithOp::Max) as f32,
        ArithOp::Sqrt => sqrt32(fa, if m.approx { None } else { m.rnd }),
        ArithOp::Rsqrt => (1.0 / (fa as f64).sqrt()) as f32,
        ArithOp::Rcp => {
            if m.approx {
                1.0 / fa
            } else {
                div32(1.0, fa, m.rnd)
            }
        }
        ArithOp::Sin => (fa as f64).sin() as f32,
        ArithOp::Cos => (fa as f64).cos() as f32,
        ArithOp::Ex2 => (fa as f64).exp2() as f32,
        ArithOp::Lg2 => (fa as f64).log2() as f32,
        ArithOp::Tanh => (fa as f64).tanh() as f32,
        _ => f32::NAN,
    };
    out32(r, m)
}

fn f64op(op: ArithOp, m: FloatMode, a: u64, b: u64, c: u64) -> u64 {
    let (fa, fb, fc) = (f64::from_bits(a), f64::from_bits(b), f64::from_bits(c));
    let (fa, fb, fc) = if m.ftz { (ftz64(fa), ftz64(fb), ftz64(fc)) } else { (fa, fb, fc) };
    // f64 arithmetic propagates a NaN operand (quieted), as the GPU does.
    let nsrc = match op {
        ArithOp::Mad => 3,
        ArithOp::Add | ArithOp::Sub | ArithOp::Mul | ArithOp::Div => 2,
        ArithOp::Sqrt | ArithOp::Rsqrt | ArithOp::Rcp | ArithOp::Sin | ArithOp::Cos | ArithOp::Ex2 | ArithOp::Lg2 => 1,
        _ => 0,
    };
    if let Some(n) = [a, b, c][..nsrc].iter().find(|x| f64::from_bits(**x).is_nan()) {
        return n | QUIET64;
    }
    let r = match op {
        ArithOp::Add => add64(fa, fb, m.rnd),
        ArithOp::Sub => add64(fa, -fb, m.rnd),
        ArithOp::Mul => mul64(fa, fb, m.rnd),
        ArithOp::Mad => fma64(fa, fb, fc, m.rnd),
        ArithOp::Div => div64(fa, fb, m.rnd),
        ArithOp::Abs => {
            return if fa.is_nan() { a & !(1 << 63) } else { out64(fa.abs(), m) };
        }
        ArithOp::Neg => {
            return if fa.is_nan() { a ^ (1 << 63) } else { out64(-fa, m) };
        }
        ArithOp::Copysign => return (fb.abs().to_bits()) | (fa.to_bits() & (1 << 63)),
        ArithOp::Min | ArithOp::Max => min_max(fa, fb, op == ArithOp::Max),
        ArithOp::Sqrt => sqrt64(fa, m.rnd),
        ArithOp::Rsqrt => 1.0 / fa.sqrt(),
        ArithOp::Rcp => div64(1.0, fa, m.rnd),
        ArithOp::Sin => fa.sin(),
        ArithOp::Cos => fa.cos(),
        ArithOp::Ex2 => fa.exp2(),
        ArithOp::Lg2 => fa.log2(),
        _ => f64::NAN,
    };
    out64(r, m)
}

fn wide_mask(w: u32) -> u64 {
    if w >= 32 { u64::MAX } else { (1u64 << (2 * w)) - 1 }
}

/// Evaluates an arithmetic operation on one lane. `a`, `b`, `c` hold the
/// operands' bits (low bits significant); the result is masked to the result width.
pub fn arith(op: ArithOp, ty: Ty, m: FloatMode, a: u64, b: u64, c: u64) -> u64 {
    match ty {
        Ty::F32 => return f32op(op, m, a, b, c),
        Ty::F64 => return f64op(op, m, a, b, c),
        t if half::is_half(t) => return half::arith(op, t, m, a, b, c),
        _ => {}
    }
    let w = ty.bits();
    let mask = ty.mask();
    let signed = ty.is_signed();
    let (sa, sb, sc) = (ty.extend(a) as i64, ty.extend(b) as i64, ty.extend(c) as i64);
    let (ua, ub, uc) = (a & mask, b & mask, c & mask);
    let r: u64 = match op {
        ArithOp::Add if m.sat && signed => (sa as i128 + sb as i128).clamp(min_of(w), max_of(w)) as u64,
        ArithOp::Sub if m.sat && signed => (sa as i128 - sb as i128).clamp(min_of(w), max_of(w)) as u64,
        ArithOp::Add => ua.wrapping_add(ub),
        ArithOp::Sub => ua.wrapping_sub(ub),
        ArithOp::Mul => ua.wrapping_mul(ub),
        ArithOp::MulHi => {
            if signed {
                ((sa as i128 * sb as i128) >> w) as u64
            } else {
                ((ua as u128 * ub as u128) >> w) as u64
            }
        }
        ArithOp::MulWide => {
            return if signed { (sa as i128 * sb as i128) as u64 } else { (ua as u128 * ub as u128) as u64 }
                & wide_mask(w);
        }
        ArithOp::Mad => ua.wrapping_mul(ub).wrapping_add(uc),
        ArithOp::MadHi => {
            let hi =
                if signed { ((sa as i128 * sb as i128) >> w) as u64 } else { ((ua as u128 * ub as u128) >> w) as u64 };
            hi.wrapping_add(uc)
        }
        ArithOp::MadWide => {
            let p = if signed { (sa as i128 * sb as i128) as u64 } else { (ua as u128 * ub as u128) as u64 };
            return p.wrapping_add(c) & wide_mask(w);
        }
        ArithOp::Mul24Lo | ArithOp::Mul24Hi | ArithOp::Mad24Lo | ArithOp::Mad24Hi => {
            let (x, y) = if signed {
                (((a << 40) as i64 >> 40), ((b << 40) as i64 >> 40))
            } else {
                ((a & 0xFF_FFFF) as i64, (b & 0xFF_FFFF) as i64)
            };
            let p = x * y;
            let part = if matches!(op, ArithOp::Mul24Hi | ArithOp::Mad24Hi) { (p >> 16) as u64 } else { p as u64 };
            if matches!(op, ArithOp::Mad24Lo | ArithOp::Mad24Hi) { part.wrapping_add(uc) } else { part }
        }
        ArithOp::Div => {
            if signed {
                if sb == 0 { u64::MAX } else { sa.wrapping_div(sb) as u64 }
            } else {
                ua.checked_div(ub).unwrap_or(u64::MAX)
            }
        }
        ArithOp::Rem => {
            if signed {
                if sb == 0 { u64::MAX } else { sa.wrapping_rem(sb) as u64 }
            } else if ub == 0 {
                u64::MAX
            } else {
                ua % ub
            }
        }
        ArithOp::Abs => sa.wrapping_abs() as u64,
        ArithOp::Neg => sa.wrapping_neg() as u64,
        ArithOp::Min => {
            if signed {
                sa.min(sb) as u64
            } else {
                ua.min(ub)
            }
        }
        ArithOp::Max => {
            if signed {
                sa.max(sb) as u64
            } else {
                ua.max(ub)
            }
        }
        ArithOp::And => ua & ub,
        ArithOp::Or => ua | ub,
        ArithOp::Xor => ua ^ ub,
        ArithOp::Not => !ua,
        ArithOp::Cnot => (ua == 0) as u64,
        ArithOp::Shl => {
            let s = b as u32;
            if s >= w { 0 } else { ua << s }
        }
        ArithOp::Shr => {
            let s = b as u32;
            if signed {
                (sa >> s.min(w - 1)) as u64
            } else if s >= w {
                0
            } else {
                ua >> s
            }
        }
        ArithOp::Popc => return ua.count_ones() as u64,
        ArithOp::Clz => return (ua.leading_zeros() - (64 - w)) as u64,
        ArithOp::Brev => ua.reverse_bits() >> (64 - w),
        ArithOp::Bfe => {
            let pos = (b & 0xFF) as u32;
            let len = (c & 0xFF) as u32;
            let msb = w - 1;
            let sbit = if signed && len != 0 { (ua >> (pos + len - 1).min(msb)) & 1 } else { 0 };
            let mut d = 0u64;
            for i in 0..w {
                let bit = if i < len && pos + i <= msb { (ua >> (pos + i)) & 1 } else { sbit };
                d |= bit << i;
            }
            d
        }
        ArithOp::ShfLWrap | ArithOp::ShfLClamp | ArithOp::ShfRWrap | ArithOp::ShfRClamp => {
            let wrap = matches!(op, ArithOp::ShfLWrap | ArithOp::ShfRWrap);
            let n = if wrap { (c & 31) as u32 } else { (c as u32).min(32) };
            let x = ((ub & 0xFFFF_FFFF) << 32) | (ua & 0xFFFF_FFFF);
            if matches!(op, ArithOp::ShfLWrap | ArithOp::ShfLClamp) { (x << n) >> 32 } else { x >> n }
        }
        ArithOp::Prmt => {
            let bytes = ((ub & 0xFFFF_FFFF) << 32) | (ua & 0xFFFF_FFFF);
            let mut d = 0u64;
            for i in 0..4 {
                let sel = (c >> (4 * i)) & 0xF;
                let byte = (bytes >> ((sel & 7) * 8)) & 0xFF;
                let byte = if sel & 8 != 0 { if byte & 0x80 != 0 { 0xFF } else { 0 } } else { byte };
                d |= byte << (8 * i);
            }
            d
        }
        ArithOp::PrmtF4e
        | ArithOp::PrmtB4e
        | ArithOp::PrmtRc8
        | ArithOp::PrmtEcl
        | ArithOp::PrmtEcr
        | ArithOp::PrmtRc16 => prmt_mode(op, a, b, c),
        ArithOp::Bfind | ArithOp::BfindShiftamt => {
            // the most significant bit that differs from the sign (unsigned: that is set)
            let x = if signed && sa < 0 { !ua & mask } else { ua };
            return if x == 0 {
                0xFFFF_FFFF
            } else {
                let pos = 63 - x.leading_zeros() as u64;
                if op == ArithOp::BfindShiftamt { (w as u64 - 1) - pos } else { pos }
            };
        }
        ArithOp::Dp4aU | ArithOp::Dp4aS | ArithOp::Dp2aLoU | ArithOp::Dp2aLoS | ArithOp::Dp2aHiU | ArithOp::Dp2aHiS => {
            return dot(op, signed, a, b, c) & 0xFFFF_FFFF;
        }
        _ => 0,
    };
    let _ = sc;
    r & mask
}

/// `prmt.b32` in one of its modes: the two low bits of `c` select the bytes of
/// {b, a} (a the low four).
fn prmt_mode(op: ArithOp, a: u64, b: u64, c: u64) -> u64 {
    let bytes = ((b & 0xFFFF_FFFF) << 32) | (a & 0xFFFF_FFFF);
    let s = c & 3;
    let mut d = 0u64;
    for k in 0..4u64 {
        let sel = match op {
            ArithOp::PrmtF4e => s + k,
            ArithOp::PrmtB4e => (s + 8 - k) & 7,
            ArithOp::PrmtRc8 => s,
            ArithOp::PrmtEcl => k.max(s),
            ArithOp::PrmtEcr => k.min(s),
            _ => 2 * (s & 1) + (k & 1), // rc16
        };
        d |= ((bytes >> (8 * sel)) & 0xFF) << (8 * k);
    }
    d
}

/// `dp4a`/`dp2a`: `c` plus the products of `a`'s bytes (dp2a: 16-bit halves,
/// signed when `a_signed`) with `b`'s bytes (signedness by the operation).
fn dot(op: ArithOp, a_signed: bool, a: u64, b: u64, c: u64) -> u64 {
    let b_signed = matches!(op, ArithOp::Dp4aS | ArithOp::Dp2aLoS | ArithOp::Dp2aHiS);
    let part = |x: u64, k: u64, bits: u64, s: bool| -> i64 {
        let v = (x >> (k * bits)) & ((1 << bits) - 1);
        if s && v >> (bits - 1) != 0 { v as i64 - (1 << bits) } else { v as i64 }
    };
    let mut acc = c as u32 as i64;
    match op {
        ArithOp::Dp4aU | ArithOp::Dp4aS => {
            for k in 0..4 {
                acc += part(a, k, 8, a_signed) * part(b, k, 8, b_signed);
            }
        }
        _ => {
            let hi = if matches!(op, ArithOp::Dp2aHiU | ArithOp::Dp2aHiS) { 2 } else { 0 };
            for k in 0..2 {
                acc += part(a, k, 16, a_signed) * part(b, k + hi, 8, b_signed);
            }
        }
    }
    acc as u64
}

/// One carry-chain step on `ty` (32 or 64 bits): the result and the carry
/// (borrow for `sub`) out. `cin` is the carry (borrow) in, 0 or 1.
pub fn carry(op: CarryOp, ty: Ty, a: u64, b: u64, c: u64, cin: u64) -> (u64, u64) {
    let w = ty.bits();
    let mask = ty.mask() as u128;
    let (a, b, c) = (a as u128 & mask, b as u128 & mask, c as u128 & mask);
    let cin = cin as u128 & 1;
    let wide = match op {
        CarryOp::Add => a + b + cin,
        CarryOp::Sub => {
            let r = a.wrapping_sub(b).wrapping_sub(cin) & mask;
            return (r as u64, (a < b + cin) as u64);
        }
        CarryOp::MadLo => ((a * b) & mask) + c + cin,
        CarryOp::MadHi => {
            // the high half of the signed product for .s32/.s64 (sign-extended
            // operands); the addition and its carry are the same for both
            let hi = if ty.is_signed() {
                let (sa, sb) = (ty.extend(a as u64) as i64 as i128, ty.extend(b as u64) as i64 as i128);
                ((sa * sb) >> w) as u128 & mask
            } else {
                (a * b) >> w
            };
            hi + c + cin
        }
    };
    ((wide & mask) as u64, (wide >> w) as u64 & 1)
}

fn min_of(w: u32) -> i128 {
    -(1i128 << (w - 1))
}

fn max_of(w: u32) -> i128 {
    (1i128 << (w - 1)) - 1
}

/// `bfi`: inserts the low `len` bits of `a` into `b` at `pos`.
pub fn bfi(ty: Ty, a: u64, b: u64, pos: u64, len: u64) -> u64 {
    let w = ty.bits();
    let (pos, len) = ((pos & 0xFF) as u32, (len & 0xFF) as u32);
    let mut f = b & ty.mask();
    for i in 0..len {
        if pos + i >= w {
            break;
        }
        let bit = (a >> i) & 1;
        f = (f & !(1 << (pos + i))) | (bit << (pos + i));
    }
    f
}

/// Evaluates a comparison.
pub fn compare(cmp: Cmp, ty: Ty, ftz: bool, a: u64, b: u64) -> bool {
    if ty.is_float() {
        let (x, y) = if ty == Ty::F32 {
            (in32(a, ftz) as f64, in32(b, ftz) as f64)
        } else if half::is_half(ty) {
            let bf = ty == Ty::BF16;
            // `.ftz` flushes subnormal `.f16` inputs to signed zero, as the half arithmetic does
            let h = |x: u64| if ftz && !bf && half::is_subnormal(x as u16, bf) { x as u16 & 0x8000 } else { x as u16 };
            (half::to_f64(h(a), bf), half::to_f64(h(b), bf))
        } else {
            (f64::from_bits(a), f64::from_bits(b))
        };
        let nan = x.is_nan() || y.is_nan();
        return match cmp {
            Cmp::Eq => x == y,
            Cmp::Ne => !nan && x != y,
            Cmp::Lt | Cmp::Lo => x < y,
            Cmp::Le | Cmp::Ls => x <= y,
            Cmp::Gt | Cmp::Hi => x > y,
            Cmp::Ge | Cmp::Hs => x >= y,
            Cmp::Equ => nan || x == y,
            Cmp::Neu => nan || x != y,
            Cmp::Ltu => nan || x < y,
            Cmp::Leu => nan || x <= y,
            Cmp::Gtu => nan || x > y,
            Cmp::Geu => nan || x >= y,
            Cmp::Num => !nan,
            Cmp::Nan => nan,
        };
    }
    let (ua, ub) = (a & ty.mask(), b & ty.mask());
    let (sa, sb) = (ty.extend(a) as i64, ty.extend(b) as i64);
    let s = ty.is_signed();
    match cmp {
        Cmp::Eq | Cmp::Equ => ua == ub,
        Cmp::Ne | Cmp::Neu => ua != ub,
        Cmp::Lt | Cmp::Ltu => {
            if s {
                sa < sb
            } else {
                ua < ub
            }
        }
        Cmp::Le | Cmp::Leu => {
            if s {
                sa <= sb
            } else {
                ua <= ub
            }
        }
        Cmp::Gt | Cmp::Gtu => {
            if s {
                sa > sb
            } else {
                ua > ub
            }
        }
        Cmp::Ge | Cmp::Geu => {
            if s {
                sa >= sb
            } else {
                ua >= ub
            }
        }
        Cmp::Lo => ua < ub,
        Cmp::Ls => ua <= ub,
        Cmp::Hi => ua > ub,
        Cmp::Hs => ua >= ub,
        Cmp::Num => true,
        Cmp::Nan => false,
    }
}

/// The float types [`compare_lanes`] specialises on.
trait Float: Copy + PartialOrd {
    fn is_nan(self) -> bool;
}

impl Float for f32 {
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
}

impl Float for f64 {
    fn is_nan(self) -> bool {
        f64::is_nan(self)
    }
}

/// Evaluates a comparison in all 32 lanes: bit `l` of the result is lane `l`'s
/// outcome, exactly as [`compare`] gives it (on narrow rows, `W = u32`, of
/// the lanes zero-extended). The type and the comparison are
/// dispatched once per warp instead of once per lane (`setp` is the most
/// frequent instruction of the ray-tracing kernels).
pub fn compare_lanes<W: Word>(cmp: Cmp, ty: Ty, ftz: bool, a: &[W; 32], b: &[W; 32]) -> u32 {
    #[inline(always)]
    fn each<W: Word>(a: &[W; 32], b: &[W; 32], f: impl Fn(u64, u64) -> bool) -> u32 {
        let mut t = 0u32;
        for l in 0..32 {
            t |= (f(a[l].wide(), b[l].wide()) as u32) << l;
        }
        t
    }
    let generic = |a: &[W; 32], b: &[W; 32]| each(a, b, |x, y| compare(cmp, ty, ftz, x, y));
    #[inline(always)]
    fn unordered<F: Float>(x: F, y: F, f: impl Fn(F, F) -> bool) -> bool {
        x.is_nan() || y.is_nan() || f(x, y)
    }
    macro_rules! ordered {
        ($conv:expr) => {{
            let c = $conv;
            match cmp {
                Cmp::Eq => each(a, b, |x, y| c(x) == c(y)),
                Cmp::Ne => each(a, b, |x, y| {
                    let (x, y) = (c(x), c(y));
                    !(x.is_nan() || y.is_nan()) && x != y
                }),
                Cmp::Lt | Cmp::Lo => each(a, b, |x, y| c(x) < c(y)),
                Cmp::Le | Cmp::Ls => each(a, b, |x, y| c(x) <= c(y)),
                Cmp::Gt | Cmp::Hi => each(a, b, |x, y| c(x) > c(y)),
                Cmp::Ge | Cmp::Hs => each(a, b, |x, y| c(x) >= c(y)),
                // unordered: true where either is NaN
                Cmp::Equ => each(a, b, |x, y| unordered(c(x), c(y), |x, y| x == y)),
                Cmp::Neu => each(a, b, |x, y| c(x) != c(y)),
                Cmp::Ltu => each(a, b, |x, y| unordered(c(x), c(y), |x, y| x < y)),
                Cmp::Leu => each(a, b, |x, y| unordered(c(x), c(y), |x, y| x <= y)),
                Cmp::Gtu => each(a, b, |x, y| unordered(c(x), c(y), |x, y| x > y)),
                Cmp::Geu => each(a, b, |x, y| unordered(c(x), c(y), |x, y| x >= y)),
                Cmp::Num => each(a, b, |x, y| !(c(x).is_nan() || c(y).is_nan())),
                Cmp::Nan => each(a, b, |x, y| c(x).is_nan() || c(y).is_nan()),
            }
        }};
    }
    match ty {
        Ty::F32 if ftz => ordered!(|x: u64| ftz32(f32of(x))),
        Ty::F32 => ordered!(f32of),
        Ty::F64 => ordered!(f64::from_bits),
        t if t.is_float() => generic(a, b),
        t => {
            let m = t.mask();
            let sh = 64 - t.bits().min(64);
            let sx = |x: u64| ((x << sh) as i64) >> sh;
            match (cmp, t.is_signed()) {
                (Cmp::Eq | Cmp::Equ, _) => each(a, b, |x, y| x & m == y & m),
                (Cmp::Ne | Cmp::Neu, _) => each(a, b, |x, y| x & m != y & m),
                (Cmp::Lt | Cmp::Ltu, true) => each(a, b, |x, y| sx(x) < sx(y)),
                (Cmp::Le | Cmp::Leu, true) => each(a, b, |x, y| sx(x) <= sx(y)),
                (Cmp::Gt | Cmp::Gtu, true) => each(a, b, |x, y| sx(x) > sx(y)),
                (Cmp::Ge | Cmp::Geu, true) => each(a, b, |x, y| sx(x) >= sx(y)),
                (Cmp::Lt | Cmp::Ltu | Cmp::Lo, _) => each(a, b, |x, y| x & m < y & m),
                (Cmp::Le | Cmp::Leu | Cmp::Ls, _) => each(a, b, |x, y| x & m <= y & m),
                (Cmp::Gt | Cmp::Gtu | Cmp::Hi, _) => each(a, b, |x, y| x & m > y & m),
                (Cmp::Ge | Cmp::Geu | Cmp::Hs, _) => each(a, b, |x, y| x & m >= y & m),
                _ => generic(a, b),
            }
        }
    }
}

fn round_int_f64(x: f64, rnd: Option<Rounding>) -> f64 {
    match rnd {
        Some(Rounding::Rni) | Some(Rounding::Rn) => x.round_ties_even(),
        Some(Rounding::Rmi) | Some(Rounding::Rm) => x.floor(),
        Some(Rounding::Rpi) | Some(Rounding::Rp) => x.ceil(),
        _ => x.trunc(),
    }
}

fn int_range(t: Ty) -> (i128, i128) {
    let w = t.bits();
    if t.is_signed() { (min_of(w), max_of(w)) } else { (0, (1i128 << w) - 1) }
}

/// Evaluates `cvt.mode.dty.sty` on one lane.
pub fn cvt(dty: Ty, sty: Ty, m: FloatMode, a: u64) -> u64 {
    if let Some(r) = half::cvt(dty, sty, m, a) {
        return r;
    }
    match (dty.is_float(), sty.is_float()) {
        (false, false) => {
            let v: i128 = if sty.is_signed() { sty.extend(a) as i64 as i128 } else { (a & sty.mask()) as i128 };
            let v = if m.sat {
                let (lo, hi) = int_range(dty);
                v.clamp(lo, hi)
            } else {
                v
            };
            (v as u64) & dty.mask()
        }
        (false, true) => {
            let x = if sty == Ty::F32 { in32(a, m.ftz) as f64 } else { f64::from_bits(a) };
            if x.is_nan() {
                return 0;
            }
            let r = round_int_f64(x, m.rnd);
            let (lo, hi) = int_range(dty);
            let v = if r <= lo as f64 {
                lo
            } else if r >= hi as f64 {
                hi
            } else {
                r as i128
            };
            (v as u64) & dty.mask()
        }
        (true, false) => {
            let v: i128 = if sty.is_signed() { sty.extend(a) as i64 as i128 } else { (a & sty.mask()) as i128 };
            if dty == Ty::F32 {
                let r = if sty.is_signed() { v as i64 as f32 } else { v as u64 as f32 };
                let err = v.cmp(&(r as i128));
                let r = direct32(r, err, m.rnd);
                out32(r, m)
            } else {
                let r = if sty.is_signed() { v as i64 as f64 } else { v as u64 as f64 };
                let err = v.cmp(&(r as i128));
                out64(direct64(r, err, m.rnd), m)
            }
        }
        (true, true) => {
            let int_round = matches!(m.rnd, Some(Rounding::Rni | Rounding::Rzi | Rounding::Rmi | Rounding::Rpi));
            match (dty, sty) {
                (Ty::F32, Ty::F32) => {
                    let x = in32(a, m.ftz);
                    let r = if int_round { round_int_f64(x as f64, m.rnd) as f32 } else { x };
                    out32(r, m)
                }
                (Ty::F64, Ty::F64) => {
                    let x = f64::from_bits(a);
                    out64(if int_round { round_int_f64(x, m.rnd) } else { x }, m)
                }
                (Ty::F64, Ty::F32) if f32of(a).is_nan() => (f32of(a) as f64).to_bits(),
                (Ty::F32, Ty::F64) if f64::from_bits(a).is_nan() => (f64::from_bits(a) as f32).to_bits() as u64,
                (Ty::F64, Ty::F32) => {
                    let x = in32(a, m.ftz) as f64;
                    out64(if int_round { round_int_f64(x, m.rnd) } else { x }, FloatMode { ftz: false, ..m })
                }
                (Ty::F32, Ty::F64) => {
                    let x = f64::from_bits(a);
                    let x = if int_round { round_int_f64(x, m.rnd) } else { x };
                    let r = x as f32;
                    let err = if r.is_finite() { sign(x - r as f64) } else { err_vs(x, 0.0, r) };
                    let r = if x.is_infinite() { r } else { direct32(r, err, m.rnd) };
                    out32(r, m)
                }
                _ => a,
            }
        }
    }
}

/// The new memory value of an atomic operation on one lane, given the old value.
pub fn atom(op: AtomOp, ty: Ty, old: u64, b: u64, c: u64) -> u64 {
    let mask = ty.mask();
    let r = match (op, ty) {
        (AtomOp::Add, Ty::F32) => {
            let s = ftz32(ftz32(f32of(old)) + ftz32(f32of(b)));
            if s.is_nan() { NAN32 as u64 } else { s.to_bits() as u64 }
        }
        (AtomOp::Add, Ty::F64) => {
            let s = f64::from_bits(old) + f64::from_bits(b);
            if s.is_nan() { NAN64 } else { s.to_bits() }
        }
        (AtomOp::Add, _) => old.wrapping_add(b),
        (AtomOp::Min | AtomOp::Max, Ty::F32 | Ty::F64) => {
            arith(if op == AtomOp::Min { ArithOp::Min } else { ArithOp::Max }, ty, FloatMode::default(), old, b, 0)
        }
        (AtomOp::Min, _) => {
            if ty.is_signed() {
                (ty.extend(old) as i64).min(ty.extend(b) as i64) as u64
            } else {
                (old & mask).min(b & mask)
            }
        }
        (AtomOp::Max, _) => {
            if ty.is_signed() {
                (ty.extend(old) as i64).max(ty.extend(b) as i64) as u64
            } else {
                (old & mask).max(b & mask)
            }
        }
        (AtomOp::Inc, _) => {
            if (old & mask) >= (b & mask) {
                0
            } else {
                old + 1
            }
        }
        (AtomOp::Dec, _) => {
            if (old & mask) == 0 || (old & mask) > (b & mask) {
                b
            } else {
                old - 1
            }
        }
        (AtomOp::Exch, _) => b,
        (AtomOp::Cas, _) => {
            if (old & mask) == (b & mask) {
                c
            } else {
                old
            }
        }
        (AtomOp::And, _) => old & b,
        (AtomOp::Or, _) => old | b,
        (AtomOp::Xor, _) => old ^ b,
    };
    r & mask
}

/// Every comparison, for tests.
#[cfg(test)]
pub(crate) const ALL_CMPS: [Cmp; 18] = [
    Cmp::Eq,
    Cmp::Ne,
    Cmp::Lt,
    Cmp::Le,
    Cmp::Gt,
    Cmp::Ge,
    Cmp::Lo,
    Cmp::Ls,
    Cmp::Hi,
    Cmp::Hs,
    Cmp::Equ,
    Cmp::Neu,
    Cmp::Ltu,
    Cmp::Leu,
    Cmp::Gtu,
    Cmp::Geu,
    Cmp::Num,
    Cmp::Nan,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compare_lanes_agrees_with_compare_lane_by_lane() {
        let edges: Vec<u64> = vec![
            0,
            1,
            u64::MAX,
            0x7f,
            0x80,
            0xffff,
            0x8000,
            0x7fff_ffff,
            0x8000_0000,
            0xffff_ffff,
            i64::MIN as u64,
            i64::MAX as u64,
            1.5f32.to_bits() as u64,
            (-2.0f32).to_bits() as u64,
            f32::NAN.to_bits() as u64,
            f32::INFINITY.to_bits() as u64,
            (-0.0f32).to_bits() as u64,
            1u64, // the smallest f32 subnormal
            0x8000_0001,
            f64::NAN.to_bits(),
            (-0.0f64).to_bits(),
            2.5f64.to_bits(),
        ];
        let cmps = ALL_CMPS;
        let tys = [
            Ty::S8,
            Ty::U8,
            Ty::S16,
            Ty::U16,
            Ty::B16,
            Ty::S32,
            Ty::U32,
            Ty::B32,
            Ty::S64,
            Ty::U64,
            Ty::B64,
            Ty::F32,
            Ty::F64,
        ];
        let n = edges.len();
        for round in 0..n {
            let a: [u64; 32] = std::array::from_fn(|l| edges[(l + round) % n]);
            let b: [u64; 32] = std::array::from_fn(|l| edges[(l * 7 + round * 3) % n]);
            for ty in tys {
                for cmp in cmps {
                    for ftz in [false, true] {
                        let want = (0..32).fold(0u32, |t, l| t | (compare(cmp, ty, ftz, a[l], b[l]) as u32) << l);
                        assert_eq!(compare_lanes(cmp, ty, ftz, &a, &b), want, "{cmp:?} {ty:?} ftz {ftz}");
                    }
                }
            }
        }
    }

    const M: FloatMode = FloatMode { rnd: None, ftz: false, sat: false, approx: false, full: false };

    fn f(x: f32) -> u64 {
        x.to_bits() as u64
    }

    #[test]
    fn shifts_clamp() {
        assert_eq!(arith(ArithOp::Shl, Ty::B32, M, 1, 32, 0), 0);
        assert_eq!(arith(ArithOp::Shl, Ty::B32, M, 1, 31, 0), 0x8000_0000);
        assert_eq!(arith(ArithOp::Shr, Ty::U32, M, 0x8000_0000, 40, 0), 0);
        assert_eq!(arith(ArithOp::Shr, Ty::S32, M, 0x8000_0000, 40, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Shr, Ty::S32, M, 0x4000_0000, 100, 0), 0);
    }

    #[test]
    fn division_edge_cases() {
        assert_eq!(arith(ArithOp::Div, Ty::U32, M, 7, 0, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Rem, Ty::U32, M, 7, 0, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Rem, Ty::S32, M, 7, 0, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Div, Ty::S32, M, 7, 0, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Div, Ty::S32, M, 0x8000_0000, 0xFFFF_FFFF, 0), 0x8000_0000);
        assert_eq!(arith(ArithOp::Rem, Ty::S32, M, 0x8000_0000, 0xFFFF_FFFF, 0), 0);
        assert_eq!(arith(ArithOp::Div, Ty::S32, M, (-7i32) as u32 as u64, 2, 0), (-3i32) as u32 as u64);
        assert_eq!(arith(ArithOp::Rem, Ty::S32, M, (-7i32) as u32 as u64, 2, 0), (-1i32) as u32 as u64);
    }

    #[test]
    fn fma_rounds_once() {
        // a*b = 1 + 2^-23 + 2^-46 (not representable); separate rounding loses 2^-46.
        let a = 1.0f32 + f32::EPSILON;
        let c = -(1.0f32 + 2.0 * f32::EPSILON);
        let fused = f32::from_bits(arith(ArithOp::Mad, Ty::F32, M, f(a), f(a), f(c)) as u32);
        let separate = a * a + c;
        assert_eq!(fused, f32::EPSILON * f32::EPSILON);
        assert_eq!(separate, 0.0);
    }

    #[test]
    fn min_max_with_nan() {
        let nan = f(f32::NAN);
        assert_eq!(arith(ArithOp::Min, Ty::F32, M, nan, f(2.0), 0), f(2.0));
        assert_eq!(arith(ArithOp::Max, Ty::F32, M, f(-1.0), nan, 0), f(-1.0));
        assert_eq!(arith(ArithOp::Min, Ty::F32, M, nan, nan, 0), NAN32 as u64);
        assert_eq!(arith(ArithOp::Min, Ty::F32, M, f(0.0), f(-0.0), 0), f(-0.0));
        assert_eq!(arith(ArithOp::Max, Ty::F32, M, f(-0.0), f(0.0), 0), f(0.0));
    }

    #[test]
    fn cvt_saturates_and_maps_nan_to_zero() {
        let rzi = FloatMode { rnd: Some(Rounding::Rzi), ..M };
        assert_eq!(cvt(Ty::S32, Ty::F32, rzi, f(3e9)), 0x7FFF_FFFF);
        assert_eq!(cvt(Ty::S32, Ty::F32, rzi, f(-3e9)), 0x8000_0000);
        assert_eq!(cvt(Ty::U32, Ty::F32, rzi, f(-5.0)), 0);
        assert_eq!(cvt(Ty::S32, Ty::F32, rzi, f(f32::NAN)), 0);
        assert_eq!(cvt(Ty::U8, Ty::F32, rzi, f(300.0)), 255);
        let rni = FloatMode { rnd: Some(Rounding::Rni), ..M };
        assert_eq!(cvt(Ty::S32, Ty::F32, rni, f(2.5)), 2);
        assert_eq!(cvt(Ty::S32, Ty::F32, rni, f(3.5)), 4);
        let sat = FloatMode { sat: true, ..M };
        assert_eq!(cvt(Ty::U8, Ty::S32, sat, (-4i32) as u32 as u64), 0);
        assert_eq!(cvt(Ty::S8, Ty::S32, sat, 1000), 127);
        assert_eq!(cvt(Ty::F32, Ty::F32, sat, f(f32::NAN)), 0);
        assert_eq!(cvt(Ty::F32, Ty::F32, sat, f(7.0)), f(1.0));
    }

    #[test]
    fn cvt_directed_int_to_float() {
        let v = (1u64 << 24) + 1; // not representable in f32
        let rz = FloatMode { rnd: Some(Rounding::Rz), ..M };
        let rp = FloatMode { rnd: Some(Rounding::Rp), ..M };
        assert_eq!(cvt(Ty::F32, Ty::U32, rz, v), f(16777216.0));
        assert_eq!(cvt(Ty::F32, Ty::U32, rp, v), f(16777218.0));
        let rm = FloatMode { rnd: Some(Rounding::Rm), ..M };
        assert_eq!(cvt(Ty::F32, Ty::S32, rm, (-(v as i64)) as u64), f(-16777218.0));
    }

    #[test]
    fn cvt_f64_to_f32_directed() {
        let x = 1.0f64 + 2f64.powi(-30);
        let rp = FloatMode { rnd: Some(Rounding::Rp), ..M };
        let rz = FloatMode { rnd: Some(Rounding::Rz), ..M };
        assert_eq!(cvt(Ty::F32, Ty::F64, rp, x.to_bits()), f(1.0f32.next_up()));
        assert_eq!(cvt(Ty::F32, Ty::F64, rz, x.to_bits()), f(1.0));
        assert_eq!(cvt(Ty::F32, Ty::F64, rz, 1e300f64.to_bits()), f(f32::MAX));
    }

    #[test]
    fn directed_add() {
        let rz = FloatMode { rnd: Some(Rounding::Rz), ..M };
        let rp = FloatMode { rnd: Some(Rounding::Rp), ..M };
        let tiny = 2f32.powi(-30);
        assert_eq!(arith(ArithOp::Add, Ty::F32, rz, f(1.0), f(tiny), 0), f(1.0));
        assert_eq!(arith(ArithOp::Add, Ty::F32, rp, f(1.0), f(tiny), 0), f(1.0f32.next_up()));
        assert_eq!(arith(ArithOp::Add, Ty::F32, rz, f(-1.0), f(-tiny), 0), f(-1.0));
    }

    #[test]
    fn nan_results_are_canonical() {
        assert_eq!(arith(ArithOp::Add, Ty::F32, M, f(f32::INFINITY), f(f32::NEG_INFINITY), 0), NAN32 as u64);
        assert_eq!(arith(ArithOp::Mul, Ty::F64, M, 0f64.to_bits(), f64::INFINITY.to_bits(), 0), NAN64);
    }

    #[test]
    fn integer_bit_ops() {
        assert_eq!(arith(ArithOp::Popc, Ty::B32, M, 0xF0F0, 0, 0), 8);
        assert_eq!(arith(ArithOp::Clz, Ty::B32, M, 1, 0, 0), 31);
        assert_eq!(arith(ArithOp::Clz, Ty::B64, M, 0, 0, 0), 64);
        assert_eq!(arith(ArithOp::Brev, Ty::B32, M, 1, 0, 0), 0x8000_0000);
        assert_eq!(arith(ArithOp::Bfe, Ty::S32, M, 0xF0, 4, 4), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Bfe, Ty::U32, M, 0xF0, 4, 4), 0xF);
        assert_eq!(bfi(Ty::B32, 0xF, 0, 28, 8), 0xF000_0000);
        assert_eq!(arith(ArithOp::Prmt, Ty::B32, M, 0x4433_2211, 0x8877_6655, 0x3210), 0x4433_2211);
        assert_eq!(arith(ArithOp::Prmt, Ty::B32, M, 0x4433_2211, 0x8877_6655, 0x7654), 0x8877_6655);
        assert_eq!(arith(ArithOp::Prmt, Ty::B32, M, 0x0000_0080, 0, 0x8888), 0xFFFF_FFFF);
    }

    /// The `prmt` modes on bytes 0x00..0x77 of {b, a}, as PTX's table lists them.
    #[test]
    fn prmt_modes() {
        let (a, b) = (0x3322_1100u64, 0x7766_5544u64);
        let p = |op, s| arith(op, Ty::B32, M, a, b, s);
        assert_eq!(p(ArithOp::PrmtF4e, 1), 0x4433_2211);
        assert_eq!(p(ArithOp::PrmtB4e, 0), 0x5566_7700);
        assert_eq!(p(ArithOp::PrmtB4e, 3), 0x0011_2233);
        assert_eq!(p(ArithOp::PrmtRc8, 2), 0x2222_2222);
        assert_eq!(p(ArithOp::PrmtEcl, 1), 0x3322_1111);
        assert_eq!(p(ArithOp::PrmtEcr, 2), 0x2222_1100);
        assert_eq!(p(ArithOp::PrmtRc16, 1), 0x3322_3322);
        assert_eq!(p(ArithOp::PrmtRc16, 6), 0x1100_1100, "only the selector's two low bits count");
    }

    #[test]
    fn bfind_and_dot_products() {
        assert_eq!(arith(ArithOp::Bfind, Ty::U32, M, 0x10, 0, 0), 4);
        assert_eq!(arith(ArithOp::Bfind, Ty::U32, M, 0, 0, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::BfindShiftamt, Ty::U32, M, 0x10, 0, 0), 27);
        assert_eq!(arith(ArithOp::Bfind, Ty::S32, M, 0xFFFF_FFF0, 0, 0), 3, "the top bit unlike the sign");
        assert_eq!(arith(ArithOp::Bfind, Ty::S32, M, 0xFFFF_FFFF, 0, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::Bfind, Ty::U64, M, 1 << 40, 0, 0), 40);
        // bytes (1, 2, 3, 0xFF) . (4, 5, 6, 7) + 10: 0xFF is 255 unsigned, -1 signed
        let (a, b) = (0xFF03_0201u64, 0x0706_0504u64);
        assert_eq!(arith(ArithOp::Dp4aU, Ty::U32, M, a, b, 10), 10 + 4 + 10 + 18 + 255 * 7);
        assert_eq!(arith(ArithOp::Dp4aU, Ty::S32, M, a, b, 10), 10 + 4 + 10 + 18 - 7);
        // halves (0x0201, 0xFF03) times bytes 2, 3 of b (6, 7)
        assert_eq!(arith(ArithOp::Dp2aHiU, Ty::S32, M, a, b, 0), (0x0201 * 6 + (0xFF03 - 0x10000) * 7) as u32 as u64);
    }

    #[test]
    fn carry_chains() {
        use crate::ptx::ir::CarryOp;
        assert_eq!(carry(CarryOp::Add, Ty::U32, 0xFFFF_FFFF, 1, 0, 0), (0, 1));
        assert_eq!(carry(CarryOp::Add, Ty::U32, 1, 1, 0, 1), (3, 0));
        assert_eq!(carry(CarryOp::Sub, Ty::U32, 0, 0, 0, 1), (0xFFFF_FFFF, 1), "borrow in and out");
        assert_eq!(carry(CarryOp::Sub, Ty::U64, 5, 3, 0, 0), (2, 0));
        assert_eq!(carry(CarryOp::MadLo, Ty::U32, 0xFFFF_FFFF, 1, 0xFFFF_FFFF, 0), (0xFFFF_FFFE, 1));
        assert_eq!(carry(CarryOp::MadHi, Ty::U32, 0xFFFF_FFFF, 1, 1, 1), (2, 0));
    }

    #[test]
    fn funnel_shifts() {
        assert_eq!(arith(ArithOp::ShfLWrap, Ty::B32, M, 0x8000_0001, 0x8000_0001, 1), 0x0000_0003);
        assert_eq!(arith(ArithOp::ShfLWrap, Ty::B32, M, 0, 1, 33), 2);
        assert_eq!(arith(ArithOp::ShfLClamp, Ty::B32, M, 0xAB, 1, 40), 0xAB);
        assert_eq!(arith(ArithOp::ShfRWrap, Ty::B32, M, 0x10, 0x1, 4), 0x1000_0001);
        assert_eq!(arith(ArithOp::ShfRClamp, Ty::B32, M, 0x10, 0x1, 99), 0x1);
    }

    #[test]
    fn mul_variants() {
        assert_eq!(arith(ArithOp::MulHi, Ty::U32, M, 0xFFFF_FFFF, 0xFFFF_FFFF, 0), 0xFFFF_FFFE);
        assert_eq!(arith(ArithOp::MulHi, Ty::S32, M, (-2i32) as u32 as u64, 3, 0), 0xFFFF_FFFF);
        assert_eq!(arith(ArithOp::MulWide, Ty::S32, M, (-2i32) as u32 as u64, 3, 0), (-6i64) as u64);
        assert_eq!(arith(ArithOp::MulWide, Ty::U32, M, 0xFFFF_FFFF, 2, 0), 0x1_FFFF_FFFE);
        assert_eq!(arith(ArithOp::Mul24Lo, Ty::U32, M, 0x0100_0003, 2, 0), 6);
        assert_eq!(arith(ArithOp::Mul24Hi, Ty::U32, M, 0xFF_FFFF, 0xFF_FFFF, 0), 0xFFFF_FE00);
        assert_eq!(arith(ArithOp::Add, Ty::S32, FloatMode { sat: true, ..M }, 0x7FFF_FFFF, 1, 0), 0x7FFF_FFFF);
    }

    #[test]
    fn atomics_inc_dec_cas() {
        assert_eq!(atom(AtomOp::Inc, Ty::U32, 5, 5, 0), 0);
        assert_eq!(atom(AtomOp::Inc, Ty::U32, 4, 5, 0), 5);
        assert_eq!(atom(AtomOp::Dec, Ty::U32, 0, 5, 0), 5);
        assert_eq!(atom(AtomOp::Dec, Ty::U32, 9, 5, 0), 5);
        assert_eq!(atom(AtomOp::Dec, Ty::U32, 3, 5, 0), 2);
        assert_eq!(atom(AtomOp::Cas, Ty::B32, 3, 3, 9), 9);
        assert_eq!(atom(AtomOp::Cas, Ty::B32, 4, 3, 9), 4);
        assert_eq!(atom(AtomOp::Min, Ty::S32, 5, (-1i32) as u32 as u64, 0), 0xFFFF_FFFF);
    }

    #[test]
    fn compare_unordered() {
        let nan = f(f32::NAN);
        assert!(!compare(Cmp::Ne, Ty::F32, false, nan, f(1.0)));
        assert!(compare(Cmp::Neu, Ty::F32, false, nan, f(1.0)));
        assert!(compare(Cmp::Nan, Ty::F32, false, nan, f(1.0)));
        assert!(!compare(Cmp::Num, Ty::F32, false, nan, f(1.0)));
        assert!(compare(Cmp::Lt, Ty::S32, false, 0xFFFF_FFFF, 0));
        assert!(!compare(Cmp::Lo, Ty::S32, false, 0xFFFF_FFFF, 0));
    }
}
