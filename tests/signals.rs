//! SIGTERM and SIGINT to a running `warplight` (issue 17, item 7): the process
//! exits with the shell's status (143, 130) and leaves neither a temporary
//! file nor a partial output, whether the signal comes while the kernel runs
//! or while the output is being written.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("warplight-signals-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A spec running `kernel` of a module with an endless loop (`spin`) and an
/// empty kernel (`empty`), with a u32 buffer `buf` of `len` elements.
fn spec(dir: &Path, kernel: &str, len: u64) -> PathBuf {
    let ptx = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry spin()\n{\n .reg .b32 %r<3>;\n .reg .pred %p<2>;\n mov.u32 %r1, 0;\nL:\n\
         add.s32 %r1, %r1, 1;\n setp.ne.s32 %p1, %r1, 0;\n @%p1 bra L;\n ret;\n}\n\
        .visible .entry empty()\n{\n ret;\n}\n";
    std::fs::write(dir.join("k.ptx"), ptx).unwrap();
    let s = format!(
        "ptx = \"k.ptx\"\nkernel = \"{kernel}\"\ngrid = 1\nblock = 32\n\n\
         [[buffer]]\nname = \"buf\"\ntype = \"u32\"\nlen = {len}\ninit = \"iota\"\n"
    );
    let p = dir.join(format!("{kernel}.toml"));
    std::fs::write(&p, s).unwrap();
    p
}

fn launch_dumping(spec: &Path, out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["launch", &spec.display().to_string(), "--dump", &format!("buf={}", out.display())])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

fn kill(sig: &str, pid: u32) {
    let ok = Command::new("kill").args([sig, &pid.to_string()]).status().unwrap().success();
    assert!(ok, "kill {sig} {pid}");
}

/// Waits (at most 10 s) until every thread of process `pid` is stopped (state
/// `T` in `/proc/PID/task/*/stat`) or the process has ended.
fn wait_stopped(pid: u32) {
    let t0 = Instant::now();
    let state = |stat: &str| stat.rsplit_once(')').and_then(|(_, r)| r.trim_start().chars().next());
    while t0.elapsed() < Duration::from_secs(10) {
        let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else { return };
        let all = tasks.flatten().all(|t| {
            let stat = std::fs::read_to_string(t.path().join("stat")).unwrap_or_default();
            matches!(state(&stat), Some('T' | 't' | 'Z' | 'X') | None)
        });
        if all {
            return;
        }
        std::thread::yield_now();
    }
}

/// Waits at most 30 s for `child`'s exit code (None: killed by a signal).
fn wait(child: &mut Child) -> Option<i32> {
    let t0 = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.code();
        }
        if t0.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            panic!("warplight did not exit after the signal");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The names in `dir` other than the spec and the PTX.
fn left_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml") && n != "k.ptx")
        .collect();
    names.sort();
    names
}

#[test]
fn a_signal_while_the_kernel_runs_exits_with_the_shells_status_and_writes_nothing() {
    for (sig, status) in [("-TERM", 143), ("-INT", 130)] {
        let d = tempdir(&sig[1..]);
        let out = d.join("out.bin");
        let mut child = launch_dumping(&spec(&d, "spin", 64), &out);
        // the kernel loops 2^32 times: it is still running when the signal comes
        std::thread::sleep(Duration::from_millis(500));
        kill(sig, child.id());
        assert_eq!(wait(&mut child), Some(status), "{sig}");
        assert_eq!(left_in(&d), Vec::<String>::new(), "{sig}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}

#[test]
fn a_signal_while_the_output_is_written_leaves_neither_it_nor_the_temporary_file() {
    let d = tempdir("write");
    let out = d.join("out.bin");
    let tmp = d.join(".out.bin.warplight-tmp");
    let spec = spec(&d, "empty", 16 << 20);
    // The process is stopped as soon as the temporary file of its 64 MiB dump
    // exists (while it is written), sent SIGTERM and continued. A try whose
    // stop came after the rename is repeated.
    for attempt in 0..8 {
        let _ = std::fs::remove_file(&out);
        let mut child = launch_dumping(&spec, &out);
        let t0 = Instant::now();
        while !tmp.exists() && child.try_wait().unwrap().is_none() && t0.elapsed() < Duration::from_secs(60) {}
        kill("-STOP", child.id());
        // kill returns before the stop takes effect: sample only once every thread is stopped
        wait_stopped(child.id());
        let caught = tmp.exists() && !out.exists();
        kill("-TERM", child.id());
        kill("-CONT", child.id());
        let code = wait(&mut child);
        assert!(!tmp.exists(), "the temporary file is left (attempt {attempt})");
        if caught {
            assert_eq!(code, Some(143));
            assert!(!out.exists(), "a partial dump is left");
            assert_eq!(left_in(&d), Vec::<String>::new());
            std::fs::remove_dir_all(&d).unwrap();
            return;
        }
        // the dump was complete before the signal: then it is whole
        let len = std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0);
        assert_eq!(len, 64 << 20, "attempt {attempt}: a partial dump (exit {code:?})");
    }
    panic!("the write was never caught in progress in 8 attempts");
}
