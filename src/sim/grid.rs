//! The grid scheduler: CTAs become resident in index order, run in parallel on
//! host threads in *rounds*, and meet between rounds, where global atomics are
//! applied in a fixed order. Results and counters are therefore the same for
//! any number of host threads.
//!
//! A round: every resident CTA issues until all its warps are blocked or
//! finished, or it has issued `round_quantum` warp instructions. Then, one CTA
//! after another in index order, each CTA's global atomics are applied in issue
//! order (lanes in lane order), finished CTAs retire and new ones become
//! resident. Plain global loads and stores go straight to memory; CTAs that
//! race on the same global address without atomics see each other's writes in
//! an order that may depend on host timing, as on a GPU.

use std::collections::BTreeMap;

use rayon::prelude::*;

use super::counters::{Counters, InstProfile, LaunchStats};
use super::cta::{Cta, CtaFault, Issued};
use super::exec::Ctx;
use super::fault::{Fault, FaultKind, HOT_LINES, HotLine};
use crate::ptx::ir::Program;

/// Scheduling parameters of the simulated machine (not of the host).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Schedule {
    /// Warp instructions a warp issues before the CTA scheduler moves on.
    pub warp_slice: u32,
    /// Warp instructions a CTA issues per round at most.
    pub round_quantum: u64,
    /// CTAs resident at once.
    pub max_resident_ctas: u32,
    /// Launch-wide warp-instruction budget (runaway detection).
    pub max_warp_instructions: u64,
    /// The random warp schedule (`--schedule random --seed N`): inside each
    /// CTA, every instruction comes from a ready warp drawn with this seed.
    /// `None`: loose round robin.
    pub random_seed: Option<u64>,
}

/// Where a launch stands, told to a [`ProgressHook`] between scheduling rounds.
pub struct Progress<'a> {
    /// CTAs that finished.
    pub ctas_retired: u64,
    /// CTAs of the grid.
    pub ctas: u64,
    /// Warp instructions issued so far (all CTAs).
    pub warp_instructions: u64,
    /// Device memory (for kernels whose progress is a counter they keep,
    /// such as a persistent-threads job queue).
    pub memory: &'a super::memory::DeviceMemory,
}

/// Called between scheduling rounds of a launch ([`super::Device::set_progress`]);
/// nothing is counted or called when none is set.
pub type ProgressHook = std::sync::Arc<dyn Fn(&Progress) + Send + Sync>;

/// An executing grid.
pub struct GridRun<'a> {
    /// Launch context.
    pub ctx: Ctx<'a>,
    kernel: u32,
    kernel_name: String,
    total_ctas: u32,
    next_cta: u32,
    /// Resident CTAs in index order.
    pub resident: Vec<Cta>,
    shared_size: usize,
    sched: Schedule,
    totals: Counters,
    profile: InstProfile,
    retired_instructions: u64,
    /// Stepping position: index into `resident` and instructions issued by it this round.
    step_cta: usize,
    step_issued: u64,
    /// A CTA that could not be made resident ([`Cta::new`]'s error).
    refused: Option<Box<Fault>>,
}

impl<'a> GridRun<'a> {
    /// Prepares a launch.
    pub fn new(ctx: Ctx<'a>, kernel: u32, shared_size: usize, sched: Schedule) -> Self {
        let total_ctas = ctx.grid[0] * ctx.grid[1] * ctx.grid[2];
        let profile = InstProfile::new(ctx.prog);
        let kernel_name = ctx.prog.functions[kernel as usize].name.clone();
        let mut g = GridRun {
            ctx,
            kernel,
            kernel_name,
            total_ctas,
            next_cta: 0,
            resident: Vec::new(),
            shared_size,
            sched,
            totals: Counters::default(),
            profile,
            retired_instructions: 0,
            step_cta: 0,
            step_issued: 0,
            refused: None,
        };
        g.admit_scheduled();
        g
    }

    /// Makes CTAs resident ([`GridRun::admit`]) and puts new ones on the
    /// random schedule when it is on.
    fn admit_scheduled(&mut self) {
        self.admit();
        if let Some(seed) = self.sched.random_seed {
            self.resident.iter_mut().for_each(|c| c.randomize(seed));
        }
    }

    fn admit(&mut self) {
        while (self.resident.len() as u32) < self.sched.max_resident_ctas.max(1) && self.next_cta < self.total_ctas {
            match Cta::new(&self.ctx, self.kernel, self.next_cta, self.shared_size, self.sched.warp_slice) {
                Ok(c) => self.resident.push(c),
                Err(f) => {
                    // reported by the next `commit` (every CTA of the kernel would refuse)
                    let [gx, gy, _] = self.ctx.grid;
                    let n = self.next_cta;
                    let id = [n % gx, (n / gx) % gy, n / (gx * gy)];
                    self.refused = Some(Box::new(make_fault(self.ctx.prog, &self.kernel_name, id, &f)));
                    return;
                }
            }
            self.next_cta += 1;
        }
    }

    fn retire(&mut self, mut c: Cta) {
        self.totals.merge(&c.counters);
        if self.ctx.per_inst {
            c.profile.expand_blocks(self.ctx.code);
        }
        self.profile.merge(&c.profile);
        if let (Some(f), Some(o)) = (self.ctx.observers, c.observer.take()) {
            f.retire(o);
        }
    }

    /// True when every CTA finished.
    pub fn done(&self) -> bool {
        self.resident.is_empty() && self.next_cta >= self.total_ctas
    }

    /// Turns a CTA fault into a located [`Fault`].
    pub fn locate(&self, cta: &Cta, f: &CtaFault) -> Box<Fault> {
        Box::new(make_fault(self.ctx.prog, &self.kernel_name, cta.id, f))
    }

    /// Runs one round on `pool` (or the current thread).
    pub fn round(&mut self, pool: Option<&rayon::ThreadPool>) -> Result<(), Box<Fault>> {
        let ctx = &self.ctx;
        let q = self.sched.round_quantum.max(1);
        let run = |c: &mut Cta| {
            let _ = c.run_round(ctx, q);
        };
        match pool {
            Some(p) if self.resident.len() > 1 => p.install(|| self.resident.par_iter_mut().for_each(run)),
            _ => self.resident.iter_mut().for_each(run),
        }
        // The between-rounds phase runs on the launch's threads too (observers
        // may settle independent parts in parallel, `ObserverFactory::end_round`).
        match pool {
            Some(p) => p.install(|| self.commit()),
            None => self.commit(),
        }
    }

    /// The between-rounds phase: faults, atomics, retirement, admission, budget.
    fn commit(&mut self) -> Result<(), Box<Fault>> {
        self.totals.rounds += 1;
        if let Some(f) = self.refused.take() {
            return Err(f);
        }
        if let Some(c) = self.resident.iter().find(|c| c.fault.is_some()) {
            let f = c.fault.clone().expect("fault");
            return Err(self.locate(c, &f));
        }
        for c in &mut self.resident {
            c.commit_atomics(&self.ctx);
        }
        if let Some(f) = self.ctx.observers {
            let mut obs: Vec<(u32, &mut dyn super::observer::MemObserver)> = self
                .resident
                .iter_mut()
                .filter_map(|c| {
                    let linear = c.linear;
                    c.observer.as_deref_mut().map(|o| (linear, o as &mut dyn super::observer::MemObserver))
                })
                .collect();
            f.end_round(&mut obs);
        }
        let mut i = 0;
        while i < self.resident.len() {
            if self.resident[i].finished() && self.resident[i].pending.is_empty() {
                let c = self.resident.remove(i);
                self.retired_instructions += c.counters.warp_instructions;
                self.retire(c);
            } else {
                i += 1;
            }
        }
        self.admit_scheduled();
        let issued: u64 =
            self.retired_instructions + self.resident.iter().map(|c| c.counters.warp_instructions).sum::<u64>();
        if issued > self.sched.max_warp_instructions
            && let Some(c) = self.resident.first()
        {
            let w = c.warps.iter().find(|w| w.state != super::warp::WarpState::Done);
            let (warp, func, pc) = w
                .map(|w| (w.id, w.frame().func, w.stack.top().map(|t| t.pc).unwrap_or(0)))
                .unwrap_or((0, self.kernel, 0));
            let f = CtaFault {
                kind: FaultKind::Runaway { budget: self.sched.max_warp_instructions, hot: self.hot_lines() },
                warp,
                func,
                pc,
                lane: None,
            };
            return Err(self.locate(c, &f));
        }
        Ok(())
    }

    /// The PTX lines the resident (still running) CTAs issued most warp
    /// instructions on, with the warps whose next instruction is there: where
    /// a runaway kernel loops.
    fn hot_lines(&self) -> Vec<HotLine> {
        let prog = self.ctx.prog;
        // ptx line -> (warp instructions, warps here, a (func, pc) on it)
        let mut lines: BTreeMap<u32, (u64, u32, (usize, usize))> = BTreeMap::new();
        let mut total = 0u64;
        for c in &self.resident {
            for (f, counts) in c.issued_profile(&self.ctx).per_fn.iter().enumerate() {
                for (pc, n) in counts.iter().enumerate() {
                    if n.warp == 0 {
                        continue;
                    }
                    total += n.warp;
                    let line = prog.functions[f].info[pc].ptx_line;
                    lines.entry(line).or_insert((0, 0, (f, pc))).0 += n.warp;
                }
            }
            for w in c.warps.iter().filter(|w| w.state != super::warp::WarpState::Done) {
                let (f, Some(pc)) = (w.frame().func as usize, w.stack.top().map(|t| t.pc as usize)) else { continue };
                if let Some(info) = prog.functions[f].info.get(pc) {
                    lines.entry(info.ptx_line).or_insert((0, 0, (f, pc))).1 += 1;
                }
            }
        }
        // Lines with a real share of the work, or with warps on them now.
        let mut v: Vec<_> =
            lines.into_iter().filter(|(_, (n, here, _))| *n as u128 * 100 >= total as u128 || *here > 0).collect();
        v.sort_by(|a, b| (b.1.0, b.1.1).cmp(&(a.1.0, a.1.1)).then(a.0.cmp(&b.0)));
        v.truncate(HOT_LINES);
        v.into_iter()
            .map(|(line, (n, here, (f, pc)))| {
                let info = &prog.functions[f].info[pc];
                HotLine {
                    ptx_line: line,
                    ptx_text: prog.ptx_lines.get(line.saturating_sub(1) as usize).cloned().unwrap_or_default(),
                    source: info
                        .src
                        .filter(|s| s.line > 0)
                        .map(|s| (prog.files.get(s.file as usize).cloned().unwrap_or_default(), s.line)),
                    warp_instructions: n,
                    share_pct: (n as u128 * 100 / total.max(1) as u128) as u32,
                    warps_here: here,
                }
            })
            .collect()
    }

    /// Runs the whole grid.
    pub fn run(self, pool: Option<&rayon::ThreadPool>) -> Result<LaunchStats, Box<Fault>> {
        self.run_with_progress(pool, None)
    }

    /// Runs the whole grid, telling `progress` where it stands after each round.
    pub fn run_with_progress(
        mut self,
        pool: Option<&rayon::ThreadPool>,
        progress: Option<&ProgressHook>,
    ) -> Result<LaunchStats, Box<Fault>> {
        while !self.done() {
            self.round(pool)?;
            if let Some(p) = progress {
                p(&Progress {
                    ctas_retired: (self.next_cta as usize - self.resident.len()) as u64,
                    ctas: self.total_ctas as u64,
                    warp_instructions: self.retired_instructions
                        + self.resident.iter().map(|c| c.counters.warp_instructions).sum::<u64>(),
                    memory: self.ctx.mem,
                });
            }
        }
        Ok(self.finish())
    }

    /// Final statistics (CTAs still resident are included).
    pub fn finish(mut self) -> LaunchStats {
        for c in std::mem::take(&mut self.resident) {
            self.retire(c);
        }
        LaunchStats { kernel: self.kernel_name, totals: self.totals, profile: self.profile }
    }

    /// Issues exactly one warp instruction, following the same round structure
    /// as [`GridRun::round`] with CTAs taken one after another. Returns the CTA
    /// position and what was issued, or `None` when the grid finished.
    pub fn step_one(&mut self) -> Result<Option<(usize, Issued)>, Box<Fault>> {
        loop {
            if self.done() {
                return Ok(None);
            }
            if self.step_cta >= self.resident.len() {
                self.commit()?;
                self.step_cta = 0;
                self.step_issued = 0;
                continue;
            }
            let k = self.step_cta;
            if self.step_issued < self.sched.round_quantum.max(1) {
                let ctx = &self.ctx;
                match self.resident[k].step(ctx) {
                    Ok(Some(i)) => {
                        self.step_issued += 1;
                        return Ok(Some((k, i)));
                    }
                    Ok(None) => {}
                    Err(f) => {
                        let c = &self.resident[k];
                        return Err(self.locate(c, &f));
                    }
                }
            }
            self.step_cta += 1;
            self.step_issued = 0;
        }
    }

    /// Counters so far (retired CTAs plus resident ones).
    pub fn counters_so_far(&self) -> Counters {
        let mut t = self.totals.clone();
        for c in &self.resident {
            t.merge(&c.counters);
        }
        t
    }
}

/// Builds a located fault.
pub fn make_fault(prog: &Program, kernel: &str, cta: [u32; 3], f: &CtaFault) -> Fault {
    let func = &prog.functions[f.func as usize];
    let info = func.info.get(f.pc as usize);
    let ptx_line = info.map(|i| i.ptx_line).unwrap_or(0);
    let ptx_text = ptx_line.checked_sub(1).and_then(|l| prog.ptx_lines.get(l as usize)).cloned().unwrap_or_default();
    let source = info
        .and_then(|i| i.src)
        .filter(|s| s.line > 0)
        .map(|s| (prog.files.get(s.file as usize).cloned().unwrap_or_default(), s.line));
    Fault {
        kind: f.kind.clone(),
        kernel: kernel.to_string(),
        function: func.name.clone(),
        pc: f.pc,
        ptx_file: prog.source_name.clone(),
        ptx_line,
        ptx_text,
        source,
        cta,
        warp: f.warp,
        lane: f.lane,
    }
}
