//! The hopper profile reproduces what Nsight Compute measured on an H100 for
//! the memory microbenchmarks (tests/fixtures/h100_micro.json): global
//! requests and sectors and L1 hit sectors exactly; shared wavefronts and
//! bank conflicts, which vary between identical launches, at least. Instruction counts (PTX vs SASS) and L2 atomic sectors
//! are compared side by side in docs/validation.md, not asserted.

use std::path::Path;
use warplight::model::validation::{Expect, compare, markdown};

/// Exact comparisons in the fixture (global and L1 metrics of every launch).
const EXACT_AT_LEAST: usize = 400;
/// Shared wavefront and bank-conflict comparisons.
const TIMED_AT_LEAST: usize = 200;

#[test]
fn hopper_profile_matches_the_h100() {
    let rows = compare(Path::new("tests/fixtures/h100_micro.json"), Path::new("kernels/micro/micro.ptx")).unwrap();
    let exact: Vec<_> = rows.iter().filter(|r| r.expect == Expect::Exact).collect();
    assert!(exact.len() >= EXACT_AT_LEAST, "{} exact comparisons", exact.len());
    // timing-dependent metrics: the GPU never counts less than the addresses alone decide
    let timed: Vec<_> = rows.iter().filter(|r| r.expect == Expect::TimingDependent).collect();
    assert!(timed.len() >= TIMED_AT_LEAST, "{} timing-dependent comparisons", timed.len());
    let below: Vec<String> = timed
        .iter()
        .filter(|r| r.measured < r.emulated)
        .map(|r| format!("{} {} {}: H100 {} < warplight {}", r.launch, r.kernel, r.metric, r.measured, r.emulated))
        .collect();
    assert!(below.is_empty(), "below the model:\n{}", below.join("\n"));
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
