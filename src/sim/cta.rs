//! A CTA (thread block): its warps, shared memory, barriers, and the warp
//! scheduler that interleaves its warps.
//!
//! Scheduling policy (documented in `docs/scheduler.md`): loose round robin.
//! The scheduler keeps issuing from the current warp for up to `warp_slice`
//! instructions, or until it blocks (barrier, global atomic, fence) or
//! finishes, then moves to the next ready warp in index order. A barrier
//! completes when every warp that has not finished waits at it (or, with a
//! thread count, when that many threads wait, counted in whole warps).

use super::cfg::EXIT_PC;
use super::counters::{Counters, InstProfile};
use super::exec::{self, CtaMut, Ctx, Effect, PendingAtomic};
use super::fault::FaultKind;
use super::simt_stack::{SimtEntry, SimtStack};
use super::warp::{Frame, Warp, WarpState};
use crate::ptx::ir::{BarRedOp, Dst, PRED_TRUE};

/// The executor's view of CTA `$cta`'s state ([`CtaMut`]), borrowing its
/// fields one by one so that the warps stay free to borrow beside it (the
/// one place [`Cta::step`] and [`Cta::issue_ready`] build it).
macro_rules! cta_mut {
    ($cta:ident) => {
        CtaMut {
            cta_id: $cta.id,
            cta_linear: $cta.linear,
            shared: &mut $cta.shared,
            counters: &mut $cta.counters,
            profile: &mut $cta.profile,
            pending: &mut $cta.pending,
            observer: $cta.observer.as_mut(),
        }
    };
}

/// One executed warp instruction, as reported to a stepper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Issued {
    /// Warp index.
    pub warp: u32,
    /// Function index.
    pub func: u32,
    /// Instruction index.
    pub pc: u32,
    /// Active lanes when issued.
    pub mask: u32,
}

/// A fault inside a CTA, before the launch adds its names.
#[derive(Debug, Clone)]
pub struct CtaFault {
    /// What.
    pub kind: FaultKind,
    /// Warp.
    pub warp: u32,
    /// Function.
    pub func: u32,
    /// PC.
    pub pc: u32,
    /// Lane.
    pub lane: Option<u32>,
}

/// Why a CTA stopped issuing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stall {
    /// All warps finished.
    Finished,
    /// Some warps wait for global atomics (resolved at the round's end).
    WaitingForRound,
}

/// A resident CTA.
pub struct Cta {
    /// Index (x, y, z).
    pub id: [u32; 3],
    /// Linear index (x fastest).
    pub linear: u32,
    /// Its warps.
    pub warps: Vec<Warp>,
    /// Shared memory.
    pub shared: Vec<u8>,
    /// Counters.
    pub counters: Counters,
    /// Per-instruction counts.
    pub profile: InstProfile,
    /// Global atomics to apply at the round's end.
    pub pending: Vec<PendingAtomic>,
    /// A fault that stopped the CTA.
    pub fault: Option<CtaFault>,
    /// Its memory observer (counter model), when one listens.
    pub observer: Option<Box<dyn super::observer::MemObserver>>,
    cur: usize,
    slice_left: u32,
    slice: u32,
    /// The random schedule's generator state (`--schedule random`), when on.
    rng: Option<u64>,
}

impl Cta {
    /// Creates CTA `linear` of the launch, with every warp at the kernel's first instruction.
    /// A kernel whose `.local` frame is larger than the device's local memory
    /// per thread (`ctx.local_limit`) is a [`FaultKind::LocalStackOverflow`]
    /// at its first instruction, before anything is allocated for it.
    pub fn new(ctx: &Ctx, kernel: u32, linear: u32, shared_size: usize, slice: u32) -> Result<Cta, CtaFault> {
        let [gx, gy, _] = ctx.grid;
        let id = [linear % gx, (linear / gx) % gy, linear / (gx * gy)];
        let threads = ctx.block[0] * ctx.block[1] * ctx.block[2];
        let nwarps = threads.div_ceil(32);
        let f = &ctx.prog.functions[kernel as usize];
        if f.local_size > ctx.local_limit {
            let kind = FaultKind::LocalStackOverflow { needed: f.local_size as u64, limit: ctx.local_limit as u64 };
            return Err(CtaFault { kind, warp: 0, func: kernel, pc: 0, lane: None });
        }
        let warps = (0..nwarps)
            .map(|w| {
                let n = (threads - w * 32).min(32);
                let lanes = if n == 32 { u32::MAX } else { (1u32 << n) - 1 };
                let mut warp = Warp {
                    id: w,
                    frames: vec![Frame::new(kernel, f, ctx.code.funcs[kernel as usize].frame_rows(), 0, 0, 0)],
                    stack: SimtStack { entries: vec![SimtEntry { pc: 0, rpc: EXIT_PC, mask: lanes }] },
                    lanes,
                    live: lanes,
                    state: WarpState::Ready,
                    local: Vec::new(),
                    local_top: f.local_size,
                    frame_pool: Vec::new(),
                    bar_red: None,
                };
                warp.ensure_local(f.local_size);
                warp
            })
            .collect();
        let mut counters = Counters { ctas: 1, warps: nwarps as u64, ..Default::default() };
        counters.rounds = 0;
        Ok(Cta {
            id,
            linear,
            warps,
            shared: vec![0u8; shared_size],
            counters,
            profile: InstProfile::new(ctx.prog),
            pending: Vec::new(),
            fault: None,
            observer: ctx.observers.map(|f| f.create(linear)),
            cur: 0,
            slice_left: slice,
            slice: slice.max(1),
            rng: None,
        })
    }

    /// Switches this CTA to the random warp schedule (once; later calls keep
    /// the generator): every instruction comes from a ready warp drawn from a
    /// generator seeded with `seed` and the CTA's index, so a seed gives one
    /// interleaving whatever the host threads.
    pub fn randomize(&mut self, seed: u64) {
        if self.rng.is_none() {
            self.rng = Some(seed ^ (self.linear as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        }
    }

    /// The next draw of the random schedule (SplitMix64).
    fn draw(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// True when every warp finished.
    pub fn finished(&self) -> bool {
        self.warps.iter().all(|w| w.state == WarpState::Done)
    }

    /// Picks the warp to issue from next, releasing barriers when possible.
    fn pick(&mut self) -> Result<Option<usize>, Stall> {
        let n = self.warps.len();
        if let Some(mut state) = self.rng {
            for attempt in 0..2 {
                let ready = self.warps.iter().filter(|w| w.state == WarpState::Ready).count();
                if ready > 0 {
                    let k = (Self::draw(&mut state) % ready as u64) as usize;
                    self.rng = Some(state);
                    let i = (0..n).filter(|&i| self.warps[i].state == WarpState::Ready).nth(k).expect("ready warp");
                    self.cur = i;
                    return Ok(Some(i));
                }
                if attempt == 0 && !self.try_release() {
                    break;
                }
            }
        } else if self.slice_left > 0 && self.warps[self.cur].state == WarpState::Ready {
            return Ok(Some(self.cur));
        }
        for attempt in 0..2 {
            if self.rng.is_some() {
                break;
            }
            // the warps after the current one, wrapping around (no division)
            let mut i = self.cur;
            for _ in 0..n {
                i += 1;
                if i == n {
                    i = 0;
                }
                if self.warps[i].state == WarpState::Ready {
                    self.cur = i;
                    self.slice_left = self.slice;
                    return Ok(Some(i));
                }
            }
            if attempt == 0 && !self.try_release() {
                break;
            }
        }
        if self.warps.iter().all(|w| w.state == WarpState::Done) {
            return Err(Stall::Finished);
        }
        if self.warps.iter().any(|w| w.state == WarpState::WaitAtomic) {
            return Err(Stall::WaitingForRound);
        }
        Ok(None) // barrier deadlock: reported by the caller
    }

    /// Writes the result of the `bar.red` reduction of the warps `waiting` at a
    /// barrier that releases: the count of true predicates (`.popc`), or
    /// whether all (`.and`) or any (`.or`) of the arriving threads' are true.
    fn complete_bar_red(&mut self, waiting: &[usize]) {
        let parts: Vec<_> = waiting.iter().filter_map(|&i| self.warps[i].bar_red).collect();
        if parts.is_empty() {
            return;
        }
        let popc: u32 = parts.iter().map(|r| (r.bits & r.lanes).count_ones()).sum();
        let all = parts.iter().all(|r| r.bits & r.lanes == r.lanes);
        let any = parts.iter().any(|r| r.bits & r.lanes != 0);
        for &i in waiting {
            let Some(r) = self.warps[i].bar_red.take() else { continue };
            let fr = self.warps[i].frames.last_mut().expect("frame");
            match (r.op, r.d) {
                (BarRedOp::Popc, Some(d)) if d.reg != Dst::SINK => {
                    for l in 0..32 {
                        if r.lanes >> l & 1 != 0 {
                            fr.set_lane(d.reg as usize, l, popc as u64 & d.mask);
                        }
                    }
                }
                (BarRedOp::And | BarRedOp::Or, _) if r.p > PRED_TRUE => {
                    let v = if (r.op == BarRedOp::And && all) || (r.op == BarRedOp::Or && any) { r.lanes } else { 0 };
                    let p = &mut fr.preds[r.p as usize];
                    *p = (*p & !r.lanes) | v;
                }
                _ => {}
            }
        }
    }

    /// Completes every barrier whose condition holds. Returns true if any did.
    fn try_release(&mut self) -> bool {
        let alive = self.warps.iter().filter(|w| w.state != WarpState::Done).count();
        let mut released = false;
        let mut ids: Vec<u32> = self
            .warps
            .iter()
            .filter_map(|w| match w.state {
                WarpState::Barrier { id, .. } => Some(id),
                _ => None,
            })
            .collect();
        ids.sort_unstable();
        ids.dedup();
        for id in ids {
            let waiting: Vec<usize> = (0..self.warps.len())
                .filter(|&i| matches!(self.warps[i].state, WarpState::Barrier { id: b, .. } if b == id))
                .collect();
            let count = waiting.iter().find_map(|&i| match self.warps[i].state {
                WarpState::Barrier { count, .. } => count,
                _ => None,
            });
            // warps arrive whole (PTX): a partial last warp counts as 32 threads
            let threads = waiting.len() as u32 * 32;
            let done = match count {
                Some(c) => threads >= c,
                None => waiting.len() == alive,
            };
            if done {
                if let Some(o) = self.observer.as_mut() {
                    o.barrier_release(id, &waiting);
                }
                self.complete_bar_red(&waiting);
                for i in waiting {
                    self.warps[i].state = WarpState::Ready;
                }
                self.counters.barriers += 1;
                released = true;
            }
        }
        released
    }

    /// Issues one warp instruction. `Ok(None)` means the CTA cannot issue now
    /// (see [`Cta::stall`]).
    pub fn step(&mut self, ctx: &Ctx) -> Result<Option<Issued>, Box<CtaFault>> {
        let w = match self.pick() {
            Ok(Some(w)) => w,
            Ok(None) => {
                let waiting = self
                    .warps
                    .iter()
                    .filter_map(|w| match w.state {
                        WarpState::Barrier { id, .. } => Some((w.id, id)),
                        _ => None,
                    })
                    .collect();
                let (wi, func, pc) = self
                    .warps
                    .iter()
                    .find(|w| w.state != WarpState::Done)
                    .map(|w| (w.id, w.frame().func, w.stack.top().map(|t| t.pc.saturating_sub(1)).unwrap_or(0)))
                    .unwrap_or((0, 0, 0));
                let f = CtaFault { kind: FaultKind::BarrierDeadlock { waiting }, warp: wi, func, pc, lane: None };
                return Err(self.record_fault(f));
            }
            Err(_) => return Ok(None),
        };
        let warp = &mut self.warps[w];
        let mask = warp.stack.top().map(|t| t.mask).unwrap_or(0);
        let mut cm = cta_mut!(self);
        let (func, pc, r) = exec::step(ctx, warp, &mut cm);
        self.slice_left = self.slice_left.saturating_sub(1);
        match r {
            Ok(Effect::Continue) => {}
            Ok(Effect::Blocked) => self.blocked(w, func, pc),
            Err(e) => return Err(self.exec_fault(w, func, pc, *e)),
        }
        Ok(Some(Issued { warp: w as u32, func, pc, mask }))
    }

    /// Why the CTA cannot issue (meaningful after `step` returned `Ok(None)`).
    pub fn stall(&self) -> Stall {
        if self.finished() { Stall::Finished } else { Stall::WaitingForRound }
    }

    /// Records the fault `e` of warp `w`'s instruction at `func`, `pc` as the
    /// CTA's and returns it (the one place [`Cta::step`] and
    /// [`Cta::issue_ready`] turn an instruction's fault into the CTA's).
    #[cold]
    fn exec_fault(&mut self, w: usize, func: u32, pc: u32, e: exec::ExecFault) -> Box<CtaFault> {
        self.record_fault(CtaFault { kind: e.kind, warp: w as u32, func, pc, lane: e.lane })
    }

    /// Keeps `f` as the CTA's fault and returns it.
    #[cold]
    fn record_fault(&mut self, f: CtaFault) -> Box<CtaFault> {
        self.fault = Some(f.clone());
        Box::new(f)
    }

    /// What follows an instruction that blocked its warp `w` (at `func`,
    /// `pc`) or finished it: the scheduler moves on, the observer hears of a
    /// barrier arrival, and barriers release when they can.
    fn blocked(&mut self, w: usize, func: u32, pc: u32) {
        self.slice_left = 0;
        let state = self.warps[w].state;
        if let (WarpState::Barrier { id, .. }, Some(o)) = (state, self.observer.as_mut()) {
            o.barrier_arrive(w as u32, func, pc, id);
        }
        if matches!(state, WarpState::Barrier { .. } | WarpState::Done) {
            self.try_release();
        }
    }

    /// Issues up to `quantum` warp instructions, stopping early when blocked.
    ///
    /// The same instructions in the same order as `quantum` calls of
    /// [`Cta::step`]: the common case, a ready warp found by the loose
    /// round robin without releasing a barrier, runs in
    /// [`Cta::issue_ready`]'s loop (one `CtaMut` for many instructions, no
    /// `Issued` built); whatever else (the random schedule, a barrier to
    /// release, no ready warp, a deadlock) goes through `step` as before.
    pub fn run_round(&mut self, ctx: &Ctx, quantum: u64) -> Result<u64, Box<CtaFault>> {
        let mut n = 0;
        while n < quantum {
            if self.rng.is_none() {
                let (issued, blocked) = self.issue_ready(ctx, quantum - n)?;
                n += issued;
                if let Some((w, func, pc)) = blocked {
                    self.blocked(w, func, pc);
                    continue;
                }
                if n >= quantum {
                    break;
                }
            }
            match self.step(ctx)? {
                Some(_) => n += 1,
                None => break,
            }
        }
        Ok(n)
    }

    /// Issues up to `quantum` instructions while [`Cta::pick`]'s round robin
    /// finds a ready warp without releasing a barrier (the random schedule
    /// is not on): the current warp while its slice lasts, else the next
    /// ready warp after it, as `pick` chooses. Stops, having issued nothing
    /// more, when no warp is ready (`pick` then tries the barriers), and
    /// right after an instruction that blocked or finished its warp,
    /// returning that warp and the instruction's place for
    /// [`Cta::blocked`]. Returns how many it issued.
    #[allow(clippy::type_complexity)]
    fn issue_ready(&mut self, ctx: &Ctx, quantum: u64) -> Result<(u64, Option<(usize, u32, u32)>), Box<CtaFault>> {
        let n_warps = self.warps.len();
        let slice = self.slice;
        let mut cm = cta_mut!(self);
        let mut n = 0;
        while n < quantum {
            let mut w = self.cur;
            if self.slice_left == 0 || self.warps[w].state != WarpState::Ready {
                // the warps after the current one, wrapping around (`pick`)
                let mut found = false;
                for _ in 0..n_warps {
                    w += 1;
                    if w == n_warps {
                        w = 0;
                    }
                    if self.warps[w].state == WarpState::Ready {
                        found = true;
                        break;
                    }
                }
                if !found {
                    break;
                }
                self.cur = w;
                self.slice_left = slice;
            }
            let (func, pc, r) = exec::step(ctx, &mut self.warps[w], &mut cm);
            self.slice_left = self.slice_left.saturating_sub(1);
            n += 1;
            match r {
                Ok(Effect::Continue) => {}
                Ok(Effect::Blocked) => return Ok((n, Some((w, func, pc)))),
                Err(e) => return Err(self.exec_fault(w, func, pc, *e)),
            }
        }
        Ok((n, None))
    }

    /// The per-instruction counts of what this CTA has issued so far. While
    /// it runs, warp and thread counts are kept per counting block, added
    /// when a warp enters the block ([`InstProfile::expand_blocks`]); a warp
    /// stopped inside a block has not issued the block's rest yet, which is
    /// taken off here, so the counts are exact at any point between
    /// instructions.
    pub fn issued_profile(&self, ctx: &Ctx) -> InstProfile {
        let mut p = self.profile.clone();
        if !ctx.per_inst {
            return p;
        }
        p.expand_blocks(ctx.code);
        for w in self.warps.iter().filter(|w| w.state != WarpState::Done) {
            let (Some(top), Some(fr)) = (w.stack.top(), w.frames.last()) else { continue };
            let (ops, counts) = (&ctx.code.funcs[fr.func as usize].ops, &mut p.per_fn[fr.func as usize]);
            let lanes = top.mask.count_ones() as u64;
            let mut pc = top.pc as usize;
            while pc < ops.len() && !ops[pc].leader {
                let c = &mut counts[pc];
                c.warp = c.warp.saturating_sub(1);
                c.thread = c.thread.saturating_sub(lanes);
                if !ops[pc].guarded() {
                    c.pred_on = c.thread;
                }
                pc += 1;
            }
        }
        p
    }

    /// Applies this CTA's pending global atomics and wakes their warps.
    pub fn commit_atomics(&mut self, ctx: &Ctx) {
        exec::apply_pending(ctx, &mut self.warps, &mut self.pending);
    }
}

#[cfg(test)]
mod tests {
    use crate::sim::access_log::{Access, AccessLog};
    use crate::sim::device::{Arg, Device, LaunchConfig, SimConfig, SimError};
    use crate::sim::grid::Schedule;

    /// Arguments of a test kernel, allocated on the device.
    type Args = fn(&mut Device) -> Vec<Arg>;

    fn ints(d: &mut Device, n: usize) -> Arg {
        Arg::Ptr(d.alloc_from(&(0..n as i32).map(|i| (i * 37 % 101) - 50).collect::<Vec<i32>>()))
    }

    fn device(warp_slice: u32, round_quantum: u64) -> Device {
        let mut config = SimConfig { threads: 1, ..SimConfig::default() };
        config.schedule = Schedule { warp_slice, round_quantum, ..config.schedule };
        Device::with_config(config)
    }

    /// A launch issues its instructions through `Cta::run_round`, whose
    /// common case (`Cta::issue_ready`) picks warps inline; a stepper issues
    /// each through `Cta::step` and its `Cta::pick`. The two must issue the
    /// same instructions in the same order: this compares every memory
    /// access (CTA, warp, instruction, lanes, addresses, in issue order),
    /// the counters, or the fault, of a
    /// launch and a stepped launch of kernels with barriers, shared and
    /// global atomics (warps waiting for the round's end), divergence,
    /// early exits and calls, under GT200's schedule (a warp slice of 1)
    /// and a loose round robin (slices of 3), with rounds that end inside a
    /// slice (a quantum of 7 warp instructions) and long ones.
    #[test]
    fn launching_issues_what_stepping_issues() {
        let cases: [(&str, &str, u32, u32, Args); 7] = [
            ("shared", "reduce_sum", 3, 256, |d| vec![Arg::Ptr(d.alloc_zeroed::<i32>(3)), ints(d, 3 * 256)]),
            ("shared", "histogram", 2, 128, |d| vec![Arg::Ptr(d.alloc_zeroed::<u32>(16)), ints(d, 700), Arg::I32(700)]),
            ("atomics", "contention", 3, 64, |d| {
                vec![Arg::Ptr(d.alloc_zeroed::<u32>(1)), Arg::Ptr(d.alloc_zeroed::<u32>(192))]
            }),
            ("atomics", "job_queue", 2, 128, |d| {
                let (next, out, owner) =
                    (d.alloc_zeroed::<u32>(1), d.alloc_zeroed::<i32>(900), d.alloc_zeroed::<i32>(900));
                vec![Arg::Ptr(next), Arg::Ptr(out), Arg::Ptr(owner), Arg::I32(900)]
            }),
            ("divergence", "early_return", 2, 96, |d| vec![Arg::Ptr(d.alloc_zeroed::<i32>(8192)), Arg::I32(41)]),
            ("calls", "call_divergent", 2, 64, |d| vec![Arg::Ptr(d.alloc_zeroed::<i32>(8192))]),
            // thread 37 stores out of bounds: both report the same fault
            ("memory", "out_of_bounds", 2, 32, |d| vec![Arg::Ptr(d.alloc_zeroed::<i32>(40))]),
        ];
        for (file, kernel, ctas, threads, args) in cases {
            let src = match file {
                "shared" => include_str!("../../kernels/tests/shared.ptx"),
                "atomics" => include_str!("../../kernels/tests/atomics.ptx"),
                "divergence" => include_str!("../../kernels/tests/divergence.ptx"),
                "calls" => include_str!("../../kernels/tests/calls.ptx"),
                _ => include_str!("../../kernels/tests/memory.ptx"),
            };
            for (slice, quantum) in [(1, 20_000), (1, 7), (3, 20_000), (3, 7)] {
                let cfg = LaunchConfig::linear(ctas, threads);
                let what = format!("{kernel}, slice {slice}, quantum {quantum}");
                // launched
                let mut dev = device(slice, quantum);
                let m = dev.load_ptx(src, file).unwrap();
                let a = args(&mut dev);
                let log = AccessLog::new();
                let launched = dev.launch_observed(&m, kernel, cfg, &a, Some(&log));
                let launched_log = log.take();
                // stepped
                let mut dev = device(slice, quantum);
                let m = dev.load_ptx(src, file).unwrap();
                let a = args(&mut dev);
                let log = AccessLog::new();
                let mut st = dev.stepper_logged(&m, kernel, cfg, &a, &log).unwrap();
                let mut stepped_log: Vec<Access> = Vec::new();
                let mut issued = 0u64;
                let fault = loop {
                    match st.step() {
                        Ok(Some(ev)) => {
                            issued += 1;
                            stepped_log.extend(ev.accesses);
                        }
                        Ok(None) => break None,
                        Err(f) => break Some(f),
                    }
                };
                stepped_log.extend(log.take());
                assert!(!launched_log.is_empty(), "{what}");
                assert_eq!(launched_log, stepped_log, "{what}: the accesses in issue order");
                match (launched, fault) {
                    (Ok(s), None) => {
                        assert_eq!(s.totals.warp_instructions, issued, "{what}");
                        assert_eq!(s.totals, st.counters(), "{what}");
                    }
                    (Err(SimError::Fault(a)), Some(b)) => {
                        assert_eq!(a, b, "{what}");
                        assert_eq!(kernel, "out_of_bounds", "{what}: {a}");
                    }
                    (a, b) => panic!("{what}: launched {a:?}, stepped {b:?}"),
                }
            }
        }
    }
}
