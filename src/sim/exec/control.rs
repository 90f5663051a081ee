//! Control instructions: branches (divergence onto the SIMT stack), `exit`,
//! barriers and fences.

use super::super::simt_stack::BranchOutcome;
use super::super::warp::{Warp, WarpState};
use super::{CtaMut, Ctx, Effect, ExecFault, fault, lane_of_mask, read};
use crate::ptx::ir::Src;
use crate::sim::fault::FaultKind;

/// `bra`: the taken lanes go to `target`, the others fall through; a split
/// pushes both paths with the branch's reconvergence point.
pub(super) fn branch(ctx: &Ctx, w: &mut Warp, cta: &mut CtaMut, func: u32, pc: u32, target: u32, exec: u32) -> Effect {
    cta.counters.branches += 1;
    let rpc = ctx.cfgs[func as usize].reconv[pc as usize];
    if w.stack.branch(exec, target, pc + 1, rpc) == BranchOutcome::Diverged {
        cta.counters.divergent_branches += 1;
        if ctx.per_inst {
            cta.profile.per_fn[func as usize][pc as usize].divergent += 1;
        }
    }
    Effect::Continue
}

/// `exit` (or `ret` from the kernel): the lanes finish.
pub(super) fn exit(ctx: &Ctx, w: &mut Warp, exec: u32) -> Effect {
    if exec == 0 {
        return Effect::Continue;
    }
    w.live &= !exec;
    w.stack.retire_lanes(0, exec);
    super::call::pop_empty_frames(ctx, w);
    if w.stack.entries.is_empty() {
        w.state = WarpState::Done;
        return Effect::Blocked;
    }
    Effect::Continue
}

/// `bar.sync`: the warp waits at barrier `id` (all its live lanes must arrive).
pub(super) fn bar(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    id: Src,
    count: Option<Src>,
    exec: u32,
) -> Result<Effect, Box<ExecFault>> {
    if exec != w.live {
        return Err(fault(FaultKind::DivergentBarrier { active: exec, live: w.live }, None));
    }
    let idv = read(ctx, w, cta, id)[lane_of_mask(exec).unwrap_or(0)] as u32;
    let cnt = count.map(|c| read(ctx, w, cta, c)[lane_of_mask(exec).unwrap_or(0)] as u32);
    // PTX: ids 0..15; a count is a multiple of the warp size (warps arrive
    // whole); more threads than the CTA's warps hold could never arrive.
    let cta_threads = (ctx.block[0] * ctx.block[1] * ctx.block[2]).div_ceil(32) * 32;
    if idv > 15 || cnt.is_some_and(|c| c == 0 || c % 32 != 0 || c > cta_threads) {
        return Err(fault(FaultKind::BadBarrier { id: idv, count: cnt, cta_threads }, None));
    }
    cta.counters.barrier_warp_arrivals += 1;
    w.state = WarpState::Barrier { id: idv, count: cnt };
    Ok(Effect::Blocked)
}

/// The member mask of `shfl.sync`/`vote.sync`: each executing lane must be
/// in its mask, and the mask may name no live lane that does not execute the
/// instruction (on another path of a divergent warp, or predicated off) —
/// the GPU leaves both undefined (before Volta) or waits for the named lanes
/// (Volta on), which a warp on a SIMT stack cannot. Lanes the mask names
/// that have exited or do not exist (a partial last warp under
/// `0xffffffff`) are ignored, as the GPU does. The forms without `.sync`
/// have no mask to check.
pub(super) fn member_mask(ctx: &Ctx, w: &Warp, cta: &CtaMut, mask: Src, exec: u32) -> Result<(), Box<ExecFault>> {
    if mask == crate::ptx::lower::warp::NO_MEMBER_MASK {
        return Ok(());
    }
    let m = read(ctx, w, cta, mask);
    let mut bits = exec;
    while bits != 0 {
        let l = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let ml = m[l] as u32;
        if ml & (1 << l) == 0 || ml & w.live & !exec != 0 {
            return Err(fault(FaultKind::MemberMask { mask: ml, lane: l as u32, active: exec, live: w.live }, Some(l)));
        }
    }
    Ok(())
}

/// The groups of lanes a `redux.sync`/`match.sync`/`vote.sync` computes
/// over (and `shfl.sync` checks): the
/// executing lanes split by the member mask each one holds (lanes 0–15 may
/// name 0x0000ffff and lanes 16–31 0xffff0000: two reductions), lowest lane's
/// group first. Every lane of a group must hold the same mask — a lane whose
/// mask names an executing lane holding another mask is undefined in PTX
/// and faults ([`FaultKind::MemberMaskDiffers`], naming that lane). The forms
/// without a mask compute over all executing lanes. [`member_mask`] has
/// checked the masks against the executing lanes before.
pub(super) fn member_groups(
    ctx: &Ctx,
    w: &Warp,
    cta: &CtaMut,
    mask: Src,
    exec: u32,
) -> Result<Vec<u32>, Box<ExecFault>> {
    if mask == crate::ptx::lower::warp::NO_MEMBER_MASK || exec == 0 {
        return Ok(vec![exec]);
    }
    let m = read(ctx, w, cta, mask);
    let mut groups = Vec::new();
    let mut rest = exec;
    while rest != 0 {
        let l = rest.trailing_zeros() as usize;
        let ml = m[l] as u32;
        let group = exec & ml;
        if let Some(k) = (0..32).find(|&k| group >> k & 1 != 0 && m[k] as u32 != ml) {
            let kind =
                FaultKind::MemberMaskDiffers { mask: m[k] as u32, other: l as u32, other_mask: ml, active: exec };
            return Err(fault(kind, Some(k)));
        }
        groups.push(group);
        rest &= !group;
    }
    Ok(groups)
}

/// `bar.warp.sync`: the lanes run together already; an observer (the race
/// checker) learns which of the member lanes passed it together: the
/// executing lanes holding the same mask, one group at a time (lanes 0–15
/// may sync under 0x0000ffff and lanes 16–31 under 0xffff0000 in one
/// instruction). Lanes of the mask that are not executing it (divergent
/// code) are not waited for. An executing lane that its own mask leaves out
/// is undefined in PTX: a [`FaultKind::MemberMask`] fault naming the lane
/// (`warplight check` reports it as synccheck's invalid member mask, at the
/// instruction's line).
pub(super) fn warp_sync(ctx: &Ctx, w: &Warp, cta: &mut CtaMut, mask: Src, exec: u32) -> Result<(), Box<ExecFault>> {
    if exec == 0 {
        return Ok(());
    }
    let m = read(ctx, w, cta, mask);
    if let Some(l) = (0..32).find(|&l| exec >> l & 1 != 0 && (m[l] as u32) >> l & 1 == 0) {
        return Err(fault(
            FaultKind::MemberMask { mask: m[l] as u32, lane: l as u32, active: exec, live: w.live },
            Some(l),
        ));
    }
    if let Some(obs) = cta.observer.as_deref_mut() {
        let mut rest = exec;
        while rest != 0 {
            let ml = m[rest.trailing_zeros() as usize] as u32;
            let group = (0..32).filter(|&k| rest >> k & 1 != 0 && m[k] as u32 == ml).fold(0u32, |g, k| g | 1 << k);
            obs.warp_sync(w.id, group);
            rest &= !group;
        }
    }
    Ok(())
}

/// `membar`/`fence`: waits for this CTA's outstanding global atomics.
pub(super) fn membar(w: &mut Warp, cta: &mut CtaMut) -> Effect {
    if !cta.pending.is_empty() {
        w.state = WarpState::WaitAtomic;
        return Effect::Blocked;
    }
    Effect::Continue
}
