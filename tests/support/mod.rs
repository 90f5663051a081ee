//! What the integration tests share: running the `warplight` binary.
//! (Each test crate that says `mod support;` compiles its own copy, so
//! helpers one crate leaves unused are allowed.)
#![allow(dead_code)]

use std::process::Command;

/// Runs `warplight args`: whether it succeeded, its stdout and its stderr.
pub fn warplight(args: &[&str]) -> (bool, String, String) {
    let (code, out, err) = warplight_code(args);
    (code == Some(0), out, err)
}

/// Runs `warplight args`: its exit code (None when killed by a signal), stdout and stderr.
pub fn warplight_code(args: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_warplight")).args(args).output().expect("run warplight");
    (o.status.code(), String::from_utf8_lossy(&o.stdout).into(), String::from_utf8_lossy(&o.stderr).into())
}
