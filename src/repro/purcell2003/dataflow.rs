//! Table 2's instruction classes read off the PTX by data flow: texture
//! fetches (TEX), stream inputs, address arithmetic (Addr) and bit packing
//! (Pack), the categories Cg 1.1's fp30 counts were given in (004:L190–197,
//! L199–203).
//!
//! The rules, per function, over the lowered instructions:
//! - **Stream**: a load from global memory whose address is a function of
//!   the thread's index alone and that runs at most once per thread: the
//!   address register has exactly one definition reaching the load, that
//!   definition is *thread-indexed* (below) and depends on `%tid`, `%ctaid`
//!   or `%laneid`, and the load's basic block lies on no cycle of the
//!   control-flow graph. It reads an element of the launch's input chosen
//!   by the thread's index alone, before any data is known (a
//!   data-independent gather, once per thread): what a 2003 pass drawn as one
//!   point per element received as that vertex's attributes, laid out by the
//!   host, instead of fetching it (stencil routing draws every photon as a
//!   point, 004:L116, from the photon texture read back to the CPU,
//!   L126–128). Whether a pass *could* receive it so is the pass's, not the
//!   load's: a screen-sized quad (004:L51) or a tile of large points gives
//!   its fragments only values interpolated from vertices shared by many of
//!   them, so every per-element datum is fetched there (see
//!   `table_2::Drawn`).
//! - **TEX**: every other load from global (or generic) memory, the fetch of
//!   a fragment program: an address that depends on loaded data, on a loop's
//!   state, on a merge of control paths, or a load in a loop.
//! - **Addr**: an instruction (not a memory access, not control) whose
//!   results feed memory addresses *only*: every use of every register it
//!   writes is the address of a load, store or atomic, or an instruction that
//!   is itself Addr, and at least one such chain ends at an address. An index
//!   that also feeds anything else (a comparison, a stored value, the loop's
//!   state) is not address arithmetic. Data flow passes through data
//!   registers and through predicates into `selp` / `set` / `setp`'s combiner
//!   (a clamp of an index is address arithmetic); guards and branches
//!   (control dependence) are uses of another kind.
//! - **Pack**: a bit-level instruction that is not Addr: `mov` into or out of
//!   a vector of parts, `bfe`, `bfi`, `prmt`, `and`, `or`, `xor`, `not`,
//!   `shl`, `shr`, and conversions to or from 16-bit floats (`cvt` with an
//!   `f16` / `bf16` side, `cvt.rn.f16x2.f32`): what packing state into a
//!   128-bit output and unpacking it again costs.
//! - everything else is **Other**.
//!
//! A value is *thread-indexed* when it is computed (a `mov`, arithmetic,
//! comparison, `selp`, conversion: not a load of memory, not a warp-wide
//! operation) from immediates, addresses of variables, kernel parameters
//! (`ld.param`), the special registers `%tid`, `%ntid`, `%ctaid`, `%nctaid`
//! and `%laneid`, and other thread-indexed values, each register or
//! predicate it reads (its guard included) reached by exactly one
//! definition. A value reached by two definitions depends on the path
//! taken (a loop counter, a merge after a branch) and is not
//! thread-indexed; this part is flow-sensitive (reaching definitions over
//! the control-flow graph), since compilers reuse a register for an index
//! and for a loop-carried value.
//!
//! The Addr analysis treats registers flow-insensitively (every write of a
//! register reaches every read of it), which is exact for the
//! single-assignment PTX compilers emit apart from loop-carried moves, and
//! errs only towards "not address-only" there.

use std::collections::HashMap;

use crate::ptx::ir::{ArithOp, Function, Kind, MemSpace, Program, SpecialReg, Src};
use crate::ptx::types::Ty;
use crate::sim::cfg::Cfg;
use crate::sim::{LaunchStats, Module};

/// The class of one instruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// A global-memory load: a texture fetch.
    Tex,
    /// A global-memory load at an address that is a function of the thread's
    /// index alone, once per thread: a stream input (a vertex attribute of a
    /// pass drawn as one point per element).
    Stream,
    /// Address arithmetic.
    Addr,
    /// Bit packing.
    Pack,
    /// Anything else.
    Other,
}

/// A value an instruction writes or reads: a data register or a predicate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Var {
    R(u16),
    P(u16),
}

/// How an instruction uses a value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Use {
    /// As the address of a memory access.
    Address,
    /// As a data operand (flows on to the instruction's results).
    Data,
    /// As anything else: a stored value, a guard, a branch condition.
    Sink,
}

fn is_memory(space: MemSpace) -> bool {
    !matches!(space, MemSpace::KernelParam | MemSpace::FrameParam)
}

/// The values an instruction writes ([`Kind::writes`], [`Kind::pred_writes`]).
fn writes(k: &Kind) -> Vec<Var> {
    k.writes().into_iter().map(Var::R).chain(k.pred_writes().into_iter().map(Var::P)).collect()
}

/// The values an instruction reads, with how it uses each.
fn uses(inst: &crate::ptx::ir::Inst) -> Vec<(Var, Use)> {
    let mut v = Vec::new();
    if let Some(g) = inst.guard {
        v.push((Var::P(g.reg), Use::Sink));
    }
    let reg = |s: &Src| if let Src::Reg(r) = s { Some(Var::R(*r)) } else { None };
    match &inst.kind {
        Kind::Ld { space, addr, .. } => {
            let u = if is_memory(*space) { Use::Address } else { Use::Sink };
            v.extend(reg(&addr.base).map(|x| (x, u)));
        }
        Kind::St { space, vals, addr, .. } => {
            v.extend(vals.iter().filter_map(reg).map(|x| (x, Use::Sink)));
            let u = if is_memory(*space) { Use::Address } else { Use::Sink };
            v.extend(reg(&addr.base).map(|x| (x, u)));
        }
        Kind::Atom { space, addr, b, c, .. } => {
            v.extend([b, c].into_iter().filter_map(reg).map(|x| (x, Use::Sink)));
            let u = if is_memory(*space) { Use::Address } else { Use::Sink };
            v.extend(reg(&addr.base).map(|x| (x, u)));
        }
        // a texture or surface access: its handle and coordinates address memory
        Kind::Tex { handle, coords, .. } | Kind::Suld { handle, coords, .. } => {
            v.extend(std::iter::once(handle).chain(coords.iter()).filter_map(reg).map(|x| (x, Use::Address)));
        }
        Kind::Txq { handle, .. } => v.extend(reg(handle).map(|x| (x, Use::Address))),
        Kind::Sust { vals, handle, coords, .. } => {
            v.extend(vals.iter().filter_map(reg).map(|x| (x, Use::Sink)));
            v.extend(std::iter::once(handle).chain(coords.iter()).filter_map(reg).map(|x| (x, Use::Address)));
        }
        k => {
            // every other instruction: its data sources flow into its results
            let flows =
                !writes(k).is_empty() && !matches!(k, Kind::Shfl { .. } | Kind::Redux { .. } | Kind::Vote { .. });
            let u = if flows { Use::Data } else { Use::Sink };
            v.extend(k.reads().into_iter().map(|r| (Var::R(r), u)));
            match k {
                Kind::Selp { p, .. } => v.push((Var::P(p.reg), Use::Data)),
                Kind::Setp { comb: Some((_, p)), .. } | Kind::Set { comb: Some((_, p)), .. } => {
                    v.push((Var::P(p.reg), Use::Data))
                }
                Kind::PredLogic { a, b, .. } => {
                    v.push((Var::P(a.reg), Use::Data));
                    v.push((Var::P(b.reg), Use::Data));
                }
                Kind::Vote { a, .. } | Kind::BarRed { a, .. } => v.push((Var::P(a.reg), Use::Sink)),
                _ => {}
            }
        }
    }
    v
}

/// Whether an instruction can be address arithmetic: it computes values
/// (not a memory access, control, or a warp-wide operation).
fn computes(k: &Kind) -> bool {
    matches!(
        k,
        Kind::Mov { .. }
            | Kind::Pack { .. }
            | Kind::Unpack { .. }
            | Kind::Arith { .. }
            | Kind::Setp { .. }
            | Kind::Set { .. }
            | Kind::Bfi { .. }
            | Kind::Selp { .. }
            | Kind::PredLogic { .. }
            | Kind::Cvt { .. }
            | Kind::Cvta { .. }
            | Kind::Carry { .. }
    )
}

/// Whether an instruction manipulates bits (packing or unpacking).
fn is_bit_op(k: &Kind) -> bool {
    let half = |t: Ty| matches!(t, Ty::F16 | Ty::BF16 | Ty::F16x2 | Ty::BF16x2);
    match k {
        Kind::Pack { .. } | Kind::Unpack { .. } | Kind::Bfi { .. } => true,
        Kind::Arith { op, .. } => matches!(
            op,
            ArithOp::And
                | ArithOp::Or
                | ArithOp::Xor
                | ArithOp::Not
                | ArithOp::Shl
                | ArithOp::Shr
                | ArithOp::Bfe
                | ArithOp::Prmt
                | ArithOp::PrmtF4e
                | ArithOp::PrmtB4e
                | ArithOp::PrmtRc8
                | ArithOp::PrmtEcl
                | ArithOp::PrmtEcr
                | ArithOp::PrmtRc16
                | ArithOp::ShfLWrap
                | ArithOp::ShfLClamp
                | ArithOp::ShfRWrap
                | ArithOp::ShfRClamp
                | ArithOp::CvtPack
        ),
        Kind::Cvt { dty, sty, .. } => half(*dty) || half(*sty),
        _ => false,
    }
}

/// A special register's part in a thread-indexed value: `Some(true)` for a
/// thread's own index (it varies between threads), `Some(false)` for a launch
/// constant, `None` for anything else (clocks, the SM, lane masks).
fn special(s: SpecialReg) -> Option<bool> {
    match s {
        SpecialReg::Tid(_) | SpecialReg::Ctaid(_) | SpecialReg::LaneId => Some(true),
        SpecialReg::Ntid(_) | SpecialReg::Nctaid(_) => Some(false),
        _ => None,
    }
}

/// The operands of a computing instruction or a load (its address base), as written.
fn operands(k: &Kind) -> Vec<Src> {
    match k {
        Kind::Mov { a, .. } | Kind::Cvt { a, .. } | Kind::Cvta { a, .. } | Kind::Unpack { a, .. } => vec![*a],
        Kind::Pack { parts, .. } => parts.clone(),
        Kind::Arith { a, b, c, .. } | Kind::Carry { a, b, c, .. } => vec![*a, *b, *c],
        Kind::Setp { a, b, .. } | Kind::Set { a, b, .. } | Kind::Selp { a, b, .. } => vec![*a, *b],
        Kind::Bfi { a, b, c, e, .. } => vec![*a, *b, *c, *e],
        Kind::Ld { addr, .. } => vec![addr.base],
        _ => Vec::new(),
    }
}

/// Reaching definitions of a function's values over its control-flow graph.
struct Reaching {
    /// Definitions of each value: (instruction, or `None` for the value's
    /// undefined state at entry, index into the bit sets).
    defs_of: HashMap<Var, Vec<(Option<usize>, usize)>>,
    /// Per instruction, the definitions reaching it (bit set over definition indices).
    at: Vec<Vec<u64>>,
}

impl Reaching {
    fn of(f: &Function, cfg: &Cfg) -> Reaching {
        let n = f.insts.len();
        let mut defs_of: HashMap<Var, Vec<(Option<usize>, usize)>> = HashMap::new();
        let mut count = 0usize;
        let mut def = |v: Var, pc: Option<usize>, defs_of: &mut HashMap<Var, Vec<(Option<usize>, usize)>>| {
            defs_of.entry(v).or_default().push((pc, count));
            count += 1;
        };
        for inst in &f.insts {
            for (v, _) in uses(inst) {
                if !defs_of.contains_key(&v) {
                    def(v, None, &mut defs_of);
                }
            }
            for v in writes(&inst.kind) {
                if !defs_of.contains_key(&v) {
                    def(v, None, &mut defs_of);
                }
            }
        }
        let mut own: Vec<Vec<(Var, usize)>> = vec![Vec::new(); n];
        for (pc, inst) in f.insts.iter().enumerate() {
            for v in writes(&inst.kind) {
                def(v, Some(pc), &mut defs_of);
                own[pc].push((v, defs_of[&v].last().expect("just pushed").1));
            }
        }
        let words = count.div_ceil(64);
        let set = |bits: &mut Vec<u64>, i: usize, on: bool| {
            if on { bits[i / 64] |= 1 << (i % 64) } else { bits[i / 64] &= !(1 << (i % 64)) }
        };
        // one instruction's effect: an unguarded write kills the value's other definitions
        let step = |bits: &mut Vec<u64>, pc: usize| {
            for &(v, d) in &own[pc] {
                if f.insts[pc].guard.is_none() {
                    for &(_, o) in &defs_of[&v] {
                        set(bits, o, false);
                    }
                }
                set(bits, d, true);
            }
        };
        let nb = cfg.blocks.len();
        let mut preds: Vec<Vec<usize>> = vec![Vec::new(); nb];
        for (b, blk) in cfg.blocks.iter().enumerate() {
            for s in blk.succs.iter().flatten() {
                preds[*s].push(b);
            }
        }
        let mut entry = vec![0u64; words];
        for ds in defs_of.values() {
            for &(pc, d) in ds {
                if pc.is_none() {
                    set(&mut entry, d, true);
                }
            }
        }
        let mut out: Vec<Vec<u64>> = vec![vec![0u64; words]; nb];
        let block_in = |b: usize, out: &[Vec<u64>]| {
            let mut bits = if b == 0 { entry.clone() } else { vec![0u64; words] };
            for &p in &preds[b] {
                for (x, y) in bits.iter_mut().zip(&out[p]) {
                    *x |= y;
                }
            }
            bits
        };
        let mut changed = true;
        while changed {
            changed = false;
            for (b, blk) in cfg.blocks.iter().enumerate() {
                let mut bits = block_in(b, &out);
                for pc in blk.start as usize..blk.end as usize {
                    step(&mut bits, pc);
                }
                if bits != out[b] {
                    out[b] = bits;
                    changed = true;
                }
            }
        }
        let mut at = vec![Vec::new(); n];
        for (b, blk) in cfg.blocks.iter().enumerate() {
            let mut bits = block_in(b, &out);
            let (start, end) = (blk.start as usize, blk.end as usize);
            for (pc, reaching) in at.iter_mut().enumerate().take(end).skip(start) {
                *reaching = bits.clone();
                step(&mut bits, pc);
            }
        }
        Reaching { defs_of, at }
    }

    /// The one definition of `v` reaching instruction `pc` (`None`: several,
    /// or only the undefined state at entry).
    fn single(&self, pc: usize, v: Var) -> Option<usize> {
        let bits = &self.at[pc];
        let mut reaching = self.defs_of.get(&v)?.iter().filter(|&&(_, d)| (bits[d / 64] >> (d % 64)) & 1 == 1);
        match (reaching.next(), reaching.next()) {
            (Some(&(Some(_), d)), None) => Some(d),
            _ => None,
        }
    }
}

/// Which instructions of `f` are stream inputs ([`Class::Stream`]; the
/// module's documentation gives the rule).
fn stream_loads(f: &Function) -> Vec<bool> {
    let n = f.insts.len();
    let cfg = Cfg::build(f);
    let r = Reaching::of(f, &cfg);
    // per definition: thread-indexed, and whether it varies with the thread (least fixed point)
    let total = r.defs_of.values().map(|d| d.len()).sum::<usize>();
    let mut site: Vec<Option<usize>> = vec![None; total];
    for ds in r.defs_of.values() {
        for &(pc, d) in ds {
            site[d] = pc;
        }
    }
    let mut indexed = vec![false; total];
    let mut varies = vec![false; total];
    let mut changed = true;
    while changed {
        changed = false;
        for (d, &at) in site.iter().enumerate() {
            let Some(pc) = at else { continue };
            if indexed[d] {
                continue;
            }
            let inst = &f.insts[pc];
            let k = &inst.kind;
            let param = matches!(k, Kind::Ld { space: MemSpace::KernelParam | MemSpace::FrameParam, .. });
            if !(param || computes(k)) {
                continue;
            }
            let mut ok = true;
            let mut var = false;
            let mut read = |v: Var| match r.single(pc, v) {
                Some(e) if indexed[e] => var |= varies[e],
                _ => ok = false,
            };
            for reg in k.reads() {
                read(Var::R(reg));
            }
            // predicates read as data, and the guard
            for (v, _) in uses(inst) {
                if let Var::P(_) = v {
                    read(v);
                }
            }
            for s in operands(k) {
                if let Src::Special(sr) = s {
                    match special(sr) {
                        Some(v) => var |= v,
                        None => ok = false,
                    }
                }
            }
            if ok {
                indexed[d] = true;
                varies[d] = var;
                changed = true;
            }
        }
    }
    // blocks on a cycle of the control-flow graph
    let on_cycle = |b: usize| {
        let mut seen = vec![false; cfg.blocks.len()];
        let mut stack: Vec<usize> = cfg.blocks[b].succs.iter().flatten().copied().collect();
        while let Some(x) = stack.pop() {
            if x == b {
                return true;
            }
            if !std::mem::replace(&mut seen[x], true) {
                stack.extend(cfg.blocks[x].succs.iter().flatten().copied());
            }
        }
        false
    };
    (0..n)
        .map(|pc| match &f.insts[pc].kind {
            Kind::Ld { space: MemSpace::Global, addr: crate::ptx::ir::Address { base: Src::Reg(b), .. }, .. } => {
                r.single(pc, Var::R(*b)).is_some_and(|d| indexed[d] && varies[d])
                    && !on_cycle(cfg.block_of[pc] as usize)
            }
            _ => false,
        })
        .collect()
}

/// The class of every instruction of `f`.
pub fn classify(f: &Function) -> Vec<Class> {
    let n = f.insts.len();
    let mut users: HashMap<Var, Vec<(usize, Use)>> = HashMap::new();
    for (i, inst) in f.insts.iter().enumerate() {
        for (var, u) in uses(inst) {
            users.entry(var).or_default().push((i, u));
        }
    }
    let outs: Vec<Vec<Var>> = f.insts.iter().map(|i| writes(&i.kind)).collect();
    let uses_of = |i: usize| outs[i].iter().flat_map(|v| users.get(v).into_iter().flatten().copied());
    // greatest set of instructions whose every use is an address or another member
    let mut addr: Vec<bool> = (0..n).map(|i| computes(&f.insts[i].kind) && uses_of(i).next().is_some()).collect();
    let mut changed = true;
    while changed {
        changed = false;
        for i in 0..n {
            if addr[i] && !uses_of(i).all(|(j, u)| u == Use::Address || (u == Use::Data && addr[j])) {
                addr[i] = false;
                changed = true;
            }
        }
    }
    // of those, the ones whose chains end at an address (not a closed cycle)
    let mut reach: Vec<bool> = (0..n).map(|i| addr[i] && uses_of(i).any(|(_, u)| u == Use::Address)).collect();
    changed = true;
    while changed {
        changed = false;
        for i in 0..n {
            if addr[i] && !reach[i] && uses_of(i).any(|(j, _)| reach[j]) {
                reach[i] = true;
                changed = true;
            }
        }
    }
    let stream = stream_loads(f);
    f.insts
        .iter()
        .enumerate()
        .map(|(i, inst)| match &inst.kind {
            Kind::Ld { space: MemSpace::Global | MemSpace::Generic, .. } if stream[i] => Class::Stream,
            Kind::Ld { space: MemSpace::Global | MemSpace::Generic, .. } => Class::Tex,
            _ if reach[i] => Class::Addr,
            k if is_bit_op(k) => Class::Pack,
            _ => Class::Other,
        })
        .collect()
}

/// The classes of every function of `prog` (indexed as `prog.functions`).
pub fn classify_program(prog: &Program) -> Vec<Vec<Class>> {
    prog.functions.iter().map(classify).collect()
}

/// Thread instructions of one launch by class (lanes active at each
/// instruction, summed; TEX counts the guard-true lanes, as the loads do).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClassCounts {
    /// Lane-level global loads that are fetches ([`Class::Tex`]).
    pub tex: u64,
    /// Lane-level global loads that are stream inputs ([`Class::Stream`]).
    pub stream: u64,
    /// Thread instructions of address arithmetic.
    pub addr: u64,
    /// Thread instructions of bit packing.
    pub pack: u64,
}

impl ClassCounts {
    /// Adds another's counts.
    pub fn merge(&mut self, o: &ClassCounts) {
        self.tex += o.tex;
        self.stream += o.stream;
        self.addr += o.addr;
        self.pack += o.pack;
    }
}

/// The counts of a launch of `module` whose instructions are classed `classes`
/// (from [`classify_program`] of the module's program), from the emulator's
/// per-instruction profile.
pub fn count(classes: &[Vec<Class>], s: &LaunchStats) -> ClassCounts {
    let mut c = ClassCounts::default();
    for (f, counts) in s.profile.per_fn.iter().enumerate() {
        let Some(cl) = classes.get(f) else { continue };
        for (pc, ic) in counts.iter().enumerate() {
            match cl.get(pc) {
                Some(Class::Tex) => c.tex += ic.pred_on,
                Some(Class::Stream) => c.stream += ic.pred_on,
                Some(Class::Addr) => c.addr += ic.thread,
                Some(Class::Pack) => c.pack += ic.thread,
                _ => {}
            }
        }
    }
    c
}

/// The static class counts of one kernel: its instructions, each once.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StaticCounts {
    /// Instructions.
    pub instructions: usize,
    /// Fetches ([`Class::Tex`]).
    pub tex: usize,
    /// Stream inputs ([`Class::Stream`]).
    pub stream: usize,
    /// Address arithmetic.
    pub addr: usize,
    /// Bit packing.
    pub pack: usize,
}

/// The static class counts of kernel `name` of `module` (instructions in its body, each once).
pub fn static_counts(module: &Module, name: &str) -> Option<StaticCounts> {
    let f = module.prog.functions.iter().find(|f| f.name == name)?;
    let cl = classify(f);
    let k = |c: Class| cl.iter().filter(|&&x| x == c).count();
    Some(StaticCounts {
        instructions: cl.len(),
        tex: k(Class::Tex),
        stream: k(Class::Stream),
        addr: k(Class::Addr),
        pack: k(Class::Pack),
    })
}
