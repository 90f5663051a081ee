//! The special-function unit's approximations: which results `.approx`
//! (and `div.full`) instructions produce, and the H200's table model.
//!
//! On an H200 (docs/gpu-measurements.md) the MUFU reciprocal, reciprocal
//! square root and square root are scale invariant: one binade fixes
//! `MUFU.RCP` and two fix `MUFU.RSQ` and `MUFU.SQRT`. Three tables,
//! `tests/fixtures/mufu/*.i8.zlib` (one signed byte per input of [1, 2) or
//! [1, 4)), hold the distance δ of the unit's result from the correctly
//! rounded one; with ptxas's wrappers around the unit (rescaling subnormal and
//! huge operands, `FMUL` for the divisions) they reproduce `rcp.approx`,
//! `rsqrt.approx`, `sqrt.approx`, `div.approx` and `div.full` (both flush
//! modes) bit for bit on all 2^32 inputs. The tables are decompressed on
//! first use (40 MiB).
//!
//! `ex2`, `lg2`, `sin`, `cos` have no bit-exact model (see docs/semantics.md
//! for their measured error); they stay computed in f64 and rounded once.

use std::sync::OnceLock;

/// How `.approx` special functions and `div.approx`/`div.full` are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SfuModel {
    /// Correctly rounded (computed exactly, rounded once): what warplight
    /// did before the measurements, kept for the gt200 and maxwell profiles.
    CorrectlyRounded,
    /// The H200's MUFU table model for `rcp`, `rsqrt`, `sqrt` and the
    /// divisions (bit exact); the others correctly rounded.
    #[default]
    Sm90,
}

/// The canonical NaN the unit returns.
const QNAN: u32 = 0x7FFF_FFFF;
const TINY: f32 = 1.175_494_4e-38; // 2^-126
const BIG: f32 = 8.507_059e37; // 2^126

struct Tables {
    rcp: Vec<i8>,
    rsqrt: Vec<i8>,
    sqrt: Vec<i8>,
}

fn inflate(z: &[u8], n: usize) -> Vec<i8> {
    let b = miniz_oxide::inflate::decompress_to_vec_zlib(z).expect("the committed MUFU tables inflate");
    assert_eq!(b.len(), n, "MUFU table size");
    b.into_iter().map(|x| x as i8).collect()
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| Tables {
        rcp: inflate(include_bytes!("../../tests/fixtures/mufu/rcp_1_2.i8.zlib"), 1 << 23),
        rsqrt: inflate(include_bytes!("../../tests/fixtures/mufu/rsqrt_1_4.i8.zlib"), 1 << 24),
        sqrt: inflate(include_bytes!("../../tests/fixtures/mufu/sqrt_1_4.i8.zlib"), 1 << 24),
    })
}

fn f(u: u32) -> f32 {
    f32::from_bits(u)
}

/// `MUFU.RCP`: subnormal inputs and results flushed.
pub fn mufu_rcp(x: u32) -> u32 {
    let s = x & 0x8000_0000;
    let e = (x >> 23) & 255;
    if e == 255 {
        return if x & 0x7F_FFFF != 0 { QNAN } else { s };
    }
    if e == 0 {
        return s | 0x7F80_0000;
    }
    let mb = 0x3F80_0000 | (x & 0x7F_FFFF);
    let rn = ((1.0f64 / f(mb) as f64) as f32).to_bits();
    let yb = rn.wrapping_add_signed(tables().rcp[(mb - 0x3F80_0000) as usize] as i32);
    let ye = ((yb >> 23) & 255) as i32 - (e as i32 - 127);
    if ye <= 0 { s } else { s | ((ye as u32) << 23) | (yb & 0x7F_FFFF) }
}

/// `MUFU.RSQ` (`sqrt == false`) or `MUFU.SQRT`: subnormal inputs flushed.
pub fn mufu_rsq(x: u32, sqrt: bool) -> u32 {
    let s = x & 0x8000_0000;
    let e = (x >> 23) & 255;
    if e == 0 {
        return if sqrt { s } else { s | 0x7F80_0000 };
    }
    if s != 0 {
        return QNAN;
    }
    if e == 255 {
        return if x & 0x7F_FFFF != 0 {
            QNAN
        } else if sqrt {
            0x7F80_0000
        } else {
            0
        };
    }
    let ue = e as i32 - 127;
    let k = ue.div_euclid(2);
    let mb = (((ue - 2 * k + 127) as u32) << 23) | (x & 0x7F_FFFF);
    let md = f(mb) as f64;
    let (rn, t) = if sqrt {
        ((md.sqrt() as f32).to_bits(), &tables().sqrt)
    } else {
        (((1.0 / md.sqrt()) as f32).to_bits(), &tables().rsqrt)
    };
    let yb = rn.wrapping_add_signed(t[(mb - 0x3F80_0000) as usize] as i32);
    let ye = ((yb >> 23) & 255) as i32 + if sqrt { k } else { -k };
    ((ye as u32) << 23) | (yb & 0x7F_FFFF)
}

/// `FMUL` (round to nearest; `.FTZ` flushes inputs and result).
fn fmul(a: u32, b: u32, ftz: bool) -> u32 {
    let flush = |x: u32| if ftz && (x >> 23) & 255 == 0 { x & 0x8000_0000 } else { x };
    let r = f(flush(a)) * f(flush(b));
    if r.is_nan() { QNAN } else { flush(r.to_bits()) }
}

const TWO24: u32 = 0x4B80_0000; // 2^24
const QUARTER: u32 = 0x3E80_0000; // 0.25

/// `rcp.approx[.ftz].f32` as ptxas builds it around `MUFU.RCP`.
pub fn rcp(x: u32, ftz: bool) -> u32 {
    if ftz {
        return mufu_rcp(x);
    }
    let ax = f(x).abs();
    let s = if ax > BIG {
        QUARTER
    } else if ax >= TINY {
        0x3F80_0000
    } else {
        TWO24
    };
    fmul(s, mufu_rcp(fmul(x, s, false)), false)
}

/// `rsqrt.approx[.ftz].f32` (`sqrt == false`) or `sqrt.approx[.ftz].f32`.
pub fn rsq(x: u32, sqrt: bool, ftz: bool) -> u32 {
    let fx = f(x);
    if ftz || fx.abs() >= TINY || fx.is_nan() {
        return mufu_rsq(x, sqrt);
    }
    let y = mufu_rsq(fmul(x, TWO24, false), sqrt);
    fmul(y, if sqrt { 0x3980_0000 } else { 0x4580_0000 }, false) // 2^-12, 2^12
}

/// `div.approx[.ftz].f32 a / b`.
pub fn div_approx(a: u32, b: u32, ftz: bool) -> u32 {
    if ftz {
        return fmul(a, mufu_rcp(b), true);
    }
    let fb = f(b);
    let (a, b) = if fb.abs() >= TINY || fb.is_nan() { (a, b) } else { (fmul(a, TWO24, false), fmul(b, TWO24, false)) };
    fmul(mufu_rcp(b), a, false)
}

/// `div.full[.ftz].f32 a / b`.
pub fn div_full(a: u32, b: u32, ftz: bool) -> u32 {
    let fb = f(b);
    let big = fb.abs() > BIG;
    let (mut a, mut b) = if big { (fmul(a, QUARTER, ftz), fmul(b, QUARTER, ftz)) } else { (a, b) };
    if !(ftz || fb.abs() >= TINY || fb.is_nan()) {
        (a, b) = (fmul(a, TWO24, false), fmul(b, TWO24, false));
    }
    fmul(mufu_rcp(b), a, ftz)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Special values of docs/gpu-measurements.md's table.
    #[test]
    fn special_values() {
        let (pz, nz, pinf, ninf, nan, tiny) = (0u32, 0x8000_0000u32, 0x7F80_0000, 0xFF80_0000, 0x7FC0_0000, 1);
        assert_eq!([pz, nz, pinf, ninf, nan].map(|x| rcp(x, false)), [pinf, ninf, pz, nz, QNAN]);
        assert_eq!(rcp(tiny, false), pinf);
        assert_eq!(rcp(0xBF80_0000, false), 0xBF80_0000);
        assert_eq!(rsq(tiny, false, false), 0x64B5_04F2);
        assert_eq!(rsq(tiny, false, true), pinf);
        assert_eq!(rsq(tiny | nz, false, true), ninf);
        assert_eq!(rsq(tiny, true, false), 0x1A35_04F3);
        assert_eq!(rsq(tiny, true, true), pz);
        assert_eq!(rsq(0xBF80_0000, true, false), QNAN);
        assert_eq!(rsq(ninf, false, false), QNAN);
        assert_eq!(rsq(pinf, true, false), pinf);
        assert_eq!(rsq(nz, true, false), nz);
    }
}
