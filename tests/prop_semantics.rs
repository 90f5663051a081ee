//! Property tests of instruction semantics against independent definitions:
//! directed rounding brackets the exact result, integer operations wrap as
//! two's complement, conversions saturate.

#![allow(clippy::needless_range_loop)]

use proptest::prelude::*;
use warplight::ptx::ir::{ArithOp, CarryOp, FloatMode, Rounding};
use warplight::ptx::types::Ty;
use warplight::sim::alu::{arith, carry, cvt};

fn mode(r: Rounding) -> FloatMode {
    FloatMode { rnd: Some(r), ..FloatMode::default() }
}

/// f32 values whose sums and products are exact in f64.
fn small_f32() -> impl Strategy<Value = f32> {
    (any::<bool>(), 0u32..(1 << 23), -12i32..12).prop_map(|(neg, m, e)| {
        let v = (1.0 + m as f32 / (1u32 << 23) as f32) * 2f32.powi(e);
        if neg { -v } else { v }
    })
}

/// Checks that `r` is the rounding of exact `x` in direction `rnd`.
fn check_directed(r: f32, x: f64, rnd: Rounding) -> Result<(), TestCaseError> {
    let rf = r as f64;
    match rnd {
        Rounding::Rm => prop_assert!(rf <= x && (r.next_up() as f64) > x, "rm {r} for {x}"),
        Rounding::Rp => prop_assert!(rf >= x && (r.next_down() as f64) < x, "rp {r} for {x}"),
        Rounding::Rz => {
            let away = if x >= 0.0 { r.next_up() } else { r.next_down() };
            prop_assert!(rf.abs() <= x.abs() && (away as f64).abs() > x.abs(), "rz {r} for {x}");
        }
        _ => prop_assert_eq!(r, x as f32),
    }
    Ok(())
}

fn f(x: f32) -> u64 {
    x.to_bits() as u64
}

proptest! {
    #[test]
    fn add_and_mul_round_in_every_direction(a in small_f32(), b in small_f32()) {
        for rnd in [Rounding::Rn, Rounding::Rz, Rounding::Rm, Rounding::Rp] {
            let s = f32::from_bits(arith(ArithOp::Add, Ty::F32, mode(rnd), f(a), f(b), 0) as u32);
            let exact = a as f64 + b as f64;
            if exact != 0.0 {
                check_directed(s, exact, rnd)?;
            }
            let p = f32::from_bits(arith(ArithOp::Mul, Ty::F32, mode(rnd), f(a), f(b), 0) as u32);
            check_directed(p, a as f64 * b as f64, rnd)?;
        }
    }

    #[test]
    fn fma_rounds_once(a in small_f32(), b in small_f32(), c in small_f32()) {
        let r = f32::from_bits(arith(ArithOp::Mad, Ty::F32, mode(Rounding::Rn), f(a), f(b), f(c)) as u32);
        // a*b is exact in f64 and a*b + c has at most 24+24+24 bits of span here: exact in f64 when small.
        let exact = a as f64 * b as f64 + c as f64;
        if (exact - (a as f64 * b as f64)) == c as f64 {
            prop_assert_eq!(r, exact as f32);
        }
    }

    #[test]
    fn int_to_float_rounds_in_every_direction(v in any::<i32>()) {
        for rnd in [Rounding::Rn, Rounding::Rz, Rounding::Rm, Rounding::Rp] {
            let r = f32::from_bits(cvt(Ty::F32, Ty::S32, mode(rnd), v as u32 as u64) as u32);
            check_directed(r, v as f64, rnd)?;
        }
    }

    #[test]
    fn float_to_int_saturates(x in any::<f32>()) {
        let rzi = cvt(Ty::S32, Ty::F32, mode(Rounding::Rzi), f(x)) as u32 as i32;
        prop_assert_eq!(rzi, x as i32); // Rust's `as` saturates and maps NaN to 0
        let rni = cvt(Ty::S32, Ty::F32, mode(Rounding::Rni), f(x)) as u32 as i32;
        prop_assert_eq!(rni, x.round_ties_even() as i32);
        let u = cvt(Ty::U32, Ty::F32, mode(Rounding::Rmi), f(x)) as u32;
        prop_assert_eq!(u, x.floor() as u32);
    }

    #[test]
    fn integer_ops_wrap(a in any::<u32>(), b in any::<u32>()) {
        let m = FloatMode::default();
        let (ai, bi) = (a as i32, b as i32);
        let ev = |op, ty| arith(op, ty, m, a as u64, b as u64, 0) as u32;
        prop_assert_eq!(ev(ArithOp::Add, Ty::U32), a.wrapping_add(b));
        prop_assert_eq!(ev(ArithOp::Sub, Ty::S32), ai.wrapping_sub(bi) as u32);
        prop_assert_eq!(ev(ArithOp::Mul, Ty::S32), ai.wrapping_mul(bi) as u32);
        prop_assert_eq!(ev(ArithOp::MulHi, Ty::U32), ((a as u64 * b as u64) >> 32) as u32);
        prop_assert_eq!(ev(ArithOp::MulHi, Ty::S32), ((ai as i64 * bi as i64) >> 32) as u32);
        prop_assert_eq!(ev(ArithOp::Min, Ty::S32), ai.min(bi) as u32);
        prop_assert_eq!(ev(ArithOp::Max, Ty::U32), a.max(b));
        prop_assert_eq!(ev(ArithOp::Shl, Ty::B32), a.checked_shl(b).unwrap_or(0));
        prop_assert_eq!(ev(ArithOp::Shr, Ty::U32), a.checked_shr(b).unwrap_or(0));
        prop_assert_eq!(ev(ArithOp::Shr, Ty::S32), (ai >> b.min(31)) as u32);
        // by zero: all ones (as an H100 computes it)
        prop_assert_eq!(ev(ArithOp::Div, Ty::U32), a.checked_div(b).unwrap_or(u32::MAX));
        prop_assert_eq!(ev(ArithOp::Rem, Ty::U32), a.checked_rem(b).unwrap_or(u32::MAX));
        prop_assert_eq!(ev(ArithOp::Div, Ty::S32), ai.checked_div(bi).map_or(u32::MAX, |q| q as u32).max(if bi == -1 && ai == i32::MIN { ai as u32 } else { 0 }));
        prop_assert_eq!(ev(ArithOp::Rem, Ty::S32), if bi == 0 { u32::MAX } else { ai.wrapping_rem(bi) as u32 });
        let wide = arith(ArithOp::MulWide, Ty::S32, m, a as u64, b as u64, 0);
        prop_assert_eq!(wide as i64, ai as i64 * bi as i64);
        prop_assert_eq!(arith(ArithOp::Popc, Ty::B32, m, a as u64, 0, 0) as u32, a.count_ones());
        prop_assert_eq!(arith(ArithOp::Brev, Ty::B32, m, a as u64, 0, 0) as u32, a.reverse_bits());
    }
}

/// `mad.hi.cc`/`madc.hi` on signed types take the high half of the signed
/// product (worked by hand): -2 × 3 = -6 has the high word 0xFFFF_FFFF, where
/// the unsigned product 0xFFFF_FFFE × 3 = 0x2_FFFF_FFFA has 2.
#[test]
fn signed_mad_hi_carry_takes_the_signed_high_half() {
    let m2 = (-2i32) as u32 as u64;
    assert_eq!(carry(CarryOp::MadHi, Ty::S32, m2, 3, 0, 0), (0xFFFF_FFFF, 0));
    assert_eq!(carry(CarryOp::MadHi, Ty::U32, m2, 3, 0, 0), (2, 0), "unsigned unchanged");
    // 0xFFFF_FFFF + 1 wraps to 0 with a carry out
    assert_eq!(carry(CarryOp::MadHi, Ty::S32, m2, 3, 1, 0), (0, 1));
    assert_eq!(carry(CarryOp::MadHi, Ty::S32, m2, 3, 0, 1), (0, 1), "carry in");
    // (-1)(-1) = 1: high word 0; unsigned 2^128 - 2^65 + 1, high word 2^64 - 2,
    // which + 5 + 1 wraps to 4 with a carry out
    let m1 = u64::MAX;
    assert_eq!(carry(CarryOp::MadHi, Ty::S64, m1, m1, 5, 1), (6, 0));
    assert_eq!(carry(CarryOp::MadHi, Ty::U64, m1, m1, 5, 1), (4, 1));
    // i64::MIN × 2 = -2^64: high word -1; + carry in = 0 with a carry out
    assert_eq!(carry(CarryOp::MadHi, Ty::S64, i64::MIN as u64, 2, 0, 1), (0, 1));
    // the low half is the same for both
    assert_eq!(carry(CarryOp::MadLo, Ty::S32, m2, 3, 0, 0), ((-6i32) as u32 as u64, 0));
}

proptest! {
    #[test]
    fn signed_mad_hi_carry_matches_i128(a in any::<i64>(), b in any::<i64>(), c in any::<u64>(), cin in 0u64..2) {
        // 32 bits: i64 product of the sign-extended words
        let (a32, b32, c32) = (a as i32, b as i32, c as u32);
        let hi = ((a32 as i64 * b32 as i64) >> 32) as u32 as u64;
        let sum = hi + c32 as u64 + cin;
        prop_assert_eq!(carry(CarryOp::MadHi, Ty::S32, a as u64, b as u64, c, cin), (sum & 0xFFFF_FFFF, sum >> 32));
        // 64 bits: i128 product
        let hi = ((a as i128 * b as i128) >> 64) as u64 as u128;
        let sum = hi + c as u128 + cin as u128;
        prop_assert_eq!(carry(CarryOp::MadHi, Ty::S64, a as u64, b as u64, c, cin), (sum as u64, (sum >> 64) as u64));
    }
}
