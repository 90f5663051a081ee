//! Thesis 003 Fig. 17 (003:L512-534): "Frame rate as the function of max
//! trace depth, for program with and without thread compaction", the
//! standard Cornell box with next-event estimation, 1,048,576 paths a frame
//! on a GTX 960M, max depths 1-10, 20, 50, 100.
//!
//! Ours: the wavefront form of the path tracer (`host::path::wavefront`) on
//! the emulator, one frame per max depth D (D levels of the inner loop: the
//! kernel's longest path D - 1 bounces), with the flag-scan-scatter
//! compaction between levels and without it. Frame rates are not
//! reproducible (the GPU is not emulated); the ratio compact / normal is
//! modelled as the ratio of the warp instructions the emulator issued for the
//! whole frame (camera rays, every level, and the compaction kernels; no
//! parameter fitted) and compared with the ratio of the printed rates. The
//! counts behind it are measured: per level, the active paths and the useful
//! lanes of the warps that issued the level's work.

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::path::Integrator;
use crate::host::path::wavefront::{self, Mode, WavefrontRender};
use crate::host::scene::Scene;
use crate::repro::compare::Tolerance;
use crate::repro::lin2017::runs;
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};
use crate::sim::Fidelity;

/// Measurement group: both modes at every max depth, emulated.
pub const DEPTHS_GROUP: &str = "lin/compaction-depth";

/// The scene: "standard Cornell box rendering with next event estimation" (003:L512).
pub const SCENE: &str = "cornell-lambert";

/// The longest image side the group emulates.
pub const MAX_SIDE: u32 = 32;

/// Fig. 17 as printed (003:L516-530): max depth, compact fps, normal fps.
pub const PRINTED: [(u32, &str, &str); 13] = [
    (1, "26.74", "48.53"),
    (2, "19.07", "24.23"),
    (3, "17.74", "15.72"),
    (4, "17.56", "12.07"),
    (5, "17.17", "9.73"),
    (6, "16.05", "7.96"),
    (7, "15.99", "7.14"),
    (8, "16.12", "6.04"),
    (9, "16.23", "5.58"),
    (10, "16.09", "5.27"),
    (20, "15.12", "2.84"),
    (50, "15.28", "1.88"),
    (100, "15.56", "1.9"),
];

/// The variant key of a run.
pub fn variant(mode: Mode, depth: u32) -> String {
    format!("{}/{depth}", mode.name())
}

fn side(ws: &Workspace) -> u32 {
    ws.resolution.clamp(8, MAX_SIDE)
}

/// The deepest max depth printed.
fn deepest() -> u32 {
    PRINTED[PRINTED.len() - 1].0
}

/// One emulated frame of the wavefront form on `scene` at `side` x `side`
/// pixels with next-event estimation, `depth` levels (the longest path
/// `depth` − 1 bounces), compacted or not: the run behind every cell of the
/// table and the per-level chart (`warplight chart lin-compaction`).
pub fn run(scene: &Scene, side: u32, depth: u32, mode: Mode) -> Result<WavefrontRender, MeasureError> {
    let camera = Camera { resolution: [side, side], ..scene.camera };
    let ps = runs::path_scene(scene)?;
    let params = runs::square(side, Integrator::Nee, depth.saturating_sub(1), 0);
    let (mut dev, m, c) = wavefront::device(&params, Fidelity::Instructions)?;
    Ok(wavefront::render(&mut dev, &m, &c, &ps, &camera, params, 1, mode, false, |_| {})?)
}

/// Measurement group [`DEPTHS_GROUP`].
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let scene = ws.scene;
    let n = side(ws);
    let mut out = Vec::new();
    for mode in Mode::ALL {
        for (depth, _, _) in PRINTED {
            let v = variant(mode, depth);
            tick(Tick { frame: None, variant: &v });
            let paths = (n * n * crate::host::path::SAMPLES_PER_FRAME) as usize;
            let r = run(scene, n, depth, mode)?;
            let mut k = BTreeMap::new();
            k.insert("paths".to_string(), paths as f64);
            k.insert("warp_instructions".to_string(), r.totals.warp_instructions as f64);
            k.insert("thread_instructions".to_string(), r.totals.thread_instructions as f64);
            k.insert("compaction_warp_instructions".to_string(), r.compaction.warp_instructions as f64);
            k.insert("global_loads".to_string(), r.totals.loads.global as f64);
            k.insert("global_stores".to_string(), r.totals.stores.global as f64);
            if depth == deepest() {
                for (l, lv) in r.levels.iter().enumerate() {
                    k.insert(format!("level_{l}_active"), lv.active as f64);
                    k.insert(format!("level_{l}_busy_warps"), lv.busy_warps as f64);
                    k.insert(format!("level_{l}_threads"), lv.threads as f64);
                    k.insert(format!("level_{l}_warp_instructions"), lv.warp_instructions as f64);
                }
            }
            out.push(Sample {
                group: DEPTHS_GROUP.into(),
                scene: scene.name.clone(),
                frame: None,
                variant: v,
                counters: k,
            });
        }
    }
    Ok(out)
}

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let get = |mode: Mode, depth: u32, n: &str| r.sum(DEPTHS_GROUP, SCENE, &variant(mode, depth), n);
    let model = "frame time proportional to the warp instructions the emulator issued for the frame (camera rays, \
                 every level, the compaction kernels; no parameter fitted)";
    let columns = vec![
        Column::not_reproducible("Compact (fps)", Unit::Number(2), "frames per second of a GTX 960M"),
        Column::not_reproducible("Normal (fps)", Unit::Number(2), "as Compact (fps)"),
        Column::modelled("compact vs normal", Unit::Change, model, Some(Tolerance::RATIO), None),
        Column::ours_only("active paths entering level D", Unit::Count),
        Column::ours_only("useful lanes at level D, normal", Unit::Percent),
        Column::ours_only("useful lanes at level D, compact", Unit::Percent),
    ];
    let deep = deepest();
    let level = |mode: Mode, l: u32, n: &str| get(mode, deep, &format!("level_{l}_{n}"));
    let useful = |mode: Mode, l: u32| -> Option<f64> {
        let (a, b) = (level(mode, l, "active")?, level(mode, l, "busy_warps")?);
        (b > 0.0).then(|| 100.0 * a / (32.0 * b))
    };
    let mut rows = Vec::new();
    let mut modelled: Vec<(u32, f64, f64)> = Vec::new();
    for (depth, c, n) in PRINTED {
        let (tc, tn): (f64, f64) = (c.parse().unwrap_or(f64::NAN), n.parse().unwrap_or(f64::NAN));
        let thesis = (tc / tn - 1.0) * 100.0;
        let ours =
            match (get(Mode::Normal, depth, "warp_instructions"), get(Mode::Compacted, depth, "warp_instructions")) {
                (Some(wn), Some(wc)) if wc > 0.0 => Some((wn / wc - 1.0) * 100.0),
                _ => None,
            };
        if let Some(o) = ours {
            modelled.push((depth, o, thesis));
        }
        let shown = |t: &str| Cell { thesis: Some(t.into()), thesis_value: t.parse().ok(), ..Cell::default() };
        let cells = vec![
            shown(c),
            shown(n),
            Cell {
                ours,
                thesis: Some(format!("{} (derived)", Unit::Change.format(thesis))),
                thesis_value: Some(thesis),
                verdict: ours.map(|o| Tolerance::RATIO.verdict(o, thesis)),
            },
            Cell { ours: level(Mode::Compacted, depth - 1, "active"), ..Cell::default() },
            Cell { ours: useful(Mode::Normal, depth - 1), ..Cell::default() },
            Cell { ours: useful(Mode::Compacted, depth - 1), ..Cell::default() },
        ];
        rows.push(Row { label: format!("max depth {depth}"), kind: RowKind::Scene, cells });
    }
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    if modelled.len() == PRINTED.len() {
        let cross = modelled.iter().find(|m| m.1 > 0.0).map(|m| m.0);
        table.checks.push(Check {
            claim: "compaction is slower at depths 1-2 and overtakes at depth 3 (003:L532-534)".into(),
            evidence: format!(
                "modelled: compaction first faster at max depth {}",
                cross.map_or("never".into(), |d| d.to_string())
            ),
            holds: cross == Some(3),
        });
        let time = |d: u32| get(Mode::Compacted, d, "warp_instructions").unwrap_or(f64::NAN);
        let ours = (time(deep) / time(5) - 1.0) * 100.0;
        let thesis = (17.17 / 15.56 - 1.0) * 100.0;
        table.checks.push(Check {
            claim: "with compaction the frame time is almost stable after depth 5 (003:L534)".into(),
            evidence: format!(
                "modelled compact frame time, depth {deep} vs 5: {ours:+.1}% (thesis, from the rates: {thesis:+.1}%; {})",
                Tolerance::RATIO.describe()
            ),
            holds: Tolerance::RATIO.verdict(ours, thesis) == crate::repro::compare::Verdict::Within,
        });
    }
    let paths = get(Mode::Normal, 1, "paths");
    let last_live = (0..deep).take_while(|&l| level(Mode::Compacted, l, "active").is_some_and(|a| a > 0.0)).last();
    if let Some(l) = last_live {
        table.checks.push(Check {
            claim: "without compaction all threads become inactive \"probably between 20 and 30\" (003:L532)".into(),
            evidence: format!(
                "measured: the last path ends at level {} of {} paths (the thesis traces 1,048,576; more paths reach \
                 deeper)",
                l + 1,
                paths.unwrap_or(f64::NAN)
            ),
            holds: (20..=30).contains(&(l + 1)),
        });
    }
    table.notes.push(format!(
        "Ours: {} paths a frame (the thesis: 1,048,576) of `scenes/cornell-lambert.toml` with next-event estimation \
         and Russian roulette, one frame per max depth D and mode; D levels of the inner loop = the kernel's longest \
         path D - 1 bounces (the last level traces and gathers emission without a light sample; docs/fixtures.md). \
         Normal: every level launches a thread per path (the threads of ended paths return at once); compact: the \
         flag-scan-scatter kernels (kernels/lin2017/compact.cu, the thesis' thrust::remove_if) between levels. Both \
         trace the same paths bit for bit (tests/lin2017_compaction.rs).",
        paths.unwrap_or(f64::NAN)
    ));
    table.notes.push(format!(
        "Modelled column: {model}, as (normal / compact − 1), against the printed rates' (compact / normal − 1); \
         tolerance {}. Measured columns from the max-depth-{deep} runs: the paths entering level D and the active \
         lanes over the lanes of the warps that issued the level's work (the `@count live` line of `path_level`).",
        Tolerance::RATIO.describe()
    ));
    vec![table]
}
