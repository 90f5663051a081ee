//! The committed clang PTX matches what clang-16 makes of the CUDA sources now.
//! Runs when clang-16 is installed (CI installs it and sets
//! WARPLIGHT_REQUIRE_CLANG=1, so there a missing compiler fails the test).

#![allow(clippy::needless_range_loop)]

use std::process::Command;

#[test]
fn committed_ptx_matches_clang_16() {
    let have = Command::new("clang-16").arg("--version").output().map(|o| o.status.success()).unwrap_or(false);
    if !have {
        assert!(std::env::var_os("WARPLIGHT_REQUIRE_CLANG").is_none(), "clang-16 is required here but not installed");
        eprintln!("clang-16 not installed: PTX drift not checked");
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
