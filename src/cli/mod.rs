//! The `warplight` command line: argument parsing, output formats, progress.

pub mod launch;
pub mod ptx_info;

use clap::{Parser, Subcommand};

/// warplight: run CUDA kernels (as PTX) warp by warp on the CPU, with counters.
#[derive(Debug, Parser)]
#[command(name = "warplight", version, about, long_about = None, after_help = "\
Examples:
  warplight launch examples/reduce.toml            run a kernel described by a spec, print counters
  warplight launch examples/reduce.toml --per-line counters per CUDA source line
  warplight kernels kernels/tests/shared.ptx       list a PTX file's kernels
  warplight check my_kernels.ptx                   parse and validate a PTX file")]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the kernel(s) of a launch spec (TOML) and print their counters.
    ///
    /// The spec names the PTX file, the kernel, grid and block, the buffers with
    /// their initial contents and the arguments; see `docs/launch-spec.md`.
    Launch(launch::LaunchArgs),
    /// List the kernels of a PTX file with their parameters and resources.
    Kernels {
        /// The PTX file.
        ptx: std::path::PathBuf,
    },
    /// Parse and validate a PTX file; report the first error with its line.
    Check {
        /// The PTX file.
        ptx: std::path::PathBuf,
    },
}

/// Runs the CLI; returns the process exit code.
pub fn main() -> i32 {
    let cli = Cli::parse();
    let r = match cli.command {
        Command::Launch(a) => launch::run(a),
        Command::Kernels { ptx } => ptx_info::kernels(&ptx),
        Command::Check { ptx } => ptx_info::check(&ptx),
    };
    match r {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}
