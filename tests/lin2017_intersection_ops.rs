//! Thesis 003 §6.4's operation counts (table lin:s6.4): the emulator's
//! counts of the standard (Möller-Trumbore) and the affine ray-triangle
//! tests against counts derived by hand from `kernels/lin2017/intersect.cu`,
//! and the measured affine routine against the path tracer's own.

use warplight::host::scene_file;
use warplight::ptx;
use warplight::repro::compare::Verdict;
use warplight::repro::lin2017::sec_6_4::{self, Ops, function_lines, measure_on, static_ops};
use warplight::repro::protocol::Protocol;
use warplight::repro::registry::{Workspace, resolve};
use warplight::repro::results::Results;

fn cornell() -> warplight::host::scene::Scene {
    scene_file::load(&scene_file::resolve(sec_6_4::SCENE)).expect("scene")
}

/// By hand from `standard()`: edges 6 sub; p = d x e2 6 mul 3 sub; det 3 mul 2 add;
/// 1/det one rcp; s = o - a 3 sub; u 3 mul 2 add 1 mul; q = s x e1 6 mul 3 sub;
/// v 3 mul 2 add 1 mul; u + v 1 add; t 3 mul 2 add 1 mul: 27 mul, 24 add/sub.
const STANDARD: Ops = Ops { mul: 27, add: 24, fma: 0, div: 1, neg: 0 };
/// By hand from `affine()`: oz 3 mul 3 add; dz 3 mul 2 add; -oz / dz one neg, one div;
/// u and v 7 mul 6 add each; u + v 1 add: 20 mul, 18 add/sub.
const AFFINE: Ops = Ops { mul: 20, add: 18, fma: 0, div: 1, neg: 1 };

#[test]
fn the_emulator_counts_the_hand_derived_operations() {
    let m = measure_on(&cornell()).expect("measure");
    assert_eq!(m.len(), 4);
    for r in &m {
        assert_eq!(r.hits, r.tests, "{r:?}");
        assert!(r.tests >= 30, "{r:?}");
        let want = if r.routine == "standard" { STANDARD } else { AFFINE };
        match r.dialect {
            // clang, contraction off: every operation an instruction of its own
            "clang" => {
                assert_eq!(r.ops, want, "{r:?}");
                assert!(r.exact, "{r:?}");
            }
            // nvcc contracts pairs into fma, nothing else: unfused, the same counts
            _ => {
                assert!(r.ops.fma > 0, "{r:?}");
                assert_eq!(
                    (r.ops.mul_unfused(), r.ops.add_unfused(), r.ops.div),
                    (want.mul, want.add, want.div),
                    "{r:?}"
                );
            }
        }
        assert!(r.max_rel_error < 1e-4, "{r:?}");
    }
}

#[test]
fn the_measured_affine_test_is_the_path_tracers() {
    // every inlined copy of path.cu's affine() compiles to the operations of
    // intersect.cu's tri_affine (the copies counted by their one division)
    let path_src = include_str!("../kernels/lin2017/path.cu");
    let path = ptx::load(include_str!("../kernels/lin2017/path.ptx"), "kernels/lin2017/path.ptx").expect("path.ptx");
    let lines = function_lines(path_src, "affine").expect("affine() in path.cu");
    let ops = static_ops(&path, "kernels/lin2017/path.cu", &lines);
    let copies = ops.div;
    assert!(copies >= 2, "{ops:?}");
    let per =
        Ops { mul: ops.mul / copies, add: ops.add / copies, fma: ops.fma / copies, div: 1, neg: ops.neg / copies };
    assert_eq!(
        Ops { mul: per.mul * copies, add: per.add * copies, fma: per.fma * copies, div: copies, neg: per.neg * copies },
        ops,
        "copies differ"
    );
    assert_eq!(per, AFFINE);
    let ours = ptx::load(sec_6_4::PTX, "kernels/lin2017/intersect.ptx").expect("intersect.ptx");
    let l = function_lines(sec_6_4::SOURCE, "affine").expect("affine() in intersect.cu");
    assert_eq!(static_ops(&ours, sec_6_4::SOURCE_FILE, &l), AFFINE);
}

#[test]
fn function_lines_span_the_definition() {
    let src = "int a;\nstatic __device__ bool f(int x) {\n  return x;\n}\nstatic __device__ bool g(int y) {\n}\n";
    assert_eq!(function_lines(src, "f"), Some(2..=4));
    assert_eq!(function_lines(src, "g"), Some(5..=6));
    assert_eq!(function_lines(src, "h"), None);
    // a call is not a definition
    assert_eq!(function_lines("  f(1);\n}\n", "f"), None);
}

#[test]
fn the_table_renders_the_recorded_verdicts() {
    let scene = cornell();
    let mut ws = Workspace::new(&scene, 0..1, 32);
    let samples = sec_6_4::measure(&mut ws, &mut |_| {}).expect("measure");
    let mut r = Results::new("test", Protocol::quick(), vec!["lin:s6.4".into()], vec![sec_6_4::OPS.into()]);
    r.samples = samples;
    let e = resolve(&["lin:s6.4".into()]).expect("registered").remove(0);
    let t = (e.table.render.expect("rendered"))(&e, &r).remove(0);
    let verdicts: Vec<Option<Verdict>> =
        t.rows.iter().flat_map(|row| row.cells[..2].iter().map(|c| c.verdict)).collect();
    // the affine test's 20 multiplications agree; 27, 24 and 18 are not 26, 23 and 13
    assert_eq!(
        verdicts,
        vec![Some(Verdict::Outside), Some(Verdict::Outside), Some(Verdict::Within), Some(Verdict::Outside)]
    );
    assert!(t.checks.iter().all(|c| c.holds), "{:?}", t.checks);
}

/// Per-test f32 instruction counts of one kernel in the H200 fixture.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Sass {
    fadd: u64,
    fmul: u64,
    ffma: u64,
}

fn sass(v: &serde_json::Value, path: &[&str]) -> Sass {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    let n = |k: &str| x[k].as_u64().unwrap_or_else(|| panic!("{path:?}.{k} in the fixture"));
    Sass { fadd: n("fadd"), fmul: n("fmul"), ffma: n("ffma") }
}

#[test]
fn the_h200_executes_the_emulators_operations() {
    // tests/fixtures/lin2017/h200_intersection_ops.json: ncu's per-thread
    // FADD/FMUL/FFMA over 4096 hitting pairs (tools/device/intersect_ops.sh)
    let f: serde_json::Value =
        serde_json::from_str(include_str!("fixtures/lin2017/h200_intersection_ops.json")).expect("fixture");
    assert_eq!(f["pairs"].as_u64(), Some(4096));
    for d in ["nvcc", "clang_ptx_jit"] {
        for k in ["tri_standard", "tri_affine"] {
            assert_eq!(f["hits"][d][k].as_u64(), Some(4096), "{d} {k}");
        }
    }
    let m = measure_on(&cornell()).expect("measure");
    for r in &m {
        let kernel = if r.routine == "standard" { "tri_standard" } else { "tri_affine" };
        // the rcp/div fast path, the same in every compilation: taken out
        let div = sass(&f, &["division_fast_path", kernel]);
        let run = sass(&f, &["dynamic", if r.dialect == "clang" { "clang_ptx_jit" } else { "nvcc" }, kernel]);
        let own = Sass { fadd: run.fadd - div.fadd, fmul: run.fmul - div.fmul, ffma: run.ffma - div.ffma };
        // unfused, the hardware does the emulator's multiplications and additions
        assert_eq!(own.fmul + own.ffma, r.ops.mul_unfused(), "{r:?} {own:?}");
        assert_eq!(own.fadd + own.ffma, r.ops.add_unfused(), "{r:?} {own:?}");
        match (r.dialect, r.routine) {
            // mul.rn/add.rn: ptxas fuses none of clang's operations
            ("clang", _) => assert_eq!((own.fmul, own.fadd, own.ffma), (r.ops.mul, r.ops.add, 0), "{r:?}"),
            // nvcc's affine PTX compiles as written
            (_, "affine") => assert_eq!((own.fmul, own.fadd, own.ffma), (r.ops.mul, r.ops.add, r.ops.fma), "{r:?}"),
            // ptxas fuses six more of the standard test's mul/add pairs (plain mul.f32/add.f32)
            _ => assert_eq!(own.ffma, r.ops.fma + 6, "{r:?} {own:?}"),
        }
    }
    // the statically listed kernels agree with those executed; the one FADD
    // more on tri_affine's division line negates the dividend for the slow path
    for (st, dy) in [("clang", "clang_ptx_jit"), ("binary", "nvcc"), ("nvcc", "nvcc")] {
        for k in ["tri_standard", "tri_affine"] {
            let (s, d) = (sass(&f, &["static", st, k]), sass(&f, &["dynamic", dy, k]));
            let extra = u64::from(k == "tri_affine");
            assert_eq!(s, Sass { fadd: d.fadd + extra, ..d }, "{st} {k}");
        }
    }
}
