//! Device (global) memory: allocations at fixed addresses, word storage that
//! host threads running different CTAs may share, and the generic-address windows.
//!
//! Storage is `AtomicU32` words accessed with `Relaxed` ordering: on x86 and ARM
//! these are plain loads and stores, and they keep concurrent CTAs sound without
//! `unsafe`. Accesses are naturally aligned (the executor faults otherwise), so an
//! access never straddles two allocations and at most two words.

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// First global address handed out (address 0 and the low 4 GiB stay unmapped).
pub const GLOBAL_BASE: u64 = 0x0000_0001_0000_0000;
/// Generic addresses `SHARED_WINDOW + off` name shared-memory offset `off`.
pub const SHARED_WINDOW: u64 = 0x0000_7000_0000_0000;
/// Generic addresses `LOCAL_WINDOW + off` name the thread's local offset `off`.
pub const LOCAL_WINDOW: u64 = 0x0000_7100_0000_0000;
/// Generic addresses `CONST_WINDOW + off` name constant-bank offset `off`.
pub const CONST_WINDOW: u64 = 0x0000_7200_0000_0000;
/// Generic addresses `PARAM_WINDOW + off` name kernel-parameter offset `off`.
pub const PARAM_WINDOW: u64 = 0x0000_7300_0000_0000;
/// Size of each window.
pub const WINDOW_SIZE: u64 = 1 << 32;
/// Allocations are aligned to this and separated by at least one unmapped gap of it.
pub const ALLOC_ALIGN: u64 = 256;

/// Which space a generic address falls in, and the offset there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GenericTarget {
    /// A global address (unchanged).
    Global(u64),
    /// Shared-memory offset.
    Shared(u64),
    /// Local-memory offset.
    Local(u64),
    /// Constant-bank offset.
    Const(u64),
    /// Kernel-parameter offset.
    Param(u64),
}

/// Decodes a generic address.
pub fn decode_generic(addr: u64) -> GenericTarget {
    let in_win = |w: u64| addr >= w && addr - w < WINDOW_SIZE;
    if in_win(SHARED_WINDOW) {
        GenericTarget::Shared(addr - SHARED_WINDOW)
    } else if in_win(LOCAL_WINDOW) {
        GenericTarget::Local(addr - LOCAL_WINDOW)
    } else if in_win(CONST_WINDOW) {
        GenericTarget::Const(addr - CONST_WINDOW)
    } else if in_win(PARAM_WINDOW) {
        GenericTarget::Param(addr - PARAM_WINDOW)
    } else {
        GenericTarget::Global(addr)
    }
}

/// One device allocation.
#[derive(Debug)]
pub struct Allocation {
    /// Its first address.
    pub base: u64,
    /// Its length in bytes.
    pub len: u64,
    /// A name for error messages (buffer or variable name).
    pub name: String,
    words: Vec<AtomicU32>,
}

impl Allocation {
    /// Loads `size` (1, 2, 4 or 8) bytes at aligned offset `off`, zero-extended.
    #[inline(always)]
    pub fn load(&self, off: u64, size: u32) -> u64 {
        let w = (off >> 2) as usize;
        match size {
            4 => self.words[w].load(Relaxed) as u64,
            8 => self.words[w].load(Relaxed) as u64 | (self.words[w + 1].load(Relaxed) as u64) << 32,
            1 => (self.words[w].load(Relaxed) >> ((off & 3) * 8)) as u64 & 0xFF,
            2 => (self.words[w].load(Relaxed) >> ((off & 3) * 8)) as u64 & 0xFFFF,
            _ => unreachable!("access size {size}"),
        }
    }

    /// Stores the low `size` bytes of `v` at aligned offset `off`.
    #[inline(always)]
    pub fn store(&self, off: u64, size: u32, v: u64) {
        let w = (off >> 2) as usize;
        match size {
            4 => self.words[w].store(v as u32, Relaxed),
            8 => {
                self.words[w].store(v as u32, Relaxed);
                self.words[w + 1].store((v >> 32) as u32, Relaxed);
            }
            1 | 2 => {
                let sh = (off & 3) * 8;
                let m = if size == 1 { 0xFFu32 } else { 0xFFFF } << sh;
                // Clearing then setting only this access's bits keeps concurrent
                // stores to the other bytes of the word intact.
                self.words[w].fetch_and(!m, Relaxed);
                self.words[w].fetch_or(((v as u32) << sh) & m, Relaxed);
            }
            _ => unreachable!("access size {size}"),
        }
    }

    /// Copies the allocation's bytes `[off, off + out.len())` into `out`.
    pub fn read_bytes(&self, off: u64, out: &mut [u8]) {
        for (k, b) in out.iter_mut().enumerate() {
            *b = self.load(off + k as u64, 1) as u8;
        }
    }

    /// Writes `data` at `off`.
    pub fn write_bytes(&self, off: u64, data: &[u8]) {
        let mut k = 0;
        while k < data.len() {
            let o = off + k as u64;
            if o.is_multiple_of(4) && k + 4 <= data.len() {
                let v = u32::from_le_bytes(data[k..k + 4].try_into().expect("4 bytes"));
                self.store(o, 4, v as u64);
                k += 4;
            } else {
                self.store(o, 1, data[k] as u64);
                k += 1;
            }
        }
    }
}

/// All device allocations of one [`crate::sim::Device`].
#[derive(Debug, Default)]
pub struct DeviceMemory {
    allocs: Vec<Allocation>,
    next: u64,
}

impl DeviceMemory {
    /// Creates an empty memory.
    pub fn new() -> Self {
        DeviceMemory { allocs: Vec::new(), next: GLOBAL_BASE }
    }

    /// Allocates `len` zeroed bytes and returns the base address.
    pub fn alloc(&mut self, len: u64, name: &str) -> u64 {
        let base = self.next;
        let words = len.div_ceil(4).max(1) as usize;
        self.allocs.push(Allocation {
            base,
            len,
            name: name.to_string(),
            words: (0..words).map(|_| AtomicU32::new(0)).collect(),
        });
        self.next = base + len.div_ceil(ALLOC_ALIGN).max(1) * ALLOC_ALIGN + ALLOC_ALIGN;
        base
    }

    /// Releases every allocation (addresses are not reused).
    pub fn clear(&mut self) {
        self.allocs.clear();
    }

    /// The allocation containing `[addr, addr + size)`, with the offset of `addr` in it.
    #[inline]
    pub fn find(&self, addr: u64, size: u64) -> Option<(&Allocation, u64)> {
        let i = self.allocs.partition_point(|a| a.base <= addr);
        if i == 0 {
            return None;
        }
        let a = &self.allocs[i - 1];
        let off = addr - a.base;
        (off.checked_add(size)? <= a.len).then_some((a, off))
    }

    /// All allocations, in address order.
    pub fn allocations(&self) -> &[Allocation] {
        &self.allocs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn allocations_have_gaps_and_bounds() {
        let mut m = DeviceMemory::new();
        let a = m.alloc(10, "a");
        let b = m.alloc(4, "b");
        assert!(b >= a + 10 + ALLOC_ALIGN);
        assert!(m.find(a + 8, 2).is_some());
        assert!(m.find(a + 8, 4).is_none());
        assert!(m.find(a - 1, 1).is_none());
        assert!(m.find(b + 4, 1).is_none());
    }

    #[test]
    fn sub_word_stores_keep_neighbours() {
        let mut m = DeviceMemory::new();
        let a = m.alloc(8, "a");
        let (al, _) = m.find(a, 8).unwrap();
        al.store(0, 8, 0x1122_3344_5566_7788);
        al.store(1, 1, 0xAB);
        al.store(6, 2, 0xCDEF);
        assert_eq!(al.load(0, 8), 0xCDEF_3344_5566_AB88);
        assert_eq!(al.load(4, 4), 0xCDEF_3344);
    }

    #[test]
    fn generic_windows_decode() {
        assert_eq!(decode_generic(SHARED_WINDOW + 12), GenericTarget::Shared(12));
        assert_eq!(decode_generic(LOCAL_WINDOW), GenericTarget::Local(0));
        assert_eq!(decode_generic(GLOBAL_BASE), GenericTarget::Global(GLOBAL_BASE));
    }
}
