//! Thesis 003's Fig. 8 (003:L305-308): bidirectional path tracing against
//! eye path tracing in the Cornell box with the light turned to the ceiling.
//! "In order to test the effect of bi-directional path tracing, we simply
//! inverted the light in the original Cornell Box scene such that light faces
//! the ceiling and the light can only bounce to other surfaces via the small
//! crevices on the rim of the light. The sample image in Figure 8 shows that
//! both rendered in 100 frames, bi-directional path tracing remarkably
//! reduces the noise level comparing to that when only using next event
//! estimation, totally worth for the reduction of frame rate to 50%."
//!
//! The caption names the right image "Uni-directional (eye) path tracing",
//! the text "only using next event estimation": both are run, `nee` (the
//! text) and `pt` (BSDF sampling alone, the caption's plainest reading).
//!
//! Ours (fixtures in `docs/fixtures.md`): `scenes/cornell-inverted.toml` at
//! the Mitsuba reference's 32 × 32, [`FRAMES`] of our frames (100 paths a
//! pixel: the thesis' 100 frames of one path, as in Figs. 6 and 9),
//! [`RUNS`] runs; the RMS error against Mitsuba 3's path tracer
//! (`tests/fixtures/mitsuba/cornell-inverted-path-32`), its own noise taken
//! out in quadrature. The frame rate is modelled by the warp instructions of
//! one emulated frame of each integrator (bit for bit the native frame).

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::image::FrameBuffer;
use crate::host::path::{Integrator, render_native};
use crate::repro::compare::Tolerance;
use crate::repro::lin2017::convergence::{Reference, mean_luminance, rmse};
use crate::repro::lin2017::runs;
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};

/// Measurement group.
pub const BDPT_NEE: &str = "lin/bdpt-nee";

/// The scene: the light turned to the ceiling, 1 cm below it.
pub const SCENE: &str = "cornell-inverted";

/// The reference: Mitsuba 3's path tracer (`tools/mitsuba/reference.py`,
/// 16 batches of 2,048 samples a pixel).
pub const REFERENCE: &str = "cornell-inverted-path";

/// Our frames (4 paths a pixel each): 100 paths, the thesis' 100 frames of one.
pub const FRAMES: u32 = 25;

/// Independent runs (seeds `SEED0 + r`).
pub const RUNS: u32 = 8;

/// The first run's seed.
pub const SEED0: u32 = 800;

/// The longest path, in bounces.
pub const BOUNCES: u32 = 16;

/// "Remarkably reduces the noise level": read as at least halving the RMS
/// error (chosen before measuring; `docs/fixtures.md`).
pub const REMARKABLY: f64 = 0.5;

/// The exposure of the displayed images (as `tools/lin-figures.sh` shows
/// the box, lit only through the light's 1 cm gap): 2^2.
pub const EXPOSURE: f32 = 2.0;

/// The RMS difference of `a` and `b` as displayed: 8-bit sRGB after
/// [`EXPOSURE`] (values above 1 clipped), over pixels and channels, in
/// units of the full scale.
pub fn display_rmse(a: &FrameBuffer, b: &FrameBuffer) -> f64 {
    let (x, y) = (a.to_srgb8(EXPOSURE), b.to_srgb8(EXPOSURE));
    let s: f64 = x.iter().zip(&y).map(|(&p, &q)| ((p as f64 - q as f64) / 255.0).powi(2)).sum();
    (s / x.len().max(1) as f64).sqrt()
}

/// The thesis' frame rate of bdpt relative to nee's, as printed (003:L305).
pub const PRINTED_RATE: &str = "50%";

/// The frame rate's tolerance: ±10 % relative.
pub const RATE_TOLERANCE: Tolerance = Tolerance::Relative(0.10);

/// The rows: variant, integrator, label.
pub const ROWS: [(&str, Integrator, &str); 3] = [
    ("bdpt", Integrator::Bdpt, "bidirectional path tracing (Fig. 8 left)"),
    ("nee", Integrator::Nee, "next-event estimation (the text's right)"),
    ("pt", Integrator::Pt, "eye path tracing, BSDF sampling only (the caption's right)"),
];

/// Measurement group [`BDPT_NEE`]: per row, `rmse_r{r}` for run `r` (RMS
/// over pixels and channels against the reference's mean), `display_r{r}`
/// (the same of the displayed images, [`display_rmse`]), and the warp
/// instructions of its first frame emulated (`frame_warps`); under
/// `reference`: `noise` (the reference's own RMS noise), `mean` (its mean
/// luminance) and `emulated_same`.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let scene = ws.scene;
    if scene.name != SCENE {
        return Err(format!("{}: Fig. 8's study runs on {SCENE} only (its Mitsuba reference)", scene.name).into());
    }
    let truth = Reference::read(&Reference::default_prefix(REFERENCE))?;
    let n = truth.mean.width;
    if truth.mean.height != n {
        return Err(format!(
            "{}: the reference is {}x{}, Fig. 8's study renders a square image",
            truth.prefix.display(),
            n,
            truth.mean.height
        )
        .into());
    }
    let camera = Camera { resolution: [n, n], ..scene.camera };
    let ps = runs::path_scene(scene)?;
    let params = |integrator: Integrator, seed: u32| runs::square(n, integrator, BOUNCES, seed);
    let mut out = Vec::new();
    let mut same = true;
    for (variant, integrator, _) in ROWS {
        tick(Tick { frame: None, variant });
        params(integrator, SEED0).check()?;
        ps.check_integrator(&scene.name, integrator)?;
        let mut k = BTreeMap::new();
        for r in 0..RUNS {
            let img = render_native(&ps, &camera, params(integrator, SEED0 + r), FRAMES, false, |_| {})?.image();
            k.insert(format!("rmse_r{r}"), rmse(&img, &truth.mean));
            k.insert(format!("display_r{r}"), display_rmse(&img, &truth.mean));
        }
        let twin = runs::emulate_twin(&ps, &camera, params(integrator, SEED0), 1)?;
        same &= twin.same;
        k.insert("frame_warps".into(), twin.emulated.totals.warp_instructions as f64);
        out.push(Sample {
            group: BDPT_NEE.into(),
            scene: scene.name.clone(),
            frame: None,
            variant: variant.into(),
            counters: k,
        });
    }
    let mut k = BTreeMap::new();
    k.insert("noise".into(), truth.noise().0);
    k.insert("mean".into(), mean_luminance(&truth.mean));
    k.insert("emulated_same".into(), same as u8 as f64);
    out.push(Sample {
        group: BDPT_NEE.into(),
        scene: scene.name.clone(),
        frame: None,
        variant: "reference".into(),
        counters: k,
    });
    Ok(out)
}

/// The two measures of the noise: the radiance's RMS error (the reference's
/// own noise taken out) and the displayed image's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// RMS error of the linear radiance, `rmse_r{r}`.
    Radiance,
    /// RMS error of the displayed 8-bit sRGB image, `display_r{r}`.
    Display,
}

impl Measure {
    fn key(self) -> &'static str {
        match self {
            Measure::Radiance => "rmse",
            Measure::Display => "display",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Measure::Radiance => "RMS error of the radiance",
            Measure::Display => "RMS error of the displayed image",
        }
    }
}

/// A row's RMS error over the runs under measure `m` (the radiance's with
/// the reference's noise taken out).
pub fn error(r: &Results, variant: &str, m: Measure) -> Option<f64> {
    let e = runs::rms((0..RUNS).map(|run| run_error(r, variant, m, run)))?;
    match m {
        Measure::Radiance => Some(runs::above_floor(e, r.sum(BDPT_NEE, SCENE, "reference", "noise")?)),
        Measure::Display => Some(e),
    }
}

/// Run `run`'s error of `variant` under `m`.
fn run_error(r: &Results, variant: &str, m: Measure, run: u32) -> Option<f64> {
    r.sum(BDPT_NEE, SCENE, variant, &format!("{}_r{run}", m.key()))
}

/// Runs in which `a`'s error `x` and `b`'s `y` under `m` satisfy `holds(x, y)`.
fn runs_where(r: &Results, a: &str, b: &str, m: Measure, holds: impl Fn(f64, f64) -> bool) -> Option<u32> {
    runs::count(RUNS, |run| Some(holds(run_error(r, a, m, run)?, run_error(r, b, m, run)?)))
}

/// A row's frame rate relative to nee's, in percent, modelled by the
/// emulated frames' warp instructions.
pub fn rate(r: &Results, variant: &str) -> Option<f64> {
    let w = |v: &str| r.sum(BDPT_NEE, SCENE, v, "frame_warps").filter(|&w| w > 0.0);
    Some(100.0 * w("nee")? / w(variant)?)
}

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let columns = vec![
        Column::ours_only("RMS error of the radiance, 8 runs", Unit::Number(4)),
        Column::ours_only("RMS error of the displayed image (exposure +2, sRGB)", Unit::Number(4)),
        Column::modelled(
            "frame rate relative to nee's",
            Unit::Percent,
            "warp instructions of one emulated frame at 32 x 32 (nee's over the row's)",
            Some(RATE_TOLERANCE),
            None,
        ),
    ];
    let rows = ROWS
        .iter()
        .map(|(variant, _, label)| {
            let rate_cell = match *variant {
                "bdpt" => Cell::compared(rate(r, variant), PRINTED_RATE, Some(RATE_TOLERANCE)),
                _ => Cell { ours: rate(r, variant), ..Cell::default() },
            };
            Row {
                label: (*label).into(),
                kind: RowKind::Scene,
                cells: vec![
                    Cell { ours: error(r, variant, Measure::Radiance), ..Cell::default() },
                    Cell { ours: error(r, variant, Measure::Display), ..Cell::default() },
                    rate_cell,
                ],
            }
        })
        .collect();
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    let num = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.4}"));
    let ratio = |a: &str, b: &str, m: Measure| error(r, a, m).zip(error(r, b, m)).map(|(a, b)| a / b);
    let of_runs = |n: Option<u32>| n.map_or("–".into(), |n| format!("{n} of {RUNS}"));
    let evidence = |other: &str, m: Measure| {
        format!(
            "measured, {} over {RUNS} runs: bdpt {} against {other} {}, a ratio of {}; bdpt the lower in {}",
            m.name(),
            num(error(r, "bdpt", m)),
            num(error(r, other, m)),
            ratio("bdpt", other, m).map_or("–".into(), |q| format!("{q:.2}")),
            of_runs(runs_where(r, "bdpt", other, m, |x, y| x < y))
        )
    };
    for m in [Measure::Radiance, Measure::Display] {
        table.checks.push(Check {
            claim: format!(
                "both rendered in 100 frames, bi-directional path tracing remarkably reduces the noise level \
                 comparing to that when only using next event estimation (003:L305; 'remarkably': at most \
                 {REMARKABLY} of nee's error; {})",
                m.name()
            ),
            evidence: format!(
                "{}, at most {REMARKABLY} of it in {}",
                evidence("nee", m),
                of_runs(runs_where(r, "bdpt", "nee", m, |x, y| x <= REMARKABLY * y))
            ),
            holds: ratio("bdpt", "nee", m).is_some_and(|q| q <= REMARKABLY),
        });
    }
    for m in [Measure::Radiance, Measure::Display] {
        table.checks.push(Check {
            claim: format!(
                "the caption's reading: bidirectional path tracing is less noisy than uni-directional (eye) path \
                 tracing (003:L308; {})",
                m.name()
            ),
            evidence: evidence("pt", m),
            holds: ratio("bdpt", "pt", m).is_some_and(|q| q < 1.0),
        });
    }
    let same = r.sum(BDPT_NEE, SCENE, "reference", "emulated_same") == Some(1.0);
    table.checks.push(Check {
        claim: "the emulated kernels make the native renderer's images".into(),
        evidence: format!("measured: seed {SEED0}'s first frame of each row, bit-identical: {same}"),
        holds: same,
    });
    table.notes.push(format!(
        "Ours: `scenes/cornell-inverted.toml` (the Lambertian box with the light's quad turned to the ceiling, 1 cm \
         below it) at 32 x 32, {BOUNCES} bounces, {FRAMES} of our frames of 4 paths (100 paths a pixel, the \
         thesis' 100 frames of one path); {RUNS} runs (seeds {SEED0}-{}). Errors against Mitsuba 3's path tracer \
         (tests/fixtures/mitsuba/{REFERENCE}-32): of the radiance, its own noise ({}) taken out in quadrature; of \
         the displayed image (exposure +2, values above 1 clipped, 8-bit sRGB; full scale 1), as the figure is \
         looked at. bdpt weighs each technique 1/c (003:L303), as the thesis' does. The frame rate is modelled by \
         one emulated frame's warp instructions; the thesis' GPU (GTX 960M) is not modelled.",
        SEED0 + RUNS - 1,
        num(r.sum(BDPT_NEE, SCENE, "reference", "noise"))
    ));
    vec![table]
}
