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
    /// What a GPU would say of this launch, when anything: more registers
    /// than a thread may have (ptxas spills the rest; counted at the
    /// maximum), or no CTA fitting on an SM (the launch fails on a GPU).
    pub notice: Option<String>,
}

/// CUDA's most 32-bit registers per thread: 124 for compute capability 1.x
/// (the CUDA occupancy calculator), 255 from 3.5 on (the CUDA C++ Programming
/// Guide's table of technical specifications). ptxas spills what is above to
/// local memory.
pub fn max_registers_per_thread(p: Profile) -> u32 {
    match p {
        Profile::Gt200 => 124,
        Profile::Maxwell | Profile::Hopper => 255,
    }
}

/// Occupancy of `kernel` with `threads` per CTA and `dynamic_shared` bytes.
pub fn occupancy(p: Profile, prog: &Program, kernel: u32, threads: u32, dynamic_shared: u32) -> Occupancy {
    let pr = p.params();
    let f = &prog.functions[kernel as usize];
    let declared = f.declared_reg_words.max(1);
    let regs = declared.min(max_registers_per_thread(p));
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
    let mut notes = Vec::new();
    if declared > regs {
        notes.push(format!(
            "the PTX declares {declared} registers per thread; {} allows {regs} (ptxas spills the rest to local \
             memory), counted as {regs}",
            pr.name
        ));
    }
    if ctas == 0 {
        notes.push(format!(
            "no CTA of {threads} threads fits on an SM (limited by {limiter}): on a GPU this launch fails \
             (too many resources requested for launch)"
        ));
    }
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
        notice: (!notes.is_empty()).then(|| notes.join("; ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prog(regs: u32) -> Program {
        let src = format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{{\n.reg .b32 %r<{regs}>;\nret;\n}}\n"
        );
        crate::ptx::load(&src, "k.ptx").unwrap()
    }

    #[test]
    fn registers_past_cudas_maximum_are_a_notice_not_zero_ctas() {
        let p = prog(60000);
        let o = occupancy(Profile::Hopper, &p, 0, 128, 0);
        assert_eq!(o.registers_per_thread, 255);
        // 255 registers round to 256 per thread: 32768 per CTA of 128 threads, 2 CTAs in 65536
        assert_eq!((o.by_registers, o.ctas_per_sm), (2, 2));
        let n = o.notice.expect("a notice");
        assert!(n.contains("declares 60000 registers per thread; hopper allows 255"), "{n}");
        let o = occupancy(Profile::Gt200, &p, 0, 32, 0);
        assert_eq!(o.registers_per_thread, 124);
        assert!(o.notice.unwrap().contains("gt200 allows 124"));
    }

    #[test]
    fn a_launch_no_sm_can_hold_says_so() {
        // 1024 threads of 255 registers need 261 120 registers; an SM has 65 536
        let o = occupancy(Profile::Hopper, &prog(255), 0, 1024, 0);
        assert_eq!(o.ctas_per_sm, 0);
        let n = o.notice.expect("a notice");
        assert!(n.contains("no CTA of 1024 threads fits on an SM (limited by registers)"), "{n}");
        assert!(!n.contains("declares"), "{n}");
        assert_eq!(occupancy(Profile::Hopper, &prog(32), 0, 256, 0).notice, None);
    }
}
