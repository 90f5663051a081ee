//! Every committed PTX file (both dialects) loads and validates.

#![allow(clippy::needless_range_loop)]

use std::path::Path;

fn ptx_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            ptx_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "ptx") {
            out.push(p);
        }
    }
}

#[test]
fn every_kernel_ptx_loads() {
    let mut files = Vec::new();
    ptx_files(Path::new("kernels"), &mut files);
    files.sort();
    assert!(files.len() >= 16, "expected both dialects of the test kernels, found {}", files.len());
    let mut errors = Vec::new();
    for f in &files {
        if let Err(e) = warplight::ptx::load_file(f) {
            errors.push(e.to_string());
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}
