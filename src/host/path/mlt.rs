//! Metropolis light transport in primary sample space (§4.8, 003:L310-336;
//! Kelemen et al. 2002): `mlt_init` and `mlt_frame` of
//! `kernels/lin2017/path.cu` on the emulator ([`render_emulated`]) and their
//! native mirror ([`render_native`]), which performs the same float
//! operations in the same order with the same counter-based random numbers.
//!
//! One Markov chain per pixel (003:L328). A chain's state is the random
//! numbers of its current path, 10 floats a path segment (003:L328: "about
//! 10 samples need to be generated for each path segment"), k segments
//! (k = max bounces plus one): 40 k bytes a chain, 40 k W H in all ([`state_bytes`]), plus
//! its current radiance and pixel (16 bytes). The path is traced by the base
//! integrator [`super::MLT_BASE`] (bdpt, as the thesis' Fig. 9), which draws
//! dimension d from slot [`slot`]`(d)` of the state after the iteration's
//! mutation: a large step (probability 0.25, 003:L318) draws every slot
//! afresh, a small step moves each by Kelemen's exponential perturbation
//! (s1 = 1/1024, s2 = 1/64; the thesis states none). Acceptance min(1, Y'/Y)
//! of the luminance Y (003:L322); both samples are splatted with their
//! expected weights, b F / Y each, b the bootstrap's mean luminance
//! (003:L330, [`BOOTSTRAP`] large steps a chain). Each chain starts at a
//! bootstrap sample picked from all chains' in proportion to Y ([`starts`]),
//! so the chains start in their stationary distribution. The splats are
//! 64-bit integer atomics in 32.32 fixed point, so the image does not depend
//! on their order.

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

use rayon::prelude::*;

use super::counts::Counts;
use super::kernel::{self, KernelRender};
use super::layout::PathScene;
use super::native::{Tracer, exp_neg};
use super::rng::{Sample, path_key, rng};
use super::{FrameParams, FrameParamsError, Progressive, eps_for, frame_of};
use crate::host::camera::Camera;
use crate::sim::{Arg, Counters, Device, DevicePtr, LaunchConfig, Module, SimError};

/// Why an MLT render was refused or failed.
#[derive(Debug, thiserror::Error)]
pub enum MltError {
    /// Settings no integrator takes (more than [`super::MAX_BOUNCES`] bounces).
    #[error(transparent)]
    Params(#[from] FrameParamsError),
    /// The chains' state (40 k W H bytes) overflows 64 bits or exceeds [`MAX_STATE_BYTES`].
    #[error(
        "mlt at {width} x {height} pixels and {max_bounces} bounces keeps {} bytes of chain state (40 k W H, k = bounces + 1): at most {MAX_STATE_BYTES}",
        bytes.map_or("more than 2^64".to_string(), |b| b.to_string())
    )]
    StateTooLarge {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
        /// Longest path in bounces.
        max_bounces: u32,
        /// The state's bytes (`None`: past 2^64).
        bytes: Option<u64>,
    },
    /// A large-step probability outside [0, 1] ([`Chains::p_large`]).
    #[error("mlt: a large-step probability of {0}: expected a probability in [0, 1]")]
    LargeStep(f32),
    /// The emulator faulted.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// The most bytes of chain state a render may keep: one allocation's bound
/// ([`crate::limits::MAX_ALLOCATION_BYTES`], 8 GiB; 1920 x 1080 at the
/// thesis' k = 30 keeps 2.3 GiB).
pub const MAX_STATE_BYTES: u64 = crate::limits::MAX_ALLOCATION_BYTES;

/// The chains' state in bytes for `params` ([`state_bytes`]), or why MLT
/// refuses them: more than [`super::MAX_BOUNCES`] bounces (the kernels'
/// `int` bound would overflow at `max_bounces + 1`), or a state past
/// [`MAX_STATE_BYTES`]. Both render functions call it first.
pub fn check(params: &FrameParams) -> Result<u64, MltError> {
    params.check()?;
    let (w, h, m) = (params.width, params.height, params.max_bounces);
    let bytes = (4 * u64::from(SLOTS_PER_SEGMENT))
        .checked_mul(u64::from(m) + 1)
        .and_then(|b| b.checked_mul(u64::from(w)))
        .and_then(|b| b.checked_mul(u64::from(h)));
    match bytes {
        Some(b) if b <= MAX_STATE_BYTES => Ok(b),
        _ => Err(MltError::StateTooLarge { width: w, height: h, max_bounces: m, bytes }),
    }
}

/// State floats a path segment (003:L328).
pub const SLOTS_PER_SEGMENT: u32 = 10;
/// The random dimension of an iteration's large-or-small choice.
pub const DIM_LARGE: u32 = 0x30000;
/// The random dimension of the acceptance test (at start-up: the start's pick, [`starts`]).
pub const DIM_ACCEPT: u32 = 0x30001;
/// The probability of a large step (003:L318's example).
pub const P_LARGE: f32 = 0.25;
/// Kelemen's largest small step s2 (the smallest is s1 = 1/1024).
pub const S2: f32 = 1.0 / 64.0;
/// ln(s2 / s1) = ln 16, as the kernel's literal.
#[allow(clippy::excessive_precision)]
const LN_S2_S1: f32 = 2.772_588_722_239_781_24;
/// Large-step samples a chain draws at start-up (the thesis states no count).
pub const BOOTSTRAP: u32 = 16;
/// The frame number of the bootstrap samples' random keys (no frame reaches it).
pub const BOOTSTRAP_FRAME: u32 = u32::MAX;
/// The frame number of the start picks' random keys (no frame reaches it).
pub const START_FRAME: u32 = u32::MAX - 1;
/// Iterations a chain takes a frame (a frame's 4 samples a pixel).
pub const STEPS: u32 = 4;
/// The splats' fixed point: 2^32 a unit.
pub const FIXED: f32 = 4_294_967_296.0;

/// State floats a chain for paths of at most `max_bounces` bounces: 10 (k = max bounces + 1).
pub fn slots(max_bounces: u32) -> usize {
    SLOTS_PER_SEGMENT as usize * (max_bounces as usize + 1)
}

/// The bytes of random numbers the chains of a `width` x `height` image keep: 40 k W H.
/// (saturating; [`check`] refuses what does not fit).
pub fn state_bytes(width: u32, height: u32, max_bounces: u32) -> u64 {
    (4 * slots(max_bounces) as u64).saturating_mul(width as u64 * height as u64)
}

/// The state slot of the integrators' random dimension `d` for paths of at
/// most `m` bounces: the kernel's `mlt_slot`. Segment s holds in slots 0-6
/// the eye bounce s's dimensions 2 + 8 s + j (j = 0-6: the light point, the
/// direction, roulette, the Fresnel switch) and in slots 7-9 bdpt's light
/// vertex s's (direction and roulette); y0's point takes segment 0's slots
/// 7-9 and its direction segment 1's 7-8 (vertex 1 draws none); the camera's
/// two take segment m's 0-1 (bounce m draws none).
pub fn slot(d: u32, m: u32) -> u32 {
    use super::native::{DIMS_CAMERA, DIMS_LIGHT};
    if d < DIMS_CAMERA {
        return SLOTS_PER_SEGMENT * m + d;
    }
    if d < DIMS_LIGHT {
        let e = d - DIMS_CAMERA;
        return SLOTS_PER_SEGMENT * (e >> 3) + (e & 7);
    }
    let e = d - DIMS_LIGHT;
    let (c, j) = (e >> 3, e & 7);
    if c == 0 {
        return if j < 3 { 7 + j } else { 14 + j };
    }
    SLOTS_PER_SEGMENT * c + 4 + j
}

/// An MLT iteration's random numbers: the chain's current samples `u`, the
/// iteration's key (its mutation's random numbers) and whether it is a large
/// step (the kernel's `Mlt`).
#[derive(Debug, Clone, Copy)]
pub struct Sampler<'a> {
    /// The chain's current primary samples ([`slots`] floats).
    pub u: &'a [f32],
    /// The iteration's counter-based key.
    pub key: u32,
    /// The longest path in bounces (k − 1).
    pub max_bounces: u32,
    /// A large step: every sample afresh.
    pub large: bool,
}

impl Sampler<'_> {
    /// Slot `slot` of the proposal, the kernel's `mlt_value`: a large step's
    /// fresh uniform, or the current value moved by s2 e^(−ln(s2/s1) v), up
    /// or down with equal probability, wrapped into [0, 1).
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // !(x < 1), NaN included: the kernel's test
    pub fn value(&self, slot: u32) -> f32 {
        let r = rng(self.key, slot);
        if self.large {
            return r;
        }
        let mut x = self.u[slot as usize];
        let r2 = r * 2.0;
        let up = r2 < 1.0;
        let v = if up { r2 } else { r2 - 1.0 };
        let dv = S2 * exp_neg(-LN_S2_S1 * v);
        x = if up { x + dv } else { x - dv };
        if x >= 1.0 {
            x -= 1.0;
        }
        if x < 0.0 {
            x += 1.0;
        }
        // a tiny negative x + 1 rounds to 1
        if !(x < 1.0) {
            x = f32::from_bits(0x3f7f_ffff);
        }
        x
    }
}

impl Sample for Sampler<'_> {
    fn at(self, d: u32) -> f32 {
        let k = slot(d, self.max_bounces);
        if (k as usize) < self.u.len() { self.value(k) } else { rng(self.key, d) }
    }
}

/// Y of an RGB radiance (003:L322): the kernel's `luminance`.
pub fn luminance(c: [f32; 3]) -> f32 {
    0.212_671 * c[0] + 0.715_160 * c[1] + 0.072_169 * c[2]
}

/// A chain's current sample: its radiance and pixel (the kernel's float4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Current {
    /// Radiance.
    pub f: [f32; 3],
    /// Pixel index.
    pub pixel: u32,
}

/// An MLT render: the image and what the chains kept.
#[derive(Debug, Clone)]
pub struct MltRender {
    /// The image as the other integrators' (per path sums, frames and, if kept, each frame's own image).
    pub image: Progressive,
    /// Per pixel and channel, the splats' sum in 32.32 fixed point.
    pub fixed: Vec<u64>,
    /// The bootstrap's mean luminance b.
    pub b: f32,
    /// The bytes allocated for the chains' random numbers: emulated, the
    /// size of the device allocation `mlt state`; natively, the host
    /// vector's. Both are the host's formula ([`state_bytes`]);
    /// `tests/lin2017_mlt_state.rs` measures what the kernels touch.
    pub state_bytes: u64,
    /// The emulator's counters summed over the launches (native: none).
    pub totals: Option<Counters>,
}

/// b, the mean luminance of the bootstrap samples `boot` (summed in order, f64).
pub fn b_of(boot: &[f32]) -> f32 {
    let s: f64 = boot.iter().map(|&y| y as f64).sum();
    (s / boot.len().max(1) as f64) as f32
}

/// The key of bootstrap sample `n` (chain c draws samples `BOOTSTRAP` c ..
/// `BOOTSTRAP` (c + 1) − 1): the kernel's `mlt_bootstrap_key`.
pub fn bootstrap_key(n: u32, seed: u32) -> u32 {
    path_key(n, BOOTSTRAP_FRAME, seed)
}

/// Each of `chains` chains' start: a bootstrap sample picked from all of
/// them (`boot`, their luminances) in proportion to Y, chain c by the
/// uniform `rng(path_key(c, START_FRAME, seed), DIM_ACCEPT)` over the
/// samples' cumulative sum (f64, in sample order). The start is then
/// distributed as the chains' stationary distribution (up to the pool's
/// finite size), so no chain needs a run-in. If the sum is not a positive
/// finite number (every sample black), chain c starts at its own first sample.
pub fn starts(boot: &[f32], chains: u32, seed: u32) -> Vec<u32> {
    let mut total = 0.0f64;
    let cdf: Vec<f64> = boot
        .iter()
        .map(|&y| {
            total += y as f64;
            total
        })
        .collect();
    let last = boot.len().saturating_sub(1) as u32;
    let usable = total.is_finite() && total > 0.0;
    (0..chains)
        .map(|c| {
            if !usable {
                return (BOOTSTRAP * c).min(last);
            }
            let r = rng(path_key(c, START_FRAME, seed), DIM_ACCEPT) as f64 * total;
            (cdf.partition_point(|&v| v <= r) as u32).min(last)
        })
        .collect()
}

/// The image of the fixed-point sums after `frames` frames, as per-path sums
/// (each of a pixel's 4 path slots a quarter of the pixel's sum), so that
/// [`Progressive::image`] divides by the frames.
fn progressive_of(p: &FrameParams, fixed: &[u64], frames: u32) -> Progressive {
    let mut out = Progressive::new(p.width, p.height);
    out.frames = frames;
    for (px, sums) in fixed.chunks(3).enumerate() {
        for k in 0..4 {
            for (c, &v) in sums.iter().enumerate() {
                out.accum[3 * (4 * px + k) + c] = (v as f64 / FIXED as f64 / STEPS as f64) as f32;
            }
        }
    }
    out
}

/// One frame's own image: the splats it added (`now` − `before`), divided by its iterations a pixel.
fn frame_image(p: &FrameParams, before: &[u64], now: &[u64]) -> crate::host::image::FrameBuffer {
    let mut fb = crate::host::image::FrameBuffer::new(p.width, p.height);
    for (i, px) in fb.pixels.iter_mut().enumerate() {
        for (c, v) in px.iter_mut().enumerate() {
            *v = ((now[3 * i + c] - before[3 * i + c]) as f64 / FIXED as f64 / STEPS as f64) as f32;
        }
    }
    fb
}

/// Adds `c` × `w` to `pixel` of the fixed-point image: the kernel's `splat`.
fn splat(image: &[AtomicU64], pixel: u32, c: [f32; 3], w: f32) {
    for (k, v) in c.iter().enumerate() {
        image[3 * pixel as usize + k].fetch_add((v * w * FIXED) as u64, Relaxed);
    }
}

/// What the chains sample: sampler `m`'s path index (4 pixel + subpixel;
/// the pixel is the index >> 2) and radiance. The renderer's is the path
/// tracer ([`Tracer::mlt_sample`]); a test may give the chains any function
/// of the samples.
pub trait Target: Sync {
    /// The sample of `m`.
    fn sample(&self, m: Sampler<'_>, counts: &mut Counts) -> (u32, [f32; 3]);
}

impl Target for Tracer<'_> {
    fn sample(&self, m: Sampler<'_>, counts: &mut Counts) -> (u32, [f32; 3]) {
        self.mlt_sample(m, counts)
    }
}

/// Where the chains start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    /// A bootstrap sample picked from all chains' in proportion to Y
    /// ([`starts`]): the kernel's, the chains' stationary distribution.
    Pool,
    /// One of the chain's own [`BOOTSTRAP`] samples in proportion to Y
    /// ([`own_starts`]): the start before issue 15's fix (native only),
    /// biased where a bright region is a small part of sample space.
    Own,
}

/// How the chains run natively: where they start and how often they take a
/// large step. The kernels' are [`Chains::KERNEL`]; the others are for the
/// studies of the thesis' start-up bias and large-step probability
/// (003:L318-324), native only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chains {
    /// Where the chains start.
    pub start: Start,
    /// The probability of a large step, in [0, 1].
    pub p_large: f32,
}

impl Chains {
    /// The kernels' chains: started from the pool, large steps with [`P_LARGE`].
    pub const KERNEL: Chains = Chains { start: Start::Pool, p_large: P_LARGE };

    /// The kernels' large steps with `start`.
    pub fn starting(start: Start) -> Chains {
        Chains { start, ..Chains::KERNEL }
    }
}

/// Renders `frames` frames of MLT natively (`params.integrator` is mlt);
/// settings [`check`] refuses are an error.
pub fn render_native(
    scene: &PathScene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    keep_frames: bool,
    progress: impl FnMut(u32),
) -> Result<MltRender, MltError> {
    let tracer = Tracer { scene, frame: frame_of(camera, eps_for(scene.lo, scene.hi)), params };
    render_target(&tracer, params, Chains::KERNEL, frames, keep_frames, progress)
}

/// Renders `frames` frames of MLT natively over `target` with `chains`
/// (`params` gives the image size, the state's length by its bounces, and
/// the seed); settings [`check`] refuses are an error, and so is a large-step
/// probability outside [0, 1].
pub fn render_target(
    target: &impl Target,
    params: FrameParams,
    chains: Chains,
    frames: u32,
    keep_frames: bool,
    mut progress: impl FnMut(u32),
) -> Result<MltRender, MltError> {
    check(&params)?;
    if !(0.0..=1.0).contains(&chains.p_large) {
        return Err(MltError::LargeStep(chains.p_large));
    }
    let (m, n) = (slots(params.max_bounces), (params.width * params.height) as usize);
    let mut boot = vec![0.0f32; BOOTSTRAP as usize * n];
    let mut counts = boot
        .par_chunks_mut(BOOTSTRAP as usize)
        .enumerate()
        .map(|(c, boot)| {
            let mut counts = Counts::default();
            boot_chain(target, &params, c as u32, boot, &mut counts);
            counts
        })
        .reduce(Counts::default, add);
    let b = b_of(&boot);
    let start = match chains.start {
        Start::Pool => starts(&boot, n as u32, params.seed),
        Start::Own => own_starts(&boot, params.seed),
    };
    let mut u = vec![0.0f32; m * n];
    let mut cur = vec![Current { f: [0.0; 3], pixel: 0 }; n];
    let c = u
        .par_chunks_mut(m)
        .zip(cur.par_iter_mut())
        .zip(start.par_iter())
        .map(|((u, cur), &start)| {
            let mut counts = Counts::default();
            *cur = start_chain(target, &params, start, u, &mut counts);
            counts
        })
        .reduce(Counts::default, add);
    counts.add(&c);
    let image: Vec<AtomicU64> = (0..3 * n).map(|_| AtomicU64::new(0)).collect();
    let mut out_frames = Vec::new();
    let mut before = vec![0u64; 3 * n];
    for f in 0..frames {
        let c = u
            .par_chunks_mut(m)
            .zip(cur.par_iter_mut())
            .enumerate()
            .map(|(c, (u, cur))| {
                let mut counts = Counts::default();
                frame_chain(target, &params, c as u32, f, b, chains.p_large, u, cur, &image, &mut counts);
                counts
            })
            .reduce(Counts::default, add);
        counts.add(&c);
        if keep_frames {
            let now: Vec<u64> = image.iter().map(|a| a.load(Relaxed)).collect();
            out_frames.push(frame_image(&params, &before, &now));
            before = now;
        }
        progress(f + 1);
    }
    let fixed: Vec<u64> = image.iter().map(|a| a.load(Relaxed)).collect();
    let mut image = progressive_of(&params, &fixed, frames);
    image.frame_images = out_frames;
    image.counts = counts;
    Ok(MltRender { image, fixed, b, state_bytes: (4 * u.len()) as u64, totals: None })
}

fn add(mut a: Counts, b: Counts) -> Counts {
    a.add(&b);
    a
}

/// Each chain's start among its own [`BOOTSTRAP`] samples (`boot`, their
/// luminances, chain by chain) in proportion to Y, by a weighted reservoir of
/// one with the uniforms `rng(bootstrap_key(n, seed), DIM_ACCEPT)`: the start
/// before issue 15's fix ([`Start::Own`]).
pub fn own_starts(boot: &[f32], seed: u32) -> Vec<u32> {
    let k = BOOTSTRAP as usize;
    (0..boot.len() / k)
        .map(|c| {
            let (mut sum, mut pick) = (0.0f32, (k * c) as u32);
            for (j, &y) in boot[k * c..k * (c + 1)].iter().enumerate() {
                let n = (k * c + j) as u32;
                sum += y;
                if j == 0 || rng(bootstrap_key(n, seed), DIM_ACCEPT) * sum < y {
                    pick = n;
                }
            }
            pick
        })
        .collect()
}

/// Chain `c`'s bootstrap samples' luminances into `boot` (the kernel's `mlt_init`).
fn boot_chain(target: &impl Target, p: &FrameParams, c: u32, boot: &mut [f32], counts: &mut Counts) {
    boot_samples(target, p, BOOTSTRAP * c, boot, counts);
}

/// The luminances of bootstrap samples `first`, `first + 1`, ... into `boot`.
fn boot_samples(target: &impl Target, p: &FrameParams, first: u32, boot: &mut [f32], counts: &mut Counts) {
    // a large step reads no current sample; the sampler's length is the state's
    let u = vec![0.0f32; slots(p.max_bounces)];
    for (j, y) in boot.iter_mut().enumerate() {
        let key = bootstrap_key(first + j as u32, p.seed);
        let m = Sampler { u: &u, key, max_bounces: p.max_bounces, large: true };
        *y = luminance(target.sample(m, counts).1);
    }
}

/// The luminances of the first `per_chain` x W x H bootstrap samples, in
/// key order (the chains' [`BOOTSTRAP`] each are the first 16 W H of them):
/// [`b_of`] their first `k` W H is the b of `k` samples a chain, and at
/// `k` = [`BOOTSTRAP`] the kernel's b bit for bit. For the study of b
/// against the bootstrap count (003:L330).
pub fn bootstrap_luminances(target: &impl Target, params: &FrameParams, per_chain: u32) -> Vec<f32> {
    let n = (params.width * params.height) as usize;
    let mut boot = vec![0.0f32; per_chain as usize * n];
    boot.par_chunks_mut(BOOTSTRAP as usize).enumerate().for_each(|(c, boot)| {
        boot_samples(target, params, BOOTSTRAP * c as u32, boot, &mut Counts::default());
    });
    boot
}

/// A chain's start at bootstrap sample `start` (the kernel's `mlt_start`):
/// the sample traced again, its random numbers into `u`.
fn start_chain(target: &impl Target, p: &FrameParams, start: u32, u: &mut [f32], counts: &mut Counts) -> Current {
    let key = bootstrap_key(start, p.seed);
    let (i, l) = target.sample(Sampler { u, key, max_bounces: p.max_bounces, large: true }, counts);
    for (k, v) in u.iter_mut().enumerate() {
        *v = rng(key, k as u32);
    }
    Current { f: l, pixel: i >> 2 }
}

/// Chain `c`'s iterations in frame `f` (the kernel's `mlt_frame`).
#[allow(clippy::too_many_arguments)]
fn frame_chain(
    target: &impl Target,
    p: &FrameParams,
    c: u32,
    f: u32,
    b: f32,
    p_large: f32,
    u: &mut [f32],
    cur: &mut Current,
    image: &[AtomicU64],
    counts: &mut Counts,
) {
    let mut yc = luminance(cur.f);
    let mut next = vec![0.0f32; u.len()];
    for t in 0..STEPS {
        let key = path_key(STEPS * c + t, f, p.seed);
        let m = Sampler { u, key, max_bounces: p.max_bounces, large: rng(key, DIM_LARGE) < p_large };
        let (i, l) = target.sample(m, counts);
        let y = luminance(l);
        let a = if yc > 0.0 { 1.0f32.min(y / yc) } else { 1.0 };
        if yc > 0.0 {
            splat(image, cur.pixel, cur.f, (1.0 - a) * b / yc);
        }
        if y > 0.0 {
            splat(image, i >> 2, l, a * b / y);
        }
        if rng(key, DIM_ACCEPT) < a {
            for (k, v) in next.iter_mut().enumerate() {
                *v = m.value(k as u32);
            }
            u.copy_from_slice(&next);
            *cur = Current { f: l, pixel: i >> 2 };
            yc = y;
        }
    }
}

/// The name of the device allocation that holds the chains' random numbers.
pub const STATE_BUFFER: &str = "mlt state";

/// Renders `frames` frames of MLT on the emulator (`mlt_init` and
/// `mlt_start` once, then `mlt_frame` a frame; `module` loaded by
/// [`kernel::load`]); settings [`check`] refuses are an error before
/// anything reaches the kernels' parameters.
#[allow(clippy::too_many_arguments)]
pub fn render_emulated(
    dev: &mut Device,
    module: &Module,
    scene: &PathScene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    keep_frames: bool,
    mut progress: impl FnMut(u32),
) -> Result<MltRender, MltError> {
    let state_len = check(&params)?;
    kernel::check_build(module, &params)?;
    let bufs = kernel::upload_scene(dev, scene, camera, &params)?;
    let n = (params.width * params.height) as usize;
    let state = dev.alloc_bytes(state_len, STATE_BUFFER);
    let chains = dev.alloc_bytes(16 * n as u64, "mlt chains");
    let boot = dev.alloc_bytes(4 * BOOTSTRAP as u64 * n as u64, "mlt bootstrap");
    let start = dev.alloc_bytes(4 * n as u64, "mlt starts");
    let image = dev.alloc_bytes(24 * n as u64, "mlt image");
    let args = |bufs_after: &[DevicePtr]| -> Vec<Arg> {
        bufs.scene_args().into_iter().chain(bufs_after.iter().copied()).map(Arg::Ptr).collect()
    };
    let cfg = LaunchConfig::linear(n.div_ceil(kernel::THREADS as usize) as u32, kernel::THREADS);
    let mut totals = Counters::default();
    let st = dev.launch(module, INIT_KERNEL, cfg, &args(&[boot]))?;
    totals.merge(&st.totals);
    let ys = dev.read::<f32>(boot, BOOTSTRAP as usize * n);
    let b = b_of(&ys);
    dev.write(start, &starts(&ys, n as u32, params.seed))?;
    let st = dev.launch(module, START_KERNEL, cfg, &args(&[state, chains, start]))?;
    totals.merge(&st.totals);
    let mut out_frames = Vec::new();
    let mut before = vec![0u64; 3 * n];
    for f in 0..frames {
        dev.write(bufs.params, &kernel::params_bytes_mlt(scene, camera, &params, f, b))?;
        let st = dev.launch(module, FRAME_KERNEL, cfg, &args(&[state, chains, image]))?;
        totals.merge(&st.totals);
        if keep_frames {
            let now = dev.read::<u64>(image, 3 * n);
            out_frames.push(frame_image(&params, &before, &now));
            before = now;
        }
        progress(f + 1);
    }
    let fixed = dev.read::<u64>(image, 3 * n);
    let mut img = progressive_of(&params, &fixed, frames);
    img.frame_images = out_frames;
    let state_bytes = dev.memory().allocations().iter().find(|a| a.name == STATE_BUFFER).map_or(0, |a| a.len);
    Ok(MltRender { image: img, fixed, b, state_bytes, totals: Some(totals) })
}

/// The start-up's bootstrap kernel.
pub const INIT_KERNEL: &str = "mlt_init";
/// The start-up's kernel that sets each chain at its start.
pub const START_KERNEL: &str = "mlt_start";
/// The frame kernel.
pub const FRAME_KERNEL: &str = "mlt_frame";

impl From<MltRender> for KernelRender {
    fn from(r: MltRender) -> KernelRender {
        KernelRender { image: r.image, totals: r.totals.unwrap_or_default(), counts: None, roulettes: None }
    }
}
