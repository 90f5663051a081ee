//! Rendering passes as kernel launches: the seed's kernels
//! (`kernels/purcell2003/*.cu`) loaded on one emulated device, and every
//! launch's counters, as the emulator reports them, summed per phase of the
//! pipeline (trace photons, build map, radiance estimate, ...).

use std::collections::BTreeMap;

use super::dataflow::{self, Class};
use crate::sim::{Arg, Device, DevicePtr, Element, LaunchConfig, LaunchStats, Module, SimConfig, SimError};

/// `kernels/purcell2003/photons.ptx`: emission, bounces, eye rays.
pub const PHOTONS_PTX: &str = include_str!("../../../kernels/purcell2003/photons.ptx");
/// `kernels/purcell2003/grid.ptx`: cell keys, bitonic sort, binary search, stencil routing.
pub const GRID_PTX: &str = include_str!("../../../kernels/purcell2003/grid.ptx");
/// `kernels/purcell2003/knn.ptx`: the kNN-grid radiance estimate.
pub const KNN_PTX: &str = include_str!("../../../kernels/purcell2003/knn.ptx");

/// Which of the three kernel files a kernel is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernels {
    /// `photons.cu`.
    Photons,
    /// `grid.cu`.
    Grid,
    /// `knn.cu`.
    Knn,
}

/// The emulator's counters of the launches of one phase, summed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PhaseCounts {
    /// Launches (rendering passes).
    pub launches: u64,
    /// Warp instructions issued.
    pub warp_instructions: u64,
    /// Thread instructions (active lanes summed over issued instructions).
    pub thread_instructions: u64,
    /// Lane-level global loads (the texture fetches of a fragment program): the
    /// guard-true lanes of every `ld.global*` instruction.
    pub lane_loads: u64,
    /// Of those, the loads at addresses that are functions of the thread's
    /// index alone, once per thread (by data flow: [`dataflow::Class::Stream`]):
    /// what a pass drawn as one point per element received as vertex attributes.
    pub stream_loads: u64,
    /// Lane-level global stores.
    pub lane_stores: u64,
    /// Lane-level atomic operations.
    pub lane_atomics: u64,
    /// CTAs run.
    pub ctas: u64,
    /// Thread instructions of address arithmetic (by data flow: [`dataflow`]).
    pub addr_instructions: u64,
    /// Thread instructions of bit packing (by data flow: [`dataflow`]).
    pub pack_instructions: u64,
}

impl PhaseCounts {
    /// Adds one launch's counters; `classes` are the classes of the module's
    /// instructions ([`dataflow::classify_program`]).
    pub fn add(&mut self, module: &Module, classes: &[Vec<Class>], s: &LaunchStats) {
        let c = dataflow::count(classes, s);
        self.addr_instructions += c.addr;
        self.pack_instructions += c.pack;
        self.stream_loads += c.stream;
        self.launches += 1;
        self.warp_instructions += s.totals.warp_instructions;
        self.thread_instructions += s.totals.thread_instructions;
        self.lane_atomics += s.totals.atomic_lane_ops;
        self.ctas += s.totals.ctas;
        let (loads, stores) = lane_memory(module, s);
        self.lane_loads += loads;
        self.lane_stores += stores;
    }

    /// Adds another phase's counts.
    pub fn merge(&mut self, o: &PhaseCounts) {
        self.launches += o.launches;
        self.warp_instructions += o.warp_instructions;
        self.thread_instructions += o.thread_instructions;
        self.lane_loads += o.lane_loads;
        self.stream_loads += o.stream_loads;
        self.lane_stores += o.lane_stores;
        self.lane_atomics += o.lane_atomics;
        self.ctas += o.ctas;
        self.addr_instructions += o.addr_instructions;
        self.pack_instructions += o.pack_instructions;
    }

    /// The counts of `later` less these (`later` a superset of these launches).
    pub fn until(&self, later: &PhaseCounts) -> PhaseCounts {
        PhaseCounts {
            launches: later.launches - self.launches,
            warp_instructions: later.warp_instructions - self.warp_instructions,
            thread_instructions: later.thread_instructions - self.thread_instructions,
            lane_loads: later.lane_loads - self.lane_loads,
            stream_loads: later.stream_loads - self.stream_loads,
            lane_stores: later.lane_stores - self.lane_stores,
            lane_atomics: later.lane_atomics - self.lane_atomics,
            ctas: later.ctas - self.ctas,
            addr_instructions: later.addr_instructions - self.addr_instructions,
            pack_instructions: later.pack_instructions - self.pack_instructions,
        }
    }
}

/// Lane-level global loads and stores of a launch, from its per-instruction
/// profile: the guard-true lanes of each `ld.global*` / `st.global*`.
pub fn lane_memory(module: &Module, s: &LaunchStats) -> (u64, u64) {
    let mut loads = 0;
    let mut stores = 0;
    for (f, counts) in s.profile.per_fn.iter().enumerate() {
        let info = &module.prog.functions[f].info;
        for (pc, c) in counts.iter().enumerate() {
            if c.pred_on == 0 {
                continue;
            }
            let op = info[pc].opcode.as_str();
            if op.starts_with("ld.global") {
                loads += c.pred_on;
            } else if op.starts_with("st.global") {
                stores += c.pred_on;
            }
        }
    }
    (loads, stores)
}

/// The seed's kernels on one emulated device, with per-phase counters.
pub struct Passes {
    /// The device.
    pub dev: Device,
    photons: Module,
    grid: Module,
    knn: Module,
    /// The instruction classes of each module's functions (photons, grid, knn).
    classes: [Vec<Vec<Class>>; 3],
    /// Counters per phase name, summed over its launches.
    pub phases: BTreeMap<String, PhaseCounts>,
    /// Counters per kernel name, summed over its launches.
    pub kernels: BTreeMap<String, PhaseCounts>,
}

impl Passes {
    /// Loads the kernels on a fresh device with the default settings and a
    /// watchdog of `max_warp_instructions` per launch (`None`: the default).
    pub fn new(max_warp_instructions: Option<u64>) -> Result<Passes, SimError> {
        Passes::configured(max_warp_instructions, &|_| {})
    }

    /// [`Passes::new`] with `set` adjusting the settings (fidelity, the
    /// device's arithmetic: [`crate::model::Profile::configure`]).
    pub fn configured(max_warp_instructions: Option<u64>, set: &dyn Fn(&mut SimConfig)) -> Result<Passes, SimError> {
        let mut c = SimConfig::default();
        if let Some(m) = max_warp_instructions {
            c.schedule.max_warp_instructions = m;
        }
        set(&mut c);
        let mut dev = Device::with_config(c);
        let photons = dev.load_ptx(PHOTONS_PTX, "kernels/purcell2003/photons.ptx")?;
        let grid = dev.load_ptx(GRID_PTX, "kernels/purcell2003/grid.ptx")?;
        let knn = dev.load_ptx(KNN_PTX, "kernels/purcell2003/knn.ptx")?;
        let classes = [&photons, &grid, &knn].map(|m| dataflow::classify_program(&m.prog));
        Ok(Passes { dev, photons, grid, knn, classes, phases: BTreeMap::new(), kernels: BTreeMap::new() })
    }

    /// The module of `k`.
    pub fn module(&self, k: Kernels) -> &Module {
        match k {
            Kernels::Photons => &self.photons,
            Kernels::Grid => &self.grid,
            Kernels::Knn => &self.knn,
        }
    }

    /// One pass: launches `kernel` and adds its counters to `phase`.
    pub fn launch(
        &mut self,
        phase: &str,
        k: Kernels,
        kernel: &str,
        cfg: LaunchConfig,
        args: &[Arg],
    ) -> Result<LaunchStats, SimError> {
        let (m, classes) = match k {
            Kernels::Photons => (&self.photons, &self.classes[0]),
            Kernels::Grid => (&self.grid, &self.classes[1]),
            Kernels::Knn => (&self.knn, &self.classes[2]),
        };
        let s = self.dev.launch(m, kernel, cfg, args)?;
        self.phases.entry(phase.to_string()).or_default().add(m, classes, &s);
        self.kernels.entry(kernel.to_string()).or_default().add(m, classes, &s);
        Ok(s)
    }

    /// A one-dimensional pass over `n` items (CTAs of 256 threads).
    pub fn launch_1d(
        &mut self,
        phase: &str,
        k: Kernels,
        kernel: &str,
        n: usize,
        args: &[Arg],
    ) -> Result<LaunchStats, SimError> {
        let ctas = n.div_ceil(THREADS as usize).max(1) as u32;
        self.launch(phase, k, kernel, LaunchConfig::linear(ctas, THREADS), args)
    }

    /// The counters of `phase` (zero if it has not run).
    pub fn phase(&self, phase: &str) -> PhaseCounts {
        self.phases.get(phase).cloned().unwrap_or_default()
    }

    /// The counters of `phase`, taken out (a later launch of it starts from zero).
    pub fn take_phase(&mut self, phase: &str) -> PhaseCounts {
        self.phases.remove(phase).unwrap_or_default()
    }

    /// The counters of every launch of `kernel` (zero if it has not run).
    pub fn kernel(&self, kernel: &str) -> PhaseCounts {
        self.kernels.get(kernel).cloned().unwrap_or_default()
    }

    /// A buffer holding `data`.
    pub fn upload<T: Element>(&mut self, data: &[T]) -> Result<DevicePtr, SimError> {
        let p = self.dev.alloc_zeroed::<T>(data.len().max(1));
        if !data.is_empty() {
            self.dev.write(p, data)?;
        }
        Ok(p)
    }
}

/// Threads per CTA of the one-dimensional passes.
pub const THREADS: u32 = 256;

/// A structure passed by value, built field by field (little-endian).
#[derive(Debug, Clone, Default)]
pub struct Bytes(pub Vec<u8>);

impl Bytes {
    /// Appends f32s.
    pub fn f32s(mut self, v: &[f32]) -> Bytes {
        for x in v {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
        self
    }

    /// Appends i32s.
    pub fn i32s(mut self, v: &[i32]) -> Bytes {
        for x in v {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
        self
    }

    /// The argument.
    pub fn arg(self) -> Arg {
        Arg::Bytes(self.0)
    }
}
