//! Device-function calls: the callee's frame (registers, parameters, local
//! area) on call, copying return values back when all its paths returned, and
//! popping frames whose lanes exited.

use super::super::cfg::EXIT_PC;
use super::super::simt_stack::SimtEntry;
use super::super::warp::{Warp, WarpState};
use super::{CtaMut, Ctx, Effect, ExecFault, fault, lane_of_mask};
use crate::ptx::ir::Kind;
use crate::sim::fault::FaultKind;

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
    let mut nf = w.take_frame(callee, cf, lb, w.stack.entries.len(), pc);
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
    let Kind::Call { rets, .. } = &ctx.prog.functions[caller.func as usize].insts[callee.call_pc as usize].kind else {
        unreachable!("call_pc names a call");
    };
    let (ps_n, ps_c) = (callee.param_size as usize, caller.param_size as usize);
    for l in 0..32 {
        if callee.returned >> l & 1 == 0 {
            continue;
        }
        for &(src, dst, size) in rets {
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
