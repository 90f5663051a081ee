//! The 3-way Fresnel regroup of thesis 003 (§6.3, 003:L536) on the emulator:
//! the wavefront form with trace and shade as separate launches
//! (`kernels/lin2017/path.cu`'s `regroup_init`, `regroup_trace`,
//! `regroup_shade`), so that the branch each path's next shading takes (the
//! Fresnel switch's specular reflection, diffuse reflection or transmission,
//! from the material its next ray hit) is known before the shade runs.
//!
//! A level is a trace launch over the states, then (by [`Mode`]) nothing, one
//! compaction of the active states, or three compactions, one per branch,
//! each appending into the second buffer (the thesis' "3 stream compaction
//! operations" into a double buffer, whose indices are then swapped), then
//! the shade launch over the result. Path i's random numbers depend on i and
//! its bounce only, and each path adds its radiance to its own slot of the
//! accumulation buffer once per frame, so every mode leaves the megakernel's
//! image bit for bit (`tests/lin2017_regroup.rs`).
//!
//! What is counted: per launch the emulator's counters; the shade launches'
//! divergent branches and their lane utilisation (thread instructions over
//! 32 x warp instructions) are the divergence the regroup removes, and the
//! frame's warp instructions (init, trace, shade and every compaction
//! kernel) model its time.

use super::kernel::{params_bytes, upload_scene};
use super::layout::PathScene;
use super::wavefront::{Compactor, THREADS, WARP};
use super::{FrameParams, Progressive};
use crate::host::camera::Camera;
use crate::sim::{Arg, Counters, Device, LaunchConfig, Module, SimError};

/// Floats of one regroup state (5 float4: `path_level`'s four and the next hit).
pub const STATE_FLOATS: usize = 20;
/// `regroup_flag`'s branch that selects every active state (plain compaction).
pub const ANY: u32 = u32::MAX;
/// The branches, in the order of the compactions: specular reflection
/// (mirror, rough mirror), diffuse reflection (and paths whose next hit is an
/// emitter or nothing), transmission (glass, rough glass).
pub const BRANCHES: [(u32, &str); 3] = [(0, "specular"), (1, "diffuse"), (2, "transmission")];

/// How the states are arranged between a level's trace and its shade.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Mode {
    /// Not at all: every level's launches cover every path.
    Normal,
    /// One compaction of the active states (from the second level on: at the
    /// first no path has ended).
    Compacted,
    /// Three compactions, one per next Fresnel branch, into the second buffer.
    Regrouped,
}

impl Mode {
    /// All three.
    pub const ALL: [Mode; 3] = [Mode::Normal, Mode::Compacted, Mode::Regrouped];

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Normal => "normal",
            Mode::Compacted => "compact",
            Mode::Regrouped => "regroup",
        }
    }
}

/// An emulated render in the regroup's wavefront form.
#[derive(Debug, Clone)]
pub struct RegroupRender {
    /// The accumulated image and, if kept, each frame's.
    pub image: Progressive,
    /// The counters of the shade launches.
    pub shade: Counters,
    /// The counters of the trace launches.
    pub trace: Counters,
    /// The counters of the compaction launches.
    pub compaction: Counters,
    /// The counters of every launch (init, trace, compaction, shade).
    pub totals: Counters,
    /// Per level, the threads the shade launched, summed over frames.
    pub shade_threads: Vec<u64>,
    /// Per branch of [`BRANCHES`], the states the compactions put in it, summed over levels and frames.
    pub per_branch: [u64; 3],
}

impl RegroupRender {
    /// The shade launches' lane utilisation: thread instructions over the lanes of the warp instructions.
    pub fn shade_lanes(&self) -> f64 {
        self.shade.thread_instructions as f64 / (WARP * self.shade.warp_instructions).max(1) as f64
    }
}

/// Renders `frames` frames in the regroup's wavefront form on `dev` (`module`
/// loaded by `kernel::load`, `compact` by `wavefront::load_compact`; both by
/// `wavefront::device`); `progress` hears each frame done.
#[allow(clippy::too_many_arguments)]
pub fn render(
    dev: &mut Device,
    module: &Module,
    compact: &Module,
    scene: &PathScene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    mode: Mode,
    keep_frames: bool,
    mut progress: impl FnMut(u32),
) -> Result<RegroupRender, SimError> {
    super::kernel::check_build(module, &params)?;
    let bufs = upload_scene(dev, scene, camera, &params)?;
    let paths = params.paths();
    let n3 = paths * 3;
    let accum = dev.alloc_zeroed::<f32>(n3);
    let last = dev.alloc_zeroed::<f32>(n3);
    let mut states = [dev.alloc_zeroed::<f32>(paths * STATE_FLOATS), dev.alloc_zeroed::<f32>(paths * STATE_FLOATS)];
    let compactor = Compactor::new(dev, paths);
    let mut r = RegroupRender {
        image: Progressive::new(params.width, params.height),
        shade: Counters::default(),
        trace: Counters::default(),
        compaction: Counters::default(),
        totals: Counters::default(),
        shade_threads: Vec::new(),
        per_branch: [0; 3],
    };
    let grid = |n: u32| LaunchConfig::linear(n.div_ceil(THREADS), THREADS);
    let scene_args: Vec<Arg> = bufs.scene_args().into_iter().map(Arg::Ptr).collect();
    for f in 0..frames {
        dev.write(bufs.params, &params_bytes(scene, camera, &params, f))?;
        let init = [Arg::Ptr(bufs.params), Arg::Ptr(states[0])];
        r.totals.merge(&dev.launch(module, "regroup_init", grid(paths as u32), &init)?.totals);
        let mut n = paths as u32;
        for l in 0..=params.max_bounces as usize {
            if n == 0 {
                break;
            }
            let mut args = scene_args.clone();
            args.extend([Arg::Ptr(states[0]), Arg::U32(n)]);
            let t = dev.launch(module, "regroup_trace", grid(n), &args)?.totals;
            r.trace.merge(&t);
            r.totals.merge(&t);
            let passes: &[(u32, &str)] = match mode {
                Mode::Normal => &[],
                Mode::Compacted if l == 0 => &[],
                Mode::Compacted => &[(ANY, "active")],
                Mode::Regrouped => &BRANCHES,
            };
            if !passes.is_empty() {
                let mut placed = 0u32;
                for (k, &(branch, _)) in passes.iter().enumerate() {
                    let (got, c) = compactor.compact_branch(dev, compact, states[0], states[1], n, branch, placed)?;
                    if mode == Mode::Regrouped {
                        r.per_branch[k] += got as u64;
                    }
                    placed += got;
                    r.compaction.merge(&c);
                    r.totals.merge(&c);
                }
                states.swap(0, 1);
                n = placed;
            }
            // every path may have ended at this level's trace: nothing to shade
            // (an empty grid is no launch)
            if n > 0 {
                let mut args = scene_args.clone();
                args.extend([Arg::Ptr(states[0]), Arg::U32(n), Arg::Ptr(accum), Arg::Ptr(last)]);
                let s = dev.launch(module, "regroup_shade", grid(n), &args)?.totals;
                r.shade.merge(&s);
                r.totals.merge(&s);
            }
            if r.shade_threads.len() <= l {
                r.shade_threads.push(0);
            }
            r.shade_threads[l] += n as u64;
        }
        r.image.frames += 1;
        if keep_frames {
            r.image.frame_images.push(Progressive::pixels_of(params.width, params.height, &dev.read::<f32>(last, n3)));
        }
        progress(f + 1);
    }
    r.image.accum = dev.read::<f32>(accum, n3);
    Ok(r)
}
