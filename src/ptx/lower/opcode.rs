//! Typed opcodes and modifiers: an instruction's words are decoded once here,
//! and validation ([`super::validate`]) and the lowering of each instruction
//! family work on the typed form, never on strings.

use crate::ptx::ast;
use crate::ptx::ir::{AtomOp, BoolOp, Cmp, InstClass, Rounding, ShflMode, VoteMode};
use crate::ptx::types::{Space, Ty};

/// Every opcode the front end lowers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[allow(missing_docs)]
pub enum Opcode {
    Mov,
    Add,
    Sub,
    Mul,
    Mad,
    Fma,
    Mul24,
    Mad24,
    Div,
    Rem,
    Abs,
    Neg,
    Min,
    Max,
    And,
    Or,
    Xor,
    Not,
    Cnot,
    Shl,
    Shr,
    Shf,
    Popc,
    Clz,
    Brev,
    Bfe,
    Bfi,
    Prmt,
    Sqrt,
    Rsqrt,
    Rcp,
    Sin,
    Cos,
    Ex2,
    Lg2,
    Copysign,
    Setp,
    Set,
    Selp,
    Cvt,
    Cvta,
    Ld,
    St,
    Atom,
    Red,
    Bra,
    Call,
    Ret,
    Exit,
    Trap,
    Bar,
    Barrier,
    Vote,
    Activemask,
    Shfl,
    Membar,
    Fence,
    Prefetch,
    Prefetchu,
    Pmevent,
    Nanosleep,
    Brkpt,
    Nop,
    Redux,
    Match,
    Bfind,
    Dp4a,
    Dp2a,
    Addc,
    Subc,
    Madc,
    Tanh,
    Tex,
    Tld4,
    Txq,
    Suld,
    Sust,
    Sured,
}

/// The instruction families, one file of the lowering each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// `mov` in all its forms ([`super::data`]).
    Data,
    /// Integer, float and bit arithmetic ([`super::arith`]).
    Arith,
    /// Comparisons, selects and predicate logic ([`super::compare`]).
    Compare,
    /// `cvt`, `cvta` ([`super::convert`]).
    Convert,
    /// Loads, stores, atomics ([`super::memory`]).
    Memory,
    /// Branches, calls, barriers, fences ([`super::control`]).
    Control,
    /// Votes and shuffles ([`super::warp`]).
    Warp,
    /// Texture and surface objects ([`super::texture`]).
    Texture,
}

impl Opcode {
    /// The opcode of a PTX opcode word, `None` for one warplight does not lower.
    pub fn parse(w: &str) -> Option<Opcode> {
        use Opcode::*;
        Some(match w {
            "mov" => Mov,
            "add" => Add,
            "sub" => Sub,
            "mul" => Mul,
            "mad" => Mad,
            "fma" => Fma,
            "mul24" => Mul24,
            "mad24" => Mad24,
            "div" => Div,
            "rem" => Rem,
            "abs" => Abs,
            "neg" => Neg,
            "min" => Min,
            "max" => Max,
            "and" => And,
            "or" => Or,
            "xor" => Xor,
            "not" => Not,
            "cnot" => Cnot,
            "shl" => Shl,
            "shr" => Shr,
            "shf" => Shf,
            "popc" => Popc,
            "clz" => Clz,
            "brev" => Brev,
            "bfe" => Bfe,
            "bfi" => Bfi,
            "prmt" => Prmt,
            "sqrt" => Sqrt,
            "rsqrt" => Rsqrt,
            "rcp" => Rcp,
            "sin" => Sin,
            "cos" => Cos,
            "ex2" => Ex2,
            "lg2" => Lg2,
            "copysign" => Copysign,
            "setp" => Setp,
            "set" => Set,
            "selp" => Selp,
            "cvt" => Cvt,
            "cvta" => Cvta,
            "ld" => Ld,
            "st" => St,
            "atom" => Atom,
            "red" => Red,
            "bra" => Bra,
            "call" => Call,
            "ret" => Ret,
            "exit" => Exit,
            "trap" => Trap,
            "bar" => Bar,
            "barrier" => Barrier,
            "vote" => Vote,
            "activemask" => Activemask,
            "shfl" => Shfl,
            "membar" => Membar,
            "fence" => Fence,
            "prefetch" => Prefetch,
            "prefetchu" => Prefetchu,
            "pmevent" => Pmevent,
            "nanosleep" => Nanosleep,
            "brkpt" => Brkpt,
            "nop" => Nop,
            "redux" => Redux,
            "match" => Match,
            "bfind" => Bfind,
            "dp4a" => Dp4a,
            "dp2a" => Dp2a,
            "addc" => Addc,
            "subc" => Subc,
            "madc" => Madc,
            "tanh" => Tanh,
            "tex" => Tex,
            "tld4" => Tld4,
            "txq" => Txq,
            "suld" => Suld,
            "sust" => Sust,
            "sured" => Sured,
            _ => return None,
        })
    }

    /// The family whose file lowers it; `and or xor not cnot` on predicates
    /// are [`Family::Compare`] (predicate logic), see [`Decoded::family`].
    fn family(self) -> Family {
        use Opcode::*;
        match self {
            Mov => Family::Data,
            Setp | Set | Selp => Family::Compare,
            Cvt | Cvta => Family::Convert,
            Ld | St | Atom | Red => Family::Memory,
            Bra | Call | Ret | Exit | Trap | Bar | Barrier | Membar | Fence | Prefetch | Prefetchu | Pmevent
            | Nanosleep | Brkpt | Nop => Family::Control,
            Vote | Activemask | Shfl | Redux | Match => Family::Warp,
            Tex | Tld4 | Txq | Suld | Sust | Sured => Family::Texture,
            _ => Family::Arith,
        }
    }

    /// The counter class of its instructions.
    pub fn class(self) -> InstClass {
        use Opcode::*;
        match self {
            Ld | St | Atom | Red | Tex | Tld4 | Txq | Suld | Sust | Sured => InstClass::Memory,
            Bra | Call | Ret | Exit | Bar | Barrier | Membar | Fence | Trap => InstClass::Control,
            Vote | Shfl | Activemask | Redux | Match => InstClass::Warp,
            Sqrt | Rsqrt | Rcp | Sin | Cos | Ex2 | Lg2 | Tanh => InstClass::Sfu,
            _ => InstClass::Alu,
        }
    }
}

/// An instruction's modifiers sorted into types, state space and words.
#[derive(Debug, Clone)]
pub struct Mods {
    /// The type words in order (`cvt.f32.s32` has two).
    pub types: Vec<Ty>,
    /// The state space, when one is written.
    pub space: Option<Space>,
    /// The other words in order, without the dot.
    pub words: Vec<String>,
}

impl Mods {
    /// Sorts the dotted words of `i`.
    pub fn of(i: &ast::Instruction) -> Mods {
        let mut m = Mods { types: Vec::new(), space: None, words: Vec::new() };
        for w in &i.mods {
            if let Some(t) = Ty::parse(w) {
                m.types.push(t);
            } else if let Some(s) = Space::parse(w).filter(|s| *s != Space::Reg) {
                m.space = Some(s);
            } else {
                m.words.push(w.clone());
            }
        }
        m
    }

    /// True when the word `w` is written.
    pub fn has(&self, w: &str) -> bool {
        self.words.iter().any(|x| x == w)
    }

    /// The first rounding mode written.
    pub fn rounding(&self) -> Option<Rounding> {
        self.words.iter().find_map(|w| rounding_of(w))
    }

    /// `.v2` / `.v4`: elements moved; 1 without.
    pub fn vec(&self) -> u32 {
        if self.has("v4") {
            4
        } else if self.has("v2") {
            2
        } else {
            1
        }
    }

    /// The `.vote` mode written.
    pub fn vote_mode(&self) -> Option<VoteMode> {
        self.words.iter().find_map(|w| {
            Some(match w.as_str() {
                "all" => VoteMode::All,
                "any" => VoteMode::Any,
                "uni" => VoteMode::Uni,
                "ballot" => VoteMode::Ballot,
                _ => return None,
            })
        })
    }

    /// The `.shfl` mode written.
    pub fn shfl_mode(&self) -> Option<ShflMode> {
        self.words.iter().find_map(|w| {
            Some(match w.as_str() {
                "up" => ShflMode::Up,
                "down" => ShflMode::Down,
                "bfly" => ShflMode::Bfly,
                "idx" => ShflMode::Idx,
                _ => return None,
            })
        })
    }
}

/// A rounding-mode word.
pub fn rounding_of(w: &str) -> Option<Rounding> {
    Some(match w {
        "rn" => Rounding::Rn,
        "rz" => Rounding::Rz,
        "rm" => Rounding::Rm,
        "rp" => Rounding::Rp,
        "rni" => Rounding::Rni,
        "rzi" => Rounding::Rzi,
        "rmi" => Rounding::Rmi,
        "rpi" => Rounding::Rpi,
        _ => return None,
    })
}

/// A comparison word of `setp`/`set`.
pub fn cmp_of(w: &str) -> Option<Cmp> {
    Some(match w {
        "eq" => Cmp::Eq,
        "ne" => Cmp::Ne,
        "lt" => Cmp::Lt,
        "le" => Cmp::Le,
        "gt" => Cmp::Gt,
        "ge" => Cmp::Ge,
        "lo" => Cmp::Lo,
        "ls" => Cmp::Ls,
        "hi" => Cmp::Hi,
        "hs" => Cmp::Hs,
        "equ" => Cmp::Equ,
        "neu" => Cmp::Neu,
        "ltu" => Cmp::Ltu,
        "leu" => Cmp::Leu,
        "gtu" => Cmp::Gtu,
        "geu" => Cmp::Geu,
        "num" => Cmp::Num,
        "nan" => Cmp::Nan,
        _ => return None,
    })
}

/// A boolean combiner word.
pub fn bool_of(w: &str) -> Option<BoolOp> {
    Some(match w {
        "and" => BoolOp::And,
        "or" => BoolOp::Or,
        "xor" => BoolOp::Xor,
        _ => return None,
    })
}

/// An atomic operation word; `None` for the words atomics accept and ignore
/// (ordering, scope, `.noftz`) and for unknown words.
pub fn atom_op_of(w: &str) -> Option<AtomOp> {
    Some(match w {
        "add" => AtomOp::Add,
        "min" => AtomOp::Min,
        "max" => AtomOp::Max,
        "inc" => AtomOp::Inc,
        "dec" => AtomOp::Dec,
        "exch" => AtomOp::Exch,
        "cas" => AtomOp::Cas,
        "and" => AtomOp::And,
        "or" => AtomOp::Or,
        "xor" => AtomOp::Xor,
        _ => return None,
    })
}

/// An instruction with its opcode and modifiers decoded.
#[derive(Debug, Clone)]
pub struct Decoded {
    /// The opcode.
    pub op: Opcode,
    /// The modifiers.
    pub mods: Mods,
    /// The full opcode as written (`ld.global.nc.f32`), for messages and listings.
    pub full: String,
}

impl Decoded {
    /// Decodes `i`; `None` when its opcode is not one warplight lowers.
    pub fn of(i: &ast::Instruction) -> Option<Decoded> {
        Some(Decoded { op: Opcode::parse(&i.opcode)?, mods: Mods::of(i), full: i.full_opcode() })
    }

    /// The family that lowers it: bitwise opcodes on `.pred` are predicate logic.
    pub fn family(&self) -> Family {
        let pred_logic = matches!(self.op, Opcode::And | Opcode::Or | Opcode::Xor | Opcode::Not | Opcode::Cnot)
            && self.mods.types.first() == Some(&Ty::Pred);
        if pred_logic { Family::Compare } else { self.op.family() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parser's list of known opcodes and this decoder agree.
    #[test]
    fn every_known_opcode_decodes() {
        for w in crate::ptx::parser::KNOWN_OPCODES {
            assert!(Opcode::parse(w).is_some(), "{w}");
        }
        assert_eq!(Opcode::parse("wmma"), None);
    }
}
