//! Image error against a converged reference (issue 14, item 8): the
//! emulated renders of a scene at a ladder of photon counts on both maps,
//! each against a native reference with many more photons and a larger k
//! ([`super::reference`]), and the progressive display of the stated count
//! against the same reference pass by pass.
//!
//! - *Error against photons*: the relative RMS error of each map's final
//!   image against the reference, over the photons stored.
//! - *Error against time*: the relative RMS error of the running image after
//!   each radiance-estimate pass, over the thread instructions the emulator
//!   counted for building the map and the estimate up to that pass (a
//!   counted proxy of GPU time: the paper's kernels are compute-bound,
//!   004:L188; not seconds).
//! - *Error against passes*: the same running images over the pass number,
//!   the paper's full against visual convergence (004:L182).
//!
//! Every image has the same direct light (the same shadow rays), the
//! reference's bit for bit: the error is the photon map's estimate's. The
//! reference's own error is measured by a second reference with other
//! photons ([`ErrorCharts::reference_noise`]) and by one with a quarter of
//! its photons and half its k ([`ErrorCharts::reference_step`]).

use serde::Serialize;

use super::image::{self, Rendered};
use super::native::MapData;
use super::photons::Geometry;
use super::reference::{self, REFERENCE_SEED, SECOND_SEED};
use super::scenes::Fixture;
use crate::chart::{Scatter, Series};
use crate::host::image::FrameBuffer;
use crate::host::scene::Scene;
use crate::repro::registry::MeasureError;

/// Relative RMS error of `a` against `b` over the three channels:
/// sqrt(Σ (a − b)²) / sqrt(Σ b²) (0 where `b` is black and `a` equals it).
pub fn rel_rmse(a: &FrameBuffer, b: &FrameBuffer) -> f64 {
    let mut err = 0.0;
    let mut norm = 0.0;
    for (x, y) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            err += (x[c] as f64 - y[c] as f64).powi(2);
            norm += (y[c] as f64).powi(2);
        }
    }
    if norm == 0.0 { if err == 0.0 { 0.0 } else { f64::INFINITY } } else { (err / norm).sqrt() }
}

/// Photons stored in a render's photon arrays (valid slots of the bounce frames).
pub fn stored(r: &Rendered) -> usize {
    match &r.maps[0] {
        MapData::Bitonic { pos, .. } => pos.iter().filter(|p| p[3] != 0.0).count(),
        MapData::Stencil { stored, .. } => stored.iter().map(|&s| s as usize).sum(),
    }
}

/// `f` with `factor` times its stated photons (the other settings kept).
pub fn with_photons(f: &Fixture, factor: f64) -> Fixture {
    Fixture { stated_photons: ((f.stated_photons as f64 * factor).round() as u32).max(1), ..*f }
}

/// The reference's settings, as multiples of the fixture's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReferenceSpec {
    /// Stored photons, times the stated count.
    pub photons: f64,
    /// Photons sought, times the stated k.
    pub k: f64,
}

/// The pass from which a progressive display stays within 1 % (relative) of
/// its final error against the reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Settling {
    /// The map: 0 bitonic, 1 stencil.
    pub map: usize,
    /// Passes of the estimate.
    pub passes: usize,
    /// The final image's relative RMS error against the reference.
    pub final_error: f64,
    /// First pass (from 1) from which every later error is within 1 % of the final one.
    pub within_1_percent: usize,
    /// Its error at pass `passes / 4` (a quarter of the way).
    pub error_at_quarter: f64,
}

/// The charts of one scene and the numbers beside them.
#[derive(Debug, Clone)]
pub struct ErrorCharts {
    /// Error of the final images against photons stored, per map.
    pub photons: Scatter,
    /// Error of the running image against counted instructions, per map, at `f`'s photons.
    pub time: Scatter,
    /// Error of the running image against passes, per map, at `f`'s photons.
    pub passes: Scatter,
    /// The reference's settings.
    pub spec: ReferenceSpec,
    /// Photons the reference emitted and stored, and its k.
    pub reference: (usize, usize, u32),
    /// Relative RMS error between the reference and a second one with other photons.
    pub reference_noise: f64,
    /// Relative RMS error of a reference with a quarter of the photons and half the k against the reference.
    pub reference_step: f64,
    /// The norm of the reference's estimate (the reference less the direct
    /// light) over the reference image's: the largest error an image with
    /// the right direct light and no estimate at all could have.
    pub indirect_share: f64,
    /// The progressive display's settling on each map.
    pub settling: [Settling; 2],
}

fn settling(map: usize, errors: &[f64]) -> Settling {
    let last = errors.last().copied().unwrap_or(f64::NAN);
    let within = errors.iter().rposition(|e| (e - last).abs() > 0.01 * last).map_or(1, |i| i + 2);
    Settling {
        map,
        passes: errors.len(),
        final_error: last,
        within_1_percent: within.min(errors.len()),
        error_at_quarter: errors.get((errors.len() / 4).max(1) - 1).copied().unwrap_or(f64::NAN),
    }
}

/// Renders `scene` `width` pixels wide on the emulator at `factors` × `f`'s
/// stated photons (1.0 among them: the time chart's run) and natively the
/// reference `spec`, and measures the charts. The emulated renders run on a
/// device whose settings `set` adjusts (profile, FMA contraction, fidelity:
/// [`image::render_configured`]). `progress` hears each step as it starts.
pub fn charts(
    scene: &Scene,
    f: &Fixture,
    width: u32,
    (factors, spec): (&[f64], ReferenceSpec),
    set: &dyn Fn(&mut crate::sim::SimConfig),
    progress: &mut dyn FnMut(&str),
) -> Result<ErrorCharts, MeasureError> {
    let geo = Geometry::of(scene);
    let k_ref = ((f.k as f64 * spec.k).round() as u32).max(1);
    let stated_ref = with_photons(f, spec.photons).stated_photons;
    progress("reference: calibration");
    let emitted = reference::emitted(&geo, f, stated_ref);
    progress(&format!("reference: {emitted} photons emitted, k = {k_ref}"));
    let refr = reference::render(scene, f, width, emitted, k_ref, REFERENCE_SEED);
    let want = refr.image.clone();
    progress("second reference (other photons)");
    let second = reference::render(scene, f, width, emitted, k_ref, SECOND_SEED);
    let reference_noise = rel_rmse(&second.image, &want);
    progress("coarser reference (a quarter of the photons, half the k)");
    let coarse = reference::render(scene, f, width, emitted.div_ceil(4), (k_ref / 2).max(1), SECOND_SEED);
    let reference_step = rel_rmse(&coarse.image, &want);
    let mut photon_series = [Vec::new(), Vec::new()];
    let mut time_series = [Vec::new(), Vec::new()];
    let mut pass_series = [Vec::new(), Vec::new()];
    let mut indirect_share = f64::NAN;
    for &factor in factors {
        progress(&format!("emulated render at {factor} x the stated photons"));
        let timed = factor == 1.0;
        let r = image::render_configured(scene, &with_photons(f, factor), width, timed, set)?;
        let n = stored(&r) as f64;
        for (m, img) in image::images(&r).iter().enumerate() {
            photon_series[m].push((n, rel_rmse(img, &want)));
        }
        if timed {
            let [w, h] = r.camera.resolution;
            let direct =
                FrameBuffer { width: w, height: h, pixels: r.direct.iter().map(|d| [d[0], d[1], d[2]]).collect() };
            indirect_share = rel_rmse(&direct, &want);
            for m in 0..2 {
                let build = r.build_instructions[m] as f64;
                for (i, (frame, &inst)) in r.progress[m].iter().zip(&r.estimate_instructions[m]).enumerate() {
                    let e = rel_rmse(frame, &want);
                    time_series[m].push((build + inst as f64, e));
                    pass_series[m].push(((i + 1) as f64, e));
                }
            }
        }
    }
    let settle = [0, 1].map(|m| settling(m, &pass_series[m].iter().map(|p| p.1).collect::<Vec<_>>()));
    let series = |s: [Vec<(f64, f64)>; 2]| {
        let [a, b] = s;
        vec![Series { name: "bitonic map".into(), points: a }, Series { name: "stencil map".into(), points: b }]
    };
    let what = format!("against a native reference ({} photons, k = {k_ref})", refr.stored);
    let scatter = |title: String, x_label: &str, log_x: bool, s| Scatter {
        title,
        x_label: x_label.into(),
        y_label: "relative RMS error".into(),
        log_x,
        log_y: true,
        connect: true,
        series: series(s),
    };
    Ok(ErrorCharts {
        photons: scatter(
            format!("{}: error of the final image {what}", scene.name),
            "photons stored",
            true,
            photon_series,
        ),
        time: scatter(
            format!("{}: progressive display at {} photons, error {what}", scene.name, f.stated_photons),
            "thread instructions, map build + estimate so far (counted, not seconds)",
            true,
            time_series,
        ),
        passes: scatter(
            format!("{}: full vs visual convergence (004:L182), error {what}", scene.name),
            "radiance-estimate passes",
            false,
            pass_series,
        ),
        spec,
        reference: (refr.emitted, refr.stored, k_ref),
        reference_noise,
        reference_step,
        indirect_share,
        settling: settle,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fb(p: &[[f32; 3]]) -> FrameBuffer {
        FrameBuffer { width: p.len() as u32, height: 1, pixels: p.to_vec() }
    }

    #[test]
    fn relative_rms_error_by_hand() {
        let b = fb(&[[3.0, 0.0, 0.0], [0.0, 4.0, 0.0]]);
        assert_eq!(rel_rmse(&b, &b), 0.0);
        // error (1, 0, 0) against a norm of 5
        let a = fb(&[[4.0, 0.0, 0.0], [0.0, 4.0, 0.0]]);
        assert!((rel_rmse(&a, &b) - 0.2).abs() < 1e-12);
        let black = fb(&[[0.0; 3]]);
        assert_eq!(rel_rmse(&black, &black), 0.0);
        assert_eq!(rel_rmse(&fb(&[[1.0, 0.0, 0.0]]), &black), f64::INFINITY);
    }
}
