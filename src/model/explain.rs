//! What one warp-level memory access costs under a device profile, spelled
//! out lane by lane for the teaching views (`warplight step`, `warplight
//! trace`): the transactions or sectors the lanes' addresses form, or the
//! banks they fall in. It uses the same functions as the counter model, so the
//! totals it shows are the counts the model adds for that instruction
//! (cache hits aside).

use crate::model::{Profile, banks, coalesce_gt200, sectors};
use crate::ptx::ir::MemSpace;
use crate::sim::access_log::Access;
use crate::sim::observer::MemOp;

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
    let (summary, units) = match a.space {
        MemSpace::Shared => shared(profile, a, head),
        MemSpace::Global | MemSpace::Local => {
            if profile == Profile::Gt200 && !(a.nc && a.space == MemSpace::Global) {
                segments(a, head)
            } else {
                sector_units(profile, a, head)
            }
        }
        _ => (format!("{head}: not modelled (uniform parameter/constant space)"), Vec::new()),
    };
    let lane_unit = (0..32).map(|l| units.iter().position(|u| u.lanes >> l & 1 != 0)).collect();
    Explanation { summary, units, lane_unit }
}

/// The key of the warp's private local-memory region (as the counter model forms it).
fn local_key(a: &Access) -> u64 {
    (a.cta as u64) << 10 | a.warp as u64
}

/// GT200 half-warp segments (global and local).
fn segments(a: &Access, head: String) -> (String, Vec<Unit>) {
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
    let summary = format!(
        "{head}: gt200 {} transaction{}, {moved} B moved for {useful} B used",
        units.len(),
        if units.len() == 1 { "" } else { "s" }
    );
    (summary, units)
}

/// 32-byte sectors (Maxwell, Hopper; GT200's texture path by 32-byte lines).
fn sector_units(profile: Profile, a: &Access, head: String) -> (String, Vec<Unit>) {
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
    let what = if profile == Profile::Gt200 { "texture lines of 32 B" } else { "sectors" };
    let summary = format!("{head}: {} 1 request, {} {what}", profile.params().name, units.len());
    (summary, units)
}

/// Shared-memory banks.
fn shared(profile: Profile, a: &Access, head: String) -> (String, Vec<Unit>) {
    let (nbanks, cost) = if profile == Profile::Gt200 {
        (16u64, banks::cost16(a.mask, a.bytes, |l| a.addrs[l]))
    } else {
        (32u64, banks::cost32(a.mask, a.bytes, |l| a.addrs[l]))
    };
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
        cost.conflicts,
        if cost.conflicts == 1 { "" } else { "s" }
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

    #[test]
    fn inactive_lanes_have_no_unit() {
        let mut a = access(MemSpace::Global, 4, |l| 4 * l as u64);
        a.mask = 0x0000_FFFF;
        let e = explain(Profile::Maxwell, &a);
        assert_eq!(e.units.len(), 2);
        assert_eq!(e.lane_unit[16], None);
    }
}
