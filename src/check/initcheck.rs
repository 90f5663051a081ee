//! Reads of memory nothing wrote. Shared memory: per byte, in the CTA's
//! shadow ([`super::racecheck::Cell::init`]). Local memory: per thread and
//! byte ([`LocalInit`]). Global memory: what the host uploaded or zeroed is
//! written; only ranges declared uninitialised (a buffer allocated without
//! being filled, as `cudaMalloc` leaves it: `--uninit NAME`) are tracked
//! ([`GlobalInit`]), in a fixed order (CTA after CTA at the end of each
//! round), so the verdict does not depend on host threads.

use std::collections::HashMap;

/// Which bytes of each thread's local memory were written.
#[derive(Debug, Default)]
pub struct LocalInit {
    /// (warp, byte offset) → lanes that wrote it.
    written: HashMap<(u32, u64), u32>,
}

impl LocalInit {
    /// Lane `lane` of `warp` wrote `bytes` bytes at local offset `off`.
    pub fn write(&mut self, warp: u32, lane: u32, off: u64, bytes: u32) {
        for b in 0..bytes as u64 {
            *self.written.entry((warp, off + b)).or_default() |= 1 << lane;
        }
    }

    /// Whether lane `lane` of `warp` wrote every byte of `[off, off + bytes)`.
    pub fn is_written(&self, warp: u32, lane: u32, off: u64, bytes: u32) -> bool {
        (0..bytes as u64).all(|b| self.written.get(&(warp, off + b)).is_some_and(|m| m >> lane & 1 != 0))
    }
}

/// Global ranges allocated without contents, and which of their bytes the
/// kernels wrote since.
#[derive(Debug, Default, Clone)]
pub struct GlobalInit {
    /// (first address, written flag per byte).
    ranges: Vec<(u64, Vec<bool>)>,
}

impl GlobalInit {
    /// Tracks `len` bytes at `base`, none written.
    pub fn add(&mut self, base: u64, len: u64) {
        self.ranges.push((base, vec![false; len as usize]));
    }

    /// True when no range is tracked (global reads are never checked).
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// Whether `addr` is in a tracked range.
    pub fn tracks(&self, addr: u64) -> bool {
        self.ranges.iter().any(|(b, v)| addr >= *b && addr - b < v.len() as u64)
    }

    fn byte(&mut self, addr: u64) -> Option<&mut bool> {
        self.ranges
            .iter_mut()
            .find(|(b, v)| addr >= *b && addr - *b < v.len() as u64)
            .map(|(b, v)| &mut v[(addr - *b) as usize])
    }

    /// A write of `bytes` bytes at `addr`.
    pub fn write(&mut self, addr: u64, bytes: u32) {
        for a in addr..addr + bytes as u64 {
            if let Some(x) = self.byte(a) {
                *x = true;
            }
        }
    }

    /// A read of `bytes` bytes at `addr`: true when one of them was never written.
    pub fn read_uninit(&mut self, addr: u64, bytes: u32) -> bool {
        (addr..addr + bytes as u64).any(|a| self.byte(a).is_some_and(|x| !*x))
    }
}

/// One tracked global access, in issue order, for [`GlobalInit`].
#[derive(Debug, Clone, Copy)]
pub struct GlobalInitAccess {
    /// Warp.
    pub warp: u32,
    /// Lane.
    pub lane: u32,
    /// Instruction.
    pub pc: super::findings::Pc,
    /// Address.
    pub addr: u64,
    /// Bytes.
    pub bytes: u32,
    /// Bytes per element.
    pub elem: u32,
    /// A store (or atomic) rather than a load.
    pub write: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracked_bytes_start_unwritten() {
        let mut g = GlobalInit::default();
        g.add(1000, 8);
        assert!(g.read_uninit(1000, 4));
        g.write(1000, 4);
        assert!(!g.read_uninit(1000, 4));
        assert!(g.read_uninit(1002, 4));
        assert!(!g.read_uninit(2000, 4), "untracked memory counts as written");
        let mut l = LocalInit::default();
        l.write(1, 3, 16, 4);
        assert!(l.is_written(1, 3, 16, 4) && !l.is_written(1, 4, 16, 4) && !l.is_written(1, 3, 16, 8));
    }
}
