//! Data instructions: moves, arithmetic, comparisons, selects, conversions,
//! predicate logic, and the lane exchanges `vote` and `shfl`.

use super::super::decode::LaneFn;
use super::super::warp::Warp;
use super::{CtaMut, Ctx, Lanes, combine, map1, map3, operand, pred_bits, read, set_pred, write};
use crate::ptx::ir::{ArithOp, BoolOp, Dst, FloatMode, Kind, PredId, PredSrc, ShflMode, Src, VoteMode};
use crate::ptx::types::Ty;
use crate::sim::alu;

/// `mov`.
pub(super) fn mov(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, d: Dst, a: Src, exec: u32) {
    let v = read(ctx, w, cta, a);
    write(w.frames.last_mut().expect("frame"), d, &v, exec);
}

/// `mov.bN d, {a, b, ...}`.
pub(super) fn pack(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, d: Dst, parts: &[Src], part_bits: u32, exec: u32) {
    let mut acc = [0u64; 32];
    let pm = (1u64 << part_bits) - 1;
    for (k, p) in parts.iter().enumerate() {
        let v = read(ctx, w, cta, *p);
        for l in 0..32 {
            acc[l] |= (v[l] & pm) << (k as u32 * part_bits);
        }
    }
    write(w.frames.last_mut().expect("frame"), d, &acc, exec);
}

/// `mov.bN {a, b, ...}, s`.
pub(super) fn unpack(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, ds: &[Dst], a: Src, part_bits: u32, exec: u32) {
    let v = read(ctx, w, cta, a);
    let pm = (1u64 << part_bits) - 1;
    let fr = w.frames.last_mut().expect("frame");
    for (k, d) in ds.iter().enumerate() {
        let part = map1(&v, |x| (x >> (k as u32 * part_bits)) & pm);
        write(fr, *d, &part, exec);
    }
}

/// Arithmetic whose 32-lane function was resolved when the module was decoded.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn resolved(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    f: LaneFn,
    reads_c: bool,
    d: Dst,
    a: Src,
    b: Src,
    c: Src,
    exec: u32,
) {
    let mut r = [0u64; 32];
    {
        let (va, vb) = (operand(ctx, w, cta, a), operand(ctx, w, cta, b));
        if reads_c {
            let vc = operand(ctx, w, cta, c);
            f(&va, &vb, &vc, &mut r);
        } else {
            f(&va, &vb, &va, &mut r);
        }
    }
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}

/// Arithmetic evaluated lane by lane (`alu::arith`): the forms that
/// [`crate::sim::decode::resolve_arith`] leaves to the general semantics.
pub(super) fn arith(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    (op, ty, mode): (ArithOp, Ty, FloatMode),
    d: Dst,
    [a, b, c]: [Src; 3],
    exec: u32,
) {
    let (va, vb) = (operand(ctx, w, cta, a), operand(ctx, w, cta, b));
    let vc = if matches!(
        op,
        ArithOp::Mad
            | ArithOp::MadHi
            | ArithOp::MadWide
            | ArithOp::Mad24Lo
            | ArithOp::Mad24Hi
            | ArithOp::Bfe
            | ArithOp::Prmt
            | ArithOp::ShfLWrap
            | ArithOp::ShfLClamp
            | ArithOp::ShfRWrap
            | ArithOp::ShfRClamp
    ) {
        read(ctx, w, cta, c)
    } else {
        [0; 32]
    };
    let r = map3(&va, &vb, &vc, |x, y, z| alu::arith(op, ty, mode, x, y, z));
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}

/// `bfi`.
pub(super) fn bfi(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, ty: Ty, d: Dst, [a, b, c, e]: [Src; 4], exec: u32) {
    let (va, vb, vc, ve) = (read(ctx, w, cta, a), read(ctx, w, cta, b), read(ctx, w, cta, c), read(ctx, w, cta, e));
    let r: Lanes = std::array::from_fn(|l| alu::bfi(ty, va[l], vb[l], vc[l], ve[l]));
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}

/// `setp`.
pub(super) fn setp(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, kind: &Kind, exec: u32) {
    let Kind::Setp { cmp, ty, p, q, a, b, comb, ftz } = kind else { unreachable!("setp") };
    let t = {
        let (va, vb) = (operand(ctx, w, cta, *a), operand(ctx, w, cta, *b));
        alu::compare_lanes(*cmp, *ty, *ftz, &va, &vb)
    };
    let fr = w.frames.last_mut().expect("frame");
    let (pv, qv) = match comb {
        Some((op, c)) => {
            let cv = pred_bits(fr, *c);
            (combine(*op, t, cv), combine(*op, !t, cv))
        }
        None => (t, !t),
    };
    set_pred(fr, *p, pv, exec);
    if let Some(q) = q {
        set_pred(fr, *q, qv, exec);
    }
}

/// `set`.
pub(super) fn set(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, kind: &Kind, exec: u32) {
    let Kind::Set { cmp, dty, sty, d, a, b, comb, ftz } = kind else { unreachable!("set") };
    let (va, vb) = (read(ctx, w, cta, *a), read(ctx, w, cta, *b));
    let fr = w.frames.last_mut().expect("frame");
    let cv = comb.map(|(op, c)| (op, pred_bits(fr, c)));
    let one = match dty {
        Ty::F32 => 1.0f32.to_bits() as u64,
        Ty::F64 => 1.0f64.to_bits(),
        t => t.mask(),
    };
    let r: Lanes = std::array::from_fn(|l| {
        let mut t = alu::compare(*cmp, *sty, *ftz, va[l], vb[l]);
        if let Some((op, c)) = cv {
            t = combine(op, t as u32, c >> l & 1) & 1 != 0;
        }
        if t { one } else { 0 }
    });
    write(fr, *d, &r, exec);
}

/// `selp`.
#[allow(clippy::too_many_arguments)]
pub(super) fn selp(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, d: Dst, a: Src, b: Src, p: PredSrc, exec: u32) {
    let mut r = [0u64; 32];
    {
        let (va, vb) = (operand(ctx, w, cta, a), operand(ctx, w, cta, b));
        let pv = pred_bits(w.frame(), p);
        for l in 0..32 {
            // branch-free: the predicate bit as an all-ones or all-zeros mask
            let m = ((pv >> l) & 1) as u64;
            let m = m.wrapping_neg();
            r[l] = (va[l] & m) | (vb[l] & !m);
        }
    }
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}

/// Predicate logic (`and/or/xor/not/mov.pred`).
pub(super) fn pred_logic(w: &mut Warp, op: Option<BoolOp>, d: PredId, a: PredSrc, b: PredSrc, exec: u32) {
    let fr = w.frames.last_mut().expect("frame");
    let av = pred_bits(fr, a);
    let v = match op {
        None => av,
        Some(o) => combine(o, av, pred_bits(fr, b)),
    };
    set_pred(fr, d, v, exec);
}

/// `cvt`.
pub(super) fn cvt(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    (dty, sty, mode): (Ty, Ty, FloatMode),
    d: Dst,
    a: Src,
    exec: u32,
) {
    let va = read(ctx, w, cta, a);
    // A destination register wider than the type gets the value sign- or zero-extended.
    let r = map1(&va, |x| dty.extend(alu::cvt(dty, sty, mode, x)));
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}

/// `vote.sync`.
pub(super) fn vote(w: &mut Warp, mode: VoteMode, d: Option<Dst>, p: PredId, a: PredSrc, exec: u32) {
    let fr = w.frames.last_mut().expect("frame");
    let pv = pred_bits(fr, a) & exec;
    match mode {
        VoteMode::Ballot => {
            if let Some(d) = d {
                write(fr, d, &[pv as u64; 32], exec);
            }
        }
        VoteMode::All => set_pred(fr, p, if pv == exec { u32::MAX } else { 0 }, exec),
        VoteMode::Any => set_pred(fr, p, if pv != 0 { u32::MAX } else { 0 }, exec),
        VoteMode::Uni => set_pred(fr, p, if pv == 0 || pv == exec { u32::MAX } else { 0 }, exec),
    }
}

/// `shfl.sync`.
#[allow(clippy::too_many_arguments)]
pub(super) fn shfl(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    mode: ShflMode,
    d: Dst,
    p: Option<PredId>,
    [a, b, c]: [Src; 3],
    exec: u32,
) {
    let (va, vb, vc) = (read(ctx, w, cta, a), read(ctx, w, cta, b), read(ctx, w, cta, c));
    let mut r = [0u64; 32];
    let mut pv = 0u32;
    for lane in 0..32u32 {
        let bval = (vb[lane as usize] & 0x1F) as u32;
        let cval = (vc[lane as usize] & 0x1F) as u32;
        let segmask = ((vc[lane as usize] >> 8) & 0x1F) as u32;
        let max_lane = (lane & segmask) | (cval & !segmask);
        let min_lane = lane & segmask;
        let (j, ok) = match mode {
            ShflMode::Up => {
                let j = lane as i32 - bval as i32;
                (j, j >= max_lane as i32)
            }
            ShflMode::Down => {
                let j = (lane + bval) as i32;
                (j, j <= max_lane as i32)
            }
            ShflMode::Bfly => {
                let j = (lane ^ bval) as i32;
                (j, j <= max_lane as i32)
            }
            ShflMode::Idx => {
                let j = (min_lane | (bval & !segmask)) as i32;
                (j, j <= max_lane as i32)
            }
        };
        let src = if ok { j as usize } else { lane as usize };
        r[lane as usize] = va[src & 31];
        if ok {
            pv |= 1 << lane;
        }
    }
    let fr = w.frames.last_mut().expect("frame");
    write(fr, d, &r, exec);
    if let Some(p) = p {
        set_pred(fr, p, pv, exec);
    }
}
