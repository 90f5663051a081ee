//! Records every warp-level memory access as an owned value, for the stepping
//! views (`warplight step`'s memory panel, `warplight trace`'s transactions).
//! A launch normally hands its events to a counter model and forgets them;
//! this observer keeps them until [`AccessLog::take`] drains them.

use std::any::Any;
use std::sync::{Arc, Mutex};

use super::observer::{MemEvent, MemObserver, MemOp, ObserverFactory};
use crate::ptx::ir::MemSpace;

/// One warp-level memory access, lane by lane.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Access {
    /// Linear CTA index.
    pub cta: u32,
    /// Warp within the CTA.
    pub warp: u32,
    /// Function index.
    pub func: u32,
    /// Instruction index.
    pub pc: u32,
    /// Load, store, atomic or reduction.
    pub op: MemOp,
    /// The state space the lanes' addresses resolved to.
    pub space: MemSpace,
    /// Through the read-only (texture) path.
    pub nc: bool,
    /// Bytes per lane.
    pub bytes: u32,
    /// Bytes of one vector element.
    pub elem_bytes: u32,
    /// Lanes taking part.
    pub mask: u32,
    /// Per-lane addresses (local memory: the thread's own offset); 0 for the
    /// lanes outside `mask`.
    pub addrs: [u64; 32],
}

/// An [`ObserverFactory`] whose observers append to one shared list.
#[derive(Debug, Default, Clone)]
pub struct AccessLog {
    events: Arc<Mutex<Vec<Access>>>,
}

impl AccessLog {
    /// An empty log.
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes the accesses recorded since the last call, in issue order.
    pub fn take(&self) -> Vec<Access> {
        std::mem::take(&mut *self.events.lock().unwrap_or_else(|p| p.into_inner()))
    }
}

struct Recorder {
    events: Arc<Mutex<Vec<Access>>>,
}

impl MemObserver for Recorder {
    fn access(&mut self, ev: &MemEvent) {
        let a = Access {
            cta: ev.cta,
            warp: ev.warp,
            func: ev.func,
            pc: ev.pc,
            op: ev.op,
            space: ev.space,
            nc: ev.nc,
            bytes: ev.bytes,
            elem_bytes: ev.elem_bytes,
            mask: ev.mask,
            // the event's entries outside its mask are not the lanes' own
            addrs: std::array::from_fn(|l| if ev.mask >> l & 1 != 0 { ev.addrs[l] } else { 0 }),
        };
        self.events.lock().unwrap_or_else(|p| p.into_inner()).push(a);
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
}

impl ObserverFactory for AccessLog {
    fn create(&self, _cta: u32) -> Box<dyn MemObserver> {
        Box::new(Recorder { events: Arc::clone(&self.events) })
    }

    fn retire(&self, _obs: Box<dyn MemObserver>) {}

    /// A log records every access at every level that observes memory.
    fn set_fidelity(&self, _level: super::Fidelity) {}
}
