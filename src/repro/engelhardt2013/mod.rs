//! Seed 001: Thomas Engelhardt (2013): Efficient From-Point Visibility for Global Illumination in Virtual Scenes with Participating Media.
//!
//! Registered so that `warplight tables --list` shows every table of the
//! seed with its status; none is reproduced yet. A table is reproduced by
//! giving it measurement groups and a render function, as
//! `src/repro/fabianowski2011/` does.

use crate::repro::registry::{Status, TableDef, Thesis};

/// The seed and its tables.
pub static THESIS: Thesis = Thesis {
    short: "engelhardt",
    dir: "engelhardt2013",
    seed: "001",
    seed_file: "001_c2103f8a7e5630e3.txt",
    citation: "Thomas Engelhardt (2013): Efficient From-Point Visibility for Global Illumination in Virtual Scenes with Participating Media",
    tables: &TABLES,
    groups: &[],
};

/// Its tables as printed (captions verbatim from the seed).
static TABLES: [TableDef; 5] = [
    TableDef {
        id: "6.1",
        title: "Average frames per second for the shadow volume example achieved with the SAT and HIB with instancing for a varying number of randomly placed objects. For comparison, we used Direct3D 10 occlusion predicates and no culling (nc). All culling techniques use a 512^2 resolution render target for determining visibility. The rendering resolution was 1600×1050 , each object consists of 606 triangles. Table: Engelhardt and Dachsbacher [2009].",
        lines: "L1111-1119",
        status: Status::Missing,
        note: "modelled when reproduced: class T, whole D3D10 pipeline (GS, shadow volumes, predicates); not reproducible by counting alone",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "6.2",
        title: "Frames per second measured on a NVIDIA 280GTX for the lizard displacement mapping for full and partial visibility (Figure 6.1). The results indicate that HIBs do not suffer from many IDs. Timings for full occlusion are given to estimate the overhead of the methods. The static scene part consists of 134414 triangles, the lizard had 7132 triangles. Table: Engelhardt and Dachsbacher [2009].",
        lines: "L1129-1139",
        status: Status::Missing,
        note: "modelled when reproduced: class T, needs timing model of D3D10 GS pipeline; proxy counts (prisms culled) countable",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "6.3",
        title: "Detailed timings in milliseconds of the CPU tasks when using the SAT approach in the shadow volume example. We also give the average relative and absolute pixel error of the queries. Table: Engelhardt and Dachsbacher [2009].",
        lines: "L1147-1154",
        status: Status::Missing,
        note: "measured when reproduced: conflicts and pixel errors by pure counting (random placement unstated: statistical); ms are CPU timings",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "6.4",
        title: "This table compares the properties and possibilities of natively supported visibility queries and our methods. ¹ the scene has to be rendered twice to resolve mutual occlusion. ² instancing is possible, if the instance transformations are evaluated on the CPU. Table: Engelhardt and Dachsbacher [2009].",
        lines: "L1162-1168",
        status: Status::NotAMeasurement,
        note: "qualitative comparison; only Accuracy column checkable by counting",
        scenes: &[],
        groups: &[],
        render: None,
    },
    TableDef {
        id: "7.1",
        title: "Rendering performance of our test scene for a screen resolution of 1920×1200 . All timings were taken on an Intel Q6600 Core2Duo processor with 2.4GHz, a GeForce 8800GTX running Vista x64 with 4GB of main memory. Table: Engelhardt and Dachsbacher [2008].",
        lines: "L1322-1330",
        status: Status::Missing,
        note: "modelled when reproduced: class T, geometry-shader-output-bound pipeline; needs rasterizer plus GS-output cost model",
        scenes: &[],
        groups: &[],
        render: None,
    },
];
