//! Helpers shared by the integration tests: load a test kernel in either PTX
//! dialect, launch it, and look up per-source-line counts.
#![allow(dead_code)]

use warplight::ptx::Program;
use warplight::sim::counters::LineCounts;
use warplight::sim::{Device, LaunchStats, Module, SimConfig};

/// The two PTX dialects every test kernel is committed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// clang-16's PTX (`kernels/**/x.ptx`).
    Clang,
    /// nvcc's PTX (`kernels/**/x.nvcc.ptx`).
    Nvcc,
}

pub const BOTH: [Dialect; 2] = [Dialect::Clang, Dialect::Nvcc];

pub fn path(file: &str, d: Dialect) -> String {
    match d {
        Dialect::Clang => format!("kernels/tests/{file}.ptx"),
        Dialect::Nvcc => format!("kernels/tests/{file}.nvcc.ptx"),
    }
}

pub fn load(dev: &mut Device, file: &str, d: Dialect) -> Module {
    let p = path(file, d);
    let src = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"));
    dev.load_ptx(&src, &p).unwrap_or_else(|e| panic!("{e}"))
}

/// A device with `threads` host threads (default configuration otherwise).
pub fn device(threads: usize) -> Device {
    Device::with_config(SimConfig { threads, ..SimConfig::default() })
}

/// The 1-based line of the first line of `cu` (a `kernels/tests/*.cu` file) that contains `needle`.
pub fn cu_line(file: &str, needle: &str) -> u32 {
    let src = std::fs::read_to_string(format!("kernels/tests/{file}.cu")).unwrap();
    src.lines().position(|l| l.contains(needle)).unwrap_or_else(|| panic!("`{needle}` not in {file}.cu")) as u32 + 1
}

/// Counts of CUDA source line `line` of `file.cu`.
pub fn source_line(stats: &LaunchStats, prog: &Program, file: &str, line: u32) -> LineCounts {
    stats
        .per_source_line(prog)
        .into_iter()
        .find(|l| l.file.ends_with(&format!("{file}.cu")) && l.line == line)
        .unwrap_or_else(|| panic!("no instructions counted on {file}.cu:{line}"))
}

/// The external program a test needs (clang-16, tmux, chromium, ...), as a path
/// to run, or `None` when the test should skip.
///
/// `program` is looked up on `PATH` (or taken as is when it contains a `/`).
/// When it is missing, the test fails if `WARPLIGHT_REQUIRE_EXTERNAL=1` is set
/// (as `.ci/run` does after installing everything), and otherwise prints
/// `skipped: <test> needs <program> (install: <install>)` and returns `None`,
/// so that `cargo test --release` passes on a machine without it. The notice is
/// written straight to stderr rather than with `eprintln!`, which the test
/// harness captures and hides for passing tests.
#[track_caller]
pub fn external(program: &str, install: &str) -> Option<std::path::PathBuf> {
    use std::io::Write;
    if let Some(p) = find_program(program) {
        return Some(p);
    }
    let required = std::env::var("WARPLIGHT_REQUIRE_EXTERNAL").is_ok_and(|v| !v.is_empty() && v != "0");
    assert!(
        !required,
        "{program} is required (WARPLIGHT_REQUIRE_EXTERNAL=1) but not installed: install with {install}"
    );
    let thread = std::thread::current();
    let test = thread.name().filter(|n| *n != "main").unwrap_or("a test");
    let _ = writeln!(std::io::stderr(), "skipped: {test} needs {program} (install: {install})");
    None
}

/// `program` if it names an executable file, else the first executable `program` on `PATH`.
fn find_program(program: &str) -> Option<std::path::PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    let executable =
        |p: &std::path::Path| std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0);
    if program.contains('/') {
        let p = std::path::PathBuf::from(program);
        return executable(&p).then_some(p);
    }
    std::env::split_paths(&std::env::var_os("PATH")?).map(|d| d.join(program)).find(|p| executable(p))
}
