//! `warplight step SPEC.toml`: step through a launch warp instruction by warp
//! instruction — interactively in the terminal (`crate::teach::tui`), or as a
//! text log (`crate::teach::log`) with `--log`, `--trace`, or when the output
//! is not a terminal.

use std::io::IsTerminal;
use std::path::PathBuf;

use crate::model::Profile;
use crate::teach::breakpoints::Breakpoints;
use crate::teach::session::Session;
use crate::teach::{log, tui};

/// Options of `warplight step`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Interactive keys (press ? in the view for all of them):\n  \
    s/space step the warp   n step a source line   c continue to a breakpoint   g go to a PTX line\n  \
    b toggle a breakpoint   a continue to a barrier   u/backspace step back\n  \
    w/W next/previous warp  ]/[ next/previous CTA  1/2/3 stack, registers, memory   q quit\n\n\
    Examples:\n  warplight step examples/if_else.toml\n  \
    warplight step examples/if_else.toml --log --break 45 --watch %r10\n  \
    warplight step examples/lessons/banks.toml --device gt200")]
pub struct StepArgs {
    /// The launch spec (TOML).
    pub spec: PathBuf,
    /// Which of the spec's launches is stepped, from 1; those before it run first.
    #[arg(long, default_value_t = 1)]
    pub launch: usize,
    /// Stop at this PTX line (repeatable): print the warp's state before it executes.
    #[arg(long = "break", value_name = "PTX_LINE")]
    pub breaks: Vec<u32>,
    /// Stop where a warp enters this CUDA source line (from the PTX's `.loc`; repeatable),
    /// e.g. `divergence.cu:11`, or `11` for line 11 of any file. A warp stops once each
    /// time it enters the line, before its first instruction, not at each PTX instruction.
    #[arg(long = "break-src", value_name = "[FILE:]LINE")]
    pub src_breaks: Vec<String>,
    /// Registers to show (repeatable), e.g. %r5 or %p1: printed at breakpoints in the log,
    /// listed in the register panel of the interactive view.
    #[arg(long = "watch", value_name = "REG")]
    pub watches: Vec<String>,
    /// Only log this warp / start the view on it: CTA slot and warp index, e.g. 0:1.
    #[arg(long, value_name = "SLOT:WARP")]
    pub warp: Option<String>,
    /// Write the text log instead of opening the interactive view.
    #[arg(long)]
    pub log: bool,
    /// Log every issued instruction (implies --log; default: only breakpoints and a summary).
    #[arg(long)]
    pub trace: bool,
    /// Stop after this many warp instructions (log), or run at most this many per
    /// continue (interactive view).
    #[arg(long, default_value_t = 100_000)]
    pub max_steps: u64,
    /// The watchdog: stop a launch as a runaway after this many warp instructions
    /// (default: the spec's `max_instructions`, else 2^32). See docs/limits.md.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_instructions: Option<u64>,
    /// Device profile for the memory panel's transactions, sectors and banks:
    /// gt200, maxwell or hopper (default: the spec's `device`, else hopper).
    #[arg(long)]
    pub device: Option<String>,
    /// Checking (`--check`, `--uninit`; the reports come before the view) and
    /// the warp schedule of the stepped launch (`--schedule random --seed N`).
    #[command(flatten)]
    pub checks: crate::check::cli::CheckArgs,
}

/// Parses `SLOT:WARP`.
pub fn parse_warp(w: &str) -> Result<(usize, u32), String> {
    let (s, n) = w.split_once(':').ok_or_else(|| format!("--warp {w}: expected SLOT:WARP, e.g. 0:1"))?;
    Ok((
        s.parse::<usize>().map_err(|_| format!("--warp {w}: bad slot"))?,
        n.parse::<u32>().map_err(|_| format!("--warp {w}: bad warp"))?,
    ))
}

/// The profile of `--device`, else of the spec's `device`, else hopper.
pub fn profile(session: &Session, device: Option<&str>) -> Result<Profile, Box<dyn std::error::Error>> {
    match device {
        Some(d) => Ok(Profile::parse(d).ok_or_else(|| format!("--device {d}: expected gt200, maxwell or hopper"))?),
        None => session.spec_profile(),
    }
}

/// Runs the command.
pub fn run(a: StepArgs) -> Result<(), Box<dyn std::error::Error>> {
    // `examples/…` from any directory: the checkout's or $WARPLIGHT_HOME's copy when not here
    let mut session = Session::load_launch(&crate::host::scene_file::data_file(&a.spec), a.launch)?;
    session.max_instructions = a.max_instructions;
    session.random_seed = a.checks.random_seed();
    let profile = profile(&session, a.device.as_deref())?;
    session.device = Some(profile);
    crate::check::cli::check_before_stepping(&session.spec, session.launch, &a.checks, a.max_instructions, profile)?;
    let only = a.warp.as_deref().map(parse_warp).transpose()?;
    let breaks = session.with_stepper(|st| Ok(Breakpoints::new(&st.module().prog, &a.breaks, &a.src_breaks)?))?;
    let interactive = !a.log && !a.trace && std::io::stdout().is_terminal() && std::io::stdin().is_terminal();
    if interactive {
        let o = tui::TuiOptions {
            breaks,
            watches: a.watches,
            start: only.unwrap_or((0, 0)),
            profile,
            max_steps: a.max_steps,
        };
        let r = tui::run(&session, o);
        print_printf(&session, &mut std::io::stdout().lock())?;
        return r;
    }
    let o = log::LogOptions { breaks, watches: a.watches, only, trace: a.trace, max_steps: a.max_steps };
    let stdout = std::io::stdout();
    let r = log::run(&session, &o, &mut stdout.lock());
    print_printf(&session, &mut stdout.lock())?;
    r
}

/// Writes the stepped launch's `printf` output up to where the last stepping
/// stopped (the log's last step, the view's position when it closed), after
/// a header; nothing when the kernel printed nothing.
pub fn print_printf(session: &Session, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    let recs = session.printf_output();
    if recs.is_empty() {
        return Ok(());
    }
    writeln!(out, "printf output of `{}` (by CTA, warp, call, then lane):", session.kernel)?;
    let mut text = crate::sim::printf::text(&recs);
    if !text.ends_with('\n') {
        text.push('\n');
    }
    out.write_all(text.as_bytes())
}
