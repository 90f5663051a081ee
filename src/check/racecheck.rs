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

/// One access as the shadow memory remembers it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Acc {
    /// Warp ([`Acc::NONE`]: no access).
    pub warp: u8,
    /// Lane.
    pub lane: u8,
    /// The warp's own clock when it accessed.
    pub clock: u32,
    /// The lane's own clock among its warp's lanes when it accessed ([`Clocks::lane_clock`]).
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
    pub const EMPTY: Acc = Acc { warp: Acc::NONE, lane: 0, clock: 0, lane_clock: 0, seq: 0, pc: (0, 0) };

    fn is_some(&self) -> bool {
        self.warp != Acc::NONE
    }

    fn same_thread(&self, o: &Acc) -> bool {
        self.warp == o.warp && self.lane == o.lane
    }
}

/// The shadow of one byte: its last write, its last two reads by different
/// threads since then, and whether anything wrote it (initcheck).
#[derive(Debug, Clone, Copy)]
pub struct Cell {
    /// Last write.
    pub write: Acc,
    /// Last read.
    pub read: Acc,
    /// Last read by another thread than `read`'s.
    pub read2: Acc,
    /// Written at least once.
    pub init: bool,
}

impl Default for Cell {
    fn default() -> Self {
        Cell { write: Acc::EMPTY, read: Acc::EMPTY, read2: Acc::EMPTY, init: false }
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

    /// Whether the earlier access `y` and the current access by (`warp`,
    /// `lane`) in memory instruction `seq` may happen in either order.
    pub fn concurrent(&self, y: &Acc, warp: u32, lane: u32, seq: u32) -> bool {
        if !y.is_some() || (y.warp as u32 == warp && y.lane as u32 == lane) {
            return false;
        }
        if y.warp as u32 == warp {
            // same warp, another lane: a barrier since orders them, and so does a warp
            // synchronisation of both lanes; one instruction does not race with itself
            let synced =
                self.lanes[warp as usize].as_ref().is_some_and(|m| y.lane_clock <= m[lane as usize][y.lane as usize]);
            return y.clock == self.own(warp) && y.seq != seq && !synced;
        }
        y.clock > self.vc[warp as usize][y.warp as usize]
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

/// Checks one lane's access to one byte against the byte's shadow and
/// updates it. Returns the hazards found (with the other party).
pub fn access(clocks: &Clocks, cell: &mut Cell, kind: Kind, x: Acc) -> [Option<(Hazard, Acc)>; 2] {
    let (warp, lane, seq) = (x.warp as u32, x.lane as u32, x.seq);
    let mut out = [None, None];
    match kind {
        Kind::Atomic => {
            cell.init = true;
        }
        Kind::Write => {
            if clocks.concurrent(&cell.write, warp, lane, seq) {
                out[0] = Some((Hazard::WriteAfterWrite, cell.write));
            }
            for r in [cell.read, cell.read2] {
                if out[1].is_none() && clocks.concurrent(&r, warp, lane, seq) {
                    out[1] = Some((Hazard::WriteAfterRead, r));
                }
            }
            cell.write = x;
            cell.read = Acc::EMPTY;
            cell.read2 = Acc::EMPTY;
            cell.init = true;
        }
        Kind::Read => {
            if clocks.concurrent(&cell.write, warp, lane, seq) {
                out[0] = Some((Hazard::ReadAfterWrite, cell.write));
            }
            if cell.read.is_some() && !cell.read.same_thread(&x) {
                cell.read2 = cell.read;
            }
            cell.read = x;
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
        Acc { warp, lane, clock: clocks.own(warp as u32), lane_clock, seq, pc: (0, seq) }
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
