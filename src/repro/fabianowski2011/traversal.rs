//! Tables 4.5–4.7 (seed 000, L1878–1924): inner-node traversals, frame rates
//! and instructions per ray of the stackless variants relative to stack-based
//! traversal, from the kernels run on the emulator over the flights (group
//! [`super::TRAVERSAL`]).

use super::flight::Totals;
use super::{flight_table, timing_table};
use crate::host::rt_kernels::Variant;
use crate::repro::compare::{Printed as P, Tolerance};
use crate::repro::registry::Entry;
use crate::repro::results::Results;
use crate::repro::table::{Column, Published, PublishedRow as Row, Table, Unit};

/// The columns' names as printed.
const NAMES: [&str; 5] = ["Stack-based", "Stackless", "push-down", "short-stack", "push-down + short-stack"];

/// Table 4.5 as printed (L1878–1888).
pub const TABLE_4_5: Published = Published {
    rows: &[
        Row { scene: "scene6", cells: &[P("7.31"), P("+35.7%"), P("+21.1%"), P("±0.0%"), P("±0.0%")] },
        Row { scene: "sponza", cells: &[P("29.81"), P("+136.7%"), P("+97.1%"), P("+0.3%"), P("+0.2%")] },
        Row { scene: "sibenik", cells: &[P("37.63"), P("+151.5%"), P("+107.2%"), P("+0.8%"), P("+0.8%")] },
        Row { scene: "fairy", cells: &[P("37.43"), P("+182.7%"), P("+98.2%"), P("+0.6%"), P("+0.6%")] },
        Row { scene: "conference", cells: &[P("19.57"), P("+108.1%"), P("+59.4%"), P("+0.3%"), P("+0.3%")] },
    ],
    average: &[P(""), P("+122.9%"), P("+76.6%"), P("+0.4%"), P("+0.4%")],
    std_dev: &[P(""), P("55.7%"), P("36.0%"), P("0.3%"), P("0.3%")],
};

/// Table 4.6 as printed (L1902–1912).
pub const TABLE_4_6: Published = Published {
    rows: &[
        Row { scene: "scene6", cells: &[P("392.6"), P("−5.3%"), P("−2.6%"), P("−1.3%"), P("−2.5%")] },
        Row { scene: "sponza", cells: &[P("213.7"), P("−37.1%"), P("−30.6%"), P("−8.7%"), P("−12.2%")] },
        Row { scene: "sibenik", cells: &[P("194.6"), P("−43.5%"), P("−35.8%"), P("−10.2%"), P("−13.8%")] },
        Row { scene: "fairy", cells: &[P("149.0"), P("−41.6%"), P("−29.8%"), P("−11.6%"), P("−14.9%")] },
        Row { scene: "conference", cells: &[P("172.0"), P("−18.1%"), P("−11.4%"), P("−4.6%"), P("−7.2%")] },
    ],
    average: &[P(""), P("−29.1%"), P("−22.0%"), P("−7.3%"), P("−10.1%")],
    std_dev: &[P(""), P("16.7%"), P("14.3%"), P("4.2%"), P("5.2%")],
};

/// Table 4.7 as printed (L1914–1924).
pub const TABLE_4_7: Published = Published {
    rows: &[
        Row { scene: "scene6", cells: &[P("674.2"), P("+18.4%"), P("+14.6%"), P("+13.6%"), P("+16.8%")] },
        Row { scene: "sponza", cells: &[P("2249.9"), P("+75.1%"), P("+61.5%"), P("+24.0%"), P("+29.8%")] },
        Row { scene: "sibenik", cells: &[P("2294.9"), P("+96.0%"), P("+74.8%"), P("+27.4%"), P("+34.0%")] },
        Row { scene: "fairy", cells: &[P("3129.6"), P("+90.5%"), P("+59.9%"), P("+28.8%"), P("+35.3%")] },
        Row { scene: "conference", cells: &[P("2246.2"), P("+42.0%"), P("+29.6%"), P("+16.5%"), P("+20.3%")] },
    ],
    average: &[P(""), P("+64.4%"), P("+48.1%"), P("+22.1%"), P("+27.2%")],
    std_dev: &[P(""), P("33.2%"), P("25.0%"), P("6.7%"), P("8.3%")],
};

fn columns(absolute: Unit, absolute_tolerance: Option<Tolerance>, why: Option<&str>) -> Vec<Column> {
    let mut c = vec![match absolute_tolerance {
        Some(t) => Column::measured(NAMES[0], absolute, t),
        None => Column::measured(NAMES[0], absolute, Tolerance::COUNT).uncompared(why.unwrap_or("")),
    }];
    c.extend(NAMES[1..].iter().map(|n| Column::measured(n, Unit::Change, Tolerance::RATIO)));
    c
}

/// Table 4.5: inner-node traversals per ray.
pub fn render_4_5(e: &Entry, r: &Results) -> Vec<Table> {
    let cols = columns(Unit::Number(2), Some(Tolerance::COUNT), None);
    vec![flight_table(e, r, &e.heading(), super::TRAVERSAL, &Variant::ALL, &TABLE_4_5, cols, |t| {
        per_ray(t, t.inner_nodes)
    })]
}

/// Table 4.7: instructions per ray (warp instructions × 32 / rays, L2142).
pub fn render_4_7(e: &Entry, r: &Results) -> Vec<Table> {
    let cols = columns(
        Unit::Number(1),
        None,
        Some("PTX instructions of clang's code, not GT200 SASS, and the thesis' per-ray normalisation is not stated"),
    );
    let mut t = flight_table(e, r, &e.heading(), super::TRAVERSAL, &Variant::ALL, &TABLE_4_7, cols, |t| {
        per_ray(t, 32 * t.warp_instructions)
    });
    t.notes.push("Instructions: every warp instruction counted for all 32 threads (seed L2142).".into());
    vec![t]
}

/// Table 4.6: frame rates from the GT200 timing model.
pub fn render_4_6(e: &Entry, r: &Results) -> Vec<Table> {
    vec![timing_table(e, r, super::TRAVERSAL, &Variant::ALL, &NAMES, &TABLE_4_6)]
}

/// A count per ray.
pub fn per_ray(t: &Totals, n: u64) -> f64 {
    n as f64 / t.rays.max(1) as f64
}
