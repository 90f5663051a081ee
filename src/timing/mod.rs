//! Per-GPU timing model: predicts a kernel's time from the emulator's counters
//! (instructions issued per warp, waits on loads per space, texture
//! fetches and misses, DRAM transactions) and the launch's residency, with parameters
//! from the GPU's specifications and published microbenchmarks only — never
//! from the frame rates it is compared with. Model and sources:
//! `docs/timing-model.md`.
//!
//! ```
//! use warplight::timing::{GTX_280, KernelCounts, Launch, LaunchShape, predict};
//! let shape = LaunchShape { ctas: 30, threads_per_cta: 256, registers_per_thread: 54, shared_per_cta: 0 };
//! let counts = KernelCounts { warp_instructions: 30.0 * 1e6, ..KernelCounts::default() };
//! let p = predict(&GTX_280, &Launch { counts, shape }).unwrap();
//! // one SM issues 1e6 warp instructions at 4 cycles each, 1.296 GHz
//! assert!((p.seconds - 4e6 / 1.296e9).abs() < 1e-9);
//! ```

pub mod counts;
pub mod gpu;
pub mod prediction;
pub mod queueing;
pub mod waits;

pub use counts::{KernelCounts, Launch};
pub use gpu::{GTX_280, GpuTiming, LaunchShape, Residency};
pub use prediction::{Bound, Prediction, predict};
pub use waits::{Waits, waits};

/// Why a prediction cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TimingError {
    /// No CTAs or no threads.
    #[error("the launch has no threads (CTAs or threads per CTA is zero)")]
    EmptyLaunch,
    /// Not one CTA fits on an SM.
    #[error("one CTA does not fit on an SM ({limiter} limit): {launch:?}")]
    DoesNotFit {
        /// The limit that is exceeded.
        limiter: &'static str,
        /// The launch.
        launch: LaunchShape,
    },
    /// A counter is negative, not finite, or inconsistent.
    #[error("counters are negative, not finite or inconsistent: {0:?}")]
    BadCounts(KernelCounts),
}
