//! The SIMT simulator: CFG and reconvergence ([`cfg`], [`simt_stack`]), warps
//! ([`warp`]), instruction semantics ([`exec`], [`alu`]), CTAs and their warp
//! scheduler ([`cta`]), the grid scheduler ([`grid`]), device memory
//! ([`memory`]), faults ([`fault`]), counters ([`counters`]), stepping
//! ([`stepper`]), fidelity levels ([`fidelity`]), the decoded executable form
//! ([`decode`], with ptxas's FMA contraction, [`contract`], and the SFU's
//! approximations, [`sfu`]), device-side `printf` ([`printf`]) and the public
//! [`Device`] API ([`device`]).

pub mod access_log;
pub mod alu;
pub mod cfg;
pub mod contract;
pub mod counters;
pub mod cta;
pub mod decode;
pub mod device;
pub mod exec;
pub mod fault;
pub mod fidelity;
pub mod grid;
pub mod half;
pub mod memory;
pub mod observer;
pub mod printf;
pub mod recording;
pub mod regalloc;
pub mod sfu;
pub mod simt_stack;
pub mod stepper;
pub mod texture;
pub mod warp;

pub use counters::{Counters, LaunchStats};
pub use device::{Arg, Device, DevicePtr, Element, LaunchConfig, Module, SimConfig, SimError};
pub use fault::{Fault, FaultKind};
pub use fidelity::Fidelity;
pub use grid::Schedule;
pub use observer::{MemEvent, MemObserver, MemOp, ObserverFactory};
pub use stepper::{StepEvent, Stepper, WarpView};
