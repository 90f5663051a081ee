//! Operands of the synchronising instructions that the GPU leaves undefined
//! are faults naming the kernel and PTX line, never hangs or silent wrong
//! results (issue 17, item 11): `bar.sync` ids past 15 and thread counts that
//! are not multiples of the warp size or exceed the CTA, `shfl.sync`/`vote.sync`
//! member masks that leave out executing lanes or name lanes on another path;
//! and a kernel whose `.local` frame exceeds the device's local memory
//! through the Rust API.

use warplight::sim::{Arg, Device, Fault, FaultKind, LaunchConfig, LaunchStats, SimConfig, SimError};

const HEAD: &str = ".version 7.8\n.target sm_90\n.address_size 64\n";

/// Barriers: the id and count come from parameters; threads at or past
/// `skip_from` leave before the barrier.
const BARRIERS: &str = "
.visible .entry bar_param(.param .u32 id, .param .u32 count, .param .u32 skip_from)
{
.reg .pred %p<2>;
.reg .b32 %r<5>;
ld.param.u32 %r1, [id];
ld.param.u32 %r2, [count];
ld.param.u32 %r3, [skip_from];
mov.u32 %r4, %tid.x;
setp.ge.u32 %p1, %r4, %r3;
@%p1 bra END;
bar.sync %r1, %r2;
END:
ret;
}
";

/// Shuffles and votes: lanes below `split` branch away; the others shuffle
/// down by one under `mask` and store the result, or take a ballot of the
/// executing lanes (`__activemask()`), or a vote without `.sync`.
const WARP_OPS: &str = "
.visible .entry shfl_split(.param .u64 out, .param .u32 split, .param .u32 mask)
{
.reg .pred %p<2>;
.reg .b32 %r<6>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [out];
ld.param.u32 %r3, [split];
ld.param.u32 %r4, [mask];
mov.u32 %r1, %tid.x;
setp.lt.u32 %p1, %r1, %r3;
@%p1 bra DONE;
shfl.sync.down.b32 %r2, %r1, 1, 31, %r4;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r2;
DONE:
ret;
}
.visible .entry ballot_split(.param .u64 out, .param .u32 split)
{
.reg .pred %p<3>;
.reg .b32 %r<6>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [out];
ld.param.u32 %r3, [split];
mov.u32 %r1, %tid.x;
setp.lt.u32 %p1, %r1, %r3;
@%p1 bra DONE;
activemask.b32 %r4;
and.b32 %r5, %r1, 1;
setp.eq.u32 %p2, %r5, 1;
vote.sync.ballot.b32 %r2, %p2, %r4;
vote.any.pred %p2, %p2;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r2;
DONE:
ret;
}
";

fn device() -> Device {
    Device::with_config(SimConfig { threads: 1, ..SimConfig::default() })
}

fn fault_of(r: Result<LaunchStats, SimError>) -> Box<Fault> {
    match r {
        Err(SimError::Fault(f)) => f,
        other => panic!("expected a fault, got {other:?}"),
    }
}

fn bar_launch(block: u32, id: u32, count: u32, skip_from: u32) -> Result<LaunchStats, SimError> {
    let mut dev = device();
    let m = dev.load_ptx(&format!("{HEAD}{BARRIERS}"), "bar.ptx").unwrap();
    let args = [Arg::U32(id), Arg::U32(count), Arg::U32(skip_from)];
    dev.launch(&m, "bar_param", LaunchConfig::linear(1, block), &args)
}

#[test]
fn barrier_ids_past_15_are_faults() {
    let f = fault_of(bar_launch(64, 16, 64, 64));
    assert_eq!(f.kind, FaultKind::BadBarrier { id: 16, count: Some(64), cta_threads: 64 });
    assert_eq!(f.ptx_line, 15, "{f}");
    let msg = f.to_string();
    assert!(msg.contains("barrier id 16 is out of range (a CTA has barriers 0 to 15)"), "{msg}");
    assert!(msg.contains("bar_param") && msg.contains("bar.ptx:15"), "{msg}");
    // a constant id past 15 is refused when the module loads, naming the line (as ptxas does)
    let e = device().load_ptx(&format!("{HEAD}.visible .entry bar_16()\n{{\nbar.sync 16;\nret;\n}}\n"), "b.ptx");
    let e = e.unwrap_err().to_string();
    assert!(e.contains("b.ptx:6") && e.contains("barrier id 16 is out of range (a CTA has barriers 0 to 15)"), "{e}");
    // 15 is the last valid id
    bar_launch(64, 15, 64, 64).unwrap();
}

#[test]
fn barrier_counts_are_whole_warps_within_the_cta() {
    let f = fault_of(bar_launch(64, 1, 33, 64));
    assert_eq!(f.kind, FaultKind::BadBarrier { id: 1, count: Some(33), cta_threads: 64 });
    assert!(f.to_string().contains("thread count of 33: it must be a positive multiple of 32"), "{f}");
    // constant counts are refused when the module loads, naming the line
    for count in [33, 0, 2048] {
        let src = format!("{HEAD}.visible .entry k()\n{{\nbar.sync 1, {count};\nret;\n}}\n");
        let e = device().load_ptx(&src, "b.ptx").unwrap_err().to_string();
        assert!(e.contains("b.ptx:6") && e.contains(&format!("a barrier thread count of {count}")), "{e}");
    }
    for count in [0, 48, 96] {
        let f = fault_of(bar_launch(64, 1, count, 64));
        assert_eq!(f.kind, FaultKind::BadBarrier { id: 1, count: Some(count), cta_threads: 64 }, "{count}");
    }
    // Two of four warps meet at barrier 1 with a count of 64; the others leave.
    bar_launch(128, 1, 64, 64).unwrap();
    // A partial last warp arrives as a whole warp: 48 threads are two warps, 64 threads.
    bar_launch(48, 1, 64, 48).unwrap();
    // A count the arriving warps never reach is a deadlock, not a hang.
    let f = fault_of(bar_launch(128, 1, 128, 64));
    assert!(matches!(f.kind, FaultKind::BarrierDeadlock { .. }), "{f}");
}

fn shfl(block: u32, split: u32, mask: u32) -> (Result<LaunchStats, SimError>, Vec<u32>) {
    let mut dev = device();
    let m = dev.load_ptx(&format!("{HEAD}{WARP_OPS}"), "warp.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(block as usize);
    let r =
        dev.launch(&m, "shfl_split", LaunchConfig::linear(1, block), &[Arg::Ptr(out), Arg::U32(split), Arg::U32(mask)]);
    (r, dev.read::<u32>(out, block as usize))
}

#[test]
fn a_member_mask_naming_lanes_on_another_path_is_a_fault() {
    // lanes 0-15 branch away; 16-31 shuffle naming the whole warp
    let (r, _) = shfl(32, 16, u32::MAX);
    let f = fault_of(r);
    assert_eq!(f.kind, FaultKind::MemberMask { mask: u32::MAX, lane: 16, active: 0xFFFF_0000, live: u32::MAX });
    assert_eq!((f.lane, f.ptx_line), (Some(16), 16), "{f}");
    let msg = f.to_string();
    assert!(msg.contains("names lane 0 that does not execute the instruction"), "{msg}");
    assert!(msg.contains("shfl_split") && msg.contains("warp.ptx:16"), "{msg}");
    // the mask of the lanes that run it: a correct shuffle
    let (r, out) = shfl(32, 16, 0xFFFF_0000);
    r.unwrap();
    let want: Vec<u32> = (0..32).map(|l| if l < 16 { 0 } else { (l + 1).min(31) }).collect();
    assert_eq!(out, want);
}

#[test]
fn a_member_mask_leaving_out_an_executing_lane_is_a_fault() {
    let (r, _) = shfl(32, 0, 0x0000_FFFF);
    let f = fault_of(r);
    assert!(matches!(f.kind, FaultKind::MemberMask { mask: 0xFFFF, active: u32::MAX, .. }), "{f}");
    assert_eq!(f.lane, Some(16));
    assert!(f.to_string().contains("leaves out lane 16 that executes the instruction"), "{f}");
}

/// Lanes 16-31 branch away; lanes 0-7 read lane 0 under `lo`, lanes 8-15
/// read lane 8 under `hi` (two member groups).
const SHFL_GROUPS: &str = "
.visible .entry shfl_groups(.param .u64 out, .param .u32 lo, .param .u32 hi)
{
.reg .pred %p<3>;
.reg .b32 %r<7>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [out];
ld.param.u32 %r4, [lo];
ld.param.u32 %r5, [hi];
mov.u32 %r1, %tid.x;
setp.ge.u32 %p1, %r1, 16;
@%p1 bra DONE;
setp.lt.u32 %p2, %r1, 8;
selp.b32 %r2, %r4, %r5, %p2;
and.b32 %r6, %r1, 8;
shfl.sync.idx.b32 %r3, %r1, %r6, 31, %r2;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r3;
DONE:
ret;
}
";

/// The fault's message gives the reason of the lane in error, not one about
/// the lanes of another member group (which leave it out legitimately).
#[test]
fn a_member_mask_fault_names_the_reason_of_its_own_lane_beside_other_groups() {
    let run = |lo: u32, hi: u32| {
        let mut dev = device();
        let m = dev.load_ptx(&format!("{HEAD}{SHFL_GROUPS}"), "groups.ptx").unwrap();
        let out = dev.alloc_zeroed::<u32>(32);
        let args = [Arg::Ptr(out), Arg::U32(lo), Arg::U32(hi)];
        let r = dev.launch(&m, "shfl_groups", LaunchConfig::linear(1, 32), &args);
        (r, dev.read::<u32>(out, 32))
    };
    // lane 8's mask names lanes 16-23, which branched away
    let f = fault_of(run(0xFF, 0x00FF_FF00).0);
    assert_eq!(f.kind, FaultKind::MemberMask { mask: 0x00FF_FF00, lane: 8, active: 0xFFFF, live: u32::MAX });
    assert_eq!((f.lane, f.ptx_line), (Some(8), 19), "{f}");
    let msg = f.to_string();
    assert!(msg.contains("member mask 0x00ffff00 names lane 16 that does not execute the instruction"), "{msg}");
    assert!(!msg.contains("leaves out"), "{msg}");
    // lane 8's mask leaves lane 8 out (lanes 0-7 are in their own group)
    let f = fault_of(run(0xFF, 0xFE00).0);
    assert_eq!(f.kind, FaultKind::MemberMask { mask: 0xFE00, lane: 8, active: 0xFFFF, live: u32::MAX });
    let msg = f.to_string();
    assert!(msg.contains("member mask 0x0000fe00 leaves out lane 8 that executes the instruction"), "{msg}");
    // the two groups, each under its own mask: each lane reads the first lane of its group
    let (r, out) = run(0xFF, 0xFF00);
    r.unwrap();
    let want: Vec<u32> = (0..32).map(|l| if (8..16).contains(&l) { 8 } else { 0 }).collect();
    assert_eq!(out, want);
}

#[test]
fn lanes_that_do_not_exist_or_exited_may_be_named() {
    // 48 threads: the second warp has 16 lanes and shuffles under 0xffffffff
    let (r, out) = shfl(48, 0, u32::MAX);
    r.unwrap();
    for t in (0..31).chain(32..47) {
        assert_eq!(out[t], t as u32 + 1, "thread {t}");
    }
}

#[test]
fn activemask_ballots_and_votes_without_sync_run_in_divergent_code() {
    let mut dev = device();
    let m = dev.load_ptx(&format!("{HEAD}{WARP_OPS}"), "warp.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(32);
    dev.launch(&m, "ballot_split", LaunchConfig::linear(1, 32), &[Arg::Ptr(out), Arg::U32(8)]).unwrap();
    // lanes 8-31 run it; the odd ones among them vote true
    let want: Vec<u32> = (0..32).map(|l| if l < 8 { 0 } else { 0xAAAA_AA00 }).collect();
    assert_eq!(dev.read::<u32>(out, 32), want);
}

#[test]
fn a_local_frame_over_the_device_limit_is_a_typed_error_through_the_api() {
    let src = format!("{HEAD}.visible .entry k()\n{{\n.local .align 4 .b8 a[4096];\nret;\n}}\n");
    let mut dev = Device::with_config(SimConfig { threads: 1, local_limit: 1024, ..SimConfig::default() });
    let m = dev.load_ptx(&src, "local.ptx").unwrap();
    let f = fault_of(dev.launch(&m, "k", LaunchConfig::linear(2, 32), &[]));
    assert_eq!(f.kind, FaultKind::LocalStackOverflow { needed: 4096, limit: 1024 });
    assert_eq!(f.kernel, "k");
    // within the limit it runs
    let mut dev = Device::with_config(SimConfig { threads: 1, local_limit: 4096, ..SimConfig::default() });
    let m = dev.load_ptx(&src, "local.ptx").unwrap();
    dev.launch(&m, "k", LaunchConfig::linear(2, 32), &[]).unwrap();
}

/// `bar.warp.sync` with the mask in `mask` for lanes below 16 and `hi` for
/// the others (`__syncwarp(m)`), then a store of the lane id.
const WARP_SYNC: &str = "
.visible .entry warp_sync(.param .u64 out, .param .u32 lo, .param .u32 hi)
{
.reg .pred %p<2>;
.reg .b32 %r<6>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [out];
ld.param.u32 %r3, [lo];
ld.param.u32 %r4, [hi];
mov.u32 %r1, %tid.x;
setp.lt.u32 %p1, %r1, 16;
selp.b32 %r5, %r3, %r4, %p1;
bar.warp.sync %r5;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r1;
ret;
}
";

fn warp_sync(lo: u32, hi: u32, checked: bool) -> (Result<LaunchStats, SimError>, Vec<warplight::check::Report>) {
    let mut dev = device();
    let m = dev.load_ptx(&format!("{HEAD}{WARP_SYNC}"), "ws.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(32);
    let args = [Arg::Ptr(out), Arg::U32(lo), Arg::U32(hi)];
    let cfg = LaunchConfig::linear(1, 32);
    if !checked {
        return (dev.launch(&m, "warp_sync", cfg, &args), Vec::new());
    }
    let opts = warplight::check::CheckOptions {
        tools: warplight::check::Tools::ALL,
        uninit: Vec::new(),
        elem_sizes: Vec::new(),
    };
    let c = warplight::check::launch_checked(&mut dev, &m, "warp_sync", cfg, &args, &opts, None).unwrap();
    (c.stats.ok_or_else(|| SimError::Fault(c.fault.unwrap())), c.reports)
}

#[test]
fn a_warp_sync_mask_leaving_out_an_executing_lane_is_a_fault_and_a_synccheck_finding() {
    // lanes 16-31 name only lanes 0-15
    let (r, _) = warp_sync(0xFFFF, 0xFFFF, false);
    let f = fault_of(r);
    assert!(matches!(f.kind, FaultKind::MemberMask { mask: 0xFFFF, active: u32::MAX, .. }), "{f}");
    assert_eq!((f.lane, f.ptx_line), (Some(16), 16), "{f}");
    assert!(f.to_string().contains("ws.ptx:16"), "{f}");
    // `warplight check`: synccheck's invalid member mask, at the line, naming the lane
    let (_, reports) = warp_sync(0xFFFF, 0xFFFF, true);
    assert_eq!(reports.len(), 1, "{reports:?}");
    let rep = &reports[0];
    assert_eq!(rep.hazard, warplight::check::Hazard::InvalidMemberMask);
    assert_eq!(rep.hazard.tool(), "synccheck");
    assert_eq!(rep.sites[0].ptx_line, 16);
    assert!(rep.note.contains("of lane 16") && rep.note.contains("leaves out lane 16"), "{}", rep.note);
    // each half naming itself (two groups), or the whole warp: no fault, no finding
    warp_sync(0xFFFF, 0xFFFF_0000, false).0.unwrap();
    warp_sync(u32::MAX, u32::MAX, false).0.unwrap();
    let (r, reports) = warp_sync(0xFFFF, 0xFFFF_0000, true);
    r.unwrap();
    assert!(reports.is_empty(), "{reports:?}");
    // a mask naming more lanes than execute it is waited for on the GPU, not an error
    warp_sync(0x0001_FFFF, 0xFFFF_0000, false).0.unwrap();
}

/// `redux.sync.add.u32` and `match.any.sync.b32` with lanes below `split`
/// naming `lo` and the others `hi`; each lane writes both results.
const GROUPS: &str = "
.visible .entry groups(.param .u64 out, .param .u32 split, .param .u32 lo, .param .u32 hi)
{
.reg .pred %p<2>;
.reg .b32 %r<12>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [out];
ld.param.u32 %r2, [split];
ld.param.u32 %r3, [lo];
ld.param.u32 %r4, [hi];
mov.u32 %r1, %tid.x;
setp.lt.u32 %p1, %r1, %r2;
selp.b32 %r5, %r3, %r4, %p1;
mul.lo.u32 %r6, %r1, %r1;
redux.sync.add.u32 %r7, %r6, %r5;
and.b32 %r8, %r1, 3;
match.any.sync.b32 %r9, %r8, %r5;
mul.wide.u32 %rd2, %r1, 8;
add.s64 %rd3, %rd1, %rd2;
st.global.v2.u32 [%rd3], {%r7, %r9};
ret;
}
";

fn groups(split: u32, lo: u32, hi: u32) -> Result<Vec<u32>, SimError> {
    let mut dev = device();
    let m = dev.load_ptx(&format!("{HEAD}{GROUPS}"), "groups.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(64);
    let args = [Arg::Ptr(out), Arg::U32(split), Arg::U32(lo), Arg::U32(hi)];
    dev.launch(&m, "groups", LaunchConfig::linear(1, 32), &args)?;
    Ok(dev.read::<u32>(out, 64))
}

/// The Rust model: each lane's redux and match over the lanes of its mask.
fn groups_model(split: u32, lo: u32, hi: u32) -> Vec<u32> {
    let mask = |l: u32| if l < split { lo } else { hi };
    let mut out = Vec::new();
    for l in 0..32u32 {
        let m = mask(l);
        let members = (0..32u32).filter(|k| m >> k & 1 != 0);
        out.push(members.clone().map(|k| k * k).fold(0u32, u32::wrapping_add));
        out.push(members.filter(|k| k & 3 == l & 3).fold(0u32, |s, k| s | 1 << k));
    }
    out
}

#[test]
fn redux_and_match_compute_each_member_group() {
    for (split, lo, hi) in [
        (16, 0xFFFF, 0xFFFF_0000),
        (8, 0xFF, 0xFFFF_FF00),
        (0, 0, u32::MAX),
        (32, u32::MAX, 0),
        (31, !(1 << 31), 1 << 31),
    ] {
        assert_eq!(groups(split, lo, hi).unwrap(), groups_model(split, lo, hi), "split {split} {lo:#x} {hi:#x}");
    }
    // lanes 0-15 name the whole warp, lanes 16-31 only themselves: undefined, a fault naming lane 16
    let e = groups(16, u32::MAX, 0xFFFF_0000).unwrap_err();
    let SimError::Fault(f) = e else { panic!("{e:?}") };
    assert_eq!(
        f.kind,
        FaultKind::MemberMaskDiffers { mask: 0xFFFF_0000, other: 0, other_mask: u32::MAX, active: u32::MAX },
        "{f}"
    );
    assert_eq!((f.lane, f.ptx_line), (Some(16), 18), "{f}");
    let msg = f.to_string();
    assert!(msg.contains("differs from the mask 0xffffffff of lane 0"), "{msg}");
    assert!(!msg.contains("lane 32") && !msg.contains("leaves out"), "{msg}");
}

/// Lane 1 holds member mask 3, every other lane the whole warp (which names
/// lane 1): a fault naming lane 1 and the mask that differs, as the fault
/// and as synccheck's finding (one message, no run of spaces).
#[test]
fn a_member_mask_differing_from_the_mask_naming_its_lane_is_named_as_such() {
    let src = format!("{HEAD}{GROUPS}").replace("setp.lt.u32 %p1, %r1, %r2;", "setp.eq.u32 %p1, %r1, 1;");
    let mut dev = device();
    let m = dev.load_ptx(&src, "groups.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(64);
    let args = [Arg::Ptr(out), Arg::U32(0), Arg::U32(3), Arg::U32(u32::MAX)];
    let f = fault_of(dev.launch(&m, "groups", LaunchConfig::linear(1, 32), &args));
    assert_eq!(f.lane, Some(1), "{f}");
    assert!(matches!(f.kind, FaultKind::MemberMaskDiffers { mask: 3, other: 0, .. }), "{f}");
    let msg = f.to_string();
    assert!(msg.contains("member mask 0x00000003 differs from the mask 0xffffffff of lane 0"), "{msg}");
    // through `warplight check`
    let reports = checked(&src, "groups", &args[1..], 64);
    assert_eq!(reports.len(), 1, "{reports:?}");
    let note = &reports[0].note;
    assert!(note.contains("of lane 1 of warp 0 differs from the mask 0xffffffff of lane 0"), "{note}");
    assert!(!note.contains("  "), "{note}");
}

/// Runs `kernel` of `src` (its first parameter a `u32` output of `n`
/// elements, then `args`) on one warp under every checking tool; the reports.
fn checked(src: &str, kernel: &str, args: &[Arg], n: usize) -> Vec<warplight::check::Report> {
    let mut dev = device();
    let m = dev.load_ptx(src, "checked.ptx").unwrap();
    let out = dev.alloc_zeroed::<u32>(n);
    let mut all = vec![Arg::Ptr(out)];
    all.extend_from_slice(args);
    let opts = warplight::check::CheckOptions {
        tools: warplight::check::Tools::ALL,
        uninit: Vec::new(),
        elem_sizes: Vec::new(),
    };
    let c =
        warplight::check::launch_checked(&mut dev, &m, kernel, LaunchConfig::linear(1, 32), &all, &opts, None).unwrap();
    c.reports
}

/// Each lane writes `s[tid]`, passes `bar.warp.sync` under `lo` (lanes
/// 0-15) or `hi` (lanes 16-31), and reads its neighbour's `s[tid ^ 1]`.
const SYNC_PAIRS: &str = "
.visible .entry pairs(.param .u64 out, .param .u32 lo, .param .u32 hi)
{
.reg .pred %p<2>;
.reg .b32 %r<12>;
.reg .b64 %rd<8>;
.shared .align 4 .b32 s[32];
ld.param.u64 %rd1, [out];
ld.param.u32 %r10, [lo];
ld.param.u32 %r11, [hi];
mov.u32 %r1, %tid.x;
setp.lt.u32 %p1, %r1, 16;
selp.b32 %r2, %r10, %r11, %p1;
shl.b32 %r3, %r1, 2;
mov.u32 %r4, s;
add.u32 %r5, %r4, %r3;
st.shared.u32 [%r5], %r1;
bar.warp.sync %r2;
xor.b32 %r6, %r1, 1;
shl.b32 %r7, %r6, 2;
add.u32 %r8, %r4, %r7;
ld.shared.u32 %r9, [%r8];
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r9;
ret;
}
";

/// `__syncwarp(0x0000ffff)` in lanes 0-15 and `__syncwarp(0xffff0000)` in
/// lanes 16-31, in one instruction, order each half's writes before its
/// reads: no race. Masks that leave the pairs' order to the hardware race.
#[test]
fn per_half_warp_syncs_order_each_halfs_accesses_for_racecheck() {
    let src = format!("{HEAD}{SYNC_PAIRS}");
    let reports = checked(&src, "pairs", &[Arg::U32(0xFFFF), Arg::U32(0xFFFF_0000)], 32);
    assert!(reports.is_empty(), "{reports:?}");
    let reports = checked(&src, "pairs", &[Arg::U32(u32::MAX), Arg::U32(u32::MAX)], 32);
    assert!(reports.is_empty(), "{reports:?}");
    // each lane in a group of its own (lanes 0-15 under 0x1ffff pass with the others of
    // that mask; lane 16 with lanes 17-31): lanes 15 and 16 are not a pair, nothing races
    let reports = checked(&src, "pairs", &[Arg::U32(0x1_FFFF), Arg::U32(0xFFFF_0000)], 32);
    assert!(reports.is_empty(), "{reports:?}");
    // the same kernel without the sync: every read races with its neighbour's write
    let unsynced = src.replace("bar.warp.sync %r2;", "");
    let reports = checked(&unsynced, "pairs", &[Arg::U32(0xFFFF), Arg::U32(0xFFFF_0000)], 32);
    assert!(reports.iter().any(|r| r.hazard == warplight::check::Hazard::ReadAfterWrite), "{reports:?}");
}

/// Lanes 0-15 pass `__syncwarp(0xffff)`; all lanes read `s[0]` in one
/// instruction; the whole warp passes `__syncwarp()`; lane 31 writes `s[0]`:
/// every read is ordered before the write.
const LANE_CLOCKS: &str = "
.visible .entry lclock(.param .u64 out)
{
.reg .pred %p<3>;
.reg .b32 %r<12>;
.reg .b64 %rd<8>;
.shared .align 4 .b32 s[1];
ld.param.u64 %rd1, [out];
mov.u32 %r1, %tid.x;
mov.u32 %r4, s;
setp.eq.u32 %p2, %r1, 0;
@%p2 st.shared.u32 [%r4], 5;
bar.sync 0;
setp.lt.u32 %p1, %r1, 16;
@!%p1 bra SKIP;
bar.warp.sync 65535;
SKIP:
ld.shared.u32 %r9, [%r4];
bar.warp.sync -1;
setp.eq.u32 %p2, %r1, 31;
@%p2 st.shared.u32 [%r4], 7;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r9;
ret;
}
";

#[test]
fn a_read_after_a_partial_warp_sync_is_ordered_by_a_full_one() {
    let src = format!("{HEAD}{LANE_CLOCKS}");
    let reports = checked(&src, "lclock", &[], 32);
    assert!(reports.is_empty(), "{reports:?}");
    // without the full sync, lane 31's write races with the other lanes' reads
    let reports = checked(&src.replace("bar.warp.sync -1;", ""), "lclock", &[], 32);
    assert!(reports.iter().any(|r| r.hazard == warplight::check::Hazard::WriteAfterRead), "{reports:?}");
}

/// `vote.sync.ballot` with lanes 0-15 naming `0x0000ffff` and lanes 16-31
/// `0xffff0000`: two ballots, each of its own lanes' votes.
const VOTE_GROUPS: &str = "
.visible .entry vote_groups(.param .u64 out, .param .u32 lo, .param .u32 hi)
{
.reg .pred %p<3>;
.reg .b32 %r<8>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [out];
ld.param.u32 %r3, [lo];
ld.param.u32 %r4, [hi];
mov.u32 %r1, %tid.x;
setp.lt.u32 %p1, %r1, 16;
selp.b32 %r5, %r3, %r4, %p1;
and.b32 %r6, %r1, 1;
setp.eq.u32 %p2, %r6, 1;
vote.sync.ballot.b32 %r2, %p2, %r5;
mul.wide.u32 %rd2, %r1, 4;
add.s64 %rd3, %rd1, %rd2;
st.global.u32 [%rd3], %r2;
ret;
}
";

#[test]
fn vote_ballots_over_each_member_group_and_faults_on_differing_masks() {
    let run = |lo: u32, hi: u32| {
        let mut dev = device();
        let m = dev.load_ptx(&format!("{HEAD}{VOTE_GROUPS}"), "vote.ptx").unwrap();
        let out = dev.alloc_zeroed::<u32>(32);
        let r =
            dev.launch(&m, "vote_groups", LaunchConfig::linear(1, 32), &[Arg::Ptr(out), Arg::U32(lo), Arg::U32(hi)]);
        r.map(|_| dev.read::<u32>(out, 32))
    };
    let want: Vec<u32> = (0..32).map(|l| if l < 16 { 0xAAAA } else { 0xAAAA_0000 }).collect();
    assert_eq!(run(0xFFFF, 0xFFFF_0000).unwrap(), want);
    assert_eq!(run(u32::MAX, u32::MAX).unwrap(), vec![0xAAAA_AAAA; 32]);
    // lanes 0-15 name the whole warp, lanes 16-31 only themselves: undefined, a fault at lane 16
    let e = run(u32::MAX, 0xFFFF_0000).unwrap_err();
    let SimError::Fault(f) = e else { panic!("{e:?}") };
    assert!(matches!(f.kind, FaultKind::MemberMaskDiffers { mask: 0xFFFF_0000, other: 0, .. }), "{f}");
    assert_eq!(f.lane, Some(16));
}
