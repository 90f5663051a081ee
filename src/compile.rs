//! CUDA C to PTX: calls clang-16 (or nvcc) with the flags the project's own
//! kernels are built with (`kernels/build.sh`) and warplight's prelude
//! (`kernels/prelude.h`, compiled into the binary), so that `warplight
//! compile kernel.cu` works from any directory without the CUDA SDK.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The prelude: CUDA keywords and intrinsics for clang without the SDK.
pub const PRELUDE: &str = include_str!("../kernels/prelude.h");

/// Which compiler makes the PTX.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// Debian's clang-16 (`$CLANG` overrides the program).
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

/// Compiles `src` to PTX (sm_90, PTX 7.8 for clang) with the prelude
/// included first, line tables on, and returns the PTX text.
pub fn compile(src: &Path, d: Dialect) -> Result<String, CompileError> {
    let file = src.display().to_string();
    if !src.is_file() {
        return Err(CompileError::Io { file, msg: "no such file".into() });
    }
    let cc = compiler(d)?;
    let dir = std::env::temp_dir().join(format!("warplight-compile-{}", std::process::id()));
    let io = |f: &Path, e: std::io::Error| CompileError::Io { file: f.display().to_string(), msg: e.to_string() };
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
    let prelude = dir.join("prelude.h");
    std::fs::write(&prelude, PRELUDE).map_err(|e| io(&prelude, e))?;
    let out = dir.join("out.ptx");
    let mut cmd = Command::new(&cc);
    match d {
        Dialect::Clang => {
            cmd.args(["-x", "cuda", "--cuda-device-only", "-nocudainc", "-nocudalib", "--cuda-gpu-arch=sm_90"])
                .args(["-Xclang", "-target-feature", "-Xclang", "+ptx78", "-O3", "-ffp-contract=on"])
                .args(["-gline-tables-only", "-fdebug-compilation-dir=.", "-S"]);
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
        std::fs::read_to_string(&out).map_err(|e| io(&out, e))
    } else {
        Err(CompileError::Failed {
            file,
            program: cc.display().to_string(),
            stderr: String::from_utf8_lossy(&o.stderr).trim_end().to_string(),
        })
    };
    let _ = std::fs::remove_dir_all(&dir);
    result
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
    fn unknown_dialects_and_missing_files_are_errors() {
        assert!(Dialect::named("gcc").is_err());
        let e = compile(Path::new("/nonexistent/k.cu"), Dialect::Clang).unwrap_err();
        assert_eq!(e.to_string(), "/nonexistent/k.cu: no such file");
    }
}
