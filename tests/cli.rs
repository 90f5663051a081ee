//! The `warplight` binary: launch specs end to end, output formats, and errors
//! that leave no partial output.

mod support;
use support::warplight;

use std::process::Command;

#[test]
fn launch_prints_counters_and_dumps_buffers() {
    let dir = tempdir();
    let dump = dir.join("sums.bin");
    let (ok, out, err) =
        warplight(&["launch", "examples/reduce.toml", "--json", "--dump", &format!("sums={}", dump.display())]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let c = &v["launches"][0]["counters"];
    assert_eq!(c["ctas"], 8);
    assert_eq!(c["barriers"], 72);
    assert!(c["l1tex__data_pipe_lsu_wavefronts_mem_shared_op_ld.sum"].as_u64().unwrap() > 0);
    let sums: Vec<i32> =
        std::fs::read(&dump).unwrap().chunks(4).map(|b| i32::from_le_bytes(b.try_into().unwrap())).collect();
    let exp: Vec<i32> = (0..8)
        .map(|b| (b * 256..(b + 1) * 256).map(|i: u64| (i.wrapping_mul(2654435761) % 100) as i32).sum())
        .collect();
    assert_eq!(sums, exp);
}

#[test]
fn metrics_selection_accepts_profiler_names() {
    let (ok, out, err) = warplight(&[
        "launch",
        "examples/reduce.toml",
        "--csv",
        "--device",
        "gt200",
        "--metrics",
        "smsp__inst_executed.sum,gld_64b,warp_serialize",
    ]);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "launch,kernel,metric,value");
    assert_eq!(lines.len(), 4);
    assert!(lines[2].starts_with("0,reduce_sum,gld_64b,"));
    let (ok, _, err) = warplight(&["launch", "examples/reduce.toml", "--metrics", "nonsense"]);
    assert!(!ok && err.contains("unknown metric `nonsense`"), "{err}");
}

#[test]
fn a_faulting_launch_writes_no_files() {
    let dir = tempdir();
    let spec = dir.join("bad.toml");
    std::fs::write(
        &spec,
        format!(
            "ptx = \"{}/kernels/tests/memory.ptx\"\nkernel = \"out_of_bounds\"\ngrid = 2\nblock = 32\nargs = [\"out\"]\n[[buffer]]\nname = \"out\"\ntype = \"i32\"\nlen = 40\n",
            env!("CARGO_MANIFEST_DIR")
        ),
    )
    .unwrap();
    let dump = dir.join("out.bin");
    let (ok, _, err) = warplight(&["launch", spec.to_str().unwrap(), "--dump", &format!("out={}", dump.display())]);
    assert!(!ok);
    assert!(err.contains("out-of-bounds") && err.contains("memory.cu"), "{err}");
    assert!(!dump.exists(), "no partial output");
}

#[test]
fn spec_errors_name_the_key() {
    let dir = tempdir();
    let spec = dir.join("s.toml");
    std::fs::write(&spec, "ptx = \"x.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\nargs = [\"missing\"]\n").unwrap();
    let (ok, _, err) = warplight(&["launch", spec.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("`args[0]`: no buffer named `missing`"), "{err}");
    let (ok, _, err) = warplight(&["launch", "examples/reduce.toml", "--device", "fermi"]);
    assert!(!ok && err.contains("unknown device profile `fermi`"), "{err}");
}

#[test]
fn check_and_kernels_commands() {
    let (ok, out, _) = warplight(&["check", "kernels/tests/shared.nvcc.ptx"]);
    assert!(ok && out.contains("ok (5 kernels"), "{out}");
    let (ok, out, _) = warplight(&["kernels", "kernels/tests/calls.ptx"]);
    assert!(ok && out.contains("recursive_fib(") && out.contains("device functions"), "{out}");
    let dir = tempdir();
    let bad = dir.join("bad.ptx");
    std::fs::write(&bad, ".version 7.8\n.target sm_90\n.entry k()\n{\n  frobnicate.u32 %r1;\n}\n").unwrap();
    let (ok, _, err) = warplight(&["check", bad.to_str().unwrap()]);
    assert!(!ok && err.contains(":5:3: unsupported instruction `frobnicate.u32`"), "{err}");
}

fn tempdir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("warplight-cli-{}-{}", std::process::id(), rand_suffix()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn rand_suffix() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    N.fetch_add(1, Ordering::Relaxed)
}

#[test]
fn step_logs_divergence_and_breakpoints() {
    let (ok, out, err) = warplight(&["step", "examples/if_else.toml", "--trace"]);
    assert!(ok, "{err}");
    // the hand-derived counts of tests/control_flow.rs, seen instruction by instruction
    assert!(out.contains("finished after 28 warp instructions"), "{out}");
    assert!(out.contains("688 thread instructions, 1 divergent branches, 2 reconvergences"), "{out}");
    assert!(out.contains("bra.uni                      mask aaaaaaaa (16 lanes)"), "{out}");
    let (ok, out, _) = warplight(&["step", "examples/if_else.toml", "--break", "45", "--watch", "%r10"]);
    assert!(ok);
    assert!(out.contains("stack[1]: pc 13 rpc 25 mask 55555555"), "{out}");
    assert!(out.contains("%r10 = 1:1 3:3 5:5"), "{out}");
    let (ok, _, err) = warplight(&["step", "examples/if_else.toml", "--warp", "nonsense"]);
    assert!(!ok && err.contains("expected SLOT:WARP"), "{err}");
}

#[test]
fn step_breaks_once_where_a_warp_enters_a_source_line() {
    // line 11 (`odd[i] = t * 3;`) spans several PTX instructions; the odd lanes enter it once
    let (ok, out, err) =
        warplight(&["step", "examples/if_else.toml", "--break-src", "divergence.cu:11", "--watch", "%r10"]);
    assert!(ok, "{err}");
    assert!(out.contains("break at source line 11, PTX line 64"), "{out}");
    assert!(out.contains("active aaaaaaaa"), "{out}");
    assert!(out.contains("1 breakpoint stops"), "{out}");
    // the else side (line 14) is entered by the even lanes
    let (ok, out, _) = warplight(&["step", "examples/if_else.toml", "--break-src", "14", "--watch", "%r10"]);
    assert!(ok);
    assert!(out.contains("active 55555555") && out.contains("%r10 = 0:0 2:2"), "{out}");
    for (arg, msg) in [
        ("divergence.cu:99", "no instruction comes from that line"),
        ("nope.cu:11", "no source file `nope.cu`"),
        ("x:y", "expected [FILE:]LINE"),
    ] {
        let (ok, _, err) = warplight(&["step", "examples/if_else.toml", "--break-src", arg]);
        assert!(!ok && err.contains(msg), "{arg}: {err}");
    }
}

#[test]
fn the_lessons_example_specs_run() {
    let mut specs: Vec<_> = std::fs::read_dir("examples/lessons").unwrap().map(|e| e.unwrap().path()).collect();
    specs.sort();
    assert_eq!(specs.len(), 6, "one spec per lesson: {specs:?}");
    for spec in &specs {
        let spec = spec.to_str().unwrap();
        for device in ["gt200", "hopper"] {
            let (ok, out, err) = warplight(&["launch", spec, "--device", device, "--csv"]);
            assert!(ok, "{spec} on {device}: {err}");
            assert!(out.lines().count() > 10, "{spec}: {out}");
        }
        let (ok, out, err) = warplight(&["step", spec, "--log"]);
        assert!(ok && out.contains("finished after"), "{spec}: {out}{err}");
    }
    // every lesson's commands name a spec that exists
    for doc in std::fs::read_dir("docs/lessons").unwrap().map(|e| e.unwrap().path()) {
        let text = std::fs::read_to_string(&doc).unwrap();
        for word in text.split_whitespace().filter(|w| w.starts_with("examples/") && w.ends_with(".toml")) {
            assert!(std::path::Path::new(word).exists(), "{}: {word} does not exist", doc.display());
        }
    }
    // lesson 3's numbers
    let (ok, out, _) = warplight(&[
        "launch",
        "examples/lessons/banks.toml",
        "--csv",
        "--metrics",
        "l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_ld.sum",
    ]);
    assert!(ok);
    let v: Vec<&str> = out.lines().skip(1).map(|l| l.rsplit(',').next().unwrap()).collect();
    assert_eq!(v, vec!["992", "0"]);
}

#[test]
fn a_closed_stdout_ends_quietly() {
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["step", "examples/reduce.toml", "--trace"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // the reader goes away, like `| head` after its lines
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(o.status.code(), Some(141), "{err}");
}

#[test]
fn trace_writes_a_page_or_nothing() {
    let dir = tempdir();
    let page = dir.join("t.html");
    let p = page.to_str().unwrap();
    let (ok, out, err) = warplight(&["trace", "examples/reduce.toml", "--cta", "1", "--warp", "0", "-o", p]);
    assert!(ok, "{err}");
    assert!(out.contains("warp instructions, 1 warps"), "{out}");
    assert!(std::fs::read_to_string(&page).unwrap().contains("reduce_sum"));
    std::fs::remove_file(&page).unwrap();
    for (args, msg) in [
        (vec!["--cta", "99"], "nothing recorded"),
        (vec!["--from", "10", "--to", "5"], "--from 10 is after --to 5"),
        (vec!["--launch", "2"], "--launch 2: the spec has 1 launch (1 to 1)"),
        (vec!["--device", "fermi"], "expected gt200, maxwell or hopper"),
    ] {
        let mut a = vec!["trace", "examples/reduce.toml", "-o", p];
        a.extend(args);
        let (ok, _, err) = warplight(&a);
        assert!(!ok && err.contains(msg), "{a:?}: {err}");
        assert!(!page.exists(), "{a:?} left a file");
    }
}

#[test]
fn step_log_steps_a_later_launch_and_checks_breakpoints() {
    // launch 2 of the bank lesson runs after launch 1, on the same buffers
    let (ok, out, err) = warplight(&["step", "examples/lessons/banks.toml", "--launch", "2", "--log"]);
    assert!(ok, "{err}");
    assert!(out.starts_with("stepping transpose") && out.contains("finished after 832 warp instructions"), "{out}");
    // a breakpoint on a line without an instruction is refused with the line's text
    let (ok, _, err) = warplight(&["step", "examples/if_else.toml", "--break", "1"]);
    assert!(!ok && err.contains("--break 1: no instruction on PTX line 1"), "{err}");
    // not a terminal: the text log even without --log
    let (ok, out, _) = warplight(&["step", "examples/lessons/stackless.toml", "--break", "97", "--watch", "%r36"]);
    assert!(ok && out.matches("break at PTX line 97").count() == 3, "{out}");
    assert!(out.contains("4 divergent branches, 8 reconvergences"), "{out}");
}

#[test]
fn scenes_are_found_from_any_directory() {
    let dir = tempdir();
    let o = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["scene", "info", "scene6"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && out.starts_with("scene scene6 ("), "{out}{}", String::from_utf8_lossy(&o.stderr));
    let o = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["scene", "info", "nosuch"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("nosuch.toml"));
}

#[test]
fn render_checks_its_output_before_working_and_never_leaves_a_partial_file() {
    let dir = tempdir();
    let out = |n: &str| dir.join(n).display().to_string();
    let (ok, _, err) = warplight(&["render", "--scene", "cornell-box", "-o", &out("x.jpg")]);
    assert!(!ok && err.contains("expected a .png or .exr file") && !dir.join("x.jpg").exists(), "{err}");
    let (ok, _, err) =
        warplight(&["render", "--scene", "cornell-box", "--resolution", "100000x100000", "-o", &out("x.png")]);
    assert!(!ok && err.contains("10000000000 pixels is more than"), "{err}");
    let (ok, _, err) = warplight(&["render", "--scene", "cornell-box", "-o", &out("no/such/x.png")]);
    assert!(!ok && err.contains("does not exist"), "{err}");
    let (ok, _, err) = warplight(&["render", "--scene", "cornell-box", "--resolution", "16x16", "-o", &out("y.png")]);
    assert!(ok, "{err}");
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["y.png"], "only the finished image is left");
}

/// An emulated render prints the ray kinds and stack pushes the emulator
/// counted on the kernel's `@count` lines: on the stack-based kernel they are
/// the native caster's, ray for ray.
#[test]
fn emulated_renders_report_ray_kinds_and_pushes() {
    let dir = tempdir();
    let png = dir.join("s.png").display().to_string();
    let counters = |variant: &str| {
        let json = dir.join(format!("{variant}.json")).display().to_string();
        let (ok, out, err) = warplight(&[
            "render",
            "--scene",
            "scene6",
            "--variant",
            variant,
            "--resolution",
            "16x16",
            "-o",
            &png,
            "--json",
            &json,
        ]);
        assert!(ok && out.contains("(primary 256, reflection ") && out.contains("stack pushes"), "{err}{out}");
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        v["counters"].clone()
    };
    let (native, emulated) = (counters("native"), counters("stack"));
    for k in ["rays", "primary", "reflection", "shadow", "pushes"] {
        assert_eq!(emulated[k], native[k], "{k}: {emulated} vs {native}");
    }
    assert!(emulated["shadow"].as_u64().unwrap() > 0 && emulated["pushes"].as_u64().unwrap() > 0, "{emulated}");
}

#[test]
fn launch_prints_a_header_and_sections_without_zero_counters() {
    let (ok, out, err) = warplight(&["launch", "examples/lessons/coalescing.toml"]);
    assert!(ok, "{err}");
    let mut head = out.lines();
    assert_eq!(head.next().unwrap(), "device hopper (H100, compute capability 9.0, 132 SMs)", "{out}");
    let spec = head.next().unwrap();
    assert!(spec.contains("coalescing.toml: 3 launches of kernels/lessons/coalescing.ptx"), "{out}");
    assert!(out.contains("launch 2 of 3: strided_read<<<(4,1,1), (256,1,1)>>>(out, in, 2)  1,024 threads"), "{out}");
    for section in ["  Launch", "  Instructions", "  Memory workload (hopper model)", "  Occupancy"] {
        assert!(out.lines().any(|l| l == section), "no section {section:?}:\n{out}");
    }
    assert!(out.lines().any(|l| l.starts_with("    mem.global_ld.sectors") && l.ends_with("128 sectors")), "{out}");
    assert!(
        out.lines().any(|l| l.starts_with("    thread_instructions ") && l.ends_with("17,408 thread inst")),
        "{out}"
    );
    // zero counters and the profiler's names are left out, and the reader is told
    assert!(!out.contains("atomics.global") && !out.contains("smsp__"), "{out}");
    assert!(out.contains("zero counters and profiler names not shown: --all shows them"), "{out}");
    assert!(out.lines().all(|l| l.chars().count() <= 120), "fits 120 columns:\n{out}");
    let (ok, all, _) = warplight(&["launch", "examples/lessons/coalescing.toml", "--all"]);
    assert!(ok && all.contains("atomics.global") && all.contains("Profiler names (Nsight Compute)"), "{all}");
    assert!(all.contains("smsp__inst_executed.sum"), "{all}");
}

#[test]
fn launch_checks_metric_names_before_running_and_lists_them() {
    // a spec whose kernel would fault: a bad metric name is reported first
    let dir = tempdir();
    let spec = dir.join("bad.toml");
    std::fs::write(
        &spec,
        format!(
            "ptx = \"{}/kernels/tests/memory.ptx\"\nkernel = \"out_of_bounds\"\ngrid = 2\nblock = 32\nargs = [\"out\"]\n[[buffer]]\nname = \"out\"\ntype = \"i32\"\nlen = 40\n",
            env!("CARGO_MANIFEST_DIR")
        ),
    )
    .unwrap();
    let (ok, _, err) = warplight(&["launch", spec.to_str().unwrap(), "--metrics", "warp_instruction"]);
    assert!(!ok && err.contains("unknown metric `warp_instruction`; did you mean warp_instructions"), "{err}");
    assert!(!err.contains("out-of-bounds"), "the kernel must not have run: {err}");
    // --list-metrics runs nothing either, and names what a launch reports
    let (ok, list, err) = warplight(&["launch", spec.to_str().unwrap(), "--list-metrics", "--device", "gt200"]);
    assert!(ok, "{err}");
    assert!(list.contains("  Memory workload (gt200 model)") && list.contains("gld_64b"), "{list}");
    let (ok, out, err) = warplight(&["launch", "examples/reduce.toml", "--json", "--device", "gt200"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for name in v["launches"][0]["counters"].as_object().unwrap().keys() {
        assert!(list.lines().any(|l| l.split_whitespace().next() == Some(name.as_str())), "{name} not listed");
    }
}

#[test]
fn launch_prints_result_buffers() {
    let (ok, out, err) = warplight(&["launch", "examples/reduce.toml", "--print", "sums", "--print", "input:8..10"]);
    assert!(ok, "{err}");
    let exp: Vec<i32> = (0..8)
        .map(|b| (b * 256..(b + 1) * 256).map(|i: u64| (i.wrapping_mul(2654435761) % 100) as i32).sum())
        .collect();
    assert!(out.contains("\nsums[0..8]:\n"), "{out}");
    let row = out.lines().find(|l| l.starts_with("  [0]")).expect("a row of sums");
    let got: Vec<i32> = row[5..].split_whitespace().map(|x| x.parse().unwrap()).collect();
    assert_eq!(got, exp);
    let input = |i: u64| (i * 2654435761) % 100;
    assert!(out.contains(&format!("input[8..10]:\n  [ 8] {:>6} {:>6}", input(8), input(9))), "{out}");
    let (ok, out, _) = warplight(&["launch", "examples/reduce.toml", "--json", "--print", "sums:1"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["print"]["sums:1..2"]["values"][0], exp[1]);
    let (ok, _, err) = warplight(&["launch", "examples/reduce.toml", "--print", "sums:4..9"]);
    assert!(!ok && err.contains("elements 4..9 are not within `sums` (0..8)"), "{err}");
}

#[test]
fn per_line_charges_inlined_library_code_to_the_calling_line() {
    let (ok, out, err) = warplight(&["launch", "examples/lessons/votes.toml", "--per-line"]);
    assert!(ok, "{err}");
    assert!(out.contains("votes.cu:12"), "{out}");
    assert!(!out.contains("prelude.h:") && !out.contains("builtin_vars.h:"), "{out}");
}

#[test]
fn step_and_trace_use_the_specs_device() {
    let dir = tempdir();
    let spec = dir.join("gt200.toml");
    let src = std::fs::read_to_string("examples/if_else.toml").unwrap();
    let src = src.replace("ptx = \"../", &format!("ptx = \"{}/", env!("CARGO_MANIFEST_DIR")));
    std::fs::write(&spec, format!("device = \"gt200\"\n{src}")).unwrap();
    let page = dir.join("t.html");
    let (ok, _, err) = warplight(&["trace", spec.to_str().unwrap(), "-o", page.to_str().unwrap()]);
    assert!(ok, "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("\"profile\":\"gt200\"") && html.contains("gt200 2 transactions"), "the spec's device");
    let (ok, _, err) =
        warplight(&["trace", spec.to_str().unwrap(), "-o", page.to_str().unwrap(), "--device", "hopper"]);
    assert!(ok, "{err}");
    assert!(std::fs::read_to_string(&page).unwrap().contains("\"profile\":\"hopper\""), "--device wins");
}

/// `--fmad`, the spec's `fmad` and the device profile decide ptxas's FFMA
/// contraction: `a*b + c` with c = -RN(a*b) is the product's rounding error
/// when fused and 0 when rounded twice.
#[test]
fn fmad_flag_spec_key_and_profile_decide_contraction() {
    let dir = std::env::temp_dir().join(format!("warplight-fmad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = ".version 8.0\n.target sm_90\n.address_size 64\n.visible .entry k(.param .u64 p)\n{\n\
               .reg .f32 %f<5>;\n.reg .b64 %rd<2>;\nld.param.u64 %rd1, [p];\ncvta.to.global.u64 %rd1, %rd1;\n\
               ld.global.f32 %f1, [%rd1];\nmul.f32 %f2, %f1, %f1;\nneg.f32 %f3, %f2;\nmul.rn.f32 %f4, %f1, %f1;\n\
               neg.f32 %f4, %f4;\nadd.f32 %f3, %f2, %f4;\nst.global.f32 [%rd1], %f3;\nret;\n}\n";
    std::fs::write(dir.join("k.ptx"), ptx).unwrap();
    let spec = |extra: &str| {
        format!(
            "{extra}ptx = \"k.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 1\nargs = [\"x\"]\n\
             [[buffer]]\nname = \"x\"\ntype = \"f32\"\nlen = 1\ninit = [1.0000001]\n"
        )
    };
    std::fs::write(dir.join("a.toml"), spec("")).unwrap();
    std::fs::write(dir.join("b.toml"), spec("fmad = false\n")).unwrap();
    let value = |args: &[&str]| {
        let (ok, out, err) = warplight(args);
        assert!(ok, "{args:?}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        v["print"]["x:0..1"]["values"][0].as_f64().unwrap()
    };
    let a = dir.join("a.toml");
    let b = dir.join("b.toml");
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let fused = value(&["launch", a, "--json", "--print", "x"]);
    assert!(fused != 0.0, "contracted by default on hopper: the product's rounding error");
    assert_eq!(value(&["launch", a, "--json", "--print", "x", "--fmad=false"]), 0.0);
    assert_eq!(value(&["launch", b, "--json", "--print", "x"]), 0.0, "the spec's fmad = false");
    assert_eq!(value(&["launch", b, "--json", "--print", "x", "--fmad=true"]), fused, "the flag over the spec");
    assert_eq!(value(&["launch", a, "--json", "--print", "x", "--device", "gt200"]), 0.0, "gt200 does not contract");
    assert_eq!(value(&["launch", a, "--json", "--print", "x", "--device", "maxwell"]), fused);
    std::fs::remove_dir_all(&dir).ok();
}

/// `warplight ARGS` run in `dir`: (success, stdout, stderr).
fn warplight_in(dir: &std::path::Path, args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_warplight")).args(args).current_dir(dir).output().unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stdout).into(), String::from_utf8_lossy(&o.stderr).into())
}

#[test]
fn launch_finds_example_specs_from_any_directory() {
    let dir = tempdir();
    let (ok, out, err) = warplight_in(&dir, &["launch", "examples/reduce.toml", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["launches"][0]["counters"]["ctas"], 8);
    // a file of this directory comes first; a name found nowhere is named in the error
    std::fs::create_dir_all(dir.join("examples")).unwrap();
    std::fs::write(dir.join("examples/reduce.toml"), "ptx = 1\n").unwrap();
    let (ok, _, err) = warplight_in(&dir, &["launch", "examples/reduce.toml"]);
    assert!(!ok && err.contains("examples/reduce.toml"), "the local file, not the checkout's: {err}");
    let (ok, _, err) = warplight_in(&dir, &["launch", "examples/nothing.toml"]);
    assert!(!ok && err.contains("examples/nothing.toml"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn validate_names_the_file_in_every_error() {
    let dir = tempdir();
    let file = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let launch = r#"{"launches": [{"id": 3, "kernel": "KERNEL", "grid": 1, "block": 32, "metrics": {}}]}"#;
    let good = file("good.json", &launch.replace("KERNEL", "ld_stride"));
    let bad_ptx = file("bad.ptx", ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n foo;\n}\n");
    let cases: [(Vec<String>, String, &str); 7] = [
        (
            vec![dir.join("none.json").display().to_string()],
            dir.join("none.json").display().to_string(),
            "No such file",
        ),
        (vec![file("x.json", "x")], dir.join("x.json").display().to_string(), "not JSON"),
        (vec![file("e.json", "{}")], dir.join("e.json").display().to_string(), "no `launches` array"),
        (
            vec![file("k.json", r#"{"launches": [{"id": 1}]}"#)],
            dir.join("k.json").display().to_string(),
            "launches[0] has no `kernel`",
        ),
        (
            vec![file("n.json", &launch.replace("KERNEL", "nope"))],
            dir.join("n.json").display().to_string(),
            "launch 3 (`nope`): no kernel `nope`",
        ),
        (
            vec![good.clone(), dir.join("none.ptx").display().to_string()],
            dir.join("none.ptx").display().to_string(),
            "No such file",
        ),
        (vec![good.clone(), bad_ptx.clone()], format!("{bad_ptx}:6:2"), "unsupported instruction `foo`"),
    ];
    for (files, named, why) in cases {
        let mut args = vec!["validate".to_string(), "--fixture".into(), files[0].clone()];
        if let Some(ptx) = files.get(1) {
            args.extend(["--ptx".into(), ptx.clone()]);
        }
        let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        let (ok, _, err) = warplight(&args);
        assert!(!ok && err.starts_with(&format!("error: {named}")) && err.contains(why), "{args:?}: {err}");
    }
    // from another directory the checkout's fixture and PTX are found
    let (ok, _, err) = warplight_in(&dir, &["validate", "--fixture", &good]);
    assert!(ok, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `step --device` and `trace --device` say that the profile sets the run's
/// arithmetic (contraction, SFU), not only the memory views.
#[test]
fn step_and_trace_help_say_the_device_sets_the_arithmetic() {
    for cmd in ["step", "trace"] {
        let (ok, out, err) = warplight(&[cmd, "--help"]);
        assert!(ok, "{cmd} --help: {err}");
        let flat = out.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(flat.contains("FMA contraction and the SFU model"), "{cmd} --help: {out}");
    }
}

/// `render` refuses options that do not apply to the method or variant
/// asked for (they were accepted and ignored), before any work.
#[test]
fn render_refuses_options_that_do_not_apply() {
    for (args, want) in [
        (vec!["--traversal", "restart"], "--traversal applies to --method path only, not raycast"),
        (vec!["--method", "purcell", "--spp", "8"], "--spp applies to --method path only, not purcell"),
        (vec!["--method", "path", "--estimator", "knn"], "--estimator applies to --method photon-map only"),
        (vec!["--method", "path", "--heuristic", "siroh"], "--heuristic applies to --method raycast only"),
        (vec!["--method", "path", "--json", "x.json"], "--json applies to --method raycast and purcell"),
        (
            vec!["--method", "photon-map", "--json", "x.json"],
            "--json applies to --method raycast and purcell (photon-map",
        ),
        (
            vec!["--method", "purcell", "--variant", "error", "--json", "x.json"],
            "--json applies to --method purcell's native and emulated variants (--variant error",
        ),
        (vec!["--fmad", "false"], "--fmad applies to emulated kernels; --method raycast --variant native runs none"),
        (
            vec!["--method", "photon-map", "--variant", "error", "--device", "hopper"],
            "--device does not apply to --method photon-map --variant error: the accuracy charts use the GT200 model",
        ),
        (
            vec!["--method", "photon-map", "--variant", "error", "--fmad", "false"],
            "--fmad does not apply to --method photon-map --variant error",
        ),
        (
            vec!["--method", "photon-map", "--variant", "error", "--fidelity", "functional"],
            "--fidelity does not apply to --method photon-map --variant error",
        ),
        (
            vec!["--method", "photon-map", "--variant", "error", "--estimator", "knn"],
            "--estimator does not apply to --method photon-map --variant error: the accuracy charts use the GT200 model of Table 6.6 and compare every estimator",
        ),
        (vec!["--method", "path", "--device", "hopper"], "--device applies to emulated kernels"),
        (vec!["--method", "path", "--fidelity", "functional"], "--fidelity applies to emulated kernels"),
    ] {
        let mut a = vec!["render", "--scene", "no-such-scene"];
        a.extend(args);
        let (ok, _, err) = warplight(&a);
        assert!(!ok && err.contains(want), "{a:?}: {err}");
    }
}

/// `render --method path --variant emulated` names the kernel it launched:
/// texture_frame for a scene with texture maps, sss_frame for translucent
/// materials, volume_frame for a medium, else the integrator's.
#[test]
fn path_render_names_the_kernel_it_launched() {
    let dir = tempdir();
    for (scene, kernel) in [
        ("cornell-scratched", "texture_frame"),
        ("sss-balls", "sss_frame"),
        ("smog-room", "volume_frame"),
        ("cornell-lambert", "path_frame"),
    ] {
        let out = dir.join(format!("{scene}.png"));
        let (ok, stdout, stderr) = warplight(&[
            "render",
            "--method",
            "path",
            "--scene",
            scene,
            "--integrator",
            "nee",
            "--spp",
            "4",
            "--resolution",
            "8x8",
            "--variant",
            "emulated",
            "--fidelity",
            "functional",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{scene}: {stderr}");
        assert!(stdout.contains(&format!("emulated {kernel}:")), "{scene}: {stdout}");
    }
}
