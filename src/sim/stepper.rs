//! Stepping through a launch one warp instruction at a time, with the same
//! scheduling (and so the same results) as a normal launch. For debuggers and
//! the teaching views.

use super::access_log::{Access, AccessLog};
use super::counters::Counters;
use super::device::{Arg, Device, LaunchConfig, Module, SimError};
use super::fault::Fault;
use super::grid::GridRun;
use super::simt_stack::SimtEntry;
use super::warp::WarpState;

/// One issued warp instruction.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StepEvent {
    /// CTA index.
    pub cta: [u32; 3],
    /// Position of the CTA among resident CTAs (for inspection calls).
    pub cta_slot: usize,
    /// Warp within the CTA.
    pub warp: u32,
    /// Function name.
    pub function: String,
    /// Instruction index.
    pub pc: u32,
    /// Its PTX line.
    pub ptx_line: u32,
    /// Its CUDA source line, when known.
    pub source_line: Option<u32>,
    /// The opcode.
    pub opcode: String,
    /// Active lanes.
    pub mask: u32,
    /// Its memory accesses (one per state space touched), when the stepper
    /// was made with [`Device::stepper_logged`]; empty otherwise.
    pub accesses: Vec<Access>,
}

/// A snapshot of a warp.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WarpView {
    /// Warp index.
    pub id: u32,
    /// Scheduling state.
    pub state: WarpState,
    /// Current function.
    pub function: String,
    /// Next PC of the running path (None when finished).
    pub next_pc: Option<u32>,
    /// PTX line of the next instruction.
    pub next_ptx_line: Option<u32>,
    /// CUDA source position (from `.loc`) of the next instruction, if the PTX has line info.
    pub next_source: Option<crate::ptx::ir::SrcLoc>,
    /// Lanes of the running path.
    pub active: u32,
    /// Lanes not exited.
    pub live: u32,
    /// SIMT stack, bottom first.
    pub stack: Vec<SimtEntry>,
    /// Call depth (1 = in the kernel).
    pub call_depth: usize,
}

/// A launch in progress, advanced by hand.
pub struct Stepper<'a> {
    run: GridRun<'a>,
    module: &'a Module,
    finished: bool,
    log: Option<&'a AccessLog>,
}

/// The stepping entry points of a [`Device`] (here, so that the device does
/// not depend on the stepper).
impl Device {
    /// Starts a launch for stepping one warp instruction at a time.
    pub fn stepper<'a>(
        &'a self,
        m: &'a Module,
        kernel: &str,
        cfg: LaunchConfig,
        args: &[Arg],
    ) -> Result<Stepper<'a>, SimError> {
        let run = self.prepare_run(m, kernel, cfg, args, None)?;
        Ok(Stepper { run, module: m, finished: false, log: None })
    }

    /// Like [`Device::stepper`], and every step's memory accesses are recorded
    /// in `log` and handed out with its [`StepEvent`].
    pub fn stepper_logged<'a>(
        &'a self,
        m: &'a Module,
        kernel: &str,
        cfg: LaunchConfig,
        args: &[Arg],
        log: &'a AccessLog,
    ) -> Result<Stepper<'a>, SimError> {
        let run = self.prepare_run(m, kernel, cfg, args, Some(log as &dyn super::observer::ObserverFactory))?;
        Ok(Stepper { run, module: m, finished: false, log: Some(log) })
    }
}

impl<'a> Stepper<'a> {
    /// The module being run.
    pub fn module(&self) -> &'a Module {
        self.module
    }

    /// Issues one warp instruction; `None` when the grid has finished.
    pub fn step(&mut self) -> Result<Option<StepEvent>, Box<Fault>> {
        if self.finished {
            return Ok(None);
        }
        match self.run.step_one()? {
            None => {
                self.finished = true;
                Ok(None)
            }
            Some((slot, i)) => {
                let prog = &self.module.prog;
                let f = &prog.functions[i.func as usize];
                let info = &f.info[i.pc as usize];
                Ok(Some(StepEvent {
                    cta: self.run.resident[slot].id,
                    cta_slot: slot,
                    warp: i.warp,
                    function: f.name.clone(),
                    pc: i.pc,
                    ptx_line: info.ptx_line,
                    source_line: info.src.map(|s| s.line),
                    opcode: info.opcode.clone(),
                    mask: i.mask,
                    accesses: self.log.map(|l| l.take()).unwrap_or_default(),
                }))
            }
        }
    }

    /// Steps until some warp's next instruction is on PTX line `line` (it has not
    /// executed yet), or the grid finishes. Returns the last event.
    pub fn run_to_ptx_line(&mut self, line: u32, max_steps: u64) -> Result<Option<StepEvent>, Box<Fault>> {
        self.run_until(max_steps, |s, ev| s.warp(ev.cta_slot, ev.warp).and_then(|w| w.next_ptx_line) == Some(line))
    }

    /// Steps until `stop(self, event)` holds after an instruction, at most `max_steps`.
    pub fn run_until(
        &mut self,
        max_steps: u64,
        mut stop: impl FnMut(&Self, &StepEvent) -> bool,
    ) -> Result<Option<StepEvent>, Box<Fault>> {
        let mut last = None;
        for _ in 0..max_steps {
            match self.step()? {
                None => return Ok(last),
                Some(ev) => {
                    let hit = stop(self, &ev);
                    last = Some(ev);
                    if hit {
                        break;
                    }
                }
            }
        }
        Ok(last)
    }

    /// True once every CTA finished.
    pub fn finished(&self) -> bool {
        self.finished || self.run.done()
    }

    /// Indices of resident CTAs, by slot.
    pub fn resident_ctas(&self) -> Vec<[u32; 3]> {
        self.run.resident.iter().map(|c| c.id).collect()
    }

    /// Number of warps in each CTA.
    pub fn warps_per_cta(&self) -> usize {
        self.run.resident.first().map(|c| c.warps.len()).unwrap_or(0)
    }

    /// A warp's state.
    pub fn warp(&self, slot: usize, warp: u32) -> Option<WarpView> {
        let c = self.run.resident.get(slot)?;
        let w = c.warps.get(warp as usize)?;
        let prog = &self.module.prog;
        let f = &prog.functions[w.frame().func as usize];
        let top = w.stack.top().copied();
        let next_pc = top.map(|t| t.pc).filter(|&pc| (pc as usize) < f.insts.len());
        Some(WarpView {
            id: w.id,
            state: w.state,
            function: f.name.clone(),
            next_pc,
            next_ptx_line: next_pc.map(|pc| f.info[pc as usize].ptx_line),
            next_source: next_pc.and_then(|pc| f.info[pc as usize].src),
            active: top.map(|t| t.mask).unwrap_or(0),
            live: w.live,
            stack: w.stack.entries.clone(),
            call_depth: w.frames.len(),
        })
    }

    /// Per-lane values of a register (data or predicate, by PTX name) in the warp's current frame.
    pub fn register(&self, slot: usize, warp: u32, name: &str) -> Option<[u64; 32]> {
        let c = self.run.resident.get(slot)?;
        let w = c.warps.get(warp as usize)?;
        let fr = w.frame();
        let f = &self.module.prog.functions[fr.func as usize];
        if let Some(i) = f.reg_names.iter().position(|n| n == name) {
            // by name through the decoded form's slot map (one row per register when stepping)
            let code = &self.module.stepping_code().funcs[fr.func as usize];
            return fr.row(code.slot(i as crate::ptx::ir::RegId));
        }
        let p = f.pred_names.iter().position(|n| n == name)?;
        let bits = fr.preds[p];
        Some(std::array::from_fn(|l| (bits >> l & 1) as u64))
    }

    /// Register names of the warp's current function.
    pub fn register_names(&self, slot: usize, warp: u32) -> Vec<String> {
        let Some(c) = self.run.resident.get(slot) else {
            return Vec::new();
        };
        let Some(w) = c.warps.get(warp as usize) else {
            return Vec::new();
        };
        let f = &self.module.prog.functions[w.frame().func as usize];
        f.reg_names.iter().chain(f.pred_names.iter().skip(2)).cloned().collect()
    }

    /// A CTA's shared memory.
    pub fn shared(&self, slot: usize) -> Option<&[u8]> {
        self.run.resident.get(slot).map(|c| c.shared.as_slice())
    }

    /// Counters so far.
    pub fn counters(&self) -> Counters {
        self.run.counters_so_far()
    }
}

#[cfg(test)]
mod tests {
    use super::super::device::{Arg, Device, LaunchConfig};
    use super::super::warp::WarpState;

    /// Arguments of a test kernel, allocated on the device.
    type Args = fn(&mut Device) -> Vec<Arg>;

    fn floats(d: &mut Device) -> Arg {
        Arg::Ptr(d.alloc_from(&(0..64).map(|i| i as f32 / 64.0).collect::<Vec<f32>>()))
    }

    /// An output buffer (some kernels write 1024 ints past their thread index).
    fn zeros(d: &mut Device) -> Arg {
        Arg::Ptr(d.alloc_zeroed::<i32>(8192))
    }

    /// `exec::step` checks for reconvergence only after an instruction (and
    /// only when the top path stands at its reconvergence point), not before
    /// the next one too: between two instructions of a warp nothing but the
    /// executor moves its stack or frames. This steps kernels with nested
    /// divergence, loops with `break`/`continue`, early `return`, divergent,
    /// recursive and indirect calls (per-lane targets) one warp instruction
    /// at a time and checks between every two instructions that a check
    /// before the next instruction would pop nothing, and that stepping
    /// counts as many reconvergences as a launch.
    #[test]
    fn the_stack_between_instructions_is_reconverged() {
        let cases: [(&str, &str, Args); 9] = [
            ("divergence", "if_else", |d| vec![zeros(d), zeros(d)]),
            ("divergence", "nested_if", |d| vec![zeros(d), zeros(d), zeros(d)]),
            ("divergence", "loop_break_continue", |d| {
                let limit: Vec<i32> = (0..64).map(|i| (i * 7) % 30).collect();
                vec![zeros(d), Arg::Ptr(d.alloc_from(&limit))]
            }),
            ("divergence", "early_return", |d| vec![zeros(d), Arg::I32(41)]),
            ("calls", "call_divergent", |d| vec![zeros(d)]),
            ("calls", "recursive_fib", |d| vec![zeros(d)]),
            ("indirect", "call_table", |d| vec![floats(d), floats(d), zeros(d), Arg::I32(60)]),
            ("indirect", "call_select", |d| vec![floats(d), zeros(d), Arg::I32(60)]),
            ("indirect", "call_virtual", |d| vec![floats(d), zeros(d), Arg::I32(60)]),
        ];
        let mut total = 0;
        for (file, kernel, args) in cases {
            let src = match file {
                "divergence" => include_str!("../../kernels/tests/divergence.ptx"),
                "calls" => include_str!("../../kernels/tests/calls.ptx"),
                _ => include_str!("../../kernels/tests/indirect.ptx"),
            };
            let mut dev = Device::new();
            let m = dev.load_ptx(src, file).unwrap();
            let args = args(&mut dev);
            let cfg = LaunchConfig::linear(1, 64);
            let mut st = dev.stepper(&m, kernel, cfg, &args).unwrap();
            let mut steps = 0;
            while st.step().unwrap().is_some() {
                steps += 1;
                for cta in &st.run.resident {
                    for w in cta.warps.iter().filter(|w| w.state != WarpState::Done && !w.stack.entries.is_empty()) {
                        let mut s = w.stack.clone();
                        let popped = s.reconverge(w.frame().stack_base);
                        assert_eq!(popped, 0, "{kernel}, warp {} after step {steps}: {:?}", w.id, w.stack.entries);
                    }
                }
            }
            let stepped = st.counters().reconvergences;
            let launched = dev.launch(&m, kernel, cfg, &args).unwrap().totals.reconvergences;
            assert_eq!(stepped, launched, "{kernel}");
            if kernel == "if_else" || kernel == "nested_if" || kernel == "call_table" {
                assert!(stepped > 0, "{kernel} reconverges");
            }
            total += stepped;
        }
        assert!(total > 10, "{total} reconvergences in all");
    }
}
