//! Texture and surface objects: what `cudaCreateTextureObject` /
//! `cudaCreateSurfaceObject` describe, held by the [`Device`](super::Device)
//! and named in kernels by a 64-bit handle, and the sampling the texture unit
//! does (addressing, point and linear filtering, read modes), as the CUDA
//! Programming Guide's "Texture Fetching" appendix defines it and an H200
//! measured it (`tests/textures.rs`, `docs/semantics.md`).
//!
//! Texels live in device memory, row-major (x fastest, channels innermost),
//! rows `row_pitch` bytes apart and slices `row_pitch × height` apart: the
//! emulator's layout of a CUDA array (the GPU's is opaque).

use super::device::DevicePtr;

/// The type of one channel of a texel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum TexelFormat {
    U8,
    S8,
    U16,
    S16,
    U32,
    S32,
    F16,
    F32,
}

impl TexelFormat {
    /// Bytes of one channel.
    pub fn bytes(self) -> u32 {
        match self {
            TexelFormat::U8 | TexelFormat::S8 => 1,
            TexelFormat::U16 | TexelFormat::S16 | TexelFormat::F16 => 2,
            TexelFormat::U32 | TexelFormat::S32 | TexelFormat::F32 => 4,
        }
    }

    /// A floating-point format (f16, f32).
    pub fn is_float(self) -> bool {
        matches!(self, TexelFormat::F16 | TexelFormat::F32)
    }

    /// An 8- or 16-bit integer format (the ones a normalized read converts).
    pub fn is_small_int(self) -> bool {
        matches!(self, TexelFormat::U8 | TexelFormat::S8 | TexelFormat::U16 | TexelFormat::S16)
    }

    /// The `txq.channel_data_type` value (CUDA's `cudaChannelFormatKind`-like
    /// code the PTX ISA leaves to the driver; warplight's numbering).
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// What a coordinate outside the texture reads (`cudaTextureAddressMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum AddressMode {
    Wrap,
    Clamp,
    Mirror,
    Border,
}

/// Point or linear filtering (`cudaTextureFilterMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum FilterMode {
    Point,
    Linear,
}

/// Whether 8- and 16-bit integer texels are returned as integers or scaled
/// to [0, 1] ([-1, 1] signed) floats (`cudaTextureReadMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ReadMode {
    ElementType,
    NormalizedFloat,
}

/// A texture object's resource and sampler.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureDesc {
    /// The first texel.
    pub data: DevicePtr,
    /// Channel type.
    pub format: TexelFormat,
    /// Channels per texel (1, 2 or 4).
    pub channels: u32,
    /// Width, height, depth in texels (0 for absent dimensions).
    pub dims: [u32; 3],
    /// Bytes between rows (0: packed, width × texel bytes).
    pub row_pitch: u64,
    /// A linear-memory resource (`cudaResourceTypeLinear`, `tex1Dfetch`):
    /// integer coordinates out of range read zeros.
    pub linear: bool,
    /// Address mode per dimension.
    pub addr: [AddressMode; 3],
    /// Filtering.
    pub filter: FilterMode,
    /// Read mode.
    pub read: ReadMode,
    /// Coordinates in [0, 1) instead of texels.
    pub normalized: bool,
}

/// A surface object: texels read and written by byte coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceDesc {
    /// The first element.
    pub data: DevicePtr,
    /// Bytes of one element.
    pub elem_bytes: u32,
    /// Width, height, depth in elements (0 for absent dimensions).
    pub dims: [u32; 3],
    /// Bytes between rows (0: packed).
    pub row_pitch: u64,
}

/// A texture or surface object.
#[derive(Debug, Clone, PartialEq)]
pub enum Object {
    /// `cudaTextureObject_t`.
    Texture(TextureDesc),
    /// `cudaSurfaceObject_t`.
    Surface(SurfaceDesc),
}

/// The handle of the `i`-th object (0 is never a handle, as in CUDA).
pub fn handle_of(i: usize) -> u64 {
    i as u64 + 1
}

/// The object of `handle`.
pub fn object(objects: &[Object], handle: u64) -> Option<&Object> {
    objects.get((handle as usize).wrapping_sub(1))
}

/// The size of dimension `d` (1 for absent ones).
fn size(dims: [u32; 3], d: usize) -> i64 {
    dims[d].max(1) as i64
}

/// Texel index `i` of a dimension of `n` texels under `mode`; `None` for a
/// border texel (reads zeros).
pub fn address(i: i64, n: i64, mode: AddressMode) -> Option<i64> {
    match mode {
        AddressMode::Clamp => Some(i.clamp(0, n - 1)),
        AddressMode::Border => (0..n).contains(&i).then_some(i),
        AddressMode::Wrap => Some(i.rem_euclid(n)),
        AddressMode::Mirror => {
            let m = i.rem_euclid(2 * n);
            Some(if m >= n { 2 * n - 1 - m } else { m })
        }
    }
}

/// A coordinate in texels: normalized ones scaled by the size; NaN reads as 0
/// and infinities as the largest finite values.
fn texel_coord(x: f32, n: i64, normalized: bool) -> f64 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(f32::MIN, f32::MAX) } as f64;
    let x = if normalized { x * n as f64 } else { x };
    x.clamp(-(2f64.powi(40)), 2f64.powi(40))
}

/// One texel of a texture as four channels of f32 bits (integer formats under
/// the element read mode: the integer, sign-extended), missing channels 0 and
/// the fourth 1.0 (as the hardware fills them).
pub fn texel(t: &TextureDesc, read: &dyn Fn(u64, u32) -> u64, idx: [i64; 3]) -> [u32; 4] {
    let eb = t.format.bytes();
    let tb = eb as u64 * t.channels as u64;
    let pitch = if t.row_pitch == 0 { tb * t.dims[0].max(1) as u64 } else { t.row_pitch };
    let base = t.data.0 + idx[0] as u64 * tb + idx[1] as u64 * pitch + idx[2] as u64 * pitch * t.dims[1].max(1) as u64;
    let int = t.read == ReadMode::ElementType;
    let mut out = [0, 0, 0, 1f32.to_bits()];
    if int && !matches!(t.format, TexelFormat::F16 | TexelFormat::F32) {
        out[3] = 1;
    }
    for (c, o) in out.iter_mut().enumerate().take(t.channels as usize) {
        let v = read(base + c as u64 * eb as u64, eb);
        *o = match t.format {
            TexelFormat::F32 => v as u32,
            TexelFormat::F16 => (super::half::to_f64(v as u16, false) as f32).to_bits(),
            TexelFormat::U8 if !int => (v as f32 / 255.0).to_bits(),
            TexelFormat::U16 if !int => (v as f32 / 65535.0).to_bits(),
            TexelFormat::S8 if !int => ((v as u8 as i8) as f32 / 127.0).max(-1.0).to_bits(),
            TexelFormat::S16 if !int => ((v as u16 as i16) as f32 / 32767.0).max(-1.0).to_bits(),
            TexelFormat::S8 => v as u8 as i8 as i32 as u32,
            TexelFormat::S16 => v as u16 as i16 as i32 as u32,
            _ => v as u32,
        };
    }
    out
}

/// One texel through the address modes (zeros for border texels).
fn fetch(t: &TextureDesc, read: &dyn Fn(u64, u32) -> u64, idx: [i64; 3]) -> [u32; 4] {
    let mut a = [0i64; 3];
    for d in 0..3 {
        match address(idx[d], size(t.dims, d), t.addr[d]) {
            Some(i) => a[d] = i,
            None => return [0; 4],
        }
    }
    texel(t, read, a)
}

/// The linear-filtering footprint along one dimension: the first texel and
/// the weight of the second in 256ths (1.8 fixed point: `256 (x − 0.5)`
/// rounded half up, as the H200 does).
fn footprint(x: f64) -> (i64, u32) {
    let q = ((x - 0.5) * 256.0 + 0.5).floor() as i64;
    (q >> 8, (q & 255) as u32)
}

/// The weights (in 256ths) of the corners of a linear footprint whose
/// second texels weigh `w` along each dimension (one to three); corner `c`
/// takes the second texel along dimension `d` when bit `d` of `c` is set.
///
/// The H200 splits the whole weight, 256, dimension by dimension: in 3-D by
/// z first (`256 − wz`, `wz`), then each part by x, then each of those by y;
/// in 2-D by x, then y. Splitting a part `v` along a dimension of weight `w`
/// gives its second texel `v·w / 256` rounded half up, the first the rest,
/// except that the y split of a part on the first x texel rounds ties down.
/// In 2-D that is `w11 = round(wx·wy)`, `w10 = wx − w11`, `w01 = wy − w11`,
/// `w00 = 256 − wx − wy + w11` (measured on 1-D and 2-D textures); in 3-D
/// the parts of the two z slices are rounded apart, so that the weights
/// along x and y need not sum to `wx` and `wy` (measured on a 3-D texture:
/// the other rules tried were off by up to 2/256). The weights are the first
/// `2^n` entries (the rest are 0).
fn corner_weights(w: &[u32]) -> [i64; 8] {
    let n = w.len();
    // the dimensions in the order they are split: z, x, y
    let order: &[usize] = if n == 3 { &[2, 0, 1] } else { &[0, 1][..n] };
    // corner `c`'s part so far at `out[c]`; splitting along `d` the parts of
    // the corners made of the dimensions split before moves `hi` of each to
    // `c | 1 << d` (the remaining entries stay 0)
    let mut out = [0i64; 8];
    out[0] = 256;
    let mut done = 0usize;
    for &d in order {
        for corner in 0..1usize << n {
            if corner & !done != 0 {
                continue;
            }
            let v = out[corner];
            let tie_down = d == 1 && corner & 1 == 0;
            let hi = (v * w[d] as i64 + if tie_down { 127 } else { 128 }) >> 8;
            out[corner] = v - hi;
            out[corner | 1 << d] = hi;
        }
        done |= 1 << d;
    }
    out
}

/// Bits of significand the texture unit filters a format in: half
/// precision for `f16` texels, single for the rest.
fn filter_precision(f: TexelFormat) -> u32 {
    if f == TexelFormat::F16 { 11 } else { 24 }
}

/// One weighted texel of a linear filter: its weight in 256ths, its value,
/// and the z slice of the footprint it lies in (0 or 1; 0 in 1-D and 2-D).
type Term = (i64, f32, usize);

/// One channel of a linear filter's result, as the H200 computes it for
/// float texels: in each z slice of the footprint (the whole footprint in
/// 1-D and 2-D) the texels (border texels as zeros) aligned to the largest
/// exponent `e` among those that weigh something, keeping `p + 4` bits from
/// there (the rest cut off toward zero), multiplied by their weights and
/// summed exactly; the slices' sums added exactly and the total rounded to
/// `p` bits, ties away from zero. Non-finite texels: the weighted sum in f64
/// (not measured).
fn filter_channel(terms: &[Term], p: u32) -> f32 {
    if terms.iter().any(|(_, v, _)| !v.is_finite()) {
        let s: f64 = terms.iter().map(|&(w, v, _)| w as f64 / 256.0 * v as f64).sum();
        return s as f32;
    }
    // each slice's sum: `sum · 2^(g − 8)`
    let mut slices = [(0i128, 0i32); 2];
    let mut n = 0;
    for z in 0..2 {
        let slice = || terms.iter().filter(move |t| t.2 == z && t.0 != 0);
        let Some(e) = slice().filter(|t| t.1 != 0.0).map(|t| exponent(t.1 as f64)).max() else {
            continue;
        };
        // the grid: 2^(e − (p − 1) − 4); |v| / grid < 2^(p + 4), exact in f64
        let g = e - (p as i32 - 1) - 4;
        let sum: i128 = slice().map(|&(w, v, _)| w as i128 * (v as f64 * 2f64.powi(-g)).trunc() as i128).sum();
        if sum != 0 {
            slices[n] = (sum, g - 8);
            n += 1;
        }
    }
    let (sum, k) = match slices[..n] {
        [] => return 0.0,
        [one] => one,
        [a, b] => add_exact(a, b),
        _ => unreachable!("two slices at most"),
    };
    round_ties_away(sum, k, p)
}

/// `a + b` for `(m, k)` standing for `m · 2^k` (each `|m| < 2^40`): exact,
/// except that a part more than 80 bits finer than the other's grid becomes
/// its sign at that depth, which leaves every rounding to 24 bits or fewer
/// as it was (it is then below 2^-40 of the other part's last bit, so it
/// decides only ties and exactness).
fn add_exact(a: (i128, i32), b: (i128, i32)) -> (i128, i32) {
    let (coarse, fine) = if a.1 >= b.1 { (a, b) } else { (b, a) };
    let fine = if coarse.1 - fine.1 > 80 { (fine.0.signum(), coarse.1 - 80) } else { fine };
    ((coarse.0 << (coarse.1 - fine.1)) + fine.0, fine.1)
}

/// `m · 2^k` rounded to `p` bits, ties away from zero.
fn round_ties_away(m: i128, k: i32, p: u32) -> f32 {
    let mut mag = m.unsigned_abs();
    let mut k = k;
    let bits = 128 - mag.leading_zeros();
    if bits > p {
        let sh = bits - p;
        mag = (mag + (1 << (sh - 1))) >> sh;
        k += sh as i32;
    }
    let v = mag as f64 * 2f64.powi(k);
    (if m < 0 { -v } else { v }) as f32
}

/// One channel of a linear filter of 8- and 16-bit integer texels under the
/// normalized-float read, as the H200 computes it: from the stored integers
/// `v` (signed ones sign-extended, −128 and −32768 not clamped to −1) and
/// weights in 256ths, a 16-bit normalized value `n` rounded half up and
/// returned as `n / 65535` (unsigned) or `n / 32767` (signed) rounded to f32:
/// `u8` widened to 16 bits as `v · 257` (`n = round(Σ w·257v / 256)`), `u16`
/// and `s16` as they are (`n = round(Σ w·v / 256)`), `s8` from the sum
/// `S = Σ w·v` (8 fractional bits) scaled by `1 + 2^-7 + 2^-15` (for the
/// exact `32767 / 32512`) with the small part taken from `S` cut to a
/// multiple of 16: `n = S + round(floor(S / 16) · 257 / 2048)`. All bit for
/// bit on the H200 (`u8` and `s8` in 1-D, 2-D and 3-D; `u16` and `s16` in
/// 2-D, the only ones measured).
fn filter_normalized(terms: &[(i64, i64)], format: TexelFormat) -> f32 {
    let sum = |k: i64| terms.iter().map(|&(w, v)| w * v * k).sum::<i64>();
    match format {
        TexelFormat::U8 => ((sum(257) + 128) >> 8) as f32 / 65535.0,
        TexelFormat::U16 => ((sum(1) + 128) >> 8) as f32 / 65535.0,
        TexelFormat::S16 => ((sum(1) + 128) >> 8) as f32 / 32767.0,
        // S + S (2^-7 + 2^-15), the second part from S >> 4, rounded half up
        _ => {
            let s = sum(1);
            (s + (((s >> 4) * 257 + 1024) >> 11)) as f32 / 32767.0
        }
    }
}

/// The binary exponent of a finite nonzero `v` (`floor(log2 |v|)`).
fn exponent(v: f64) -> i32 {
    let bits = v.abs().to_bits();
    let e = (bits >> 52) as i32;
    if e == 0 {
        // subnormal in f64 (no f32 value is)
        -1074 + 63 - (bits.leading_zeros() as i32)
    } else {
        e - 1023
    }
}

/// Whether texels `i` and `i + 1` of dimension `d` are one texel clamped
/// at an edge under the clamp mode: the H200 then gives the second no
/// weight, as if it clamped the coordinate (measured in 3-D, where that
/// changes the other weights; in 1-D and 2-D it changes nothing). Under the
/// mirror mode, whose edge texels repeat too, it does not (measured in 3-D).
fn one_texel(t: &TextureDesc, d: usize, i: i64) -> bool {
    t.addr[d] == AddressMode::Clamp && (i < 0 || i >= size(t.dims, d) - 1)
}

/// `tex` with float coordinates (`dims` of them used).
pub fn sample(t: &TextureDesc, read: &dyn Fn(u64, u32) -> u64, coords: [f32; 3], dims: usize) -> [u32; 4] {
    let mut x = [0f64; 3];
    for d in 0..dims {
        x[d] = texel_coord(coords[d], size(t.dims, d), t.normalized);
    }
    if t.filter == FilterMode::Point {
        return fetch(t, read, x.map(|v| v.floor() as i64));
    }
    // A 1-D texture filters as a 2-D one of height 1 sampled at y = 0: the
    // footprint's other row is row -1, which the border mode reads as zeros
    // (so the H200 returns about half the value there).
    let dims = if dims == 1 { 2 } else { dims };
    let fp = x.map(footprint);
    let mut ws = [0u32; 3];
    for d in 0..dims {
        ws[d] = if one_texel(t, d, fp[d].0) { 0 } else { fp[d].1 };
    }
    // normalized integer texels filter from their stored integers
    let normalized = t.read == ReadMode::NormalizedFloat && t.format.is_small_int();
    let stored = TextureDesc { read: ReadMode::ElementType, ..t.clone() };
    // the texels that weigh something: weight, value, z slice
    let mut texels = [(0i64, [0u32; 4], 0usize); 8];
    let mut n = 0;
    for (corner, w) in corner_weights(&ws[..dims]).into_iter().enumerate().take(1 << dims) {
        if w == 0 {
            continue;
        }
        let mut idx = [0i64; 3];
        for d in 0..dims {
            idx[d] = fp[d].0 + (corner >> d & 1) as i64;
        }
        let v = fetch(if normalized { &stored } else { t }, read, idx);
        texels[n] = (w, v, corner >> 2 & 1);
        n += 1;
    }
    let texels = &texels[..n];
    let mut out = [0u32; 4];
    for (c, o) in out.iter_mut().enumerate() {
        *o = if normalized {
            let mut ch = [(0i64, 0i64); 8];
            for (k, (w, v, _)) in texels.iter().enumerate() {
                ch[k] = (*w, stored_int(t, c, v[c]));
            }
            filter_normalized(&ch[..n], t.format).to_bits()
        } else {
            let mut ch: [Term; 8] = [(0, 0.0, 0); 8];
            for (k, (w, v, z)) in texels.iter().enumerate() {
                ch[k] = (*w, f32::from_bits(v[c]), *z);
            }
            filter_channel(&ch[..n], filter_precision(t.format)).to_bits()
        };
    }
    out
}

/// Channel `c`'s stored integer from [`texel`]'s element-type read `bits`
/// (sign-extended for signed formats); the fourth channel of a texel with
/// fewer channels, which reads 1, is the format's largest value (1.0).
fn stored_int(t: &TextureDesc, c: usize, bits: u32) -> i64 {
    if c == 3 && t.channels < 4 && bits == 1 {
        return match t.format {
            TexelFormat::U8 => 255,
            TexelFormat::S8 => 127,
            TexelFormat::S16 => 32767,
            _ => 65535,
        };
    }
    bits as i32 as i64
}

/// `tex` with integer coordinates: the texel, no filtering; out of range a
/// linear resource reads zeros, an array its address mode.
pub fn fetch_int(t: &TextureDesc, read: &dyn Fn(u64, u32) -> u64, coords: [i32; 3], dims: usize) -> [u32; 4] {
    let mut idx = [0i64; 3];
    for d in 0..dims {
        idx[d] = coords[d] as i64;
        if t.linear && !(0..size(t.dims, d)).contains(&idx[d]) {
            return [0; 4];
        }
    }
    fetch(t, read, idx)
}

/// `tld4.comp.2d`: component `comp` of the four texels bilinear filtering at
/// (x, y) would use, in the order (i, j+1), (i+1, j+1), (i+1, j), (i, j).
pub fn gather(t: &TextureDesc, read: &dyn Fn(u64, u32) -> u64, x: f32, y: f32, comp: u8) -> [u32; 4] {
    let (i, _) = footprint(texel_coord(x, size(t.dims, 0), t.normalized));
    let (j, _) = footprint(texel_coord(y, size(t.dims, 1), t.normalized));
    [(i, j + 1), (i + 1, j + 1), (i + 1, j), (i, j)].map(|(a, b)| fetch(t, read, [a, b, 0])[comp as usize])
}

/// The byte address of a surface access of `size` bytes at byte x and rows
/// y, z; `None` when out of range (after `.clamp` clamps it), and always when
/// the access is wider than a row (no position holds it, clamped or not).
pub fn surface_addr(s: &SurfaceDesc, coords: [i32; 3], dims: usize, size: u32, clamp: bool) -> Option<u64> {
    let row = s.elem_bytes as i64 * s.dims[0].max(1) as i64;
    if row < size as i64 || size == 0 {
        return None;
    }
    let pitch = if s.row_pitch == 0 { row as u64 } else { s.row_pitch };
    let mut x = coords[0] as i64;
    let mut yz = [0i64; 2];
    for d in 1..dims {
        yz[d - 1] = coords[d] as i64;
    }
    if clamp {
        x = x.clamp(0, row - size as i64);
        for d in 1..dims {
            yz[d - 1] = yz[d - 1].clamp(0, size_dim(s.dims, d) - 1);
        }
    }
    if !(0..=row - size as i64).contains(&x) || (1..dims).any(|d| !(0..size_dim(s.dims, d)).contains(&yz[d - 1])) {
        return None;
    }
    Some(s.data.0 + x as u64 + yz[0] as u64 * pitch + yz[1] as u64 * pitch * s.dims[1].max(1) as u64)
}

fn size_dim(dims: [u32; 3], d: usize) -> i64 {
    size(dims, d)
}

/// The bytes a resource of `dims` elements of `elem` bytes spans from its
/// first element, rows `row_pitch` apart (0: packed); an error when a row
/// pitch is shorter than a row or the span passes 2^64.
fn span(elem: u64, dims: [u32; 3], row_pitch: u64) -> Result<u64, String> {
    let row = elem.checked_mul(dims[0].max(1) as u64).ok_or("its rows pass 2^64 bytes")?;
    if row_pitch != 0 && row_pitch < row {
        return Err(format!("row pitch {row_pitch} is shorter than a row ({row} bytes)"));
    }
    let pitch = if row_pitch == 0 { row } else { row_pitch };
    let rows = dims[1].max(1) as u64 * dims[2].max(1) as u64;
    pitch.checked_mul(rows - 1).and_then(|b| b.checked_add(row)).ok_or_else(|| "it spans past 2^64 bytes".to_string())
}

impl TextureDesc {
    /// Checks the descriptor as `cudaCreateTextureObject` would: 1, 2 or 4
    /// channels; normalized reads of 8- and 16-bit integer formats only
    /// (`cudaErrorInvalidNormSetting`); linear filtering of floats only, that
    /// is a float format or a normalized read (`cudaErrorInvalidFilterSetting`);
    /// and the texels (`dims`, `row_pitch`) within one allocation from `data`
    /// (`fits(addr, bytes)`). The error says what is wrong.
    pub fn validate(&self, fits: impl Fn(u64, u64) -> bool) -> Result<(), String> {
        if ![1, 2, 4].contains(&self.channels) {
            return Err(format!("{} channels (1, 2 or 4)", self.channels));
        }
        if let Some(e) = self.read_error() {
            return Err(e.into());
        }
        let bytes = span(self.format.bytes() as u64 * self.channels as u64, self.dims, self.row_pitch)?;
        if !fits(self.data.0, bytes) {
            return Err(format!("its {bytes} bytes from {:#x} are not within one allocation", self.data.0));
        }
        Ok(())
    }

    /// What CUDA rejects in the read mode and filter of this format
    /// ([`read_setting_error`]). `None`: fine.
    pub fn read_error(&self) -> Option<&'static str> {
        read_setting_error(self.format, self.filter, self.read).map(|(_, why)| why)
    }
}

/// The texture setting a [`read_setting_error`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadSetting {
    /// The read mode.
    Read,
    /// The filter mode.
    Filter,
}

/// What CUDA rejects in the read mode and filter of a texture of `format`
/// (the one place these rules are written; the API and launch specs both
/// ask it): a normalized read of anything but an 8- or 16-bit integer format
/// (`cudaErrorInvalidNormSetting`), or linear filtering of texels that do not
/// read as floats (`cudaErrorInvalidFilterSetting`). The setting at fault
/// and why; `None`: fine.
pub fn read_setting_error(
    format: TexelFormat,
    filter: FilterMode,
    read: ReadMode,
) -> Option<(ReadSetting, &'static str)> {
    if read == ReadMode::NormalizedFloat && !format.is_small_int() {
        return Some((ReadSetting::Read, "normalized reads are for 8- and 16-bit integer formats"));
    }
    if filter == FilterMode::Linear && !format.is_float() && read != ReadMode::NormalizedFloat {
        return Some((
            ReadSetting::Filter,
            "linear filtering needs float texels: an f16 or f32 format, or read = \"normalized\" \
             (CUDA rejects linear filtering of a non-float texture)",
        ));
    }
    None
}

impl SurfaceDesc {
    /// Checks the descriptor as `cudaCreateSurfaceObject` would: elements of
    /// at least one byte, and all of them (`dims`, `row_pitch`) within one
    /// allocation from `data` (`fits(addr, bytes)`).
    pub fn validate(&self, fits: impl Fn(u64, u64) -> bool) -> Result<(), String> {
        if self.elem_bytes == 0 {
            return Err("elements of 0 bytes".into());
        }
        let bytes = span(self.elem_bytes as u64, self.dims, self.row_pitch)?;
        if !fits(self.data.0, bytes) {
            return Err(format!("its {bytes} bytes from {:#x} are not within one allocation", self.data.0));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn address_modes_fold_indices() {
        assert_eq!(address(-1, 4, AddressMode::Clamp), Some(0));
        assert_eq!(address(5, 4, AddressMode::Clamp), Some(3));
        assert_eq!(address(-1, 4, AddressMode::Border), None);
        assert_eq!(address(-1, 4, AddressMode::Wrap), Some(3));
        assert_eq!(address(4, 4, AddressMode::Mirror), Some(3));
        assert_eq!(address(-1, 4, AddressMode::Mirror), Some(0));
        assert_eq!(address(8, 4, AddressMode::Mirror), Some(0));
    }

    #[test]
    fn surface_accesses_wider_than_a_row_have_no_address() {
        let s = SurfaceDesc { data: DevicePtr(0x1000), elem_bytes: 4, dims: [1, 2, 0], row_pitch: 0 };
        // a 4-byte row: an 8-byte access fits nowhere, clamped or not
        assert_eq!(surface_addr(&s, [0, 0, 0], 2, 8, true), None);
        assert_eq!(surface_addr(&s, [0, 1, 0], 2, 8, false), None);
        // a 4-byte one clamps to x = 0 of row 1
        assert_eq!(surface_addr(&s, [9, 1, 0], 2, 4, true), Some(0x1004));
        let z = SurfaceDesc { elem_bytes: 0, ..s };
        assert_eq!(surface_addr(&z, [0, 0, 0], 2, 4, true), None);
    }

    #[test]
    fn linear_filtering_and_normalized_reads_need_the_formats_cuda_accepts() {
        let t = |format, filter, read| TextureDesc {
            data: DevicePtr(0x1000),
            format,
            channels: 1,
            dims: [4, 0, 0],
            row_pitch: 0,
            linear: false,
            addr: [AddressMode::Clamp; 3],
            filter,
            read,
            normalized: false,
        };
        let ok = |t: TextureDesc| t.validate(|_, _| true);
        use {FilterMode::*, ReadMode::*, TexelFormat::*};
        assert!(ok(t(F32, Linear, ElementType)).is_ok());
        assert!(ok(t(F16, Linear, ElementType)).is_ok());
        assert!(ok(t(U8, Linear, NormalizedFloat)).is_ok());
        assert!(ok(t(S8, Point, ElementType)).is_ok());
        for f in [U8, S8, U16, S16, U32, S32] {
            let e = ok(t(f, Linear, ElementType)).unwrap_err();
            assert!(e.contains("linear filtering needs float texels"), "{f:?}: {e}");
        }
        for f in [U32, S32, F16, F32] {
            let e = ok(t(f, Point, NormalizedFloat)).unwrap_err();
            assert!(e.contains("normalized reads"), "{f:?}: {e}");
        }
    }

    #[test]
    fn footprint_weights_have_eight_fractional_bits() {
        assert_eq!(footprint(1.0), (0, 128));
        assert_eq!(footprint(0.5 + 1.0 / 1024.0), (0, 0));
        assert_eq!(footprint(0.5 + 2.0 / 1024.0), (0, 1));
        assert_eq!(footprint(0.5 + 3.0 / 1024.0), (0, 1));
        assert_eq!(footprint(-0.5 + 2.0 / 1024.0), (-1, 1));
    }

    #[test]
    fn corner_weights_round_the_product_and_sum_to_one() {
        // 1-D: the two weights
        assert_eq!(corner_weights(&[3])[..2], [253, 3]);
        // 2-D: w11 = round(232 · 176 / 256) = round(159.5) = 160 (half up)
        assert_eq!(corner_weights(&[232, 176])[..4], [8, 72, 16, 160]);
        for ws in [[0u32, 0], [255, 255], [1, 128], [77, 200]] {
            let c = corner_weights(&ws);
            assert_eq!(c.iter().sum::<i64>(), 256, "{ws:?}");
            assert!(c.iter().all(|&w| (0..=256).contains(&w)), "{ws:?}: {c:?}");
        }
    }

    #[test]
    fn filtering_aligns_to_the_largest_texel_and_rounds_ties_away() {
        // weights 1/256 and 255/256 of 1.0 and 2^-30: the small texel is cut
        // off entirely (below the grid 2^-27 of the larger one)
        let r = filter_channel(&[(1, 1.0, 0), (255, 2f32.powi(-30), 0)], 24);
        assert_eq!(r, 1.0 / 256.0);
        // alone, a small texel keeps all its bits (`sample` leaves out the
        // corners that weigh nothing, so they never set the grid)
        assert_eq!(filter_channel(&[(256, 2f32.powi(-30), 0)], 24), 2f32.powi(-30));
        // a tie rounds away from zero: 1 + 2^-24 (exactly between two f32)
        let v = 1.0 + 2f32.powi(-23);
        assert_eq!(filter_channel(&[(128, 1.0, 0), (128, v, 0)], 24), v);
        assert_eq!(filter_channel(&[(128, -1.0, 0), (128, -v, 0)], 24), -v);
        // half precision: 11 bits
        assert_eq!(filter_channel(&[(128, 1.0, 0), (128, 1.0 + 2f32.powi(-10), 0)], 11), 1.0 + 2f32.powi(-10));
    }

    #[test]
    fn each_z_slice_is_aligned_to_its_own_largest_texel() {
        // the 2^-30 texel in slice 1 keeps its bits beside slice 0's 1.0
        // (aligned together it would be cut off, leaving 1/256 exactly):
        // 2^-8 + 255 x 2^-38, rounded to 24 bits
        let r = filter_channel(&[(1, 1.0, 0), (255, 2f32.powi(-30), 1)], 24);
        assert_eq!(r, 2f32.powi(-8) + 2f32.powi(-30));
        // slices far apart: the finer one still decides a tie (1 + 2^-24
        // rounds away, to 1 + 2^-23, unless a little is taken off it)
        let v = 1.0 + 2f32.powi(-23);
        let tie = [(128, 1.0, 0), (128, v, 0)];
        assert_eq!(filter_channel(&[tie[0], tie[1], (256, 2f32.powi(-120), 1)], 24), v);
        assert_eq!(filter_channel(&[tie[0], tie[1], (256, -(2f32.powi(-120)), 1)], 24), 1.0);
    }

    #[test]
    fn normalized_texels_filter_in_sixteen_bit_fixed_point() {
        use TexelFormat::*;
        // 0 and 255 at one half: 257 x 255 x 128 / 256 = 32767.5 -> 32768
        assert_eq!(filter_normalized(&[(128, 0), (128, 255)], U8), 32768.0 / 65535.0);
        // full weight on 255 is exactly 1.0; a u16 texel is not widened
        assert_eq!(filter_normalized(&[(256, 255)], U8), 1.0);
        assert_eq!(filter_normalized(&[(255, 65535), (1, 0)], U16), 65279.0 / 65535.0);
        // signed: half up toward +inf, and -32768 / -128 are not clamped to -1
        assert_eq!(filter_normalized(&[(128, -3), (128, 0)], S16), -1.0 / 32767.0);
        assert_eq!(filter_normalized(&[(256, -32768)], S16), -32768.0 / 32767.0);
        assert_eq!(filter_normalized(&[(256, 127)], S8), 1.0);
        assert_eq!(filter_normalized(&[(256, -128)], S8), -33025.0 / 32767.0);
        // s8, three channels the H200 returned (n2s8) where the exact scale,
        // round(S · 32767 / 32512), gives one step more: S = -7586 (-7645.499),
        // -12676 (-12775.421), 17278 (17413.516)
        assert_eq!(filter_normalized(&[(22, -47), (234, -28)], S8), -7646.0 / 32767.0);
        assert_eq!(filter_normalized(&[(188, -28), (68, -109)], S8), -12776.0 / 32767.0);
        assert_eq!(filter_normalized(&[(2, 3), (254, 68)], S8), 17413.0 / 32767.0);
    }

    /// The split as a list of parts (the definition the in-place
    /// [`corner_weights`] replaced): every part splits into its first and
    /// its second texel's share along each dimension in turn.
    fn corner_weights_by_parts(w: &[u32]) -> Vec<i64> {
        let n = w.len();
        let order: Vec<usize> = if n == 3 { vec![2, 0, 1] } else { (0..n).collect() };
        let mut parts: Vec<(usize, i64)> = vec![(0, 256)];
        for &d in &order {
            let mut next = Vec::new();
            for &(corner, v) in &parts {
                let tie_down = d == 1 && corner & 1 == 0;
                let hi = (v * w[d] as i64 + if tie_down { 127 } else { 128 }) >> 8;
                next.push((corner, v - hi));
                next.push((corner | 1 << d, hi));
            }
            parts = next;
        }
        let mut out = vec![0; 1 << n];
        for (corner, v) in parts {
            out[corner] = v;
        }
        out
    }

    #[test]
    fn corner_weights_in_place_are_the_split_of_parts() {
        let ws = [0u32, 1, 2, 77, 127, 128, 129, 200, 254, 255];
        for &a in &ws {
            assert_eq!(corner_weights(&[a])[..2], corner_weights_by_parts(&[a])[..], "{a}");
            assert!(corner_weights(&[a])[2..].iter().all(|&v| v == 0));
            for &b in &ws {
                assert_eq!(corner_weights(&[a, b])[..4], corner_weights_by_parts(&[a, b])[..], "{a} {b}");
                for &c in &ws {
                    assert_eq!(corner_weights(&[a, b, c])[..], corner_weights_by_parts(&[a, b, c])[..], "{a} {b} {c}");
                }
            }
        }
    }

    #[test]
    fn three_d_weights_split_z_then_x_then_y() {
        // measured on the H200: wx, wy, wz = 165, 202, 127 (corner = x + 2y + 4z)
        assert_eq!(corner_weights(&[165, 202, 127]), [10, 18, 36, 65, 9, 17, 36, 65]);
        for ws in [[0u32, 0, 0], [255, 255, 255], [1, 128, 77], [64, 105, 26]] {
            let c = corner_weights(&ws);
            assert_eq!(c.iter().sum::<i64>(), 256, "{ws:?}");
            // the z split is exact
            assert_eq!(c[4..].iter().sum::<i64>(), ws[2] as i64, "{ws:?}");
        }
    }
}
