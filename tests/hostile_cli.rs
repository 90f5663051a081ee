//! Careless input through the command line (issue 17): `warplight check`
//! refuses constant barrier operands a GPU cannot run, naming file and line;
//! `launch --csv` keeps the occupancy notice of a kernel with more registers
//! than a thread may have.

mod support;
use support::warplight_code;

use std::path::PathBuf;

const HEAD: &str = ".version 7.8\n.target sm_90\n.address_size 64\n";

fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("warplight-hostile-cli-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn check_refuses_constant_barrier_ids_and_counts_naming_the_line() {
    let d = tempdir("check");
    let cases = [
        ("bar.sync 16;", "barrier id 16 is out of range (a CTA has barriers 0 to 15)"),
        ("barrier.sync.aligned 31;", "barrier id 31 is out of range"),
        ("bar.sync 1, 33;", "a barrier thread count of 33: it must be a positive multiple of 32"),
        ("bar.sync 0, 4096;", "a barrier thread count of 4096"),
        ("bar.red.popc.u32 %r1, 0, 48, %p1;", "a barrier thread count of 48"),
    ];
    for (line, want) in cases {
        let ptx = d.join("k.ptx");
        let body = format!(
            ".visible .entry k()\n{{\n .reg .b32 %r<2>;\n .reg .pred %p<2>;\n setp.eq.u32 %p1, 0, 0;\n {line}\n ret;\n}}\n"
        );
        std::fs::write(&ptx, format!("{HEAD}{body}")).unwrap();
        let (code, out, err) = warplight_code(&["check", &ptx.display().to_string()]);
        assert_eq!(code, Some(1), "{line}: {out}{err}");
        assert!(err.contains("k.ptx:9:") && err.contains(want), "{line}: {err}");
    }
    // the same in registers, and the largest constant forms, pass: a launch checks the values
    let ok = ".visible .entry k()\n{\n .reg .b32 %r<3>;\n mov.u32 %r1, 16;\n mov.u32 %r2, 33;\n\
              bar.sync %r1, %r2;\n bar.sync 15, 1024;\n bar.sync 0, 32;\n ret;\n}\n";
    let ptx = d.join("ok.ptx");
    std::fs::write(&ptx, format!("{HEAD}{ok}")).unwrap();
    let (code, out, err) = warplight_code(&["check", &ptx.display().to_string()]);
    assert_eq!(code, Some(0), "{out}{err}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn the_occupancy_notice_of_a_clamped_register_count_reaches_csv() {
    let d = tempdir("csv");
    // 300 registers declared: hopper allows 255 per thread
    let ptx = format!("{HEAD}.visible .entry k()\n{{\n .reg .b32 %r<300>;\n ret;\n}}\n");
    std::fs::write(d.join("k.ptx"), ptx).unwrap();
    std::fs::write(d.join("k.toml"), "ptx = \"k.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\n").unwrap();
    let spec = d.join("k.toml").display().to_string();
    let (code, out, err) = warplight_code(&["launch", &spec, "--csv", "--device", "hopper"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains("0,k,occupancy.registers_per_thread,255\n"), "{out}");
    assert!(out.contains("0,k,occupancy.registers_declared,300\n"), "{out}");
    // every cell after the header stays a number
    for l in out.lines().skip(1) {
        assert!(l.rsplit(',').next().unwrap().parse::<f64>().is_ok(), "{l}");
    }
    assert!(err.contains("note: launch 0 (k): ") && err.contains("declares 300 registers per thread"), "{err}");
    // the terminal report says it too; a kernel within the limit has no note
    let (_, out, _) = warplight_code(&["launch", &spec, "--device", "hopper"]);
    assert!(out.contains("note: ") && out.contains("declares 300 registers per thread"), "{out}");
    let ptx = format!("{HEAD}.visible .entry k()\n{{\n .reg .b32 %r<30>;\n ret;\n}}\n");
    std::fs::write(d.join("k.ptx"), ptx).unwrap();
    let (code, out, err) = warplight_code(&["launch", &spec, "--csv", "--device", "hopper"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(!out.contains("registers_declared") && !err.contains("note:"), "{out}{err}");
    std::fs::remove_dir_all(&d).unwrap();
}
