//! Loads, stores and address spaces: per-lane resolution of generic
//! addresses, bounds and alignment checks, and the memory events the counter
//! models observe (one per state space an instruction touched).

use super::super::memory::{
    Allocation, CONST_WINDOW, GenericTarget, LOCAL_WINDOW, PARAM_WINDOW, SHARED_WINDOW, decode_generic,
};
use super::super::observer::{MemEvent, MemOp};
use super::super::warp::Warp;
use super::{CtaMut, Ctx, ExecFault, Lanes, fault, map1, operand, read, write};
use crate::ptx::ir::{Address, Dst, MemSpace, Src};
use crate::ptx::types::Ty;
use crate::sim::fault::FaultKind;

/// A memory space as resolved for one lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Resolved {
    Global(u64),
    Shared(u64),
    Local(u64),
    Const(u64),
    KParam(u64),
    FParam(u64),
}

impl Resolved {
    pub(super) fn space(self) -> MemSpace {
        match self {
            Resolved::Global(_) => MemSpace::Global,
            Resolved::Shared(_) => MemSpace::Shared,
            Resolved::Local(_) => MemSpace::Local,
            Resolved::Const(_) => MemSpace::Const,
            Resolved::KParam(_) => MemSpace::KernelParam,
            Resolved::FParam(_) => MemSpace::FrameParam,
        }
    }
    pub(super) fn addr(self) -> u64 {
        match self {
            Resolved::Global(a)
            | Resolved::Shared(a)
            | Resolved::Local(a)
            | Resolved::Const(a)
            | Resolved::KParam(a)
            | Resolved::FParam(a) => a,
        }
    }
}

#[inline]
pub(super) fn resolve(space: MemSpace, addr: u64) -> Resolved {
    match space {
        MemSpace::Global => Resolved::Global(addr),
        MemSpace::Shared => Resolved::Shared(addr),
        MemSpace::Local => Resolved::Local(addr),
        MemSpace::Const => Resolved::Const(addr),
        MemSpace::KernelParam => Resolved::KParam(addr),
        MemSpace::FrameParam => Resolved::FParam(addr),
        MemSpace::Generic => match decode_generic(addr) {
            GenericTarget::Global(a) => Resolved::Global(a),
            GenericTarget::Shared(a) => Resolved::Shared(a),
            GenericTarget::Local(a) => Resolved::Local(a),
            GenericTarget::Const(a) => Resolved::Const(a),
            GenericTarget::Param(a) => Resolved::KParam(a),
        },
    }
}

/// The allocation holding `size` bytes at global address `addr`, trying the
/// previous lane's allocation before searching.
#[inline(always)]
fn find_global<'m>(
    ctx: &Ctx<'m>,
    last: &mut Option<&'m Allocation>,
    addr: u64,
    size: u32,
) -> Option<(&'m Allocation, u64)> {
    if let Some(al) = *last
        && addr >= al.base
        && (addr - al.base).checked_add(size as u64).is_some_and(|e| e <= al.len)
    {
        return Some((al, addr - al.base));
    }
    let (al, off) = ctx.mem.find(addr, size as u64)?;
    *last = Some(al);
    Some((al, off))
}

fn bytes_load(buf: &[u8], off: u64, size: u32) -> Option<u64> {
    let o = off as usize;
    let s = buf.get(o..o.checked_add(size as usize)?)?;
    let mut b = [0u8; 8];
    b[..size as usize].copy_from_slice(s);
    Some(u64::from_le_bytes(b))
}

fn bytes_store(buf: &mut [u8], off: u64, size: u32, v: u64) -> Option<()> {
    let o = off as usize;
    let s = buf.get_mut(o..o.checked_add(size as usize)?)?;
    s.copy_from_slice(&v.to_le_bytes()[..size as usize]);
    Some(())
}

/// Whether `addr` is a multiple of `size`: a mask test for the sizes
/// accesses have (powers of two), not a division.
#[inline(always)]
fn aligned(addr: u64, size: u32) -> bool {
    if size.is_power_of_two() { addr & (size as u64 - 1) == 0 } else { addr.is_multiple_of(size as u64) }
}

/// One lane's access. `store = Some(v)` writes; returns the loaded value otherwise.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn access(
    ctx: &Ctx,
    w: &mut Warp,
    shared: &mut [u8],
    r: Resolved,
    lane: usize,
    size: u32,
    align: u32,
    store: Option<u64>,
) -> Result<u64, Box<ExecFault>> {
    let a = r.addr();
    let oob = || fault(FaultKind::OutOfBounds { space: r.space(), addr: a, size }, Some(lane));
    if !aligned(a, align) {
        return Err(fault(FaultKind::Misaligned { space: r.space(), addr: a, size: align }, Some(lane)));
    }
    match r {
        Resolved::Global(addr) => {
            let (al, off) = ctx.mem.find(addr, size as u64).ok_or_else(oob)?;
            Ok(match store {
                Some(v) => {
                    al.store(off, size, v);
                    0
                }
                None => al.load(off, size),
            })
        }
        Resolved::Shared(off) => match store {
            Some(v) => bytes_store(shared, off, size, v).map(|_| 0).ok_or_else(oob),
            None => bytes_load(shared, off, size).ok_or_else(oob),
        },
        Resolved::Local(off) => {
            if off.checked_add(size as u64).is_none_or(|e| e > w.local_top as u64) {
                return Err(oob());
            }
            Ok(match store {
                Some(v) => {
                    w.local_store(lane, off, size, v);
                    0
                }
                None => w.local_load(lane, off, size),
            })
        }
        Resolved::Const(off) => match store {
            Some(_) => Err(fault(FaultKind::ReadOnly { space: MemSpace::Const }, Some(lane))),
            None => bytes_load(&ctx.prog.const_bank, off, size).ok_or_else(oob),
        },
        Resolved::KParam(off) => match store {
            Some(_) => Err(fault(FaultKind::ReadOnly { space: MemSpace::KernelParam }, Some(lane))),
            None => bytes_load(&ctx.kparams, off, size).ok_or_else(oob),
        },
        Resolved::FParam(off) => {
            let f = w.frames.last_mut().expect("frame");
            let ps = f.param_size as u64;
            if off.checked_add(size as u64).is_none_or(|e| e > ps) {
                return Err(oob());
            }
            let base = lane as u64 * ps + off;
            match store {
                Some(v) => bytes_store(&mut f.params, base, size, v).map(|_| 0).ok_or_else(oob),
                None => bytes_load(&f.params, base, size).ok_or_else(oob),
            }
        }
    }
}

/// Per-lane resolved accesses of one instruction, for observers.
pub(super) struct Touched {
    space: [Option<MemSpace>; 32],
    addr: [u64; 32],
    /// Lanes set.
    lanes: u32,
    /// The space of the first lane set, and whether every lane resolved to it.
    first: Option<MemSpace>,
    uniform: bool,
}

impl Touched {
    pub(super) fn new() -> Self {
        Touched { space: [None; 32], addr: [0; 32], lanes: 0, first: None, uniform: true }
    }
    #[inline(always)]
    pub(super) fn set(&mut self, lane: usize, r: Resolved) {
        let s = r.space();
        self.space[lane] = Some(s);
        self.addr[lane] = r.addr();
        self.lanes |= 1 << lane;
        match self.first {
            None => self.first = Some(s),
            Some(f) => self.uniform &= f == s,
        }
    }
}

/// Sends one event per space the lanes touched.
#[allow(clippy::too_many_arguments)]
pub(super) fn emit(
    cta: &mut CtaMut,
    w: &Warp,
    func: u32,
    pc: u32,
    op: MemOp,
    nc: bool,
    elem: u32,
    n: u32,
    t: &Touched,
) {
    let (cta_linear, warp) = (cta.cta_linear, w.id);
    let Some(obs) = cta.observer.as_deref_mut() else { return };
    let mut send = |space, mask| {
        obs.access(&MemEvent {
            func,
            pc,
            op,
            space,
            nc,
            bytes: elem * n,
            elem_bytes: elem,
            mask,
            addrs: &t.addr,
            cta: cta_linear,
            warp,
        })
    };
    if t.uniform {
        // the usual case: every lane in one space
        if let Some(space) = t.first {
            send(space, t.lanes);
        }
        return;
    }
    let mut done = 0u32;
    for l in 0..32 {
        let Some(space) = t.space[l] else { continue };
        if done >> l & 1 != 0 {
            continue;
        }
        let mask = (0..32).filter(|&k| t.space[k] == Some(space)).fold(0u32, |m, k| m | 1 << k);
        done |= mask;
        send(space, mask);
    }
}

/// Loads (`store` = None) or stores `vals.len()` consecutive elements of `ty`
/// for every active lane: loaded values go to `vals`, what every lane touched
/// to `touched`. Returns the first lane's resolved space (for counting).
#[allow(clippy::too_many_arguments)]
fn vector_access(
    ctx: &Ctx,
    w: &mut Warp,
    shared: &mut [u8],
    space: MemSpace,
    ty: Ty,
    addrs: &Lanes,
    exec: u32,
    vals: &mut [Lanes],
    store: bool,
    touched: &mut Touched,
) -> Result<Option<Resolved>, Box<ExecFault>> {
    let size = ty.bytes();
    let n = vals.len() as u32;
    let mut first = None;
    if space == MemSpace::Global {
        if let Some(first) = global_in_one(ctx, ty, addrs, exec, vals, store, touched) {
            return Ok(Some(first));
        }
        // Global space named in the instruction: no per-lane resolution, and
        // consecutive lanes mostly hit one allocation.
        let mut last = None;
        let mut m = exec;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let a = addrs[l];
            let r = Resolved::Global(a);
            first.get_or_insert(r);
            touched.set(l, r);
            check_vector_align(r, l, size * n)?;
            for (k, v) in vals.iter_mut().enumerate() {
                let ak = a.wrapping_add((k as u32 * size) as u64);
                let oob = || fault(FaultKind::OutOfBounds { space: MemSpace::Global, addr: ak, size }, Some(l));
                if !aligned(ak, size) {
                    return Err(fault(FaultKind::Misaligned { space: MemSpace::Global, addr: ak, size }, Some(l)));
                }
                let (al, off) = find_global(ctx, &mut last, ak, size).ok_or_else(oob)?;
                if store {
                    al.store(off, size, v[l] & ty.mask());
                } else {
                    v[l] = ty.extend(al.load(off, size));
                }
            }
        }
        return Ok(first);
    }
    let mut m = exec;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let r = resolve(space, addrs[l]);
        first.get_or_insert(r);
        touched.set(l, r);
        check_vector_align(r, l, size * n)?;
        for (k, v) in vals.iter_mut().enumerate() {
            let rk = resolve(space, addrs[l].wrapping_add((k as u32 * size) as u64));
            if store {
                access(ctx, w, shared, rk, l, size, size, Some(v[l] & ty.mask()))?;
            } else {
                v[l] = ty.extend(access(ctx, w, shared, rk, l, size, size, None)?);
            }
        }
    }
    Ok(first)
}

/// The common global access at once: when every active lane's whole access
/// (`vals.len()` elements of `ty`) is aligned to its size and all of them lie
/// in one allocation, no lane can fault, and the accesses are made with one
/// bounds check and one allocation search for the warp instead of per lane
/// and element. Returns `None`, having touched nothing, otherwise (the
/// per-lane path then finds the faulting lane). Values, the lanes' order
/// (lowest lane first, its elements in order: what overlapping stores
/// leave) and what `touched` records are those of the per-lane path: with
/// the access aligned to its power-of-two size every element is aligned to
/// its own, and the one allocation holding the lowest to the highest byte is
/// the one each element's search would find (allocations do not overlap).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn global_in_one(
    ctx: &Ctx,
    ty: Ty,
    addrs: &Lanes,
    exec: u32,
    vals: &mut [Lanes],
    store: bool,
    touched: &mut Touched,
) -> Option<Resolved> {
    let size = ty.bytes();
    let total = size * vals.len() as u32;
    if exec == 0 || !total.is_power_of_two() {
        return None;
    }
    // lowest and highest address, and the OR of the low bits (alignment)
    let (mut lo, mut hi, mut low_bits) = (u64::MAX, 0u64, 0u64);
    let mut m = exec;
    while m != 0 {
        let a = addrs[m.trailing_zeros() as usize];
        m &= m - 1;
        lo = lo.min(a);
        hi = hi.max(a);
        low_bits |= a;
    }
    if low_bits & (total as u64 - 1) != 0 {
        return None;
    }
    let span = (hi - lo).checked_add(total as u64)?;
    let (al, lo_off) = ctx.mem.find(lo, span)?;
    let first = exec.trailing_zeros() as usize;
    touched.first = Some(MemSpace::Global);
    touched.lanes |= exec;
    let mut m = exec;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let a = addrs[l];
        touched.space[l] = Some(MemSpace::Global);
        touched.addr[l] = a;
        let off = lo_off + (a - lo);
        for (k, v) in vals.iter_mut().enumerate() {
            let ok = off + (k as u32 * size) as u64;
            if store {
                al.store(ok, size, v[l] & ty.mask());
            } else {
                v[l] = ty.extend(al.load(ok, size));
            }
        }
    }
    Some(Resolved::Global(addrs[first]))
}

/// Vector accesses must be aligned to their whole size.
fn check_vector_align(r: Resolved, lane: usize, total: u32) -> Result<(), Box<ExecFault>> {
    if !aligned(r.addr(), total) {
        return Err(fault(FaultKind::Misaligned { space: r.space(), addr: r.addr(), size: total }, Some(lane)));
    }
    Ok(())
}

/// Counts a memory instruction under the space its first lane resolved to.
pub(super) fn count_space(c: &mut crate::sim::counters::SpaceCounts, r: Resolved) {
    match r {
        Resolved::Global(_) => c.global += 1,
        Resolved::Shared(_) => c.shared += 1,
        Resolved::Local(_) => c.local += 1,
        Resolved::Const(_) => c.constant += 1,
        Resolved::KParam(_) | Resolved::FParam(_) => c.param += 1,
    }
}

/// Every lane's address: base operand plus offset (32-bit bases wrap, then zero-extend).
pub(super) fn addresses(ctx: &Ctx, w: &Warp, cta: &CtaMut, a: &Address) -> Lanes {
    let base = operand(ctx, w, cta, a.base);
    if a.wide {
        map1(&base, |b| b.wrapping_add(a.offset as u64))
    } else {
        map1(&base, |b| (b as u32).wrapping_add(a.offset as u32) as u64)
    }
}

/// `ld`: `ds.len()` elements per lane.
#[allow(clippy::too_many_arguments)]
pub(super) fn load(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    (func, pc): (u32, u32),
    space: MemSpace,
    ty: Ty,
    ds: &[Dst],
    addr: &Address,
    nc: bool,
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    let addrs = addresses(ctx, w, cta, addr);
    // a scalar load needs one lane array, not four
    let mut one = [[0u64; 32]; 1];
    let mut four;
    let vals: &mut [Lanes] = if ds.len() == 1 {
        &mut one
    } else {
        four = [[0u64; 32]; 4];
        &mut four[..ds.len()]
    };
    transfer(ctx, w, cta, (func, pc), space, ty, &addrs, false, nc, exec, vals)?;
    let fr = w.frames.last_mut().expect("frame");
    for (v, d) in vals.iter().zip(ds) {
        write(fr, *d, v, exec);
    }
    Ok(())
}

/// Loads (`store` false: into `vals`) or stores (`store` true: from `vals`)
/// `vals.len()` elements of `ty` per active lane at `addrs`, counts the
/// instruction under the space its first lane resolved to and tells the
/// observer (`nc`: a non-coherent load; stores pass false).
#[allow(clippy::too_many_arguments)]
pub(super) fn transfer(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    (func, pc): (u32, u32),
    space: MemSpace,
    ty: Ty,
    addrs: &Lanes,
    store: bool,
    nc: bool,
    exec: u32,
    vals: &mut [Lanes],
) -> Result<(), Box<ExecFault>> {
    let mut touched = Touched::new();
    let first = vector_access(ctx, w, cta.shared, space, ty, addrs, exec, vals, store, &mut touched)?;
    let (counts, op) =
        if store { (&mut cta.counters.stores, MemOp::Store) } else { (&mut cta.counters.loads, MemOp::Load) };
    if let Some(r) = first {
        count_space(counts, r);
    }
    emit(cta, w, func, pc, op, nc, ty.bytes(), vals.len() as u32, &touched);
    Ok(())
}

/// `st`: `srcs.len()` elements per lane.
#[allow(clippy::too_many_arguments)]
pub(super) fn store(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    (func, pc): (u32, u32),
    space: MemSpace,
    ty: Ty,
    srcs: &[Src],
    addr: &Address,
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    let addrs = addresses(ctx, w, cta, addr);
    let mut vs = [[0u64; 32]; 4];
    for (k, v) in srcs.iter().enumerate() {
        vs[k] = read(ctx, w, cta, *v);
    }
    transfer(ctx, w, cta, (func, pc), space, ty, &addrs, true, false, exec, &mut vs[..srcs.len()])
}

/// `cvta`: between a space's own addresses and generic ones.
#[allow(clippy::too_many_arguments)]
pub(super) fn cvta(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &CtaMut,
    to_generic: bool,
    space: MemSpace,
    d: Dst,
    a: Src,
    exec: u32,
) {
    let va = read(ctx, w, cta, a);
    let win = match space {
        MemSpace::Shared => SHARED_WINDOW,
        MemSpace::Local => LOCAL_WINDOW,
        MemSpace::Const => CONST_WINDOW,
        MemSpace::KernelParam => PARAM_WINDOW,
        _ => 0,
    };
    let r = if to_generic { map1(&va, |x| x.wrapping_add(win)) } else { map1(&va, |x| x.wrapping_sub(win)) };
    write(w.frames.last_mut().expect("frame"), d, &r, exec);
}
