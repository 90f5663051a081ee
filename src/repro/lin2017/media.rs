//! Thesis 003's claim about the volume march (§5.2, 003:L367): Pauly's
//! stratified pattern ("assigns same offset for each segment and randomizes
//! the offset for a new ray") "can be shown to have a lower variance than"
//! normal Monte Carlo sampling, which "would randomly pick a point in each
//! segment". Measured here: the path tracer (natively; the emulated kernel
//! traces the same bits) renders a medium scene with each pattern at several
//! step counts, and the variance of a pixel's frames is averaged over the
//! pixels (`warplight chart media`).

use crate::host::camera::Camera;
use crate::host::path::layout::LayoutError;
use crate::host::path::{FrameParams, Integrator, PixelSampling, RenderError, Termination, Traversal, render_native};
use crate::host::scene::{Jitter, Scene};
use crate::host::scene_file::MAX_MEDIUM_STEPS;
use crate::repro::lin2017::runs;

/// One measurement: a pattern at a step count.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MarchVariance {
    /// The pattern.
    pub jitter: Jitter,
    /// Steps across the medium box's diagonal (its step Δt = diagonal / steps).
    pub steps: u32,
    /// A pixel's variance over frames (one frame: 4 paths a pixel), averaged over pixels and channels.
    pub variance: f64,
    /// The image's mean (both patterns are unbiased: the same mean within noise).
    pub mean: f64,
}

/// Why the march cannot be measured.
#[derive(Debug, thiserror::Error)]
pub enum MediaError {
    /// The scene has no `[medium]`.
    #[error("scene `{0}` has no participating medium ([medium])")]
    NoMedium(String),
    /// Fewer than two frames: no variance.
    #[error("{0} frames: the variance needs at least 2")]
    Frames(u32),
    /// A step count past the kernel's march: its steps beyond
    /// [`MAX_MEDIUM_STEPS`] a ray would be dropped, not marched.
    #[error("{0} steps across the medium's box: the march takes at most {MAX_MEDIUM_STEPS} a ray")]
    Steps(u32),
    /// The layout refused the scene.
    #[error(transparent)]
    Layout(#[from] LayoutError),
    /// The renderer refused it.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// The variance of each pattern at each of `steps` (steps across the medium
/// box's diagonal), rendering `frames` frames of `size` x `size` pixels with
/// nee at `max_bounces` bounces and `seed`.
pub fn march_variance(
    scene: &Scene,
    size: u32,
    frames: u32,
    max_bounces: u32,
    steps: &[u32],
    seed: u32,
) -> Result<Vec<MarchVariance>, MediaError> {
    if frames < 2 {
        return Err(MediaError::Frames(frames));
    }
    if let Some(&n) = steps.iter().find(|&&n| n as f32 > MAX_MEDIUM_STEPS) {
        return Err(MediaError::Steps(n));
    }
    let mut ps = runs::path_scene(scene)?;
    let Some(base) = ps.medium else { return Err(MediaError::NoMedium(scene.name.clone())) };
    let diag = (0..3).map(|k| (base[4 + k] - base[k]).powi(2)).sum::<f32>().sqrt();
    let cam = Camera { resolution: [size, size], ..scene.camera };
    let p = FrameParams {
        width: size,
        height: size,
        integrator: Integrator::Nee,
        max_bounces,
        seed,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    };
    let mut out = Vec::new();
    for jitter in [Jitter::Stratified, Jitter::PerStep] {
        for &n in steps {
            let mut m = base;
            m[3] = diag / n.max(1) as f32;
            m[11] = if jitter == Jitter::PerStep { 1.0 } else { 0.0 };
            ps.medium = Some(m);
            let r = render_native(&ps, &cam, p, frames, true, |_| {})?;
            let (variance, mean) = runs::pixel_variance(&r.frame_images).ok_or(MediaError::Frames(frames))?;
            out.push(MarchVariance { jitter, steps: n, variance, mean });
        }
    }
    Ok(out)
}
