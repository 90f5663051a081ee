//! Linear texture filtering and surface reductions against an H200
//! (`tools/device/issue20_leftovers.sh`, `issue20_tex_bfs.sh` and
//! `issue20_s8_stepped.sh`; fixtures
//! `tests/fixtures/validation/h200_tex_filter{,2,3}.{json,bin.z}` and
//! `h200_sured.json`). The textures' texels come from the hash rule of
//! `tools/device/tex_filter_host.cu` (the fixture maker checked the GPU's
//! texels against it), the coordinates and results from the fixture.
//!
//! `f32`, `f16`, `u8` and `s8` texels in 1-D and 2-D, `u16` and `s16` ones in
//! 2-D (the only measured), and `u8` and `s8` ones in 3-D, filter bit for bit
//! as the H200 does (`docs/semantics.md`:
//! weights split in 256ths, float texels aligned to the largest and the sum
//! rounded ties away, normalized integers summed in 16-bit fixed point);
//! float 3-D textures are bit for bit but for the listed channels
//! ([`misses`]), each off by at most the listed amount.

use std::path::Path;

use serde_json::Value;
use warplight::sim::texture::{self, AddressMode, FilterMode, ReadMode, SurfaceDesc, TexelFormat, TextureDesc};
use warplight::sim::{Arg, Device, DevicePtr, LaunchConfig};

fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    x
}

/// One measured case: its description and the kept samples.
struct Case {
    name: String,
    dims: usize,
    format: TexelFormat,
    size: [u32; 3],
    addr: AddressMode,
    normalized: bool,
    texels: String,
    seed: u32,
    coords: Vec<f32>,
    out: Vec<u32>,
}

impl Case {
    /// Texel element `e` (channels innermost), as `tex_filter_host.cu` makes it.
    fn texel_bits(&self, e: u32) -> u32 {
        let (ch, k) = (e % 4, e / 4);
        if self.texels == "random" {
            let h = hash32(e.wrapping_add(self.seed << 20));
            return match self.format {
                TexelFormat::F32 => (h & 0x807F_FFFF) | ((120 + hash32(h) % 15) << 23),
                TexelFormat::F16 => (h & 0x83FF) | ((8 + hash32(h) % 15) << 10),
                TexelFormat::U16 | TexelFormat::S16 => h & 0xFFFF,
                _ => h & 0xFF,
            };
        }
        let x = k % self.size[0];
        let y = if self.size[1] > 0 { k / self.size[0] % self.size[1] } else { 0 };
        let v = match self.texels.as_str() {
            "pair" => [[0.0, 1.0, 1.0, -3.0], [1.0, 0.0, 2.0, 5.0]][x as usize][ch as usize],
            "index" => [x as f32, (4096 - x) as f32, 1.0, 0.0][ch as usize],
            _ => [x as f32, y as f32, (x == 0 && y == 0) as u32 as f32, (2 * x + 3 * y) as f32][ch as usize],
        };
        f32::to_bits(v)
    }

    /// The texel bytes in the emulator's layout (row-major, channels innermost).
    fn bytes(&self) -> Vec<u8> {
        let count = self.size.iter().map(|&d| d.max(1)).product::<u32>() * 4;
        let eb = self.format.bytes() as usize;
        (0..count).flat_map(|e| self.texel_bits(e).to_le_bytes()[..eb].to_vec()).collect()
    }

    fn desc(&self, data: DevicePtr) -> TextureDesc {
        let int = self.format.is_small_int();
        TextureDesc {
            data,
            format: self.format,
            channels: 4,
            dims: self.size,
            row_pitch: 0,
            linear: false,
            addr: [self.addr; 3],
            filter: FilterMode::Linear,
            read: if int { ReadMode::NormalizedFloat } else { ReadMode::ElementType },
            normalized: self.normalized,
        }
    }

    fn count(&self) -> usize {
        self.out.len() / 4
    }

    fn coords(&self, i: usize) -> [f32; 3] {
        let mut c = [0f32; 3];
        c[..self.dims].copy_from_slice(&self.coords[i * self.dims..(i + 1) * self.dims]);
        c
    }

    /// Bit for bit.
    fn exact(&self) -> bool {
        misses(&self.name).0 == 0
    }
}

/// How far warplight's rules miss the H200 on a case: the channels that
/// differ, and the most one differs by (units in the last place of the f32
/// result). Float 3-D filters add their two z slices' sums in a way no rule
/// tried matches on these few channels.
fn misses(name: &str) -> (usize, u32) {
    match name {
        "r3" | "r3b" | "r3w" => (3, 1),
        "r3m" => (5, 1),
        // 32,768 channels: mostly one ulp, more where the slices cancel
        "r3big" => (34, 6),
        // one ulp of f16 (2^13 of f32's)
        "h3" => (6, 1 << 13),
        _ => (0, 0),
    }
}

fn cases() -> Vec<Case> {
    let mut all = cases_of("h200_tex_filter");
    all.extend(cases_of("h200_tex_filter2"));
    all.extend(cases_of("h200_tex_filter3"));
    all
}

fn cases_of(stem: &str) -> Vec<Case> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/validation");
    let meta: Value =
        serde_json::from_str(&std::fs::read_to_string(root.join(format!("{stem}.json"))).unwrap()).unwrap();
    let z = std::fs::read(root.join(format!("{stem}.bin.z"))).unwrap();
    let blob = miniz_oxide::inflate::decompress_to_vec_zlib(&z).unwrap();
    let words: Vec<u32> = blob.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().unwrap())).collect();
    let mut at = 0;
    let mut out = Vec::new();
    for c in meta["cases"].as_array().unwrap() {
        let dims = c["dims"].as_u64().unwrap() as usize;
        let n = c["kept"]["count"].as_u64().unwrap() as usize;
        let coords: Vec<f32> = words[at..at + n * dims].iter().map(|&w| f32::from_bits(w)).collect();
        at += n * dims;
        let res = words[at..at + n * 4].to_vec();
        at += n * 4;
        let size: Vec<u32> = c["size"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u32).collect();
        out.push(Case {
            name: c["name"].as_str().unwrap().to_string(),
            dims,
            format: match c["format"].as_str().unwrap() {
                "f32" => TexelFormat::F32,
                "f16" => TexelFormat::F16,
                "u16" => TexelFormat::U16,
                "s16" => TexelFormat::S16,
                "s8" => TexelFormat::S8,
                _ => TexelFormat::U8,
            },
            size: [size[0], size[1], size[2]],
            addr: match c["addr"].as_str().unwrap() {
                "clamp" => AddressMode::Clamp,
                "border" => AddressMode::Border,
                "wrap" => AddressMode::Wrap,
                _ => AddressMode::Mirror,
            },
            normalized: c["normalized"].as_bool().unwrap(),
            texels: c["texels"].as_str().unwrap().to_string(),
            seed: c["seed"].as_u64().unwrap() as u32,
            coords,
            out: res,
        });
    }
    assert_eq!(at, words.len(), "the fixture's samples are all read");
    out
}

/// Every kept sample of every case through `texture::sample`: bit for bit
/// but for the channels each case [`misses`], each within its bound.
#[test]
fn linear_filtering_equals_the_h200() {
    let cases = cases();
    assert_eq!(cases.len(), 32);
    let mut report = Vec::new();
    for c in &cases {
        let bytes = c.bytes();
        let base = 0x1000u64;
        let read = |a: u64, n: u32| {
            let o = (a - base) as usize;
            let mut b = [0u8; 8];
            b[..n as usize].copy_from_slice(&bytes[o..o + n as usize]);
            u64::from_le_bytes(b)
        };
        let desc = c.desc(DevicePtr(base));
        let (count, bound) = misses(&c.name);
        let (mut differ, mut worst_ulps) = (0, 0u32);
        for i in 0..c.count() {
            let got = texture::sample(&desc, &read, c.coords(i), c.dims);
            for (&gb, &wb) in got.iter().zip(&c.out[4 * i..4 * i + 4]) {
                if gb != wb {
                    differ += 1;
                    worst_ulps = worst_ulps.max((gb as i32).wrapping_sub(wb as i32).unsigned_abs());
                }
            }
        }
        report.push(format!("{}: {differ} of {} channels differ", c.name, 4 * c.count()));
        // exactly the measured misses: fewer means the rule improved (update
        // `misses` and docs/semantics.md), more that it broke
        assert_eq!(differ, count, "{}: {differ} channels differ ({worst_ulps} ulp)", c.name);
        assert!(worst_ulps <= bound, "{}: off by {worst_ulps} ulp", c.name);
    }
    println!("{}", report.join("\n"));
}

fn load(dev: &mut Device, stem: &str, nvcc: bool) -> warplight::sim::Module {
    let p = format!("kernels/validation/{stem}{}.ptx", if nvcc { ".nvcc" } else { "" });
    let src = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"));
    dev.load_ptx(&src, &p).unwrap_or_else(|e| panic!("{e}"))
}

/// The probe's kernels (`kernels/validation/tex_filter.cu`, both dialects)
/// give the H200's bits on a part of each exact case.
#[test]
fn filtering_kernels_give_the_h200s_bits() {
    for c in cases().iter().filter(|c| c.exact()) {
        let n = c.count().min(256);
        for nvcc in [false, true] {
            let mut dev = Device::new();
            let m = load(&mut dev, "tex_filter", nvcc);
            let data = dev.alloc_from(&c.bytes());
            let h = dev.create_texture(c.desc(data)).unwrap();
            let crd = dev.alloc_from(&c.coords[..n * c.dims]);
            let out = dev.alloc_from(&vec![0u32; 4 * n]);
            let kernel = ["tf_1d", "tf_2d", "tf_3d"][c.dims - 1];
            let args = [Arg::U64(h), Arg::Ptr(crd), Arg::Ptr(out), Arg::I32(n as i32)];
            dev.launch(&m, kernel, LaunchConfig::linear(n.div_ceil(128) as u32, 128), &args)
                .unwrap_or_else(|e| panic!("{}: {e}", c.name));
            assert_eq!(dev.read::<u32>(out, 4 * n), c.out[..4 * n], "{} (nvcc: {nvcc})", c.name);
        }
    }
}

/// `sured.b` (`kernels/validation/sured.cu`, both dialects) leaves every
/// surface as the H200 did: in range, clamped and ignored out of range, 32
/// and 64 bits.
#[test]
fn surface_reductions_equal_the_h200() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/validation/h200_sured.json");
    let f: Value = serde_json::from_str(&std::fs::read_to_string(root).unwrap()).unwrap();
    let words = |v: &Value| -> Vec<u32> { v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as u32).collect() };
    let cases = f["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 14);
    for c in cases {
        let kernel = c["kernel"].as_str().unwrap();
        let (init, want) = (words(&c["init"]), words(&c["out"]));
        assert_ne!(init, want, "{kernel}: the launch changed the surface");
        for nvcc in [false, true] {
            let mut dev = Device::new();
            let m = load(&mut dev, "sured", nvcc);
            let data = dev.alloc_from(&init);
            let elem_bytes = c["elem_bytes"].as_u64().unwrap() as u32;
            let h = dev.create_surface(SurfaceDesc { data, elem_bytes, dims: [4, 4, 0], row_pitch: 0 }).unwrap();
            let threads = c["threads"].as_u64().unwrap() as u32;
            dev.launch(&m, kernel, LaunchConfig::linear(1, threads), &[Arg::U64(h)]).unwrap();
            assert_eq!(dev.read::<u32>(data, init.len()), want, "{kernel} (nvcc: {nvcc})");
        }
    }
}
