//! PTX forms that nvcc emits for ordinary kernels (issue 20): the predefined
//! constant `WARP_SZ`, 32-bit register addresses that wrap at 2^32 before
//! the offset is added (`[%r4+68]` with %r4 = 0xFFFFFFC0 is offset 4), and
//! modules where one kernel needs an instruction warplight does not execute
//! (only that kernel fails).

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

/// A module with a kernel that needs `sad` (not executed yet), a kernel
/// that reaches it through a device function, one that samples a layered texture,
/// and two ordinary kernels.
const MIXED: &str = "\
.version 7.8
.target sm_90
.address_size 64

.func (.param .b32 r) sum(.param .b32 a)
{
	.reg .b32 %r<3>;
	ld.param.b32 %r1, [a];
	sad.u32 %r2, %r1, %r1, %r1;
	st.param.b32 [r], %r2;
	ret;
}

.visible .entry good(.param .u64 out)
{
	.reg .b32 %r<2>;
	.reg .b64 %rd<4>;
	ld.param.u64 %rd1, [out];
	mov.u32 %r1, %tid.x;
	mul.wide.u32 %rd2, %r1, 4;
	add.s64 %rd3, %rd1, %rd2;
	st.global.u32 [%rd3], %r1;
	ret;
}

.visible .entry bad(.param .u64 out)
{
	.reg .b32 %r<3>;
	.reg .b64 %rd<2>;
	ld.param.u64 %rd1, [out];
	mov.u32 %r1, %tid.x;
	sad.u32 %r2, %r1, %r1, %r1;
	st.global.u32 [%rd1], %r2;
	ret;
}

.visible .entry calls_bad(.param .u64 out)
{
	.reg .b32 %r<3>;
	.reg .b64 %rd<2>;
	ld.param.u64 %rd1, [out];
	{
		.param .b32 a;
		st.param.b32 [a], 1;
		.param .b32 r;
		call.uni (r), sum, (a);
		ld.param.b32 %r2, [r];
	}
	st.global.u32 [%rd1], %r2;
	ret;
}

.visible .entry texture(.param .u64 t, .param .u64 out)
{
	.reg .f32 %f<5>;
	.reg .b64 %rd<3>;
	ld.param.u64 %rd1, [t];
	tex.a2d.v4.f32.f32 {%f1, %f2, %f3, %f4}, [%rd1, {%f1, %f1}];
	ret;
}

.visible .entry also_good(.param .u64 out)
{
	.reg .b32 %r<2>;
	.reg .b64 %rd<2>;
	ld.param.u64 %rd1, [out];
	mov.u32 %r1, 7;
	st.global.u32 [%rd1], %r1;
	ret;
}
";

/// One unsupported instruction fails only the kernels that need it (issue 20
/// item 1): the module loads, the other kernels run, and the unusable ones
/// carry the error naming file, line and instruction.
#[test]
fn an_unsupported_instruction_fails_only_its_kernels() {
    let mut dev = Device::new();
    let m = dev.load_ptx(MIXED, "mixed.ptx").unwrap_or_else(|e| panic!("the module must load: {e}"));
    let out = dev.alloc_zeroed::<u32>(32);
    dev.launch(&m, "good", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(dev.read::<u32>(out, 32), (0..32).collect::<Vec<u32>>());
    dev.launch(&m, "also_good", LaunchConfig::linear(1, 1), &[Arg::Ptr(out)]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(dev.read::<u32>(out, 1), [7]);

    let error = |k: &str| m.prog.kernel_error(m.prog.kernel(k).unwrap()).map(|e| e.to_string());
    assert_eq!(error("good"), None);
    assert_eq!(error("also_good"), None);
    let bad = error("bad").expect("`bad` is unusable");
    assert!(bad.starts_with("mixed.ptx:32:2: unsupported instruction `sad.u32`"), "{bad}");
    assert!(bad.contains("| sad.u32 %r2, %r1, %r1, %r1;"), "quotes the line: {bad}");
    // through the device function: the callee's instruction is named
    let calls = error("calls_bad").expect("`calls_bad` is unusable");
    assert!(calls.starts_with("mixed.ptx:9:2: unsupported instruction `sad.u32`"), "{calls}");
    let tex = error("texture").expect("`texture` is unusable");
    assert!(tex.starts_with("mixed.ptx:58:2: unsupported instruction `tex.a2d.v4.f32.f32`"), "{tex}");

    // launched anyway through the library, the launch is refused with the same error
    let e = dev.launch(&m, "bad", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap_err().to_string();
    assert!(e.contains("mixed.ptx:32:2: unsupported instruction `sad.u32`"), "{e}");
    let e = dev.launch(&m, "calls_bad", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap_err().to_string();
    assert!(e.contains("mixed.ptx:9:2: unsupported instruction `sad.u32`"), "{e}");
}

/// A module none of whose kernels can run still fails to load, with the first error.
#[test]
fn a_module_with_no_usable_kernel_fails_to_load() {
    let only_bad =
        MIXED.replace(".visible .entry good(", ".func good(").replace(".visible .entry also_good(", ".func also_good(");
    let e = warplight::ptx::load(&only_bad, "bad.ptx").unwrap_err().to_string();
    assert!(e.starts_with("bad.ptx:9:2: unsupported instruction `sad.u32`"), "{e}");
}

/// `check` reports every unusable kernel and fails, `kernels` marks them, and
/// `launch` runs the good kernel and refuses the bad one with the error.
#[test]
fn the_command_line_names_unusable_kernels() {
    let dir = std::env::temp_dir().join(format!("warplight-unusable-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = dir.join("mixed.ptx");
    std::fs::write(&ptx, MIXED).unwrap();
    let warplight = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_warplight")).args(args).output().unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let p = ptx.to_str().unwrap();
    let (ok, _, err) = warplight(&["check", p]);
    assert!(!ok && err.contains("3 of 5 kernels cannot run"), "{err}");
    assert!(
        err.contains("kernel `bad`: ") && err.contains("mixed.ptx:32:2: unsupported instruction `sad.u32`"),
        "{err}"
    );
    let calls = err.lines().find(|l| l.starts_with("kernel `calls_bad`")).unwrap_or_default();
    assert!(calls.contains("(through `sum`, which it calls): ") && calls.contains("mixed.ptx:9:2: "), "{err}");
    assert!(err.contains("kernel `texture`: "), "{err}");
    assert!(!err.contains("kernel `good`"), "{err}");

    let (ok, out, err) = warplight(&["kernels", p]);
    assert!(ok, "{err}");
    // the line after a kernel's signature
    let next = |k: &str| {
        let lines: Vec<&str> = out.lines().collect();
        let i = lines.iter().position(|l| l.starts_with(&format!("  {k}("))).unwrap_or_else(|| panic!("{out}"));
        lines[i + 1].to_string()
    };
    assert!(
        next("bad").contains("unusable: ") && next("bad").contains(":32:2: unsupported instruction `sad.u32`"),
        "{out}"
    );
    assert!(next("good").contains("instructions") && next("also_good").contains("instructions"), "{out}");

    let spec = |k: &str| {
        format!(
            "ptx = \"mixed.ptx\"\nkernel = \"{k}\"\ngrid = 1\nblock = 32\nargs = [\"out\"]\n[[buffer]]\nname = \"out\"\ntype = \"u32\"\nlen = 32\n"
        )
    };
    for (k, runs) in [("good", true), ("bad", false), ("calls_bad", false)] {
        let f = dir.join(format!("{k}.toml"));
        std::fs::write(&f, spec(k)).unwrap();
        let (ok, _, err) = warplight(&["launch", f.to_str().unwrap()]);
        assert_eq!(ok, runs, "{k}: {err}");
        if !runs {
            assert!(err.contains("unsupported instruction `sad.u32`") && err.contains("mixed.ptx:"), "{k}: {err}");
        }
    }
    // stepping and tracing it fail the same way
    let bad = dir.join("bad.toml");
    let html = dir.join("t.html");
    for args in [
        vec!["step", bad.to_str().unwrap(), "--log"],
        vec!["trace", bad.to_str().unwrap(), "-o", html.to_str().unwrap()],
    ] {
        let (ok, _, err) = warplight(&args);
        assert!(!ok && err.contains(":32:2: unsupported instruction `sad.u32`"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `%globaltimer` (and its low half) reads a deterministic count like
/// `%clock64`: increasing within a run, equal between runs.
#[test]
fn globaltimer_is_deterministic_and_increasing() {
    let body = ".reg .b32 %r<2>;\n.reg .b64 %rd<4>;\nld.param.u64 %rd1, [out];\nmov.u64 %rd2, %globaltimer;\n\
                mov.u32 %r1, %globaltimer_lo;\nmov.u64 %rd3, %globaltimer;\nst.global.u64 [%rd1], %rd2;\n\
                st.global.u32 [%rd1+8], %r1;\nst.global.u64 [%rd1+16], %rd3;\nret;";
    let a = run(body, 6);
    let (t0, t1, t2) = (a[0] as u64 | (a[1] as u64) << 32, a[2] as u64, a[4] as u64 | (a[5] as u64) << 32);
    assert!(t0 < t1 && t1 < t2, "{t0} {t1} {t2}");
    assert_eq!(run(body, 6), a, "the same in a second run");
}

/// `popc`, `clz` and `brev` on 64-bit values (counts into 32-bit registers).
#[test]
fn bit_counts_of_64_bit_values() {
    let out = run(
        ".reg .b32 %r<4>;\n.reg .b64 %rd<5>;\nld.param.u64 %rd1, [out];\nmov.u64 %rd2, 0xF000000000000001;\n\
         popc.b64 %r1, %rd2;\nclz.b64 %r2, %rd2;\nmov.u64 %rd3, 1;\nclz.b64 %r3, %rd3;\nbrev.b64 %rd4, %rd3;\n\
         st.global.u32 [%rd1], %r1;\nst.global.u32 [%rd1+4], %r2;\nst.global.u32 [%rd1+8], %r3;\n\
         st.global.u64 [%rd1+16], %rd4;\nret;",
        6,
    );
    assert_eq!(out, [5, 0, 63, 0, 0, 0x8000_0000]);
}

/// Function pointers to an unusable function and to one naming shared
/// memory: `via_pointer` reaches `bad_fn` only through a register, `via_table`
/// through a table in global memory; `no_pointer` calls nothing indirectly.
const INDIRECT: &str = "
.version 7.8
.target sm_90
.address_size 64
.shared .align 4 .b8 big[4096];
.func (.param .b32 r) bad_fn(.param .b32 a)
{
	.reg .b32 %r<3>;
	ld.param.b32 %r1, [a];
	sad.u32 %r2, %r1, %r1, %r1;
	st.param.b32 [r], %r2;
	ret;
}
.func (.param .b32 r) shared_fn(.param .b32 a)
{
	.reg .b32 %r<3>;
	ld.param.b32 %r1, [a];
	st.shared.u32 [big], %r1;
	st.param.b32 [r], %r1;
	ret;
}
.global .align 8 .u64 table[1] = {shared_fn};
.visible .entry via_pointer(.param .u64 out)
{
	.reg .b32 %r<3>;
	.reg .b64 %rd<3>;
	mov.u64 %rd1, bad_fn;
	{
		.param .b32 a;
		st.param.b32 [a], 1;
		.param .b32 r;
		proto: .callprototype (.param .b32 _) _ (.param .b32 _);
		call (r), %rd1, (a), proto;
		ld.param.b32 %r2, [r];
	}
	ret;
}
.visible .entry via_table(.param .u64 out)
{
	.reg .b32 %r<3>;
	.reg .b64 %rd<3>;
	ld.global.u64 %rd1, [table];
	{
		.param .b32 a;
		st.param.b32 [a], 1;
		.param .b32 r;
		proto2: .callprototype (.param .b32 _) _ (.param .b32 _);
		call (r), %rd1, (a), proto2;
		ld.param.b32 %r2, [r];
	}
	ret;
}
.visible .entry no_pointer(.param .u64 out)
{
	ret;
}
";

/// An unusable function reached only through a function pointer makes every
/// kernel making an indirect call unusable (which function a register holds
/// is known at run time only), and a function reached that way counts for
/// the kernel's shared memory: conservative, never silently wrong.
#[test]
fn indirect_calls_reach_every_function_whose_address_is_taken() {
    let mut dev = Device::new();
    let m = dev.load_ptx(INDIRECT, "ind.ptx").unwrap_or_else(|e| panic!("{e}"));
    let k = |n: &str| m.prog.kernel(n).unwrap();
    let mut taken: Vec<&str> =
        m.prog.address_taken().iter().map(|&f| m.prog.functions[f as usize].name.as_str()).collect();
    taken.sort();
    assert_eq!(taken, ["bad_fn", "shared_fn"]);
    let e = m.prog.kernel_error(k("via_pointer")).expect("via_pointer reaches bad_fn").to_string();
    assert!(e.starts_with("ind.ptx:10:2: unsupported instruction `sad.u32`"), "{e}");
    // via_table may hold any taken function too
    assert!(m.prog.kernel_error(k("via_table")).is_some());
    assert!(m.prog.kernel_error(k("no_pointer")).is_none());
    assert_eq!(m.prog.kernel_shared_size(k("no_pointer")), 0);
    // without the unusable function: via_table runs, and its shared memory is shared_fn's
    let fine = INDIRECT.replace("sad.u32 %r2, %r1, %r1, %r1;", "add.u32 %r2, %r1, %r1;");
    let m = dev.load_ptx(&fine, "fine.ptx").unwrap();
    let kt = m.prog.kernel("via_table").unwrap();
    assert!(m.prog.kernel_error(kt).is_none());
    assert_eq!(m.prog.kernel_shared_size(kt), 4096);
    assert_eq!(m.prog.kernel_shared_size(m.prog.kernel("no_pointer").unwrap()), 0);
    let out = dev.alloc_zeroed::<u32>(1);
    dev.launch(&m, "via_table", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap();
}

/// A direct call passing an argument or taking a return value of another
/// size than the function declares is refused at load, naming file and line.
#[test]
fn direct_calls_with_mismatched_sizes_are_errors() {
    let src = |arg: &str, ret: &str| {
        format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n\
             .func (.param .b32 r) f(.param .b64 a)\n{{\n\t.reg .b64 %rd<2>;\n\tld.param.b64 %rd1, [a];\n\
             \tst.param.b32 [r], 1;\n\tret;\n}}\n\
             .visible .entry k()\n{{\n\t.reg .b32 %r<2>;\n\t{{\n\t\t.param {arg} a;\n\t\tst.param.b32 [a], 1;\n\
             \t\t.param {ret} r;\n\t\tcall.uni (r), f, (a);\n\t\tld.param.b32 %r1, [r];\n\t}}\n\tret;\n}}\n"
        )
    };
    warplight::ptx::load(&src(".b64", ".b32"), "call.ptx").unwrap_or_else(|e| panic!("{e}"));
    let e = warplight::ptx::load(&src(".b32", ".b32"), "call.ptx").unwrap_err().to_string();
    assert!(
        e.starts_with("call.ptx:18:3: invalid")
            && e.contains("argument 1 of the call of `f` has 4 byte(s); the function's has 8"),
        "{e}"
    );
    let e = warplight::ptx::load(&src(".b64", ".b64"), "call.ptx").unwrap_err().to_string();
    assert!(e.contains("call.ptx:18:3") && e.contains("return value 1 of the call of `f` has 8 byte(s)"), "{e}");
}
