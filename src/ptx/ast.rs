//! The syntax tree: PTX as written, before names and types are resolved.

use super::error::Pos;
use super::types::{Space, Ty};

/// A parsed PTX module.
#[derive(Debug, Clone, Default)]
pub struct Module {
    /// `.version` text, e.g. `7.8`.
    pub version: String,
    /// `.target` words, e.g. `sm_90`.
    pub target: Vec<String>,
    /// `.address_size` (64 when absent).
    pub address_size: u32,
    /// `.file` table: id and path.
    pub files: Vec<(u32, String)>,
    /// Module-scope variables.
    pub vars: Vec<VarDecl>,
    /// Functions and kernels, in source order.
    pub functions: Vec<Function>,
}

/// Literal values in initializers and operands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Literal {
    /// An integer (with its sign applied, as two's complement bits).
    Int(u64),
    /// An f32 given by its bits.
    F32(u32),
    /// An f64 given by its bits.
    F64(u64),
    /// A decimal float.
    Float(f64),
}

/// A variable declaration (`.reg`, `.shared`, `.param`, ...).
#[derive(Debug, Clone)]
pub struct VarDecl {
    /// Its state space.
    pub space: Space,
    /// `.align N`.
    pub align: Option<u32>,
    /// `.v2` / `.v4`.
    pub vector: Option<u32>,
    /// Element type.
    pub ty: Ty,
    /// Name.
    pub name: String,
    /// `name<N>`: a range of N registers `name0..name{N-1}`.
    pub range: Option<u32>,
    /// Array dimensions (`None` for `[]`).
    pub dims: Vec<Option<u64>>,
    /// Initializer, flattened.
    pub init: Option<Vec<Literal>>,
    /// Elements of the initializer that name a symbol (a function, for tables
    /// of function pointers and vtables): element index and name; `init`
    /// holds 0 there.
    pub init_syms: Vec<(usize, String)>,
    /// `.extern`.
    pub is_extern: bool,
    /// Where it was declared.
    pub pos: Pos,
}

impl VarDecl {
    /// Size in bytes of the declared object (0 for an unsized `[]` array).
    pub fn size_bytes(&self) -> u64 {
        let elems: u64 = self.dims.iter().map(|d| d.unwrap_or(0)).product();
        elems * self.ty.bytes() as u64 * self.vector.unwrap_or(1) as u64
    }
}

/// `.entry` or `.func`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FunctionKind {
    /// A kernel.
    Entry,
    /// A device function.
    Func,
}

/// A function or kernel.
#[derive(Debug, Clone)]
pub struct Function {
    /// Entry or device function.
    pub kind: FunctionKind,
    /// Its name.
    pub name: String,
    /// Return parameters (`.func (.param .b32 r) f(...)`).
    pub returns: Vec<VarDecl>,
    /// Parameters.
    pub params: Vec<VarDecl>,
    /// Body; `None` for a declaration without one.
    pub body: Option<Vec<Stmt>>,
    /// Where the function starts.
    pub pos: Pos,
}

/// A statement in a function body.
#[derive(Debug, Clone)]
pub enum Stmt {
    /// `name:`
    Label(String, Pos),
    /// A declaration inside the body.
    Decl(VarDecl),
    /// `.loc file line col`
    Loc {
        /// File id.
        file: u32,
        /// Source line.
        line: u32,
        /// Source column.
        col: u32,
    },
    /// An instruction.
    Inst(Instruction),
    /// `{ ... }` scope.
    Block(Vec<Stmt>),
}

/// An instruction as written.
#[derive(Debug, Clone)]
pub struct Instruction {
    /// `@%p` or `@!%p`: (negated, name).
    pub guard: Option<(bool, String)>,
    /// The opcode word: `ld`, `setp`.
    pub opcode: String,
    /// The dotted modifiers in order: `global`, `f32`.
    pub mods: Vec<String>,
    /// Operands.
    pub operands: Vec<Operand>,
    /// Where the instruction starts.
    pub pos: Pos,
}

impl Instruction {
    /// The full opcode as written: `ld.global.f32`.
    pub fn full_opcode(&self) -> String {
        let mut s = self.opcode.clone();
        for m in &self.mods {
            s.push('.');
            s.push_str(m);
        }
        s
    }
}

/// An operand as written.
#[derive(Debug, Clone, PartialEq)]
pub enum Operand {
    /// A register, special register (`%tid.x` keeps its `.x`), label or symbol name.
    Name(String),
    /// A literal.
    Lit(Literal),
    /// `!%p`
    Not(String),
    /// `[base+offset]`: base name (or none for an absolute address) and byte offset.
    Addr(Option<String>, i64),
    /// `sym+8` (or `sym-8`): a variable's address plus a byte offset, PTX's
    /// address expression as a value (`mov.u32 %r1, sym+8`).
    Offset(String, i64),
    /// `{a, b, ...}`
    Vector(Vec<Operand>),
    /// `(a, b, ...)` in `call`.
    List(Vec<Operand>),
    /// `p|q` (the two results of `setp`).
    Pair(String, String),
    /// `[handle, {c0, c1, ...}]`: a texture or surface object (register or
    /// name) and its coordinates (`tex`, `tld4`, `suld`, `sust`).
    TexAddr(String, Vec<Operand>),
}
