//! Global-memory coalescing of compute capability 1.2/1.3 (GT200, the GTX 280
//! of theses 000 and 002), per half-warp, as the CUDA Programming Guide
//! (App. G.3.2) states it:
//!
//! 1. Find the segment containing the address of the lowest-numbered active
//!    thread: 32 B for 1-byte words, 64 B for 2-byte words, 128 B for 4-, 8-
//!    and 16-byte words.
//! 2. Find all other active threads whose address lies in that segment.
//! 3. If the transaction is 128 B and only its lower or upper half is used,
//!    shrink it to 64 B; if 64 B and only one half is used, to 32 B.
//! 4. Issue it and mark those threads serviced; repeat until all are.

/// Transactions by size.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Transactions {
    /// 32-byte transactions.
    pub t32: u64,
    /// 64-byte transactions.
    pub t64: u64,
    /// 128-byte transactions.
    pub t128: u64,
}

impl Transactions {
    /// All transactions.
    pub fn count(&self) -> u64 {
        self.t32 + self.t64 + self.t128
    }

    /// Bytes moved.
    pub fn bytes(&self) -> u64 {
        32 * self.t32 + 64 * self.t64 + 128 * self.t128
    }

    fn add(&mut self, size: u64) {
        match size {
            32 => self.t32 += 1,
            64 => self.t64 += 1,
            _ => self.t128 += 1,
        }
    }

    /// Adds `o`.
    pub fn merge(&mut self, o: &Transactions) {
        self.t32 += o.t32;
        self.t64 += o.t64;
        self.t128 += o.t128;
    }
}

/// Transactions of one half-warp: `lanes` are (address, bytes) of its active threads
/// (at most 16; every thread accesses the same number of bytes).
pub fn half_warp(lanes: &[(u64, u32)]) -> Transactions {
    let mut addr = [0u64; 16];
    for (k, (a, _)) in lanes.iter().take(16).enumerate() {
        addr[k] = *a;
    }
    let bytes = lanes.first().map(|l| l.1).unwrap_or(4);
    let mask = if lanes.len() >= 16 { u16::MAX } else { (1u16 << lanes.len()) - 1 };
    half_warp_masked(&addr, bytes, mask)
}

/// The segment algorithm over the threads in `mask` (no allocation).
fn half_warp_masked(addr: &[u64; 16], bytes: u32, mask: u16) -> Transactions {
    let mut t = Transactions::default();
    half_warp_segments(addr, bytes, mask, |_, size, _| t.add(size));
    t
}

/// Runs the segment algorithm over the threads in `mask`, calling
/// `issue(base, size, threads)` for each transaction (threads as a mask of `addr` indices).
fn half_warp_segments(addr: &[u64; 16], bytes: u32, mut mask: u16, mut issue: impl FnMut(u64, u64, u16)) {
    let seg = match bytes {
        1 => 32u64,
        2 => 64,
        _ => 128,
    };
    while mask != 0 {
        let base = addr[mask.trailing_zeros() as usize] / seg * seg;
        let (mut lo, mut hi) = (u64::MAX, 0u64);
        let mut rest = mask;
        let mut served = 0u16;
        while rest != 0 {
            let k = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let a = addr[k];
            if a >= base && a < base + seg {
                lo = lo.min(a);
                hi = hi.max(a + bytes as u64);
                served |= 1 << k;
            }
        }
        mask &= !served;
        let (mut b, mut size) = (base, seg);
        while size > 32 {
            let half = size / 2;
            if hi <= b + half {
                size = half;
            } else if lo >= b + half {
                b += half;
                size = half;
            } else {
                break;
            }
        }
        issue(b, size, served);
    }
}

/// One transaction of a warp-level access, for display.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Segment {
    /// Half-warp (0 or 1).
    pub half: u32,
    /// Address of the first byte moved.
    pub base: u64,
    /// 32, 64 or 128 bytes.
    pub size: u64,
    /// Lanes it serves (warp lane mask).
    pub lanes: u32,
}

/// Calls `f(half, addresses, lanes)` for each half-warp with active lanes
/// (addresses of inactive lanes are 0; `lanes` is the half-warp's 16-bit mask).
fn half_warps(mask: u32, addr: impl Fn(usize) -> u64, mut f: impl FnMut(u32, &[u64; 16], u16)) {
    for h in 0..2u32 {
        let m = (mask >> (16 * h)) as u16;
        if m == 0 {
            continue;
        }
        let mut a = [0u64; 16];
        for (k, slot) in a.iter_mut().enumerate() {
            if m >> k & 1 != 0 {
                *slot = addr(16 * h as usize + k);
            }
        }
        f(h, &a, m);
    }
}

/// The transactions of [`warp`], listed in issue order (for teaching views).
pub fn warp_segments(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64) -> Vec<Segment> {
    let mut v = Vec::new();
    half_warps(mask, addr, |h, a, m| {
        half_warp_segments(a, bytes, m, |base, size, lanes| {
            v.push(Segment { half: h, base, size, lanes: (lanes as u32) << (16 * h) })
        })
    });
    v
}

/// Transactions of a warp-level access: each half-warp separately. A 16-byte
/// word access by a full half-warp spans two segments and so is split.
pub fn warp(mask: u32, bytes: u32, addr: impl Fn(usize) -> u64) -> Transactions {
    let mut t = Transactions::default();
    half_warps(mask, addr, |_, a, m| t.merge(&half_warp_masked(a, bytes, m)));
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hw(addrs: impl Iterator<Item = u64>, w: u32) -> Transactions {
        half_warp(&addrs.map(|a| (a, w)).collect::<Vec<_>>())
    }

    #[test]
    fn segments_agree_with_counts() {
        for (stride, bytes) in [(1u64, 4u32), (2, 4), (1, 8), (1, 16), (3, 4), (1, 1), (1, 2), (64, 4)] {
            let addr = |l: usize| 0x1000 + l as u64 * stride * bytes as u64;
            let t = warp(u32::MAX, bytes, addr);
            let segs = warp_segments(u32::MAX, bytes, addr);
            assert_eq!(segs.len() as u64, t.count(), "stride {stride} bytes {bytes}");
            assert_eq!(segs.iter().map(|s| s.size).sum::<u64>(), t.bytes());
            let served = segs.iter().fold(0u32, |m, s| {
                assert_eq!(m & s.lanes, 0, "a lane served twice");
                m | s.lanes
            });
            assert_eq!(served, u32::MAX);
        }
        // a coalesced float load: one 64-byte transaction per half-warp
        let s = warp_segments(u32::MAX, 4, |l| 0x1000 + 4 * l as u64);
        assert_eq!(
            s,
            vec![
                Segment { half: 0, base: 0x1000, size: 64, lanes: 0xFFFF },
                Segment { half: 1, base: 0x1040, size: 64, lanes: 0xFFFF_0000 }
            ]
        );
    }

    // CUDA C Programming Guide, CC 1.2/1.3 examples (Figure G-2 and text).
    #[test]
    fn aligned_consecutive_words_are_one_64_byte_transaction() {
        // 16 threads x 4 bytes, aligned: 64 bytes in a 128-byte segment's lower half.
        let t = hw((0..16).map(|k| 1024 + 4 * k), 4);
        assert_eq!(t, Transactions { t32: 0, t64: 1, t128: 0 });
    }

    #[test]
    fn permuted_words_still_coalesce() {
        let t = hw((0..16).map(|k| 1024 + 4 * ((k * 7) % 16)), 4);
        assert_eq!(t.count(), 1);
        assert_eq!(t.t64, 1);
    }

    #[test]
    fn misaligned_run_crossing_a_segment_gives_two_transactions() {
        // starting at 1024 + 68: spans bytes 1092..1156, crossing 1152
        let t = hw((0..16).map(|k| 1024 + 68 + 4 * k), 4);
        assert_eq!(t.count(), 2);
        assert_eq!((t.t64, t.t32), (1, 1), "one 64-byte and one 32-byte transaction: {t:?}");
    }

    #[test]
    fn eight_byte_words_use_a_128_byte_segment() {
        let t = hw((0..16).map(|k| 2048 + 8 * k), 8);
        assert_eq!(t, Transactions { t32: 0, t64: 0, t128: 1 });
    }

    #[test]
    fn sixteen_byte_words_need_two_segments() {
        let t = hw((0..16).map(|k| 4096 + 16 * k), 16);
        assert_eq!(t, Transactions { t32: 0, t64: 0, t128: 2 });
    }

    #[test]
    fn scattered_words_are_one_transaction_each() {
        let t = hw((0..16).map(|k| k * 4096), 4);
        assert_eq!(t.t32, 16);
    }

    #[test]
    fn same_address_is_one_32_byte_transaction() {
        assert_eq!(hw((0..16).map(|_| 512), 4), Transactions { t32: 1, t64: 0, t128: 0 });
    }

    #[test]
    fn bytes_use_32_byte_segments() {
        let t = hw((0..16).map(|k| 96 + k), 1);
        assert_eq!(t, Transactions { t32: 1, t64: 0, t128: 0 });
    }

    #[test]
    fn warp_counts_half_warps_separately() {
        let t = warp(u32::MAX, 4, |l| 1024 + 4 * l as u64);
        assert_eq!(t, Transactions { t32: 0, t64: 2, t128: 0 });
    }
}
