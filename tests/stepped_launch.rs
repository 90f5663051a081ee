//! The stepped launch of `step` and `trace`: it runs under the random warp
//! schedule when asked (the same interleaving as `launch --schedule random`
//! with that seed), its `printf` output is shown after the log, the view and
//! the trace, and `examples/…` specs are found from any directory.

use std::path::Path;
use std::process::Command;

use warplight::teach::session::Session;

/// Runs the stepped launch to its end; returns the buffer `name`'s i32 values.
fn step_to_end(spec: &str, seed: Option<u64>, name: &str) -> Vec<i32> {
    let mut s = Session::load(Path::new(spec)).unwrap_or_else(|e| panic!("{spec}: {e}"));
    s.random_seed = seed;
    s.with_stepper_and_buffers(|st, bufs| {
        while st.step()?.is_some() {}
        let (_, bytes) = bufs.read(name, 0, usize::MAX).expect("buffer");
        Ok(bytes.chunks_exact(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect())
    })
    .unwrap_or_else(|e| panic!("{spec}: {e}"))
}

/// `warplight ARGS` in `dir`: (success, stdout, stderr).
fn warplight(args: &[&str], dir: &Path) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_warplight")).args(args).current_dir(dir).output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn the_stepped_launch_follows_the_random_schedule_of_launch() {
    let spec = "tests/fixtures/sanitizer/planted_race_raw.toml";
    // lesson 5 without its barrier: the default schedule hides the race ...
    let truth: Vec<i32> = (0..2).map(|c| (0..256).map(|i| (256 * c + i) % 7).sum()).collect();
    assert_eq!(step_to_end(spec, None, "sums"), truth);
    // ... and stepping under a random schedule shows it, as `launch --schedule random` does
    let stepped: Vec<Vec<i32>> = (1..=4).map(|seed| step_to_end(spec, Some(seed), "sums")).collect();
    assert!(stepped.iter().any(|s| *s != truth), "some seed shows the race: {stepped:?}");
    for (seed, sums) in (1..=4).zip(&stepped) {
        let seed = seed.to_string();
        let (ok, out, err) =
            warplight(&["launch", spec, "--schedule", "random", "--seed", &seed, "--print", "sums"], Path::new("."));
        assert!(ok, "{err}");
        let printed = out.split("sums[0..2]:").nth(1).unwrap_or_else(|| panic!("{out}"));
        let values: Vec<i32> = printed.split_whitespace().filter_map(|w| w.parse().ok()).take(2).collect::<Vec<_>>();
        assert_eq!(&values, sums, "seed {seed}: the stepped launch and `launch` interleave alike\n{out}");
    }
    // the step log under a random schedule: another warp order than the default one
    let order = |extra: &[&str]| {
        let mut args = vec!["step", spec, "--trace", "--max-steps", "200"];
        args.extend_from_slice(extra);
        let (ok, out, err) = warplight(&args, Path::new("."));
        assert!(ok, "{err}");
        out
    };
    let random = order(&["--schedule", "random", "--seed", "3"]);
    assert_ne!(order(&[]), random);
    assert_eq!(order(&["--schedule", "random", "--seed", "3"]), random, "one seed, one interleaving");
}

#[test]
fn printf_output_follows_the_step_log_and_the_trace() {
    let dir = std::env::temp_dir().join(format!("warplight-stepped-printf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = std::fs::canonicalize("tests/fixtures/printf/printf.ptx").unwrap();
    let spec = format!(
        "ptx = {:?}\nkernel = \"printf_kernel\"\ngrid = 2\nblock = 40\nargs = [\"ret\"]\n\
         [[buffer]]\nname = \"ret\"\ntype = \"i32\"\nlen = 80\n",
        ptx.display().to_string()
    );
    std::fs::write(dir.join("p.toml"), spec).unwrap();
    // the whole launch, by CTA, warp, call, lane: warp 0's 32 lanes, its second call
    // (thread 0 after the barrier), then warp 1's 8 lanes
    let (ok, out, err) = warplight(&["step", "p.toml", "--log", "--max-steps", "100000"], &dir);
    assert!(ok, "{err}");
    let (_, printed) = out.split_once("printf output of `printf_kernel`").unwrap_or_else(|| panic!("{out}"));
    let lines: Vec<&str> = printed.lines().skip(1).collect();
    assert_eq!(lines.len(), 82, "{printed}");
    assert!(lines[0].starts_with("cta 0 t  0: d=-20 u=4294967276"), "{}", lines[0]);
    assert_eq!(lines[32], "cta 0 done");
    assert!(lines[33].starts_with("cta 0 t 32: "), "{}", lines[33]);
    assert!(lines[41].starts_with("cta 1 t  0: d=20 "), "{}", lines[41]);
    assert_eq!(lines[73], "cta 1 done");
    assert!(lines[81].starts_with("cta 1 t 39: "), "{}", lines[81]);
    // a log cut before the call prints nothing of it
    let (ok, out, err) = warplight(&["step", "p.toml", "--log", "--max-steps", "3"], &dir);
    assert!(ok && !out.contains("printf output"), "{err}{out}");
    // the trace: after the line naming the page
    let (ok, out, err) = warplight(&["trace", "p.toml", "-o", "p.html", "--cta", "0"], &dir);
    assert!(ok, "{err}");
    assert!(out.starts_with("wrote p.html") && out.contains("printf output of `printf_kernel`"), "{out}");
    assert_eq!(out.lines().filter(|l| l.ends_with(" done")).count(), 2, "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn example_specs_are_found_from_any_directory() {
    let elsewhere = std::env::temp_dir();
    let (ok, out, err) = warplight(&["step", "examples/if_else.toml", "--log", "--max-steps", "5"], &elsewhere);
    assert!(ok, "{err}");
    assert!(out.contains("if_else"), "{out}");
    let (ok, out, err) = warplight(&["trace", "examples/if_else.toml", "-o", "/dev/null/x.html"], &elsewhere);
    assert!(!ok && !err.contains("examples/if_else.toml: No such file"), "{err}{out}");
    // a name found nowhere is still named in the error
    let (ok, _, err) = warplight(&["step", "examples/nothing.toml", "--log"], &elsewhere);
    assert!(!ok && err.contains("examples/nothing.toml"), "{err}");
}
