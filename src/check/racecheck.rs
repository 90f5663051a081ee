//! Races: two threads touch the same byte, at least one writes, and nothing
//! orders them. Inside a CTA, barriers order accesses: each warp carries a
//! vector clock ([`Clocks`]) that a completed barrier merges among the warps
//! it released, so the verdict depends on which barriers separate the
//! accesses and never on the order the scheduler happened to run them in
//! (a race that lockstep scheduling hides is reported all the same). Threads
//! of one warp are ordered by barriers and by `bar.warp.sync` (`__syncwarp`)
//! only, as on Volta and later GPUs, where a warp's threads need not run in
//! lockstep: each lane carries a vector clock over its warp's lanes that a
//! warp synchronisation merges among the lanes that passed it together. The
//! lanes of one instruction do not race with each other. Between CTAs nothing
//! orders plain accesses ([`CrossCta`]). Atomics never race.

use std::collections::{BTreeMap, HashMap};

use super::Hazard;
use super::findings::{Findings, Key, Pc, SpaceKey};

/// One instruction's access by one or more lanes of a warp, as the shadow
/// memory remembers it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Acc {
    /// Warp ([`Acc::NONE`]: no access).
    pub warp: u8,
    /// The lanes that accessed (bit per lane; a write: one lane).
    pub lanes: u32,
    /// The warp's own clock when it accessed.
    pub clock: u32,
    /// The lanes' own clock among their warp's lanes when they accessed
    /// ([`Clocks::lane_clock`]; the same for every lane of a slot).
    pub lane_clock: u32,
    /// The warp's memory-instruction count (same value: same instruction).
    pub seq: u32,
    /// The instruction.
    pub pc: Pc,
}

impl Acc {
    /// Warp value of an empty slot.
    pub const NONE: u8 = u8::MAX;
    /// No access.
    pub const EMPTY: Acc = Acc { warp: Acc::NONE, lanes: 0, clock: 0, lane_clock: 0, seq: 0, pc: (0, 0) };

    fn is_some(&self) -> bool {
        self.warp != Acc::NONE
    }
}

/// Reads that no longer fit in a byte's two read slots, merged into one
/// summary that over-approximates them: the warps and lanes that read, and the
/// largest warp and lane clocks among the reads. A later access races with the
/// summary when it might race with one of them, so nothing is missed; the
/// price is a possible report where lanes' own clocks differed (partial
/// `__syncwarp` masks) or warps' clocks differed (barriers of some warps only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lost {
    /// Warps that read (bit per warp; 0: nothing lost).
    pub warps: u32,
    /// Lanes that read, over all those warps.
    pub lanes: u32,
    /// The largest warp clock of the reads.
    pub clock: u32,
    /// The largest lane clock of the reads.
    pub lane_clock: u32,
    /// The first read merged in, named as the other party of a report.
    pub first: Acc,
}

impl Lost {
    /// Nothing lost.
    pub const NONE: Lost = Lost { warps: 0, lanes: 0, clock: 0, lane_clock: 0, first: Acc::EMPTY };

    fn add(&mut self, r: &Acc) {
        if self.warps == 0 {
            self.first = *r;
        }
        self.warps |= 1 << r.warp;
        self.lanes |= r.lanes;
        self.clock = self.clock.max(r.clock);
        self.lane_clock = self.lane_clock.max(r.lane_clock);
    }
}

/// The shadow of one byte: its last write, the reads since then that are not
/// ordered before a later read (two, each one instruction's lanes, and the
/// rest merged into [`Lost`]), and whether anything wrote it (initcheck).
#[derive(Debug, Clone, Copy)]
pub struct Cell {
    /// Last write.
    pub write: Acc,
    /// Reads since the last write, oldest first.
    pub reads: [Acc; 2],
    /// Older reads since the last write that may still race.
    pub lost: Lost,
    /// Written at least once.
    pub init: bool,
}

impl Default for Cell {
    fn default() -> Self {
        Cell { write: Acc::EMPTY, reads: [Acc::EMPTY; 2], lost: Lost::NONE, init: false }
    }
}

/// The vector clocks of one warp's lanes over its lanes (row: lane).
type LaneClocks = [[u32; 32]; 32];

/// One vector clock per warp of a CTA (at most 32 warps), and per lane of a
/// warp one over the warp's lanes (made at the warp's first `bar.warp.sync`;
/// until then every lane's own clock is 1 and it knows nothing of the others).
#[derive(Debug, Clone)]
pub struct Clocks {
    vc: Vec<[u32; 32]>,
    lanes: Vec<Option<Box<LaneClocks>>>,
}

impl Clocks {
    /// Clocks for `warps` warps: each at 1 in its own component.
    pub fn new(warps: usize) -> Self {
        let vc = (0..warps)
            .map(|w| {
                let mut v = [0u32; 32];
                v[w] = 1;
                v
            })
            .collect();
        Clocks { vc, lanes: vec![None; warps] }
    }

    /// Lane `l` of warp `w`'s own clock among the warp's lanes.
    pub fn lane_clock(&self, w: u32, l: u32) -> u32 {
        self.lanes[w as usize].as_ref().map_or(1, |m| m[l as usize][l as usize])
    }

    /// Lanes `mask` of warp `w` passed a `bar.warp.sync` together: each learns
    /// what the others did, then starts a new epoch of its own.
    pub fn warp_sync(&mut self, w: u32, mask: u32) {
        let m = self.lanes[w as usize].get_or_insert_with(|| {
            let mut m = Box::new([[0u32; 32]; 32]);
            for (l, row) in m.iter_mut().enumerate() {
                row[l] = 1;
            }
            m
        });
        let mut merged = [0u32; 32];
        let members = || (0..32usize).filter(|l| mask >> l & 1 != 0);
        for l in members() {
            for (x, y) in merged.iter_mut().zip(&m[l]) {
                *x = (*x).max(*y);
            }
        }
        for l in members() {
            m[l] = merged;
            m[l][l] += 1;
        }
    }

    /// Warp `w`'s own clock.
    pub fn own(&self, w: u32) -> u32 {
        self.vc[w as usize][w as usize]
    }

    /// A barrier released `warps`: each learns what the others did, then
    /// starts a new epoch of its own.
    pub fn barrier(&mut self, warps: &[usize]) {
        let mut m = [0u32; 32];
        for &w in warps {
            for (x, y) in m.iter_mut().zip(&self.vc[w]) {
                *x = (*x).max(*y);
            }
        }
        for &w in warps {
            let mut v = m;
            v[w] += 1;
            self.vc[w] = v;
        }
    }

    /// Of `lanes` of warp `warp`, which read or wrote at a lane clock of
    /// `lane_clock` (or less) that lane `lane` has not learnt of through a
    /// warp synchronisation (bit per lane; `lane` itself excluded).
    fn unsynced(&self, warp: u32, lane: u32, lanes: u32, lane_clock: u32) -> u32 {
        let lanes = lanes & !(1 << lane);
        match &self.lanes[warp as usize] {
            None => lanes,
            Some(m) => {
                (0..32).filter(|l| lanes >> l & 1 != 0 && lane_clock > m[lane as usize][*l]).fold(0, |a, l| a | 1 << l)
            }
        }
    }

    /// The lanes of the earlier access `y` that may happen in either order
    /// with the current access by (`warp`, `lane`) in memory instruction
    /// `seq` (bit per lane; 0: `y` happens before it, or is the same thread or
    /// instruction).
    pub fn concurrent(&self, y: &Acc, warp: u32, lane: u32, seq: u32) -> u32 {
        if !y.is_some() {
            return 0;
        }
        if y.warp as u32 == warp {
            // same warp, another lane: a barrier since orders them, and so does a warp
            // synchronisation of both lanes; one instruction does not race with itself
            if y.clock != self.own(warp) || y.seq == seq {
                return 0;
            }
            return self.unsynced(warp, lane, y.lanes, y.lane_clock);
        }
        if y.clock > self.vc[warp as usize][y.warp as usize] { y.lanes } else { 0 }
    }

    /// Whether one of the reads merged into `lost` may happen in either order
    /// with the current access by (`warp`, `lane`) (over-approximated).
    pub fn lost_concurrent(&self, lost: &Lost, warp: u32, lane: u32) -> bool {
        let others = lost.warps & !(1 << warp);
        let other_warp =
            (0..self.vc.len() as u32).any(|u| others >> u & 1 != 0 && lost.clock > self.vc[warp as usize][u as usize]);
        let own_warp = lost.warps >> warp & 1 != 0
            && lost.clock >= self.own(warp)
            && self.unsynced(warp, lane, lost.lanes, lost.lane_clock) != 0;
        other_warp || own_warp
    }
}

/// The kind of an access.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A load.
    Read,
    /// A store.
    Write,
    /// An atomic (reads and writes; never races).
    Atomic,
}

/// Records the read `x` (one lane) among a byte's reads: the same
/// instruction's other lanes at the same lane clock take it in (so a slot's
/// `lane_clock` is exact for each of its lanes), reads ordered before it are
/// forgotten (whatever races with them races with `x` or was reported), and
/// the oldest read is merged into [`Lost`] when both slots hold reads that
/// may still race. The same instruction's lanes at another lane clock (a
/// partial `__syncwarp` before it) are kept, not forgotten: they are not
/// ordered before `x`, only not racing with it.
fn add_read(clocks: &Clocks, cell: &mut Cell, x: Acc) {
    let (warp, lane) = (x.warp as u32, x.lanes.trailing_zeros());
    let same_inst = |g: &Acc| g.is_some() && g.warp == x.warp && g.seq == x.seq;
    if let Some(g) = cell.reads.iter_mut().find(|g| same_inst(g) && g.lane_clock == x.lane_clock) {
        g.lanes |= x.lanes;
        return;
    }
    for g in &mut cell.reads {
        if !same_inst(g) && clocks.concurrent(g, warp, lane, x.seq) == 0 {
            *g = Acc::EMPTY;
        }
    }
    if cell.lost.warps != 0 && !clocks.lost_concurrent(&cell.lost, warp, lane) {
        cell.lost = Lost::NONE;
    }
    match cell.reads {
        [a, b] if !a.is_some() && !b.is_some() => cell.reads = [x, Acc::EMPTY],
        [a, b] if !b.is_some() => cell.reads = [a, x],
        [a, b] if !a.is_some() => cell.reads = [b, x],
        [a, b] => {
            cell.lost.add(&a);
            cell.reads = [b, x];
        }
    }
}

/// Checks one lane's access to one byte against the byte's shadow and
/// updates it. `x.lanes` holds that one lane. Returns the hazards found, each
/// with the other party (its lanes: those that may race).
pub fn access(clocks: &Clocks, cell: &mut Cell, kind: Kind, x: Acc) -> [Option<(Hazard, Acc)>; 2] {
    let (warp, lane, seq) = (x.warp as u32, x.lanes.trailing_zeros(), x.seq);
    let mut out = [None, None];
    let racing = |y: &Acc| {
        let lanes = clocks.concurrent(y, warp, lane, seq);
        (lanes != 0).then_some(Acc { lanes, ..*y })
    };
    match kind {
        Kind::Atomic => {
            cell.init = true;
        }
        Kind::Write => {
            if let Some(y) = racing(&cell.write) {
                out[0] = Some((Hazard::WriteAfterWrite, y));
            }
            let lost =
                (cell.lost.warps != 0 && clocks.lost_concurrent(&cell.lost, warp, lane)).then_some(cell.lost.first);
            if let Some(y) = cell.reads.iter().find_map(racing).or(lost) {
                out[1] = Some((Hazard::WriteAfterRead, y));
            }
            cell.write = x;
            cell.reads = [Acc::EMPTY; 2];
            cell.lost = Lost::NONE;
            cell.init = true;
        }
        Kind::Read => {
            if let Some(y) = racing(&cell.write) {
                out[0] = Some((Hazard::ReadAfterWrite, y));
            }
            add_read(clocks, cell, x);
        }
    }
    out
}

/// A plain global access of one thread, as the CTA-crossing check sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GAcc {
    /// Linear CTA.
    pub cta: u32,
    /// Warp.
    pub warp: u32,
    /// Lane.
    pub lane: u32,
    /// Instruction.
    pub pc: Pc,
    /// Bytes of the word touched (bit per byte).
    pub bytes: u8,
    /// Bytes per element of the access.
    pub elem: u32,
}

/// Per CTA and round, the first read and first write of each global word
/// (with their order), for the CTA-crossing check.
#[derive(Debug, Default)]
pub struct RoundLog {
    /// word address → (first read, first write), each with its sequence number.
    pub words: HashMap<u64, [Option<(u64, GAcc)>; 2]>,
    next: u64,
}

impl RoundLog {
    /// Notes an access to the word at `word` (an address multiple of 4).
    pub fn note(&mut self, word: u64, write: bool, a: GAcc) {
        let n = self.next;
        self.next += 1;
        let slot = &mut self.words.entry(word).or_default()[write as usize];
        match slot {
            Some((_, b)) if b.warp == a.warp && b.lane == a.lane && b.pc == a.pc => b.bytes |= a.bytes,
            Some(_) => {}
            None => *slot = Some((n, a)),
        }
    }
}

/// The accesses of up to two CTAs per kind to one global word.
#[derive(Debug, Default, Clone, Copy)]
struct Word {
    reads: [Option<GAcc>; 2],
    writes: [Option<GAcc>; 2],
}

fn remember(slots: &mut [Option<GAcc>; 2], a: GAcc) {
    match slots {
        [None, _] => slots[0] = Some(a),
        [Some(x), None] if x.cta != a.cta => slots[1] = Some(a),
        _ => {}
    }
}

/// Plain global accesses of different CTAs to the same bytes in one launch.
#[derive(Debug, Default)]
pub struct CrossCta {
    words: HashMap<u64, Word>,
}

impl CrossCta {
    /// Replays one CTA's round (words in address order, reads and writes of
    /// a word in issue order) and records the hazards with other CTAs.
    pub fn replay(&mut self, log: RoundLog, found: &mut Findings) {
        let sorted: BTreeMap<u64, [Option<(u64, GAcc)>; 2]> = log.words.into_iter().collect();
        for (word, [r, w]) in sorted {
            let mut both: Vec<(u64, bool, GAcc)> = Vec::with_capacity(2);
            if let Some((n, a)) = r {
                both.push((n, false, a));
            }
            if let Some((n, a)) = w {
                both.push((n, true, a));
            }
            both.sort_by_key(|x| x.0);
            let cell = self.words.entry(word).or_default();
            for (_, write, a) in both {
                let clash = |slots: &[Option<GAcc>; 2]| {
                    slots.iter().flatten().find(|o| o.cta != a.cta && o.bytes & a.bytes != 0).copied()
                };
                let mut hit = |h: Hazard, o: GAcc| {
                    let key = Key { hazard: h, space: SpaceKey::Global, at: a.pc, with: Some(o.pc) };
                    let addr = word + a.bytes.trailing_zeros() as u64;
                    found.add(key, a.cta, a.warp, a.lane, Some((o.cta, o.warp, 1 << o.lane)), addr, a.elem);
                };
                if write {
                    if let Some(o) = clash(&cell.writes) {
                        hit(Hazard::WriteAfterWrite, o);
                    }
                    if let Some(o) = clash(&cell.reads) {
                        hit(Hazard::WriteAfterRead, o);
                    }
                    remember(&mut cell.writes, a);
                } else {
                    if let Some(o) = clash(&cell.writes) {
                        hit(Hazard::ReadAfterWrite, o);
                    }
                    remember(&mut cell.reads, a);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn acc(warp: u8, lane: u8, clocks: &Clocks, seq: u32) -> Acc {
        let lane_clock = clocks.lane_clock(warp as u32, lane as u32);
        Acc { warp, lanes: 1 << lane, clock: clocks.own(warp as u32), lane_clock, seq, pc: (0, seq) }
    }

    /// The hazard and the other party's warp and lanes.
    fn war(h: [Option<(Hazard, Acc)>; 2]) -> Option<(u8, u32)> {
        h[1].filter(|x| x.0 == Hazard::WriteAfterRead).map(|x| (x.1.warp, x.1.lanes))
    }

    #[test]
    fn a_partial_warp_sync_orders_only_its_lanes_reads_before_a_write() {
        // v = s[0] by all 32 lanes; lanes 16-31 pass __syncwarp(0xFFFF0000); lane 31 writes:
        // lanes 0-15's reads race with the write (the two reads kept last, lanes 30 and 31,
        // are ordered before it)
        let mut c = Clocks::new(1);
        let mut cell = Cell::default();
        for lane in 0..32 {
            assert_eq!(access(&c, &mut cell, Kind::Read, acc(0, lane, &c, 1)), [None, None]);
        }
        c.warp_sync(0, 0xFFFF_0000);
        let h = access(&c, &mut cell, Kind::Write, acc(0, 31, &c, 2));
        assert_eq!(war(h), Some((0, 0xFFFF)));
        // with the whole warp synchronised, nothing races
        let mut c = Clocks::new(1);
        let mut cell = Cell::default();
        for lane in 0..32 {
            access(&c, &mut cell, Kind::Read, acc(0, lane, &c, 1));
        }
        c.warp_sync(0, u32::MAX);
        assert_eq!(access(&c, &mut cell, Kind::Write, acc(0, 31, &c, 2)), [None, None]);
    }

    #[test]
    fn a_read_by_lanes_at_different_lane_clocks_orders_each_before_a_full_warp_sync() {
        // lanes 0-15 pass __syncwarp(0xFFFF); all 32 lanes read s[0] in one instruction;
        // the whole warp passes __syncwarp(); lane 31 writes: every read is ordered before it
        let mut c = Clocks::new(1);
        let mut cell = Cell::default();
        c.warp_sync(0, 0xFFFF);
        for lane in 0..32 {
            assert_eq!(access(&c, &mut cell, Kind::Read, acc(0, lane, &c, 1)), [None, None]);
        }
        c.warp_sync(0, u32::MAX);
        assert_eq!(access(&c, &mut cell, Kind::Write, acc(0, 31, &c, 2)), [None, None]);
        // the read takes one slot per lane clock, each exact for its lanes
        let mut c = Clocks::new(1);
        let mut cell = Cell::default();
        c.warp_sync(0, 0xFFFF);
        for lane in 0..32 {
            access(&c, &mut cell, Kind::Read, acc(0, lane, &c, 1));
        }
        assert_eq!(cell.reads.map(|r| (r.lanes, r.lane_clock)), [(0xFFFF, 2), (0xFFFF_0000, 1)]);
        // without the full sync, lane 31 has learnt of no other lane's read: they race
        let h = access(&c, &mut cell, Kind::Write, acc(0, 31, &c, 2));
        assert_eq!(war(h), Some((0, 0xFFFF)));
    }

    #[test]
    fn a_read_pushed_out_of_the_slots_still_races() {
        // warps 0, 1, 2 read one after another (unordered): warp 0's read no longer has a slot;
        // a barrier of warps 1-3 orders warps 1 and 2's reads before warp 3's write, not warp 0's
        let mut c = Clocks::new(4);
        let mut cell = Cell::default();
        for w in 0..3 {
            access(&c, &mut cell, Kind::Read, acc(w, 5, &c, 1));
        }
        c.barrier(&[1, 2, 3]);
        let h = access(&c, &mut cell, Kind::Write, acc(3, 0, &c, 1));
        assert_eq!(war(h), Some((0, 1 << 5)));
        // after a barrier of every warp, the same write races with nothing
        let mut c = Clocks::new(4);
        let mut cell = Cell::default();
        for w in 0..3 {
            access(&c, &mut cell, Kind::Read, acc(w, 5, &c, 1));
        }
        c.barrier(&[0, 1, 2, 3]);
        assert_eq!(access(&c, &mut cell, Kind::Write, acc(3, 0, &c, 1)), [None, None]);
    }

    #[test]
    fn reads_ordered_before_a_later_read_are_forgotten() {
        // lane 1 reads, then lanes 1 and 2 synchronise and lane 2 reads: lane 1's read is
        // ordered before lane 2's and leaves the slots; lane 3's read fills the other
        let mut c = Clocks::new(1);
        let mut cell = Cell::default();
        access(&c, &mut cell, Kind::Read, acc(0, 1, &c, 1));
        c.warp_sync(0, 0b110);
        access(&c, &mut cell, Kind::Read, acc(0, 2, &c, 2));
        access(&c, &mut cell, Kind::Read, acc(0, 3, &c, 3));
        assert_eq!(cell.reads.map(|r| r.lanes), [1 << 2, 1 << 3]);
        assert_eq!(cell.lost, Lost::NONE);
    }

    #[test]
    fn a_barrier_orders_warps_and_nothing_else_does() {
        let mut c = Clocks::new(2);
        let mut cell = Cell::default();
        assert_eq!(access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 1)), [None, None]);
        // warp 1 reads what warp 0 wrote, no barrier between: read-after-write
        let h = access(&c, &mut cell, Kind::Read, acc(1, 0, &c, 1));
        assert_eq!(h[0].map(|x| x.0), Some(Hazard::ReadAfterWrite));
        c.barrier(&[0, 1]);
        // after the barrier, warp 0 writing again: ordered with warp 1's read
        assert_eq!(access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 2)), [None, None]);
        // same warp, another lane, another instruction, no barrier: a race
        let h = access(&c, &mut cell, Kind::Read, acc(0, 5, &c, 3));
        assert_eq!(h[0].map(|x| x.0), Some(Hazard::ReadAfterWrite));
        // the same thread never races with itself
        let h = access(&c, &mut cell, Kind::Write, acc(0, 5, &c, 4));
        assert_eq!(h[0].map(|x| x.0), Some(Hazard::WriteAfterWrite)); // with lane 0's write
        assert!(h[1].is_none());
    }

    #[test]
    fn lanes_of_one_instruction_do_not_race() {
        let c = Clocks::new(1);
        let mut cell = Cell::default();
        access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 1));
        assert_eq!(access(&c, &mut cell, Kind::Write, acc(0, 1, &c, 1)), [None, None]);
    }

    #[test]
    fn a_warp_sync_orders_its_lanes_and_no_others() {
        let mut c = Clocks::new(2);
        let mut cell = Cell::default();
        access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 1));
        // lanes 0 and 1 pass a __syncwarp(0b11) together: lane 1 reads lane 0's value
        c.warp_sync(0, 0b11);
        assert_eq!(access(&c, &mut cell, Kind::Read, acc(0, 1, &c, 2)), [None, None]);
        // lane 2 was not in the mask: it races with lane 0's write ...
        let mut other = Cell::default();
        let mut c2 = Clocks::new(1);
        access(&c2, &mut other, Kind::Write, acc(0, 0, &c2, 1));
        c2.warp_sync(0, 0b11);
        let h = access(&c2, &mut other, Kind::Read, acc(0, 2, &c2, 2));
        assert_eq!(h[0].map(|x| x.0), Some(Hazard::ReadAfterWrite));
        // ... and lane 0 writing again after the sync races with lane 1's read before the next one
        let h = access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 3));
        assert_eq!(h[1].map(|x| x.0), Some(Hazard::WriteAfterRead));
        // the sync orders lanes of its own warp only: warp 1 still races with warp 0
        let h = access(&c, &mut cell, Kind::Read, acc(1, 1, &c, 1));
        assert_eq!(h[0].map(|x| x.0), Some(Hazard::ReadAfterWrite));
    }

    #[test]
    fn warp_syncs_order_transitively() {
        let mut c = Clocks::new(1);
        let mut cell = Cell::default();
        access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 1));
        c.warp_sync(0, 0b011); // lanes 0, 1
        c.warp_sync(0, 0b110); // lanes 1, 2: lane 2 now knows lane 0's past
        assert_eq!(access(&c, &mut cell, Kind::Read, acc(0, 2, &c, 2)), [None, None]);
        // a sync of lanes 1 and 2 alone orders nothing lane 0 did after the first one
        access(&c, &mut cell, Kind::Write, acc(0, 0, &c, 3));
        c.warp_sync(0, 0b110);
        let h = access(&c, &mut cell, Kind::Read, acc(0, 2, &c, 4));
        assert_eq!(h[0].map(|x| x.0), Some(Hazard::ReadAfterWrite));
    }

    #[test]
    fn different_ctas_race_on_overlapping_bytes_only() {
        let mut x = CrossCta::default();
        let mut f = Findings::default();
        let g = |cta, bytes| GAcc { cta, warp: 0, lane: 0, pc: (0, 7), bytes, elem: 4 };
        let mut log = RoundLog::default();
        log.note(64, true, g(0, 0b0011));
        x.replay(log, &mut f);
        let mut log = RoundLog::default();
        log.note(64, true, g(1, 0b1100));
        x.replay(log, &mut f);
        assert!(f.map.is_empty());
        let mut log = RoundLog::default();
        log.note(64, false, g(2, 0b0001));
        x.replay(log, &mut f);
        assert_eq!(f.map.keys().map(|k| k.hazard).collect::<Vec<_>>(), [Hazard::ReadAfterWrite]);
    }
}
