//! Counter models per device generation: they observe the simulator's memory
//! events ([`crate::sim::MemEvent`]) and count what the memory system of a
//! GT200, a Maxwell or a Hopper GPU would see — requests, sectors or
//! segment transactions, shared-memory wavefronts and bank conflicts, cache
//! hits — per launch and per instruction. Rules and sources: `docs/devices.md`.
//!
//! ```
//! use warplight::model::{Model, Profile};
//! use warplight::sim::{Arg, Device, LaunchConfig};
//! let mut dev = Device::new();
//! let m = dev.load_ptx(&std::fs::read_to_string("kernels/tests/memory.ptx").unwrap(), "memory.ptx").unwrap();
//! let out = dev.alloc_zeroed::<i32>(64);
//! let model = Model::new(Profile::Hopper, &m.prog);
//! dev.launch_observed(&m, "partial_warp", LaunchConfig::linear(2, 32), &[Arg::Ptr(out)], Some(&model)).unwrap();
//! let stats = model.finish();
//! assert_eq!(stats.counters.global_st.sectors, 8); // 2 warps x 128 contiguous bytes
//! ```

pub mod atomic_tally;
pub mod atomics;
pub mod banks;
pub mod cache;
pub mod coalesce_gt200;
pub mod explain;
pub mod occupancy;
pub mod profile;
pub mod sectors;
pub mod uniform;
pub mod validation;
pub mod validation_suite;
pub mod vectorize;

use std::any::Any;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::ptx::Program;
use crate::ptx::ir::MemSpace;
use crate::sim::counters::Counters;
use crate::sim::{Fidelity, MemEvent, MemObserver, MemOp, ObserverFactory};
pub use occupancy::{Occupancy, occupancy};
pub use profile::Profile;

/// Counts of one kind of global, local or texture access.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct AccessCounts {
    /// Warp-level instructions.
    pub instructions: u64,
    /// Requests to the memory pipeline (one per warp instruction on sector profiles;
    /// one per half-warp transaction group on GT200).
    pub requests: u64,
    /// 32-byte sectors (sector profiles) or transactions (GT200).
    pub sectors: u64,
    /// GT200 transactions by size.
    pub t32: u64,
    /// 64-byte transactions.
    pub t64: u64,
    /// 128-byte transactions.
    pub t128: u64,
    /// Bytes the threads asked for.
    pub bytes: u64,
    /// Sector lookups that hit in the modelled cache (L1 or texture).
    pub hits: u64,
    /// Sector lookups that missed.
    pub misses: u64,
}

impl AccessCounts {
    fn merge(&mut self, o: &AccessCounts) {
        self.instructions += o.instructions;
        self.requests += o.requests;
        self.sectors += o.sectors;
        self.t32 += o.t32;
        self.t64 += o.t64;
        self.t128 += o.t128;
        self.bytes += o.bytes;
        self.hits += o.hits;
        self.misses += o.misses;
    }
}

/// Counts of shared (or constant) memory accesses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct BankCounts {
    /// Warp-level instructions.
    pub instructions: u64,
    /// Passes through the banks.
    pub wavefronts: u64,
    /// Passes beyond the minimum for the access width.
    pub bank_conflicts: u64,
}

impl BankCounts {
    fn merge(&mut self, o: &BankCounts) {
        self.instructions += o.instructions;
        self.wavefronts += o.wavefronts;
        self.bank_conflicts += o.bank_conflicts;
    }
}

/// Memory counters of a launch under one profile.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct MemCounters {
    /// Global loads (read-only loads too where the profile has no texture path).
    pub global_ld: AccessCounts,
    /// Global stores.
    pub global_st: AccessCounts,
    /// Local loads.
    pub local_ld: AccessCounts,
    /// Local stores.
    pub local_st: AccessCounts,
    /// Read-only loads through the texture path (`ld.global.nc` on GT200 and Maxwell).
    pub texture: AccessCounts,
    /// Global atomics with a result.
    pub global_atom: AccessCounts,
    /// Global reductions (atomics without a result).
    pub global_red: AccessCounts,
    /// Shared loads.
    pub shared_ld: BankCounts,
    /// Shared stores.
    pub shared_st: BankCounts,
    /// Shared atomics.
    pub shared_atom: BankCounts,
    /// Constant loads: wavefronts = serialized passes over distinct addresses.
    pub const_ld: BankCounts,
    /// Parameter loads and stores (warp level).
    pub param: u64,
    /// Warp instructions that serialized on shared or constant conflicts (GT200's `warp_serialize`).
    pub warp_serialize: u64,
}

impl MemCounters {
    fn merge(&mut self, o: &MemCounters) {
        for (a, b) in [
            (&mut self.global_ld, &o.global_ld),
            (&mut self.global_st, &o.global_st),
            (&mut self.local_ld, &o.local_ld),
            (&mut self.local_st, &o.local_st),
            (&mut self.texture, &o.texture),
            (&mut self.global_atom, &o.global_atom),
            (&mut self.global_red, &o.global_red),
        ] {
            a.merge(b);
        }
        for (a, b) in [
            (&mut self.shared_ld, &o.shared_ld),
            (&mut self.shared_st, &o.shared_st),
            (&mut self.shared_atom, &o.shared_atom),
            (&mut self.const_ld, &o.const_ld),
        ] {
            a.merge(b);
        }
        self.param += o.param;
        self.warp_serialize += o.warp_serialize;
    }
}

/// Memory counts of one instruction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct InstMem {
    /// Requests.
    pub requests: u64,
    /// Sectors or transactions.
    pub sectors: u64,
    /// Shared wavefronts.
    pub wavefronts: u64,
    /// Shared bank conflicts.
    pub bank_conflicts: u64,
}

/// One CTA's model state: counters and caches.
pub struct CtaModel {
    profile: Profile,
    counters: MemCounters,
    per_inst: Vec<Vec<InstMem>>,
    l1: Option<cache::SectorCache>,
    /// A texture cache of this CTA's own (when not shared between SMs).
    tex: Option<cache::SectorCache>,
    /// Texture lines looked up this round, for a cache shared between SMs:
    /// the lines of each half-warp lookup end at the next `tex_ends` entry.
    tex_pending: Vec<u64>,
    tex_ends: Vec<usize>,
    /// Scratch space reused by every event, so that counting allocates nothing.
    lines: Vec<u64>,
    pairs: Vec<(u64, u64)>,
    /// Simulates caches (fidelity `caches`); without, hits and misses stay 0.
    caches: bool,
    /// What ptxas makes of the accesses ([`vectorize`]); None: counted as the PTX says.
    plan: Option<Arc<vectorize::Plan>>,
}

impl CtaModel {
    /// A CTA's model of `profile`, with per-instruction counts shaped as `shape`
    /// (instructions per function).
    pub fn new(profile: Profile, shape: &[usize]) -> Self {
        Self::with_caches(profile, shape, true)
    }

    /// As [`CtaModel::new`]; without `caches` no cache is simulated.
    pub fn with_caches(profile: Profile, shape: &[usize], caches: bool) -> Self {
        let p = profile.params();
        CtaModel {
            profile,
            counters: MemCounters::default(),
            per_inst: shape.iter().map(|&n| vec![InstMem::default(); n]).collect(),
            l1: (caches && p.l1_bytes > 0).then(|| cache::SectorCache::new(p.l1_bytes, 128, 4)),
            tex: (caches && p.tex_bytes > 0 && p.tex_shared_sms == 1)
                .then(|| cache::SectorCache::new(p.tex_bytes, p.tex_line, p.tex_ways)),
            tex_pending: Vec::new(),
            tex_ends: Vec::new(),
            lines: Vec::with_capacity(64),
            pairs: Vec::with_capacity(64),
            caches,
            plan: None,
        }
    }

    /// As [`CtaModel::with_caches`], counting the accesses as ptxas's code makes
    /// them ([`vectorize::Plan`]).
    pub fn with_plan(profile: Profile, shape: &[usize], caches: bool, plan: Option<Arc<vectorize::Plan>>) -> Self {
        CtaModel { plan, ..Self::with_caches(profile, shape, caches) }
    }

    fn global(&mut self, ev: &MemEvent, kind: Kind) -> InstMem {
        let lanes = ev.mask.count_ones() as u64;
        let mut im = InstMem::default();
        let c = match kind {
            Kind::Load => &mut self.counters.global_ld,
            Kind::Store => &mut self.counters.global_st,
            Kind::Texture => &mut self.counters.texture,
            Kind::Atom => &mut self.counters.global_atom,
            Kind::Red => &mut self.counters.global_red,
            Kind::LocalLoad => &mut self.counters.local_ld,
            Kind::LocalStore => &mut self.counters.local_st,
        };
        c.instructions += 1;
        c.bytes += lanes * ev.bytes as u64;
        let local = matches!(kind, Kind::LocalLoad | Kind::LocalStore);
        let key = (ev.cta as u64) << 10 | ev.warp as u64;
        let physical = |l: usize| if local { sectors::local_physical(key, l, ev.addrs[l]) } else { ev.addrs[l] };
        if self.profile == Profile::Gt200 {
            if kind == Kind::Texture {
                // The texture path does not coalesce: one request per half-warp
                // with active lanes, one lookup per distinct 32-byte line in it.
                let mut lines = std::mem::take(&mut self.lines);
                for h in 0..2 {
                    let m = ev.mask & (0xFFFF << (16 * h));
                    sectors::sectors_into(m, ev.bytes, |l| ev.addrs[l], &mut lines);
                    c.requests += (!lines.is_empty()) as u64;
                    im.requests += (!lines.is_empty()) as u64;
                    c.sectors += lines.len() as u64;
                    im.sectors += lines.len() as u64;
                    match self.tex.as_mut() {
                        Some(cache) => {
                            for &s in &lines {
                                if cache.access(s) {
                                    c.hits += 1;
                                } else {
                                    c.misses += 1;
                                }
                            }
                        }
                        // a cache shared by the TPC: looked up at the round's end
                        None if self.caches && !lines.is_empty() => {
                            self.tex_pending.extend_from_slice(&lines);
                            self.tex_ends.push(self.tex_pending.len());
                        }
                        None => {}
                    }
                }
                self.lines = lines;
                return im;
            }
            // Local memory is interleaved per thread, so give the coalescer word addresses.
            let t = if local {
                let mut t = coalesce_gt200::Transactions::default();
                let words = ev.bytes.div_ceil(4);
                for k in 0..words as u64 {
                    t.merge(&coalesce_gt200::warp(ev.mask, ev.bytes.min(4), |l| {
                        sectors::local_physical(key, l, ev.addrs[l] + 4 * k)
                    }));
                }
                t
            } else {
                coalesce_gt200::warp(ev.mask, ev.bytes, |l| ev.addrs[l])
            };
            c.requests += 1;
            c.sectors += t.count();
            c.t32 += t.t32;
            c.t64 += t.t64;
            c.t128 += t.t128;
            im.requests = 1;
            im.sectors = t.count();
            return im;
        }
        if self.profile == Profile::Hopper && matches!(kind, Kind::Atom | Kind::Red) {
            // lanes on one address are served one after another (atomics.rs)
            let n = atomics::sectors(ev.mask, ev.bytes, |l| ev.addrs[l], &mut self.lines);
            c.requests += 1;
            c.sectors += n;
            return InstMem { requests: 1, sectors: n, ..InstMem::default() };
        }
        let mut secs = std::mem::take(&mut self.lines);
        if local {
            sectors::local_sectors_into(key, ev.mask, ev.bytes, |l| ev.addrs[l], &mut secs);
        } else {
            sectors::sectors_into(ev.mask, ev.bytes, physical, &mut secs);
        }
        c.requests += 1;
        c.sectors += secs.len() as u64;
        im.requests = 1;
        im.sectors = secs.len() as u64;
        let cache = match kind {
            Kind::Texture => self.tex.as_mut(),
            Kind::Load | Kind::LocalLoad => self.l1.as_mut(),
            _ => None,
        };
        if let Some(cache) = cache {
            for &s in &secs {
                if cache.access(s) {
                    c.hits += 1;
                } else {
                    c.misses += 1;
                }
            }
        } else if matches!(kind, Kind::Store | Kind::LocalStore)
            && let Some(l1) = self.l1.as_mut()
        {
            // write-through: stores keep cached sectors valid
            for &s in &secs {
                l1.access(s);
            }
        }
        self.lines = secs;
        im
    }

    fn banked(&mut self, ev: &MemEvent, which: Bank) -> InstMem {
        let cost = if self.profile == Profile::Gt200 {
            banks::cost16_with(ev.mask, ev.bytes, |l| ev.addrs[l], &mut self.pairs)
        } else if self.profile == Profile::Hopper {
            let load = matches!(which, Bank::Load);
            banks::cost32_hopper_with(ev.mask, ev.bytes, load, |l| ev.addrs[l], &mut self.pairs)
        } else {
            banks::cost32_with(ev.mask, ev.bytes, |l| ev.addrs[l], &mut self.pairs)
        };
        let c = match which {
            Bank::Load => &mut self.counters.shared_ld,
            Bank::Store => &mut self.counters.shared_st,
            Bank::Atom => &mut self.counters.shared_atom,
        };
        c.instructions += 1;
        c.wavefronts += cost.wavefronts;
        c.bank_conflicts += cost.conflicts;
        if cost.conflicts > 0 {
            self.counters.warp_serialize += 1;
        }
        InstMem { wavefronts: cost.wavefronts, bank_conflicts: cost.conflicts, ..InstMem::default() }
    }

    fn constant(&mut self, ev: &MemEvent) -> InstMem {
        // The constant cache serves one address per pass (per half-warp on GT200).
        let groups: &[u32] = if self.profile == Profile::Gt200 { &[0xFFFF, 0xFFFF_0000] } else { &[u32::MAX] };
        let mut passes = 0;
        let a = &mut self.lines;
        for g in groups {
            a.clear();
            a.extend((0..32).filter(|l| (ev.mask & g) >> l & 1 != 0).map(|l| ev.addrs[l]));
            a.sort_unstable();
            a.dedup();
            passes += a.len() as u64;
        }
        let min = groups.iter().filter(|g| ev.mask & **g != 0).count() as u64;
        let c = &mut self.counters.const_ld;
        c.instructions += 1;
        c.wavefronts += passes;
        c.bank_conflicts += passes - min;
        if passes > min {
            self.counters.warp_serialize += 1;
        }
        InstMem { wavefronts: passes, bank_conflicts: passes - min, ..InstMem::default() }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Load,
    Store,
    Texture,
    Atom,
    Red,
    LocalLoad,
    LocalStore,
}

#[derive(Debug, Clone, Copy)]
enum Bank {
    Load,
    Store,
    Atom,
}

impl CtaModel {
    /// Counts one warp-level access into the CTA's counters and returns what it
    /// cost that instruction. The one implementation of the profile's rules:
    /// the counters and the teaching views ([`explain`]) both take it from here.
    pub fn count(&mut self, ev: &MemEvent) -> InstMem {
        let action = self.plan.as_ref().map_or(vectorize::Action::Count, |p| p.action(ev.func, ev.pc));
        match action {
            vectorize::Action::Count => {}
            vectorize::Action::Skip => return InstMem::default(),
            vectorize::Action::Widen { bytes, shift } => {
                let mut addrs = *ev.addrs;
                for a in addrs.iter_mut() {
                    *a = a.wrapping_add_signed(shift);
                }
                let wide = MemEvent { bytes, addrs: &addrs, ..*ev };
                return self.count_as_written(&wide);
            }
            vectorize::Action::Red if self.profile == Profile::Hopper && ev.op == MemOp::Atomic => {
                let red = MemEvent { op: MemOp::Reduction, ..*ev };
                return self.count_as_written(&red);
            }
            vectorize::Action::Red => {}
            vectorize::Action::Uniform { red, full_warp_only }
                if self.profile == Profile::Hopper
                    && matches!(ev.op, MemOp::Atomic | MemOp::Reduction)
                    && ev.mask != 0
                    && (!full_warp_only || ev.mask == u32::MAX) =>
            {
                // one lane (the first active one) does it for the warp
                let op = if red || ev.op == MemOp::Reduction { MemOp::Reduction } else { MemOp::Atomic };
                let one = MemEvent { op, mask: 1 << ev.mask.trailing_zeros(), ..*ev };
                return self.count_as_written(&one);
            }
            // `red` comes only with `full_warp_only: false`, and an atomic event has an
            // active lane, so every hopper `red` atomic took the arm above
            vectorize::Action::Uniform { red, full_warp_only } => {
                debug_assert!(!(red && full_warp_only), "a uniform reduction for full warps only");
            }
        }
        self.count_as_written(ev)
    }

    /// [`CtaModel::count`] without the ptxas plan.
    fn count_as_written(&mut self, ev: &MemEvent) -> InstMem {
        match (ev.space, ev.op) {
            (MemSpace::Global, MemOp::Load) if ev.nc && self.profile != Profile::Hopper => {
                self.global(ev, Kind::Texture)
            }
            (MemSpace::Global, MemOp::Load) => self.global(ev, Kind::Load),
            (MemSpace::Global, MemOp::Store) => self.global(ev, Kind::Store),
            (MemSpace::Global, MemOp::Atomic) => self.global(ev, Kind::Atom),
            (MemSpace::Global, MemOp::Reduction) => self.global(ev, Kind::Red),
            (MemSpace::Local, MemOp::Load) => self.global(ev, Kind::LocalLoad),
            (MemSpace::Local, _) => self.global(ev, Kind::LocalStore),
            (MemSpace::Shared, MemOp::Load) => self.banked(ev, Bank::Load),
            (MemSpace::Shared, MemOp::Store) => self.banked(ev, Bank::Store),
            (MemSpace::Shared, _) => self.banked(ev, Bank::Atom),
            (MemSpace::Const, _) => self.constant(ev),
            _ => {
                self.counters.param += 1;
                InstMem::default()
            }
        }
    }

    /// The counters so far.
    pub fn counters(&self) -> &MemCounters {
        &self.counters
    }
}

impl MemObserver for CtaModel {
    fn access(&mut self, ev: &MemEvent) {
        let im = self.count(ev);
        let slot = &mut self.per_inst[ev.func as usize][ev.pc as usize];
        slot.requests += im.requests;
        slot.sectors += im.sectors;
        slot.wavefronts += im.wavefronts;
        slot.bank_conflicts += im.bank_conflicts;
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }

    fn as_any_mut(&mut self) -> Option<&mut dyn Any> {
        Some(self)
    }
}

/// A counter model for one launch: hand it to [`crate::sim::Device::launch_observed`],
/// then take the results with [`Model::finish`].
pub struct Model {
    profile: Profile,
    shape: Vec<usize>,
    acc: Mutex<ModelStats>,
    /// Texture caches shared by the SMs of a texture processor cluster (GT200),
    /// by cluster; created on first use.
    shared_tex: Mutex<Vec<Option<cache::SectorCache>>>,
    /// Simulates caches (set by the launch's fidelity; on by default).
    caches: AtomicBool,
    /// The ptxas plan of the program ([`vectorize`]), when applied.
    plan: Option<Arc<vectorize::Plan>>,
}

/// One texture-processor cluster's CTA models of a round, with their cluster index.
type Cluster<'a, 'b> = &'a mut [(u32, &'b mut CtaModel)];

/// Replays one texture-processor cluster's lookups of a round into its cache:
/// the cluster's CTAs take turns one half-warp lookup at a time, in CTA order.
fn replay_cluster(cache: &mut cache::SectorCache, group: Cluster) {
    let mut next = vec![0usize; group.len()];
    loop {
        let mut any = false;
        for (j, (_, m)) in group.iter_mut().enumerate() {
            let Some(&end) = m.tex_ends.get(next[j]) else { continue };
            let start = if next[j] == 0 { 0 } else { m.tex_ends[next[j] - 1] };
            for i in start..end {
                if cache.access(m.tex_pending[i]) {
                    m.counters.texture.hits += 1;
                } else {
                    m.counters.texture.misses += 1;
                }
            }
            next[j] += 1;
            any = true;
        }
        if !any {
            break;
        }
    }
    for (_, m) in group.iter_mut() {
        m.tex_pending.clear();
        m.tex_ends.clear();
    }
}

/// What a model counted.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct ModelStats {
    /// The profile.
    pub profile: Profile,
    /// Launch totals.
    pub counters: MemCounters,
    /// Per instruction: `per_inst[function][pc]`.
    #[serde(skip)]
    pub per_inst: Vec<Vec<InstMem>>,
}

impl Model {
    /// A model of `profile` for kernels of `prog`. On the maxwell and hopper
    /// profiles the accesses are counted as ptxas's code makes them
    /// ([`vectorize`]) unless that is switched off ([`vectorize::set_default`]).
    pub fn new(profile: Profile, prog: &Program) -> Self {
        Self::with_vectorize(profile, prog, vectorize::default_on())
    }

    /// A model of `profile` for kernels of `prog`; `vectorize`: count the
    /// accesses as ptxas's code makes them (maxwell and hopper only).
    pub fn with_vectorize(profile: Profile, prog: &Program, vectorize: bool) -> Self {
        let shape: Vec<usize> = prog.functions.iter().map(|f| f.insts.len()).collect();
        let per_inst = shape.iter().map(|&n| vec![InstMem::default(); n]).collect();
        Model {
            profile,
            shape,
            acc: Mutex::new(ModelStats { profile, counters: MemCounters::default(), per_inst }),
            shared_tex: Mutex::new(Vec::new()),
            caches: AtomicBool::new(true),
            plan: (vectorize && profile != Profile::Gt200).then(|| Arc::new(vectorize::Plan::new(prog))),
        }
    }

    /// The results (summed over every CTA that retired).
    pub fn finish(&self) -> ModelStats {
        self.acc.lock().expect("model lock").clone()
    }
}

impl ObserverFactory for Model {
    fn create(&self, _cta: u32) -> Box<dyn MemObserver> {
        Box::new(CtaModel::with_plan(self.profile, &self.shape, self.caches.load(Ordering::Relaxed), self.plan.clone()))
    }

    fn set_fidelity(&self, level: Fidelity) {
        self.caches.store(level >= Fidelity::Caches, Ordering::Relaxed);
    }

    /// Replays the round's texture lookups of the CTAs that share a texture
    /// cache. CTA `i` runs on SM `i mod SMs` (persistent CTAs: one per SM),
    /// SMs `3k..3k+2` form cluster `k`; the clusters' CTAs take turns one
    /// half-warp lookup at a time, in CTA order — a fixed stand-in for the
    /// hardware's interleaving.
    fn end_round(&self, observers: &mut [(u32, &mut dyn MemObserver)]) {
        let p = self.profile.params();
        if p.tex_bytes == 0 || p.tex_shared_sms <= 1 {
            return;
        }
        let mut ctas: Vec<(u32, &mut CtaModel)> = observers
            .iter_mut()
            .filter_map(|(linear, o)| {
                let cluster = (*linear % p.sms) / p.tex_shared_sms;
                o.as_any_mut()?.downcast_mut::<CtaModel>().map(|m| (cluster, m))
            })
            .filter(|(_, m)| !m.tex_ends.is_empty())
            .collect();
        if ctas.is_empty() {
            return;
        }
        ctas.sort_by_key(|c| c.0); // stable: CTA order within a cluster
        let mut caches = self.shared_tex.lock().expect("model lock");
        // Each cluster's cache is its own: replay the clusters in parallel
        // (on the launch's host threads), each in its fixed order.
        let mut work: Vec<(usize, cache::SectorCache, Cluster)> = ctas
            .chunk_by_mut(|a, b| a.0 == b.0)
            .map(|group| {
                let k = group[0].0 as usize;
                if caches.len() <= k {
                    caches.resize(k + 1, None);
                }
                let cache =
                    caches[k].take().unwrap_or_else(|| cache::SectorCache::new(p.tex_bytes, p.tex_line, p.tex_ways));
                (k, cache, group)
            })
            .collect();
        work.par_iter_mut().for_each(|(_, cache, group)| replay_cluster(cache, group));
        for (k, cache, _) in work {
            caches[k] = Some(cache);
        }
    }

    fn retire(&self, obs: Box<dyn MemObserver>) {
        let Ok(m) = obs.into_any().downcast::<CtaModel>() else { return };
        let mut acc = self.acc.lock().expect("model lock");
        acc.counters.merge(&m.counters);
        for (a, b) in acc.per_inst.iter_mut().zip(&m.per_inst) {
            for (x, y) in a.iter_mut().zip(b) {
                x.requests += y.requests;
                x.sectors += y.sectors;
                x.wavefronts += y.wavefronts;
                x.bank_conflicts += y.bank_conflicts;
            }
        }
    }
}

impl ModelStats {
    /// Every counter of the profile under its warplight name (`mem.global_ld.sectors`)
    /// and the profiler's name for it on that generation (Nsight Compute for Hopper,
    /// nvprof for Maxwell, the CC 1.x profiler for GT200), given the core counters.
    pub fn metrics(&self, core: &Counters) -> Vec<(String, u64)> {
        let mut out = Vec::new();
        let mc = &self.counters;
        let v = serde_json::to_value(mc).expect("serialize");
        if let serde_json::Value::Object(m) = v {
            for (k, x) in m {
                match x {
                    serde_json::Value::Object(inner) => {
                        for (k2, y) in inner {
                            out.push((format!("mem.{k}.{k2}"), y.as_u64().unwrap_or(0)));
                        }
                    }
                    y => out.push((format!("mem.{k}"), y.as_u64().unwrap_or(0))),
                }
            }
        }
        for (name, value) in self.profiler_names(core) {
            out.push((name.to_string(), value));
        }
        out
    }

    /// The profiler-named metrics of this profile.
    pub fn profiler_names(&self, core: &Counters) -> Vec<(&'static str, u64)> {
        let m = &self.counters;
        match self.profile {
            Profile::Hopper => vec![
                ("smsp__inst_executed.sum", core.warp_instructions),
                ("smsp__thread_inst_executed.sum", core.thread_instructions),
                ("smsp__thread_inst_executed_pred_on.sum", core.thread_instructions_pred_on),
                ("smsp__sass_branch_targets.sum", core.branches),
                ("smsp__sass_branch_targets_threads_divergent.sum", core.divergent_branches),
                ("smsp__inst_executed_op_texture.sum", core.textures.instructions),
                ("l1tex__t_requests_pipe_tex_mem_texture.sum", core.textures.requests),
                ("smsp__inst_executed_op_surface_ld.sum", core.textures.surface_loads),
                ("smsp__inst_executed_op_surface_st.sum", core.textures.surface_stores),
                ("smsp__inst_executed_op_surface_red.sum", core.textures.surface_reductions),
                ("smsp__sass_inst_executed_op_global_ld.sum", m.global_ld.instructions),
                ("smsp__sass_inst_executed_op_global_st.sum", m.global_st.instructions),
                ("smsp__sass_inst_executed_op_shared_ld.sum", m.shared_ld.instructions),
                ("smsp__sass_inst_executed_op_shared_st.sum", m.shared_st.instructions),
                ("smsp__sass_inst_executed_op_local_ld.sum", m.local_ld.instructions),
                ("smsp__sass_inst_executed_op_local_st.sum", m.local_st.instructions),
                ("smsp__sass_inst_executed_op_shared_atom.sum", m.shared_atom.instructions),
                ("smsp__sass_inst_executed_op_global_atom.sum", m.global_atom.instructions),
                ("smsp__sass_inst_executed_op_global_red.sum", m.global_red.instructions),
                ("l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum", m.global_ld.requests),
                ("l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum", m.global_ld.sectors),
                ("l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum", m.global_ld.hits),
                ("l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_miss.sum", m.global_ld.misses),
                ("l1tex__t_requests_pipe_lsu_mem_global_op_st.sum", m.global_st.requests),
                ("l1tex__t_sectors_pipe_lsu_mem_global_op_st.sum", m.global_st.sectors),
                ("l1tex__t_requests_pipe_lsu_mem_local_op_ld.sum", m.local_ld.requests),
                ("l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum", m.local_ld.sectors),
                ("l1tex__t_requests_pipe_lsu_mem_local_op_st.sum", m.local_st.requests),
                ("l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum", m.local_st.sectors),
                ("l1tex__data_pipe_lsu_wavefronts_mem_shared_op_ld.sum", m.shared_ld.wavefronts),
                ("l1tex__data_pipe_lsu_wavefronts_mem_shared_op_st.sum", m.shared_st.wavefronts),
                ("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_ld.sum", m.shared_ld.bank_conflicts),
                ("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_st.sum", m.shared_st.bank_conflicts),
                ("l1tex__t_requests_pipe_lsu_mem_global_op_atom.sum", m.global_atom.requests),
                ("l1tex__t_requests_pipe_lsu_mem_global_op_red.sum", m.global_red.requests),
                ("l1tex__t_sectors_pipe_lsu_mem_global_op_atom.sum", m.global_atom.sectors),
                ("l1tex__t_sectors_pipe_lsu_mem_global_op_red.sum", m.global_red.sectors),
                ("l1tex__data_pipe_lsu_wavefronts_mem_shared_op_atom.sum", m.shared_atom.wavefronts),
                ("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_atom.sum", m.shared_atom.bank_conflicts),
                ("lts__t_sectors_op_atom.sum", m.global_atom.sectors),
                ("lts__t_sectors_op_red.sum", m.global_red.sectors),
            ],
            Profile::Maxwell => vec![
                ("inst_executed", core.warp_instructions),
                ("gld_transactions", m.global_ld.sectors),
                ("gst_transactions", m.global_st.sectors),
                ("global_load_requests", m.global_ld.requests),
                ("global_store_requests", m.global_st.requests),
                ("local_load_transactions", m.local_ld.sectors),
                ("local_store_transactions", m.local_st.sectors),
                ("shared_load_transactions", m.shared_ld.wavefronts),
                ("shared_store_transactions", m.shared_st.wavefronts),
                ("tex_cache_transactions", m.texture.sectors),
                ("tex_cache_hits", m.texture.hits),
                ("branch", core.branches),
                ("divergent_branch", core.divergent_branches),
            ],
            Profile::Gt200 => vec![
                ("instructions", core.warp_instructions),
                // The CC 1.x profiler counts barriers as branches.
                ("branch", core.branches + core.barrier_warp_arrivals),
                ("divergent_branch", core.divergent_branches),
                ("gld_32b", m.global_ld.t32),
                ("gld_64b", m.global_ld.t64),
                ("gld_128b", m.global_ld.t128),
                ("gst_32b", m.global_st.t32),
                ("gst_64b", m.global_st.t64),
                ("gst_128b", m.global_st.t128),
                ("local_load", m.local_ld.instructions),
                ("local_store", m.local_st.instructions),
                ("warp_serialize", m.warp_serialize),
                ("tex_cache_hit", m.texture.hits),
                ("tex_cache_miss", m.texture.misses),
            ],
        }
    }
}
