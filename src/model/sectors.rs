//! Sector-based coalescing (Maxwell and later, Hopper included): a warp-level
//! global or local access is one request for the set of 32-byte sectors its
//! active lanes touch, as Nsight Compute counts `l1tex__t_sectors_*`.

/// Bytes per sector.
pub const SECTOR: u64 = 32;

/// Local memory is interleaved across the threads of a warp: 4-byte word `w` of
/// lane `l` lives at `base + (w * 32 + l) * 4`. Returns that address for byte
/// offset `off` of lane `lane`, in a region private to the warp `warp_key`.
pub fn local_physical(warp_key: u64, lane: usize, off: u64) -> u64 {
    (warp_key << 32) + ((off / 4) * 32 + lane as u64) * 4 + off % 4
}

/// The distinct sectors touched by the lanes in `mask`, each accessing `bytes`
/// bytes at `addr(lane)`. Sorted, without duplicates.
pub fn sectors(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64) -> Vec<u64> {
    let mut v = Vec::with_capacity(32);
    sectors_into(mask, bytes, addr, &mut v);
    v
}

/// [`sectors`] into `v` (cleared first), so that a caller reusing `v` allocates nothing.
///
/// Lanes of a warp mostly touch their sectors in ascending order, several
/// lanes one sector: a sector equal to the last one pushed is not pushed
/// again, and when every sector came in ascending order the list is already
/// sorted and free of duplicates, so the sort is skipped (the result is the
/// same sorted set either way).
pub fn sectors_into(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64, v: &mut Vec<u64>) {
    v.clear();
    let span = bytes.max(1) as u64 - 1;
    let mut sorted = true;
    // the last sector pushed (none yet: no sector number reaches u64::MAX)
    let mut top = u64::MAX;
    let mut m = mask;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let a = addr(l);
        let (first, last) = (a / SECTOR, (a + span) / SECTOR);
        // first..=last (empty only if `a + span` wrapped), without
        // `RangeInclusive`'s bookkeeping per step
        if first > last {
            continue;
        }
        let mut s = first;
        loop {
            if s != top {
                sorted &= top == u64::MAX || top < s;
                v.push(s);
                top = s;
            }
            if s >= last {
                break;
            }
            s += 1;
        }
    }
    if !sorted {
        v.sort_unstable();
        v.dedup();
    }
}

/// Sectors of a local-memory access (interleaved layout, see [`local_physical`]).
pub fn local_sectors(warp_key: u64, mask: u32, bytes: u32, off: impl Fn(usize) -> u64) -> Vec<u64> {
    let mut v = Vec::with_capacity(32);
    local_sectors_into(warp_key, mask, bytes, off, &mut v);
    v
}

/// [`local_sectors`] into `v` (cleared first).
pub fn local_sectors_into(warp_key: u64, mask: u32, bytes: u32, off: impl Fn(usize) -> u64, v: &mut Vec<u64>) {
    v.clear();
    for l in 0..32 {
        if mask >> l & 1 == 0 {
            continue;
        }
        let o = off(l);
        // each 4-byte word of the access lands 128 bytes after the previous one
        let mut w = o / 4 * 4;
        while w < o + bytes.max(1) as u64 {
            v.push(local_physical(warp_key, l, w) / SECTOR);
            w += 4;
        }
    }
    v.sort_unstable();
    v.dedup();
}

#[cfg(test)]
mod tests {
    use super::*;

    // Worked examples from the Nsight Compute reference points of an H100
    // (../shared/docs/ptx-toolchain.md): one 4-byte load per thread.
    #[test]
    fn strided_float_loads() {
        let base = 0x1_0000_0000u64;
        let n = |stride: u64, offset: u64| sectors(u32::MAX, 4, |l| base + (l as u64 * stride + offset) * 4).len();
        assert_eq!(n(1, 0), 4);
        assert_eq!(n(1, 1), 5);
        assert_eq!(n(2, 0), 8);
        assert_eq!(n(4, 0), 16);
        assert_eq!(n(8, 0), 32);
        assert_eq!(n(32, 0), 32);
        assert_eq!(n(0, 0), 1);
    }

    #[test]
    fn vector_loads_span_sectors() {
        let n = sectors(u32::MAX, 16, |l| l as u64 * 16).len();
        assert_eq!(n, 16);
        assert_eq!(sectors(1, 16, |_| 24).len(), 2, "a misaligned span crosses a sector boundary");
    }

    #[test]
    fn sectors_come_sorted_and_distinct_in_any_lane_order() {
        // ascending, descending, repeated and scattered lane addresses, partial masks
        let layouts: [fn(usize) -> u64; 5] = [
            |l| 0x1000 + 4 * l as u64,
            |l| 0x2000 - 8 * l as u64,
            |l| 0x3000 + 64 * (l as u64 % 3),
            |l| 0x4000 + (l as u64 * 7919 % 31) * 40,
            |_| 0x5010,
        ];
        for addr in layouts {
            for mask in [u32::MAX, 0x8000_0001, 0x0F0F_F0F0, 1, 0] {
                for bytes in [1, 4, 8, 16] {
                    let mut want: Vec<u64> = (0..32)
                        .filter(|l| mask >> l & 1 != 0)
                        .flat_map(|l| addr(l) / SECTOR..=(addr(l) + bytes as u64 - 1) / SECTOR)
                        .collect();
                    want.sort_unstable();
                    want.dedup();
                    assert_eq!(sectors(mask, bytes, addr), want, "mask {mask:#x}, {bytes} bytes");
                }
            }
        }
    }

    #[test]
    fn same_local_offset_coalesces() {
        // every lane at local offset 8: 32 consecutive words = 4 sectors
        assert_eq!(local_sectors(0, u32::MAX, 4, |_| 8).len(), 4);
        // an 8-byte access: two words 128 bytes apart per lane = 8 sectors
        assert_eq!(local_sectors(0, u32::MAX, 8, |_| 8).len(), 8);
        // lanes at different offsets 16 words apart spread out
        assert_eq!(local_sectors(0, u32::MAX, 4, |l| l as u64 * 64).len(), 32);
    }
}
