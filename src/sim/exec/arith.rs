//! Data instructions: moves, arithmetic, comparisons, selects, conversions,
//! predicate logic, and the lane exchanges `vote` and `shfl`.

use super::super::contract::Fused;
use super::super::warp::Warp;
use super::{CtaMut, Ctx, Lanes, combine, lane_masks, map1, map3, operand, pred_bits, read, select, set_pred, write};
use crate::ptx::ir::{
    ArithOp, BoolOp, CarryOp, Dst, FloatMode, Kind, PredId, PredSrc, ReduxOp, RegId, ShflMode, Src, VoteMode,
};
use crate::ptx::types::Ty;
use crate::sim::{alu, half};

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
            | ArithOp::PrmtF4e
            | ArithOp::PrmtB4e
            | ArithOp::PrmtRc8
            | ArithOp::PrmtEcl
            | ArithOp::PrmtEcr
            | ArithOp::PrmtRc16
            | ArithOp::Dp4aU
            | ArithOp::Dp4aS
            | ArithOp::Dp2aLoU
            | ArithOp::Dp2aLoS
            | ArithOp::Dp2aHiU
            | ArithOp::Dp2aHiS
            | ArithOp::ShfLWrap
            | ArithOp::ShfLClamp
            | ArithOp::ShfRWrap
            | ArithOp::ShfRClamp
    ) {
        read(ctx, w, cta, c)
    } else {
        [0; 32]
    };
    // the special functions take the unit's bits from the same model as the
    // compact form (an instruction is interpreted when its function is too
    // large to compact, for one)
    let r = match crate::sim::decode::resolve_sfu(op, ty, mode, ctx.code.sfu) {
        Some(f) => {
            let mut r = [0u64; 32];
            f(&va, &vb, &vc, &mut r);
            r
        }
        None => map3(&va, &vb, &vc, |x, y, z| alu::arith(op, ty, mode, x, y, z)),
    };
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}

/// An `add`/`sub` that ptxas contracts with the `mul` feeding it
/// ([`crate::sim::contract`]): fma(±a, b, ±c) with one rounding, the add's
/// `.ftz` and `.sat`.
pub(super) fn fused(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, (ty, mode): (Ty, FloatMode), d: Dst, fz: &Fused, exec: u32) {
    let sign = 1u64 << (ty.bits() - 1);
    let (va, vb, vc) = (read(ctx, w, cta, fz.a), read(ctx, w, cta, fz.b), read(ctx, w, cta, fz.c));
    let (na, nc) = (if fz.neg_product { sign } else { 0 }, if fz.neg_c { sign } else { 0 });
    let m = FloatMode { rnd: None, approx: false, full: false, ..mode };
    let r = map3(&va, &vb, &vc, |x, y, z| alu::arith(ArithOp::Mad, ty, m, x ^ na, y, z ^ nc));
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
    if matches!(ty, Ty::F16x2 | Ty::BF16x2) {
        return setp_x2(ctx, w, cta, kind, exec);
    }
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

/// `setp.cmp[.bool].f16x2 p|q, a, b[, c]` (and `.bf16x2`): `p` compares the
/// lower halves, `q` the upper ones, each combined with `c`.
fn setp_x2(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, kind: &Kind, exec: u32) {
    let Kind::Setp { cmp, ty, p, q, a, b, comb, ftz } = kind else { unreachable!("setp") };
    let half = if *ty == Ty::BF16x2 { Ty::BF16 } else { Ty::F16 };
    let (va, vb) = (read(ctx, w, cta, *a), read(ctx, w, cta, *b));
    let (mut lo, mut hi) = (0u32, 0u32);
    for l in 0..32 {
        lo |= (alu::compare(*cmp, half, *ftz, va[l] & 0xFFFF, vb[l] & 0xFFFF) as u32) << l;
        hi |= (alu::compare(*cmp, half, *ftz, va[l] >> 16 & 0xFFFF, vb[l] >> 16 & 0xFFFF) as u32) << l;
    }
    let fr = w.frames.last_mut().expect("frame");
    let (pv, qv) = match comb {
        Some((op, c)) => {
            let cv = pred_bits(fr, *c);
            (combine(*op, lo, cv), combine(*op, hi, cv))
        }
        None => (lo, hi),
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
    let one = half::set_true(*dty, false);
    if matches!(sty, Ty::F16x2 | Ty::BF16x2) {
        let r: Lanes = std::array::from_fn(|l| {
            let c = cv.map(|(op, c)| (op, c >> l & 1 != 0));
            half::set_x2(*cmp, *dty, *sty, *ftz, va[l], vb[l], c)
        });
        return write(fr, *d, &r, exec);
    }
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
        let (oa, ob) = (operand(ctx, w, cta, a), operand(ctx, w, cta, b));
        // the lanes borrowed once, so that the loop is over two plain arrays
        let (va, vb): (&Lanes, &Lanes) = (&oa, &ob);
        select(&lane_masks(pred_bits(w.frame(), p)), va, vb, &mut r);
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

/// `redux.sync`: the operation over the member lanes that execute it (`exec`),
/// given to each of them.
#[allow(clippy::too_many_arguments)]
pub(super) fn redux(ctx: &Ctx, w: &mut Warp, cta: &CtaMut, op: ReduxOp, ty: Ty, d: Dst, a: Src, exec: u32) {
    let va = read(ctx, w, cta, a);
    let lanes = (0..32).filter(|l| exec >> l & 1 != 0).map(|l| va[l] & 0xFFFF_FFFF);
    let r = match op {
        ReduxOp::Add => lanes.fold(0u64, |s, x| (s + x) & 0xFFFF_FFFF),
        ReduxOp::And => lanes.fold(0xFFFF_FFFF, |s, x| s & x),
        ReduxOp::Or => lanes.fold(0, |s, x| s | x),
        ReduxOp::Xor => lanes.fold(0, |s, x| s ^ x),
        ReduxOp::Min | ReduxOp::Max if ty == Ty::S32 => {
            let v = lanes.map(|x| x as u32 as i32);
            let m = if op == ReduxOp::Min { v.min() } else { v.max() };
            m.unwrap_or(0) as u32 as u64
        }
        ReduxOp::Min => lanes.min().unwrap_or(0),
        ReduxOp::Max => lanes.max().unwrap_or(0),
    };
    write(w.frames.last_mut().expect("frame"), d, &[r; 32], exec);
}

/// `match.any.sync` / `match.all.sync` among the member lanes that execute it (`exec`).
#[allow(clippy::too_many_arguments)]
pub(super) fn match_sync(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    all: bool,
    ty: Ty,
    d: Dst,
    p: Option<PredId>,
    a: Src,
    exec: u32,
) {
    let va = read(ctx, w, cta, a);
    let m = ty.mask();
    let same =
        |l: usize| (0..32).filter(|&k| exec >> k & 1 != 0 && va[k] & m == va[l] & m).fold(0u32, |s, k| s | 1 << k);
    let first = exec.trailing_zeros() as usize;
    let agree = same(first) == exec;
    let r: Lanes = std::array::from_fn(|l| match (all, agree) {
        (false, _) => same(l) as u64,
        (true, true) => exec as u64,
        (true, false) => 0,
    });
    let fr = w.frames.last_mut().expect("frame");
    write(fr, d, &r, exec);
    if let Some(p) = p {
        set_pred(fr, p, if agree { u32::MAX } else { 0 }, exec);
    }
}

/// A carry-chain instruction (`alu::carry`), reading and writing the
/// condition-code register `cc`.
#[allow(clippy::too_many_arguments)]
pub(super) fn carry(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    (op, cin, cout, ty): (CarryOp, bool, bool, Ty),
    d: Dst,
    [a, b, c]: [Src; 3],
    cc: RegId,
    exec: u32,
) {
    let (va, vb, vc) = (read(ctx, w, cta, a), read(ctx, w, cta, b), read(ctx, w, cta, c));
    let vcc = read(ctx, w, cta, Src::Reg(cc));
    let mut r = [0u64; 32];
    let mut co = [0u64; 32];
    for l in 0..32 {
        (r[l], co[l]) = alu::carry(op, ty, va[l], vb[l], vc[l], if cin { vcc[l] } else { 0 });
    }
    let fr = w.frames.last_mut().expect("frame");
    write(fr, d, &r, exec);
    if cout {
        write(fr, Dst { reg: cc, mask: 1 }, &co, exec);
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
