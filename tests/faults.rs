//! Faults and errors are values with locations, never panics; the device stays usable.

#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use warplight::sim::texture::{AddressMode, FilterMode, ReadMode, SurfaceDesc, TexelFormat, TextureDesc};
use warplight::sim::{Arg, FaultKind, LaunchConfig, SimConfig, SimError};

fn fault_of(r: Result<warplight::sim::LaunchStats, SimError>) -> Box<warplight::sim::Fault> {
    match r {
        Err(SimError::Fault(f)) => f,
        other => panic!("expected a fault, got {other:?}"),
    }
}

#[test]
fn out_of_bounds_store_names_thread_and_lines() {
    for d in BOTH {
        let mut dev = device(2);
        let m = load(&mut dev, "memory", d);
        let out = dev.alloc_zeroed::<i32>(40);
        let f = fault_of(dev.launch(&m, "out_of_bounds", LaunchConfig::linear(2, 32), &[Arg::Ptr(out)]));
        assert!(matches!(f.kind, FaultKind::OutOfBounds { size: 4, .. }), "{d:?}: {f}");
        assert_eq!((f.cta, f.warp, f.lane), ([1, 0, 0], 0, Some(5)), "{d:?}: thread 37 = CTA 1 lane 5");
        let (file, line) = f.source.clone().expect("source line from .loc");
        assert!(file.ends_with("memory.cu"));
        assert_eq!(line, cu_line("memory", "out[t == 37 ? 4000 : t] = t;"));
        assert!(f.ptx_text.contains("st.global"), "{}", f.ptx_text);
        let msg = f.to_string();
        assert!(msg.contains("out-of-bounds") && msg.contains("lane 5"), "{msg}");
        // Threads of CTA 0 wrote before the fault: no lost output.
        assert_eq!(dev.read::<i32>(out, 32), (0..32).collect::<Vec<_>>());
        // The device remains usable.
        let ok = dev.launch(&m, "partial_warp", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]);
        assert!(ok.is_ok());
    }
}

#[test]
fn barrier_in_divergent_code_is_a_fault() {
    for d in BOTH {
        let mut dev = device(1);
        let m = load(&mut dev, "shared", d);
        let out = dev.alloc_zeroed::<i32>(64);
        let f = fault_of(dev.launch(&m, "divergent_barrier", LaunchConfig::linear(1, 64), &[Arg::Ptr(out)]));
        match f.kind {
            FaultKind::DivergentBarrier { active, live } => {
                assert_eq!((active, live), (0xFF, u32::MAX), "{d:?}");
            }
            k => panic!("{d:?}: {k}"),
        }
        assert_eq!(f.warp, 0);
    }
}

#[test]
fn runaway_kernel_stops_at_budget() {
    let mut cfg = SimConfig { threads: 1, ..SimConfig::default() };
    cfg.schedule.max_warp_instructions = 50_000;
    cfg.schedule.round_quantum = 1000;
    let mut dev = warplight::sim::Device::with_config(cfg);
    let m = load(&mut dev, "divergence", Dialect::Clang);
    let flag = dev.alloc_zeroed::<i32>(1);
    let f = fault_of(dev.launch(&m, "spin", LaunchConfig::linear(1, 32), &[Arg::Ptr(flag)]));
    assert!(matches!(f.kind, FaultKind::Runaway { budget: 50_000, .. }), "{f}");
}

#[test]
fn launch_errors_are_clear() {
    let mut dev = device(1);
    let m = load(&mut dev, "memory", Dialect::Clang);
    let out = dev.alloc_zeroed::<i32>(4);
    let e = dev.launch(&m, "nope", LaunchConfig::linear(1, 32), &[]).unwrap_err();
    assert!(matches!(e, SimError::UnknownKernel { .. }));
    assert!(e.to_string().contains("partial_warp"), "lists kernels: {e}");
    let e = dev.launch(&m, "partial_warp", LaunchConfig::linear(1, 32), &[]).unwrap_err();
    assert!(matches!(e, SimError::ArgCount { expected: 1, got: 0, .. }), "{e}");
    let e = dev.launch(&m, "partial_warp", LaunchConfig::linear(1, 32), &[Arg::U32(1)]).unwrap_err();
    assert!(matches!(e, SimError::ArgSize { expected: 8, got: 4, .. }), "{e}");
    let e = dev.launch(&m, "partial_warp", LaunchConfig::linear(1, 2048), &[Arg::Ptr(out)]).unwrap_err();
    assert!(matches!(e, SimError::BadLaunch(_)), "{e}");
    let e = dev.launch(&m, "partial_warp", LaunchConfig::linear(0, 32), &[Arg::Ptr(out)]).unwrap_err();
    assert!(matches!(e, SimError::BadLaunch(_)), "{e}");
}

#[test]
fn ptx_errors_name_file_line_and_instruction() {
    let src = ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n .reg .b32 %r<3>;\n tex.a2d.v4.f32.f32 %r1, [t, {%r1, %r2}];\n ret;\n}\n";
    let e = warplight::ptx::load(src, "bad.ptx").unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("bad.ptx:7:2: unsupported instruction `tex.a2d.v4.f32.f32`"), "{msg}");
    assert!(msg.contains("tex.a2d.v4.f32.f32 %r1"), "shows the line: {msg}");

    let src =
        ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n add.s32 %r1, %r2, 1;\n ret;\n}\n";
    let e = warplight::ptx::load(src, "undeclared.ptx").unwrap_err();
    assert_eq!((e.pos.line, e.pos.col), (6, 2));
    assert!(e.to_string().contains("undeclared register `%r2`"), "{e}");

    let src = ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n bra.uni NOWHERE;\n}\n";
    let e = warplight::ptx::load(src, "label.ptx").unwrap_err();
    assert!(e.to_string().contains("undefined label `NOWHERE`"), "{e}");
}

#[test]
fn misaligned_access_is_a_fault() {
    let src = r#".version 7.8
.target sm_90
.address_size 64
.visible .entry k(.param .u64 p)
{
  .reg .b32 %r<2>;
  .reg .b64 %rd<3>;
  ld.param.u64 %rd1, [p];
  add.s64 %rd2, %rd1, 2;
  ld.global.u32 %r1, [%rd2];
  ret;
}
"#;
    let mut dev = device(1);
    let m = dev.load_ptx(src, "mis.ptx").unwrap();
    let b = dev.alloc_zeroed::<u32>(8);
    let f = fault_of(dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(b)]));
    assert!(matches!(f.kind, FaultKind::Misaligned { size: 4, .. }), "{f}");
    assert_eq!(f.ptx_line, 10);
    assert_eq!(f.lane, Some(0));
}

#[test]
fn barrier_deadlock_is_reported() {
    // Warp 0 waits at barrier 1, warp 1 at barrier 2: neither can complete.
    let src = r#".version 7.8
.target sm_90
.address_size 64
.visible .entry k()
{
  .reg .b32 %r<3>;
  .reg .pred %p<2>;
  mov.u32 %r1, %tid.x;
  setp.lt.u32 %p1, %r1, 32;
  @%p1 bra A;
  bar.sync 2;
  bra.uni END;
A:
  bar.sync 1;
END:
  ret;
}
"#;
    let mut dev = device(1);
    let m = dev.load_ptx(src, "dl.ptx").unwrap();
    let f = fault_of(dev.launch(&m, "k", LaunchConfig::linear(1, 64), &[]));
    assert!(matches!(&f.kind, FaultKind::BarrierDeadlock { waiting } if waiting.len() == 2), "{f}");
}

#[test]
fn recursion_past_the_local_limit_overflows() {
    let src = r#".version 7.8
.target sm_90
.address_size 64
.func f()
{
  .local .align 8 .b8 depot[256];
  call.uni f, ();
  ret;
}
.visible .entry k()
{
  call.uni f, ();
  ret;
}
"#;
    let mut cfg = SimConfig { threads: 1, ..SimConfig::default() };
    cfg.local_limit = 4096;
    let mut dev = warplight::sim::Device::with_config(cfg);
    let m = dev.load_ptx(src, "rec.ptx").unwrap();
    let f = fault_of(dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[]));
    assert!(matches!(f.kind, FaultKind::LocalStackOverflow { limit: 4096, .. }), "{f}");
}

/// `f(a) = a + 1` called through a function-pointer table with the call
/// site's return declaration `RET` and prototype `PROTO`.
const INDIRECT: &str = ".version 7.8\n.target sm_90\n.address_size 64\n\
    .func (.param .b32 r) f(.param .b32 a)\n{\n.reg .b32 %r<3>;\nld.param.b32 %r1, [a];\nadd.s32 %r2, %r1, 1;\n\
    st.param.b32 [r], %r2;\nret;\n}\n\
    .global .align 8 .u64 tab[1] = {f};\n\
    .visible .entry k(.param .u64 out)\n{\n.reg .b64 %rd<4>;\n.reg .b32 %r<2>;\n\
    ld.param.u64 %rd2, [out];\ncvta.to.global.u64 %rd3, %rd2;\nmov.u64 %rd2, tab;\nld.global.u64 %rd1, [%rd2];\nmov.b32 %r1, 0;\n\
    {\n.param .b32 param0;\nst.param.b32 [param0], 41;\nRET\nprototype_0 : .callprototype PROTO;\nCALL\n}\n\
    st.global.b32 [%rd3], %r1;\nret;\n}\n";

/// `out[0]` after the launch, or its error.
fn indirect(ret: &str, proto: &str, call: &str) -> (Result<warplight::sim::LaunchStats, SimError>, u32) {
    let src = INDIRECT.replace("RET", ret).replace("PROTO", proto).replace("CALL", call);
    let mut dev = warplight::sim::Device::new();
    let m = dev.load_ptx(&src, "indirect.ptx").unwrap_or_else(|e| panic!("{e}"));
    let out = dev.alloc_zeroed::<u32>(1);
    let r = dev.launch(&m, "k", LaunchConfig::linear(1, 1), &[Arg::Ptr(out)]);
    (r, dev.read::<u32>(out, 1)[0])
}

/// An indirect call whose call site declares other return values than the
/// called function returns (count or size) faults; copying back what fits
/// left the rest of a 64-bit value unset, or nothing at all.
#[test]
fn indirect_calls_check_the_return_values() {
    let call = "call (retval0), %rd1, (param0), prototype_0;\nld.param.b32 %r1, [retval0];";
    let (ok, v) = indirect(".param .b32 retval0;", "(.param .b32 _) _ (.param .b32 _)", call);
    ok.unwrap();
    assert_eq!(v, 42);
    let (wide, _) = indirect(".param .b64 retval0;", "(.param .b64 _) _ (.param .b32 _)", call);
    let f = fault_of(wide);
    assert_eq!(f.lane, Some(0));
    let FaultKind::Unsupported(msg) = &f.kind else { panic!("{f}") };
    assert!(msg.contains("expecting 1 return value(s) [8-byte]; it returns 1 [4-byte]"), "{msg}");
    let (none, _) = indirect("", "_ (.param .b32 _)", "call %rd1, (param0), prototype_0;");
    let f = fault_of(none);
    let FaultKind::Unsupported(msg) = &f.kind else { panic!("{f}") };
    assert!(msg.contains("`f` expecting 0 return value(s) []; it returns 1 [4-byte]"), "{msg}");
}

fn surface(elem_bytes: u32, dims: [u32; 3], row_pitch: u64, data: warplight::sim::DevicePtr) -> SurfaceDesc {
    SurfaceDesc { data, elem_bytes, dims, row_pitch }
}

/// Texture and surface descriptors are checked when created: the channel
/// count, the element size, and the extent within one allocation.
#[test]
fn bad_texture_and_surface_descriptors_are_errors() {
    let mut dev = warplight::sim::Device::new();
    let data = dev.alloc_zeroed::<u32>(12); // 48 bytes
    let tex = |channels: u32, dims: [u32; 3], row_pitch: u64| TextureDesc {
        data,
        format: TexelFormat::F32,
        channels,
        dims,
        row_pitch,
        linear: false,
        addr: [AddressMode::Clamp; 3],
        filter: FilterMode::Point,
        read: ReadMode::ElementType,
        normalized: false,
    };
    let bad = |r: Result<u64, SimError>| match r {
        Err(e @ SimError::BadObject { .. }) => e.to_string(),
        other => panic!("expected a bad object, got {other:?}"),
    };
    // 12 one-channel texels fill it: 4 × 3, or 2 two-channel texels a row with a 16-byte pitch (16·2 + 16)
    assert!(dev.create_texture(tex(1, [4, 3, 0], 0)).is_ok());
    assert!(dev.create_texture(tex(2, [2, 2, 0], 32)).is_ok());
    assert!(dev.create_texture(tex(4, [3, 0, 0], 0)).is_ok());
    assert!(bad(dev.create_texture(tex(3, [2, 2, 0], 0))).contains("3 channels (1, 2 or 4)"));
    let e = bad(dev.create_texture(tex(1, [4, 4, 0], 0)));
    assert!(e.starts_with("bad texture object: its 64 bytes from") && e.contains("not within one allocation"), "{e}");
    let e = bad(dev.create_texture(tex(2, [2, 2, 0], 8)));
    assert!(e.contains("row pitch 8 is shorter than a row (16 bytes)"), "{e}");
    // one slice past: 2 × 2 × 4 texels of 4 bytes are 64
    assert!(bad(dev.create_texture(tex(1, [2, 2, 4], 0))).contains("its 64 bytes"));
    assert!(dev.create_surface(surface(4, [4, 3, 0], 0, data)).is_ok());
    assert!(bad(dev.create_surface(surface(0, [4, 3, 0], 0, data))).contains("elements of 0 bytes"));
    assert!(bad(dev.create_surface(surface(4, [4, 3, 2], 0, data))).contains("its 96 bytes"));
    let e = bad(dev.create_surface(surface(4, [1, 1, 0], 0, warplight::sim::DevicePtr(data.0 + 48))));
    assert!(e.starts_with("bad surface object: its 4 bytes from"), "{e}");
}

/// A `.clamp` surface access wider than a row fits at no position: a fault
/// (`clamp` with reversed bounds panicked); `.zero` reads zeros.
#[test]
fn surface_accesses_wider_than_a_row_fault_under_clamp() {
    let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry k(.param .u64 h, .param .u64 out)\n{\n.reg .b64 %rd<4>;\n.reg .b32 %r<3>;\n\
        ld.param.u64 %rd1, [h];\nld.param.u64 %rd2, [out];\ncvta.to.global.u64 %rd3, %rd2;\nmov.b32 %r1, 5;\nmov.b32 %r2, 5;\n\
        suld.b.2d.v2.b32.MODE {%r1, %r2}, [%rd1, {%r1, %r2}];\nst.global.v2.b32 [%rd3], {%r1, %r2};\nret;\n}\n";
    for mode in ["clamp", "zero"] {
        let mut dev = warplight::sim::Device::new();
        let m = dev.load_ptx(&src.replace("MODE", mode), "narrow.ptx").unwrap_or_else(|e| panic!("{e}"));
        let data = dev.alloc_from(&[7u32, 7]);
        // rows of one 4-byte element; the access is 8 bytes
        let h = dev.create_surface(surface(4, [1, 2, 0], 0, data)).unwrap();
        let out = dev.alloc_from(&[9u32, 9]);
        let r = dev.launch(&m, "k", LaunchConfig::linear(1, 1), &[Arg::U64(h), Arg::Ptr(out)]);
        if mode == "zero" {
            r.unwrap();
            assert_eq!(dev.read::<u32>(out, 2), vec![0, 0]);
            continue;
        }
        let f = fault_of(r);
        let FaultKind::Unsupported(msg) = &f.kind else { panic!("{f}") };
        assert!(msg.contains("8-byte surface access is wider than a row (4 bytes) with .clamp"), "{msg}");
    }
}
