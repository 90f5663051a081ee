//! The core's counters: instructions, branches, divergence, reconvergence,
//! barriers and memory instructions, per launch and per instruction.
//! Kept as plain integers in each CTA and summed when the CTA retires.

use std::collections::BTreeMap;

use crate::ptx::ir::{InstClass, Program};

/// Launch-wide totals.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counters {
    /// Warp instructions issued (predicated-off ones included, as hardware counts).
    pub warp_instructions: u64,
    /// Sum over issued warp instructions of active lanes.
    pub thread_instructions: u64,
    /// Sum over issued warp instructions of lanes whose guard predicate was true.
    pub thread_instructions_pred_on: u64,
    /// Warp instructions by class: ALU, SFU, memory, control, warp-level.
    pub by_class: ClassCounts,
    /// Branch instructions (`bra`) issued.
    pub branches: u64,
    /// Branches whose active lanes went both ways.
    pub divergent_branches: u64,
    /// Times a divergent path reached its reconvergence point (SIMT stack pops).
    pub reconvergences: u64,
    /// Barriers completed per CTA (one per barrier instance, not per warp).
    pub barriers: u64,
    /// Warp-level `bar.sync` instructions executed.
    pub barrier_warp_arrivals: u64,
    /// Device-function calls (warp level).
    pub calls: u64,
    /// Warp-level load instructions per space (global, shared, local, const, param).
    pub loads: SpaceCounts,
    /// Warp-level store instructions per space.
    pub stores: SpaceCounts,
    /// Warp-level atomic instructions per space (global, shared).
    pub atomics: SpaceCounts,
    /// Lane-level atomic operations performed.
    pub atomic_lane_ops: u64,
    /// Texture and surface instructions (warp level).
    pub textures: TextureCounts,
    /// CTAs executed.
    pub ctas: u64,
    /// Warps executed.
    pub warps: u64,
    /// Scheduling rounds of the grid (see `docs/scheduler.md`).
    pub rounds: u64,
}

/// Warp instructions per [`InstClass`].
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
#[allow(missing_docs)]
pub struct ClassCounts {
    pub alu: u64,
    pub sfu: u64,
    pub memory: u64,
    pub control: u64,
    pub warp: u64,
}

impl ClassCounts {
    /// Adds one instruction of class `c`.
    #[inline]
    pub fn add(&mut self, c: InstClass) {
        match c {
            InstClass::Alu => self.alu += 1,
            InstClass::Sfu => self.sfu += 1,
            InstClass::Memory => self.memory += 1,
            InstClass::Control => self.control += 1,
            InstClass::Warp => self.warp += 1,
        }
    }
}

/// Warp-level texture and surface instructions.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct TextureCounts {
    /// `tex` and `tld4` (Nsight Compute: `smsp__inst_executed_op_texture`).
    pub instructions: u64,
    /// Texture requests: one per quad (four consecutive lanes) with an
    /// active lane, per `tex`/`tld4` (`l1tex__t_requests_pipe_tex_mem_texture`).
    pub requests: u64,
    /// `txq`.
    pub queries: u64,
    /// `suld` (`smsp__inst_executed_op_surface_ld`).
    pub surface_loads: u64,
    /// `sust` (`smsp__inst_executed_op_surface_st`).
    pub surface_stores: u64,
    /// `sured` (`smsp__inst_executed_op_surface_red`): surface reductions,
    /// not counted as stores.
    pub surface_reductions: u64,
}

/// Counts per memory space (generic accesses are counted in the space they resolve to
/// for the first active lane).
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
#[allow(missing_docs)]
pub struct SpaceCounts {
    pub global: u64,
    pub shared: u64,
    pub local: u64,
    pub constant: u64,
    pub param: u64,
}

impl Counters {
    /// Adds `o` into `self`.
    pub fn merge(&mut self, o: &Counters) {
        macro_rules! add {
            ($($f:ident).+) => { self.$($f).+ += o.$($f).+; };
        }
        add!(warp_instructions);
        add!(thread_instructions);
        add!(thread_instructions_pred_on);
        add!(by_class.alu);
        add!(by_class.sfu);
        add!(by_class.memory);
        add!(by_class.control);
        add!(by_class.warp);
        add!(branches);
        add!(divergent_branches);
        add!(reconvergences);
        add!(barriers);
        add!(barrier_warp_arrivals);
        add!(calls);
        for (a, b) in [(&mut self.loads, &o.loads), (&mut self.stores, &o.stores), (&mut self.atomics, &o.atomics)] {
            a.global += b.global;
            a.shared += b.shared;
            a.local += b.local;
            a.constant += b.constant;
            a.param += b.param;
        }
        add!(atomic_lane_ops);
        add!(textures.instructions);
        add!(textures.requests);
        add!(textures.queries);
        add!(textures.surface_loads);
        add!(textures.surface_stores);
        add!(textures.surface_reductions);
        add!(ctas);
        add!(warps);
    }
}

/// Counts of one instruction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct InstCounts {
    /// Times issued by a warp.
    pub warp: u64,
    /// Active lanes summed.
    pub thread: u64,
    /// Lanes with a true guard summed.
    pub pred_on: u64,
    /// For branches: times the warp diverged here.
    pub divergent: u64,
}

impl InstCounts {
    fn add(&mut self, o: &InstCounts) {
        self.warp += o.warp;
        self.thread += o.thread;
        self.pred_on += o.pred_on;
        self.divergent += o.divergent;
    }
}

/// Per-instruction counts of every function of a program.
///
/// While a CTA runs, the executor counts per *counting block*
/// ([`counting_leaders`](super::decode::counting_leaders)): one add of the
/// warp and thread counts at the block's first instruction per entry, and
/// `pred_on` only for guarded instructions. [`InstProfile::expand_blocks`]
/// turns that into per-instruction counts (a CTA's profile is expanded when
/// it retires, before it is merged into the launch's).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InstProfile {
    /// `per_fn[f][pc]`.
    pub per_fn: Vec<Vec<InstCounts>>,
}

impl InstProfile {
    /// An all-zero profile shaped like `prog`.
    pub fn new(prog: &Program) -> Self {
        InstProfile { per_fn: prog.functions.iter().map(|f| vec![InstCounts::default(); f.insts.len()]).collect() }
    }

    /// Turns counts kept per counting block (at each block's first
    /// instruction; `pred_on` only at guarded instructions) into counts per
    /// instruction: every instruction of a block was issued as often, with
    /// as many lanes, as its first, and an unguarded instruction's `pred_on`
    /// is its thread count. Non-first instructions' warp and thread counts
    /// are assigned, not added, so expanding twice changes nothing.
    pub fn expand_blocks(&mut self, code: &super::decode::Code) {
        for (counts, f) in self.per_fn.iter_mut().zip(&code.funcs) {
            let (mut warp, mut thread) = (0, 0);
            for (c, op) in counts.iter_mut().zip(&f.ops) {
                if op.leader {
                    (warp, thread) = (c.warp, c.thread);
                } else {
                    (c.warp, c.thread) = (warp, thread);
                }
                if !op.guarded() {
                    c.pred_on = c.thread;
                }
            }
        }
    }

    /// Adds `o` into `self`.
    pub fn merge(&mut self, o: &InstProfile) {
        for (a, b) in self.per_fn.iter_mut().zip(&o.per_fn) {
            for (x, y) in a.iter_mut().zip(b) {
                x.add(y);
            }
        }
    }
}

/// Counts attributed to one line (PTX or CUDA source).
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct LineCounts {
    /// File name.
    pub file: String,
    /// Line number.
    pub line: u32,
    /// Summed counts of the instructions on that line.
    pub counts: InstCountsSer,
}

/// Serializable form of [`InstCounts`].
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
#[allow(missing_docs)]
pub struct InstCountsSer {
    pub warp_instructions: u64,
    pub thread_instructions: u64,
    pub thread_instructions_pred_on: u64,
    pub divergent_branches: u64,
}

/// Results of one kernel launch.
#[derive(Debug, Clone)]
pub struct LaunchStats {
    /// The kernel's name.
    pub kernel: String,
    /// Totals.
    pub totals: Counters,
    /// Per-instruction counts.
    pub profile: InstProfile,
}

impl LaunchStats {
    fn lines_by(&self, prog: &Program, key: impl Fn(usize, usize) -> Option<(String, u32)>) -> Vec<LineCounts> {
        let mut map: BTreeMap<(String, u32), InstCountsSer> = BTreeMap::new();
        for (f, counts) in self.profile.per_fn.iter().enumerate() {
            for (pc, c) in counts.iter().enumerate() {
                if c.warp == 0 {
                    continue;
                }
                let Some(k) = key(f, pc) else { continue };
                let e = map.entry(k).or_default();
                e.warp_instructions += c.warp;
                e.thread_instructions += c.thread;
                e.thread_instructions_pred_on += c.pred_on;
                e.divergent_branches += c.divergent;
            }
        }
        let _ = prog;
        map.into_iter().map(|((file, line), counts)| LineCounts { file, line, counts }).collect()
    }

    /// Counts per PTX line.
    pub fn per_ptx_line(&self, prog: &Program) -> Vec<LineCounts> {
        self.lines_by(prog, |f, pc| Some((prog.source_name.clone(), prog.functions[f].info[pc].ptx_line)))
    }

    /// Counts per CUDA source line (instructions without `.loc` are left out).
    pub fn per_source_line(&self, prog: &Program) -> Vec<LineCounts> {
        self.lines_by(prog, |f, pc| {
            let s = prog.functions[f].info[pc].src?;
            Some((prog.files.get(s.file as usize).cloned().unwrap_or_default(), s.line))
        })
    }
}

/// Nsight Compute metric names accepted as aliases of warplight's counters.
/// warplight counts PTX instructions; Nsight Compute counts SASS, so the
/// instruction metrics are comparable in kind, not in value.
pub const NCU_ALIASES: &[(&str, &str)] = &[
    ("smsp__inst_executed.sum", "warp_instructions"),
    ("smsp__thread_inst_executed.sum", "thread_instructions"),
    ("smsp__thread_inst_executed_pred_on.sum", "thread_instructions_pred_on"),
    ("smsp__sass_branch_targets.sum", "branches"),
    ("smsp__sass_branch_targets_threads_divergent.sum", "divergent_branches"),
    ("launch__grid_size", "ctas"),
    ("smsp__inst_executed_op_texture.sum", "textures.instructions"),
    ("l1tex__t_requests_pipe_tex_mem_texture.sum", "textures.requests"),
    ("smsp__inst_executed_op_surface_ld.sum", "textures.surface_loads"),
    ("smsp__inst_executed_op_surface_st.sum", "textures.surface_stores"),
    ("smsp__inst_executed_op_surface_red.sum", "textures.surface_reductions"),
];

impl Counters {
    /// All counters as (dotted name, value), in a stable order.
    pub fn flatten(&self) -> Vec<(String, u64)> {
        fn walk(prefix: &str, v: &serde_json::Value, out: &mut Vec<(String, u64)>) {
            match v {
                serde_json::Value::Object(m) => {
                    for (k, x) in m {
                        let name = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                        walk(&name, x, out);
                    }
                }
                serde_json::Value::Number(n) => out.push((prefix.to_string(), n.as_u64().unwrap_or(0))),
                _ => {}
            }
        }
        let mut out = Vec::new();
        walk("", &serde_json::to_value(self).expect("counters serialize"), &mut out);
        out
    }

    /// A counter by warplight name or Nsight Compute alias.
    pub fn get(&self, name: &str) -> Option<u64> {
        let name = NCU_ALIASES.iter().find(|(a, _)| *a == name).map(|(_, n)| *n).unwrap_or(name);
        self.flatten().into_iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}
