//! Thesis 003 §4.8's MLT parameters: the bootstrap count and the
//! large-step probability.
//!
//! The normalisation (003:L330): "the estimation of
//! global radiance r̄ = ‖∫_S f dX‖ [...] at the beginning will affect the
//! overall luminance of the final result. [...] r̄ functions as a scaling
//! factor for all samples. As a result, in the case where the rendered
//! result is required to be physically authentic, more sample should be
//! taken to estimate the global radiance, although it causes a considerable
//! overhead." The bootstrap count is not stated.
//!
//! Ours: b (our r̄), the mean luminance of the bootstrap samples (bdpt large
//! steps, `mlt_init` in `kernels/lin2017/path.cu`; 16 a chain there), over
//! [`COUNTS`] samples a chain, natively on the boxes of Fig. 9 at 32 × 32,
//! [`RUNS`] runs each, against the Mitsuba reference's mean luminance; the
//! samples of k a chain are the first k W H of one sequence, so at 16 b is
//! the kernel's bit for bit. Beside it: an MLT render's mean luminance
//! against its b, emulated (the splats carry b: each iteration adds b F / Y
//! with weights summing to 1), and the start-up's cost in bdpt frames.
//!
//! The large-step probability. The thesis' example (003:L318): "If, for
//! example, the random number is lower than the threshold 0.25, it means on
//! average there is 1 large mutation and 3 small (local) mutations out of 4
//! mutations." Its advice (003:L324): "In practice, if the scene contains
//! mostly diffuse surfaces, large mutation rate can be set larger. On the
//! other hand, if the intricate optical effects are the emphasis of
//! rendering, large mutation rate should be set much smaller." Ours: MLT's
//! error after 100 mutations a chain at [`LARGE_STEPS`] on a diffuse box,
//! one with a glossy back wall and one with a glass caustic, natively
//! ([`mlt::Chains`]; the kernel's is the constant 0.25).

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::path::layout::PathScene;
use crate::host::path::native::Tracer;
use crate::host::path::{Integrator, SAMPLES_PER_FRAME, eps_for, frame_of, kernel, mlt};
use crate::repro::lin2017::convergence::{Reference, mean_luminance};
use crate::repro::lin2017::{fig_9, runs};
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};
use crate::sim::Fidelity;

/// Measurement group.
pub const BOOTSTRAP_GROUP: &str = "lin/mlt-bootstrap";

/// Bootstrap samples a chain (a pixel) measured; the kernel's is 16.
pub const COUNTS: [u32; 6] = [1, 4, 16, 64, 256, 1024];

/// Independent runs (seeds `SEED0 + r`).
pub const RUNS: u32 = 8;

/// The runs' first seed.
pub const SEED0: u32 = 900;

/// The image side.
pub const SIDE: u32 = crate::repro::lin2017::convergence::REFERENCE_SIDE;

/// How far an MLT image's mean luminance may lie from its b (the fixed-point
/// splats truncate; the image's pixels are rounded to f32).
const B_SCALES_IMAGE: f64 = 1e-4;

/// Measurement group [`BOOTSTRAP_GROUP`]: per run `r` and count `k`,
/// `b_k{k}_r{r}` (b relative to the truth's mean luminance, minus 1); one
/// emulated MLT frame's mean luminance relative to its b (`image_vs_b`).
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let scene = ws.scene;
    let truth = Reference::read(&Reference::default_prefix(fig_9::truth_of(&scene.name)?))?;
    let truth_y = mean_luminance(&truth.mean);
    let n = SIDE;
    let camera = Camera { resolution: [n, n], ..scene.camera };
    let ps = runs::path_scene(scene)?;
    let params = |seed: u32| runs::square(n, Integrator::Mlt, fig_9::BOUNCES, seed);
    mlt::check(&params(SEED0))?;
    let mut k = BTreeMap::new();
    let most = COUNTS[COUNTS.len() - 1];
    for r in 0..RUNS {
        tick(Tick { frame: None, variant: "bootstrap" });
        let p = params(SEED0 + r);
        let tracer = Tracer { scene: &ps, frame: frame_of(&camera, eps_for(ps.lo, ps.hi)), params: p };
        let boot = mlt::bootstrap_luminances(&tracer, &p, most);
        for c in COUNTS {
            let b = mlt::b_of(&boot[..(c * n * n) as usize]);
            k.insert(format!("b_k{c}_r{r}"), b as f64 / truth_y - 1.0);
        }
    }
    tick(Tick { frame: None, variant: "emulated" });
    let p = params(SEED0);
    let (mut dev, module) = kernel::device(&p, Fidelity::Functional)?;
    let e = mlt::render_emulated(&mut dev, &module, &ps, &camera, p, 1, false, |_| {})?;
    let b = e.b;
    let tracer = Tracer { scene: &ps, frame: frame_of(&camera, eps_for(ps.lo, ps.hi)), params: p };
    let ours = mlt::b_of(&mlt::bootstrap_luminances(&tracer, &p, mlt::BOOTSTRAP));
    k.insert("image_vs_b".into(), mean_luminance(&e.image.image()) / b as f64 - 1.0);
    k.insert("kernel_b_is_ours".into(), (ours.to_bits() == b.to_bits()) as u8 as f64);
    Ok(vec![Sample {
        group: BOOTSTRAP_GROUP.into(),
        scene: scene.name.clone(),
        frame: None,
        variant: "b".into(),
        counters: k,
    }])
}

/// b's relative error at `c` samples a chain: the RMS over runs and the largest.
fn b_error(r: &Results, scene: &str, c: u32) -> Option<(f64, f64)> {
    let mut s = 0.0f64;
    let mut worst = 0.0f64;
    for run in 0..RUNS {
        let v = r.sum(BOOTSTRAP_GROUP, scene, "b", &format!("b_k{c}_r{run}"))?;
        s += v * v;
        worst = worst.max(v.abs());
    }
    Some(((s / RUNS as f64).sqrt(), worst))
}

/// The table: a row per scene and bootstrap count.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let columns = vec![
        Column::ours_only("bootstrap samples a pixel", Unit::Count),
        Column::ours_only("b vs truth, RMS over runs", Unit::Percent),
        Column::ours_only("largest of the runs", Unit::Percent),
        Column::ours_only("RMS x sqrt(samples)", Unit::Number(2)),
        Column::ours_only("start-up in bdpt frames", Unit::Number(2)),
    ];
    let scenes: Vec<&str> =
        fig_9::SCENES.iter().copied().filter(|s| r.sum(BOOTSTRAP_GROUP, s, "b", "image_vs_b").is_some()).collect();
    let mut rows = Vec::new();
    for &scene in &scenes {
        for c in COUNTS {
            let err = b_error(r, scene, c);
            rows.push(Row {
                label: format!("{scene}: {c}{}", if c == mlt::BOOTSTRAP { " (the kernel's)" } else { "" }),
                kind: RowKind::Scene,
                cells: vec![
                    Cell { ours: Some(c as f64), ..Cell::default() },
                    Cell { ours: err.map(|e| 100.0 * e.0), ..Cell::default() },
                    Cell { ours: err.map(|e| 100.0 * e.1), ..Cell::default() },
                    Cell { ours: err.map(|e| e.0 * (c as f64).sqrt()), ..Cell::default() },
                    Cell { ours: Some(c as f64 / SAMPLES_PER_FRAME as f64), ..Cell::default() },
                ],
            });
        }
    }
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    for &scene in &scenes {
        let get = |c: &str| r.sum(BOOTSTRAP_GROUP, scene, "b", c);
        let dev = get("image_vs_b");
        table.checks.push(Check {
            claim: format!("{scene}: r̄ scales every sample, so it sets the image's overall luminance (003:L330)"),
            evidence: format!(
                "measured on the emulator, one MLT frame (seed {SEED0}): the image's mean luminance {} from b \
                 (holds within {B_SCALES_IMAGE:e}); the kernel's b equals the native bootstrap's: {}",
                dev.map_or("–".into(), |d| format!("{:+.2e}", d)),
                get("kernel_b_is_ours") == Some(1.0)
            ),
            holds: dev.is_some_and(|d| d.abs() <= B_SCALES_IMAGE) && get("kernel_b_is_ours") == Some(1.0),
        });
        let first = b_error(r, scene, COUNTS[0]).map(|e| e.0);
        let last = b_error(r, scene, COUNTS[COUNTS.len() - 1]).map(|e| e.0);
        let kernel = b_error(r, scene, mlt::BOOTSTRAP).map(|e| e.0);
        table.checks.push(Check {
            claim: format!(
                "{scene}: more bootstrap samples estimate the brightness better, at a considerable overhead (003:L330)"
            ),
            evidence: format!(
                "measured over {RUNS} runs: b's RMS error {} at {} a pixel, {} at 16 (the kernel's), {} at {} \
                 ({} bdpt frames of start-up); holds if it falls by at least half the 1/sqrt law's {:.0}x",
                first.map_or("–".into(), |e| format!("{:.1} %", 100.0 * e)),
                COUNTS[0],
                kernel.map_or("–".into(), |e| format!("{:.1} %", 100.0 * e)),
                last.map_or("–".into(), |e| format!("{:.2} %", 100.0 * e)),
                COUNTS[COUNTS.len() - 1],
                COUNTS[COUNTS.len() - 1] / SAMPLES_PER_FRAME,
                ((COUNTS[COUNTS.len() - 1] / COUNTS[0]) as f64).sqrt()
            ),
            holds: first
                .zip(last)
                .is_some_and(|(f, l)| l * 0.5 * ((COUNTS[COUNTS.len() - 1] / COUNTS[0]) as f64).sqrt() <= f),
        });
    }
    table.notes.push(format!(
        "Ours: b = the mean luminance (Y = 0.212671 R + 0.715160 G + 0.072169 B, 003:L322) of k x W x H bootstrap \
         samples (bdpt large steps; mlt::bootstrap_luminances, the kernel's mlt_init for k = 16), {} at {SIDE} x \
         {SIDE}, {} bounces, {RUNS} runs (seeds {SEED0}-{}), against the Mitsuba reference's mean luminance \
         (tests/fixtures/mitsuba/). 'RMS x sqrt(samples)' is constant where the error falls as 1/sqrt(k); \
         the start-up costs k / 4 bdpt frames (a frame traces 4 paths a pixel). Fixtures: docs/fixtures.md.",
        scenes.iter().map(|s| format!("`scenes/{s}.toml`")).collect::<Vec<_>>().join(" and "),
        fig_9::BOUNCES,
        SEED0 + RUNS - 1
    ));
    vec![table]
}

/// Measurement group of the large-step study.
pub const LARGE_STEP_GROUP: &str = "lin/mlt-large-step";

/// The large-step probabilities measured (the kernel's: 0.25, 003:L318's example).
pub const LARGE_STEPS: [f32; 5] = [0.05, 0.1, 0.25, 0.5, 1.0];

/// The study's scenes: a diffuse box, one with a glossy back wall and one
/// with a caustic (the tall box smooth glass).
pub const LARGE_STEP_SCENES: [&str; 3] = ["cornell-lambert", "cornell-rough", "cornell-caustic"];

/// The intricate effect of each scene that has one: the material whose
/// pixels (the camera ray's first hit) the region error is taken over.
pub const INTRICATE: [(&str, &str, &str); 2] =
    [("cornell-rough", "roughMirror", "the glossy back wall"), ("cornell-caustic", "clearGlass", "the glass box")];

/// Frames a run: the thesis' 100 (of one mutation a chain; ours 4 a frame).
pub const LARGE_STEP_FRAMES: u32 = 25;

/// Measurement group [`LARGE_STEP_GROUP`]: per large-step probability
/// (variant `p0.25`) and run `r`, the image's RMS error against the truth
/// after [`LARGE_STEP_FRAMES`] frames with its brightness (b) removed,
/// `noise_r{r}`, and on the scenes of [`INTRICATE`] the same over the
/// pixels that see their intricate material, `region_r{r}`, and their
/// count, `region_pixels` (none is an error). Native: the
/// kernel's probability is a constant.
pub fn measure_large_step(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let scene = ws.scene;
    if !LARGE_STEP_SCENES.contains(&scene.name.as_str()) {
        return Err(format!("{}: the large-step study runs on {LARGE_STEP_SCENES:?} only", scene.name).into());
    }
    let truth = Reference::read(&Reference::default_prefix(&scene.name))?;
    let truth_y = mean_luminance(&truth.mean);
    let n = SIDE;
    if (truth.mean.width, truth.mean.height) != (n, n) {
        return Err(format!("{}: expected {n}x{n}", truth.prefix.display()).into());
    }
    let camera = Camera { resolution: [n, n], ..scene.camera };
    let tree = runs::sah_tree(scene);
    let ps = PathScene::new(scene, &tree)?;
    let region: Option<Vec<bool>> = INTRICATE
        .iter()
        .find(|(s, _, _)| *s == scene.name)
        .map(|(_, material, _)| {
            let mask: Vec<bool> =
                runs::first_hit_materials(scene, &camera, &tree).iter().map(|m| *m == Some(*material)).collect();
            if mask.contains(&true) {
                Ok(mask)
            } else {
                Err(format!("{}: the camera sees no {material}, the study's region", scene.name))
            }
        })
        .transpose()?;
    let frame = frame_of(&camera, eps_for(ps.lo, ps.hi));
    let mut out = Vec::new();
    for p_large in LARGE_STEPS {
        let variant = format!("p{p_large}");
        tick(Tick { frame: None, variant: &variant });
        let mut k = BTreeMap::new();
        for r in 0..RUNS {
            let p = runs::square(n, Integrator::Mlt, fig_9::BOUNCES, SEED0 + r);
            let tracer = Tracer { scene: &ps, frame, params: p };
            let chains = mlt::Chains { p_large, ..mlt::Chains::KERNEL };
            let img = mlt::render_target(&tracer, p, chains, LARGE_STEP_FRAMES, false, |_| {})?.image.image();
            let scaled = fig_9::scaled(&img, truth_y);
            k.insert(format!("noise_r{r}"), crate::repro::lin2017::convergence::rmse(&scaled, &truth.mean));
            if let Some(mask) = &region {
                k.insert(format!("region_r{r}"), runs::masked_rmse(&scaled, &truth.mean, |i| mask[i]));
            }
        }
        if let Some(mask) = &region {
            k.insert("region_pixels".into(), mask.iter().filter(|&&m| m).count() as f64);
        }
        out.push(Sample {
            group: LARGE_STEP_GROUP.into(),
            scene: scene.name.clone(),
            frame: None,
            variant,
            counters: k,
        });
    }
    Ok(out)
}

/// The RMS over runs of the brightness-removed error at large-step
/// probability `p`: over the image, or (`region`) the pixels of the scene's
/// intricate material.
fn large_step_noise(r: &Results, scene: &str, p: f32, region: bool) -> Option<f64> {
    let key = if region { "region" } else { "noise" };
    runs::rms((0..RUNS).map(|run| r.sum(LARGE_STEP_GROUP, scene, &format!("p{p}"), &format!("{key}_r{run}"))))
}

/// The large-step probability of least noise on `scene` (`region`: over its
/// intricate material's pixels).
pub fn best_large_step(r: &Results, scene: &str, region: bool) -> Option<f32> {
    LARGE_STEPS
        .iter()
        .map(|&p| large_step_noise(r, scene, p, region).map(|e| (p, e)))
        .collect::<Option<Vec<_>>>()?
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(p, _)| p)
}

/// The large-step table: a row per probability, a column per scene and per
/// intricate region.
pub fn render_large_step(e: &Entry, r: &Results) -> Vec<Table> {
    // (scene, region or not, column name)
    let mut cols: Vec<(&str, bool, String)> = Vec::new();
    for s in LARGE_STEP_SCENES {
        cols.push((s, false, format!("{s}: RMS error, brightness removed")));
        if let Some((_, _, what)) = INTRICATE.iter().find(|(x, _, _)| *x == s) {
            cols.push((s, true, format!("{s}: the same over {what}")));
        }
    }
    let columns = cols.iter().map(|(_, _, name)| Column::ours_only(name, Unit::Number(4))).collect();
    let rows = LARGE_STEPS
        .iter()
        .map(|&p| Row {
            label: format!("large steps {p}{}", if p == mlt::P_LARGE { " (the kernel's)" } else { "" }),
            kind: RowKind::Scene,
            cells: cols
                .iter()
                .map(|(s, region, _)| Cell { ours: large_step_noise(r, s, p, *region), ..Cell::default() })
                .collect(),
        })
        .collect();
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    let diffuse = best_large_step(r, LARGE_STEP_SCENES[0], false);
    let show = |p: Option<f32>| p.map_or("–".into(), |p| p.to_string());
    for (scene, _, what) in INTRICATE {
        for region in [false, true] {
            let intricate = best_large_step(r, scene, region);
            let pixels = r
                .sum(LARGE_STEP_GROUP, scene, &format!("p{}", mlt::P_LARGE), "region_pixels")
                .map_or("–".into(), |n| format!("{n:.0}"));
            let over = if region { format!("over {what} ({pixels} pixels)") } else { "over the image".into() };
            table.checks.push(Check {
                claim: format!(
                    "a larger large-step rate suits diffuse scenes, a smaller one intricate effects (003:L324): \
                     {scene}, {over}"
                ),
                evidence: format!(
                    "measured over {RUNS} runs of {LARGE_STEP_FRAMES} frames: the least error at large steps {} on \
                     the diffuse box (over the image), {} on {scene} {over} (holds if the diffuse box's is the larger)",
                    show(diffuse),
                    show(intricate)
                ),
                holds: diffuse.zip(intricate).is_some_and(|(d, g)| d > g),
            });
        }
    }
    table.notes.push(format!(
        "Ours: MLT over bdpt natively (mlt::render_target with mlt::Chains {{ p_large, start from the pool }}; the \
         kernel's probability is the constant 0.25), {} at {SIDE} x {SIDE}, {} bounces, {RUNS} runs (seeds {SEED0}-{}) of \
         {LARGE_STEP_FRAMES} frames (the thesis' 100 mutations a chain); the error: RMS over pixels and channels \
         against the Mitsuba reference with each image scaled to its mean luminance first (b's error removed: \
         lin:s4.8-bootstrap), the runs' mean square. Small steps: Kelemen's s1 = 1/1024, s2 = 1/64.",
        LARGE_STEP_SCENES.iter().map(|s| format!("`scenes/{s}.toml`")).collect::<Vec<_>>().join(", "),
        fig_9::BOUNCES,
        SEED0 + RUNS - 1
    ));
    vec![table]
}
