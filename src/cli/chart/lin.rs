//! `warplight chart lin-convergence` and `lin-compaction`: thesis 003's
//! convergence and compaction charts (`crate::repro::lin2017::convergence`,
//! `crate::repro::lin2017::lanes`), measured or redrawn from their JSON.

use std::path::{Path, PathBuf};

use super::{parse_size, write};
use crate::chart::Chart;
use crate::host::path::{Integrator, PixelSampling, Termination};
use crate::repro::lin2017::convergence::{self, Convergence, Options, Reference};
use crate::repro::lin2017::lanes::{self, Compaction};
use crate::repro::lin2017::pixel_sampling::{self, PixelSamplingData};

/// Where the charts and their data go, or come from.
#[derive(Debug, clap::Args)]
pub struct Out {
    /// Redraw from this chart data (written by an earlier run) instead of measuring.
    #[arg(long)]
    pub from: Option<PathBuf>,
    /// Output .svg or .png with `{}` for each chart's name (lin-convergence:
    /// spp, seconds, instructions, mean; lin-pixel-sampling: spp, seconds,
    /// away; lin-compaction: lanes, paths); the
    /// data goes beside them as `{}` = data, .json.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Size in pixels, WIDTHxHEIGHT (default 960x540).
    #[arg(long)]
    pub chart_size: Option<String>,
}

/// Reads the data from `--from` or measures (and saves) it, reports it, and draws its charts.
fn chart_of<T: serde::Serialize + serde::de::DeserializeOwned>(
    out: &Out,
    names: &[&str],
    measure: impl FnOnce() -> Result<T, Box<dyn std::error::Error>>,
    report: impl Fn(&T),
    charts: impl Fn(&T) -> Vec<crate::chart::Scatter>,
) -> Result<(), Box<dyn std::error::Error>> {
    let size = parse_size(out.chart_size.as_deref())?;
    for name in names {
        crate::chart::Format::of(&named(&out.output, name, false)?)?;
    }
    let data: T = match &out.from {
        Some(f) => read_json(f)?,
        None => {
            let d = measure()?;
            save(&d, &out.output)?;
            d
        }
    };
    report(&data);
    for (c, name) in charts(&data).into_iter().zip(names) {
        write(&Chart::Scatter(c), &named(&out.output, name, false)?, size)?;
    }
    Ok(())
}

/// Options of `warplight chart lin-convergence`.
#[derive(Debug, clap::Args)]
pub struct ConvergenceArgs {
    /// A scene with a committed Mitsuba reference (scenes/ name or path).
    #[arg(long, default_value = "cornell-rough")]
    pub scene: String,
    /// The reference's files' prefix (PREFIX.exr, PREFIX-var.exr, PREFIX.json);
    /// default tests/fixtures/mitsuba/SCENE-32. The render takes its size.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Integrators, comma-separated.
    #[arg(long, default_value = "pt,nee,mis,mis-power,bdpt,mlt", value_delimiter = ',')]
    pub integrators: Vec<String>,
    /// How paths end, comma-separated: roulette (the thesis' Russian
    /// roulette), fixed-depth (every path runs to --bounces; the kernel's
    /// second build). A curve for each integrator and ending.
    #[arg(long, alias = "terminations", default_value = "roulette", value_delimiter = ',')]
    pub termination: Vec<String>,
    /// Native frames (4 samples a pixel each); points at 1, 2, 4, ... frames and the last.
    #[arg(long, default_value_t = 1024)]
    pub frames: u32,
    /// Emulated renders, in frames each, comma-separated (0: none).
    #[arg(long, default_value = "1,2,4", value_delimiter = ',')]
    pub emulated_frames: Vec<u32>,
    /// The longest path in bounces (the references': 16).
    #[arg(long, default_value_t = 16)]
    pub bounces: u32,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// The data and the charts.
    #[command(flatten)]
    pub out: Out,
}

/// Options of `warplight chart lin-pixel-sampling`.
#[derive(Debug, clap::Args)]
pub struct PixelSamplingArgs {
    /// The scene (scenes/ name or path).
    #[arg(long, default_value = "cornell-lambert")]
    pub scene: String,
    /// Pixel samplings, comma-separated: tent (the thesis'), stratified:D
    /// (D x D strata of a subpixel, row by row; stratified:1 is the box filter
    /// unstratified) and progressive:D (D a power of two: the strata in a
    /// scrambled order whose every 4^j frames stratify a 2^j x 2^j grid).
    #[arg(
        long,
        default_value = "tent,stratified:1,stratified:2,stratified:4,stratified:8,progressive:8",
        value_delimiter = ','
    )]
    pub pixels: Vec<String>,
    /// The integrator: pt, nee, mis, mis-power or bdpt.
    #[arg(long, default_value = "nee")]
    pub integrator: String,
    /// The longest path in bounces (0: the camera ray alone, the pixel integral).
    #[arg(long, default_value_t = 16)]
    pub bounces: u32,
    /// Image side in pixels.
    #[arg(long, default_value_t = 32)]
    pub size: u32,
    /// Frames of the measured run (4 samples a pixel each); points at 1, 2, 4, ... and the last.
    #[arg(long, default_value_t = 1024)]
    pub frames: u32,
    /// Frames of each sampling's reference, at least (rounded up to whole rounds of D²).
    #[arg(long, default_value_t = 8192)]
    pub reference_frames: u32,
    /// Frames of each build to emulate for its warp instructions (0: none).
    #[arg(long, default_value_t = 1)]
    pub emulated_frames: u32,
    /// Seed of the measured runs (the references': this plus a fixed offset).
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// The data and the charts.
    #[command(flatten)]
    pub out: Out,
}

/// Options of `warplight chart lin-compaction`.
#[derive(Debug, clap::Args)]
pub struct CompactionArgs {
    /// The scene (Fig. 17's: the Lambertian Cornell box).
    #[arg(long, default_value = "cornell-lambert")]
    pub scene: String,
    /// Image side in pixels (4 paths a pixel).
    #[arg(long, default_value_t = 32)]
    pub size: u32,
    /// Levels of the frame (the longest path depth − 1 bounces).
    #[arg(long, default_value_t = 30)]
    pub depth: u32,
    /// The data and the charts.
    #[command(flatten)]
    pub out: Out,
}

/// `out` with `{}` replaced by `name` (and, for the data, the extension .json).
fn named(out: &Path, name: &str, json: bool) -> Result<PathBuf, String> {
    let s = out.display().to_string();
    if !s.contains("{}") {
        return Err(format!("-o {s}: put {{}} in the name for each chart's name, e.g. lin-{{}}.svg"));
    }
    let p = PathBuf::from(s.replace("{}", name));
    Ok(if json { p.with_extension("json") } else { p })
}

fn read_json<T: serde::de::DeserializeOwned>(p: &Path) -> Result<T, String> {
    let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: not the chart data ({e})", p.display()))
}

fn save(data: &impl serde::Serialize, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let p = named(out, "data", true)?;
    let mut text = serde_json::to_string_pretty(data)?;
    text.push('\n');
    crate::cli::write_atomically(&p, text.as_bytes())?;
    eprintln!("wrote {}", p.display());
    Ok(())
}

/// The reference's prefix: as given, else tests/fixtures/mitsuba/SCENE-32 of the checkout.
fn reference_prefix(given: Option<&Path>, scene: &str) -> PathBuf {
    if let Some(p) = given {
        return p.to_path_buf();
    }
    Reference::default_prefix(scene)
}

/// Runs `chart lin-convergence`.
pub fn lin_convergence(a: ConvergenceArgs) -> Result<(), Box<dyn std::error::Error>> {
    let measure = || -> Result<Convergence, Box<dyn std::error::Error>> {
        let integrators = a
            .integrators
            .iter()
            .map(|s| {
                Integrator::parse(s)
                    .ok_or_else(|| format!("--integrators: unknown `{s}` (pt, nee, mis, mis-power, bdpt, mlt)"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let terminations = a
            .termination
            .iter()
            .map(|s| {
                Termination::parse(s).ok_or_else(|| format!("--termination: unknown `{s}` (roulette, fixed-depth)"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let scene = crate::host::scene_file::load(&crate::host::scene_file::resolve(&a.scene))?;
        let r = Reference::read(&reference_prefix(a.reference.as_deref(), &scene.name))?;
        let o = Options {
            integrators,
            terminations,
            frames: a.frames,
            emulated_frames: a.emulated_frames.iter().copied().filter(|&f| f > 0).collect(),
            bounces: a.bounces,
            seed: a.seed,
        };
        Ok(convergence::measure(&scene, &r, &o, &mut |s| eprintln!("{s}"))?)
    };
    chart_of(&a.out, &convergence::CHARTS, measure, report_convergence, Convergence::charts)
}

fn report_convergence(data: &Convergence) {
    for c in &data.curves {
        let last = c.native.last();
        println!(
            "{}: slope {} (from 16 spp, the reference's noise taken out); at {} spp RMSE {:.4e}, mean {:.2} %, {:.2} s; emulated = native: {}",
            c.label(),
            c.slope(16, data.reference_rmse).map_or("–".into(), |s| format!("{s:.3}")),
            last.map_or(0, |p| p.spp),
            last.map_or(f64::NAN, |p| p.rmse),
            last.map_or(f64::NAN, |p| 100.0 * p.rel_mean),
            last.map_or(f64::NAN, |p| p.seconds),
            c.emulated_equals_native
        );
        if let Some(v) = c.variance_seconds(data.reference_rmse) {
            println!("  error variance x seconds {v:.4e} (the reference's noise taken out; lower is more efficient)");
        }
        if let (Some(v), Some(s), Some(vs)) = (c.frame_variance, c.frame_seconds, c.frame_variance_seconds()) {
            println!("  one frame: variance {v:.4e} (over the frames), {s:.4e} s; their product {vs:.4e}");
        }
        for p in &c.emulated {
            let w = p.warp_instructions.unwrap_or(0);
            println!(
                "  emulated {} spp: {w} warp instructions, RMSE {:.4e}, {:.2} s; variance x warp instructions {:.4e}",
                p.spp,
                p.rmse,
                p.seconds,
                p.error_variance(data.reference_rmse) * w as f64
            );
        }
    }
    println!(
        "reference: {} spp, RMS standard error {:.4e}, mean luminance's relative standard error <= {:.3} %",
        data.reference_spp,
        data.reference_rmse,
        100.0 * data.reference_rel_mean
    );
}

/// Runs `chart lin-compaction`.
pub fn lin_compaction(a: CompactionArgs) -> Result<(), Box<dyn std::error::Error>> {
    let measure = || -> Result<Compaction, Box<dyn std::error::Error>> {
        let scene = crate::host::scene_file::load(&crate::host::scene_file::resolve(&a.scene))?;
        Ok(lanes::measure(&scene, a.size, a.depth).map_err(|e| e.to_string())?)
    };
    let report = |data: &Compaction| {
        for (n, c) in data.normal.iter().zip(&data.compact) {
            let pc = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.1} %"));
            println!(
                "level {}: active {}, useful lanes {} without, {} with compaction",
                n.level,
                c.active,
                pc(n.useful_percent()),
                pc(c.useful_percent())
            );
        }
    };
    chart_of(&a.out, &lanes::CHARTS, measure, report, Compaction::charts)
}

/// Runs `chart lin-pixel-sampling`.
pub fn lin_pixel_sampling(a: PixelSamplingArgs) -> Result<(), Box<dyn std::error::Error>> {
    let measure = || -> Result<PixelSamplingData, Box<dyn std::error::Error>> {
        let samplings = a
            .pixels
            .iter()
            .map(|s| PixelSampling::parse(s).map_err(|e| format!("--pixels: {e}")))
            .collect::<Result<Vec<_>, _>>()?;
        let integrator = Integrator::parse(&a.integrator)
            .ok_or_else(|| format!("--integrator: unknown `{}` (pt, nee, mis, mis-power, bdpt)", a.integrator))?;
        let scene = crate::host::scene_file::load(&crate::host::scene_file::resolve(&a.scene))?;
        let o = pixel_sampling::Options {
            samplings,
            integrator,
            bounces: a.bounces,
            size: a.size,
            frames: a.frames,
            reference_frames: a.reference_frames,
            emulated_frames: a.emulated_frames,
            seed: a.seed,
        };
        Ok(pixel_sampling::measure(&scene, &o, &mut |s| eprintln!("{s}"))?)
    };
    chart_of(&a.out, &pixel_sampling::CHARTS, measure, report_pixel_sampling, PixelSamplingData::charts)
}

fn report_pixel_sampling(data: &PixelSamplingData) {
    let tent = data.curve(PixelSampling::Tent);
    // c's error at p over the tent's at as many frames, by `error` (the whole image, or away from the lights)
    let vs_tent = |c: &pixel_sampling::Curve, p: &pixel_sampling::Point, error: fn(&_, &_) -> f64| {
        let t = tent.filter(|_| c.pixels != PixelSampling::Tent)?;
        t.at(p.frames).map(|q| error(c, p) / error(t, q))
    };
    for c in &data.curves {
        let last = c.native.last();
        let ratio = last
            .and_then(|p| vs_tent(c, p, pixel_sampling::Curve::error))
            .map_or(String::new(), |r| format!(", {r:.2} x the tent's error at as many samples"));
        println!(
            "{}: slope {} over whole rounds; at {} spp error {:.4e}{ratio}; reference {} frames, its noise {:.3e}; {:.3e} s a frame{}",
            c.pixels.label(),
            c.slope(1).map_or("–".into(), |s| format!("{s:.3}")),
            last.map_or(0, |p| p.spp),
            last.map_or(f64::NAN, |p| c.error(p)),
            c.reference_frames,
            c.reference_rmse,
            c.frame_seconds,
            match (c.warp_instructions_per_frame, c.emulated_equals_native) {
                (Some(w), Some(same)) => format!("; emulated {w:.0} warp instructions a frame (= native: {same})"),
                _ => String::new(),
            }
        );
        if let Some(p) = last {
            let ratio = vs_tent(c, p, pixel_sampling::Curve::error_away)
                .map_or(String::new(), |r| format!(", {r:.2} x the tent's"));
            println!(
                "  over the {} pixels away from the lights' silhouettes: error {:.4e}{ratio}; reference noise {:.3e}",
                data.away_pixels,
                c.error_away(p),
                c.reference_rmse_away
            );
        }
        let partial: Vec<String> = c
            .native
            .iter()
            .filter(|p| !p.whole_rounds)
            .map(|p| format!("{} frames {:.3e}", p.frames, c.error(p)))
            .collect();
        if !partial.is_empty() {
            let fair = if c.pixels.fair(1) {
                " (fair images: the progressive order)"
            } else {
                " (biased: the strata seen cover the top of each subpixel)"
            };
            println!("  inside a round of {} frames{fair}: {}", c.pixels.round(), partial.join(", "));
        }
    }
    let strata = data.one_per_stratum();
    if strata.len() >= 2 {
        let pts: Vec<String> = strata.iter().map(|(s, e)| format!("{s} spp {e:.3e}")).collect();
        println!(
            "one sample a stratum (D² frames): {}; slope {} (O(1/n) is -1, O(1/sqrt n) -0.5)",
            pts.join(", "),
            data.one_per_stratum_slope().map_or("–".into(), |s| format!("{s:.3}"))
        );
    }
    for (pixels, g, e) in data.progressive_levels() {
        let rowwise = data
            .curve(PixelSampling::Stratified(g))
            .and_then(|c| c.at(g * g).map(|p| c.error(p)))
            .map_or(String::new(), |r| format!(", {:.2} x stratified {g}x{g}'s at as many frames", e / r));
        println!("{} at {} frames (one ray a cell of {g}x{g}): error {e:.3e}{rowwise}", pixels.label(), g * g);
    }
}
