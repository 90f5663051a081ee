//! Stratified pixels against the tent filter (§4.2, 003:L221-230; extract
//! A.10): `warplight chart lin-pixel-sampling`.
//!
//! The thesis claims that stratifying a pixel into D x D strata "reduces the
//! error of estimation from O(1/√n) to O(1/n)" (003:L223), that smallpt's
//! tent filter "produces same image quality given same sampling number as
//! stratified sampling does" (003:L225), and that stratification cannot
//! refine successively, needing D² samples as a unit (003:L223). Each
//! sampling is rendered natively by its own build's twin (the tent filter:
//! the thesis' `path.ptx`; strata: `path_stratified.ptx`, frame f in stratum
//! f mod D² row by row, or in the progressive order that answers the
//! successive-refinement objection, [`PixelSampling::Progressive`]):
//!
//! - *Its own reference.* The filters converge to different images (the tent
//!   spans two subpixels, a stratum's box one), so each curve is measured
//!   against a long render of its own sampling with other random numbers
//!   (`reference_seed`), in whole rounds of D² frames. The reference's own
//!   noise (the RMS standard error of its mean, from the spread of its
//!   rounds, each an independent estimate) is taken out of each error:
//!   √(rmse² − floor²).
//! - *Points* at 1, 2, 4, ... frames and the last; a point ends inside a
//!   round when its frames are not a multiple of D² (then the strata seen so
//!   far cover only the top of each subpixel under the row order: the
//!   successive-refinement problem the thesis names; the progressive order's
//!   are fair, and [`PixelSamplingData::progressive_levels`] sets its points
//!   at 4^j frames beside the row order's one sample a stratum).
//! - *One sample a stratum*: the point of each D at exactly D² frames, the
//!   regime of the O(1/n) claim (n = D² samples a subpixel, D growing).
//! - *Cost*: native seconds a frame (measured), and the warp instructions of
//!   an emulated frame of each build (counted), with the emulated image
//!   checked to equal the native twin's bit for bit.
//!
//! Two scenes separate what stratifying two of a path's dimensions can do:
//! at 0 bounces under an environment map (`env-spheres`) the estimate is the
//! pixel integral alone; on the Cornell box at 16 bounces the path's other
//! dimensions carry most of the variance.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::chart::{Scatter, Series};
use crate::host::camera::Camera;
use crate::host::path::layout::{LayoutError, PathScene};
use crate::host::path::native::Tracer;
use crate::host::path::{
    FrameParams, FrameParamsError, Integrator, PixelSampling, Progressive, SAMPLES_PER_FRAME, eps_for, frame_of,
};
use crate::host::scene::Scene;
use crate::repro::lin2017::convergence::checkpoints;
use crate::repro::lin2017::runs;

/// The seed of a curve's reference: the measured run's plus this (other random numbers).
pub const REFERENCE_SEED_OFFSET: u32 = 0x9e37_79b9;

/// The charts' names (`{}` in `warplight chart lin-pixel-sampling -o`).
pub const CHARTS: [&str; 3] = ["spp", "seconds", "away"];

/// Why the comparison cannot be measured.
#[derive(Debug, thiserror::Error)]
pub enum PixelSamplingChartError {
    /// Settings that give no curve.
    #[error("{0}")]
    Settings(String),
    /// The scene's layout refused it.
    #[error(transparent)]
    Layout(#[from] LayoutError),
    /// The path tracer refused the settings.
    #[error(transparent)]
    Params(#[from] FrameParamsError),
    /// The emulated or the native render failed.
    #[error(transparent)]
    Twin(#[from] runs::TwinError),
}

/// What to measure.
#[derive(Debug, Clone)]
pub struct Options {
    /// The samplings, a curve each.
    pub samplings: Vec<PixelSampling>,
    /// The integrator (pt, nee, mis, mis-power or bdpt).
    pub integrator: Integrator,
    /// The longest path in bounces (0: the camera ray alone).
    pub bounces: u32,
    /// Image side in pixels.
    pub size: u32,
    /// The measured run's frames (4 samples a pixel each).
    pub frames: u32,
    /// Each reference's frames, at least; rounded up to whole rounds of D².
    pub reference_frames: u32,
    /// Frames of each build to emulate (0: none).
    pub emulated_frames: u32,
    /// Seed of the measured runs.
    pub seed: u32,
}

/// One running image's error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// Frames in it.
    pub frames: u32,
    /// Samples a pixel.
    pub spp: u32,
    /// RMS difference from the curve's reference, over pixels and channels.
    pub rmse: f64,
    /// The same over the pixels away from the lights' silhouettes
    /// ([`PixelSamplingData::away_pixels`]; every pixel when no light is seen).
    #[serde(default)]
    pub rmse_away: f64,
    /// Native seconds from the run's start to this frame's end (measured).
    pub seconds: f64,
    /// Whether its frames are whole rounds (a multiple of D²).
    pub whole_rounds: bool,
}

/// One sampling's curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    /// The sampling.
    pub pixels: PixelSampling,
    /// Its reference's frames (whole rounds).
    pub reference_frames: u32,
    /// Its reference's own noise: the RMS over pixels and channels of the
    /// standard error of its mean, from the spread of its rounds.
    pub reference_rmse: f64,
    /// The same over the pixels away from the lights' silhouettes.
    #[serde(default)]
    pub reference_rmse_away: f64,
    /// The measured run's points.
    pub native: Vec<Point>,
    /// Native seconds a frame (the measured run's).
    pub frame_seconds: f64,
    /// Warp instructions an emulated frame of its build took (counted; None: not emulated).
    pub warp_instructions_per_frame: Option<f64>,
    /// Whether the emulated frames equal the native twin's bit for bit (None: not emulated).
    pub emulated_equals_native: Option<bool>,
}

impl Curve {
    /// A point's error with the reference's noise taken out: √(rmse² − floor²), at least 0
    /// ([`runs::above_floor`]).
    pub fn error(&self, p: &Point) -> f64 {
        runs::above_floor(p.rmse, self.reference_rmse)
    }

    /// The same away from the lights' silhouettes.
    pub fn error_away(&self, p: &Point) -> f64 {
        runs::above_floor(p.rmse_away, self.reference_rmse_away)
    }

    /// The least-squares slope of log error against log spp over the points
    /// of whole rounds (frames ≥ D²) from `from_frames` on; −1/2 for
    /// independent samples.
    pub fn slope(&self, from_frames: u32) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .native
            .iter()
            .filter(|p| p.whole_rounds && p.frames >= from_frames.max(self.pixels.round()) && self.error(p) > 0.0)
            .map(|p| ((p.spp as f64).ln(), self.error(p).ln()))
            .collect();
        runs::fit_slope(&pts)
    }

    /// The point at `frames`.
    pub fn at(&self, frames: u32) -> Option<&Point> {
        self.native.iter().find(|p| p.frames == frames)
    }
}

/// The chart data (`docs/images/lin-pixels-*-data.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PixelSamplingData {
    /// The scene's name.
    pub scene: String,
    /// Image side in pixels.
    pub size: u32,
    /// The integrator.
    pub integrator: String,
    /// The longest path in bounces.
    pub bounces: u32,
    /// Seed of the measured runs.
    pub seed: u32,
    /// Seed of the references.
    pub reference_seed: u32,
    /// Threads the native renders ran on (rayon).
    pub native_threads: usize,
    /// Pixels away from the lights' silhouettes: none of the 3 x 3 pixels
    /// around them has its centre's camera ray hit an emitter first.
    #[serde(default)]
    pub away_pixels: usize,
    /// A curve per sampling.
    pub curves: Vec<Curve>,
}

impl PixelSamplingData {
    /// The curve of `pixels`.
    pub fn curve(&self, pixels: PixelSampling) -> Option<&Curve> {
        self.curves.iter().find(|c| c.pixels == pixels)
    }

    /// One sample a stratum: (spp, error) of each stratified curve at
    /// exactly D² frames, D ascending.
    pub fn one_per_stratum(&self) -> Vec<(f64, f64)> {
        let mut v: Vec<(u32, f64, f64)> = self
            .curves
            .iter()
            .filter_map(|c| match c.pixels {
                PixelSampling::Stratified(d) => c.at(d * d).map(|p| (d, p.spp as f64, c.error(p))),
                PixelSampling::Tent | PixelSampling::Progressive(_) => None,
            })
            .filter(|p| p.2 > 0.0)
            .collect();
        v.sort_by_key(|p| p.0);
        v.into_iter().map(|(_, s, e)| (s, e)).collect()
    }

    /// The progressive curves' points at 4^j frames, j = 0, 1, ... up to
    /// D² (the frames that stratify a 2^j x 2^j grid): (curve, d = 2^j,
    /// error), to set beside [`PixelSamplingData::one_per_stratum`]'s
    /// stratified:d at d² frames.
    pub fn progressive_levels(&self) -> Vec<(PixelSampling, u32, f64)> {
        let mut v = Vec::new();
        for c in &self.curves {
            if let PixelSampling::Progressive(d) = c.pixels {
                let mut g = 1;
                while g <= d {
                    if let Some(p) = c.at(g * g) {
                        v.push((c.pixels, g, c.error(p)));
                    }
                    g *= 2;
                }
            }
        }
        v
    }

    /// The slope of [`PixelSamplingData::one_per_stratum`] in log-log: −1 if the error is O(1/n).
    pub fn one_per_stratum_slope(&self) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self.one_per_stratum().into_iter().map(|(s, e)| (s.ln(), e.ln())).collect();
        runs::fit_slope(&pts)
    }

    /// The charts, in [`CHARTS`]' order: the error (the reference's noise
    /// taken out) against samples a pixel, with the one-sample-a-stratum
    /// points as their own series, and against native seconds.
    pub fn charts(&self) -> Vec<Scatter> {
        let head =
            format!("{} ({}x{}, {}, {} bounces)", self.scene, self.size, self.size, self.integrator, self.bounces);
        let series = |x: &dyn Fn(&Point) -> f64, y: &dyn Fn(&Curve, &Point) -> f64| -> Vec<Series> {
            self.curves
                .iter()
                .map(|c| Series {
                    name: c.pixels.label(),
                    points: c.native.iter().map(|p| (x(p), y(c, p))).filter(|p| p.0 > 0.0 && p.1 > 0.0).collect(),
                })
                .filter(|s| !s.points.is_empty())
                .collect()
        };
        let mut spp = series(&|p| p.spp as f64, &Curve::error);
        let strata = self.one_per_stratum();
        if strata.len() >= 2 {
            spp.push(Series { name: "one sample a stratum (D² frames)".into(), points: strata });
        }
        let secs = series(&|p| p.seconds, &Curve::error);
        let away = series(&|p| p.spp as f64, &Curve::error_away);
        let scatter = |title: String, x_label: &str, series| Scatter {
            title,
            x_label: x_label.into(),
            y_label: "RMS error, its reference's noise taken out".into(),
            log_x: true,
            log_y: true,
            connect: true,
            series,
        };
        vec![
            scatter(
                format!("{head}: stratified pixels vs the tent filter, error vs samples (native; measured)"),
                "samples per pixel",
                spp,
            ),
            scatter(
                format!("{head}: stratified pixels vs the tent filter, error vs time (native host seconds; measured)"),
                "seconds (native, this machine)",
                secs,
            ),
            scatter(
                format!(
                    "{head}: error vs samples over the {} pixels away from the lights' silhouettes (native; measured)",
                    self.away_pixels
                ),
                "samples per pixel",
                away,
            ),
        ]
    }
}

/// Frames of `tracer` from 0 to `frames`, streamed: the running mean at
/// each of `marks` (per pixel and channel) with the seconds it took, and
/// the variance of the mean from the spread of whole rounds of `round`
/// frames (None below two rounds).
struct Stream {
    means: Vec<(u32, Vec<f64>, f64)>,
    var_of_mean: Option<Vec<f64>>,
}

fn stream(tracer: &Tracer, frames: u32, marks: &[u32], round: u32) -> Stream {
    let (w, h) = (tracer.params.width, tracer.params.height);
    let mut accum = vec![0.0f32; tracer.params.paths() * 3];
    let mut last = accum.clone();
    let cells = (w * h * 3) as usize;
    let (mut sum, mut in_round) = (vec![0.0f64; cells], vec![0.0f64; cells]);
    let (mut rounds_sum, mut rounds_sq) = (vec![0.0f64; cells], vec![0.0f64; cells]);
    let mut means = Vec::new();
    let t0 = Instant::now();
    for f in 0..frames {
        tracer.frame(f, &mut accum, &mut last);
        let img = Progressive::pixels_of(w, h, &last);
        for (c, v) in img.pixels.iter().flatten().enumerate() {
            sum[c] += *v as f64;
            in_round[c] += *v as f64;
        }
        let n = f + 1;
        if n % round == 0 {
            for c in 0..cells {
                let m = in_round[c] / round as f64;
                rounds_sum[c] += m;
                rounds_sq[c] += m * m;
                in_round[c] = 0.0;
            }
        }
        if marks.contains(&n) {
            means.push((n, sum.iter().map(|s| s / n as f64).collect(), t0.elapsed().as_secs_f64()));
        }
    }
    let rounds = (frames / round) as f64;
    let var_of_mean = (rounds >= 2.0).then(|| {
        rounds_sum
            .iter()
            .zip(&rounds_sq)
            .map(|(s, q)| ((q - s * s / rounds) / (rounds - 1.0)).max(0.0) / rounds)
            .collect()
    });
    Stream { means, var_of_mean }
}

/// Renders `scene` with each sampling of `o` and measures its curve
/// against its own reference; `progress` hears each step.
pub fn measure(
    scene: &Scene,
    o: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<PixelSamplingData, PixelSamplingChartError> {
    if o.samplings.is_empty() || o.frames == 0 || o.size == 0 || o.reference_frames == 0 {
        return Err(PixelSamplingChartError::Settings(
            "expected at least one sampling, a positive image size, frame count and reference frame count".into(),
        ));
    }
    if o.integrator == Integrator::Mlt {
        return Err(PixelSamplingChartError::Settings(
            "mlt takes its camera sample from its chain, never a stratum: chart pt, nee, mis, mis-power or bdpt".into(),
        ));
    }
    let ps: PathScene = runs::path_scene(scene)?;
    ps.check_integrator(&scene.name, o.integrator)?;
    let camera = Camera { resolution: [o.size, o.size], ..scene.camera };
    let frame = frame_of(&camera, eps_for(ps.lo, ps.hi));
    let away = away_from_lights(scene, &camera);
    let cells_away: Vec<bool> = away.iter().flat_map(|&a| [a; 3]).collect();
    let marks = checkpoints(o.frames);
    let reference_seed = o.seed.wrapping_add(REFERENCE_SEED_OFFSET);
    let mut curves = Vec::new();
    for &pixels in &o.samplings {
        let params = FrameParams { pixels, ..FrameParams::new(o.size, o.size, o.integrator, o.bounces, o.seed) };
        params.check()?;
        let round = pixels.round();
        let reference_frames = o.reference_frames.div_ceil(round).max(2) * round;
        progress(&format!("{}: reference, {reference_frames} native frames", pixels.label()));
        let ref_params = FrameParams { seed: reference_seed, ..params };
        let r = stream(&Tracer { scene: &ps, frame, params: ref_params }, reference_frames, &[reference_frames], round);
        let ref_mean = &r.means[0].1;
        let var = r.var_of_mean.unwrap_or_default();
        let reference_rmse = masked_mean(&var, &cells_away, false).sqrt();
        let reference_rmse_away = masked_mean(&var, &cells_away, true).sqrt();
        progress(&format!("{}: {} native frames", pixels.label(), o.frames));
        let run = stream(&Tracer { scene: &ps, frame, params }, o.frames, &marks, round);
        let native: Vec<Point> = run
            .means
            .iter()
            .map(|(n, mean, seconds)| {
                let sq: Vec<f64> = mean.iter().zip(ref_mean).map(|(a, b)| (a - b).powi(2)).collect();
                Point {
                    frames: *n,
                    spp: n * SAMPLES_PER_FRAME,
                    rmse: masked_mean(&sq, &cells_away, false).sqrt(),
                    rmse_away: masked_mean(&sq, &cells_away, true).sqrt(),
                    seconds: *seconds,
                    whole_rounds: n % round == 0,
                }
            })
            .collect();
        let frame_seconds = native.last().map_or(0.0, |p| p.seconds / p.frames as f64);
        let (mut warp, mut same) = (None, None);
        if o.emulated_frames > 0 {
            progress(&format!("{}: {} emulated frame(s)", pixels.label(), o.emulated_frames));
            let t = runs::emulate_twin(&ps, &camera, params, o.emulated_frames)?;
            warp = Some(t.emulated.totals.warp_instructions as f64 / o.emulated_frames as f64);
            same = Some(t.same);
        }
        curves.push(Curve {
            pixels,
            reference_frames,
            reference_rmse,
            reference_rmse_away,
            native,
            frame_seconds,
            warp_instructions_per_frame: warp,
            emulated_equals_native: same,
        });
    }
    Ok(PixelSamplingData {
        scene: scene.name.clone(),
        size: o.size,
        integrator: o.integrator.name().into(),
        bounces: o.bounces,
        seed: o.seed,
        reference_seed,
        native_threads: rayon::current_num_threads(),
        away_pixels: away.iter().filter(|&&a| a).count(),
        curves,
    })
}

/// The mean of `v` over every cell (`only` false) or over the cells where `mask` holds (0 over none).
fn masked_mean(v: &[f64], mask: &[bool], only: bool) -> f64 {
    let (s, n) = v.iter().zip(mask).filter(|(_, m)| **m || !only).fold((0.0, 0usize), |(s, n), (x, _)| (s + x, n + 1));
    if n == 0 { 0.0 } else { s / n as f64 }
}

/// Per pixel of `camera`: whether none of the 3 x 3 pixels around it (itself
/// included) has its centre's camera ray hit an emitting material first, so
/// that its footprint holds no light's silhouette.
pub fn away_from_lights(scene: &Scene, camera: &Camera) -> Vec<bool> {
    let hits = runs::first_hit_materials(scene, camera, &runs::sah_tree(scene));
    let emits = |name: Option<&str>| {
        name.and_then(|n| scene.materials.iter().find(|m| m.name == n))
            .is_some_and(|m| m.emission.iter().any(|&e| e > 0.0))
    };
    let lit: Vec<bool> = hits.into_iter().map(emits).collect();
    let [w, h] = camera.resolution.map(|v| v as i64);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            !(-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u) && (0..h).contains(&v) && lit[(v * w + u) as usize]
                })
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference's noise comes out of the error; the slope reads only
    /// whole rounds from D² frames on.
    #[test]
    fn a_curves_error_and_slope() {
        let point = |frames: u32, rmse: f64| Point {
            frames,
            spp: 4 * frames,
            rmse,
            rmse_away: rmse,
            seconds: 1.0,
            whole_rounds: frames.is_multiple_of(4),
        };
        let c = Curve {
            pixels: PixelSampling::Stratified(2),
            reference_frames: 64,
            reference_rmse: 3.0,
            reference_rmse_away: 3.0,
            // errors 4 (rmse 5), 2, 1 at 4, 16, 64 frames: slope -1/2; frames 2 ends inside a round
            native: vec![point(2, 100.0), point(4, 5.0), point(16, 13f64.sqrt()), point(64, 10f64.sqrt())],
            frame_seconds: 0.1,
            warp_instructions_per_frame: None,
            emulated_equals_native: None,
        };
        assert_eq!(c.error(&c.native[1]), 4.0);
        assert_eq!(c.error(&point(1, 1.0)), 0.0, "below the floor");
        assert!((c.slope(1).unwrap() + 0.5).abs() < 1e-12, "{:?}", c.slope(1));
    }
}
