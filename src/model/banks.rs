//! Shared-memory banks.
//!
//! - 32 banks × 4 bytes (Maxwell and later): the lanes of a warp-level access
//!   are served in groups of at most 128 requested bytes (all 32 lanes for
//!   4-byte accesses, 16 for 8-byte, 8 for 16-byte). A group needs as many
//!   wavefronts as the most distinct 4-byte words any one bank must deliver;
//!   lanes reading the same word share it. Bank conflicts are the wavefronts
//!   beyond one per group — the minimum for the access width — as Nsight
//!   Compute's `l1tex__data_bank_conflicts_pipe_lsu_mem_shared_*` counts them.
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
    let group = (128 / bytes.clamp(4, 16)) as usize;
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
