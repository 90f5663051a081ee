//! Frame rates of thesis 000's ray-tracing kernels (Tables 4.1, 4.6, 4.10;
//! seed 000 L1664–1674, L1902–1912, L2146–2157) from the GTX 280 timing model
//! ([`crate::timing`]) applied to the emulator's counters of each frame. No
//! parameter comes from the thesis' frame rates: the model's parameters are
//! the GTX 280's specifications and published GT200 microbenchmarks
//! (`docs/timing-model.md`); the launch is the thesis' (30 persistent CTAs of
//! 256 threads, 54 registers per thread, L1896, L2140).
//!
//! The measurement groups record the counters of [`counts_of`] under the
//! names of [`KernelCounts::counters`] (`timing_*`) beside their own; a
//! results file without them yields no frame rates (the table says so).

use crate::host::camera::Camera;
use crate::host::kdtree::KdTree;
use crate::host::rt_kernels::{self, CTAS, THREADS, Variant};
use crate::host::scene::Scene;
use crate::model::{ModelStats, Profile};
use crate::ptx::Program;
use crate::repro::compare::Tolerance;
use crate::repro::results::Results;
use crate::repro::table::{RowKind, Table};
use crate::sim::{Device, LaunchStats, SimError};
use crate::timing::{GTX_280, KernelCounts, Launch, LaunchShape, Prediction, predict, waits};

/// Registers per thread of the thesis' kernel: "a single CUDA kernel using 54
/// registers, allowing 256 threads to be resident per SM" (seed 000 L1896).
/// Our PTX's register declarations say nothing about ptxas' allocation.
pub const REGISTERS: u32 = 54;

/// The image side the thesis' frame rates are for (§A.2: 512 × 512).
pub const THESIS_RESOLUTION: u32 = 512;

/// The tolerance of a predicted absolute frame rate: ±15 % (issue 16's goal).
pub const FPS_TOLERANCE: Tolerance = Tolerance::Relative(0.15);

/// The launch shape of `kernel` of `prog`: the thesis' persistent launch,
/// its 54 registers, and the shared memory the kernel's PTX declares.
pub fn shape(prog: &Program, kernel: &str) -> LaunchShape {
    let shared = prog
        .functions
        .iter()
        .position(|f| f.is_entry && f.name == kernel)
        .map_or(0, |k| prog.kernel_shared_size(k as u32));
    LaunchShape { ctas: CTAS, threads_per_cta: THREADS, registers_per_thread: REGISTERS, shared_per_cta: shared }
}

/// The timing model's counters of one launch of `prog` on the gt200
/// profile: warp instructions (SFU class apart), shared-memory bank-conflict
/// passes, waits on shared, global/local and texture loads
/// ([`crate::timing::waits`]), warp-level texture loads, 32-bit texel fetches
/// (texture bytes / 4), texture L1 misses, and DRAM bytes (32/64/128-byte
/// segment transactions of global and local accesses, 32-byte texture lines
/// that missed).
pub fn counts_of(prog: &Program, launch: &LaunchStats, memory: &ModelStats) -> KernelCounts {
    let m = &memory.counters;
    let t = &launch.totals;
    let w = waits(prog, &launch.profile);
    let seg = |a: &crate::model::AccessCounts| (a.t32 * 32 + a.t64 * 64 + a.t128 * 128) as f64;
    let line = crate::model::Profile::Gt200.params().tex_line as f64;
    KernelCounts {
        warp_instructions: t.warp_instructions as f64,
        sfu_instructions: t.by_class.sfu as f64,
        shared_extra_passes: (m.shared_ld.bank_conflicts + m.shared_st.bank_conflicts + m.shared_atom.bank_conflicts)
            as f64,
        shared_waits: w.shared as f64,
        global_waits: w.global as f64,
        texture_waits: w.texture as f64,
        texture_loads: m.texture.instructions as f64,
        texel_fetches: m.texture.bytes as f64 / 4.0,
        texture_misses: m.texture.misses as f64,
        dram_bytes: seg(&m.global_ld)
            + seg(&m.global_st)
            + seg(&m.local_ld)
            + seg(&m.local_st)
            + seg(&m.global_atom)
            + seg(&m.global_red)
            + m.texture.misses as f64 * line,
    }
}

/// A mean frame of `variant` of `group` on `scene` at the thesis' 512 × 512:
/// the recorded counters summed over the frames, divided by the frames and
/// scaled by the pixels; `None` when the results lack the timing counters.
pub fn mean_frame(r: &Results, group: &str, scene: &str, variant: &str) -> Option<KernelCounts> {
    let frames: u32 = r.scene(scene)?.frames.iter().map(|f| f.len()).sum();
    let c = KernelCounts::from_counters(|n| r.sum(group, scene, variant, n))?;
    let res = r.protocol.resolution.max(1) as f64;
    Some(c.scaled((THESIS_RESOLUTION as f64 / res).powi(2) / frames.max(1) as f64))
}

/// The predicted frame of `variant` (a kernel of [`crate::host::rt_kernels`])
/// on the GTX 280, or `None` when not measured with the timing counters.
/// Residency is the launch's one CTA per SM: every variant's shared memory
/// (at most the 12 KB short stacks) fits beside it (checked by
/// `tests/timing_model.rs` against each kernel's PTX through [`shape`]).
pub fn frame(r: &Results, group: &str, scene: &str, variant: &str) -> Option<Prediction> {
    let counts = mean_frame(r, group, scene, variant)?;
    predict(&GTX_280, &Launch { counts, shape: persistent(REGISTERS) }).ok()
}

/// Predicted frames per second, or NaN when not measured.
pub fn fps(r: &Results, group: &str, scene: &str, variant: &str) -> f64 {
    frame(r, group, scene, variant).map_or(f64::NAN, |p| p.fps())
}

/// The timing counters of the camera rays of a photon-mapped frame: chapter
/// 4's stack kernel (`raytrace.cu`, primary, reflection and shadow rays) on
/// the SIROH tree `tree` under the gt200 memory model, the light moved by
/// `light_offset`. Tables 6.4 and 6.6 add the gather's counters to these: the
/// thesis' frame is ray tracing and density estimation (§A.2).
pub fn camera_rays(
    scene: &Scene,
    tree: &KdTree,
    cam: &Camera,
    light_offset: [f32; 3],
) -> Result<KernelCounts, SimError> {
    let mut config = rt_kernels::sim_config(cam);
    Profile::Gt200.configure(&mut config, None);
    let mut dev = Device::with_config(config);
    let module = rt_kernels::load(&mut dev)?;
    let light = glam::Vec3::from(light_offset);
    let rk = rt_kernels::render(&mut dev, &module, scene, tree, cam, light, Variant::Stack, Profile::Gt200)?;
    Ok(counts_of(&module.prog, &rk.launch, &rk.memory))
}

/// Appends `k`'s counters as `stage.` + [`KernelCounts::counters`]' names.
pub fn record(c: &mut Vec<(String, f64)>, stage: &str, k: &KernelCounts) {
    c.extend(k.counters().into_iter().map(|(n, v)| (format!("{stage}.{n}"), v)));
}

/// The mean frame of `variant` of `group` on `scene` recorded under `stage`
/// ([`record`]): the counters summed over the variant's samples, divided by
/// their number and scaled from the run's resolution to a `side` × `side`
/// image; `None` when the results lack the counters (measured before they were
/// recorded).
pub fn stage_frame(
    r: &Results,
    group: &str,
    scene: &str,
    variant: &str,
    stage: &str,
    side: u32,
) -> Option<KernelCounts> {
    let frames = r.samples.iter().filter(|s| s.group == group && s.scene == scene && s.variant == variant).count();
    let c = KernelCounts::from_counters(|n| r.sum(group, scene, variant, &format!("{stage}.{n}")))?;
    let res = r.protocol.resolution.max(1) as f64;
    Some(c.scaled((side as f64 / res).powi(2) / frames.max(1) as f64))
}

/// The persistent launch of `registers` registers a thread (30 CTAs of 256
/// threads, no shared memory): how the photon-map and scene-BVH tables'
/// frames are modelled.
pub fn persistent(registers: u32) -> LaunchShape {
    LaunchShape { ctas: CTAS, threads_per_cta: THREADS, registers_per_thread: registers, shared_per_cta: 0 }
}

/// Predicted milliseconds of a [`stage_frame`] run as `shape` on the GTX
/// 280; `None` when not measured with the timing counters.
#[allow(clippy::too_many_arguments)]
pub fn stage_ms(
    r: &Results,
    group: &str,
    scene: &str,
    variant: &str,
    stage: &str,
    side: u32,
    shape: LaunchShape,
) -> Option<f64> {
    predicted_ms_at(&stage_frame(r, group, scene, variant, stage, side)?, shape)
}

/// The GTX 280 timing model's milliseconds for `counts` run as `shape`.
pub fn predicted_ms_at(counts: &KernelCounts, shape: LaunchShape) -> Option<f64> {
    predict(&GTX_280, &Launch { counts: *counts, shape }).ok().map(|p| p.seconds * 1e3)
}

/// Predicted frames per second of a [`stage_ms`], NaN when not measured
/// with the timing counters (the table then prints no value).
#[allow(clippy::too_many_arguments)]
pub fn stage_fps(
    r: &Results,
    group: &str,
    scene: &str,
    variant: &str,
    stage: &str,
    side: u32,
    shape: LaunchShape,
) -> f64 {
    stage_ms(r, group, scene, variant, stage, side, shape).map_or(f64::NAN, |ms| 1e3 / ms)
}

/// What the frame-rate columns of a table are called modelled by.
pub const MODEL: &str = "GTX 280 timing model on the emulator's counters";

/// A note for a table whose frame-rate columns lack their counters, or
/// `None` when every row has them.
pub fn unmeasured_note(rows: &[(String, f64)]) -> Option<String> {
    let missing: Vec<&str> = rows.iter().filter(|(_, v)| !v.is_finite()).map(|(l, _)| l.as_str()).collect();
    (!missing.is_empty()).then(|| {
        format!(
            "Frame rates not measured for {}: the results were recorded without the timing counters (timing_*); \
             re-measure to model them.",
            missing.join(", ")
        )
    })
}

/// One line naming the model.
pub fn describe() -> String {
    format!(
        "GTX 280 timing model (docs/timing-model.md): {} SMs at {:.3} GHz, {} warps per SM (30 CTAs x 256 threads, {} registers), \
         issue {} cycles per warp instruction, load latencies {}/{}/{}/{} cycles (global+local / texture hit / texture miss / shared), \
         {:.1} GB/s, {:.1} Gtexel/s; parameters from specifications and microbenchmarks, none from the thesis' frame rates; counts scaled to 512 x 512",
        GTX_280.sms,
        GTX_280.shader_clock_hz / 1e9,
        THREADS / 32,
        REGISTERS,
        GTX_280.alu_cycles,
        GTX_280.global_latency,
        GTX_280.texture_hit_latency,
        GTX_280.texture_miss_latency,
        GTX_280.shared_latency,
        GTX_280.dram_bytes_per_s / 1e9,
        GTX_280.texels_per_s / 1e9,
    )
}

/// A note listing each compared cell's error: the absolute column as a
/// relative error, the relative columns as the difference in percentage
/// points and whether the sign agrees.
pub fn error_note(t: &Table) -> String {
    let mut parts = Vec::new();
    let (mut signs, mut right) = (0, 0);
    for row in t.rows.iter().filter(|r| r.kind == RowKind::Scene) {
        let mut cells = Vec::new();
        for (c, cell) in t.columns.iter().zip(&row.cells) {
            let (Some(o), Some(th)) = (cell.ours, cell.thesis_value) else { continue };
            if c.unit == crate::repro::table::Unit::Change {
                signs += 1;
                let same = (o >= 0.0) == (th >= 0.0) || th == 0.0;
                right += usize::from(same);
                cells.push(format!("{} {:+.1} pp{}", c.name, o - th, if same { "" } else { " (sign)" }));
            } else {
                cells.push(format!("{} {:+.1} %", c.name, (o / th - 1.0) * 100.0));
            }
        }
        if !cells.is_empty() {
            parts.push(format!("{}: {}", row.label, cells.join(", ")));
        }
    }
    if parts.is_empty() {
        return "Per-cell error: none (no frame rates: re-measure; the results lack the timing_* counters).".into();
    }
    format!(
        "Per-cell error (ours - thesis): {}. Relative columns with the thesis' sign: {right} of {signs}.",
        parts.join("; ")
    )
}
