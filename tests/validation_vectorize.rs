//! ptxas's vectorisation of shared accesses, its dropped repeated loads and
//! its reductions, as the hopper (and maxwell) counters count them
//! (`src/model/vectorize.rs`): hand-derived counts on small kernels, with the
//! pass on (the default) and off.

use warplight::model::uniform::{Uniformity, analyse};
use warplight::model::{MemCounters, Model, Profile};
use warplight::ptx::ir::{Function, PredId, PredSrc};
use warplight::sim::{Arg, Device, LaunchConfig};

fn counters(
    ptx: &str,
    kernel: &str,
    cfg: LaunchConfig,
    args: &dyn Fn(&mut Device) -> Vec<Arg>,
    vectorize: bool,
    profile: Profile,
) -> MemCounters {
    let mut dev = Device::new();
    let m = dev.load_ptx(ptx, "test.ptx").unwrap();
    let a = args(&mut dev);
    let model = Model::with_vectorize(profile, &m.prog, vectorize);
    dev.launch_observed(&m, kernel, cfg, &a, Some(&model)).unwrap();
    model.finish().counters
}

fn suite(dialect: &str) -> String {
    let p = if dialect == "nvcc" { "kernels/validation/suite.nvcc.ptx" } else { "kernels/validation/suite.ptx" };
    std::fs::read_to_string(p).unwrap()
}

/// (instructions, wavefronts, bank conflicts)
fn triple(c: &warplight::model::BankCounts) -> (u64, u64, u64) {
    (c.instructions, c.wavefronts, c.bank_conflicts)
}

#[test]
fn unrolled_tiled_matmul_reads_a_row_as_lds128() {
    // One 16 x 16 tile (n = 16), 8 warps; each warp holds rows ty, ty+1.
    // Per warp: As[ty][k..k+3] -> 4 LDS.128, each half-warp on one 16-byte
    // element: 2 wavefronts (paired lanes); Bs[k][tx] -> 16 LDS, lanes l and
    // l+16 on one word, 16 words in 16 banks: 1 wavefront. 20 loads, 24 wavefronts.
    // As written: 32 LDS of 1 wavefront (rows ty and ty+1 are 16 banks apart).
    let args = |d: &mut Device| {
        let a = d.alloc_from(&vec![1.0f32; 256]);
        let b = d.alloc_from(&vec![2.0f32; 256]);
        let c = d.alloc_zeroed::<f32>(256);
        vec![Arg::Ptr(a), Arg::Ptr(b), Arg::Ptr(c), Arg::I32(16)]
    };
    let cfg = LaunchConfig { grid: [1, 1, 1], block: [16, 16, 1], dynamic_shared: 0 };
    for dialect in ["clang", "nvcc"] {
        let ptx = suite(dialect);
        let on = counters(&ptx, "matmul_tiled", cfg, &args, true, Profile::Hopper);
        assert_eq!(triple(&on.shared_ld), (8 * 20, 8 * 24, 0), "{dialect}");
        assert_eq!(triple(&on.shared_st), (16, 16, 0), "{dialect}");
        let off = counters(&ptx, "matmul_tiled", cfg, &args, false, Profile::Hopper);
        assert_eq!(triple(&off.shared_ld), (8 * 32, 8 * 32, 0), "{dialect}");
        // Maxwell merges the same way; without lane pairing an LDS.128 takes 4 wavefronts
        let mx = counters(&ptx, "matmul_tiled", cfg, &args, true, Profile::Maxwell);
        // (each quarter-warp on one element: 1 wavefront each, no conflict)
        assert_eq!(triple(&mx.shared_ld), (8 * 20, 8 * (4 * 4 + 16), 0), "{dialect}");
    }
}

#[test]
fn unrolled_sorting_network_loads_and_stores_eight_words_as_two_128_bit_accesses() {
    // One CTA of 256 threads (8 warps), thread t sorts s[8t .. 8t+7].
    // Per warp: p[0..7] -> 2 LDS.128 (and 2 STS.128) with lanes 32 bytes apart:
    // each quarter-warp spans 256 bytes, 2 wavefronts, so 8 per access, 4
    // conflicts; the tile's copy in and out: 8 STS and 8 LDS of 1 wavefront.
    // Loads: 10 instructions, 24 wavefronts, 8 conflicts; stores the same.
    // As written: 8 scalar p[j] loads, lanes 8 words apart: 8-way, 8 wavefronts.
    let args = |d: &mut Device| {
        let keys: Vec<u32> = (0..2048u32).map(|i| i.wrapping_mul(2_654_435_761) % 1000).collect();
        vec![Arg::Ptr(d.alloc_from(&keys))]
    };
    let cfg = LaunchConfig::linear(1, 256);
    for dialect in ["clang", "nvcc"] {
        let ptx = suite(dialect);
        let on = counters(&ptx, "sort8_network", cfg, &args, true, Profile::Hopper);
        assert_eq!(triple(&on.shared_ld), (8 * 10, 8 * 24, 8 * 8), "{dialect}");
        assert_eq!(triple(&on.shared_st), (8 * 10, 8 * 24, 8 * 8), "{dialect}");
        let off = counters(&ptx, "sort8_network", cfg, &args, false, Profile::Hopper);
        assert_eq!(triple(&off.shared_ld), (8 * 16, 8 * (8 * 8 + 8), 8 * 8 * 7), "{dialect}");
        assert_eq!(triple(&off.shared_st), (8 * 16, 8 * (8 * 8 + 8), 8 * 8 * 7), "{dialect}");
    }
}

/// One warp; `s` 16-byte aligned at shared offset 0. Base %r4 = 4 tid (4-byte
/// alignment provable), %r6 = 8 tid (8-byte).
const PROBE: &str = r#"
.version 7.8
.target sm_90
.address_size 64
.visible .entry probe(.param .u64 out)
{
    .reg .pred %p<4>;
    .reg .b32 %r<16>;
    .reg .f32 %f<16>;
    .reg .b64 %rd<4>;
    .shared .align 16 .b8 s[1024];
    mov.u32 %r1, %tid.x;
    shl.b32 %r2, %r1, 2;
    mov.u32 %r3, s;
    add.u32 %r4, %r3, %r2;
    shl.b32 %r5, %r1, 3;
    add.u32 %r6, %r3, %r5;
    st.shared.f32 [%r4], 0f3F800000;
    bar.sync 0;
    // 1: a repeated load is dropped
    ld.shared.f32 %f1, [%r4];
    ld.shared.f32 %f2, [%r4];
    // 2: a store ends the run: the next load of that address counts
    st.shared.f32 [%r4+512], %f2;
    ld.shared.f32 %f3, [%r4];
    // 3: the base redefined: counts again
    add.u32 %r4, %r4, 0;
    ld.shared.f32 %f4, [%r4];
    // 4: adjacent words from a 4-byte aligned base: not merged
    ld.shared.f32 %f5, [%r4+128];
    ld.shared.f32 %f6, [%r4+132];
    // 5: from an 8-byte aligned base: one 8-byte load
    ld.shared.f32 %f7, [%r6+256];
    ld.shared.f32 %f8, [%r6+260];
    // 6: under different guards: not merged
    setp.eq.u32 %p1, %r1, 0;
    @%p1 ld.shared.f32 %f9, [%r6+8];
    ld.shared.f32 %f10, [%r6+12];
    add.f32 %f11, %f1, %f3;
    add.f32 %f11, %f11, %f4;
    add.f32 %f11, %f11, %f5;
    add.f32 %f11, %f11, %f6;
    add.f32 %f11, %f11, %f7;
    add.f32 %f11, %f11, %f8;
    add.f32 %f11, %f11, %f9;
    add.f32 %f11, %f11, %f10;
    ld.param.u64 %rd1, [out];
    mul.wide.u32 %rd2, %r1, 4;
    add.u64 %rd3, %rd1, %rd2;
    st.global.f32 [%rd3], %f11;
    // 7: an atomic whose result nobody reads is a reduction; one that is read is not
    atom.global.add.u32 %r10, [%rd1], 1;
    atom.global.add.u32 %r11, [%rd1+4], 1;
    // 8: a `red` at a uniform address, and atomics at a lane's own word
    red.global.add.u32 [%rd1+8], 1;
    atom.global.add.u32 %r12, [%rd3], 1;
    st.global.u32 [%rd3+128], %r11;
    ret;
}
"#;

#[test]
fn repeated_loads_alignment_guards_and_reductions() {
    let args = |d: &mut Device| vec![Arg::Ptr(d.alloc_zeroed::<f32>(64))];
    let cfg = LaunchConfig::linear(1, 32);
    let on = counters(PROBE, "probe", cfg, &args, true, Profile::Hopper);
    // loads: 1 (f1), f3, f4, f5, f6, one 8-byte (f7, f8), f9, f10 = 8 instructions
    assert_eq!(on.shared_ld.instructions, 8);
    // wavefronts: 4-byte loads at 4 tid: 1 each (f1 f3 f4 f5 f6); f9: one
    // lane, 1; f10, 4 bytes at 8 tid: lanes 2 words apart, 2-way, 2; the
    // 8-byte load at 8 tid + 256: 2 (two half-warps, no pairs)
    assert_eq!(on.shared_ld.wavefronts, 5 + 1 + 2 + 2);
    assert_eq!((on.global_red.instructions, on.global_atom.instructions), (3, 1));
    // the same-address atomics: their address is a kernel parameter, the same
    // in every lane, so ptxas merges each into one lane's (1 L1 sector each);
    // the lanes' own words (4 tid): 4 sectors
    assert_eq!((on.global_red.sectors, on.global_atom.sectors), (1 + 1 + 4, 1));
    let off = counters(PROBE, "probe", cfg, &args, false, Profile::Hopper);
    assert_eq!(off.shared_ld.instructions, 10);
    // f1 f2 f3 f4 f5 f6: 1 each; f7 f8 f10 at 8 tid: 2 each; f9: 1
    assert_eq!(off.shared_ld.wavefronts, 6 + 3 * 2 + 1);
    assert_eq!((off.global_red.instructions, off.global_atom.instructions), (1, 3));
    // as written: 32 lanes on one word, 32 L1 sectors each
    assert_eq!((off.global_red.sectors, off.global_atom.sectors), (32, 32 + 32 + 4));
    // the GT200 profile never applies the pass
    let gt = counters(PROBE, "probe", cfg, &args, true, Profile::Gt200);
    assert_eq!(gt.shared_ld.instructions, 10);
}

// ---- which values ptxas can prove warp-uniform (src/model/uniform.rs)

fn uniformity(ptx: &str) -> (Function, Uniformity) {
    let mut dev = Device::new();
    let m = dev.load_ptx(ptx, "u.ptx").unwrap();
    let f = m.prog.functions[0].clone();
    let u = analyse(&f);
    (f, u)
}

fn reg(f: &Function, name: &str) -> usize {
    f.reg_names.iter().position(|n| n == name).unwrap_or_else(|| panic!("no {name}"))
}

const UHEAD: &str = ".version 7.8\n.target sm_90\n.address_size 64\n";

#[test]
fn params_block_index_and_loads_are_uniform_thread_index_is_not() {
    let ptx = format!(
        "{UHEAD}.visible .entry k(.param .u64 p) {{\n.reg .b32 %r<6>;\n.reg .b64 %rd<6>;\n\
         ld.param.u64 %rd1, [p];\ncvta.to.global.u64 %rd2, %rd1;\nmov.u32 %r1, %ctaid.x;\n\
         mul.wide.u32 %rd3, %r1, 4;\nadd.s64 %rd4, %rd2, %rd3;\nld.global.u32 %r2, [%rd2];\n\
         mov.u32 %r3, %tid.x;\nadd.s32 %r4, %r2, %r3;\natom.global.add.u32 %r5, [%rd4], 1;\nret;\n}}\n"
    );
    let (f, u) = uniformity(&ptx);
    for r in ["%rd1", "%rd2", "%r1", "%rd3", "%rd4", "%r2"] {
        assert!(u.regs[reg(&f, r)], "{r} uniform");
    }
    for r in ["%r3", "%r4", "%r5"] {
        assert!(!u.regs[reg(&f, r)], "{r} varying");
    }
}

#[test]
fn divergent_branches_make_registers_defined_twice_varying() {
    // %r1 is 1 or 2 depending on the lane's branch; %r2, defined once, stays uniform
    let body = "mov.u32 %r3, %tid.x;\nsetp.lt.u32 %p1, %r3, 5;\nmov.u32 %r2, 7;\nmov.u32 %r1, 1;\n\
                @%p1 bra L;\nmov.u32 %r1, 2;\nL:\nadd.u32 %r4, %r1, %r2;\nret;\n";
    let ptx = format!("{UHEAD}.visible .entry k() {{\n.reg .pred %p<2>;\n.reg .b32 %r<5>;\n{body}}}\n");
    let (f, u) = uniformity(&ptx);
    assert!(!u.regs[reg(&f, "%r1")]);
    assert!(u.regs[reg(&f, "%r2")]);
    assert!(!u.regs[reg(&f, "%r4")]);
    // the same with a uniform condition: both stay uniform
    let ptx = ptx.replace("mov.u32 %r3, %tid.x;", "mov.u32 %r3, %ctaid.x;");
    let (f, u) = uniformity(&ptx);
    assert!(u.regs[reg(&f, "%r1")]);
    assert!(u.regs[reg(&f, "%r4")]);
}

#[test]
fn a_varying_guard_makes_the_result_varying() {
    let body = "mov.u32 %r3, %laneid;\nsetp.lt.u32 %p1, %r3, 5;\nmov.u32 %r1, 1;\n@%p1 mov.u32 %r2, 2;\nret;\n";
    let ptx = format!("{UHEAD}.visible .entry k() {{\n.reg .pred %p<2>;\n.reg .b32 %r<5>;\n{body}}}\n");
    let (f, u) = uniformity(&ptx);
    assert!(u.regs[reg(&f, "%r1")]);
    assert!(!u.regs[reg(&f, "%r2")]);
    let p1 = f.pred_names.iter().position(|n| n == "%p1").unwrap() as PredId;
    assert!(!u.pred(PredSrc { reg: p1, neg: false }));
}

#[test]
fn global_loads_under_divergent_control_flow_are_varying() {
    // one load of a parameter's word; the branch on %r3 is divergent (%tid) or not (%ctaid)
    let body = "ld.param.u64 %rd1, [p];\nld.global.u32 %r1, [%rd1];\nld.const.u32 %r2, [%rd1];\n\
                mov.u32 %r3, %tid.x;\nsetp.lt.u32 %p1, %r3, 5;\n@%p1 bra L;\nL:\nret;\n";
    let ptx = format!(
        "{UHEAD}.visible .entry k(.param .u64 p) {{\n.reg .pred %p<2>;\n.reg .b32 %r<5>;\n.reg .b64 %rd<2>;\n{body}}}\n"
    );
    let (f, u) = uniformity(&ptx);
    assert!(u.regs[reg(&f, "%rd1")]);
    assert!(!u.regs[reg(&f, "%r1")], "a global load may run at different times for different lanes");
    assert!(u.regs[reg(&f, "%r2")], "constant memory does not change");
    let (f, u) = uniformity(&ptx.replace("%tid.x", "%ctaid.x"));
    assert!(u.regs[reg(&f, "%r1")]);
}

/// Warp reductions, carry chains and `bar.red` touch no memory: a function
/// holding them is planned like any other (adjacent 4-byte shared accesses
/// from an 8-aligned base merge into `STS.64`/`LDS.64`); `bar.red` ends a
/// run as `bar.sync` does.
#[test]
fn redux_carry_and_bar_red_do_not_stop_the_plan() {
    let ptx = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry k(.param .u64 out)\n{\n\
        .reg .b32 %r<14>;\n.reg .b64 %rd<3>;\n.reg .pred %p<2>;\n\
        .shared .align 16 .b8 sm[1024];\n\
        mov.u32 %r1, %tid.x;\nshl.b32 %r2, %r1, 3;\nmov.u32 %r3, sm;\nadd.u32 %r4, %r3, %r2;\n\
        st.shared.u32 [%r4], %r1;\nst.shared.u32 [%r4+4], %r1;\n\
        redux.sync.add.u32 %r5, %r1, -1;\nadd.cc.u32 %r6, %r5, %r1;\naddc.u32 %r7, %r5, 0;\n\
        match.any.sync.b32 %r12, %r1, -1;\n\
        ld.shared.u32 %r8, [%r4];\nld.shared.u32 %r9, [%r4+4];\n\
        setp.ne.u32 %p1, %r8, 0;\nbar.red.popc.u32 %r10, 0, %p1;\n\
        ld.shared.u32 %r13, [%r4];\n\
        add.u32 %r11, %r8, %r9;\nadd.u32 %r11, %r11, %r6;\nadd.u32 %r11, %r11, %r7;\nadd.u32 %r11, %r11, %r10;\n\
        add.u32 %r11, %r11, %r12;\nadd.u32 %r11, %r11, %r13;\n\
        ld.param.u64 %rd1, [out];\nmul.wide.u32 %rd2, %r1, 4;\nadd.s64 %rd1, %rd1, %rd2;\n\
        st.global.u32 [%rd1], %r11;\nret;\n}\n";
    let args = |d: &mut Device| vec![Arg::Ptr(d.alloc_zeroed::<u32>(32))];
    let cfg = LaunchConfig::linear(1, 32);
    let on = counters(ptx, "k", cfg, &args, true, Profile::Hopper);
    // one STS.64; one LDS.64, then the load after bar.red on its own
    assert_eq!(on.shared_st.instructions, 1);
    assert_eq!(on.shared_ld.instructions, 2);
    let off = counters(ptx, "k", cfg, &args, false, Profile::Hopper);
    assert_eq!((off.shared_st.instructions, off.shared_ld.instructions), (2, 3));
}

/// ptxas merges adjacent shared words at a base stepped round a loop when the
/// base's first value and its step keep the pair aligned, and not when the
/// base is 4 mod 8 with the pair at `p - 1, p`: the SASS of
/// `kernels/validation/loop_stepped.cu` on the H200's ptxas 13.0
/// (`tests/fixtures/validation/loop_stepped.{clang,nvcc}.sass`,
/// `tools/device/issue20_s8_stepped.sh`). One CTA of 8 warps, 4 iterations:
/// shared load instructions (pass on, pass off).
#[test]
fn loads_at_a_loop_stepped_base_merge_as_ptxas_merges_them() {
    let args = |n: Option<i32>| {
        move |d: &mut Device| {
            let input: Vec<f32> = (0..2048).map(|i| (i % 7) as f32).collect();
            let mut a = vec![Arg::Ptr(d.alloc_from(&input)), Arg::Ptr(d.alloc_zeroed::<f32>(256))];
            a.extend(n.map(Arg::I32));
            a
        }
    };
    let cfg = LaunchConfig::linear(1, 256);
    // (kernel, clang's (on, off), nvcc's (on, off)); None: no merge, the two equal
    type OnOff = Option<(u64, u64)>;
    let cases: [(&str, OnOff, OnOff); 8] = [
        ("stepped_pairs", Some((32, 64)), Some((32, 32))),
        ("stepped_quads", Some((32, 128)), Some((32, 32))),
        ("stepped_sub", Some((32, 64)), Some((32, 64))),
        ("stepped_wide", Some((32, 64)), Some((32, 32))),
        ("stepped_split", Some((64, 96)), Some((64, 64))),
        ("stepped_odd", Some((64, 64)), Some((32, 32))),
        ("stepped_guarded", None, None),
        ("fixed_pairs", Some((64, 128)), Some((64, 64))),
    ];
    for dialect in ["clang", "nvcc"] {
        let p = format!("kernels/validation/loop_stepped{}.ptx", if dialect == "nvcc" { ".nvcc" } else { "" });
        let ptx = std::fs::read_to_string(&p).unwrap();
        for (kernel, clang, nvcc) in cases {
            let a = args((kernel != "fixed_pairs").then_some(4));
            let on = counters(&ptx, kernel, cfg, &a, true, Profile::Hopper).shared_ld.instructions;
            let off = counters(&ptx, kernel, cfg, &a, false, Profile::Hopper).shared_ld.instructions;
            match if dialect == "nvcc" { nvcc } else { clang } {
                Some(want) => assert_eq!((on, off), want, "{kernel} ({dialect})"),
                None => assert!(on == off && on > 0, "{kernel} ({dialect}): {on} vs {off}"),
            }
        }
    }
}
