//! A deterministic checker with compute-sanitizer's four tools
//! (`docs/checking.md`): [`memcheck`] (out-of-bounds and misaligned accesses,
//! named by buffer and index), [`racecheck`] (shared- and global-memory
//! races, judged by the barriers between accesses rather than by the order
//! the scheduler ran them in), [`initcheck`] (reads of memory nothing wrote:
//! shared, local, and global buffers allocated without contents) and
//! [`synccheck`] (divergent, mismatched and deadlocked barriers).
//!
//! The checker is a memory observer ([`checker::Checker`]), installed only
//! when asked for: without `--check` the emulator runs exactly as before.
//! Reports are the same for any number of host threads.

pub mod checker;
pub mod cli;
pub mod findings;
pub mod initcheck;
pub mod memcheck;
pub mod racecheck;
pub mod spec;
pub mod synccheck;
pub mod tee;

use std::fmt;

use crate::sim::counters::LaunchStats;
use crate::sim::fault::Fault;
use crate::sim::observer::ObserverFactory;
use crate::sim::{Arg, Device, Fidelity, LaunchConfig, Module, SimError};

/// The tools to run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Tools {
    /// Out-of-bounds and misaligned accesses.
    pub memcheck: bool,
    /// Races.
    pub racecheck: bool,
    /// Uninitialised reads.
    pub initcheck: bool,
    /// Barrier misuse.
    pub synccheck: bool,
}

/// Errors of the checker's options.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// A tool name that is none of the four.
    #[error("--check {0}: unknown tool (memcheck, racecheck, initcheck, synccheck or all)")]
    UnknownTool(String),
    /// `--uninit` names no buffer of the spec.
    #[error("--uninit {0}: the spec has no buffer of that name")]
    UnknownBuffer(String),
    /// The launch runs below the `memory` fidelity, where nothing observes accesses.
    #[error("--check needs --fidelity memory or caches (accesses are not observed below memory)")]
    Fidelity,
}

impl Tools {
    /// Every tool.
    pub const ALL: Tools = Tools { memcheck: true, racecheck: true, initcheck: true, synccheck: true };

    /// From names (`memcheck`, `racecheck`, `initcheck`, `synccheck`, `all`).
    pub fn parse<S: AsRef<str>>(names: &[S]) -> Result<Tools, CheckError> {
        let mut t = Tools::default();
        for n in names {
            match n.as_ref().trim() {
                "memcheck" => t.memcheck = true,
                "racecheck" => t.racecheck = true,
                "initcheck" => t.initcheck = true,
                "synccheck" => t.synccheck = true,
                "all" => t = Tools::ALL,
                other => return Err(CheckError::UnknownTool(other.to_string())),
            }
        }
        Ok(t)
    }

    /// Whether any tool runs.
    pub fn any(&self) -> bool {
        self.memcheck || self.racecheck || self.initcheck || self.synccheck
    }

    /// Whether the tool that finds `h` runs.
    pub fn runs(&self, h: Hazard) -> bool {
        match h.tool() {
            "memcheck" => self.memcheck,
            "racecheck" => self.racecheck,
            "initcheck" => self.initcheck,
            _ => self.synccheck,
        }
    }
}

/// A class of hazard.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub enum Hazard {
    /// A read of a byte another thread wrote, with nothing ordering them.
    ReadAfterWrite,
    /// A write of a byte another thread read, with nothing ordering them.
    WriteAfterRead,
    /// Two threads write a byte with nothing ordering them.
    WriteAfterWrite,
    /// A read of a byte nothing wrote.
    UninitializedRead,
    /// An access outside every buffer (or the space).
    OutOfBounds,
    /// An access not aligned to its size.
    Misaligned,
    /// A barrier reached by part of a warp.
    DivergentBarrier,
    /// Warps released together from different barrier instructions.
    MismatchedBarrier,
    /// Warps waiting at barriers that can never complete.
    BarrierDeadlock,
    /// A warp-synchronous instruction (`bar.warp.sync`, `shfl.sync`,
    /// `vote.sync`, `redux.sync`, `match.sync`) whose member mask leaves out
    /// a lane executing it, or (all but `bar.warp.sync`, which does not wait
    /// for lanes on another path) names a live lane not executing it or
    /// differs between lanes it names: undefined in PTX.
    InvalidMemberMask,
}

impl Hazard {
    /// The compute-sanitizer tool that finds it.
    pub fn tool(self) -> &'static str {
        match self {
            Hazard::ReadAfterWrite | Hazard::WriteAfterRead | Hazard::WriteAfterWrite => "racecheck",
            Hazard::UninitializedRead => "initcheck",
            Hazard::OutOfBounds | Hazard::Misaligned => "memcheck",
            Hazard::DivergentBarrier
            | Hazard::MismatchedBarrier
            | Hazard::BarrierDeadlock
            | Hazard::InvalidMemberMask => "synccheck",
        }
    }

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Hazard::ReadAfterWrite => "read-after-write race",
            Hazard::WriteAfterRead => "write-after-read race",
            Hazard::WriteAfterWrite => "write-after-write race",
            Hazard::UninitializedRead => "uninitialised read",
            Hazard::OutOfBounds => "out-of-bounds access",
            Hazard::Misaligned => "misaligned access",
            Hazard::DivergentBarrier => "divergent barrier",
            Hazard::MismatchedBarrier => "mismatched barriers",
            Hazard::BarrierDeadlock => "barrier deadlock",
            Hazard::InvalidMemberMask => "invalid member mask",
        }
    }

    /// What each site of a report did (the later access first).
    pub fn roles(self) -> [&'static str; 2] {
        match self {
            Hazard::ReadAfterWrite => ["read", "write"],
            Hazard::WriteAfterRead => ["write", "read"],
            Hazard::WriteAfterWrite => ["write", "write"],
            Hazard::UninitializedRead => ["read", ""],
            Hazard::OutOfBounds | Hazard::Misaligned => ["access", ""],
            Hazard::DivergentBarrier | Hazard::BarrierDeadlock | Hazard::MismatchedBarrier => ["barrier", "barrier"],
            Hazard::InvalidMemberMask => ["warp-synchronous instruction", ""],
        }
    }
}

/// An instruction and who executed it.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Site {
    /// The function (kernel or device function).
    pub function: String,
    /// Instruction index in it.
    pub pc: u32,
    /// PTX line.
    pub ptx_line: u32,
    /// PTX text.
    pub ptx_text: String,
    /// CUDA file and line, when the PTX has `.loc`.
    pub source: Option<(String, u32)>,
    /// CTA (x, y, z).
    pub cta: [u32; 3],
    /// Warp within the CTA.
    pub warp: u32,
    /// Lanes involved (bit per lane).
    pub lanes: u32,
    /// Thread index of the first of them.
    pub first_thread: [u32; 3],
}

/// One hazard: its class, where, who, and how often.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Report {
    /// The class.
    pub hazard: Hazard,
    /// The memory space ("shared", "global", "local"; empty for barriers).
    pub space: String,
    /// The kernel.
    pub kernel: String,
    /// The element named by buffer and index (`data[4096]`, `part[33]`).
    pub location: String,
    /// The instruction that found it, then the one it conflicts with.
    pub sites: Vec<Site>,
    /// Lane-level occurrences over the launch.
    pub count: u64,
    /// More detail.
    pub note: String,
}

/// Lanes of a mask as `0-3,8,31`.
pub fn lane_list(m: u32) -> String {
    let mut out = Vec::new();
    let mut l = 0;
    while l < 32 {
        if m >> l & 1 == 0 {
            l += 1;
            continue;
        }
        let start = l;
        while l < 32 && m >> l & 1 != 0 {
            l += 1;
        }
        out.push(if l - 1 == start { format!("{start}") } else { format!("{start}-{}", l - 1) });
    }
    if out.is_empty() { "none".into() } else { out.join(",") }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.hazard.tool(), self.hazard.name())?;
        if !self.space.is_empty() {
            write!(f, " on {} memory", self.space)?;
        }
        if !self.location.is_empty() {
            write!(f, " at {}", self.location)?;
        }
        writeln!(f, " in kernel `{}` ({} time{})", self.kernel, self.count, if self.count == 1 { "" } else { "s" })?;
        for (s, role) in self.sites.iter().zip(self.hazard.roles()) {
            let [tx, ty, tz] = s.first_thread;
            let [cx, cy, cz] = s.cta;
            write!(f, "  {role:<7} PTX line {}", s.ptx_line)?;
            if let Some((file, line)) = &s.source {
                write!(f, ", {file}:{line}")?;
            }
            if s.function != self.kernel {
                write!(f, " (in `{}`)", s.function)?;
            }
            writeln!(
                f,
                ": CTA ({cx},{cy},{cz}) warp {} lanes {} (thread ({tx},{ty},{tz}))  {}",
                s.warp,
                lane_list(s.lanes),
                s.ptx_text
            )?;
        }
        if !self.note.is_empty() {
            writeln!(f, "  {}", self.note)?;
        }
        Ok(())
    }
}

/// What to check and how to name buffers.
#[derive(Debug, Clone, Default)]
pub struct CheckOptions {
    /// The tools.
    pub tools: Tools,
    /// Global ranges (address, bytes) allocated without contents (initcheck).
    pub uninit: Vec<(u64, u64)>,
    /// Element size of named buffers (to index them); others are indexed by the access size.
    pub elem_sizes: Vec<(String, u32)>,
}

/// A checked launch's outcome.
#[derive(Debug)]
pub struct Checked {
    /// Counters, when the launch finished.
    pub stats: Option<LaunchStats>,
    /// The fault that stopped it, if one did.
    pub fault: Option<Box<Fault>>,
    /// The hazards, in a fixed order (class, then instruction).
    pub reports: Vec<Report>,
}

/// Runs a kernel with the checker (and `with`, a counter model, beside it).
/// A fault the tools name (out of bounds, divergent barrier, ...) becomes a
/// report too, and stays in [`Checked::fault`]; other errors are returned.
#[allow(clippy::too_many_arguments)]
pub fn launch_checked(
    dev: &mut Device,
    m: &Module,
    kernel: &str,
    cfg: LaunchConfig,
    args: &[Arg],
    opts: &CheckOptions,
    with: Option<&dyn ObserverFactory>,
) -> Result<Checked, SimError> {
    if dev.config().fidelity < Fidelity::Memory {
        return Err(SimError::BadLaunch(CheckError::Fidelity.to_string()));
    }
    let checker = checker::Checker::new(opts.tools, cfg.block, &opts.uninit);
    let r = match with {
        Some(first) => {
            let tee = tee::Tee { first, second: &checker };
            dev.launch_observed(m, kernel, cfg, args, Some(&tee))
        }
        None => dev.launch_observed(m, kernel, cfg, args, Some(&checker)),
    };
    let (stats, fault) = match r {
        Ok(s) => (Some(s), None),
        Err(SimError::Fault(f)) => (None, Some(f)),
        Err(e) => return Err(e),
    };
    let findings = checker.findings();
    let k = m.prog.kernel(kernel).map(|k| m.prog.functions[k as usize].name.clone()).unwrap_or(kernel.to_string());
    let names = findings::Names {
        prog: &m.prog,
        kernel: k,
        grid: cfg.grid,
        block: cfg.block,
        allocations: dev.memory().allocations(),
        elem_sizes: &opts.elem_sizes,
    };
    let mut reports: Vec<Report> = findings.reports(&names).into_iter().filter(|r| opts.tools.runs(r.hazard)).collect();
    if let Some(f) = &fault
        && let Some(r) = fault_report(f, &names)
        && opts.tools.runs(r.hazard)
    {
        reports.push(r);
    }
    Ok(Checked { stats, fault, reports })
}

/// The report for a fault one of the tools names.
pub fn fault_report(f: &Fault, names: &findings::Names) -> Option<Report> {
    let func = names.prog.functions.iter().position(|x| x.name == f.function)? as u32;
    let [x, y, z] = f.cta;
    let [gx, gy, _] = names.grid;
    let cta = x + gx * (y + gy * z);
    memcheck::from_fault(f, names, (func, f.pc), cta).or_else(|| synccheck::from_fault(f, names, (func, f.pc), cta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tools_and_lanes() {
        assert_eq!(Tools::parse(&["racecheck"]).unwrap(), Tools { racecheck: true, ..Default::default() });
        assert_eq!(Tools::parse(&["all"]).unwrap(), Tools::ALL);
        assert!(Tools::parse(&["racecheque"]).is_err());
        assert_eq!(lane_list(0b1011_0001), "0,4-5,7");
        assert_eq!(lane_list(u32::MAX), "0-31");
        assert_eq!(lane_list(0), "none");
    }
}
