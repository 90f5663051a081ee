//! Layout: sizes, alignments and offsets of variables and parameters, the
//! initial bytes of module variables, and function signatures.

use super::operands::lit_bits;
use super::{LResult, invalid, unsupported};
use crate::ptx::ast::{self, Stmt};
use crate::ptx::ir::Param;
use crate::ptx::types::Space;

/// `v` rounded up to a multiple of `a` (1 when `a` is 0).
pub(super) fn align_up(v: u64, a: u64) -> u64 {
    let a = a.max(1);
    v.div_ceil(a) * a
}

/// The function-scope `.shared` declarations of a body, nested blocks included.
pub(super) fn collect_shared<'a>(body: &'a [Stmt], out: &mut Vec<&'a ast::VarDecl>) {
    for s in body {
        match s {
            Stmt::Decl(d) if d.space == Space::Shared => out.push(d),
            Stmt::Block(b) => collect_shared(b, out),
            _ => {}
        }
    }
}

/// The initial bytes of a module variable (zeros past its initializer).
pub(super) fn init_bytes(v: &ast::VarDecl) -> LResult<Vec<u8>> {
    let size = v.size_bytes() as usize;
    let mut out = Vec::with_capacity(size);
    if let Some(init) = &v.init {
        let eb = v.ty.bytes() as usize;
        for l in init {
            let bits = lit_bits(*l, v.ty, v.pos)?;
            out.extend_from_slice(&bits.to_le_bytes()[..eb]);
        }
        if out.len() > size && size > 0 {
            return invalid(v.pos, format!("initializer of `{}` has more elements than the array", v.name));
        }
    }
    out.resize(size, 0);
    Ok(out)
}

/// A function's parameters and return parameters laid out.
#[derive(Debug, Clone)]
pub(super) struct Signature {
    /// True for a kernel.
    pub(super) is_entry: bool,
    /// False for a declaration without a body.
    pub(super) has_body: bool,
    /// The function's name.
    pub(super) name: String,
    /// Parameters with their offsets.
    pub(super) params: Vec<Param>,
    /// Return parameters with their offsets (before the parameters).
    pub(super) returns: Vec<Param>,
    /// Bytes of the parameter area.
    pub(super) param_area: u32,
}

/// Lays out the parameters of `f` (kernel parameter area for entries, frame area otherwise).
pub(super) fn signature(f: &ast::Function) -> LResult<Signature> {
    let is_entry = f.kind == ast::FunctionKind::Entry;
    let mut off: u64 = 0;
    let mut place = |v: &ast::VarDecl| -> LResult<Param> {
        if v.space != Space::Param && v.space != Space::Reg {
            return unsupported(v.pos, format!(".{} parameter", v.space));
        }
        if v.space == Space::Reg {
            return unsupported(v.pos, ".reg parameters (use .param)");
        }
        let size = v.size_bytes().max(v.ty.bytes() as u64 * v.vector.unwrap_or(1) as u64);
        let size = if v.dims.is_empty() { v.ty.bytes() as u64 * v.vector.unwrap_or(1) as u64 } else { size };
        let align = v.align.map(|a| a as u64).unwrap_or(v.ty.bytes() as u64);
        off = align_up(off, align);
        let p = Param { name: v.name.clone(), ty: v.ty, offset: off as u32, size: size as u32 };
        off += size;
        Ok(p)
    };
    let returns = f.returns.iter().map(&mut place).collect::<LResult<Vec<_>>>()?;
    let params = f.params.iter().map(&mut place).collect::<LResult<Vec<_>>>()?;
    Ok(Signature {
        is_entry,
        has_body: f.body.is_some(),
        name: f.name.clone(),
        params,
        returns,
        param_area: off as u32,
    })
}
