//! The hopper profile reproduces what Nsight Compute measured on an H100 for
//! the memory microbenchmarks (tests/fixtures/h100_micro.json): global
//! requests and sectors, shared wavefronts and bank conflicts, and L1 hit
//! sectors, exactly. Instruction counts (PTX vs SASS) and L2 atomic sectors
//! are compared side by side in docs/validation.md, not asserted.

use std::path::Path;
use warplight::model::validation::{Expect, compare, markdown};

#[test]
fn hopper_profile_matches_the_h100() {
    let rows = compare(Path::new("tests/fixtures/h100_micro.json"), Path::new("kernels/micro/micro.ptx")).unwrap();
    let exact: Vec<_> = rows.iter().filter(|r| r.expect == Expect::Exact).collect();
    assert!(exact.len() >= 200, "{} exact comparisons", exact.len());
    let bad: Vec<String> = exact
        .iter()
        .filter(|r| r.measured != r.emulated)
        .map(|r| {
            format!(
                "{} {} ({}, {}) {}: H100 {} warplight {}",
                r.launch, r.kernel, r.args.0, r.args.1, r.metric, r.measured, r.emulated
            )
        })
        .collect();
    assert!(bad.is_empty(), "{} differences:\n{}", bad.len(), bad.join("\n"));
    // docs/validation.md is generated from the same rows
    let doc = std::fs::read_to_string("docs/validation.md").unwrap();
    assert!(doc.contains(&markdown(&rows)), "docs/validation.md is stale: run `warplight validate --markdown`");
}
