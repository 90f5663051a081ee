//! The vectorisation pass (`src/model/vectorize.rs`) against the SASS that
//! ptxas 13.5 makes of hand-written probe kernels
//! (`tests/fixtures/validation/vectorize_probes.{ptx,sass}`, `ptxas
//! -arch=sm_90 -O3`, read with `nvdisasm -c`; no device run). Each kernel
//! reads two adjacent shared words at one base: one `LDS.64` or two `LDS`.
//! The expected counts are the SASS's `LDS` instructions (times the
//! iterations in the two loops), one warp of 32 lanes.

use warplight::model::{Model, Profile};
use warplight::sim::{Arg, Device, LaunchConfig};

const PTX: &str = "tests/fixtures/validation/vectorize_probes.ptx";
const SASS: &str = "tests/fixtures/validation/vectorize_probes.sass";

/// Shared load instructions of one warp of `kernel` (loops: 4 iterations).
fn shared_loads(kernel: &str, vectorize: bool) -> u64 {
    let ptx = std::fs::read_to_string(PTX).unwrap();
    let mut dev = Device::new();
    let m = dev.load_ptx(&ptx, PTX).unwrap();
    let out = dev.alloc_zeroed::<u32>(32);
    let model = Model::with_vectorize(Profile::Hopper, &m.prog, vectorize);
    let cfg = LaunchConfig::linear(1, 32);
    let args = if kernel.contains("step") { vec![Arg::Ptr(out), Arg::U32(4)] } else { vec![Arg::Ptr(out)] };
    dev.launch_observed(&m, kernel, cfg, &args, Some(&model)).unwrap();
    model.finish().counters.shared_ld.instructions
}

/// (kernel, shared loads as ptxas 13.5 makes them, as the PTX writes them)
const CASES: [(&str, u64, u64); 15] = [
    // a base stepped round a loop, by `add 8` and by `sub 8`: LDS.64
    ("loop_step8", 4, 8),
    ("sub_step", 4, 8),
    // the array's address minus 64 tid: 64-bit `sub` of a varying register, no merge ...
    ("sub_sym64", 2, 2),
    // ... the same by `add` of -64 tid, by a 32-bit `sub`: LDS.64
    ("addneg_sym64", 1, 2),
    ("sub_sym32", 1, 2),
    // 2048 - 64 tid added to the address: 64-bit no merge, 32-bit LDS.64
    ("sub_int64", 2, 2),
    ("sub_int32", 1, 2),
    // 128 tid - 64 tid (64-bit): no merge
    ("sub_varvar", 2, 2),
    // `neg` of 64 tid added to the address: 64-bit no merge, 32-bit LDS.64
    ("neg_add", 2, 2),
    ("neg_add32", 1, 2),
    // 64-bit `sub` of a register holding 16: LDS.64
    ("sub_creg64", 1, 2),
    // `.align 4` 1,156 bytes, the kernel's only array: LDS.64
    ("odd_add", 1, 2),
    // the pair in a `.align 4` array laid out after one of 1,156 bytes (at
    // 0x484): no merge; plus one load of the first array
    ("second_var", 3, 3),
    // the 1,156-byte array declared after one of 1,024 bytes (at 0x400):
    // LDS.64; plus one load of the other
    ("order_x", 2, 3),
    // an unused 4-byte array declared first takes no room: LDS.64
    ("unused_first", 1, 2),
];

#[test]
fn shared_pairs_merge_where_ptxas_13_5_merges_them() {
    let sass = std::fs::read_to_string(SASS).unwrap();
    for (kernel, want_on, want_off) in CASES {
        // the fixture holds the kernel, and its SASS has LDS.64 exactly when a merge is expected
        let body = sass.split(&format!(".text.{kernel}:")).nth(1).unwrap_or_else(|| panic!("{kernel} not in the SASS"));
        let body = body.split(".text.").next().unwrap_or(body);
        assert_eq!(body.contains("LDS.64"), want_on < want_off, "{kernel}: SASS");
        let on = shared_loads(kernel, true);
        let off = shared_loads(kernel, false);
        assert_eq!((on, off), (want_on, want_off), "{kernel}");
    }
}
