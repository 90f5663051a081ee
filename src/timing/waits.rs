//! Load waits: how often a warp stalls on memory. A GT200 warp keeps issuing
//! past a load until an instruction reads the load's destination register
//! (per-warp scoreboarding: Lindholm et al., "NVIDIA Tesla: A Unified Graphics
//! and Computing Architecture", IEEE Micro 28(2), 2008), so loads issued back
//! to back — a node's two words, a triangle's eleven — cost one wait, not one
//! each. A static scan of each straight-line run of a PTX function marks the
//! instructions that first read a pending load's result; their execution
//! counts (the emulator's per-instruction profile) are the waits. Pending
//! loads at a branch or a branch target count as a wait there.

use crate::ptx::Program;
use crate::ptx::ir::{Function, Kind, MemSpace, RegId};
use crate::sim::counters::InstProfile;

/// Warp-level waits by the slowest space a wait is for.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Waits {
    /// Waits for global or local loads or atomics (global latency).
    pub global: u64,
    /// Waits for texture-path loads only (`ld.global.nc`).
    pub texture: u64,
    /// Waits for shared loads only.
    pub shared: u64,
}

/// What a pending load waits for; ordered by latency.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Space {
    Shared,
    Texture,
    Global,
}

/// The load's destination registers and the space it waits on, if it is a load that stalls.
fn load(k: &Kind) -> Option<(Vec<RegId>, Space)> {
    match k {
        Kind::Ld { space, ds, nc, .. } => {
            let s = match space {
                MemSpace::Shared => Space::Shared,
                MemSpace::Global if *nc => Space::Texture,
                MemSpace::Global | MemSpace::Local | MemSpace::Generic => Space::Global,
                // constant and parameter loads hit on-chip caches: not modelled as waits
                MemSpace::Const | MemSpace::KernelParam | MemSpace::FrameParam => return None,
            };
            Some((ds.iter().map(|d| d.reg).collect(), s))
        }
        Kind::Atom { d: Some(d), .. } => Some((vec![d.reg], Space::Global)),
        _ => None,
    }
}

/// Per instruction of `f`: the space of the wait it causes, if any.
///
/// Only the targets of branches start a new straight-line run: a label no
/// branch names (clang's `$L__tmp` line-table labels, one between most
/// inlined statements) joins nothing, and the loads before it are still
/// pending after it.
fn wait_points(f: &Function) -> Vec<Option<Space>> {
    let mut targets = vec![false; f.insts.len()];
    for inst in &f.insts {
        if let Kind::Bra { target, .. } = inst.kind
            && let Some(x) = targets.get_mut(target as usize)
        {
            *x = true;
        }
    }
    let mut out = vec![None; f.insts.len()];
    let mut pending: Vec<(RegId, Space)> = Vec::new();
    for (pc, inst) in f.insts.iter().enumerate() {
        let barrier = targets[pc]
            || matches!(
                inst.kind,
                Kind::Bra { .. }
                    | Kind::Call { .. }
                    | Kind::CallIndirect { .. }
                    | Kind::Ret
                    | Kind::Exit
                    | Kind::Bar { .. }
            );
        let r = inst.kind.reads();
        let hit = pending.iter().any(|(p, _)| r.contains(p));
        if (hit || barrier) && !pending.is_empty() {
            out[pc] = pending.iter().map(|(_, s)| *s).max();
            pending.clear();
        }
        if let Some((ds, s)) = load(&inst.kind) {
            pending.extend(ds.into_iter().map(|d| (d, s)));
        }
    }
    out
}

/// The waits of a launch: each wait point's warp executions.
pub fn waits(prog: &Program, profile: &InstProfile) -> Waits {
    let mut w = Waits::default();
    for site in wait_sites(prog, profile) {
        w.global += site.waits.global;
        w.texture += site.waits.texture;
        w.shared += site.waits.shared;
    }
    w
}

/// One instruction where warps wait on loads, and how often they did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaitSite {
    /// Index into [`Program::functions`].
    pub function: usize,
    /// The instruction's index in its function.
    pub pc: usize,
    /// Its warp executions, under the slowest space waited on.
    pub waits: Waits,
}

/// The wait points of `prog` that `profile` executed, in program order
/// (what [`waits`] sums; for finding where a kernel's waits come from).
pub fn wait_sites(prog: &Program, profile: &InstProfile) -> Vec<WaitSite> {
    let mut out = Vec::new();
    for (fi, (f, counts)) in prog.functions.iter().zip(&profile.per_fn).enumerate() {
        for (pc, (point, c)) in wait_points(f).iter().zip(counts).enumerate() {
            let mut w = Waits::default();
            match point {
                Some(Space::Global) => w.global = c.warp,
                Some(Space::Texture) => w.texture = c.warp,
                Some(Space::Shared) => w.shared = c.warp,
                None => continue,
            }
            if c.warp > 0 {
                out.push(WaitSite { function: fi, pc, waits: w });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{Arg, Device, LaunchConfig};

    /// Two independent texture loads then their use: one wait per warp; a
    /// dependent chain of two global loads: two.
    #[test]
    fn back_to_back_loads_wait_once_and_chains_wait_per_load() {
        let ptx = r#"
.version 7.0
.target sm_50
.address_size 64
.visible .entry k(.param .u64 p, .param .u64 q)
{
    .reg .b32 %r<8>;
    .reg .b64 %rd<8>;
    ld.param.u64 %rd1, [p];
    ld.param.u64 %rd2, [q];
    ld.global.nc.u32 %r1, [%rd1];
    ld.global.nc.u32 %r2, [%rd1+4];
    add.s32 %r3, %r1, %r2;
    ld.global.u64 %rd3, [%rd2];
    ld.global.u32 %r4, [%rd3];
    add.s32 %r5, %r4, %r3;
    st.global.u32 [%rd1+8], %r5;
    ret;
}
"#;
        let mut dev = Device::new();
        let m = dev.load_ptx(ptx, "waits.ptx").unwrap();
        let a = dev.alloc_zeroed::<u32>(4);
        let b = dev.alloc_zeroed::<u64>(1);
        dev.write(b, &[a.0 + 4]).unwrap();
        let stats = dev.launch(&m, "k", LaunchConfig::linear(1, 64), &[Arg::Ptr(a), Arg::Ptr(b)]).unwrap();
        let w = waits(&m.prog, &stats.profile);
        assert_eq!(w, Waits { global: 4, texture: 2, shared: 0 });
    }
}
