//! Shared-memory banks.
//!
//! - 32 banks × 4 bytes (Maxwell and later): the lanes of a warp-level access
//!   are served in groups of at most 128 requested bytes (all 32 lanes for
//!   4-byte accesses, 16 for 8-byte, 8 for 16-byte). A group needs as many
//!   wavefronts as the most distinct 4-byte words any one bank must deliver;
//!   lanes reading the same word share it. Bank conflicts are the wavefronts
//!   beyond one per group — the minimum for the access width — as Nsight
//!   Compute's `l1tex__data_bank_conflicts_pipe_lsu_mem_shared_*` counts them.
//! - Hopper loads of 8 and 16 bytes where lanes pair up (lanes `n` and
//!   `n^1`, or `n` and `n^2`, read the same address wherever both are
//!   active) are served in groups twice as large (the whole warp for 8 bytes,
//!   half-warps for 16): the shared memory returns 128 bytes a wavefront, and
//!   paired lanes share their data, so each wavefront packs twice the lanes.
//!   An NVIDIA engineer's rule for compute capability 7.x
//!   (forums.developer.nvidia.com, "Unexpected shared memory bank conflict",
//!   2019), measured on the H200 by the single-warp probes of
//!   `kernels/validation/suite.cu` (`docs/validation.md`): a 16-byte load
//!   where each half-warp reads one element takes 2 wavefronts, not 4; all
//!   lanes on one element: 2; lanes `l` and `l+16` sharing: still 8 (no
//!   pairs). [`cost32_hopper_with`].
//! - 16 banks × 4 bytes per half-warp (compute capability 1.x): each half-warp
//!   is served separately; distinct words in one bank serialize. On 1.x,
//!   8- and 16-bit accesses to different bytes of one word conflict too, and
//!   a 64-bit access is two 32-bit passes.

/// Wavefronts and conflicts of one access.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BankCost {
    /// Passes through the banks.
    pub wavefronts: u64,
    /// Passes beyond the minimum.
    pub conflicts: u64,
}

/// Degree of a set of (bank, key) pairs: the largest number of distinct keys in one bank.
fn degree(pairs: &mut Vec<(u64, u64)>) -> u64 {
    pairs.sort_unstable();
    pairs.dedup();
    let mut best = 0u64;
    let mut i = 0;
    while i < pairs.len() {
        let mut j = i;
        while j < pairs.len() && pairs[j].0 == pairs[i].0 {
            j += 1;
        }
        best = best.max((j - i) as u64);
        i = j;
    }
    best
}

/// 32 banks × 4 bytes, Volta and later (Hopper) and Maxwell.
pub fn cost32(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64) -> BankCost {
    cost32_with(mask, bytes, addr, &mut Vec::with_capacity(64))
}

/// [`cost32`] with a caller's scratch buffer, so that a caller reusing it allocates nothing.
pub fn cost32_with(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64, pairs: &mut Vec<(u64, u64)>) -> BankCost {
    cost32_groups(mask, bytes, (128 / bytes.clamp(4, 16)) as usize, addr, pairs)
}

/// Whether lanes `n` and `n ^ x` access the same address wherever both are active.
fn paired(mask: u32, x: usize, addr: &impl Fn(usize) -> u64) -> bool {
    (0..32).all(|n| mask >> n & 1 == 0 || mask >> (n ^ x) & 1 == 0 || addr(n) == addr(n ^ x))
}

/// Hopper: [`cost32_with`], with loads of 8 or 16 bytes whose lanes pair up
/// (`n` and `n^1`, or `n` and `n^2`, on one address) served in groups of twice
/// the lanes (see the module comment). `load`: the pairing applies to loads only.
pub fn cost32_hopper_with(
    mask: u32,
    bytes: u32,
    load: bool,
    addr: impl Fn(usize) -> u64,
    pairs: &mut Vec<(u64, u64)>,
) -> BankCost {
    let mut group = (128 / bytes.clamp(4, 16)) as usize;
    if load && group < 32 && (paired(mask, 1, &addr) || paired(mask, 2, &addr)) {
        group *= 2;
    }
    cost32_groups(mask, bytes, group, addr, pairs)
}

/// 32 banks, lanes served in groups of `group`.
fn cost32_groups(
    mask: u32,
    bytes: u32,
    group: usize,
    addr: impl Fn(usize) -> u64,
    pairs: &mut Vec<(u64, u64)>,
) -> BankCost {
    let mut c = BankCost::default();
    for g in (0..32).step_by(group) {
        pairs.clear();
        for l in g..g + group {
            if mask >> l & 1 == 0 {
                continue;
            }
            let a = addr(l);
            let mut w = a / 4;
            while w * 4 < a + bytes.max(1) as u64 {
                pairs.push((w % 32, w));
                w += 1;
            }
        }
        if pairs.is_empty() {
            continue;
        }
        let d = degree(pairs);
        c.wavefronts += d;
        c.conflicts += d - 1;
    }
    c
}

/// 16 banks × 4 bytes per half-warp, compute capability 1.x (GT200).
pub fn cost16(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64) -> BankCost {
    cost16_with(mask, bytes, addr, &mut Vec::with_capacity(16))
}

/// [`cost16`] with a caller's scratch buffer.
pub fn cost16_with(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64, pairs: &mut Vec<(u64, u64)>) -> BankCost {
    let mut c = BankCost::default();
    for h in 0..2 {
        // A 64-bit (or 128-bit) access is served as consecutive 32-bit passes.
        let passes = bytes.div_ceil(4).max(1) as u64;
        for p in 0..passes {
            pairs.clear();
            for l in h * 16..h * 16 + 16 {
                if mask >> l & 1 == 0 {
                    continue;
                }
                let a = addr(l) + 4 * p;
                let key = if bytes < 4 { a } else { a / 4 };
                pairs.push(((a / 4) % 16, key));
            }
            if pairs.is_empty() {
                continue;
            }
            let d = degree(pairs);
            c.wavefronts += d;
            c.conflicts += d - 1;
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    // H100 reference points (../shared/docs/ptx-toolchain.md): float loads at
    // (t * stride) % 1056; per warp-instruction wavefronts / conflicts.
    fn strided(stride: u64) -> BankCost {
        cost32(u32::MAX, 4, |l| ((l as u64 * stride) % 1056) * 4)
    }

    #[test]
    fn hopper_reference_strides() {
        assert_eq!(strided(1), BankCost { wavefronts: 1, conflicts: 0 });
        assert_eq!(strided(2), BankCost { wavefronts: 2, conflicts: 1 });
        assert_eq!(strided(4), BankCost { wavefronts: 4, conflicts: 3 });
        assert_eq!(strided(8), BankCost { wavefronts: 8, conflicts: 7 });
        assert_eq!(strided(16), BankCost { wavefronts: 16, conflicts: 15 });
        assert_eq!(strided(32), BankCost { wavefronts: 32, conflicts: 31 });
        assert_eq!(strided(33), BankCost { wavefronts: 1, conflicts: 0 });
    }

    #[test]
    fn broadcast_is_free() {
        assert_eq!(cost32(u32::MAX, 4, |_| 64), BankCost { wavefronts: 1, conflicts: 0 });
    }

    #[test]
    fn wide_accesses_need_more_wavefronts() {
        assert_eq!(cost32(u32::MAX, 8, |l| l as u64 * 8), BankCost { wavefronts: 2, conflicts: 0 });
        assert_eq!(cost32(u32::MAX, 16, |l| l as u64 * 16), BankCost { wavefronts: 4, conflicts: 0 });
    }

    fn hopper(mask: u32, bytes: u32, f: impl Fn(usize) -> u64) -> u64 {
        cost32_hopper_with(mask, bytes, true, f, &mut Vec::new()).wavefronts
    }

    // The H200's single-warp probes (kernels/validation/suite.cu, probe_index):
    // element i of a float4 (float2) array at 16 i (8 i).
    #[test]
    fn hopper_paired_lanes_pack_wide_loads() {
        let modes: [fn(usize) -> u64; 7] = [
            |l| (l as u64 >> 4) * 2,
            |l| (l as u64 & 15) * 2,
            |_| 5,
            |l| l as u64 >> 1,
            |l| (l as u64 & 1) | ((l as u64 >> 2) << 1),
            |l| (l as u64 >> 3) * 4,
            |l| l as u64,
        ];
        // measured: LDS.128 2 8 2 2 2 2 4, LDS.64 1 4 1 1 1 1 2
        let w16: Vec<u64> = modes.iter().map(|m| hopper(u32::MAX, 16, |l| m(l) * 16)).collect();
        assert_eq!(w16, [2, 8, 2, 2, 2, 2, 4]);
        let w8: Vec<u64> = modes.iter().map(|m| hopper(u32::MAX, 8, |l| m(l) * 8)).collect();
        assert_eq!(w8, [1, 4, 1, 1, 1, 1, 2]);
        // without pairs (and on Maxwell) quarter- and half-warps stay apart
        assert_eq!(cost32(u32::MAX, 16, |l| (l as u64 >> 4) * 32).wavefronts, 4);
        // conflicts are the wavefronts beyond one per group
        assert_eq!(cost32_hopper_with(u32::MAX, 16, true, |l| (l as u64 & 15) * 32, &mut Vec::new()).conflicts, 4);
        // stores do not pack
        assert_eq!(cost32_hopper_with(u32::MAX, 16, false, |_| 0, &mut Vec::new()).wavefronts, 4);
        // 4-byte loads are one group already
        assert_eq!(hopper(u32::MAX, 4, |_| 0), 1);
    }

    #[test]
    fn cc1_half_warps_and_16_banks() {
        // stride 1: each half-warp hits 16 distinct banks
        assert_eq!(cost16(u32::MAX, 4, |l| l as u64 * 4), BankCost { wavefronts: 2, conflicts: 0 });
        // stride 16 words: all 16 threads of a half-warp in bank 0
        assert_eq!(cost16(u32::MAX, 4, |l| l as u64 * 64), BankCost { wavefronts: 32, conflicts: 30 });
        // stride 2 words: 2-way conflicts
        assert_eq!(cost16(0xFFFF, 4, |l| l as u64 * 8), BankCost { wavefronts: 2, conflicts: 1 });
        // bytes of one word conflict on 1.x
        assert_eq!(cost16(0xF, 1, |l| l as u64), BankCost { wavefronts: 4, conflicts: 3 });
    }
}
