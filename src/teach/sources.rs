//! Finding the CUDA source files a PTX module's `.file` directives name.
//! Paths in PTX are as the compiler saw them (relative to where it ran, or
//! absolute on another machine), so several places are tried.

use std::path::{Path, PathBuf};

use crate::ptx::Program;

/// The places tried for `file` named by the PTX at `ptx`: the path itself, then
/// `file` under the PTX's folder and each folder above it, then the file name
/// beside the PTX.
pub fn candidates(ptx: &Path, file: &str) -> Vec<PathBuf> {
    let mut v = vec![PathBuf::from(file)];
    let dir = ptx.parent().unwrap_or(Path::new("."));
    let rel = file.trim_start_matches("./");
    for d in dir.ancestors() {
        v.push(d.join(rel));
    }
    if let Some(name) = Path::new(file).file_name() {
        v.push(dir.join(name));
    }
    v
}

/// The lines of `file` named by the PTX at `ptx`, if any candidate can be read.
pub fn read(ptx: &Path, file: &str) -> Option<Vec<String>> {
    candidates(ptx, file)
        .iter()
        .find_map(|p| std::fs::read_to_string(p).ok())
        .map(|s| s.lines().map(str::to_string).collect())
}

/// Every `.file` of `prog`, read where found, indexed like [`Program::files`]
/// (and so like [`SrcLoc::file`](crate::ptx::ir::SrcLoc)).
pub fn read_all(prog: &Program, ptx: &Path) -> Vec<Option<Vec<String>>> {
    prog.files.iter().map(|f| read(ptx, f)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_source_relative_to_an_ancestor_of_the_ptx() {
        let root = env!("CARGO_MANIFEST_DIR");
        let ptx = Path::new(root).join("kernels/tests/divergence.ptx");
        let lines = read(&ptx, "./kernels/tests/divergence.cu").expect("found");
        assert!(lines.iter().any(|l| l.contains("if_else")));
        let by_name = read(&ptx, "/elsewhere/kernels/tests/divergence.cu").expect("found by name");
        assert_eq!(lines, by_name);
        assert!(read(&ptx, "no_such_file.cu").is_none());
    }
}
