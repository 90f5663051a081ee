//! The public face of the simulator: a [`Device`] with memory, [`Module`]s
//! loaded on it, and kernel launches.
//!
//! ```
//! use warplight::sim::{Arg, Device, LaunchConfig};
//! let ptx = r#"
//! .version 7.8
//! .target sm_90
//! .address_size 64
//! .visible .entry twice(.param .u64 p)
//! {
//!   .reg .b32 %r<3>;
//!   .reg .b64 %rd<4>;
//!   ld.param.u64 %rd1, [p];
//!   mov.u32 %r1, %tid.x;
//!   mul.wide.u32 %rd2, %r1, 4;
//!   add.s64 %rd3, %rd1, %rd2;
//!   shl.b32 %r2, %r1, 1;
//!   st.global.u32 [%rd3], %r2;
//!   ret;
//! }
//! "#;
//! let mut dev = Device::new();
//! let module = dev.load_ptx(ptx, "twice.ptx").unwrap();
//! let out = dev.alloc_zeroed::<u32>(32);
//! let stats = dev.launch(&module, "twice", LaunchConfig::linear(1, 32), &[Arg::Ptr(out)]).unwrap();
//! assert_eq!(dev.read::<u32>(out, 32)[5], 10);
//! assert_eq!(stats.totals.warp_instructions, 7);
//! ```

use std::collections::HashMap;

use super::cfg::Cfg;
use super::counters::LaunchStats;
use super::decode::{Code, FloatOptions};
use super::exec::Ctx;
use super::fault::Fault;
use super::fidelity::Fidelity;
use super::grid::{GridRun, Schedule};
use super::memory::DeviceMemory;
use super::observer::ObserverFactory;
use super::sfu::SfuModel;
use crate::ptx::{self, Program, PtxError};

/// Errors of loading and launching.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The PTX did not load.
    #[error("{0}")]
    Ptx(#[from] PtxError),
    /// No kernel of that name.
    #[error("no kernel `{name}` in {file}; kernels: {available}")]
    UnknownKernel {
        /// Requested name.
        name: String,
        /// PTX file.
        file: String,
        /// Comma-separated kernel names.
        available: String,
    },
    /// Wrong number of arguments.
    #[error("kernel `{kernel}` takes {expected} argument(s), {got} given")]
    ArgCount {
        /// Kernel.
        kernel: String,
        /// Parameters declared.
        expected: usize,
        /// Arguments given.
        got: usize,
    },
    /// An argument of the wrong size.
    #[error("argument {index} of `{kernel}` (`{param}`, .{ty}) takes {expected} bytes, the value given has {got}")]
    ArgSize {
        /// Kernel.
        kernel: String,
        /// 0-based argument index.
        index: usize,
        /// Parameter name.
        param: String,
        /// Parameter type.
        ty: String,
        /// Parameter size.
        expected: u32,
        /// Argument size.
        got: usize,
    },
    /// An impossible launch configuration.
    #[error("bad launch configuration: {0}")]
    BadLaunch(String),
    /// A device pointer that is not the start of an allocation, or an access past its end.
    #[error("bad device memory access: {0}")]
    BadPointer(String),
    /// A texture or surface descriptor that cannot be created: a bad channel
    /// count or element size, or texels outside every allocation.
    #[error("bad {what} object: {msg}")]
    BadObject {
        /// `texture` or `surface`.
        what: &'static str,
        /// What is wrong.
        msg: String,
    },
    /// The kernel faulted.
    #[error("{0}")]
    Fault(Box<Fault>),
}

/// A device address returned by [`Device::alloc`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DevicePtr(pub u64);

/// Plain values that device memory holds.
pub trait Element: Copy + Default {
    /// Size in bytes.
    const SIZE: usize;
    /// Little-endian bytes.
    fn to_bytes(self, out: &mut [u8]);
    /// From little-endian bytes.
    fn from_bytes(b: &[u8]) -> Self;
}

macro_rules! element {
    ($($t:ty),*) => {$(
        impl Element for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            fn to_bytes(self, out: &mut [u8]) {
                out.copy_from_slice(&self.to_le_bytes());
            }
            fn from_bytes(b: &[u8]) -> Self {
                <$t>::from_le_bytes(b.try_into().expect("element size"))
            }
        }
    )*};
}
element!(u8, u16, u32, u64, i8, i16, i32, i64, f32, f64);

/// Converts a slice of elements to bytes.
pub fn to_bytes<T: Element>(v: &[T]) -> Vec<u8> {
    let mut out = vec![0u8; v.len() * T::SIZE];
    for (x, chunk) in v.iter().zip(out.chunks_mut(T::SIZE)) {
        x.to_bytes(chunk);
    }
    out
}

/// Converts bytes to elements.
pub fn from_bytes<T: Element>(b: &[u8]) -> Vec<T> {
    b.chunks_exact(T::SIZE).map(T::from_bytes).collect()
}

/// The current bytes of `prog`'s `__constant__` variables, by name.
fn constants_of(prog: &Program) -> Vec<(String, Vec<u8>)> {
    prog.const_vars
        .iter()
        .map(|(name, off, size)| (name.clone(), prog.const_bank[*off as usize..(*off + *size) as usize].to_vec()))
        .collect()
}

/// A kernel argument.
#[derive(Debug, Clone, PartialEq)]
pub enum Arg {
    /// A device pointer (8 bytes).
    Ptr(DevicePtr),
    /// 32-bit unsigned.
    U32(u32),
    /// 32-bit signed.
    I32(i32),
    /// 64-bit unsigned.
    U64(u64),
    /// 64-bit signed.
    I64(i64),
    /// f32.
    F32(f32),
    /// f64.
    F64(f64),
    /// Raw bytes (structures passed by value).
    Bytes(Vec<u8>),
}

impl Arg {
    fn bytes(&self) -> Vec<u8> {
        match self {
            Arg::Ptr(p) => p.0.to_le_bytes().to_vec(),
            Arg::U32(v) => v.to_le_bytes().to_vec(),
            Arg::I32(v) => v.to_le_bytes().to_vec(),
            Arg::U64(v) => v.to_le_bytes().to_vec(),
            Arg::I64(v) => v.to_le_bytes().to_vec(),
            Arg::F32(v) => v.to_le_bytes().to_vec(),
            Arg::F64(v) => v.to_le_bytes().to_vec(),
            Arg::Bytes(b) => b.clone(),
        }
    }
}

/// Grid and CTA shape of a launch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LaunchConfig {
    /// CTAs per dimension.
    pub grid: [u32; 3],
    /// Threads per CTA per dimension.
    pub block: [u32; 3],
    /// Dynamic shared memory per CTA in bytes.
    pub dynamic_shared: u32,
}

impl LaunchConfig {
    /// A 1-D launch of `ctas` CTAs of `threads` threads.
    pub fn linear(ctas: u32, threads: u32) -> Self {
        LaunchConfig { grid: [ctas, 1, 1], block: [threads, 1, 1], dynamic_shared: 0 }
    }
}

/// Settings of the simulator (host threads and the simulated machine's scheduling).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SimConfig {
    /// Host threads running CTAs (0 = all cores). Never changes results.
    pub threads: usize,
    /// Scheduling parameters; these define the simulated machine and so the results
    /// of kernels whose CTAs communicate.
    pub schedule: Schedule,
    /// Simulated SMs (`%smid` = CTA index mod this).
    pub num_sms: u32,
    /// Local memory per thread (call stack and local arrays) in bytes.
    pub local_limit: u32,
    /// Most device-function frames on a warp's call stack; a deeper call is a
    /// [`FaultKind::CallDepth`](super::FaultKind::CallDepth) fault.
    pub max_call_depth: u32,
    /// Largest CTA.
    pub max_threads_per_cta: u32,
    /// Largest shared memory per CTA.
    pub max_shared_per_cta: u32,
    /// How much beyond the results a launch models ([`Fidelity`]); never changes results.
    pub fidelity: Fidelity,
    /// ptxas's FFMA contraction of unrounded `mul` + `add`/`sub` pairs
    /// (`--fmad=true`, sm_50 and later; [`super::contract`]), applied when a
    /// module is loaded. On by default; off reproduces `ptxas --fmad=false`
    /// and the GT200 profile (whose FMAD truncates the product: not modelled).
    pub fmad: bool,
    /// How approximate special functions are computed ([`SfuModel`]): the
    /// H200's table model by default.
    pub sfu: SfuModel,
}

/// The default watchdog: warp instructions per launch (2^32, a few minutes of
/// simulation) before a launch is stopped as a runaway.
pub const DEFAULT_MAX_WARP_INSTRUCTIONS: u64 = 1 << 32;

/// The default call-depth limit: device-function frames per warp. CUDA's
/// default 1 KiB stack per thread allows far fewer for real code.
pub const DEFAULT_MAX_CALL_DEPTH: u32 = 1024;

/// Most host threads per available core that [`cap_host_threads`] allows.
pub const HOST_THREADS_PER_CORE: usize = 4;

/// Most host threads [`cap_host_threads`] allows at all.
pub const MAX_HOST_THREADS: usize = 1024;

/// The host threads actually used for a request of `requested` (0 = all
/// cores): at most [`HOST_THREADS_PER_CORE`] per available core and at most
/// [`MAX_HOST_THREADS`]. Returns the count and, when it had to be lowered, why.
pub fn cap_host_threads(requested: usize) -> (usize, Option<String>) {
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let cap = (cores * HOST_THREADS_PER_CORE).min(MAX_HOST_THREADS);
    if requested > cap {
        let why = format!(
            "using {cap} host threads instead of {requested} ({HOST_THREADS_PER_CORE} per core on {cores} core{}, \
             at most {MAX_HOST_THREADS}); results do not depend on it",
            if cores == 1 { "" } else { "s" }
        );
        (cap, Some(why))
    } else {
        (requested, None)
    }
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            threads: 0,
            schedule: Schedule {
                warp_slice: 1,
                round_quantum: 20_000,
                max_resident_ctas: 240,
                max_warp_instructions: DEFAULT_MAX_WARP_INSTRUCTIONS,
                random_seed: None,
            },
            num_sms: 30,
            local_limit: 64 * 1024,
            max_call_depth: DEFAULT_MAX_CALL_DEPTH,
            max_threads_per_cta: 1024,
            max_shared_per_cta: 228 * 1024,
            fidelity: super::fidelity::default_level(),
            fmad: super::contract::default_on(),
            sfu: SfuModel::Sm90,
        }
    }
}

/// A program loaded on a device: its CFGs and the addresses of its `.global` variables.
#[derive(Debug)]
pub struct Module {
    /// The program.
    pub prog: Program,
    /// CFG of each function.
    pub cfgs: Vec<Cfg>,
    /// The decoded, executable form.
    pub code: Code,
    /// The decoded form with one frame row per virtual register, made on the
    /// first [`Module::stepping_code`] (steppers inspect every register by name).
    stepping: std::sync::OnceLock<Code>,
    /// What `code` was decoded with.
    opts: FloatOptions,
    globals: Vec<u64>,
    /// Its place in a recording ([`super::recording`]): the log's id and the
    /// module's index there, when loaded from PTX text while one ran.
    recorded: Option<(u64, usize)>,
}

impl Module {
    /// The executable form steppers run: as [`Module::code`], with registers
    /// not compacted, so that every register shows its last value by name.
    /// Results and counters are the same as `code`'s.
    pub fn stepping_code(&self) -> &Code {
        self.stepping.get_or_init(|| Code::decode_with(&self.prog, self.opts, false))
    }

    /// The device address of a module-scope `.global` variable.
    pub fn global(&self, name: &str) -> Option<DevicePtr> {
        self.prog.globals.iter().position(|g| g.name == name).map(|i| DevicePtr(self.globals[i]))
    }

    /// Overwrites the start of module `.const` variable `name` (`cudaMemcpyToSymbol`).
    pub fn write_constant(&mut self, name: &str, bytes: &[u8]) -> Result<(), String> {
        let Some((_, off, size)) = self.prog.const_vars.iter().find(|c| c.0 == name) else {
            let names: Vec<&str> = self.prog.const_vars.iter().map(|c| c.0.as_str()).collect();
            return Err(format!("the module has no __constant__ `{name}` (it has: {})", names.join(", ")));
        };
        if bytes.len() > *size as usize {
            return Err(format!("{} bytes do not fit `{name}` ({size} bytes)", bytes.len()));
        }
        self.prog.const_bank[*off as usize..*off as usize + bytes.len()].copy_from_slice(bytes);
        Ok(())
    }
}

/// The progress hook every new device starts with ([`set_default_progress`]).
static DEFAULT_PROGRESS: std::sync::RwLock<Option<super::grid::ProgressHook>> = std::sync::RwLock::new(None);

/// Sets the progress hook ([`Device::set_progress`]) of every device made
/// from now on: for callers whose launches run on devices that code below
/// them makes (`tables`, through the reproductions).
pub fn set_default_progress(hook: Option<super::grid::ProgressHook>) {
    if let Ok(mut h) = DEFAULT_PROGRESS.write() {
        *h = hook;
    }
}

/// A simulated GPU: memory plus a host thread pool.
pub struct Device {
    mem: DeviceMemory,
    config: SimConfig,
    pool: Option<rayon::ThreadPool>,
    sizes: HashMap<u64, u64>,
    printf: super::printf::PrintfSink,
    progress: Option<super::grid::ProgressHook>,
    textures: Vec<super::texture::Object>,
    /// The observer of launches made without one ([`Device::set_observer`]).
    observer: Option<std::sync::Arc<dyn ObserverFactory + Send>>,
    /// What the host does with the device, while a recording runs ([`super::recording`]).
    log: Option<super::recording::SharedLog>,
}

impl Default for Device {
    fn default() -> Self {
        Self::new()
    }
}

impl Device {
    /// A device with the default configuration.
    pub fn new() -> Self {
        Self::with_config(SimConfig::default())
    }

    /// A device with `config`.
    pub fn with_config(config: SimConfig) -> Self {
        let (threads, _) = cap_host_threads(config.threads);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok();
        Device {
            mem: DeviceMemory::new(),
            config,
            pool,
            sizes: HashMap::new(),
            printf: Default::default(),
            progress: DEFAULT_PROGRESS.read().ok().and_then(|h| h.clone()),
            textures: Vec::new(),
            observer: None,
            log: super::recording::attach(),
        }
    }

    /// Sets (or clears) the hook that [`Device::launch`] tells where a launch
    /// stands between scheduling rounds: CTAs retired of the grid's, for
    /// progress bars and ETAs (`render`, `launch`, `tables`).
    pub fn set_progress(&mut self, hook: Option<super::grid::ProgressHook>) {
        self.progress = hook;
    }

    /// Sets (or clears) the observer of every launch made by
    /// [`Device::launch`] (fidelity `memory` or above): for code that launches
    /// on its own (a renderer's frames) while a caller tallies the accesses.
    /// A launch given an observer ([`Device::launch_observed`]) uses that one.
    pub fn set_observer(&mut self, observer: Option<std::sync::Arc<dyn ObserverFactory + Send>>) {
        self.observer = observer;
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// Device memory.
    pub fn memory(&self) -> &DeviceMemory {
        &self.mem
    }

    /// Allocates `bytes` zeroed bytes.
    pub fn alloc_bytes(&mut self, bytes: u64, name: &str) -> DevicePtr {
        let p = self.alloc_unlogged(bytes, name);
        self.log(|l| l.alloc(p.0, bytes, name));
        p
    }

    /// Allocates without logging it (a module's `.global` variables, which
    /// a replay's module brings itself).
    fn alloc_unlogged(&mut self, bytes: u64, name: &str) -> DevicePtr {
        let p = self.mem.alloc(bytes, name);
        self.sizes.insert(p, bytes);
        DevicePtr(p)
    }

    /// Tells the recording's log, if one runs.
    fn log(&self, f: impl FnOnce(&mut super::recording::DeviceLog)) {
        if let Some(l) = &self.log {
            f(&mut l.lock().unwrap_or_else(|e| e.into_inner()));
        }
    }

    /// Allocates `n` zeroed elements.
    pub fn alloc_zeroed<T: Element>(&mut self, n: usize) -> DevicePtr {
        self.alloc_bytes((n * T::SIZE) as u64, "buffer")
    }

    /// Allocates and fills with `data`.
    pub fn alloc_from<T: Element>(&mut self, data: &[T]) -> DevicePtr {
        let p = self.alloc_zeroed::<T>(data.len());
        self.write(p, data).expect("fresh allocation fits");
        p
    }

    /// Writes elements at `p`.
    pub fn write<T: Element>(&mut self, p: DevicePtr, data: &[T]) -> Result<(), SimError> {
        let bytes = to_bytes(data);
        let (al, off) = self
            .mem
            .find(p.0, bytes.len() as u64)
            .ok_or_else(|| SimError::BadPointer(format!("{} bytes at {:#x}", bytes.len(), p.0)))?;
        al.write_bytes(off, &bytes);
        self.log(|l| l.write(p.0, &bytes));
        Ok(())
    }

    /// Reads `n` elements at `p`.
    pub fn read<T: Element>(&self, p: DevicePtr, n: usize) -> Vec<T> {
        self.try_read(p, n).expect("read within an allocation")
    }

    /// Reads `n` elements at `p`, or an error if out of bounds.
    pub fn try_read<T: Element>(&self, p: DevicePtr, n: usize) -> Result<Vec<T>, SimError> {
        let len = (n * T::SIZE) as u64;
        let (al, off) =
            self.mem.find(p.0, len).ok_or_else(|| SimError::BadPointer(format!("{len} bytes at {:#x}", p.0)))?;
        let mut b = vec![0u8; len as usize];
        al.read_bytes(off, &mut b);
        self.log(|l| l.read(p.0, &b));
        Ok(from_bytes(&b))
    }

    /// Creates a texture object (`cudaCreateTextureObject`) over texels already
    /// in device memory; the handle is what a kernel's `cudaTextureObject_t`
    /// parameter takes ([`Arg::U64`]). An error when the descriptor is
    /// invalid ([`super::texture::TextureDesc::validate`]).
    pub fn create_texture(&mut self, desc: super::texture::TextureDesc) -> Result<u64, SimError> {
        desc.validate(|a, n| self.mem.find(a, n).is_some())
            .map_err(|msg| SimError::BadObject { what: "texture", msg })?;
        self.log(|l| l.refuse("a texture object (its handle is the emulator's)"));
        self.textures.push(super::texture::Object::Texture(desc));
        Ok(super::texture::handle_of(self.textures.len() - 1))
    }

    /// Creates a surface object (`cudaCreateSurfaceObject`); the handle is a
    /// `cudaSurfaceObject_t` argument ([`Arg::U64`]). An error when the
    /// descriptor is invalid ([`super::texture::SurfaceDesc::validate`]).
    pub fn create_surface(&mut self, desc: super::texture::SurfaceDesc) -> Result<u64, SimError> {
        desc.validate(|a, n| self.mem.find(a, n).is_some())
            .map_err(|msg| SimError::BadObject { what: "surface", msg })?;
        self.log(|l| l.refuse("a surface object (its handle is the emulator's)"));
        self.textures.push(super::texture::Object::Surface(desc));
        Ok(super::texture::handle_of(self.textures.len() - 1))
    }

    /// Registers an object without [`Device::create_texture`]'s checks: how
    /// tests reach a descriptor outside every allocation.
    #[cfg(test)]
    pub(crate) fn create_object_unchecked(&mut self, obj: super::texture::Object) -> u64 {
        self.textures.push(obj);
        super::texture::handle_of(self.textures.len() - 1)
    }

    /// Size of the allocation starting at `p`.
    pub fn size_of(&self, p: DevicePtr) -> Option<u64> {
        self.sizes.get(&p.0).copied()
    }

    /// Parses, validates and loads PTX text, allocating its `.global` variables.
    pub fn load_ptx(&mut self, src: &str, name: &str) -> Result<Module, SimError> {
        let prog = ptx::load(src, name)?;
        Ok(self.load_parsed(prog, src))
    }

    /// Loads `prog`, parsed from the PTX text `src` (which a recording keeps,
    /// [`super::recording`]; [`Device::load`] has no text to keep).
    pub fn load_parsed(&mut self, prog: Program, src: &str) -> Module {
        let mut m = self.load(prog);
        if let Some(l) = &self.log {
            let name = m.prog.source_name.clone();
            let mut log = l.lock().unwrap_or_else(|e| e.into_inner());
            let index = log.module(&name, src, constants_of(&m.prog));
            m.recorded = Some((log.id(), index));
        }
        m
    }

    /// Loads a validated program.
    pub fn load(&mut self, prog: Program) -> Module {
        let cfgs = prog.functions.iter().map(Cfg::build).collect();
        let mut globals = Vec::new();
        for g in &prog.globals {
            let p = self.alloc_unlogged(g.size.max(1), &g.name);
            if let Some((al, off)) = self.mem.find(p.0, g.init.len() as u64) {
                al.write_bytes(off, &g.init);
            }
            globals.push(p.0);
        }
        let opts = FloatOptions { fmad: self.config.fmad, sfu: self.config.sfu };
        let code = Code::decode(&prog, opts);
        Module { prog, cfgs, code, stepping: std::sync::OnceLock::new(), opts, globals, recorded: None }
    }

    fn prepare(
        &self,
        m: &Module,
        kernel: &str,
        cfg: &LaunchConfig,
        args: &[Arg],
    ) -> Result<(u32, Vec<u8>, usize), SimError> {
        let k = m.prog.kernel(kernel).ok_or_else(|| SimError::UnknownKernel {
            name: kernel.to_string(),
            file: m.prog.source_name.clone(),
            available: m.prog.kernel_names().join(", "),
        })?;
        if let Some(e) = m.prog.kernel_error(k) {
            // the module loaded, but this kernel (or a function it calls) needs an unsupported instruction
            return Err(SimError::Ptx(e.clone()));
        }
        let f = &m.prog.functions[k as usize];
        if f.insts.is_empty() {
            // Only declared (`.entry k(...);`): a body, even an empty one, has an exit.
            return Err(SimError::BadLaunch(format!(
                "kernel `{kernel}` is declared without a body in {}",
                m.prog.source_name
            )));
        }
        if args.len() != f.params.len() {
            return Err(SimError::ArgCount { kernel: kernel.into(), expected: f.params.len(), got: args.len() });
        }
        let mut kp = vec![0u8; f.kernel_param_size as usize];
        for (i, (a, p)) in args.iter().zip(&f.params).enumerate() {
            let b = a.bytes();
            if b.len() != p.size as usize {
                return Err(SimError::ArgSize {
                    kernel: kernel.into(),
                    index: i,
                    param: p.name.clone(),
                    ty: p.ty.to_string(),
                    expected: p.size,
                    got: b.len(),
                });
            }
            kp[p.offset as usize..p.offset as usize + b.len()].copy_from_slice(&b);
        }
        if cfg.grid.contains(&0) || cfg.block.contains(&0) {
            return Err(SimError::BadLaunch(format!("grid {:?} and block {:?} must be non-zero", cfg.grid, cfg.block)));
        }
        let threads = cfg.block.iter().map(|&x| x as u64).product::<u64>();
        if threads > self.config.max_threads_per_cta as u64 {
            return Err(SimError::BadLaunch(format!(
                "{threads} threads per CTA; at most {} allowed",
                self.config.max_threads_per_cta
            )));
        }
        let ctas = cfg.grid.iter().map(|&x| x as u64).product::<u64>();
        if ctas > u32::MAX as u64 {
            return Err(SimError::BadLaunch(format!("{ctas} CTAs is too many")));
        }
        let shared = m.prog.static_shared_size.div_ceil(16) as usize * 16 + cfg.dynamic_shared as usize;
        if shared > self.config.max_shared_per_cta as usize {
            return Err(SimError::BadLaunch(format!(
                "{shared} bytes of shared memory per CTA; at most {} allowed",
                self.config.max_shared_per_cta
            )));
        }
        Ok((k, kp, shared))
    }

    fn ctx<'a>(
        &'a self,
        m: &'a Module,
        code: &'a Code,
        kp: Vec<u8>,
        cfg: &LaunchConfig,
        observers: Option<&'a dyn ObserverFactory>,
    ) -> Ctx<'a> {
        Ctx {
            prog: &m.prog,
            code,
            cfgs: &m.cfgs,
            mem: &self.mem,
            kparams: kp,
            global_addrs: &m.globals,
            grid: cfg.grid,
            block: cfg.block,
            num_sms: self.config.num_sms.max(1),
            local_limit: self.config.local_limit,
            max_call_depth: self.config.max_call_depth,
            observers,
            per_inst: self.config.fidelity >= Fidelity::Instructions,
            printf: super::printf::PrintfTarget { sink: &self.printf, launch: self.printf.begin_launch() },
            textures: &self.textures,
        }
    }

    /// The `printf` output of the kernels run since the last call, in a
    /// deterministic order (launch, CTA, warp, call, lane; [`super::printf`]).
    pub fn take_printf(&self) -> Vec<super::printf::PrintfRecord> {
        self.printf.take()
    }

    /// Runs a kernel to completion (observed by the device's observer, if one
    /// is set: [`Device::set_observer`]). On a fault, memory keeps what the kernel wrote
    /// before it, and the error names the instruction, CTA, warp and lane.
    pub fn launch(
        &mut self,
        m: &Module,
        kernel: &str,
        cfg: LaunchConfig,
        args: &[Arg],
    ) -> Result<LaunchStats, SimError> {
        let observer = self.observer.clone();
        self.launch_observed(m, kernel, cfg, args, observer.as_deref().map(|o| o as &dyn ObserverFactory))
    }

    /// As [`Device::launch`], with a counter model observing every memory access.
    pub fn launch_observed(
        &mut self,
        m: &Module,
        kernel: &str,
        cfg: LaunchConfig,
        args: &[Arg],
        observers: Option<&dyn ObserverFactory>,
    ) -> Result<LaunchStats, SimError> {
        let (k, kp, shared) = self.prepare(m, kernel, &cfg, args)?;
        if let Some(l) = &self.log {
            // a module of this device's log, or of none (loaded from a program, or on another device)
            let mut log = l.lock().unwrap_or_else(|e| e.into_inner());
            let index = m.recorded.filter(|r| r.0 == log.id()).map(|r| r.1);
            log.launch(index, constants_of(&m.prog), kernel, &cfg, args);
        }
        // Below `memory` nobody listens; the listener learns whether to simulate caches.
        let fidelity = self.config.fidelity;
        let observers = observers.filter(|_| fidelity >= Fidelity::Memory);
        if let Some(o) = observers {
            o.set_fidelity(fidelity);
        }
        let ctx = self.ctx(m, &m.code, kp, &cfg, observers);
        let run = GridRun::new(ctx, k, shared, self.config.schedule.clone());
        let st = run.run_with_progress(self.pool.as_ref(), self.progress.as_ref()).map_err(SimError::Fault)?;
        // the launch totals are counted at every fidelity
        self.log(|l| l.launched(st.totals.warp_instructions));
        Ok(st)
    }

    /// Checks a launch and makes its runner (for [`super::stepper`], which
    /// adds the stepping entry points to `Device`), running the module's
    /// [`Module::stepping_code`].
    pub(crate) fn prepare_run<'a>(
        &'a self,
        m: &'a Module,
        kernel: &str,
        cfg: LaunchConfig,
        args: &[Arg],
        observers: Option<&'a dyn ObserverFactory>,
    ) -> Result<GridRun<'a>, SimError> {
        let (k, kp, shared) = self.prepare(m, kernel, &cfg, args)?;
        self.log(|l| l.refuse("a stepped launch (the teaching views run warps outside Device::launch)"));
        let ctx = self.ctx(m, m.stepping_code(), kp, &cfg, observers);
        Ok(GridRun::new(ctx, k, shared, self.config.schedule.clone()))
    }
}
