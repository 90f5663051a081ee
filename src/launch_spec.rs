//! Launch specifications: a TOML file that names a PTX file, a kernel, its grid,
//! its buffers with their initial contents, and its arguments — everything
//! `warplight launch` needs to run any kernel without writing Rust.
//!
//! ```toml
//! ptx = "micro.ptx"            # relative to the spec file
//! kernel = "copy_stride"
//! grid = [64, 1, 1]
//! block = [256, 1, 1]
//! args = ["in", "out", 1, 0]   # buffer names or scalar literals, in parameter order
//! [[buffer]]
//! name = "in"
//! type = "f32"                 # u8..u64, i8..i64, f32, f64
//! len = 655360
//! init = "iota"                # "zeros" | "iota" | { hash = 2654435761, modulo = 16384 } | { file = "x.bin" } | [1, 2, 3]
//! ```
//!
//! Several `[[launch]]` tables (each with `kernel`, `grid`, `block`, `args` and
//! optionally `shared`) may replace the top-level launch keys; they run in order
//! on the same buffers.
//!
//! Optional top-level limits hold for every launch: `max_instructions` (the
//! watchdog, warp instructions per launch) and `max_call_depth` (nested
//! device-function calls per warp); see `docs/limits.md`.
//! `[[texture]]` and `[[surface]]` tables describe texture and surface
//! objects over buffers, passed to kernels by name ([`objects`]). `fmad = false` turns
//! off ptxas's FMA contraction of unrounded `mul` + `add` pairs (on by default
//! for the maxwell and hopper profiles; docs/semantics.md).

pub mod objects;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::model::{Model, ModelStats, Occupancy, Profile, occupancy};
use crate::ptx::types::Ty;
use crate::sim::{Arg, Device, DevicePtr, LaunchConfig, LaunchStats, Module, SimConfig, SimError};

/// A problem with a spec file, naming the file and the key.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file could not be read.
    #[error("{file}: {msg}")]
    Io {
        /// The file.
        file: String,
        /// What failed.
        msg: String,
    },
    /// The TOML is malformed.
    #[error("{file}: {msg}")]
    Toml {
        /// The file.
        file: String,
        /// The parser's message (with line and column).
        msg: String,
    },
    /// A key is missing or has the wrong shape.
    #[error("{file}: `{key}`: {msg}")]
    Key {
        /// The file.
        file: String,
        /// The key, dotted (`buffer[1].init`).
        key: String,
        /// What was expected.
        msg: String,
    },
    /// Loading or running failed.
    #[error("{0}")]
    Sim(#[from] SimError),
    /// The spec asks for more than a limit allows (`docs/limits.md`).
    #[error("{0}")]
    Limit(#[from] crate::limits::LimitError),
}

/// Element types of buffers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ElemType {
    U8,
    U16,
    U32,
    U64,
    I8,
    I16,
    I32,
    I64,
    F32,
    F64,
}

impl ElemType {
    fn parse(s: &str) -> Option<ElemType> {
        Some(match s {
            "u8" => ElemType::U8,
            "u16" => ElemType::U16,
            "u32" => ElemType::U32,
            "u64" => ElemType::U64,
            "i8" | "s8" => ElemType::I8,
            "i16" | "s16" => ElemType::I16,
            "i32" | "s32" => ElemType::I32,
            "i64" | "s64" => ElemType::I64,
            "f32" => ElemType::F32,
            "f64" => ElemType::F64,
            _ => return None,
        })
    }

    /// Size in bytes.
    pub fn size(self) -> usize {
        match self {
            ElemType::U8 | ElemType::I8 => 1,
            ElemType::U16 | ElemType::I16 => 2,
            ElemType::U32 | ElemType::I32 | ElemType::F32 => 4,
            ElemType::U64 | ElemType::I64 | ElemType::F64 => 8,
        }
    }

    /// The range of an integer type, as i128.
    fn int_range(self) -> Option<(i128, i128)> {
        Some(match self {
            ElemType::U8 => (0, u8::MAX as i128),
            ElemType::U16 => (0, u16::MAX as i128),
            ElemType::U32 => (0, u32::MAX as i128),
            ElemType::U64 => (0, u64::MAX as i128),
            ElemType::I8 => (i8::MIN as i128, i8::MAX as i128),
            ElemType::I16 => (i16::MIN as i128, i16::MAX as i128),
            ElemType::I32 => (i32::MIN as i128, i32::MAX as i128),
            ElemType::I64 => (i64::MIN as i128, i64::MAX as i128),
            ElemType::F32 | ElemType::F64 => return None,
        })
    }

    /// An error unless `v` is a number this type holds exactly: integers
    /// within range, floats for integer types only when whole and in range,
    /// and finite floats within f32's range for `f32` (`inf` and `nan`
    /// written as such are kept). Values never wrap.
    pub fn check_value(self, v: &toml::Value) -> Result<(), String> {
        let name = format!("{self:?}").to_ascii_lowercase();
        match (v, self.int_range()) {
            (toml::Value::Integer(x), Some((lo, hi))) => {
                if (lo..=hi).contains(&(*x as i128)) {
                    Ok(())
                } else {
                    Err(format!("{x} is out of range for {name} ({lo} to {hi})"))
                }
            }
            (toml::Value::Float(x), Some((lo, hi))) => {
                if x.fract() == 0.0 && *x >= lo as f64 && *x <= hi as f64 {
                    Ok(())
                } else {
                    Err(format!("{x} is not a whole number from {lo} to {hi} ({name})"))
                }
            }
            (toml::Value::Integer(_), None) => Ok(()),
            (toml::Value::Float(x), None) => {
                if self == ElemType::F32 && x.is_finite() && x.abs() > f32::MAX as f64 {
                    Err(format!("{x} is out of range for f32 (it would become infinity)"))
                } else {
                    Ok(())
                }
            }
            _ => Err("expected a number".into()),
        }
    }

    fn is_float(self) -> bool {
        matches!(self, ElemType::F32 | ElemType::F64)
    }

    /// Encodes element `v` (an integer value or a float value) as little-endian bytes.
    fn encode(self, int: i128, float: f64, use_float: bool, out: &mut Vec<u8>) {
        let n = self.size();
        match self {
            ElemType::F32 => out.extend_from_slice(&(if use_float { float } else { int as f64 } as f32).to_le_bytes()),
            ElemType::F64 => out.extend_from_slice(&(if use_float { float } else { int as f64 }).to_le_bytes()),
            _ => {
                let v = if use_float { float as i128 } else { int };
                out.extend_from_slice(&(v as u64).to_le_bytes()[..n]);
            }
        }
    }

    /// Decodes one element to a display string.
    pub fn show(self, b: &[u8]) -> String {
        let mut w = [0u8; 8];
        w[..b.len()].copy_from_slice(b);
        let u = u64::from_le_bytes(w);
        match self {
            ElemType::F32 => format!("{}", f32::from_bits(u as u32)),
            ElemType::F64 => format!("{}", f64::from_bits(u)),
            ElemType::I8 => format!("{}", u as u8 as i8),
            ElemType::I16 => format!("{}", u as u16 as i16),
            ElemType::I32 => format!("{}", u as u32 as i32),
            ElemType::I64 => format!("{}", u as i64),
            _ => format!("{u}"),
        }
    }
}

/// How a buffer starts.
#[derive(Debug, Clone, PartialEq)]
pub enum Init {
    /// All zero.
    Zeros,
    /// Element i = i.
    Iota,
    /// Element i = (i × mul) mod modulo, in 64-bit unsigned arithmetic.
    Hash {
        /// Multiplier.
        mul: u64,
        /// Modulus.
        modulo: u64,
    },
    /// Raw bytes from a file (relative to the spec).
    File(PathBuf),
    /// Explicit values (the rest is zero).
    Values(Vec<toml::Value>),
}

/// One buffer.
#[derive(Debug, Clone)]
pub struct BufferSpec {
    /// Its name.
    pub name: String,
    /// Element type.
    pub ty: ElemType,
    /// Element count.
    pub len: usize,
    /// Initial contents.
    pub init: Init,
}

/// A kernel argument as written.
#[derive(Debug, Clone, PartialEq)]
pub enum ArgSpec {
    /// A buffer's address plus a byte offset (`"x"`, `"x+16"`, `{ buffer = "x", offset = 16 }`).
    Buffer(String, u64),
    /// An integer scalar.
    Int(i64),
    /// A float scalar.
    Float(f64),
    /// A texture or surface object's handle (`[[texture]]`, `[[surface]]`).
    Object(String),
}

/// One launch.
#[derive(Debug, Clone)]
pub struct LaunchSpec {
    /// Kernel name.
    pub kernel: String,
    /// Grid.
    pub grid: [u32; 3],
    /// Block.
    pub block: [u32; 3],
    /// Dynamic shared memory bytes.
    pub shared: u32,
    /// Arguments.
    pub args: Vec<ArgSpec>,
}

/// A parsed spec file.
#[derive(Debug, Clone)]
pub struct Spec {
    /// The spec file.
    pub file: PathBuf,
    /// The PTX file (resolved against the spec's directory).
    pub ptx: PathBuf,
    /// Device profile name, when given.
    pub device: Option<String>,
    /// Buffers in declaration order.
    pub buffers: Vec<BufferSpec>,
    /// `__constant__` variables of the module to fill before the launches (`[[constant]]`).
    pub constants: Vec<BufferSpec>,
    /// Texture and surface objects over buffers (`[[texture]]`, `[[surface]]`).
    pub objects: Vec<objects::ObjectSpec>,
    /// Launches in order.
    pub launches: Vec<LaunchSpec>,
    /// The watchdog: most warp instructions of one launch (`max_instructions`),
    /// when given.
    pub max_instructions: Option<u64>,
    /// Most nested device-function calls per warp (`max_call_depth`), when given.
    pub max_call_depth: Option<u32>,
    /// ptxas's FMA contraction (`fmad = false` turns it off), when given.
    pub fmad: Option<bool>,
}

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn err<T>(&self, key: &str, msg: impl Into<String>) -> Result<T, SpecError> {
        Err(SpecError::Key { file: self.file.to_string(), key: key.to_string(), msg: msg.into() })
    }

    fn dims(&self, t: &toml::Table, key: &str, prefix: &str) -> Result<[u32; 3], SpecError> {
        let k = format!("{prefix}{key}");
        let v = match t.get(key) {
            Some(v) => v,
            None => return self.err(&k, "missing; expected [x, y, z] or a number"),
        };
        let nums: Vec<&toml::Value> = match v {
            toml::Value::Array(a) => a.iter().collect(),
            x @ toml::Value::Integer(_) => vec![x],
            _ => return self.err(&k, "expected [x, y, z] or a number"),
        };
        if nums.is_empty() || nums.len() > 3 {
            return self.err(&k, "expected 1 to 3 dimensions");
        }
        let mut d = [1u32; 3];
        for (i, n) in nums.iter().enumerate() {
            match n.as_integer() {
                Some(x) if x >= 1 && x <= u32::MAX as i64 => d[i] = x as u32,
                Some(x) if x > u32::MAX as i64 => {
                    let axis = ["x", "y", "z"][i];
                    return self.err(&k, format!("{key}.{axis} = {x} is more than CUDA allows"));
                }
                _ => return self.err(&k, "dimensions are positive integers"),
            }
        }
        crate::limits::check_dims(key, d).or_else(|m| self.err(&k, m))?;
        Ok(d)
    }

    fn launch(&self, t: &toml::Table, prefix: &str) -> Result<LaunchSpec, SpecError> {
        let kernel = match t.get("kernel").and_then(|v| v.as_str()) {
            Some(k) => k.to_string(),
            None => return self.err(&format!("{prefix}kernel"), "missing; expected the kernel's name"),
        };
        let args = match t.get("args") {
            None => Vec::new(),
            Some(toml::Value::Array(a)) => a
                .iter()
                .enumerate()
                .map(|(i, v)| match v {
                    toml::Value::String(s) => match s.split_once('+') {
                        None => Ok(ArgSpec::Buffer(s.trim().to_string(), 0)),
                        Some((n, o)) => match o.trim().parse::<u64>() {
                            Ok(o) => Ok(ArgSpec::Buffer(n.trim().to_string(), o)),
                            Err(_) => self.err(
                                &format!("{prefix}args[{i}]"),
                                format!("{s:?}: expected NAME or NAME+BYTES (a byte offset into the buffer)"),
                            ),
                        },
                    },
                    toml::Value::Table(t) => match (t.get("buffer").and_then(|v| v.as_str()), t.get("offset")) {
                        (Some(n), None) => Ok(ArgSpec::Buffer(n.to_string(), 0)),
                        (Some(n), Some(o)) => match o.as_integer() {
                            Some(o) if o >= 0 => Ok(ArgSpec::Buffer(n.to_string(), o as u64)),
                            _ => self.err(&format!("{prefix}args[{i}].offset"), "expected a non-negative byte offset"),
                        },
                        _ => self.err(&format!("{prefix}args[{i}]"), "expected { buffer = \"NAME\", offset = BYTES }"),
                    },
                    toml::Value::Integer(x) => Ok(ArgSpec::Int(*x)),
                    toml::Value::Float(x) => Ok(ArgSpec::Float(*x)),
                    toml::Value::Boolean(b) => Ok(ArgSpec::Int(*b as i64)),
                    _ => self.err(&format!("{prefix}args[{i}]"), "expected a buffer name or a number"),
                })
                .collect::<Result<_, _>>()?,
            Some(_) => return self.err(&format!("{prefix}args"), "expected an array"),
        };
        let shared = match t.get("shared") {
            None => 0,
            Some(v) => match v.as_integer() {
                Some(x) if x >= 0 && x <= MAX_DYNAMIC_SHARED as i64 => x as u32,
                _ => {
                    return self.err(
                        &format!("{prefix}shared"),
                        format!(
                            "expected bytes of dynamic shared memory, at most {MAX_DYNAMIC_SHARED} \
                             (the simulated device's shared memory per CTA)"
                        ),
                    );
                }
            },
        };
        Ok(LaunchSpec {
            kernel,
            grid: self.dims(t, "grid", prefix)?,
            block: self.dims(t, "block", prefix)?,
            shared,
            args,
        })
    }
}

/// The largest buffer a spec may declare (the host must hold it, and a copy);
/// the host-memory budget ([`crate::limits::memory_budget`]) may allow less.
pub const MAX_BUFFER_BYTES: u64 = crate::limits::MAX_ALLOCATION_BYTES;

/// The largest PTX file a spec may name.
pub const MAX_PTX_BYTES: u64 = 256 << 20;

/// The most dynamic shared memory a launch may ask for: the simulated
/// device's shared memory per CTA (`SimConfig::max_shared_per_cta`).
pub const MAX_DYNAMIC_SHARED: u32 = 228 * 1024;

/// The keys a spec knows: at the top, in `[[buffer]]` and in `[[launch]]` tables.
const TOP_KEYS: [&str; 15] = [
    "ptx",
    "device",
    "max_instructions",
    "max_call_depth",
    "fmad",
    "buffer",
    "constant",
    "texture",
    "surface",
    "launch",
    "kernel",
    "grid",
    "block",
    "shared",
    "args",
];
const BUFFER_KEYS: [&str; 4] = ["name", "type", "len", "init"];
const LAUNCH_KEYS: [&str; 5] = ["kernel", "grid", "block", "shared", "args"];

/// Edit distance (insertions, deletions, substitutions).
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            cur.push((prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

impl Ctx<'_> {
    /// The `[[buffer]]` (or `[[constant]]`) tables under `key`.
    fn buffers(&self, t: &toml::Table, key: &str, dir: &Path) -> Result<Vec<BufferSpec>, SpecError> {
        let cx = self;
        let mut buffers = Vec::new();
        if let Some(b) = t.get(key) {
            let Some(arr) = b.as_array() else { return cx.err(key, format!("expected [[{key}]] tables")) };
            for (i, v) in arr.iter().enumerate() {
                let k = |f: &str| format!("{key}[{i}].{f}");
                let Some(bt) = v.as_table() else { return cx.err(&format!("{key}[{i}]"), "expected a table") };
                cx.known_keys(bt, &BUFFER_KEYS, &format!("{key}[{i}]."))?;
                let name = match bt.get("name").and_then(|v| v.as_str()) {
                    Some(n) => n.to_string(),
                    None => return cx.err(&k("name"), "missing"),
                };
                let ty = match bt.get("type").and_then(|v| v.as_str()).and_then(ElemType::parse) {
                    Some(t) => t,
                    None => return cx.err(&k("type"), "expected one of u8 u16 u32 u64 i8 i16 i32 i64 f32 f64"),
                };
                let len = match bt.get("len").and_then(|v| v.as_integer()) {
                    Some(n) if n >= 0 => n as usize,
                    _ => return cx.err(&k("len"), "expected a non-negative element count"),
                };
                // checked before anything is allocated (`len = 2^62` wrapped to 0 bytes)
                match len.checked_mul(ty.size()) {
                    Some(bytes) if bytes as u64 <= MAX_BUFFER_BYTES => {}
                    _ => {
                        return cx.err(
                            &k("len"),
                            format!(
                                "{len} elements of {} bytes is more than a buffer may hold ({} GiB)",
                                ty.size(),
                                MAX_BUFFER_BYTES >> 30
                            ),
                        );
                    }
                }
                let init = match bt.get("init") {
                    None => Init::Zeros,
                    Some(toml::Value::String(s)) if s == "zeros" => Init::Zeros,
                    Some(toml::Value::String(s)) if s == "iota" => {
                        let last = len.saturating_sub(1).min(i64::MAX as usize) as i64;
                        ty.check_value(&toml::Value::Integer(last))
                            .or_else(|e| cx.err(&k("init"), format!("iota over {len} elements reaches {last}: {e}")))?;
                        Init::Iota
                    }
                    Some(toml::Value::Array(a)) => {
                        if a.len() > len {
                            return cx.err(&k("init"), format!("{} values for {len} elements", a.len()));
                        }
                        for (j, v) in a.iter().enumerate() {
                            ty.check_value(v).or_else(|m| cx.err(&format!("{key}[{i}].init[{j}]"), m))?;
                        }
                        Init::Values(a.clone())
                    }
                    Some(toml::Value::Table(it)) => {
                        if let Some(f) = it.get("file").and_then(|v| v.as_str()) {
                            Init::File(dir.join(f))
                        } else {
                            match (
                                it.get("hash").and_then(|v| v.as_integer()),
                                it.get("modulo").and_then(|v| v.as_integer()),
                            ) {
                                (Some(m), Some(n)) if n > 0 && m >= 0 => {
                                    ty.check_value(&toml::Value::Integer(n - 1)).or_else(|e| {
                                        cx.err(&k("init"), format!("modulo {n} gives values up to {}: {e}", n - 1))
                                    })?;
                                    Init::Hash { mul: m as u64, modulo: n as u64 }
                                }
                                _ => {
                                    return cx.err(
                                        &k("init"),
                                        "expected { hash = M, modulo = N } with N > 0, or { file = \"x.bin\" }",
                                    );
                                }
                            }
                        }
                    }
                    Some(_) => return cx.err(&k("init"), "expected \"zeros\", \"iota\", a table or an array"),
                };
                if buffers.iter().any(|b: &BufferSpec| b.name == name) {
                    return cx.err(&k("name"), format!("buffer `{name}` declared twice"));
                }
                buffers.push(BufferSpec { name, ty, len, init });
            }
        }
        Ok(buffers)
    }

    /// An error for the first key of `t` not in `known`, with the nearest known key.
    fn known_keys(&self, t: &toml::Table, known: &[&str], prefix: &str) -> Result<(), SpecError> {
        for k in t.keys() {
            if known.contains(&k.as_str()) {
                continue;
            }
            let near = known.iter().map(|n| (distance(k, n), *n)).min().filter(|(d, _)| *d <= 2);
            let hint = match near {
                Some((_, n)) => format!("unknown key; did you mean `{n}`?"),
                None => format!("unknown key; known: {}", known.join(", ")),
            };
            return self.err(&format!("{prefix}{k}"), hint);
        }
        Ok(())
    }
}

impl Spec {
    /// Reads and validates a spec file.
    pub fn load(path: &Path) -> Result<Spec, SpecError> {
        let file = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| SpecError::Io { file: file.clone(), msg: e.to_string() })?;
        Spec::parse(&text, path)
    }

    /// Parses spec text; `path` resolves relative file names and names errors.
    pub fn parse(text: &str, path: &Path) -> Result<Spec, SpecError> {
        let file = path.display().to_string();
        let cx = Ctx { file: &file };
        let t: toml::Table =
            toml::from_str(text).map_err(|e| SpecError::Toml { file: file.clone(), msg: e.to_string() })?;
        cx.known_keys(&t, &TOP_KEYS, "")?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let ptx = match t.get("ptx").and_then(|v| v.as_str()) {
            Some(p) => dir.join(p),
            None => return cx.err("ptx", "missing; expected the PTX file's path"),
        };
        let device = t.get("device").and_then(|v| v.as_str()).map(|s| s.to_string());
        let positive = |key: &str, max: u64| -> Result<Option<u64>, SpecError> {
            match t.get(key) {
                None => Ok(None),
                Some(v) => match v.as_integer() {
                    Some(x) if x >= 1 && x as u64 <= max => Ok(Some(x as u64)),
                    _ => cx.err(key, format!("expected an integer from 1 to {max}")),
                },
            }
        };
        let max_instructions = positive("max_instructions", i64::MAX as u64)?;
        let max_call_depth = positive("max_call_depth", u32::MAX as u64)?.map(|d| d as u32);
        let fmad = match t.get("fmad") {
            None => None,
            Some(v) => match v.as_bool() {
                Some(b) => Some(b),
                None => return cx.err("fmad", "expected true or false"),
            },
        };
        let buffers = cx.buffers(&t, "buffer", dir)?;
        let constants = cx.buffers(&t, "constant", dir)?;
        let objects = cx.objects(&t, &buffers)?;
        let launches = match t.get("launch") {
            Some(toml::Value::Array(a)) => a
                .iter()
                .enumerate()
                .map(|(i, v)| match v.as_table() {
                    Some(lt) => {
                        cx.known_keys(lt, &LAUNCH_KEYS, &format!("launch[{i}]."))?;
                        cx.launch(lt, &format!("launch[{i}]."))
                    }
                    None => cx.err(&format!("launch[{i}]"), "expected a table"),
                })
                .collect::<Result<Vec<_>, _>>()?,
            Some(_) => return cx.err("launch", "expected [[launch]] tables"),
            None => vec![cx.launch(&t, "")?],
        };
        if launches.is_empty() {
            return cx.err("launch", "no launch: an empty list runs nothing; give at least one [[launch]] table");
        }
        let mut launches = launches;
        for (li, l) in launches.iter_mut().enumerate() {
            for (ai, a) in l.args.iter_mut().enumerate() {
                let key =
                    if t.contains_key("launch") { format!("launch[{li}].args[{ai}]") } else { format!("args[{ai}]") };
                if let ArgSpec::Buffer(n, off) = a
                    && objects.iter().any(|o| &o.name == n)
                {
                    if *off != 0 {
                        return cx.err(&key, format!("`{n}` is a texture or surface object: it takes no offset"));
                    }
                    *a = ArgSpec::Object(n.clone());
                }
                if let ArgSpec::Buffer(n, off) = a {
                    match buffers.iter().find(|b| &b.name == n) {
                        None => return cx.err(&key, format!("no buffer named `{n}`")),
                        Some(b) if *off > (b.len * b.ty.size()) as u64 => {
                            return cx.err(
                                &key,
                                format!("offset {off} is past the end of `{n}` ({} bytes)", b.len * b.ty.size()),
                            );
                        }
                        Some(_) => {}
                    }
                }
            }
        }
        Ok(Spec {
            file: path.to_path_buf(),
            ptx,
            device,
            buffers,
            constants,
            objects,
            launches,
            max_instructions,
            max_call_depth,
            fmad,
        })
    }

    /// The simulator settings for this spec on a GPU of `profile`: `threads`
    /// host threads, the spec's limits, `max_instructions` (a command-line
    /// flag) over the spec's `max_instructions`, and the device's arithmetic
    /// ([`Profile::configure`]): FMA contraction from `fmad` (a command-line
    /// flag) over the spec's `fmad` over the profile's default, and the
    /// profile's SFU model. `launch`, `step`, `trace` and `--check` all run
    /// on these settings.
    pub fn sim_config(
        &self,
        threads: usize,
        max_instructions: Option<u64>,
        profile: Profile,
        fmad: Option<bool>,
    ) -> SimConfig {
        let mut c = SimConfig { threads, ..SimConfig::default() };
        profile.configure(&mut c, fmad.or(self.fmad));
        if let Some(n) = max_instructions.or(self.max_instructions) {
            c.schedule.max_warp_instructions = n;
        }
        if let Some(d) = self.max_call_depth {
            c.max_call_depth = d;
        }
        c
    }

    /// The initial bytes of buffer `b`.
    pub fn initial_bytes(&self, b: &BufferSpec) -> Result<Vec<u8>, SpecError> {
        let size = b.ty.size();
        let mut out = Vec::with_capacity(b.len * size);
        match &b.init {
            Init::Zeros => out.resize(b.len * size, 0),
            Init::Iota => (0..b.len).for_each(|i| b.ty.encode(i as i128, i as f64, false, &mut out)),
            Init::Hash { mul, modulo } => (0..b.len).for_each(|i| {
                let v = (i as u64).wrapping_mul(*mul) % modulo;
                b.ty.encode(v as i128, v as f64, false, &mut out)
            }),
            Init::File(p) => {
                let io = |msg: String| SpecError::Io { file: p.display().to_string(), msg };
                // only a regular file, and only as much as the buffer holds: never /dev/zero or a FIFO
                let meta = std::fs::metadata(p).map_err(|e| io(e.to_string()))?;
                if !meta.is_file() {
                    return Err(io("not a regular file (a buffer is filled from a file's bytes)".into()));
                }
                if meta.len() > (b.len * size) as u64 {
                    return Err(SpecError::Key {
                        file: self.file.display().to_string(),
                        key: format!("buffer `{}`.init.file", b.name),
                        msg: format!("{} has {} bytes; the buffer holds {}", p.display(), meta.len(), b.len * size),
                    });
                }
                let data = std::fs::read(p).map_err(|e| io(e.to_string()))?;
                if data.len() > b.len * size {
                    return Err(SpecError::Key {
                        file: self.file.display().to_string(),
                        key: format!("buffer `{}`.init.file", b.name),
                        msg: format!("{} has {} bytes; the buffer holds {}", p.display(), data.len(), b.len * size),
                    });
                }
                out = data;
                out.resize(b.len * size, 0);
            }
            Init::Values(vals) => {
                for v in vals {
                    let (i, f, fl) = match v {
                        toml::Value::Integer(x) => (*x as i128, 0.0, false),
                        toml::Value::Float(x) => (0, *x, true),
                        _ => (0, 0.0, false),
                    };
                    b.ty.encode(i, f, fl || (b.ty.is_float() && !matches!(v, toml::Value::Integer(_))), &mut out);
                }
                out.resize(b.len * size, 0);
            }
        }
        Ok(out)
    }
}

/// Buffers of a spec allocated on a device.
pub struct Prepared {
    /// The loaded module.
    pub module: Module,
    /// Buffer name → (device pointer, spec).
    pub buffers: BTreeMap<String, (DevicePtr, BufferSpec)>,
    /// Texture and surface object name → handle.
    pub objects: BTreeMap<String, u64>,
}

/// Loads the spec's PTX (a `.cu` is compiled with clang-16 first,
/// `crate::compile`) and allocates and fills its buffers.
pub fn prepare(spec: &Spec, dev: &mut Device) -> Result<Prepared, SpecError> {
    let src = if spec.ptx.extension().is_some_and(|e| e == "cu") {
        crate::compile::compile(&spec.ptx, crate::compile::Dialect::Clang)
            .map_err(|e| SpecError::Io { file: spec.file.display().to_string(), msg: format!("ptx: {e}") })?
    } else {
        let io = |msg: String| SpecError::Io { file: spec.ptx.display().to_string(), msg };
        // only a regular file of bounded size: never /dev/zero or a FIFO
        let meta = std::fs::metadata(&spec.ptx).map_err(|e| io(e.to_string()))?;
        if !meta.is_file() || meta.len() > MAX_PTX_BYTES {
            return Err(io(format!("not a regular file of at most {} MiB", MAX_PTX_BYTES >> 20)));
        }
        std::fs::read_to_string(&spec.ptx).map_err(|e| io(e.to_string()))?
    };
    let prog = crate::ptx::load(&src, &spec.ptx.display().to_string()).map_err(SimError::from)?;
    check_resources(spec, &prog, dev.config())?;
    let mut module = dev.load_parsed(prog, &src);
    for (i, c) in spec.constants.iter().enumerate() {
        let bytes = spec.initial_bytes(c)?;
        module.write_constant(&c.name, &bytes).map_err(|msg| SpecError::Key {
            file: spec.file.display().to_string(),
            key: format!("constant[{i}]"),
            msg,
        })?;
    }
    let mut buffers = BTreeMap::new();
    for b in &spec.buffers {
        let bytes = spec.initial_bytes(b)?;
        let p = dev.alloc_bytes(bytes.len() as u64, &b.name);
        dev.write(p, &bytes)?;
        buffers.insert(b.name.clone(), (p, b.clone()));
    }
    let mut objects = BTreeMap::new();
    for o in &spec.objects {
        let (handle, table) = match o.at(buffers[&o.buffer].0) {
            crate::sim::texture::Object::Texture(t) => (dev.create_texture(t), "texture"),
            crate::sim::texture::Object::Surface(s) => (dev.create_surface(s), "surface"),
        };
        // the spec's checks come first; the device's own are the last word
        let handle = handle.map_err(|e| SpecError::Key {
            file: spec.file.display().to_string(),
            key: format!("{table} `{}`", o.name),
            msg: e.to_string(),
        })?;
        objects.insert(o.name.clone(), handle);
    }
    Ok(Prepared { module, buffers, objects })
}

/// Host bytes the simulator holds for one resident CTA of `kernel` with
/// `threads` threads and `shared` bytes of shared memory: per warp, the
/// kernel's registers (8 bytes × 32 lanes each), predicates, parameter area
/// and `.local` frame (32 lanes), and one frame of the largest device
/// function besides. An estimate of `src/sim/{cta,warp}.rs`'s layout; deep
/// calls need more (`docs/limits.md`).
pub fn cta_host_bytes(prog: &crate::ptx::Program, kernel: u32, threads: u64, shared: u64) -> u64 {
    let frame = |f: &crate::ptx::ir::Function| -> u64 {
        f.reg_masks.len() as u64 * 256 + f.num_preds as u64 * 4 + (f.frame_param_size as u64 + f.local_size as u64) * 32
    };
    let k = &prog.functions[kernel as usize];
    let callee = prog.functions.iter().filter(|f| !f.is_entry).map(frame).max().unwrap_or(0);
    threads.div_ceil(32) * (frame(k) + callee) + shared
}

/// Checks the spec against the module and the device before anything is
/// allocated: each launched kernel's `.local` frame against the device's
/// local memory, and the buffers, module variables and resident CTAs'
/// state against the host-memory budget ([`crate::limits::memory_budget`]).
pub fn check_resources(spec: &Spec, prog: &crate::ptx::Program, config: &SimConfig) -> Result<(), SpecError> {
    use crate::limits::{LimitError, check_memory, show_bytes};
    let file = spec.file.display().to_string();
    let bytes = |b: &BufferSpec| (b.len * b.ty.size()) as u64;
    let globals: u64 = prog.globals.iter().map(|g| g.size.max(1).div_ceil(4) * 4).fold(0, u64::saturating_add);
    let buffers: u64 = spec.buffers.iter().map(bytes).fold(0, u64::saturating_add);
    let staging = spec.buffers.iter().chain(&spec.constants).map(bytes).max().unwrap_or(0);
    let largest_global = prog.globals.iter().max_by_key(|g| g.size);
    let memory = globals.saturating_add(buffers);
    let what = || match largest_global {
        Some(g) if g.size > buffers => format!(
            "{}: the module's .global variables ({}; `{}` alone is {})",
            spec.ptx.display(),
            show_bytes(globals),
            g.name,
            show_bytes(g.size)
        ),
        _ => format!("{file}: the buffers and the module's .global variables ({})", show_bytes(memory)),
    };
    check_memory(what, memory.saturating_add(staging)).map_err(SpecError::Limit)?;
    let multi = spec.launches.len() > 1;
    for (i, l) in spec.launches.iter().enumerate() {
        let key = if multi { format!("launch[{i}].kernel") } else { "kernel".to_string() };
        let Some(k) = prog.kernel(&l.kernel) else { continue };
        let f = &prog.functions[k as usize];
        if f.local_size > config.local_limit {
            return Err(SpecError::Key {
                file,
                key,
                msg: format!(
                    "kernel `{}` has {} of .local memory per thread; the simulated device has {} (docs/limits.md)",
                    l.kernel,
                    show_bytes(f.local_size as u64),
                    show_bytes(config.local_limit as u64)
                ),
            });
        }
        let threads: u64 = l.block.iter().map(|&x| x as u64).product();
        let ctas: u64 = l.grid.iter().map(|&x| x as u64).product();
        let resident = ctas.min(config.schedule.max_resident_ctas.max(1) as u64);
        let shared = prog.static_shared_size as u64 + l.shared as u64;
        let per_cta = cta_host_bytes(prog, k, threads, shared);
        let need = memory.saturating_add(resident.saturating_mul(per_cta));
        check_memory(
            || {
                format!(
                    "{file}: `{key}`: kernel `{}` ({} registers, {} .local per thread) with {resident} resident CTAs of \
                     {threads} threads ({} each) beside the buffers",
                    l.kernel,
                    f.reg_masks.len(),
                    show_bytes(f.local_size as u64),
                    show_bytes(per_cta)
                )
            },
            need,
        )
        .map_err(|e: LimitError| SpecError::Limit(e))?;
    }
    Ok(())
}

/// The kernel arguments of launch `l`, typed by the kernel's parameters.
pub fn arguments(spec: &Spec, p: &Prepared, l: &LaunchSpec) -> Result<Vec<Arg>, SpecError> {
    let file = spec.file.display().to_string();
    let f = match p.module.prog.kernel(&l.kernel) {
        Some(k) => match p.module.prog.kernel_error(k) {
            // a kernel that needs an instruction warplight does not execute
            Some(e) => return Err(SpecError::Sim(SimError::Ptx(e.clone()))),
            None => &p.module.prog.functions[k as usize],
        },
        None => {
            return Err(SpecError::Sim(SimError::UnknownKernel {
                name: l.kernel.clone(),
                file: p.module.prog.source_name.clone(),
                available: p.module.prog.kernel_names().join(", "),
            }));
        }
    };
    if f.params.len() != l.args.len() {
        return Err(SpecError::Key {
            file,
            key: "args".into(),
            msg: format!("kernel `{}` takes {} argument(s), the spec gives {}", l.kernel, f.params.len(), l.args.len()),
        });
    }
    let mut out = Vec::new();
    for (i, (a, prm)) in l.args.iter().zip(&f.params).enumerate() {
        let bad = |msg: String| SpecError::Key { file: file.clone(), key: format!("args[{i}]"), msg };
        out.push(match a {
            ArgSpec::Buffer(n, off) => {
                if prm.size != 8 {
                    return Err(bad(format!(
                        "buffer `{n}` passed to `{}`, a {}-byte .{} parameter",
                        prm.name, prm.size, prm.ty
                    )));
                }
                Arg::Ptr(DevicePtr(p.buffers[n].0.0 + off))
            }
            ArgSpec::Int(x) => match (prm.ty, prm.size) {
                (Ty::F32, _) => Arg::F32(*x as f32),
                (Ty::F64, _) => Arg::F64(*x as f64),
                (_, 4) => Arg::Bytes((*x as u32).to_le_bytes().to_vec()),
                (_, 8) => Arg::Bytes((*x as u64).to_le_bytes().to_vec()),
                (_, 2) => Arg::Bytes((*x as u16).to_le_bytes().to_vec()),
                (_, 1) => Arg::Bytes(vec![*x as u8]),
                (t, s) => return Err(bad(format!("cannot pass an integer to `{}` (.{t}, {s} bytes)", prm.name))),
            },
            ArgSpec::Object(n) => {
                if prm.size != 8 {
                    return Err(bad(format!(
                        "object `{n}` passed to `{}`, a {}-byte .{} parameter (a handle is 8 bytes)",
                        prm.name, prm.size, prm.ty
                    )));
                }
                Arg::U64(p.objects[n])
            }
            ArgSpec::Float(x) => match prm.ty {
                Ty::F32 => Arg::F32(*x as f32),
                Ty::F64 => Arg::F64(*x),
                t => return Err(bad(format!("float literal for `{}`, a .{t} parameter", prm.name))),
            },
        });
    }
    Ok(out)
}

/// What one launch produced.
#[derive(Debug, Clone)]
pub struct LaunchResult {
    /// The core's counters.
    pub stats: LaunchStats,
    /// The device profile's memory counters.
    pub memory: ModelStats,
    /// Occupancy under the profile.
    pub occupancy: Occupancy,
}

impl LaunchResult {
    /// Every counter: the core's, the memory model's (`mem.*`), the profiler's names
    /// for the profile, and occupancy (`occupancy.*`).
    pub fn metrics(&self) -> Vec<(String, u64)> {
        let mut v = self.stats.totals.flatten();
        v.extend(self.memory.metrics(&self.stats.totals));
        let o = &self.occupancy;
        for (k, x) in [
            ("occupancy.registers_per_thread", o.registers_per_thread),
            ("occupancy.shared_per_cta", o.shared_per_cta),
            ("occupancy.ctas_per_sm", o.ctas_per_sm),
            ("occupancy.pct", o.occupancy_pct),
        ] {
            v.push((k.to_string(), x as u64));
        }
        v
    }
}

/// Runs every launch of the spec in order under `profile`; returns each launch's results.
pub fn run(spec: &Spec, dev: &mut Device, p: &Prepared, profile: Profile) -> Result<Vec<LaunchResult>, SpecError> {
    let mut out = Vec::new();
    for l in &spec.launches {
        let args = arguments(spec, p, l)?;
        let cfg = LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
        let model = Model::new(profile, &p.module.prog);
        let stats = dev.launch_observed(&p.module, &l.kernel, cfg, &args, Some(&model))?;
        let k = p.module.prog.kernel(&l.kernel).expect("checked by arguments()");
        let threads = l.block.iter().product();
        out.push(LaunchResult {
            stats,
            memory: model.finish(),
            occupancy: occupancy(profile, &p.module.prog, k, threads, l.shared),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Spec, SpecError> {
        Spec::parse(s, Path::new("dir/spec.toml"))
    }

    #[test]
    fn parses_the_documented_example() {
        let s = parse(
            r#"ptx = "micro.ptx"
kernel = "copy_stride"
grid = [64, 1, 1]
block = [256, 1, 1]
args = ["in", "out", 1, 0.5]
[[buffer]]
name = "in"
type = "f32"
len = 8
init = { hash = 2654435761, modulo = 16 }
[[buffer]]
name = "out"
type = "u8"
len = 4
init = [1, 2, 3]
"#,
        )
        .unwrap();
        assert_eq!(s.ptx, Path::new("dir/micro.ptx"));
        assert_eq!(s.launches[0].grid, [64, 1, 1]);
        assert_eq!(s.launches[0].args[3], ArgSpec::Float(0.5));
        let inb = s.initial_bytes(&s.buffers[0]).unwrap();
        let first: Vec<f32> = inb.chunks(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
        let exp: Vec<f32> = (0..8u64).map(|i| (i.wrapping_mul(2654435761) % 16) as f32).collect();
        assert_eq!(first, exp);
        assert_eq!(s.initial_bytes(&s.buffers[1]).unwrap(), vec![1, 2, 3, 0]);
    }

    #[test]
    fn limits_come_from_the_flag_then_the_spec_then_the_default() {
        let base = "ptx = \"a.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\n";
        let s = parse(base).unwrap();
        assert_eq!((s.max_instructions, s.max_call_depth), (None, None));
        let c = s.sim_config(3, None, Profile::Hopper, None);
        assert_eq!(c.threads, 3);
        assert_eq!(c.schedule.max_warp_instructions, crate::sim::device::DEFAULT_MAX_WARP_INSTRUCTIONS);
        assert_eq!(c.max_call_depth, crate::sim::device::DEFAULT_MAX_CALL_DEPTH);
        assert_eq!(s.sim_config(0, Some(7), Profile::Hopper, None).schedule.max_warp_instructions, 7);
        let s = parse(&format!("max_instructions = 1000\nmax_call_depth = 9\n{base}")).unwrap();
        assert_eq!(s.sim_config(0, None, Profile::Hopper, None).schedule.max_warp_instructions, 1000);
        assert_eq!(s.sim_config(0, Some(7), Profile::Hopper, None).schedule.max_warp_instructions, 7);
        assert_eq!(s.sim_config(0, None, Profile::Hopper, None).max_call_depth, 9);
        assert_eq!(parse(&format!("fmad = false\n{base}")).unwrap().fmad, Some(false));
        assert_eq!(s.fmad, None);
        for bad in ["max_instructions = 0", "max_call_depth = 4294967296", "max_call_depth = 1.5"] {
            let e = parse(&format!("{bad}\n{base}")).unwrap_err();
            assert!(e.to_string().contains("expected an integer from 1 to"), "{bad}: {e}");
        }
        let e = parse(&format!("fmad = 1\n{base}")).unwrap_err();
        assert!(e.to_string().contains("`fmad`: expected true or false"), "{e}");
    }

    #[test]
    fn errors_name_the_key() {
        let e = parse("ptx = \"a.ptx\"\nkernel = \"k\"\ngrid = [0]\nblock = 32\n").unwrap_err();
        assert_eq!(e.to_string(), "dir/spec.toml: `grid`: dimensions are positive integers");
        let e = parse("ptx = \"a.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\nargs = [\"nope\"]\n").unwrap_err();
        assert!(e.to_string().contains("`args[0]`: no buffer named `nope`"), "{e}");
        let e = parse("ptx = \"a.ptx\"\n[[buffer]]\nname = \"b\"\ntype = \"f16\"\nlen = 1\n").unwrap_err();
        assert!(e.to_string().contains("`buffer[0].type`"), "{e}");
        let e = parse("ptx = \"a.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\nshraed = 256\n").unwrap_err();
        assert!(e.to_string().contains("`shraed`: unknown key; did you mean `shared`?"), "{e}");
        let e = parse("ptx = \"a.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\n[[buffer]]\nname = \"b\"\ntype = \"f32\"\nlen = 1\nint = \"iota\"\n").unwrap_err();
        assert!(e.to_string().contains("`buffer[0].int`: unknown key; did you mean `init`?"), "{e}");
        let e = parse("ptx = \"a.ptx\"\nwhatever = 1\n").unwrap_err();
        assert!(e.to_string().contains("`whatever`: unknown key; known: ptx, device"), "{e}");
        let big = "ptx = \"a.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 32\n[[buffer]]\nname = \"b\"\ntype = \"f32\"\nlen = 4611686018427387904\n";
        let e = parse(big).unwrap_err();
        assert!(e.to_string().contains("is more than a buffer may hold (8 GiB)"), "{e}");
        let e = parse("ptx = 3").unwrap_err();
        assert!(e.to_string().contains("`ptx`: missing"), "{e}");
        let e = parse("ptx = \"a.ptx\"\nkernel = [").unwrap_err();
        assert!(matches!(e, SpecError::Toml { .. }));
    }
}
