//! Half-precision comparisons (`set`/`setp` on `.f16` and `.f16x2`): `.ftz`
//! flushes subnormal inputs to zero before comparing, as the half arithmetic
//! does; without it a subnormal is not zero.

use warplight::sim::{Arg, Device, LaunchConfig, SimConfig};

const KERNEL: &str = ".version 7.8
.target sm_90
.address_size 64
.visible .entry k(.param .u64 out)
{
.reg .b32 %r<12>;
.reg .b16 %h<4>;
.reg .b64 %rd<4>;
.reg .pred %p<3>;
ld.param.u64 %rd1, [out];
mov.b32 %r1, 0x80010001;
mov.b32 %r2, 0;
set.eq.ftz.u32.f16x2 %r3, %r1, %r2;
set.eq.u32.f16x2 %r4, %r1, %r2;
set.eq.ftz.f16x2.f16x2 %r5, %r1, %r2;
mov.b16 %h1, 0x0001;
mov.b16 %h2, 0;
setp.eq.ftz.f16 %p1, %h1, %h2;
selp.u32 %r6, 1, 0, %p1;
setp.eq.f16 %p2, %h1, %h2;
selp.u32 %r7, 1, 0, %p2;
set.gt.ftz.u32.f16 %r8, %h1, %h2;
set.gt.u32.f16 %r9, %h1, %h2;
st.global.v4.u32 [%rd1], {%r3, %r4, %r5, %r6};
st.global.v4.u32 [%rd1+16], {%r7, %r8, %r9, %r2};
ret;
}
";

#[test]
fn ftz_flushes_subnormal_halves_before_comparing() {
    let mut dev = Device::with_config(SimConfig { threads: 1, ..SimConfig::default() });
    let m = dev.load_ptx(KERNEL, "half_compare.ptx").unwrap_or_else(|e| panic!("{e}"));
    let out = dev.alloc_zeroed::<u32>(8);
    dev.launch(&m, "k", LaunchConfig::linear(1, 1), &[Arg::Ptr(out)]).unwrap();
    let got = dev.read::<u32>(out, 8);
    // halves 0x0001 and 0x8001 (±2^-24) flush to ±0, which equal +0
    assert_eq!(got[0], 0xFFFF_FFFF, "set.eq.ftz.u32.f16x2");
    assert_eq!(got[1], 0, "set.eq.u32.f16x2: subnormals are not zero");
    assert_eq!(got[2], 0x3C00_3C00, "set.eq.ftz.f16x2.f16x2: 1.0 in each half");
    assert_eq!(got[3], 1, "setp.eq.ftz.f16");
    assert_eq!(got[4], 0, "setp.eq.f16");
    assert_eq!(got[5], 0, "set.gt.ftz.u32.f16: +0 > +0 is false");
    assert_eq!(got[6], 0xFFFF_FFFF, "set.gt.u32.f16: 2^-24 > 0");
}
