//! The page of `warplight trace` in headless Chromium: it loads without
//! console messages or errors, its self-test steps through events with the
//! arrow keys (and shows the printf output up to the current instruction),
//! and a screenshot is taken. Needs Debian's `chromium` (`.ci/run`
//! installs it; WARPLIGHT_CHROMIUM names another binary); skips without it
//! unless WARPLIGHT_REQUIRE_EXTERNAL=1 (see `common::external`).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> Option<PathBuf> {
    let program = std::env::var("WARPLIGHT_CHROMIUM").unwrap_or_else(|_| "chromium".into());
    common::external(&program, "apt-get install chromium")
}

/// Runs headless Chromium on `url` with `extra` arguments; returns (stdout, stderr).
fn headless(chromium: &Path, dir: &Path, url: &str, extra: &[&str]) -> (String, String) {
    let profile = dir.join(format!("profile-{}", extra.len()));
    let o = Command::new("timeout")
        .arg("120")
        .arg(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("chromium runs");
    (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// `warplight trace ARGS -o PAGE` in the checkout; returns its stdout.
fn record(args: &[&str], page: &Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .arg("trace")
        .args(args)
        .arg("-o")
        .arg(page)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn console_lines(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.contains(":CONSOLE")).collect()
}

#[test]
fn trace_page_steps_in_headless_chromium() {
    let Some(chromium) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("warplight-trace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("if_else.html");
    record(&["examples/if_else.toml"], &page);
    let url = format!("file://{}#selftest=11", page.display());

    // The detector works: a page with a console message and an uncaught error is caught.
    let bad = dir.join("bad.html");
    std::fs::write(&bad, "<html><body><script>console.error('boom'); missing();</script></body></html>").unwrap();
    let (_, err) = headless(&chromium, &dir, &format!("file://{}", bad.display()), &["--dump-dom"]);
    assert_eq!(console_lines(&err).len(), 2, "{err}");

    // Load, step 11 events with the arrow key, read back what the page shows.
    let (dom, err) = headless(&chromium, &dir, &url, &["--dump-dom"]);
    assert!(console_lines(&err).is_empty(), "console output: {:?}", console_lines(&err));
    assert!(dom.contains("<div id=\"errors\"></div>"), "errors on the page: {dom}");
    assert!(
        dom.contains("selftest ok: event 12 shown, 32 mask cells, 1 memory diagram, 0 errors, op bra, fx diverged"),
        "{}",
        dom.lines().filter(|l| l.contains("selftest")).collect::<Vec<_>>().join("\n")
    );

    // A screenshot of the page after those steps.
    let shot = dir.join("trace.png");
    let (_, err) = headless(
        &chromium,
        &dir,
        &url,
        &["--hide-scrollbars", "--window-size=1280,900", &format!("--screenshot={}", shot.display())],
    );
    let img = image::open(&shot).unwrap_or_else(|e| panic!("no screenshot ({e}): {err}")).to_rgb8();
    assert_eq!(img.dimensions(), (1280, 900));
    let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 50, "the screenshot is nearly blank ({} colours)", colours.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_trace_of_128_warps_folds_and_loads_cleanly() {
    let Some(chromium) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("warplight-trace128-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // reduce_sum over 16 CTAs of 8 warps
    let spec = dir.join("wide.toml");
    std::fs::write(
        &spec,
        format!(
            "ptx = \"{}/kernels/tests/shared.ptx\"\nkernel = \"reduce_sum\"\ngrid = 16\nblock = 256\nargs = [\"sums\", \"input\"]\n\
             [[buffer]]\nname = \"input\"\ntype = \"i32\"\nlen = 4096\ninit = \"iota\"\n\
             [[buffer]]\nname = \"sums\"\ntype = \"i32\"\nlen = 16\n",
            env!("CARGO_MANIFEST_DIR")
        ),
    )
    .unwrap();
    let page = dir.join("wide.html");
    let out = record(&[spec.to_str().unwrap(), "--max-events", "100000"], &page);
    assert!(out.contains("128 warps"), "{out}");
    let url = format!("file://{}#selftest=40", page.display());
    let (dom, err) = headless(&chromium, &dir, &url, &["--dump-dom"]);
    assert!(console_lines(&err).is_empty(), "console output: {:?}", console_lines(&err));
    assert!(
        dom.contains("selftest ok"),
        "{}",
        dom.lines().filter(|l| l.contains("selftest")).collect::<Vec<_>>().join("\n")
    );
    // many warps start folded: 128 rows of 8 pixels, not 40
    assert!(dom.contains("id=\"fold\" type=\"checkbox\"") && dom.contains("height: 1028px"), "folded timeline");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_page_shows_printf_output_up_to_the_current_instruction() {
    let Some(chromium) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("warplight-trace-printf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("printf.html");
    record(&["tests/fixtures/printf/printf.toml", "--cta", "0"], &page);
    // the recorded instructions, as the page numbers them from 0: the first that printed
    let html = std::fs::read_to_string(&page).unwrap();
    let data = html.split("id=\"data\">").nth(1).unwrap().split("</script>").next().unwrap();
    let t: serde_json::Value = serde_json::from_str(data).unwrap();
    let events = t["events"].as_array().unwrap();
    let first = events.iter().position(|e| e.get("out").is_some()).unwrap();
    let selftest = |n: usize| {
        let (dom, err) = headless(&chromium, &dir, &format!("file://{}#selftest={n}", page.display()), &["--dump-dom"]);
        assert!(console_lines(&err).is_empty(), "console output: {:?}", console_lines(&err));
        dom.lines().find(|l| l.contains("selftest")).map(str::to_string).unwrap_or_default()
    };
    // before the call nothing; at it warp 0's 32 lines, highlighted; at the end all 41 of CTA 0
    let before = selftest(first - 1);
    assert!(before.contains("selftest ok") && before.contains(", 0 printf lines shown"), "{before}");
    let at = selftest(first);
    assert!(at.contains("selftest ok") && at.contains("32 printf lines shown, 32 of this step"), "{at}");
    let end = selftest(events.len());
    assert!(end.contains("selftest ok") && end.contains("41 printf lines shown, 0 of this step"), "{end}");
    let _ = std::fs::remove_dir_all(&dir);
}
