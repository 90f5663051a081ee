//! Runs `kernels/lin2017/path.cu` on the emulator: uploads the laid-out
//! scene once, launches `path_frame` once per frame (one thread per path,
//! 256-thread CTAs) and keeps the accumulation buffer on the device across
//! launches; the counters of every launch are summed, and the traversal
//! events of the `@count` lines read off each launch's profile. The kernel
//! comes in three builds ([`KernelBuild`]): the thesis' (Russian roulette,
//! the tent filter; `path.ptx`), the fixed depth (`path_fixed_depth.ptx`,
//! [`super::Termination`]) and stratified pixels (`path_stratified.ptx`,
//! [`super::PixelSampling`]); every render refuses a module of another build
//! than its frames need.

use super::counts::{self, Counts, Roulettes};
use super::layout::PathScene;
use super::{FrameParams, Progressive, eps_for, frame_of};
use crate::host::camera::Camera;
use crate::host::rt_kernels::upload;
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Counters, Device, DevicePtr, Fidelity, LaunchConfig, Module, SimConfig, SimError};

/// The kernel's PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/lin2017/path.ptx");
/// The same kernel without Russian roulette (`kernels/lin2017/path_fixed_depth.cu`).
pub const FIXED_DEPTH_PTX: &str = include_str!("../../../kernels/lin2017/path_fixed_depth.ptx");
/// The empty entry point that marks the fixed-depth build.
pub const FIXED_DEPTH_MARK: &str = "path_fixed_depth_build";
/// The same kernel with stratified pixels (`kernels/lin2017/path_stratified.cu`).
pub const STRATIFIED_PTX: &str = include_str!("../../../kernels/lin2017/path_stratified.ptx");
/// The empty entry point that marks the stratified build.
pub const STRATIFIED_MARK: &str = "path_stratified_build";

/// The builds of `kernels/lin2017/path.cu`: one source, compiled as the
/// thesis wrote it or with one of its alternatives switched in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum KernelBuild {
    /// Russian roulette and the tent filter (`path.ptx`): every counted table's.
    Thesis,
    /// No roulette: paths run to the longest path (`path_fixed_depth.ptx`, [`super::Termination`]).
    FixedDepth,
    /// Stratified pixels (`path_stratified.ptx`, [`super::PixelSampling`]).
    Stratified,
}

impl KernelBuild {
    /// Every build, the thesis' first.
    pub const ALL: [KernelBuild; 3] = [KernelBuild::Thesis, KernelBuild::FixedDepth, KernelBuild::Stratified];

    /// The build that frames of `params` need (their settings checked by [`FrameParams::check`]).
    pub fn of(params: &FrameParams) -> KernelBuild {
        if params.termination == super::Termination::FixedDepth {
            KernelBuild::FixedDepth
        } else if params.pixels != super::PixelSampling::Tent {
            KernelBuild::Stratified
        } else {
            KernelBuild::Thesis
        }
    }

    /// Its PTX and file name.
    pub fn ptx(self) -> (&'static str, &'static str) {
        match self {
            KernelBuild::Thesis => (PTX, "kernels/lin2017/path.ptx"),
            KernelBuild::FixedDepth => (FIXED_DEPTH_PTX, "kernels/lin2017/path_fixed_depth.ptx"),
            KernelBuild::Stratified => (STRATIFIED_PTX, "kernels/lin2017/path_stratified.ptx"),
        }
    }

    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            KernelBuild::Thesis => "thesis' (roulette, tent filter)",
            KernelBuild::FixedDepth => "fixed-depth",
            KernelBuild::Stratified => "stratified-pixel",
        }
    }

    /// Which build `module` is: the others' carry their empty marker kernel.
    pub fn of_module(module: &Module) -> KernelBuild {
        let has = |mark: &str| module.prog.functions.iter().any(|f| f.name == mark);
        if has(FIXED_DEPTH_MARK) {
            KernelBuild::FixedDepth
        } else if has(STRATIFIED_MARK) {
            KernelBuild::Stratified
        } else {
            KernelBuild::Thesis
        }
    }
}

/// Refuses frames of `params` that no build has ([`FrameParams::check_build`])
/// or on `module` when it is another build of the kernel than theirs (a path
/// would end, or a camera ray fall, otherwise than `params` say).
pub fn check_build(module: &Module, params: &FrameParams) -> Result<(), SimError> {
    params.check_build().map_err(|e| SimError::BadLaunch(e.to_string()))?;
    let (built, want) = (KernelBuild::of_module(module), KernelBuild::of(params));
    if built != want {
        return Err(SimError::BadLaunch(format!(
            "the frames need the {} build of the kernel, the loaded one is the {} build (load it with kernel::load_for)",
            want.name(),
            built.name()
        )));
    }
    Ok(())
}

/// The kernel's entry point (pt, nee, mis).
pub const KERNEL: &str = "path_frame";
/// The bidirectional path tracer's entry point.
pub const BDPT_KERNEL: &str = "bdpt_frame";

/// The entry point that renders `integrator` (mlt: its frame kernel, after `mlt_init` and `mlt_start`).
pub fn entry(integrator: super::Integrator) -> &'static str {
    match integrator {
        super::Integrator::Bdpt => BDPT_KERNEL,
        super::Integrator::Mlt => super::mlt::FRAME_KERNEL,
        _ => KERNEL,
    }
}
/// The entry point with a participating medium (pt, nee, mis; §5.2).
pub const VOLUME_KERNEL: &str = "volume_frame";

/// The entry point with translucent materials (pt, nee, mis; §5.3).
pub const SSS_KERNEL: &str = "sss_frame";

/// The entry point with texture maps (pt, nee, mis; §5.4).
pub const TEXTURE_KERNEL: &str = "texture_frame";

/// The entry point that renders `integrator` on `scene`: [`VOLUME_KERNEL`]
/// when it has a medium, [`SSS_KERNEL`] when it has a translucent material,
/// [`TEXTURE_KERNEL`] when it has texture maps, else [`entry`].
pub fn entry_for(scene: &PathScene, integrator: super::Integrator) -> &'static str {
    if scene.medium.is_some() {
        VOLUME_KERNEL
    } else if scene.has_translucent() {
        SSS_KERNEL
    } else if scene.textures.is_some() {
        TEXTURE_KERNEL
    } else {
        entry(integrator)
    }
}

/// Threads per CTA.
pub const THREADS: u32 = 256;
/// Warp instructions per path the watchdog allows one launch (a path of the
/// default 16 bounces needs well under a tenth of this).
pub const WARP_INSTRUCTIONS_PER_PATH: u64 = 1 << 14;

/// Loads the thesis' kernel (Russian roulette, the tent filter) on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    load_for(dev, KernelBuild::Thesis)
}

/// Loads `build` of the kernel on `dev` (for frames of `params`: [`KernelBuild::of`]).
pub fn load_for(dev: &mut Device, build: KernelBuild) -> Result<Module, SimError> {
    let (text, name) = build.ptx();
    dev.load_ptx(text, name)
}

/// A fresh device for frames of `params` ([`sim_config`]) at `fidelity`,
/// with the kernel loaded.
pub fn device(params: &FrameParams, fidelity: crate::sim::Fidelity) -> Result<(Device, Module), SimError> {
    let mut cfg = sim_config(params);
    cfg.fidelity = fidelity;
    let mut dev = Device::with_config(cfg);
    let m = load_for(&mut dev, KernelBuild::of(params))?;
    Ok((dev, m))
}

/// The simulator settings for frames of `params`: the default, with a
/// watchdog that grows with the number of paths (under mlt, with the
/// start-up's samples: [`super::mlt::BOOTSTRAP`] a pixel) and, at a fixed
/// depth, where every path runs to the longest path, with its bounces past
/// the default 16.
pub fn sim_config(params: &FrameParams) -> SimConfig {
    let mut c = SimConfig::default();
    let mut paths = params.paths() as u64;
    if params.integrator == super::Integrator::Mlt {
        paths = paths.max(params.width as u64 * params.height as u64 * super::mlt::BOOTSTRAP as u64);
    }
    let mut per_path = WARP_INSTRUCTIONS_PER_PATH;
    if params.termination == super::Termination::FixedDepth {
        let segments = u64::from(params.max_bounces) + 1;
        per_path = per_path.saturating_mul(segments.div_ceil(u64::from(super::DEFAULT_MAX_BOUNCES) + 1));
    }
    let budget = paths.saturating_mul(per_path);
    c.schedule.max_warp_instructions = c.schedule.max_warp_instructions.max(budget);
    c
}

/// The kernel's parameter block for `frame`.
pub fn params_bytes(scene: &PathScene, camera: &Camera, params: &FrameParams, frame: u32) -> Vec<u8> {
    params_bytes_mlt(scene, camera, params, frame, 0.0)
}

/// The parameter block for `frame` of `mlt_frame`, whose `mlt_b` is `b`
/// (the other kernels read no `mlt_b`).
pub fn params_bytes_mlt(scene: &PathScene, camera: &Camera, params: &FrameParams, frame: u32, b: f32) -> Vec<u8> {
    let c = frame_of(camera, eps_for(scene.lo, scene.hi));
    let mut floats = Vec::with_capacity(22);
    for v in [c.pos, c.fwd, c.right, c.up, scene.lo, scene.hi] {
        floats.extend_from_slice(&v);
    }
    floats.extend_from_slice(&[c.eps, c.tan_half, c.aspect, scene.light_area]);
    let mut bytes = to_bytes(&floats);
    for v in [
        params.width as i32,
        params.height as i32,
        params.paths() as i32,
        frame as i32,
        params.integrator.code(),
        params.max_bounces_i32(),
        scene.lights.len() as i32,
        params.seed as i32,
        params.traversal.code(),
        scene.env.as_ref().map_or(0, |e| e.width as i32),
        scene.env.as_ref().map_or(0, |e| e.height as i32),
    ] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(&b.to_le_bytes());
    bytes.extend_from_slice(&params.pixels.strata().to_le_bytes());
    bytes
}

/// The scene's buffers on the device, in the kernels' argument order.
#[derive(Debug, Clone, Copy)]
pub struct SceneBuffers {
    /// The parameter block (`Params`), rewritten per frame.
    pub params: DevicePtr,
    /// Nodes, references, triangle rows, triangle data, materials, lights,
    /// node boxes, environment texels (one black texel when there is none).
    pub data: [DevicePtr; 8],
}

impl SceneBuffers {
    /// The kernels' first nine arguments: the parameter block, then the scene's data.
    pub fn scene_args(&self) -> [DevicePtr; 9] {
        let d = self.data;
        [self.params, d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7]]
    }
}

/// The rows of `v`, one after the other.
fn flat<const N: usize>(v: &[[f32; N]]) -> Vec<f32> {
    v.iter().flatten().copied().collect()
}

/// Uploads the laid-out scene and frame 0's parameter block.
pub fn upload_scene(
    dev: &mut Device,
    scene: &PathScene,
    camera: &Camera,
    params: &FrameParams,
) -> Result<SceneBuffers, SimError> {
    let nodes: Vec<u32> = scene.nodes.iter().flatten().copied().collect();
    let pp = upload(dev, &params_bytes(scene, camera, params, 0), "params")?;
    let nb = upload(dev, &to_bytes(&nodes), "nodes")?;
    let rb = upload(dev, &to_bytes(&scene.refs), "refs")?;
    let tb = upload(dev, &to_bytes(&flat(&scene.tris)), "tris")?;
    let db = upload(dev, &to_bytes(&flat(&scene.tri_data)), "tri_data")?;
    let mb = upload(dev, &to_bytes(&flat(&scene.mats)), "materials")?;
    let lb = upload(dev, &to_bytes(&flat(&scene.lights)), "lights")?;
    let bb = upload(dev, &to_bytes(&flat(&scene.up)), "boxes")?;
    let none = [[0.0f32; 4]];
    let texels = scene.env.as_ref().map_or(&none[..], |e| &e.texels[..]);
    let eb = upload(dev, &to_bytes(&flat(texels)), "environment")?;
    Ok(SceneBuffers { params: pp, data: [nb, rb, tb, db, mb, lb, bb, eb] })
}

/// An emulated progressive render.
#[derive(Debug, Clone)]
pub struct KernelRender {
    /// The accumulated image and, if kept, each frame's.
    pub image: Progressive,
    /// The emulator's counters summed over the frames' launches.
    pub totals: Counters,
    /// The traversal events read off the `@count` lines, when the fidelity
    /// counts instructions (`instructions` or above).
    pub counts: Option<Counts>,
    /// Russian roulette's tests read off the same lines' tags, likewise.
    pub roulettes: Option<Roulettes>,
}

/// Renders `frames` frames of `camera`'s view on `dev` (with `module` loaded
/// by [`load`]); `keep_frames` keeps each frame's image; `progress` is told
/// each finished frame. Refused ([`SimError::BadLaunch`], naming why): mlt
/// settings [`super::mlt::check`] refuses, and bdpt or mlt on a scene with a
/// medium, translucent materials or texture maps ([`PathScene::ignores_medium`]).
#[allow(clippy::too_many_arguments)]
pub fn render(
    dev: &mut Device,
    module: &Module,
    scene: &PathScene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    keep_frames: bool,
    mut progress: impl FnMut(u32),
) -> Result<KernelRender, SimError> {
    check_build(module, &params)?;
    if scene.ignores_medium(params.integrator) {
        // volume_frame, sss_frame and texture_frame would run bdpt's integrator as a path tracer, mlt's kernels ignore them
        return Err(SimError::BadLaunch(super::RenderError::Medium(params.integrator.name()).to_string()));
    }
    if params.integrator == super::Integrator::Mlt {
        return super::mlt::render_emulated(dev, module, scene, camera, params, frames, keep_frames, progress)
            .map(KernelRender::from)
            .map_err(|e| match e {
                super::mlt::MltError::Sim(e) => e,
                refused => SimError::BadLaunch(refused.to_string()),
            });
    }
    let bufs = upload_scene(dev, scene, camera, &params)?;
    let pp = bufs.params;
    let n = params.paths() * 3;
    let accum = dev.alloc_zeroed::<f32>(n);
    let last = dev.alloc_zeroed::<f32>(n);
    // volume_frame takes the medium between the scene and the buffers
    let medium = scene.medium.map(|m| upload(dev, &to_bytes(&m), "medium")).transpose()?;
    // texture_frame takes the maps there
    let mut maps = Vec::new();
    if let Some(t) = &scene.textures {
        let m: Vec<i32> = t.mats.iter().flatten().copied().collect();
        maps.push(upload(dev, &to_bytes(&m), "tex_mats")?);
        maps.push(upload(dev, &to_bytes(&flat(&t.uvs)), "uvs")?);
        maps.push(upload(dev, &to_bytes(&t.info), "tex_info")?);
        maps.push(upload(dev, &to_bytes(&t.texels), "texels")?);
    }
    let args: Vec<Arg> =
        bufs.scene_args().into_iter().chain(medium).chain(maps).chain([accum, last]).map(Arg::Ptr).collect();
    let ctas = params.paths().div_ceil(THREADS as usize) as u32;
    let mut out = Progressive::new(params.width, params.height);
    let mut totals = Counters::default();
    let counted = dev.config().fidelity >= Fidelity::Instructions;
    let tags = counts::tags();
    let mut events = Counts::default();
    let mut roulettes = Roulettes::default();
    for f in 0..frames {
        dev.write(pp, &params_bytes(scene, camera, &params, f))?;
        let st = dev.launch(module, entry_for(scene, params.integrator), LaunchConfig::linear(ctas, THREADS), &args)?;
        totals.merge(&st.totals);
        if counted {
            let tagged = counts::tagged(&module.prog, &st.profile, &tags);
            events.add(&Counts::from_tags(&tagged));
            roulettes.add(&Roulettes::from_tags(&tagged));
        }
        out.frames += 1;
        if keep_frames {
            out.frame_images.push(Progressive::pixels_of(params.width, params.height, &dev.read::<f32>(last, n)));
        }
        progress(f + 1);
    }
    out.accum = dev.read::<f32>(accum, n);
    Ok(KernelRender { image: out, totals, counts: counted.then_some(events), roulettes: counted.then_some(roulettes) })
}
