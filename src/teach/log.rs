//! The text log of `warplight step` (its non-interactive mode, for scripts,
//! tests and lessons): each issued warp instruction with its active mask and
//! what it did to the warp's control flow, each `printf` line at the step
//! that printed it, and at breakpoints the SIMT stack and watched registers
//! lane by lane.

use std::io::Write;

use super::breakpoints::Breakpoints;
use super::printed::{self, Printed};
use super::session::{Error, Session};
use super::track;
use crate::sim::stepper::Stepper;

/// What to log.
#[derive(Debug, Clone, Default)]
pub struct LogOptions {
    /// Breakpoints.
    pub breaks: Breakpoints,
    /// Registers printed at breakpoints.
    pub watches: Vec<String>,
    /// Only this warp (CTA slot, warp).
    pub only: Option<(usize, u32)>,
    /// Every instruction, not only breakpoints.
    pub trace: bool,
    /// Step limit.
    pub max_steps: u64,
}

/// Steps the session's launch and writes the log to `out`.
pub fn run(session: &Session, o: &LogOptions, out: &mut dyn Write) -> Result<(), Error> {
    session.with_stepping(|st, _, printed| log(session, st, printed, o, out))
}

fn log(
    session: &Session,
    st: &mut Stepper,
    printed: &Printed,
    o: &LogOptions,
    out: &mut dyn Write,
) -> Result<(), Error> {
    let prog = &st.module().prog;
    let l = session.launch_spec();
    writeln!(
        out,
        "stepping {} (grid {:?}, block {:?}) from {}",
        l.kernel,
        l.grid,
        l.block,
        session.spec.ptx.display()
    )?;
    let mut steps = 0u64;
    let mut hits = 0u64;
    let mut tracker = track::Tracker::default();
    while steps < o.max_steps {
        let Some(ev) = st.step()? else { break };
        steps += 1;
        let recs = printed.take();
        let selected = o.only.is_none_or(|(s, w)| s == ev.cta_slot && w == ev.warp);
        let Some(w) = st.warp(ev.cta_slot, ev.warp) else { continue };
        let fx = tracker.observe(&ev, &w);
        if o.trace && selected {
            writeln!(
                out,
                "{steps:>7}  cta {:?} warp {:>2}  {:>5}: {:<28} mask {:08x} ({:>2} lanes){}{}",
                ev.cta,
                ev.warp,
                ev.ptx_line,
                ev.opcode,
                ev.mask,
                ev.mask.count_ones(),
                ev.source_line.map(|l| format!("  src line {l}")).unwrap_or_default(),
                if fx.word().is_empty() { String::new() } else { format!("  [{}]", fx.word()) }
            )?;
        }
        // the step's printf output, at the step (with or without --trace)
        if selected {
            for line in printed::labelled(&recs) {
                writeln!(out, "{steps:>7}  {line}")?;
            }
        }
        let Some(hit) = o.breaks.hit(&ev, &w) else { continue };
        if !selected {
            continue;
        }
        hits += 1;
        let next = hit.ptx_line;
        let text = prog.ptx_lines.get(next as usize - 1).map(|s| s.trim()).unwrap_or("");
        let src = hit.source_line.map(|l| format!("source line {l}, ")).unwrap_or_default();
        writeln!(out, "break at {src}PTX line {next} ({text}): cta {:?} warp {} in {}", ev.cta, ev.warp, w.function)?;
        writeln!(out, "  active {:08x}  live {:08x}  call depth {}", w.active, w.live, w.call_depth)?;
        for (i, e) in w.stack.iter().enumerate().rev() {
            let rpc = if e.rpc == u32::MAX { "exit".to_string() } else { e.rpc.to_string() };
            writeln!(out, "  stack[{i}]: pc {} rpc {rpc} mask {:08x}", e.pc, e.mask)?;
        }
        for r in &o.watches {
            match st.register(ev.cta_slot, ev.warp, r) {
                Some(v) => {
                    let lanes: Vec<String> =
                        (0..32).filter(|l| w.active >> l & 1 != 0).map(|l| format!("{l}:{}", v[l])).collect();
                    writeln!(out, "  {r} = {}", lanes.join(" "))?;
                }
                None => writeln!(
                    out,
                    "  {r}: no such register in {} (known: {})",
                    w.function,
                    st.register_names(ev.cta_slot, ev.warp).join(" ")
                )?,
            }
        }
    }
    let c = st.counters();
    writeln!(
        out,
        "{} after {steps} warp instructions; {} breakpoint stops; {} thread instructions, {} divergent branches, {} reconvergences",
        if st.finished() { "finished" } else { "stopped" },
        hits,
        c.thread_instructions,
        c.divergent_branches,
        c.reconvergences
    )?;
    Ok(())
}
