//! Seed 004's Tables 1 and 2 through the registry, against committed
//! baselines of their verdicts:
//! - a reduced subset run here (the three scenes with 100 times fewer photons
//!   and photons sought, 16 pixels wide): every compared cell and every check
//!   of `purcell:1` (a, b, c) and `purcell:2` gives the verdict
//!   `docs/results/purcell-baseline-reduced.json` records, cell for cell (a
//!   verdict that moves either way fails until the baseline is re-recorded:
//!   `WARPLIGHT_RECORD_BASELINE=1 cargo test --release --test purcell2003_tables`;
//!   `WARPLIGHT_PURCELL_RESULTS=FILE` also writes the run's raw results);
//! - the quick protocol's committed raw results
//!   (`docs/results/purcell-quick.json`), rendered by `warplight tables
//!   purcell:1 purcell:2 --from`, keep every cell that
//!   `docs/results/purcell-quick.baseline.json` records within tolerance.

use std::path::Path;
use std::process::Command;

use warplight::repro::baseline::Baseline;
use warplight::repro::protocol::{FrameRange, Protocol};
use warplight::repro::purcell2003::passes::PhaseCounts;
use warplight::repro::purcell2003::scenes::FIXTURES;
use warplight::repro::purcell2003::{pipeline, table_2};
use warplight::repro::registry::{Workspace, resolve};
use warplight::repro::results::{Results, SceneInfo};
use warplight::repro::table::Table;

/// Photons (stored, pilot) and photons sought divided by this (docs/fixtures.md).
const DIV: u32 = 100;
/// Image width of the reduced run.
const SIDE: u32 = 16;
/// The reduced run's baseline.
const REDUCED: &str = "docs/results/purcell-baseline-reduced.json";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The reduced run: the pipeline on the three scenes, the kernels on the Cornell box.
fn reduced_tables() -> (Results, Vec<Table>) {
    let mut r = Results::new(
        "test",
        Protocol::quick().with(Some(1), Some(SIDE)),
        vec!["purcell:1".into(), "purcell:2".into()],
        vec![pipeline::PIPELINE.into(), table_2::KERNELS.into()],
    );
    for f in FIXTURES {
        let path = warplight::host::scene_file::resolve(f.scene);
        let scene = warplight::host::scene_file::load(&path).expect("scene");
        let mut ws = Workspace::new(&scene, 0..1, SIDE);
        let small = f.reduced(DIV);
        let t = std::time::Instant::now();
        r.samples.extend(pipeline::measure_with(&mut ws, &small, &mut |_| {}).expect("pipeline"));
        eprintln!("{}: pipeline {:.1} s", f.scene, t.elapsed().as_secs_f64());
        if f.scene == table_2::SCENE {
            let t = std::time::Instant::now();
            r.samples.extend(table_2::measure_with(&mut ws, &small, &mut |_| {}).expect("kernels"));
            eprintln!("{}: kernels {:.1} s", f.scene, t.elapsed().as_secs_f64());
        }
        r.scenes.push(SceneInfo {
            name: f.scene.into(),
            triangles: scene.triangles.len(),
            thesis_triangles: scene.thesis.map(|t| t.triangles),
            flight_frames: scene.flight.frames,
            frames: vec![FrameRange { start: 0, end: 1 }],
        });
    }
    let mut tables = Vec::new();
    for id in ["purcell:1", "purcell:2"] {
        let e = resolve(&[id.into()]).unwrap()[0];
        tables.extend((e.table.render.unwrap())(&e, &r));
    }
    (r, tables)
}

/// Every verdict of the reduced run is the baseline's.
#[test]
fn reduced_run_verdicts_are_the_baselines() {
    let (r, tables) = reduced_tables();
    let scenes: Vec<String> = r.scenes.iter().map(|s| s.name.clone()).collect();
    let now = Baseline::record(&r.protocol.describe(), &scenes, &tables);
    let file = root().join(REDUCED);
    // the raw results, for `warplight tables purcell:1 purcell:2 --from FILE`
    if let Some(out) = std::env::var_os("WARPLIGHT_PURCELL_RESULTS") {
        std::fs::write(out, serde_json::to_string_pretty(&r).unwrap()).unwrap();
    }
    if std::env::var_os("WARPLIGHT_RECORD_BASELINE").is_some() {
        std::fs::write(&file, serde_json::to_string_pretty(&now).unwrap() + "\n").unwrap();
        eprintln!("recorded {}", file.display());
    }
    let base: Baseline = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert_eq!(base.protocol, now.protocol);
    assert_eq!(base.scenes, now.scenes);
    let mut cells = 0;
    for addr in ["purcell:1", "purcell:1c", "purcell:2"] {
        let (want, got) = (&base.tables[addr], &now.tables[addr]);
        assert!(!want.is_empty(), "{addr}: the baseline records verdicts");
        assert_eq!(got, want, "{addr}: verdicts differ from the committed baseline {REDUCED}");
        cells += want.len();
    }
    // Table 2: TEX compared on 8 rows, 7 checks; Table 1: 3 x 3 checks; 1c: 3 + 1 checks
    assert!(cells >= 8 + 7 + 9 + 4, "{cells} verdicts");
}

/// The committed quick run, rendered again, keeps every cell its baseline records within tolerance.
#[test]
fn the_quick_runs_tables_keep_their_baseline() {
    let o = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .current_dir(root())
        .args([
            "tables",
            "purcell:1",
            "purcell:2",
            "--from",
            "docs/results/purcell-quick.json",
            "--baseline",
            "docs/results/purcell-quick.baseline.json",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("no cell dropped out of tolerance"), "{err}");
}

/// TEX by how a row's pass was drawn: the routing row (one point per photon)
/// drops its stream inputs, a quad's row keeps every load, and a label that
/// is not a row of Table 2 is an error (it was silently read as a quad).
#[test]
fn table_2_rows_say_how_their_pass_was_drawn() {
    let c = PhaseCounts { lane_loads: 4, stream_loads: 3, ..Default::default() };
    let routing = table_2::sample("stencil-routing", &c, 2.0).unwrap();
    assert_eq!(routing.counters["tex_per_iteration"], 0.5);
    assert_eq!((routing.counters["loads_per_iteration"], routing.counters["stream_per_iteration"]), (2.0, 1.5));
    assert_eq!(table_2::sample("bitonic-sort", &c, 2.0).unwrap().counters["tex_per_iteration"], 2.0);
    let e = table_2::sample("stencil-route", &c, 2.0).unwrap_err();
    assert_eq!(e, table_2::UnknownRow("stencil-route".into()));
    assert!(e.to_string().contains("no row `stencil-route`"), "{e}");
}
