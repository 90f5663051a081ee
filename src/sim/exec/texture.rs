//! Texture and surface instructions (`tex`, `tld4`, `txq`, `suld.b`,
//! `sust.b`, `sured.b`): each lane's object handle names a texture or surface object of
//! the device ([`crate::sim::texture`]); texels are read from and written to
//! device memory.

use std::cell::{Cell, RefCell};

use super::{CtaMut, Ctx, ExecFault, Lanes, fault, read, write};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;
use crate::sim::fault::FaultKind;
use crate::sim::observer::{MemEvent, MemOp};
use crate::sim::texture::{self, Object, SurfaceDesc, TextureDesc};
use crate::sim::warp::Warp;

/// Loads `size` bytes of device memory at `addr`; outside every allocation
/// it reads 0 and records the address in `miss` (the first one), for the
/// caller to fault on ([`out_of_bounds`]).
fn load(ctx: &Ctx, addr: u64, size: u32, miss: &Cell<Option<(u64, u32)>>) -> u64 {
    ctx.mem.find(addr, size as u64).map(|(a, off)| a.load(off, size)).unwrap_or_else(|| {
        if miss.get().is_none() {
            miss.set(Some((addr, size)));
        }
        0
    })
}

/// A texel or surface element outside every allocation: the fault of a
/// global access out of bounds (what memcheck reports).
fn out_of_bounds(addr: u64, size: u32, lane: usize) -> Box<ExecFault> {
    fault(FaultKind::OutOfBounds { space: MemSpace::Global, addr, size }, Some(lane))
}

fn bad_handle(what: &str, h: u64, lane: usize) -> Box<ExecFault> {
    fault(FaultKind::Unsupported(format!("{h:#x} is not a {what} object of this device")), Some(lane))
}

fn tex_of<'a>(ctx: &'a Ctx, h: u64, lane: usize) -> Result<&'a TextureDesc, Box<ExecFault>> {
    match texture::object(ctx.textures, h) {
        Some(Object::Texture(t)) => Ok(t),
        _ => Err(bad_handle("texture", h, lane)),
    }
}

fn surf_of<'a>(ctx: &'a Ctx, h: u64, lane: usize) -> Result<&'a SurfaceDesc, Box<ExecFault>> {
    match texture::object(ctx.textures, h) {
        Some(Object::Surface(s)) => Ok(s),
        _ => Err(bad_handle("surface", h, lane)),
    }
}

fn lanes(exec: u32) -> impl Iterator<Item = usize> {
    (0..32).filter(move |l| exec >> l & 1 != 0)
}

/// One lane's texture-path accesses of one instruction: (address, bytes,
/// bytes per element), in order.
type Footprint = Vec<(u64, u32, u32)>;

/// Hands one instruction's texture-path accesses (`per_lane[l]`: lane `l`'s)
/// to the CTA's observer: the k-th access of every lane in one event per
/// access size ([`crate::sim::observer::MemObserver::texture_access`]).
fn observe(cta: &mut CtaMut, w: &Warp, (func, pc): (u32, u32), op: MemOp, per_lane: &[Footprint]) {
    let cta_linear = cta.cta_linear;
    let Some(obs) = cta.observer.as_deref_mut() else { return };
    let rounds = per_lane.iter().map(Vec::len).max().unwrap_or(0);
    for k in 0..rounds {
        let mut left = (0..per_lane.len()).filter(|&l| per_lane[l].len() > k).fold(0u32, |m, l| m | 1 << l);
        while left != 0 {
            let (_, bytes, elem) = per_lane[left.trailing_zeros() as usize][k];
            let (mut addrs, mut mask) = ([0u64; 32], 0u32);
            for l in lanes(left) {
                let (a, b, e) = per_lane[l][k];
                if (b, e) == (bytes, elem) {
                    addrs[l] = a;
                    mask |= 1 << l;
                }
            }
            left &= !mask;
            obs.texture_access(&MemEvent {
                func,
                pc,
                op,
                space: MemSpace::Global,
                nc: op == MemOp::Load,
                bytes,
                elem_bytes: elem,
                mask,
                addrs: &addrs,
                cta: cta_linear,
                warp: w.id,
            });
        }
    }
}

/// `tex` / `tld4` at instruction `at` (function, pc).
#[allow(clippy::too_many_arguments)]
pub(super) fn tex(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    at: (u32, u32),
    geom: TexGeom,
    gather: Option<u8>,
    cty: Ty,
    ds: &[Dst],
    handle: Src,
    coords: &[Src],
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    cta.counters.textures.instructions += 1;
    cta.counters.textures.requests += (0..8).filter(|q| exec >> (4 * q) & 0xF != 0).count() as u64;
    let h = read(ctx, w, cta, handle);
    let cs: Vec<Lanes> = coords.iter().map(|c| read(ctx, w, cta, *c)).collect();
    let miss = Cell::new(None);
    // the texels each lane read, for the observer
    let watch = cta.observer.is_some();
    let (texels, mut per_lane) = (RefCell::new(Vec::new()), vec![Footprint::new(); 32]);
    let rd = |a: u64, n: u32| {
        if watch {
            texels.borrow_mut().push((a, n, n));
        }
        load(ctx, a, n, &miss)
    };
    let mut out = [[0u64; 32]; 4];
    for l in lanes(exec) {
        let t = tex_of(ctx, h[l], l)?;
        let dims = geom.dims();
        let v = if let Some(comp) = gather {
            texture::gather(t, &rd, f32::from_bits(cs[0][l] as u32), f32::from_bits(cs[1][l] as u32), comp)
        } else if cty == Ty::F32 {
            let mut x = [0f32; 3];
            for d in 0..dims {
                x[d] = f32::from_bits(cs[d][l] as u32);
            }
            texture::sample(t, &rd, x, dims)
        } else {
            let mut x = [0i32; 3];
            for d in 0..dims {
                x[d] = cs[d][l] as u32 as i32;
            }
            texture::fetch_int(t, &rd, x, dims)
        };
        if let Some((a, n)) = miss.get() {
            return Err(out_of_bounds(a, n, l));
        }
        for c in 0..4 {
            out[c][l] = v[c] as u64;
        }
        per_lane[l] = texels.take();
    }
    observe(cta, w, at, MemOp::Load, &per_lane);
    let f = w.frames.last_mut().expect("frame");
    for (d, v) in ds.iter().zip(&out) {
        write(f, *d, v, exec);
    }
    Ok(())
}

/// `txq`.
pub(super) fn txq(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    query: TxqQuery,
    d: Dst,
    handle: Src,
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    cta.counters.textures.queries += 1;
    let h = read(ctx, w, cta, handle);
    let mut out = [0u64; 32];
    for l in lanes(exec) {
        let t = tex_of(ctx, h[l], l)?;
        out[l] = match query {
            // as the H200 answers (tests/fixtures/gpu_txq.txt): a CUDA array's height is
            // at least 1, its depth 0 unless 3-D; a linear resource has neither
            TxqQuery::Width => t.dims[0].max(1),
            TxqQuery::Height if t.linear => 0,
            TxqQuery::Height => t.dims[1].max(1),
            TxqQuery::Depth => t.dims[2],
            TxqQuery::ChannelDataType => t.format.code(),
            TxqQuery::ChannelOrder => t.channels,
            TxqQuery::NormalizedCoords => t.normalized as u32,
            TxqQuery::FilterMode => (t.filter == texture::FilterMode::Linear) as u32,
            TxqQuery::AddrMode0 => t.addr[0] as u32,
            TxqQuery::AddrMode1 => t.addr[1] as u32,
            TxqQuery::AddrMode2 => t.addr[2] as u32,
            TxqQuery::ArraySize => 0,
            TxqQuery::NumMipmapLevels | TxqQuery::NumSamples => 1,
        } as u64;
    }
    write(w.frames.last_mut().expect("frame"), d, &out, exec);
    Ok(())
}

/// The byte address of lane `l`'s surface access, `None` to skip it (`.zero`
/// out of range); `.trap` out of range faults, as does `.clamp` for an access
/// wider than a row.
fn surf_addr(
    s: &SurfaceDesc,
    cs: &[Lanes],
    geom: TexGeom,
    size: u32,
    clamp: SurfClamp,
    l: usize,
) -> Result<Option<u64>, Box<ExecFault>> {
    let mut x = [0i32; 3];
    for d in 0..geom.dims() {
        x[d] = cs[d][l] as u32 as i32;
    }
    let a = texture::surface_addr(s, x, geom.dims(), size, clamp == SurfClamp::Clamp);
    // clamped, only an access wider than a row has no address
    if a.is_none() && clamp == SurfClamp::Clamp {
        let row = s.elem_bytes as u64 * s.dims[0].max(1) as u64;
        return Err(fault(
            FaultKind::Unsupported(format!("{size}-byte surface access is wider than a row ({row} bytes) with .clamp")),
            Some(l),
        ));
    }
    if a.is_none() && clamp == SurfClamp::Trap {
        return Err(fault(
            FaultKind::Unsupported(format!("surface access out of range at ({}, {}, {}) with .trap", x[0], x[1], x[2])),
            Some(l),
        ));
    }
    Ok(a)
}

/// `suld.b` at instruction `at` (function, pc).
#[allow(clippy::too_many_arguments)]
pub(super) fn suld(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    at: (u32, u32),
    geom: TexGeom,
    ty: Ty,
    ds: &[Dst],
    handle: Src,
    coords: &[Src],
    clamp: SurfClamp,
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    cta.counters.textures.surface_loads += 1;
    let h = read(ctx, w, cta, handle);
    let cs: Vec<Lanes> = coords.iter().map(|c| read(ctx, w, cta, *c)).collect();
    let eb = ty.bytes();
    let mut out = vec![[0u64; 32]; ds.len()];
    let mut per_lane = vec![Footprint::new(); 32];
    for l in lanes(exec) {
        let s = surf_of(ctx, h[l], l)?;
        if let Some(a) = surf_addr(s, &cs, geom, eb * ds.len() as u32, clamp, l)? {
            for (k, o) in out.iter_mut().enumerate() {
                let at = a + (k as u32 * eb) as u64;
                let (al, off) = ctx.mem.find(at, eb as u64).ok_or_else(|| out_of_bounds(at, eb, l))?;
                o[l] = al.load(off, eb);
            }
            per_lane[l].push((a, eb * ds.len() as u32, eb));
        }
    }
    observe(cta, w, at, MemOp::Load, &per_lane);
    let f = w.frames.last_mut().expect("frame");
    for (d, v) in ds.iter().zip(&out) {
        write(f, *d, v, exec);
    }
    Ok(())
}

/// `sust.b`, and with `red` the reduction `sured.b`: every lane's element is
/// checked now (out of range, outside every allocation: the lowest such lane
/// faults) and the operation applied with the CTA's global atomics at the
/// round's end, in lane order (`atomic::apply_pending`). `inst`: the
/// instruction (function, pc).
#[allow(clippy::too_many_arguments)]
pub(super) fn sust(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    inst: (u32, u32),
    (geom, ty, red): (TexGeom, Ty, Option<AtomOp>),
    vals: &[Src],
    handle: Src,
    coords: &[Src],
    clamp: SurfClamp,
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    let t = &mut cta.counters.textures;
    *if red.is_some() { &mut t.surface_reductions } else { &mut t.surface_stores } += 1;
    let h = read(ctx, w, cta, handle);
    let cs: Vec<Lanes> = coords.iter().map(|c| read(ctx, w, cta, *c)).collect();
    let vs: Vec<Lanes> = vals.iter().map(|v| read(ctx, w, cta, *v)).collect();
    let eb = ty.bytes();
    // every lane's elements first, in lane order: outside every allocation
    // the lowest such lane faults, before anything is stored
    let mut at = Vec::new();
    let mut per_lane = vec![Footprint::new(); 32];
    for l in lanes(exec) {
        let s = surf_of(ctx, h[l], l)?;
        if let Some(a) = surf_addr(s, &cs, geom, eb * vals.len() as u32, clamp, l)? {
            for k in 0..vals.len() {
                let ak = a + (k as u32 * eb) as u64;
                ctx.mem.find(ak, eb as u64).ok_or_else(|| out_of_bounds(ak, eb, l))?;
                at.push((l, k, ak));
            }
            per_lane[l].push((a, eb * vals.len() as u32, eb));
        }
    }
    if let Some(op) = red {
        if eb > 1 && at.iter().any(|&(_, _, a)| a % eb as u64 != 0) {
            let &(l, _, a) = at.iter().find(|&&(_, _, a)| a % eb as u64 != 0).expect("found");
            return Err(fault(FaultKind::Misaligned { space: MemSpace::Global, addr: a, size: eb }, Some(l)));
        }
        observe(cta, w, inst, MemOp::Reduction, &per_lane);
        let lanes = at.iter().map(|&(l, k, a)| (l as u8, a, vs[k][l], 0)).collect::<Vec<_>>();
        if !lanes.is_empty() {
            cta.pending.push(super::atomic::PendingAtomic { warp: w.id, op, ty, d: None, lanes });
        }
        return Ok(());
    }
    observe(cta, w, inst, MemOp::Store, &per_lane);
    // lanes storing to one element: the lowest lane's value stays (the H200's order)
    for &(l, k, ak) in at.iter().rev() {
        if let Some((al, off)) = ctx.mem.find(ak, eb as u64) {
            al.store(off, eb, vs[k][l]);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::ptx::ir::MemSpace;
    use crate::sim::fault::FaultKind;
    use crate::sim::texture::{AddressMode, FilterMode, Object, ReadMode, SurfaceDesc, TexelFormat, TextureDesc};
    use crate::sim::{Arg, Device, DevicePtr, LaunchConfig, SimError};

    /// Lane 0 fetches texel 2 of a 1-D texture, loads and stores the element
    /// at byte 4 of row 1 of a surface (`.trap`: in range of its extent).
    const PTX: &str = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry fetch(.param .u64 h)\n{\n.reg .b64 %rd<2>;\n.reg .b32 %r<2>;\n.reg .f32 %f<5>;\n\
        ld.param.u64 %rd1, [h];\nmov.b32 %r1, 2;\ntex.1d.v4.f32.s32 {%f1, %f2, %f3, %f4}, [%rd1, {%r1}];\nret;\n}\n\
        .visible .entry load(.param .u64 h)\n{\n.reg .b64 %rd<2>;\n.reg .b32 %r<4>;\n\
        ld.param.u64 %rd1, [h];\nmov.b32 %r1, 4;\nmov.b32 %r2, 1;\nsuld.b.2d.b32.trap {%r3}, [%rd1, {%r1, %r2}];\nret;\n}\n\
        .visible .entry store(.param .u64 h)\n{\n.reg .b64 %rd<2>;\n.reg .b32 %r<4>;\n\
        ld.param.u64 %rd1, [h];\nmov.b32 %r1, 4;\nmov.b32 %r2, 1;\nmov.b32 %r3, 7;\n\
        sust.b.2d.b32.trap [%rd1, {%r1, %r2}], {%r3};\nret;\n}\n";

    /// A texel or surface element outside every allocation faults as a global
    /// access out of bounds does (it read 0 and dropped the store).
    #[test]
    fn texels_and_surface_elements_outside_every_allocation_fault() {
        let mut dev = Device::new();
        let m = dev.load_ptx(PTX, "oob.ptx").unwrap();
        let nowhere = 0xdead_0000_0000u64;
        assert!(dev.memory().find(nowhere, 64).is_none());
        let tex = dev.create_object_unchecked(Object::Texture(TextureDesc {
            data: DevicePtr(nowhere),
            format: TexelFormat::F32,
            channels: 1,
            dims: [4, 0, 0],
            row_pitch: 0,
            linear: true,
            addr: [AddressMode::Clamp; 3],
            filter: FilterMode::Point,
            read: ReadMode::ElementType,
            normalized: false,
        }));
        let surf = dev.create_object_unchecked(Object::Surface(SurfaceDesc {
            data: DevicePtr(nowhere),
            elem_bytes: 4,
            dims: [2, 2, 0],
            row_pitch: 0,
        }));
        // texel 2: 8 bytes in; surface byte 4 of row 1 (8-byte rows): 12 bytes in
        for (kernel, h, addr) in
            [("fetch", tex, nowhere + 8), ("load", surf, nowhere + 12), ("store", surf, nowhere + 12)]
        {
            let r = dev.launch(&m, kernel, LaunchConfig::linear(1, 1), &[Arg::U64(h)]);
            let Err(SimError::Fault(f)) = r else { panic!("{kernel}: expected a fault, got {r:?}") };
            assert_eq!(f.kind, FaultKind::OutOfBounds { space: MemSpace::Global, addr, size: 4 }, "{kernel}");
            assert_eq!(f.lane, Some(0), "{kernel}");
        }
    }

    /// Lane 0 stores 7 to element (0, 0) of its surface, lane 1 to its own.
    const STORE2: &str = ".version 7.8\n.target sm_90\n.address_size 64\n\
        .visible .entry store2(.param .u64 h0, .param .u64 h1)\n{\n.reg .pred %p<2>;\n.reg .b64 %rd<4>;\n\
        .reg .b32 %r<4>;\nld.param.u64 %rd1, [h0];\nld.param.u64 %rd2, [h1];\nmov.u32 %r1, %tid.x;\n\
        setp.eq.u32 %p1, %r1, 0;\nselp.b64 %rd3, %rd1, %rd2, %p1;\nmov.b32 %r2, 0;\nmov.b32 %r3, 7;\n\
        sust.b.2d.b32.trap [%rd3, {%r2, %r2}], {%r3};\nret;\n}\n";

    /// A `sust` whose lane 1 stores outside every allocation faults on lane 1
    /// and stores nothing, not even lane 0's element, which is in range.
    #[test]
    fn a_surface_store_faulting_in_a_later_lane_stores_nothing() {
        let mut dev = Device::new();
        let m = dev.load_ptx(STORE2, "store2.ptx").unwrap();
        let data = dev.alloc_from(&[0x11u32; 4]);
        let nowhere = 0xdead_0000_0000u64;
        assert!(dev.memory().find(nowhere, 64).is_none());
        let surf = |dev: &mut Device, data| {
            dev.create_object_unchecked(Object::Surface(SurfaceDesc {
                data,
                elem_bytes: 4,
                dims: [2, 2, 0],
                row_pitch: 0,
            }))
        };
        let (good, bad) = (surf(&mut dev, data), surf(&mut dev, DevicePtr(nowhere)));
        let r = dev.launch(&m, "store2", LaunchConfig::linear(1, 2), &[Arg::U64(good), Arg::U64(bad)]);
        let Err(SimError::Fault(f)) = r else { panic!("expected a fault, got {r:?}") };
        assert_eq!(f.kind, FaultKind::OutOfBounds { space: MemSpace::Global, addr: nowhere, size: 4 });
        assert_eq!(f.lane, Some(1));
        assert_eq!(dev.read::<u32>(data, 4), [0x11; 4], "lane 0's element was stored");
        // both lanes in range: both store
        let r = dev.launch(&m, "store2", LaunchConfig::linear(1, 2), &[Arg::U64(good), Arg::U64(good)]);
        r.unwrap();
        assert_eq!(dev.read::<u32>(data, 4), [7, 0x11, 0x11, 0x11]);
    }
}
