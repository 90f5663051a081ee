//! Who updates which address with global atomics: a count of the sharing
//! that makes atomics contend, without timing. Lanes of one warp-level
//! atomic on one address are served one after another (the hardware
//! serialises them: `atomics.rs`); warps updating one address meet at the L2
//! slice that owns it, in an order the emulator does not model. This tally
//! counts both kinds of sharing over everything it observes (one launch, if
//! attached to one): per address the lane updates and whether more than one
//! warp made them. Its sums do not depend on the order CTAs run or retire in.
//! Counted: `atom` and `red` whose lanes resolve to global memory (generic
//! addresses included); not counted: surface reductions (`sured`, the
//! texture path). Warps are keyed by CTA and warp, so attach it to one
//! launch at a time (or one frame of launches where one alone makes
//! atomics): the same warp of two launches counts as one.

use std::any::Any;
use std::collections::HashMap;
use std::sync::Mutex;

use crate::ptx::ir::MemSpace;
use crate::sim::Fidelity;
use crate::sim::observer::{MemEvent, MemObserver, MemOp, ObserverFactory};

/// Updates of one address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Updates {
    /// Lane updates.
    lanes: u64,
    /// The first warp seen updating it (CTA << 10 | warp).
    warp: u64,
    /// Whether another warp updated it too.
    shared: bool,
}

impl Updates {
    fn merge(&mut self, o: Updates) {
        self.lanes += o.lanes;
        self.shared |= o.shared || o.warp != self.warp;
    }
}

/// What the tally saw.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct AtomicSharing {
    /// Warp-level global atomics and reductions.
    pub instructions: u64,
    /// Lane updates they made.
    pub lane_updates: u64,
    /// Distinct addresses updated.
    pub addresses: u64,
    /// Lane updates to an address another lane of the same instruction also
    /// updated, beyond the first (serialised within the warp).
    pub same_instruction_repeats: u64,
    /// Addresses updated by more than one warp.
    pub shared_addresses: u64,
    /// Lane updates to those addresses.
    pub shared_lane_updates: u64,
    /// The most lane updates of one address.
    pub max_per_address: u64,
}

/// One CTA's tally.
#[derive(Default)]
struct CtaTally {
    per_address: HashMap<u64, Updates>,
    instructions: u64,
    repeats: u64,
    /// Scratch: one instruction's lane addresses.
    lanes: Vec<u64>,
}

impl MemObserver for CtaTally {
    fn access(&mut self, ev: &MemEvent) {
        if ev.space != MemSpace::Global || !matches!(ev.op, MemOp::Atomic | MemOp::Reduction) {
            return;
        }
        self.instructions += 1;
        let warp = (ev.cta as u64) << 10 | ev.warp as u64;
        self.lanes.clear();
        self.lanes.extend((0..32).filter(|l| ev.mask >> l & 1 == 1).map(|l| ev.addrs[l]));
        self.lanes.sort_unstable();
        let before = self.lanes.len();
        self.lanes.dedup();
        self.repeats += (before - self.lanes.len()) as u64;
        for l in (0..32).filter(|l| ev.mask >> l & 1 == 1) {
            self.per_address
                .entry(ev.addrs[l])
                .and_modify(|u| u.merge(Updates { lanes: 1, warp, shared: false }))
                .or_insert(Updates { lanes: 1, warp, shared: false });
        }
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
}

/// An [`ObserverFactory`] tallying global atomics by address over every
/// launch it observes (fidelity `memory` or above).
#[derive(Default)]
pub struct AtomicTally {
    merged: Mutex<CtaTally>,
}

impl AtomicTally {
    /// An empty tally.
    pub fn new() -> Self {
        Self::default()
    }

    /// What it has seen so far.
    pub fn sharing(&self) -> AtomicSharing {
        let t = self.merged.lock().unwrap_or_else(|p| p.into_inner());
        let mut s = AtomicSharing {
            instructions: t.instructions,
            same_instruction_repeats: t.repeats,
            addresses: t.per_address.len() as u64,
            ..AtomicSharing::default()
        };
        for u in t.per_address.values() {
            s.lane_updates += u.lanes;
            s.max_per_address = s.max_per_address.max(u.lanes);
            if u.shared {
                s.shared_addresses += 1;
                s.shared_lane_updates += u.lanes;
            }
        }
        s
    }
}

impl ObserverFactory for AtomicTally {
    fn create(&self, _cta: u32) -> Box<dyn MemObserver> {
        Box::new(CtaTally::default())
    }

    fn retire(&self, obs: Box<dyn MemObserver>) {
        let Ok(cta) = obs.into_any().downcast::<CtaTally>() else { return };
        let mut t = self.merged.lock().unwrap_or_else(|p| p.into_inner());
        t.instructions += cta.instructions;
        t.repeats += cta.repeats;
        for (a, u) in cta.per_address {
            t.per_address.entry(a).and_modify(|m| m.merge(u)).or_insert(u);
        }
    }

    fn set_fidelity(&self, _level: Fidelity) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(op: MemOp, space: MemSpace, mask: u32, addrs: &[u64; 32], cta: u32, warp: u32) -> MemEvent<'_> {
        MemEvent { func: 0, pc: 0, op, space, nc: false, bytes: 4, elem_bytes: 4, mask, addrs, cta, warp }
    }

    #[test]
    fn counts_repeats_within_an_instruction_and_sharing_between_warps() {
        let tally = AtomicTally::new();
        // CTA 0 warp 0: lanes 0-3 on addresses 8, 8, 8, 16 (two repeats)
        let mut a = [0u64; 32];
        a[..4].copy_from_slice(&[8, 8, 8, 16]);
        let mut o = tally.create(0);
        o.access(&event(MemOp::Reduction, MemSpace::Global, 0b1111, &a, 0, 0));
        // a load and a shared atomic are not counted
        o.access(&event(MemOp::Load, MemSpace::Global, 0b1111, &a, 0, 0));
        o.access(&event(MemOp::Atomic, MemSpace::Shared, 0b1111, &a, 0, 0));
        tally.retire(o);
        // CTA 1 warp 0: lane 0 on 16 (shared with CTA 0), lane 1 on 24
        let mut b = [0u64; 32];
        b[..2].copy_from_slice(&[16, 24]);
        let mut o = tally.create(1);
        o.access(&event(MemOp::Atomic, MemSpace::Global, 0b11, &b, 1, 0));
        tally.retire(o);
        let s = tally.sharing();
        assert_eq!(
            s,
            AtomicSharing {
                instructions: 2,
                lane_updates: 6,
                addresses: 3,
                same_instruction_repeats: 2,
                shared_addresses: 1,
                shared_lane_updates: 2,
                max_per_address: 3,
            }
        );
    }

    #[test]
    fn three_warps_in_two_ctas_merge_in_any_order() {
        // warps 0 and 1 of CTA 0 and warp 0 of CTA 1 each add once to address 8;
        // warp 1 of CTA 0 alone to 16
        let one = |a: u64| {
            let mut x = [0u64; 32];
            x[0] = a;
            x
        };
        let (a8, a16) = (one(8), one(16));
        let run = |order: [u32; 2]| {
            let tally = AtomicTally::new();
            for cta in order {
                let mut o = tally.create(cta);
                o.access(&event(MemOp::Reduction, MemSpace::Global, 1, &a8, cta, 0));
                if cta == 0 {
                    o.access(&event(MemOp::Reduction, MemSpace::Global, 1, &a8, 0, 1));
                    o.access(&event(MemOp::Reduction, MemSpace::Global, 1, &a16, 0, 1));
                }
                tally.retire(o);
            }
            tally.sharing()
        };
        let s = run([0, 1]);
        assert_eq!(s, run([1, 0]));
        assert_eq!((s.lane_updates, s.addresses, s.shared_addresses, s.shared_lane_updates), (4, 2, 1, 3));
        assert_eq!(s.max_per_address, 3);
    }

    #[test]
    fn the_order_ctas_retire_in_does_not_matter() {
        let mut a = [0u64; 32];
        a[0] = 64;
        let run = |order: [u32; 2]| {
            let tally = AtomicTally::new();
            for cta in order {
                let mut o = tally.create(cta);
                o.access(&event(MemOp::Reduction, MemSpace::Global, 1, &a, cta, 0));
                tally.retire(o);
            }
            tally.sharing()
        };
        assert_eq!(run([0, 1]), run([1, 0]));
        assert_eq!(run([0, 1]).shared_addresses, 1);
    }
}
