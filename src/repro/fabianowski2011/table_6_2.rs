//! Thesis 000 Table 6.2 (seed 000, L2667–2681): photon map node counts,
//! relative to the VVH, and construction timings with LBVH.
//!
//! Interactions and node counts (inner nodes and leaves, both built with
//! n_auto) are measured by [`super::vvh`]; the LBVH construction times are a
//! GTX 280's and not reproduced. The scenarios Scene 6 with 2^18 photons and
//! Conference with 2^19 (§6.1.4) are rows of their own ([`vvh::SCENARIOS`]).

use super::vvh::{self, Builder};
use super::{table_6_6, timing};
use crate::repro::compare::{Printed as P, Tolerance, mean_sd};
use crate::repro::registry::Entry;
use crate::repro::results::Results;
use crate::repro::table::{Check, Column, Published, PublishedRow as Row, Table, Unit};

/// Table 6.2 as printed: Interactions, Nodes VVH, Nodes LBVH, LBVH construction (ms).
pub const THESIS: Published = Published {
    rows: &[
        Row { scene: "scene6", cells: &[P("160298"), P("23313"), P("−5.8%"), P("10.68")] },
        Row { scene: "scene6 (2^18, s=28)", cells: &[P("319997"), P("24839"), P("−7.0%"), P("19.27")] },
        Row { scene: "sponza", cells: &[P("292551"), P("166635"), P("+2.8%"), P("18.13")] },
        Row { scene: "sibenik", cells: &[P("413316"), P("236247"), P("+3.3%"), P("26.02")] },
        Row { scene: "fairy", cells: &[P("8911"), P("5345"), P("+5.2%"), P("2.67")] },
        Row { scene: "conference", cells: &[P("97911"), P("36557"), P("−1.4%"), P("7.31")] },
        Row { scene: "conference (2^19, s=50)", cells: &[P("390223"), P("39411"), P("−4.3%"), P("24.53")] },
        Row { scene: "passage", cells: &[P("70256"), P("5477"), P("−7.7%"), P("6.06")] },
        Row { scene: "ring", cells: &[P("74101"), P("31081"), P("−1.1%"), P("6.28")] },
    ],
    average: &[P(""), P(""), P("−1.8%"), P("")],
    std_dev: &[P(""), P(""), P("4.7%"), P("")],
};

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let scenes = vvh::rows(r);
    let columns = vec![
        Column::measured("Interactions", Unit::Number(0), Tolerance::COUNT),
        Column::measured("Nodes VVH", Unit::Number(0), Tolerance::COUNT),
        Column::measured("Nodes LBVH", Unit::Change, Tolerance::RATIO),
        Column::modelled("LBVH ms", Unit::Number(2), timing::MODEL, Some(timing::FPS_TOLERANCE), None),
    ];
    let auto = |b| vvh::variant(b, None);
    let ours: Vec<(String, Vec<f64>)> = scenes
        .iter()
        .filter_map(|s| {
            let v = vvh::measured(r, s, &auto(Builder::Vvh))?;
            let l = vvh::measured(r, s, &auto(Builder::Lbvh))?;
            // the build recorded once per row (vvh::LBVH_BUILD): its launches, each at its own grid
            let ms = table_6_6::recorded_ms(r, vvh::PM_BUILDERS, s, &auto(Builder::Lbvh), vvh::LBVH_BUILD, 1.0);
            Some((s.clone(), vec![v.interactions, v.nodes, (l.nodes / v.nodes - 1.0) * 100.0, ms.unwrap_or(f64::NAN)]))
        })
        .collect();
    let mut t = Table::compare(&e.address(), &e.heading(), columns, &THESIS, &ours);
    if !ours.is_empty() {
        let rel: Vec<f64> = ours.iter().map(|(_, v)| v[2]).collect();
        let (m, sd) = mean_sd(&rel);
        t.checks.push(Check {
            claim: "LBVH node counts within a few percent of the VVH's (average −1.8%, SD 4.7%)".into(),
            evidence: format!("ours: {m:+.1}% on average, SD {sd:.1}%"),
            holds: m.abs() <= 15.0,
        });
    }
    t.notes.push(vvh::run_note(r, &scenes, "VVH and LBVH photon maps with n_auto (native builds)"));
    let ms: Vec<(String, f64)> = ours.iter().map(|(l, v)| (l.clone(), v[3])).collect();
    t.notes.push(match timing::unmeasured_note(&ms) {
        Some(n) => n,
        None => format!(
            "LBVH ms (modelled): lbvh.cu's launches building the LBVH with n_auto on the emulator (Morton codes, the \
             radix sorts by code and by level, runs, levels, merges), each launch's gt200 counters predicted at its \
             own grid by the {} (the build's counts are not scaled: they do not depend on the image) and summed, as Table 6.6's LBVH ms; within ±15 % relative. The thesis' times include \
             what our launches do not model (driver and launch overheads, its own radix sort).",
            timing::describe()
        ),
    });
    t.notes.push(vvh::HOW.into());
    t.notes.push(vvh::scenario_note(&scenes));
    t.notes.push(
        "Nodes count inner nodes and leaves. The thesis' interaction counts differ from its own Table 5.1 (extract \
         erratum 9); ours are those of our Table 5.1 run."
            .into(),
    );
    vec![t]
}
