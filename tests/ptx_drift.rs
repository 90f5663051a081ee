//! The committed clang PTX matches what clang-16 makes of the CUDA sources now.
//! Needs clang-16 (`.ci/run` installs it); skips without it unless
//! WARPLIGHT_REQUIRE_EXTERNAL=1 (see `common::external`).

#![allow(clippy::needless_range_loop)]

mod common;

use std::process::Command;

#[test]
fn committed_ptx_matches_clang_16() {
    if common::external("clang-16", "apt-get install clang-16").is_none() {
        return;
    }
    let out = Command::new("bash").args(["kernels/build.sh", "--check"]).output().expect("run kernels/build.sh");
    assert!(
        out.status.success(),
        "kernels/build.sh --check failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
