//! Thesis 003's path tracer (Lin 2017, chapters 3, 4 and 6), the kernel
//! `kernels/lin2017/path.cu` run on the emulator ([`kernel`]) and its native
//! mirror ([`native`]): tent-filtered camera rays in 4 subpixels, the
//! flattened SAH kd-tree with the 8-byte short-stack traversal, the affine
//! triangle test, Lambertian / mirror / Fresnel-switched glass shading, an
//! equirectangular environment map ([`environment`]),
//! next-event estimation, multiple importance sampling and Russian roulette,
//! accumulated progressively over frames (one launch per frame, 4 samples
//! per pixel per frame). [`stats`] compares renders with a reference by a
//! per-block Welch t-test under Holm's correction.

pub mod build;
pub mod bvh;
pub mod counts;
pub mod environment;
pub mod gpu_build;
pub mod kernel;
pub mod layout;
pub mod mlt;
pub mod native;
pub mod pixels;
pub mod regroup;
pub mod rng;
pub mod stats;
pub mod wavefront;

pub use pixels::{PixelSampling, PixelSamplingError};

use super::camera::Camera;
use super::image::FrameBuffer;

/// The light-transport estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Integrator {
    /// BSDF sampling only: emission counted wherever a path hits a light.
    Pt,
    /// Next-event estimation at diffuse hits (§4.4); emission after a diffuse bounce not counted.
    Nee,
    /// Both strategies weighted by the balance heuristic (§4.6, β = 1).
    MisBalance,
    /// Both strategies weighted by the power heuristic (§4.6, β = 2).
    MisPower,
    /// Bidirectional path tracing (§4.7): a light and an eye subpath per
    /// path, every Lambertian pair connected, the thesis' uniform weights
    /// over the combinations that can make a path (`bdpt_frame`; the
    /// megakernel only, not the wavefront form). Not in [`Integrator::ALL`].
    Bdpt,
    /// Metropolis light transport in primary sample space (§4.8) over
    /// [`MLT_BASE`]: one chain a pixel, splats anywhere ([`mlt`]; `mlt_init`,
    /// `mlt_start` and `mlt_frame`). Consistent, not unbiased per pixel. Not in [`Integrator::ALL`].
    Mlt,
}

/// The integrator whose paths MLT mutates: bdpt, as the thesis' Fig. 9
/// (003:L332: "bi-directional path tracing ... is used").
pub const MLT_BASE: Integrator = Integrator::Bdpt;

impl Integrator {
    /// The unidirectional integrators (those the wavefront form also runs; bdpt is not one).
    pub const ALL: [Integrator; 4] = [Integrator::Pt, Integrator::Nee, Integrator::MisBalance, Integrator::MisPower];

    /// The kernel's code (mlt: its base's, which `mlt_frame` traces).
    pub fn code(self) -> i32 {
        match self {
            Integrator::Pt => 0,
            Integrator::Nee => 1,
            Integrator::MisBalance => 2,
            Integrator::MisPower => 3,
            Integrator::Bdpt => 4,
            Integrator::Mlt => MLT_BASE.code(),
        }
    }

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Pt => "pt",
            Integrator::Nee => "nee",
            Integrator::MisBalance => "mis",
            Integrator::MisPower => "mis-power",
            Integrator::Bdpt => "bdpt",
            Integrator::Mlt => "mlt",
        }
    }

    /// Parses a command-line name (`mis` is the balance heuristic).
    pub fn parse(s: &str) -> Option<Integrator> {
        match s {
            "mis-balance" => Some(Integrator::MisBalance),
            "bdpt" => Some(Integrator::Bdpt),
            "mlt" => Some(Integrator::Mlt),
            _ => Integrator::ALL.into_iter().find(|i| i.name() == s),
        }
    }
}

/// The kd-tree traversal (§3.4, Fig. 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Traversal {
    /// The 8-byte short stack of Santos et al. (entries {node, tfar}).
    ShortStack,
    /// kd-restart (Foley and Sugerman 2005): no stack, a leaf without a hit
    /// restarts the descent at the root from its exit.
    Restart,
    /// kd-backtrack (Foley and Sugerman 2005): no stack, a leaf without a hit
    /// climbs the parent links to the first node whose box reaches past its exit.
    Backtrack,
    /// The standard stack whose entries also hold tnear ({node, tnear, tfar},
    /// 12 bytes), against which 003:L175 counts the short stack's 8 bytes.
    /// Not a row of Fig. 3.
    FullStack,
}

impl Traversal {
    /// Every traversal, in Fig. 3's row order.
    pub const ALL: [Traversal; 3] = [Traversal::ShortStack, Traversal::Restart, Traversal::Backtrack];

    /// The kernel's code.
    pub fn code(self) -> i32 {
        match self {
            Traversal::ShortStack => 0,
            Traversal::Restart => 1,
            Traversal::Backtrack => 2,
            Traversal::FullStack => 3,
        }
    }

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Traversal::ShortStack => "short-stack",
            Traversal::Restart => "restart",
            Traversal::Backtrack => "backtrack",
            Traversal::FullStack => "full-stack",
        }
    }

    /// As Fig. 3 names its rows.
    pub fn label(self) -> &'static str {
        match self {
            Traversal::ShortStack => "8-byte stack",
            Traversal::Restart => "Kd-restart",
            Traversal::Backtrack => "Kd-backtrack",
            Traversal::FullStack => "12-byte stack",
        }
    }

    /// Parses a command-line name (`stack` is the short stack, `stack12` the full one).
    pub fn parse(s: &str) -> Option<Traversal> {
        match s {
            "stack" => Some(Traversal::ShortStack),
            "stack12" | "full-stack" => Some(Traversal::FullStack),
            _ => Traversal::ALL.into_iter().find(|t| t.name() == s),
        }
    }
}

/// How a path ends besides leaving the scene and reaching the longest path
/// (§4.5, 003:L267-271). Each is its own build of the kernel: the thesis'
/// roulette is `kernels/lin2017/path.cu`, the fixed depth
/// `kernels/lin2017/path_fixed_depth.cu` (the same source compiled with
/// `PATH_FIXED_DEPTH`), so the counted tables run the kernel as the thesis wrote it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// Russian roulette on the bounce's mask f cos / p: go on with q = its
    /// largest RGB component, then divide by q (the thesis').
    #[default]
    Roulette,
    /// No roulette: every path goes on to the longest path (the alternative
    /// the thesis claims roulette beats, 003:L269).
    FixedDepth,
}

impl Termination {
    /// Both, the thesis' first.
    pub const ALL: [Termination; 2] = [Termination::Roulette, Termination::FixedDepth];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Termination::Roulette => "roulette",
            Termination::FixedDepth => "fixed-depth",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Termination> {
        Termination::ALL.into_iter().find(|t| t.name() == s)
    }
}

/// Samples per pixel in one frame (the 2 x 2 subpixels, §4.2).
pub const SAMPLES_PER_FRAME: u32 = 4;

/// Default longest path, in bounces (not stated by the thesis; `docs/fixtures.md`).
pub const DEFAULT_MAX_BOUNCES: u32 = 16;

/// The longest path [`FrameParams::check`] allows, in bounces: the eye
/// subpath's random dimensions (`2 + 8 bounce + 0..6`) stay below bdpt's
/// light subpath's (from `0x10000`, `kernels/lin2017/path.cu`) up to bounce
/// 8190, so the two never share random numbers.
pub const MAX_BOUNCES: u32 = 8190;

/// Settings of a frame the path tracer refuses.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameParamsError {
    /// A longest path beyond [`MAX_BOUNCES`].
    #[error(
        "a longest path of {0} bounces: at most {MAX_BOUNCES} (beyond, the eye and light subpaths would share random numbers)"
    )]
    TooManyBounces(u32),
    /// A strata count out of range.
    #[error(transparent)]
    Pixels(#[from] PixelSamplingError),
    /// An ending and a pixel sampling that no build of the kernel has together.
    #[error(
        "no build of the kernel has both {0} termination and {1} pixels (stratified pixels keep the thesis' roulette)"
    )]
    NoBuild(&'static str, String),
    /// Stratified pixels under mlt.
    #[error("{0} pixels under mlt: its camera sample is its chain's, so it takes the tent filter only")]
    MltPixels(String),
}

/// The settings of a frame as the kernel reads them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The integrator.
    pub integrator: Integrator,
    /// Longest path in bounces: emission seen after up to this many bounces counts.
    pub max_bounces: u32,
    /// Seed of the random numbers.
    pub seed: u32,
    /// The kd-tree traversal.
    pub traversal: Traversal,
    /// How a path ends: with the thesis' roulette or at the longest path (a
    /// second build of the kernel, [`kernel::KernelBuild`]).
    pub termination: Termination,
    /// Where camera rays fall in their subpixels: the thesis' tent filter,
    /// or D x D strata (a third build of the kernel, [`kernel::KernelBuild`]).
    pub pixels: PixelSampling,
}

impl FrameParams {
    /// Paths per frame: 4 per pixel.
    pub fn paths(&self) -> usize {
        self.width as usize * self.height as usize * SAMPLES_PER_FRAME as usize
    }

    /// The thesis' settings for `width` x `height` pixels: the short stack,
    /// Russian roulette and the tent filter.
    pub fn new(width: u32, height: u32, integrator: Integrator, max_bounces: u32, seed: u32) -> FrameParams {
        FrameParams {
            width,
            height,
            integrator,
            max_bounces,
            seed,
            traversal: Traversal::ShortStack,
            termination: Termination::Roulette,
            pixels: PixelSampling::Tent,
        }
    }

    /// Refuses settings the tracer does not take: more than [`MAX_BOUNCES`]
    /// bounces, and what [`FrameParams::check_build`] refuses.
    pub fn check(&self) -> Result<(), FrameParamsError> {
        if self.max_bounces > MAX_BOUNCES {
            return Err(FrameParamsError::TooManyBounces(self.max_bounces));
        }
        self.check_build()
    }

    /// Refuses settings no build of the kernel has (every render, native or
    /// emulated, checks them): a strata count out of range, and stratified
    /// pixels with a fixed depth or under mlt (whose camera sample is its chain's).
    pub fn check_build(&self) -> Result<(), FrameParamsError> {
        self.pixels.check()?;
        if self.pixels != PixelSampling::Tent {
            if self.termination != Termination::Roulette {
                return Err(FrameParamsError::NoBuild(self.termination.name(), self.pixels.name()));
            }
            if self.integrator == Integrator::Mlt {
                return Err(FrameParamsError::MltPixels(self.pixels.name()));
            }
        }
        Ok(())
    }

    /// The longest path as the kernel's `int` holds it (saturated, never
    /// negative), which the native tracer uses too.
    pub fn max_bounces_i32(&self) -> i32 {
        i32::try_from(self.max_bounces).unwrap_or(i32::MAX)
    }
}

/// The camera and ray epsilon in the kernel's form.
pub fn frame_of(camera: &Camera, eps: f32) -> native::Frame {
    let (r, u, f) = camera.frame();
    let [w, h] = camera.resolution;
    native::Frame {
        pos: camera.position,
        fwd: f.into(),
        right: r.into(),
        up: u.into(),
        tan_half: (camera.fov_y.to_radians() * 0.5).tan(),
        aspect: w as f32 / h as f32,
        eps,
    }
}

/// The ray epsilon for a scene of bounds `lo`..`hi`: the ray caster's rule
/// (scene diagonal × 1e-5).
pub fn eps_for(lo: [f32; 3], hi: [f32; 3]) -> f32 {
    let d = glam::Vec3::from(hi) - glam::Vec3::from(lo);
    d.max(glam::Vec3::ZERO).length().max(1e-3) * crate::host::raycast::EPS_REL
}

/// A progressive render: per-path sums over frames and, per pixel, the
/// frames' pixel means (for the statistical test's batch estimates).
#[derive(Debug, Clone, PartialEq)]
pub struct Progressive {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Frames accumulated.
    pub frames: u32,
    /// Per path (3 floats): the radiance summed over frames (the device's accumulation buffer).
    pub accum: Vec<f32>,
    /// Per frame, per pixel: the mean of its 4 subpixel paths (kept when asked).
    pub frame_images: Vec<FrameBuffer>,
    /// The traversal events, when traced natively (the emulated render's are in `kernel::KernelRender`).
    pub counts: counts::Counts,
}

impl Progressive {
    /// An empty accumulation.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize * SAMPLES_PER_FRAME as usize * 3;
        Progressive {
            width,
            height,
            frames: 0,
            accum: vec![0.0; n],
            frame_images: Vec::new(),
            counts: counts::Counts::default(),
        }
    }

    /// The pixel means of one frame's per-path radiance `last`.
    pub fn pixels_of(width: u32, height: u32, last: &[f32]) -> FrameBuffer {
        let mut fb = FrameBuffer::new(width, height);
        for (p, px) in fb.pixels.iter_mut().enumerate() {
            for (c, v) in px.iter_mut().enumerate() {
                let s: f64 = (0..4).map(|k| last[3 * (4 * p + k) + c] as f64).sum();
                *v = (s / 4.0) as f32;
            }
        }
        fb
    }

    /// The image: each pixel's mean over its subpixels and frames.
    pub fn image(&self) -> FrameBuffer {
        let mut fb = Self::pixels_of(self.width, self.height, &self.accum);
        let k = 1.0 / self.frames.max(1) as f32;
        for px in &mut fb.pixels {
            for c in px.iter_mut() {
                *c *= k;
            }
        }
        fb
    }
}

/// Why a render was refused.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// MLT settings [`mlt::check`] refuses (more than [`MAX_BOUNCES`]
    /// bounces, or more chain state than [`mlt::MAX_STATE_BYTES`]).
    #[error(transparent)]
    Mlt(#[from] mlt::MltError),
    /// An integrator that ignores the scene's participating medium, its
    /// translucent materials or its texture maps
    /// ([`layout::PathScene::ignores_medium`]).
    #[error(
        "the scene has a participating medium, translucent materials or texture maps, which only pt, nee, mis and mis-power render (volume_frame, sss_frame, texture_frame); not {0}"
    )]
    Medium(&'static str),
    /// Settings no build of the kernel has ([`FrameParams::check_build`]).
    #[error(transparent)]
    Params(#[from] FrameParamsError),
}

/// Renders `frames` frames natively; `keep_frames` keeps each frame's image
/// (mlt: [`mlt::render_native`]'s image). Refused: mlt with settings
/// [`mlt::check`] refuses, and bdpt or mlt on a scene with a medium (they
/// would ignore it; the kernels refuse it too, [`kernel::render`]). The
/// other integrators take any bound (a longest path past the kernel's `int`
/// saturates).
pub fn render_native(
    scene: &layout::PathScene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    keep_frames: bool,
    mut progress: impl FnMut(u32),
) -> Result<Progressive, RenderError> {
    if scene.ignores_medium(params.integrator) {
        return Err(RenderError::Medium(params.integrator.name()));
    }
    params.check_build()?;
    if params.integrator == Integrator::Mlt {
        return Ok(mlt::render_native(scene, camera, params, frames, keep_frames, progress)?.image);
    }
    let eps = eps_for(scene.lo, scene.hi);
    let tracer = native::Tracer { scene, frame: frame_of(camera, eps), params };
    let mut out = Progressive::new(params.width, params.height);
    let mut last = vec![0.0f32; out.accum.len()];
    for f in 0..frames {
        let c = tracer.frame(f, &mut out.accum, &mut last);
        out.counts.add(&c);
        out.frames += 1;
        if keep_frames {
            out.frame_images.push(Progressive::pixels_of(params.width, params.height, &last));
        }
        progress(f + 1);
    }
    Ok(out)
}
