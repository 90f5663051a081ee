//! Thesis 000 Table 6.3 (seed 000, L2683–2699): photon map node traversals,
//! interaction retrievals per query point and rendering frame rates with
//! LBVH construction, relative to the VVH.
//!
//! n_T and n_I are measured by [`super::vvh`] (both trees with n_auto); the
//! frame rates are modelled: the GTX 280 timing model on the emulator's
//! counters of each frame's camera rays and gather ([`vvh::frame_rate`]).

use super::vvh::{self, Builder};
use crate::repro::compare::{Printed as P, Tolerance, mean_sd};
use crate::repro::registry::Entry;
use crate::repro::results::Results;
use crate::repro::table::{Check, Column, Published, PublishedRow as Row, Table, Unit};

/// Table 6.3 as printed: Interactions, n_T VVH, n_T LBVH, n_I VVH, n_I LBVH, FPS VVH, FPS LBVH.
pub const THESIS: Published = Published {
    rows: &[
        Row {
            scene: "scene6",
            cells: &[P("160298"), P("288.4"), P("+4.3%"), P("1163.8"), P("+8.9%"), P("3.74"), P("−3.9%")],
        },
        Row {
            scene: "scene6 (2^18, s=28)",
            cells: &[P("319997"), P("334.7"), P("+2.7%"), P("2636.1"), P("+9.1%"), P("1.67"), P("−5.8%")],
        },
        Row {
            scene: "sponza",
            cells: &[P("292551"), P("401.4"), P("+14.1%"), P("386.4"), P("+8.7%"), P("7.13"), P("−8.4%")],
        },
        Row {
            scene: "sibenik",
            cells: &[P("413316"), P("461.9"), P("+13.3%"), P("466.5"), P("+8.6%"), P("6.12"), P("−12.8%")],
        },
        Row {
            scene: "fairy",
            cells: &[P("8911"), P("114.2"), P("+29.5%"), P("89.9"), P("+6.1%"), P("33.58"), P("−7.4%")],
        },
        Row {
            scene: "conference",
            cells: &[P("97911"), P("392.6"), P("+13.5%"), P("596.3"), P("+10.3%"), P("6.11"), P("−7.7%")],
        },
        Row {
            scene: "conference (2^19, s=50)",
            cells: &[P("390223"), P("587.1"), P("+9.7%"), P("3494.4"), P("+12.3%"), P("1.11"), P("−10.2%")],
        },
        Row {
            scene: "passage",
            cells: &[P("70256"), P("211.3"), P("+11.8%"), P("1683.6"), P("+7.2%"), P("5.67"), P("−7.9%")],
        },
        Row {
            scene: "ring",
            cells: &[P("74101"), P("369.9"), P("+21.0%"), P("481.9"), P("+13.1%"), P("9.40"), P("−12.7%")],
        },
    ],
    average: &[P(""), P(""), P("+13.3%"), P(""), P("+9.4%"), P(""), P("−8.5%")],
    std_dev: &[P(""), P(""), P("8.1%"), P(""), P("2.2%"), P(""), P("3.0%")],
};

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let scenes = vvh::rows(r);
    let model = super::timing::MODEL;
    let columns = vec![
        Column::measured("Interactions", Unit::Number(0), Tolerance::COUNT),
        Column::measured("n_T VVH", Unit::Number(1), Tolerance::COUNT),
        Column::measured("n_T LBVH", Unit::Change, Tolerance::RATIO),
        Column::measured("n_I VVH", Unit::Number(1), Tolerance::COUNT),
        Column::measured("n_I LBVH", Unit::Change, Tolerance::RATIO),
        Column::modelled("FPS VVH", Unit::Number(2), model, Some(super::timing::FPS_TOLERANCE), None),
        Column::modelled("FPS LBVH", Unit::Change, model, Some(Tolerance::RATIO), None),
    ];
    let auto = |b| vvh::variant(b, None);
    let ours: Vec<(String, Vec<f64>)> = scenes
        .iter()
        .filter_map(|s| {
            let v = vvh::measured(r, s, &auto(Builder::Vvh))?;
            let l = vvh::measured(r, s, &auto(Builder::Lbvh))?;
            let ch = |a: f64, b: f64| (a / b - 1.0) * 100.0;
            let fv = vvh::frame_rate(r, s, &auto(Builder::Vvh));
            let fl = vvh::frame_rate(r, s, &auto(Builder::Lbvh));
            Some((s.clone(), vec![v.interactions, v.n_t, ch(l.n_t, v.n_t), v.n_i, ch(l.n_i, v.n_i), fv, ch(fl, fv)]))
        })
        .collect();
    let mut t = Table::compare(&e.address(), &e.heading(), columns, &THESIS, &ours);
    if !ours.is_empty() {
        let (nt, _) = mean_sd(&ours.iter().map(|(_, v)| v[2]).collect::<Vec<_>>());
        let (ni, _) = mean_sd(&ours.iter().map(|(_, v)| v[4]).collect::<Vec<_>>());
        t.checks.push(Check {
            claim: "the LBVH's spatial-median splits cost more traversal than the VVH: \"13.3% more nodes are \
                    traversed and 9.4% more interactions retrieved on average\" (L2699)"
                .into(),
            evidence: format!("ours: n_T {nt:+.1}%, n_I {ni:+.1}% on average"),
            holds: nt > 0.0 && ni > 0.0,
        });
        let fl: Vec<f64> = ours.iter().map(|(_, v)| v[6]).filter(|x| x.is_finite()).collect();
        if fl.len() == ours.len() {
            let (m, _) = mean_sd(&fl);
            t.checks.push(Check {
                claim: "LBVH photon maps render slower than VVH ones: \"-8.5%\" FPS on average (Table 6.3), \
                        modelled: the GTX 280 timing model predicts a lower frame rate with the LBVH"
                    .into(),
                evidence: format!(
                    "ours (modelled): FPS LBVH {m:+.1}% on average, lower in {} of {} rows",
                    fl.iter().filter(|x| **x < 0.0).count(),
                    fl.len()
                ),
                holds: m < 0.0,
            });
        }
    }
    t.notes.push(vvh::run_note(r, &scenes, "VVH and LBVH photon maps with n_auto, native walks"));
    t.notes.push(vvh::HOW.into());
    t.notes.push(vvh::scenario_note(&scenes));
    t.notes.push(vvh::fps_note());
    let fps: Vec<(String, f64)> = ours.iter().map(|(l, v)| (l.clone(), v[5])).collect();
    if let Some(n) = super::timing::unmeasured_note(&fps) {
        t.notes.push(n);
    }
    t.notes.push(super::timing::error_note(&t));
    vec![t]
}
