//! The counters of one kernel launch that the timing model reads: what the
//! emulator counts (instructions issued per warp, waits on loads per space,
//! texture loads, misses and texels, DRAM bytes) and the launch's shape.

use std::collections::BTreeMap;

use super::gpu::LaunchShape;

/// Counters of one launch, summed over the whole GPU.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KernelCounts {
    /// Warp instructions issued (both sides of divergent branches, masked lanes included).
    pub warp_instructions: f64,
    /// Of them, special-function-unit instructions (reciprocal, square root, transcendental).
    pub sfu_instructions: f64,
    /// Shared-memory passes beyond one per half-warp (bank conflicts).
    pub shared_extra_passes: f64,
    /// Warp-level waits on shared loads alone ([`super::waits`]).
    pub shared_waits: f64,
    /// Warp-level waits on global or local loads or atomics with a result.
    pub global_waits: f64,
    /// Warp-level waits on texture (read-only path) loads alone.
    pub texture_waits: f64,
    /// Warp-level texture (read-only path) loads.
    pub texture_loads: f64,
    /// Thread-level 32-bit texel fetches.
    pub texel_fetches: f64,
    /// Texture L1 lookups that missed.
    pub texture_misses: f64,
    /// Bytes moved between the chip and DRAM: global and local transactions, texture misses.
    pub dram_bytes: f64,
}

/// The counters' names, in field order (prefixed `timing_` in results).
pub const NAMES: [&str; 10] = [
    "warp_instructions",
    "sfu_instructions",
    "shared_extra_passes",
    "shared_waits",
    "global_waits",
    "texture_waits",
    "texture_loads",
    "texel_fetches",
    "texture_misses",
    "dram_bytes",
];

/// Prefix of the counters' names in a results file.
pub const PREFIX: &str = "timing_";

impl KernelCounts {
    fn fields(&self) -> [f64; 10] {
        [
            self.warp_instructions,
            self.sfu_instructions,
            self.shared_extra_passes,
            self.shared_waits,
            self.global_waits,
            self.texture_waits,
            self.texture_loads,
            self.texel_fetches,
            self.texture_misses,
            self.dram_bytes,
        ]
    }

    fn from_fields(f: [f64; 10]) -> KernelCounts {
        KernelCounts {
            warp_instructions: f[0],
            sfu_instructions: f[1],
            shared_extra_passes: f[2],
            shared_waits: f[3],
            global_waits: f[4],
            texture_waits: f[5],
            texture_loads: f[6],
            texel_fetches: f[7],
            texture_misses: f[8],
            dram_bytes: f[9],
        }
    }

    /// Every counter multiplied by `k` (per frame from a total, or to another resolution).
    pub fn scaled(&self, k: f64) -> KernelCounts {
        KernelCounts::from_fields(self.fields().map(|v| v * k))
    }

    /// Adds another launch's counters.
    pub fn add(&mut self, o: &KernelCounts) {
        let (a, b) = (self.fields(), o.fields());
        *self = KernelCounts::from_fields(std::array::from_fn(|i| a[i] + b[i]));
    }

    /// As named counters, `timing_warp_instructions`, … (for a results file).
    pub fn counters(&self) -> BTreeMap<String, f64> {
        NAMES.iter().zip(self.fields()).map(|(n, v)| (format!("{PREFIX}{n}"), v)).collect()
    }

    /// From named counters as [`KernelCounts::counters`] writes them; `None` when one is missing.
    pub fn from_counters(get: impl Fn(&str) -> Option<f64>) -> Option<KernelCounts> {
        let mut f = [0.0; 10];
        for (i, n) in NAMES.iter().enumerate() {
            f[i] = get(&format!("{PREFIX}{n}"))?;
        }
        Some(KernelCounts::from_fields(f))
    }
}

/// A launch: its counters and its shape.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Launch {
    /// What it did.
    pub counts: KernelCounts,
    /// How it was launched.
    pub shape: LaunchShape,
}
