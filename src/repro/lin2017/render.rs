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
    /// Russian roulette's tests, counted by the emulator (the megakernel at
    /// fidelity `instructions` or above; mlt's render counts none).
    pub roulettes: Option<crate::host::path::counts::Roulettes>,
}

/// How the emulated frames are launched: the megakernel (one launch a
/// frame, the default) or one of the wavefront forms of §6.3 (a launch per
/// level, with or without thread compaction; or trace and shade apart, the
/// states compacted or regrouped by Fresnel branch between them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// `path_frame` (and the other entry points): one launch a frame.
    Megakernel,
    /// `path_init`, then `path_level` per level (`host::path::wavefront`), in that mode.
    Levels(crate::host::path::wavefront::Mode),
    /// `regroup_init`, then `regroup_trace` and `regroup_shade` per level (`host::path::regroup`), in that mode.
    Split(crate::host::path::regroup::Mode),
}

impl Form {
    /// Every form with its name, as `--form` takes it.
    pub const ALL: [(&'static str, Form); 6] = {
        use crate::host::path::{regroup, wavefront};
        [
            ("megakernel", Form::Megakernel),
            ("wavefront", Form::Levels(wavefront::Mode::Normal)),
            ("compacted", Form::Levels(wavefront::Mode::Compacted)),
            ("split", Form::Split(regroup::Mode::Normal)),
            ("split-compacted", Form::Split(regroup::Mode::Compacted)),
            ("regrouped", Form::Split(regroup::Mode::Regrouped)),
        ]
    };

    /// The form named `s`, or an error listing them.
    pub fn parse(s: &str) -> Result<Form, String> {
        Form::ALL.iter().find(|f| f.0 == s).map(|f| f.1).ok_or_else(|| {
            let names: Vec<&str> = Form::ALL.iter().map(|f| f.0).collect();
            format!("--form {s}: unknown form; expected {}", names.join(", "))
        })
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        Form::ALL.iter().find(|f| f.1 == self).map_or("megakernel", |f| f.0)
    }
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
    render_form(scene, camera, params, frames, emulated, Form::Megakernel)
}

/// As [`render`], the emulated frames launched in `form`. The wavefront
/// forms trace pt, nee, mis and mis-power on scenes without a medium,
/// translucent materials or texture maps (their kernels run `step()`, the
/// plain path tracer's bounce), on the emulator only; anything else is refused.
pub fn render_form(
    scene: &crate::host::scene::Scene,
    camera: &Camera,
    params: FrameParams,
    frames: u32,
    emulated: Option<&dyn Fn(&mut crate::sim::SimConfig)>,
    form: Form,
) -> Result<PathRender, Box<dyn std::error::Error>> {
    params.check()?;
    if form != Form::Megakernel {
        use crate::host::path::Integrator;
        if emulated.is_none() {
            return Err(
                format!("--form {}: the wavefront forms are launches, so --variant emulated", form.name()).into()
            );
        }
        if matches!(params.integrator, Integrator::Bdpt | Integrator::Mlt) {
            return Err(format!(
                "--form {}: the wavefront forms trace pt, nee, mis and mis-power, not {}",
                form.name(),
                params.integrator.name()
            )
            .into());
        }
    }
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
    let entry = kernel::entry_for(&ps, params.integrator);
    if form != Form::Megakernel && entry != kernel::KERNEL {
        return Err(format!(
            "--form {}: scene `{}` needs the {entry} kernel (a medium, translucent materials or texture maps); the wavefront forms run the plain path tracer",
            form.name(),
            scene.name,
        )
        .into());
    }
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
    let mut roulettes = None;
    let (image, instructions) = match emulated {
        None => (render_native(&ps, camera, params, frames, false, tick)?.image(), None),
        Some(set) => {
            let mut cfg = kernel::sim_config(&params);
            set(&mut cfg);
            let mut dev = Device::with_config(cfg);
            let module = kernel::load_for(&mut dev, kernel::KernelBuild::of(&params))?;
            let (image, totals) = match form {
                Form::Megakernel => {
                    let k = kernel::render(&mut dev, &module, &ps, camera, params, frames, false, tick)?;
                    roulettes = k.roulettes;
                    (k.image, k.totals)
                }
                Form::Levels(mode) => {
                    let compact = crate::host::path::wavefront::load_compact(&mut dev)?;
                    let r = crate::host::path::wavefront::render(
                        &mut dev, &module, &compact, &ps, camera, params, frames, mode, false, tick,
                    )?;
                    (r.image, r.totals)
                }
                Form::Split(mode) => {
                    let compact = crate::host::path::wavefront::load_compact(&mut dev)?;
                    let r = crate::host::path::regroup::render(
                        &mut dev, &module, &compact, &ps, camera, params, frames, mode, false, tick,
                    )?;
                    (r.image, r.totals)
                }
            };
            (image.image(), Some((totals.warp_instructions, totals.thread_instructions)))
        }
    };
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    let kernel = match form {
        Form::Megakernel => entry,
        Form::Levels(crate::host::path::wavefront::Mode::Normal) => "path_init and path_level",
        Form::Levels(_) => "path_init, path_level and the compaction kernels",
        Form::Split(crate::host::path::regroup::Mode::Normal) => "regroup_init, regroup_trace and regroup_shade",
        Form::Split(_) => "regroup_init, regroup_trace, regroup_shade and the compaction kernels",
    };
    Ok(PathRender { image, frames, seconds: t0.elapsed().as_secs_f64(), instructions, kernel, roulettes })
}
