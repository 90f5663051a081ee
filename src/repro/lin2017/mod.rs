//! Seed 003: Lin Daqi (2017): Real Time Path Tracing on GPU.
//!
//! Every table of the seed is registered with its status. Reproduced:
//! [`fig_3`], the data table of Fig. 3 (traversals × constructions), from
//! the measurement group [`fig_3::TRAVERSALS`]; [`fig_16`], thread
//! compaction's worked example, counted; [`fig_17`], frame rate against max
//! depth with and without compaction (ratios modelled, active paths and
//! useful lanes per level counted); [`table_1`], triangle clipping's
//! speedup (modelled from instruction counts, tests and visits per ray
//! counted); [`table_2`], the GPU SAH kd-tree build of §6.5 on the emulator
//! against the serial build (tree statistics, launches, instructions and
//! bytes counted; seconds not reproducible); [`sec_6_4`], the operations
//! of the standard and the affine ray-triangle tests (§6.4's text), counted;
//! [`sec_6_3`], the 3-way regroup by Fresnel branch (§6.3's text; speedup
//! modelled, the shade kernel's divergence counted); [`fig_6`], MIS at 10
//! frames against BSDF sampling at 100, the error per region measured;
//! [`fig_7`], the balance
//! against the power heuristic by histogram correlation with the ground
//! truth (measured; the order of the two compared, and their variance over
//! 16 seeds); [`fig_8`], bidirectional against eye path tracing under the
//! light turned to the ceiling (error measured, frame rate modelled);
//! [`fig_9`], Monte Carlo against MLT at frames 1, 30 and 100
//! (error and the lit ceiling's brightness measured over 8 runs, the frame
//! cost modelled); [`sec_4_8`], MLT's brightness against its bootstrap
//! count (§4.8's r̄) and its error against the large-step probability
//! (measured).

pub mod convergence;
pub mod fig_16;
pub mod fig_17;
pub mod fig_3;
pub mod fig_6;
pub mod fig_7;
pub mod fig_8;
pub mod fig_9;
pub mod lanes;
pub mod media;
pub mod pixel_sampling;
pub mod render;
pub mod runs;
pub mod sec_4_8;
pub mod sec_6_3;
pub mod sec_6_4;
pub mod table_1;
pub mod table_2;

use crate::host::kdtree::Heuristic;
use crate::repro::registry::{Group, Side, Status, TableDef, Thesis};

/// The seed and its tables.
pub static THESIS: Thesis = Thesis {
    short: "lin",
    dir: "lin2017",
    seed: "003",
    seed_file: "003_0cecf91ec9b1cabd.txt",
    citation: "Lin Daqi (2017): Real Time Path Tracing on GPU",
    tables: &TABLES,
    groups: &GROUPS,
};

/// The measurement groups.
static GROUPS: [Group; 13] = [
    Group {
        name: fig_3::TRAVERSALS,
        what: "the path tracer with 3 kd-tree traversals on SAH and space-median trees, on the emulator",
        per_frame: false,
        variants: 6,
        seconds_per_side: 0.0,
        seconds_per_triangle: 4e-4,
        side: Side::AtMost(fig_3::MAX_SIDE),
        trees: &[] as &[Heuristic],
        measure: fig_3::measure,
    },
    Group {
        name: fig_16::EXAMPLE,
        what: "one level of the wavefront path tracer over 128 paths before and after compaction, on the emulator",
        per_frame: false,
        variants: 1,
        seconds_per_side: 0.0,
        seconds_per_triangle: 1e-3,
        side: Side::Own("an 8x4 image, 128 paths"),
        trees: &[] as &[Heuristic],
        measure: fig_16::measure_group,
    },
    Group {
        name: fig_17::DEPTHS_GROUP,
        what: "the wavefront path tracer with and without compaction at 13 max depths, on the emulator",
        per_frame: false,
        variants: 26,
        seconds_per_side: 0.05,
        seconds_per_triangle: 0.0,
        side: Side::AtMost(fig_17::MAX_SIDE),
        trees: &[] as &[Heuristic],
        measure: fig_17::measure,
    },
    Group {
        name: table_1::CLIPPING,
        what: "the path tracer on the SAH tree built with and without triangle clipping, on the emulator",
        per_frame: false,
        variants: 2,
        seconds_per_side: 0.5,
        seconds_per_triangle: 1e-4,
        side: Side::AtMost(table_1::MAX_SIDE),
        trees: &[] as &[Heuristic],
        measure: table_1::measure,
    },
    Group {
        name: table_2::BUILDS,
        what: "the GPU SAH kd-tree build of §6.5 on the emulator, and the serial CPU build",
        per_frame: false,
        variants: 1,
        seconds_per_side: 0.0,
        seconds_per_triangle: 2e-3,
        side: Side::Protocol,
        trees: &[] as &[Heuristic],
        measure: table_2::measure,
    },
    Group {
        name: sec_6_4::OPS,
        what: "the standard and the affine ray-triangle tests over the scene's triangles, clang's and nvcc's PTX, on the emulator",
        per_frame: false,
        variants: 4,
        seconds_per_side: 0.0,
        seconds_per_triangle: 1e-3,
        side: Side::Protocol,
        trees: &[] as &[Heuristic],
        measure: sec_6_4::measure,
    },
    Group {
        name: fig_6::MIS_BSDF,
        what: "MIS at 3 frames and BSDF sampling at 30, 8 runs natively at 64 x 64, their first frames on the emulator, error per region against a converged render",
        per_frame: false,
        variants: 2,
        seconds_per_side: 0.1,
        seconds_per_triangle: 0.0,
        side: Side::Fixed(fig_6::SIDE, "its converged truth's"),
        trees: &[] as &[Heuristic],
        measure: fig_6::measure,
    },
    Group {
        name: fig_7::HEURISTICS,
        what: "MIS with the balance and the power heuristic at 128 x 128, 3 frames: seed 0 on the emulator, seeds 0-15 natively, against a converged render",
        per_frame: false,
        variants: 2,
        seconds_per_side: 0.2,
        seconds_per_triangle: 0.0,
        side: Side::Fixed(fig_7::SIDE, "its converged truth's"),
        trees: &[] as &[Heuristic],
        measure: fig_7::measure,
    },
    Group {
        name: fig_8::BDPT_NEE,
        what: "bdpt, nee and pt at 25 frames, 8 runs each natively at 32 x 32 against the Mitsuba reference, and one frame of each on the emulator",
        per_frame: false,
        variants: 3,
        seconds_per_side: 0.2,
        seconds_per_triangle: 0.0,
        side: Side::Fixed(convergence::REFERENCE_SIDE, "its Mitsuba reference's"),
        trees: &[] as &[Heuristic],
        measure: fig_8::measure,
    },
    Group {
        name: fig_9::MC_MLT,
        what: "bdpt to 256 frames and MLT (two starts) to 25 frames, 8 runs each natively at 32 x 32, and their first frames on the emulator",
        per_frame: false,
        variants: 4,
        seconds_per_side: 0.2,
        seconds_per_triangle: 0.0,
        side: Side::Fixed(convergence::REFERENCE_SIDE, "its Mitsuba references'"),
        trees: &[] as &[Heuristic],
        measure: fig_9::measure,
    },
    Group {
        name: sec_4_8::BOOTSTRAP_GROUP,
        what: "MLT's b over 1 to 1,024 bootstrap samples a pixel, 8 runs natively at 32 x 32, and one MLT frame on the emulator",
        per_frame: false,
        variants: 9,
        seconds_per_side: 0.05,
        seconds_per_triangle: 0.0,
        side: Side::Fixed(sec_4_8::SIDE, "its Mitsuba references'"),
        trees: &[] as &[Heuristic],
        measure: sec_4_8::measure,
    },
    Group {
        name: sec_4_8::LARGE_STEP_GROUP,
        what: "MLT natively at 5 large-step probabilities, 8 runs of 25 frames at 32 x 32, against the Mitsuba reference",
        per_frame: false,
        variants: 5,
        seconds_per_side: 0.1,
        seconds_per_triangle: 0.0,
        side: Side::Fixed(sec_4_8::SIDE, "its Mitsuba references'"),
        trees: &[] as &[Heuristic],
        measure: sec_4_8::measure_large_step,
    },
    Group {
        name: sec_6_3::REGROUP_GROUP,
        what: "the wavefront path tracer with trace and shade apart, without, with compaction and regrouped by Fresnel branch, on the emulator",
        per_frame: false,
        variants: 3,
        seconds_per_side: 0.05,
        seconds_per_triangle: 0.0,
        side: Side::AtMost(sec_6_3::MAX_SIDE),
        trees: &[] as &[Heuristic],
        measure: sec_6_3::measure,
    },
];

/// Its tables as printed (captions verbatim from the seed).
static TABLES: [TableDef; 15] = [
    TableDef {
        id: "1",
        title: "Speedup of triangle clipping for different models",
        lines: "L153-160",
        status: Status::Modelled,
        note: "FPS not reproducible (GPU, resolution, spp, camera not stated); speedup modelled by emulated warp instructions; triangle tests and node visits per ray counted with and without clipping",
        scenes: &table_1::SCENES,
        groups: &[table_1::CLIPPING],
        render: Some(table_1::render),
    },
    TableDef {
        id: "fig3",
        title: "Time (seconds) to render 64 samples/pixel \"bunny&ball\" scene in 512x512",
        lines: "L181-189",
        status: Status::Modelled,
        note: "seconds not reproducible (GPU and scene not stated); relative times modelled by emulated warp instructions; traversal work counted per ray",
        scenes: &[fig_3::SCENE],
        groups: &[fig_3::TRAVERSALS],
        render: Some(fig_3::render),
    },
    TableDef {
        id: "fig6",
        title: "Left: multiple important sampling Right: single importance (light) sampling",
        lines: "L286-288",
        status: Status::Partly,
        note: "IMAGE: MIS at 10 frames against BSDF sampling at 100 (the text's reading of the caption's 'light'), the RMS error per region measured over 8 runs against a converged render; materials not stated",
        scenes: &[fig_6::SCENE],
        groups: &[fig_6::MIS_BSDF],
        render: Some(fig_6::render),
    },
    TableDef {
        id: "fig7",
        title: "Left: balance heuristic Middle: power heuristic Right: ground truth",
        lines: "L291-293",
        status: Status::Partly,
        note: "histogram correlation with the ground truth measured (seed 0 emulated; ground truth our converged render, as the thesis' was its own); bins, tone mapping and resolution not stated, so only the order of the two and their variance over 16 seeds are compared",
        scenes: &[fig_7::SCENE],
        groups: &[fig_7::HEURISTICS],
        render: Some(fig_7::render),
    },
    TableDef {
        id: "fig8",
        title: "Left: Bi-directional path tracing Right: Uni-directional (eye) path tracing",
        lines: "L305-308",
        status: Status::Partly,
        note: "IMAGE + TIMING ratio: bdpt against nee (the text) and pt (the caption) at 100 paths a pixel (the thesis' 100 frames) on the inverted-light box, the RMS error against Mitsuba measured over 8 runs; the frame rate (50%) modelled by emulated warp instructions",
        scenes: &[fig_8::SCENE],
        groups: &[fig_8::BDPT_NEE],
        render: Some(fig_8::render),
    },
    TableDef {
        id: "fig9",
        title: "Upper: Monte Carlo Lower: Metropolis (Both use bi-directional path tracing)",
        lines: "L332-336",
        status: Status::Partly,
        note: "IMAGE: frames 1, 30, 100 on Fig. 8's box and the original; error against Mitsuba and the lit ceiling's brightness measured over 8 runs, the frames Monte Carlo needs for MLT's error measured, the frame cost modelled by emulated warp instructions",
        scenes: &fig_9::SCENES,
        groups: &[fig_9::MC_MLT],
        render: Some(fig_9::render),
    },
    TableDef {
        id: "fig16",
        title: "Upper: Before thread compaction Lower: After thread compaction",
        lines: "L505-510",
        status: Status::Reproduced,
        note: "useful lanes 25% -> 75%, warps 3 -> 1, occupancy 75%: counted by the emulator (toy lanes x 8)",
        scenes: &[fig_16::SCENE],
        groups: &[fig_16::EXAMPLE],
        render: Some(fig_16::render),
    },
    TableDef {
        id: "fig17",
        title: "Frame rate as the function of max trace depth, for program with and without thread compaction",
        lines: "L512-532",
        status: Status::Modelled,
        note: "fps not reproducible (GTX 960M); compact/normal modelled by emulated warp instructions; active paths and useful lanes per level counted",
        scenes: &[fig_17::SCENE],
        groups: &[fig_17::DEPTHS_GROUP],
        render: Some(fig_17::render),
    },
    TableDef {
        id: "2",
        title: "Speedup of our GPU SAH Kd-tree comparing with Wald's CPU algorithm",
        lines: "L580-587",
        status: Status::Partly,
        note: "seconds not reproducible (i7-4770, GTX 1070); the GPU build runs on the emulator: tree statistics against the serial build, launches, warp instructions, bytes per level counted",
        scenes: &table_2::SCENES,
        groups: &[table_2::BUILDS],
        render: Some(table_2::render),
    },
    TableDef {
        id: "s6.4",
        title: "6.4 A More Efficient Ray-triangle Intersection Algorithm",
        lines: "L538-546",
        status: Status::Reproduced,
        note: "operations per test counted by the emulator on both routines (clang's PTX, not contracted; nvcc's, contracted); the standard routine is our reading (Möller-Trumbore)",
        scenes: &[sec_6_4::SCENE],
        groups: &[sec_6_4::OPS],
        render: Some(sec_6_4::render),
    },
    TableDef {
        id: "s4.8-bootstrap",
        title: "4.8 Metropolis Light Transport",
        lines: "L310-330",
        status: Status::Reproduced,
        note: "r-bar, the start-up's global radiance estimate, against the bootstrap count (not stated): b's error over 8 runs measured natively, b setting the image's luminance measured on the emulator",
        scenes: &fig_9::SCENES,
        groups: &[sec_4_8::BOOTSTRAP_GROUP],
        render: Some(sec_4_8::render),
    },
    TableDef {
        id: "s4.8-large-step",
        title: "4.8 Metropolis Light Transport",
        lines: "L310-324",
        status: Status::Reproduced,
        note: "the large-step probability (0.25 the thesis' example) against the error on a diffuse, a glossy and a caustic box: measured natively (the kernel's probability is a constant)",
        scenes: &sec_4_8::LARGE_STEP_SCENES,
        groups: &[sec_4_8::LARGE_STEP_GROUP],
        render: Some(sec_4_8::render_large_step),
    },
    TableDef {
        id: "s6.3-regroup",
        title: "6.3 Thread Compaction",
        lines: "L501-536",
        status: Status::Modelled,
        note: "the regroup by Fresnel branch (L536, \"up to 30% speedup\"): speedup not reproducible as time, modelled by emulated warp instructions (the 3 compactions included); the shade kernel's divergent branches and useful lanes counted",
        scenes: &sec_6_3::SCENES,
        groups: &[sec_6_3::REGROUP_GROUP],
        render: Some(sec_6_3::render),
    },
    TableDef {
        id: "3",
        title: "Speedup of our path tracer on different graphics cards, comparing with NVIDIA's",
        lines: "L600-605",
        status: Status::NotReproducible,
        note: "TIMING + EXTERNAL; OptiX comparator cannot be emulated; own side only via counted proxies",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4",
        title: "Comparing convergence rate of our path tracer and Cycles Render in 1 minute's render time",
        lines: "L620-625",
        status: Status::NotReproducible,
        note: "IMAGE + EXTERNAL (Cycles); only \"ours\" sigma as image metric at equal samples",
        scenes: &[],
        groups: &[],
        render: None,
    },
];
