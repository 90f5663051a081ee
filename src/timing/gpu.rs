//! A GPU's timing parameters: clocks, issue rates, latencies, bandwidths and
//! residency limits, each from a published specification or microbenchmark
//! (sources per field in `docs/timing-model.md`). One constant per GPU.

use super::TimingError;

/// The shape of a launch, for residency: how many warps each SM holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct LaunchShape {
    /// CTAs launched.
    pub ctas: u32,
    /// Threads per CTA.
    pub threads_per_cta: u32,
    /// 32-bit registers per thread of the GPU binary (ptxas' count, not the PTX declarations).
    pub registers_per_thread: u32,
    /// Shared memory per CTA in bytes (static and dynamic).
    pub shared_per_cta: u32,
}

/// Timing parameters of one GPU.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GpuTiming {
    /// The GPU.
    pub name: &'static str,
    /// Streaming multiprocessors.
    pub sms: u32,
    /// Scalar processors (lanes) per SM.
    pub sps_per_sm: u32,
    /// Shader (SP) clock in Hz: the clock every cycle count below is in.
    pub shader_clock_hz: f64,
    /// Issue cycles of one warp instruction on the SPs (32 threads / SPs per SM).
    pub alu_cycles: f64,
    /// Issue cycles of one warp instruction on the special-function units.
    pub sfu_cycles: f64,
    /// Register read-after-write latency of an SP instruction in cycles: with
    /// fewer than `alu_latency / alu_cycles` resident warps dependent
    /// instructions cannot issue back to back.
    pub alu_latency: f64,
    /// Cycles of one extra shared-memory pass (a bank conflict's replay of a half-warp).
    pub shared_pass_cycles: f64,
    /// Latency of a shared-memory load in cycles.
    pub shared_latency: f64,
    /// Latency of a global or local load (and of an atomic with a result) in cycles.
    pub global_latency: f64,
    /// Latency of a texture fetch that hits the SM's texture L1 in cycles.
    pub texture_hit_latency: f64,
    /// Latency of a texture fetch that misses L1 (served by the texture L2) in cycles.
    pub texture_miss_latency: f64,
    /// DRAM bandwidth in bytes per second.
    pub dram_bytes_per_s: f64,
    /// Texel fetches per second of the whole chip (point-sampled 32-bit texels).
    pub texels_per_s: f64,
    /// Resident warps per SM at most.
    pub max_warps_per_sm: u32,
    /// Resident CTAs per SM at most.
    pub max_ctas_per_sm: u32,
    /// 32-bit registers per SM.
    pub registers_per_sm: u32,
    /// Registers are allocated per CTA in units of this many.
    pub register_unit: u32,
    /// Warps are counted for register allocation in multiples of this many.
    pub register_warp_granularity: u32,
    /// Shared memory per SM in bytes.
    pub shared_per_sm: u32,
    /// Shared memory is allocated per CTA in units of this many bytes.
    pub shared_unit: u32,
}

/// NVIDIA GeForce GTX 280 (GT200, compute capability 1.3).
pub const GTX_280: GpuTiming = GpuTiming {
    name: "GeForce GTX 280",
    sms: 30,
    sps_per_sm: 8,
    shader_clock_hz: 1.296e9,
    alu_cycles: 4.0,
    sfu_cycles: 16.0,
    alu_latency: 24.0,
    shared_pass_cycles: 2.0,
    shared_latency: 38.0,
    global_latency: 440.0,
    texture_hit_latency: 261.0,
    texture_miss_latency: 371.0,
    dram_bytes_per_s: 141.7e9,
    texels_per_s: 48.2e9,
    max_warps_per_sm: 32,
    max_ctas_per_sm: 8,
    registers_per_sm: 16384,
    register_unit: 512,
    register_warp_granularity: 2,
    shared_per_sm: 16384,
    shared_unit: 512,
};

/// Resident CTAs per SM and what limits them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Residency {
    /// CTAs resident on one SM at a time.
    pub ctas_per_sm: u32,
    /// Warps resident on one SM (the CTAs the launch gives an SM, at most `ctas_per_sm`).
    pub warps_per_sm: u32,
    /// SMs that receive work.
    pub active_sms: u32,
    /// The binding limit: `threads`, `registers`, `shared memory`, `CTA slots` or `launch`.
    pub limiter: &'static str,
}

impl GpuTiming {
    /// Which GPU a name denotes (`gtx280`, `gt200`).
    pub fn by_name(name: &str) -> Option<&'static GpuTiming> {
        match name.to_ascii_lowercase().replace([' ', '-', '_'], "").as_str() {
            "gtx280" | "geforcegtx280" | "gt200" => Some(&GTX_280),
            _ => None,
        }
    }

    /// Texel fetches one SM's share of the texture units serves per shader cycle.
    pub fn texels_per_sm_cycle(&self) -> f64 {
        self.texels_per_s / self.sms as f64 / self.shader_clock_hz
    }

    /// DRAM bytes per shader cycle of the whole chip.
    pub fn dram_bytes_per_cycle(&self) -> f64 {
        self.dram_bytes_per_s / self.shader_clock_hz
    }

    /// Resident warps per SM for a launch: the residency limits of the
    /// occupancy rules (threads, registers per CTA rounded up, shared memory
    /// per CTA rounded up, CTA slots), and no more CTAs than the launch gives
    /// each SM.
    pub fn residency(&self, l: &LaunchShape) -> Result<Residency, TimingError> {
        if l.ctas == 0 || l.threads_per_cta == 0 {
            return Err(TimingError::EmptyLaunch);
        }
        let warps = l.threads_per_cta.div_ceil(32);
        let alloc_warps = warps.div_ceil(self.register_warp_granularity) * self.register_warp_granularity;
        let regs = (l.registers_per_thread * alloc_warps * 32).div_ceil(self.register_unit) * self.register_unit;
        let shared = l.shared_per_cta.div_ceil(self.shared_unit) * self.shared_unit;
        let limits = [
            (self.max_warps_per_sm / warps, "threads"),
            (self.registers_per_sm.checked_div(regs).unwrap_or(u32::MAX), "registers"),
            (self.shared_per_sm.checked_div(shared).unwrap_or(u32::MAX), "shared memory"),
            (self.max_ctas_per_sm, "CTA slots"),
        ];
        let (fit, limiter) = limits.iter().copied().min_by_key(|(n, _)| *n).expect("four limits");
        if fit == 0 {
            return Err(TimingError::DoesNotFit { limiter, launch: *l });
        }
        let per_sm = l.ctas.div_ceil(self.sms);
        let (ctas_per_sm, limiter) = if per_sm < fit { (per_sm, "launch") } else { (fit, limiter) };
        Ok(Residency { ctas_per_sm, warps_per_sm: ctas_per_sm * warps, active_sms: l.ctas.min(self.sms), limiter })
    }
}
