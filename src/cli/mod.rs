//! The `warplight` command line: argument parsing, output formats, progress.

pub mod chart;
pub mod compile;
pub use crate::files::{interrupt, write_atomically};
pub mod launch;
pub mod ptx_info;
pub mod record;
pub mod render;
pub mod run;
pub mod scene_info;
pub mod step;
pub mod step_session;
pub mod table_format;
pub mod tables;
pub mod trace;
pub mod validate;

use clap::{Parser, Subcommand};

/// warplight: run CUDA kernels (as PTX) warp by warp on the CPU, with counters.
#[derive(Debug, Parser)]
#[command(name = "warplight", version, about, long_about = None, after_help = "\
Examples:
  warplight render --scene cornell-box -o cornell.png   render a scene's first flight frame
  warplight tables 4.4                             kd-tree statistics beside thesis 000's Table 4.4
  warplight chart table 4.5 --from r.json -o t.svg  a table's values beside the thesis' as a chart
  warplight launch examples/reduce.toml            run a kernel described by a spec, print counters
  warplight launch examples/reduce.toml --per-line counters per CUDA source line
  warplight step examples/if_else.toml             step a warp through an if/else (interactive)
  warplight trace examples/if_else.toml -o t.html  the same as an HTML timeline
  warplight kernels kernels/tests/shared.ptx       list a PTX file's kernels
  warplight check my_kernels.ptx                   parse and validate a PTX file")]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Most host memory a command may plan to use (4G, 512M, bytes); default:
    /// $WARPLIGHT_MEMORY_BUDGET, else half of this machine's memory. See docs/limits.md.
    #[arg(long, global = true, value_name = "SIZE", value_parser = crate::limits::parse_bytes)]
    pub memory_budget: Option<u64>,
    /// A folder of scene files searched first for scene names (before scenes/,
    /// $WARPLIGHT_HOME/scenes and the checkout's scenes/).
    /// (Named --scene-dir: `tables --scenes` lists scene names.)
    #[arg(long = "scene-dir", global = true, value_name = "DIR")]
    pub scene_dir: Option<std::path::PathBuf>,
    /// Count shared accesses as the PTX writes them, not as ptxas merges
    /// (LDS.64/128, STS.64/128) and drops repeated loads, and global atomics
    /// with an unused result as atomics, not reductions (maxwell, hopper). See docs/devices.md.
    #[arg(long = "no-ptxas-vectorize", global = true)]
    pub no_ptxas_vectorize: bool,
    /// Record what the command does with its emulated devices (allocations,
    /// host writes, launches, host reads with the emulator's bytes) into the
    /// folder DIR, made if missing: recording.json, data.bin and the modules'
    /// PTX. `python3 tools/device/replay.py DIR` replays it on an NVIDIA GPU, compares
    /// every read with the emulator's bytes and times each launch
    /// (docs/gpu-replay.md). The recording is held in memory until the command ends.
    #[arg(long, global = true, value_name = "DIR")]
    pub record: Option<std::path::PathBuf>,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the kernel(s) of a launch spec (TOML) and print their counters.
    ///
    /// The spec names the PTX file, the kernel, grid and block, the buffers with
    /// their initial contents and the arguments; see `docs/launch-spec.md`.
    Launch(launch::LaunchArgs),
    /// Step through a launch warp by warp: an interactive terminal view (source,
    /// PTX, active lanes, SIMT stack, registers, memory transactions), or with
    /// `--log`/`--trace` a text log with breakpoints (`--break LINE --watch %r1`).
    Step(step::StepArgs),
    /// Record a launch into a self-contained HTML page: a timeline per warp to scrub,
    /// active masks, divergence and reconvergence, memory transactions per instruction.
    Trace(trace::TraceArgs),
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
    /// Render a frame of a scene's camera flight to PNG or EXR and print its counters.
    Render(render::RenderArgs),
    /// Compile a .cu and launch one kernel of it, buffers and arguments on the command line
    /// (`warplight run saxpy.cu --grid 4 --block 256 --buffer x=f32:1000:iota --args 1000,x`).
    Run(run::RunArgs),
    /// Compile CUDA C to PTX with clang-16 (or nvcc) and warplight's prelude: `warplight compile k.cu`.
    Compile(compile::CompileArgs),
    /// Reproduce thesis tables beside the published values (`warplight tables 4.4`).
    Tables(tables::TablesArgs),
    /// Draw charts (SVG or PNG): a table beside the thesis', counters along a flight, speed vs accuracy.
    ///
    /// `chart table 4.5 --from r.json -o t.svg`: a reproduced table's values
    /// beside the thesis' with the tolerance bands; `chart flight`: a counter
    /// frame by frame along a flight; `chart scatter`: speed against accuracy
    /// from JSON; `chart media`, `chart lin-convergence`, `chart
    /// lin-compaction`: thesis 003's march variance, error against Mitsuba
    /// vs samples and time, and lanes and paths per level.
    Chart(chart::ChartArgs),
    /// Scenes: `warplight scene info NAME` prints triangles (and the thesis'
    /// count), extent, materials, lights, camera and flight.
    Scene {
        /// What to do.
        #[command(subcommand)]
        what: SceneCommand,
    },
    /// Compare the hopper profile with the H100 measurements of the memory
    /// microbenchmarks (tests/fixtures/h100_micro.json).
    Validate {
        /// The fixture.
        #[arg(long, default_value = "tests/fixtures/h100_micro.json")]
        fixture: std::path::PathBuf,
        /// The microbenchmarks' PTX.
        #[arg(long, default_value = "kernels/micro/micro.ptx")]
        ptx: std::path::PathBuf,
        /// Print docs/validation.md (header and table).
        #[arg(long)]
        markdown: bool,
    },
}

/// `warplight scene ...`
#[derive(Debug, Subcommand)]
pub enum SceneCommand {
    /// Summarise a scene: NAME is a file in scenes/ (`sponza`) or a path to a .toml.
    Info {
        /// Scene name or path.
        name: String,
    },
}

/// Runs the CLI; returns the process exit code.
pub fn main() -> i32 {
    let cli = Cli::parse();
    // from here on a signal removes the temporary files of the outputs being written
    interrupt::install();
    if let Some(b) = cli.memory_budget {
        crate::limits::set_memory_budget(b);
    }
    if let Some(d) = cli.scene_dir {
        crate::host::scene_file::set_scene_dir(d);
    }
    if cli.no_ptxas_vectorize {
        crate::model::vectorize::set_default(false);
    }
    if let Some(dir) = &cli.record {
        if let Err(e) = record::check(dir) {
            eprintln!("error: {e}");
            return 1;
        }
        crate::sim::recording::start();
    }
    let r = match cli.command {
        Command::Launch(a) => launch::run(a),
        Command::Kernels { ptx } => ptx_info::kernels(&ptx),
        Command::Check { ptx } => ptx_info::check(&ptx),
        Command::Validate { fixture, ptx, markdown } => validate::run(&fixture, &ptx, markdown),
        Command::Scene { what: SceneCommand::Info { name } } => scene_info::info(&name),
        Command::Tables(a) => tables::run(a),
        Command::Compile(a) => compile::run(a),
        Command::Run(a) => run::run(a),
        Command::Chart(a) => chart::run(a),
        Command::Render(a) => render::run(a),
        Command::Step(a) => step::run(a),
        Command::Trace(a) => trace::run(a),
    };
    let r = match &cli.record {
        Some(dir) => r.and_then(|()| record::write(dir)),
        None => r,
    };
    match r {
        Ok(()) => 0,
        // the reader of stdout went away (`warplight step ... | head`): end as C tools do
        Err(e) if e.downcast_ref::<std::io::Error>().is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe) => 141,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}
