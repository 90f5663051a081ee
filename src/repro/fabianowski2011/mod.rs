//! Seed 000: Bartosz Fabianowski (2011), *Interactive Manycore Photon
//! Mapping*. Chapter 4 (kd-tree construction and traversal, Tables 4.1–4.10)
//! runs on the emulator; the other tables are registered with their status.
//!
//! Measurement groups (one run serves several tables):
//! - [`TRAVERSAL`]: the five §4.2 traversal kernels over the flights (Tables 4.5–4.7);
//! - [`CACHES`]: the seven §4.3 cache kernels (Tables 4.8–4.10);
//! - [`HEURISTICS`]: the stack kernel on SAH, 4.1.2 and SIROH trees (Table 4.1);
//! - [`HEURISTIC_COUNTS`]: the native caster's counts on the three trees (Table 4.3);
//! - [`SHADOW_LIGHT`]: shadow rays from a light inside and outside (Table 4.2 (b));
//! - [`BUILDS`]: timed SAH and SIROH builds (Table 4.4).

pub mod accuracy;
pub mod caches;
pub mod flight;
pub mod knn;
pub mod lbvh;
pub mod photon_image;
pub mod photons;
pub mod pm_layout;
pub mod sah;
pub mod scene_bvh;
pub mod spills;
pub mod table_4_1;
pub mod table_4_2;
pub mod table_4_3;
pub mod table_4_4;
pub mod table_5_1;
pub mod table_6_1;
pub mod table_6_2;
pub mod table_6_3;
pub mod table_6_4;
pub mod table_6_5;
pub mod table_6_6;
pub mod timing;
pub mod traversal;
pub mod vkde;
pub mod vvh;

use flight::{SceneRun, Totals};

use crate::host::kdtree::Heuristic;
use crate::host::rt_kernels::Variant;
use crate::repro::registry::{Entry, Group, Side, Status, TableDef, Thesis};
use crate::repro::results::Results;
use crate::repro::table::{Column, Published, Table};

/// The five scenes of chapter 4's tables, in their order.
pub const SCENES: [&str; 5] = ["scene6", "sponza", "sibenik", "fairy", "conference"];

/// Group: the traversal variants over the flights.
pub const TRAVERSAL: &str = "fabianowski/traversal";
/// Group: the cache variants over the flights.
pub const CACHES: &str = "fabianowski/caches";
/// Group: the stack kernel on three trees.
pub const HEURISTICS: &str = "fabianowski/heuristics";
/// Group: native counts on three trees.
pub const HEURISTIC_COUNTS: &str = "fabianowski/heuristic-counts";
/// Group: shadow rays from two lights.
pub const SHADOW_LIGHT: &str = "fabianowski/shadow-light";
/// Group: timed tree builds.
pub const BUILDS: &str = "fabianowski/builds";

/// Emulated kernels: core-seconds per frame and variant per pixel of the
/// image side, at the thesis' 512 x 512: a run of Tables 4.6, 4.10 and 4.1 on
/// frame 0 of Scene 6, Sponza and Sibenik took 753 CPU-seconds for 45 kernel
/// runs, of which the plan's own tree term covers 37 s (the 4.1.2 trees):
/// (753 - 37) / 45 / 512 = 0.0311. The cost of a run grows with the pixels
/// (about 0.5 s + 6.2e-5 s per pixel: 1.1 s at 96 x 96, 2.8 s at 192 x 192,
/// 15.9 s at 512 x 512), so this per-side rate overestimates smaller images
/// (the quick protocol about 2.8 x) and is exact at the thesis' size
/// (docs/reproduction-fabianowski2011.md, "Cost of the full protocol").
pub const EMULATED: f64 = 0.0311;
/// The native caster: a 512 x 512 frame in 0.4 s on two cores (README "Speed").
const NATIVE: f64 = 0.0016;

/// The thesis and its tables.
pub static THESIS: Thesis = Thesis {
    short: "fabianowski",
    dir: "fabianowski2011",
    seed: "000",
    seed_file: "000_f44e1f0be984c6fd.txt",
    citation: "Bartosz Fabianowski (2011): Interactive Manycore Photon Mapping",
    tables: &TABLES,
    groups: &GROUPS,
};

/// The trees of Tables 4.1 and 4.3.
const HEURISTIC_TREES: [Heuristic; 3] = [Heuristic::Sah, Heuristic::Numerical, Heuristic::Siroh];

/// The measurement groups.
static GROUPS: [Group; 13] = [
    Group {
        name: TRAVERSAL,
        what: "5 traversal kernels on the emulator",
        per_frame: true,
        variants: 5,
        seconds_per_side: EMULATED,
        seconds_per_triangle: 0.0,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: flight::measure_traversal,
    },
    Group {
        name: CACHES,
        what: "7 cache kernels on the emulator",
        per_frame: true,
        variants: 7,
        seconds_per_side: EMULATED,
        seconds_per_triangle: 0.0,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: flight::measure_caches,
    },
    Group {
        name: HEURISTICS,
        what: "the stack kernel on SAH, 4.1.2 and SIROH trees on the emulator",
        per_frame: true,
        variants: 3,
        seconds_per_side: EMULATED,
        seconds_per_triangle: 0.0,
        side: Side::Protocol,
        trees: &HEURISTIC_TREES,
        measure: table_4_1::measure,
    },
    Group {
        name: HEURISTIC_COUNTS,
        what: "the native caster on SAH, 4.1.2 and SIROH trees",
        per_frame: true,
        variants: 3,
        seconds_per_side: NATIVE,
        seconds_per_triangle: 0.0,
        side: Side::Protocol,
        trees: &HEURISTIC_TREES,
        measure: table_4_3::measure,
    },
    Group {
        name: SHADOW_LIGHT,
        what: "shadow rays from two lights over SAH and SIROH trees (frame 0)",
        per_frame: false,
        variants: 4,
        seconds_per_side: NATIVE,
        seconds_per_triangle: 0.0,
        side: Side::Protocol,
        trees: &[Heuristic::Sah, Heuristic::Siroh],
        measure: table_4_2::measure_group,
    },
    Group {
        name: BUILDS,
        what: "timed SAH and SIROH builds",
        per_frame: false,
        variants: 2,
        seconds_per_side: 0.0,
        seconds_per_triangle: 8e-6,
        side: Side::Protocol,
        trees: &[],
        measure: table_4_4::measure_group,
    },
    Group {
        name: table_5_1::PHOTON_STATS,
        what: "photon tracing and kernel construction on the emulator with Table 5.1's parameters (once per scene)",
        per_frame: false,
        variants: 1,
        seconds_per_side: 0.0,
        seconds_per_triangle: 2e-5,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: table_5_1::measure_photons,
    },
    Group {
        name: table_5_1::VKDE_QUERIES,
        what: "VKDE on the emulator at the primary and reflection hits of each frame (photons and kernels traced again)",
        per_frame: true,
        variants: 1,
        seconds_per_side: 0.12,
        seconds_per_triangle: 2e-5,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: table_5_1::measure_queries,
    },
    Group {
        name: table_6_4::PM_LAYOUTS,
        what: "VKDE gathers through the complete and compact LBVH photon maps on the emulator (Table 5.1's kernels)",
        per_frame: true,
        variants: 2,
        seconds_per_side: 0.1,
        seconds_per_triangle: 2e-5,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: table_6_4::measure,
    },
    Group {
        name: table_6_5::SCENE_BVH,
        what: "ray traversal of the SAH scene BVH in the complete and compact layouts on the emulator",
        per_frame: true,
        variants: 2,
        seconds_per_side: 0.05,
        seconds_per_triangle: 2e-5,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: table_6_5::measure,
    },
    Group {
        name: table_6_5::SCENE_BVH_A,
        what: "Table 6.5 (a): primary and shadow rays through the SAH scene BVH, the older baseline (t_a stacked) and the compact layout on the emulator",
        per_frame: true,
        variants: 2,
        seconds_per_side: 0.03,
        seconds_per_triangle: 2e-5,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: table_6_5::measure_a,
    },
    Group {
        name: table_6_6::PIPELINE,
        what: "the §6.3 pipeline on the emulator with the light moving: photon tracing, kernels, LBVH, ray tracing and gathers every frame",
        per_frame: true,
        variants: 1,
        seconds_per_side: 0.1,
        seconds_per_triangle: 2e-5,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: table_6_6::measure,
    },
    Group {
        name: vvh::PM_BUILDERS,
        what: "VVH and LBVH photon maps with n_auto and leaf thresholds 1-128, native walks at each frame's queries and the emulated gathers (the frame rates' counters)",
        per_frame: true,
        variants: 18,
        seconds_per_side: EMULATED,
        seconds_per_triangle: 2e-4,
        side: Side::Protocol,
        trees: &[Heuristic::Siroh],
        measure: vvh::measure,
    },
];

/// Every table of the thesis, as printed.
static TABLES: [TableDef; N] = [
    TableDef {
        id: "2.1",
        title: "Summary of radiometric terms",
        lines: "L396-404",
        status: Status::NotAMeasurement,
        note: "definitions of radiometric terms (symbol, unit); extract: \"Not a measurement\"",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.1",
        title: "Ray tracing frame rates with the numerical approximation from section 4.1.2 and SIROH for two CUDA benchmark environments, relative to the SAH",
        lines: "L1664-1674",
        status: Status::Modelled,
        note: "frame rates of the stack kernel on SAH, 4.1.2 and SIROH trees through the GTX 280 timing model; code base I's absolute rates not reproducible",
        scenes: &SCENES,
        groups: &[HEURISTICS],
        render: Some(table_4_1::render),
    },
    TableDef {
        id: "4.2",
        title: "Ray tracing frame rates with SIROH for two other ray tracers, relative to the SAH",
        lines: "L1686-1697",
        status: Status::Partly,
        note: "third-party ray tracers; (b)'s finding (a light outside the scene makes SIROH lose) checked on shadow-ray traversals",
        scenes: &SCENES,
        groups: &[SHADOW_LIGHT],
        render: Some(table_4_2::render),
    },
    TableDef {
        id: "4.3",
        title: "Inner node traversals, triangle plane intersections and barycentric coordinate calculations with the numerical approximation from section 4.1.2 and SIROH, relative to the SAH",
        lines: "L1699-1709",
        status: Status::Reproduced,
        note: "counted by the native caster, step for step the stack kernel",
        scenes: &SCENES,
        groups: &[HEURISTIC_COUNTS],
        render: Some(table_4_3::render),
    },
    TableDef {
        id: "4.4",
        title: "Construction timings and kd-tree statistics with SIROH, relative to the SAH",
        lines: "L1711-1721",
        status: Status::Reproduced,
        note: "tree statistics exact; timings on this machine (CPU I and II's absolute timings not reproducible)",
        scenes: &SCENES,
        groups: &[BUILDS],
        render: Some(table_4_4::render),
    },
    TableDef {
        id: "4.5",
        title: "Inner node traversals per ray with stackless traversal, relative to a stack-based traversal",
        lines: "L1878-1888",
        status: Status::Reproduced,
        note: "the five traversal kernels on the emulator",
        scenes: &SCENES,
        groups: &[TRAVERSAL],
        render: Some(traversal::render_4_5),
    },
    TableDef {
        id: "4.6",
        title: "Ray tracing frame rates with stackless traversal, relative to a stack-based traversal",
        lines: "L1902-1912",
        status: Status::Modelled,
        note: "the GTX 280 timing model (specifications and microbenchmarks, no fit) on the emulator's counts",
        scenes: &SCENES,
        groups: &[TRAVERSAL],
        render: Some(traversal::render_4_6),
    },
    TableDef {
        id: "4.7",
        title: "Instructions per ray with stackless traversal, relative to a stack-based traversal",
        lines: "L1914-1924",
        status: Status::Reproduced,
        note: "warp instructions x 32 per ray on the emulator (PTX, not GT200 SASS)",
        scenes: &SCENES,
        groups: &[TRAVERSAL],
        render: Some(traversal::render_4_7),
    },
    TableDef {
        id: "4.8",
        title: "Global memory accesses during inner node traversal with explicitly managed caches, relative to baseline without",
        lines: "L2066-2119",
        status: Status::Reproduced,
        note: "(a), (b), (d) counted on the emulator; (c) from the gt200 profile's texture cache model",
        scenes: &SCENES,
        groups: &[CACHES],
        render: Some(caches::render_4_8),
    },
    TableDef {
        id: "4.9",
        title: "Instructions per ray with explicitly managed caches, relative to baseline without",
        lines: "L2123-2134",
        status: Status::Reproduced,
        note: "warp instructions x 32 per ray on the emulator (PTX, not GT200 SASS)",
        scenes: &SCENES,
        groups: &[CACHES],
        render: Some(caches::render_4_9),
    },
    TableDef {
        id: "4.10",
        title: "Ray tracing frame rates with explicitly managed caches, relative to baseline without",
        lines: "L2146-2157",
        status: Status::Modelled,
        note: "the GTX 280 timing model (specifications and microbenchmarks, no fit) on the emulator's counts",
        scenes: &SCENES,
        groups: &[CACHES],
        render: Some(caches::render_4_10),
    },
    TableDef {
        id: "5.1",
        title: "Photon tracing and density estimation statistics",
        lines: "L2452-2464",
        status: Status::Reproduced,
        note: "interactions, discarded, clamped and k_VK counted on the emulator (photons.cu, vkde.cu; the native references count the same) with the table's emissions and s; statistical (true-RNG sequence lost); k_kNN chosen by eye",
        scenes: &table_5_1::SCENES,
        groups: &[table_5_1::PHOTON_STATS, table_5_1::VKDE_QUERIES],
        render: Some(table_5_1::render),
    },
    TableDef {
        id: "6.1",
        title: "Rendering frame rates with different minimal photon map leaf size thresholds",
        lines: "L2629-2659",
        status: Status::Partly,
        note: "n_auto measured (§6.1.3 as printed); frame rates modelled (GTX 280 timing model on the emulator's counters of the camera rays and the gather through each photon map); n_T/n_I per threshold measured by native walks of VVH and LBVH photon maps; rows reconciled (Ring row lost, labels shifted)",
        scenes: &table_5_1::SCENES,
        groups: &[vvh::PM_BUILDERS],
        render: Some(table_6_1::render),
    },
    TableDef {
        id: "6.2",
        title: "Photon map node counts, relative to the VVH, and construction timings with LBVH",
        lines: "L2667-2681",
        status: Status::Partly,
        note: "interactions and VVH/LBVH node counts measured (serial VVH builder, LBVH with dual merge, n_auto); LBVH ms not reproduced (GTX 280); interactions differ from 5.1 in the thesis",
        scenes: &table_5_1::SCENES,
        groups: &[vvh::PM_BUILDERS],
        render: Some(table_6_2::render),
    },
    TableDef {
        id: "6.3",
        title: "Photon map node traversals, interaction retrievals per query point and rendering frame rates with LBVH construction, relative to the VVH",
        lines: "L2683-2697",
        status: Status::Partly,
        note: "n_T and n_I per query point measured (native walks of VVH and LBVH photon maps with n_auto, bit for bit pmgather.cu); FPS modelled (GTX 280 timing model on the emulator's counters of the camera rays and the gather)",
        scenes: &table_5_1::SCENES,
        groups: &[vvh::PM_BUILDERS],
        render: Some(table_6_3::render),
    },
    TableDef {
        id: "6.4",
        title: "Global memory accesses during node traversal, instructions per query point and rendering frame rates with compact BVH photon map (C), relative to complete BVH (B)",
        lines: "L2804-2817",
        status: Status::Partly,
        note: "n_T, stack and bytes counted on the emulator (B and C layouts of the LBVH photon map; the byte model checked against the memory model's counters); instructions of the gather kernel alone; FPS modelled (GTX 280 timing model on the emulator's counters of raytrace.cu's camera rays and the gather at 512 x 512); Conference bytes misprint",
        scenes: &table_6_4::SCENES,
        groups: &[table_6_4::PM_LAYOUTS],
        render: Some(table_6_4::render),
    },
    TableDef {
        id: "6.5",
        title: "Global memory accesses during node traversal, instructions per ray and frame rates with compact BVH (C), relative to complete BVH (B)",
        lines: "L2829-2853",
        status: Status::Partly,
        note: "(a) and (b): node and stack accesses and bytes counted on the emulator (SAH scene BVH in [AL09]'s complete and the compact pairs, Alg. 6.1; (a)'s baseline stacks t_a for primary rays; the byte models checked on the memory model's counters), instructions of the traversal kernel alone (shown, compared relative only), register cap 64 by a spill model of the PTX; FPS modelled (GTX 280 timing model on the traversal kernel's counters, shading not modelled)",
        scenes: &table_6_5::SCENES,
        groups: &[table_6_5::SCENE_BVH_A, table_6_5::SCENE_BVH],
        render: Some(table_6_5::render),
    },
    TableDef {
        id: "6.6",
        title: "Photon interactions, contributions per query, times per frame for photon tracing, LBVH photon map construction, rendering and frame rates with dynamic illumination",
        lines: "L2865-2876",
        status: Status::Modelled,
        note: "interactions and k counted with the light moving every frame; Trace, LBVH and Render ms and FPS modelled (GTX 280 timing model on the emulator's counters of the whole pipeline; host sorts and visualisation not modelled); k copied from 5.1 in the thesis",
        scenes: &table_6_6::SCENES,
        groups: &[table_6_6::PIPELINE],
        render: Some(table_6_6::render),
    },
    TableDef {
        id: "7.1",
        title: "Light source type, absorption and scattering coefficients, homogeneity and anisotropy of the participating medium for nine benchmark scenarios",
        lines: "L3147-3159",
        status: Status::NotAMeasurement,
        note: "class P fixtures (medium/light parameters); units m^-1 inferred, spot angle ambiguous",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "7.2",
        title: "Adaptation dampening for different bounce depths and benchmark scenarios",
        lines: "L3161-3172",
        status: Status::NotAMeasurement,
        note: "class P, hand-tuned dampening parameters; evaluation uses column \"Bounce 0, 1\"",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "7.3",
        title: "Photon tracing and density estimation statistics with kernel bandwidths obtained by the baseline (B) and photon differentials (PD) methods",
        lines: "L3182-3196",
        status: Status::Missing,
        note: "measured when reproduced: extinctions, clamped, k class C, statistical (Sobol details unknown); k_B needs 85-NN baseline",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "7.4",
        title: "Density estimation instructions per ray with different job queue types and packetization",
        lines: "L3293-3307",
        status: Status::Missing,
        note: "measured when reproduced: class S, best emulator target: warp formation per queue type, divergence, vote-based packets",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "7.5",
        title: "Density estimation times per frame with different job queue types and packetization",
        lines: "L3319-3333",
        status: Status::Missing,
        note: "modelled when reproduced: class T; check time proportional to instructions except queue III; Packet QI average misprint",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "7.6",
        title: "Photon extinction events, contributions per query, times per frame for photon tracing, LBVH photon map construction, ray tracing (RT), density estimation (DE) and frame rates with dynamic illumination",
        lines: "L3335-3347",
        status: Status::Missing,
        note: "modelled when reproduced: ms/FPS class T (FPS = 1000/sum ms); extinctions and k countable (class C)",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "A.1",
        title: "Properties of the benchmark scenes used for algorithm evaluation",
        lines: "L3463-3473",
        status: Status::NotAMeasurement,
        note: "class P scene fixtures; loader check of triangle counts and scaled extents",
        scenes: &[],
        groups: &[],
        render: None,
    },
];

const N: usize = 25;

/// The scenes of `group` in `r`, in the table's order first, then any others in the order run.
pub fn scenes_of(r: &Results, group: &str) -> Vec<String> {
    let mut v: Vec<String> = SCENES.iter().filter(|s| r.has(group, s)).map(|s| s.to_string()).collect();
    for s in &r.scenes {
        if r.has(group, &s.name) && !v.contains(&s.name) {
            v.push(s.name.clone());
        }
    }
    v
}

/// The note naming the protocol and the scenes as run.
pub fn run_note(r: &Results, scenes: &[String], what: &str) -> String {
    let s: Vec<String> = scenes
        .iter()
        .map(|n| {
            let info = r.scene(n);
            let tri = info.map_or(String::new(), |i| format!(" {} triangles", i.triangles));
            format!("{n}{tri}, frames {}", r.frames_text(n))
        })
        .collect();
    format!(
        "Ours: {what}; protocol {}. Scenes: {} (variants as in `warplight scene info NAME`; Fairy Forest is not available). Fixtures: docs/fixtures.md.",
        r.protocol.describe(),
        if s.is_empty() { "none".into() } else { s.join("; ") }
    )
}

/// A flight table: per scene the baseline's per-ray value (`pick`) and the
/// other variants relative to it (percent, or percentage points for a
/// [`crate::repro::table::Unit::Points`] column).
#[allow(clippy::too_many_arguments)]
pub fn flight_table(
    e: &Entry,
    r: &Results,
    heading: &str,
    group: &str,
    variants: &[Variant],
    published: &Published,
    columns: Vec<Column>,
    pick: impl Fn(&Totals) -> f64,
) -> Table {
    let names: Vec<&str> = variants.iter().map(|v| v.name()).collect();
    let scenes = scenes_of(r, group);
    let ours: Vec<(String, Vec<f64>)> = scenes
        .iter()
        .filter_map(|s| {
            let run = SceneRun::from_results(r, group, s, variants, &names)?;
            let v: Vec<f64> = run.totals.iter().map(&pick).collect();
            let row = (0..v.len())
                .map(|i| {
                    if i == 0 {
                        v[0]
                    } else if columns[i].unit == crate::repro::table::Unit::Points {
                        v[i] - v[0]
                    } else {
                        (v[i] / v[0] - 1.0) * 100.0
                    }
                })
                .collect();
            Some((s.clone(), row))
        })
        .collect();
    let mut t = Table::compare(&e.address(), heading, columns, published, &ours);
    t.notes.push(run_note(
        r,
        &scenes,
        "SIROH trees, 30 persistent CTAs x 256 threads, 32-pixel job blocks, clang-16 PTX, gt200 profile",
    ));
    t.notes.push(COUNTING.into());
    t.notes.push(flight::materials_note(r, group, &scenes, variants[0].name()));
    t
}

/// How the flight tables' counts are made.
pub const COUNTING: &str = "Counts by the emulator: the kernels run without in-kernel tallies; rays, inner-node steps, \
     leaf visits, triangle tests and local-memory stack pushes and pops are the executions of the instructions on the \
     source lines tagged `@count` in kernels/fabianowski2011/raytrace.cu, texture node fetches are inner-node steps less \
     the inner nodes the shared-memory node cache served (an observer of the emulator's memory events). An instrumented \
     build agrees exactly (tests/raytrace.rs). Shadow rays go from the point light toward the hit (seed 000 L3411, L1561).";

/// A frame-rate table through the GTX 280 timing model ([`timing`]; no
/// parameter from the thesis): every column predicted, the absolute one
/// compared within ±15 %, the relative ones within the ratio tolerance.
pub fn timing_table(
    e: &Entry,
    r: &Results,
    group: &str,
    variants: &[Variant],
    names: &[&str],
    published: &Published,
) -> Table {
    let scenes = scenes_of(r, group);
    let ours: Vec<(String, Vec<f64>)> = scenes
        .iter()
        .map(|s| {
            let p: Vec<f64> = variants.iter().map(|v| timing::fps(r, group, s, v.name())).collect();
            let row = (0..p.len()).map(|i| if i == 0 { p[0] } else { (p[i] / p[0] - 1.0) * 100.0 }).collect();
            (s.clone(), row)
        })
        .collect();
    let model = "GTX 280 timing model";
    let mut cols = vec![Column::modelled(
        names[0],
        crate::repro::table::Unit::Number(1),
        model,
        Some(timing::FPS_TOLERANCE),
        None,
    )];
    cols.extend(names[1..].iter().map(|n| {
        Column::modelled(
            n,
            crate::repro::table::Unit::Change,
            model,
            Some(crate::repro::compare::Tolerance::RATIO),
            None,
        )
    }));
    let mut t = Table::compare(&e.address(), &e.heading(), cols, published, &ours);
    t.notes.push(format!("{}.", timing::describe()));
    t.notes.push(timing::error_note(&t));
    t.notes.push(run_note(r, &scenes, "SIROH trees, counts scaled to 512 x 512"));
    t
}
