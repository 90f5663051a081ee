//! Thesis 003 §4.8's r̄ (003:L330): MLT's b against the bootstrap count
//! (`warplight tables lin:s4.8-bootstrap`). The recorded errors and
//! verdicts, and the checks following the evidence.

use warplight::repro::lin2017::fig_9::SCENES;
use warplight::repro::lin2017::sec_4_8::{self, BOOTSTRAP_GROUP};
use warplight::repro::protocol::Protocol;
use warplight::repro::registry::{Workspace, resolve};
use warplight::repro::results::{Results, Sample};
use warplight::repro::table::Table;

fn table_of(samples: &[Sample]) -> Table {
    let mut r =
        Results::new("test", Protocol::quick(), vec!["lin:s4.8-bootstrap".into()], vec![BOOTSTRAP_GROUP.into()]);
    r.samples = samples.to_vec();
    let e = resolve(&["lin:s4.8-bootstrap".into()]).expect("registered").remove(0);
    (e.table.render.expect("rendered"))(&e, &r).remove(0)
}

/// b's RMS error over the runs (%) at 1, 4, 16, 64, 256, 1024 samples a
/// pixel: the inverted box (bdpt's heavy tail: one run of 16 is +401 %),
/// then the original box (about 21 % / sqrt(k)).
const RECORDED: [[f64; 6]; 2] = [[72.9, 39.0, 148.6, 35.7, 22.8, 11.8], [20.8, 10.9, 4.3, 3.7, 1.5, 0.6]];

/// Per scene: b sets the image's luminance; the error falls with the count.
const CHECKS: [bool; 4] = [true, false, true, true];

#[test]
fn bootstrap_table_records_its_errors_and_checks() {
    let mut samples = Vec::new();
    for name in SCENES {
        let scene = warplight::host::scene_file::load(&warplight::host::scene_file::resolve(name)).expect("scene");
        let mut ws = Workspace::new(&scene, 0..1, 32);
        samples.extend(sec_4_8::measure(&mut ws, &mut |_| {}).expect("measure"));
    }
    let t = table_of(&samples);
    for c in &t.checks {
        eprintln!("{} {}: {}", if c.holds { "✓" } else { "✗" }, c.claim, c.evidence);
    }
    let got: Vec<f64> = t.rows.iter().map(|r| r.cells[1].ours.expect("measured")).collect();
    eprintln!("{got:?}");
    for (g, w) in got.iter().zip(RECORDED.iter().flatten()) {
        assert!((g - w).abs() <= 0.06, "{got:?} against {RECORDED:?}");
    }
    assert_eq!(got.len(), 12);
    let holds: Vec<bool> = t.checks.iter().map(|c| c.holds).collect();
    assert_eq!(holds, CHECKS);

    // an image 1 % off its b, or a kernel b that is not the native one, fails the first check
    for s in samples.iter_mut().filter(|s| s.scene == "cornell-lambert") {
        s.counters.insert("image_vs_b".into(), 0.01);
    }
    assert_eq!(table_of(&samples).checks.iter().map(|c| c.holds).collect::<Vec<_>>(), [true, false, false, true]);
    for s in samples.iter_mut().filter(|s| s.scene == "cornell-inverted") {
        s.counters.insert("kernel_b_is_ours".into(), 0.0);
    }
    assert!(!table_of(&samples).checks[0].holds);
}
