//! Device `printf` (`vprintf` calls) in the emulator, on clang's and nvcc's
//! PTX of one kernel (`tests/fixtures/printf/printf.cu`, committed in both
//! dialects), and a student's kernel with `expf` and `printf` run with one
//! command from another directory (issue 18's "done when").

mod common;

use std::process::Command;

use warplight::sim::{Arg, Device, LaunchConfig};

/// What `printf.cu` prints for thread `t` of CTA `c` (as glibc formats it).
fn expected_line(c: u32, t: u32) -> String {
    let i = c * 40 + t;
    let f = i as f32 * 0.5 - 3.25;
    format!(
        "cta {c} t {t:>2}: d={} u={} x={:x} X={} f={:.3} e={} g={} s={:<6}| c={} p={} ld={} lld={} pct=%\n",
        i as i32 - 20,
        (i as i32 - 20) as u32,
        i * 4099,
        // C's %#06X: no prefix for 0, the width counts the prefix
        if i == 0 { "000000".to_string() } else { format!("0X{i:04X}") },
        f,
        Lit(f as f64),
        G(f as f64),
        &"warplight"[..(i % 5) as usize],
        (b'A' + (i % 26) as u8) as char,
        "0x1000",
        -(i as i64) * 1_000_000_007,
        (i as i64) << 40,
    )
}

/// `%e` of a value as C prints it (mantissa and a two-digit exponent).
struct Lit(f64);
impl std::fmt::Display for Lit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = format!("{:.6e}", self.0);
        let (m, e) = s.split_once('e').unwrap();
        let e: i32 = e.parse().unwrap();
        write!(f, "{m}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
    }
}

/// `%g` of the values `printf.cu` prints (|v| < 100, multiples of 0.5).
struct G(f64);
impl std::fmt::Display for G {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

fn run_printf(ptx_file: &str) -> String {
    let src = std::fs::read_to_string(ptx_file).unwrap();
    let mut dev = Device::new();
    let m = dev.load_ptx(&src, ptx_file).unwrap_or_else(|e| panic!("{e}"));
    let out = dev.alloc_zeroed::<i32>(80);
    let cfg = LaunchConfig { grid: [2, 1, 1], block: [40, 1, 1], dynamic_shared: 0 };
    dev.launch(&m, "printf_kernel", cfg, &[Arg::Ptr(out)]).unwrap_or_else(|e| panic!("{e}"));
    // printf's return value: the number of arguments used (15)
    assert!(dev.read::<i32>(out, 80).iter().all(|&r| r == 15), "{:?}", dev.read::<i32>(out, 8));
    warplight::sim::printf::text(&dev.take_printf())
}

#[test]
fn printf_prints_per_lane_in_cta_warp_lane_order_from_both_dialects() {
    // CTA 0's warp 0 (lanes 0-31), its warp 1 (8 lanes), then CTA 1, whatever the host threads
    let mut want = String::new();
    for c in 0..2 {
        for t in 0..40 {
            want += &expected_line(c, t);
        }
        want += &format!("cta {c} done\n");
    }
    for file in ["tests/fixtures/printf/printf.ptx", "tests/fixtures/printf/printf.nvcc.ptx"] {
        let got = run_printf(file);
        // the "done" line is printed by thread 0 after a barrier: warp 0's second call
        let reordered: String = {
            let mut lines: Vec<&str> = got.lines().collect();
            let done: Vec<usize> =
                lines.iter().enumerate().filter(|(_, l)| l.ends_with("done")).map(|(i, _)| i).collect();
            assert_eq!(done.len(), 2, "{file}: {got}");
            // warp 0's calls come first in each CTA: its 32 lines, its "done", then warp 1's 8
            assert_eq!((done[0], done[1]), (32, 32 + 1 + 8 + 32), "{file}:\n{got}");
            let d1 = lines.remove(done[1]);
            let d0 = lines.remove(done[0]);
            lines.insert(40, d0);
            lines.insert(81, d1);
            lines.iter().map(|l| format!("{l}\n")).collect()
        };
        for (g, w) in reordered.lines().zip(want.lines()) {
            assert_eq!(g, w, "{file}");
        }
        assert_eq!(reordered, want, "{file}");
    }
}

#[test]
fn a_students_kernel_with_expf_and_printf_runs_with_one_command_from_any_directory() {
    let dir = std::env::temp_dir().join(format!("warplight-printf-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("softmax.cu"), STUDENT).unwrap();
    let warplight = |args: &[&str], env: &[(&str, &str)]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_warplight"));
        c.args(args).current_dir(&dir);
        for (k, v) in env {
            c.env(k, v);
        }
        let o = c.output().unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let run = ["run", "softmax.cu", "--grid", "1", "--block", "8", "--buffer", "x=f32:8:iota", "--args", "x,8"];
    if common::external("clang-16", "apt-get install clang-16").is_none() {
        return;
    }
    // without libdevice: the error names the function and how to install the library
    let (ok, _, err) = warplight(&run, &[("WARPLIGHT_LIBDEVICE", "none")]);
    assert!(!ok && err.contains("`expf` is in CUDA's math library (libdevice), which was not found"), "{err}");
    assert!(err.contains("pip install nvidia-cuda-nvcc"), "{err}");
    let (ok, _, err) = warplight(&run, &[("WARPLIGHT_LIBDEVICE", "/nonexistent/libdevice.10.bc")]);
    assert!(
        !ok && err.contains("/nonexistent/libdevice.10.bc: libdevice not found there (WARPLIGHT_LIBDEVICE)"),
        "{err}"
    );
    let libdevice = match warplight::compile::find_libdevice(None) {
        Ok(Some(p)) => p,
        _ => {
            let required = std::env::var("WARPLIGHT_REQUIRE_EXTERNAL").is_ok_and(|v| !v.is_empty() && v != "0");
            assert!(!required, "libdevice is required (WARPLIGHT_REQUIRE_EXTERNAL=1): pip install nvidia-cuda-nvcc");
            use std::io::Write;
            let _ = writeln!(
                std::io::stderr(),
                "skipped: the rest of this test needs libdevice (install: pip install nvidia-cuda-nvcc)"
            );
            return;
        }
    };
    let (ok, out, err) = warplight(&run, &[]);
    assert!(ok, "{err}{out}");
    // e^i / sum e^j for i = 0..8, printed per thread in lane order, before the counters
    let sum: f64 = (0..8).map(|j| (j as f64).exp()).sum();
    let lines: Vec<&str> = out.lines().take(8).collect();
    for (i, l) in lines.iter().enumerate() {
        let (head, rest) = l.split_once(" = ").unwrap_or_else(|| panic!("{out}"));
        assert_eq!(head, format!("thread {i}: exp({i})"), "{out}");
        let (e, soft) = rest.split_once(", softmax = ").unwrap_or_else(|| panic!("{out}"));
        let (e, soft): (f64, f64) = (e.parse().unwrap(), soft.parse().unwrap());
        assert!(e.to_string().len() <= 10 && rest.split_once('.').unwrap().1.find(',') == Some(4), "%.4f: {l}");
        assert!((e - (i as f64).exp()).abs() < 1e-3 && (soft - (i as f64).exp() / sum).abs() < 1e-6, "{l}");
    }
    assert!(out.contains("device hopper"), "{out}");
    let want: String = lines.iter().map(|l| format!("{l}\n")).collect();
    // the same with --libdevice, and through `compile` + `launch --json` (printf in the JSON)
    let lib = libdevice.display().to_string();
    let (ok, out, err) = warplight(&["compile", "softmax.cu", "--libdevice", &lib], &[]);
    assert!(ok && out.contains("kernel softmax"), "{err}{out}");
    std::fs::write(dir.join("s.toml"), SPEC).unwrap();
    let (ok, out, err) = warplight(&["launch", "s.toml", "--json"], &[]);
    assert!(ok, "{err}{out}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["printf"].as_array().unwrap().len(), 8);
    assert_eq!(j["printf"][3]["lane"], 3);
    assert_eq!(j["printf"][3]["text"].as_str().unwrap(), want.lines().nth(3).unwrap().to_string() + "\n");
    std::fs::remove_dir_all(&dir).ok();
}

const STUDENT: &str = r#"#include <cstdio>
__global__ void softmax(float *x, int n) {
  int i = threadIdx.x;
  float e = expf(x[i]);
  float sum = 0;
  for (int j = 0; j < n; j++) sum += expf(x[j]);
  printf("thread %d: exp(%d) = %.4f, softmax = %f\n", i, i, e, e / sum);
  x[i] = e / sum;
}
"#;

const SPEC: &str = "ptx = \"softmax.ptx\"
kernel = \"_Z7softmaxPfi\"
grid = 1
block = 8
args = [\"x\", 8]
[[buffer]]
name = \"x\"
type = \"f32\"
len = 8
init = \"iota\"
";
