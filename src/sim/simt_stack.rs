//! The per-warp SIMT reconvergence stack (immediate post-dominator scheme, as
//! on the GT200-era GPUs): each entry is a path of the warp — a PC, the PC
//! where it rejoins its sibling path, and the lanes that follow it.

/// One stack entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct SimtEntry {
    /// Next instruction of this path.
    pub pc: u32,
    /// Reconvergence PC: when `pc` reaches it, the entry is popped.
    pub rpc: u32,
    /// Lanes on this path.
    pub mask: u32,
}

/// What a branch did to the warp.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchOutcome {
    /// All active lanes went the same way.
    Uniform,
    /// Lanes split; both paths were pushed.
    Diverged,
}

/// The stack of one call frame level is a contiguous segment of one vector;
/// entries below `base` belong to callers.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SimtStack {
    /// Entries, bottom first.
    pub entries: Vec<SimtEntry>,
}

impl SimtStack {
    /// The running path (top of stack).
    #[inline]
    pub fn top(&self) -> Option<&SimtEntry> {
        self.entries.last()
    }

    /// Mutable top.
    #[inline]
    pub fn top_mut(&mut self) -> Option<&mut SimtEntry> {
        self.entries.last_mut()
    }

    /// Pushes a path.
    pub fn push(&mut self, e: SimtEntry) {
        self.entries.push(e);
    }

    /// Pops entries whose PC reached their reconvergence PC (above `base`).
    /// Returns how many reconvergences happened.
    #[inline]
    pub fn reconverge(&mut self, base: usize) -> u32 {
        let mut n = 0;
        while self.entries.len() > base + 1 {
            let t = self.entries[self.entries.len() - 1];
            if t.pc != t.rpc {
                break;
            }
            self.entries.pop();
            n += 1;
        }
        n
    }

    /// Applies a branch executed by the top path: `taken` lanes go to `target`, the
    /// other active lanes fall through to `next`; divergent paths rejoin at `rpc`.
    /// The fall-through path runs first; the taken path waits below it.
    pub fn branch(&mut self, taken: u32, target: u32, next: u32, rpc: u32) -> BranchOutcome {
        let top = *self.entries.last().expect("branch on empty stack");
        let not_taken = top.mask & !taken;
        if not_taken == 0 {
            self.entries.last_mut().expect("top").pc = target;
            return BranchOutcome::Uniform;
        }
        if taken == 0 {
            self.entries.last_mut().expect("top").pc = next;
            return BranchOutcome::Uniform;
        }
        // The current entry becomes the reconvergence entry; then the two paths.
        // (With `rpc == EXIT_PC` the paths rejoin only as their lanes finish; the
        // reconvergence entry is then dropped when its last lane retires.)
        self.entries.last_mut().expect("top").pc = rpc;
        self.entries.push(SimtEntry { pc: target, rpc, mask: taken });
        self.entries.push(SimtEntry { pc: next, rpc, mask: not_taken });
        BranchOutcome::Diverged
    }

    /// Removes `lanes` (finished threads) from all entries at or above `base`,
    /// dropping entries left empty. Returns true when no entry above `base` remains.
    pub fn retire_lanes(&mut self, base: usize, lanes: u32) -> bool {
        for e in &mut self.entries[base..] {
            e.mask &= !lanes;
        }
        let mut i = base;
        while i < self.entries.len() {
            if self.entries[i].mask == 0 {
                self.entries.remove(i);
            } else {
                i += 1;
            }
        }
        self.entries.len() <= base
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::cfg::EXIT_PC;

    #[test]
    fn divergent_branch_pushes_two_paths_then_pops_at_join() {
        let mut s = SimtStack::default();
        s.push(SimtEntry { pc: 0, rpc: EXIT_PC, mask: 0xFFFF_FFFF });
        let o = s.branch(0x5555_5555, 10, 1, 20);
        assert_eq!(o, BranchOutcome::Diverged);
        assert_eq!(s.entries.len(), 3);
        assert_eq!(*s.top().unwrap(), SimtEntry { pc: 1, rpc: 20, mask: 0xAAAA_AAAA });
        s.top_mut().unwrap().pc = 20;
        assert_eq!(s.reconverge(0), 1);
        assert_eq!(*s.top().unwrap(), SimtEntry { pc: 10, rpc: 20, mask: 0x5555_5555 });
        s.top_mut().unwrap().pc = 20;
        assert_eq!(s.reconverge(0), 1);
        assert_eq!(*s.top().unwrap(), SimtEntry { pc: 20, rpc: EXIT_PC, mask: 0xFFFF_FFFF });
    }

    #[test]
    fn uniform_branch_moves_pc() {
        let mut s = SimtStack::default();
        s.push(SimtEntry { pc: 0, rpc: EXIT_PC, mask: 0xF });
        assert_eq!(s.branch(0xF, 7, 1, 3), BranchOutcome::Uniform);
        assert_eq!(s.top().unwrap().pc, 7);
    }

    #[test]
    fn retiring_lanes_drops_empty_paths() {
        let mut s = SimtStack::default();
        s.push(SimtEntry { pc: 0, rpc: EXIT_PC, mask: 0xF });
        s.branch(0x3, 10, 1, EXIT_PC);
        assert_eq!(s.entries.len(), 3);
        assert!(!s.retire_lanes(0, 0xC));
        assert_eq!(s.entries.len(), 2);
        assert_eq!(*s.top().unwrap(), SimtEntry { pc: 10, rpc: EXIT_PC, mask: 0x3 });
        assert!(s.retire_lanes(0, 0x3));
    }
}
