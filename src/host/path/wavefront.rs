//! The wavefront form of the path tracer (Fig. 1's inner loop, 003:L119) and
//! thread compaction between its levels (§6.3, 003:L501-536), on the
//! emulator.
//!
//! A frame is `path_init` (every path's camera ray into its 64-byte state)
//! and then one `path_level` launch per level of the inner loop. Without
//! compaction ([`Mode::Normal`]) every level launches a thread for every
//! path, and the threads of ended paths return at once. With compaction
//! ([`Mode::Compacted`]) the active states are moved to the front of a second
//! buffer after every level by the flag, scan and scatter kernels of
//! `kernels/lin2017/compact.cu` (the thesis' `thrust::remove_if`), and the
//! next level launches a thread for each active path only. Random numbers
//! depend on the path and its bounce alone, so both forms trace exactly the
//! megakernel's paths (`tests/lin2017_compaction.rs`).
//!
//! Per level the emulator counts, at the `@count live` line of `path_level`
//! (the first load of an active state), the lanes that entered the level's
//! work and the warps that issued it: the active paths and the useful-lane
//! fraction of Fig. 16 and Fig. 17's proxies.

use super::counts;
use super::kernel::{self, SceneBuffers, params_bytes, upload_scene};
use super::layout::PathScene;
use super::{FrameParams, Progressive};
use crate::host::camera::Camera;
use crate::host::rt_kernels::{CountTag, tagged_counts};
use crate::sim::{Arg, Counters, Device, DevicePtr, Fidelity, LaunchConfig, Module, SimError};

/// The compaction kernels' PTX (clang-16), compiled in.
pub const COMPACT_PTX: &str = include_str!("../../../kernels/lin2017/compact.ptx");
/// Threads per CTA of every wavefront and compaction launch (`COMPACT_THREADS`).
pub const THREADS: u32 = 256;
/// Floats of one path's state (4 float4).
pub const STATE_FLOATS: usize = 16;
/// The state's flag bit of an active path (`PATH_ACTIVE`).
pub const PATH_ACTIVE: u32 = 2;
/// Lanes of a warp.
pub const WARP: u64 = 32;

/// Whether the levels compact their states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Mode {
    /// Every level launches a thread per path (ended paths return at once).
    Normal,
    /// Flag, scan and scatter the active states between levels; launch those alone.
    Compacted,
}

impl Mode {
    /// Both, in Fig. 17's column order (compact, normal).
    pub const ALL: [Mode; 2] = [Mode::Compacted, Mode::Normal];

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Normal => "normal",
            Mode::Compacted => "compact",
        }
    }
}

/// Loads the compaction kernels on `dev`.
pub fn load_compact(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(COMPACT_PTX, "kernels/lin2017/compact.ptx")
}

/// What one level cost, summed over frames.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Level {
    /// Threads launched for the level (`path_level`).
    pub threads: u64,
    /// Paths that entered the level's work (lanes at the `live` line).
    pub active: u64,
    /// Warps that issued the `live` line (warps with at least one active path).
    pub busy_warps: u64,
    /// Warps holding the level's threads (those of a CTA beyond `n` return at once).
    pub warps: u64,
    /// Warp instructions of the level's `path_level` launch.
    pub warp_instructions: u64,
    /// Thread instructions of it.
    pub thread_instructions: u64,
    /// Warp instructions of the compaction after the level (flag, scan, scatter).
    pub compact_warp_instructions: u64,
}

impl Level {
    /// Active lanes over the lanes of the warps that issued the level's work:
    /// Fig. 16's useful-operation fraction.
    pub fn useful_fraction(&self) -> f64 {
        self.active as f64 / (WARP * self.busy_warps).max(1) as f64
    }

    fn add(&mut self, o: &Level) {
        self.threads += o.threads;
        self.active += o.active;
        self.busy_warps += o.busy_warps;
        self.warps += o.warps;
        self.warp_instructions += o.warp_instructions;
        self.thread_instructions += o.thread_instructions;
        self.compact_warp_instructions += o.compact_warp_instructions;
    }
}

/// An emulated wavefront render.
#[derive(Debug, Clone)]
pub struct WavefrontRender {
    /// The accumulated image and, if kept, each frame's.
    pub image: Progressive,
    /// Per level (0 = camera rays), summed over frames; counted at fidelity
    /// `instructions` or above (the `live` columns are 0 below it).
    pub levels: Vec<Level>,
    /// The counters of every launch (initialisation, levels, compaction).
    pub totals: Counters,
    /// The counters of the compaction launches alone.
    pub compaction: Counters,
}

/// The device buffers of one compaction.
#[derive(Debug, Clone, Copy)]
pub struct Compactor {
    flags: DevicePtr,
    offsets: DevicePtr,
    sums: DevicePtr,
}

impl Compactor {
    /// Buffers for compacting up to `n` states.
    pub fn new(dev: &mut Device, n: usize) -> Compactor {
        let blocks = n.div_ceil(THREADS as usize).max(1);
        Compactor {
            flags: dev.alloc_zeroed::<u32>(n.max(1)),
            offsets: dev.alloc_zeroed::<u32>(n.max(1)),
            sums: dev.alloc_zeroed::<u32>(blocks + 1),
        }
    }

    /// Moves the active ones of the first `n` states of `from` to the front
    /// of `to`, in order; returns how many, and the launches' counters.
    pub fn compact(
        &self,
        dev: &mut Device,
        module: &Module,
        from: DevicePtr,
        to: DevicePtr,
        n: u32,
    ) -> Result<(u32, Counters), SimError> {
        let flag = ("compact_flag", vec![Arg::Ptr(from), Arg::U32(n), Arg::Ptr(self.flags)]);
        self.pass(dev, module, n, flag, ("compact_scatter", vec![Arg::Ptr(from)]), &[Arg::U32(n), Arg::Ptr(to)])
    }

    /// The 3-way regroup's compaction of one branch (`compact.cu`'s
    /// `regroup_flag` and `regroup_scatter`, 80-byte states of
    /// [`super::regroup`]): the active ones of the first `n` states of `from`
    /// whose next branch is `branch` ([`super::regroup::ANY`]: every active
    /// one) appended, in order, to `to` from state `base` on; returns how
    /// many, and the launches' counters.
    #[allow(clippy::too_many_arguments)]
    pub fn compact_branch(
        &self,
        dev: &mut Device,
        module: &Module,
        from: DevicePtr,
        to: DevicePtr,
        n: u32,
        branch: u32,
        base: u32,
    ) -> Result<(u32, Counters), SimError> {
        let flag = ("regroup_flag", vec![Arg::Ptr(from), Arg::U32(n), Arg::U32(branch), Arg::Ptr(self.flags)]);
        let tail = [Arg::U32(n), Arg::U32(base), Arg::Ptr(to)];
        self.pass(dev, module, n, flag, ("regroup_scatter", vec![Arg::Ptr(from)]), &tail)
    }

    /// Flag (the kernel and its arguments), scan, scan the CTA sums, scatter
    /// (the kernel, its arguments before the flags, offsets and sums, and
    /// those after them).
    fn pass(
        &self,
        dev: &mut Device,
        module: &Module,
        n: u32,
        flag: (&str, Vec<Arg>),
        scatter: (&str, Vec<Arg>),
        scatter_tail: &[Arg],
    ) -> Result<(u32, Counters), SimError> {
        let mut c = Counters::default();
        if n == 0 {
            return Ok((0, c));
        }
        let blocks = n.div_ceil(THREADS);
        let grid = LaunchConfig::linear(blocks, THREADS);
        let (f, o, s) = (Arg::Ptr(self.flags), Arg::Ptr(self.offsets), Arg::Ptr(self.sums));
        c.merge(&dev.launch(module, flag.0, grid, &flag.1)?.totals);
        c.merge(&dev.launch(module, "compact_scan", grid, &[f.clone(), Arg::U32(n), o.clone(), s.clone()])?.totals);
        let one = LaunchConfig::linear(1, THREADS);
        c.merge(&dev.launch(module, "compact_scan_sums", one, &[s.clone(), Arg::U32(blocks)])?.totals);
        let mut args = scatter.1;
        args.extend([f, o, s]);
        args.extend_from_slice(scatter_tail);
        c.merge(&dev.launch(module, scatter.0, grid, &args)?.totals);
        let total = dev.try_read::<u32>(self.sums, blocks as usize + 1)?[blocks as usize];
        Ok((total, c))
    }
}

/// The `live` tag of `path_level` (the compiled-in source has it:
/// `tests/lin2017_traversal.rs` checks every tag against the PTX).
pub fn live_tag() -> CountTag {
    counts::tags().into_iter().find(|t| t.name == "live").expect("kernels/lin2017/path.cu tags its `live` line")
}

/// Launches `path_level` over the first `n` states of `states` (finished
/// paths add to `out` = [accumulation, last]) and returns the level's costs;
/// its counters are merged into `totals`.
#[allow(clippy::too_many_arguments)]
pub fn level(
    dev: &mut Device,
    module: &Module,
    bufs: &SceneBuffers,
    states: DevicePtr,
    n: u32,
    out: [DevicePtr; 2],
    live: &CountTag,
    totals: &mut Counters,
) -> Result<Level, SimError> {
    if n == 0 {
        return Ok(Level::default());
    }
    let mut args: Vec<Arg> = bufs.scene_args().into_iter().map(Arg::Ptr).collect();
    args.extend([Arg::Ptr(states), Arg::U32(n), Arg::Ptr(out[0]), Arg::Ptr(out[1])]);
    let blocks = n.div_ceil(THREADS);
    let st = dev.launch(module, "path_level", LaunchConfig::linear(blocks, THREADS), &args)?;
    totals.merge(&st.totals);
    let tag = std::slice::from_ref(live);
    let get = |select: fn(&crate::sim::counters::InstCounts) -> u64| {
        tagged_counts(&module.prog, &st.profile, counts::SOURCE_FILE, tag, select).get("live").copied().unwrap_or(0)
    };
    Ok(Level {
        threads: n as u64,
        active: get(|c| c.pred_on),
        busy_warps: get(|c| c.warp),
        warps: (n as u64).div_ceil(WARP),
        warp_instructions: st.totals.warp_instructions,
        thread_instructions: st.totals.thread_instructions,
        compact_warp_instructions: 0,
    })
}

/// Renders `frames` frames in the wavefront form on `dev` (`module` loaded by
/// [`kernel::load`], `compact` by [`load_compact`]).
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
) -> Result<WavefrontRender, SimError> {
    super::kernel::check_build(module, &params)?;
    let live = live_tag();
    let bufs = upload_scene(dev, scene, camera, &params)?;
    let paths = params.paths();
    let n3 = paths * 3;
    let accum = dev.alloc_zeroed::<f32>(n3);
    let last = dev.alloc_zeroed::<f32>(n3);
    let live = &live;
    let mut states = [dev.alloc_zeroed::<f32>(paths * STATE_FLOATS), dev.alloc_zeroed::<f32>(paths * STATE_FLOATS)];
    let compactor = Compactor::new(dev, paths);
    let counted = dev.config().fidelity >= Fidelity::Instructions;
    let mut out = Progressive::new(params.width, params.height);
    let mut levels: Vec<Level> = Vec::new();
    let mut totals = Counters::default();
    let mut compaction = Counters::default();
    let blocks = (paths as u32).div_ceil(THREADS);
    for f in 0..frames {
        dev.write(bufs.params, &params_bytes(scene, camera, &params, f))?;
        let init = [Arg::Ptr(bufs.params), Arg::Ptr(states[0])];
        totals.merge(&dev.launch(module, "path_init", LaunchConfig::linear(blocks, THREADS), &init)?.totals);
        let mut n = paths as u32;
        for l in 0..=params.max_bounces as usize {
            let mut lv = level(dev, module, &bufs, states[0], n, [accum, last], live, &mut totals)?;
            if mode == Mode::Compacted && l < params.max_bounces as usize {
                let (k, c) = compactor.compact(dev, compact, states[0], states[1], n)?;
                lv.compact_warp_instructions = c.warp_instructions;
                totals.merge(&c);
                compaction.merge(&c);
                states.swap(0, 1);
                n = k;
            }
            if !counted {
                lv.active = 0;
                lv.busy_warps = 0;
            }
            if levels.len() <= l {
                levels.push(Level::default());
            }
            levels[l].add(&lv);
        }
        out.frames += 1;
        if keep_frames {
            out.frame_images.push(Progressive::pixels_of(params.width, params.height, &dev.read::<f32>(last, n3)));
        }
        progress(f + 1);
    }
    out.accum = dev.read::<f32>(accum, n3);
    Ok(WavefrontRender { image: out, levels, totals, compaction })
}

/// Loads both modules on a fresh device for `params` at `fidelity`.
pub fn device(params: &FrameParams, fidelity: Fidelity) -> Result<(Device, Module, Module), SimError> {
    let (mut dev, m) = kernel::device(params, fidelity)?;
    let c = load_compact(&mut dev)?;
    Ok((dev, m, c))
}
