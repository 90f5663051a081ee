//! What thesis 003's image figures share (Figs. 6, 7, 9, §4.8 and the
//! convergence charts): the scene laid out on the thesis' SAH kd-tree, an
//! emulated render checked against its native twin bit for bit, and the RMS
//! of an error over independent runs.

use crate::host::camera::Camera;
use crate::host::image::FrameBuffer;
use crate::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use crate::host::path::layout::{LayoutError, PathScene};
use crate::host::path::{
    FrameParams, Integrator, PixelSampling, RenderError, Termination, Traversal, kernel, render_native,
};
use crate::host::raycast::{Caster, TraceStats};
use crate::host::scene::Scene;
use crate::model::atomic_tally::{AtomicSharing, AtomicTally};
use crate::sim::{Fidelity, SimError};

/// `scene` laid out for the path tracer on the thesis' SAH kd-tree.
pub fn path_scene(scene: &Scene) -> Result<PathScene, LayoutError> {
    PathScene::new(scene, &sah_tree(scene))
}

/// Per pixel of `camera`, the name of the material its centre's camera ray
/// hits first on `tree` (of `scene`), if any.
pub fn first_hit_materials<'s>(scene: &'s Scene, camera: &Camera, tree: &KdTree) -> Vec<Option<&'s str>> {
    let caster = Caster::new(scene, tree);
    let mut st = TraceStats::default();
    let [w, h] = camera.resolution;
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let hit = caster.intersect(&camera.ray(x, y), 0.0, f32::INFINITY, false, &mut st);
            out.push(hit.map(|h| scene.materials[scene.triangles[h.tri as usize].material as usize].name.as_str()));
        }
    }
    out
}

/// The unbiased variance of each pixel's channel over `frames`, averaged
/// over pixels and channels, and the mean of all (two passes in f64); None
/// below two frames.
pub fn pixel_variance(frames: &[FrameBuffer]) -> Option<(f64, f64)> {
    let n = frames.len();
    if n < 2 {
        return None;
    }
    let cells = frames[0].pixels.len() * 3;
    let (mut var, mut all) = (0.0, 0.0);
    for c in 0..cells {
        let xs = frames.iter().map(|f| f.pixels[c / 3][c % 3] as f64);
        let mean = xs.clone().sum::<f64>() / n as f64;
        var += xs.map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        all += mean;
    }
    Some((var / cells.max(1) as f64, all / cells.max(1) as f64))
}

/// A square image of `side` pixels traced with `integrator`, at most
/// `bounces` bounces, `seed`, on the 8-byte short stack (the figures' settings).
pub fn square(side: u32, integrator: Integrator, bounces: u32, seed: u32) -> FrameParams {
    FrameParams {
        width: side,
        height: side,
        integrator,
        max_bounces: bounces,
        seed,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    }
}

/// Why an emulated render could not be compared with its native twin.
#[derive(Debug, thiserror::Error)]
pub enum TwinError {
    /// The emulator failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The native renderer refused the settings.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// An emulated render and whether it equals the native one.
#[derive(Debug, Clone)]
pub struct Twin {
    /// The emulated render.
    pub emulated: kernel::KernelRender,
    /// Whether its accumulation buffer equals the native render's bit for bit.
    pub same: bool,
    /// Host seconds the emulated render took (the native twin not counted).
    pub seconds: f64,
}

/// `frames` frames of `params` on the emulator at functional fidelity (the
/// path kernel's simulator settings otherwise), and natively: the emulated
/// render, whether the two accumulation buffers are equal bit for bit, and
/// the emulated render's host time.
pub fn emulate_twin(ps: &PathScene, camera: &Camera, params: FrameParams, frames: u32) -> Result<Twin, TwinError> {
    let (mut dev, module) = kernel::device(&params, Fidelity::Functional)?;
    let t0 = std::time::Instant::now();
    let emulated = kernel::render(&mut dev, &module, ps, camera, params, frames, false, |_| {})?;
    let seconds = t0.elapsed().as_secs_f64();
    let twin = render_native(ps, camera, params, frames, false, |_| {})?;
    let same = emulated.image.accum.len() == twin.accum.len()
        && emulated.image.accum.iter().zip(&twin.accum).all(|(a, b)| a.to_bits() == b.to_bits());
    Ok(Twin { emulated, same, seconds })
}

/// The global atomics of one frame of `params` on the emulator at memory
/// fidelity (the path kernel's simulator settings otherwise), tallied by
/// address over the frame's launches ([`AtomicTally`]; MLT's start-up
/// kernels make none). One frame only: the tally keys warps by CTA and warp,
/// so the same warp in two launches would count as one, and warps of two
/// launches, which never run at once, as sharing.
pub fn atomic_sharing(ps: &PathScene, camera: &Camera, params: FrameParams) -> Result<AtomicSharing, SimError> {
    let (mut dev, module) = kernel::device(&params, Fidelity::Memory)?;
    let tally = std::sync::Arc::new(AtomicTally::new());
    dev.set_observer(Some(tally.clone()));
    kernel::render(&mut dev, &module, ps, camera, params, 1, false, |_| {})?;
    Ok(tally.sharing())
}

/// The SAH kd-tree of `scene` as the thesis builds it.
pub fn sah_tree(scene: &Scene) -> KdTree {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    build(&tris, BuildParams::thesis(Heuristic::Sah))
}

/// The RMS difference of `a` and `b` over the pixels where `mask` holds and
/// their channels (0 over no pixel); the squares summed in pixel and
/// channel order.
pub fn masked_rmse(a: &FrameBuffer, b: &FrameBuffer, mask: impl Fn(usize) -> bool) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for (i, (x, y)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        if mask(i) {
            for c in 0..3 {
                s += (x[c] as f64 - y[c] as f64).powi(2);
            }
            n += 3;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// A committed ground truth (`rel`, relative to the checkout) of
/// `side` x `side` pixels; any other size is an error naming the file.
pub fn read_truth(
    rel: &str,
    side: u32,
) -> Result<crate::host::image::FrameBuffer, crate::repro::registry::MeasureError> {
    let path = crate::host::scene_file::data_file(std::path::Path::new(rel));
    let truth = crate::host::path::stats::read_exr(&path)?;
    if (truth.width, truth.height) != (side, side) {
        return Err(format!("{}: {}x{}, expected {side}x{side}", path.display(), truth.width, truth.height).into());
    }
    Ok(truth)
}

/// The root of the mean square of `errors` (the RMS over runs); `None` if
/// any is missing or there are none.
pub fn rms(errors: impl IntoIterator<Item = Option<f64>>) -> Option<f64> {
    let (mut s, mut n) = (0.0, 0usize);
    for e in errors {
        s += e?.powi(2);
        n += 1;
    }
    (n > 0).then(|| (s / n as f64).sqrt())
}

/// The runs `0..runs` for which `holds` is true; `None` if it is `None`
/// for any (a value missing).
pub fn count(runs: u32, mut holds: impl FnMut(u32) -> Option<bool>) -> Option<u32> {
    let mut n = 0;
    for run in 0..runs {
        n += u32::from(holds(run)?);
    }
    Some(n)
}

/// `rms`, an RMS error against a reference, with the reference's own RMS
/// noise `floor` taken out in quadrature (0 where the floor exceeds it; a
/// NaN stays NaN).
pub fn above_floor(rms: f64, floor: f64) -> f64 {
    let v = rms * rms - floor * floor;
    if v.is_nan() { f64::NAN } else { v.max(0.0).sqrt() }
}

/// The least-squares slope of `pts` (x, y), as of log error on log samples;
/// None below two points or with no spread in x.
pub fn fit_slope(pts: &[(f64, f64)]) -> Option<f64> {
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The running means of `frames` (frame images of one run, in order) after
/// each count of frames in `marks`, as `(frames, mean image)`; sums in f64.
pub fn running_means(frames: &[FrameBuffer], marks: &[u32]) -> Vec<(u32, FrameBuffer)> {
    let Some(first) = frames.first() else { return Vec::new() };
    let (w, h) = (first.width, first.height);
    let mut sum = vec![[0.0f64; 3]; (w * h) as usize];
    let mut out = Vec::new();
    for (f, img) in frames.iter().enumerate() {
        for (s, p) in sum.iter_mut().zip(&img.pixels) {
            for (a, &v) in s.iter_mut().zip(p) {
                *a += v as f64;
            }
        }
        let n = f as u32 + 1;
        if marks.contains(&n) {
            let mut fb = FrameBuffer::new(w, h);
            for (q, s) in fb.pixels.iter_mut().zip(&sum) {
                *q = s.map(|v| (v / n as f64) as f32);
            }
            out.push((n, fb));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_over_runs() {
        assert_eq!(rms([Some(3.0), Some(4.0)]), Some(12.5f64.sqrt()));
        assert_eq!(rms([Some(3.0), None]), None);
        assert_eq!(rms(std::iter::empty()), None);
    }

    #[test]
    fn running_means_at_the_marks() {
        let frame = |v: f32| FrameBuffer { width: 1, height: 1, pixels: vec![[v, 2.0 * v, 0.0]] };
        let at = running_means(&[frame(1.0), frame(3.0), frame(8.0)], &[1, 3]);
        assert_eq!(at.iter().map(|(n, _)| *n).collect::<Vec<_>>(), [1, 3]);
        assert_eq!(at[0].1.pixels[0], [1.0, 2.0, 0.0]);
        assert_eq!(at[1].1.pixels[0], [4.0, 8.0, 0.0]);
        assert!(running_means(&[], &[1]).is_empty());
    }

    #[test]
    fn count_of_runs() {
        assert_eq!(count(3, |r| Some(r != 1)), Some(2));
        assert_eq!(count(3, |r| (r != 2).then_some(true)), None);
    }

    #[test]
    fn floor_taken_out_in_quadrature() {
        assert_eq!(above_floor(5.0, 3.0), 4.0);
        assert_eq!(above_floor(3.0, 5.0), 0.0);
        assert!(above_floor(f64::NAN, 1.0).is_nan());
    }

    #[test]
    fn slopes_of_power_laws() {
        let logs: Vec<(f64, f64)> =
            (0..5).map(|k| (4u32 << k) as f64).map(|x| (x.ln(), (3.0 * x).powf(-0.75).ln())).collect();
        assert!((fit_slope(&logs).unwrap() + 0.75).abs() < 1e-12);
        assert_eq!(fit_slope(&logs[..1]), None);
        assert_eq!(fit_slope(&[(1.0, 1.0), (1.0, 2.0)]), None, "no spread in x");
    }
}
