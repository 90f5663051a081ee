//! Thesis 000 Table 4.3: inner-node traversals, triangle-plane intersections
//! and barycentric calculations per ray with the numerical approximation of
//! §4.1.2 and with SIROH, relative to the SAH (seed 000, L1699–1709). Purely
//! functional counts: the native caster performs the stack-based kernel's
//! traversal step for step (tests/raytrace.rs), so it counts them here.

use super::table_4_1::HEURISTICS_RUN;
use super::{HEURISTIC_COUNTS, run_note, scenes_of};
use crate::host::raycast::{Caster, render as cast};
use crate::repro::compare::{Printed as P, Tolerance};
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Column, Published, PublishedRow as Row, Table, Unit};

/// Table 4.3 as printed (L1699–1709): traversals, plane intersections and
/// triangle (barycentric) intersections, each SAH absolute, 4.1.2 and SIROH relative.
pub const THESIS: Published = Published {
    rows: &[
        Row {
            scene: "scene6",
            cells: &[
                P("9.68"),
                P("−24.9%"),
                P("−25.2%"),
                P("7.59"),
                P("−15.3%"),
                P("−14.3%"),
                P("1.10"),
                P("−7.3%"),
                P("−3.0%"),
            ],
        },
        Row {
            scene: "sponza",
            cells: &[
                P("30.83"),
                P("−0.5%"),
                P("−4.3%"),
                P("7.95"),
                P("+1.1%"),
                P("+25.5%"),
                P("3.06"),
                P("−12.3%"),
                P("−13.7%"),
            ],
        },
        Row {
            scene: "sibenik",
            cells: &[
                P("40.44"),
                P("−5.8%"),
                P("−5.6%"),
                P("5.06"),
                P("−11.0%"),
                P("−10.5%"),
                P("2.04"),
                P("−7.2%"),
                P("−4.0%"),
            ],
        },
        Row {
            scene: "fairy",
            cells: &[
                P("41.30"),
                P("+5.5%"),
                P("−1.1%"),
                P("8.09"),
                P("−5.7%"),
                P("−3.9%"),
                P("2.35"),
                P("−2.8%"),
                P("−6.5%"),
            ],
        },
        Row {
            scene: "conference",
            cells: &[
                P("23.56"),
                P("−13.0%"),
                P("−18.6%"),
                P("12.99"),
                P("−21.4%"),
                P("−17.4%"),
                P("2.29"),
                P("−6.1%"),
                P("+1.4%"),
            ],
        },
    ],
    average: &[P(""), P("−7.7%"), P("−11.0%"), P(""), P("−10.4%"), P("−4.1%"), P(""), P("−7.1%"), P("−5.2%")],
    std_dev: &[P(""), P("11.8%"), P("10.4%"), P(""), P("8.7%"), P("17.3%"), P(""), P("3.4%"), P("5.6%")],
};

/// The counters, in the table's order.
pub const COUNTERS: [&str; 3] = ["inner_nodes", "plane_tests", "barycentric_tests"];

/// Measurement group [`HEURISTIC_COUNTS`]: the native caster over the flight on each heuristic's tree.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let mut out = Vec::new();
    for (h, name) in HEURISTICS_RUN {
        ws.build(h);
        let caster = Caster::new(ws.scene, ws.tree(h));
        for f in ws.frames.clone() {
            tick(Tick { frame: Some(f), variant: name });
            let cam = super::flight::camera(ws.scene, f, ws.resolution);
            let st = cast(&caster, &cam, ws.scene.flight.light_offset(f)).1;
            let values = [st.rays, st.inner_nodes, st.plane_tests, st.barycentric_tests];
            out.push(Sample {
                group: HEURISTIC_COUNTS.into(),
                scene: ws.scene.name.clone(),
                frame: Some(f),
                variant: name.into(),
                counters: ["rays", COUNTERS[0], COUNTERS[1], COUNTERS[2]]
                    .iter()
                    .zip(values)
                    .map(|(n, v)| (n.to_string(), v as f64))
                    .collect(),
            });
        }
    }
    Ok(out)
}

/// Per heuristic (SAH, 4.1.2, SIROH): traversals, plane and barycentric tests per ray.
pub fn per_ray(r: &Results, scene: &str) -> Option<[[f64; 3]; 3]> {
    let mut out = [[0.0; 3]; 3];
    for (i, (_, name)) in HEURISTICS_RUN.iter().enumerate() {
        let rays = r.sum(HEURISTIC_COUNTS, scene, name, "rays")?.max(1.0);
        for (q, c) in COUNTERS.iter().enumerate() {
            out[i][q] = r.sum(HEURISTIC_COUNTS, scene, name, c)? / rays;
        }
    }
    Some(out)
}

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let scenes = scenes_of(r, HEURISTIC_COUNTS);
    let mut columns = Vec::new();
    for q in ["Trav.", "Plane", "Tri"] {
        columns.push(Column::measured(&format!("{q} SAH"), Unit::Number(2), Tolerance::COUNT));
        columns.push(Column::measured(&format!("{q} 4.1.2"), Unit::Change, Tolerance::RATIO));
        columns.push(Column::measured(&format!("{q} SIROH"), Unit::Change, Tolerance::RATIO));
    }
    let ours: Vec<(String, Vec<f64>)> = scenes
        .iter()
        .filter_map(|s| {
            let p = per_ray(r, s)?;
            let mut v = Vec::new();
            for ((sah, num), siroh) in p[0].iter().zip(p[1]).zip(p[2]) {
                v.push(*sah);
                v.push((num / sah - 1.0) * 100.0);
                v.push((siroh / sah - 1.0) * 100.0);
            }
            Some((s.clone(), v))
        })
        .collect();
    let mut t = Table::compare(&e.address(), &e.heading(), columns, &THESIS, &ours);
    t.notes.push(run_note(
        r,
        &scenes,
        "stack-based traversal counted by the native caster (step for step the stack kernel), primary, shadow and reflection rays",
    ));
    vec![t]
}
