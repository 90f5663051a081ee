//! Texture and surface instructions (`tex`, `tld4`, `txq`, `suld.b`,
//! `sust.b`): each lane's object handle names a texture or surface object of
//! the device ([`crate::sim::texture`]); texels are read from and written to
//! device memory.

use super::{CtaMut, Ctx, ExecFault, Lanes, fault, read, write};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;
use crate::sim::fault::FaultKind;
use crate::sim::texture::{self, Object, SurfaceDesc, TextureDesc};
use crate::sim::warp::Warp;

/// Loads `size` bytes of device memory at `addr` (0 outside every allocation).
fn load(ctx: &Ctx, addr: u64, size: u32) -> u64 {
    ctx.mem.find(addr, size as u64).map(|(a, off)| a.load(off, size)).unwrap_or(0)
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

/// `tex` / `tld4`.
#[allow(clippy::too_many_arguments)]
pub(super) fn tex(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
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
    let rd = |a: u64, n: u32| load(ctx, a, n);
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
        for c in 0..4 {
            out[c][l] = v[c] as u64;
        }
    }
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
/// out of range); `.trap` out of range faults.
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
    if a.is_none() && clamp == SurfClamp::Trap {
        return Err(fault(
            FaultKind::Unsupported(format!("surface access out of range at ({}, {}, {}) with .trap", x[0], x[1], x[2])),
            Some(l),
        ));
    }
    Ok(a)
}

/// `suld.b`.
#[allow(clippy::too_many_arguments)]
pub(super) fn suld(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
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
    for l in lanes(exec) {
        let s = surf_of(ctx, h[l], l)?;
        if let Some(a) = surf_addr(s, &cs, geom, eb * ds.len() as u32, clamp, l)? {
            for (k, o) in out.iter_mut().enumerate() {
                o[l] = load(ctx, a + (k as u32 * eb) as u64, eb);
            }
        }
    }
    let f = w.frames.last_mut().expect("frame");
    for (d, v) in ds.iter().zip(&out) {
        write(f, *d, v, exec);
    }
    Ok(())
}

/// `sust.b`.
#[allow(clippy::too_many_arguments)]
pub(super) fn sust(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    geom: TexGeom,
    ty: Ty,
    vals: &[Src],
    handle: Src,
    coords: &[Src],
    clamp: SurfClamp,
    exec: u32,
) -> Result<(), Box<ExecFault>> {
    cta.counters.textures.surface_stores += 1;
    let h = read(ctx, w, cta, handle);
    let cs: Vec<Lanes> = coords.iter().map(|c| read(ctx, w, cta, *c)).collect();
    let vs: Vec<Lanes> = vals.iter().map(|v| read(ctx, w, cta, *v)).collect();
    let eb = ty.bytes();
    // lanes storing to one element: the lowest lane's value stays (the H200's order)
    for l in lanes(exec).collect::<Vec<_>>().into_iter().rev() {
        let s = surf_of(ctx, h[l], l)?;
        if let Some(a) = surf_addr(s, &cs, geom, eb * vals.len() as u32, clamp, l)? {
            for (k, v) in vs.iter().enumerate() {
                let at = a + (k as u32 * eb) as u64;
                if let Some((al, off)) = ctx.mem.find(at, eb as u64) {
                    al.store(off, eb, v[l]);
                }
            }
        }
    }
    Ok(())
}
