//! Image error against a converged reference (issue 14, item 8): the
//! emulated renders of a scene at a ladder of photon counts on both maps,
//! each against a reference render with many more photons (the bitonic map,
//! which loses no photon), and the progressive display of the stated count
//! against the same reference pass by pass.
//!
//! - *Error against photons*: the relative RMS error of each map's final
//!   image against the reference, over the photons stored.
//! - *Error against time*: the relative RMS error of the running image after
//!   each radiance-estimate pass, over the thread instructions the emulator
//!   counted for building the map and the estimate up to that pass (a
//!   counted proxy of GPU time: the paper's kernels are compute-bound,
//!   004:L188; not seconds).
//!
//! The reference is the same estimator (the same k and r_max) with more
//! photons, so it carries the kNN estimate's own bias at that count; the
//! charts show how far each render is from it, not from the exact radiance.

use super::image::{self, Rendered};
use super::native::MapData;
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

/// The two charts of one scene.
#[derive(Debug, Clone)]
pub struct ErrorCharts {
    /// Error of the final images against photons stored, per map.
    pub photons: Scatter,
    /// Error of the running image against counted instructions, per map, at `f`'s photons.
    pub time: Scatter,
    /// Photons the reference stored.
    pub reference_stored: usize,
}

/// Renders `scene` `width` pixels wide at `factors` × `f`'s stated photons
/// (1.0 among them: the time chart's run) and the reference at
/// `reference_factor` × them, and measures both charts. `progress` hears
/// each render as it starts (its factor).
pub fn charts(
    scene: &Scene,
    f: &Fixture,
    width: u32,
    factors: &[f64],
    reference_factor: f64,
    progress: &mut dyn FnMut(f64),
) -> Result<ErrorCharts, MeasureError> {
    progress(reference_factor);
    let reference = image::render(scene, &with_photons(f, reference_factor), width)?;
    let want = image::images(&reference)[0].clone();
    let mut photon_series = [Vec::new(), Vec::new()];
    let mut time_series = [Vec::new(), Vec::new()];
    for &factor in factors {
        progress(factor);
        let timed = factor == 1.0;
        let r = image::render_with(scene, &with_photons(f, factor), width, timed)?;
        let n = stored(&r) as f64;
        for (m, img) in image::images(&r).iter().enumerate() {
            photon_series[m].push((n, rel_rmse(img, &want)));
        }
        if timed {
            for (m, series) in time_series.iter_mut().enumerate() {
                let build = r.build_instructions[m] as f64;
                for (frame, &inst) in r.progress[m].iter().zip(&r.estimate_instructions[m]) {
                    series.push((build + inst as f64, rel_rmse(frame, &want)));
                }
            }
        }
    }
    let series = |s: [Vec<(f64, f64)>; 2]| {
        let [a, b] = s;
        vec![Series { name: "bitonic map".into(), points: a }, Series { name: "stencil map".into(), points: b }]
    };
    let reference_stored = stored(&reference);
    let what = format!("against the bitonic map with {reference_stored} photons");
    Ok(ErrorCharts {
        photons: Scatter {
            title: format!("{}: error of the final image {what}", scene.name),
            x_label: "photons stored".into(),
            y_label: "relative RMS error".into(),
            log_x: true,
            log_y: true,
            connect: true,
            series: series(photon_series),
        },
        time: Scatter {
            title: format!("{}: progressive display at {} stored photons, error {what}", scene.name, f.stated_photons),
            x_label: "thread instructions, map build + estimate so far (counted, not seconds)".into(),
            y_label: "relative RMS error".into(),
            log_x: true,
            log_y: true,
            connect: true,
            series: series(time_series),
        },
        reference_stored,
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
