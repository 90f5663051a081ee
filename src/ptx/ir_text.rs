//! A compact textual rendering of the IR ([`super::ir`]): one line per
//! instruction with every field of its [`Kind`], the layout of each function
//! and of the module. The lowering's snapshot tests (`tests/ptx_lowering.rs`)
//! compare it with committed text, so every field is printed: the matches
//! below destructure each variant completely, and a field added to the IR
//! does not compile until it is rendered here.
//!
//! ```
//! let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
//!            .visible .entry k(.param .u64 p)\n{\n .reg .b32 %r<2>;\n add.s32 %r1, %r0, 5;\n ret;\n}\n";
//! let prog = warplight::ptx::load(src, "k.ptx").unwrap();
//! let text = warplight::ptx::ir_text::program(&prog);
//! assert!(text.contains("add.s32 %r1:32 <- %r0, 5, 0"), "{text}");
//! ```

use std::fmt::Write;

use super::ir::*;

/// The whole module: globals, constants, shared layout, then every function.
pub fn program(p: &Program) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "module {} (PTX {}, target {})", p.source_name, p.version, p.target.join(","));
    for (i, f) in p.files.iter().enumerate() {
        let _ = writeln!(s, "file {i} {f}");
    }
    for (i, g) in p.globals.iter().enumerate() {
        let GlobalVar { name, size, align, init } = g;
        let nonzero = init.iter().filter(|b| **b != 0).count();
        let _ = writeln!(
            s,
            "global {i} {name}: {size} B align {align}, init {} B ({nonzero} non-zero, sum {})",
            init.len(),
            init.iter().map(|b| *b as u64).sum::<u64>()
        );
    }
    for (name, off, size) in &p.const_vars {
        let _ = writeln!(s, "const {name} @{off}: {size} B");
    }
    if !p.const_bank.is_empty() {
        let _ = writeln!(s, "const bank {} B: {}", p.const_bank.len(), hex(&p.const_bank));
    }
    for v in &p.shared_vars {
        let SharedVar { name, offset, size, align, scope } = v;
        let scope = scope.map(|f| format!(" (in function {f})")).unwrap_or_default();
        let _ = writeln!(s, "shared {name} @{offset}: {size} B align {align}{scope}");
    }
    let _ = writeln!(s, "static shared {} B", p.static_shared_size);
    for f in &p.functions {
        s.push('\n');
        s.push_str(&function(f));
        if let Some(e) = &f.unsupported {
            let _ = writeln!(s, "  unusable: {e}");
        }
    }
    s
}

/// Bytes as hexadecimal, at most 64 of them.
fn hex(b: &[u8]) -> String {
    let mut s: String = b.iter().take(64).map(|x| format!("{x:02x}")).collect();
    if b.len() > 64 {
        s.push('…');
    }
    s
}

/// One function: its signature and layout, then its instructions.
pub fn function(f: &Function) -> String {
    let Function {
        name,
        is_entry,
        params,
        returns,
        frame_param_size,
        kernel_param_size,
        local_size,
        local_align,
        reg_masks,
        reg_names,
        num_preds,
        pred_names,
        insts,
        info,
        labels,
        declared_reg_words,
        shared_refs,
        shared_symbols,
        unsupported: _,
    } = f;
    let mut s = String::new();
    let param_list = |ps: &[Param]| {
        ps.iter().map(|p| format!(".{} {} @{}+{}", p.ty, p.name, p.offset, p.size)).collect::<Vec<_>>().join(", ")
    };
    let _ = writeln!(
        s,
        "{} {name}({}) -> ({})",
        if *is_entry { "entry" } else { "func" },
        param_list(params),
        param_list(returns)
    );
    let _ = writeln!(
        s,
        "  kernel params {kernel_param_size} B, frame params {frame_param_size} B, local {local_size} B align \
         {local_align}, {} regs ({declared_reg_words} words), {num_preds} preds, shared refs {shared_refs:?}",
        reg_masks.len()
    );
    if !shared_symbols.is_empty() {
        let _ = writeln!(s, "  shared symbols at {shared_symbols:?}");
    }
    debug_assert_eq!(reg_names.len(), reg_masks.len());
    debug_assert_eq!(pred_names.len(), *num_preds as usize);
    let names = Names { regs: reg_names, preds: pred_names };
    for (k, (inst, inf)) in insts.iter().zip(info).enumerate() {
        for (l, _) in labels.iter().filter(|(_, i)| *i as usize == k) {
            let _ = writeln!(s, " {l}:");
        }
        let InstInfo { ptx_line, ptx_col, src, opcode, class } = inf;
        let guard = match &inst.guard {
            Some(g) => format!("@{} ", names.pred_src(*g)),
            None => String::new(),
        };
        let src = match src {
            Some(SrcLoc { file, line, col }) => format!(" src {file}:{line}:{col}"),
            None => String::new(),
        };
        let _ = writeln!(
            s,
            "  {k:>3} {:<7} {guard}{}    ; {ptx_line}:{ptx_col} {opcode}{src}",
            format!("{class:?}").to_lowercase(),
            names.kind(&inst.kind)
        );
    }
    for (l, _) in labels.iter().filter(|(_, i)| *i as usize >= insts.len()) {
        let _ = writeln!(s, " {l}: (end)");
    }
    s
}

/// Register names of one function.
struct Names<'a> {
    regs: &'a [String],
    preds: &'a [String],
}

/// A lower-case enum name (`ShfLWrap` → `shflwrap`).
fn lc(x: impl std::fmt::Debug) -> String {
    format!("{x:?}").to_lowercase()
}

impl Names<'_> {
    fn reg(&self, r: RegId) -> String {
        self.regs.get(r as usize).cloned().unwrap_or_else(|| format!("r#{r}"))
    }

    fn pred(&self, p: PredId) -> String {
        self.preds.get(p as usize).cloned().unwrap_or_else(|| format!("p#{p}"))
    }

    fn pred_src(&self, p: PredSrc) -> String {
        let PredSrc { reg, neg } = p;
        format!("{}{}", if neg { "!" } else { "" }, self.pred(reg))
    }

    fn dst(&self, d: Dst) -> String {
        let Dst { reg, mask } = d;
        if reg == Dst::SINK {
            return format!("_:{}", mask.count_ones());
        }
        format!("{}:{}", self.reg(reg), mask.count_ones())
    }

    fn dsts(&self, ds: &[Dst]) -> String {
        ds.iter().map(|d| self.dst(*d)).collect::<Vec<_>>().join(", ")
    }

    /// A `.sync` form's member mask, or `none` for the forms without one.
    fn member_mask(&self, m: Src) -> String {
        if m == crate::ptx::lower::warp::NO_MEMBER_MASK { "none".into() } else { self.src(m) }
    }

    fn src(&self, s: Src) -> String {
        match s {
            Src::Reg(r) => self.reg(r),
            Src::Imm(v) if v < 0x10000 => v.to_string(),
            Src::Imm(v) => format!("{v:#x}"),
            Src::Special(r) => special(r),
            Src::LocalAddr(o) => format!("local+{o}"),
            Src::GlobalAddr(g, o) => format!("global{g}+{o}"),
        }
    }

    fn srcs(&self, ss: &[Src]) -> String {
        ss.iter().map(|x| self.src(*x)).collect::<Vec<_>>().join(", ")
    }

    fn addr(&self, a: Address) -> String {
        let Address { base, offset, wide } = a;
        format!("[{}{offset:+}{}]", self.src(base), if wide { "" } else { " w32" })
    }

    fn comb(&self, c: Option<(BoolOp, PredSrc)>) -> String {
        match c {
            Some((op, p)) => format!(" {} {}", lc(op), self.pred_src(p)),
            None => String::new(),
        }
    }

    fn kind(&self, k: &Kind) -> String {
        match k {
            Kind::Mov { d, a } => format!("mov {} <- {}", self.dst(*d), self.src(*a)),
            Kind::Pack { d, parts, part_bits } => {
                format!("pack.{part_bits} {} <- {{{}}}", self.dst(*d), self.srcs(parts))
            }
            Kind::Unpack { ds, a, part_bits } => {
                format!("unpack.{part_bits} {{{}}} <- {}", self.dsts(ds), self.src(*a))
            }
            Kind::Arith { op, ty, mode, d, a, b, c } => format!(
                "{}.{ty}{} {} <- {}, {}, {}",
                lc(op),
                float_mode(*mode),
                self.dst(*d),
                self.src(*a),
                self.src(*b),
                self.src(*c)
            ),
            Kind::Setp { cmp, ty, p, q, a, b, comb, ftz } => format!(
                "setp.{}.{ty}{} {}{} <- {}, {}{}",
                lc(cmp),
                if *ftz { ".ftz" } else { "" },
                self.pred(*p),
                q.map(|q| format!("|{}", self.pred(q))).unwrap_or_default(),
                self.src(*a),
                self.src(*b),
                self.comb(*comb)
            ),
            Kind::Set { cmp, dty, sty, d, a, b, comb, ftz } => format!(
                "set.{}.{dty}.{sty}{} {} <- {}, {}{}",
                lc(cmp),
                if *ftz { ".ftz" } else { "" },
                self.dst(*d),
                self.src(*a),
                self.src(*b),
                self.comb(*comb)
            ),
            Kind::Bfi { ty, d, a, b, c, e } => format!(
                "bfi.{ty} {} <- {}, {}, {}, {}",
                self.dst(*d),
                self.src(*a),
                self.src(*b),
                self.src(*c),
                self.src(*e)
            ),
            Kind::Selp { d, a, b, p } => {
                format!("selp {} <- {}, {}, {}", self.dst(*d), self.src(*a), self.src(*b), self.pred_src(*p))
            }
            Kind::PredLogic { op, d, a, b } => format!(
                "pred.{} {} <- {}, {}",
                op.map(lc).unwrap_or_else(|| "mov".into()),
                self.pred(*d),
                self.pred_src(*a),
                self.pred_src(*b)
            ),
            Kind::Cvt { dty, sty, mode, d, a } => {
                format!("cvt.{dty}.{sty}{} {} <- {}", float_mode(*mode), self.dst(*d), self.src(*a))
            }
            Kind::Cvta { to_generic, space, d, a } => format!(
                "cvta.{}.{} {} <- {}",
                if *to_generic { "to_generic" } else { "from_generic" },
                lc(space),
                self.dst(*d),
                self.src(*a)
            ),
            Kind::Ld { space, ty, ds, addr, nc, volatile } => format!(
                "ld.{}.{ty}{}{} {{{}}} <- {}",
                lc(space),
                if *nc { ".nc" } else { "" },
                if *volatile { ".volatile" } else { "" },
                self.dsts(ds),
                self.addr(*addr)
            ),
            Kind::St { space, ty, vals, addr, volatile } => format!(
                "st.{}.{ty}{} {} <- {{{}}}",
                lc(space),
                if *volatile { ".volatile" } else { "" },
                self.addr(*addr),
                self.srcs(vals)
            ),
            Kind::Atom { space, op, ty, d, addr, b, c } => format!(
                "atom.{}.{}.{ty} {} <- {}, {}, {}",
                lc(space),
                lc(op),
                d.map(|d| self.dst(d)).unwrap_or_else(|| "(red)".into()),
                self.addr(*addr),
                self.src(*b),
                self.src(*c)
            ),
            Kind::Bra { target, uni } => format!("bra{} {target}", if *uni { ".uni" } else { "" }),
            Kind::Call { func, args, rets } => format!("call f{func} args {args:?} rets {rets:?}"),
            Kind::CallIndirect { target, args, rets } => {
                format!("call.indirect {} args {args:?} rets {rets:?}", self.src(*target))
            }
            Kind::Tex { geom, gather, dty, cty, ds, handle, coords } => format!(
                "{}.{}.{dty}.{cty} {{{}}} <- [{}, {{{}}}]",
                gather.map(|c| format!("tld4.{}", ["r", "g", "b", "a"][c as usize])).unwrap_or_else(|| "tex".into()),
                lc(geom),
                self.dsts(ds),
                self.src(*handle),
                self.srcs(coords)
            ),
            Kind::Txq { query, d, handle } => format!("txq.{} {} <- [{}]", lc(query), self.dst(*d), self.src(*handle)),
            Kind::Suld { geom, ty, ds, handle, coords, clamp } => format!(
                "suld.{}.{ty}.{} {{{}}} <- [{}, {{{}}}]",
                lc(geom),
                lc(clamp),
                self.dsts(ds),
                self.src(*handle),
                self.srcs(coords)
            ),
            Kind::Sust { geom, ty, vals, handle, coords, clamp, red } => format!(
                "{}.{}.{ty}.{} [{}, {{{}}}] <- {{{}}}",
                red.map_or("sust".to_string(), |op| format!("sured.{}", lc(op))),
                lc(geom),
                lc(clamp),
                self.src(*handle),
                self.srcs(coords),
                self.srcs(vals)
            ),
            Kind::Ret => "ret".into(),
            Kind::Exit => "exit".into(),
            Kind::Bar { id, count } => {
                format!("bar {}{}", self.src(*id), count.map(|c| format!(", {}", self.src(c))).unwrap_or_default())
            }
            Kind::Vote { mode, d, p, a, membermask } => format!(
                "vote.{} {} {} <- {}, mask {}",
                lc(mode),
                d.map(|d| self.dst(d)).unwrap_or_else(|| "-".into()),
                self.pred(*p),
                self.pred_src(*a),
                self.member_mask(*membermask)
            ),
            Kind::Shfl { mode, d, p, a, b, c, membermask } => format!(
                "shfl.{} {}{} <- {}, {}, {}, mask {}",
                lc(mode),
                self.dst(*d),
                p.map(|p| format!("|{}", self.pred(p))).unwrap_or_default(),
                self.src(*a),
                self.src(*b),
                self.src(*c),
                self.member_mask(*membermask)
            ),
            Kind::Redux { op, ty, d, a, membermask } => {
                format!("redux.{}.{ty} {} <- {}, mask {}", lc(op), self.dst(*d), self.src(*a), self.src(*membermask))
            }
            Kind::Match { all, ty, d, p, a, membermask } => format!(
                "match.{}.{ty} {}{} <- {}, mask {}",
                if *all { "all" } else { "any" },
                self.dst(*d),
                p.map(|p| format!("|{}", self.pred(p))).unwrap_or_default(),
                self.src(*a),
                self.src(*membermask)
            ),
            Kind::Carry { op, cin, cout, ty, d, a, b, c, cc } => format!(
                "carry.{}{}{}.{ty} {} <- {}, {}, {} ({})",
                lc(op),
                if *cin { ".cin" } else { "" },
                if *cout { ".cout" } else { "" },
                self.dst(*d),
                self.src(*a),
                self.src(*b),
                self.src(*c),
                self.reg(*cc)
            ),
            Kind::BarRed { op, d, p, id, count, a } => format!(
                "bar.red.{} {} {} <- {}{}, {}",
                lc(op),
                d.map(|d| self.dst(d)).unwrap_or_else(|| "-".into()),
                self.pred(*p),
                self.src(*id),
                count.map(|c| format!(", {}", self.src(c))).unwrap_or_default(),
                self.pred_src(*a)
            ),
            Kind::WarpSync { membermask } => format!("warpsync mask {}", self.src(*membermask)),
            Kind::Membar => "membar".into(),
            Kind::Nop => "nop".into(),
            Kind::Trap => "trap".into(),
        }
    }
}

/// `.rn.ftz.sat.approx` for the modifiers that are set.
fn float_mode(m: FloatMode) -> String {
    let FloatMode { rnd, ftz, sat, approx, full } = m;
    let mut s = String::new();
    if let Some(r) = rnd {
        s.push('.');
        s.push_str(&lc(r));
    }
    for (on, w) in [(ftz, ".ftz"), (sat, ".sat"), (approx && !full, ".approx"), (full, ".full")] {
        if on {
            s.push_str(w);
        }
    }
    s
}

/// A special register as PTX writes it.
fn special(r: SpecialReg) -> String {
    let dim = |d: u8| ["x", "y", "z"].get(d as usize).copied().unwrap_or("?");
    match r {
        SpecialReg::Tid(d) => format!("%tid.{}", dim(d)),
        SpecialReg::Ntid(d) => format!("%ntid.{}", dim(d)),
        SpecialReg::Ctaid(d) => format!("%ctaid.{}", dim(d)),
        SpecialReg::Nctaid(d) => format!("%nctaid.{}", dim(d)),
        other => format!("%{}", lc(other)),
    }
}
