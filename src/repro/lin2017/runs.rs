//! What thesis 003's image figures share (Figs. 6, 7, 9, §4.8 and the
//! convergence charts): the scene laid out on the thesis' SAH kd-tree, an
//! emulated render checked against its native twin bit for bit, and the RMS
//! of an error over independent runs.

use crate::host::camera::Camera;
use crate::host::kdtree::{BuildParams, Heuristic, build};
use crate::host::path::layout::{LayoutError, PathScene};
use crate::host::path::{FrameParams, Integrator, RenderError, Traversal, kernel, render_native};
use crate::host::scene::Scene;
use crate::sim::{Device, Fidelity, SimError};

/// `scene` laid out for the path tracer on the thesis' SAH kd-tree.
pub fn path_scene(scene: &Scene) -> Result<PathScene, LayoutError> {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    PathScene::new(scene, &tree)
}

/// A square image of `side` pixels traced with `integrator`, at most
/// `bounces` bounces, `seed`, on the 8-byte short stack (the figures' settings).
pub fn square(side: u32, integrator: Integrator, bounces: u32, seed: u32) -> FrameParams {
    FrameParams { width: side, height: side, integrator, max_bounces: bounces, seed, traversal: Traversal::ShortStack }
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
}

/// `frames` frames of `params` on the emulator at functional fidelity (the
/// path kernel's simulator settings otherwise), and natively: the emulated
/// render, and whether the two accumulation buffers are equal bit for bit.
pub fn emulate_twin(ps: &PathScene, camera: &Camera, params: FrameParams, frames: u32) -> Result<Twin, TwinError> {
    let mut cfg = kernel::sim_config(&params);
    cfg.fidelity = Fidelity::Functional;
    let mut dev = Device::with_config(cfg);
    let module = kernel::load(&mut dev)?;
    let emulated = kernel::render(&mut dev, &module, ps, camera, params, frames, false, |_| {})?;
    let twin = render_native(ps, camera, params, frames, false, |_| {})?;
    let same = emulated.image.accum.len() == twin.accum.len()
        && emulated.image.accum.iter().zip(&twin.accum).all(|(a, b)| a.to_bits() == b.to_bits());
    Ok(Twin { emulated, same })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_over_runs() {
        assert_eq!(rms([Some(3.0), Some(4.0)]), Some(12.5f64.sqrt()));
        assert_eq!(rms([Some(3.0), None]), None);
        assert_eq!(rms(std::iter::empty()), None);
    }
}
