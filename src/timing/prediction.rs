//! The model: one SM as a closed queueing network. Its resident warps
//! alternate between issuing instructions and waiting on memory loads; while
//! one waits the others issue. Stations with a service rate: the SM's issue
//! port (4 cycles a warp instruction, 16 on the SFUs, 2 per bank-conflict
//! pass), its share of the texture units and of DRAM bandwidth. A pure delay:
//! the latencies of the waits. Mean value analysis gives the rounds per
//! cycle; the kernel takes (waits per SM) / (rounds per cycle). All SMs get
//! equal work.

use super::counts::Launch;
use super::gpu::{GpuTiming, Residency};
use super::{TimingError, queueing};

/// What limits a kernel most.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Bound {
    /// The issue port is the busiest resource.
    Issue,
    /// The texture units are.
    Texture,
    /// DRAM bandwidth is.
    Bandwidth,
    /// No station is more than half busy: warps mostly wait on memory latency.
    Latency,
}

/// A predicted kernel time and its parts, per SM.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// Kernel time in seconds.
    pub seconds: f64,
    /// Kernel time in shader cycles.
    pub cycles: f64,
    /// Issue-port cycles per SM (instructions alone).
    pub issue_cycles: f64,
    /// Texture-unit cycles per SM.
    pub texture_cycles: f64,
    /// DRAM cycles (the chip's bytes over its bandwidth).
    pub dram_cycles: f64,
    /// Memory latency per SM summed over its loads (overlapped by other warps).
    pub latency_cycles: f64,
    /// Waits on loads, per SM.
    pub waits_per_sm: f64,
    /// Resident warps per SM.
    pub warps_per_sm: u32,
    /// Issue-port utilisation (0–1).
    pub issue_utilisation: f64,
    /// The bottleneck.
    pub bound: Bound,
}

impl Prediction {
    /// Frames per second if the kernel is the frame.
    pub fn fps(&self) -> f64 {
        1.0 / self.seconds
    }
}

/// Predicts the time of `launch` on `gpu`.
pub fn predict(gpu: &GpuTiming, launch: &Launch) -> Result<Prediction, TimingError> {
    let res: Residency = gpu.residency(&launch.shape)?;
    let c = &launch.counts;
    let fields = [
        c.warp_instructions,
        c.sfu_instructions,
        c.shared_extra_passes,
        c.shared_waits,
        c.global_waits,
        c.texture_waits,
        c.texture_loads,
        c.texel_fetches,
        c.texture_misses,
        c.dram_bytes,
    ];
    if fields.iter().any(|v| !v.is_finite() || *v < 0.0) {
        return Err(TimingError::BadCounts(*c));
    }
    if c.sfu_instructions > c.warp_instructions {
        return Err(TimingError::BadCounts(*c));
    }
    let sms = res.active_sms as f64;
    let w = res.warps_per_sm;
    // an SP instruction every alu_cycles, unless too few warps cover the register latency
    let alu = gpu.alu_cycles.max(gpu.alu_latency / w as f64);
    let issue_cycles = ((c.warp_instructions - c.sfu_instructions) * alu
        + c.sfu_instructions * gpu.sfu_cycles.max(alu)
        + c.shared_extra_passes * gpu.shared_pass_cycles)
        / sms;
    let texture_cycles = c.texel_fetches / gpu.texels_per_sm_cycle() / sms;
    // DRAM is shared: the SM's share of the bytes over its share of the bandwidth
    let dram_cycles = c.dram_bytes / gpu.dram_bytes_per_cycle();
    // a texture wait pays the miss latency if one of its loads missed: at most every miss in another wait
    let miss = if c.texture_waits > 0.0 { (c.texture_misses / c.texture_waits).min(1.0) } else { 0.0 };
    let tex_latency = gpu.texture_hit_latency + miss * (gpu.texture_miss_latency - gpu.texture_hit_latency);
    let rounds = (c.shared_waits + c.global_waits + c.texture_waits) / sms;
    let latency_cycles =
        (c.global_waits * gpu.global_latency + c.texture_waits * tex_latency + c.shared_waits * gpu.shared_latency)
            / sms;
    let stations = [issue_cycles, texture_cycles, dram_cycles];
    let cycles = if rounds > 0.0 {
        let d: Vec<f64> = stations.iter().map(|s| s / rounds).collect();
        let x = queueing::throughput(&d, latency_cycles / rounds, w);
        rounds / x
    } else {
        stations.iter().copied().fold(0.0, f64::max)
    };
    let util = |s: f64| if cycles > 0.0 { s / cycles } else { 0.0 };
    let (busiest, u) = [
        (Bound::Issue, util(issue_cycles)),
        (Bound::Texture, util(texture_cycles)),
        (Bound::Bandwidth, util(dram_cycles)),
    ]
    .into_iter()
    .fold((Bound::Latency, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    Ok(Prediction {
        seconds: cycles / gpu.shader_clock_hz,
        cycles,
        issue_cycles,
        texture_cycles,
        dram_cycles,
        latency_cycles,
        waits_per_sm: rounds,
        warps_per_sm: w,
        issue_utilisation: util(issue_cycles),
        bound: if u >= 0.5 { busiest } else { Bound::Latency },
    })
}
