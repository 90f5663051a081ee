//! `warplight render`: render a frame of a scene's flight.

use std::path::PathBuf;
use std::time::Instant;

use super::scene_info::scene_path;
use crate::host::kdtree::{BuildParams, Heuristic, build};
use std::io::IsTerminal;

use crate::host::raycast::{Caster, render};
use crate::host::rt_kernels::{self, Variant};
use crate::host::scene_file;
use crate::model::Profile;
use crate::sim::Device;

/// Options of `warplight render`.
#[derive(Debug, Clone, clap::Args)]
pub struct RenderArgs {
    /// Scene name (in scenes/) or path to a scene .toml.
    #[arg(long, default_value = "cornell-box")]
    pub scene: String,
    /// Frame of the camera flight (0 = the start pose).
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Frames A to B-1 of the flight (`A..B`), one image each: `-o out.png`
    /// writes out-0000.png, out-0001.png, ... (the frame number, 4 digits).
    #[arg(long, value_name = "A..B", conflicts_with = "frame")]
    pub frames: Option<String>,
    /// Image size WIDTHxHEIGHT (default: the scene's camera).
    #[arg(long)]
    pub resolution: Option<String>,
    /// Renderer: `native` (the Rust reference ray caster), or a kernel variant run
    /// on the emulator: stack, stackless, push-down, short-stack, push-down+short-stack,
    /// node-cache-1, stack-cache-1, node-cache-1+stack-cache-1, node-cache-2+stack-cache-2.
    /// `--method purcell --variant error`: seed 004's error charts instead of images (see --method).
    /// `--method photon-map --variant error`: thesis 000's estimators against a converged reference (charts).
    #[arg(long, default_value = "native")]
    pub variant: String,
    /// Device profile of the emulated kernels (every method's): their memory
    /// counters and arithmetic (FMA contraction, SFU model): gt200, maxwell, hopper.
    #[arg(long, default_value = "gt200")]
    pub device: String,
    /// ptxas's FMA contraction in the emulated kernels: --fmad=false rounds every
    /// instruction as written (default: on for maxwell and hopper, off for gt200).
    #[arg(long, value_name = "BOOL")]
    pub fmad: Option<bool>,
    /// What the emulated kernels model beyond the image: functional, instructions,
    /// memory or caches (the full model). The image is the same at every level.
    #[arg(long, default_value_t = crate::sim::Fidelity::Caches)]
    pub fidelity: crate::sim::Fidelity,
    /// kd-tree heuristic: sah or siroh.
    #[arg(long, default_value = "sah")]
    pub heuristic: String,
    /// Exposure for the PNG, in stops (negative darkens).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Output image (.png, or .exr for linear float).
    #[arg(short, long, default_value = "render.png")]
    pub output: PathBuf,
    /// Also write the counters as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Method: `raycast` (thesis 000's Whitted ray caster), `path` (thesis 003's
    /// path tracer), `photon-map` (thesis 000 ch. 5; `--estimator`) or `purcell`
    /// (seed 004's GPU photon map on both grid maps: OUT-bitonic.png, OUT-stencil.png;
    /// `--json` the convergence chart); the last three take `--variant native` or `emulated`.
    /// `--method purcell --variant error -o OUT.png`: the error of both maps' images against a
    /// converged native reference (64x the stated photons, 8x k) over photons stored
    /// (OUT-photons.svg) and pass by pass at the stated photons over counted instructions
    /// (OUT-time.svg) and over passes (OUT-passes.svg, full vs visual convergence), each with
    /// its JSON, and OUT-summary.json (the reference's own error, when each display settles).
    #[arg(long, default_value = "raycast")]
    pub method: String,
    /// Path tracer: pt, nee, mis (balance heuristic), mis-power, bdpt (bidirectional:
    /// light and eye subpaths, every Lambertian pair connected, the thesis' uniform weights),
    /// or mlt (Metropolis light transport in primary sample space over bdpt: one chain a
    /// pixel, 16 bootstrap samples a pixel for b, large steps with probability 0.25,
    /// --spp mutations a pixel; consistent, with start-up bias in early frames).
    /// A scene with a `[medium]` (participating media, §5.2: smog-room, fog-box) is
    /// marched by pt, nee and mis (kernel volume_frame: steps of the scene's `step`
    /// with one random offset a ray, Beer's law, single scattering from direct
    /// light with a shadow ray at each sample); bdpt and mlt refuse it.
    /// A scene with a `kind = "translucent"` material (subsurface scattering, §5.3:
    /// bunny-jade) is traced by pt, nee and mis (kernel sss_frame: the 3-way
    /// Fresnel switch at its surface, at most one scattering inside, at
    /// d = -ln(xi) / ((1 - g) sigma_s), the direction from HG(g)); bdpt and mlt refuse it.
    /// A scene with texture maps (albedo, roughness, metalness, §5.4:
    /// cornell-scratched) is traced by pt, nee and mis (kernel texture_frame: at each
    /// hit the metalness picks the Lambertian or the Cook-Torrance lobe); bdpt and mlt refuse it.
    /// A `kind = "coated"` material (the thesis' own, §4.5: cornell-coated) takes every
    /// integrator: its coat's Schlick switch picks a mirror reflection or Ashikhmin and
    /// Shirley's coupled diffuse, which nee and mis light-sample (bdpt does not connect through it).
    #[arg(long, default_value = "nee")]
    pub integrator: String,
    /// Path tracer: samples per pixel, a multiple of 4 (one frame traces the 2 x 2 subpixels).
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Path tracer: the longest path in bounces (at most 8190).
    #[arg(long, default_value_t = crate::host::path::DEFAULT_MAX_BOUNCES,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(crate::host::path::MAX_BOUNCES)))]
    pub bounces: u32,
    /// Path tracer: seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Path tracer: the kd-tree traversal, stack (the 8-byte short stack), stack12 (12-byte entries), restart or backtrack.
    #[arg(long, default_value = "stack")]
    pub traversal: String,
    /// Path tracer: how a path ends, roulette (the thesis' Russian roulette,
    /// §4.5) or fixed-depth (no roulette: every path runs to --bounces; a
    /// second build of the kernel, kernels/lin2017/path_fixed_depth.cu).
    #[arg(long, default_value = "roulette")]
    pub termination: String,
    /// Path tracer: where camera rays fall in their subpixels, tent (the
    /// thesis' tent filter over uniform jitter, §4.2) or stratified:D (frame f
    /// in stratum f mod D² of a D x D grid, a box filter; a third build of the
    /// kernel, kernels/lin2017/path_stratified.cu; whole rounds need --spp a
    /// multiple of 4·D²) or progressive:D (D a power of two: the same strata in
    /// a scrambled order, every 4^j frames one ray in each cell of a 2^j x 2^j
    /// grid and every frame count a fair image).
    #[arg(long, default_value = "tent")]
    pub pixels: String,
    /// Path tracer, emulated: how the frames are launched. megakernel (one launch
    /// a frame); wavefront (a launch a level: path_init, then path_level per
    /// bounce), compacted (the same with thread compaction between levels, §6.3);
    /// split (trace and shade of each level apart), split-compacted (the active
    /// states compacted between them) or regrouped (compacted by next Fresnel
    /// branch, the 3-way regroup of §6.3). The same image bit for bit; pt, nee,
    /// mis and mis-power on scenes without media, translucent materials or textures.
    #[arg(long, default_value = "megakernel")]
    pub form: String,
    /// Photon map (thesis 000 ch. 5): vkde, vkde-epanechnikov, knn (Table 5.1's k) or knn:K.
    #[arg(long, default_value = "vkde")]
    pub estimator: String,
}

/// The trace counters as JSON. An emulated run's ray kinds, stack pushes
/// (local memory) and texel fetches are the emulator's per-line counts of the
/// kernel's `@count` lines, like its other counters.
fn counters_json(st: &crate::host::raycast::TraceStats) -> serde_json::Value {
    serde_json::to_value(st).unwrap_or_default()
}

/// The largest image `render` makes (its frame buffer holds 12 bytes a pixel).
const MAX_PIXELS: u64 = crate::limits::MAX_PIXELS;

/// Host bytes a pixel costs: the native caster's frame buffer and the image
/// written; an emulated render adds the kernels' device buffers (colour, hit
/// and counters: 52 bytes) and their copies.
fn bytes_per_pixel(emulated: bool) -> u64 {
    if emulated { 128 } else { 32 }
}

/// `out.png` for frame 5: `out-0005.png`.
fn frame_output(output: &std::path::Path, frame: u32) -> PathBuf {
    let stem = output.file_stem().and_then(|s| s.to_str()).unwrap_or("render");
    let ext = output.extension().and_then(|s| s.to_str()).unwrap_or("png");
    output.with_file_name(format!("{stem}-{frame:04}.{ext}"))
}

/// Runs the command: one frame, or each frame of `--frames A..B` with the
/// range's progress and ETA on stderr.
pub fn run(a: RenderArgs) -> Result<(), Box<dyn std::error::Error>> {
    let Some(frames) = &a.frames else { return run_frame(a) };
    let range = crate::repro::protocol::FrameRange::parse(frames)?;
    // the whole range is checked before the first frame
    let flight = scene_file::load(&scene_path(&a.scene))?.flight.frames;
    if range.end > flight {
        return Err(format!("--frames {frames}: the flight has {flight} frames (0..{flight})").into());
    }
    let t0 = Instant::now();
    for (i, f) in (range.start..range.end).enumerate() {
        let b = RenderArgs { frames: None, frame: f, output: frame_output(&a.output, f), ..a.clone() };
        run_frame(b)?;
        let done = i as u32 + 1;
        let left = range.len() - done;
        let eta = t0.elapsed().as_secs_f64() / done as f64 * left as f64;
        eprintln!(
            "frames {done}/{} done in {:.1} s{}",
            range.len(),
            t0.elapsed().as_secs_f64(),
            if left > 0 { format!(", eta {eta:.0} s") } else { String::new() }
        );
    }
    Ok(())
}

/// A bar of the image's pixels, moved by the kernels' job queue (the
/// simulator's progress hook), with an ETA; on a terminal only.
fn pixel_progress(dev: &mut Device, kernel: &str, pixels: u64) -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = indicatif::ProgressBar::new(pixels);
    let style = "{msg} [{bar:30}] {pos}/{len} pixels [{elapsed}, eta {eta}]";
    pb.set_style(indicatif::ProgressStyle::with_template(style).ok()?);
    pb.set_message(format!("emulating {kernel}"));
    pb.enable_steady_tick(std::time::Duration::from_millis(200));
    let bar = pb.clone();
    dev.set_progress(Some(std::sync::Arc::new(move |p: &crate::sim::grid::Progress| {
        let queue = p.memory.allocations().iter().find(|a| a.name == rt_kernels::JOB_QUEUE);
        if let Some(q) = queue {
            // pixels claimed by the warps (in blocks of 32); those of the last blocks are still running
            bar.set_position(q.load(0, 4).min(pixels));
        }
    })));
    Some(pb)
}

/// Writes `fb` to `out` as OpenEXR (`.exr`) or PNG: encoded in memory, then
/// written beside the output under a temporary name and renamed, so that
/// neither a failure nor a signal leaves a partial image.
pub(crate) fn write_image(
    fb: &crate::host::image::FrameBuffer,
    out: &std::path::Path,
    exposure: f32,
) -> Result<(), String> {
    let exr = out.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    super::write_atomically(out, &encode(fb, exr, exposure)?)
}

/// The image as the bytes of a PNG (sRGB, `exposure` stops) or an OpenEXR
/// file (linear 32-bit float RGB).
fn encode(fb: &crate::host::image::FrameBuffer, exr: bool, exposure: f32) -> Result<Vec<u8>, String> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    if exr {
        use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = fb.get(x as u32, y as u32);
            (p[0], p[1], p[2])
        });
        let image = Image::from_channels((fb.width as usize, fb.height as usize), channels);
        image.write().to_buffered(&mut bytes).map_err(|e| format!("encoding the EXR image: {e}"))?;
    } else {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new(&mut bytes)
            .write_image(&fb.to_srgb8(exposure), fb.width, fb.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| format!("encoding the PNG image: {e}"))?;
    }
    Ok(bytes.into_inner())
}

/// An error naming the first option given a value other than its default
/// for a method or variant it does not apply to (rather than ignoring it).
fn check_applicable(a: &RenderArgs) -> Result<(), String> {
    let m = a.method.as_str();
    let path_only = [
        ("--integrator", a.integrator != "nee"),
        ("--spp", a.spp != 16),
        ("--bounces", a.bounces != crate::host::path::DEFAULT_MAX_BOUNCES),
        ("--seed", a.seed != 0),
        ("--traversal", a.traversal != "stack"),
        ("--termination", a.termination != "roulette"),
        ("--pixels", a.pixels != "tent"),
        ("--form", a.form != "megakernel"),
    ];
    if let Some((o, _)) = path_only.iter().find(|x| m != "path" && x.1) {
        return Err(format!("{o} applies to --method path only, not {m}"));
    }
    if m != "photon-map" && a.estimator != "vkde" {
        return Err(format!("--estimator applies to --method photon-map only, not {m}"));
    }
    if m != "raycast" && a.heuristic != "sah" {
        return Err(format!("--heuristic applies to --method raycast only ({m} builds its own tree)"));
    }
    if !matches!(m, "raycast" | "purcell") && a.json.is_some() {
        return Err(format!("--json applies to --method raycast and purcell ({m} writes no counters)"));
    }
    if m == "purcell" && a.variant == "error" && a.json.is_some() {
        return Err("--json applies to --method purcell's native and emulated variants (--variant error writes \
                    each chart's data beside -o as JSON)"
            .into());
    }
    // the accuracy charts run fixed models and every estimator (accuracy::run_cli takes none of these)
    if m == "photon-map" && a.variant == "error" {
        let fixed = [
            ("--device", a.device != "gt200"),
            ("--fmad", a.fmad.is_some()),
            ("--fidelity", a.fidelity != crate::sim::Fidelity::Caches),
            ("--estimator", a.estimator != "vkde"),
        ];
        if let Some((o, _)) = fixed.iter().find(|x| x.1) {
            return Err(format!(
                "{o} does not apply to --method photon-map --variant error: the accuracy charts use the GT200 \
                 model of Table 6.6 and compare every estimator"
            ));
        }
    }
    // natively, raycast and path run no kernel (purcell's native variant still emulates the map passes)
    if matches!(m, "raycast" | "path") && a.variant == "native" {
        let emulated_only = [
            ("--device", a.device != "gt200"),
            ("--fmad", a.fmad.is_some()),
            ("--fidelity", a.fidelity != crate::sim::Fidelity::Caches),
        ];
        if let Some((o, _)) = emulated_only.iter().find(|x| x.1) {
            return Err(format!("{o} applies to emulated kernels; --method {m} --variant native runs none"));
        }
    }
    Ok(())
}

/// Renders one frame.
fn run_frame(a: RenderArgs) -> Result<(), Box<dyn std::error::Error>> {
    if !matches!(a.method.as_str(), "raycast" | "path" | "photon-map" | "purcell") {
        return Err(format!("unknown method `{}`; expected raycast, path, photon-map or purcell", a.method).into());
    }
    check_applicable(&a)?;
    let kernel_variant = match a.variant.as_str() {
        _ if a.method == "path" || a.method == "photon-map" || a.method == "purcell" => None,
        "native" => None,
        v => Some(Variant::parse(v).ok_or_else(|| {
            let names: Vec<&str> = Variant::EVERY.iter().map(|v| v.name()).collect();
            format!("unknown variant `{v}`; expected native, {}", names.join(", "))
        })?),
    };
    let profile = Profile::parse(&a.device).ok_or_else(|| format!("unknown device `{}`", a.device))?;
    let h = match a.heuristic.as_str() {
        "sah" => Heuristic::Sah,
        "siroh" => Heuristic::Siroh,
        o => return Err(format!("unknown heuristic `{o}`; expected sah or siroh").into()),
    };
    // the output is checked before any work: its format, and that its folder exists
    let ext = a.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        return Err(format!("-o {}: expected a .png or .exr file", a.output.display()).into());
    }
    let parent = a.output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    if !parent.is_dir() {
        return Err(format!("-o {}: the folder {} does not exist", a.output.display(), parent.display()).into());
    }
    let scene = scene_file::load(&scene_path(&a.scene))?;
    if a.frame >= scene.flight.frames {
        return Err(format!("frame {} is past the flight's {} frames", a.frame, scene.flight.frames).into());
    }
    let mut cam = scene.flight.camera(&scene.camera, a.frame);
    if let Some(r) = &a.resolution {
        let (w, h) = r
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
            .filter(|(w, h)| *w > 0 && *h > 0)
            .ok_or_else(|| format!("--resolution {r}: expected WIDTHxHEIGHT, e.g. 512x512"))?;
        if w as u64 * h as u64 > MAX_PIXELS {
            return Err(format!(
                "--resolution {r}: {} pixels is more than {MAX_PIXELS} (16384 x 16384); render in tiles or smaller",
                w as u64 * h as u64
            )
            .into());
        }
        cam.resolution = [w, h];
    }
    let [width, height] = cam.resolution;
    if a.method == "path" {
        return run_path(&a, &scene, &cam, profile);
    }
    if a.method == "photon-map" {
        return run_photon_map(&a, &scene, &cam);
    }
    if a.method == "purcell" {
        return crate::repro::purcell2003::image::run_cli(&a, &scene, &cam, profile);
    }
    crate::limits::check_memory(
        || format!("a render of {width} x {height} pixels"),
        (width as u64 * height as u64).saturating_mul(bytes_per_pixel(kernel_variant.is_some())),
    )?;
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let t0 = Instant::now();
    let tree = build(&tris, BuildParams::thesis(h));
    let build_s = t0.elapsed().as_secs_f64();
    let caster = Caster::new(&scene, &tree);
    let t1 = Instant::now();
    let (fb, st, emulated) = match kernel_variant {
        None => {
            let (fb, st) = render(&caster, &cam, scene.flight.light_offset(a.frame));
            (fb, st, None)
        }
        Some(v) => {
            let mut config = rt_kernels::sim_config(&cam);
            config.fidelity = a.fidelity;
            profile.configure(&mut config, a.fmad);
            let mut dev = Device::with_config(config);
            let module = rt_kernels::load(&mut dev)?;
            let pb = pixel_progress(&mut dev, v.kernel(), width as u64 * height as u64);
            let k = rt_kernels::render(
                &mut dev,
                &module,
                &scene,
                &tree,
                &cam,
                scene.flight.light_offset(a.frame),
                v,
                profile,
            );
            if let Some(pb) = pb {
                pb.finish_and_clear();
            }
            let k = k?;
            (k.image.clone(), k.trace, Some(k))
        }
    };
    let render_s = t1.elapsed().as_secs_f64();
    write_image(&fb, &a.output, a.exposure)?;
    let ts = tree.stats();
    println!(
        "{} frame {} ({}x{}), {} triangles, {} tree: {} inner nodes, {} references, depth {} (built in {:.3} s)",
        scene.name,
        a.frame,
        cam.resolution[0],
        cam.resolution[1],
        scene.triangles.len(),
        h,
        ts.inner_nodes,
        ts.tri_refs,
        ts.depth,
        build_s
    );
    // an emulated run's ray kinds come from the emulator's counts of the kernel's `@count` lines
    let kinds = format!("primary {}, reflection {}, shadow {}", st.primary, st.reflection, st.shadow);
    // the functional level keeps no per-line counters: the kernels' work is then unknown, not zero
    let counted = emulated.as_ref().is_none_or(|k| k.counted);
    if !counted {
        println!(
            "  rays and per-ray work not counted at --fidelity functional (they need the instructions level)  in {render_s:.3} s"
        );
    } else {
        println!("  rays {} ({kinds})  in {:.3} s: {:.2} M rays/s", st.rays, render_s, st.rays as f64 / render_s / 1e6);
        println!(
            "  per ray: {:.2} inner nodes, {:.2} leaves, {:.2} plane tests, {:.2} barycentric tests, {:.2} stack pushes{}",
            st.inner_nodes as f64 / st.rays.max(1) as f64,
            st.leaves as f64 / st.rays.max(1) as f64,
            st.plane_tests as f64 / st.rays.max(1) as f64,
            st.barycentric_tests as f64 / st.rays.max(1) as f64,
            st.pushes as f64 / st.rays.max(1) as f64,
            if emulated.is_some() { " (local memory)" } else { "" }
        );
        if st.texel_fetches > 0 {
            println!("  texture maps: {} texel fetches", st.texel_fetches);
        }
    }
    if let Some(k) = &emulated {
        let c = &k.launch.totals;
        println!(
            "  emulated {}: {} warp instructions, {} thread instructions{}",
            k.launch.kernel,
            c.warp_instructions,
            c.thread_instructions,
            if counted {
                format!(
                    " ({:.0} instructions per ray by the thesis' rule: warp instructions x 32 / rays)",
                    c.warp_instructions as f64 * 32.0 / st.rays.max(1) as f64
                )
            } else {
                String::new()
            }
        );
        println!(
            "  branches {} (divergent {}), global atomics {}, {} profile: {} global load transactions, {} texture lookups ({} hits)",
            c.branches,
            c.divergent_branches,
            c.atomics.global,
            profile,
            k.memory.counters.global_ld.sectors,
            k.memory.counters.texture.sectors,
            k.memory.counters.texture.hits
        );
    }
    println!("  wrote {}", a.output.display());
    if let Some(j) = &a.json {
        let v = serde_json::json!({
            "scene": scene.name, "frame": a.frame, "variant": a.variant, "heuristic": h,
            "resolution": cam.resolution, "tree": ts, "counters": if counted { counters_json(&st) } else { serde_json::Value::Null }, "render_seconds": render_s,
            "emulator": emulated.as_ref().map(|k| serde_json::json!({
                "totals": k.launch.totals, "memory": k.memory.metrics(&k.launch.totals).into_iter().collect::<std::collections::BTreeMap<_, _>>(),
            })),
        });
        super::write_atomically(j, serde_json::to_string_pretty(&v)?.as_bytes())?;
    }
    Ok(())
}

/// `warplight render --method path` (thesis 003's path tracer,
/// [`crate::repro::lin2017::render`]) with the command's options.
fn run_path(
    a: &RenderArgs,
    scene: &crate::host::scene::Scene,
    camera: &crate::host::camera::Camera,
    profile: Profile,
) -> Result<(), Box<dyn std::error::Error>> {
    use crate::host::path::{FrameParams, Integrator, PixelSampling, Termination, Traversal};
    let integrator = Integrator::parse(&a.integrator).ok_or_else(|| {
        format!(
            "unknown integrator `{}`; expected pt, nee, mis (balance heuristic), mis-power, bdpt or mlt",
            a.integrator
        )
    })?;
    let traversal = Traversal::parse(&a.traversal)
        .ok_or_else(|| format!("unknown traversal `{}`; expected stack, stack12, restart or backtrack", a.traversal))?;
    let termination = Termination::parse(&a.termination)
        .ok_or_else(|| format!("unknown termination `{}`; expected roulette or fixed-depth", a.termination))?;
    let pixels = PixelSampling::parse(&a.pixels)?;
    let frames = crate::repro::lin2017::render::frames_for(a.spp)?;
    // the emulated kernel runs on the command's profile, FMA contraction and fidelity
    let set = |c: &mut crate::sim::SimConfig| {
        c.fidelity = a.fidelity;
        profile.configure(c, a.fmad);
    };
    let emulated: Option<&dyn Fn(&mut crate::sim::SimConfig)> = match a.variant.as_str() {
        "native" => None,
        "emulated" => Some(&set),
        v => return Err(format!("--method path --variant {v}: expected native or emulated").into()),
    };
    let [width, height] = camera.resolution;
    let params =
        FrameParams { width, height, integrator, max_bounces: a.bounces, seed: a.seed, traversal, termination, pixels };
    let form = crate::repro::lin2017::render::Form::parse(&a.form)?;
    let r = crate::repro::lin2017::render::render_form(scene, camera, params, frames, emulated, form)?;
    write_image(&r.image, &a.output, a.exposure)?;
    println!(
        "{} ({}x{}), path tracer {} ({} traversal, {}{}), {} spp ({} frames of 4 subpixels), at most {} bounces: {:.3} s, {:.3} M paths/s{}",
        scene.name,
        width,
        height,
        integrator.name(),
        traversal.name(),
        termination.name(),
        if pixels == PixelSampling::Tent { String::new() } else { format!(", {} pixels", pixels.name()) }
            + &if form == crate::repro::lin2017::render::Form::Megakernel {
                String::new()
            } else {
                format!(", {} form", form.name())
            },
        a.spp,
        frames,
        a.bounces,
        r.seconds,
        params.paths() as f64 * frames as f64 / r.seconds.max(1e-9) / 1e6,
        if emulated.is_some() { " (emulated)" } else { " (native)" }
    );
    if let Some((w, t)) = r.instructions {
        println!("  emulated {}: {w} warp instructions, {t} thread instructions", r.kernel);
    }
    if let Some(q) = r.roulettes.filter(|q| q.tests > 0) {
        println!(
            "  Russian roulette: {} tests, {} ({:.2} %) with q, the mask's largest channel, 1 or more: kept undivided (003:L269 takes the mask to be at most 1; exactly 1 at white smooth mirrors and glass and at coats' reflections, above 1 at rough ones' grazing samples and at bright coated diffuse near the normal)",
            q.tests,
            q.at_or_above_one(),
            100.0 * q.at_or_above_one() as f64 / q.tests as f64
        );
    }
    if !pixels.fair(frames) {
        println!(
            "  note: {} pixels take {} frames a round; {} frames end inside a round, so the last round's strata cover only the top of each subpixel",
            pixels.name(),
            pixels.round(),
            frames
        );
    }
    println!("  wrote {}", a.output.display());
    Ok(())
}

/// `warplight render --method photon-map`: the direct light of the native ray
/// caster plus the photon-mapped indirect light of `scene` seen by `cam`,
/// natively (`--variant native`) or with the photon, construction and
/// estimation kernels on the emulator (`--variant emulated`; bit for bit the same).
fn run_photon_map(
    a: &RenderArgs,
    scene: &crate::host::scene::Scene,
    cam: &crate::host::camera::Camera,
) -> Result<(), Box<dyn std::error::Error>> {
    use crate::repro::fabianowski2011::photon_image::{Options, parse_estimator, render_parameters};
    use crate::repro::fabianowski2011::{knn, photon_image, vkde};
    let (estimator, shape) = parse_estimator(&a.estimator, &scene.name).ok_or_else(|| {
        format!(
            "unknown estimator `{}`; expected vkde, vkde-epanechnikov, knn or knn:K (1..={})",
            a.estimator,
            knn::K_MAX
        )
    })?;
    let emulated = match a.variant.as_str() {
        "native" => false,
        "emulated" => true,
        "error" => return crate::repro::fabianowski2011::accuracy::run_cli(scene, cam, &a.output),
        v => return Err(format!("--method photon-map --variant {v}: expected native, emulated or error").into()),
    };
    let (photons, spread) = render_parameters(&scene.name);
    let o = Options { photons, spread, h_max: vkde::H_MAX, estimator, shape, emulated };
    let [width, height] = cam.resolution;
    crate::limits::check_memory(
        || format!("a photon-mapped render of {width} x {height} pixels with {photons} photons"),
        photon_image::host_bytes(photons, width as u64 * height as u64, emulated),
    )?;
    // the emulated kernels run on the command's profile, FMA contraction and fidelity
    let profile = Profile::parse(&a.device).ok_or_else(|| format!("unknown device `{}`", a.device))?;
    let dev = emulated.then(|| {
        let mut config = crate::sim::SimConfig { fidelity: a.fidelity, ..Default::default() };
        profile.configure(&mut config, a.fmad);
        Device::with_config(config)
    });
    let t = std::time::Instant::now();
    let (image, r) = photon_image::render_scene(scene, cam, &o, scene.flight.light_offset(a.frame), dev)?;
    let out = &a.output;
    write_image(&image, out, a.exposure)?;
    let c = &r.maps.constructed;
    println!(
        "{} ({}x{}), photon map: {} photons, s = {}, {} interactions ({} discarded, {} clamped), {:?} {:?}, \
         {} query points, {:.1} contributions each: {:.3} s{}",
        scene.name,
        cam.resolution[0],
        cam.resolution[1],
        photons,
        spread,
        c.interactions,
        c.discarded,
        c.clamped,
        estimator,
        shape,
        r.queries,
        r.contributions as f64 / r.queries.max(1) as f64,
        t.elapsed().as_secs_f64(),
        if emulated { " (emulated)" } else { " (native)" }
    );
    println!("  wrote {} (direct light of the ray caster + photon-mapped indirect light)", out.display());
    Ok(())
}
