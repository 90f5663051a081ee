//! Thesis 000 Table 6.5 (seed 000, L2829–2853): global memory accesses during
//! node traversal, instructions per ray and frame rates with the compact BVH
//! (C) relative to the complete BVH of [AL09] (B), for ray tracing.
//!
//! Measured on the emulator: the SAH BVH over each scene's triangles
//! ([`super::sah::Params::SCENE`], L2800), laid out as B and C
//! ([`super::scene_bvh`]), traversed by `scenebvh.cu` for every ray of each
//! frame of the flight: up to four rays per pixel as part (b) traces them
//! ("primary, reflection and shadow rays", L2845), spawned at the hits of
//! the kd-tree caster (the same hits, `tests/scene_bvh.rs`). Node accesses,
//! stack pushes and pops are the executions of the kernels' `@count` lines;
//! the bytes are the emulator's memory model's read-only (pairs) and local
//! (stack) traffic, so Bytes_B = 28·NodeAcc + 4·(pushes + pops) and Bytes_C =
//! 16·NodeAcc + 12·(pushes + pops) are checked on its counters, not assumed.
//! Instructions are warp instructions × 32 per ray of the traversal kernel
//! alone. The register cap of 64 (L2825) is applied by the spill model of
//! [`super::spills`] to each kernel's PTX, its spill traffic counted as local
//! memory traffic from the launch's per-instruction counts.
//!
//! Part (a) (the older code base: primary rays and a shadow ray where one
//! hits, at 1024 × 1024 in the thesis) runs the same way with its baseline as
//! the table describes it (`trace_complete_ta`: primary rays stack the pair
//! with t_a, 8 bytes, and skip entries beyond the hit; shadow rays stack the
//! pair, 4 bytes), its bytes checked as B 28·NodeAcc + 4·(pushes + pops) +
//! 4·(t_a words) and C as in (b).

use super::pm_layout::{self, Layout, change};
use super::scene_bvh::{self, Rays, SceneBvh, Traversal};
use super::scenes_of;
use super::spills;
use super::timing;
use crate::host::kdtree::Heuristic;
use crate::host::raycast::Caster;
use crate::repro::compare::{Printed as P, Tolerance, mean_sd};
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Check, Column, Published, PublishedRow as Row, Table, Unit};
use crate::sim::Device;

/// Group: the B and C ray traversals of part (b) on the emulator over the flight.
pub const SCENE_BVH: &str = "fabianowski/scene-bvh";
/// Group: the B and C ray traversals of part (a) (primary and shadow rays, t_a stacked by B).
pub const SCENE_BVH_A: &str = "fabianowski/scene-bvh-a";

/// The five scenes of Table 6.5, in its order.
pub const SCENES: [&str; 5] = ["scene6", "sponza", "sibenik", "fairy", "conference"];

/// The register cap of the compact kernel (L2825).
pub const REGISTER_CAP: u32 = 64;

/// The baseline's registers: "The rendering kernel uses 61 registers in the
/// baseline" (L2825); the compact kernel runs at [`REGISTER_CAP`].
pub const REGISTERS_B: u32 = 61;

/// The stage name of a frame's timing counters in the samples: the traversal
/// kernel's counters with the spill traffic at the cap added as DRAM bytes,
/// `render.` + [`crate::timing::KernelCounts::counters`]' names.
pub const FRAME: &str = "render";

/// Table 6.5 (b) as printed: Nodes, Node accesses, Stack accesses, Bytes B,
/// Bytes C, Instr. B, Instr. C, FPS B, FPS C.
pub const THESIS_B: Published = Published {
    rows: &[
        Row {
            scene: "scene6",
            cells: &[
                P("582"),
                P("16.99"),
                P("4.04"),
                P("508.2"),
                P("−27.5%"),
                P("1213.2"),
                P("+36.4%"),
                P("242.5"),
                P("−9.1%"),
            ],
        },
        Row {
            scene: "sponza",
            cells: &[
                P("46942"),
                P("53.10"),
                P("10.10"),
                P("1567.5"),
                P("−32.9%"),
                P("3242.0"),
                P("+33.6%"),
                P("163.1"),
                P("−6.2%"),
            ],
        },
        Row {
            scene: "sibenik",
            cells: &[
                P("56870"),
                P("70.66"),
                P("13.28"),
                P("2084.8"),
                P("−32.1%"),
                P("4276.5"),
                P("+37.1%"),
                P("111.9"),
                P("−6.5%"),
            ],
        },
        Row {
            scene: "fairy",
            cells: &[
                P("97086"),
                P("51.83"),
                P("8.91"),
                P("1522.4"),
                P("−32.7%"),
                P("3573.5"),
                P("+34.1%"),
                P("145.4"),
                P("−9.2%"),
            ],
        },
        Row {
            scene: "conference",
            cells: &[
                P("149352"),
                P("43.45"),
                P("8.25"),
                P("1282.7"),
                P("−31.3%"),
                P("2843.7"),
                P("+35.4%"),
                P("172.4"),
                P("−6.6%"),
            ],
        },
    ],
    average: &[P(""), P(""), P(""), P(""), P("−31.3%"), P(""), P("+35.3%"), P(""), P("−7.5%")],
    std_dev: &[P(""), P(""), P(""), P(""), P("2.2%"), P(""), P("1.4%"), P(""), P("1.5%")],
};

/// Table 6.5 (a) as printed (same columns).
pub const THESIS_A: Published = Published {
    rows: &[
        Row {
            scene: "scene6",
            cells: &[
                P("582"),
                P("17.41"),
                P("4.39"),
                P("534.6"),
                P("−30.3%"),
                P("1386.4"),
                P("+16.1%"),
                P("88.0"),
                P("+0.1%"),
            ],
        },
        Row {
            scene: "sponza",
            cells: &[
                P("46942"),
                P("50.36"),
                P("10.09"),
                P("1488.2"),
                P("−35.4%"),
                P("3065.9"),
                P("+22.3%"),
                P("43.7"),
                P("+0.4%"),
            ],
        },
        Row {
            scene: "sibenik",
            cells: &[
                P("56870"),
                P("67.50"),
                P("13.14"),
                P("1999.9"),
                P("−35.0%"),
                P("3942.6"),
                P("+22.8%"),
                P("33.9"),
                P("+1.9%"),
            ],
        },
        Row {
            scene: "fairy",
            cells: &[
                P("97086"),
                P("49.14"),
                P("8.73"),
                P("1459.9"),
                P("−34.7%"),
                P("3166.0"),
                P("+21.1%"),
                P("42.2"),
                P("+0.5%"),
            ],
        },
        Row {
            scene: "conference",
            cells: &[
                P("149352"),
                P("41.85"),
                P("8.09"),
                P("1251.4"),
                P("−33.8%"),
                P("2618.7"),
                P("+21.7%"),
                P("49.8"),
                P("+1.3%"),
            ],
        },
    ],
    average: &[P(""), P(""), P(""), P(""), P("−33.8%"), P(""), P("+20.8%"), P(""), P("+0.8%")],
    std_dev: &[P(""), P(""), P(""), P(""), P("2.1%"), P(""), P("2.7%"), P(""), P("0.8%")],
};

/// One part of the table: its group, and its baseline's and C's variant names and traversals.
#[derive(Debug, Clone, Copy)]
struct Part {
    group: &'static str,
    variants: [(&'static str, Traversal); 2],
    /// The image side the thesis' frame rates are for.
    side: u32,
}

/// Part (b): the current code base's baseline (the pair alone on the stack) against C.
const PART_B: Part =
    Part { group: SCENE_BVH, variants: [("B", Traversal::Complete), ("C", Traversal::Compact)], side: 512 };
/// Part (a): the older code base's baseline (t_a stacked for primary rays) against C.
const PART_A: Part =
    Part { group: SCENE_BVH_A, variants: [("B", Traversal::CompleteTa), ("C", Traversal::Compact)], side: 1024 };

/// Measurement group [`SCENE_BVH`]: per frame and layout, part (b)'s rays
/// (primary, reflection and shadow), the traversal's counts, the traffic,
/// the warp instructions and the spill traffic under the register cap.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    measure_part(ws, tick, PART_B, Rays::WithReflections)
}

/// Measurement group [`SCENE_BVH_A`]: as [`measure`] for part (a): primary
/// rays and a shadow ray where one hits, the baseline stacking t_a.
pub fn measure_a(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    measure_part(ws, tick, PART_A, Rays::PrimaryShadow)
}

fn measure_part(
    ws: &mut Workspace,
    tick: &mut dyn FnMut(Tick),
    part: Part,
    rays: Rays,
) -> Result<Vec<Sample>, MeasureError> {
    ws.build(Heuristic::Siroh);
    let tree = ws.tree(Heuristic::Siroh);
    let bvh = SceneBvh::build(ws.scene);
    let caster = Caster::new(ws.scene, tree);
    let mut dev = Device::new();
    let module = scene_bvh::load(&mut dev)?;
    let mut out = Vec::new();
    for f in ws.frames.clone() {
        let cam = super::flight::camera(ws.scene, f, ws.resolution);
        let fr = scene_bvh::frame_rays(&caster, &cam, rays);
        for (name, traversal) in part.variants {
            tick(Tick { frame: Some(f), variant: name });
            let t = scene_bvh::trace_kernel_with(&mut dev, &module, &bvh, traversal, &fr.rays)
                .map_err(|e| format!("{}: {e}", ws.scene.name))?;
            let entry = traversal.entry();
            let fi = module.prog.functions.iter().position(|x| x.name == entry).ok_or("kernel not in the PTX")?;
            let func = &module.prog.functions[fi];
            let counts = &t.launch.profile.per_fn[fi];
            let plan = spills::plan(func, REGISTER_CAP, Some(counts.as_slice()));
            let (spill_ld, spill_st) = spills::traffic(func, &plan, counts);
            let c = [
                ("rays", fr.rays.len() as f64),
                ("primary", fr.stats.primary as f64),
                ("reflection", fr.stats.reflection as f64),
                ("shadow", fr.stats.shadow as f64),
                ("nodes", t.walk.nodes as f64),
                ("pushes", t.walk.pushes as f64),
                ("pops", t.walk.pops as f64),
                ("ta_words", t.ta_words as f64),
                ("tested", t.walk.retrieved as f64),
                ("node_bytes", t.traffic.nodes as f64),
                ("stack_bytes", t.traffic.stack as f64),
                ("warp_instructions", t.launch.totals.warp_instructions as f64),
                ("register_demand", plan.demand as f64),
                ("spilled_registers", plan.spilled.len() as f64),
                ("spill_bytes", (spill_ld + spill_st) as f64),
                ("bvh_nodes", bvh.nodes() as f64),
            ];
            let mut c: Vec<(String, f64)> = c.iter().map(|(n, v)| (n.to_string(), *v)).collect();
            // the frame's timing counters: the traversal, its spills at the cap as local (DRAM) traffic
            let mut frame = timing::counts_of(&module.prog, &t.launch, &t.memory);
            frame.dram_bytes += (spill_ld + spill_st) as f64;
            timing::record(&mut c, FRAME, &frame);
            out.push(Sample {
                group: part.group.into(),
                scene: ws.scene.name.clone(),
                frame: Some(f),
                variant: name.into(),
                counters: c.into_iter().collect(),
            });
        }
    }
    Ok(out)
}

/// Per-ray values of one layout of one scene.
#[derive(Debug, Clone, Copy)]
struct PerRay {
    nodes: f64,
    pushes: f64,
    bytes: f64,
    instructions: f64,
    spill: f64,
    demand: f64,
    /// The emulator's bytes equal the byte model exactly (every frame summed).
    exact: bool,
    /// Every pushed entry was popped (then 4·(pushes + pops) = 8·pushes for B).
    balanced: bool,
}

fn per_ray(r: &Results, part: Part, scene: &str, which: usize) -> Option<PerRay> {
    let (v, traversal) = part.variants[which];
    let g = |c: &str| r.sum(part.group, scene, v, c);
    let rays = g("rays")?;
    let (nodes, pushes, pops) = (g("nodes")?, g("pushes")?, g("pops")?);
    let ta_words = g("ta_words").unwrap_or(0.0);
    let (nb, sb) = (g("node_bytes")?, g("stack_bytes")?);
    let (per_node, per_entry) = match traversal.layout() {
        Layout::Complete => (28.0, 4.0),
        Layout::Compact => (16.0, 12.0),
    };
    let frames = r.samples.iter().filter(|s| s.group == part.group && s.scene == scene && s.variant == v).count();
    Some(PerRay {
        nodes: nodes / rays,
        pushes: pushes / rays,
        bytes: (nb + sb) / rays,
        instructions: g("warp_instructions")? * 32.0 / rays,
        spill: g("spill_bytes")? / rays,
        demand: g("register_demand")? / frames.max(1) as f64,
        exact: nb == per_node * nodes && sb == per_entry * (pushes + pops) + 4.0 * ta_words,
        balanced: pushes == pops,
    })
}

fn columns() -> Vec<Column> {
    let mut c = vec![
        Column::measured("Nodes", Unit::Number(0), Tolerance::COUNT),
        Column::measured("Node acc.", Unit::Number(2), Tolerance::COUNT),
        Column::measured("Stack acc.", Unit::Number(2), Tolerance::COUNT),
    ];
    c.extend(pm_layout::layout_columns([1, 1, 1], "its whole rendering kernel", "the traversal kernel alone"));
    c
}

/// The modelled frame rate of variant `which` of `part` on `scene`: the
/// traversal kernel's counters (spills at the cap as DRAM traffic) at the
/// part's image side, one persistent launch at the thesis' registers (B 61,
/// C 64); NaN when measured without the timing counters.
fn frame_rate(r: &Results, part: Part, scene: &str, which: usize) -> f64 {
    let registers = if which == 0 { REGISTERS_B } else { REGISTER_CAP };
    let v = part.variants[which].0;
    timing::stage_fps(r, part.group, scene, v, FRAME, part.side, timing::persistent(registers))
}

/// The modelled frame rates of both layouts of part (b) on `scene` (B, C), NaN when not measured.
pub fn frame_rates(r: &Results, scene: &str) -> [f64; 2] {
    [frame_rate(r, PART_B, scene, 0), frame_rate(r, PART_B, scene, 1)]
}

/// What one part's rows and checks are made of.
struct Measured {
    ours: Vec<(String, Vec<f64>)>,
    exact: Vec<(String, bool, bool)>,
    registers: Vec<String>,
    skipped: Vec<f64>,
    demands: Vec<(f64, f64)>,
    /// Per scene the modelled FPS B (NaN: measured without the timing counters).
    fps: Vec<(String, f64)>,
}

fn measured(r: &Results, part: Part) -> (Vec<String>, Measured) {
    let scenes = scenes_of(r, part.group);
    let mut m =
        Measured { ours: vec![], exact: vec![], registers: vec![], skipped: vec![], demands: vec![], fps: vec![] };
    for s in &scenes {
        let (Some(b), Some(c)) = (per_ray(r, part, s, 0), per_ray(r, part, s, 1)) else { continue };
        let v = part.variants[0].0;
        let frames = r.samples.iter().filter(|x| x.group == part.group && &x.scene == s && x.variant == v).count();
        let nodes = r.sum(part.group, s, v, "bvh_nodes").unwrap_or(f64::NAN) / frames.max(1) as f64;
        m.exact.push((s.clone(), b.exact && c.exact, b.balanced));
        m.registers.push(format!(
            "{s}: B {} words, C {} words; spill traffic at the cap {:.1} / {:.1} bytes per ray",
            b.demand, c.demand, b.spill, c.spill
        ));
        m.skipped.push(change(c.nodes, b.nodes));
        m.demands.push((b.demand, c.demand));
        let fb = frame_rate(r, part, s, 0);
        let fc = frame_rate(r, part, s, 1);
        m.fps.push((s.clone(), fb));
        m.ours.push((
            s.clone(),
            vec![
                nodes,
                b.nodes,
                b.pushes,
                b.bytes,
                change(c.bytes, b.bytes),
                b.instructions,
                change(c.instructions, b.instructions),
                fb,
                change(fc, fb),
            ],
        ));
    }
    (scenes, m)
}

/// The checks both parts make: the byte model on the emulator's counters,
/// the bandwidth and instruction claim (`claim`), and the register demand.
fn common_checks(t: &mut Table, m: &Measured, model: &str, claim: &str) {
    t.checks.push(Check {
        claim: format!(
            "{model}, on the emulator's memory counters (read-only pair and local stack traffic) against its \
             per-instruction counts"
        ),
        evidence: m
            .exact
            .iter()
            .map(|(s, x, bal)| {
                format!(
                    "{s}: {}{}",
                    if *x { "exact" } else { "NOT exact" },
                    if *bal { ", every entry popped" } else { ", shadow rays end with entries left" }
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
        holds: m.exact.iter().all(|x| x.1),
    });
    let bytes: Vec<f64> = m.ours.iter().map(|(_, v)| v[4]).collect();
    let instr: Vec<f64> = m.ours.iter().map(|(_, v)| v[6]).collect();
    let (bm, _) = mean_sd(&bytes);
    let (im, _) = mean_sd(&instr);
    t.checks.push(Check {
        claim: claim.into(),
        evidence: format!("ours: bytes {bm:+.1}%, instructions {im:+.1}% on average"),
        holds: bm < 0.0 && im > 0.0,
    });
    t.checks.push(Check {
        claim: format!(
            "\"The rendering kernel uses 61 registers in the baseline and 67 for the compact BVH \
             representation. [...] we force the register count to 64, spilling some information into slow \
             local memory\" (L2825): C needs more registers than B; spills at a cap of {REGISTER_CAP} counted \
             as local traffic (spill model of the PTX's liveness, not ptxas)"
        ),
        evidence: m.registers.join("; "),
        holds: m.demands.iter().all(|(b, c)| c > b),
    });
}

/// The table: parts (a) and (b) measured.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let bvh_note = "the SAH BVH (C_T = 1, C_I = 3, leaves of at most 5 triangles where splitting does not pay, \
                    object partitions, without [EG07]'s split clipping) in [AL09]'s complete pairs (B) and the \
                    compact pairs with Algorithm 6.1 (C)";
    // part (a)
    let (scenes_a, ma) = measured(r, PART_A);
    let mut a = Table::compare(
        &format!("{}a", e.address()),
        &format!("{}\n\n(a) Older code base, primary and shadow rays", e.heading()),
        columns(),
        &THESIS_A,
        &ma.ours,
    );
    if !ma.ours.is_empty() {
        common_checks(
            &mut a,
            &ma,
            "byte model (a) (extract §3.13: B's entries are 8 bytes (node + t_a) for primary rays and 4 for shadow \
             rays, C's 12): B 28 bytes a node access, 4 a push or pop and 4 more a t_a word, C 16 and 12",
            "\"the compact representation reduces bandwidth requirements by 33.8%\" at 20.8% more instructions \
             (Table 6.5 (a) averages): C moves fewer bytes and executes more instructions",
        );
    }
    a.notes.push(super::run_note(
        r,
        &scenes_a,
        &format!(
            "scenebvh.cu on the emulator (gt200 memory model), {bvh_note}; B of the older code base \
             (trace_complete_ta: primary rays stack the pair with its entry distance t_a and skip entries beyond \
             the hit, shadow rays the pair alone), every primary ray of each frame and the shadow ray toward each \
             primary hit on a diffuse surface facing the light; the thesis renders 1024 x 1024"
        ),
    ));
    a.notes.push(
        "Part (a)'s baseline is a reconstruction from the table's description (L2829-2843: 8-byte stack entries \
         of node and t_a for primary rays, 4 bytes for shadow rays, 12 for C); the older code base itself is not \
         available. Stack acc. is the entries pushed per ray; Bytes add 8 a primary ray's entry pushed and popped \
         (4 the pair, 4 t_a each way) and 4 a shadow ray's."
            .into(),
    );
    // part (b)
    let (scenes, mb) = measured(r, PART_B);
    let heading = "(b) Current code base, primary, reflection and shadow rays".to_string();
    let mut t = Table::compare(&format!("{}b", e.address()), &heading, columns(), &THESIS_B, &mb.ours);
    if !mb.ours.is_empty() {
        common_checks(
            &mut t,
            &mb,
            "byte model (extract §3.13): Bytes_B = 28·NodeAcc + 8·StackAcc; here per push or pop one entry, B 28 \
             bytes a node access and 4 an entry, C 16 and 12",
            "\"the compact BVH representation has 31.3% lower global memory bandwidth requirements on average\" \
             while executing more instructions (+35.3%)",
        );
        let (m, _) = mean_sd(&mb.skipped);
        t.checks.insert(
            1,
            Check {
                claim: "\"Using the compact BVH representation, the check is retained and 2.39% fewer nodes are \
                        traversed on average\" (L2845)"
                    .into(),
                evidence: format!("ours: C traverses {m:+.2}% nodes relative to B on average"),
                holds: m < 0.0,
            },
        );
    }
    t.notes.push(super::run_note(
        r,
        &scenes,
        &format!(
            "scenebvh.cu on the emulator (gt200 memory model), {bvh_note}, every primary, reflection and shadow ray \
             of each frame"
        ),
    ));
    let counting = "Counts by the emulator: node accesses (two a pair fetched), stack pushes and pops (and part (a)'s \
         t_a words) are the executions of the `@count` lines of kernels/fabianowski2011/scenebvh.cu; Stack acc. is \
         the entries pushed per ray (each read back once when popped, so the thesis' 8 bytes a stack access are a \
         4-byte push and pop); Bytes are the memory model's bytes requested through the read-only path (pairs) and \
         local memory (stack); Instr. are warp instructions x 32 per ray of the traversal kernel alone (PTX, not \
         GT200 SASS), the thesis' of its whole rendering kernel, so only the relative Instr. C is comparable in \
         kind. Nodes is the size of our SAH BVH (inner nodes and leaves): the thesis' BVH represents large \
         triangles by several boxes [EG07] (not done here) over its own scene variants.";
    let registers = format!(
        "Registers (L2825: 61 for B, 67 for C, forced to {REGISTER_CAP}): the demand is the most 32-bit register \
         words live at once in the kernel's PTX; above the cap the spill model of src/repro/fabianowski2011/spills.rs \
         keeps the cheapest registers in local memory and counts each executed read and write as 4 bytes a lane. \
         The thesis' counts are of its whole rendering kernel, ours of the traversal alone."
    );
    for (x, m, side) in [(&mut a, &ma, PART_A.side), (&mut t, &mb, PART_B.side)] {
        x.notes.push(counting.into());
        x.notes.push(registers.clone());
        x.notes.push(format!(
            "Modelled FPS: {}. A frame here is the traversal kernel (scenebvh.cu) for every ray of the frame, its \
             spill traffic at the cap added as DRAM bytes, scaled to the thesis' {side} x {side}{} and predicted as one \
             persistent launch at the thesis' registers (B {REGISTERS_B}, C {REGISTER_CAP}: one CTA of 256 threads \
             an SM either way) instead of chapter 4's 54. Not modelled: the shading and ray generation of the \
             thesis' whole rendering kernel. Our traversal's PTX executes three to four times the instructions per \
             ray the thesis counts for its whole kernel in GT200 code (Instr. B), so the absolute frame rates come out \
             low; the relative FPS C compares two kernels of the same code. FPS B within {}, FPS C (C against B) \
             within {}.",
            timing::describe(),
            if side == 512 { "" } else { " (the thesis' side of part (a), not the 512 x 512 above)" },
            timing::FPS_TOLERANCE.describe(),
            Tolerance::RATIO.describe()
        ));
        if let Some(n) = timing::unmeasured_note(&m.fps) {
            x.notes.push(n);
        }
        let e = timing::error_note(x);
        x.notes.push(e);
    }
    vec![a, t]
}
