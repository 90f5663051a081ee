//! Thesis 003 §6.3's regroup by Fresnel branch (003:L536): "we can also use
//! stream compaction to do a rearrangement of threads such that threads that
//! will be running the same Fresnel branch in next iteration are grouped
//! together. The number of stream compaction operations will be equal to the
//! number of Fresnel branches (which in our case is 3). By using double
//! buffering, the results of stream compaction can be copied or appended to
//! another array. After generating the resorted array, the indices for the
//! buffers are swapped. In our experiment with a simple scene adapted from
//! the Cornell box with glossy reflection, diffuse reflection and caustics,
//! up to 30% speedup can be achieved from regrouping the threads."
//!
//! Ours: the regroup's wavefront form (`host::path::regroup`) on the
//! emulator, one frame of `scenes/cornell-glossy.toml` with next-event
//! estimation, with the plain compaction (the thesis' form before the
//! regroup), with the three compactions, and with none. The speedup is not
//! reproducible as time (no GPU is emulated); it is modelled as the ratio of
//! the warp instructions of the whole frame (camera rays, traces, shades and
//! every compaction kernel: the regroup pays for its own three passes), with
//! no parameter. Measured beside it: the shade kernel's divergent branches
//! and lane utilisation, the divergence the regroup is meant to remove.

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::path::Integrator;
use crate::host::path::regroup::{self, Mode};
use crate::host::path::wavefront;
use crate::repro::compare::Tolerance;
use crate::repro::lin2017::runs;
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};
use crate::sim::Fidelity;

/// Measurement group: the three modes, emulated.
pub const REGROUP_GROUP: &str = "lin/fresnel-regroup";

/// The scene: "a simple scene adapted from the Cornell box with glossy
/// reflection, diffuse reflection and caustics" (003:L536).
pub const SCENE: &str = "cornell-glossy";

/// The same box in the thesis' own material model: its diffuse walls coated
/// (§4.5: every such hit takes the Fresnel switch's specular or diffuse
/// branch, which `regroup_trace` draws ahead).
pub const COATED_SCENE: &str = "cornell-glossy-coated";

/// The table's scenes, in its order.
pub const SCENES: [&str; 2] = [SCENE, COATED_SCENE];

/// The longest image side the group emulates.
pub const MAX_SIDE: u32 = 32;

/// The claim as printed (003:L536).
pub const PRINTED: &str = "up to 30%";

/// Measurement group [`REGROUP_GROUP`].
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let scene = ws.scene;
    let n = ws.resolution.clamp(8, MAX_SIDE);
    let camera = Camera { resolution: [n, n], ..scene.camera };
    let ps = runs::path_scene(scene)?;
    let params = runs::square(n, Integrator::Nee, 16, 0);
    let mut out = Vec::new();
    let mut first: Option<Vec<f32>> = None;
    for mode in Mode::ALL {
        tick(Tick { frame: None, variant: mode.name() });
        let (mut dev, m, c) = wavefront::device(&params, Fidelity::Instructions)?;
        let r = regroup::render(&mut dev, &m, &c, &ps, &camera, params, 1, mode, false, |_| {})?;
        let same = match &first {
            None => {
                first = Some(r.image.accum.clone());
                true
            }
            Some(a) => a.iter().zip(&r.image.accum).all(|(x, y)| x.to_bits() == y.to_bits()),
        };
        let mut k = BTreeMap::new();
        k.insert("paths".to_string(), params.paths() as f64);
        k.insert("warp_instructions".to_string(), r.totals.warp_instructions as f64);
        k.insert("thread_instructions".to_string(), r.totals.thread_instructions as f64);
        k.insert("compaction_warp_instructions".to_string(), r.compaction.warp_instructions as f64);
        k.insert("trace_warp_instructions".to_string(), r.trace.warp_instructions as f64);
        k.insert("shade_warp_instructions".to_string(), r.shade.warp_instructions as f64);
        k.insert("shade_thread_instructions".to_string(), r.shade.thread_instructions as f64);
        k.insert("shade_branches".to_string(), r.shade.branches as f64);
        k.insert("shade_divergent_branches".to_string(), r.shade.divergent_branches as f64);
        k.insert("same_image".to_string(), same as u8 as f64);
        for (b, (_, name)) in regroup::BRANCHES.iter().enumerate() {
            k.insert(format!("branch_{name}"), r.per_branch[b] as f64);
        }
        out.push(Sample {
            group: REGROUP_GROUP.into(),
            scene: scene.name.clone(),
            frame: None,
            variant: mode.name().into(),
            counters: k,
        });
    }
    Ok(out)
}

/// The table: per scene of [`SCENES`] its three modes, the regroup's row
/// with the modelled speedup against the printed bound.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let model = "frame time proportional to the warp instructions the emulator issued for the frame (camera rays, \
                 traces, shades and every compaction kernel; no parameter fitted)";
    let columns = vec![
        Column::modelled("speedup from regrouping", Unit::Change, model, Some(Tolerance::RATIO), None),
        Column::ours_only("warp instructions, frame", Unit::Count),
        Column::ours_only("of them compaction", Unit::Count),
        Column::ours_only("shade: divergent branches", Unit::Count),
        Column::ours_only("shade: useful lanes", Unit::Percent),
        Column::ours_only("shade: warp instructions", Unit::Count),
    ];
    let mut table = Table {
        address: e.address(),
        heading: e.heading(),
        columns,
        rows: Vec::new(),
        checks: Vec::new(),
        notes: Vec::new(),
    };
    for scene in SCENES {
        let get = |mode: Mode, n: &str| r.sum(REGROUP_GROUP, scene, mode.name(), n);
        let warps = |m: Mode| get(m, "warp_instructions");
        let speedup = match (warps(Mode::Compacted), warps(Mode::Regrouped)) {
            (Some(c), Some(g)) if g > 0.0 => Some((c / g - 1.0) * 100.0),
            _ => None,
        };
        let lanes = |m: Mode| {
            get(m, "shade_thread_instructions")
                .zip(get(m, "shade_warp_instructions"))
                .map(|(t, w)| 100.0 * t / (32.0 * w).max(1.0))
        };
        let prefix = format!("{scene}: ");
        for (mode, label) in [
            (Mode::Normal, "no compaction"),
            (Mode::Compacted, "compaction (without regrouping)"),
            (Mode::Regrouped, "regroup: 3 compactions by Fresnel branch"),
        ] {
            let first = if mode == Mode::Regrouped {
                // "up to 30%": the bound the thesis observed, compared as +30 %
                Cell {
                    ours: speedup,
                    thesis: Some(PRINTED.into()),
                    thesis_value: Some(30.0),
                    verdict: speedup.map(|s| Tolerance::RATIO.verdict(s, 30.0)),
                }
            } else {
                Cell::default()
            };
            let cells = vec![
                first,
                Cell { ours: warps(mode), ..Cell::default() },
                Cell { ours: get(mode, "compaction_warp_instructions"), ..Cell::default() },
                Cell { ours: get(mode, "shade_divergent_branches"), ..Cell::default() },
                Cell { ours: lanes(mode), ..Cell::default() },
                Cell { ours: get(mode, "shade_warp_instructions"), ..Cell::default() },
            ];
            table.rows.push(Row { label: format!("{prefix}{label}"), kind: RowKind::Scene, cells });
        }
        let div = |m: Mode| get(m, "shade_divergent_branches");
        table.checks.push(Check {
            claim: format!(
                "{prefix}regrouping by the next Fresnel branch removes thread divergence in shading (003:L265, L536)"
            ),
            evidence: format!(
                "measured: the shade kernel's divergent branches {} with compaction, {} regrouped; useful lanes {} -> {}",
                div(Mode::Compacted).map_or("–".into(), |d| format!("{d:.0}")),
                div(Mode::Regrouped).map_or("–".into(), |d| format!("{d:.0}")),
                lanes(Mode::Compacted).map_or("–".into(), |l| format!("{l:.1}%")),
                lanes(Mode::Regrouped).map_or("–".into(), |l| format!("{l:.1}%")),
            ),
            holds: div(Mode::Compacted).zip(div(Mode::Regrouped)).is_some_and(|(c, g)| g < c),
        });
        table.checks.push(Check {
            claim: format!("{prefix}regrouping speeds the frame up, by at most 30% (003:L536: \"up to 30% speedup\")"),
            evidence: format!(
                "modelled by warp instructions, the regroup's own passes included: {}",
                speedup.map_or("–".into(), |s| format!("{s:+.1}%"))
            ),
            holds: speedup.is_some_and(|s| s > 0.0 && s <= 30.0),
        });
        let same = [Mode::Compacted, Mode::Regrouped].iter().all(|&m| get(m, "same_image") == Some(1.0));
        table.checks.push(Check {
            claim: format!("{prefix}the rearrangement leaves the image unchanged"),
            evidence: format!("measured: accumulation buffers of the three modes bit-identical: {same}"),
            holds: same,
        });
    }
    let branch = |scene: &str, n: &str| {
        r.sum(REGROUP_GROUP, scene, Mode::Regrouped.name(), &format!("branch_{n}")).unwrap_or(f64::NAN)
    };
    let per_branch = |scene: &str| {
        format!(
            "specular {:.0}, diffuse {:.0}, transmission {:.0}",
            branch(scene, "specular"),
            branch(scene, "diffuse"),
            branch(scene, "transmission")
        )
    };
    table.notes.push(format!(
        "Ours: {} paths, one frame of `scenes/cornell-glossy.toml` (tall box rough glass, short box rough gold \
         mirror, back wall a smooth mirror; docs/fixtures.md) with next-event estimation, 16 bounces, on the \
         emulator. A level is `regroup_trace` (the next ray traced, the branch of its hit stored), the states \
         arranged, then `regroup_shade` (kernels/lin2017/path.cu). Compaction: one flag-scan-scatter pass of the \
         active states (from the second level on); regroup: three, one per branch (specular: mirror and rough \
         mirror; diffuse, with the paths whose next hit is a light or nothing; transmission: glass), appended into \
         the second buffer, which is then swapped in (kernels/lin2017/compact.cu). States per branch over the \
         frame: {}.",
        r.sum(REGROUP_GROUP, SCENE, Mode::Normal.name(), "paths").unwrap_or(f64::NAN),
        per_branch(SCENE),
    ));
    table.notes.push(format!(
        "`{COATED_SCENE}`: the same box with its diffuse walls in the thesis' own material model (§4.5, the coated \
         diffuse: a coat's Schlick switch between its mirror reflection and Ashikhmin and Shirley's lobe), so that \
         every wall hit takes a Fresnel branch as the thesis' shading does; `regroup_trace` draws a coat's switch \
         ahead of the shading (specular group for the coat's reflection). States per branch: {}.",
        per_branch(COATED_SCENE),
    ));
    table.notes.push(format!(
        "Modelled column: {model}, as (compaction / regroup − 1) against the printed \"{PRINTED}\" (an upper bound \
         the thesis observed on its GPU; tolerance {}). Shade columns: the emulator's counters of the \
         `regroup_shade` launches (divergent branches; useful lanes = thread instructions / (32 × warp \
         instructions)).",
        Tolerance::RATIO.describe()
    ));
    vec![table]
}
