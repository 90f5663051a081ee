//! Occupancy: how many CTAs of a kernel fit on one SM of a profile, from the
//! registers and shared memory the PTX declares. (ptxas allocates registers
//! itself; the PTX count is an upper bound of what the source needs.)

use super::profile::Profile;
use crate::ptx::Program;

/// Resident CTAs per SM and what limits them.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Occupancy {
    /// 32-bit registers per thread (from the PTX declarations, at least 16... see docs).
    pub registers_per_thread: u32,
    /// Shared memory per CTA in bytes (static + dynamic).
    pub shared_per_cta: u32,
    /// CTAs per SM allowed by each limit: threads, registers, shared memory, the CTA slot count.
    pub by_threads: u32,
    /// By registers.
    pub by_registers: u32,
    /// By shared memory.
    pub by_shared: u32,
    /// By the per-SM CTA limit.
    pub by_cta_slots: u32,
    /// The smallest of them.
    pub ctas_per_sm: u32,
    /// Resident warps / maximum warps per SM, in percent.
    pub occupancy_pct: u32,
    /// Which limit binds.
    pub limiter: &'static str,
}

/// Occupancy of `kernel` with `threads` per CTA and `dynamic_shared` bytes.
pub fn occupancy(p: Profile, prog: &Program, kernel: u32, threads: u32, dynamic_shared: u32) -> Occupancy {
    let pr = p.params();
    let f = &prog.functions[kernel as usize];
    let regs = f.declared_reg_words.max(1);
    let shared = prog.kernel_shared_size(kernel).div_ceil(16) * 16 + dynamic_shared;
    let warps = threads.div_ceil(32);
    let regs_per_warp = (regs * 32).div_ceil(pr.reg_alloc_unit) * pr.reg_alloc_unit;
    let by_threads = pr.max_threads_per_sm / (warps * 32).max(1);
    let by_registers = pr.regs_per_sm / (regs_per_warp * warps).max(1);
    let by_shared = pr.shared_per_sm.checked_div(shared).unwrap_or(u32::MAX);
    let by_cta_slots = pr.max_ctas_per_sm;
    let limits = [
        (by_threads, "threads"),
        (by_registers, "registers"),
        (by_shared, "shared memory"),
        (by_cta_slots, "CTA slots"),
    ];
    let (ctas, limiter) = limits.iter().copied().min_by_key(|(n, _)| *n).expect("limits");
    Occupancy {
        registers_per_thread: regs,
        shared_per_cta: shared,
        by_threads,
        by_registers,
        by_shared: by_shared.min(1 << 16),
        by_cta_slots,
        ctas_per_sm: ctas,
        occupancy_pct: (ctas * warps * 3200 / pr.max_threads_per_sm).min(100),
        limiter,
    }
}
