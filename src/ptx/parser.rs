//! Tokens → syntax tree ([`super::ast`]).

use super::ast::*;
use super::error::{Pos, PtxErrorKind};
use super::lexer::{Tok, Token};
use super::types::{Space, Ty};

type PResult<T> = Result<T, (Pos, PtxErrorKind)>;

/// Opcodes the lowering decodes; a syntax error in any other instruction is
/// reported as that instruction being unsupported.
pub const KNOWN_OPCODES: &[&str] = &[
    "mov",
    "add",
    "sub",
    "mul",
    "mad",
    "fma",
    "mul24",
    "mad24",
    "div",
    "rem",
    "abs",
    "neg",
    "min",
    "max",
    "and",
    "or",
    "xor",
    "not",
    "cnot",
    "shl",
    "shr",
    "shf",
    "popc",
    "clz",
    "brev",
    "bfe",
    "bfi",
    "prmt",
    "sqrt",
    "rsqrt",
    "rcp",
    "sin",
    "cos",
    "ex2",
    "lg2",
    "copysign",
    "setp",
    "set",
    "selp",
    "cvt",
    "cvta",
    "ld",
    "st",
    "atom",
    "red",
    "bra",
    "call",
    "ret",
    "exit",
    "trap",
    "bar",
    "barrier",
    "vote",
    "activemask",
    "shfl",
    "membar",
    "fence",
    "prefetch",
    "prefetchu",
    "pmevent",
    "nanosleep",
    "brkpt",
    "nop",
    "redux",
    "match",
    "bfind",
    "dp4a",
    "dp2a",
    "tex",
    "tld4",
    "txq",
    "suld",
    "sust",
    "sured",
    "tanh",
    "addc",
    "subc",
    "madc",
];

/// Deepest nesting of `{ }` blocks, initializer braces and operand lists the
/// parser accepts; deeper input is an error at the brace that goes too deep
/// (instead of overflowing the stack).
pub const MAX_NESTING: u32 = 256;

/// Parses a token stream into a module.
pub fn parse(tokens: &[Token]) -> PResult<Module> {
    let mut p = Parser { t: tokens, i: 0, depth: 0 };
    p.module()
}

struct Parser<'a> {
    t: &'a [Token],
    i: usize,
    /// Current nesting of blocks, initializer braces and operand lists.
    depth: u32,
}

fn syntax<T>(pos: Pos, msg: impl Into<String>) -> PResult<T> {
    Err((pos, PtxErrorKind::Syntax(msg.into())))
}

impl<'a> Parser<'a> {
    /// Runs `f` one nesting level deeper, failing at `pos` past [`MAX_NESTING`].
    fn nested<T>(&mut self, pos: Pos, what: &str, f: impl FnOnce(&mut Self) -> PResult<T>) -> PResult<T> {
        if self.depth >= MAX_NESTING {
            return Err((pos, PtxErrorKind::Limit(format!("{what} nested more than {MAX_NESTING} deep"))));
        }
        self.depth += 1;
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn peek(&self) -> Option<&'a Tok> {
        self.t.get(self.i).map(|t| &t.tok)
    }
    fn peek_at(&self, k: usize) -> Option<&'a Tok> {
        self.t.get(self.i + k).map(|t| &t.tok)
    }
    fn pos(&self) -> Pos {
        self.t.get(self.i).or_else(|| self.t.last()).map(|t| t.pos).unwrap_or(Pos { line: 1, col: 1 })
    }
    fn next(&mut self) -> PResult<&'a Token> {
        let t = self.t.get(self.i);
        match t {
            Some(t) => {
                self.i += 1;
                Ok(t)
            }
            None => syntax(self.pos(), "unexpected end of file"),
        }
    }
    fn is_punct(&self, c: char) -> bool {
        self.peek() == Some(&Tok::Punct(c))
    }
    fn eat_punct(&mut self, c: char) -> bool {
        if self.is_punct(c) {
            self.i += 1;
            true
        } else {
            false
        }
    }
    fn expect_punct(&mut self, c: char) -> PResult<()> {
        if self.eat_punct(c) {
            Ok(())
        } else {
            syntax(self.pos(), format!("expected `{c}`, found {}", self.describe()))
        }
    }
    fn describe(&self) -> String {
        match self.peek() {
            None => "end of file".into(),
            Some(Tok::Ident(s)) => format!("`{s}`"),
            Some(Tok::Dot(s)) => format!("`.{s}`"),
            Some(Tok::Punct(c)) => format!("`{c}`"),
            Some(Tok::Str(s)) => format!("\"{s}\""),
            Some(t) => format!("{t:?}"),
        }
    }
    fn expect_ident(&mut self) -> PResult<String> {
        let pos = self.pos();
        match self.next()?.tok {
            Tok::Ident(ref s) => Ok(s.clone()),
            _ => {
                self.i -= 1;
                syntax(pos, format!("expected a name, found {}", self.describe()))
            }
        }
    }
    fn expect_int(&mut self) -> PResult<u64> {
        let pos = self.pos();
        match self.next()?.tok {
            Tok::Int(v) => Ok(v),
            _ => {
                self.i -= 1;
                syntax(pos, format!("expected an integer, found {}", self.describe()))
            }
        }
    }
    fn peek_dot(&self) -> Option<&'a str> {
        match self.peek() {
            Some(Tok::Dot(s)) => Some(s.as_str()),
            _ => None,
        }
    }

    fn module(&mut self) -> PResult<Module> {
        let mut m = Module { address_size: 64, ..Default::default() };
        while let Some(tok) = self.peek() {
            let pos = self.pos();
            let Tok::Dot(d) = tok else {
                return syntax(pos, format!("expected a directive, found {}", self.describe()));
            };
            match d.as_str() {
                "version" => {
                    self.i += 1;
                    m.version = match &self.next()?.tok {
                        Tok::Float(f) => format!("{f}"),
                        Tok::Int(a) => {
                            let mut v = a.to_string();
                            if let Some(Tok::Dot(_)) = self.peek() {
                                // `7.8` lexes as a float; this branch is defensive.
                                v.push('.');
                            }
                            v
                        }
                        _ => return syntax(pos, "bad .version"),
                    };
                }
                "target" => {
                    self.i += 1;
                    m.target.push(self.expect_ident()?);
                    while self.eat_punct(',') {
                        m.target.push(self.expect_ident()?);
                    }
                }
                "address_size" => {
                    self.i += 1;
                    m.address_size = self.expect_int()? as u32;
                    if m.address_size != 64 && m.address_size != 32 {
                        return syntax(pos, "address_size must be 32 or 64");
                    }
                }
                "file" => {
                    self.i += 1;
                    let id = self.expect_int()? as u32;
                    let name = match &self.next()?.tok {
                        Tok::Str(s) => s.clone(),
                        _ => return syntax(pos, "expected a file name string"),
                    };
                    let mut full = name;
                    // `.file 1 "dir" "name"` (DWARF 5) or `.file 1 "name", time, size`
                    if let Some(Tok::Str(s)) = self.peek() {
                        full = format!("{full}/{s}");
                        self.i += 1;
                    }
                    while self.eat_punct(',') {
                        self.expect_int()?;
                    }
                    m.files.push((id, full));
                }
                "section" => {
                    self.i += 1;
                    self.next()?; // section name
                    self.skip_braced()?;
                }
                "pragma" => {
                    self.i += 1;
                    self.next()?;
                    self.expect_punct(';')?;
                }
                _ => self.module_item(&mut m)?,
            }
        }
        Ok(m)
    }

    fn skip_braced(&mut self) -> PResult<()> {
        self.expect_punct('{')?;
        let mut depth = 1;
        while depth > 0 {
            match self.next()?.tok {
                Tok::Punct('{') => depth += 1,
                Tok::Punct('}') => depth -= 1,
                _ => {}
            }
        }
        Ok(())
    }

    fn module_item(&mut self, m: &mut Module) -> PResult<()> {
        let mut is_extern = false;
        loop {
            match self.peek_dot() {
                Some("visible") | Some("weak") | Some("common") => self.i += 1,
                Some("extern") => {
                    is_extern = true;
                    self.i += 1
                }
                _ => break,
            }
        }
        let pos = self.pos();
        match self.peek_dot() {
            Some("entry") | Some("func") => {
                let f = self.function()?;
                m.functions.push(f);
                Ok(())
            }
            Some(s) if Space::parse(s).is_some() => {
                for mut v in self.var_decls()? {
                    v.is_extern = is_extern;
                    m.vars.push(v);
                }
                self.expect_punct(';')?;
                Ok(())
            }
            Some(s) => Err((pos, PtxErrorKind::UnsupportedDirective(format!(".{s}")))),
            None => syntax(pos, format!("expected a directive, found {}", self.describe())),
        }
    }

    /// `.space [.align n] [.vN] .type name[<n>][dims] [= init]`
    fn var_decl(&mut self) -> PResult<VarDecl> {
        let pos = self.pos();
        let space = match &self.next()?.tok {
            Tok::Dot(s) => Space::parse(s).ok_or((pos, PtxErrorKind::Syntax(format!("`.{s}` is no state space"))))?,
            _ => return syntax(pos, "expected a state space"),
        };
        let (mut align, mut vector, mut ty) = (None, None, None);
        while let Some(d) = self.peek_dot() {
            let p = self.pos();
            self.i += 1;
            match d {
                "align" => align = Some(self.expect_int()? as u32),
                "v2" => vector = Some(2),
                "v4" => vector = Some(4),
                "ptr" | "global" | "shared" | "local" | "const" => {} // `.ptr.global.align` attributes of params
                _ => match Ty::parse(d) {
                    Some(t) => ty = Some(t),
                    None => return Err((p, PtxErrorKind::UnsupportedDirective(format!(".{d}")))),
                },
            }
        }
        let ty = ty.ok_or((pos, PtxErrorKind::Syntax("declaration without a type".into())))?;
        self.decl_name(VarDecl {
            space,
            align,
            vector,
            ty,
            name: String::new(),
            range: None,
            dims: Vec::new(),
            init: None,
            init_syms: Vec::new(),
            is_extern: false,
            pos,
        })
    }

    /// A declaration followed by more names of the same space and type
    /// (`.reg .b32 %a, %b, %r<4>;`, which ptxas accepts): one [`VarDecl`] each.
    fn var_decls(&mut self) -> PResult<Vec<VarDecl>> {
        let first = self.var_decl()?;
        let mut out = vec![first];
        while self.eat_punct(',') {
            let head = VarDecl { pos: self.pos(), ..out[0].clone() };
            out.push(self.decl_name(head)?);
        }
        Ok(out)
    }

    /// The part of a declaration after its type: `name[<n>][dims] [= init]`,
    /// filled into `head` (which carries the space, alignment and type).
    fn decl_name(&mut self, head: VarDecl) -> PResult<VarDecl> {
        let VarDecl { space, align, vector, ty, pos, .. } = head;
        let name = self.expect_ident()?;
        let mut range = None;
        if self.eat_punct('<') {
            range = Some(self.expect_int()? as u32);
            self.expect_punct('>')?;
        }
        let mut dims = Vec::new();
        while self.eat_punct('[') {
            if self.eat_punct(']') {
                dims.push(None);
            } else {
                dims.push(Some(self.expect_int()?));
                self.expect_punct(']')?;
            }
        }
        let mut init = None;
        let mut init_syms = Vec::new();
        if self.eat_punct('=') {
            let mut vals = Vec::new();
            // the elements a brace at each depth stands for: the whole array (left to the
            // layout), a row of the dimensions after it, ..., one vector, one element
            let mut rows: Vec<Option<u64>> = vec![None];
            let levels: Vec<Option<u64>> = dims.iter().skip(1).copied().chain(vector.map(|n| Some(n as u64))).collect();
            for k in 0..levels.len() {
                rows.push(levels[k..].iter().try_fold(1u64, |a, d| a.checked_mul((*d)?)));
            }
            self.initializer(&mut vals, &mut init_syms, (&name, &rows, 0))?;
            // `t[] = {..}`, `t[][2] = {..}`: the first dimension from the initializer's
            // elements over the other dimensions' (the last row filled with zeros)
            if dims.first() == Some(&None) && dims[1..].iter().all(Option::is_some) {
                let inner: u64 = dims[1..].iter().flatten().product();
                if inner > 0 {
                    dims[0] = Some((vals.len() as u64 / vector.unwrap_or(1) as u64).div_ceil(inner));
                }
            }
            init = Some(vals);
        }
        Ok(VarDecl { space, align, vector, ty, name, range, dims, init, init_syms, is_extern: false, pos })
    }

    /// Reads an initializer into `out`, flattened. A nested brace at depth
    /// `d` stands for `rows[d]` elements (one beyond the list: a single
    /// element): fewer are padded with zeros, as C pads `t[2][2] = {{1},{2}}`
    /// to `{1, 0, 2, 0}`; more are an error. `(name, rows, depth)`.
    fn initializer(
        &mut self,
        out: &mut Vec<Literal>,
        syms: &mut Vec<(usize, String)>,
        (name, rows, depth): (&str, &[Option<u64>], usize),
    ) -> PResult<()> {
        let pos = self.pos();
        if self.eat_punct('{') {
            let start = out.len();
            self.nested(pos, "initializer braces", |p| {
                if !p.is_punct('}') {
                    p.initializer(out, syms, (name, rows, depth + 1))?;
                    while p.eat_punct(',') {
                        p.initializer(out, syms, (name, rows, depth + 1))?;
                    }
                }
                p.expect_punct('}')
            })?;
            let Some(n) = (if depth == 0 { None } else { rows.get(depth).copied().unwrap_or(Some(1)) }) else {
                return Ok(());
            };
            let got = (out.len() - start) as u64;
            if got > n {
                return Err((
                    pos,
                    PtxErrorKind::Invalid(format!(
                        "an initializer brace of `{name}` holds {got} elements; it has room for {n}"
                    )),
                ));
            }
            // `n` is a checked product of the later dimensions and may be near 2^64
            let Some(len) = (start as u64).checked_add(n) else {
                return Err((
                    pos,
                    PtxErrorKind::Limit(format!(
                        "the initializer of `{name}` padded to whole rows passes 2^64 elements"
                    )),
                ));
            };
            crate::limits::check_memory(
                || format!("the initializer of `{name}` padded to whole rows"),
                len.saturating_mul(std::mem::size_of::<Literal>() as u64),
            )
            .map_err(|e| (pos, PtxErrorKind::Limit(e.to_string())))?;
            out.resize(len as usize, Literal::Int(0));
            Ok(())
        } else {
            let pos = self.pos();
            // a symbol's address (`{_Z4addfff, ...}`): resolved by the lowering
            if let Some(Tok::Ident(name)) = self.peek()
                && !name.starts_with('%')
                && self.peek_at(1) != Some(&Tok::Punct('('))
            {
                syms.push((out.len(), name.clone()));
                out.push(Literal::Int(0));
                self.i += 1;
                return Ok(());
            }
            match self.literal()? {
                Some(l) => {
                    out.push(l);
                    Ok(())
                }
                None => Err((pos, PtxErrorKind::Unsupported(format!("initializer {}", self.describe())))),
            }
        }
    }

    fn literal(&mut self) -> PResult<Option<Literal>> {
        let neg = self.eat_punct('-');
        let lit = match self.peek() {
            Some(Tok::Int(v)) => Literal::Int(if neg { v.wrapping_neg() } else { *v }),
            Some(Tok::F32Bits(b)) => Literal::F32(if neg { b ^ 0x8000_0000 } else { *b }),
            Some(Tok::F64Bits(b)) => Literal::F64(if neg { b ^ (1 << 63) } else { *b }),
            Some(Tok::Float(f)) => Literal::Float(if neg { -f } else { *f }),
            _ => {
                if neg {
                    self.i -= 1;
                }
                return Ok(None);
            }
        };
        self.i += 1;
        Ok(Some(lit))
    }

    fn function(&mut self) -> PResult<Function> {
        let pos = self.pos();
        let kind = match self.next()?.tok {
            Tok::Dot(ref s) if s == "entry" => FunctionKind::Entry,
            _ => FunctionKind::Func,
        };
        let mut returns = Vec::new();
        if kind == FunctionKind::Func && self.is_punct('(') {
            returns = self.param_list()?;
        }
        let name = self.expect_ident()?;
        let mut params = Vec::new();
        if self.is_punct('(') {
            params = self.param_list()?;
        }
        // performance directives
        while let Some(d) = self.peek_dot() {
            match d {
                "maxntid" | "reqntid" | "minnctapersm" | "maxnreg" | "maxnctapersm" | "noreturn" | "pragma"
                | "explicitcluster" | "reqnctapercluster" | "maxclusterrank" => {
                    self.i += 1;
                    while let Some(Tok::Int(_)) | Some(Tok::Str(_)) = self.peek() {
                        self.i += 1;
                        if !self.eat_punct(',') {
                            break;
                        }
                    }
                    self.eat_punct(';');
                }
                _ => {
                    return Err((self.pos(), PtxErrorKind::UnsupportedDirective(format!(".{d}"))));
                }
            }
        }
        if self.eat_punct(';') {
            return Ok(Function { kind, name, returns, params, body: None, pos });
        }
        self.expect_punct('{')?;
        let body = self.block_body()?;
        Ok(Function { kind, name, returns, params, body: Some(body), pos })
    }

    fn param_list(&mut self) -> PResult<Vec<VarDecl>> {
        self.expect_punct('(')?;
        let mut v = Vec::new();
        if self.eat_punct(')') {
            return Ok(v);
        }
        loop {
            v.push(self.var_decl()?);
            if self.eat_punct(')') {
                return Ok(v);
            }
            self.expect_punct(',')?;
        }
    }

    /// Statements up to and including the closing `}`.
    fn block_body(&mut self) -> PResult<Vec<Stmt>> {
        let mut out = Vec::new();
        loop {
            let pos = self.pos();
            match self.peek() {
                None => return syntax(pos, "missing `}` at end of function"),
                Some(Tok::Punct('}')) => {
                    self.i += 1;
                    return Ok(out);
                }
                Some(Tok::Punct('{')) => {
                    self.i += 1;
                    out.push(Stmt::Block(self.nested(pos, "blocks `{ }`", |p| p.block_body())?));
                }
                Some(Tok::Dot(d)) => match d.as_str() {
                    "loc" => {
                        self.i += 1;
                        let file = self.expect_int()? as u32;
                        let line = self.expect_int()? as u32;
                        let col = self.expect_int()? as u32;
                        // DWARF extras (`, function_name ..., inlined_at ...`) stay on the line.
                        while self.peek().is_some() && self.pos().line == pos.line {
                            self.i += 1;
                        }
                        out.push(Stmt::Loc { file, line, col });
                    }
                    "pragma" => {
                        self.i += 1;
                        self.next()?;
                        self.expect_punct(';')?;
                    }
                    s if Space::parse(s).is_some() => {
                        out.extend(self.var_decls()?.into_iter().map(Stmt::Decl));
                        self.expect_punct(';')?;
                    }
                    _ => return Err((pos, PtxErrorKind::UnsupportedDirective(format!(".{d}")))),
                },
                // `prototype_0 : .callprototype (...) _ (...);`: the signature of an
                // indirect call, which warplight takes from the called function itself
                Some(Tok::Ident(_))
                    if self.peek_at(1) == Some(&Tok::Punct(':'))
                        && matches!(self.peek_at(2), Some(Tok::Dot(d)) if d == "callprototype") =>
                {
                    if !self.skip_statement() {
                        return syntax(pos, "missing `;` after `.callprototype`");
                    }
                }
                Some(Tok::Ident(name)) if self.peek_at(1) == Some(&Tok::Punct(':')) => {
                    self.i += 2;
                    out.push(Stmt::Label(name.clone(), pos));
                }
                Some(Tok::Ident(_)) | Some(Tok::Punct('@')) => out.push(Stmt::Inst(self.instruction()?)),
                _ => {
                    return syntax(pos, format!("expected an instruction, found {}", self.describe()));
                }
            }
        }
    }

    fn instruction(&mut self) -> PResult<Instruction> {
        let pos = self.pos();
        let mut guard = None;
        if self.eat_punct('@') {
            let neg = self.eat_punct('!');
            guard = Some((neg, self.expect_ident()?));
        }
        let opcode = self.expect_ident()?;
        let mut mods = Vec::new();
        while let Some(Token { tok: Tok::Dot(m), glued: true, .. }) = self.t.get(self.i) {
            mods.push(m.clone());
            self.i += 1;
        }
        let start = self.i;
        let operands = match self.operand_list() {
            Ok(o) => o,
            // Operand syntax of instructions warplight does not know (textures, tensor
            // ops...) is not parsed: the instruction is kept without operands (the
            // lowering reports it unsupported, failing only its function) when its
            // `;` is found before the block ends, else it is named as the error.
            Err(_) if !KNOWN_OPCODES.contains(&opcode.as_str()) => {
                self.i = start;
                if self.skip_statement() {
                    Vec::new()
                } else {
                    let mut full = opcode.clone();
                    for m in &mods {
                        full.push('.');
                        full.push_str(m);
                    }
                    return Err((pos, PtxErrorKind::Unsupported(full)));
                }
            }
            Err(e) => return Err(e),
        };
        Ok(Instruction { guard, opcode, mods, operands, pos })
    }

    /// Skips tokens through the next `;` outside braces; false (and nothing
    /// skipped) when a `}` closing the enclosing block or the end of the file
    /// comes first.
    fn skip_statement(&mut self) -> bool {
        let start = self.i;
        let mut depth = 0usize;
        while let Some(t) = self.peek() {
            self.i += 1;
            match t {
                Tok::Punct(';') if depth == 0 => return true,
                Tok::Punct('{') => depth += 1,
                Tok::Punct('}') if depth == 0 => break,
                Tok::Punct('}') => depth -= 1,
                _ => {}
            }
        }
        self.i = start;
        false
    }

    fn operand_list(&mut self) -> PResult<Vec<Operand>> {
        let mut operands = Vec::new();
        if !self.eat_punct(';') {
            loop {
                operands.push(self.operand()?);
                if self.eat_punct(';') {
                    break;
                }
                if !self.eat_punct(',') {
                    return syntax(self.pos(), format!("expected `,` or `;`, found {}", self.describe()));
                }
            }
        }
        Ok(operands)
    }

    fn name_with_component(&mut self) -> PResult<String> {
        let mut n = self.expect_ident()?;
        if n.starts_with('%')
            && let Some(Token { tok: Tok::Dot(c), glued: true, .. }) = self.t.get(self.i)
        {
            n.push('.');
            n.push_str(c);
            self.i += 1;
        }
        Ok(n)
    }

    fn operand(&mut self) -> PResult<Operand> {
        let pos = self.pos();
        match self.peek() {
            Some(Tok::Punct('[')) => {
                self.i += 1;
                let mut base = None;
                let mut off: i64 = 0;
                if let Some(Tok::Ident(_)) = self.peek() {
                    base = Some(self.name_with_component()?);
                    if self.eat_punct('+') {
                        let neg = self.eat_punct('-');
                        let v = self.expect_int()? as i64;
                        off = if neg { -v } else { v };
                    } else if self.eat_punct('-') {
                        off = -(self.expect_int()? as i64);
                    }
                } else {
                    let neg = self.eat_punct('-');
                    let v = self.expect_int()? as i64;
                    off = if neg { -v } else { v };
                }
                // `[handle, {coordinates}]` of texture and surface instructions
                if let Some(b) = base.as_ref().filter(|_| off == 0 && self.is_punct(','))
                    && self.eat_punct(',')
                {
                    let b = b.clone();
                    let coords = match self.operand()? {
                        Operand::Vector(v) => v,
                        one => vec![one],
                    };
                    self.expect_punct(']')?;
                    return Ok(Operand::TexAddr(b, coords));
                }
                self.expect_punct(']')?;
                Ok(Operand::Addr(base, off))
            }
            Some(Tok::Punct('{')) | Some(Tok::Punct('(')) => {
                let brace = self.is_punct('{');
                let close = if brace { '}' } else { ')' };
                self.i += 1;
                let v = self.nested(pos, "operand lists", |p| {
                    let mut v = Vec::new();
                    if !p.eat_punct(close) {
                        loop {
                            v.push(p.operand()?);
                            if p.eat_punct(close) {
                                break;
                            }
                            p.expect_punct(',')?;
                        }
                    }
                    Ok(v)
                })?;
                Ok(if brace { Operand::Vector(v) } else { Operand::List(v) })
            }
            Some(Tok::Punct('!')) => {
                self.i += 1;
                Ok(Operand::Not(self.expect_ident()?))
            }
            Some(Tok::Ident(_)) => {
                let n = self.name_with_component()?;
                if self.eat_punct('|') {
                    let q = self.expect_ident()?;
                    return Ok(Operand::Pair(n, q));
                }
                // `sym+8`, `sym-8`: an address expression (the lowering checks that `sym` is a variable)
                if let Some(Tok::Punct(sign @ ('+' | '-'))) = self.peek() {
                    let mut neg = *sign == '-';
                    self.i += 1;
                    if !neg && self.eat_punct('-') {
                        neg = true;
                    }
                    let sign = if neg { '-' } else { '+' };
                    let at = self.pos();
                    let Some(Tok::Int(v)) = self.peek() else {
                        return syntax(
                            at,
                            format!(
                                "expected an integer byte offset after `{n}{sign}` (an address expression is a \
                                 variable plus or minus an integer, `{n}+8`), found {}",
                                self.describe()
                            ),
                        );
                    };
                    self.i += 1;
                    let Ok(v) = i64::try_from(*v) else {
                        return syntax(at, format!("offset {v} of `{n}{sign}{v}` out of range"));
                    };
                    return Ok(Operand::Offset(n, if neg { -v } else { v }));
                }
                Ok(Operand::Name(n))
            }
            _ => match self.literal()? {
                Some(l) => Ok(Operand::Lit(l)),
                None => syntax(pos, format!("expected an operand, found {}", self.describe())),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::lexer::lex;
    use super::*;

    fn parse_str(s: &str) -> Module {
        parse(&lex(s).unwrap()).unwrap()
    }

    #[test]
    fn parses_entry_with_params_and_body() {
        let m = parse_str(
            ".version 7.8\n.target sm_90\n.address_size 64\n\
             .visible .entry k(.param .u64 k_p0, .param .u32 k_p1)\n{\n\
             .reg .b32 %r<4>;\n$L1:\n @!%p1 bra $L1;\n ld.global.nc.v2.f32 {%f1, %f2}, [%rd1+-8];\n ret;\n}\n",
        );
        assert_eq!(m.version, "7.8");
        assert_eq!(m.functions.len(), 1);
        let f = &m.functions[0];
        assert_eq!(f.params.len(), 2);
        let body = f.body.as_ref().unwrap();
        assert!(matches!(&body[0], Stmt::Decl(d) if d.range == Some(4)));
        let Stmt::Inst(i) = &body[2] else { panic!() };
        assert_eq!(i.guard, Some((true, "%p1".into())));
        let Stmt::Inst(ld) = &body[3] else { panic!() };
        assert_eq!(ld.full_opcode(), "ld.global.nc.v2.f32");
        assert_eq!(ld.operands[1], Operand::Addr(Some("%rd1".into()), -8));
    }

    #[test]
    fn a_symbol_plus_an_offset_is_an_address_expression() {
        let m = parse_str(
            ".global .u32 g[4];\n.entry k()\n{\n.reg .b32 %r<3>;\n.reg .b64 %rd<2>;\n\
             mov.u32 %r1, g+8;\nmov.u64 %rd1, g - 4;\nmov.u32 %r2, g+0x10;\nmov.u32 %r2, g+-2;\nret;\n}\n",
        );
        let ops: Vec<Operand> = m.functions[0]
            .body
            .as_ref()
            .unwrap()
            .iter()
            .filter_map(|s| match s {
                Stmt::Inst(i) if i.opcode == "mov" => Some(i.operands[1].clone()),
                _ => None,
            })
            .collect();
        let want = [8, -4, 16, -2].map(|o| Operand::Offset("g".into(), o));
        assert_eq!(ops, want);
        // bad forms: no integer after the sign, a register offset, a second term
        for (body, what) in [
            ("mov.u32 %r1, g+;", "after `g+`"),
            ("mov.u32 %r1, g+%r2;", "found `%r2`"),
            ("mov.u32 %r1, g-h;", "found `h`"),
            ("mov.u32 %r1, g+8+4;", "expected `,` or `;`, found `+`"),
        ] {
            let src = format!(".entry k()\n{{\n{body}\nret;\n}}\n");
            let (pos, kind) = parse(&lex(&src).unwrap()).unwrap_err();
            assert_eq!(pos.line, 3, "{body}: {kind}");
            assert!(matches!(&kind, PtxErrorKind::Syntax(m) if m.contains(what)), "{body}: {kind}");
        }
    }

    #[test]
    fn one_declaration_may_name_several_registers() {
        let m = parse_str(
            ".entry k()\n{\n.reg .b32 %a, %b, %r<4>;\n.reg .f32 %f;\nret;\n}\n.global .u32 g0, g1[2] = {1, 2};\n",
        );
        let body = m.functions[0].body.as_ref().unwrap();
        let names: Vec<(String, Option<u32>)> = body
            .iter()
            .filter_map(|s| match s {
                Stmt::Decl(d) => Some((d.name.clone(), d.range)),
                _ => None,
            })
            .collect();
        let want = [("%a", None), ("%b", None), ("%r", Some(4)), ("%f", None)];
        assert_eq!(names, want.map(|(n, r)| (n.to_string(), r)));
        assert!(matches!(&body[2], Stmt::Decl(d) if d.ty == Ty::B32));
        assert_eq!(m.vars.len(), 2);
        assert_eq!((m.vars[1].name.as_str(), m.vars[1].dims.as_slice()), ("g1", &[Some(2)][..]));
        assert!(m.vars[0].init.is_none());
    }

    #[test]
    fn nesting_past_the_limit_is_an_error_at_the_brace() {
        let n = MAX_NESTING as usize;
        let ok = format!(".entry k()\n{{\n{}{}}}\n", "{ ".repeat(n), "} ".repeat(n));
        assert!(parse(&lex(&ok).unwrap()).is_ok());
        let deep = format!(".entry k()\n{{\n{}\n{{{}}}\n", "{ ".repeat(n), "} ".repeat(n + 1));
        let (pos, kind) = parse(&lex(&deep).unwrap()).unwrap_err();
        assert_eq!((pos.line, pos.col), (4, 1));
        assert!(matches!(kind, PtxErrorKind::Limit(ref m) if m.contains("blocks")), "{kind}");
        let init = format!(".global .u32 g[1] = {}1{};", "{".repeat(n + 1), "}".repeat(n + 1));
        let (pos, kind) = parse(&lex(&init).unwrap()).unwrap_err();
        assert_eq!(pos.col, 21 + n as u32);
        assert!(matches!(kind, PtxErrorKind::Limit(ref m) if m.contains("initializer")), "{kind}");
    }

    #[test]
    fn padding_an_initializer_past_2_pow_64_elements_is_an_error_at_the_brace() {
        // the last seven dimensions multiply to 2^64 - 1 (the Fermat factors of
        // 2^64 - 1), so the inner brace after one element pads to 1 + (2^64 - 1)
        let src = ".global .u32 t[2][3][5][17][257][641][65537][6700417]\n  = {1, {2}};\n";
        let (pos, kind) = parse(&lex(src).unwrap()).unwrap_err();
        assert_eq!((pos.line, pos.col), (2, 9));
        assert!(matches!(kind, PtxErrorKind::Limit(ref m) if m.contains("`t`") && m.contains("2^64")), "{kind}");
    }

    #[test]
    fn reports_missing_semicolon_position() {
        let toks = lex(".version 7.8\n.entry k()\n{\n add.s32 %r1, %r2 %r3;\n}").unwrap();
        let e = parse(&toks).unwrap_err();
        assert_eq!(e.0.line, 4);
    }
}
