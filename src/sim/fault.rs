//! Faults: what went wrong while a kernel ran, and where. A fault stops the
//! launch and is returned as a value; the device stays usable.

use std::fmt;

use crate::ptx::ir::MemSpace;

/// What kind of fault.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub enum FaultKind {
    /// An address outside every allocation (or outside the space's size).
    OutOfBounds {
        /// Space as resolved (generic addresses are resolved first).
        space: MemSpace,
        /// The faulting address (offset within the space for non-global spaces).
        addr: u64,
        /// Access size in bytes.
        size: u32,
    },
    /// An address not aligned to the access size.
    Misaligned {
        /// Space as resolved.
        space: MemSpace,
        /// The faulting address.
        addr: u64,
        /// Required alignment.
        size: u32,
    },
    /// A write to a read-only space (const, kernel parameters).
    ReadOnly {
        /// The space.
        space: MemSpace,
    },
    /// `bar.sync` executed by only part of a warp's live threads.
    DivergentBarrier {
        /// Lanes that reached the barrier.
        active: u32,
        /// Lanes alive in the warp.
        live: u32,
    },
    /// `bar.sync`/`barrier` with a barrier id past 15, or a thread count that
    /// is not a positive multiple of the warp size within the CTA's warps
    /// (undefined on the GPU; `docs/limits.md`).
    BadBarrier {
        /// The barrier id (0 to 15 are valid).
        id: u32,
        /// The thread count operand, when given.
        count: Option<u32>,
        /// The CTA's threads in whole warps (the most a count may be).
        cta_threads: u32,
    },
    /// A warp-synchronous instruction (`shfl.sync`, `vote.sync`,
    /// `redux.sync`, `match.sync`, `bar.warp.sync`) whose member mask leaves
    /// out a lane that executes it, or (not `bar.warp.sync`) names live lanes
    /// of the warp that do not execute it with it (on another path, or
    /// predicated off): undefined on the GPU.
    MemberMask {
        /// The member mask of the lane in error.
        mask: u32,
        /// The lane in error (the lowest one), whose mask this is: one its
        /// own mask leaves out, or one whose mask names the lanes that do not
        /// execute it. Other lanes may hold other masks (member groups).
        lane: u32,
        /// Lanes that execute the instruction.
        active: u32,
        /// Lanes alive in the warp (not exited).
        live: u32,
    },
    /// A warp-synchronous instruction where lane `other`'s member mask names
    /// an executing lane (the fault's lane) that holds another mask: the
    /// lanes a mask names must all pass the same mask, undefined otherwise.
    MemberMaskDiffers {
        /// The member mask of the fault's lane.
        mask: u32,
        /// The lane whose mask names the fault's lane.
        other: u32,
        /// That lane's member mask.
        other_mask: u32,
        /// Lanes that execute the instruction.
        active: u32,
    },
    /// Every warp of a CTA is waiting at barriers that can never complete.
    BarrierDeadlock {
        /// (warp, barrier id) of each waiting warp.
        waiting: Vec<(u32, u32)>,
    },
    /// The launch exceeded its warp-instruction budget (the watchdog).
    Runaway {
        /// The budget.
        budget: u64,
        /// Where the still-running CTAs spent their instructions, most first
        /// (at most [`HOT_LINES`] lines): the hot loop.
        hot: Vec<HotLine>,
    },
    /// A call would make a warp's call stack deeper than the limit
    /// (unbounded recursion without `.local` frames never overflows local memory).
    CallDepth {
        /// The limit (device-function frames).
        limit: u32,
        /// The function being called.
        callee: String,
        /// The call stack, outermost first, consecutive repeats counted.
        chain: Vec<(String, u32)>,
    },
    /// A thread's local memory (its call stack) outgrew the configured limit.
    LocalStackOverflow {
        /// Bytes needed.
        needed: u64,
        /// The limit.
        limit: u64,
    },
    /// `trap` executed.
    Trap,
    /// An instruction form the simulator does not execute.
    Unsupported(String),
}

impl fmt::Display for FaultKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FaultKind::OutOfBounds { space, addr, size } => {
                write!(f, "out-of-bounds {size}-byte {space:?} access at {addr:#x}")
            }
            FaultKind::Misaligned { space, addr, size } => {
                write!(f, "misaligned {space:?} access at {addr:#x} (needs {size}-byte alignment)")
            }
            FaultKind::ReadOnly { space } => write!(f, "store to read-only {space:?} space"),
            FaultKind::DivergentBarrier { active, live } => {
                write!(f, "barrier reached by part of a warp: active lanes {active:#010x}, live lanes {live:#010x}")
            }
            FaultKind::BadBarrier { id, count, cta_threads } => {
                if *id > 15 {
                    write!(f, "barrier id {id} is out of range (a CTA has barriers 0 to 15)")
                } else {
                    write!(
                        f,
                        "barrier {id} with a thread count of {}: it must be a positive multiple of 32 \
                         and at most the CTA's {cta_threads} threads in whole warps",
                        count.unwrap_or(0)
                    )
                }
            }
            FaultKind::MemberMask { mask, lane, active, live } => {
                // the lane's own reason: lanes of other member groups may
                // legitimately run the instruction under other masks
                if mask >> lane & 1 == 0 {
                    write!(
                        f,
                        "member mask {mask:#010x} leaves out lane {lane} that executes the instruction \
                         (active lanes {active:#010x}; undefined on the GPU)"
                    )
                } else {
                    write!(
                        f,
                        "member mask {mask:#010x} names lane {} that does not execute the instruction with the others \
                         (active lanes {active:#010x}, live lanes {live:#010x}; the GPU would wait for it or is undefined: \
                         use __activemask() or converge first)",
                        (mask & live & !active).trailing_zeros()
                    )
                }
            }
            FaultKind::MemberMaskDiffers { mask, other, other_mask, active } => write!(
                f,
                "member mask {mask:#010x} differs from the mask {other_mask:#010x} of lane {other}, which names this \
                 lane (active lanes {active:#010x}; the lanes a mask names must hold the same mask, undefined on the GPU)"
            ),
            FaultKind::BarrierDeadlock { waiting } => {
                write!(f, "barrier deadlock: warps wait at barriers that cannot complete (warp, barrier): {waiting:?}")
            }
            FaultKind::Runaway { budget, .. } => write!(
                f,
                "runaway kernel: more than {budget} warp instructions (the watchdog; raise it with \
                 --max-instructions or the spec key `max_instructions`)"
            ),
            FaultKind::CallDepth { limit, callee, .. } => write!(
                f,
                "call stack overflow: calling `{callee}` would nest more than {limit} device-function calls \
                 (unbounded recursion? the limit is the spec key `max_call_depth`)"
            ),
            FaultKind::LocalStackOverflow { needed, limit } => {
                write!(f, "local memory (call stack) needs {needed} bytes per thread, limit is {limit}")
            }
            FaultKind::Trap => write!(f, "trap instruction executed"),
            FaultKind::Unsupported(s) => write!(f, "unsupported: {s}"),
        }
    }
}

/// Most hot lines a [`FaultKind::Runaway`] names.
pub const HOT_LINES: usize = 5;

/// One PTX line of a runaway kernel's hot loop.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct HotLine {
    /// PTX line.
    pub ptx_line: u32,
    /// Its text.
    pub ptx_text: String,
    /// CUDA source file and line from `.loc`, when present.
    pub source: Option<(String, u32)>,
    /// Warp instructions the still-running CTAs issued on it.
    pub warp_instructions: u64,
    /// Its share of all warp instructions of the still-running CTAs, in percent.
    pub share_pct: u32,
    /// Warps whose next instruction is on it when the watchdog fired.
    pub warps_here: u32,
}

/// `k → f ×3 → g`, eliding the middle of very long chains (mutual recursion).
fn show_chain(chain: &[(String, u32)]) -> String {
    let item = |(n, k): &(String, u32)| if *k > 1 { format!("{n} ×{k}") } else { n.clone() };
    const HEAD: usize = 4;
    const TAIL: usize = 6;
    if chain.len() <= HEAD + TAIL + 1 {
        return chain.iter().map(item).collect::<Vec<_>>().join(" → ");
    }
    let skipped: u64 = chain[HEAD..chain.len() - TAIL].iter().map(|(_, k)| *k as u64).sum();
    let mut parts: Vec<String> = chain[..HEAD].iter().map(item).collect();
    parts.push(format!("… {skipped} more …"));
    parts.extend(chain[chain.len() - TAIL..].iter().map(item));
    parts.join(" → ")
}

/// A fault with the place it happened.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Fault {
    /// What happened.
    pub kind: FaultKind,
    /// The kernel launched.
    pub kernel: String,
    /// The function executing (the kernel or a device function).
    pub function: String,
    /// Instruction index in that function.
    pub pc: u32,
    /// The instruction's PTX file, line and text.
    pub ptx_file: String,
    /// PTX line.
    pub ptx_line: u32,
    /// The PTX instruction text.
    pub ptx_text: String,
    /// CUDA source file and line from `.loc`, when present.
    pub source: Option<(String, u32)>,
    /// CTA index (x, y, z).
    pub cta: [u32; 3],
    /// Warp index within the CTA.
    pub warp: u32,
    /// The first faulting lane, when the fault is per lane.
    pub lane: Option<u32>,
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} in kernel `{}`", self.kind, self.kernel)?;
        if self.function != self.kernel {
            write!(f, " (function `{}`)", self.function)?;
        }
        write!(f, "\n  at {}:{}: {}", self.ptx_file, self.ptx_line, self.ptx_text.trim())?;
        if let Some((file, line)) = &self.source {
            write!(f, "\n  source {file}:{line}")?;
        }
        write!(f, "\n  CTA ({}, {}, {}), warp {}", self.cta[0], self.cta[1], self.cta[2], self.warp)?;
        if let Some(l) = self.lane {
            write!(f, ", lane {l} (thread {} of the CTA)", self.warp * 32 + l)?;
        }
        if let FaultKind::CallDepth { chain, .. } = &self.kind {
            write!(f, "\n  call chain: {}", show_chain(chain))?;
        }
        if let FaultKind::Runaway { hot, .. } = &self.kind
            && !hot.is_empty()
        {
            write!(f, "\n  hot loop (share of the running CTAs' warp instructions; where their warps are now):")?;
            for h in hot {
                write!(f, "\n    {}:{}  {:>3}%  {}", self.ptx_file, h.ptx_line, h.share_pct, h.ptx_text.trim())?;
                if let Some((file, line)) = &h.source {
                    write!(f, "  [{file}:{line}]")?;
                }
                if h.warps_here > 0 {
                    write!(f, "  <- {} warp{}", h.warps_here, if h.warps_here == 1 { "" } else { "s" })?;
                }
            }
        }
        Ok(())
    }
}

impl std::error::Error for Fault {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn call_chains_count_repeats_and_elide_long_middles() {
        let c = |v: &[(&str, u32)]| v.iter().map(|(n, k)| (n.to_string(), *k)).collect::<Vec<_>>();
        assert_eq!(show_chain(&c(&[("k", 1), ("f", 3), ("g", 1)])), "k → f ×3 → g");
        let long: Vec<(String, u32)> = (0..20).map(|i| (format!("f{i}"), 1 + i % 2)).collect();
        assert_eq!(
            show_chain(&long),
            "f0 → f1 ×2 → f2 → f3 ×2 → … 15 more … → f14 → f15 ×2 → f16 → f17 ×2 → f18 → f19 ×2"
        );
    }
}
