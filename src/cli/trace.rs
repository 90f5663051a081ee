//! `warplight trace SPEC.toml -o trace.html`: record a launch into one
//! self-contained HTML timeline (see `crate::teach::trace`).

use std::io::IsTerminal;
use std::path::PathBuf;

use crate::teach::session::Session;
use crate::teach::trace::{self, TraceOptions};

/// Options of `warplight trace`.
#[derive(Debug, clap::Args)]
#[command(after_help = "The page needs no network: open it in any browser. Keys there: Left/Right step,\n\
Home/End, Space plays; choose a warp to step along it alone; click the timeline to jump.\n\n\
Examples:\n  warplight trace examples/if_else.toml -o if_else.html\n  \
warplight trace examples/reduce.toml --cta 0 --warp 0 --warp 1 -o reduce.html\n  \
warplight trace examples/lessons/coalescing.toml --launch 3 --device gt200 --cta 0 -o stride32.html")]
pub struct TraceArgs {
    /// The launch spec (TOML).
    pub spec: PathBuf,
    /// Which of the spec's launches is recorded, from 1; those before it run first.
    #[arg(long, default_value_t = 1)]
    pub launch: usize,
    /// The HTML file to write (written only when the recording succeeded).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Keep only this CTA (linear index; repeatable). Default: all.
    #[arg(long = "cta", value_name = "N")]
    pub ctas: Vec<u32>,
    /// Keep only this warp of each kept CTA (repeatable). Default: all.
    #[arg(long = "warp", value_name = "N")]
    pub warps: Vec<u32>,
    /// First step kept (warp instructions of the whole launch, counted from 1).
    #[arg(long, default_value_t = 1)]
    pub from: u64,
    /// Stop recording after this step.
    #[arg(long, default_value_t = u64::MAX)]
    pub to: u64,
    /// Most instructions kept; the page says when the recording was cut.
    #[arg(long, default_value_t = 20_000)]
    pub max_events: usize,
    /// The watchdog: stop a launch as a runaway after this many warp instructions
    /// (default: the spec's `max_instructions`, else 2^32). See docs/limits.md.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_instructions: Option<u64>,
    /// Device profile for the memory transactions, sectors and banks: gt200, maxwell or hopper
    /// (default: the spec's `device`, else hopper).
    #[arg(long)]
    pub device: Option<String>,
    /// Checking (`--check`, `--uninit`; the reports go to stderr) and the
    /// warp schedule of the recorded launch (`--schedule random --seed N`).
    #[command(flatten)]
    pub checks: crate::check::cli::CheckArgs,
}

/// Runs the command.
pub fn run(a: TraceArgs) -> Result<(), Box<dyn std::error::Error>> {
    if a.from > a.to {
        return Err(format!("--from {} is after --to {}", a.from, a.to).into());
    }
    // `examples/…` from any directory: the checkout's or $WARPLIGHT_HOME's copy when not here
    let mut session = Session::load_launch(&crate::host::scene_file::data_file(&a.spec), a.launch)?;
    let profile = crate::cli::step::profile(&session, a.device.as_deref())?;
    session.max_instructions = a.max_instructions;
    session.random_seed = a.checks.random_seed();
    session.device = Some(profile);
    crate::check::cli::check_before_stepping(&session.spec, session.launch, &a.checks, a.max_instructions, profile)?;
    let o = TraceOptions { ctas: a.ctas, warps: a.warps, from: a.from, to: a.to, max_events: a.max_events, profile };
    let spinner = std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new_spinner();
        pb.set_style(indicatif::ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("template"));
        pb
    });
    let t = trace::record_with(&session, &o, |steps| {
        if let Some(pb) = &spinner {
            pb.set_message(format!("recording {}: {steps} warp instructions", session.kernel));
            pb.tick();
        }
    });
    if let Some(pb) = spinner {
        pb.finish_and_clear();
    }
    let t = t?;
    if t.events.is_empty() {
        return Err("nothing recorded: no instruction matched --cta/--warp/--from/--to".into());
    }
    let page = trace::html(&t)?;
    crate::cli::write_atomically(&a.output, page.as_bytes())?;
    println!(
        "wrote {} ({} KiB): {} of {} warp instructions, {} warps{}",
        a.output.display(),
        page.len() / 1024,
        t.events.len(),
        t.total_steps,
        t.warps.len(),
        if t.truncated { format!(" (cut at --max-events {})", a.max_events) } else { String::new() }
    );
    crate::cli::step::print_printf(&session, &mut std::io::stdout().lock())?;
    Ok(())
}
