//! Thesis 003 Fig. 16 (003:L505-507): thread compaction's worked example.
//! A toy warp of 4 lanes, one block of 4 warps: before compaction 3 of the
//! 12 running threads are active ("25%" useful operations); grouped into one
//! warp, "75%", and "same amount of work can be done by 1/3 amount of
//! warps"; the block with one idle warp is at "75%" occupancy.
//!
//! The emulator's warps have 32 lanes, so every toy lane is 8 lanes: 128
//! paths of the Cornell box in 4 warps, warp 0 all ended, warps 1-3 with 8
//! active paths each. `path_level` runs one level over the 128 states, then
//! over the 24 states the compaction kernels moved to the front; the
//! emulator counts, at the `live` line, the active lanes and the warps that
//! issued the level's work. Both runs must leave the same radiance and the
//! same continuing states (the compaction kept the paths).

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::path::wavefront::{self, Compactor, Level, PATH_ACTIVE, STATE_FLOATS, THREADS};
use crate::host::path::{FrameParams, Integrator, PixelSampling, Termination, Traversal, kernel};
use crate::host::scene::Scene;
use crate::repro::compare::Tolerance;
use crate::repro::lin2017::runs;
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};
use crate::sim::{Arg, Counters, Fidelity, LaunchConfig};

/// Measurement group: the worked example on the emulator.
pub const EXAMPLE: &str = "lin/compaction-example";

/// The scene whose paths fill the example's states.
pub const SCENE: &str = "cornell-lambert";

/// Emulated lanes per toy lane (32 / 4).
pub const SCALE: u64 = 8;

/// Warps of the block.
pub const WARPS: u64 = 4;

/// The example counted.
#[derive(Debug, Clone, PartialEq)]
pub struct Example {
    /// The level over the 128 states as they are.
    pub before: Level,
    /// The level over the compacted 24.
    pub after: Level,
    /// Whether both left the same radiance and continuing states, bit for bit.
    pub same_radiance: bool,
}

impl Example {
    /// Warps with work over the block's warps (before compaction).
    pub fn occupancy(&self) -> f64 {
        self.before.busy_warps as f64 / self.before.warps as f64
    }
}

/// Whether state `j` of the example is active: warps 1-3, their first 8 lanes.
pub fn active(j: usize) -> bool {
    let (warp, lane) = (j / 32, j % 32);
    warp > 0 && (lane as u64) < SCALE
}

/// Runs the example on the Cornell box `scene`.
pub fn measure_on(scene: &Scene) -> Result<Example, MeasureError> {
    let ps = runs::path_scene(scene)?;
    // 8 x 4 pixels of 4 paths: 128 paths, 4 warps
    let params = FrameParams {
        width: 8,
        height: 4,
        integrator: Integrator::Nee,
        max_bounces: crate::host::path::DEFAULT_MAX_BOUNCES,
        seed: 0,
        traversal: Traversal::ShortStack,
        termination: Termination::Roulette,
        pixels: PixelSampling::Tent,
    };
    let camera = Camera { resolution: [8, 4], ..scene.camera };
    let n = params.paths();
    let (mut dev, module, compact) = wavefront::device(&params, Fidelity::Instructions)?;
    let bufs = kernel::upload_scene(&mut dev, &ps, &camera, &params)?;
    let states = dev.alloc_zeroed::<f32>(n * STATE_FLOATS);
    let packed = dev.alloc_zeroed::<f32>(n * STATE_FLOATS);
    let init = [Arg::Ptr(bufs.params), Arg::Ptr(states)];
    dev.launch(&module, "path_init", LaunchConfig::linear((n as u32).div_ceil(THREADS), THREADS), &init)?;
    let mut s = dev.read::<f32>(states, n * STATE_FLOATS);
    for j in (0..n).filter(|&j| !active(j)) {
        let w = &mut s[j * STATE_FLOATS + 15];
        *w = f32::from_bits(w.to_bits() & !PATH_ACTIVE);
    }
    dev.write(states, &s)?;
    dev.write(packed, &s)?;
    let live = wavefront::live_tag();
    let out = |dev: &mut crate::sim::Device| [dev.alloc_zeroed::<f32>(n * 3), dev.alloc_zeroed::<f32>(n * 3)];
    let (out_a, out_b) = (out(&mut dev), out(&mut dev));
    let mut totals = Counters::default();
    let before = wavefront::level(&mut dev, &module, &bufs, states, n as u32, out_a, &live, &mut totals)?;
    let compacted = dev.alloc_zeroed::<f32>(n * STATE_FLOATS);
    let (k, _) = Compactor::new(&mut dev, n).compact(&mut dev, &compact, packed, compacted, n as u32)?;
    let after = wavefront::level(&mut dev, &module, &bufs, compacted, k, out_b, &live, &mut totals)?;
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let (ra, rb) = (dev.read::<f32>(out_a[0], n * 3), dev.read::<f32>(out_b[0], n * 3));
    let (sa, sb) = (dev.read::<f32>(states, n * STATE_FLOATS), dev.read::<f32>(compacted, n * STATE_FLOATS));
    let kept = (0..n)
        .filter(|&j| active(j))
        .enumerate()
        .all(|(slot, j)| same(&sa[j * STATE_FLOATS..][..STATE_FLOATS], &sb[slot * STATE_FLOATS..][..STATE_FLOATS]));
    Ok(Example {
        before,
        after,
        same_radiance: same(&ra, &rb) && kept && k as usize == (0..n).filter(|&j| active(j)).count(),
    })
}

/// Runs the example on `scenes/cornell-lambert.toml`.
pub fn measure() -> Result<Example, MeasureError> {
    let path = crate::host::scene_file::resolve(SCENE);
    let scene = crate::host::scene_file::load(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    measure_on(&scene)
}

/// Measurement group [`EXAMPLE`].
pub fn measure_group(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    tick(Tick { frame: None, variant: "example" });
    let e = measure_on(ws.scene)?;
    let mut out = Vec::new();
    for (v, l) in [("before", e.before), ("after", e.after)] {
        let mut m = BTreeMap::new();
        m.insert("threads".to_string(), l.threads as f64);
        m.insert("warps".to_string(), l.warps as f64);
        m.insert("busy_warps".to_string(), l.busy_warps as f64);
        m.insert("active".to_string(), l.active as f64);
        m.insert("same_radiance".to_string(), e.same_radiance as u8 as f64);
        out.push(Sample {
            group: EXAMPLE.into(),
            scene: ws.scene.name.clone(),
            frame: None,
            variant: v.into(),
            counters: m,
        });
    }
    Ok(out)
}

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let get = |v: &str, n: &str| r.sum(EXAMPLE, SCENE, v, n);
    let exact = Tolerance::Points(0.0);
    let columns = vec![
        Column::measured("running threads (toy)", Unit::Count, Tolerance::Relative(0.0)),
        Column::measured("warps with work", Unit::Count, Tolerance::Relative(0.0)),
        Column::measured("useful lanes", Unit::Percent, exact),
        Column::ours_only("active lanes (emulated)", Unit::Count),
        Column::ours_only("lanes of warps with work (emulated)", Unit::Count),
    ];
    let mut rows = Vec::new();
    let mut fractions = Vec::new();
    for (v, label, printed) in
        [("before", "before compaction", ["12", "3", "25%"]), ("after", "after compaction", ["4", "1", "75%"])]
    {
        let busy = get(v, "busy_warps");
        let active = get(v, "active");
        let frac = busy.zip(active).map(|(b, a)| 100.0 * a / (32.0 * b).max(1.0));
        fractions.push(frac);
        let running = busy.map(|b| b * 32.0 / SCALE as f64);
        let ours = [running, busy, frac];
        let mut cells: Vec<Cell> =
            ours.iter().zip(printed).zip(&columns).map(|((o, p), c)| Cell::compared(*o, p, c.tolerance)).collect();
        cells.push(Cell { ours: active, ..Cell::default() });
        cells.push(Cell { ours: busy.map(|b| 32.0 * b), ..Cell::default() });
        rows.push(Row { label: label.into(), kind: RowKind::Scene, cells });
    }
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    let occ = get("before", "busy_warps").zip(get("before", "warps")).map(|(b, w)| 100.0 * b / w);
    table.checks.push(Check {
        claim: "a block of 4 warps with one inactive warp is at 75% occupancy (003:L507)".into(),
        evidence: format!("warps with work / warps launched = {}", occ.map_or("–".into(), |o| format!("{o:.1}%"))),
        holds: occ == Some(75.0),
    });
    table.checks.push(Check {
        claim: "the same work is done by 1/3 of the warps, and the paths are unchanged by the compaction".into(),
        evidence: format!(
            "warps with work {} -> {}; radiance and continuing states bit-identical: {}",
            get("before", "busy_warps").unwrap_or(f64::NAN),
            get("after", "busy_warps").unwrap_or(f64::NAN),
            get("before", "same_radiance") == Some(1.0)
        ),
        holds: get("before", "busy_warps") == Some(3.0)
            && get("after", "busy_warps") == Some(1.0)
            && get("before", "same_radiance") == Some(1.0),
    });
    table.notes.push(
        "Counted by the emulator: one level of the path tracer's wavefront form (`path_level`, \
         kernels/lin2017/path.cu) over 128 states of Cornell-box paths with warp 0 ended and 8 of 32 lanes active in \
         warps 1-3 (the toy's 4-lane warps scaled by 8: each toy lane is 8 lanes), then over the 24 states the \
         flag-scan-scatter kernels (kernels/lin2017/compact.cu) moved to the front. Active lanes and warps with work \
         are the lanes and warp issues of the `@count live` line (the first load of an active state). Running \
         threads (toy) = lanes of the warps with work / 8."
            .into(),
    );
    vec![table]
}
