//! Fuzzes the PTX front end: any input must load or return an error, never panic.
//! Run: `cargo install cargo-fuzz && cd fuzz && RUSTC_BOOTSTRAP=1 cargo fuzz run ptx_load ../kernels/tests`
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(src) = std::str::from_utf8(data) {
        let _ = warplight::ptx::load(src, "fuzz.ptx");
    }
});
