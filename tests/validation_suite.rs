//! The validation suite (kernels/validation/suite.cu, clang's and nvcc's PTX)
//! against what an H200 computed and Nsight Compute measured
//! (tests/fixtures/validation/h200.json): every output buffer bit for bit,
//! every metric the addresses decide exactly (listed exceptions, each with
//! its reason, must still differ), timing-dependent shared-memory metrics at
//! least the model's count, and bfs's L1 hit sectors timing-dependent (at
//! most the model's count, varying between identical runs).
//! docs/validation.md carries the generated tables
//! (`WARPLIGHT_PRINT_SUITE=1 cargo test --release --test validation_suite -- --nocapture`).

use std::path::Path;
use warplight::model::validation_suite::{Expect, Report, VARIES_BETWEEN_RUNS, compare};

/// Exact metrics known to differ: (case, dialect, metric, why). Each is
/// explained in docs/validation.md.
const KNOWN: &[(&str, &str, &str, &str)] = &[];

fn report() -> Report {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    compare(&root.join("tests/fixtures/validation/h200.json"), root).unwrap()
}

#[test]
fn the_suite_matches_the_h200() {
    let r = report();
    if std::env::var_os("WARPLIGHT_PRINT_SUITE").is_some() {
        println!("{}\n{}", r.summary_markdown(), r.differences_markdown());
    }
    // every case of both dialects ran, with outputs and metrics
    assert!(r.outputs.len() >= 66, "{} cases", r.outputs.len());
    let exact = r.rows.iter().filter(|x| x.expect == Expect::Exact).count();
    assert!(exact >= 1700, "{exact} exact comparisons");
    let timed = r.rows.iter().filter(|x| x.expect == Expect::TimingDependent).count();
    assert!(timed >= 100, "{timed} timing-dependent comparisons");

    let differ: Vec<String> = r
        .outputs
        .iter()
        .filter(|o| !o.differ.is_empty())
        .map(|o| format!("{} {}: {:?}", o.case, o.dialect, o.differ))
        .collect();
    assert!(differ.is_empty(), "outputs differ from the GPU's:\n{}", differ.join("\n"));

    let known = |c: &str, d: &str, m: &str| KNOWN.iter().any(|k| (k.0, k.1, k.2) == (c, d, m));
    let unexpected: Vec<String> = r
        .exact_differences()
        .iter()
        .filter(|x| !known(&x.case, &x.dialect, &x.metric))
        .map(|x| format!("{} {} {}: H200 {} warplight {}", x.case, x.dialect, x.metric, x.measured, x.emulated))
        .collect();
    assert!(unexpected.is_empty(), "{} differences:\n{}", unexpected.len(), unexpected.join("\n"));
    for k in KNOWN {
        assert!(
            r.exact_differences()
                .iter()
                .any(|x| (x.case.as_str(), x.dialect.as_str(), x.metric.as_str()) == (k.0, k.1, k.2)),
            "{} {} {} is equal now: remove it from KNOWN ({})",
            k.0,
            k.1,
            k.2,
            k.3
        );
    }
    timed_metrics_vary_and_stay_at_most_the_model(&r);
    let below: Vec<String> = r
        .outside_the_bound()
        .iter()
        .map(|x| format!("{} {} {}: H200 {} warplight {}", x.case, x.dialect, x.metric, x.measured, x.emulated))
        .collect();
    assert!(below.is_empty(), "outside the model's bound:\n{}", below.join("\n"));

    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/validation.md")).unwrap();
    assert!(
        doc.contains(&r.summary_markdown()) && doc.contains(&r.differences_markdown()),
        "docs/validation.md is stale: WARPLIGHT_PRINT_SUITE=1 cargo test --release --test validation_suite -- --nocapture"
    );
}

/// Each metric of [`VARIES_BETWEEN_RUNS`], per dialect: the H200's count in the suite's
/// fixture and in every repeated run at most warplight's, the repeated runs
/// not all equal, and the metrics the addresses decide (global load sectors
/// and requests) equal in every run and to warplight's.
fn timed_metrics_vary_and_stay_at_most_the_model(r: &Report) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("tests/fixtures/validation/h200_bfs_repeat.json")).unwrap();
    let repeat: serde_json::Value = serde_json::from_str(&text).unwrap();
    let emulated = |case: &str, dialect: &str, metric: &str| {
        let row =
            r.rows.iter().find(|x| (x.case.as_str(), x.dialect.as_str(), x.metric.as_str()) == (case, dialect, metric));
        row.unwrap_or_else(|| panic!("{case} {dialect} {metric}: no such row"))
    };
    for &(case, metric) in VARIES_BETWEEN_RUNS {
        assert_eq!(repeat["case"], case, "the repeated runs are of {case}");
        for dialect in ["clang", "nvcc"] {
            let row = emulated(case, dialect, metric);
            assert_eq!(row.expect, Expect::VariesBetweenRuns, "{case} {dialect} {metric}");
            assert!(
                row.measured <= row.emulated,
                "{case} {dialect} {metric}: H200 {} > warplight {}",
                row.measured,
                row.emulated
            );
            let runs = repeat["runs"][dialect].as_array().unwrap();
            assert_eq!(runs.len(), 5);
            let counts: Vec<u64> = runs.iter().map(|run| run[metric].as_u64().unwrap()).collect();
            assert!(
                counts.iter().all(|&c| c <= row.emulated),
                "{dialect}: {counts:?} above warplight's {}",
                row.emulated
            );
            assert!(counts.iter().min() < counts.iter().max(), "{dialect}: {counts:?} did not vary");
            for fixed in
                ["l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum", "l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum"]
            {
                let want = emulated(case, dialect, fixed).emulated;
                assert!(
                    runs.iter().all(|run| run[fixed].as_u64() == Some(want)),
                    "{dialect} {fixed}: not {want} in every run"
                );
            }
        }
    }
}

/// ptxas's warp-uniform atomics (kernels/validation/uniform_atomics.cu,
/// tests/fixtures/validation/h200_uniform_atomics.json): every output and
/// every exact metric equal, and the merge visible — an atomic of 32 lanes on
/// one address costs one L1 sector per warp where it is merged, 32 where not.
#[test]
fn uniform_atomics_match_the_h200() {
    let r = uniform_atomics_report("h200_uniform_atomics.json", 52);
    // merged: 4 warps, one sector each; a full warp's varying operand with the result used: 1
    assert_eq!(sectors(&r, "ua_inc", "red"), 4);
    assert_eq!(sectors(&r, "ua_add_val_ret", "atom"), 1);
    // not merged: 24 lanes with varying operands, floats, lane-dependent addresses
    assert_eq!(sectors(&r, "ua_add_val_ret_24", "atom"), 24);
    assert_eq!(sectors(&r, "ua_f32", "red"), 128);
    assert_eq!(sectors(&r, "ua_warp", "red"), 128);
}

/// The 64-bit forms of ptxas's warp-uniform atomics
/// (kernels/validation/uniform_atomics64.cu,
/// tests/fixtures/validation/h200_uniform_atomics64.json): ptxas has no
/// 64-bit `REDUX`, so only an `add` of a uniform operand is merged (one L1
/// sector per warp); a varying operand costs one sector per lane, its result
/// used or not. Every output and every exact metric equal.
#[test]
fn uniform_atomics_64_bit_match_the_h200() {
    let r = uniform_atomics_report("h200_uniform_atomics64.json", 42);
    // merged: a uniform operand, result unused (4 warps) or used (1 warp, 24 lanes)
    assert_eq!(sectors(&r, "ua64_inc", "red"), 4);
    assert_eq!(sectors(&r, "ua64_cond", "red"), 4);
    assert_eq!(sectors(&r, "ua64_inc_ret", "atom"), 1);
    assert_eq!(sectors(&r, "ua64_inc_ret_24", "atom"), 1);
    // not merged: a varying operand (no 64-bit REDUX), doubles, exch, cas
    assert_eq!(sectors(&r, "ua64_add_val", "red"), 128);
    assert_eq!(sectors(&r, "ua64_min", "red"), 128);
    assert_eq!(sectors(&r, "ua64_add_val_ret", "atom"), 32);
    assert_eq!(sectors(&r, "ua64_f64", "red"), 32);
    assert_eq!(sectors(&r, "ua64_cas", "atom"), 32);
}

/// A ptxas uniform-atomic fixture compared: `outputs` outputs (cases ×
/// dialects), every output and every exact metric equal to the H200's, and
/// docs/validation.md holding its summary.
fn uniform_atomics_report(fixture: &str, outputs: usize) -> Report {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let r = compare(&root.join("tests/fixtures/validation").join(fixture), root).unwrap();
    if std::env::var_os("WARPLIGHT_PRINT_SUITE").is_some() {
        println!("{}\n{}", r.summary_markdown(), r.differences_markdown());
    }
    assert_eq!(r.outputs.len(), outputs, "{fixture}: cases × 2 dialects");
    let differ: Vec<String> = r
        .outputs
        .iter()
        .filter(|o| !o.differ.is_empty())
        .map(|o| format!("{} {}: {:?}", o.case, o.dialect, o.differ))
        .collect();
    assert!(differ.is_empty(), "outputs differ from the GPU's:\n{}", differ.join("\n"));
    let unexpected: Vec<String> = r
        .exact_differences()
        .iter()
        .map(|x| format!("{} {} {}: H200 {} warplight {}", x.case, x.dialect, x.metric, x.measured, x.emulated))
        .collect();
    assert!(unexpected.is_empty(), "{} differences:\n{}", unexpected.len(), unexpected.join("\n"));
    let doc = std::fs::read_to_string(root.join("docs/validation.md")).unwrap();
    assert!(
        doc.contains(&r.summary_markdown()),
        "docs/validation.md is stale: WARPLIGHT_PRINT_SUITE=1 cargo test --release --test validation_suite -- --nocapture"
    );
    r
}

/// The L1 sectors warplight counts for `case`'s global `op` (`atom`/`red`),
/// the same in both dialects' rows.
fn sectors(r: &Report, case: &str, op: &str) -> u64 {
    let m = format!("l1tex__t_sectors_pipe_lsu_mem_global_op_{op}.sum");
    let rows: Vec<_> = r.rows.iter().filter(|x| x.case == case && x.metric == m).collect();
    assert_eq!(rows.len(), 2, "{case} {m}");
    rows[0].emulated
}
