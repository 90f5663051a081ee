//! A set-associative LRU cache of lines made of 32-byte sectors, as L1TEX and
//! the texture caches are organised. Hits are counted per sector: a hit needs
//! the line's tag present and the sector's data valid.

/// The cache.
#[derive(Debug, Clone)]
pub struct SectorCache {
    sectors_per_line: u64,
    sets: usize,
    ways: usize,
    /// (tag, valid-sector bits, last use) per way, `sets * ways` entries.
    lines: Vec<(u64, u32, u64)>,
    clock: u64,
}

impl SectorCache {
    /// A cache of `bytes` bytes with lines of `line_bytes` (a multiple of 32) and `ways` ways.
    pub fn new(bytes: u64, line_bytes: u64, ways: usize) -> Self {
        let lines = (bytes / line_bytes).max(1) as usize;
        let ways = ways.clamp(1, lines);
        let sets = (lines / ways).max(1);
        SectorCache {
            sectors_per_line: (line_bytes / 32).max(1),
            sets,
            ways,
            lines: vec![(u64::MAX, 0, 0); sets * ways],
            clock: 0,
        }
    }

    /// Looks up sector number `sector` (address / 32), filling it on a miss.
    /// Returns true on a hit.
    pub fn access(&mut self, sector: u64) -> bool {
        self.clock += 1;
        let line = sector / self.sectors_per_line;
        let bit = 1u32 << (sector % self.sectors_per_line);
        let set = (line % self.sets as u64) as usize;
        let ways = &mut self.lines[set * self.ways..(set + 1) * self.ways];
        if let Some(w) = ways.iter_mut().find(|w| w.0 == line) {
            w.2 = self.clock;
            let hit = w.1 & bit != 0;
            w.1 |= bit;
            return hit;
        }
        let victim = ways.iter_mut().min_by_key(|w| w.2).expect("at least one way");
        *victim = (line, bit, self.clock);
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sector_hits_need_the_sector() {
        let mut c = SectorCache::new(1024, 128, 2);
        assert!(!c.access(0));
        assert!(c.access(0));
        assert!(!c.access(1), "same line, other sector: a miss");
        assert!(c.access(1));
    }

    #[test]
    fn lru_evicts_the_oldest_line() {
        // 2 lines, fully associative
        let mut c = SectorCache::new(256, 128, 2);
        c.access(0);
        c.access(4);
        c.access(0);
        c.access(8); // evicts line 1 (sector 4)
        assert!(c.access(0));
        assert!(!c.access(4));
    }
}
