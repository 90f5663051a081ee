//! `warplight compile kernel.cu`: CUDA C to PTX with clang-16 or nvcc, the
//! project's flags and the prelude (`crate::compile`).

use std::path::PathBuf;

use crate::compile::{CompileOptions, Dialect, compile_with, demangle};

/// Options of `warplight compile`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
The prelude (kernels/prelude.h: the CUDA keywords, threadIdx & co., atomics, shuffles, votes,
__syncthreads, __ldg, printf) is included first, so a .cu needs no #include. CUDA's math
library (expf, sinf, powf, min, max, abs, ...; docs/prelude.md) comes from libdevice, found
through --libdevice, WARPLIGHT_LIBDEVICE, a CUDA install or `pip install nvidia-cuda-nvcc`.
Kernels declared
`extern \"C\" __global__` keep their names; others get C++ names (_Z5saxpyifPfS_), which
`compile` lists beside the plain name.

Examples:
  warplight compile saxpy.cu                   writes saxpy.ptx beside it
  warplight compile saxpy.cu -o /tmp/s.ptx --dialect nvcc
  warplight launch spec.toml                   with ptx = \"saxpy.ptx\" in the spec")]
pub struct CompileArgs {
    /// The CUDA source.
    pub source: PathBuf,
    /// The PTX file to write (default: the source with the extension .ptx).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// clang (Debian's clang-16, the default) or nvcc.
    #[arg(long, default_value = "clang")]
    pub dialect: String,
    /// libdevice.10.bc, CUDA's math library (default: WARPLIGHT_LIBDEVICE, CUDA installs,
    /// the pip package nvidia-cuda-nvcc).
    #[arg(long, value_name = "FILE")]
    pub libdevice: Option<PathBuf>,
}

/// Runs the command.
pub fn run(a: CompileArgs) -> Result<(), Box<dyn std::error::Error>> {
    let d = Dialect::named(&a.dialect)?;
    let out = a.output.clone().unwrap_or_else(|| a.source.with_extension("ptx"));
    if out == a.source {
        return Err(format!("{}: the output would overwrite the source", out.display()).into());
    }
    let ptx = compile_with(&a.source, &CompileOptions { dialect: d, libdevice: a.libdevice.clone() })?;
    // check that warplight can run what was made before writing it
    let prog = crate::ptx::load(&ptx, &out.display().to_string())?;
    super::write_atomically(&out, ptx.as_bytes())?;
    println!("wrote {}", out.display());
    let mut mangled = false;
    for name in prog.kernel_names() {
        match demangle(name) {
            Some(plain) => {
                mangled = true;
                println!("  kernel {plain} (PTX name {name})");
            }
            None => println!("  kernel {name}"),
        }
    }
    if mangled {
        println!("  (declare kernels `extern \"C\" __global__` to keep their plain names in the PTX)");
    }
    Ok(())
}
