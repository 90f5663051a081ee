//! Loads, stores and address spaces: per-lane resolution of generic
//! addresses, bounds and alignment checks, and the memory events the counter
//! models observe (one per state space an instruction touched).

use super::super::memory::{
    Allocation, CONST_WINDOW, GenericTarget, LOCAL_WINDOW, PARAM_WINDOW, SHARED_WINDOW, WINDOW_SIZE, decode_generic,
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
    if t.uniform {
        // the usual case: every lane in one space
        if let Some(space) = t.first {
            emit_one(cta, w, (func, pc), op, nc, elem, n, space, t.lanes, &t.addr);
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
        emit_one(cta, w, (func, pc), op, nc, elem, n, space, mask, &t.addr);
    }
}

/// Sends the observer one event: the lanes in `mask` accessed `n` elements of
/// `elem` bytes each in `space` at `addrs` (the other lanes' entries are not
/// theirs to read: see [`MemEvent::addrs`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn emit_one(
    cta: &mut CtaMut,
    w: &Warp,
    (func, pc): (u32, u32),
    op: MemOp,
    nc: bool,
    elem: u32,
    n: u32,
    space: MemSpace,
    mask: u32,
    addrs: &Lanes,
) {
    let (cta_linear, warp) = (cta.cta_linear, w.id);
    let Some(obs) = cta.observer.as_deref_mut() else { return };
    obs.access(&MemEvent {
        func,
        pc,
        op,
        space,
        nc,
        bytes: elem * n,
        elem_bytes: elem,
        mask,
        addrs,
        cta: cta_linear,
        warp,
    })
}

/// Loads (`store` = None) or stores `vals.len()` consecutive elements of `ty`
/// for every active lane, lane by lane: loaded values go to `vals`, what
/// every lane touched to `touched`. Returns the first lane's resolved space
/// (for counting). The per-lane path: it finds the faulting lane and
/// resolves lanes of several spaces ([`transfer`] takes the common warps
/// through the per-warp paths first).
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
/// leave) and what the observer hears (the lanes' addresses, in
/// [`transfer`]) are those of the per-lane path: with
/// the access aligned to its power-of-two size every element is aligned to
/// its own, and the one allocation holding the lowest to the highest byte is
/// the one each element's search would find (allocations do not overlap).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn global_in_one(ctx: &Ctx, ty: Ty, addrs: &Lanes, exec: u32, vals: &mut [Lanes], store: bool) -> Option<Resolved> {
    let size = ty.bytes();
    let (lo, hi, total) = aligned_span(size, vals.len(), addrs, exec)?;
    let span = (hi - lo).checked_add(total as u64)?;
    let (al, lo_off) = ctx.mem.find(lo, span)?;
    let at = |_, a| lo_off + (a - lo);
    let mem = |_, off, size, v: Option<u64>| match v {
        Some(v) => {
            al.store(off, size, v);
            0
        }
        None => al.load(off, size),
    };
    lanes_in_one(ty, addrs, exec, vals, store, at, mem);
    Some(Resolved::Global(addrs[exec.trailing_zeros() as usize]))
}

/// [`Ty::extend`] and [`Ty::mask`] with the type's width and signedness
/// resolved once per warp instruction instead of once per lane and element.
#[derive(Debug, Clone, Copy)]
struct Extend {
    signed: bool,
    /// 64 less the type's width (for sign extension).
    sh: u32,
    /// The type's value bits.
    mask: u64,
}

impl Extend {
    #[inline(always)]
    fn of(ty: Ty) -> Self {
        let b = ty.bits().min(64);
        Extend { signed: ty.is_signed(), sh: 64 - b, mask: if b == 64 { u64::MAX } else { (1u64 << b) - 1 } }
    }

    /// `ty.extend(v)`.
    #[inline(always)]
    fn apply(self, v: u64) -> u64 {
        // the signed types are 8 bits wide or more, so `sh` < 64 here
        if self.signed { (((v << self.sh) as i64) >> self.sh) as u64 } else { v & self.mask }
    }
}

/// Calls `f(size)` with `size` a constant for the access sizes a per-warp
/// path meets (1, 2, 4, 8 bytes), so that an inlined `f` is compiled once
/// per size; any other size is passed as it is.
#[inline(always)]
fn by_size(size: u32, mut f: impl FnMut(u32)) {
    match size {
        4 => f(4),
        8 => f(8),
        2 => f(2),
        1 => f(1),
        s => f(s),
    }
}

/// The lowest and highest address of the active lanes and the whole access's
/// size in bytes (`n` elements of `size` bytes per lane), when the warp has an
/// active lane, the access's size is a power of two and every active lane's
/// address is aligned to it: the precondition every `*_in_one` fast path
/// starts from. `None` otherwise.
#[inline(always)]
fn aligned_span(size: u32, n: usize, addrs: &Lanes, exec: u32) -> Option<(u64, u64, u32)> {
    let total = size * n as u32;
    if exec == 0 || !total.is_power_of_two() {
        return None;
    }
    let (lo, hi, low_bits) = lane_span(addrs, exec);
    if low_bits & (total as u64 - 1) != 0 {
        return None;
    }
    Some((lo, hi, total))
}

/// The lowest and the highest of the active lanes' addresses, and the OR of
/// all of them (whose low bits tell whether every one is aligned).
#[inline(always)]
fn lane_span(addrs: &Lanes, exec: u32) -> (u64, u64, u64) {
    let (mut lo, mut hi, mut low_bits) = (u64::MAX, 0u64, 0u64);
    let mut m = exec;
    while m != 0 {
        let a = addrs[m.trailing_zeros() as usize];
        m &= m - 1;
        lo = lo.min(a);
        hi = hi.max(a);
        low_bits |= a;
    }
    (lo, hi, low_bits)
}

/// The common local access (the traversal stack) at once: when the
/// instruction names the local space, or the generic space and every active
/// lane's address lies in the local window, and every active lane's whole
/// access (`vals.len()` elements of `ty`) is aligned to its size and ends
/// within the thread's local memory in use (`Warp::local_top`), no lane can
/// fault, and the lanes are loaded or stored without resolving, aligning
/// and bounding each lane and element. Returns `None`, having touched
/// nothing, otherwise (the per-lane path then finds the faulting lane, or
/// resolves lanes of several spaces). Values, lane and element order and
/// what the observer hears (the local offset, not the generic address: see
/// [`transfer`]) are those of the per-lane path: the local window is aligned far beyond any
/// access size, so a generic address and its local offset have the same
/// alignment; the access aligned to its power-of-two size aligns each
/// element to its own; and every element's offset lies below the highest
/// lane's end, below `local_top`, so each element resolves to the local
/// space as its lane's first does.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn local_in_one(
    w: &mut Warp,
    space: MemSpace,
    ty: Ty,
    addrs: &Lanes,
    exec: u32,
    vals: &mut [Lanes],
    store: bool,
) -> Option<Resolved> {
    let window = match space {
        MemSpace::Local => 0,
        MemSpace::Generic => LOCAL_WINDOW,
        _ => return None,
    };
    let size = ty.bytes();
    let (lo, hi, total) = aligned_span(size, vals.len(), addrs, exec)?;
    if lo < window || hi - window >= WINDOW_SIZE {
        return None;
    }
    // offsets below the window's size cannot overflow
    if hi - window + total as u64 > w.local_top as u64 {
        return None;
    }
    let at = |_, a| a - window;
    let mem = |l, off, size, v: Option<u64>| match v {
        Some(v) => {
            w.local_store(l, off, size, v);
            0
        }
        None => w.local_load(l, off, size),
    };
    lanes_in_one(ty, addrs, exec, vals, store, at, mem);
    Some(Resolved::Local(addrs[exec.trailing_zeros() as usize] - window))
}

/// The common access to the current frame's parameter area (a call's
/// arguments and return values, `ld.param`/`st.param` in a function) at
/// once: when every active lane's whole access is aligned to its
/// power-of-two size and ends within one lane's parameter area
/// (`Frame::param_size`), no lane can fault and the lanes' areas are
/// loaded or stored without checks per lane and element. Returns `None`,
/// having touched nothing, otherwise (the per-lane path then reports the
/// faulting lane). Values, order and what the observer hears are the
/// per-lane path's, for the reasons given at [`local_in_one`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn params_in_one(w: &mut Warp, ty: Ty, addrs: &Lanes, exec: u32, vals: &mut [Lanes], store: bool) -> Option<Resolved> {
    let size = ty.bytes();
    let (_, hi, total) = aligned_span(size, vals.len(), addrs, exec)?;
    let f = w.frames.last_mut().expect("frame");
    let ps = f.param_size as u64;
    // every lane's area is in `params` (32 of them), so no access below can miss
    if hi.checked_add(total as u64).is_none_or(|e| e > ps) {
        return None;
    }
    let params = &mut f.params;
    let at = |l, a| l as u64 * ps + a;
    let mem = |_, off, size, v: Option<u64>| match v {
        Some(v) => {
            bytes_store(params, off, size, v).expect("within the lane's area");
            0
        }
        None => bytes_load(params, off, size).expect("within the lane's area"),
    };
    lanes_in_one(ty, addrs, exec, vals, store, at, mem);
    Some(Resolved::FParam(addrs[exec.trailing_zeros() as usize]))
}

/// The lane loop of the per-warp paths ([`global_in_one`], [`local_in_one`],
/// [`params_in_one`]), once their checks have shown that no lane can fault:
/// for every active lane, lowest first, `at(lane, address)` gives the
/// offset of its first element; its `vals.len()` elements of `ty`,
/// `ty.bytes()` apart, are stored (`mem(lane, offset, size, Some(value
/// masked to the type))`) or loaded (`mem(lane, offset, size, None)`,
/// extended to the type). The loop is compiled once per access size
/// ([`by_size`]) and the type's extension resolved once ([`Extend`]).
#[inline(always)]
fn lanes_in_one(
    ty: Ty,
    addrs: &Lanes,
    exec: u32,
    vals: &mut [Lanes],
    store: bool,
    at: impl Fn(usize, u64) -> u64,
    mut mem: impl FnMut(usize, u64, u32, Option<u64>) -> u64,
) {
    let ext = Extend::of(ty);
    // one loop per direction and, for loads, per kind of extension, so that
    // neither is decided per lane and element
    by_size(ty.bytes(), |size| {
        if store {
            each_element(exec, addrs, vals, size, &at, |l, off, v| {
                mem(l, off, size, Some(*v & ext.mask));
            })
        } else if ext.signed {
            each_element(exec, addrs, vals, size, &at, |l, off, v| *v = ext.apply(mem(l, off, size, None)))
        } else {
            each_element(exec, addrs, vals, size, &at, |l, off, v| *v = mem(l, off, size, None) & ext.mask)
        }
    });
}

/// `f(lane, offset, value)` for every active lane, lowest first, and each of
/// its elements in order (`size` bytes apart from `at(lane, address)`).
#[inline(always)]
fn each_element(
    exec: u32,
    addrs: &Lanes,
    vals: &mut [Lanes],
    size: u32,
    at: &impl Fn(usize, u64) -> u64,
    mut f: impl FnMut(usize, u64, &mut u64),
) {
    let mut m = exec;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let off = at(l, addrs[l]);
        for (k, v) in vals.iter_mut().enumerate() {
            f(l, off + (k as u32 * size) as u64, &mut v[l]);
        }
    }
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
    let (elem, n) = (ty.bytes(), vals.len() as u32);
    let op = if store { MemOp::Store } else { MemOp::Load };
    // the per-warp paths: the whole warp's access at once when no lane can
    // fault and every lane resolves to one space (`None`, having touched
    // nothing, otherwise: the per-lane path then runs)
    let in_one = match space {
        MemSpace::Global => global_in_one(ctx, ty, addrs, exec, vals, store),
        MemSpace::Local | MemSpace::Generic => local_in_one(w, space, ty, addrs, exec, vals, store),
        MemSpace::FrameParam => params_in_one(w, ty, addrs, exec, vals, store),
        _ => None,
    };
    if let Some(r) = in_one {
        // one space for every active lane: one event, at the instruction's own
        // addresses (less the window for a generic local access), with
        // nothing recorded per lane
        count_space(if store { &mut cta.counters.stores } else { &mut cta.counters.loads }, r);
        let offsets;
        let at = if space == MemSpace::Generic {
            offsets = addrs.map(|a| a.wrapping_sub(LOCAL_WINDOW));
            &offsets
        } else {
            addrs
        };
        emit_one(cta, w, (func, pc), op, nc, elem, n, r.space(), exec, at);
        return Ok(());
    }
    let mut touched = Touched::new();
    let first = vector_access(ctx, w, cta.shared, space, ty, addrs, exec, vals, store, &mut touched)?;
    if let Some(r) = first {
        count_space(if store { &mut cta.counters.stores } else { &mut cta.counters.loads }, r);
    }
    emit(cta, w, func, pc, op, nc, elem, n, &touched);
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

#[cfg(test)]
mod tests {
    use crate::sim::DevicePtr;
    use crate::sim::device::{Arg, Device, LaunchConfig, SimError};
    use crate::sim::fault::FaultKind;
    use crate::sim::memory::LOCAL_WINDOW;

    /// Every thread stores `3 * tid` into its local word `(tid % 8) * 4`
    /// (`st.local`), loads it back through its generic address (`ld`), stores
    /// a pair at `32 + (tid % 4) * 8` (`st.local.v2`) and loads it back
    /// generically (`ld.v2`); then a generic load from a per-lane address
    /// that is local for all lanes but `mix`, whose address is `inp`'s
    /// (global). Thread `bad` adds `delta` to its first offset; thread `off`
    /// adds 4096 (past its local memory) to every offset and is predicated
    /// off the local accesses. `out[tid]` gets the scalar, `out[64 + tid]`
    /// the pair's sum, `out[128 + tid]` the mixed load.
    const LANES: &str = r#".version 7.8
.target sm_90
.address_size 64
.visible .entry lanes(.param .u64 out, .param .u64 inp, .param .u32 bad, .param .u32 delta, .param .u32 off, .param .u32 mix)
{
  .local .align 8 .b8 depot[64];
  .reg .pred %p<4>;
  .reg .b32 %r<20>;
  .reg .b64 %rd<20>;
  ld.param.u64 %rd1, [out];
  ld.param.u64 %rd15, [inp];
  ld.param.u32 %r1, [bad];
  ld.param.u32 %r2, [delta];
  ld.param.u32 %r11, [off];
  ld.param.u32 %r16, [mix];
  mov.u32 %r3, %tid.x;
  and.b32 %r4, %r3, 7;
  shl.b32 %r4, %r4, 2;
  setp.eq.u32 %p2, %r3, %r11;
  selp.b32 %r6, 4096, 0, %p2;
  add.u32 %r4, %r4, %r6;
  setp.eq.u32 %p1, %r3, %r1;
  selp.b32 %r5, %r2, 0, %p1;
  add.u32 %r12, %r4, %r5;
  mov.u64 %rd2, depot;
  cvt.u64.u32 %rd3, %r12;
  add.u64 %rd4, %rd2, %rd3;
  mul.lo.u32 %r7, %r3, 3;
  mov.u32 %r8, 7;
  @!%p2 st.local.u32 [%rd4], %r7;
  cvta.local.u64 %rd5, %rd4;
  @!%p2 ld.u32 %r8, [%rd5];
  and.b32 %r9, %r3, 3;
  shl.b32 %r9, %r9, 3;
  add.u32 %r9, %r9, 32;
  add.u32 %r9, %r9, %r6;
  cvt.u64.u32 %rd6, %r9;
  add.u64 %rd7, %rd2, %rd6;
  add.u32 %r10, %r7, 1;
  mov.u32 %r13, 0;
  mov.u32 %r14, 0;
  @!%p2 st.local.v2.u32 [%rd7], {%r7, %r10};
  cvta.local.u64 %rd8, %rd7;
  @!%p2 ld.v2.u32 {%r13, %r14}, [%rd8];
  add.u32 %r15, %r13, %r14;
  setp.eq.u32 %p3, %r3, %r16;
  cvta.local.u64 %rd16, %rd2;
  @%p3 mov.u64 %rd16, %rd15;
  ld.u32 %r17, [%rd16];
  mul.wide.u32 %rd9, %r3, 4;
  add.u64 %rd10, %rd1, %rd9;
  st.global.u32 [%rd10], %r8;
  st.global.u32 [%rd10+256], %r15;
  st.global.u32 [%rd10+512], %r17;
  ret;
}
"#;

    struct Run {
        dev: Device,
        out: DevicePtr,
        r: Result<crate::sim::LaunchStats, SimError>,
    }

    fn run(bad: u32, delta: u32, off: u32, mix: u32) -> Run {
        let mut dev = Device::new();
        let m = dev.load_ptx(LANES, "lanes.ptx").unwrap();
        let out = dev.alloc_zeroed::<u32>(192);
        let inp = dev.alloc_from(&[0x55u32]);
        let args = [Arg::Ptr(out), Arg::Ptr(inp), Arg::U32(bad), Arg::U32(delta), Arg::U32(off), Arg::U32(mix)];
        let r = dev.launch(&m, "lanes", LaunchConfig::linear(1, 64), &args);
        Run { dev, out, r }
    }

    /// The per-warp paths' extension, resolved once per instruction, is
    /// `Ty::extend` and `Ty::mask` for every type and value.
    #[test]
    fn extend_resolved_per_warp_is_the_types_own() {
        use crate::ptx::types::Ty;
        let tys = [
            Ty::B8,
            Ty::U8,
            Ty::S8,
            Ty::B16,
            Ty::U16,
            Ty::S16,
            Ty::F16,
            Ty::BF16,
            Ty::B32,
            Ty::U32,
            Ty::S32,
            Ty::F32,
            Ty::F16x2,
            Ty::BF16x2,
            Ty::B64,
            Ty::U64,
            Ty::S64,
            Ty::F64,
            Ty::Pred,
        ];
        let vals = [0u64, 1, 0x7F, 0x80, 0xFF, 0x8000, 0xFFFF, 0x8000_0000, 0xFFFF_FFFF, 0x1_8000_0080, u64::MAX];
        for ty in tys {
            let e = super::Extend::of(ty);
            assert_eq!(e.mask, ty.mask(), "{ty:?}");
            for v in vals {
                assert_eq!(e.apply(v), ty.extend(v), "{ty:?} {v:#x}");
            }
        }
    }

    /// The local accesses of whole warps take the per-warp path
    /// (`local_in_one`): the values each lane stored come back, through
    /// local and generic addresses, scalars and pairs; a lane predicated off
    /// whose address lies past local memory neither faults nor stops the
    /// others; a generic load whose lanes are partly global resolves each
    /// lane; and the instructions count under the local space.
    #[test]
    fn local_accesses_per_warp_keep_each_lanes_values() {
        let Run { dev, out, r } = run(64, 0, 37, 5);
        let stats = r.unwrap();
        let got = dev.read::<u32>(out, 192);
        for t in 0..64u32 {
            let (scalar, pair, mixed) = (got[t as usize], got[64 + t as usize], got[128 + t as usize]);
            if t == 37 {
                assert_eq!((scalar, pair), (7, 0), "thread {t} is predicated off");
            } else {
                assert_eq!((scalar, pair), (3 * t, 6 * t + 1), "thread {t}");
            }
            // thread 5 reads `inp`; the others their word 0, which thread t % 8 == 0 wrote
            let want = if t == 5 {
                0x55
            } else if t == 37 {
                0 // never stored
            } else if t % 8 == 0 {
                3 * t
            } else {
                0
            };
            assert_eq!(mixed, want, "thread {t}");
        }
        // per warp: 2 local stores, 3 local loads (the mixed one counts
        // under its first lane's space: lane 0 is local in both warps)
        assert_eq!((stats.totals.stores.local, stats.totals.loads.local), (4, 6));
        assert_eq!((stats.totals.stores.global, stats.totals.loads.global), (6, 0));
    }

    /// The fast paths' common precondition, edge by edge: no active lane, a
    /// size that is not a power of two, one misaligned active lane (an
    /// inactive one does not matter), and a `.v4` of words whose first lane
    /// is 16-aligned but whose last is only 8-aligned decline; otherwise the
    /// span is the active lanes' lowest and highest address and the whole
    /// access's size.
    #[test]
    fn aligned_span_declines_exactly_the_unaligned_warps() {
        use super::aligned_span;
        let mut a = [0u64; 32];
        for (l, x) in a.iter_mut().enumerate() {
            *x = 0x1000 + 16 * l as u64;
        }
        assert_eq!(aligned_span(4, 1, &a, 0), None, "no active lane");
        assert_eq!(aligned_span(4, 3, &a, u32::MAX), None, "12 bytes: not a power of two");
        assert_eq!(aligned_span(4, 1, &a, 1 << 7), Some((0x1070, 0x1070, 4)), "one lane");
        assert_eq!(aligned_span(4, 4, &a, u32::MAX), Some((0x1000, 0x11f0, 16)), "a .v4 of words");
        let mut b = a;
        b[31] += 8;
        assert_eq!(aligned_span(4, 4, &b, u32::MAX), None, "the last lane only 8-aligned");
        assert_eq!(aligned_span(4, 4, &b, u32::MAX >> 1), Some((0x1000, 0x11e0, 16)), "lane 31 inactive");
        assert_eq!(aligned_span(4, 2, &b, u32::MAX), Some((0x1000, 0x11f8, 8)), "a pair: 8-aligned suffices");
        b[3] += 2;
        assert_eq!(aligned_span(2, 1, &b, 1 << 3), Some((0x1032, 0x1032, 2)), "a half-word at 2");
        assert_eq!(aligned_span(4, 1, &b, 1 << 3 | 1), None, "a word at 2");
    }

    /// A warp of one frame whose parameter area is `param_size` bytes a lane,
    /// with `local_top` bytes of local memory a thread.
    fn warp(local_top: u32, param_size: u32) -> crate::sim::warp::Warp {
        use crate::sim::simt_stack::{SimtEntry, SimtStack};
        use crate::sim::warp::{Frame, Warp, WarpState};
        let frame = Frame {
            func: 0,
            regs: Vec::new(),
            regs32: Vec::new(),
            preds: vec![0, u32::MAX],
            params: vec![0; param_size as usize * 32],
            param_size,
            local_base: 0,
            stack_base: 0,
            call_pc: 0,
            returned: 0,
        };
        let mut w = Warp {
            id: 0,
            frames: vec![frame],
            stack: SimtStack { entries: vec![SimtEntry { pc: 0, rpc: 0, mask: u32::MAX }] },
            lanes: u32::MAX,
            live: u32::MAX,
            state: WarpState::Ready,
            local: Vec::new(),
            local_top,
            frame_pool: Vec::new(),
            bar_red: None,
        };
        w.ensure_local(local_top);
        w
    }

    /// The per-warp local and parameter paths at the edge of what a thread
    /// has: an access whose last byte is the last of `local_top` (or of the
    /// lane's parameter area) takes the path (`Some`, with the first
    /// lane's local offset) and loads what was stored; one element further
    /// (the access ending one word past the edge) declines (`None`) and
    /// stores nothing. Scalars and pairs, local and generic addresses.
    #[test]
    fn per_warp_local_and_parameter_paths_end_exactly_at_the_edge() {
        use super::{Resolved, local_in_one, params_in_one};
        use crate::ptx::ir::MemSpace;
        use crate::ptx::types::Ty;
        const TOP: u32 = 64;
        for n in [1usize, 2] {
            let size = 4 * n as u64;
            for (space, window) in [(MemSpace::Local, 0), (MemSpace::Generic, LOCAL_WINDOW)] {
                // lane l at offset 8 * (l % 4): lane 3's access the highest
                for (last, fits) in [(TOP as u64 - size, true), (TOP as u64 - size + 4 * n as u64, false)] {
                    let mut w = warp(TOP, 0);
                    let mut addrs = [0u64; 32];
                    for (l, a) in addrs.iter_mut().enumerate() {
                        *a = window + if l % 4 == 3 { last } else { 8 * (l % 4) as u64 };
                    }
                    let exec = 0xF0F0_F0F0 | 0x8888_8888;
                    let mut vals = [[0u64; 32]; 2];
                    for (k, v) in vals.iter_mut().enumerate() {
                        *v = std::array::from_fn(|l| (l * 10 + k) as u64);
                    }
                    let st = local_in_one(&mut w, space, Ty::U32, &addrs, exec, &mut vals[..n], true);
                    assert_eq!(st.is_some(), fits, "{space:?} n {n} last {last}");
                    if !fits {
                        assert!(w.local.iter().all(|&x| x == 0), "nothing stored");
                        continue;
                    }
                    assert_eq!(st, Some(Resolved::Local(addrs[exec.trailing_zeros() as usize] - window)));
                    let mut back = [[0u64; 32]; 2];
                    let ld = local_in_one(&mut w, space, Ty::U32, &addrs, 1 << 3, &mut back[..n], false);
                    assert!(ld.is_some());
                    // each lane's local memory is its own
                    for k in 0..n {
                        assert_eq!(back[k][3], vals[k][3], "element {k}");
                    }
                }
            }
            // the parameter area: 16 bytes a lane
            for (last, fits) in [(16 - size, true), (16 - size + 4 * n as u64, false)] {
                let mut w = warp(0, 16);
                let mut addrs = [0u64; 32];
                addrs[5] = last;
                let mut vals = [[7u64; 32]; 2];
                let st = params_in_one(&mut w, Ty::U32, &addrs, 1 << 5 | 1, &mut vals[..n], true);
                assert_eq!(st.is_some(), fits, "param n {n} last {last}");
                if fits {
                    assert_eq!(st, Some(Resolved::FParam(0)));
                    let p = &w.frames[0].params;
                    assert_eq!(p[5 * 16 + last as usize], 7, "lane 5's own area");
                    assert_eq!(p[16 + last as usize], 0, "not lane 1's");
                } else {
                    assert!(w.frames[0].params.iter().all(|&b| b == 0), "nothing stored");
                }
            }
        }
    }

    /// A lane whose local access is misaligned or out of bounds makes the
    /// per-warp path decline: the per-lane path reports that lane, in the
    /// space and at the address (the local offset) it did before.
    #[test]
    fn a_faulting_lane_takes_the_per_lane_path() {
        for (delta, bad) in [(2u32, 13u32), (4096, 45), (64, 0), (30, 33)] {
            let Run { r, .. } = run(bad, delta, 99, 99);
            let Err(SimError::Fault(f)) = r else { panic!("delta {delta}: expected a fault, got {r:?}") };
            assert_eq!((f.warp, f.lane), (bad / 32, Some(bad % 32)), "delta {delta}: {f}");
            let want = (bad % 8) * 4 + delta;
            match f.kind {
                FaultKind::Misaligned { space, addr, size: 4 } if delta % 4 != 0 => {
                    assert_eq!((space, addr), (crate::ptx::ir::MemSpace::Local, want as u64), "{f}")
                }
                FaultKind::OutOfBounds { space, addr, size: 4 } if delta % 4 == 0 => {
                    assert_eq!((space, addr), (crate::ptx::ir::MemSpace::Local, want as u64), "{f}")
                }
                _ => panic!("delta {delta}: {f}"),
            }
        }
        // the window's own arithmetic: a generic address is its local offset plus the window
        assert_eq!(LOCAL_WINDOW % (1 << 32), 0);
    }

    /// Threads with `tid % 4 != 1` call `addmul(tid, {tid + 5, 7 tid}, 3)`
    /// (a scalar, a pair and a 12-byte array's last word as arguments, a
    /// pair and a scalar back, as the compiler passes them): the calls'
    /// parameter accesses, under a partial mask, take the per-warp path
    /// (`params_in_one`).
    const CALLS: &str = r#".version 7.8
.target sm_90
.address_size 64
.func (.param .align 16 .b8 rv[12]) addmul(.param .b32 a, .param .align 16 .b8 p[12])
{
  .reg .b32 %r<8>;
  ld.param.u32 %r1, [a];
  ld.param.v2.u32 {%r2, %r3}, [p+0];
  ld.param.u32 %r6, [p+8];
  mul.lo.u32 %r4, %r1, %r2;
  add.u32 %r5, %r4, %r3;
  st.param.v2.u32 [rv+0], {%r5, %r1};
  st.param.u32 [rv+8], %r6;
  ret;
}
.visible .entry calls(.param .u64 out)
{
  .reg .pred %p1;
  .reg .b32 %r<12>;
  .reg .b64 %rd<4>;
  ld.param.u64 %rd1, [out];
  mov.u32 %r1, %tid.x;
  mov.u32 %r6, 99;
  mov.u32 %r7, 98;
  mov.u32 %r8, 97;
  and.b32 %r2, %r1, 3;
  setp.eq.u32 %p1, %r2, 1;
  @%p1 bra SKIP;
  add.u32 %r3, %r1, 5;
  mul.lo.u32 %r4, %r1, 7;
  mov.u32 %r5, 3;
  {
  .param .b32 param0;
  st.param.b32 [param0+0], %r1;
  .param .align 16 .b8 param1[12];
  st.param.v2.b32 [param1+0], {%r3, %r4};
  st.param.b32 [param1+8], %r5;
  .param .align 16 .b8 retval0[12];
  call.uni (retval0), addmul, (param0, param1);
  ld.param.v2.b32 {%r6, %r7}, [retval0+0];
  ld.param.b32 %r8, [retval0+8];
  }
SKIP:
  add.u32 %r9, %r6, %r7;
  add.u32 %r10, %r9, %r8;
  mul.wide.u32 %rd2, %r1, 4;
  add.u64 %rd3, %rd1, %rd2;
  st.global.u32 [%rd3], %r10;
  ret;
}
"#;

    #[test]
    fn call_parameters_per_warp_keep_each_lanes_values() {
        let mut dev = Device::new();
        let m = dev.load_ptx(CALLS, "calls.ptx").unwrap();
        let out = dev.alloc_zeroed::<u32>(64);
        dev.launch(&m, "calls", LaunchConfig::linear(1, 64), &[Arg::Ptr(out)]).unwrap();
        let got = dev.read::<u32>(out, 64);
        for t in 0..64u32 {
            let want = if t % 4 == 1 { 99 + 98 + 97 } else { t * (t + 5) + 7 * t + t + 3 };
            assert_eq!(got[t as usize], want, "thread {t}");
        }
    }
}
