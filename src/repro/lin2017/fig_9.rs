//! Thesis 003's Fig. 9 (003:L332-336): Monte Carlo against Metropolis, both
//! over bidirectional path tracing, at frames 1, 30 and 100. "While
//! maintaining a low noise level from the initial frame, MLT estimator
//! exhibits start-up bias as shown by the dim color of the part of the
//! ceiling directly illuminated by the light. In frame 100, the MLT estimator
//! almost reaches the equilibrium [...]. It is worth mentioning that such
//! level of variance is can only be achieved in frame number > 1000 by MC
//! estimator while the MLT estimator is only slightly slower than MC
//! estimator, cause of which mainly attributes to the atomic memory write".
//!
//! Ours (fixtures in `docs/fixtures.md`):
//!
//! - the scenes: `scenes/cornell-inverted.toml`, Fig. 8's box with the
//!   light turned to the ceiling, the only Cornell box of the thesis with a
//!   part of the ceiling "directly illuminated by the light" (our reading of
//!   the unstated scene), and `scenes/cornell-lambert.toml`, the original box,
//!   whose brightest part is the light on the ceiling; 32 × 32, 16 bounces;
//! - a thesis frame traces one path a pixel (MLT: one mutation a chain, a
//!   chain a pixel, 003:L326), ours four: its frames 1, 30, 100 are our
//!   frames 1, 8, 25 (4, 32, 100 paths a pixel) ([`OUR_FRAMES`]);
//! - the truth: Mitsuba 3's path-tracer references
//!   (`tests/fixtures/mitsuba/cornell-inverted-path-32`, `cornell-lambert-32`);
//!   the thesis' "part of the ceiling directly illuminated by the light" is
//!   their pixels brighter than [`LIT`] of the brightest;
//! - MLT with our start (each chain from the pool of all bootstrap samples,
//!   in proportion to Y) and with the start before issue 15's fix (each chain
//!   among its own 16 samples, natively only), [`RUNS`] independent runs
//!   each; Monte Carlo (bdpt) to [`MC_FRAMES`] frames;
//! - "such level of variance": the RMS error against the truth, the
//!   reference's own noise taken out in quadrature, with each image first
//!   scaled to the truth's mean luminance (MLT's overall brightness is b's,
//!   003:L330, an error of its own, shown beside); the Monte Carlo frames
//!   that reach MLT's frame-100 noise, read off its curve (or extrapolated
//!   from its last point by the 1/N law of its variance);
//! - "only slightly slower": an MLT frame's warp instructions over a bdpt
//!   frame's, emulated (the start-up excluded; atomics counted as
//!   instructions, their conflicts not modelled);
//! - "the atomic memory write as each thread [...] can write color to all
//!   pixels": one MLT frame's and one bdpt frame's global atomics tallied by
//!   address ([`runs::atomic_sharing`]): updates, addresses, those shared
//!   between warps, repeats within an instruction.

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::image::FrameBuffer;
use crate::host::path::native::Tracer;
use crate::host::path::{Integrator, SAMPLES_PER_FRAME, eps_for, frame_of, mlt, render_native};
use crate::repro::lin2017::convergence::{Reference, rmse};
use crate::repro::lin2017::runs;
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};

/// Measurement group: Monte Carlo and MLT (two starts), natively over runs, and one emulated frame of each.
pub const MC_MLT: &str = "lin/mc-mlt";

/// The scenes: Fig. 8's box, the light turned to the ceiling (a part of the
/// ceiling directly lit), and the original box (the light on the ceiling).
pub const SCENES: [&str; 2] = ["cornell-inverted", "cornell-lambert"];

/// The truth of one of [`SCENES`]: Mitsuba 3's path tracer on it
/// (`tests/fixtures/mitsuba/NAME-32`); an error for any other scene.
pub fn truth_of(scene: &str) -> Result<&'static str, MeasureError> {
    match scene {
        "cornell-inverted" => Ok("cornell-inverted-path"),
        "cornell-lambert" => Ok("cornell-lambert"),
        other => {
            Err(format!("{other}: no Mitsuba path-tracer reference for Fig. 9's study (scenes: {SCENES:?})").into())
        }
    }
}

/// The thesis' frames (one path a pixel each).
pub const THESIS_FRAMES: [u32; 3] = [1, 30, 100];

/// Ours at as many paths a pixel (4 a frame): 4, 32, 100.
pub const OUR_FRAMES: [u32; 3] = [1, 8, 25];

/// Monte Carlo's frames: 1,024 paths a pixel, past the thesis' "> 1000".
pub const MC_FRAMES: u32 = 256;

/// Independent runs (seeds `SEED0 + r`).
pub const RUNS: u32 = 8;

/// The runs' first seed.
pub const SEED0: u32 = 900;

/// "The part of the ceiling directly illuminated by the light": the truth's
/// pixels brighter than this fraction of its brightest.
pub const LIT: f64 = 0.125;

/// The longest path, in bounces (the reference's).
pub const BOUNCES: u32 = 16;

/// "slightly slower", read as at most this factor of a bdpt frame's work.
pub const SLIGHTLY: f64 = 1.5;

/// "almost reaches the equilibrium", read as the lit ceiling within this fraction of the truth.
pub const ALMOST: f64 = 0.10;

/// "dim", read as the lit ceiling darker than the truth by more than this fraction.
pub const DIM: f64 = 0.10;

/// The table's rows: variant, label.
pub const ROWS: [(&str, &str); 3] = [
    ("mc", "Monte Carlo (bdpt)"),
    ("mlt", "MLT over bdpt, chains started from the pool (ours)"),
    ("mlt-own", "MLT over bdpt, chains started among their own samples (before issue 15's fix)"),
];

/// The frames at which Monte Carlo's curve is read: powers of two to [`MC_FRAMES`] and [`OUR_FRAMES`].
pub fn mc_marks() -> Vec<u32> {
    let mut v = crate::repro::lin2017::convergence::checkpoints(MC_FRAMES);
    v.extend(OUR_FRAMES);
    v.sort_unstable();
    v.dedup();
    v
}

/// The lit ceiling's mask and summed luminance in the truth.
struct Lit {
    mask: Vec<bool>,
    truth: f64,
}

impl Lit {
    fn of(truth: &FrameBuffer) -> Lit {
        let max = truth.pixels.iter().map(|&p| mlt::luminance(p) as f64).fold(0.0, f64::max);
        let mask: Vec<bool> = truth.pixels.iter().map(|&p| mlt::luminance(p) as f64 > LIT * max).collect();
        let truth = Self::sum(&mask, truth);
        Lit { mask, truth }
    }

    fn sum(mask: &[bool], img: &FrameBuffer) -> f64 {
        img.pixels.iter().zip(mask).filter(|(_, m)| **m).map(|(&p, _)| mlt::luminance(p) as f64).sum()
    }

    /// The lit ceiling's luminance in `img` relative to the truth's, minus 1.
    fn relative(&self, img: &FrameBuffer) -> f64 {
        Self::sum(&self.mask, img) / self.truth - 1.0
    }
}

/// `img` scaled to mean luminance `y`: its error without the error of its
/// overall brightness (for MLT, b's).
pub fn scaled(img: &FrameBuffer, y: f64) -> FrameBuffer {
    let k = (y / crate::repro::lin2017::convergence::mean_luminance(img)) as f32;
    let mut out = img.clone();
    if k.is_finite() {
        for p in &mut out.pixels {
            *p = p.map(|c| c * k);
        }
    }
    out
}

/// Measurement group [`MC_MLT`]: per variant and run `r`, at each mark `f`
/// the RMS error `rmse_f{f}_r{r}` and the lit ceiling's relative luminance
/// `lit_f{f}_r{r}`; `emulated_same` and the emulated frames' warp
/// instructions (`mc_frame_warps`, `mlt_frame_warps`); MLT's b relative to
/// the truth's mean luminance, `b_r{r}`.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let scene = ws.scene;
    let truth = Reference::read(&Reference::default_prefix(truth_of(&scene.name)?))?;
    let truth_y = crate::repro::lin2017::convergence::mean_luminance(&truth.mean);
    let n = truth.mean.width;
    let lit = Lit::of(&truth.mean);
    let camera = Camera { resolution: [n, n], ..scene.camera };
    let ps = runs::path_scene(scene)?;
    let params = |integrator: Integrator, seed: u32| runs::square(n, integrator, BOUNCES, seed);
    params(Integrator::Mlt, SEED0).check()?;
    mlt::check(&params(Integrator::Mlt, SEED0))?;
    let record = |k: &mut BTreeMap<String, f64>, r: u32, at: Vec<(u32, FrameBuffer)>| {
        for (f, img) in at {
            k.insert(format!("rmse_f{f}_r{r}"), rmse(&img, &truth.mean));
            k.insert(format!("noise_f{f}_r{r}"), rmse(&scaled(&img, truth_y), &truth.mean));
            k.insert(format!("lit_f{f}_r{r}"), lit.relative(&scaled(&img, truth_y)));
        }
    };
    let mut out = Vec::new();
    for (variant, _) in ROWS {
        tick(Tick { frame: None, variant });
        let mut k = BTreeMap::new();
        for r in 0..RUNS {
            let seed = SEED0 + r;
            let frames = match variant {
                "mc" => {
                    render_native(&ps, &camera, params(Integrator::Bdpt, seed), MC_FRAMES, true, |_| {})?.frame_images
                }
                _ => {
                    let p = params(Integrator::Mlt, seed);
                    let tracer = Tracer { scene: &ps, frame: frame_of(&camera, eps_for(ps.lo, ps.hi)), params: p };
                    let start = if variant == "mlt" { mlt::Start::Pool } else { mlt::Start::Own };
                    let last = OUR_FRAMES[OUR_FRAMES.len() - 1];
                    let run = mlt::render_target(&tracer, p, mlt::Chains::starting(start), last, true, |_| {})?;
                    k.insert(format!("b_r{r}"), run.b as f64 / truth_y - 1.0);
                    run.image.frame_images
                }
            };
            let marks = if variant == "mc" { mc_marks() } else { OUR_FRAMES.to_vec() };
            record(&mut k, r, runs::running_means(&frames, &marks));
        }
        out.push(Sample {
            group: MC_MLT.into(),
            scene: scene.name.clone(),
            frame: None,
            variant: variant.into(),
            counters: k,
        });
    }
    // one emulated frame of each integrator, and a second MLT frame for its
    // cost without the start-up
    tick(Tick { frame: None, variant: "emulated" });
    let mut k = BTreeMap::new();
    let mut same = true;
    let mut warps = |integrator: Integrator, frames: u32| -> Result<u64, MeasureError> {
        let t = runs::emulate_twin(&ps, &camera, params(integrator, SEED0), frames)?;
        same &= t.same;
        Ok(t.emulated.totals.warp_instructions)
    };
    let mc = warps(Integrator::Bdpt, 1)?;
    let mlt1 = warps(Integrator::Mlt, 1)?;
    let mlt2 = warps(Integrator::Mlt, 2)?;
    k.insert("mc_frame_warps".into(), mc as f64);
    k.insert("mlt_startup_and_frame_warps".into(), mlt1 as f64);
    k.insert("mlt_frame_warps".into(), mlt2.saturating_sub(mlt1) as f64);
    k.insert("emulated_same".into(), same as u8 as f64);
    // who writes where: one frame of each at memory fidelity, its global atomics tallied by address
    for (prefix, integrator) in [("mlt", Integrator::Mlt), ("mc", Integrator::Bdpt)] {
        let a = runs::atomic_sharing(&ps, &camera, params(integrator, SEED0))?;
        for (name, v) in [
            ("instructions", a.instructions),
            ("lane_updates", a.lane_updates),
            ("addresses", a.addresses),
            ("repeats", a.same_instruction_repeats),
            ("shared_addresses", a.shared_addresses),
            ("shared_updates", a.shared_lane_updates),
            ("max_per_address", a.max_per_address),
        ] {
            k.insert(format!("{prefix}_atomic_{name}"), v as f64);
        }
    }
    k.insert("truth_noise".into(), truth.noise().0);
    k.insert("lit_pixels".into(), lit.mask.iter().filter(|&&m| m).count() as f64);
    k.insert("side".into(), n as f64);
    out.push(Sample {
        group: MC_MLT.into(),
        scene: scene.name.clone(),
        frame: None,
        variant: "emulated".into(),
        counters: k,
    });
    Ok(out)
}

/// One variant's means over the runs at frame `f`.
#[derive(Debug, Clone, Copy)]
struct At {
    /// RMS error, the truth's own noise taken out in quadrature.
    error: f64,
    /// The same with each image first scaled to the truth's mean luminance.
    noise: f64,
    /// The lit ceiling's luminance relative to the truth's, minus 1.
    lit: f64,
}

fn at(r: &Results, scene: &str, variant: &str, f: u32) -> Option<At> {
    let floor = r.sum(MC_MLT, scene, "emulated", "truth_noise").unwrap_or(0.0);
    let get = |c: &str, run: u32| r.sum(MC_MLT, scene, variant, &format!("{c}_f{f}_r{run}"));
    let over_runs = |c: &str| runs::rms((0..RUNS).map(|run| get(c, run))).map(|e| runs::above_floor(e, floor));
    let mut lit = 0.0;
    for run in 0..RUNS {
        lit += get("lit", run)?;
    }
    Some(At { error: over_runs("rmse")?, noise: over_runs("noise")?, lit: lit / RUNS as f64 })
}

/// The thesis frames (paths a pixel) from which on Monte Carlo's RMS error
/// stays at or below `target` (`noise`: with the images scaled to the
/// truth's mean first): interpolated (log-log) after the last mark above
/// it, or extrapolated past the last mark by the 1/N law of its variance;
/// the first mark (4 paths) when no mark is above. `None` without data.
pub fn mc_paths_to_reach(r: &Results, scene: &str, target: f64, noise: bool) -> Option<f64> {
    let curve: Vec<(f64, f64)> = mc_marks()
        .into_iter()
        .map(|f| at(r, scene, "mc", f).map(|a| ((f * SAMPLES_PER_FRAME) as f64, if noise { a.noise } else { a.error })))
        .collect::<Option<_>>()?;
    // the paths from which on Monte Carlo's error stays at or below the
    // target: its curve wanders (bdpt's heavy tail), so the last crossing
    let Some(above) = curve.iter().rposition(|&(_, e)| e > target) else {
        return curve.first().map(|&(p, _)| p);
    };
    if let Some(&(p1, e1)) = curve.get(above + 1) {
        let (p0, e0) = curve[above];
        if e1 > 0.0 {
            let t = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return Some((p0.ln() + t * (p1.ln() - p0.ln())).exp());
        }
        return Some(p1);
    }
    let (p, e) = curve[above];
    (target > 0.0).then(|| p * (e / target).powi(2))
}

/// RMS over runs of MLT's b relative to the truth's mean luminance.
fn b_error(r: &Results, scene: &str, variant: &str) -> Option<f64> {
    let mut s = 0.0;
    for run in 0..RUNS {
        s += r.sum(MC_MLT, scene, variant, &format!("b_r{run}"))?.powi(2);
    }
    Some((s / RUNS as f64).sqrt())
}

/// The table: a row per scene and estimator, the checks per scene.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let mut columns = Vec::new();
    for f in THESIS_FRAMES {
        columns.push(Column::ours_only(&format!("lit ceiling vs truth, frame {f}"), Unit::Change));
    }
    for f in THESIS_FRAMES {
        columns.push(Column::ours_only(&format!("RMS error, frame {f}"), Unit::Number(4)));
    }
    columns.push(Column::ours_only("noise (brightness removed), frame 1", Unit::Number(4)));
    columns.push(Column::ours_only("noise (brightness removed), frame 100", Unit::Number(4)));
    columns.push(
        Column::measured("MC frames for this noise at frame 100", Unit::Count, crate::repro::compare::Tolerance::COUNT)
            .uncompared(
                "the thesis prints a bound (\"> 1000\"), compared in the checks; the paths of one-path frames from which \
                 on Monte Carlo stays at or below the row's noise (4: from its first frame)",
            ),
    );
    columns.push(Column::ours_only("b vs truth, RMS over runs", Unit::Percent));
    let scenes: Vec<&str> =
        SCENES.iter().copied().filter(|s| r.sum(MC_MLT, s, "emulated", "lit_pixels").is_some()).collect();
    let mut rows = Vec::new();
    for &scene in &scenes {
        for (variant, label) in ROWS {
            let a = |i: usize| at(r, scene, variant, OUR_FRAMES[i]);
            let mut cells = Vec::new();
            for i in 0..3 {
                cells.push(Cell { ours: a(i).map(|a| 100.0 * a.lit), ..Cell::default() });
            }
            for i in 0..3 {
                cells.push(Cell { ours: a(i).map(|a| a.error), ..Cell::default() });
            }
            cells.push(Cell { ours: a(0).map(|a| a.noise), ..Cell::default() });
            cells.push(Cell { ours: a(2).map(|a| a.noise), ..Cell::default() });
            let mlt = variant != "mc";
            cells.push(if mlt {
                Cell {
                    ours: a(2).and_then(|a| mc_paths_to_reach(r, scene, a.noise, true)),
                    thesis: Some("> 1000".into()),
                    ..Cell::default()
                }
            } else {
                Cell::default()
            });
            cells.push(Cell {
                ours: if mlt { b_error(r, scene, variant).map(|b| 100.0 * b) } else { None },
                ..Cell::default()
            });
            rows.push(Row { label: format!("{scene}: {label}"), kind: RowKind::Scene, cells });
        }
    }
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    for &scene in &scenes {
        checks(&mut table, r, scene);
    }
    let emu = |s: &str, c: &str| r.sum(MC_MLT, s, "emulated", c);
    let num = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.4}"));
    let side = scenes.first().and_then(|s| emu(s, "side")).map_or("–".into(), |n| format!("{n:.0}"));
    table.notes.push(format!(
        "Ours: {} at {side} x {side}, {BOUNCES} bounces, natively, {RUNS} runs (seeds {SEED0}-{}); thesis frames 1, 30, \
         100 of one path a pixel are our frames 1, 8, 25 of 4. `cornell-inverted` is Fig. 8's box (the light \
         facing the ceiling, lighting it through the 1 cm gap: the thesis' \"part of the ceiling directly \
         illuminated by the light\", our reading of Fig. 9's unstated scene); `cornell-lambert` the original box, \
         whose brightest part is the light on the ceiling. Truth: Mitsuba 3's path tracer \
         (tests/fixtures/mitsuba/cornell-inverted-path-32, cornell-lambert-32); the lit ceiling: the truth's pixels \
         brighter than {LIT} of its brightest ({}), its luminance measured with each image scaled to the truth's \
         mean luminance first (b's error removed: it is the last column). RMS errors: over pixels and channels, the runs' mean square \
         with the truth's own noise ({}) taken out. MLT: primary-sample space over bdpt, 16 bootstrap samples a \
         chain, b their mean luminance, large steps 0.25 (kernels/lin2017/path.cu: mlt_init, mlt_start, \
         mlt_frame); 'own start' is the start before issue 15's fix, native only.",
        scenes.iter().map(|s| format!("`scenes/{s}.toml`")).collect::<Vec<_>>().join(" and "),
        SEED0 + RUNS - 1,
        scenes
            .iter()
            .map(|s| format!("{} pixels of {s}", emu(s, "lit_pixels").map_or("–".into(), |n| format!("{n:.0}"))))
            .collect::<Vec<_>>()
            .join(", "),
        scenes.iter().map(|s| format!("{} in {s}", num(emu(s, "truth_noise")))).collect::<Vec<_>>().join(", "),
    ));
    vec![table]
}

/// The checks of one scene.
fn checks(table: &mut Table, r: &Results, scene: &str) {
    let emu = |c: &str| r.sum(MC_MLT, scene, "emulated", c);
    let pct = |v: Option<f64>| v.map_or("–".into(), |v| format!("{:+.1} %", 100.0 * v));
    let num = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.4}"));
    let a = |v: &str, i: usize| at(r, scene, v, OUR_FRAMES[i]);
    let err = |v: &str, i: usize| a(v, i).map(|a| a.error);
    let noise = |v: &str, i: usize| a(v, i).map(|a| a.noise);
    let lit = |v: &str, i: usize| a(v, i).map(|a| a.lit);
    table.checks.push(Check {
        claim: format!("{scene}: MLT's noise is low from the initial frame (003:L332)"),
        evidence: format!(
            "measured, frame 1 (4 paths a pixel), over {RUNS} runs, brightness removed: MLT's RMS error {} against \
             Monte Carlo's {} (with it: {} against {})",
            num(noise("mlt", 0)),
            num(noise("mc", 0)),
            num(err("mlt", 0)),
            num(err("mc", 0))
        ),
        holds: noise("mlt", 0).zip(noise("mc", 0)).is_some_and(|(m, c)| m < c),
    });
    for (v, whose) in [("mlt", "chains from the pool (ours)"), ("mlt-own", "chains among their own samples")] {
        table.checks.push(Check {
            claim: format!(
                "{scene}: MLT shows start-up bias, the directly lit ceiling dim at frame 1 (003:L332), with {whose}"
            ),
            evidence: format!(
                "measured: the lit ceiling {} of the truth at frame 1, mean over runs (dim: below −{:.0} %)",
                pct(lit(v, 0)),
                100.0 * DIM
            ),
            holds: lit(v, 0).is_some_and(|l| l < -DIM),
        });
    }
    table.checks.push(Check {
        claim: format!("{scene}: in frame 100 MLT almost reaches the equilibrium on the lit ceiling (003:L332)"),
        evidence: format!(
            "measured at frame 100, mean over runs: {} (pool start), {} (own start); read as within ±{:.0} %",
            pct(lit("mlt", 2)),
            pct(lit("mlt-own", 2)),
            100.0 * ALMOST
        ),
        holds: lit("mlt", 2).is_some_and(|l| l.abs() <= ALMOST),
    });
    let needed = noise("mlt", 2).and_then(|t| mc_paths_to_reach(r, scene, t, true));
    let needed_err = err("mlt", 2).and_then(|t| mc_paths_to_reach(r, scene, t, false));
    table.checks.push(Check {
        claim: format!(
            "{scene}: MLT's level of variance at frame 100 takes Monte Carlo more than 1000 frames (003:L332)"
        ),
        evidence: format!(
            "measured (pool start), brightness removed: MLT's RMS error at frame 100 {}, Monte Carlo's at 1,024 \
             paths {}: it reaches MLT's at {} frames of one path (read off its curve, beyond 1,024 by 1/N); with \
             the brightness (b's error) kept, at {}",
            num(noise("mlt", 2)),
            num(at(r, scene, "mc", MC_FRAMES).map(|a| a.noise)),
            needed.map_or("–".into(), |p| format!("{p:.0}")),
            needed_err.map_or("–".into(), |p| format!("{p:.0}")),
        ),
        holds: needed.is_some_and(|p| p > 1000.0),
    });
    let ratio = emu("mlt_frame_warps").zip(emu("mc_frame_warps")).map(|(m, c)| m / c);
    table.checks.push(Check {
        claim: format!("{scene}: the MLT estimator is only slightly slower than MC (003:L332)"),
        evidence: format!(
            "modelled by emulated warp instructions: an MLT frame (its second, the start-up excluded) {} a bdpt \
             frame's (read as at most {SLIGHTLY}x; atomic conflicts not modelled: on an H200 the frames without \
             atomic splats, or without splats, take the same time within their spread, docs/gpu-replay.md)",
            ratio.map_or("–".into(), |x| format!("{x:.2}x"))
        ),
        holds: ratio.is_some_and(|x| x <= SLIGHTLY),
    });
    let atomic = |p: &str, name: &str| emu(&format!("{p}_atomic_{name}"));
    let count = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.0}"));
    let shared_share = atomic("mlt", "shared_updates")
        .zip(atomic("mlt", "lane_updates"))
        .filter(|&(_, n)| n > 0.0)
        .map(|(s, n)| 100.0 * s / n);
    table.checks.push(Check {
        claim: format!(
            "{scene}: each thread runs an independent MLT task which can write color to all pixels on the screen \
             (003:L332), the thesis' cause of the slowdown; read as: an MLT frame's splats are atomics to \
             addresses that more than one warp updates, a bdpt frame makes none (their time is not modelled)"
        ),
        evidence: format!(
            "counted in one emulated MLT frame (its start-up's kernels make no atomics): {} warp-level atomics ({} \
             of an MLT frame's warp instructions, its second's), {} lane updates of {} addresses (the image's 3 channels of {} pixels), {} of the updates to addresses \
             that more than one warp updates, at most {} on one address, {} repeats within one instruction; a bdpt \
             frame: {} atomic lane updates (each path writes its own pixel)",
            count(atomic("mlt", "instructions")),
            atomic("mlt", "instructions")
                .zip(emu("mlt_frame_warps"))
                .filter(|&(_, w)| w > 0.0)
                .map_or("–".into(), |(a, w)| format!("{:.3}%", 100.0 * a / w)),
            count(atomic("mlt", "lane_updates")),
            count(atomic("mlt", "addresses")),
            count(emu("side").map(|n| n * n)),
            shared_share.map_or("–".into(), |x| format!("{x:.1}%")),
            count(atomic("mlt", "max_per_address")),
            count(atomic("mlt", "repeats")),
            count(atomic("mc", "lane_updates")),
        ),
        holds: atomic("mlt", "shared_updates").is_some_and(|s| s > 0.0)
            && atomic("mc", "lane_updates") == Some(0.0),
    });
    let same = emu("emulated_same") == Some(1.0);
    table.checks.push(Check {
        claim: format!("{scene}: the emulated kernels make the native renderer's images"),
        evidence: format!("measured: bdpt's first frame and MLT's first two, seed {SEED0}, bit-identical: {same}"),
        holds: same,
    });
}
