//! Device `printf` (`vprintf` calls) in the emulator, on clang's and nvcc's
//! PTX of one kernel (`tests/fixtures/printf/printf.cu`, committed in both
//! dialects), a student's kernel with `expf` and `printf` run with one
//! command from another directory (issue 18's "done when"), and each line at
//! the step that printed it in the step log, the terminal view and the trace.

mod common;

use std::path::Path;
use std::process::Command;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use warplight::model::Profile;
use warplight::sim::{Arg, Device, LaunchConfig};
use warplight::teach::breakpoints::Breakpoints;
use warplight::teach::session::Session;
use warplight::teach::{log, trace, tui};

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

/// The printf kernel as a spec: 2 CTAs of 40 threads (warp 1 has 8 lanes).
const SPEC_FILE: &str = "tests/fixtures/printf/printf.toml";

fn printf_session() -> Session {
    Session::load(Path::new(SPEC_FILE)).unwrap_or_else(|e| panic!("{SPEC_FILE}: {e}"))
}

/// What lane `lane` of warp `warp` of CTA `c` prints at a call: the first
/// call's line, or for the second call (thread 0 after the barrier) `done`.
fn labelled(c: u32, warp: u32, lane: u32, done: bool) -> String {
    let text = if done { format!("cta {c} done\n") } else { expected_line(c, warp * 32 + lane) };
    format!("cta {c} warp {warp} lane {lane:>2}> {}", text.trim_end_matches('\n'))
}

/// The step log: the lines a step printed follow it, with its step number;
/// the whole launch's output still follows the log.
#[test]
fn the_step_log_shows_each_printf_line_at_its_step() {
    let s = printf_session();
    let o = log::LogOptions { trace: true, max_steps: 1_000_000, ..Default::default() };
    let mut out = Vec::new();
    log::run(&s, &o, &mut out).unwrap();
    let out = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = out.lines().collect();
    // each call of a warp: its trace line, then one line a lane, in lane order, same step
    let calls: Vec<usize> =
        (0..lines.len()).filter(|&i| lines[i].contains(": call") && lines[i].contains(" mask ")).collect();
    assert_eq!(calls.len(), 6, "2 CTAs x (2 warps' first calls + thread 0's second)\n{out}");
    let mut seen = Vec::new();
    for &i in &calls {
        let step = lines[i].split_whitespace().next().unwrap();
        let printed: Vec<&str> = lines[i + 1..]
            .iter()
            .take_while(|l| l.split_whitespace().next() == Some(step) && l.contains("> "))
            .copied()
            .collect();
        let (c, w): (u32, u32) = {
            let f: Vec<&str> = lines[i].split(['[', ',', ']']).collect();
            (
                f[1].trim().parse().unwrap(),
                lines[i].split("warp").nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap(),
            )
        };
        let done = seen.contains(&(c, w));
        seen.push((c, w));
        let want: Vec<String> = if done {
            vec![labelled(c, 0, 0, true)]
        } else {
            (0..if w == 0 { 32 } else { 8 }).map(|l| labelled(c, w, l, false)).collect()
        };
        let got: Vec<String> = printed.iter().map(|l| l.split_once(step).unwrap().1.trim_start().to_string()).collect();
        assert_eq!(got, want, "step {step}\n{out}");
    }
    // without --trace the printed lines still show, at their steps; --warp keeps one warp's
    let o = log::LogOptions { max_steps: 1_000_000, only: Some((0, 1)), ..Default::default() };
    let mut out = Vec::new();
    log::run(&s, &o, &mut out).unwrap();
    let out = String::from_utf8(out).unwrap();
    let printed: Vec<&str> = out.lines().filter(|l| l.contains("> ")).collect();
    assert_eq!(printed.len(), 8, "{out}");
    assert!(printed.iter().all(|l| l.contains(" cta 0 warp 1 lane ")), "{out}");
    // the whole launch's output, in CTA, warp, call, lane order, for after the log
    assert_eq!(s.printf_output().len(), 82);
}

/// The terminal view: the step that printed says so on the message line, and
/// panel 5 lists the output with the step of each line; stepping back takes
/// it away again.
#[test]
fn the_terminal_view_shows_each_printf_line_at_its_step() {
    let s = printf_session();
    // the PTX line of the first printf call
    let t = trace::record(&s, &trace_all()).unwrap();
    let call = t.events.iter().find(|e| !e.out.is_empty()).unwrap();
    let script = format!("5g{}\n", call.line);
    let (before, _) = view(&s, &script);
    assert!(before.contains("nothing printed yet"), "{before}");
    let (after, app) = view(&s, &format!("{script}s"));
    assert!(app.message.contains("printf: 32 lines, the last cta 0 warp 0 lane 31>"), "{}", app.message);
    // the panel's last 8 rows: lanes 24 to 31 of warp 0, at the step that printed them
    for lane in 24..32 {
        let want = format!("{:>6} {}", app.steps, labelled(0, 0, lane, false));
        assert!(after.lines().any(|r| r.trim_start_matches('│').starts_with(&want[..60])), "{want}\n{after}");
    }
    assert!(after.contains(&format!("5 printf output: 32 lines to step {}", app.steps)), "{after}");
    // k scrolls back through the output; u steps back before the call
    let (scrolled, _) = view(&s, &format!("{script}skkk"));
    assert!(scrolled.contains(&labelled(0, 0, 21, false)[..40]), "{scrolled}");
    let (back, app) = view(&s, &format!("{script}su"));
    assert!(back.contains("nothing printed yet") && app.message.contains("stepped back"), "{back}");
}

/// The trace: each recorded instruction carries its lanes' output, and the
/// page holds it.
#[test]
fn the_trace_records_each_printf_line_at_its_instruction() {
    let s = printf_session();
    let mut o = trace_all();
    o.ctas = vec![1];
    let t = trace::record(&s, &o).unwrap();
    let printing: Vec<&trace::TraceEvent> = t.events.iter().filter(|e| !e.out.is_empty()).collect();
    assert_eq!(printing.len(), 3, "warp 0's and warp 1's calls, thread 0's second call");
    for e in &printing {
        assert!(e.op.starts_with("call"), "{}", e.op);
        let w = t.warps[e.w].warp;
        let done = e.out.len() == 1;
        let want: Vec<(u32, String)> = if done {
            vec![(0, "cta 1 done\n".to_string())]
        } else {
            (0..e.mask.count_ones()).map(|l| (l, expected_line(1, w * 32 + l))).collect()
        };
        assert_eq!(e.out, want, "step {}", e.step);
    }
    // the instructions that printed nothing carry no output in the page's data
    let page = trace::html(&t).unwrap();
    assert_eq!(page.matches("\"out\":").count(), 3);
    assert!(page.contains("\"out\":[[0,\"cta 1 t  0: d=20 "), "the data holds the text");
    assert!(page.contains("id=\"out\""), "the page has the output pane");
}

fn trace_all() -> trace::TraceOptions {
    trace::TraceOptions {
        ctas: vec![],
        warps: vec![],
        from: 1,
        to: u64::MAX,
        max_events: 100_000,
        profile: Profile::Hopper,
    }
}

/// The terminal view (80x24) after `script` (characters, `\n` for Enter): the screen and the view's state.
fn view(s: &Session, script: &str) -> (String, tui::App) {
    let o = tui::TuiOptions {
        breaks: Breakpoints::default(),
        watches: vec![],
        start: (0, 0),
        profile: Profile::Hopper,
        max_steps: 100_000,
    };
    let mut keys = script
        .chars()
        .map(|c| KeyEvent::new(if c == '\n' { KeyCode::Enter } else { KeyCode::Char(c) }, KeyModifiers::NONE));
    let mut term = Terminal::new(TestBackend::new(80, 24)).unwrap();
    let app = tui::drive(&mut term, s, o, || Ok(keys.next())).unwrap();
    let buf = term.backend().buffer();
    let rows: Vec<String> = (0..24).map(|y| (0..80).map(|x| buf[(x, y)].symbol().to_string()).collect()).collect();
    (rows.join("\n"), app)
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
