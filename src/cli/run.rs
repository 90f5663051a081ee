//! `warplight run kernel.cu --grid … --block … --buffer … --args …`: compile a
//! CUDA source and launch one kernel of it without writing a spec file. The
//! options become a launch spec (`docs/launch-spec.md`) that `launch` runs.

use std::path::PathBuf;

use super::launch::{LaunchOptions, run_spec};
use crate::launch_spec::Spec;

/// Options of `warplight run`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Buffers: NAME=TYPE:LEN[:INIT], TYPE one of u8 u16 u32 u64 i8 i16 i32 i64 f32 f64,
INIT zeros (the default), iota (0, 1, 2, ...), hash=M/N (element i is i*M mod N) or file=PATH.
Arguments: --args in the kernel's parameter order: buffer names (NAME+BYTES for an address
inside a buffer) or numbers.

Example (saxpy.cu: __global__ void saxpy(int n, float a, const float *x, float *y)):
  warplight run saxpy.cu --grid 4 --block 256 --buffer x=f32:1000:iota --buffer y=f32:1000 \\
      --args 1000,2.0,x,y --dump y=y.bin --per-line")]
pub struct RunArgs {
    /// The CUDA source (.cu, compiled with clang-16) or PTX file.
    pub source: PathBuf,
    /// The kernel (its plain name); default: the file's only kernel.
    #[arg(long)]
    pub kernel: Option<String>,
    /// Grid size: N or X,Y,Z.
    #[arg(long)]
    pub grid: String,
    /// Block size: N or X,Y,Z.
    #[arg(long)]
    pub block: String,
    /// Dynamic shared memory in bytes.
    #[arg(long, default_value_t = 0)]
    pub shared: u64,
    /// A buffer: NAME=TYPE:LEN[:INIT] (repeat for more).
    #[arg(long = "buffer", value_name = "NAME=TYPE:LEN[:INIT]")]
    pub buffers: Vec<String>,
    /// The kernel's arguments, comma-separated: buffer names or numbers.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub args: Vec<String>,
    /// The compiler of a .cu: clang (Debian's clang-16, the default) or nvcc (as `compile`).
    #[arg(long, default_value = "clang")]
    pub dialect: String,
    /// libdevice.10.bc, CUDA's math library (default: WARPLIGHT_LIBDEVICE, CUDA installs,
    /// the pip package nvidia-cuda-nvcc; as `compile`).
    #[arg(long, value_name = "FILE")]
    pub libdevice: Option<PathBuf>,
    /// How to run and what to print (as `launch`).
    #[command(flatten)]
    pub options: LaunchOptions,
}

fn dims(what: &str, s: &str) -> Result<String, String> {
    let v: Result<Vec<u32>, _> = s.split(',').map(|x| x.trim().parse::<u32>()).collect();
    match v {
        Ok(v) if (1..=3).contains(&v.len()) => Ok(format!("{v:?}")),
        _ => Err(format!("--{what} {s}: expected N or X,Y,Z")),
    }
}

fn toml_str(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// One `--buffer` as a `[[buffer]]` table.
fn buffer(b: &str) -> Result<(String, String), String> {
    let bad = || format!("--buffer {b}: expected NAME=TYPE:LEN[:INIT], e.g. x=f32:1024:iota");
    let (name, rest) = b.split_once('=').ok_or_else(bad)?;
    let mut parts = rest.splitn(3, ':');
    let ty = parts.next().filter(|t| !t.is_empty()).ok_or_else(bad)?;
    let len: u64 = parts.next().and_then(|l| l.trim().parse().ok()).ok_or_else(bad)?;
    let init = match parts.next().unwrap_or("zeros") {
        "zeros" => toml_str("zeros"),
        "iota" => toml_str("iota"),
        x if x.starts_with("hash=") => {
            let (m, n) = x[5..].split_once('/').ok_or_else(|| format!("--buffer {b}: hash=M/N"))?;
            let num = |v: &str| v.parse::<u64>().map_err(|_| format!("--buffer {b}: {v:?} is not a number"));
            format!("{{ hash = {}, modulo = {} }}", num(m)?, num(n)?)
        }
        x if x.starts_with("file=") => format!("{{ file = {} }}", toml_str(&x[5..])),
        other => return Err(format!("--buffer {b}: unknown init {other:?} (zeros, iota, hash=M/N, file=PATH)")),
    };
    Ok((
        name.to_string(),
        format!("[[buffer]]\nname = {}\ntype = {}\nlen = {len}\ninit = {init}\n", toml_str(name), toml_str(ty)),
    ))
}

/// The launch spec `warplight run`'s options describe.
pub fn spec_text(a: &RunArgs, kernel: &str) -> Result<String, String> {
    let mut names = Vec::new();
    let mut tables = String::new();
    for b in &a.buffers {
        let (n, t) = buffer(b)?;
        names.push(n);
        tables.push_str(&t);
    }
    let args: Vec<String> = a
        .args
        .iter()
        .map(|x| {
            let x = x.trim();
            let buffer = x.split_once('+').map_or(x, |(n, _)| n.trim());
            if names.iter().any(|n| n == buffer) {
                Ok(toml_str(x))
            } else if x.parse::<i64>().is_ok() || x.parse::<f64>().is_ok_and(f64::is_finite) {
                Ok(x.to_string())
            } else {
                Err(format!("--args: {x:?} is neither a number nor a --buffer name ({})", names.join(", ")))
            }
        })
        .collect::<Result<_, _>>()?;
    Ok(format!(
        "ptx = {}\nkernel = {}\ngrid = {}\nblock = {}\nshared = {}\nargs = [{}]\n{tables}",
        toml_str(&a.source.display().to_string()),
        toml_str(kernel),
        dims("grid", &a.grid)?,
        dims("block", &a.block)?,
        a.shared,
        args.join(", ")
    ))
}

/// Runs the command.
pub fn run(mut a: RunArgs) -> Result<(), Box<dyn std::error::Error>> {
    // `examples/softmax.cu` from any directory: the checkout's or $WARPLIGHT_HOME's copy when not here
    a.source = crate::host::scene_file::data_file(&a.source);
    let dialect = crate::compile::Dialect::named(&a.dialect)?;
    crate::compile::set_command_line_options(crate::compile::CompileOptions {
        dialect,
        libdevice: a.libdevice.clone(),
    });
    let kernel = match &a.kernel {
        Some(k) => k.clone(),
        None => only_kernel(&a.source)?,
    };
    let text = spec_text(&a, &kernel)?;
    // relative paths in the spec (the source, file= inits) are relative to the current directory
    let spec = Spec::parse(&text, std::path::Path::new("command line"))?;
    run_spec(spec, &a.options)
}

/// The plain name of the file's only kernel, or an error listing them.
fn only_kernel(src: &std::path::Path) -> Result<String, Box<dyn std::error::Error>> {
    let ptx = if src.extension().is_some_and(|e| e == "cu") {
        crate::compile::compile(src, crate::compile::Dialect::Clang)?
    } else {
        std::fs::read_to_string(src).map_err(|e| format!("{}: {e}", src.display()))?
    };
    let prog = crate::ptx::load(&ptx, &src.display().to_string())?;
    let names: Vec<String> =
        prog.kernel_names().iter().map(|n| crate::compile::demangle(n).unwrap_or_else(|| n.to_string())).collect();
    match names.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(format!("{}: no kernel (__global__ function)", src.display()).into()),
        many => {
            Err(format!("{} has {} kernels; name one with --kernel: {}", src.display(), many.len(), many.join(", "))
                .into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_become_a_spec() {
        assert_eq!(
            buffer("x=f32:4:iota").unwrap().1,
            "[[buffer]]\nname = \"x\"\ntype = \"f32\"\nlen = 4\ninit = \"iota\"\n"
        );
        assert!(buffer("x=f32:4:hash=7/16").unwrap().1.contains("init = { hash = 7, modulo = 16 }"));
        assert!(buffer("x=f32").is_err() && buffer("x=f32:4:ones").is_err());
        assert_eq!(dims("grid", "4,2").unwrap(), "[4, 2]");
        assert!(dims("grid", "a").is_err());
    }
}
