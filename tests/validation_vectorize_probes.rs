//! The vectorisation pass (`src/model/vectorize.rs`) against the SASS that
//! ptxas 13.5 makes of hand-written probe kernels (`ptxas -arch=sm_90 -O3`,
//! read with `nvdisasm -c`; no device run), one warp of 32 lanes. The
//! expected counts are read from the SASS: each kernel's `LDS*` and `STS*`
//! instructions (its callees' code included, which ptxas compiles into the
//! kernel's section), those inside a loop (a label and a later branch back
//! to it) times the loop's iterations.
//!
//! - `vectorize_probes.{ptx,sass}`: the probes the rule was read off (a
//!   regression record, not a check of the rule).
//! - `vectorize_heldout.{ptx,sass}`, `vectorize_heldout2.{ptx,sass}`: written,
//!   with the rule's prediction in their comments, before their SASS was
//!   made. The first round's `mix_scope` and `fscope_first` missed and the
//!   layout order was corrected from them (`docs/validation.md`,
//!   "Vectorisation: the alignment rule"); the second round was predicted
//!   with the corrected order.

use warplight::model::{Model, Profile};
use warplight::sim::{Arg, Device, LaunchConfig};

const DIR: &str = "tests/fixtures/validation";

/// Iterations of the probes' loops (their parameter `n`).
const ITERS: u32 = 4;

/// Shared (load, store) instructions of one warp of `kernel` in `file`.ptx.
fn shared_counts(file: &str, kernel: &str, vectorize: bool) -> (u64, u64) {
    let path = format!("{DIR}/{file}.ptx");
    let ptx = std::fs::read_to_string(&path).unwrap();
    let mut dev = Device::new();
    let m = dev.load_ptx(&ptx, &path).unwrap();
    let out = dev.alloc_zeroed::<u32>(32);
    let model = Model::with_vectorize(Profile::Hopper, &m.prog, vectorize);
    let cfg = LaunchConfig::linear(1, 32);
    let args = if kernel.contains("step") { vec![Arg::Ptr(out), Arg::U32(ITERS)] } else { vec![Arg::Ptr(out)] };
    dev.launch_observed(&m, kernel, cfg, &args, Some(&model)).unwrap();
    let c = model.finish().counters;
    (c.shared_ld.instructions, c.shared_st.instructions)
}

/// The kernel's section of `nvdisasm -c` output: its lines up to the next section.
fn section<'a>(sass: &'a str, kernel: &str) -> Vec<&'a str> {
    let start = format!(".text.{kernel}:");
    let mut lines = sass.lines().skip_while(|l| l.trim() != start).skip(1);
    let mut out = Vec::new();
    for l in lines.by_ref() {
        if l.starts_with("//---") || l.trim_start().starts_with(".section") {
            break;
        }
        out.push(l);
    }
    assert!(!out.is_empty(), "{kernel} not in the SASS");
    out
}

/// An instruction line's opcode (`LDS.64`), without its address and guard.
fn opcode(line: &str) -> Option<&str> {
    let rest = line.trim_start().strip_prefix("/*")?.split_once("*/")?.1;
    let mut words = rest.split_whitespace();
    let w = words.next()?;
    if w.starts_with('@') { words.next() } else { Some(w) }
}

/// Shared (loads, stores) of one warp as the SASS has them: static `LDS*`,
/// `STS*`, times `ITERS` inside a loop.
fn sass_counts(lines: &[&str]) -> (u64, u64) {
    // loops: a label, and a later branch back to it
    let mut weight = vec![1u64; lines.len()];
    for (b, l) in lines.iter().enumerate() {
        let Some(target) = l.split("BRA `(").nth(1).and_then(|t| t.split(')').next()) else { continue };
        if let Some(a) = lines[..b].iter().position(|x| x.trim() == format!("{target}:")) {
            weight[a..=b].iter_mut().for_each(|w| *w = u64::from(ITERS));
        }
    }
    let count = |p: &str| {
        lines
            .iter()
            .zip(&weight)
            .filter(|(l, _)| opcode(l).is_some_and(|o| o == p || o.starts_with(&format!("{p}."))))
            .map(|(_, w)| w)
            .sum()
    };
    (count("LDS"), count("STS"))
}

/// (file, kernels)
const PROBES: [(&str, &[&str]); 3] = [
    (
        "vectorize_probes",
        &[
            "loop_step8",
            "sub_step",
            "sub_sym64",
            "addneg_sym64",
            "sub_sym32",
            "sub_int64",
            "sub_int32",
            "sub_varvar",
            "neg_add",
            "neg_add32",
            "sub_creg64",
            "odd_add",
            "second_var",
            "order_x",
            "unused_first",
        ],
    ),
    (
        "vectorize_heldout",
        &[
            "k_big",
            "k_abs",
            "k_reg",
            "abs_both",
            "abs_quad",
            "abs_st",
            "lit_addr",
            "callee_var",
            "callee_pair",
            "mix_scope",
            "fscope_first",
        ],
    ),
    ("vectorize_heldout2", &["own_first", "cfs_pair", "two_callees", "mod_order", "abs_after_own"]),
];

#[test]
fn shared_accesses_merge_where_ptxas_13_5_merges_them() {
    let mut wrong = Vec::new();
    for (file, kernels) in PROBES {
        let sass = std::fs::read_to_string(format!("{DIR}/{file}.sass")).unwrap();
        for kernel in kernels {
            let want = sass_counts(&section(&sass, kernel));
            let got = shared_counts(file, kernel, true);
            let (off_ld, off_st) = shared_counts(file, kernel, false);
            assert!(off_ld >= got.0 && off_st >= got.1, "{file} {kernel}: merging added accesses");
            if got != want {
                wrong.push(format!("{file} {kernel}: SASS {want:?}, warplight {got:?}"));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_sass_reader_counts_loops_and_callees() {
    let sass = std::fs::read_to_string(format!("{DIR}/vectorize_probes.sass")).unwrap();
    // one LDS.64 in a loop of ITERS iterations
    assert_eq!(sass_counts(&section(&sass, "loop_step8")), (u64::from(ITERS), 0));
    assert_eq!(sass_counts(&section(&sass, "second_var")), (3, 0));
    let held = std::fs::read_to_string(format!("{DIR}/vectorize_heldout.sass")).unwrap();
    // the callee's LDS is in the kernel's section; the store pair is one STS.64
    assert_eq!(sass_counts(&section(&held, "callee_var")), (3, 0));
    assert_eq!(sass_counts(&section(&held, "abs_st")), (1, 1));
}
