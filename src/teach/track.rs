//! What a step did to its warp's control flow, read from the warp's state
//! after the step: a branch that split the warp (divergence), a path that
//! reached its reconvergence point and rejoined (reconvergence), a barrier.

use std::collections::HashMap;

use crate::sim::stepper::{StepEvent, WarpView};
use crate::sim::warp::WarpState;

/// Control-flow effect of one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Effect {
    /// The warp split: fewer lanes run next than ran this instruction, and the
    /// SIMT stack grew.
    pub diverged: bool,
    /// Lanes rejoined: the lanes that run next include all that ran this
    /// instruction, and more.
    pub reconverged: bool,
    /// This path reached its reconvergence point and a waiting path runs next
    /// (none of this instruction's lanes).
    pub switched: bool,
    /// The warp now waits at a barrier.
    pub at_barrier: bool,
    /// The warp finished.
    pub exited: bool,
}

/// The effect of `ev`, given the warp's state before (`stack_before`: SIMT stack depth) and after.
pub fn effect(ev: &StepEvent, stack_before: usize, after: &WarpView) -> Effect {
    let exited = after.next_pc.is_none() || after.live == 0;
    Effect {
        diverged: !exited
            && after.stack.len() > stack_before
            && after.active & !ev.mask == 0
            && after.active != ev.mask,
        reconverged: !exited && after.active & ev.mask == ev.mask && after.active != ev.mask,
        switched: !exited && after.active & ev.mask == 0 && after.active != 0,
        at_barrier: matches!(after.state, WarpState::Barrier { .. }),
        exited,
    }
}

impl Effect {
    /// A short word for logs and the timeline, or `""`.
    pub fn word(&self) -> &'static str {
        if self.diverged {
            "diverged"
        } else if self.reconverged {
            "reconverged"
        } else if self.switched {
            "other path"
        } else if self.at_barrier {
            "waits at barrier"
        } else if self.exited {
            "exited"
        } else {
            ""
        }
    }
}

/// Remembers each warp's SIMT stack depth between its steps, to tell the
/// effect of each step.
#[derive(Debug, Clone, Default)]
pub struct Tracker {
    depth: HashMap<(usize, u32), usize>,
}

impl Tracker {
    /// The effect of `ev`, whose warp is now in state `after`.
    pub fn observe(&mut self, ev: &StepEvent, after: &WarpView) -> Effect {
        let before = self.depth.insert((ev.cta_slot, ev.warp), after.stack.len()).unwrap_or(1);
        effect(ev, before, after)
    }
}
