//! Layout: sizes, alignments and offsets of variables and parameters, the
//! initial bytes of module variables, and function signatures.

use super::operands::lit_bits;
use super::{LResult, invalid, unsupported};
use crate::limits;
use crate::ptx::ast::{self, Stmt};
use crate::ptx::error::PtxErrorKind;
use crate::ptx::ir::Param;
use crate::ptx::types::Space;

/// The size in bytes of a declared variable, computed without wrapping: an
/// error naming the variable when its dimensions multiply past 2^64 bytes.
pub(super) fn var_size(v: &ast::VarDecl) -> LResult<u64> {
    let elem = v.ty.bytes() as u64 * v.vector.unwrap_or(1) as u64;
    v.dims
        .iter()
        .try_fold(elem, |acc, d| acc.checked_mul(d.unwrap_or(0)))
        .ok_or_else(|| (v.pos, PtxErrorKind::Limit(format!("`{}`: its dimensions multiply past 2^64 bytes", v.name))))
}

/// Checks a module variable's size before anything is allocated for it: the
/// space's own bound (the constant bank, a CTA's shared memory, the largest
/// allocation) and, for `.global` variables, the host-memory budget (their
/// bytes are allocated when the module loads). `total` is what the space
/// holds with this variable. The error names the variable; its position, the line.
pub(super) fn check_var_size(v: &ast::VarDecl, size: u64, total: u64) -> LResult<()> {
    let show = limits::show_bytes;
    // a bound that is no whole number of units (32 764) is given in bytes
    let exact = |n: u64| if show(n).contains('.') { format!("{n} bytes") } else { show(n) };
    let bound = match v.space {
        Space::Const => Some((limits::MAX_CONST_BANK_BYTES, "the constant bank holds")),
        Space::Shared => Some((limits::MAX_STATIC_SHARED_BYTES, "a CTA's shared memory holds")),
        Space::Global => Some((limits::MAX_ALLOCATION_BYTES, "one allocation may hold")),
        Space::Local => Some((limits::MAX_LOCAL_BYTES, "a thread's local memory holds")),
        Space::Param => Some((limits::MAX_PARAM_BYTES, "a parameter area holds")),
        _ => None,
    };
    if let Some((max, what)) = bound
        && total > max
    {
        let with =
            if total > size { format!(" ({} with the variables before it)", show(total)) } else { String::new() };
        return Err((
            v.pos,
            PtxErrorKind::Limit(format!(
                ".{} variable `{}` is {}{with}; {what} at most {} (docs/limits.md)",
                v.space,
                v.name,
                show(size),
                exact(max)
            )),
        ));
    }
    if v.space == Space::Global {
        let what = || {
            if total > size {
                format!("the module's .global variables up to `{}`", v.name)
            } else {
                format!(".global variable `{}`", v.name)
            }
        };
        limits::check_memory(what, total).map_err(|e| (v.pos, PtxErrorKind::Limit(e.to_string())))?;
    }
    Ok(())
}

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
/// The size must have been checked ([`check_var_size`]).
pub(super) fn init_bytes(v: &ast::VarDecl) -> LResult<Vec<u8>> {
    let size = var_size(v)? as usize;
    let mut out = Vec::with_capacity(size);
    if let Some(init) = &v.init {
        let eb = v.ty.bytes() as usize;
        for l in init {
            let bits = lit_bits(*l, v.ty, v.pos)?;
            out.extend_from_slice(&bits.to_le_bytes()[..eb]);
        }
        // a zero-length array takes no element either (`t[0] = {f}`)
        if out.len() > size {
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
        let elem = v.ty.bytes() as u64 * v.vector.unwrap_or(1) as u64;
        let size = if v.dims.is_empty() { elem } else { var_size(v)?.max(elem) };
        let align = v.align.map(|a| a as u64).unwrap_or(v.ty.bytes() as u64);
        off = align_up(off, align);
        let p = Param { name: v.name.clone(), ty: v.ty, offset: off as u32, size: size as u32 };
        off = off.saturating_add(size);
        check_var_size(v, size, off)?;
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
