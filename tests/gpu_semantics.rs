//! Instruction semantics against a real GPU: the `sem_*` kernels of
//! `kernels/tests/semantics_*.cu` were run on an H200 (the 51 kernels of
//! `semantics_int.cu` and `semantics_float.cu` earlier on an H100, with the
//! same bits) by `tools/gpu/semantics_fixture.cu`; their inputs and outputs
//! are in `tests/fixtures/gpu_semantics.json`. warplight must produce the
//! same bits, from clang's PTX and from nvcc's.

#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use serde_json::Value;
use warplight::sim::{Arg, LaunchConfig};

fn fixture() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/fixtures/gpu_semantics.json").unwrap()).unwrap()
}

fn words(v: &Value) -> Vec<u64> {
    v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect()
}

#[test]
fn every_semantics_kernel_matches_the_gpu() {
    let fx = fixture();
    assert_eq!(fx["compute_capability"], "9.0");
    let n = fx["n"].as_u64().unwrap() as usize;
    let kernels = fx["kernels"].as_object().unwrap();
    assert!(kernels.len() >= 59);
    let mut mismatches = Vec::new();
    let mut checked = 0;
    for d in BOTH {
        let mut dev = device(2);
        let mi = load(&mut dev, "semantics_int", d);
        let mf = load(&mut dev, "semantics_float", d);
        let me = load(&mut dev, "semantics_ext", d);
        for (name, k) in kernels {
            let m = [&mi, &mf, &me].into_iter().find(|m| m.prog.kernel(name).is_some()).expect("a module has it");
            let (a, b) = (words(&k["a"]), words(&k["b"]));
            let expect = words(&k["out_words"]);
            let (da, db) = if k["in_bytes"] == 8 {
                (dev.alloc_from(&a), dev.alloc_from(&b))
            } else {
                let a32: Vec<u32> = a.iter().map(|&x| x as u32).collect();
                let b32: Vec<u32> = b.iter().map(|&x| x as u32).collect();
                (dev.alloc_from(&a32), dev.alloc_from(&b32))
            };
            let out = dev.alloc_zeroed::<u32>(expect.len());
            dev.launch(
                m,
                name,
                LaunchConfig::linear(1, n as u32),
                &[Arg::Ptr(out), Arg::Ptr(da), Arg::Ptr(db), Arg::I32(n as i32)],
            )
            .unwrap_or_else(|e| panic!("{d:?} {name}: {e}"));
            checked += 1;
            let got = dev.read::<u32>(out, expect.len());
            let per = expect.len() / n;
            for i in 0..expect.len() {
                if got[i] as u64 != expect[i] {
                    let t = i / per;
                    mismatches.push(format!(
                        "{d:?} {name} thread {t} (a={:#x}, b={:#x}) word {i}: gpu {:#010x}, warplight {:#010x}",
                        a[t], b[t], expect[i], got[i]
                    ));
                }
            }
        }
    }
    assert_eq!(checked, 2 * kernels.len(), "kernels run in both dialects");
    assert!(mismatches.is_empty(), "{} mismatches:\n{}", mismatches.len(), mismatches.join("\n"));
}
