//! A register cap and its spills, modelled on the PTX (Table 6.5 (b), L2825:
//! "The rendering kernel uses 61 registers in the baseline and 67 for the
//! compact BVH representation. […] we force the register count to 64,
//! spilling some information into slow local memory instead").
//!
//! The emulator runs PTX, whose virtual registers have no cap; ptxas decides
//! what a capped kernel spills. This module models that decision, not
//! ptxas's: the **demand** of a kernel is the most 32-bit register words live
//! at once (the liveness of [`crate::sim::regalloc::Liveness`] over the PTX as
//! written, a `.b64` counting two words, predicates apart as GT200 keeps them
//! in condition registers); under a cap below the demand, registers are
//! spilled everywhere, one at a time, each time the one live at the most
//! pressed instruction with the fewest executed reads and writes per
//! instruction it is live across, until no instruction needs more words than
//! the cap. Every executed read of a spilled register is then a 4-byte
//! local load per word and lane, every write a local store: the spill traffic
//! of a launch follows from its per-instruction counts.

use std::collections::HashMap;

use crate::ptx::ir::{Function, RegId};
use crate::sim::cfg::Cfg;
use crate::sim::counters::InstCounts;
use crate::sim::regalloc::Liveness;

/// 32-bit words of register `r` of `f`.
fn words(f: &Function, r: RegId) -> u32 {
    if f.reg_masks[r as usize] > u32::MAX as u64 { 2 } else { 1 }
}

/// Per instruction: the registers it reads and writes.
fn refs(f: &Function) -> Vec<(Vec<RegId>, Vec<RegId>)> {
    f.insts
        .iter()
        .map(|i| {
            let (mut u, mut d) = (Vec::new(), Vec::new());
            i.kind.clone().visit_regs_mut(&mut |r, read, written| {
                if read {
                    u.push(*r);
                }
                if written {
                    d.push(*r);
                }
            });
            (u, d)
        })
        .collect()
}

/// Which registers a cap spills, and the demand without it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SpillPlan {
    /// The most register words live at once without a cap.
    pub demand: u32,
    /// The cap applied.
    pub cap: u32,
    /// Registers kept in local memory.
    pub spilled: Vec<RegId>,
}

/// Register words live at (before or written by) each instruction of `f`.
pub fn pressure(f: &Function) -> Vec<u32> {
    let live = Liveness::of(f, &Cfg::build(f), &HashMap::new());
    let r = refs(f);
    (0..f.insts.len())
        .map(|pc| {
            let mut set: Vec<RegId> = live.live_in[pc].iter().collect();
            for &d in &r[pc].1 {
                if !set.contains(&d) {
                    set.push(d);
                }
            }
            set.iter().map(|&x| words(f, x)).sum()
        })
        .collect()
}

/// The registers of `f` spilled under `cap` words, weighing each register's
/// references by `counts` (executions per instruction; the static count when
/// `None`).
pub fn plan(f: &Function, cap: u32, counts: Option<&[InstCounts]>) -> SpillPlan {
    let live = Liveness::of(f, &Cfg::build(f), &HashMap::new());
    let r = refs(f);
    let n = f.reg_masks.len();
    let pcs = f.insts.len();
    // the registers at each instruction, and each register's weight
    let at: Vec<Vec<RegId>> = (0..pcs)
        .map(|pc| {
            let mut set: Vec<RegId> = live.live_in[pc].iter().collect();
            for &d in &r[pc].1 {
                if !set.contains(&d) {
                    set.push(d);
                }
            }
            set
        })
        .collect();
    let mut span = vec![0u64; n];
    let mut used = vec![0u64; n];
    for (pc, set) in at.iter().enumerate() {
        for &x in set {
            span[x as usize] += 1;
        }
        let times = counts.map_or(1, |c| c.get(pc).map_or(0, |c| c.warp));
        for &x in r[pc].0.iter().chain(&r[pc].1) {
            used[x as usize] += times;
        }
    }
    let mut press: Vec<u32> = at.iter().map(|s| s.iter().map(|&x| words(f, x)).sum()).collect();
    let demand = press.iter().copied().max().unwrap_or(0);
    let mut spilled = Vec::new();
    let mut is_spilled = vec![false; n];
    while let Some((worst, p)) = press.iter().copied().enumerate().max_by_key(|&(i, p)| (p, std::cmp::Reverse(i))) {
        if p <= cap {
            break;
        }
        // the cheapest register live there: fewest references per instruction spanned
        let Some(&victim) = at[worst].iter().filter(|&&x| !is_spilled[x as usize]).min_by(|&&a, &&b| {
            let ca = used[a as usize] as f64 / span[a as usize].max(1) as f64;
            let cb = used[b as usize] as f64 / span[b as usize].max(1) as f64;
            ca.total_cmp(&cb).then(a.cmp(&b))
        }) else {
            break;
        };
        is_spilled[victim as usize] = true;
        spilled.push(victim);
        for (pc, set) in at.iter().enumerate() {
            if set.contains(&victim) {
                press[pc] -= words(f, victim);
            }
        }
    }
    spilled.sort_unstable();
    SpillPlan { demand, cap, spilled }
}

/// Spill traffic of a launch in bytes: (local loads, local stores), from its
/// per-instruction counts of `f` (active lanes per execution).
pub fn traffic(f: &Function, plan: &SpillPlan, counts: &[InstCounts]) -> (u64, u64) {
    if plan.spilled.is_empty() {
        return (0, 0);
    }
    let r = refs(f);
    let (mut ld, mut st) = (0u64, 0u64);
    for (pc, c) in counts.iter().enumerate().take(r.len()) {
        for &x in &r[pc].0 {
            if plan.spilled.binary_search(&x).is_ok() {
                ld += 4 * words(f, x) as u64 * c.thread;
            }
        }
        for &x in &r[pc].1 {
            if plan.spilled.binary_search(&x).is_ok() {
                st += 4 * words(f, x) as u64 * c.pred_on;
            }
        }
    }
    (ld, st)
}
