//! `warplight validate`: the hopper profile against the H100 measurements of
//! the memory microbenchmarks (`crate::model::validation`), as a list of the
//! metrics that differ or as docs/validation.md's table. Every error names
//! the file it is about.

use std::path::Path;

use crate::host::scene_file::data_file;
use crate::model::validation::{Expect, compare, markdown};

/// Runs the command: `fixture` and `ptx` as given, else found in the checkout
/// or `$WARPLIGHT_HOME` ([`data_file`]).
pub fn run(fixture: &Path, ptx: &Path, md: bool) -> Result<(), Box<dyn std::error::Error>> {
    // the checkout's files (or $WARPLIGHT_HOME's) from any directory
    let (fixture, ptx) = (data_file(fixture), data_file(ptx));
    let rows = compare(&fixture, &ptx)?;
    if md {
        print!("{}", include_str!("validation_header.md"));
        print!("{}", markdown(&rows));
        return Ok(());
    }
    let exact = rows.iter().filter(|r| r.expect == Expect::Exact).count();
    let equal = rows.iter().filter(|r| r.expect == Expect::Exact && r.measured == r.emulated).count();
    for r in rows.iter().filter(|r| r.measured != r.emulated) {
        println!(
            "{:>3} {:<13} ({:>4}, {}) {:<62} H100 {:>8}  warplight {:>8}{}",
            r.launch,
            r.kernel,
            r.args.0,
            r.args.1,
            r.metric,
            r.measured,
            r.emulated,
            if r.expect == Expect::Exact { "  DIFFERS" } else { "" }
        );
    }
    println!("{equal} of {exact} exactly compared metrics equal; {} shown side by side", rows.len() - exact);
    if equal != exact {
        return Err(format!(
            "{}: the hopper profile differs from the H100 in {} of {exact} exactly compared metrics",
            fixture.display(),
            exact - equal
        )
        .into());
    }
    Ok(())
}
