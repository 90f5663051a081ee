//! Two observer factories as one: the counter model and the checker watch
//! the same launch ([`Tee`]).

use std::any::Any;

use crate::sim::fidelity::Fidelity;
use crate::sim::observer::{MemEvent, MemObserver, ObserverFactory};

/// Passes every event to the observers of two factories.
pub struct Tee<'a> {
    /// The first factory (the counter model).
    pub first: &'a dyn ObserverFactory,
    /// The second factory (the checker).
    pub second: &'a dyn ObserverFactory,
}

/// The two observers of one CTA.
struct Both {
    first: Box<dyn MemObserver>,
    second: Box<dyn MemObserver>,
}

impl MemObserver for Both {
    fn access(&mut self, ev: &MemEvent) {
        self.first.access(ev);
        self.second.access(ev);
    }
    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
    fn as_any_mut(&mut self) -> Option<&mut dyn Any> {
        Some(self)
    }
    fn barrier_arrive(&mut self, warp: u32, func: u32, pc: u32, id: u32) {
        self.first.barrier_arrive(warp, func, pc, id);
        self.second.barrier_arrive(warp, func, pc, id);
    }
    fn barrier_release(&mut self, id: u32, warps: &[usize]) {
        self.first.barrier_release(id, warps);
        self.second.barrier_release(id, warps);
    }
    fn warp_sync(&mut self, warp: u32, lanes: u32) {
        self.first.warp_sync(warp, lanes);
        self.second.warp_sync(warp, lanes);
    }
    fn texture_access(&mut self, ev: &MemEvent) {
        self.first.texture_access(ev);
        self.second.texture_access(ev);
    }
}

impl ObserverFactory for Tee<'_> {
    fn create(&self, cta: u32) -> Box<dyn MemObserver> {
        Box::new(Both { first: self.first.create(cta), second: self.second.create(cta) })
    }

    fn retire(&self, obs: Box<dyn MemObserver>) {
        if let Ok(b) = obs.into_any().downcast::<Both>() {
            let Both { first, second } = *b;
            self.first.retire(first);
            self.second.retire(second);
        }
    }

    fn end_round(&self, observers: &mut [(u32, &mut dyn MemObserver)]) {
        let mut both: Vec<(u32, &mut Both)> = observers
            .iter_mut()
            .filter_map(|(c, o)| o.as_any_mut().and_then(|a| a.downcast_mut::<Both>()).map(|b| (*c, b)))
            .collect();
        let mut firsts: Vec<(u32, &mut dyn MemObserver)> = Vec::with_capacity(both.len());
        let mut seconds: Vec<(u32, &mut dyn MemObserver)> = Vec::with_capacity(both.len());
        for (c, b) in both.iter_mut() {
            let Both { first, second } = &mut **b;
            firsts.push((*c, first.as_mut()));
            seconds.push((*c, second.as_mut()));
        }
        self.first.end_round(&mut firsts);
        self.second.end_round(&mut seconds);
    }

    fn set_fidelity(&self, level: Fidelity) {
        self.first.set_fidelity(level);
        self.second.set_fidelity(level);
    }
}
