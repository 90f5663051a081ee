//! Seed 002: Mahmoud Zeidan (2011): Applying Parallel Processing Approach for Interactive Global Illumination.
//!
//! Registered so that `warplight tables --list` shows every table of the
//! seed with its status; none is reproduced yet. A table is reproduced by
//! giving it measurement groups and a render function, as
//! `src/repro/fabianowski2011/` does.

use crate::repro::registry::{Status, TableDef, Thesis};

/// The seed and its tables.
pub static THESIS: Thesis = Thesis {
    short: "zeidan",
    dir: "zeidan2011",
    seed: "002",
    seed_file: "002_74e6b19bea473f3c.txt",
    citation: "Mahmoud Zeidan (2011): Applying Parallel Processing Approach for Interactive Global Illumination",
    tables: &TABLES,
    groups: &[],
};

/// Its tables as printed (captions verbatim from the seed).
static TABLES: [TableDef; 12] = [
    TableDef {
        id: "3.1",
        title: "Device memory spaces and corresponding size on NVIDIA GTX285 card.",
        lines: "L410-417",
        status: Status::NotAMeasurement,
        note: "STATIC spec table; an emulator config target",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "3.2",
        title: "Frequently used scan operations.",
        lines: "L456-461",
        status: Status::NotAMeasurement,
        note: "STATIC table of scan operators and identities",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.1",
        title: "Parallel utilities which will be used in all subsequent sections.",
        lines: "L576-591",
        status: Status::NotAMeasurement,
        note: "STATIC API list; implement each as emulated kernels",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.2",
        title: "Benchmark scenes used in our experiments.",
        lines: "L1145-1152",
        status: Status::NotAMeasurement,
        note: "STATIC fixture list; triangle counts usable as loader check",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.3",
        title: "KD-tree build time, ray casting, and tree quality statistics for our test scenes.",
        lines: "L1164-1171",
        status: Status::Missing,
        note: "measured when reproduced: SAH and #nodes/MB countable (parameters partly unstated); ms/fps need GTX 285 timing model",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.4",
        title: "Number of small roots and initial memory size.",
        lines: "L1175-1182",
        status: Status::Missing,
        note: "measured when reproduced: # small roots and initial memory size class COUNT; \"initial memory\" definition not stated",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.5",
        title: "SAH BVH build time, ray casting, and tree quality statistics for our test scenes.",
        lines: "L1217-1224",
        status: Status::Missing,
        note: "measured when reproduced: SAH and #nodes/MB countable (~40 B/node); ms/fps need GTX 285 timing model",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.6",
        title: "LBVH build time, ray casting, and tree quality statistics for our test scenes.",
        lines: "L1226-1233",
        status: Status::Missing,
        note: "measured when reproduced: SAH and #nodes/MB countable, node counts constrain Morton bits; ms/fps need timing model",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.7",
        title: "Hybrid SAH BVH build time, ray casting, and tree quality statistics for our test scenes.",
        lines: "L1235-1242",
        status: Status::Missing,
        note: "measured when reproduced: SAH and #nodes/MB countable (LBVH split level unstated); ms/fps need timing model",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.8",
        title: "Binned SAH BVH build time, ray casting, and tree quality statistics for our test scenes using five stages.",
        lines: "L1244-1251",
        status: Status::Missing,
        note: "measured when reproduced: SAH and #nodes/MB countable (leaf policy unstated); ms/fps need GTX 285 timing model",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "4.9",
        title: "Hybrid binned SAH BVH build time, ray casting, and tree quality statistics for our test scenes.",
        lines: "L1255-1262",
        status: Status::Missing,
        note: "measured when reproduced: SAH and #nodes/MB countable; ms/fps need GTX 285 timing model",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "5.1",
        title: "Ray tracing rendering time for our test scenes",
        lines: "L1750-1760",
        status: Status::Missing,
        note: "modelled when reproduced: class TIMING; ray/bounce counts would be countable only with camera/material fixtures",
        scenes: &[],
        groups: &[],
        render: None,
    },
];
