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

/// `__syncwarp` (the prelude's, `bar.warp.sync`) compiles and runs; the line
/// table names the prelude as the project's `kernels/prelude.h`, never the
/// temporary folder it was compiled from, so the same source gives the same PTX.
#[test]
fn syncwarp_compiles_and_the_ptx_names_no_temporary_folder() {
    if common::external("clang-16", "apt-get install clang-16").is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("warplight-syncwarp-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("rotate.cu"), ROTATE).unwrap();
    let (ok, out, err) = warplight_in(&dir, &["compile", "rotate.cu", "-o", "a.ptx"], None);
    assert!(ok && out.contains("kernel rotate"), "{err}{out}");
    let (ok, _, err) = warplight_in(&dir, &["compile", "rotate.cu", "-o", "b.ptx"], None);
    assert!(ok, "{err}");
    let a = std::fs::read_to_string(dir.join("a.ptx")).unwrap();
    assert_eq!(a, std::fs::read_to_string(dir.join("b.ptx")).unwrap(), "two compilations, one PTX");
    assert!(a.contains("bar.warp.sync") && a.contains(".file\t3 \"kernels/prelude.h\""), "{a}");
    assert!(!a.contains("warplight-compile-"), "{a}");
    // each lane reads its neighbour's value after the warp synchronised
    let (ok, out, err) = warplight_in(
        &dir,
        &["run", "rotate.cu", "--grid", "1", "--block", "64", "--buffer", "o=i32:64", "--args", "o", "--print", "o"],
        None,
    );
    assert!(ok, "{err}{out}");
    let values: Vec<i32> = out
        .split("o[0..64]:")
        .nth(1)
        .unwrap_or_else(|| panic!("{out}"))
        .lines()
        .flat_map(|l| {
            l.split(']').nth(1).unwrap_or("").split_whitespace().map(|v| v.parse::<i32>().unwrap()).collect::<Vec<_>>()
        })
        .collect();
    let want: Vec<i32> = (0..64).map(|t| (t + 1) % 32 + t / 32 * 32).collect();
    assert_eq!(values, want, "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `run` takes `--libdevice` and `--dialect` as `compile` does: the option
/// wins over `WARPLIGHT_LIBDEVICE`, and a file that is not there is named.
#[test]
fn run_takes_the_compile_options() {
    if common::external("clang-16", "apt-get install clang-16").is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("warplight-run-options-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("e.cu"),
        "extern \"C\" __global__ void e(float *x) { x[threadIdx.x] = expf(x[threadIdx.x]); }\n",
    )
    .unwrap();
    let run = |extra: &[&str], env_lib: &str| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_warplight"));
        c.args([
            "run",
            "e.cu",
            "--grid",
            "1",
            "--block",
            "4",
            "--buffer",
            "x=f32:4:iota",
            "--args",
            "x",
            "--print",
            "x",
        ])
        .args(extra)
        .current_dir(&dir)
        .env("WARPLIGHT_LIBDEVICE", env_lib);
        let o = c.output().unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (ok, _, err) = run(&["--libdevice", "/nonexistent/libdevice.10.bc"], "none");
    assert!(!ok && err.contains("/nonexistent/libdevice.10.bc: libdevice not found there (--libdevice)"), "{err}");
    let (ok, _, err) = run(&["--dialect", "gcc"], "none");
    assert!(!ok && err.contains("--dialect gcc: expected clang or nvcc"), "{err}");
    let Ok(Some(lib)) = warplight::compile::find_libdevice(None) else {
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "skipped: the rest of run_takes_the_compile_options needs libdevice (install: pip install nvidia-cuda-nvcc)"
        );
        return;
    };
    // WARPLIGHT_LIBDEVICE=none alone fails; --libdevice overrides it
    let (ok, _, err) = run(&[], "none");
    assert!(!ok && err.contains("`expf` is in CUDA's math library"), "{err}");
    let (ok, out, err) = run(&["--libdevice", &lib.display().to_string()], "none");
    assert!(ok && out.contains("2.7182817"), "{err}{out}");
    std::fs::remove_dir_all(&dir).ok();
}

const ROTATE: &str = "extern \"C\" __global__ void rotate(int *out) {
  __shared__ int s[64];
  int t = threadIdx.x;
  s[t] = t;
  __syncwarp();
  out[t] = s[(t + 1) % 32 + t / 32 * 32];
}
";
