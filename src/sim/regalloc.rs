//! Register allocation at decode time: which row of a warp's register frame
//! each PTX virtual register lives in.
//!
//! The front end declares one virtual register per value (`%f<410>`,
//! `%r<298>`, ...), and a frame with one 32-lane row per virtual register is
//! mostly dead rows: the ray tracer's `trace_stack` declares about 820 and
//! has far fewer live at any point. As `ptxas` does, a liveness analysis
//! over the function's CFG gives each register the instructions at which it
//! is live, and a linear scan over those intervals assigns registers to
//! slots so that two registers live at the same instruction never share one.
//!
//! **Why the results stay bit-identical.** Each lane of a warp executes its
//! own thread's path through the CFG (the SIMT stack only interleaves the
//! paths), and every instruction writes only its executing lanes. So a
//! thread's liveness holds lane by lane: a register that is live in a lane
//! was last written by that lane's own definition, and no other register
//! shares its slot at that point. Two kinds of read see a register where it
//! is not live, and those registers keep a slot of their own for the whole
//! function (*pinned*), so that they read exactly the values they did with
//! one row per register:
//! - a register read before any definition on some path (live at the
//!   function's entry): it reads the zeros of a fresh frame, or what the
//!   previous call of the function left in a reused frame;
//! - the source of `shfl`, which reads other lanes, also inactive or exited
//!   ones.
//!
//! A definition *kills* (ends the live range above it) only when it writes
//! every executing lane: a guarded instruction, `redux` and `match` (which
//! write the member lanes) do not kill, so their registers stay live across
//! them and no other register is placed in the lanes they leave alone.
//! A `call` reads and writes no register of the caller (arguments travel
//! through the parameter area, and the callee has its own frame), so live
//! ranges simply span it.
//!
//! **Two classes of rows.** Registers of 32 bits or fewer (most of a ray
//! tracer's: `%r`, `%f`, `%h`) get *narrow* rows of 32-bit lanes, the others
//! wide rows of 64-bit lanes; the scan keeps a pool of slots per class, and
//! a slot never changes class, so a frame is its wide rows followed by its
//! narrow ones ([`Allocation::wide`]). A narrow row holds exactly what a
//! wide row would: every write is truncated to the register's width, so a
//! wide row of such a register holds a zero-extended value. The executor's
//! narrow forms work on half the bytes of the wide ones.
//!
//! **Adding an instruction.** Its register fields must be visited by
//! `Kind::visit_regs_mut` (renaming and liveness come from there); if its
//! handler writes fewer than all executing lanes, it must not kill (`effect`
//! in this file); if it reads registers of other lanes, those registers must
//! be pinned ([`Allocation::compact`]). An instruction's sources and
//! destinations never share a slot, so a handler may write a destination
//! before it has read every source.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use super::cfg::Cfg;
use super::contract::Fused;
use crate::ptx::ir::{Function, Inst, Kind, RegId, Src};

/// The widest register mask that a narrow (32-bit) row holds.
pub const NARROW_MASK: u64 = 0xFFFF_FFFF;

/// Where each virtual register of one function lives in a frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Allocation {
    /// The slot (frame row) of each virtual register, indexed by the IR's
    /// [`RegId`]. A register no instruction names gets slot 0 and is never read.
    pub slot: Vec<RegId>,
    /// Rows a frame of the function needs.
    pub rows: u32,
    /// Of them, the 64-bit rows: slots `0..wide`. The slots from `wide` on
    /// are *narrow* rows of 32-bit lanes, given only to registers of 32 bits
    /// or fewer ([`NARROW_MASK`]), whose values always fit them.
    pub wide: u32,
    /// Registers that keep a slot of their own for the whole function (see
    /// the module documentation), in increasing order.
    pub pinned: Vec<RegId>,
}

impl Allocation {
    /// One row per virtual register, in declaration order (no compaction),
    /// every row wide.
    pub fn identity(f: &Function) -> Allocation {
        let n = f.reg_masks.len();
        Allocation { slot: (0..n as RegId).collect(), rows: n as u32, wide: n as u32, pinned: Vec::new() }
    }

    /// Compacts the registers of `f` by liveness over `cfg` and a linear scan.
    /// `fused` are the contracted `add`/`sub` instructions, which read their
    /// `mul`'s factors at their own PC.
    pub fn compact(f: &Function, cfg: &Cfg, fused: &HashMap<u32, Fused>) -> Allocation {
        let n = f.reg_masks.len();
        let live = Liveness::intervals(f, cfg, fused);
        let end = f.insts.len() as u32;
        let (mut start, mut stop) = (live.start, live.end);
        let mut pinned: Vec<RegId> = live.entry.iter().collect();
        for i in &f.insts {
            if let Kind::Shfl { a: Src::Reg(r), .. } = i.kind {
                pinned.push(r);
            }
        }
        pinned.sort_unstable();
        pinned.dedup();
        for &r in &pinned {
            start[r as usize] = 0;
            stop[r as usize] = end;
        }
        // linear scan over intervals sorted by start; the lowest free slot
        // of the register's class (wide, narrow) first
        let mut order: Vec<usize> = (0..n).filter(|&r| start[r] <= stop[r]).collect();
        order.sort_by_key(|&r| (start[r], r));
        let narrow = |r: usize| usize::from(f.reg_masks[r] <= NARROW_MASK);
        let mut slot = vec![0 as RegId; n];
        let mut active: BinaryHeap<Reverse<(u32, usize, RegId)>> = BinaryHeap::new();
        let mut free: [BinaryHeap<Reverse<RegId>>; 2] = Default::default();
        let mut rows = [0u32; 2];
        for r in order {
            while let Some(&Reverse((e, c, s))) = active.peek() {
                if e >= start[r] {
                    break;
                }
                active.pop();
                free[c].push(Reverse(s));
            }
            let c = narrow(r);
            let s = match free[c].pop() {
                Some(Reverse(s)) => s,
                None => {
                    rows[c] += 1;
                    (rows[c] - 1) as RegId
                }
            };
            slot[r] = s;
            active.push(Reverse((stop[r], c, s)));
        }
        // the narrow rows follow the wide ones
        for (r, s) in slot.iter_mut().enumerate() {
            if start[r] <= stop[r] && narrow(r) == 1 {
                *s += rows[0] as RegId;
            }
        }
        Allocation { slot, rows: rows[0] + rows[1], wide: rows[0], pinned }
    }
}

/// A set of registers as a bit vector.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RegSet(Vec<u64>);

impl RegSet {
    fn new(n: usize) -> RegSet {
        RegSet(vec![0; n.div_ceil(64)])
    }

    fn insert(&mut self, r: RegId) {
        self.0[r as usize / 64] |= 1 << (r % 64);
    }

    fn remove(&mut self, r: RegId) {
        self.0[r as usize / 64] &= !(1 << (r % 64));
    }

    /// Whether `r` is in the set.
    pub fn contains(&self, r: RegId) -> bool {
        self.0[r as usize / 64] >> (r % 64) & 1 != 0
    }

    /// `self |= other`; whether it grew.
    fn union(&mut self, other: &RegSet) -> bool {
        let mut grew = false;
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            let n = *a | b;
            grew |= n != *a;
            *a = n;
        }
        grew
    }

    /// The registers in the set, in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = RegId> + '_ {
        self.0.iter().enumerate().flat_map(|(k, &w)| {
            let mut rest = w;
            std::iter::from_fn(move || {
                (rest != 0).then(|| {
                    let b = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    (k * 64 + b) as RegId
                })
            })
        })
    }
}

/// What one instruction does to liveness.
#[derive(Debug, Clone, Default)]
struct Effect {
    /// Registers it reads.
    uses: Vec<RegId>,
    /// Registers it writes.
    defs: Vec<RegId>,
    /// Whether its writes cover every executing lane (then they end the live
    /// range above the instruction).
    kills: bool,
}

fn effect(i: &Inst, fused: Option<&Fused>) -> Effect {
    let mut e = Effect::default();
    let mut k = i.kind.clone();
    k.visit_regs_mut(&mut |r, read, written| {
        if read {
            e.uses.push(*r);
        }
        if written {
            e.defs.push(*r);
        }
    });
    if let Some(fz) = fused {
        for s in [fz.a, fz.b, fz.c] {
            if let Src::Reg(r) = s {
                e.uses.push(r);
            }
        }
    }
    e.kills = i.guard.is_none() && !matches!(i.kind, Kind::Redux { .. } | Kind::Match { .. });
    e
}

/// Liveness of a function's data registers.
#[derive(Debug, Clone)]
pub struct Liveness {
    /// Registers live at each instruction, before it executes (empty from
    /// [`Liveness::intervals`]).
    pub live_in: Vec<RegSet>,
    /// Registers live at the function's entry (read before written on some path).
    pub entry: RegSet,
    /// First instruction at which each register is live or written
    /// (`u32::MAX` when none).
    start: Vec<u32>,
    /// Last such instruction (0 when none).
    end: Vec<u32>,
}

impl Liveness {
    /// Iterative backward dataflow over the blocks of `cfg`, then one pass
    /// over each block's instructions for the registers live before each.
    pub fn of(f: &Function, cfg: &Cfg, fused: &HashMap<u32, Fused>) -> Liveness {
        Liveness::analyse(f, cfg, fused, true)
    }

    /// As [`Liveness::of`] without the sets per instruction (`live_in` is
    /// empty): what the allocator needs, in memory proportional to the blocks.
    pub fn intervals(f: &Function, cfg: &Cfg, fused: &HashMap<u32, Fused>) -> Liveness {
        Liveness::analyse(f, cfg, fused, false)
    }

    fn analyse(f: &Function, cfg: &Cfg, fused: &HashMap<u32, Fused>, per_pc: bool) -> Liveness {
        let n = f.reg_masks.len();
        let effects: Vec<Effect> =
            f.insts.iter().enumerate().map(|(pc, i)| effect(i, fused.get(&(pc as u32)))).collect();
        let nb = cfg.blocks.len();
        // per block: registers used before a killing definition, and killed
        let mut gen_ = vec![RegSet::new(n); nb];
        let mut kill = vec![RegSet::new(n); nb];
        for (b, blk) in cfg.blocks.iter().enumerate() {
            for e in &effects[blk.start as usize..blk.end as usize] {
                for &u in &e.uses {
                    if !kill[b].contains(u) {
                        gen_[b].insert(u);
                    }
                }
                if e.kills {
                    e.defs.iter().for_each(|&d| kill[b].insert(d));
                }
            }
        }
        let mut live_in_b = gen_.clone();
        let mut live_out_b = vec![RegSet::new(n); nb];
        let mut changed = true;
        while changed {
            changed = false;
            for b in (0..nb).rev() {
                let mut out = RegSet::new(n);
                for s in cfg.blocks[b].succs.iter().flatten() {
                    out.union(&live_in_b[*s]);
                }
                let mut inn = out.clone();
                for (w, k) in inn.0.iter_mut().zip(&kill[b].0) {
                    *w &= !k;
                }
                inn.union(&gen_[b]);
                live_out_b[b] = out;
                if inn != live_in_b[b] {
                    live_in_b[b] = inn;
                    changed = true;
                }
            }
        }
        // the intervals: a register's uses and definitions, and the first
        // (last) instruction of each block it is live into (out of) span the
        // instructions at which it is live
        let (mut start, mut end) = (vec![u32::MAX; n], vec![0u32; n]);
        let mut mark = |r: RegId, pc: u32| {
            start[r as usize] = start[r as usize].min(pc);
            end[r as usize] = end[r as usize].max(pc);
        };
        for (b, blk) in cfg.blocks.iter().enumerate() {
            live_in_b[b].iter().for_each(|r| mark(r, blk.start));
            live_out_b[b].iter().for_each(|r| mark(r, blk.end - 1));
            for pc in blk.start..blk.end {
                let e = &effects[pc as usize];
                e.uses.iter().chain(&e.defs).for_each(|&r| mark(r, pc));
            }
        }
        // per instruction, when asked for
        let mut live_in = Vec::new();
        if per_pc {
            live_in = vec![RegSet::new(n); f.insts.len()];
            for (b, blk) in cfg.blocks.iter().enumerate() {
                let mut live = live_out_b[b].clone();
                for pc in (blk.start..blk.end).rev() {
                    let e = &effects[pc as usize];
                    if e.kills {
                        e.defs.iter().for_each(|&d| live.remove(d));
                    }
                    e.uses.iter().for_each(|&u| live.insert(u));
                    live_in[pc as usize] = live.clone();
                }
            }
        }
        let entry = match cfg.blocks.first() {
            Some(b) if b.start == 0 => live_in_b[0].clone(),
            _ => RegSet::new(n),
        };
        Liveness { live_in, entry, start, end }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ptx;

    /// A kernel `k` with `body`, three predicates and eight 32-bit registers.
    fn program(body: &str) -> crate::ptx::Program {
        let src = format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n.entry k(.param .u64 out)\n{{\n.reg .pred %p<3>;\n.reg .b32 %r<8>;\n.reg .b64 %rd<2>;\n{body}\n}}\n"
        );
        ptx::load(&src, "t.ptx").unwrap()
    }

    fn reg(p: &crate::ptx::Program, name: &str) -> RegId {
        p.functions[0].reg_names.iter().position(|n| n == name).unwrap() as RegId
    }

    fn alloc(p: &crate::ptx::Program) -> (Allocation, Liveness) {
        let f = &p.functions[0];
        let cfg = Cfg::build(f);
        let fused = HashMap::new();
        (Allocation::compact(f, &cfg, &fused), Liveness::of(f, &cfg, &fused))
    }

    /// No two registers live before the same instruction, nor a register
    /// written by an instruction and one live across it, share a slot.
    fn assert_no_interference(p: &crate::ptx::Program, a: &Allocation, l: &Liveness) {
        let f = &p.functions[0];
        for (pc, live) in l.live_in.iter().enumerate() {
            let mut regs: Vec<RegId> = live.iter().collect();
            let after = l.live_in.get(pc + 1);
            let mut k = f.insts[pc].kind.clone();
            k.visit_regs_mut(&mut |r, _, w| {
                if w {
                    regs.push(*r);
                    // a definition against everything live after it
                    regs.extend(after.into_iter().flat_map(|s| s.iter()));
                }
            });
            regs.sort_unstable();
            regs.dedup();
            for (i, &x) in regs.iter().enumerate() {
                for &y in &regs[i + 1..] {
                    let (nx, ny) = (&f.reg_names[x as usize], &f.reg_names[y as usize]);
                    assert_ne!(a.slot[x as usize], a.slot[y as usize], "{nx} and {ny} share a slot at pc {pc}");
                }
            }
        }
    }

    #[test]
    fn straight_line_values_reuse_slots() {
        // %r1 dies at the add that defines %r3; %r2 dies at the mul.
        let p = program(
            "mov.u32 %r1, %tid.x;\n mov.u32 %r2, 3;\n add.s32 %r3, %r1, %r2;\n mul.lo.s32 %r4, %r3, %r2;\n \
             add.s32 %r5, %r4, 1;\n add.s32 %r6, %r5, 1;\n ld.param.u64 %rd1, [out];\n st.global.u32 [%rd1], %r6;\n ret;",
        );
        let (a, l) = alloc(&p);
        assert_no_interference(&p, &a, &l);
        // at most three 32-bit values are ever live together (%r3, %r2 and
        // the result): narrow rows; %rd1 has the one wide row, slot 0
        assert!(a.wide == 1 && a.rows - a.wide <= 3, "{} rows, {} wide: {:?}", a.rows, a.wide, a.slot);
        assert_eq!(a.slot[reg(&p, "%rd1") as usize], 0);
        assert!(["%r1", "%r2", "%r3", "%r4", "%r5", "%r6"].iter().all(|r| a.slot[reg(&p, r) as usize] >= 1));
        assert!(a.pinned.is_empty(), "nothing is read before written: {:?}", a.pinned);
        // a value takes a slot freed before its instruction: %r6 the one of
        // %r4 (dead after pc 4), not the one of %r5, which pc 5 reads (an
        // instruction's sources and destination never share a slot)
        let s = |n: &str| a.slot[reg(&p, n) as usize];
        assert_eq!(s("%r6"), s("%r4"));
        assert_ne!(s("%r6"), s("%r5"));
    }

    #[test]
    fn two_registers_live_together_never_share_a_slot() {
        let p = program(
            "mov.u32 %r1, %tid.x;\n mov.u32 %r2, %ctaid.x;\n mov.u32 %r3, 7;\n add.s32 %r4, %r1, %r3;\n \
             add.s32 %r5, %r2, %r4;\n add.s32 %r6, %r1, %r5;\n ld.param.u64 %rd1, [out];\n st.global.u32 [%rd1], %r6;\n ret;",
        );
        let (a, l) = alloc(&p);
        assert_no_interference(&p, &a, &l);
        let s = |n: &str| a.slot[reg(&p, n) as usize];
        // %r1 lives from its mov to the last add: it crosses every other value
        for other in ["%r2", "%r3", "%r4", "%r5"] {
            assert_ne!(s("%r1"), s(other), "%r1 and {other}");
        }
    }

    #[test]
    fn a_register_live_across_a_loop_back_edge_keeps_its_slot_through_the_loop() {
        // %r1 (the bound) is read at the loop's end, so it is live in the
        // whole loop, also at its top, before %r3 (a temporary) is written.
        let p = program(
            "mov.u32 %r1, %tid.x;\n mov.u32 %r2, 0;\nLOOP:\n add.s32 %r3, %r2, 5;\n add.s32 %r2, %r3, 1;\n \
             setp.lt.u32 %p1, %r2, %r1;\n @%p1 bra LOOP;\n ld.param.u64 %rd1, [out];\n st.global.u32 [%rd1], %r2;\n ret;",
        );
        let (a, l) = alloc(&p);
        assert_no_interference(&p, &a, &l);
        let s = |n: &str| a.slot[reg(&p, n) as usize];
        assert_ne!(s("%r1"), s("%r3"));
        assert_ne!(s("%r1"), s("%r2"));
        // %r2 is live at the loop's top (the back edge carries it)
        let top = 2;
        assert!(l.live_in[top].contains(reg(&p, "%r2")) && l.live_in[top].contains(reg(&p, "%r1")));
        assert!(!l.live_in[top].contains(reg(&p, "%r3")), "%r3 is written before it is read in each iteration");
    }

    #[test]
    fn registers_read_before_written_and_shuffle_sources_are_pinned() {
        // %r7 is read with no definition on the path (reads the frame's old
        // contents); %r1 is a shuffle source (read by other, maybe inactive, lanes).
        let p = program(
            "mov.u32 %r1, %tid.x;\n shfl.sync.bfly.b32 %r2, %r1, 1, 31, -1;\n add.s32 %r3, %r2, %r7;\n \
             ld.param.u64 %rd1, [out];\n st.global.u32 [%rd1], %r3;\n ret;",
        );
        let (a, l) = alloc(&p);
        assert_no_interference(&p, &a, &l);
        assert_eq!(a.pinned, vec![reg(&p, "%r1"), reg(&p, "%r7")]);
        let s = |n: &str| a.slot[reg(&p, n) as usize];
        for other in ["%r2", "%r3", "%rd1"] {
            assert_ne!(s("%r1"), s(other));
            assert_ne!(s("%r7"), s(other));
        }
    }

    #[test]
    fn a_guarded_definition_does_not_end_a_live_range() {
        // `@%p1 mov %r2` writes only some lanes: the others keep the %r2
        // written before, so %r2 stays live from its first definition and
        // %r3 (live in between) cannot take its slot.
        let p = program(
            "mov.u32 %r1, %tid.x;\n setp.eq.u32 %p1, %r1, 0;\n mov.u32 %r2, 1;\n add.s32 %r3, %r1, 2;\n \
             @%p1 mov.u32 %r2, %r3;\n ld.param.u64 %rd1, [out];\n st.global.u32 [%rd1], %r2;\n ret;",
        );
        let (a, l) = alloc(&p);
        assert_no_interference(&p, &a, &l);
        assert!(l.live_in[3].contains(reg(&p, "%r2")), "live across the guarded write");
        assert_ne!(a.slot[reg(&p, "%r2") as usize], a.slot[reg(&p, "%r3") as usize]);
        assert!(!l.entry.contains(reg(&p, "%r2")), "the unguarded mov ends its range");
    }

    #[test]
    fn values_live_across_a_call_stay_in_the_callers_slots() {
        let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
            .func (.param .b32 r) g(.param .b32 x)\n{\n.reg .b32 %r<4>;\n\
            ld.param.u32 %r1, [x];\n add.s32 %r2, %r1, 1;\n st.param.b32 [r], %r2;\n ret;\n}\n\
            .entry k(.param .u64 out)\n{\n.reg .b32 %r<6>;\n.reg .b64 %rd<2>;\n\
            mov.u32 %r1, %tid.x;\n mov.u32 %r2, 9;\n\
            { .param .b32 a;\n st.param.b32 [a], %r2;\n .param .b32 b;\n call (b), g, (a);\n ld.param.b32 %r3, [b];\n }\n\
            add.s32 %r4, %r3, %r1;\n ld.param.u64 %rd1, [out];\n st.global.u32 [%rd1], %r4;\n ret;\n}\n";
        let p = ptx::load(src, "t.ptx").unwrap();
        let k = p.functions.iter().position(|f| f.name == "k").unwrap();
        let f = &p.functions[k];
        let cfg = Cfg::build(f);
        let a = Allocation::compact(f, &cfg, &HashMap::new());
        let l = Liveness::of(f, &cfg, &HashMap::new());
        let r = |n: &str| f.reg_names.iter().position(|x| x == n).unwrap() as RegId;
        let call = f.insts.iter().position(|i| matches!(i.kind, Kind::Call { .. })).unwrap();
        assert!(l.live_in[call].contains(r("%r1")), "%r1 is live across the call");
        assert!(!l.live_in[call].contains(r("%r2")), "%r2 went into the argument before it");
        assert_ne!(a.slot[r("%r1") as usize], a.slot[r("%r3") as usize]);
    }

    #[test]
    fn identity_keeps_one_row_per_register() {
        let p = program("mov.u32 %r1, 1;\n ret;");
        let a = Allocation::identity(&p.functions[0]);
        assert_eq!(a.rows as usize, p.functions[0].reg_masks.len());
        assert!(a.slot.iter().enumerate().all(|(i, &s)| s as usize == i));
    }

    /// The visitor sees what [`Kind::reads`] reads, and renaming through it
    /// changes every register field once.
    #[test]
    fn the_register_visitor_agrees_with_reads() {
        let p = program(
            "mov.u32 %r1, %tid.x;\n shfl.sync.bfly.b32 %r2, %r1, 1, 31, -1;\n mov.b64 %rd1, {%r1, %r2};\n \
             mov.b64 {%r3, %r4}, %rd1;\n add.cc.u32 %r5, %r3, %r4;\n addc.u32 %r6, %r3, %r4;\n \
             st.global.v2.u32 [%rd1+8], {%r5, %r6};\n ret;",
        );
        for i in &p.functions[0].insts {
            let mut k = i.kind.clone();
            let mut reads = Vec::new();
            k.visit_regs_mut(&mut |r, rd, _| {
                if rd {
                    reads.push(*r)
                }
            });
            assert_eq!(reads, i.kind.reads(), "{:?}", i.kind);
            let mut renamed = i.kind.clone();
            renamed.visit_regs_mut(&mut |r, _, _| *r += 100);
            // each field renamed exactly once
            let moved: Vec<RegId> = i.kind.reads().iter().map(|r| r + 100).collect();
            assert_eq!(renamed.reads(), moved);
            let mut back = renamed.clone();
            back.visit_regs_mut(&mut |r, _, _| *r -= 100);
            assert_eq!(back, i.kind);
        }
    }
}
