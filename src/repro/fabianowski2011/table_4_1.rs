//! Thesis 000 Table 4.1: ray-tracing frame rates with the numerical
//! approximation of §4.1.2 and with SIROH, relative to the SAH (seed 000,
//! L1664–1674). The thesis measured two CUDA code bases on a GTX 280; we run
//! the stack-based kernel (code base II's traversal) over each heuristic's
//! tree on the emulator and turn its counts into frame rates with the GTX 280
//! timing model ([`super::timing`]; parameters from specifications and
//! microbenchmarks, none from the thesis). Code base II's SAH frame rates are
//! predicted and compared; code base I is not described beyond §A.1.1, so only
//! its relative columns are compared (with our one kernel's).

use super::flight;
use super::{HEURISTICS, run_note, scenes_of, timing};
use crate::host::kdtree::Heuristic;
use crate::host::rt_kernels::Variant;
use crate::repro::compare::{Printed as P, Tolerance};
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Column, Published, PublishedRow as Row, Table, Unit};

/// Table 4.1 as printed (L1664–1674): code base I (SAH fps, 4.1.2, SIROH), code base II (SAH fps, SIROH).
pub const THESIS: Published = Published {
    rows: &[
        Row { scene: "scene6", cells: &[P("382.2"), P("+7.5%"), P("+7.0%"), P("341.8"), P("+14.9%")] },
        Row { scene: "sponza", cells: &[P("99.6"), P("+1.9%"), P("±0.0%"), P("215.6"), P("−0.8%")] },
        Row { scene: "sibenik", cells: &[P("101.0"), P("+2.0%"), P("+2.1%"), P("189.4"), P("+2.7%")] },
        Row { scene: "fairy", cells: &[P("75.9"), P("+1.3%"), P("+2.7%"), P("144.1"), P("+3.4%")] },
        Row { scene: "conference", cells: &[P("71.9"), P("+5.1%"), P("+4.2%"), P("171.0"), P("+0.5%")] },
    ],
    average: &[P(""), P("+3.5%"), P("+3.2%"), P(""), P("+4.1%")],
    std_dev: &[P(""), P("2.7%"), P("2.6%"), P(""), P("6.2%")],
};

/// The heuristics, in the table's order, with their variant names in the results.
pub const HEURISTICS_RUN: [(Heuristic, &str); 3] =
    [(Heuristic::Sah, "sah"), (Heuristic::Numerical, "numerical"), (Heuristic::Siroh, "siroh")];

/// Measurement group [`HEURISTICS`]: the stack kernel over the flight on each heuristic's tree.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let mut out = Vec::new();
    for (h, name) in HEURISTICS_RUN {
        ws.build(h);
        out.extend(flight::samples(ws, ws.tree(h), HEURISTICS, &[(Variant::Stack, name)], tick)?);
    }
    Ok(out)
}

/// Predicted frame rates per heuristic (SAH, 4.1.2, SIROH); NaN where not measured.
pub fn predicted(r: &Results, scene: &str) -> [f64; 3] {
    HEURISTICS_RUN.map(|(_, name)| timing::fps(r, HEURISTICS, scene, name))
}

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let scenes = scenes_of(r, HEURISTICS);
    let model = "GTX 280 timing model";
    let columns = vec![
        Column::not_reproducible("CB I SAH", Unit::Number(1), "code base I is not described beyond its frame rates"),
        Column::modelled("CB I 4.1.2", Unit::Change, model, Some(Tolerance::RATIO), None),
        Column::modelled("CB I SIROH", Unit::Change, model, Some(Tolerance::RATIO), None),
        Column::modelled("CB II SAH", Unit::Number(1), model, Some(timing::FPS_TOLERANCE), None),
        Column::modelled("CB II SIROH", Unit::Change, model, Some(Tolerance::RATIO), None),
    ];
    let ours: Vec<(String, Vec<f64>)> = scenes
        .iter()
        .map(|s| {
            let p = predicted(r, s);
            let num = (p[1] / p[0] - 1.0) * 100.0;
            let siroh = (p[2] / p[0] - 1.0) * 100.0;
            (s.clone(), vec![f64::NAN, num, siroh, p[0], siroh])
        })
        .collect();
    let mut t = Table::compare(&e.address(), &e.heading(), columns, &THESIS, &ours);
    t.notes.push(
        "Our 4.1.2 and SIROH columns are one kernel's; both code bases' relative columns are compared with them."
            .into(),
    );
    t.notes.push(format!("{}.", timing::describe()));
    t.notes.push(timing::error_note(&t));
    t.notes.push(run_note(r, &scenes, "the stack-based kernel on each heuristic's tree"));
    vec![t]
}
