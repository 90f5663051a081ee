//! What the tests of thesis 003's registry tables share: a table rendered
//! from measured samples as `warplight tables` renders it, a scene loaded by
//! name, and the checks printed.

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
