//! PTX scalar types and state spaces.

use std::fmt;

/// A PTX fundamental type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[allow(missing_docs)]
pub enum Ty {
    B8,
    B16,
    B32,
    B64,
    U8,
    U16,
    U32,
    U64,
    S8,
    S16,
    S32,
    S64,
    F16,
    /// bfloat16.
    BF16,
    /// Two `.f16` in 32 bits (the first in the low half).
    F16x2,
    /// Two `.bf16` in 32 bits.
    BF16x2,
    F32,
    F64,
    Pred,
}

impl Ty {
    /// Parses a type suffix such as `u32` (without the dot).
    pub fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "b8" => Ty::B8,
            "b16" => Ty::B16,
            "b32" => Ty::B32,
            "b64" => Ty::B64,
            "u8" => Ty::U8,
            "u16" => Ty::U16,
            "u32" => Ty::U32,
            "u64" => Ty::U64,
            "s8" => Ty::S8,
            "s16" => Ty::S16,
            "s32" => Ty::S32,
            "s64" => Ty::S64,
            "f16" => Ty::F16,
            "bf16" => Ty::BF16,
            "f16x2" => Ty::F16x2,
            "bf16x2" => Ty::BF16x2,
            "f32" => Ty::F32,
            "f64" => Ty::F64,
            "pred" => Ty::Pred,
            _ => return None,
        })
    }

    /// Width in bits (predicates count as 1).
    pub fn bits(self) -> u32 {
        match self {
            Ty::B8 | Ty::U8 | Ty::S8 => 8,
            Ty::B16 | Ty::U16 | Ty::S16 | Ty::F16 | Ty::BF16 => 16,
            Ty::B32 | Ty::U32 | Ty::S32 | Ty::F32 | Ty::F16x2 | Ty::BF16x2 => 32,
            Ty::B64 | Ty::U64 | Ty::S64 | Ty::F64 => 64,
            Ty::Pred => 1,
        }
    }

    /// Width in bytes (a predicate counts as one byte).
    pub fn bytes(self) -> u32 {
        self.bits().div_ceil(8)
    }

    /// True for `.f16`, `.f32`, `.f64`.
    pub fn is_float(self) -> bool {
        matches!(self, Ty::F16 | Ty::BF16 | Ty::F16x2 | Ty::BF16x2 | Ty::F32 | Ty::F64)
    }

    /// True for the signed integer types.
    pub fn is_signed(self) -> bool {
        matches!(self, Ty::S8 | Ty::S16 | Ty::S32 | Ty::S64)
    }

    /// True for the integer and bit types.
    pub fn is_int(self) -> bool {
        !self.is_float() && self != Ty::Pred
    }

    /// All-ones mask of the type's width.
    pub fn mask(self) -> u64 {
        match self.bits() {
            64 => u64::MAX,
            b => (1u64 << b) - 1,
        }
    }

    /// Sign- or zero-extends the low bits of `v` to 64 bits as this type prescribes.
    pub fn extend(self, v: u64) -> u64 {
        let b = self.bits();
        if b >= 64 {
            return v;
        }
        if self.is_signed() {
            let sh = 64 - b;
            (((v << sh) as i64) >> sh) as u64
        } else {
            v & self.mask()
        }
    }
}

impl fmt::Display for Ty {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = format!("{self:?}").to_lowercase();
        f.write_str(&s)
    }
}

/// A PTX state space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[allow(missing_docs)]
pub enum Space {
    Reg,
    Global,
    Shared,
    Local,
    Param,
    Const,
    /// No space given: a generic address.
    Generic,
}

impl Space {
    /// Parses a state space word (without the dot).
    pub fn parse(s: &str) -> Option<Space> {
        Some(match s {
            "reg" => Space::Reg,
            "global" => Space::Global,
            "shared" => Space::Shared,
            "local" => Space::Local,
            "param" => Space::Param,
            "const" => Space::Const,
            _ => return None,
        })
    }
}

impl fmt::Display for Space {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = format!("{self:?}").to_lowercase();
        f.write_str(&s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extend_signs_and_zeros() {
        assert_eq!(Ty::S8.extend(0x80), 0xFFFF_FFFF_FFFF_FF80);
        assert_eq!(Ty::U8.extend(0x180), 0x80);
        assert_eq!(Ty::S32.extend(0xFFFF_FFFF), u64::MAX);
        assert_eq!(Ty::B64.extend(5), 5);
    }
}
