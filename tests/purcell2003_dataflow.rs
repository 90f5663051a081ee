//! Table 2's instruction classes (TEX, Addr, Pack) read off hand-written PTX
//! by data flow (`repro::purcell2003::dataflow`): every instruction's class
//! named by hand.

use warplight::ptx;
use warplight::repro::purcell2003::dataflow::{Class, classify};

const HEAD: &str = ".version 7.8\n.target sm_90\n.address_size 64\n";

/// The classes of the kernel's instructions, in order.
fn classes(body: &str) -> Vec<Class> {
    let src = format!("{HEAD}{body}");
    let prog = ptx::load(&src, "test.ptx").expect("the test's PTX loads");
    classify(&prog.functions[0])
}

use Class::{Addr, Other, Pack, Tex};

#[test]
fn index_arithmetic_that_only_feeds_addresses_is_addr_and_the_loads_are_tex() {
    // out[i] = in[2 * i + 1] * 3.0: 2 * i + 1, its widening and the pointer
    // sums feed addresses only
    let got = classes(
        "
.visible .entry k(.param .u64 in, .param .u64 out)
{
.reg .b32 %r<4>;
.reg .b64 %rd<8>;
.reg .f32 %f<3>;
ld.param.u64 %rd1, [in];
ld.param.u64 %rd2, [out];
mov.u32 %r1, %tid.x;
mad.lo.s32 %r2, %r1, 2, 1;
mul.wide.s32 %rd3, %r2, 4;
add.s64 %rd4, %rd1, %rd3;
ld.global.f32 %f1, [%rd4];
mul.f32 %f2, %f1, 0f40400000;
mul.wide.s32 %rd5, %r1, 4;
add.s64 %rd6, %rd2, %rd5;
st.global.f32 [%rd6], %f2;
ret;
}",
    );
    // the thread index feeds both addresses only: it is address arithmetic too
    assert_eq!(got, [Other, Other, Addr, Addr, Addr, Addr, Tex, Other, Addr, Addr, Other, Other]);
}

#[test]
fn an_index_that_also_feeds_a_value_or_a_comparison_is_not_addr() {
    // j = i + 1 is both the address of a load and a stored value; k = i + 2
    // both an address and the operand of a comparison that guards the store
    let got = classes(
        "
.visible .entry k(.param .u64 a)
{
.reg .pred %p<2>;
.reg .b32 %r<6>;
.reg .b64 %rd<8>;
ld.param.u64 %rd1, [a];
mov.u32 %r1, %tid.x;
add.s32 %r2, %r1, 1;
mul.wide.u32 %rd2, %r2, 4;
add.s64 %rd3, %rd1, %rd2;
ld.global.u32 %r3, [%rd3];
add.s32 %r4, %r1, 2;
setp.lt.u32 %p1, %r4, 100;
mul.wide.u32 %rd4, %r4, 4;
add.s64 %rd5, %rd1, %rd4;
@%p1 st.global.u32 [%rd5], %r2;
ret;
}",
    );
    assert_eq!(got, [Other, Other, Other, Addr, Addr, Tex, Other, Other, Addr, Addr, Other, Other]);
}

#[test]
fn a_clamp_through_a_predicate_and_selp_is_addr_but_a_loop_counter_is_not() {
    // the clamp min(i, 7) by setp + selp feeds the address only; the loop
    // counter feeds the branch's comparison (control, not an address)
    let got = classes(
        "
.visible .entry k(.param .u64 a)
{
.reg .pred %p<3>;
.reg .b32 %r<8>;
.reg .b64 %rd<6>;
.reg .f32 %f<4>;
ld.param.u64 %rd1, [a];
mov.u32 %r1, %tid.x;
setp.gt.u32 %p1, %r1, 7;
selp.b32 %r2, 7, %r1, %p1;
mul.wide.u32 %rd2, %r2, 4;
add.s64 %rd3, %rd1, %rd2;
mov.f32 %f1, 0f00000000;
mov.u32 %r3, 0;
LOOP:
ld.global.f32 %f2, [%rd3];
add.f32 %f1, %f1, %f2;
add.s32 %r3, %r3, 1;
setp.lt.u32 %p2, %r3, 4;
@%p2 bra LOOP;
st.global.f32 [%rd3], %f1;
ret;
}",
    );
    assert_eq!(got, [Other, Addr, Addr, Addr, Addr, Addr, Other, Other, Tex, Other, Other, Other, Other, Other, Other]);
}

#[test]
fn packing_two_halves_and_bit_fields_is_pack_and_a_shift_feeding_an_address_is_addr() {
    // state = pack_2half(x, y) | (n << 16 in a second word); unpacked again;
    // the index's shift (i << 4) feeds the address only
    let got = classes(
        "
.visible .entry k(.param .u64 a)
{
.reg .b16 %h<3>;
.reg .b32 %r<10>;
.reg .b64 %rd<4>;
.reg .f32 %f<4>;
ld.param.u64 %rd1, [a];
mov.u32 %r1, %tid.x;
shl.b32 %r2, %r1, 4;
cvt.u64.u32 %rd2, %r2;
add.s64 %rd3, %rd1, %rd2;
ld.global.v2.f32 {%f1, %f2}, [%rd3];
cvt.rn.f16.f32 %h1, %f1;
cvt.rn.f16.f32 %h2, %f2;
mov.b32 %r3, {%h1, %h2};
shl.b32 %r4, %r1, 16;
or.b32 %r5, %r4, 5;
and.b32 %r6, %r5, 65535;
st.global.v2.u32 [%rd3+8], {%r3, %r6};
ret;
}",
    );
    assert_eq!(got, [Other, Other, Addr, Addr, Addr, Tex, Pack, Pack, Pack, Pack, Pack, Pack, Other, Other]);
}

#[test]
fn kernel_parameters_and_shared_memory_are_not_fetches() {
    // ld.param is not a texture fetch; ld.shared is not one either, but its
    // address is still address arithmetic
    let got = classes(
        "
.visible .entry k(.param .u32 n)
{
.reg .b32 %r<6>;
.shared .align 4 .b8 s[128];
ld.param.u32 %r1, [n];
mov.u32 %r2, %tid.x;
shl.b32 %r3, %r2, 2;
mov.u32 %r4, s;
add.s32 %r5, %r4, %r3;
ld.shared.u32 %r1, [%r5];
st.shared.u32 [%r5+4], %r1;
ret;
}",
    );
    assert_eq!(got, [Other, Addr, Addr, Addr, Addr, Other, Other, Other]);
}
