//! Atomic operations: shared-memory atomics apply at once; global ones are
//! checked at issue and applied at the round's end in a fixed order
//! ([`apply_pending`]), so results do not depend on host threads.

use super::super::warp::{Warp, WarpState};
use super::memory::{Resolved, Touched, access, addresses, count_space, emit, resolve};
use super::{CtaMut, Ctx, Effect, ExecFault, fault, read, write};
use crate::ptx::ir::{Address, AtomOp, Dst, MemSpace, Src};
use crate::ptx::types::Ty;
use crate::sim::alu;
use crate::sim::fault::FaultKind;
use crate::sim::observer::MemOp;

/// A warp's global atomic operations, applied in order when the round ends.
#[derive(Debug, Clone)]
pub struct PendingAtomic {
    /// Issuing warp.
    pub warp: u32,
    /// Operation.
    pub op: AtomOp,
    /// Type.
    pub ty: Ty,
    /// Destination register (in the warp's current frame).
    pub d: Option<Dst>,
    /// (lane, address, b, c) in lane order.
    pub lanes: Vec<(u8, u64, u64, u64)>,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn atomic(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    (func, pc): (u32, u32),
    space: MemSpace,
    op: AtomOp,
    ty: Ty,
    d: Option<Dst>,
    addr: &Address,
    b: Src,
    c: Src,
    exec: u32,
) -> Result<Effect, Box<ExecFault>> {
    let addrs = addresses(ctx, w, cta, addr);
    let (vb, vc) = (read(ctx, w, cta, b), read(ctx, w, cta, c));
    let size = ty.bytes();
    let mut old = [0u64; 32];
    let mut global = Vec::new();
    let mut first = None;
    let mut touched = Touched::new();
    for l in 0..32 {
        if exec >> l & 1 == 0 {
            continue;
        }
        let r = resolve(space, addrs[l]);
        first.get_or_insert(r);
        touched.set(l, r);
        cta.counters.atomic_lane_ops += 1;
        match r {
            Resolved::Shared(_) => {
                let o = access(ctx, w, cta.shared, r, l, size, size, None)?;
                let n = alu::atom(op, ty, o, vb[l], vc[l]);
                access(ctx, w, cta.shared, r, l, size, size, Some(n))?;
                old[l] = o;
            }
            Resolved::Global(a) => {
                // Check now so the fault names this instruction; apply at the round's end.
                if a % size as u64 != 0 {
                    return Err(fault(FaultKind::Misaligned { space: MemSpace::Global, addr: a, size }, Some(l)));
                }
                if ctx.mem.find(a, size as u64).is_none() {
                    return Err(fault(FaultKind::OutOfBounds { space: MemSpace::Global, addr: a, size }, Some(l)));
                }
                global.push((l as u8, a, vb[l], vc[l]));
            }
            other => {
                return Err(fault(FaultKind::Unsupported(format!("atomic on the {:?} space", other.space())), Some(l)));
            }
        }
    }
    if let Some(r) = first {
        count_space(&mut cta.counters.atomics, r);
    }
    let mop = if d.is_some() { MemOp::Atomic } else { MemOp::Reduction };
    emit(cta, w, func, pc, mop, false, size, 1, &touched);
    if let Some(d) = d {
        let shared_lanes = exec & !global.iter().fold(0u32, |m, g| m | 1 << g.0);
        write(w.frames.last_mut().expect("frame"), d, &old, shared_lanes);
    }
    if global.is_empty() {
        return Ok(Effect::Continue);
    }
    cta.pending.push(PendingAtomic { warp: w.id, op, ty, d, lanes: global });
    if d.is_some() {
        w.state = WarpState::WaitAtomic;
        return Ok(Effect::Blocked);
    }
    Ok(Effect::Continue)
}

/// Applies a CTA's pending global atomics in order and wakes the waiting warps.
pub fn apply_pending(ctx: &Ctx, warps: &mut [Warp], pending: &mut Vec<PendingAtomic>) {
    for p in pending.drain(..) {
        let size = p.ty.bytes();
        let w = &mut warps[p.warp as usize];
        for &(l, a, b, c) in &p.lanes {
            let (al, off) = ctx.mem.find(a, size as u64).expect("checked at issue");
            let old = al.load(off, size);
            al.store(off, size, alu::atom(p.op, p.ty, old, b, c));
            if let Some(d) = p.d
                && d.reg != Dst::SINK
            {
                w.frames.last_mut().expect("frame").set_lane(d.reg as usize, l as usize, old & d.mask);
            }
        }
    }
    for w in warps.iter_mut() {
        if w.state == WarpState::WaitAtomic {
            w.state = WarpState::Ready;
        }
    }
}
