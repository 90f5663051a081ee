//! Memory-access events: what each warp-level memory instruction touched,
//! lane by lane. Counter models (`crate::model`) observe these; the simulator
//! does not know which model, if any, is listening.

use std::any::Any;

use crate::ptx::ir::MemSpace;

/// The kind of memory operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MemOp {
    /// A load.
    Load,
    /// A store.
    Store,
    /// An atomic that returns the old value (`atom`).
    Atomic,
    /// An atomic without a result (`red`).
    Reduction,
}

/// One warp-level memory instruction's accesses to one state space.
/// (A generic access whose lanes resolve to several spaces gives one event per space.)
#[derive(Debug, Clone, Copy)]
pub struct MemEvent<'a> {
    /// Function index.
    pub func: u32,
    /// Instruction index.
    pub pc: u32,
    /// What kind of access.
    pub op: MemOp,
    /// The space the lanes' addresses resolved to.
    pub space: MemSpace,
    /// Through the read-only (texture / non-coherent) path: `ld.global.nc`.
    pub nc: bool,
    /// Bytes each lane accesses (element size × vector width).
    pub bytes: u32,
    /// Size of one vector element.
    pub elem_bytes: u32,
    /// Lanes taking part.
    pub mask: u32,
    /// Per-lane addresses in `space` (for local memory: the thread's own
    /// offset). Only the lanes in `mask` are meaningful: the entries of the
    /// other lanes are whatever the executor had there (another space's
    /// address, an inactive lane's operand), so observers read lanes of
    /// `mask` only.
    pub addrs: &'a [u64; 32],
    /// Linear CTA index.
    pub cta: u32,
    /// Warp within the CTA.
    pub warp: u32,
}

/// Receives the memory events of one CTA.
pub trait MemObserver: Send {
    /// One warp-level access.
    fn access(&mut self, ev: &MemEvent);
    /// The observer as `Any`, for its factory to take its results back.
    fn into_any(self: Box<Self>) -> Box<dyn Any>;
    /// The observer as `Any` while its CTA runs, for factories that settle
    /// state shared between CTAs at the end of each round (see
    /// [`ObserverFactory::end_round`]); `None` by default.
    fn as_any_mut(&mut self) -> Option<&mut dyn Any> {
        None
    }
    /// Warp `warp` arrived at barrier `id` with the `bar.sync` at (`func`,
    /// `pc`) (checkers match barriers by these). Default: nothing.
    fn barrier_arrive(&mut self, _warp: u32, _func: u32, _pc: u32, _id: u32) {}
    /// Barrier `id` completed and released `warps` (ascending): what they
    /// did before it happens before what they do after. Default: nothing.
    fn barrier_release(&mut self, _id: u32, _warps: &[usize]) {}
    /// Lanes `lanes` of warp `warp` executed one `bar.warp.sync` together:
    /// what each did before it happens before what the others do after.
    /// Default: nothing.
    fn warp_sync(&mut self, _warp: u32, _lanes: u32) {}
    /// One warp-level access to global memory through the texture path: the
    /// texels a `tex` or `tld4` read ([`MemOp::Load`]; one event per texel of
    /// a lane's footprint and texel size) or the elements a `suld`
    /// ([`MemOp::Load`]) or `sust` ([`MemOp::Store`]) accessed. The memory
    /// model counts this path apart (texture counters), so only checkers look
    /// at it. Default: nothing.
    fn texture_access(&mut self, _ev: &MemEvent) {}
}

/// Makes one observer per CTA and collects them when the CTA retires.
/// Collection must not depend on the order CTAs retire in (sums do not).
pub trait ObserverFactory: Sync {
    /// An observer for CTA `cta` (linear index).
    fn create(&self, cta: u32) -> Box<dyn MemObserver>;
    /// Takes back a retired CTA's observer.
    fn retire(&self, obs: Box<dyn MemObserver>);
    /// Called once at the end of every scheduling round, before any CTA
    /// retires, with the resident CTAs' observers (linear CTA index, observer)
    /// in CTA order. A model of hardware shared between CTAs (a cache per
    /// texture processor cluster) replays the round's accesses here in a fixed
    /// order, so that its results do not depend on host threads. Default: nothing.
    fn end_round(&self, _observers: &mut [(u32, &mut dyn MemObserver)]) {}
    /// Called before a launch with its [`Fidelity`](super::Fidelity) (`memory`
    /// or `caches`): a model with caches leaves them out below `caches`.
    /// Required, so that a factory wrapping another one cannot forget to pass it on.
    fn set_fidelity(&self, level: super::Fidelity);
}
