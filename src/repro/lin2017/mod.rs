//! Seed 003: Lin Daqi (2017): Real Time Path Tracing on GPU.
//!
//! Registered so that `warplight tables --list` shows every table of the
//! seed with its status; none is reproduced yet. A table is reproduced by
//! giving it measurement groups and a render function, as
//! `src/repro/fabianowski2011/` does.

pub mod render;

use crate::repro::registry::{Status, TableDef, Thesis};

/// The seed and its tables.
pub static THESIS: Thesis = Thesis {
    short: "lin",
    dir: "lin2017",
    seed: "003",
    seed_file: "003_0cecf91ec9b1cabd.txt",
    citation: "Lin Daqi (2017): Real Time Path Tracing on GPU",
    tables: &TABLES,
    groups: &[],
};

/// Its tables as printed (captions verbatim from the seed).
static TABLES: [TableDef; 4] = [
    TableDef {
        id: "1",
        title: "Speedup of triangle clipping for different models",
        lines: "L153-160",
        status: Status::Missing,
        note: "modelled when reproduced: TIMING; resolution/spp/camera not stated; proxy counts tri-tests and node visits per ray",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "2",
        title: "Speedup of our GPU SAH Kd-tree comparing with Wald's CPU algorithm",
        lines: "L580-587",
        status: Status::Missing,
        note: "modelled when reproduced: TIMING, CPU column EXTERNAL; COUNT proxies tree stats, launches, bytes per level",
        scenes: &[],
        groups: &[],
        render: None,
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
