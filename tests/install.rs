//! `cargo install --path . --root DIR` gives a `warplight` that works from
//! any directory: examples found through the checkout it was built from,
//! file errors that name the file.
//!
//! Installing builds the release binary (in this checkout's `target/`, so it
//! is quick after `cargo test --release`, which built the same binary), so
//! the test runs only when CI asks for it (`WARPLIGHT_REQUIRE_EXTERNAL=1`, as
//! `.ci/run` sets, or `WARPLIGHT_TEST_INSTALL=1`) and otherwise prints
//! `skipped: …`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn asked(var: &str) -> bool {
    std::env::var(var).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// `bin ARGS` in `dir` with a clean environment for warplight: (success, stdout, stderr).
fn run(bin: &Path, args: &[&str], dir: &Path) -> (bool, String, String) {
    let o = Command::new(bin)
        .args(args)
        .current_dir(dir)
        .env_remove("WARPLIGHT_HOME")
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", bin.display()));
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn cargo_install_gives_a_binary_that_works_outside_the_checkout() {
    if !asked("WARPLIGHT_REQUIRE_EXTERNAL") && !asked("WARPLIGHT_TEST_INSTALL") {
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "skipped: cargo_install_gives_a_binary_that_works_outside_the_checkout runs `cargo install` \
             (set WARPLIGHT_TEST_INSTALL=1; CI sets WARPLIGHT_REQUIRE_EXTERNAL=1)"
        );
        return;
    }
    let checkout = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = std::env::temp_dir().join(format!("warplight-install-test-{}", std::process::id()));
    let outside = root.join("elsewhere");
    std::fs::create_dir_all(&outside).unwrap();
    let cargo = std::env::var_os("CARGO").map(PathBuf::from).unwrap_or_else(|| "cargo".into());
    let o = Command::new(cargo)
        .args(["install", "--locked", "--offline", "--path"])
        .arg(checkout)
        .arg("--root")
        .arg(&root)
        .env("CARGO_TARGET_DIR", checkout.join("target"))
        .output()
        .unwrap();
    assert!(o.status.success(), "cargo install failed:\n{}", String::from_utf8_lossy(&o.stderr));
    let bin = root.join("bin/warplight");
    assert!(bin.is_file(), "{} was not installed", bin.display());

    let (ok, out, err) = run(&bin, &["--version"], &outside);
    assert!(ok && out.starts_with("warplight "), "{err}{out}");
    // the README's examples, named as in the README, from a directory without them
    let (ok, out, err) = run(&bin, &["step", "examples/if_else.toml", "--log", "--max-steps", "3"], &outside);
    assert!(ok && out.contains("if_else"), "{err}{out}");
    // file errors name the file
    let (ok, _, err) = run(&bin, &["step", "no_such_spec.toml", "--log"], &outside);
    assert!(!ok && err.contains("no_such_spec.toml"), "{err}");
    let (ok, _, err) = run(&bin, &["compile", "no_such_kernel.cu"], &outside);
    assert!(!ok && err.contains("no_such_kernel.cu: no such file"), "{err}");
    std::fs::remove_dir_all(&root).ok();
}
