//! Global atomics on Hopper: the L1 sectors of a warp-level atomic or
//! reduction. Lanes on one address are served one after another, so a sector
//! is counted once for each lane of its most requested address: the sum over
//! the touched sectors of the largest number of lanes on one address in it.
//! Measured on the H200 by the single-warp probes of
//! `kernels/validation/suite.cu` (`l1tex__t_sectors_pipe_lsu_mem_global_op_{atom,red}.sum`):
//! 32 lanes on consecutive words: 4 sectors; on one word: 32; lanes `l` and
//! `l+16` on one word, 16 words: 4; words 8 apart: 32; 2 apart: 8. (An
//! atomic whose address ptxas proves warp-uniform is one lane's access,
//! counted so by the ptxas plan: `vectorize.rs`, `uniform.rs`.)

/// L1 sectors of a warp-level global atomic: lanes in `mask`, `bytes` each at `addr(lane)`.
pub fn sectors(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64, scratch: &mut Vec<u64>) -> u64 {
    scratch.clear();
    scratch.extend((0..32).filter(|l| mask >> l & 1 != 0).map(&addr));
    scratch.sort_unstable();
    // (sector, lanes on its most requested address), over runs of equal addresses
    let mut total = 0u64;
    let mut i = 0;
    let mut sector_best: Option<(u64, u64)> = None;
    while i < scratch.len() {
        let a = scratch[i];
        let mut j = i;
        while j < scratch.len() && scratch[j] == a {
            j += 1;
        }
        let n = (j - i) as u64;
        // an access spanning sectors touches each of them
        let (first, last) = (a / 32, (a + bytes.max(1) as u64 - 1) / 32);
        for s in first..=last {
            match sector_best {
                Some((cur, best)) if cur == s => sector_best = Some((s, best.max(n))),
                Some((_, best)) => {
                    total += best;
                    sector_best = Some((s, n));
                }
                None => sector_best = Some((s, n)),
            }
        }
        i = j;
    }
    if let Some((_, best)) = sector_best {
        total += best;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(stride: u64, span: u64) -> u64 {
        sectors(u32::MAX, 4, |l| 4096 + ((l as u64 * stride) % span) * 4, &mut Vec::new())
    }

    // The H200's atom_probe launches (stride, span): lane l adds at word (l * stride) % span.
    #[test]
    fn measured_probes() {
        assert_eq!(probe(1, 32), 4);
        assert_eq!(probe(0, 1), 32);
        assert_eq!(probe(1, 16), 4);
        assert_eq!(probe(8, 256), 32);
        assert_eq!(probe(2, 64), 8);
    }

    #[test]
    fn partial_warps_and_mixed_multiplicities() {
        // lanes 0..3 on word 0, lane 4 on word 1 (same sector), lane 5 in the next sector
        let a = [0u64, 0, 0, 0, 4, 32];
        assert_eq!(sectors(0x3F, 4, |l| a[l], &mut Vec::new()), 4 + 1);
        assert_eq!(sectors(0, 4, |_| 0, &mut Vec::new()), 0);
    }
}
