//! `warplight render --method path`: thesis 003's path tracer, progressive
//! over frames (4 samples per pixel a frame), native or on the emulator,
//! written as EXR (linear) or PNG, with a progress bar on a terminal.

use std::io::IsTerminal;
use std::time::Instant;

use crate::host::camera::Camera;
use crate::host::image::FrameBuffer;
use crate::host::kdtree::{BuildParams, Heuristic, build};
use crate::host::path::build::{self as path_build, Construction};
use crate::host::path::layout::PathScene;
use crate::host::path::{FrameParams, SAMPLES_PER_FRAME, Traversal, kernel, render_native};
use crate::sim::Device;

/// What a path render produced.
#[derive(Debug, Clone)]
pub struct PathRender {
    /// The image.
    pub image: FrameBuffer,
    /// Frames traced.
    pub frames: u32,
    /// Seconds spent tracing.
    pub seconds: f64,
    /// The emulator's warp and thread instructions, when emulated.
    pub instructions: Option<(u64, u64)>,
    /// The kernel that renders the scene ([`kernel::entry_for`]).
    pub kernel: &'static str,
}

/// Frames for `spp` samples per pixel: `spp` must be a positive multiple of 4.
pub fn frames_for(spp: u32) -> Result<u32, String> {
    if spp == 0 || !spp.is_multiple_of(SAMPLES_PER_FRAME) {
        return Err(format!(
            "--spp {spp}: expected a positive multiple of {SAMPLES_PER_FRAME} (a frame traces one path in each of a pixel's 2 x 2 subpixels)"
        ));
    }
    Ok(spp / SAMPLES_PER_FRAME)
}

/// A progress bar over `frames` frames, on a terminal only.
fn bar(frames: u32, what: &str) -> Option<indicatif::ProgressBar> {
    std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new(frames as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} frames ({eta})") {
            pb.set_style(style);
        }
        pb.set_message(what.to_string());
        pb
    })
}

/// Renders `scene` with the path tracer: natively, or with `emulated` on
/// the emulator, `emulated` setting the kernel's settings (fidelity, the
/// device's arithmetic: [`crate::model::Profile::configure`]).
pub fn render(
    scene: &crate::host::scene::Scene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    emulated: Option<&dyn Fn(&mut crate::sim::SimConfig)>,
) -> Result<PathRender, Box<dyn std::error::Error>> {
    params.check()?;
    if params.integrator == crate::host::path::Integrator::Mlt {
        // the chains' state (40 k W H bytes) within its bound, before anything is built
        crate::host::path::mlt::check(&params)?;
    }
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    // the stackless traversals cannot return to a split plane they crossed:
    // they need thesis 003's SAH tree, which keeps a triangle lying in a split
    // plane on both sides (docs/reproduction-lin2017.md, Fig. 3)
    let tree = match params.traversal {
        Traversal::ShortStack | Traversal::FullStack => build(&tris, BuildParams::thesis(Heuristic::Sah)),
        _ => path_build::build(&tris, &path_build::Params::fig3(Construction::Sah, tris.len())),
    };
    let ps = PathScene::new(scene, &tree)?;
    ps.check_integrator(&scene.name, params.integrator)?;
    let what = format!(
        "{} {} {}x{}",
        if emulated.is_some() { "emulating" } else { "tracing" },
        params.integrator.name(),
        params.width,
        params.height
    );
    let pb = bar(frames, &what);
    let tick = |f: u32| {
        if let Some(pb) = &pb {
            pb.set_position(f as u64);
        }
    };
    let t0 = Instant::now();
    let (image, instructions) = match emulated {
        None => (render_native(&ps, camera, params, frames, false, tick)?.image(), None),
        Some(set) => {
            let mut cfg = kernel::sim_config(&params);
            set(&mut cfg);
            let mut dev = Device::with_config(cfg);
            let module = kernel::load_for(&mut dev, kernel::KernelBuild::of(&params))?;
            let k = kernel::render(&mut dev, &module, &ps, camera, params, frames, false, tick)?;
            (k.image.image(), Some((k.totals.warp_instructions, k.totals.thread_instructions)))
        }
    };
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    let kernel = kernel::entry_for(&ps, params.integrator);
    Ok(PathRender { image, frames, seconds: t0.elapsed().as_secs_f64(), instructions, kernel })
}
