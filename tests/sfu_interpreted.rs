//! An instruction the executor interprets instead of compacting (here: an
//! immediate operand in a function whose constant table is full, as in very
//! large generated kernels) computes the special functions with the same
//! model as a compacted one: the H200's `MUFU.RCP` bits, not the correctly
//! rounded reciprocal.

use warplight::sim::{Arg, Device, LaunchConfig, sfu};

#[test]
fn interpreted_special_functions_use_the_units_model() {
    // an input whose MUFU reciprocal differs from the correctly rounded one
    let x = (0x3f80_0001u32..)
        .find(|&b| sfu::rcp(b, false) != (1.0 / f32::from_bits(b)).to_bits())
        .expect("an input where the unit is not correctly rounded");
    let mut body = String::new();
    // 0x8000 distinct immediates fill the function's constant table
    for k in 0..0x8000u32 {
        body += &format!("add.u32 %r1, %r1, {};\n", k + 1_000_000);
    }
    let ptx = format!(
        ".version 7.8\n.target sm_90\n.address_size 64\n\
         .visible .entry k(.param .u64 out)\n{{\n.reg .b32 %r<3>;\n.reg .f32 %f<3>;\n.reg .b64 %rd<2>;\n\
         mov.u32 %r1, 0;\n{body}\
         rcp.approx.f32 %f1, 0f{x:08X};\nrcp.approx.f32 %f2, %f1;\n\
         ld.param.u64 %rd1, [out];\nst.global.f32 [%rd1], %f1;\nst.global.u32 [%rd1+4], %r1;\nret;\n}}\n"
    );
    let mut dev = Device::new();
    let m = dev.load_ptx(&ptx, "big.ptx").unwrap();
    let out = dev.alloc_from(&[0u32; 2]);
    dev.launch(&m, "k", LaunchConfig::linear(1, 1), &[Arg::Ptr(out)]).unwrap();
    let got = dev.read::<u32>(out, 2);
    assert_eq!(got[0], sfu::rcp(x, false), "rcp.approx of {x:#x}");
    assert_ne!(got[0], (1.0 / f32::from_bits(x)).to_bits());
    // the adds ran too: sum of 1_000_000 + k
    let sum = (0..0x8000u32).fold(0u32, |s, k| s.wrapping_add(k + 1_000_000));
    assert_eq!(got[1], sum);
}
