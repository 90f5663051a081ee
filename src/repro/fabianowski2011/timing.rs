//! A GT200 timing model for the frame-rate tables 4.6 and 4.10 (thesis 000,
//! L1902–1912, L2146–2157): frame time = a · (warp instructions) + b · (memory
//! transactions), per frame at 512 × 512. The two costs are fitted by least
//! squares to the thesis' stack-based frame rates only (the baseline column),
//! then the model predicts every other column.
//!
//! What it stands for: the GTX 280 issues one warp instruction per SM per
//! ~4 cycles (8 SPs), so instructions cost time in proportion; memory
//! transactions whose latency the resident warps cannot hide add a cost per
//! transaction. Both coefficients absorb everything else (clock, occupancy,
//! SASS versus PTX counts).

use super::flight::SceneRun;

/// The fitted model.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Fit {
    /// Seconds per warp instruction (per 512 × 512 frame).
    pub per_instruction: f64,
    /// Seconds per memory transaction.
    pub per_transaction: f64,
    /// Relative error of the fitted baseline frame rates, root mean square.
    pub baseline_rms_error: f64,
}

/// Per-frame counts at 512 × 512 of variant `i` of a run (scaled from the run's resolution).
fn per_frame(r: &SceneRun, i: usize) -> (f64, f64) {
    let scale = (512.0 / r.resolution as f64).powi(2) / r.frames.max(1) as f64;
    let t = &r.totals[i];
    (t.warp_instructions as f64 * scale, t.mem_transactions as f64 * scale)
}

/// Fits a, b ≥ 0 to the baselines' frame rates (column 0 of each run with a
/// baseline: `(scene, fps)`).
pub fn fit(runs: &[SceneRun], baselines: &[(&str, f64)]) -> Fit {
    let rows: Vec<(f64, f64, f64)> = runs
        .iter()
        .filter_map(|r| baselines.iter().find(|p| p.0 == r.scene).map(|p| (r, p.1)))
        .map(|(r, fps)| {
            let (w, m) = per_frame(r, 0);
            (w, m, 1.0 / fps)
        })
        .collect();
    // least squares on frame time, with non-negative coefficients
    let (mut sww, mut swm, mut smm, mut swt, mut smt) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(w, m, t) in &rows {
        sww += w * w;
        swm += w * m;
        smm += m * m;
        swt += w * t;
        smt += m * t;
    }
    let det = sww * smm - swm * swm;
    let (mut a, mut b) =
        if det.abs() > 0.0 { ((swt * smm - smt * swm) / det, (smt * sww - swt * swm) / det) } else { (0.0, 0.0) };
    if a < 0.0 || b < 0.0 {
        // one-parameter fits; keep the better
        let a1 = if sww > 0.0 { swt / sww } else { 0.0 };
        let b1 = if smm > 0.0 { smt / smm } else { 0.0 };
        let err = |a: f64, b: f64| rows.iter().map(|&(w, m, t)| (a * w + b * m - t).powi(2)).sum::<f64>();
        (a, b) = if err(a1, 0.0) <= err(0.0, b1) { (a1, 0.0) } else { (0.0, b1) };
    }
    let rms = (rows.iter().map(|&(w, m, t)| ((1.0 / (a * w + b * m)) * t - 1.0).powi(2)).sum::<f64>()
        / rows.len().max(1) as f64)
        .sqrt();
    Fit { per_instruction: a, per_transaction: b, baseline_rms_error: rms }
}

/// Predicted frame rate of variant `i`.
pub fn fps(f: &Fit, r: &SceneRun, i: usize) -> f64 {
    let (w, m) = per_frame(r, i);
    1.0 / (f.per_instruction * w + f.per_transaction * m)
}

/// One line describing the fitted model.
pub fn describe(f: &Fit) -> String {
    format!(
        "GT200 timing model: frame time = {:.3e} s x warp instructions + {:.3e} s x memory transactions (512 x 512), \
         fitted to the thesis' stack-based frame rates only; those baselines reproduced to {:.1} % RMS",
        f.per_instruction,
        f.per_transaction,
        f.baseline_rms_error * 100.0
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::rt_kernels::Variant;
    use crate::repro::fabianowski2011::flight::Totals;

    fn run(scene: &str, w: u64, m: u64) -> SceneRun {
        SceneRun {
            scene: scene.into(),
            triangles: 1,
            frames: 1,
            resolution: 512,
            variants: vec![Variant::Stack],
            totals: vec![Totals { warp_instructions: w, mem_transactions: m, rays: 1, ..Totals::default() }],
        }
    }

    #[test]
    fn the_fit_recovers_consistent_costs() {
        let (a, b) = (2e-10, 5e-9);
        let runs =
            [run("scene6", 1_000_000, 200_000), run("sponza", 4_000_000, 300_000), run("sibenik", 3_000_000, 900_000)];
        let fps: Vec<f64> = runs
            .iter()
            .map(|r| 1.0 / (a * r.totals[0].warp_instructions as f64 + b * r.totals[0].mem_transactions as f64))
            .collect();
        let f = fit(&runs, &[("scene6", fps[0]), ("sponza", fps[1]), ("sibenik", fps[2])]);
        assert!((f.per_instruction / a - 1.0).abs() < 1e-6 && (f.per_transaction / b - 1.0).abs() < 1e-6, "{f:?}");
        assert!(f.baseline_rms_error < 1e-9);
        assert!((fps_of(&f, &runs[1]) / fps[1] - 1.0).abs() < 1e-9);
    }

    fn fps_of(f: &Fit, r: &SceneRun) -> f64 {
        fps(f, r, 0)
    }
}
