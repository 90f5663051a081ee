//! The traversal work Fig. 3's comparison counts (003:L181-189): rays traced,
//! inner-node steps, leaf visits, triangle tests, short-stack pushes and pops,
//! and kd-backtrack's climbs to a parent.
//!
//! The kernel keeps no tallies. A line of `kernels/lin2017/path.cu` ending in
//! `// @count NAME OPCODE` executes exactly one `OPCODE` instruction per
//! `NAME` event; [`tagged`] sums, over every PTX instruction that `.loc`
//! places on such a line, the lanes that executed it (the emulator's
//! per-instruction counters, fidelity `instructions` or above). The native
//! mirror counts the same events as it traces (`native::Tracer::path_counted`);
//! `tests/lin2017_traversal.rs` holds the two equal.

use std::collections::BTreeMap;

use crate::host::rt_kernels::{CountTag, count_tags, tagged_counts};
use crate::ptx::ir::Program;
use crate::sim::counters::InstProfile;

/// The kernel's CUDA source, whose `@count` tags name the lines counted.
pub const SOURCE: &str = include_str!("../../../kernels/lin2017/path.cu");
/// The source's path as the PTX's `.file` directive names it (suffix).
pub const SOURCE_FILE: &str = "kernels/lin2017/path.cu";

/// Traversal events, summed over rays.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    /// Rays traced (camera, bounce and shadow rays).
    pub rays: u64,
    /// Inner-node steps (a split distance computed).
    pub inner: u64,
    /// Leaves visited.
    pub leaves: u64,
    /// Triangle tests (the affine test's distance division).
    pub tri_tests: u64,
    /// Short-stack pushes (8-byte entries).
    pub pushes: u64,
    /// Short-stack pops.
    pub pops: u64,
    /// kd-backtrack: parent links followed (a node box read and intersected each).
    pub ascents: u64,
}

impl Counts {
    /// Adds `o` into `self`.
    pub fn add(&mut self, o: &Counts) {
        self.rays += o.rays;
        self.inner += o.inner;
        self.leaves += o.leaves;
        self.tri_tests += o.tri_tests;
        self.pushes += o.pushes;
        self.pops += o.pops;
        self.ascents += o.ascents;
    }

    /// From the tag names' totals.
    pub fn from_tags(c: &BTreeMap<String, u64>) -> Counts {
        let get = |n: &str| c.get(n).copied().unwrap_or(0);
        Counts {
            rays: get("rays"),
            inner: get("inner"),
            leaves: get("leaves"),
            tri_tests: get("tri_tests"),
            pushes: get("push"),
            pops: get("pop"),
            ascents: get("ascents"),
        }
    }
}

/// Russian roulette's tests (003:L267-271), read off `roulette()`'s two
/// tagged lines: every test, and those whose mask's largest channel q was
/// below 1 (then the path ends with probability 1 − q, or goes on divided by
/// q). The rest had q ≥ 1: the mask the thesis takes to be "always less than
/// or equal to 1" (003:L269) was not, and the path went on undivided.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Roulettes {
    /// Roulette tests (one per sampled bounce of a path or a light subpath).
    pub tests: u64,
    /// Of them, tests whose mask's largest channel was below 1.
    pub below_one: u64,
}

impl Roulettes {
    /// From the tag names' totals.
    pub fn from_tags(c: &BTreeMap<String, u64>) -> Roulettes {
        let get = |n: &str| c.get(n).copied().unwrap_or(0);
        Roulettes { tests: get("roulettes"), below_one: get("roulettes_below_one") }
    }

    /// Adds `o` into `self`.
    pub fn add(&mut self, o: &Roulettes) {
        self.tests += o.tests;
        self.below_one += o.below_one;
    }

    /// Tests whose mask had a channel of 1 or more (003:L269's claim broken).
    pub fn at_or_above_one(&self) -> u64 {
        self.tests - self.below_one
    }
}

/// The `@count` tags of `kernels/lin2017/path.cu`.
pub fn tags() -> Vec<CountTag> {
    count_tags(SOURCE)
}

/// Per tag name, the lanes that executed the tagged instructions (guard true)
/// in `profile`, over every PTX instruction on a tagged line of `path.cu`
/// whose opcode is the tag's.
pub fn tagged(prog: &Program, profile: &InstProfile, tags: &[CountTag]) -> BTreeMap<String, u64> {
    tagged_counts(prog, profile, SOURCE_FILE, tags, |c| c.pred_on)
}
