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
    /// Every warp of a CTA is waiting at barriers that can never complete.
    BarrierDeadlock {
        /// (warp, barrier id) of each waiting warp.
        waiting: Vec<(u32, u32)>,
    },
    /// The launch exceeded its warp-instruction budget.
    Runaway {
        /// The budget.
        budget: u64,
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
            FaultKind::BarrierDeadlock { waiting } => {
                write!(f, "barrier deadlock: warps wait at barriers that cannot complete (warp, barrier): {waiting:?}")
            }
            FaultKind::Runaway { budget } => {
                write!(f, "runaway kernel: more than {budget} warp instructions")
            }
            FaultKind::LocalStackOverflow { needed, limit } => {
                write!(f, "local memory (call stack) needs {needed} bytes per thread, limit is {limit}")
            }
            FaultKind::Trap => write!(f, "trap instruction executed"),
            FaultKind::Unsupported(s) => write!(f, "unsupported: {s}"),
        }
    }
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
        Ok(())
    }
}

impl std::error::Error for Fault {}
