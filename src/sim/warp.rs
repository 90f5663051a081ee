//! Warp state: call frames with their register files (32-lane arrays), the SIMT
//! stack, local memory, and what the warp is waiting for.

use super::simt_stack::SimtStack;
use crate::ptx::ir::{BarRedOp, Dst, Function, PredId};

/// One call frame: the registers and parameter area of a function invocation.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Function index in the program.
    pub func: u32,
    /// Data registers, one 32-lane array each (structure of arrays): the
    /// wide rows (slots `0..regs.len()`).
    pub regs: Vec<[u64; 32]>,
    /// The narrow rows of 32-bit lanes (slot `regs.len() + i` is row `i`):
    /// registers of 32 bits or fewer (`regalloc::Allocation::wide`), whose
    /// values, zero-extended, are what a wide row would hold.
    pub regs32: Vec<[u32; 32]>,
    /// Predicate registers as lane bitmasks (index 0 = false, 1 = true).
    pub preds: Vec<u32>,
    /// Per-lane parameter area: lane `l` at `l * param_size ..`.
    pub params: Vec<u8>,
    /// Size of one lane's parameter area.
    pub param_size: u32,
    /// Start of this frame's local area in each thread's local space.
    pub local_base: u32,
    /// First SIMT stack entry of this frame.
    pub stack_base: usize,
    /// The `call` instruction in the caller (callee frames only).
    pub call_pc: u32,
    /// Lanes that executed `ret` in this frame.
    pub returned: u32,
}

impl Frame {
    /// A fresh frame for `f` with `rows` (wide, narrow) register rows
    /// (zeroed): the slots its decoded form allocates (`FnCode::frame_rows`).
    pub fn new(
        func: u32,
        f: &Function,
        rows: (usize, usize),
        local_base: u32,
        stack_base: usize,
        call_pc: u32,
    ) -> Frame {
        let mut preds = vec![0u32; f.num_preds as usize];
        preds[1] = u32::MAX;
        Frame {
            func,
            regs: vec![[0u64; 32]; rows.0],
            regs32: vec![[0u32; 32]; rows.1],
            preds,
            params: vec![0u8; f.frame_param_size as usize * 32],
            param_size: f.frame_param_size,
            local_base,
            stack_base,
            call_pc,
            returned: 0,
        }
    }
}

impl Frame {
    /// Row `slot` as 64-bit lanes (a narrow row zero-extended).
    pub fn row(&self, slot: usize) -> Option<[u64; 32]> {
        match self.regs.get(slot) {
            Some(r) => Some(*r),
            None => self.regs32.get(slot.checked_sub(self.regs.len())?).map(|n| std::array::from_fn(|l| n[l] as u64)),
        }
    }

    /// Sets lane `l` of row `slot` to `v`, a value of the register's width.
    pub fn set_lane(&mut self, slot: usize, l: usize, v: u64) {
        let nw = self.regs.len();
        if slot < nw {
            self.regs[slot][l] = v;
        } else {
            self.regs32[slot - nw][l] = v as u32;
        }
    }
}

/// What a warp is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum WarpState {
    /// Can issue.
    Ready,
    /// Waiting at barrier `id` (with an optional thread count).
    Barrier {
        /// Barrier id.
        id: u32,
        /// Expected threads, when given.
        count: Option<u32>,
    },
    /// Waiting for its global atomics (or a fence) to complete at the round's end.
    WaitAtomic,
    /// All lanes finished.
    Done,
}

/// One warp.
#[derive(Debug, Clone)]
pub struct Warp {
    /// Warp index within its CTA.
    pub id: u32,
    /// Call frames, kernel first.
    pub frames: Vec<Frame>,
    /// Reconvergence stack.
    pub stack: SimtStack,
    /// Lanes that exist (a partial last warp has fewer than 32).
    pub lanes: u32,
    /// Lanes that have not exited.
    pub live: u32,
    /// Scheduling state.
    pub state: WarpState,
    /// Local memory, 4-byte words interleaved across lanes: word `w` of lane `l`
    /// is `local[w * 32 + l]` (the layout GPUs use so that equal offsets coalesce).
    pub local: Vec<u32>,
    /// Bytes of local memory in use per thread (top of the frame stack).
    pub local_top: u32,
    /// Frames of returned calls, kept for reuse so that calls do not allocate.
    pub frame_pool: Vec<Frame>,
    /// The reduction this warp contributes to the barrier it waits at (`bar.red`).
    pub bar_red: Option<BarRedWait>,
}

/// A warp's part of a `bar.red` reduction, completed when the barrier releases.
#[derive(Debug, Clone, Copy)]
pub struct BarRedWait {
    /// The reduction.
    pub op: BarRedOp,
    /// The lanes that arrived.
    pub lanes: u32,
    /// Their predicate values.
    pub bits: u32,
    /// `.popc`: the register the count goes to.
    pub d: Option<Dst>,
    /// `.and`/`.or`: the predicate the result goes to.
    pub p: PredId,
}

impl Warp {
    /// A frame for a call of `func`, reused from an earlier call when possible.
    /// Registers keep stale values: PTX leaves them undefined at entry.
    pub fn take_frame(
        &mut self,
        func: u32,
        f: &Function,
        rows: (usize, usize),
        local_base: u32,
        stack_base: usize,
        call_pc: u32,
    ) -> Frame {
        match self.frame_pool.iter().rposition(|fr| fr.func == func) {
            Some(i) => {
                let mut fr = self.frame_pool.swap_remove(i);
                fr.local_base = local_base;
                fr.stack_base = stack_base;
                fr.call_pc = call_pc;
                fr.returned = 0;
                fr
            }
            None => Frame::new(func, f, rows, local_base, stack_base, call_pc),
        }
    }

    /// Returns a finished frame to the pool.
    pub fn recycle(&mut self, fr: Frame) {
        if self.frame_pool.len() < 64 {
            self.frame_pool.push(fr);
        }
    }

    /// The current frame.
    #[inline]
    pub fn frame(&self) -> &Frame {
        self.frames.last().expect("warp has a frame")
    }

    /// Grows local memory to `bytes` per lane.
    pub fn ensure_local(&mut self, bytes: u32) {
        let words = bytes.div_ceil(4) as usize * 32;
        if self.local.len() < words {
            self.local.resize(words, 0);
        }
    }

    /// Loads `size` bytes at local offset `off` of lane `l` (bounds checked by the caller).
    #[inline(always)]
    pub fn local_load(&self, l: usize, off: u64, size: u32) -> u64 {
        let w = (off >> 2) as usize * 32 + l;
        match size {
            4 => self.local[w] as u64,
            8 => self.local[w] as u64 | (self.local[w + 32] as u64) << 32,
            _ => (self.local[w] >> ((off & 3) * 8)) as u64 & if size == 1 { 0xFF } else { 0xFFFF },
        }
    }

    /// Stores `size` bytes at local offset `off` of lane `l`.
    #[inline(always)]
    pub fn local_store(&mut self, l: usize, off: u64, size: u32, v: u64) {
        let w = (off >> 2) as usize * 32 + l;
        match size {
            4 => self.local[w] = v as u32,
            8 => {
                self.local[w] = v as u32;
                self.local[w + 32] = (v >> 32) as u32;
            }
            _ => {
                let sh = (off & 3) * 8;
                let m = if size == 1 { 0xFFu32 } else { 0xFFFF } << sh;
                self.local[w] = (self.local[w] & !m) | (((v as u32) << sh) & m);
            }
        }
    }
}
