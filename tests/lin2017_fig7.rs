//! Thesis 003's Fig. 7 (003:L291-293): the balance against the power
//! heuristic, compared by histogram correlation with a ground truth
//! (`warplight tables lin:fig7`). The table's recorded values and verdicts,
//! and its checks failing where the evidence says otherwise.

mod lin2017_tables;
use lin2017_tables::{checks_of, load, table_named};
use std::collections::BTreeMap;

use warplight::repro::lin2017::fig_7::{self, HEURISTICS, ROWS, SCENE, SEEDS};
use warplight::repro::registry::Workspace;
use warplight::repro::results::Sample;
use warplight::repro::table::Table;

fn table_of(samples: Vec<Sample>) -> Table {
    table_named("lin:fig7", HEURISTICS, &samples)
}

/// The measured table: seed 0's correlations and errors (emulated) and the
/// checks. A change to the path kernel's MIS or to the ground truth moves
/// these: re-measure and update `docs/reproduction-lin2017.md`.
#[test]
fn fig7_records_its_values_and_checks() {
    let scene = load(SCENE);
    let mut ws = Workspace::new(&scene, 0..1, 32);
    let samples = fig_7::measure(&mut ws, &mut |_| {}).expect("measure");
    let t = table_of(samples);
    let ours: Vec<Vec<Option<f64>>> = t.rows.iter().map(|r| r.cells.iter().map(|c| c.ours).collect()).collect();
    eprintln!("{ours:?}");
    let holds = checks_of(&t);
    for (row, want) in ours.iter().zip(RECORDED) {
        for (got, w) in row.iter().zip(want) {
            let got = got.expect("measured");
            assert!((got - w).abs() < 1e-6, "{ours:?}");
        }
    }
    assert_eq!(holds, CHECKS);
}

/// Per row (balance, power): 256-, 64- and 16-bin correlation and RMS error
/// of seed 0 (emulated), mean correlation and mean RMS error over 16 seeds.
const RECORDED: [[f64; 6]; 2] = [
    [0.799218, 0.847709, 0.907583, 0.079825, 0.803354, 0.083979],
    [0.798772, 0.847011, 0.906859, 0.079515, 0.803263, 0.083529],
];

/// power above balance at seed 0: no; a minor difference: yes; lower
/// variance (paired t over 16 seeds): yes; the histogram correlation tells
/// them apart over 16 seeds: no (7 of 16); the ground truth's mean against
/// Mitsuba: yes; emulated = native: yes.
const CHECKS: [bool; 6] = [false, true, true, false, true, true];

/// Synthetic counters: per row, seed 0's values and per seed the RMS error
/// `err(row, seed)` and 256-bin correlation `corr(row, seed)`.
fn synthetic(err: impl Fn(usize, u32) -> f64, corr: impl Fn(usize, u32) -> f64) -> Vec<Sample> {
    ROWS.iter()
        .enumerate()
        .map(|(i, (integrator, _))| {
            let mut k = BTreeMap::new();
            for b in fig_7::BINS {
                k.insert(format!("corr{b}"), corr(i, 0));
            }
            k.insert("rmse".to_string(), err(i, 0));
            k.insert("same_image".to_string(), 1.0);
            k.insert("truth_y".to_string(), 0.2);
            k.insert("mitsuba_y".to_string(), 0.2);
            k.insert("mitsuba_rel_noise".to_string(), 0.001);
            for s in 0..SEEDS {
                k.insert(format!("rmse_s{s}"), err(i, s));
                k.insert(format!("corr256_s{s}"), corr(i, s));
            }
            Sample {
                group: HEURISTICS.into(),
                scene: SCENE.into(),
                frame: None,
                variant: integrator.name().into(),
                counters: k,
            }
        })
        .collect()
}

#[test]
fn the_checks_follow_the_evidence() {
    // power lower in error on every seed (by a varying margin) and higher in correlation: all hold
    let t = table_of(synthetic(|i, s| 0.1 - 0.001 * i as f64 * (1.0 + (s % 3) as f64), |i, _| 0.75 + 0.003 * i as f64));
    assert!(t.checks.iter().all(|c| c.holds), "{:?}", t.checks);
    // power higher in error: the variance check fails; correlation lower and far apart: order and minor fail
    let t = table_of(synthetic(|i, s| 0.1 + 0.001 * i as f64 * (1.0 + (s % 3) as f64), |i, _| 0.75 - 0.1 * i as f64));
    let holds: Vec<bool> = t.checks.iter().map(|c| c.holds).collect();
    assert_eq!(holds, [false, false, false, false, true, true], "{:?}", t.checks);
    // a ground truth 5 % off Mitsuba's fails its check
    let mut samples = synthetic(|_, _| 0.1, |_, _| 0.75);
    for s in &mut samples {
        s.counters.insert("truth_y".into(), 0.21);
    }
    assert!(!table_of(samples).checks[4].holds);
}
