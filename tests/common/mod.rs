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
