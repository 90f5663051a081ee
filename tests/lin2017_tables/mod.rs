//! What the tests of thesis 003's registry tables share: a table rendered
//! from measured samples as `warplight tables` renders it, a scene loaded by
//! name, the checks printed and the recorded values asserted. Each test
//! file uses some of them.
#![allow(dead_code)]

use warplight::host::scene::Scene;
use warplight::repro::protocol::Protocol;
use warplight::repro::registry::resolve;
use warplight::repro::results::{Results, Sample};
use warplight::repro::table::Table;

/// The registered table `address` (its first) rendered from `samples` of measurement group `group`.
pub fn table_named(address: &str, group: &str, samples: &[Sample]) -> Table {
    let mut r = Results::new("test", Protocol::quick(), vec![address.into()], vec![group.into()]);
    r.samples = samples.to_vec();
    let e = resolve(&[address.into()]).expect("registered").remove(0);
    (e.table.render.expect("rendered"))(&e, &r).remove(0)
}

/// The scene `name` of `scenes/`.
pub fn load(name: &str) -> Scene {
    warplight::host::scene_file::load(&warplight::host::scene_file::resolve(name)).expect("scene")
}

/// Prints `t`'s checks (shown with `--nocapture`) and returns their verdicts.
pub fn checks_of(t: &Table) -> Vec<bool> {
    for c in &t.checks {
        eprintln!("{} {}: {}", if c.holds { "✓" } else { "✗" }, c.claim, c.evidence);
    }
    t.checks.iter().map(|c| c.holds).collect()
}

/// Asserts that each of `t`'s rows holds its `recorded` values (every cell,
/// in order), each within `close(got, recorded)`; prints the rows.
pub fn assert_recorded<const N: usize>(t: &Table, recorded: &[[f64; N]], close: impl Fn(f64, f64) -> bool) {
    assert_eq!(t.rows.len(), recorded.len(), "rows");
    for (row, want) in t.rows.iter().zip(recorded) {
        let got: Vec<f64> = row.cells.iter().map(|c| c.ours.expect("measured")).collect();
        eprintln!("{}: {got:?}", row.label);
        assert_eq!(got.len(), N, "{}: cells", row.label);
        for (g, w) in got.iter().zip(want) {
            assert!(close(*g, *w), "{}: {got:?} against {want:?}", row.label);
        }
    }
}
