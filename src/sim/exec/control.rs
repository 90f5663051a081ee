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
    cta.counters.barrier_warp_arrivals += 1;
    w.state = WarpState::Barrier { id: idv, count: cnt };
    Ok(Effect::Blocked)
}

/// `membar`/`fence`: waits for this CTA's outstanding global atomics.
pub(super) fn membar(w: &mut Warp, cta: &mut CtaMut) -> Effect {
    if !cta.pending.is_empty() {
        w.state = WarpState::WaitAtomic;
        return Effect::Blocked;
    }
    Effect::Continue
}
