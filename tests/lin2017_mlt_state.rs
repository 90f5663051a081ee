//! MLT's chain state (§4.8, 003:L328), review 7 findings 5 and 6.
//!
//! The footprint: the start-up (`mlt_init`, `mlt_start`) and `mlt_frame` touch exactly 40 k W H bytes of
//! the state buffer (k = max bounces + 1), measured from the emulator's
//! access log (every address the kernels load or store) in a buffer twice
//! that size, so that the kernels, not the host's `mlt::state_bytes`, decide
//! how much they use. (`tests/lin2017_mlt.rs` allocates `state_bytes` and
//! counts the stores with the memory model.)
//!
//! The bounds: a longest path past `MAX_BOUNCES` and a state past
//! `mlt::MAX_STATE_BYTES` (or past 2^64) are typed errors of both MLT entry
//! points, before any allocation or launch (before the fix, 2^31 bounces
//! wrapped to one segment and u32::MAX panicked in `par_chunks_mut(0)`).

#[allow(dead_code)]
mod lin2017_mitsuba;

use std::collections::BTreeSet;

use lin2017_mitsuba::scene_of;
use warplight::host::camera::Camera;
use warplight::host::path::mlt::{self, MltError};
use warplight::host::path::{
    self, FrameParams, FrameParamsError, Integrator, MAX_BOUNCES, PixelSampling, RenderError, Termination, Traversal,
    kernel,
};
use warplight::ptx::ir::MemSpace;
use warplight::sim::access_log::AccessLog;
use warplight::sim::{Arg, Device, Fidelity, LaunchConfig};

fn params(width: u32, height: u32, max_bounces: u32) -> FrameParams {
    FrameParams {
        width,
        height,
        integrator: Integrator::Mlt,
        max_bounces,
        seed: 1,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    }
}

#[test]
fn the_kernels_touch_40_k_w_h_bytes_of_state() {
    let (scene, ps, _) = scene_of("cornell-lambert", 8);
    let (w, h) = (8u32, 6u32);
    let cam = Camera { resolution: [w, h], ..scene.camera };
    for max_bounces in [29u32, 3] {
        let (k, n) = (max_bounces as u64 + 1, (w * h) as u64);
        let p = params(w, h, max_bounces);
        let mut cfg = kernel::sim_config(&p);
        cfg.fidelity = Fidelity::Memory;
        let mut dev = Device::with_config(cfg);
        let module = kernel::load(&mut dev).expect("load PTX");
        let bufs = kernel::upload_scene(&mut dev, &ps, &cam, &p).expect("upload");
        // twice the thesis' 40 k W H: what lies past it would show in the log
        let room = 2 * 40 * k * n;
        let state = dev.alloc_bytes(room, mlt::STATE_BUFFER);
        let chains = dev.alloc_bytes(16 * n, "mlt chains");
        let boot = dev.alloc_bytes(4 * mlt::BOOTSTRAP as u64 * n, "mlt bootstrap");
        let start = dev.alloc_bytes(4 * n, "mlt starts");
        let image = dev.alloc_bytes(24 * n, "mlt image");
        let args = |after: &[warplight::sim::DevicePtr]| -> Vec<Arg> {
            bufs.scene_args().into_iter().chain(after.iter().copied()).map(Arg::Ptr).collect()
        };
        let cfg = LaunchConfig::linear(1, kernel::THREADS);
        let log = AccessLog::new();
        dev.launch_observed(&module, mlt::INIT_KERNEL, cfg, &args(&[boot]), Some(&log)).expect("mlt_init");
        let ys = dev.read::<f32>(boot, (mlt::BOOTSTRAP as u64 * n) as usize);
        dev.write(start, &mlt::starts(&ys, n as u32, p.seed)).expect("starts");
        dev.launch_observed(&module, mlt::START_KERNEL, cfg, &args(&[state, chains, start]), Some(&log))
            .expect("mlt_start");
        dev.write(bufs.params, &kernel::params_bytes_mlt(&ps, &cam, &p, 0, mlt::b_of(&ys))).expect("params");
        dev.launch_observed(&module, mlt::FRAME_KERNEL, cfg, &args(&[state, chains, image]), Some(&log))
            .expect("mlt_frame");
        // the state's bytes the three kernels loaded or stored
        let mut touched = BTreeSet::new();
        for a in log.take().iter().filter(|a| a.space == MemSpace::Global) {
            for l in (0..32).filter(|l| a.mask >> l & 1 != 0) {
                let at = a.addrs[l];
                if at >= state.0 && at < state.0 + room {
                    touched.extend((at - state.0)..(at - state.0 + u64::from(a.bytes)));
                }
            }
        }
        let end = touched.last().map_or(0, |b| b + 1);
        eprintln!("k = {k}, {w} x {h}: the kernels touched {} state bytes, the last at {end}", touched.len());
        assert_eq!(end, 40 * k * n, "k = {k}: the state's extent, 40 k W H");
        assert_eq!(touched.len() as u64, 40 * k * n, "k = {k}: every byte below it");
    }
}

#[test]
fn mlt_refuses_bounds_it_cannot_keep() {
    let (scene, ps, _) = scene_of("cornell-lambert", 2);
    let cam = Camera { resolution: [2, 2], ..scene.camera };
    // within the bounds: the state's bytes
    assert_eq!(mlt::check(&params(2, 2, 16)).expect("fits"), 40 * 17 * 4);
    assert_eq!(mlt::check(&params(1920, 1080, 29)).expect("the thesis' example"), 2_488_320_000);
    for mb in [MAX_BOUNCES + 1, 1 << 31, u32::MAX] {
        let p = params(2, 2, mb);
        let e = mlt::render_native(&ps, &cam, p, 1, false, |_| {}).map(|_| ()).unwrap_err();
        assert!(matches!(e, MltError::Params(FrameParamsError::TooManyBounces(b)) if b == mb), "{mb}: {e:?}");
        // the integrators' entry point returns the same error (it panicked on it before)
        let e = path::render_native(&ps, &cam, p, 1, false, |_| {}).map(|_| ()).unwrap_err();
        assert!(
            matches!(e, RenderError::Mlt(MltError::Params(FrameParamsError::TooManyBounces(b))) if b == mb),
            "{mb}: {e:?}"
        );
        let mut dev = Device::with_config(kernel::sim_config(&p));
        let module = kernel::load(&mut dev).expect("load PTX");
        let before = dev.memory().allocations().len();
        let e = mlt::render_emulated(&mut dev, &module, &ps, &cam, p, 1, false, |_| {}).map(|_| ()).unwrap_err();
        assert!(matches!(e, MltError::Params(FrameParamsError::TooManyBounces(_))), "{mb}: {e:?}");
        assert_eq!(dev.memory().allocations().len(), before, "{mb}: allocated before refusing");
        // kernel::render (the emulated path of every integrator) refuses it too
        assert!(kernel::render(&mut dev, &module, &ps, &cam, p, 1, false, |_| {}).is_err(), "{mb}");
    }
    // within the bounce bound, the state past its bound: 40 x 8191 x 1920 x 1080 = 679 GB
    let e = mlt::check(&params(1920, 1080, MAX_BOUNCES)).unwrap_err();
    assert!(matches!(e, MltError::StateTooLarge { bytes: Some(679_394_304_000), .. }), "{e:?}");
    assert!(e.to_string().contains("679394304000") && e.to_string().contains("8190 bounces"), "{e}");
    // one byte past the bound is refused, the bound itself taken
    let at = |w: u32| mlt::check(&FrameParams { width: w, ..params(1, 1, 0) });
    let widest = (mlt::MAX_STATE_BYTES / 40) as u32;
    assert!(at(widest).is_ok() && at(widest + 1).is_err());
    // past 2^64: 40 x 8191 x (2^32 - 1)^2
    let e = mlt::check(&params(u32::MAX, u32::MAX, MAX_BOUNCES)).unwrap_err();
    assert!(matches!(e, MltError::StateTooLarge { bytes: None, .. }), "{e:?}");
    assert!(e.to_string().contains("more than 2^64"), "{e}");
    // the native render refuses it before allocating (it would need 679 GB)
    let e = mlt::render_native(&ps, &cam, params(1920, 1080, MAX_BOUNCES), 1, false, |_| {}).map(|_| ()).unwrap_err();
    assert!(matches!(e, MltError::StateTooLarge { .. }), "{e:?}");
    let e = path::render_native(&ps, &cam, params(1920, 1080, MAX_BOUNCES), 1, false, |_| {}).map(|_| ()).unwrap_err();
    assert!(matches!(e, RenderError::Mlt(MltError::StateTooLarge { .. })), "{e:?}");
}
