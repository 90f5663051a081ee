//! `warplight step SPEC.toml`: step through a launch warp instruction by warp
//! instruction and print a log — each issued instruction with its active mask,
//! and at breakpoints the SIMT stack and watched registers lane by lane.
//! (The interactive terminal view is planned; this is its scriptable mode.)

use std::path::PathBuf;

use crate::launch_spec::{self, Spec};
use crate::ptx::Program;
use crate::ptx::ir::SrcLoc;
use crate::sim::{Device, LaunchConfig};

/// Options of `warplight step`.
#[derive(Debug, clap::Args)]
pub struct StepArgs {
    /// The launch spec (TOML); its first launch is stepped.
    pub spec: PathBuf,
    /// Stop at this PTX line (repeatable): print the warp's state before it executes.
    #[arg(long = "break", value_name = "PTX_LINE")]
    pub breaks: Vec<u32>,
    /// Stop where a warp enters this CUDA source line (from the PTX's `.loc`; repeatable),
    /// e.g. `divergence.cu:11`, or `11` for line 11 of any file. A warp stops once each
    /// time it enters the line, before its first instruction, not at each PTX instruction.
    #[arg(long = "break-src", value_name = "[FILE:]LINE")]
    pub src_breaks: Vec<String>,
    /// Registers to print at breakpoints (repeatable), e.g. %r5 or %p1.
    #[arg(long = "watch", value_name = "REG")]
    pub watches: Vec<String>,
    /// Only log this warp: CTA slot and warp index, e.g. 0:1.
    #[arg(long, value_name = "SLOT:WARP")]
    pub warp: Option<String>,
    /// Log every issued instruction (default: only breakpoints and a summary).
    #[arg(long)]
    pub trace: bool,
    /// Stop after this many warp instructions.
    #[arg(long, default_value_t = 100_000)]
    pub max_steps: u64,
}

/// Runs the command.
pub fn run(a: StepArgs) -> Result<(), Box<dyn std::error::Error>> {
    let spec = Spec::load(&a.spec)?;
    let mut dev = Device::new();
    let prepared = launch_spec::prepare(&spec, &mut dev)?;
    let l = spec.launches.first().ok_or("the spec has no launch")?;
    let args = launch_spec::arguments(&spec, &prepared, l)?;
    let only = match &a.warp {
        None => None,
        Some(w) => {
            let (s, n) = w.split_once(':').ok_or_else(|| format!("--warp {w}: expected SLOT:WARP, e.g. 0:1"))?;
            Some((
                s.parse::<usize>().map_err(|_| format!("--warp {w}: bad slot"))?,
                n.parse::<u32>().map_err(|_| format!("--warp {w}: bad warp"))?,
            ))
        }
    };
    let prog = &prepared.module.prog;
    let src_breaks = a.src_breaks.iter().map(|b| source_breakpoint(prog, b)).collect::<Result<Vec<_>, _>>()?;
    let cfg = LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
    let mut st = dev.stepper(&prepared.module, &l.kernel, cfg, &args)?;
    println!("stepping {} (grid {:?}, block {:?}) from {}", l.kernel, l.grid, l.block, spec.ptx.display());
    let mut steps = 0u64;
    let mut hits = 0u64;
    while steps < a.max_steps {
        let Some(ev) = st.step()? else { break };
        steps += 1;
        let selected = only.is_none_or(|(s, w)| s == ev.cta_slot && w == ev.warp);
        if a.trace && selected {
            println!(
                "{steps:>7}  cta {:?} warp {:>2}  {:>5}: {:<28} mask {:08x} ({:>2} lanes){}",
                ev.cta,
                ev.warp,
                ev.ptx_line,
                ev.opcode,
                ev.mask,
                ev.mask.count_ones(),
                ev.source_line.map(|l| format!("  src line {l}")).unwrap_or_default()
            );
        }
        // breakpoints: the warp that just issued is about to execute a breakpoint line
        let Some(w) = st.warp(ev.cta_slot, ev.warp) else { continue };
        let Some(next) = w.next_ptx_line else { continue };
        let at_ptx = a.breaks.contains(&next);
        let at_src = w
            .next_source
            .filter(|s| src_breaks.iter().any(|b| b.matches(*s)) && ev.source_line != Some(s.line))
            .map(|s| s.line);
        if !selected || !(at_ptx || at_src.is_some()) {
            continue;
        }
        hits += 1;
        let text = prog.ptx_lines.get(next as usize - 1).map(|s| s.trim()).unwrap_or("");
        let src = at_src.map(|l| format!("source line {l}, ")).unwrap_or_default();
        println!("break at {src}PTX line {next} ({text}): cta {:?} warp {} in {}", ev.cta, ev.warp, w.function);
        println!("  active {:08x}  live {:08x}  call depth {}", w.active, w.live, w.call_depth);
        for (i, e) in w.stack.iter().enumerate().rev() {
            let rpc = if e.rpc == u32::MAX { "exit".to_string() } else { e.rpc.to_string() };
            println!("  stack[{i}]: pc {} rpc {rpc} mask {:08x}", e.pc, e.mask);
        }
        for r in &a.watches {
            match st.register(ev.cta_slot, ev.warp, r) {
                Some(v) => {
                    let lanes: Vec<String> =
                        (0..32).filter(|l| w.active >> l & 1 != 0).map(|l| format!("{l}:{}", v[l])).collect();
                    println!("  {r} = {}", lanes.join(" "));
                }
                None => println!(
                    "  {r}: no such register in {} (known: {})",
                    w.function,
                    st.register_names(ev.cta_slot, ev.warp).join(" ")
                ),
            }
        }
    }
    let c = st.counters();
    println!(
        "{} after {steps} warp instructions; {} breakpoint stops; {} thread instructions, {} divergent branches, {} reconvergences",
        if st.finished() { "finished" } else { "stopped" },
        hits,
        c.thread_instructions,
        c.divergent_branches,
        c.reconvergences
    );
    Ok(())
}

/// A `--break-src` breakpoint: a source line in some files (all when `files` is `None`).
struct SourceBreak {
    files: Option<Vec<u32>>,
    line: u32,
}

impl SourceBreak {
    fn matches(&self, s: SrcLoc) -> bool {
        s.line == self.line && self.files.as_ref().is_none_or(|f| f.contains(&s.file))
    }
}

/// Parses `[FILE:]LINE` against the program's `.file` table (FILE matches a path's end).
fn source_breakpoint(prog: &Program, spec: &str) -> Result<SourceBreak, String> {
    if prog.files.is_empty() {
        return Err(format!(
            "--break-src {spec}: {} has no source line information (.file/.loc); \
             compile with line info (see kernels/build.sh) or break at PTX lines with --break",
            prog.source_name
        ));
    }
    let (file, line) = match spec.rsplit_once(':') {
        Some((f, l)) => (Some(f), l),
        None => (None, spec),
    };
    let line =
        line.parse::<u32>().map_err(|_| format!("--break-src {spec}: expected [FILE:]LINE, e.g. kernel.cu:12"))?;
    let files = match file {
        None => None,
        Some(f) => {
            let ids: Vec<u32> = (0..prog.files.len() as u32)
                .filter(|&i| {
                    let p = &prog.files[i as usize];
                    p == f || p.ends_with(&format!("/{f}"))
                })
                .collect();
            if ids.is_empty() {
                return Err(format!("--break-src {spec}: no source file `{f}` (files: {})", prog.files.join(", ")));
            }
            Some(ids)
        }
    };
    let b = SourceBreak { files, line };
    let used = prog.functions.iter().flat_map(|f| &f.info).filter_map(|i| i.src).any(|s| b.matches(s));
    if !used {
        return Err(format!("--break-src {spec}: no instruction comes from that line"));
    }
    Ok(b)
}
