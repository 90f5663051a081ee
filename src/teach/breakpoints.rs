//! Breakpoints of the stepping views: PTX lines, and CUDA source lines
//! (`[FILE:]LINE`, through the PTX's `.loc` information).

use crate::ptx::Program;
use crate::ptx::ir::SrcLoc;
use crate::sim::stepper::{StepEvent, WarpView};

/// A source-line breakpoint: a line in some files (all when `files` is `None`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceBreak {
    files: Option<Vec<u32>>,
    line: u32,
}

impl SourceBreak {
    /// Whether `s` is on this breakpoint's line.
    pub fn matches(&self, s: SrcLoc) -> bool {
        s.line == self.line && self.files.as_ref().is_none_or(|f| f.contains(&s.file))
    }

    /// Parses `[FILE:]LINE` against the program's `.file` table (FILE matches a path's end).
    pub fn parse(prog: &Program, spec: &str) -> Result<SourceBreak, String> {
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
}

/// PTX-line and source-line breakpoints.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Breakpoints {
    /// PTX lines (1-based).
    pub ptx: Vec<u32>,
    /// Source lines.
    pub src: Vec<SourceBreak>,
}

/// Where a warp stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hit {
    /// The PTX line about to run.
    pub ptx_line: u32,
    /// The source line entered, for a source breakpoint.
    pub source_line: Option<u32>,
}

impl Breakpoints {
    /// Parses `--break` lines and `--break-src` specs, checking PTX lines hold instructions.
    pub fn new(prog: &Program, ptx: &[u32], src: &[String]) -> Result<Breakpoints, String> {
        for &l in ptx {
            let has_inst = prog.functions.iter().flat_map(|f| &f.info).any(|i| i.ptx_line == l);
            if !has_inst {
                let text = prog.ptx_lines.get(l.saturating_sub(1) as usize).map(|s| s.trim()).unwrap_or("past the end");
                return Err(format!("--break {l}: no instruction on PTX line {l} ({text})"));
            }
        }
        let src = src.iter().map(|b| SourceBreak::parse(prog, b)).collect::<Result<Vec<_>, _>>()?;
        Ok(Breakpoints { ptx: ptx.to_vec(), src })
    }

    /// Adds or removes a PTX-line breakpoint; returns whether it is now set.
    pub fn toggle_ptx(&mut self, line: u32) -> bool {
        if let Some(i) = self.ptx.iter().position(|&l| l == line) {
            self.ptx.remove(i);
            false
        } else {
            self.ptx.push(line);
            true
        }
    }

    /// Whether the warp that just issued `ev` (now in state `w`) is about to run a
    /// breakpoint line. A source breakpoint fires once when the warp enters its line.
    pub fn hit(&self, ev: &StepEvent, w: &WarpView) -> Option<Hit> {
        let next = w.next_ptx_line?;
        let at_ptx = self.ptx.contains(&next);
        let at_src = w
            .next_source
            .filter(|s| self.src.iter().any(|b| b.matches(*s)) && ev.source_line != Some(s.line))
            .map(|s| s.line);
        (at_ptx || at_src.is_some()).then_some(Hit { ptx_line: next, source_line: at_src })
    }
}
