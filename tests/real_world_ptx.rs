//! PTX forms that nvcc emits for ordinary kernels (issue 20): the predefined
//! constant `WARP_SZ`, and 32-bit register addresses that wrap at 2^32 before
//! the offset is added (`[%r4+68]` with %r4 = 0xFFFFFFC0 is offset 4).

use warplight::sim::{Arg, Device, LaunchConfig};

fn run(body: &str, out_words: usize) -> Vec<u32> {
    let ptx =
        format!(".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k(.param .u64 out)\n{{\n{body}\n}}\n");
    let mut dev = Device::new();
    let m = dev.load_ptx(&ptx, "k.ptx").unwrap_or_else(|e| panic!("{e}"));
    let out = dev.alloc_zeroed::<u32>(out_words);
    dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap_or_else(|e| panic!("{e}"));
    dev.read::<u32>(out, out_words)
}

#[test]
fn warp_sz_is_32() {
    let out = run(
        ".reg .b32 %r<2>;\n.reg .b64 %rd<2>;\nld.param.u64 %rd1, [out];\nmov.u32 %r1, WARP_SZ;\nst.global.u32 [%rd1], %r1;\nret;",
        1,
    );
    assert_eq!(out, [32]);
}

#[test]
fn a_32_bit_base_wraps_before_the_offset_is_added() {
    // shared: store 7 at [%r4+68] with %r4 = 0xFFFFFFC0 (offset 4), read it back at [s+4]
    let out = run(
        ".shared .align 4 .b8 s[128];\n.reg .b32 %r<6>;\n.reg .b64 %rd<2>;\n\
         ld.param.u64 %rd1, [out];\nmov.u32 %r1, s;\nadd.u32 %r4, %r1, -64;\nmov.u32 %r2, 7;\n\
         st.shared.u32 [%r4+68], %r2;\nld.shared.u32 %r3, [s+4];\nst.global.u32 [%rd1], %r3;\nret;",
        1,
    );
    assert_eq!(out, [7], "the store must land at offset 4 of s");
}

#[test]
fn a_64_bit_base_does_not_wrap() {
    // the same arithmetic in 64 bits stays an ordinary 64-bit address: out + 4
    let out = run(
        ".reg .b32 %r<2>;\n.reg .b64 %rd<4>;\nld.param.u64 %rd1, [out];\nadd.u64 %rd2, %rd1, -64;\n\
         mov.u32 %r1, 9;\nst.global.u32 [%rd2+68], %r1;\nret;",
        2,
    );
    assert_eq!(out, [0, 9]);
}

/// A spec passes `buffer + offset` as a pointer argument (`"out+8"`, `{ buffer = "out", offset = 8 }`).
#[test]
fn a_spec_passes_an_address_inside_a_buffer() {
    let dir = std::env::temp_dir().join(format!("warplight-offset-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("k.ptx"),
        ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k(.param .u64 out)\n{\n.reg .b32 %r<2>;\n.reg .b64 %rd<2>;\nld.param.u64 %rd1, [out];\nmov.u32 %r1, 5;\nst.global.u32 [%rd1], %r1;\nret;\n}\n",
    )
    .unwrap();
    let spec = |arg: &str| {
        format!(
            "ptx = \"k.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 1\nargs = [{arg}]\n[[buffer]]\nname = \"out\"\ntype = \"u32\"\nlen = 4\n"
        )
    };
    for (i, arg) in ["\"out+8\"", "{ buffer = \"out\", offset = 8 }"].iter().enumerate() {
        let file = dir.join(format!("s{i}.toml"));
        std::fs::write(&file, spec(arg)).unwrap();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
            .args(["launch", file.to_str().unwrap(), "--dump", &format!("out={}", dir.join("o.bin").display())])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let words: Vec<u32> = std::fs::read(dir.join("o.bin"))
            .unwrap()
            .chunks(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(words, [0, 0, 5, 0], "{arg}");
    }
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, spec("\"out+32\"")).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["launch", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("offset 32 is past the end of `out` (16 bytes)"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A spec fills `__constant__` memory (`[[constant]]`, as cudaMemcpyToSymbol does).
#[test]
fn a_spec_initialises_constant_memory() {
    let dir = std::env::temp_dir().join(format!("warplight-const-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("k.ptx"),
        ".version 7.8\n.target sm_90\n.address_size 64\n.const .align 4 .b8 taps[16];\n.visible .entry k(.param .u64 out)\n{\n.reg .b32 %r<2>;\n.reg .b64 %rd<2>;\nld.param.u64 %rd1, [out];\nld.const.u32 %r1, [taps+8];\nst.global.u32 [%rd1], %r1;\nret;\n}\n",
    )
    .unwrap();
    let spec = |c: &str| {
        format!(
            "ptx = \"k.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 1\nargs = [\"out\"]\n[[buffer]]\nname = \"out\"\ntype = \"u32\"\nlen = 1\n{c}"
        )
    };
    let launch = |file: &std::path::Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
            .args(["launch", file.to_str().unwrap(), "--dump", &format!("out={}", dir.join("o.bin").display())])
            .output()
            .unwrap()
    };
    let f = dir.join("s.toml");
    std::fs::write(&f, spec("[[constant]]\nname = \"taps\"\ntype = \"u32\"\nlen = 4\ninit = [1, 2, 3, 4]\n")).unwrap();
    let o = launch(&f);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(dir.join("o.bin")).unwrap(), 3u32.to_le_bytes());
    // a name the module lacks, and more bytes than the variable holds
    std::fs::write(&f, spec("[[constant]]\nname = \"tap\"\ntype = \"u32\"\nlen = 1\n")).unwrap();
    let e = String::from_utf8_lossy(&launch(&f).stderr).into_owned();
    assert!(e.contains("constant[0]") && e.contains("no __constant__ `tap` (it has: taps)"), "{e}");
    std::fs::write(&f, spec("[[constant]]\nname = \"taps\"\ntype = \"u32\"\nlen = 5\n")).unwrap();
    let e = String::from_utf8_lossy(&launch(&f).stderr).into_owned();
    assert!(e.contains("20 bytes do not fit `taps` (16 bytes)"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
