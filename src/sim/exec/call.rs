//! Device-function calls: the callee's frame (registers, parameters, local
//! area) on call, copying return values back when all its paths returned, and
//! popping frames whose lanes exited. `vprintf` (device `printf`), declared
//! without a body, is executed here ([`vprintf`], `crate::sim::printf`).

use super::super::cfg::EXIT_PC;
use super::super::simt_stack::SimtEntry;
use super::super::warp::{Warp, WarpState};
use super::memory::{access, resolve};
use super::{CtaMut, Ctx, Effect, ExecFault, fault, lane_of_mask};
use crate::ptx::ir::{Kind, MemSpace};
use crate::sim::fault::FaultKind;
use crate::sim::printf::{self, PrintfRecord};

/// `call`: pushes the callee's frame and a path for the calling lanes.
pub(super) fn call(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    pc: u32,
    callee: u32,
    args: &[(u32, u32, u32)],
    exec: u32,
) -> Result<Effect, Box<ExecFault>> {
    if exec == 0 {
        return Ok(Effect::Continue);
    }
    cta.counters.calls += 1;
    let cf = &ctx.prog.functions[callee as usize];
    if cf.insts.is_empty() && cf.name == printf::VPRINTF {
        return vprintf(ctx, w, cta, pc, args, exec);
    }
    // Device-function frames on the stack after this call (the kernel's is not one).
    let depth = w.frames.len() as u64;
    if depth > ctx.max_call_depth as u64 {
        let names = w.frames.iter().map(|fr| ctx.prog.functions[fr.func as usize].name.as_str());
        return Err(fault(
            FaultKind::CallDepth { limit: ctx.max_call_depth, callee: cf.name.clone(), chain: call_chain(names) },
            lane_of_mask(exec),
        ));
    }
    let caller = w.frame();
    let caller_fn = &ctx.prog.functions[caller.func as usize];
    let lb = (caller.local_base + caller_fn.local_size).div_ceil(cf.local_align) * cf.local_align;
    let need = lb as u64 + cf.local_size as u64;
    if need > ctx.local_limit as u64 {
        return Err(fault(FaultKind::LocalStackOverflow { needed: need, limit: ctx.local_limit as u64 }, None));
    }
    let (caller_func, caller_ps) = (caller.func, caller.param_size);
    let rows = ctx.code.funcs[callee as usize].frame_rows();
    let mut nf = w.take_frame(callee, cf, rows, lb, w.stack.entries.len(), pc);
    let caller = w.frames.last().expect("caller");
    debug_assert_eq!(caller.func, caller_func);
    let ps_c = caller_ps as usize;
    let ps_n = nf.param_size as usize;
    for l in 0..32 {
        if exec >> l & 1 == 0 {
            continue;
        }
        for &(src, dst, size) in args {
            let (s, d, n) = (src as usize, dst as usize, size as usize);
            nf.params[l * ps_n + d..l * ps_n + d + n].copy_from_slice(&caller.params[l * ps_c + s..l * ps_c + s + n]);
        }
    }
    w.ensure_local(need as u32);
    w.local_top = need as u32;
    w.stack.push(SimtEntry { pc: 0, rpc: EXIT_PC, mask: exec });
    w.frames.push(nf);
    Ok(Effect::Continue)
}

/// `call` through a register: the lanes calling the function of the lowest
/// active lane's address call it now; the others re-issue the call after it
/// returns (one call per distinct target, as the GPU serialises them), and all
/// rejoin after the call.
pub(super) fn call_indirect(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    pc: u32,
    target: crate::ptx::ir::Src,
    args: &[(u32, u32)],
    exec: u32,
) -> Result<Effect, Box<ExecFault>> {
    if exec == 0 {
        return Ok(Effect::Continue);
    }
    let t = super::read(ctx, w, cta, target);
    let first = exec.trailing_zeros() as usize;
    let n = ctx.prog.functions.len();
    let Some(callee) = crate::ptx::ir::func_at(t[first], n) else {
        return Err(fault(
            FaultKind::Unsupported(format!("indirect call of {:#x}, which is not a function's address", t[first])),
            Some(first),
        ));
    };
    let group = (0..32).filter(|&l| exec >> l & 1 != 0 && t[l] == t[first]).fold(0u32, |m, l| m | 1 << l);
    let cf = &ctx.prog.functions[callee as usize];
    if cf.is_entry || cf.params.len() != args.len() {
        return Err(fault(
            FaultKind::Unsupported(format!(
                "indirect call of `{}` with {} argument(s); it takes {}",
                cf.name,
                args.len(),
                cf.params.len()
            )),
            Some(first),
        ));
    }
    // each argument as large as the parameter it fills (never a shortened copy)
    if let Some((k, (&(_, size), p))) = args.iter().zip(&cf.params).enumerate().find(|(_, (a, p))| a.1 != p.size) {
        return Err(fault(
            FaultKind::Unsupported(format!(
                "indirect call of `{}`: argument {} has {size} byte(s); the parameter has {}",
                cf.name,
                k + 1,
                p.size
            )),
            Some(first),
        ));
    }
    // the return values as the call site declares them: the callee's, or a fault
    // (copying back fewer or truncated values would leave registers unset)
    if let Kind::CallIndirect { rets, .. } = &ctx.prog.functions[w.frame().func as usize].insts[pc as usize].kind
        && (rets.len() != cf.returns.len() || rets.iter().zip(&cf.returns).any(|(&(_, size), r)| size != r.size))
    {
        let show =
            |sizes: &mut dyn Iterator<Item = u32>| sizes.map(|b| format!("{b}-byte")).collect::<Vec<_>>().join(", ");
        return Err(fault(
            FaultKind::Unsupported(format!(
                "indirect call of `{}` expecting {} return value(s) [{}]; it returns {} [{}]",
                cf.name,
                rets.len(),
                show(&mut rets.iter().map(|r| r.1)),
                cf.returns.len(),
                show(&mut cf.returns.iter().map(|r| r.size))
            )),
            Some(first),
        ));
    }
    let rest = exec & !group;
    if rest != 0 {
        // the others call again from the same instruction; the group rejoins after it
        let next = pc + 1;
        w.stack.push(SimtEntry { pc, rpc: next, mask: rest });
        w.stack.push(SimtEntry { pc: next, rpc: next, mask: group });
    }
    let triples: Vec<(u32, u32, u32)> =
        args.iter().zip(&cf.params).map(|(&(off, size), p)| (off, p.offset, size)).collect();
    call(ctx, w, cta, pc, callee, &triples, group)
}

/// The return values a call at `pc` of `caller` copies back: (callee offset,
/// caller offset, size).
fn call_rets(ctx: &Ctx, caller: u32, pc: u32, callee: u32) -> Vec<(u32, u32, u32)> {
    match &ctx.prog.functions[caller as usize].insts[pc as usize].kind {
        Kind::Call { rets, .. } => rets.clone(),
        Kind::CallIndirect { rets, .. } => rets
            .iter()
            .zip(&ctx.prog.functions[callee as usize].returns)
            // the sizes are equal: `call_indirect` faults otherwise
            .map(|(&(off, size), r)| (r.offset, off, size))
            .collect(),
        _ => unreachable!("call_pc names a call"),
    }
}

/// One lane's view of memory for `printf`: generic addresses resolved as
/// loads resolve them.
struct LaneMemory<'a, 'c, 'm> {
    ctx: &'a Ctx<'c>,
    w: &'a mut Warp,
    shared: &'a mut [u8],
    lane: usize,
    _m: std::marker::PhantomData<&'m ()>,
}

impl printf::Memory for LaneMemory<'_, '_, '_> {
    fn byte(&mut self, addr: u64) -> Option<u8> {
        let r = resolve(MemSpace::Generic, addr);
        access(self.ctx, self.w, self.shared, r, self.lane, 1, 1, None).ok().map(|v| v as u8)
    }
}

/// `call vprintf, (format, args)`: formats each active lane's call
/// ([`printf::format`]) into the launch's sink, and returns the number of
/// arguments used (negative when memory was unreadable, as CUDA's -1).
fn vprintf(
    ctx: &Ctx,
    w: &mut Warp,
    cta: &mut CtaMut,
    pc: u32,
    args: &[(u32, u32, u32)],
    exec: u32,
) -> Result<Effect, Box<ExecFault>> {
    let [(fmt_off, _, 8), (args_off, _, 8)] = args else {
        return Err(fault(
            FaultKind::Unsupported("`vprintf` called with other than two 64-bit arguments".into()),
            lane_of_mask(exec),
        ));
    };
    let seq = ctx.printf.sink.next_seq();
    let ps = w.frame().param_size as usize;
    let word = |w: &Warp, l: usize, off: u32| {
        let o = l * ps + off as usize;
        u64::from_le_bytes(w.frame().params[o..o + 8].try_into().expect("8 bytes"))
    };
    let mut recs = Vec::new();
    let mut results = [0i32; 32];
    for l in (0..32).filter(|l| exec >> l & 1 != 0) {
        let (fmt, buf) = (word(w, l, *fmt_off), word(w, l, *args_off));
        let mut mem = LaneMemory { ctx, w, shared: cta.shared, lane: l, _m: std::marker::PhantomData };
        let text = match printf::format(&mut mem, fmt, buf) {
            Ok((text, n)) => {
                results[l] = n as i32;
                text
            }
            Err(e) => {
                results[l] = -1;
                format!("[{e}]\n")
            }
        };
        recs.push(PrintfRecord {
            launch: ctx.printf.launch,
            cta_linear: cta.cta_linear,
            cta: cta.cta_id,
            warp: w.id,
            seq,
            lane: l as u32,
            text,
        });
    }
    ctx.printf.sink.push(recs);
    // the return value, when the call takes it (`call (retval0), vprintf, ...`)
    let f = w.frame().func as usize;
    if let Kind::Call { rets, .. } = &ctx.prog.functions[f].insts[pc as usize].kind
        && let [(_, dst, size @ 1..=8)] = rets.as_slice()
    {
        let (dst, size) = (*dst as usize, *size as usize);
        let frame = w.frames.last_mut().expect("caller frame");
        for l in (0..32).filter(|l| exec >> l & 1 != 0) {
            let o = l * ps + dst;
            frame.params[o..o + size].copy_from_slice(&(results[l] as i64).to_le_bytes()[..size]);
        }
    }
    Ok(Effect::Continue)
}

/// `ret` from a device function: the lanes leave the callee; when all its
/// paths returned, the frame pops.
pub(super) fn ret(ctx: &Ctx, w: &mut Warp, exec: u32) -> Effect {
    if exec == 0 {
        return Effect::Continue;
    }
    let fr = w.frames.last_mut().expect("frame");
    fr.returned |= exec;
    let base = fr.stack_base;
    if w.stack.retire_lanes(base, exec) {
        return_from_call(ctx, w);
    }
    if w.stack.entries.is_empty() {
        w.state = WarpState::Done;
        return Effect::Blocked;
    }
    Effect::Continue
}

/// Function names of a call stack (outermost first), consecutive repeats
/// counted: `k, f, f, f` becomes `[(k, 1), (f, 3)]`.
pub fn call_chain<'a>(names: impl Iterator<Item = &'a str>) -> Vec<(String, u32)> {
    let mut out: Vec<(String, u32)> = Vec::new();
    for n in names {
        match out.last_mut() {
            Some((last, k)) if last == n => *k += 1,
            _ => out.push((n.to_string(), 1)),
        }
    }
    out
}

/// Pops callee frames whose paths are all gone (their lanes exited).
pub(super) fn pop_empty_frames(ctx: &Ctx, w: &mut Warp) {
    while w.frames.len() > 1 && w.stack.entries.len() <= w.frame().stack_base {
        let done = w.frames.pop().expect("callee frame");
        w.recycle(done);
        let f = w.frame();
        w.local_top = f.local_base + ctx.prog.functions[f.func as usize].local_size;
    }
}

/// All of a callee's paths returned: copy return values back and pop the frame.
fn return_from_call(ctx: &Ctx, w: &mut Warp) {
    let callee = w.frames.pop().expect("callee frame");
    let caller = w.frames.last_mut().expect("caller frame");
    let rets = call_rets(ctx, caller.func, callee.call_pc, callee.func);
    let (ps_n, ps_c) = (callee.param_size as usize, caller.param_size as usize);
    for l in 0..32 {
        if callee.returned >> l & 1 == 0 {
            continue;
        }
        for &(src, dst, size) in &rets {
            let (s, d, n) = (src as usize, dst as usize, size as usize);
            caller.params[l * ps_c + d..l * ps_c + d + n]
                .copy_from_slice(&callee.params[l * ps_n + s..l * ps_n + s + n]);
        }
    }
    let cf = &ctx.prog.functions[caller.func as usize];
    w.local_top = caller.local_base + cf.local_size;
    w.recycle(callee);
}

#[cfg(test)]
mod tests {
    #[test]
    fn call_chain_counts_consecutive_repeats() {
        let names = ["k", "f", "f", "g", "f"];
        let c = super::call_chain(names.into_iter());
        let want: Vec<(String, u32)> =
            [("k", 1), ("f", 2), ("g", 1), ("f", 1)].map(|(n, k)| (n.to_string(), k)).to_vec();
        assert_eq!(c, want);
    }
}
