//! What one warp-level memory access costs under a device profile, spelled
//! out lane by lane for the teaching views (`warplight step`, `warplight
//! trace`): the transactions or sectors the lanes' addresses form, or the
//! banks they fall in. The numbers come from the counter model itself
//! ([`CtaModel::count`], the one implementation of the rules), so they are
//! the counts the model adds for that instruction (cache hits aside); the
//! units listed are formed by the same functions the model uses.

use crate::model::{CtaModel, InstMem, Profile, coalesce_gt200, sectors};
use crate::ptx::ir::MemSpace;
use crate::sim::access_log::Access;
use crate::sim::observer::{MemEvent, MemOp};

/// A group of lanes served together: a transaction, a sector, or a bank.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Unit {
    /// What it is, e.g. `64 B segment at 0x1040` or `bank 5: 2 words`.
    pub label: String,
    /// The lanes it serves.
    pub lanes: u32,
}

/// An access explained.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Explanation {
    /// One line: what, how many lanes, what it costs.
    pub summary: String,
    /// Transactions or sectors in order; for shared memory every bank, lanes or not
    /// (so a lane's unit index is its bank).
    pub units: Vec<Unit>,
    /// For each lane, the index of the first unit serving it (None: inactive).
    pub lane_unit: Vec<Option<usize>>,
    /// What the counter model counts for this access.
    pub cost: InstMem,
}

/// What the counter model of `profile` counts for `a` (a fresh model: no cache state).
pub fn cost(profile: Profile, a: &Access) -> InstMem {
    let ev = MemEvent {
        func: a.func,
        pc: a.pc,
        op: a.op,
        space: a.space,
        nc: a.nc,
        bytes: a.bytes,
        elem_bytes: a.elem_bytes,
        mask: a.mask,
        addrs: &a.addrs,
        cta: a.cta,
        warp: a.warp,
    };
    CtaModel::new(profile, &[]).count(&ev)
}

/// Whether `profile` sends `a` through GT200's texture path (per half-warp lines).
fn gt200_texture(profile: Profile, a: &Access) -> bool {
    profile == Profile::Gt200 && a.nc && a.space == MemSpace::Global && a.op == MemOp::Load
}

/// The name of an access, e.g. `global load` or `shared atomic`.
pub fn access_name(a: &Access) -> String {
    let space = match a.space {
        MemSpace::Global if a.nc => "read-only global",
        MemSpace::Global => "global",
        MemSpace::Shared => "shared",
        MemSpace::Local => "local",
        MemSpace::Const => "constant",
        MemSpace::KernelParam => "kernel parameter",
        MemSpace::FrameParam => "parameter",
        MemSpace::Generic => "generic",
    };
    let op = match a.op {
        MemOp::Load => "load",
        MemOp::Store => "store",
        MemOp::Atomic => "atomic",
        MemOp::Reduction => "reduction",
    };
    format!("{space} {op}")
}

/// Explains `a` under `profile`.
pub fn explain(profile: Profile, a: &Access) -> Explanation {
    let lanes = a.mask.count_ones();
    let head = format!("{} {}B x{lanes}", access_name(a), a.bytes);
    let cost = cost(profile, a);
    let (summary, units) = match a.space {
        MemSpace::Shared => shared(profile, a, head, &cost),
        MemSpace::Global | MemSpace::Local if gt200_texture(profile, a) => texture_lines(a, head, &cost),
        MemSpace::Global | MemSpace::Local if profile == Profile::Gt200 => segments(a, head, &cost),
        MemSpace::Global | MemSpace::Local => sector_units(profile, a, head, &cost),
        MemSpace::Const => {
            let p = cost.wavefronts;
            (format!("{head}: {} constant-cache pass{}", p, if p == 1 { "" } else { "es" }), Vec::new())
        }
        _ => (format!("{head}: not modelled (uniform parameter space)"), Vec::new()),
    };
    let lane_unit = (0..32).map(|l| units.iter().position(|u| u.lanes >> l & 1 != 0)).collect();
    Explanation { summary, units, lane_unit, cost }
}

/// The key of the warp's private local-memory region (as the counter model forms it).
fn local_key(a: &Access) -> u64 {
    (a.cta as u64) << 10 | a.warp as u64
}

/// GT200 half-warp segments (global and local).
fn segments(a: &Access, head: String, cost: &InstMem) -> (String, Vec<Unit>) {
    let segs = if a.space == MemSpace::Local {
        // interleaved per thread: each 4-byte word is its own coalescing pass
        let key = local_key(a);
        (0..a.bytes.div_ceil(4) as u64)
            .flat_map(|k| {
                coalesce_gt200::warp_segments(a.mask, a.bytes.min(4), |l| {
                    sectors::local_physical(key, l, a.addrs[l] + 4 * k)
                })
            })
            .collect()
    } else {
        coalesce_gt200::warp_segments(a.mask, a.bytes, |l| a.addrs[l])
    };
    let moved: u64 = segs.iter().map(|s| s.size).sum();
    let useful = a.mask.count_ones() as u64 * a.bytes as u64;
    let units = segs
        .iter()
        .map(|s| Unit { label: format!("half-warp {}: {} B at {:#x}", s.half, s.size, s.base), lanes: s.lanes })
        .collect::<Vec<_>>();
    let n = cost.sectors;
    let summary =
        format!("{head}: gt200 {n} transaction{}, {moved} B moved for {useful} B used", if n == 1 { "" } else { "s" });
    (summary, units)
}

/// GT200's texture path: no coalescing; each half-warp is a request for the
/// distinct 32-byte lines its lanes read.
fn texture_lines(a: &Access, head: String, cost: &InstMem) -> (String, Vec<Unit>) {
    let mut units = Vec::new();
    for h in 0..2u32 {
        let m = a.mask & (0xFFFF << (16 * h));
        for s in sectors::sectors(m, a.bytes, |l| a.addrs[l]) {
            let lanes = (0..32)
                .filter(|&l| m >> l & 1 != 0 && sectors::sectors(1 << l, a.bytes, |_| a.addrs[l]).contains(&s))
                .fold(0u32, |acc, l| acc | 1 << l);
            units.push(Unit { label: format!("half-warp {h}: line {:#x}", s * sectors::SECTOR), lanes });
        }
    }
    let (r, n) = (cost.requests, cost.sectors);
    let summary = format!(
        "{head}: gt200 texture path, {r} request{} (one per half-warp), {n} line{} of 32 B",
        if r == 1 { "" } else { "s" },
        if n == 1 { "" } else { "s" }
    );
    (summary, units)
}

/// 32-byte sectors (Maxwell, Hopper; GT200's texture path by 32-byte lines).
fn sector_units(profile: Profile, a: &Access, head: String, cost: &InstMem) -> (String, Vec<Unit>) {
    let key = local_key(a);
    let local = a.space == MemSpace::Local;
    let secs = if local {
        sectors::local_sectors(key, a.mask, a.bytes, |l| a.addrs[l])
    } else {
        sectors::sectors(a.mask, a.bytes, |l| a.addrs[l])
    };
    let units = secs
        .iter()
        .map(|&s| {
            let mut lanes = 0u32;
            for l in 0..32 {
                if a.mask >> l & 1 == 0 {
                    continue;
                }
                let one = 1u32 << l;
                let hit = if local {
                    sectors::local_sectors(key, one, a.bytes, |_| a.addrs[l]).contains(&s)
                } else {
                    sectors::sectors(one, a.bytes, |_| a.addrs[l]).contains(&s)
                };
                if hit {
                    lanes |= one;
                }
            }
            Unit { label: format!("sector {:#x}", s * sectors::SECTOR), lanes }
        })
        .collect::<Vec<_>>();
    let (r, n) = (cost.requests, cost.sectors);
    let summary = format!(
        "{head}: {} {r} request{}, {n} sector{}",
        profile.params().name,
        if r == 1 { "" } else { "s" },
        if n == 1 { "" } else { "s" }
    );
    (summary, units)
}

/// Shared-memory banks.
fn shared(profile: Profile, a: &Access, head: String, cost: &InstMem) -> (String, Vec<Unit>) {
    let nbanks = if profile == Profile::Gt200 { 16u64 } else { 32u64 };
    // one unit per bank, empty ones included, so that a lane's unit is its bank
    let mut units = Vec::new();
    for b in 0..nbanks {
        let mut lanes = 0u32;
        let mut words = Vec::new();
        for l in 0..32 {
            if a.mask >> l & 1 != 0 && (a.addrs[l] / 4) % nbanks == b {
                lanes |= 1 << l;
                words.push(a.addrs[l] / 4);
            }
        }
        words.sort_unstable();
        words.dedup();
        let w = words.len();
        units.push(Unit { label: format!("bank {b}: {w} word{}", if w == 1 { "" } else { "s" }), lanes });
    }
    let summary = format!(
        "{head}: {} {nbanks} banks, {} wavefront{}, {} conflict{}",
        profile.params().name,
        cost.wavefronts,
        if cost.wavefronts == 1 { "" } else { "s" },
        cost.bank_conflicts,
        if cost.bank_conflicts == 1 { "" } else { "s" }
    );
    (summary, units)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn access(space: MemSpace, bytes: u32, addr: impl Fn(usize) -> u64) -> Access {
        Access {
            cta: 0,
            warp: 0,
            func: 0,
            pc: 0,
            op: MemOp::Load,
            space,
            nc: false,
            bytes,
            elem_bytes: bytes,
            mask: u32::MAX,
            addrs: std::array::from_fn(addr),
        }
    }

    #[test]
    fn coalesced_load_per_profile() {
        let a = access(MemSpace::Global, 4, |l| 0x1000 + 4 * l as u64);
        let g = explain(Profile::Gt200, &a);
        assert_eq!(g.units.len(), 2, "{g:?}");
        assert!(g.summary.contains("2 transactions, 128 B moved for 128 B used"), "{}", g.summary);
        assert_eq!(g.lane_unit[15], Some(0));
        assert_eq!(g.lane_unit[16], Some(1));
        let h = explain(Profile::Hopper, &a);
        assert_eq!(h.units.len(), 4);
        assert_eq!(h.units[1].lanes, 0xFF00);
        assert!(h.summary.ends_with("1 request, 4 sectors"), "{}", h.summary);
    }

    #[test]
    fn strided_shared_conflicts() {
        // stride 32 words: every lane in bank 0 -> 32-way on Hopper, 16-way per half-warp on GT200
        let a = access(MemSpace::Shared, 4, |l| 128 * l as u64);
        let h = explain(Profile::Hopper, &a);
        assert_eq!(h.units.len(), 32);
        assert_eq!(h.units[0].label, "bank 0: 32 words");
        assert_eq!(h.units[1].lanes, 0);
        assert!(h.summary.contains("32 wavefronts, 31 conflicts"), "{}", h.summary);
        let g = explain(Profile::Gt200, &a);
        assert!(g.summary.contains("32 wavefronts, 30 conflicts"), "{}", g.summary);
        // stride 33: conflict-free
        let p = explain(Profile::Hopper, &access(MemSpace::Shared, 4, |l| 132 * l as u64));
        assert!(p.units.iter().all(|u| u.lanes.count_ones() == 1));
        assert_eq!(p.lane_unit[1], Some(1));
        assert_eq!(p.lane_unit[31], Some(31));
        assert!(p.summary.contains("1 wavefront, 0 conflicts"), "{}", p.summary);
    }

    /// Issue 19 item 4: GT200 `ld.global.nc`, lanes 0 and 16 read one 32-byte
    /// line. The texture path serves each half-warp separately: two requests,
    /// two lookups, as the counters say.
    #[test]
    fn gt200_texture_counts_per_half_warp_as_the_counters_do() {
        let mut a = access(MemSpace::Global, 4, |_| 0x1000);
        a.nc = true;
        a.mask = 1 | 1 << 16;
        let e = explain(Profile::Gt200, &a);
        assert_eq!((e.cost.requests, e.cost.sectors), (2, 2));
        assert_eq!(e.units.len(), 2, "{e:?}");
        assert_eq!((e.units[0].lanes, e.units[1].lanes), (1, 1 << 16));
        assert!(e.summary.contains("2 requests (one per half-warp), 2 lines"), "{}", e.summary);
        // and the counters of a model that saw it
        let mut m = CtaModel::new(Profile::Gt200, &[]);
        let ev = MemEvent {
            func: 0,
            pc: 0,
            op: MemOp::Load,
            space: MemSpace::Global,
            nc: true,
            bytes: 4,
            elem_bytes: 4,
            mask: a.mask,
            addrs: &a.addrs,
            cta: 0,
            warp: 0,
        };
        m.count(&ev);
        assert_eq!((m.counters().texture.requests, m.counters().texture.sectors), (2, 2));
    }

    #[test]
    fn inactive_lanes_have_no_unit() {
        let mut a = access(MemSpace::Global, 4, |l| 4 * l as u64);
        a.mask = 0x0000_FFFF;
        let e = explain(Profile::Maxwell, &a);
        assert_eq!(e.units.len(), 2);
        assert_eq!(e.lane_unit[16], None);
    }
}
