//! `warplight compile`: a student's .cu (no includes) to PTX that warplight
//! runs, from any directory; the compiler's errors and a missing compiler
//! explained.

mod common;

use std::process::Command;

fn warplight_in(dir: &std::path::Path, args: &[&str], path: Option<&str>) -> (bool, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_warplight"));
    c.args(args).current_dir(dir);
    if let Some(p) = path {
        c.env("PATH", p);
    }
    let o = c.output().unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stdout).into(), String::from_utf8_lossy(&o.stderr).into())
}

#[test]
fn a_cu_file_compiles_and_runs_from_any_directory() {
    let dir = std::env::temp_dir().join(format!("warplight-compile-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // without a compiler: a clear error with the install command, whatever else is installed
    std::fs::write(dir.join("saxpy.cu"), SAXPY).unwrap();
    let (ok, _, err) = warplight_in(&dir, &["compile", "saxpy.cu"], Some("/nonexistent"));
    assert!(!ok && err.contains("clang-16 is not installed; install it with `apt-get install clang-16`"), "{err}");
    if common::external("clang-16", "apt-get install clang-16").is_none() {
        return;
    }
    let (ok, out, err) = warplight_in(&dir, &["compile", "saxpy.cu"], None);
    assert!(ok, "{err}");
    assert!(out.contains("kernel saxpy (PTX name _Z5saxpyifPKfPf)") && out.contains("kernel scale\n"), "{out}");
    // the PTX runs: y = 2 x + y over 1000 elements
    std::fs::write(dir.join("saxpy.toml"), SPEC).unwrap();
    let (ok, out, err) = warplight_in(&dir, &["launch", "saxpy.toml", "--json", "--dump", "y=y.bin"], None);
    assert!(ok, "{err}{out}");
    let y: Vec<f32> = std::fs::read(dir.join("y.bin"))
        .unwrap()
        .chunks(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert!(y.iter().enumerate().all(|(i, v)| *v == 3.0 * i as f32), "{:?}", &y[..8]);
    // a spec may name the .cu itself, and a C++ kernel by its plain name
    let spec_cu = SPEC.replace("saxpy.ptx", "saxpy.cu").replace("_Z5saxpyifPKfPf", "saxpy");
    std::fs::write(dir.join("saxpy_cu.toml"), spec_cu).unwrap();
    let (ok, out, err) = warplight_in(&dir, &["launch", "saxpy_cu.toml", "--dump", "y=y2.bin"], None);
    assert!(ok, "{err}{out}");
    assert_eq!(std::fs::read(dir.join("y2.bin")).unwrap(), std::fs::read(dir.join("y.bin")).unwrap());
    let (ok, out, err) = warplight_in(&dir, &["step", "saxpy_cu.toml", "--log", "--break-src", "saxpy.cu:3"], None);
    assert!(ok && out.contains("stepping saxpy") && out.contains("break at source line 3"), "{err}{out}");
    // `warplight run`: the same launch from the command line, no spec file
    let (ok, out, err) = warplight_in(
        &dir,
        &[
            "run",
            "saxpy.cu",
            "--kernel",
            "saxpy",
            "--grid",
            "4",
            "--block",
            "256",
            "--buffer",
            "x=f32:1000:iota",
            "--buffer",
            "y=f32:1000:iota",
            "--args",
            "1000,2.0,x,y",
            "--dump",
            "y=y3.bin",
        ],
        None,
    );
    assert!(ok, "{err}{out}");
    assert_eq!(std::fs::read(dir.join("y3.bin")).unwrap(), std::fs::read(dir.join("y.bin")).unwrap());
    let (ok, _, err) = warplight_in(&dir, &["run", "saxpy.cu", "--grid", "1", "--block", "32"], None);
    assert!(!ok && err.contains("saxpy.cu has 2 kernels; name one with --kernel: saxpy, scale"), "{err}");
    let (ok, _, err) = warplight_in(
        &dir,
        &["run", "saxpy.cu", "--kernel", "scale", "--grid", "1", "--block", "32", "--args", "nope,2"],
        None,
    );
    assert!(!ok && err.contains("\"nope\" is neither a number nor a --buffer name"), "{err}");
    // compiler errors come with the compiler's messages
    std::fs::write(dir.join("bad.cu"), "__global__ void k() { undeclared = 1; }\n").unwrap();
    let (ok, _, err) = warplight_in(&dir, &["compile", "bad.cu"], None);
    assert!(!ok && err.contains("bad.cu: ") && err.contains("undeclared"), "{err}");
    assert!(!dir.join("bad.ptx").exists());
    std::fs::remove_dir_all(&dir).ok();
}

const SAXPY: &str = "__global__ void saxpy(int n, float a, const float *x, float *y) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) y[i] = a * x[i] + y[i];
}
extern \"C\" __global__ void scale(float *y, float a) { y[threadIdx.x] *= a; }
";

const SPEC: &str = "ptx = \"saxpy.ptx\"
kernel = \"_Z5saxpyifPKfPf\"
grid = 4
block = 256
args = [1000, 2.0, \"x\", \"y\"]
[[buffer]]
name = \"x\"
type = \"f32\"
len = 1000
init = \"iota\"
[[buffer]]
name = \"y\"
type = \"f32\"
len = 1000
init = \"iota\"
";
