//! Syntax tree → validated IR: resolves names, lays out variables and
//! parameters, checks operands and types, and decodes every instruction into
//! [`Kind`]. Anything it cannot decode is an error at the instruction's position.

use std::collections::HashMap;

use super::ast::{self, Literal, Operand, Stmt};
use super::error::{Pos, PtxErrorKind};
use super::ir::*;
use super::types::{Space, Ty};

type LResult<T> = Result<T, (Pos, PtxErrorKind)>;

fn invalid<T>(pos: Pos, msg: impl Into<String>) -> LResult<T> {
    Err((pos, PtxErrorKind::Invalid(msg.into())))
}

fn unsupported<T>(pos: Pos, what: impl Into<String>) -> LResult<T> {
    Err((pos, PtxErrorKind::Unsupported(what.into())))
}

fn align_up(v: u64, a: u64) -> u64 {
    let a = a.max(1);
    v.div_ceil(a) * a
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
        shared_off = align_up(shared_off, align);
        let off = shared_off;
        shared_off += v.size_bytes();
        if shared_off > u32::MAX as u64 {
            return invalid(v.pos, "shared memory too large");
        }
        prog.shared_vars.push(SharedVar {
            name: v.name.clone(),
            offset: off as u32,
            size: v.size_bytes() as u32,
            align: align as u32,
        });
        Ok(off as u32)
    };
    for v in &m.vars {
        match v.space {
            Space::Shared => {
                let off = place_shared(v, &mut prog, &mut extern_shared)?;
                module_syms.insert(v.name.clone(), Sym::Shared(off));
            }
            Space::Const => {
                let align = v.align.unwrap_or(v.ty.bytes()) as u64;
                let off = align_up(prog.const_bank.len() as u64, align);
                let bytes = init_bytes(v)?;
                prog.const_bank.resize(off as usize, 0);
                prog.const_bank.extend_from_slice(&bytes);
                prog.const_vars.push((v.name.clone(), off as u32, bytes.len() as u32));
                module_syms.insert(v.name.clone(), Sym::Const(off as u32));
            }
            Space::Global => {
                if v.is_extern {
                    return unsupported(v.pos, format!(".extern .global {}", v.name));
                }
                let bytes = init_bytes(v)?;
                let idx = prog.globals.len() as u32;
                prog.globals.push(GlobalVar {
                    name: v.name.clone(),
                    size: v.size_bytes(),
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
        prog.shared_vars.push(SharedVar { name: name.clone(), offset: dyn_base, size: 0, align: 16 });
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
    let sigs: Vec<Signature> = defs.iter().map(|f| signature(f)).collect::<LResult<_>>()?;

    for (k, f) in defs.iter().enumerate() {
        let shared = fn_index
            .iter()
            .enumerate()
            .filter(|(_, i)| **i == k)
            .flat_map(|(a, _)| fn_shared[a].iter().map(|(n, o)| (n.clone(), *o)))
            .collect::<HashMap<_, _>>();
        let lowered = FnLower::new(f, &sigs, k, &module_syms, shared, &file_ids).run()?;
        prog.functions.push(lowered);
    }
    Ok(prog)
}

fn collect_shared<'a>(body: &'a [Stmt], out: &mut Vec<&'a ast::VarDecl>) {
    for s in body {
        match s {
            Stmt::Decl(d) if d.space == Space::Shared => out.push(d),
            Stmt::Block(b) => collect_shared(b, out),
            _ => {}
        }
    }
}

fn lit_bits(l: Literal, ty: Ty, pos: Pos) -> LResult<u64> {
    Ok(match (l, ty) {
        (Literal::Int(v), Ty::F32) => ((v as i64) as f32).to_bits() as u64,
        (Literal::Int(v), Ty::F64) => ((v as i64) as f64).to_bits(),
        (Literal::Int(v), t) => v & t.mask(),
        (Literal::F32(b), Ty::F64) => (f32::from_bits(b) as f64).to_bits(),
        (Literal::F32(b), t) => b as u64 & t.mask(),
        (Literal::F64(b), Ty::F32) => (f64::from_bits(b) as f32).to_bits() as u64,
        (Literal::F64(b), t) => b & t.mask(),
        (Literal::Float(x), Ty::F32) => (x as f32).to_bits() as u64,
        (Literal::Float(x), Ty::F64) => x.to_bits(),
        (Literal::Float(_), t) => return invalid(pos, format!("float literal used as .{t}")),
    })
}

fn init_bytes(v: &ast::VarDecl) -> LResult<Vec<u8>> {
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

#[derive(Debug, Clone)]
struct Signature {
    is_entry: bool,
    has_body: bool,
    name: String,
    params: Vec<Param>,
    returns: Vec<Param>,
    param_area: u32,
}

fn signature(f: &ast::Function) -> LResult<Signature> {
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
}

/// Modifier words of one instruction, sorted into kinds.
struct Mods {
    types: Vec<Ty>,
    space: Option<Space>,
    words: Vec<String>,
}

impl Mods {
    fn has(&self, w: &str) -> bool {
        self.words.iter().any(|x| x == w)
    }
    fn rounding(&self) -> Option<Rounding> {
        self.words.iter().find_map(|w| {
            Some(match w.as_str() {
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
        })
    }
    fn vec(&self) -> u32 {
        if self.has("v4") {
            4
        } else if self.has("v2") {
            2
        } else {
            1
        }
    }
    /// Fails when a word is not in `allowed`.
    fn only(&self, allowed: &[&str], pos: Pos, op: &str) -> LResult<()> {
        for w in &self.words {
            if !allowed.contains(&w.as_str()) {
                return unsupported(pos, format!("{op} (modifier .{w})"));
            }
        }
        Ok(())
    }
}

const ROUNDINGS: &[&str] = &["rn", "rz", "rm", "rp", "rni", "rzi", "rmi", "rpi"];

fn cmp_of(w: &str) -> Option<Cmp> {
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

fn bool_of(w: &str) -> Option<BoolOp> {
    Some(match w {
        "and" => BoolOp::And,
        "or" => BoolOp::Or,
        "xor" => BoolOp::Xor,
        _ => return None,
    })
}

fn special_reg(name: &str) -> Option<SpecialReg> {
    let dim = |c: &str| match c {
        "x" => Some(0u8),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    };
    if let Some((base, comp)) = name.split_once('.') {
        let d = dim(comp)?;
        return Some(match base {
            "%tid" => SpecialReg::Tid(d),
            "%ntid" => SpecialReg::Ntid(d),
            "%ctaid" => SpecialReg::Ctaid(d),
            "%nctaid" => SpecialReg::Nctaid(d),
            _ => return None,
        });
    }
    Some(match name {
        "%laneid" => SpecialReg::LaneId,
        "%warpid" => SpecialReg::WarpId,
        "%nwarpid" => SpecialReg::NWarpId,
        "%smid" => SpecialReg::SmId,
        "%nsmid" => SpecialReg::NSmId,
        "%gridid" => SpecialReg::GridId,
        "%lanemask_eq" => SpecialReg::LaneMaskEq,
        "%lanemask_le" => SpecialReg::LaneMaskLe,
        "%lanemask_lt" => SpecialReg::LaneMaskLt,
        "%lanemask_ge" => SpecialReg::LaneMaskGe,
        "%lanemask_gt" => SpecialReg::LaneMaskGt,
        "%clock" => SpecialReg::Clock,
        "%clock64" => SpecialReg::Clock64,
        _ => return None,
    })
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
        }
    }

    fn run(mut self) -> LResult<Function> {
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
        Ok(self.out)
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
                Stmt::Inst(i) => self.inst(i)?,
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
                self.local = align_up(self.local, align);
                let off = self.local;
                self.local += d.size_bytes();
                self.out.local_align = self.out.local_align.max(align as u32);
                self.declare(d.name.clone(), Sym::Local(off as u32));
            }
            Space::Param => {
                let align = d.align.unwrap_or(d.ty.bytes()) as u64;
                self.frame_param = align_up(self.frame_param, align);
                let off = self.frame_param;
                let size =
                    if d.dims.is_empty() { d.ty.bytes() as u64 * d.vector.unwrap_or(1) as u64 } else { d.size_bytes() };
                self.frame_param += size;
                self.declare(d.name.clone(), Sym::FrameParam(off as u32, size as u32));
            }
            Space::Shared => {} // placed with the module
            _ => return unsupported(d.pos, format!(".{} variable inside a function", d.space)),
        }
        Ok(())
    }

    fn emit(&mut self, kind: Kind, guard: Option<PredSrc>, pos: Pos, opcode: String, class: InstClass) {
        self.out.insts.push(Inst { guard, kind });
        self.out.info.push(InstInfo { ptx_line: pos.line, ptx_col: pos.col, src: self.loc, opcode, class });
    }

    fn dst(&self, op: &Operand, pos: Pos) -> LResult<Dst> {
        match op {
            Operand::Name(n) if n == "_" => Ok(Dst { reg: Dst::SINK, mask: u64::MAX }),
            Operand::Name(n) => match self.lookup(n) {
                Some(Sym::Reg(id)) => Ok(Dst { reg: id, mask: self.out.reg_masks[id as usize] }),
                Some(_) => invalid(pos, format!("`{n}` is not a data register")),
                None => invalid(pos, format!("undeclared register `{n}`")),
            },
            _ => invalid(pos, "destination must be a register"),
        }
    }

    fn pred_dst(&self, op: &Operand, pos: Pos) -> LResult<PredId> {
        match op {
            Operand::Name(n) if n == "_" => Ok(PRED_FALSE),
            Operand::Name(n) => match self.lookup(n) {
                Some(Sym::Pred(id)) => Ok(id),
                Some(_) => invalid(pos, format!("`{n}` is not a predicate register")),
                None => invalid(pos, format!("undeclared predicate `{n}`")),
            },
            _ => invalid(pos, "destination must be a predicate register"),
        }
    }

    fn pred_src(&self, op: &Operand, pos: Pos) -> LResult<PredSrc> {
        match op {
            Operand::Not(n) => Ok(PredSrc { reg: self.pred_dst(&Operand::Name(n.clone()), pos)?, neg: true }),
            Operand::Name(_) => Ok(PredSrc { reg: self.pred_dst(op, pos)?, neg: false }),
            Operand::Lit(Literal::Int(v)) => {
                Ok(PredSrc { reg: if *v != 0 { PRED_TRUE } else { PRED_FALSE }, neg: false })
            }
            _ => invalid(pos, "expected a predicate"),
        }
    }

    fn src(&self, op: &Operand, ty: Ty, pos: Pos) -> LResult<Src> {
        match op {
            Operand::Lit(l) => Ok(Src::Imm(lit_bits(*l, ty, pos)?)),
            Operand::Name(n) => match self.lookup(n) {
                Some(Sym::Reg(id)) => Ok(Src::Reg(id)),
                Some(Sym::Shared(o))
                | Some(Sym::Const(o))
                | Some(Sym::KernelParam(o))
                | Some(Sym::FrameParam(o, _)) => Ok(Src::Imm(o as u64)),
                Some(Sym::Local(o)) => Ok(Src::LocalAddr(o)),
                Some(Sym::Global(g)) => Ok(Src::GlobalAddr(g, 0)),
                Some(Sym::Pred(_)) => invalid(pos, format!("predicate `{n}` used as a value")),
                Some(Sym::Func(_)) => unsupported(pos, format!("address of function `{n}`")),
                None => match special_reg(n) {
                    Some(s) => Ok(Src::Special(s)),
                    // PTX's predefined constant (nvcc writes it for `warpSize`)
                    None if n == "WARP_SZ" => Ok(Src::Imm(32)),
                    None if n.starts_with('%') => invalid(pos, format!("undeclared register `{n}`")),
                    None => invalid(pos, format!("undeclared name `{n}`")),
                },
            },
            Operand::Not(_) => invalid(pos, "`!` applies to predicates only"),
            _ => invalid(pos, "expected a register or literal"),
        }
    }

    /// An address operand and the space its symbol lives in (if a symbol).
    fn address(&self, op: &Operand, pos: Pos) -> LResult<(Address, Option<MemSpace>)> {
        let Operand::Addr(base, off) = op else {
            return invalid(pos, "expected an address `[...]`");
        };
        let Some(name) = base else {
            return Ok((Address { base: Src::Imm(0), offset: *off, wide: true }, None));
        };
        let (b, space) = match self.lookup(name) {
            Some(Sym::Reg(id)) => (Src::Reg(id), None),
            Some(Sym::Shared(o)) => (Src::Imm(o as u64), Some(MemSpace::Shared)),
            Some(Sym::Const(o)) => (Src::Imm(o as u64), Some(MemSpace::Const)),
            Some(Sym::KernelParam(o)) => (Src::Imm(o as u64), Some(MemSpace::KernelParam)),
            Some(Sym::FrameParam(o, _)) => (Src::Imm(o as u64), Some(MemSpace::FrameParam)),
            Some(Sym::Local(o)) => (Src::LocalAddr(o), Some(MemSpace::Local)),
            Some(Sym::Global(g)) => (Src::GlobalAddr(g, 0), Some(MemSpace::Global)),
            Some(Sym::Pred(_)) | Some(Sym::Func(_)) => {
                return invalid(pos, format!("`{name}` is not an address"));
            }
            None => return invalid(pos, format!("undeclared name `{name}`")),
        };
        // a 32-bit register base is added to the offset in 32 bits (nvcc's `[%r4+68]` with
        // %r4 = 0xFFFFFFC0 addresses 4), then widened
        let wide = match b {
            Src::Reg(id) => self.out.reg_masks.get(id as usize).is_none_or(|m| *m > u32::MAX as u64),
            _ => true,
        };
        Ok((Address { base: b, offset: *off, wide }, space))
    }

    fn mods(&self, i: &ast::Instruction) -> Mods {
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

    fn operands(&self, i: &ast::Instruction, n: usize) -> LResult<()> {
        if i.operands.len() != n {
            return invalid(i.pos, format!("`{}` takes {n} operands, found {}", i.full_opcode(), i.operands.len()));
        }
        Ok(())
    }

    fn one_type(&self, i: &ast::Instruction, m: &Mods) -> LResult<Ty> {
        match m.types.as_slice() {
            [t] => Ok(*t),
            [] => invalid(i.pos, format!("`{}` needs a type", i.full_opcode())),
            _ => invalid(i.pos, format!("`{}` has more than one type", i.full_opcode())),
        }
    }

    fn mem_space(&self, m: &Mods, sym_space: Option<MemSpace>, pos: Pos) -> LResult<MemSpace> {
        let declared = match m.space {
            None => MemSpace::Generic,
            Some(Space::Global) => MemSpace::Global,
            Some(Space::Shared) => MemSpace::Shared,
            Some(Space::Local) => MemSpace::Local,
            Some(Space::Const) => MemSpace::Const,
            Some(Space::Param) => {
                if self.sigs[self.me].is_entry {
                    MemSpace::KernelParam
                } else {
                    MemSpace::FrameParam
                }
            }
            Some(s) => return unsupported(pos, format!("state space .{s}")),
        };
        Ok(match (declared, sym_space) {
            (MemSpace::KernelParam, Some(MemSpace::FrameParam)) => MemSpace::FrameParam,
            (MemSpace::Generic, Some(s)) => s,
            (d, Some(s)) if d != s && !(d == MemSpace::FrameParam && s == MemSpace::KernelParam) => {
                return invalid(pos, format!("symbol of the {s:?} space used with a {d:?} access"));
            }
            (d, _) => d,
        })
    }

    fn inst(&mut self, i: &ast::Instruction) -> LResult<()> {
        let pos = i.pos;
        let guard = match &i.guard {
            None => None,
            Some((neg, n)) => Some(PredSrc { reg: self.pred_dst(&Operand::Name(n.clone()), pos)?, neg: *neg }),
        };
        let m = self.mods(i);
        let full = i.full_opcode();
        let ops = &i.operands;
        let op = i.opcode.as_str();
        let class = match op {
            "ld" | "st" | "atom" | "red" => InstClass::Memory,
            "bra" | "call" | "ret" | "exit" | "bar" | "barrier" | "membar" | "fence" | "trap" => InstClass::Control,
            "vote" | "shfl" | "activemask" => InstClass::Warp,
            "sqrt" | "rsqrt" | "rcp" | "sin" | "cos" | "ex2" | "lg2" => InstClass::Sfu,
            _ => InstClass::Alu,
        };
        let kind = match op {
            "mov" => {
                self.operands(i, 2)?;
                m.only(&[], pos, &full)?;
                let t = self.one_type(i, &m)?;
                if t == Ty::Pred {
                    Kind::PredLogic {
                        op: None,
                        d: self.pred_dst(&ops[0], pos)?,
                        a: self.pred_src(&ops[1], pos)?,
                        b: PredSrc { reg: PRED_FALSE, neg: false },
                    }
                } else if let Operand::Vector(parts) = &ops[1] {
                    let part_bits = t.bits() / parts.len() as u32;
                    let pt = part_ty(part_bits, pos)?;
                    let parts = parts.iter().map(|p| self.src(p, pt, pos)).collect::<LResult<Vec<_>>>()?;
                    Kind::Pack { d: self.dst(&ops[0], pos)?, parts, part_bits }
                } else if let Operand::Vector(ds) = &ops[0] {
                    let part_bits = t.bits() / ds.len() as u32;
                    part_ty(part_bits, pos)?;
                    let ds = ds.iter().map(|d| self.dst(d, pos)).collect::<LResult<Vec<_>>>()?;
                    Kind::Unpack { ds, a: self.src(&ops[1], t, pos)?, part_bits }
                } else {
                    Kind::Mov { d: self.dst(&ops[0], pos)?, a: self.src(&ops[1], t, pos)? }
                }
            }
            "and" | "or" | "xor" | "not" | "cnot" if m.types.first() == Some(&Ty::Pred) => {
                let bop = bool_of(op);
                let n = if op == "not" || op == "cnot" { 2 } else { 3 };
                self.operands(i, n)?;
                let d = self.pred_dst(&ops[0], pos)?;
                let mut a = self.pred_src(&ops[1], pos)?;
                let b = if n == 3 { self.pred_src(&ops[2], pos)? } else { PredSrc { reg: PRED_FALSE, neg: false } };
                if op == "not" {
                    a.neg = !a.neg;
                }
                Kind::PredLogic { op: bop, d, a, b }
            }
            "add" | "sub" | "mul" | "mad" | "fma" | "mul24" | "mad24" | "div" | "rem" | "abs" | "neg" | "min"
            | "max" | "and" | "or" | "xor" | "not" | "cnot" | "shl" | "shr" | "shf" | "popc" | "clz" | "brev"
            | "bfe" | "prmt" | "sqrt" | "rsqrt" | "rcp" | "sin" | "cos" | "ex2" | "lg2" | "copysign" => {
                self.arith(i, &m, &full)?
            }
            "bfi" => {
                self.operands(i, 5)?;
                m.only(&[], pos, &full)?;
                let t = self.one_type(i, &m)?;
                Kind::Bfi {
                    ty: t,
                    d: self.dst(&ops[0], pos)?,
                    a: self.src(&ops[1], t, pos)?,
                    b: self.src(&ops[2], t, pos)?,
                    c: self.src(&ops[3], Ty::U32, pos)?,
                    e: self.src(&ops[4], Ty::U32, pos)?,
                }
            }
            "setp" | "set" => {
                let mut cmp = None;
                let mut comb = None;
                let mut ftz = false;
                for w in &m.words {
                    if let Some(c) = cmp_of(w).filter(|_| cmp.is_none()) {
                        cmp = Some(c);
                    } else if let Some(b) = bool_of(w) {
                        comb = Some(b);
                    } else if w == "ftz" {
                        ftz = true;
                    } else {
                        return unsupported(pos, format!("{full} (modifier .{w})"));
                    }
                }
                let Some(cmp) = cmp else {
                    return invalid(pos, format!("`{full}` needs a comparison"));
                };
                let n = if comb.is_some() { 4 } else { 3 };
                self.operands(i, n)?;
                let (sty, dty) = if op == "setp" {
                    (self.one_type(i, &m)?, Ty::Pred)
                } else {
                    match m.types.as_slice() {
                        [d, s] => (*s, *d),
                        _ => return invalid(pos, "`set` needs a destination and a source type"),
                    }
                };
                let comb = match comb {
                    Some(b) => Some((b, self.pred_src(&ops[3], pos)?)),
                    None => None,
                };
                let a = self.src(&ops[1], sty, pos)?;
                let b = self.src(&ops[2], sty, pos)?;
                if op == "setp" {
                    let (p, q) = match &ops[0] {
                        Operand::Pair(p, q) => (
                            self.pred_dst(&Operand::Name(p.clone()), pos)?,
                            Some(self.pred_dst(&Operand::Name(q.clone()), pos)?),
                        ),
                        o => (self.pred_dst(o, pos)?, None),
                    };
                    Kind::Setp { cmp, ty: sty, p, q, a, b, comb, ftz }
                } else {
                    Kind::Set { cmp, dty, sty, d: self.dst(&ops[0], pos)?, a, b, comb, ftz }
                }
            }
            "selp" => {
                self.operands(i, 4)?;
                m.only(&[], pos, &full)?;
                let t = self.one_type(i, &m)?;
                Kind::Selp {
                    d: self.dst(&ops[0], pos)?,
                    a: self.src(&ops[1], t, pos)?,
                    b: self.src(&ops[2], t, pos)?,
                    p: self.pred_src(&ops[3], pos)?,
                }
            }
            "cvt" => {
                self.operands(i, 2)?;
                let mut allowed = ROUNDINGS.to_vec();
                allowed.extend(["ftz", "sat"]);
                m.only(&allowed, pos, &full)?;
                let [dty, sty] = m.types.as_slice() else {
                    return invalid(pos, "`cvt` needs a destination and a source type");
                };
                if *dty == Ty::F16 || *sty == Ty::F16 {
                    return unsupported(pos, format!("{full} (.f16)"));
                }
                let mode = FloatMode { rnd: m.rounding(), ftz: m.has("ftz"), sat: m.has("sat"), approx: false };
                if dty.is_float()
                    && sty.is_int()
                    && matches!(mode.rnd, Some(Rounding::Rni | Rounding::Rzi | Rounding::Rmi | Rounding::Rpi))
                {
                    return invalid(pos, "integer rounding modifier on an int-to-float conversion");
                }
                Kind::Cvt { dty: *dty, sty: *sty, mode, d: self.dst(&ops[0], pos)?, a: self.src(&ops[1], *sty, pos)? }
            }
            "cvta" => {
                self.operands(i, 2)?;
                let to = m.has("to");
                m.only(&["to"], pos, &full)?;
                let t = self.one_type(i, &m)?;
                let space = match m.space {
                    Some(Space::Global) => MemSpace::Global,
                    Some(Space::Shared) => MemSpace::Shared,
                    Some(Space::Local) => MemSpace::Local,
                    Some(Space::Const) => MemSpace::Const,
                    Some(Space::Param) => MemSpace::KernelParam,
                    _ => return invalid(pos, "`cvta` needs a state space"),
                };
                Kind::Cvta { to_generic: !to, space, d: self.dst(&ops[0], pos)?, a: self.src(&ops[1], t, pos)? }
            }
            "ld" | "st" => {
                self.operands(i, 2)?;
                let allowed = [
                    "v2",
                    "v4",
                    "nc",
                    "volatile",
                    "weak",
                    "relaxed",
                    "acquire",
                    "release",
                    "ca",
                    "cg",
                    "cs",
                    "lu",
                    "cv",
                    "wb",
                    "wt",
                    "cta",
                    "gpu",
                    "sys",
                    "L1::evict_normal",
                    "L1::evict_unchanged",
                    "L1::evict_first",
                    "L1::evict_last",
                    "L1::no_allocate",
                    "L2::64B",
                    "L2::128B",
                    "L2::256B",
                    "L2::evict_first",
                    "L2::evict_last",
                    "L2::evict_normal",
                ];
                m.only(&allowed, pos, &full)?;
                let t = self.one_type(i, &m)?;
                let vec = m.vec() as usize;
                let (addr_op, val_op) = if op == "ld" { (&ops[1], &ops[0]) } else { (&ops[0], &ops[1]) };
                let (addr, sym_space) = self.address(addr_op, pos)?;
                let space = self.mem_space(&m, sym_space, pos)?;
                let vals: Vec<&Operand> = match val_op {
                    Operand::Vector(v) => v.iter().collect(),
                    o => vec![o],
                };
                if vals.len() != vec {
                    return invalid(pos, format!("`{full}` moves {vec} value(s), found {}", vals.len()));
                }
                let volatile = m.has("volatile") || m.has("relaxed") || m.has("acquire") || m.has("release");
                if op == "ld" {
                    let ds = vals.iter().map(|v| self.dst(v, pos)).collect::<LResult<Vec<_>>>()?;
                    Kind::Ld { space, ty: t, ds, addr, nc: m.has("nc"), volatile }
                } else {
                    let vs = vals.iter().map(|v| self.src(v, t, pos)).collect::<LResult<Vec<_>>>()?;
                    Kind::St { space, ty: t, vals: vs, addr, volatile }
                }
            }
            "atom" | "red" => {
                let mut aop = None;
                for w in &m.words {
                    let o = match w.as_str() {
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
                        "relaxed" | "acquire" | "release" | "acq_rel" | "cta" | "gpu" | "sys" | "noftz" => continue,
                        _ => return unsupported(pos, format!("{full} (modifier .{w})")),
                    };
                    aop = Some(o);
                }
                let Some(aop) = aop else {
                    return invalid(pos, format!("`{full}` needs an operation"));
                };
                let t = self.one_type(i, &m)?;
                if t.bits() < 32 || t == Ty::F16 {
                    return unsupported(pos, format!("{full} (types narrower than 32 bits)"));
                }
                let has_d = op == "atom";
                let n = usize::from(has_d) + 2 + usize::from(aop == AtomOp::Cas);
                self.operands(i, n)?;
                let k = usize::from(has_d);
                let (addr, sym_space) = self.address(&ops[k], pos)?;
                let space = self.mem_space(&m, sym_space, pos)?;
                if !matches!(space, MemSpace::Global | MemSpace::Shared | MemSpace::Generic) {
                    return invalid(pos, "atomics work on global, shared or generic addresses only");
                }
                let b = self.src(&ops[k + 1], t, pos)?;
                let c = if aop == AtomOp::Cas { self.src(&ops[k + 2], t, pos)? } else { Src::Imm(0) };
                let d = if has_d { Some(self.dst(&ops[0], pos)?) } else { None };
                Kind::Atom { space, op: aop, ty: t, d, addr, b, c }
            }
            "bra" => {
                self.operands(i, 1)?;
                m.only(&["uni"], pos, &full)?;
                let Operand::Name(l) = &ops[0] else {
                    return invalid(pos, "`bra` needs a label");
                };
                self.fixups.push((self.out.insts.len(), l.clone(), pos));
                Kind::Bra { target: u32::MAX, uni: m.has("uni") }
            }
            "call" => {
                m.only(&["uni"], pos, &full)?;
                self.call(i)?
            }
            "ret" => {
                m.only(&["uni"], pos, &full)?;
                if self.sigs[self.me].is_entry { Kind::Exit } else { Kind::Ret }
            }
            "exit" => Kind::Exit,
            "trap" => Kind::Trap,
            "bar" | "barrier" => {
                if m.has("warp") {
                    Kind::Nop // bar.warp.sync: the warp executes in lockstep here
                } else {
                    m.only(&["sync", "aligned"], pos, &full)?;
                    if !m.has("sync") && op == "bar" && !m.words.is_empty() {
                        return unsupported(pos, full.clone());
                    }
                    if ops.is_empty() || ops.len() > 2 {
                        return invalid(pos, format!("`{full}` takes a barrier id and an optional thread count"));
                    }
                    let id = self.src(&ops[0], Ty::U32, pos)?;
                    let count = if ops.len() == 2 { Some(self.src(&ops[1], Ty::U32, pos)?) } else { None };
                    Kind::Bar { id, count }
                }
            }
            "vote" => {
                m.only(&["sync", "all", "any", "uni", "ballot"], pos, &full)?;
                let mode = if m.has("all") {
                    VoteMode::All
                } else if m.has("any") {
                    VoteMode::Any
                } else if m.has("uni") {
                    VoteMode::Uni
                } else if m.has("ballot") {
                    VoteMode::Ballot
                } else {
                    return invalid(pos, "`vote` needs a mode");
                };
                let sync = m.has("sync");
                self.operands(i, if sync { 3 } else { 2 })?;
                let membermask = if sync { self.src(&ops[2], Ty::U32, pos)? } else { Src::Imm(u32::MAX as u64) };
                let a = self.pred_src(&ops[1], pos)?;
                if mode == VoteMode::Ballot {
                    Kind::Vote { mode, d: Some(self.dst(&ops[0], pos)?), p: PRED_FALSE, a, membermask }
                } else {
                    Kind::Vote { mode, d: None, p: self.pred_dst(&ops[0], pos)?, a, membermask }
                }
            }
            "activemask" => {
                self.operands(i, 1)?;
                Kind::Vote {
                    mode: VoteMode::Ballot,
                    d: Some(self.dst(&ops[0], pos)?),
                    p: PRED_FALSE,
                    a: PredSrc { reg: PRED_TRUE, neg: false },
                    membermask: Src::Imm(u32::MAX as u64),
                }
            }
            "shfl" => {
                m.only(&["sync", "up", "down", "bfly", "idx"], pos, &full)?;
                let mode = if m.has("up") {
                    ShflMode::Up
                } else if m.has("down") {
                    ShflMode::Down
                } else if m.has("bfly") {
                    ShflMode::Bfly
                } else if m.has("idx") {
                    ShflMode::Idx
                } else {
                    return invalid(pos, "`shfl` needs a mode");
                };
                let sync = m.has("sync");
                self.operands(i, if sync { 5 } else { 4 })?;
                let (d, p) = match &ops[0] {
                    Operand::Pair(d, p) => (
                        self.dst(&Operand::Name(d.clone()), pos)?,
                        Some(self.pred_dst(&Operand::Name(p.clone()), pos)?),
                    ),
                    o => (self.dst(o, pos)?, None),
                };
                Kind::Shfl {
                    mode,
                    d,
                    p,
                    a: self.src(&ops[1], Ty::B32, pos)?,
                    b: self.src(&ops[2], Ty::U32, pos)?,
                    c: self.src(&ops[3], Ty::U32, pos)?,
                    membermask: if sync { self.src(&ops[4], Ty::U32, pos)? } else { Src::Imm(u32::MAX as u64) },
                }
            }
            "membar" | "fence" => Kind::Membar,
            "prefetch" | "prefetchu" | "pmevent" | "nanosleep" | "brkpt" | "nop" => Kind::Nop,
            _ => return unsupported(pos, full),
        };
        self.emit(kind, guard, pos, full, class);
        Ok(())
    }

    fn call(&mut self, i: &ast::Instruction) -> LResult<Kind> {
        let pos = i.pos;
        let ops = &i.operands;
        let mut k = 0;
        let mut rets: &[Operand] = &[];
        if let Some(Operand::List(r)) = ops.first() {
            rets = r;
            k = 1;
        }
        let Some(Operand::Name(fname)) = ops.get(k) else {
            return invalid(pos, "`call` needs a function name");
        };
        let args: &[Operand] = match ops.get(k + 1) {
            Some(Operand::List(a)) => a,
            None => &[],
            Some(_) => return unsupported(pos, "indirect call with a prototype"),
        };
        if ops.len() > k + 2 {
            return unsupported(pos, "indirect call with a prototype");
        }
        let fidx = match self.lookup(fname) {
            Some(Sym::Func(f)) => f as usize,
            Some(Sym::Reg(_)) => return unsupported(pos, "indirect call through a register"),
            _ => return invalid(pos, format!("call of undeclared function `{fname}`")),
        };
        let callee = &self.sigs[fidx];
        if callee.is_entry {
            return invalid(pos, format!("`{fname}` is a kernel and cannot be called"));
        }
        if !callee.has_body {
            return unsupported(pos, format!("call of `{fname}`, which has no body in this module"));
        }
        if args.len() != callee.params.len() || rets.len() != callee.returns.len() {
            return invalid(
                pos,
                format!(
                    "`{}` takes {} argument(s) and {} return value(s); the call passes {} and {}",
                    callee.name,
                    callee.params.len(),
                    callee.returns.len(),
                    args.len(),
                    rets.len()
                ),
            );
        }
        let param_var = |o: &Operand| -> LResult<(u32, u32)> {
            match o {
                Operand::Name(n) => match self.lookup(n) {
                    Some(Sym::FrameParam(off, size)) => Ok((off, size)),
                    _ => unsupported(pos, format!("call argument `{n}` that is not a .param variable")),
                },
                _ => unsupported(pos, "call argument that is not a .param variable"),
            }
        };
        let mut a = Vec::new();
        for (o, p) in args.iter().zip(&callee.params) {
            let (off, size) = param_var(o)?;
            a.push((off, p.offset, size.min(p.size)));
        }
        let mut r = Vec::new();
        for (o, p) in rets.iter().zip(&callee.returns) {
            let (off, size) = param_var(o)?;
            r.push((p.offset, off, size.min(p.size)));
        }
        Ok(Kind::Call { func: fidx as u32, args: a, rets: r })
    }

    fn arith(&self, i: &ast::Instruction, m: &Mods, full: &str) -> LResult<Kind> {
        let pos = i.pos;
        let ops = &i.operands;
        let t = self.one_type(i, m)?;
        let op = i.opcode.as_str();
        let mut allowed: Vec<&str> = vec!["ftz", "sat", "approx", "full"];
        allowed.extend(ROUNDINGS);
        let mut words_ok = |extra: &[&'static str]| {
            allowed.extend(extra);
            m.only(&allowed, pos, full)
        };
        let (aop, nsrc) = match op {
            "add" => (ArithOp::Add, 2),
            "sub" => (ArithOp::Sub, 2),
            "mul" => {
                words_ok(&["lo", "hi", "wide"])?;
                let o = if m.has("hi") {
                    ArithOp::MulHi
                } else if m.has("wide") {
                    ArithOp::MulWide
                } else {
                    ArithOp::Mul
                };
                (o, 2)
            }
            "mad" | "fma" => {
                words_ok(&["lo", "hi", "wide"])?;
                let o = if m.has("hi") {
                    ArithOp::MadHi
                } else if m.has("wide") {
                    ArithOp::MadWide
                } else {
                    ArithOp::Mad
                };
                (o, 3)
            }
            "mul24" => {
                words_ok(&["lo", "hi"])?;
                (if m.has("hi") { ArithOp::Mul24Hi } else { ArithOp::Mul24Lo }, 2)
            }
            "mad24" => {
                words_ok(&["lo", "hi"])?;
                (if m.has("hi") { ArithOp::Mad24Hi } else { ArithOp::Mad24Lo }, 3)
            }
            "div" => (ArithOp::Div, 2),
            "rem" => (ArithOp::Rem, 2),
            "abs" => (ArithOp::Abs, 1),
            "neg" => (ArithOp::Neg, 1),
            "min" => (ArithOp::Min, 2),
            "max" => (ArithOp::Max, 2),
            "and" => (ArithOp::And, 2),
            "or" => (ArithOp::Or, 2),
            "xor" => (ArithOp::Xor, 2),
            "not" => (ArithOp::Not, 1),
            "cnot" => (ArithOp::Cnot, 1),
            "shl" => (ArithOp::Shl, 2),
            "shr" => (ArithOp::Shr, 2),
            "popc" => (ArithOp::Popc, 1),
            "clz" => (ArithOp::Clz, 1),
            "brev" => (ArithOp::Brev, 1),
            "bfe" => (ArithOp::Bfe, 3),
            "shf" => {
                words_ok(&["l", "r", "wrap", "clamp"])?;
                let o = match (m.has("l"), m.has("wrap")) {
                    (true, true) => ArithOp::ShfLWrap,
                    (true, false) => ArithOp::ShfLClamp,
                    (false, true) => ArithOp::ShfRWrap,
                    (false, false) => ArithOp::ShfRClamp,
                };
                (o, 3)
            }
            "prmt" => {
                words_ok(&[])?;
                (ArithOp::Prmt, 3)
            }
            "sqrt" => (ArithOp::Sqrt, 1),
            "rsqrt" => (ArithOp::Rsqrt, 1),
            "rcp" => (ArithOp::Rcp, 1),
            "sin" => (ArithOp::Sin, 1),
            "cos" => (ArithOp::Cos, 1),
            "ex2" => (ArithOp::Ex2, 1),
            "lg2" => (ArithOp::Lg2, 1),
            "copysign" => (ArithOp::Copysign, 2),
            _ => return unsupported(pos, full.to_string()),
        };
        m.only(&allowed, pos, full)?;
        if m.has("cc") {
            return unsupported(pos, format!("{full} (carry chains)"));
        }
        self.operands(i, nsrc + 1)?;
        if t.is_float() && t != Ty::F32 && t != Ty::F64 {
            return unsupported(pos, format!("{full} (.{t})"));
        }
        if t.is_float() && matches!(aop, ArithOp::MulHi | ArithOp::MulWide | ArithOp::MadHi | ArithOp::MadWide) {
            return invalid(pos, format!("`{full}`: .hi/.wide apply to integers"));
        }
        let mode = FloatMode {
            rnd: m.rounding(),
            ftz: m.has("ftz"),
            sat: m.has("sat"),
            approx: m.has("approx") || m.has("full"),
        };
        // Source operand types.
        let src_ty = |k: usize| -> Ty {
            match (aop, k) {
                (ArithOp::Shl | ArithOp::Shr, 1) => Ty::U32,
                (ArithOp::Bfe, 1 | 2) => Ty::U32,
                (ArithOp::ShfLWrap | ArithOp::ShfLClamp | ArithOp::ShfRWrap | ArithOp::ShfRClamp, 2) => Ty::U32,
                (ArithOp::MadWide, 2) => wide_of(t),
                (ArithOp::Prmt, _) => Ty::B32,
                _ => t,
            }
        };
        let mut s = [Src::Imm(0); 3];
        for k in 0..nsrc {
            s[k] = self.src(&ops[k + 1], src_ty(k), pos)?;
        }
        let d = self.dst(&ops[0], pos)?;
        Ok(Kind::Arith { op: aop, ty: t, mode, d, a: s[0], b: s[1], c: s[2] })
    }
}

fn wide_of(t: Ty) -> Ty {
    match t {
        Ty::S16 => Ty::S32,
        Ty::U16 => Ty::U32,
        Ty::S32 => Ty::S64,
        Ty::U32 => Ty::U64,
        o => o,
    }
}

fn part_ty(bits: u32, pos: Pos) -> LResult<Ty> {
    Ok(match bits {
        8 => Ty::B8,
        16 => Ty::B16,
        32 => Ty::B32,
        _ => return invalid(pos, "vector move parts must be 8, 16 or 32 bits"),
    })
}
