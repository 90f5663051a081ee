//! CUDA C to PTX: calls clang-16 (or nvcc) with the flags the project's own
//! kernels are built with (`kernels/build.sh`) and warplight's prelude
//! (`kernels/prelude.h`, compiled into the binary), so that `warplight
//! compile kernel.cu` works from any directory without the CUDA SDK.
//!
//! CUDA's math library (`expf`, `sinf`, `powf`, `min`, ...; `docs/prelude.md`)
//! comes from libdevice, NVIDIA's bitcode library, which clang links into the
//! kernel when [`find_libdevice`] finds it (`kernels/cuda_math.h` declares the
//! functions). A few instructions of libdevice's that warplight does not
//! execute are rewritten into equivalent ones ([`rewrite_for_warplight`]).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The prelude: CUDA keywords and intrinsics for clang without the SDK.
pub const PRELUDE: &str = include_str!("../kernels/prelude.h");

/// CUDA's math library declarations for clang (included by the prelude when
/// `WL_CUDA_MATH` is defined, which [`compile`] does when libdevice is found).
pub const CUDA_MATH: &str = include_str!("../kernels/cuda_math.h");

/// The folder the PTX's line table names for the prelude and
/// `cuda_math.h` (`.file 3 "kernels/prelude.h"`): the project's copies, which
/// are compiled into the binary, so that PTX does not depend on where it was
/// compiled.
pub const PRELUDE_DIR: &str = "kernels";

/// The environment variable naming libdevice (`libdevice.10.bc`).
pub const LIBDEVICE_ENV: &str = "WARPLIGHT_LIBDEVICE";

/// How to get libdevice when it is missing.
pub const LIBDEVICE_HINT: &str = "install it with `pip install nvidia-cuda-nvcc` (no GPU needed; warplight finds it \
through `python3`), or name the file with --libdevice PATH or WARPLIGHT_LIBDEVICE=PATH \
(CUDA toolkits have it at nvvm/libdevice/libdevice.10.bc)";

/// CUDA math functions a student is likely to call: when clang reports one of
/// them undeclared and libdevice is missing, the error says how to get it.
const MATH_NAMES: &[&str] = &[
    "min",
    "max",
    "abs",
    "expf",
    "exp",
    "exp10f",
    "expm1f",
    "logf",
    "log",
    "log2f",
    "log10f",
    "log1pf",
    "sinf",
    "sin",
    "cosf",
    "cos",
    "tanf",
    "tan",
    "sincosf",
    "asinf",
    "acosf",
    "atanf",
    "atan2f",
    "sinhf",
    "coshf",
    "tanhf",
    "powf",
    "pow",
    "cbrtf",
    "floorf",
    "floor",
    "ceilf",
    "ceil",
    "roundf",
    "round",
    "truncf",
    "fmodf",
    "hypotf",
    "erff",
    "lgammaf",
    "tgammaf",
    "__expf",
    "__logf",
    "__powf",
    "__fdividef",
    "__sincosf",
    "__tanf",
    "fmin",
    "fmax",
    "fabs",
    "isnan",
    "isinf",
    "copysignf",
    "umin",
    "umax",
    "llmin",
    "llmax",
    "llabs",
    "printf",
];

/// Which compiler makes the PTX.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dialect {
    /// Debian's clang-16 (`$CLANG` overrides the program).
    #[default]
    Clang,
    /// NVIDIA's nvcc (`$NVCC`, else `nvcc` on `PATH`).
    Nvcc,
}

impl Dialect {
    /// By name.
    pub fn named(s: &str) -> Result<Dialect, CompileError> {
        match s {
            "clang" => Ok(Dialect::Clang),
            "nvcc" => Ok(Dialect::Nvcc),
            other => Err(CompileError::Dialect(other.into())),
        }
    }
}

/// Why a compilation failed.
#[derive(Debug, thiserror::Error)]
pub enum CompileError {
    /// Unknown dialect.
    #[error("--dialect {0}: expected clang or nvcc")]
    Dialect(String),
    /// The compiler is not installed.
    #[error("{program} is not installed; {hint}")]
    NotInstalled {
        /// The program looked for.
        program: String,
        /// How to install it.
        hint: &'static str,
    },
    /// Reading or writing a file failed.
    #[error("{file}: {msg}")]
    Io {
        /// The file.
        file: String,
        /// What went wrong.
        msg: String,
    },
    /// The source calls a CUDA math function and libdevice was not found.
    #[error("{file}: `{function}` is in CUDA's math library (libdevice), which was not found; {hint}\n{stderr}")]
    NoLibdevice {
        /// The source.
        file: String,
        /// The undeclared function.
        function: String,
        /// How to install libdevice.
        hint: &'static str,
        /// The compiler's messages.
        stderr: String,
    },
    /// `--libdevice` or `WARPLIGHT_LIBDEVICE` names no file.
    #[error("{file}: libdevice not found there ({from}); {hint}")]
    LibdeviceMissing {
        /// The path given.
        file: String,
        /// Where it was given (the option or the variable).
        from: &'static str,
        /// How to install libdevice.
        hint: &'static str,
    },
    /// The compiler rejected the source.
    #[error("{file}: {program} failed:\n{stderr}")]
    Failed {
        /// The source.
        file: String,
        /// The compiler.
        program: String,
        /// Its messages.
        stderr: String,
    },
}

const CLANG_HINT: &str = "install it with `apt-get install clang-16` (Debian/Ubuntu; any clang 16 works with CLANG=/path/to/clang), or use --dialect nvcc";
const NVCC_HINT: &str =
    "`pip install nvidia-cuda-nvcc` installs one without a GPU; point NVCC at its bin/nvcc or put it on PATH";

/// An executable on `PATH` (or `program` itself when it contains a `/`).
fn which(program: &str) -> Option<PathBuf> {
    if program.contains('/') {
        let p = PathBuf::from(program);
        return p.is_file().then_some(p);
    }
    std::env::split_paths(&std::env::var_os("PATH")?).map(|d| d.join(program)).find(|p| p.is_file())
}

/// The compiler of `d`, or why it cannot be had.
pub fn compiler(d: Dialect) -> Result<PathBuf, CompileError> {
    let (var, default, hint) = match d {
        Dialect::Clang => ("CLANG", "clang-16", CLANG_HINT),
        Dialect::Nvcc => ("NVCC", "nvcc", NVCC_HINT),
    };
    let program = std::env::var(var).ok().filter(|v| !v.is_empty()).unwrap_or_else(|| default.to_string());
    which(&program).ok_or(CompileError::NotInstalled { program, hint })
}

/// How to compile a CUDA source.
#[derive(Debug, Clone, Default)]
pub struct CompileOptions {
    /// The compiler.
    pub dialect: Dialect,
    /// libdevice as named by `--libdevice`; `None` looks for it ([`find_libdevice`]).
    pub libdevice: Option<PathBuf>,
}

/// The libdevice file under a CUDA installation or pip package root.
fn libdevice_under(root: &Path) -> Option<PathBuf> {
    ["nvvm/libdevice/libdevice.10.bc", "libdevice/libdevice.10.bc"].iter().map(|r| root.join(r)).find(|p| p.is_file())
}

/// The roots of the pip packages `nvidia-cuda-nvcc` (`nvidia/cu13`, CUDA 13)
/// and `nvidia-cuda-nvcc-cu12` (`nvidia/cuda_nvcc`), as `python3` sees them.
fn pip_roots() -> Vec<PathBuf> {
    let python = std::env::var("PYTHON").ok().filter(|p| !p.is_empty()).unwrap_or_else(|| "python3".into());
    let Ok(o) = Command::new(python)
        .args(["-c", "import nvidia\nfor p in nvidia.__path__: print(p)"])
        .stderr(std::process::Stdio::null())
        .output()
    else {
        return Vec::new();
    };
    let mut roots = Vec::new();
    for dir in String::from_utf8_lossy(&o.stdout).lines().map(PathBuf::from) {
        let mut subs: Vec<PathBuf> =
            std::fs::read_dir(&dir).map(|d| d.flatten().map(|e| e.path()).collect()).unwrap_or_default();
        subs.sort();
        roots.extend(subs);
    }
    roots
}

/// libdevice (`libdevice.10.bc`, CUDA's math library as LLVM bitcode).
///
/// In order: `explicit` (`--libdevice`), `$WARPLIGHT_LIBDEVICE` (`none`
/// compiles without the math library), `$CUDA_HOME`, `$CUDA_PATH`, beside
/// `$NVCC` or the `nvcc` on `PATH`, `/usr/local/cuda`, Debian's
/// `nvidia-cuda-toolkit`, and the pip package `nvidia-cuda-nvcc` as
/// `python3` finds it. `Ok(None)` when none has it; an error when the file
/// named explicitly does not exist.
pub fn find_libdevice(explicit: Option<&Path>) -> Result<Option<PathBuf>, CompileError> {
    let named = |p: &Path, from: &'static str| {
        if p.is_file() {
            Ok(Some(p.to_path_buf()))
        } else {
            Err(CompileError::LibdeviceMissing { file: p.display().to_string(), from, hint: LIBDEVICE_HINT })
        }
    };
    if let Some(p) = explicit {
        return named(p, "--libdevice");
    }
    if let Some(v) = std::env::var_os(LIBDEVICE_ENV).filter(|v| !v.is_empty()) {
        if v == "none" {
            return Ok(None);
        }
        return named(Path::new(&v), LIBDEVICE_ENV);
    }
    let mut roots: Vec<PathBuf> = ["CUDA_HOME", "CUDA_PATH"]
        .iter()
        .filter_map(std::env::var_os)
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .collect();
    if let Ok(nvcc) = compiler(Dialect::Nvcc)
        && let Some(root) = std::fs::canonicalize(&nvcc).ok().and_then(|p| Some(p.parent()?.parent()?.to_path_buf()))
    {
        roots.push(root);
    }
    roots.extend(["/usr/local/cuda", "/usr/lib/cuda", "/usr/lib/nvidia-cuda-toolkit"].map(PathBuf::from));
    if let Some(p) = roots.iter().find_map(|r| libdevice_under(r)) {
        return Ok(Some(p));
    }
    Ok(pip_roots().iter().find_map(|r| libdevice_under(r)))
}

/// Rewrites what libdevice brings that warplight does not execute into
/// equivalent PTX on the same line, so that line numbers stay:
/// `min/max.NaN.f32` ([`nan_min_max`], `sinhf`). Everything else of
/// libdevice's, the inline-assembly carry chains (`mad.lo.cc.u32`,
/// `madc.hi.cc.u32`, `addc`, `subc`: the trigonometric functions' argument
/// reduction) and register lists (`.reg .u32 r0, r1;`) included, runs as clang
/// wrote it.
pub fn rewrite_for_warplight(ptx: &str) -> String {
    let mut out = String::with_capacity(ptx.len() + 256);
    for line in ptx.lines() {
        out.push_str(&nan_min_max(line));
        out.push('\n');
    }
    out
}

/// `min.NaN.f32 d, a, b` (and `max`; libdevice's `sinhf` uses it): the
/// result is NaN when an operand is, else `min`. Written with `setp.nan`,
/// `min` and `selp` on the same line.
fn nan_min_max(line: &str) -> std::borrow::Cow<'_, str> {
    let t = line.trim();
    let Some((op, rest)) =
        t.strip_prefix("min.NaN.f32").map(|r| ("min", r)).or_else(|| t.strip_prefix("max.NaN.f32").map(|r| ("max", r)))
    else {
        return line.into();
    };
    let ops: Vec<&str> = rest.trim().trim_end_matches(';').split(',').map(str::trim).collect();
    let [d, a, b] = ops.as_slice() else {
        return line.into();
    };
    format!(
        "\t{{ .reg .pred %wl_p; .reg .f32 %wl_t; setp.nan.f32 %wl_p, {a}, {b}; {op}.f32 %wl_t, {a}, {b}; \
         selp.f32 {d}, 0f7FFFFFFF, %wl_t, %wl_p; }} // warplight: {op}.NaN.f32"
    )
    .into()
}

static COMMAND_LINE: std::sync::OnceLock<CompileOptions> = std::sync::OnceLock::new();

/// Sets the options of the command line (`warplight run kernel.cu --dialect
/// nvcc --libdevice FILE`) for every `.cu` this process compiles through
/// [`compile`] (a launch spec's `ptx = "kernel.cu"` included); once, before
/// any work.
pub fn set_command_line_options(o: CompileOptions) {
    let _ = COMMAND_LINE.set(o);
}

/// Compiles `src` to PTX with clang-16 or nvcc, libdevice looked for
/// ([`compile_with`]): with the command line's options when they were set
/// ([`set_command_line_options`]), else with dialect `d` and the default options.
pub fn compile(src: &Path, d: Dialect) -> Result<String, CompileError> {
    match COMMAND_LINE.get() {
        Some(o) => compile_with(src, o),
        None => compile_with(src, &CompileOptions { dialect: d, libdevice: None }),
    }
}

/// Compiles `src` to PTX (sm_90, PTX 7.8 for clang) with the prelude
/// included first, line tables on, and returns the PTX text. With clang and
/// libdevice found, CUDA's math library is declared (`WL_CUDA_MATH`) and
/// libdevice linked in.
pub fn compile_with(src: &Path, opts: &CompileOptions) -> Result<String, CompileError> {
    let d = opts.dialect;
    let file = src.display().to_string();
    if !src.is_file() {
        return Err(CompileError::Io { file, msg: "no such file".into() });
    }
    let cc = compiler(d)?;
    let libdevice = match d {
        Dialect::Clang => find_libdevice(opts.libdevice.as_deref())?,
        Dialect::Nvcc => None, // nvcc brings its own math library
    };
    // one folder per compilation: tests and threads compile at the same time
    static COMPILATIONS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COMPILATIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("warplight-compile-{}-{n}", std::process::id()));
    let io = |f: &Path, e: std::io::Error| CompileError::Io { file: f.display().to_string(), msg: e.to_string() };
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
    let prelude = dir.join("prelude.h");
    std::fs::write(&prelude, PRELUDE).map_err(|e| io(&prelude, e))?;
    let math = dir.join("cuda_math.h");
    std::fs::write(&math, CUDA_MATH).map_err(|e| io(&math, e))?;
    let out = dir.join("out.ptx");
    let mut cmd = Command::new(&cc);
    match d {
        Dialect::Clang => {
            cmd.args(["-x", "cuda", "--cuda-device-only", "-nocudainc", "-nocudalib", "--cuda-gpu-arch=sm_90"])
                .args(["-Xclang", "-target-feature", "-Xclang", "+ptx78", "-O3", "-ffp-contract=on"])
                .args(["-gline-tables-only", "-fdebug-compilation-dir=.", "-S"])
                // the prelude's lines name the project's copy, not this temporary folder
                .arg(format!("-fdebug-prefix-map={}={PRELUDE_DIR}", dir.display()));
            if let Some(lib) = &libdevice {
                // nvcc's defaults: no flush to zero, precise transcendentals
                cmd.arg("-DWL_CUDA_MATH").args(["-Xclang", "-mlink-builtin-bitcode", "-Xclang"]).arg(lib);
            }
        }
        Dialect::Nvcc => {
            cmd.args(["-arch=sm_90", "-O3", "-ptx", "-lineinfo"]);
        }
    }
    // the prelude comes first unless the source includes it itself (`#include "prelude.h"` finds this copy)
    let text = std::fs::read_to_string(src).map_err(|e| io(src, e))?;
    if !text.contains("prelude.h") {
        cmd.arg("-include").arg(&prelude);
    }
    cmd.arg(format!("-I{}", dir.display())).arg("-o").arg(&out).arg(src);
    let o = cmd.output().map_err(|e| io(&cc, e))?;
    let result = if o.status.success() {
        std::fs::read_to_string(&out).map_err(|e| io(&out, e)).map(|p| match d {
            Dialect::Clang => rewrite_for_warplight(&p),
            Dialect::Nvcc => p,
        })
    } else {
        let stderr = String::from_utf8_lossy(&o.stderr).trim_end().to_string();
        match undeclared_math(&stderr).filter(|_| d == Dialect::Clang && libdevice.is_none()) {
            Some(function) => Err(CompileError::NoLibdevice { file, function, hint: LIBDEVICE_HINT, stderr }),
            None => Err(CompileError::Failed { file, program: cc.display().to_string(), stderr }),
        }
    };
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// The first CUDA math function clang reports undeclared, if any.
fn undeclared_math(stderr: &str) -> Option<String> {
    stderr.lines().find_map(|l| {
        let rest = l.split("use of undeclared identifier '").nth(1)?;
        let name = rest.split('\'').next()?;
        MATH_NAMES.contains(&name).then(|| name.to_string())
    })
}

pub use crate::ptx::ir::demangle;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demangles_plain_function_names() {
        assert_eq!(demangle("_Z5saxpyifPfS_").as_deref(), Some("saxpy"));
        assert_eq!(demangle("_Z10reduce_sumPiPKi").as_deref(), Some("reduce_sum"));
        assert_eq!(demangle("reduce_sum"), None);
        assert_eq!(demangle("_Z99x"), None);
    }

    #[test]
    fn only_nan_min_max_is_rewritten_and_lines_stay() {
        let ptx = "\tmad.lo.cc.u32 r0, a, b, c;\n\tmadc.hi.u32 r1, a, b, 0;\n\tmin.NaN.f32 %f2, %f1, 0f42FC0000;\n\t.reg .u32 r0, r1;\n";
        let out = rewrite_for_warplight(ptx);
        assert_eq!(out.lines().count(), 4);
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(lines[..2], ["\tmad.lo.cc.u32 r0, a, b, c;", "\tmadc.hi.u32 r1, a, b, 0;"]);
        assert!(lines[2].contains("setp.nan.f32 %wl_p, %f1, 0f42FC0000; min.f32 %wl_t, %f1, 0f42FC0000;"));
        assert!(lines[2].contains("selp.f32 %f2, 0f7FFFFFFF, %wl_t, %wl_p;"));
        assert_eq!(lines[3], "\t.reg .u32 r0, r1;");
    }

    #[test]
    fn unknown_dialects_and_missing_files_are_errors() {
        assert!(Dialect::named("gcc").is_err());
        let e = compile(Path::new("/nonexistent/k.cu"), Dialect::Clang).unwrap_err();
        assert_eq!(e.to_string(), "/nonexistent/k.cu: no such file");
    }
}
