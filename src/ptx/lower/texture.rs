//! Texture and surface objects: `tex`, `tld4`, `txq`, `suld.b`, `sust.b`, `sured.b`
//! through a 64-bit object handle in a register (`cudaTextureObject_t`,
//! `cudaSurfaceObject_t`), as nvcc and clang write them for `tex2D<T>(obj, x,
//! y)`, `tex2Dgather`, `surf2Dread`/`surf2Dwrite`. Texture references
//! (`.texref` variables), mipmaps, layered and cube textures are not lowered.

use super::opcode::{Decoded, Opcode};
use super::validate::operands;
use super::{FnLower, LResult, invalid, unsupported};
use crate::ptx::ast::{self, Operand};
use crate::ptx::ir::*;
use crate::ptx::types::Ty;

/// The geometry word of a texture or surface instruction.
fn geom(d: &Decoded) -> Option<TexGeom> {
    d.mods.words.iter().find_map(|w| match w.as_str() {
        "1d" => Some(TexGeom::D1),
        "2d" => Some(TexGeom::D2),
        "3d" => Some(TexGeom::D3),
        _ => None,
    })
}

/// The `txq` query word.
fn query(w: &str) -> Option<TxqQuery> {
    Some(match w {
        "width" => TxqQuery::Width,
        "height" => TxqQuery::Height,
        "depth" => TxqQuery::Depth,
        "channel_data_type" => TxqQuery::ChannelDataType,
        "channel_order" => TxqQuery::ChannelOrder,
        "normalized_coords" => TxqQuery::NormalizedCoords,
        "filter_mode" => TxqQuery::FilterMode,
        "addr_mode_0" => TxqQuery::AddrMode0,
        "addr_mode_1" => TxqQuery::AddrMode1,
        "addr_mode_2" => TxqQuery::AddrMode2,
        "array_size" => TxqQuery::ArraySize,
        "num_mipmap_levels" => TxqQuery::NumMipmapLevels,
        "num_samples" => TxqQuery::NumSamples,
        _ => return None,
    })
}

/// The out-of-range mode of a surface instruction (`.trap` when none is written).
fn clamp_mode(d: &Decoded) -> SurfClamp {
    if d.mods.has("clamp") {
        SurfClamp::Clamp
    } else if d.mods.has("zero") {
        SurfClamp::Zero
    } else {
        SurfClamp::Trap
    }
}

/// The operation of `sured.b.op` (`None` without exactly one).
fn sured_op(d: &Decoded) -> Option<AtomOp> {
    let ops: Vec<AtomOp> = d
        .mods
        .words
        .iter()
        .filter_map(|w| match w.as_str() {
            "add" => Some(AtomOp::Add),
            "min" => Some(AtomOp::Min),
            "max" => Some(AtomOp::Max),
            "and" => Some(AtomOp::And),
            "or" => Some(AtomOp::Or),
            _ => None,
        })
        .collect();
    match ops.as_slice() {
        [op] => Some(*op),
        _ => None,
    }
}

/// Coordinates a geometry takes as written (`.3d` pads to four).
fn coord_count(g: TexGeom) -> usize {
    match g {
        TexGeom::D1 => 1,
        TexGeom::D2 => 2,
        TexGeom::D3 => 4,
    }
}

/// Fails when a word of `d` is neither in `allowed` nor a geometry.
fn only(d: &Decoded, allowed: &[&str], i: &ast::Instruction) -> LResult<()> {
    for w in &d.mods.words {
        if !allowed.contains(&w.as_str()) && !matches!(w.as_str(), "1d" | "2d" | "3d") {
            return unsupported(i.pos, format!("{} (modifier .{w})", d.full));
        }
    }
    Ok(())
}

/// The coordinates of a `[handle, {coords}]` operand, checked against the geometry.
fn tex_addr<'a>(op: &'a Operand, g: TexGeom, d: &Decoded, i: &ast::Instruction) -> LResult<&'a [Operand]> {
    let Operand::TexAddr(_, c) = op else {
        return invalid(i.pos, format!("`{}` needs `[object, {{coordinates}}]`", d.full));
    };
    if c.len() != coord_count(g) {
        return invalid(i.pos, format!("`{}` takes {} coordinate(s), found {}", d.full, coord_count(g), c.len()));
    }
    Ok(c)
}

/// Checks the shape of a texture or surface instruction.
pub(super) fn validate(d: &Decoded, i: &ast::Instruction) -> LResult<()> {
    let pos = i.pos;
    let m = &d.mods;
    let Some(g) = geom(d) else {
        return match d.op {
            Opcode::Txq => {
                only(d, &[], i).ok();
                operands(i, 2)?;
                if m.words.len() != 1 || query(&m.words[0]).is_none() {
                    return unsupported(pos, d.full.clone());
                }
                if m.types.as_slice() != [Ty::B32] {
                    return invalid(pos, format!("`{}` needs .b32", d.full));
                }
                if !matches!(i.operands[1], Operand::Addr(Some(_), 0)) {
                    return invalid(pos, format!("`{}` needs `[object]`", d.full));
                }
                Ok(())
            }
            // a1d, a2d, cube, 2dms ...: not lowered
            _ => unsupported(pos, d.full.clone()),
        };
    };
    operands(i, 2)?;
    match d.op {
        Opcode::Tex | Opcode::Tld4 => {
            let comps: &[&str] = if d.op == Opcode::Tld4 { &["v4", "r", "g", "b", "a"] } else { &["v4"] };
            only(d, comps, i)?;
            if !m.has("v4") {
                return unsupported(pos, d.full.clone());
            }
            if d.op == Opcode::Tld4
                && (g != TexGeom::D2
                    || m.words.iter().filter(|w| matches!(w.as_str(), "r" | "g" | "b" | "a")).count() != 1)
            {
                return invalid(pos, format!("`{}` needs .2d and one of .r .g .b .a", d.full));
            }
            let [dty, cty] = m.types.as_slice() else {
                return invalid(pos, format!("`{}` needs a result and a coordinate type", d.full));
            };
            if !matches!(dty, Ty::F32 | Ty::S32 | Ty::U32) || !matches!(cty, Ty::F32 | Ty::S32) {
                return unsupported(pos, d.full.clone());
            }
            if d.op == Opcode::Tld4 && *cty != Ty::F32 {
                return invalid(pos, format!("`{}` takes .f32 coordinates", d.full));
            }
            match &i.operands[0] {
                Operand::Vector(v) if v.len() == 4 => {}
                _ => return invalid(pos, format!("`{}` writes four registers", d.full)),
            }
            tex_addr(&i.operands[1], g, d, i)?;
        }
        Opcode::Sured => {
            only(d, &["b", "add", "min", "max", "and", "or", "trap", "clamp", "zero"], i)?;
            if !m.has("b") {
                return unsupported(pos, format!("{} (formatted surface reduction)", d.full));
            }
            let Some(op) = sured_op(d) else {
                return invalid(pos, format!("`{}` needs one of .add .min .max .and .or", d.full));
            };
            let t = match m.types.as_slice() {
                [t] => *t,
                _ => return invalid(pos, format!("`{}` needs one type", d.full)),
            };
            // the PTX ISA's types per operation (`.b64` is `sured.p`'s alone)
            let ok = match op {
                AtomOp::And | AtomOp::Or => t == Ty::B32,
                AtomOp::Add => matches!(t, Ty::U32 | Ty::U64 | Ty::S32),
                _ => matches!(t, Ty::U32 | Ty::U64 | Ty::S32 | Ty::S64),
            };
            if !ok {
                return invalid(
                    pos,
                    format!("`{}`: .add takes .u32 .u64 .s32, .min .max .u32 .u64 .s32 .s64, .and .or .b32", d.full),
                );
            }
            if i.operands.len() != 2 || matches!(i.operands[1], Operand::Vector(_)) {
                return invalid(pos, format!("`{}` takes an address and one value", d.full));
            }
            tex_addr(&i.operands[0], g, d, i)?;
        }
        Opcode::Suld | Opcode::Sust => {
            only(d, &["b", "v2", "v4", "trap", "clamp", "zero"], i)?;
            if !m.has("b") {
                return unsupported(pos, format!("{} (formatted surface access)", d.full));
            }
            let t = match m.types.as_slice() {
                [t] => *t,
                _ => return invalid(pos, format!("`{}` needs one type", d.full)),
            };
            if !matches!(t, Ty::B8 | Ty::B16 | Ty::B32 | Ty::B64) {
                return invalid(pos, format!("`{}` takes .b8 .b16 .b32 .b64", d.full));
            }
            let (vals, addr) =
                if d.op == Opcode::Suld { (&i.operands[0], &i.operands[1]) } else { (&i.operands[1], &i.operands[0]) };
            let n = match vals {
                Operand::Vector(v) => v.len(),
                _ => 1,
            };
            if n != m.vec() as usize {
                return invalid(pos, format!("`{}` moves {} value(s), found {n}", d.full, m.vec()));
            }
            tex_addr(addr, g, d, i)?;
        }
        _ => return unsupported(pos, d.full.clone()),
    }
    Ok(())
}

impl FnLower<'_> {
    /// The object handle of `[handle, ...]` / `[handle]`.
    fn handle(&self, name: &str, pos: crate::ptx::error::Pos) -> LResult<Src> {
        self.src(&Operand::Name(name.to_string()), Ty::U64, pos)
    }

    /// Lowers a validated texture or surface instruction.
    pub(super) fn lower_texture(&self, i: &ast::Instruction, d: &Decoded) -> LResult<Kind> {
        let (pos, ops, m) = (i.pos, &i.operands, &d.mods);
        let vec_of = |o: &Operand| -> Vec<Operand> {
            match o {
                Operand::Vector(v) => v.clone(),
                one => vec![one.clone()],
            }
        };
        if d.op == Opcode::Txq {
            let Operand::Addr(Some(h), _) = &ops[1] else { unreachable!("validated") };
            let q = query(&m.words[0]).expect("validated");
            return Ok(Kind::Txq { query: q, d: self.dst(&ops[0], pos)?, handle: self.handle(h, pos)? });
        }
        let g = geom(d).expect("validated");
        let (addr, vals) =
            if matches!(d.op, Opcode::Sust | Opcode::Sured) { (&ops[0], &ops[1]) } else { (&ops[1], &ops[0]) };
        let Operand::TexAddr(h, c) = addr else { unreachable!("validated") };
        let handle = self.handle(h, pos)?;
        match d.op {
            Opcode::Tex | Opcode::Tld4 => {
                let (dty, cty) = (m.types[0], m.types[1]);
                let coords = c[..g.dims()].iter().map(|o| self.src(o, cty, pos)).collect::<LResult<Vec<_>>>()?;
                let ds = vec_of(vals).iter().map(|o| self.dst(o, pos)).collect::<LResult<Vec<_>>>()?;
                let gather = (d.op == Opcode::Tld4)
                    .then(|| ["r", "g", "b", "a"].iter().position(|w| m.has(w)).expect("validated") as u8);
                Ok(Kind::Tex { geom: g, gather, dty, cty, ds, handle, coords })
            }
            _ => {
                let t = m.types[0];
                let coords = c[..g.dims()].iter().map(|o| self.src(o, Ty::S32, pos)).collect::<LResult<Vec<_>>>()?;
                let clamp = clamp_mode(d);
                if d.op == Opcode::Suld {
                    let ds = vec_of(vals).iter().map(|o| self.dst(o, pos)).collect::<LResult<Vec<_>>>()?;
                    Ok(Kind::Suld { geom: g, ty: t, ds, handle, coords, clamp })
                } else {
                    let vs = vec_of(vals).iter().map(|o| self.src(o, t, pos)).collect::<LResult<Vec<_>>>()?;
                    let red = if d.op == Opcode::Sured { sured_op(d) } else { None };
                    Ok(Kind::Sust { geom: g, ty: t, vals: vs, handle, coords, clamp, red })
                }
            }
        }
    }
}
