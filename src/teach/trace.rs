//! `warplight trace`: a launch recorded step by step into one self-contained
//! HTML page (no network; data, script and style inline) — a timeline per
//! warp the reader can scrub, with the active mask of each instruction as a
//! 32-cell strip, divergence and reconvergence marked, the SIMT stack, the
//! memory transactions, sectors or banks of each memory instruction under a
//! device profile, and the `printf` output at the instruction that printed
//! it. Its size is bounded: choose CTAs, warps and a step range, and at most
//! `max_events` instructions are kept.

use serde::Serialize;

use super::session::{Error, Session};
use super::sources;
use super::track::Tracker;
use super::user_lines;
use crate::model::Profile;
use crate::model::explain;

/// What to record.
#[derive(Debug, Clone)]
pub struct TraceOptions {
    /// Linear CTA indices to keep (empty: all).
    pub ctas: Vec<u32>,
    /// Warp indices within a CTA to keep (empty: all).
    pub warps: Vec<u32>,
    /// First global step kept (1-based count of warp instructions issued).
    pub from: u64,
    /// Last global step kept.
    pub to: u64,
    /// Most instructions kept.
    pub max_events: usize,
    /// Profile for the memory views.
    pub profile: Profile,
}

/// A recorded warp.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TraceWarp {
    /// CTA index.
    pub cta: [u32; 3],
    /// Linear CTA index.
    pub linear: u32,
    /// Warp within the CTA.
    pub warp: u32,
}

/// A memory access as the page shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceMem {
    /// One-line cost summary.
    pub summary: String,
    /// Lowest active address.
    pub base: u64,
    /// Per-lane offset from `base` (None: inactive lane).
    pub offsets: Vec<Option<u64>>,
    /// Per-lane unit index.
    pub lane_unit: Vec<Option<usize>>,
    /// Unit labels (empty for a bank no lane uses).
    pub units: Vec<String>,
}

/// One issued warp instruction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceEvent {
    /// Global step number (1-based).
    pub step: u64,
    /// Index into [`Trace::warps`].
    pub w: usize,
    /// PTX line.
    pub line: u32,
    /// The user's source file index and line (library code shows its calling
    /// line, compiler-generated code the line the warp last ran; see
    /// [`user_lines`]).
    pub src: Option<(u32, u32)>,
    /// Whether the instruction's own line is not `src`: compiler-generated
    /// (`.loc` line 0) or inlined from a library file.
    pub src_inherited: bool,
    /// Opcode.
    pub op: String,
    /// Lanes that ran it.
    pub mask: u32,
    /// Lanes that run next (after the instruction).
    pub next: u32,
    /// Lanes not exited.
    pub live: u32,
    /// `diverged`, `reconverged`, `waits at barrier`, `exited` or empty.
    pub fx: String,
    /// SIMT stack after the instruction, bottom first: (pc, PTX line of pc, rpc PTX line or 0 for exit, mask).
    pub stack: Vec<(u32, u32, u32, u32)>,
    /// Its memory accesses.
    pub mem: Vec<TraceMem>,
    /// Its `printf` output: (lane, text) in lane order; absent from the page's
    /// data when it printed nothing.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub out: Vec<(u32, String)>,
}

/// A source file for the page.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TraceSource {
    /// Its name as the PTX gives it.
    pub name: String,
    /// Its lines (empty when not found).
    pub lines: Vec<String>,
}

/// A recorded launch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trace {
    /// Kernel name.
    pub kernel: String,
    /// Device profile name.
    pub profile: String,
    /// PTX file name.
    pub ptx_name: String,
    /// PTX text, by line.
    pub ptx: Vec<String>,
    /// Source files, indexed like the PTX's `.file` table.
    pub sources: Vec<TraceSource>,
    /// Warps that appear in `events`.
    pub warps: Vec<TraceWarp>,
    /// Instructions, in issue order.
    pub events: Vec<TraceEvent>,
    /// Warp instructions the launch issued in all (or up to `to`).
    pub total_steps: u64,
    /// Whether `max_events` cut the recording short.
    pub truncated: bool,
    /// Whether the launch ran to its end.
    pub finished: bool,
}

/// Records the session's launch.
pub fn record(session: &Session, o: &TraceOptions) -> Result<Trace, Error> {
    record_with(session, o, |_| {})
}

/// As [`record`], calling `tick(steps)` every 4096 warp instructions (for a progress display).
pub fn record_with(session: &Session, o: &TraceOptions, mut tick: impl FnMut(u64)) -> Result<Trace, Error> {
    session.with_stepping(|st, _, printed| {
        let prog = &st.module().prog;
        let l = session.launch_spec();
        let grid = l.grid;
        let found = sources::read_all(prog, &session.ptx_path());
        let sources = prog
            .files
            .iter()
            .zip(found)
            .map(|(name, lines)| TraceSource { name: name.clone(), lines: lines.unwrap_or_default() })
            .collect();
        let mut t = Trace {
            kernel: session.kernel.clone(),
            profile: o.profile.params().name.to_string(),
            ptx_name: session.spec.ptx.display().to_string(),
            ptx: prog.ptx_lines.clone(),
            sources,
            warps: Vec::new(),
            events: Vec::new(),
            total_steps: 0,
            truncated: false,
            finished: false,
        };
        let mut tracker = Tracker::default();
        let user = user_lines::attribute(prog);
        let mut last_user: std::collections::HashMap<([u32; 3], u32), (u32, u32)> = Default::default();
        let mut step = 0u64;
        while step < o.to {
            let Some(ev) = st.step()? else {
                t.finished = true;
                break;
            };
            step += 1;
            let out = printed.take();
            if step.is_multiple_of(4096) {
                tick(step);
            }
            let w = st.warp(ev.cta_slot, ev.warp).ok_or("stepped warp vanished")?;
            let fx = tracker.observe(&ev, &w);
            let fi = prog.functions.iter().position(|f| f.name == ev.function);
            let own = fi.and_then(|f| prog.functions[f].info[ev.pc as usize].src);
            let charged = fi.and_then(|f| user_lines::user_loc(prog, user[f][ev.pc as usize]));
            if let Some(c) = charged {
                last_user.insert((ev.cta, ev.warp), (c.file, c.line));
            }
            let src = charged.map(|c| (c.file, c.line)).or_else(|| last_user.get(&(ev.cta, ev.warp)).copied());
            let src_inherited = own.map(|o| (o.file, o.line)) != src;
            let linear = ev.cta[0] + grid[0] * (ev.cta[1] + grid[1] * ev.cta[2]);
            let keep = step >= o.from
                && (o.ctas.is_empty() || o.ctas.contains(&linear))
                && (o.warps.is_empty() || o.warps.contains(&ev.warp));
            if !keep {
                continue;
            }
            if t.events.len() >= o.max_events {
                t.truncated = true;
                break;
            }
            let tw = TraceWarp { cta: ev.cta, linear, warp: ev.warp };
            let wi = match t.warps.iter().position(|x| *x == tw) {
                Some(i) => i,
                None => {
                    t.warps.push(tw);
                    t.warps.len() - 1
                }
            };
            let func = prog.functions.iter().find(|f| f.name == w.function);
            let line_of = |pc: u32| func.and_then(|f| f.info.get(pc as usize)).map(|i| i.ptx_line).unwrap_or(0);
            let stack = w
                .stack
                .iter()
                .map(|e| (e.pc, line_of(e.pc), if e.rpc == u32::MAX { 0 } else { line_of(e.rpc) }, e.mask))
                .collect();
            let mem = ev
                .accesses
                .iter()
                .map(|a| {
                    let e = explain::explain(o.profile, a);
                    let base = (0..32).filter(|l| a.mask >> l & 1 != 0).map(|l| a.addrs[l]).min().unwrap_or(0);
                    TraceMem {
                        summary: e.summary,
                        base,
                        offsets: (0..32).map(|l| (a.mask >> l & 1 != 0).then(|| a.addrs[l] - base)).collect(),
                        lane_unit: e.lane_unit,
                        units: e
                            .units
                            .into_iter()
                            .map(|u| if u.lanes == 0 { String::new() } else { u.label })
                            .collect(),
                    }
                })
                .collect();
            t.events.push(TraceEvent {
                step,
                w: wi,
                line: ev.ptx_line,
                src,
                src_inherited,
                op: ev.opcode.clone(),
                mask: ev.mask,
                next: w.active,
                live: w.live,
                fx: fx.word().to_string(),
                stack,
                mem,
                out: out.into_iter().map(|r| (r.lane, r.text)).collect(),
            });
        }
        t.total_steps = step;
        Ok(t)
    })
}

/// The page's template; `/*TRACE_DATA*/null` is replaced by the trace as JSON.
const TEMPLATE: &str = include_str!("trace.html");

/// Renders `t` as one HTML page.
pub fn html(t: &Trace) -> Result<String, Error> {
    // `<` only occurs inside JSON strings, where `\u003c` means the same: the
    // data can then never close the script element it sits in.
    let json = serde_json::to_string(t)?.replace('<', "\\u003c");
    let page = TEMPLATE.replacen("/*TRACE_DATA*/null", &json, 1);
    if page.len() == TEMPLATE.len() {
        return Err("trace template lacks its data marker".into());
    }
    Ok(page)
}
