//! Thesis 003's convergence claims as charts (issue 15, item 5; extract
//! A.10): the error of each integrator's running image against the committed
//! Mitsuba 3 reference (`tests/fixtures/mitsuba/`), over samples per pixel
//! and over time, log-log (`warplight chart lin-convergence`).
//!
//! - *Error*: the RMS error over pixels and channels, and the relative error
//!   of the image's mean luminance (Y = 0.212671 R + 0.715160 G + 0.072169 B,
//!   the thesis' MLT scalar, 003:L322). The reference's own noise is stated
//!   beside them, from its variance-of-the-mean image: an error can fall no
//!   further than that floor.
//! - *Time*: two axes, both labelled as what they are. Native host seconds,
//!   measured in the same run (the native twin on rayon, on a shared
//!   machine), and the warp instructions the emulator counts for the kernels
//!   that made an image (a proxy for GPU time: there is no timing model of
//!   the thesis' GTX 960M). Emulation is slow, so the emulated points are the
//!   first few frames only; each emulated image is checked to equal the
//!   native render of as many frames bit for bit
//!   ([`Curve::emulated_equals_native`]), so the native curve is the
//!   emulated one at more samples.
//!
//! Each integrator may be charted with either ending of its paths
//! ([`Termination`]: the thesis' Russian roulette, or the kernel's
//! fixed-depth build), a curve for each pair, each with one frame's variance
//! over its frames and the seconds a frame took: the cost of roulette's
//! variance against the time it saves (003:L269).
//!
//! Path tracing, next-event estimation, MIS (balance and power) and bdpt
//! frames are independent, so the running image after f frames is the mean
//! of f frames' images. MLT's frames are not (the chains go on); its running
//! image is the same mean of its frames' splat images, the estimate its
//! render would return after f frames.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::chart::{Scatter, Series};
use crate::host::camera::Camera;
use crate::host::image::{FrameBuffer, ImageError};
use crate::host::path::layout::LayoutError;
use crate::host::path::{FrameParams, Integrator, SAMPLES_PER_FRAME, Termination, mlt, render_native, stats};
use crate::host::scene::Scene;
use crate::repro::lin2017::runs;

/// The integrators charted, in the order of the thesis' chapter 4.
pub const INTEGRATORS: [Integrator; 6] =
    [Integrator::Pt, Integrator::Nee, Integrator::MisBalance, Integrator::MisPower, Integrator::Bdpt, Integrator::Mlt];

/// Luminance weights (003:L322).
const Y: [f64; 3] = [0.212671, 0.715160, 0.072169];

/// Why the convergence cannot be measured or drawn.
#[derive(Debug, thiserror::Error)]
pub enum ConvergenceError {
    /// A reference file could not be read.
    #[error("reference: {0}")]
    Image(#[from] ImageError),
    /// The reference's metadata could not be read.
    #[error("{path}: {msg}")]
    Metadata {
        /// The file.
        path: String,
        /// What is wrong.
        msg: String,
    },
    /// The reference's size is not the render's.
    #[error("{path}: the reference is {w}x{h}, the render {size}x{size}")]
    Size {
        /// The reference's mean image.
        path: String,
        /// Its width.
        w: u32,
        /// Its height.
        h: u32,
        /// The render's side.
        size: u32,
    },
    /// Settings that give no curve.
    #[error("{0}")]
    Settings(String),
    /// The scene's layout refused it (or the integrator, for a medium).
    #[error(transparent)]
    Layout(#[from] LayoutError),
    /// The path tracer refused the settings.
    #[error(transparent)]
    Params(#[from] crate::host::path::FrameParamsError),
    /// MLT refused the settings.
    #[error(transparent)]
    Mlt(#[from] mlt::MltError),
    /// The emulated or the native render failed.
    #[error(transparent)]
    Twin(#[from] runs::TwinError),
    /// The native renderer refused the settings.
    #[error(transparent)]
    Render(#[from] crate::host::path::RenderError),
}

/// The side of the committed Mitsuba references (`tests/fixtures/mitsuba/SCENE-32*`).
pub const REFERENCE_SIDE: u32 = 32;

/// A committed Mitsuba reference: its mean image, its variance of the mean, and its sample count.
#[derive(Debug, Clone)]
pub struct Reference {
    /// The files' common prefix (`tests/fixtures/mitsuba/cornell-rough-32`).
    pub prefix: PathBuf,
    /// The mean image.
    pub mean: FrameBuffer,
    /// Per pixel and channel: the variance of the mean (from its batches).
    pub var: FrameBuffer,
    /// Samples a pixel (batches × samples a subpixel × 4 subpixels).
    pub spp: u64,
}

impl Reference {
    /// The committed reference of `scene`: `tests/fixtures/mitsuba/SCENE-32` of the checkout.
    pub fn default_prefix(scene: &str) -> PathBuf {
        let rel = format!("tests/fixtures/mitsuba/{scene}-{REFERENCE_SIDE}");
        let exr = crate::host::scene_file::data_file(Path::new(&format!("{rel}.exr")));
        PathBuf::from(exr.display().to_string().trim_end_matches(".exr"))
    }

    /// Reads `PREFIX.exr`, `PREFIX-var.exr` and `PREFIX.json` (`tools/mitsuba/reference.py`'s files).
    pub fn read(prefix: &Path) -> Result<Reference, ConvergenceError> {
        let with = |suffix: &str| PathBuf::from(format!("{}{suffix}", prefix.display()));
        let mean = stats::read_exr(&with(".exr"))?;
        let var = stats::read_exr(&with("-var.exr"))?;
        let meta_path = with(".json");
        let bad = |msg: String| ConvergenceError::Metadata { path: meta_path.display().to_string(), msg };
        let text = std::fs::read_to_string(&meta_path).map_err(|e| bad(e.to_string()))?;
        let meta: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        let field = |k: &str| meta.get(k).and_then(serde_json::Value::as_u64).ok_or_else(|| bad(format!("no `{k}`")));
        let spp = field("batches")? * field("spp_per_subpixel_per_batch")? * u64::from(SAMPLES_PER_FRAME);
        if (var.width, var.height) != (mean.width, mean.height) {
            return Err(ImageError::Size(mean.width, mean.height, var.width, var.height).into());
        }
        Ok(Reference { prefix: prefix.to_path_buf(), mean, var, spp })
    }

    /// The reference's own noise: the RMS over pixels and channels of its
    /// standard error (what an RMS error against it cannot fall below), and
    /// a bound on the relative standard error of its mean luminance (the
    /// channels of a pixel taken as fully correlated: σ_Y ≤ Σ w_c σ_c).
    pub fn noise(&self) -> (f64, f64) {
        let n = self.var.pixels.len() as f64;
        let mse = self.var.pixels.iter().flat_map(|p| p.iter()).map(|&v| v as f64).sum::<f64>() / (3.0 * n);
        let var_y: f64 = self
            .var
            .pixels
            .iter()
            .map(|p| (0..3).map(|c| Y[c] * (p[c] as f64).max(0.0).sqrt()).sum::<f64>().powi(2))
            .sum();
        (mse.sqrt(), var_y.sqrt() / n / mean_luminance(&self.mean))
    }
}

/// The RMS difference of `a` and `b` over pixels and channels.
pub fn rmse(a: &FrameBuffer, b: &FrameBuffer) -> f64 {
    runs::masked_rmse(a, b, |_| true)
}

/// The mean luminance of an image.
pub fn mean_luminance(a: &FrameBuffer) -> f64 {
    let s: f64 = a.pixels.iter().map(|p| (0..3).map(|c| Y[c] * p[c] as f64).sum::<f64>()).sum();
    s / a.pixels.len().max(1) as f64
}

/// One image's errors and what it cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// Samples a pixel.
    pub spp: u32,
    /// RMS error against the reference.
    pub rmse: f64,
    /// |mean luminance − the reference's| / the reference's.
    pub rel_mean: f64,
    /// Native: host seconds from the render's start to this frame's end (measured).
    pub seconds: f64,
    /// Emulated: warp instructions of every launch that made the image (counted).
    pub warp_instructions: Option<u64>,
    /// Emulated: thread instructions of the same.
    pub thread_instructions: Option<u64>,
}

impl Point {
    /// The error's variance: its mean square with the reference's own noise
    /// `floor` taken out (rmse² − floor², at least 0).
    pub fn error_variance(&self, floor: f64) -> f64 {
        (self.rmse * self.rmse - floor * floor).max(0.0)
    }

    fn of(image: &FrameBuffer, r: &Reference, spp: u32, seconds: f64) -> Point {
        let want = mean_luminance(&r.mean);
        Point {
            spp,
            rmse: rmse(image, &r.mean),
            rel_mean: (mean_luminance(image) - want).abs() / want,
            seconds,
            warp_instructions: None,
            thread_instructions: None,
        }
    }
}

/// One integrator's curves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    /// The integrator (`warplight render --integrator` name).
    pub integrator: String,
    /// How its paths end (the thesis' roulette, or the fixed-depth build).
    #[serde(default)]
    pub termination: Termination,
    /// Native renders' running images at 1, 2, 4, ... frames.
    pub native: Vec<Point>,
    /// Emulated renders of a few frames each.
    pub emulated: Vec<Point>,
    /// Whether every emulated render's accumulation equals the native render of as many frames, bit for bit.
    pub emulated_equals_native: bool,
    /// The variance of one frame's pixel (4 samples), over the native
    /// frames, averaged over pixels and channels: what the error's variance
    /// is at 1 frame, with no reference in it. None for MLT, whose frames
    /// are not independent.
    #[serde(default)]
    pub frame_variance: Option<f64>,
    /// Native host seconds a frame took: the last point's over its frames.
    #[serde(default)]
    pub frame_seconds: Option<f64>,
}

impl Curve {
    /// The least-squares slope of log(error) against log(spp) over the native
    /// points from `from_spp` on, the error with the reference's own noise
    /// `floor` taken out (√(rmse² − floor²)); -1/2 for an unbiased Monte Carlo estimate.
    pub fn slope(&self, from_spp: u32, floor: f64) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .native
            .iter()
            .filter(|p| p.spp >= from_spp && p.rmse > floor)
            .map(|p| ((p.spp as f64).ln(), p.error_variance(floor).sqrt().ln()))
            .collect();
        runs::fit_slope(&pts)
    }

    /// The native point at `spp`.
    pub fn at(&self, spp: u32) -> Option<&Point> {
        self.native.iter().find(|p| p.spp == spp)
    }

    /// The series' name: the integrator, and the ending when it is not the thesis' roulette.
    pub fn label(&self) -> String {
        label(&self.integrator, self.termination)
    }

    /// The cost of an accuracy from the frames' own spread: one frame's
    /// variance times its native seconds ([`Curve::frame_variance`]).
    pub fn frame_variance_seconds(&self) -> Option<f64> {
        Some(self.frame_variance? * self.frame_seconds?)
    }

    /// The cost of an accuracy at the last native point: the error's
    /// variance (its mean square, the reference's `floor` taken out) times
    /// the seconds it took. Constant for an unbiased estimator as it
    /// converges; the lower, the more efficient (the inverse of Veach's
    /// efficiency, 1 / (variance × time)).
    pub fn variance_seconds(&self, floor: f64) -> Option<f64> {
        let p = self.native.last()?;
        Some(p.error_variance(floor) * p.seconds)
    }
}

/// A scene's curves: the chart data (`docs/images/lin-convergence-*-data.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Convergence {
    /// The scene's name.
    pub scene: String,
    /// Image side in pixels.
    pub size: u32,
    /// The longest path in bounces.
    pub bounces: u32,
    /// Seed of the random numbers.
    pub seed: u32,
    /// The reference's files' prefix.
    pub reference: String,
    /// The reference's samples a pixel.
    pub reference_spp: u64,
    /// The reference's own noise: RMS of its standard error over pixels and channels.
    pub reference_rmse: f64,
    /// A bound on the relative standard error of the reference's mean luminance.
    pub reference_rel_mean: f64,
    /// Threads the native renders ran on (rayon).
    pub native_threads: usize,
    /// The emulator's fidelity and device for the emulated points.
    pub emulated_with: String,
    /// Per integrator and ending (the integrators' order, each with the endings in turn).
    pub curves: Vec<Curve>,
}

/// What to measure.
#[derive(Debug, Clone)]
pub struct Options {
    /// The integrators.
    pub integrators: Vec<Integrator>,
    /// The endings each integrator is measured with (a curve for each pair).
    pub terminations: Vec<Termination>,
    /// Native frames (4 samples a pixel each); points at 1, 2, 4, ... and the last.
    pub frames: u32,
    /// Emulated renders, in frames each (may be empty).
    pub emulated_frames: Vec<u32>,
    /// The longest path in bounces.
    pub bounces: u32,
    /// Seed.
    pub seed: u32,
}

/// The frame counts a curve has points at: powers of two below `frames`, and `frames`.
pub fn checkpoints(frames: u32) -> Vec<u32> {
    let mut v: Vec<u32> = (0..32).map(|k| 1u32 << k).take_while(|&f| f < frames).collect();
    v.push(frames);
    v
}

/// Renders `scene` at the reference's size with every integrator of `o`,
/// natively (and briefly on the emulator) and measures the curves;
/// `progress` hears each step.
pub fn measure(
    scene: &Scene,
    r: &Reference,
    o: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Convergence, ConvergenceError> {
    let size = r.mean.width;
    if r.mean.height != size {
        return Err(ConvergenceError::Size {
            path: r.prefix.display().to_string(),
            w: r.mean.width,
            h: r.mean.height,
            size,
        });
    }
    if o.frames == 0 || o.integrators.is_empty() || o.terminations.is_empty() || o.emulated_frames.contains(&0) {
        return Err(ConvergenceError::Settings(
            "expected at least one integrator and ending, a positive frame count and positive emulated frame counts"
                .into(),
        ));
    }
    let ps = runs::path_scene(scene)?;
    let camera = Camera { resolution: [size, size], ..scene.camera };
    let (ref_rmse, ref_rel) = r.noise();
    let marks = checkpoints(o.frames);
    let mut curves = Vec::new();
    let runs: Vec<(Integrator, Termination)> =
        o.integrators.iter().flat_map(|&i| o.terminations.iter().map(move |&t| (i, t))).collect();
    for (integrator, termination) in runs {
        ps.check_integrator(&scene.name, integrator)?;
        let params = FrameParams { termination, ..runs::square(size, integrator, o.bounces, o.seed) };
        params.check()?;
        if integrator == Integrator::Mlt {
            mlt::check(&params)?;
        }
        let name = label(integrator.name(), termination);
        progress(&format!("{name}: {} native frames", o.frames));
        let mut at = Vec::with_capacity(o.frames as usize);
        let t0 = Instant::now();
        let run = render_native(&ps, &camera, params, o.frames, true, |_| at.push(t0.elapsed().as_secs_f64()))?;
        let frame_variance =
            (integrator != Integrator::Mlt).then(|| runs::pixel_variance(&run.frame_images)).flatten().map(|(v, _)| v);
        let frame_seconds = at.last().map(|&s| s / o.frames as f64);
        let native = runs::running_means(&run.frame_images, &marks)
            .into_iter()
            .map(|(frames, mean)| Point::of(&mean, r, frames * SAMPLES_PER_FRAME, at[frames as usize - 1]))
            .collect();
        let mut emulated = Vec::new();
        let mut equal = true;
        for &ef in &o.emulated_frames {
            progress(&format!("{name}: {ef} emulated frame(s)"));
            let runs::Twin { emulated: k, same, seconds } = runs::emulate_twin(&ps, &camera, params, ef)?;
            equal &= same;
            let mut p = Point::of(&k.image.image(), r, ef * SAMPLES_PER_FRAME, seconds);
            p.warp_instructions = Some(k.totals.warp_instructions);
            p.thread_instructions = Some(k.totals.thread_instructions);
            emulated.push(p);
        }
        curves.push(Curve {
            integrator: integrator.name().into(),
            termination,
            native,
            emulated_equals_native: equal,
            emulated,
            frame_variance,
            frame_seconds,
        });
    }
    Ok(Convergence {
        scene: scene.name.clone(),
        size,
        bounces: o.bounces,
        seed: o.seed,
        reference: r.prefix.display().to_string(),
        reference_spp: r.spp,
        reference_rmse: ref_rmse,
        reference_rel_mean: ref_rel,
        native_threads: rayon::current_num_threads(),
        emulated_with: "functional fidelity, the path kernel's default simulator settings (kernel::sim_config)".into(),
        curves,
    })
}

/// A curve's name: `integrator`, and `termination` when it is not the thesis' roulette.
fn label(integrator: &str, termination: Termination) -> String {
    match termination {
        Termination::Roulette => integrator.to_string(),
        t => format!("{integrator}, {}", t.name()),
    }
}

/// The charts' names (`{}` in `warplight chart lin-convergence -o`).
pub const CHARTS: [&str; 4] = ["spp", "seconds", "instructions", "mean"];

impl Convergence {
    /// The charts, in [`CHARTS`]' order: RMS error against samples a pixel,
    /// against native seconds, against emulated warp instructions, and the
    /// mean luminance's relative error against samples a pixel; each with the
    /// reference's own noise as a flat series.
    pub fn charts(&self) -> Vec<Scatter> {
        let head = format!(
            "{} ({}x{}, {} bounces) against Mitsuba 3 ({} spp)",
            self.scene, self.size, self.size, self.bounces, self.reference_spp
        );
        let series = |pick: &dyn Fn(&Curve) -> Vec<(f64, f64)>| -> Vec<Series> {
            self.curves
                .iter()
                .map(|c| Series { name: c.label(), points: pick(c) })
                .filter(|s| !s.points.is_empty())
                .collect()
        };
        let floor = |s: &mut Vec<Series>, y: f64, what: &str| {
            let xs: Vec<f64> = s.iter().flat_map(|s| s.points.iter().map(|p| p.0)).collect();
            let (lo, hi) = xs.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
            if lo.is_finite() && y > 0.0 {
                s.push(Series { name: format!("the reference's own noise ({what})"), points: vec![(lo, y), (hi, y)] });
            }
        };
        let positive = |v: Vec<(f64, f64)>| v.into_iter().filter(|p| p.0 > 0.0 && p.1 > 0.0).collect::<Vec<_>>();
        let mut spp = series(&|c| positive(c.native.iter().map(|p| (p.spp as f64, p.rmse)).collect()));
        floor(&mut spp, self.reference_rmse, "RMS standard error");
        let mut secs = series(&|c| positive(c.native.iter().map(|p| (p.seconds, p.rmse)).collect()));
        floor(&mut secs, self.reference_rmse, "RMS standard error");
        let mut inst = series(&|c| {
            positive(c.emulated.iter().filter_map(|p| Some((p.warp_instructions? as f64, p.rmse))).collect())
        });
        floor(&mut inst, self.reference_rmse, "RMS standard error");
        let mut mean = series(&|c| positive(c.native.iter().map(|p| (p.spp as f64, p.rel_mean)).collect()));
        floor(&mut mean, self.reference_rel_mean, "bound on its standard error");
        let scatter = |title: String, x_label: &str, y_label: &str, series| Scatter {
            title,
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: true,
            log_y: true,
            connect: true,
            series,
        };
        vec![
            scatter(format!("{head}: RMS error vs samples (native; measured)"), "samples per pixel", "RMS error", spp),
            scatter(
                format!(
                    "{head}: RMS error vs native time (measured, {} rayon threads, shared machine)",
                    self.native_threads
                ),
                "native host seconds (measured, same run)",
                "RMS error",
                secs,
            ),
            scatter(
                format!("{head}: RMS error vs emulated warp instructions (counted; emulated = native bit for bit)"),
                "emulated warp instructions (counted; a GPU-time proxy, no GTX 960M timing model)",
                "RMS error",
                inst,
            ),
            scatter(
                format!("{head}: relative error of the mean luminance vs samples (native; measured)"),
                "samples per pixel",
                "|mean Y − reference| / reference",
                mean,
            ),
        ]
    }
}
