//! The longest path's bound (review 6, finding 5): `--bounces` beyond
//! `MAX_BOUNCES` is refused with a typed error (the CLI where it parses the
//! option, the library in `FrameParams::check`), and a library caller that
//! passes a larger count anyway gets the same image natively and emulated —
//! the kernel's `int` no longer wraps to -1 (which gave nee no light samples
//! and bdpt a division by zero).

#[allow(dead_code)]
mod lin2017_mitsuba;

use std::process::Command;

use lin2017_mitsuba::scene_of;
use warplight::host::path::{
    FrameParams, FrameParamsError, Integrator, MAX_BOUNCES, PixelSampling, Termination, Traversal, kernel,
    render_native,
};
use warplight::sim::{Device, Fidelity};

fn params(integrator: Integrator, max_bounces: u32) -> FrameParams {
    FrameParams {
        width: 4,
        height: 4,
        integrator,
        max_bounces,
        seed: 1,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    }
}

#[test]
fn more_bounces_than_the_bound_are_refused() {
    assert_eq!(params(Integrator::Nee, MAX_BOUNCES).check(), Ok(()));
    assert_eq!(params(Integrator::Nee, 0).check(), Ok(()));
    let e = params(Integrator::Bdpt, MAX_BOUNCES + 1).check().unwrap_err();
    assert_eq!(e, FrameParamsError::TooManyBounces(MAX_BOUNCES + 1));
    assert!(e.to_string().contains("8190"), "{e}");
    // the eye subpath's dimensions 2 + 8 b + 0..6 stay below the light subpath's 0x10000
    const { assert!(2 + 8 * MAX_BOUNCES + 6 < 0x10000 && 2 + 8 * (MAX_BOUNCES + 1) + 6 >= 0x10000) };
}

#[test]
fn the_cli_refuses_bounces_past_the_bound() {
    let out = std::env::temp_dir().join(format!("warplight-bounces-{}.png", std::process::id()));
    let o = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["render", "--scene", "cornell-lambert", "--method", "path", "--resolution", "4x4", "--spp", "4"])
        .args(["--bounces", "3000000000", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "accepted: {err}");
    assert!(err.contains("--bounces") && err.contains("8190"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_huge_bound_renders_alike_natively_and_emulated() {
    let (_, ps, cam) = scene_of("cornell-lambert", 4);
    for integrator in [Integrator::Nee, Integrator::Bdpt] {
        for max_bounces in [u32::MAX, 1 << 31] {
            let p = params(integrator, max_bounces);
            let native = render_native(&ps, &cam, p, 1, false, |_| {}).expect("render");
            let mut cfg = kernel::sim_config(&p);
            cfg.fidelity = Fidelity::Functional;
            let mut dev = Device::with_config(cfg);
            let module = kernel::load(&mut dev).unwrap();
            let emu = kernel::render(&mut dev, &module, &ps, &cam, p, 1, false, |_| {}).unwrap();
            assert!(emu.image.accum.iter().all(|v| v.is_finite()), "{integrator:?} {max_bounces}: not finite");
            let differ = native.accum.iter().zip(&emu.image.accum).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
            assert_eq!(differ, 0, "{integrator:?} {max_bounces}: {differ} values differ");
            // and as with a large bound the kernel can hold
            let same = render_native(&ps, &cam, params(integrator, MAX_BOUNCES), 1, false, |_| {}).expect("render");
            assert!(same.accum.iter().sum::<f32>() > 0.0);
        }
    }
}
