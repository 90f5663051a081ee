//! Table 2's instruction classes (TEX, stream inputs, Addr, Pack) read off
//! hand-written PTX by data flow (`repro::purcell2003::dataflow`): every
//! instruction's class named by hand; and the classes of the seed's kernels'
//! loads.

use warplight::ptx;
use warplight::repro::purcell2003::dataflow::{Class, classify};

const HEAD: &str = ".version 7.8\n.target sm_90\n.address_size 64\n";

/// The classes of the kernel's instructions, in order.
fn classes(body: &str) -> Vec<Class> {
    let src = format!("{HEAD}{body}");
    let prog = ptx::load(&src, "test.ptx").expect("the test's PTX loads");
    classify(&prog.functions[0])
}

use Class::{Addr, Other, Pack, Stream, Tex};

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
    // the thread index feeds both addresses only: it is address arithmetic too;
    // the load's address is the thread's index alone: a stream input
    assert_eq!(got, [Other, Other, Addr, Addr, Addr, Addr, Stream, Other, Addr, Addr, Other, Other]);
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
    assert_eq!(got, [Other, Other, Other, Addr, Addr, Stream, Other, Other, Addr, Addr, Other, Other]);
}

#[test]
fn a_clamp_through_a_predicate_and_selp_is_addr_but_a_loop_counter_is_not() {
    // the clamp min(i, 7) by setp + selp feeds the address only; the loop
    // counter feeds the branch's comparison (control, not an address); the
    // load's address is thread-indexed, but the load runs in a loop: a fetch
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
    assert_eq!(got, [Other, Other, Addr, Addr, Addr, Stream, Pack, Pack, Pack, Pack, Pack, Pack, Other, Other]);
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

/// The loads' classes of a kernel, in order.
fn loads(body: &str) -> Vec<Class> {
    classes(body).into_iter().filter(|c| matches!(c, Tex | Stream)).collect()
}

#[test]
fn a_thread_indexed_load_is_a_stream_input_and_one_at_loaded_data_is_a_fetch() {
    // j = idx[tid] (thread-indexed: stream); data[j] (address from loaded data: TEX);
    // data[n] (a uniform address, the same for every thread: TEX)
    let got = loads(
        "
.visible .entry k(.param .u64 idx, .param .u64 data, .param .u32 n)
{
.reg .b32 %r<6>;
.reg .b64 %rd<10>;
.reg .f32 %f<4>;
ld.param.u64 %rd1, [idx];
ld.param.u64 %rd2, [data];
ld.param.u32 %r5, [n];
cvta.to.global.u64 %rd3, %rd1;
mov.u32 %r1, %ctaid.x;
mov.u32 %r2, %ntid.x;
mov.u32 %r3, %tid.x;
mad.lo.s32 %r4, %r1, %r2, %r3;
mul.wide.s32 %rd4, %r4, 4;
add.s64 %rd5, %rd3, %rd4;
ld.global.u32 %r1, [%rd5];
mul.wide.u32 %rd6, %r1, 4;
add.s64 %rd7, %rd2, %rd6;
ld.global.f32 %f1, [%rd7];
mul.wide.u32 %rd8, %r5, 4;
add.s64 %rd9, %rd2, %rd8;
ld.global.f32 %f2, [%rd9];
add.f32 %f3, %f1, %f2;
st.global.f32 [%rd5], %f3;
ret;
}",
    );
    assert_eq!(got, [Stream, Tex, Tex]);
}

#[test]
fn a_load_at_a_loop_counter_or_after_a_data_dependent_branch_is_a_fetch() {
    // after the loop, a[i] with i the loop's counter (two definitions reach
    // it); after a branch on loaded data, a[j] with j = tid or tid + 1
    // (two definitions reach it); a[tid] guarded by loaded data is still
    // thread-indexed (a stream input read on some paths only)
    let got = loads(
        "
.visible .entry k(.param .u64 a)
{
.reg .pred %p<3>;
.reg .b32 %r<8>;
.reg .b64 %rd<12>;
.reg .f32 %f<6>;
ld.param.u64 %rd1, [a];
mov.u32 %r1, %tid.x;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
ld.global.f32 %f1, [%rd3];
mov.u32 %r2, %r1;
LOOP:
add.s32 %r2, %r2, 32;
setp.lt.u32 %p1, %r2, 1024;
@%p1 bra LOOP;
mul.wide.u32 %rd4, %r2, 4;
add.s64 %rd5, %rd1, %rd4;
ld.global.f32 %f2, [%rd5];
setp.gt.f32 %p2, %f1, 0f00000000;
mov.u32 %r3, %r1;
@%p2 bra SKIP;
add.s32 %r3, %r1, 1;
SKIP:
mul.wide.u32 %rd6, %r3, 4;
add.s64 %rd7, %rd1, %rd6;
ld.global.f32 %f3, [%rd7];
add.s32 %r4, %r1, 2;
mul.wide.u32 %rd8, %r4, 4;
add.s64 %rd9, %rd1, %rd8;
@%p2 ld.global.f32 %f4, [%rd9];
add.f32 %f5, %f2, %f3;
st.global.f32 [%rd3], %f5;
ret;
}",
    );
    assert_eq!(got, [Stream, Tex, Tex, Stream]);
}

#[test]
fn a_register_reused_by_a_later_loop_still_gives_a_stream_input_before_it() {
    // stencil_route's shape: v = first + tid indexes the photon's load, then
    // the same register carries the insertion loop's value (v = max(old, v));
    // only the first definition reaches the load (flow-sensitive), but the
    // loop's atomics are not loads; a load in that loop at v is a fetch
    let got = loads(
        "
.visible .entry k(.param .u64 pos, .param .u64 slots, .param .u32 first)
{
.reg .pred %p<3>;
.reg .b32 %r<8>;
.reg .b64 %rd<10>;
.reg .f32 %f<3>;
ld.param.u64 %rd1, [pos];
ld.param.u64 %rd2, [slots];
ld.param.u32 %r1, [first];
mov.u32 %r2, %tid.x;
add.s32 %r3, %r2, %r1;
mul.wide.u32 %rd3, %r3, 16;
add.s64 %rd4, %rd1, %rd3;
ld.global.f32 %f1, [%rd4+12];
setp.eq.f32 %p1, %f1, 0f00000000;
@%p1 bra DONE;
ld.global.v2.f32 {%f1, %f2}, [%rd4];
mov.u32 %r4, 4;
LOOP:
atom.global.min.u32 %r5, [%rd2], %r3;
max.u32 %r3, %r5, %r3;
mul.wide.u32 %rd5, %r3, 16;
add.s64 %rd6, %rd1, %rd5;
ld.global.f32 %f2, [%rd6];
add.s64 %rd2, %rd2, 4;
add.s32 %r4, %r4, -1;
setp.ne.s32 %p2, %r4, 0;
@%p2 bra LOOP;
DONE:
ret;
}",
    );
    assert_eq!(got, [Stream, Stream, Tex]);
}

#[test]
fn the_seed_kernels_loads_are_classed_as_their_sources_say() {
    use warplight::repro::purcell2003::dataflow::static_counts;
    use warplight::repro::purcell2003::passes::{Kernels, Passes};
    let p = Passes::new(None).unwrap();
    let grid = p.module(Kernels::Grid);
    let knn = p.module(Kernels::Knn);
    let c = |m, k: &str| static_counts(m, k).unwrap_or_else(|| panic!("kernel {k}"));
    // stencil_route: the photon's flag and position at pos[first + e], once per thread
    let r = c(grid, "stencil_route");
    assert_eq!((r.stream, r.tex), (3, 0), "stencil_route");
    // bitonic_pass: in[e] and in[csign * offset + e], both data-independent
    let b = c(grid, "bitonic_pass");
    assert_eq!((b.stream, b.tex), (2, 0), "bitonic_pass");
    // binary_search: every probe's address depends on the previous probes' keys
    let s = c(grid, "binary_search");
    assert_eq!(s.stream, 0, "binary_search");
    assert!(s.tex >= 1, "binary_search");
    // stencil_fill: its slot's photon index (stream), then that photon's data (fetches)
    let f = c(grid, "stencil_fill");
    assert!(f.stream >= 1 && f.tex >= 3, "stencil_fill: {f:?}");
    // the estimate: the lookups in its loop are fetches whatever their address
    for (k, fetches) in [("knn_bitonic", 6), ("knn_stencil", 5)] {
        let e = c(knn, k);
        assert!(e.tex >= fetches, "{k}: {e:?}");
    }
}
