//! The checker as a memory observer: one [`CtaCheck`] per CTA watches its
//! accesses and barriers; the [`Checker`] factory settles what crosses CTAs
//! (global races, global initialisation) at the end of every round, CTA after
//! CTA in index order, so reports do not depend on host threads.

use std::any::Any;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use super::Hazard;
use super::Tools;
use super::findings::{Findings, Key, SpaceKey};
use super::initcheck::{GlobalInit, GlobalInitAccess, LocalInit};
use super::racecheck::{self, Acc, Cell, Clocks, CrossCta, GAcc, RoundLog};
use super::synccheck::Arrivals;
use crate::ptx::ir::MemSpace;
use crate::sim::fidelity::Fidelity;
use crate::sim::observer::{MemEvent, MemObserver, MemOp, ObserverFactory};

/// What all CTAs of a launch share.
#[derive(Debug, Default)]
struct State {
    findings: Findings,
    cross: CrossCta,
    init: GlobalInit,
}

/// Makes the per-CTA checkers of one launch and collects their findings.
pub struct Checker {
    tools: Tools,
    warps: usize,
    block_threads: u32,
    uninit: Arc<GlobalInit>,
    state: Arc<Mutex<State>>,
}

impl Checker {
    /// A checker running `tools` on CTAs of `block` threads; `uninit`: global
    /// ranges (address, bytes) allocated without contents.
    pub fn new(tools: Tools, block: [u32; 3], uninit: &[(u64, u64)]) -> Self {
        let threads = block.iter().product::<u32>();
        let mut init = GlobalInit::default();
        for &(b, l) in uninit {
            init.add(b, l);
        }
        let state = State { init: init.clone(), ..Default::default() };
        Checker {
            tools,
            warps: threads.div_ceil(32) as usize,
            block_threads: threads,
            uninit: Arc::new(init),
            state: Arc::new(Mutex::new(state)),
        }
    }

    /// Everything found (call after the launch; CTAs still resident when it
    /// stopped have handed theirs over as they were dropped).
    pub fn findings(&self) -> Findings {
        std::mem::take(&mut self.state.lock().expect("checker state").findings)
    }
}

impl ObserverFactory for Checker {
    fn create(&self, cta: u32) -> Box<dyn MemObserver> {
        Box::new(CtaCheck {
            cta,
            tools: self.tools,
            threads: self.block_threads,
            clocks: Clocks::new(self.warps),
            seq: vec![0; self.warps],
            shared: Vec::new(),
            global: HashMap::new(),
            local: LocalInit::default(),
            arrivals: Arrivals::new(self.warps),
            round: RoundLog::default(),
            init_log: Vec::new(),
            uninit: self.uninit.clone(),
            found: Findings::default(),
            state: self.state.clone(),
        })
    }

    fn retire(&self, obs: Box<dyn MemObserver>) {
        drop(obs); // CtaCheck hands its findings over when dropped
    }

    fn end_round(&self, observers: &mut [(u32, &mut dyn MemObserver)]) {
        let mut st = self.state.lock().expect("checker state");
        for (_, o) in observers.iter_mut() {
            if let Some(c) = o.as_any_mut().and_then(|a| a.downcast_mut::<CtaCheck>()) {
                c.settle(&mut st);
            }
        }
    }

    fn set_fidelity(&self, _level: Fidelity) {}
}

/// Lanes of warp `w` that exist in a CTA of `threads` threads.
pub fn warp_lanes(threads: u32, w: u32) -> u32 {
    let n = threads.saturating_sub(w * 32).min(32);
    if n == 32 { u32::MAX } else { (1u32 << n) - 1 }
}

/// Shared-memory shadow page size (bytes).
const PAGE: usize = 256;

/// The shadow of shared byte `addr`, its page made on first touch.
fn shared_cell(pages: &mut Vec<Option<Box<[Cell]>>>, addr: u64) -> &mut Cell {
    let (page, off) = (addr as usize / PAGE, addr as usize % PAGE);
    if pages.len() <= page {
        pages.resize_with(page + 1, || None);
    }
    &mut pages[page].get_or_insert_with(|| vec![Cell::default(); PAGE].into_boxed_slice())[off]
}

/// The checker of one CTA.
pub struct CtaCheck {
    cta: u32,
    tools: Tools,
    threads: u32,
    clocks: Clocks,
    /// Memory instructions issued per warp.
    seq: Vec<u32>,
    /// Shared-memory shadow, in pages made on first touch.
    shared: Vec<Option<Box<[Cell]>>>,
    /// Global-memory shadow of this CTA's accesses (races between its warps).
    global: HashMap<u64, Cell>,
    local: LocalInit,
    arrivals: Arrivals,
    round: RoundLog,
    init_log: Vec<GlobalInitAccess>,
    uninit: Arc<GlobalInit>,
    found: Findings,
    state: Arc<Mutex<State>>,
}

impl CtaCheck {
    /// Hands this round's cross-CTA accesses and the findings to the launch.
    fn settle(&mut self, st: &mut State) {
        st.cross.replay(std::mem::take(&mut self.round), &mut st.findings);
        for a in std::mem::take(&mut self.init_log) {
            if a.write {
                st.init.write(a.addr, a.bytes);
            } else if st.init.read_uninit(a.addr, a.bytes) {
                let key = Key { hazard: Hazard::UninitializedRead, space: SpaceKey::Global, at: a.pc, with: None };
                st.findings.add(key, self.cta, a.warp, a.lane, None, a.addr, a.elem);
            }
        }
        st.findings.merge(std::mem::take(&mut self.found));
    }

    /// Races and initialisation of shared memory (and races of this CTA's
    /// warps on global memory) for one lane's access.
    #[allow(clippy::too_many_arguments)]
    fn byte_checks(&mut self, space: MemSpace, ev: &MemEvent, lane: u32, kind: racecheck::Kind, seq: u32) {
        let warp = ev.warp;
        let x = Acc {
            warp: warp as u8,
            lanes: 1 << lane,
            clock: self.clocks.own(warp),
            lane_clock: self.clocks.lane_clock(warp, lane),
            seq,
            pc: (ev.func, ev.pc),
        };
        let base = ev.addrs[lane as usize];
        let race = self.tools.racecheck;
        let uninit_check = self.tools.initcheck && space == MemSpace::Shared && kind == racecheck::Kind::Read;
        let mut seen = [false; 4];
        for b in 0..ev.bytes as u64 {
            let addr = base + b;
            let cell = match space {
                MemSpace::Shared => shared_cell(&mut self.shared, addr),
                _ => self.global.entry(addr).or_default(),
            };
            let uninit = uninit_check && !cell.init;
            let hits = if race {
                racecheck::access(&self.clocks, cell, kind, x)
            } else {
                if kind != racecheck::Kind::Read {
                    cell.init = true;
                }
                [None, None]
            };
            let sk = SpaceKey::of(space);
            if uninit && !seen[3] {
                seen[3] = true;
                let key = Key { hazard: Hazard::UninitializedRead, space: sk, at: x.pc, with: None };
                self.found.add(key, self.cta, warp, lane, None, addr, ev.elem_bytes);
            }
            for (h, y) in hits.into_iter().flatten() {
                let slot = match h {
                    Hazard::ReadAfterWrite => 0,
                    Hazard::WriteAfterRead => 1,
                    _ => 2,
                };
                if std::mem::replace(&mut seen[slot], true) {
                    continue;
                }
                let key = Key { hazard: h, space: sk, at: x.pc, with: Some(y.pc) };
                let other = Some((self.cta, y.warp as u32, y.lanes));
                self.found.add(key, self.cta, warp, lane, other, addr, ev.elem_bytes);
            }
        }
    }
}

impl MemObserver for CtaCheck {
    fn access(&mut self, ev: &MemEvent) {
        let kind = match ev.op {
            MemOp::Load => racecheck::Kind::Read,
            MemOp::Store => racecheck::Kind::Write,
            MemOp::Atomic | MemOp::Reduction => racecheck::Kind::Atomic,
        };
        let seq = {
            let s = &mut self.seq[ev.warp as usize];
            *s += 1;
            *s
        };
        let lanes = (0..32u32).filter(|l| ev.mask >> l & 1 != 0);
        match ev.space {
            MemSpace::Shared if self.tools.racecheck || self.tools.initcheck => {
                for lane in lanes {
                    self.byte_checks(MemSpace::Shared, ev, lane, kind, seq);
                }
            }
            MemSpace::Global => {
                let track_init = self.tools.initcheck && !self.uninit.is_empty();
                for lane in lanes {
                    let addr = ev.addrs[lane as usize];
                    if self.tools.racecheck {
                        self.byte_checks(MemSpace::Global, ev, lane, kind, seq);
                        if kind != racecheck::Kind::Atomic {
                            let mut a = addr;
                            while a < addr + ev.bytes as u64 {
                                let word = a & !3;
                                let end = (word + 4).min(addr + ev.bytes as u64);
                                let bytes = (((1u32 << (end - a)) - 1) << (a - word)) as u8;
                                let g = GAcc {
                                    cta: self.cta,
                                    warp: ev.warp,
                                    lane,
                                    pc: (ev.func, ev.pc),
                                    bytes,
                                    elem: ev.elem_bytes,
                                };
                                self.round.note(word, kind == racecheck::Kind::Write, g);
                                a = end;
                            }
                        }
                    }
                    if track_init && self.uninit.tracks(addr) {
                        self.init_log.push(GlobalInitAccess {
                            warp: ev.warp,
                            lane,
                            pc: (ev.func, ev.pc),
                            addr,
                            bytes: ev.bytes,
                            elem: ev.elem_bytes,
                            write: kind != racecheck::Kind::Read,
                        });
                    }
                }
            }
            MemSpace::Local if self.tools.initcheck => {
                for lane in lanes {
                    let off = ev.addrs[lane as usize];
                    if kind == racecheck::Kind::Read {
                        if !self.local.is_written(ev.warp, lane, off, ev.bytes) {
                            let key = Key {
                                hazard: Hazard::UninitializedRead,
                                space: SpaceKey::Local,
                                at: (ev.func, ev.pc),
                                with: None,
                            };
                            self.found.add(key, self.cta, ev.warp, lane, None, off, ev.elem_bytes);
                        }
                    } else {
                        self.local.write(ev.warp, lane, off, ev.bytes);
                    }
                }
            }
            _ => {}
        }
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }

    fn as_any_mut(&mut self) -> Option<&mut dyn Any> {
        Some(self)
    }

    fn barrier_arrive(&mut self, warp: u32, func: u32, pc: u32, _id: u32) {
        if self.tools.synccheck {
            self.arrivals.arrive(warp, (func, pc));
        }
    }

    fn texture_access(&mut self, ev: &MemEvent) {
        // texels and surface elements are global memory: races and initialisation as for ld/st
        self.access(ev);
    }

    fn warp_sync(&mut self, warp: u32, lanes: u32) {
        if self.tools.racecheck {
            self.clocks.warp_sync(warp, lanes);
        }
    }

    fn barrier_release(&mut self, _id: u32, warps: &[usize]) {
        self.clocks.barrier(warps);
        if self.tools.synccheck {
            let threads = self.threads;
            self.arrivals.release(warps, self.cta, |w| warp_lanes(threads, w), &mut self.found);
        }
    }
}

impl Drop for CtaCheck {
    fn drop(&mut self) {
        // a poisoned lock means another CTA's checker panicked: nothing to add to
        let state = self.state.clone();
        if let Ok(mut st) = state.lock() {
            self.settle(&mut st);
        }
    }
}
