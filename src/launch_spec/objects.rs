//! Texture and surface objects in a launch spec: `[[texture]]` and
//! `[[surface]]` tables describe what `cudaCreateTextureObject` /
//! `cudaCreateSurfaceObject` would over a `[[buffer]]` holding the texels
//! (row-major, x fastest, channels innermost: `src/sim/texture.rs`). A
//! kernel argument naming the object passes its 64-bit handle
//! (`cudaTextureObject_t`, `cudaSurfaceObject_t`).
//!
//! ```toml
//! [[texture]]
//! name = "tex"                 # what `args` names
//! buffer = "texels"            # the [[buffer]] holding the texels
//! format = "f32"               # u8 s8 u16 s16 u32 s32 f16 f32 (one channel)
//! channels = 1                 # 1, 2 or 4
//! width = 8                    # height and depth for 2-D and 3-D textures
//! address = "clamp"            # clamp | border | wrap | mirror, or one per dimension
//! filter = "linear"            # point | linear
//! read = "element"             # element | normalized (8- and 16-bit integers as [0, 1] floats)
//! normalized_coords = false    # coordinates in [0, 1) instead of texels
//! # linear = true              # a linear-memory resource (tex1Dfetch): 1-D, reads zeros out of range
//! # row_pitch = 64             # bytes between rows (default: packed)
//! [[surface]]
//! name = "surf"
//! buffer = "image"
//! format = "s32"
//! width = 8
//! height = 4
//! ```

use super::{BufferSpec, Ctx, SpecError};
use crate::sim::DevicePtr;
use crate::sim::texture::{
    AddressMode, FilterMode, Object, ReadMode, ReadSetting, SurfaceDesc, TexelFormat, TextureDesc, read_setting_error,
};

/// The keys of a `[[texture]]` table.
const TEXTURE_KEYS: [&str; 13] = [
    "name",
    "buffer",
    "format",
    "channels",
    "width",
    "height",
    "depth",
    "row_pitch",
    "address",
    "filter",
    "read",
    "normalized_coords",
    "linear",
];

/// The keys of a `[[surface]]` table.
const SURFACE_KEYS: [&str; 8] = ["name", "buffer", "format", "channels", "width", "height", "depth", "row_pitch"];

/// A texture or surface object of a spec.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSpec {
    /// Its name (what `args` names).
    pub name: String,
    /// The buffer holding its texels.
    pub buffer: String,
    /// The object, its `data` pointer still unset (0) until the buffer is allocated.
    pub object: Object,
}

impl ObjectSpec {
    /// The object over texels at `data`.
    pub fn at(&self, data: DevicePtr) -> Object {
        match &self.object {
            Object::Texture(t) => Object::Texture(TextureDesc { data, ..t.clone() }),
            Object::Surface(s) => Object::Surface(SurfaceDesc { data, ..s.clone() }),
        }
    }
}

fn format(s: &str) -> Option<TexelFormat> {
    Some(match s {
        "u8" => TexelFormat::U8,
        "s8" | "i8" => TexelFormat::S8,
        "u16" => TexelFormat::U16,
        "s16" | "i16" => TexelFormat::S16,
        "u32" => TexelFormat::U32,
        "s32" | "i32" => TexelFormat::S32,
        "f16" => TexelFormat::F16,
        "f32" => TexelFormat::F32,
        _ => return None,
    })
}

fn address(s: &str) -> Option<AddressMode> {
    Some(match s {
        "clamp" => AddressMode::Clamp,
        "border" => AddressMode::Border,
        "wrap" => AddressMode::Wrap,
        "mirror" => AddressMode::Mirror,
        _ => return None,
    })
}

/// What the texels of an object span.
struct Layout {
    format: TexelFormat,
    channels: u32,
    dims: [u32; 3],
    row_pitch: u64,
}

impl Ctx<'_> {
    /// The `[[texture]]` and `[[surface]]` tables of `t`, checked against `buffers`.
    pub(super) fn objects(&self, t: &toml::Table, buffers: &[BufferSpec]) -> Result<Vec<ObjectSpec>, SpecError> {
        let mut out: Vec<ObjectSpec> = Vec::new();
        for key in ["texture", "surface"] {
            let Some(v) = t.get(key) else { continue };
            let Some(arr) = v.as_array() else { return self.err(key, format!("expected [[{key}]] tables")) };
            for (i, v) in arr.iter().enumerate() {
                let at = format!("{key}[{i}]");
                let Some(ot) = v.as_table() else { return self.err(&at, "expected a table") };
                let keys: &[&str] = if key == "texture" { &TEXTURE_KEYS } else { &SURFACE_KEYS };
                self.known_keys(ot, keys, &format!("{at}."))?;
                let o = self.object(ot, &at, key == "texture", buffers)?;
                if buffers.iter().any(|b| b.name == o.name) || out.iter().any(|x| x.name == o.name) {
                    return self.err(&format!("{at}.name"), format!("`{}` names a buffer or object already", o.name));
                }
                out.push(o);
            }
        }
        Ok(out)
    }

    fn object(
        &self,
        t: &toml::Table,
        at: &str,
        texture: bool,
        buffers: &[BufferSpec],
    ) -> Result<ObjectSpec, SpecError> {
        let k = |f: &str| format!("{at}.{f}");
        let string = |f: &str| t.get(f).and_then(|v| v.as_str());
        let Some(name) = string("name") else { return self.err(&k("name"), "missing") };
        let Some(buffer) = string("buffer") else {
            return self.err(&k("buffer"), "missing; expected the [[buffer]] holding the texels");
        };
        let Some(b) = buffers.iter().find(|b| b.name == buffer) else {
            return self.err(&k("buffer"), format!("no buffer named `{buffer}`"));
        };
        let Some(format) = string("format").and_then(format) else {
            return self.err(&k("format"), "expected one of u8 s8 u16 s16 u32 s32 f16 f32");
        };
        let uint = |f: &str, default: Option<u64>| -> Result<Option<u64>, SpecError> {
            match t.get(f) {
                None => Ok(default),
                Some(v) => match v.as_integer() {
                    Some(x) if x >= 1 && x <= u32::MAX as i64 => Ok(Some(x as u64)),
                    _ => self.err(&k(f), "expected a positive integer"),
                },
            }
        };
        let channels = uint("channels", Some(1))?.unwrap_or(1) as u32;
        if ![1, 2, 4].contains(&channels) {
            return self.err(&k("channels"), "expected 1, 2 or 4 (CUDA's channel counts)");
        }
        let Some(width) = uint("width", None)? else { return self.err(&k("width"), "missing; expected texels") };
        let height = uint("height", None)?;
        let depth = uint("depth", None)?;
        if depth.is_some() && height.is_none() {
            return self.err(&k("depth"), "a 3-D object needs a height too");
        }
        let dims = [width as u32, height.unwrap_or(0) as u32, depth.unwrap_or(0) as u32];
        let texel = format.bytes() as u64 * channels as u64;
        let row_pitch = match uint("row_pitch", None)? {
            None => 0,
            Some(_) if height.is_none() => return self.err(&k("row_pitch"), "a 1-D object has no rows"),
            Some(p) if p < width * texel => {
                return self.err(&k("row_pitch"), format!("{p} bytes is less than a row ({width} × {texel} bytes)"));
            }
            Some(p) => p,
        };
        let lay = Layout { format, channels, dims, row_pitch };
        self.fits(&lay, b, &k("buffer"))?;
        let object = if texture {
            self.texture(t, at, lay)?
        } else {
            Object::Surface(SurfaceDesc {
                data: DevicePtr(0),
                elem_bytes: texel as u32,
                dims: lay.dims,
                row_pitch: lay.row_pitch,
            })
        };
        Ok(ObjectSpec { name: name.to_string(), buffer: buffer.to_string(), object })
    }

    /// An error unless buffer `b` holds every texel of `lay`.
    fn fits(&self, lay: &Layout, b: &BufferSpec, key: &str) -> Result<(), SpecError> {
        let texel = lay.format.bytes() as u64 * lay.channels as u64;
        let [w, h, d] = lay.dims.map(|x| x.max(1) as u64);
        let shape = format!("{w} × {h} × {d} texels of {texel} bytes");
        // the last row needs only its texels, not the whole pitch
        let need = w.checked_mul(texel).and_then(|row| {
            let pitch = if lay.row_pitch == 0 { row } else { lay.row_pitch };
            pitch.checked_mul(h * d - 1)?.checked_add(row)
        });
        let Some(need) = need else {
            return self.err(key, format!("the object's texels span more than 2^64 bytes ({shape})"));
        };
        let have = (b.len as u64).saturating_mul(b.ty.size() as u64);
        if have < need {
            return self.err(key, format!("`{}` has {have} bytes; the object's texels span {need} ({shape})", b.name));
        }
        Ok(())
    }

    fn texture(&self, t: &toml::Table, at: &str, lay: Layout) -> Result<Object, SpecError> {
        let k = |f: &str| format!("{at}.{f}");
        let choice = |f: &str, default: &str, options: &[&str]| -> Result<String, SpecError> {
            match t.get(f) {
                None => Ok(default.to_string()),
                Some(v) => match v.as_str() {
                    Some(s) if options.contains(&s) => Ok(s.to_string()),
                    _ => self.err(&k(f), format!("expected one of {}", options.join(", "))),
                },
            }
        };
        let flag = |f: &str| -> Result<bool, SpecError> {
            match t.get(f) {
                None => Ok(false),
                Some(v) => v.as_bool().map_or_else(|| self.err(&k(f), "expected true or false"), Ok),
            }
        };
        let filter = if choice("filter", "point", &["point", "linear"])? == "linear" {
            FilterMode::Linear
        } else {
            FilterMode::Point
        };
        let read = if choice("read", "element", &["element", "normalized"])? == "normalized" {
            ReadMode::NormalizedFloat
        } else {
            ReadMode::ElementType
        };
        let normalized = flag("normalized_coords")?;
        let linear = flag("linear")?;
        const MODES: &str = "expected clamp, border, wrap or mirror, or an array of them (one per dimension)";
        let modes: Vec<AddressMode> = match t.get("address") {
            None => vec![AddressMode::Clamp],
            Some(toml::Value::String(s)) => match address(s) {
                Some(m) => vec![m],
                None => return self.err(&k("address"), MODES),
            },
            Some(toml::Value::Array(a)) if (1..=3).contains(&a.len()) => {
                match a.iter().map(|v| v.as_str().and_then(address)).collect::<Option<Vec<_>>>() {
                    Some(m) => m,
                    None => return self.err(&k("address"), MODES),
                }
            }
            Some(_) => return self.err(&k("address"), MODES),
        };
        // one mode for every dimension, or one per dimension (the last repeated)
        let addr = [0, 1, 2].map(|d| modes[d.min(modes.len() - 1)]);
        if !normalized && modes.iter().any(|m| matches!(m, AddressMode::Wrap | AddressMode::Mirror)) {
            return self.err(
                &k("address"),
                "wrap and mirror need normalized_coords = true (CUDA supports them with normalized coordinates only)",
            );
        }
        if let Some((setting, why)) = read_setting_error(lay.format, filter, read) {
            let key = match setting {
                ReadSetting::Read => "read",
                ReadSetting::Filter => "filter",
            };
            return self.err(&k(key), why);
        }
        if linear && lay.dims[1] != 0 {
            return self.err(&k("linear"), "a linear-memory texture is 1-D (no height)");
        }
        Ok(Object::Texture(TextureDesc {
            data: DevicePtr(0),
            format: lay.format,
            channels: lay.channels,
            dims: lay.dims,
            row_pitch: lay.row_pitch,
            linear,
            addr,
            filter,
            read,
            normalized,
        }))
    }
}
