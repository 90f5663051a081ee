//! The baseline: a committed record of which compared cells of which tables
//! agree with the thesis under a given protocol. A regression test runs the
//! tables again and fails when a cell recorded as within tolerance drops out
//! of it (cells that move into tolerance are reported, not failed).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::compare::Verdict;
use super::table::Table;

/// Verdicts per table address, keyed `row / column`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    /// The protocol the verdicts were recorded under (`quick: 3 frame(s) ...`).
    pub protocol: String,
    /// Scenes run.
    pub scenes: Vec<String>,
    /// address → (cell → "within" | "outside").
    pub tables: BTreeMap<String, BTreeMap<String, String>>,
}

fn word(v: Verdict) -> &'static str {
    match v {
        Verdict::Within => "within",
        Verdict::Outside => "outside",
    }
}

impl Baseline {
    /// Records the verdicts of `tables` (host timings left out: they vary from run to run).
    pub fn record(protocol: &str, scenes: &[String], tables: &[Table]) -> Baseline {
        let mut b = Baseline { protocol: protocol.into(), scenes: scenes.to_vec(), tables: BTreeMap::new() };
        for t in tables {
            let m = b.tables.entry(t.address.clone()).or_default();
            for (row, col, v) in t.verdicts() {
                m.insert(format!("{row} / {col}"), word(v).into());
            }
        }
        b
    }

    /// Cells recorded within tolerance that `tables` no longer has within
    /// (regressions), and cells newly within (improvements).
    pub fn compare(&self, tables: &[Table]) -> (Vec<String>, Vec<String>) {
        let now = Baseline::record(&self.protocol, &self.scenes, tables);
        let (mut worse, mut better) = (Vec::new(), Vec::new());
        for (addr, cells) in &self.tables {
            let current = now.tables.get(addr);
            for (cell, was) in cells {
                let is = current.and_then(|c| c.get(cell)).map(String::as_str).unwrap_or("missing");
                if was == "within" && is != "within" {
                    worse.push(format!("{addr} {cell}: recorded within tolerance, now {is}"));
                }
                if was != "within" && is == "within" {
                    better.push(format!("{addr} {cell}: now within tolerance"));
                }
            }
        }
        (worse, better)
    }
}
