//! Syntax tree → validated IR, along the lines of naga's and ZLUDA's front
//! ends: this file places the module's variables (with [`layout`], which also
//! lays out signatures) and walks each function body; every instruction is decoded once into a typed
//! opcode and modifiers ([`opcode`]), its shape checked ([`validate`]), and it
//! is lowered into a [`Kind`] by the file of its family ([`data`], [`arith`],
//! [`compare`], [`convert`], [`memory`], [`control`], [`warp`]), resolving its
//! operands ([`operands`]).
//!
//! Anything it cannot decode is an error at the instruction's position. An
//! instruction warplight does not execute (valid PTX, `unsupported`) fails only
//! the function that holds it and the kernels that call that function
//! ([`Function::unsupported`]); the rest of the module loads. A module none of
//! whose kernels can run fails to load with the first such error.

use std::collections::HashMap;

use super::ast::{self, Stmt};
use super::error::{Pos, PtxError, PtxErrorKind};
use super::ir::*;
use super::types::{Space, Ty};

pub mod arith;
pub mod compare;
pub mod control;
pub mod convert;
pub mod data;
pub mod layout;
pub mod memory;
pub mod opcode;
pub mod operands;
pub mod texture;
pub mod validate;
pub mod warp;

use layout::{Signature, align_up, check_var_size, collect_shared, init_bytes, signature, var_size};
use opcode::{Decoded, Family, Opcode};

/// The name of the condition-code register of carry chains (no PTX name can
/// have a space, so it cannot collide with a declared register).
const CC_REG: &str = "%cc (carry)";

/// A lowering result: errors carry the position; the file is added by [`super::load`].
pub type LResult<T> = Result<T, (Pos, PtxErrorKind)>;

/// An `invalid` error at `pos`.
fn invalid<T>(pos: Pos, msg: impl Into<String>) -> LResult<T> {
    Err((pos, PtxErrorKind::Invalid(msg.into())))
}

/// An `unsupported` error at `pos`.
fn unsupported<T>(pos: Pos, what: impl Into<String>) -> LResult<T> {
    Err((pos, PtxErrorKind::Unsupported(what.into())))
}

#[derive(Debug, Clone, Copy)]
enum Sym {
    Reg(RegId),
    Pred(PredId),
    KernelParam(u32),
    FrameParam(u32, u32),
    Local(u32),
    Shared(u32),
    Const(u32),
    Global(u32),
    Func(u32),
}

/// Marks every function that calls an unusable one (directly or through
/// others) unusable, with the callee's error. An indirect call may reach any
/// function whose address the module takes ([`Program::callees`]), so a
/// function making one inherits the error of any unusable such function:
/// conservative, never a launch that runs into a `trap` unannounced.
fn mark_callers_unusable(prog: &mut Program) {
    let taken = prog.address_taken();
    let callees: Vec<Vec<u32>> = (0..prog.functions.len() as u32).map(|f| prog.callees(f, &taken)).collect();
    loop {
        let mut changed = false;
        for (k, calls) in callees.iter().enumerate() {
            if prog.functions[k].unsupported.is_some() {
                continue;
            }
            let inherited =
                calls.iter().find_map(|&c| prog.functions.get(c as usize).and_then(|f| f.unsupported.clone()));
            if inherited.is_some() {
                prog.functions[k].unsupported = inherited;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

/// Lowers a parsed module.
pub fn lower(m: &ast::Module, source_name: &str, src: &str) -> LResult<Program> {
    let mut prog = Program {
        source_name: source_name.to_string(),
        ptx_lines: src.lines().map(|l| l.to_string()).collect(),
        target: m.target.clone(),
        version: m.version.clone(),
        files: Vec::new(),
        functions: Vec::new(),
        globals: Vec::new(),
        const_bank: Vec::new(),
        const_vars: Vec::new(),
        shared_vars: Vec::new(),
        static_shared_size: 0,
    };
    let mut file_ids = HashMap::new();
    for (id, name) in &m.files {
        file_ids.insert(*id, prog.files.len() as u32);
        prog.files.push(name.clone());
    }
    let mut module_syms: HashMap<String, Sym> = HashMap::new();
    let mut extern_shared = Vec::new();
    let mut shared_off: u64 = 0;
    let mut place_shared = |v: &ast::VarDecl, prog: &mut Program, extern_shared: &mut Vec<String>| -> LResult<u32> {
        if v.is_extern || v.dims.iter().any(|d| d.is_none()) {
            extern_shared.push(v.name.clone());
            return Ok(u32::MAX);
        }
        let align = v.align.unwrap_or(v.ty.bytes()) as u64;
        let size = var_size(v)?;
        shared_off = align_up(shared_off, align);
        let off = shared_off;
        shared_off = off.saturating_add(size);
        check_var_size(v, size, shared_off)?;
        prog.shared_vars.push(SharedVar {
            name: v.name.clone(),
            offset: off as u32,
            size: size as u32,
            align: align as u32,
            scope: None,
        });
        Ok(off as u32)
    };
    let mut global_bytes: u64 = 0;
    // initializer elements naming a symbol: (global index or None for the
    // const bank, byte offset of the variable, element bytes, the names)
    let mut sym_inits: Vec<(Option<usize>, usize, usize, &ast::VarDecl)> = Vec::new();
    for v in &m.vars {
        match v.space {
            Space::Shared => {
                let off = place_shared(v, &mut prog, &mut extern_shared)?;
                module_syms.insert(v.name.clone(), Sym::Shared(off));
            }
            Space::Const => {
                let align = v.align.unwrap_or(v.ty.bytes()) as u64;
                let off = align_up(prog.const_bank.len() as u64, align);
                let size = var_size(v)?;
                check_var_size(v, size, off.saturating_add(size))?;
                let bytes = init_bytes(v)?;
                prog.const_bank.resize(off as usize, 0);
                prog.const_bank.extend_from_slice(&bytes);
                if !v.init_syms.is_empty() {
                    sym_inits.push((None, off as usize, v.ty.bytes() as usize, v));
                }
                prog.const_vars.push((v.name.clone(), off as u32, bytes.len() as u32));
                module_syms.insert(v.name.clone(), Sym::Const(off as u32));
            }
            Space::Global => {
                if v.is_extern {
                    return unsupported(v.pos, format!(".extern .global {}", v.name));
                }
                let size = var_size(v)?;
                global_bytes = global_bytes.saturating_add(size);
                check_var_size(v, size, global_bytes)?;
                let bytes = init_bytes(v)?;
                let idx = prog.globals.len() as u32;
                if !v.init_syms.is_empty() {
                    sym_inits.push((Some(idx as usize), 0, v.ty.bytes() as usize, v));
                }
                prog.globals.push(GlobalVar {
                    name: v.name.clone(),
                    size,
                    align: v.align.unwrap_or(v.ty.bytes()),
                    init: bytes,
                });
                module_syms.insert(v.name.clone(), Sym::Global(idx));
            }
            _ => return unsupported(v.pos, format!("module-scope .{} variable", v.space)),
        }
    }
    // Function-scope shared variables join the module layout.
    let mut fn_shared: Vec<HashMap<String, u32>> = Vec::new();
    for f in &m.functions {
        let mut map = HashMap::new();
        if let Some(body) = &f.body {
            let mut decls = Vec::new();
            collect_shared(body, &mut decls);
            for d in decls {
                let off = place_shared(d, &mut prog, &mut extern_shared)?;
                map.insert(d.name.clone(), off);
            }
        }
        fn_shared.push(map);
    }
    prog.static_shared_size = shared_off as u32;
    let dyn_base = align_up(shared_off, 16) as u32;
    for name in &extern_shared {
        prog.shared_vars.push(SharedVar { name: name.clone(), offset: dyn_base, size: 0, align: 16, scope: None });
    }
    let fix_extern = |off: u32| if off == u32::MAX { dyn_base } else { off };
    for s in module_syms.values_mut() {
        if let Sym::Shared(o) = s {
            *o = fix_extern(*o);
        }
    }
    for map in &mut fn_shared {
        for o in map.values_mut() {
            *o = fix_extern(*o);
        }
    }

    // Signatures. A declaration followed by a definition keeps the definition.
    let mut fn_index: Vec<usize> = Vec::new(); // ast function -> program function
    let mut by_name: HashMap<String, usize> = HashMap::new();
    let mut defs: Vec<&ast::Function> = Vec::new();
    for f in &m.functions {
        match by_name.get(&f.name) {
            Some(&i) => {
                if f.body.is_some() {
                    if defs[i].body.is_some() {
                        return invalid(f.pos, format!("function `{}` defined twice", f.name));
                    }
                    defs[i] = f;
                }
                fn_index.push(i);
            }
            None => {
                by_name.insert(f.name.clone(), defs.len());
                fn_index.push(defs.len());
                defs.push(f);
            }
        }
    }
    for (name, &i) in &by_name {
        module_syms.insert(name.clone(), Sym::Func(i as u32));
    }
    // function addresses in initializers (tables of function pointers, vtables)
    for (global, off, eb, v) in sym_inits {
        for (k, name) in &v.init_syms {
            let Some(&f) = by_name.get(name) else {
                return unsupported(
                    v.pos,
                    format!("initializer of `{}` naming `{name}`, which is not a function", v.name),
                );
            };
            if eb != 8 {
                return invalid(v.pos, format!("function address `{name}` in a {eb}-byte element of `{}`", v.name));
            }
            let bytes = func_addr(f as u32).to_le_bytes();
            let at = off + k * eb;
            let dst = match global {
                Some(g) => &mut prog.globals[g].init,
                None => &mut prog.const_bank,
            };
            // init_bytes refused initializers longer than the variable; checked again, never indexed blindly
            let Some(slot) = dst.get_mut(at..at + 8) else {
                return invalid(v.pos, format!("function address `{name}` past the end of `{}`", v.name));
            };
            slot.copy_from_slice(&bytes);
        }
    }
    // function-scope variables belong to the function (its definition) that declares them
    for (a, map) in fn_shared.iter().enumerate() {
        for v in prog.shared_vars.iter_mut().filter(|v| v.size > 0 && map.values().any(|&o| o == v.offset)) {
            v.scope = Some(fn_index[a] as u32);
        }
    }
    let sigs: Vec<Signature> = defs.iter().map(|f| signature(f)).collect::<LResult<_>>()?;
    // the first unsupported instruction or declaration of each function
    let mut own_errors: Vec<Option<(Pos, PtxErrorKind)>> = Vec::new();

    for (k, f) in defs.iter().enumerate() {
        let shared = fn_index
            .iter()
            .enumerate()
            .filter(|(_, i)| **i == k)
            .flat_map(|(a, _)| fn_shared[a].iter().map(|(n, o)| (n.clone(), *o)))
            .collect::<HashMap<_, _>>();
        let new = |shared| FnLower::new(f, &sigs, k, &module_syms, shared, &file_ids);
        let (lowered, own) = match new(shared.clone()).run() {
            Ok(r) => r,
            // a declaration warplight cannot place (the body is not lowered): a `trap` stands for it
            Err((pos, kind @ PtxErrorKind::Unsupported(_))) => (new(shared).stub(pos), Some((pos, kind))),
            Err(e) => return Err(e),
        };
        own_errors.push(own);
        prog.functions.push(lowered);
    }
    let wrap = |(pos, kind): &(Pos, PtxErrorKind)| PtxError::at(source_name, src, *pos, kind.clone());
    for (f, e) in prog.functions.iter_mut().zip(&own_errors) {
        f.unsupported = e.as_ref().map(wrap);
    }
    mark_callers_unusable(&mut prog);
    // nothing in the module can run: fail as a whole, with the first error
    let usable = prog.functions.iter().any(|f| f.is_entry && f.unsupported.is_none());
    if !usable && let Some(first) = own_errors.into_iter().flatten().next() {
        return Err(first);
    }
    Ok(prog)
}

struct FnLower<'a> {
    f: &'a ast::Function,
    sigs: &'a [Signature],
    me: usize,
    module: &'a HashMap<String, Sym>,
    scopes: Vec<HashMap<String, Sym>>,
    file_ids: &'a HashMap<u32, u32>,
    out: Function,
    labels: HashMap<String, u32>,
    fixups: Vec<(usize, String, Pos)>,
    loc: Option<SrcLoc>,
    frame_param: u64,
    local: u64,
    /// Offsets of the shared variables this function names (for per-kernel occupancy).
    shared_refs: std::cell::RefCell<std::collections::BTreeSet<u32>>,
    /// The first instruction of the body warplight does not execute.
    unsupported: Option<(Pos, PtxErrorKind)>,
}

impl<'a> FnLower<'a> {
    fn new(
        f: &'a ast::Function,
        sigs: &'a [Signature],
        me: usize,
        module: &'a HashMap<String, Sym>,
        shared: HashMap<String, u32>,
        file_ids: &'a HashMap<u32, u32>,
    ) -> Self {
        let sig = &sigs[me];
        let mut top = HashMap::new();
        for (n, o) in shared {
            top.insert(n, Sym::Shared(o));
        }
        let mut frame_param = 0u64;
        let mut kernel_param_size = 0u32;
        for p in sig.params.iter() {
            if sig.is_entry {
                top.insert(p.name.clone(), Sym::KernelParam(p.offset));
                kernel_param_size = kernel_param_size.max(p.offset + p.size);
            } else {
                top.insert(p.name.clone(), Sym::FrameParam(p.offset, p.size));
            }
        }
        for p in &sig.returns {
            top.insert(p.name.clone(), Sym::FrameParam(p.offset, p.size));
        }
        if !sig.is_entry {
            frame_param = sig.param_area as u64;
        }
        let out = Function {
            name: f.name.clone(),
            is_entry: sig.is_entry,
            params: sig.params.clone(),
            returns: sig.returns.clone(),
            frame_param_size: 0,
            kernel_param_size,
            local_size: 0,
            local_align: 16,
            reg_masks: Vec::new(),
            reg_names: Vec::new(),
            num_preds: 2,
            pred_names: vec!["false".into(), "true".into()],
            insts: Vec::new(),
            info: Vec::new(),
            labels: Vec::new(),
            declared_reg_words: 0,
            shared_refs: Vec::new(),
            shared_symbols: Vec::new(),
            unsupported: None,
        };
        FnLower {
            f,
            sigs,
            me,
            module,
            scopes: vec![top],
            file_ids,
            out,
            labels: HashMap::new(),
            fixups: Vec::new(),
            loc: None,
            frame_param,
            local: 0,
            shared_refs: Default::default(),
            unsupported: None,
        }
    }

    /// Lowers the body; also returns the first unsupported instruction, which
    /// the body holds as a `trap` in its place.
    fn run(mut self) -> LResult<(Function, Option<(Pos, PtxErrorKind)>)> {
        if let Some(body) = &self.f.body {
            self.block(body)?;
            let needs_ret = !matches!(
                self.out.insts.last(),
                Some(Inst { guard: None, kind: Kind::Ret | Kind::Exit | Kind::Bra { .. } })
            ) || self.labels.values().any(|&i| i as usize == self.out.insts.len());
            if needs_ret {
                // Falling off the end of a body returns; for a kernel that is an
                // exit of the thread, as on the GPU.
                let pos = self.f.pos;
                let kind = if self.sigs[self.me].is_entry { Kind::Exit } else { Kind::Ret };
                self.emit(kind, None, pos, "ret".into(), InstClass::Control);
            }
        }
        for (idx, label, pos) in std::mem::take(&mut self.fixups) {
            let Some(&t) = self.labels.get(&label) else {
                return invalid(pos, format!("undefined label `{label}`"));
            };
            if let Kind::Bra { target, .. } = &mut self.out.insts[idx].kind {
                *target = t;
            }
        }
        let mut labels: Vec<_> = self.labels.into_iter().collect();
        labels.sort_by_key(|(_, i)| *i);
        self.out.labels = labels;
        self.out.frame_param_size = align_up(self.frame_param, 8) as u32;
        self.out.local_size = align_up(self.local, 16) as u32;
        self.out.shared_refs = self.shared_refs.take().into_iter().collect();
        Ok((self.out, self.unsupported))
    }

    /// The function with a body of one `trap` at `pos`: what stands for a
    /// function whose body cannot be lowered.
    fn stub(mut self, pos: Pos) -> Function {
        self.emit(Kind::Trap, None, pos, "trap".into(), InstClass::Control);
        self.out.frame_param_size = align_up(self.frame_param, 8) as u32;
        self.out
    }

    fn lookup(&self, name: &str) -> Option<Sym> {
        let sym = self.scopes.iter().rev().find_map(|s| s.get(name)).or_else(|| self.module.get(name)).copied();
        if let Some(Sym::Shared(o)) = sym {
            self.shared_refs.borrow_mut().insert(o);
        }
        sym
    }

    fn declare(&mut self, name: String, sym: Sym) {
        self.scopes.last_mut().expect("scope").insert(name, sym);
    }

    fn block(&mut self, body: &[Stmt]) -> LResult<()> {
        // Labels are function-wide: collect this block's first so forward branches resolve.
        for s in body {
            match s {
                Stmt::Decl(d) => self.decl(d)?,
                Stmt::Label(name, pos) => {
                    if self.labels.insert(name.clone(), self.out.insts.len() as u32).is_some() {
                        return invalid(*pos, format!("label `{name}` defined twice"));
                    }
                }
                Stmt::Loc { file, line, col } => {
                    self.loc = self.file_ids.get(file).map(|&f| SrcLoc { file: f, line: *line, col: *col });
                }
                Stmt::Inst(i) => match self.inst(i) {
                    Err((pos, kind @ PtxErrorKind::Unsupported(_))) => {
                        // the function cannot run; the rest of its body is still checked
                        self.unsupported.get_or_insert((pos, kind));
                        self.emit(Kind::Trap, None, pos, i.full_opcode(), InstClass::Control);
                    }
                    r => r?,
                },
                Stmt::Block(b) => {
                    self.scopes.push(HashMap::new());
                    self.block(b)?;
                    self.scopes.pop();
                }
            }
        }
        Ok(())
    }

    fn decl(&mut self, d: &ast::VarDecl) -> LResult<()> {
        match d.space {
            Space::Reg => {
                if d.vector.is_some() || !d.dims.is_empty() {
                    return unsupported(d.pos, "vector or array registers");
                }
                // the count is checked before any name is made (`.reg .b32 %r<4294967295>`)
                if let Some(n) = d.range {
                    let (have, cap) = if d.ty == Ty::Pred {
                        (self.out.num_preds as usize, u16::MAX as usize)
                    } else {
                        (self.out.reg_masks.len(), Dst::SINK as usize)
                    };
                    if n as usize > cap.saturating_sub(have) {
                        return invalid(
                            d.pos,
                            format!("`{}<{n}>`: more registers than a function can have ({cap} in all)", d.name),
                        );
                    }
                }
                let names: Vec<String> = match d.range {
                    Some(n) => (0..n).map(|i| format!("{}{i}", d.name)).collect(),
                    None => vec![d.name.clone()],
                };
                for n in names {
                    if d.ty == Ty::Pred {
                        let id = self.out.num_preds;
                        if id == u16::MAX {
                            return invalid(d.pos, "too many predicate registers");
                        }
                        self.out.num_preds += 1;
                        self.out.pred_names.push(n.clone());
                        self.declare(n, Sym::Pred(id));
                    } else {
                        let id = self.out.reg_masks.len();
                        if id >= Dst::SINK as usize {
                            return invalid(d.pos, "too many registers");
                        }
                        self.out.reg_masks.push(d.ty.mask());
                        self.out.reg_names.push(n.clone());
                        self.out.declared_reg_words += if d.ty.bits() > 32 { 2 } else { 1 };
                        self.declare(n, Sym::Reg(id as RegId));
                    }
                }
            }
            Space::Local => {
                let align = d.align.unwrap_or(d.ty.bytes()) as u64;
                let size = var_size(d)?;
                self.local = align_up(self.local, align);
                let off = self.local;
                self.local = off.saturating_add(size);
                // bounded so that the frame size (and each offset) fits its u32
                check_var_size(d, size, align_up(self.local, 16))?;
                self.out.local_align = self.out.local_align.max(align as u32);
                self.declare(d.name.clone(), Sym::Local(off as u32));
            }
            Space::Param => {
                let align = d.align.unwrap_or(d.ty.bytes()) as u64;
                self.frame_param = align_up(self.frame_param, align);
                let off = self.frame_param;
                let size =
                    if d.dims.is_empty() { d.ty.bytes() as u64 * d.vector.unwrap_or(1) as u64 } else { var_size(d)? };
                self.frame_param = off.saturating_add(size);
                check_var_size(d, size, self.frame_param)?;
                self.declare(d.name.clone(), Sym::FrameParam(off as u32, size as u32));
            }
            Space::Shared => {} // placed with the module
            _ => return unsupported(d.pos, format!(".{} variable inside a function", d.space)),
        }
        Ok(())
    }

    /// The register that holds the condition code of carry chains (`CC.CF`,
    /// 0 or 1), added on first use; PTX declares no register for it.
    fn cc_reg(&mut self) -> RegId {
        if let Some(r) = self.out.reg_names.iter().position(|n| n == CC_REG) {
            return r as RegId;
        }
        self.out.reg_masks.push(1);
        self.out.reg_names.push(CC_REG.into());
        (self.out.reg_masks.len() - 1) as RegId
    }

    fn emit(&mut self, kind: Kind, guard: Option<PredSrc>, pos: Pos, opcode: String, class: InstClass) {
        self.out.insts.push(Inst { guard, kind });
        self.out.info.push(InstInfo { ptx_line: pos.line, ptx_col: pos.col, src: self.loc, opcode, class });
    }

    fn inst(&mut self, i: &ast::Instruction) -> LResult<()> {
        let pos = i.pos;
        let guard = match &i.guard {
            None => None,
            Some((neg, n)) => Some(PredSrc { reg: self.pred_named(n, pos)?, neg: *neg }),
        };
        let Some(d) = Decoded::of(i) else {
            return unsupported(pos, i.full_opcode());
        };
        validate::validate(&d, i)?;
        let kind = match (d.family(), d.op) {
            (Family::Data, _) => self.lower_mov(i, &d)?,
            (Family::Arith, Opcode::Bfi) => self.lower_bfi(i, &d)?,
            (Family::Arith, Opcode::Addc | Opcode::Subc | Opcode::Madc) => self.lower_carry(i, &d)?,
            (Family::Arith, _) if d.mods.has("cc") => self.lower_carry(i, &d)?,
            (Family::Arith, _) => self.lower_arith(i, &d)?,
            (Family::Compare, Opcode::Setp | Opcode::Set) => self.lower_setp(i, &d)?,
            (Family::Compare, Opcode::Selp) => self.lower_selp(i, &d)?,
            (Family::Compare, _) => self.lower_pred_logic(i, &d)?,
            (Family::Convert, Opcode::Cvt) => self.lower_cvt(i, &d)?,
            (Family::Convert, _) => self.lower_cvta(i, &d)?,
            (Family::Memory, Opcode::Atom | Opcode::Red) => self.lower_atom(i, &d)?,
            (Family::Memory, _) => self.lower_ld_st(i, &d)?,
            (Family::Control, _) => self.lower_control(i, &d)?,
            (Family::Warp, Opcode::Vote) => self.lower_vote(i, &d)?,
            (Family::Warp, Opcode::Activemask) => self.lower_activemask(i)?,
            (Family::Warp, Opcode::Redux) => self.lower_redux(i, &d)?,
            (Family::Warp, Opcode::Match) => self.lower_match(i, &d)?,
            (Family::Warp, _) => self.lower_shfl(i, &d)?,
            (Family::Texture, _) => self.lower_texture(i, &d)?,
        };
        // a shared variable's name as the moved value or the address base
        let names_shared = |o: &ast::Operand| match o {
            ast::Operand::Name(n) | ast::Operand::Offset(n, _) | ast::Operand::Addr(Some(n), _) => {
                matches!(self.lookup(n), Some(Sym::Shared(_)))
            }
            _ => false,
        };
        let symbol = match &kind {
            Kind::Mov { .. } | Kind::Cvta { .. } => i.operands.get(1).is_some_and(names_shared),
            Kind::Ld { .. } | Kind::St { .. } | Kind::Atom { .. } => {
                i.operands.iter().any(|o| matches!(o, ast::Operand::Addr(..)) && names_shared(o))
            }
            _ => false,
        };
        if symbol {
            self.out.shared_symbols.push(self.out.insts.len() as u32);
        }
        let class = d.op.class();
        self.emit(kind, guard, pos, d.full, class);
        Ok(())
    }
}
