//! Recordings of what a host does with emulated devices, to replay on a GPU.
//!
//! While a recording runs ([`start`] .. [`finish`]), every [`Device`] made
//! keeps a log of its allocations, host writes, launches (the module's PTX,
//! the kernel, the grid, the arguments, changed `__constant__` variables) and
//! host reads, the bytes each read returned included. `tools/device/replay.py`
//! replays the log on a real GPU through the driver's JIT, compares every read
//! with the emulator's bytes, and times each launch; so any emulated workload
//! (a path-traced frame, the wavefront loop, a kd-tree build) becomes a
//! ground-truth run without a host program of its own. On disk
//! ([`Recording::files`]): `recording.json` (the devices' logs, blobs as
//! offsets into `data.bin`), `data.bin` (written and read bytes) and one
//! `.ptx` file per module.
//!
//! Not replayable, and so marked with the reason (the replay refuses the
//! device): a module loaded from a parsed [`crate::ptx`] program rather than
//! PTX text, texture or surface objects (their handles are the emulator's),
//! by-value structure arguments (they may hold pointers) and stepped launches
//! (the teaching views run warps one at a time outside [`Device::launch`]).
//! Writes through [`Device::memory`] bypass the log; the project's host code
//! makes none.
//!
//! [`Device`]: super::Device
//! [`Device::launch`]: super::Device::launch
//! [`Device::memory`]: super::Device::memory

use std::sync::{Arc, Mutex};

use serde::Serialize;

use super::device::{Arg, LaunchConfig};

/// The recording format's version (`recording.json`'s `format`).
pub const FORMAT: u32 = 1;

/// Bytes of `data.bin`: where a written or read block lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Blob {
    /// Offset into `data.bin`.
    pub offset: u64,
    /// Length in bytes.
    pub len: u64,
}

/// A kernel argument as recorded: pointers apart, since the replay moves
/// them to its own allocations; floats as their bits.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RecordedArg {
    /// A device address (8 bytes), inside an allocation or one past its end.
    Ptr(u64),
    /// 32-bit unsigned.
    U32(u32),
    /// 32-bit signed.
    I32(i32),
    /// 64-bit unsigned (not moved: the replay passes it as is).
    U64(u64),
    /// 64-bit signed.
    I64(i64),
    /// An f32's bits.
    F32(u32),
    /// An f64's bits.
    F64(u64),
    /// A scalar of 1, 2, 4 or 8 bytes given as bytes (a launch spec's
    /// numbers take the parameter's width), little-endian, passed as is.
    Bytes(Vec<u8>),
}

/// One thing the host did with a device.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "op", rename_all = "snake_case")]
pub enum Op {
    /// `bytes` zeroed bytes at `addr`.
    Alloc {
        /// The emulator's address.
        addr: u64,
        /// Its size.
        bytes: u64,
        /// Its name.
        name: String,
    },
    /// A host write at `addr`.
    Write {
        /// Where.
        addr: u64,
        /// What.
        data: Blob,
    },
    /// Module `module`'s `__constant__` variable `name` set (changed since
    /// the last launch of the module).
    Constant {
        /// Index into the device's modules.
        module: usize,
        /// The variable.
        name: String,
        /// Its bytes from its start.
        data: Blob,
    },
    /// A kernel launch.
    Launch {
        /// Index into the device's modules.
        module: usize,
        /// The entry point.
        kernel: String,
        /// CTAs per dimension.
        grid: [u32; 3],
        /// Threads per CTA per dimension.
        block: [u32; 3],
        /// Dynamic shared memory bytes.
        shared: u32,
        /// The arguments.
        args: Vec<RecordedArg>,
        /// The warp instructions the emulator issued for it (counted at
        /// every fidelity; None until the launch has run, or when it failed).
        #[serde(skip_serializing_if = "Option::is_none")]
        warp_instructions: Option<u64>,
    },
    /// A host read at `addr`, with what the emulator returned.
    Read {
        /// Where.
        addr: u64,
        /// The emulator's bytes.
        data: Blob,
    },
}

/// A module as recorded: its PTX text and its constants as last launched.
#[derive(Debug, Clone)]
struct RecordedModule {
    name: String,
    ptx: String,
    constants: Vec<(String, Vec<u8>)>,
}

/// One device's log.
#[derive(Debug, Default)]
pub struct DeviceLog {
    /// Unique among the logs of the process (a module knows its log by it).
    id: u64,
    modules: Vec<RecordedModule>,
    ops: Vec<Op>,
    data: Vec<u8>,
    unreplayable: Option<String>,
}

impl DeviceLog {
    fn blob(&mut self, bytes: &[u8]) -> Blob {
        let b = Blob { offset: self.data.len() as u64, len: bytes.len() as u64 };
        self.data.extend_from_slice(bytes);
        b
    }

    /// The log's identity, unique in the process.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Marks the log as not replayable (the first reason stays).
    pub fn refuse(&mut self, why: &str) {
        self.unreplayable.get_or_insert_with(|| why.to_string());
    }

    /// A module loaded from `ptx` (named `name`) with its constants'
    /// initial bytes; its index.
    pub fn module(&mut self, name: &str, ptx: &str, constants: Vec<(String, Vec<u8>)>) -> usize {
        self.modules.push(RecordedModule { name: name.to_string(), ptx: ptx.to_string(), constants });
        self.modules.len() - 1
    }

    /// An allocation.
    pub fn alloc(&mut self, addr: u64, bytes: u64, name: &str) {
        self.ops.push(Op::Alloc { addr, bytes, name: name.to_string() });
    }

    /// A host write.
    pub fn write(&mut self, addr: u64, bytes: &[u8]) {
        let data = self.blob(bytes);
        self.ops.push(Op::Write { addr, data });
    }

    /// A host read and what it returned.
    pub fn read(&mut self, addr: u64, bytes: &[u8]) {
        let data = self.blob(bytes);
        self.ops.push(Op::Read { addr, data });
    }

    /// A launch of `kernel` in module `module` (None: a module the log does
    /// not hold, so the log is refused), its constants now `constants`.
    pub fn launch(
        &mut self,
        module: Option<usize>,
        constants: Vec<(String, Vec<u8>)>,
        kernel: &str,
        cfg: &LaunchConfig,
        args: &[Arg],
    ) {
        let Some(m) = module else {
            self.refuse("a module loaded from a parsed program, not PTX text");
            return;
        };
        let mut recorded = Vec::with_capacity(args.len());
        for a in args {
            recorded.push(match a {
                Arg::Ptr(p) => RecordedArg::Ptr(p.0),
                Arg::U32(v) => RecordedArg::U32(*v),
                Arg::I32(v) => RecordedArg::I32(*v),
                Arg::U64(v) => RecordedArg::U64(*v),
                Arg::I64(v) => RecordedArg::I64(*v),
                Arg::F32(v) => RecordedArg::F32(v.to_bits()),
                Arg::F64(v) => RecordedArg::F64(v.to_bits()),
                Arg::Bytes(b) if matches!(b.len(), 1 | 2 | 4 | 8) => RecordedArg::Bytes(b.clone()),
                Arg::Bytes(_) => {
                    self.refuse("a structure passed by value (it may hold device pointers)");
                    return;
                }
            });
        }
        for (name, bytes) in constants {
            let known = self.modules[m].constants.iter().position(|c| c.0 == name);
            if known.is_some_and(|i| self.modules[m].constants[i].1 == bytes) {
                continue;
            }
            let data = self.blob(&bytes);
            self.ops.push(Op::Constant { module: m, name: name.clone(), data });
            match known {
                Some(i) => self.modules[m].constants[i].1 = bytes,
                None => self.modules[m].constants.push((name, bytes)),
            }
        }
        self.ops.push(Op::Launch {
            module: m,
            kernel: kernel.to_string(),
            grid: cfg.grid,
            block: cfg.block,
            shared: cfg.dynamic_shared,
            args: recorded,
            warp_instructions: None,
        });
    }

    /// The last launch issued `warp` warp instructions on the emulator.
    pub fn launched(&mut self, warp: u64) {
        if let Some(Op::Launch { warp_instructions, .. }) = self.ops.last_mut() {
            *warp_instructions = Some(warp);
        }
    }

    /// The operations so far.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// The bytes of `b`.
    pub fn bytes(&self, b: Blob) -> &[u8] {
        &self.data[b.offset as usize..(b.offset + b.len) as usize]
    }

    /// Why the log cannot be replayed, if it cannot.
    pub fn unreplayable(&self) -> Option<&str> {
        self.unreplayable.as_deref()
    }
}

/// A device's log, shared between the device and the recording.
pub type SharedLog = Arc<Mutex<DeviceLog>>;

/// The logs of the devices made since [`start`], while one runs.
static RECORDING: Mutex<Option<Vec<SharedLog>>> = Mutex::new(None);

/// Starts a recording: every device made from now on logs what the host does
/// with it, until [`finish`]. A recording already running is discarded.
pub fn start() {
    if let Ok(mut r) = RECORDING.lock() {
        *r = Some(Vec::new());
    }
}

/// A new device's log, when a recording runs.
pub(crate) fn attach() -> Option<SharedLog> {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    let mut r = RECORDING.lock().ok()?;
    let logs = r.as_mut()?;
    let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let log = SharedLog::new(Mutex::new(DeviceLog { id, ..DeviceLog::default() }));
    logs.push(log.clone());
    Some(log)
}

/// Ends the recording: the devices' logs in the order they were made (None
/// when none was running).
pub fn finish() -> Option<Recording> {
    let logs = RECORDING.lock().ok()?.take()?;
    let devices = logs
        .into_iter()
        .map(|l| match Arc::try_unwrap(l) {
            Ok(m) => m.into_inner().unwrap_or_else(|e| e.into_inner()),
            // a device still alive keeps its handle: take what it logged (the
            // recording is over), leaving it an empty log of the same id
            Err(shared) => {
                let mut g = shared.lock().unwrap_or_else(|e| e.into_inner());
                let id = g.id;
                std::mem::replace(&mut *g, DeviceLog { id, ..DeviceLog::default() })
            }
        })
        .collect();
    Some(Recording { devices })
}

/// The logs of a recording's devices.
#[derive(Debug, Default)]
pub struct Recording {
    /// One log a device, in the order the devices were made.
    pub devices: Vec<DeviceLog>,
}

/// `recording.json`'s module entry.
#[derive(Serialize)]
struct ModuleEntry<'a> {
    name: &'a str,
    file: String,
}

/// `recording.json`'s device entry.
#[derive(Serialize)]
struct DeviceEntry<'a> {
    modules: Vec<ModuleEntry<'a>>,
    unreplayable: Option<&'a str>,
    ops: Vec<Op>,
}

/// `recording.json`.
#[derive(Serialize)]
struct Manifest<'a> {
    format: u32,
    what: &'a str,
    devices: Vec<DeviceEntry<'a>>,
}

impl Recording {
    /// Launches over all devices.
    pub fn launches(&self) -> usize {
        self.devices.iter().map(|d| d.ops.iter().filter(|o| matches!(o, Op::Launch { .. })).count()).sum()
    }

    /// The files of the recording, by name, for a folder: `recording.json`
    /// (`what` says what was recorded: the command line), `data.bin` and
    /// `d{D}-m{M}.ptx` for device D's module M. Blobs are offsets into the
    /// one `data.bin`, device after device.
    pub fn files(&self, what: &str) -> Vec<(String, Vec<u8>)> {
        let mut files = Vec::new();
        let mut data = Vec::new();
        let mut devices = Vec::new();
        for (d, log) in self.devices.iter().enumerate() {
            let base = data.len() as u64;
            data.extend_from_slice(&log.data);
            let shift = |b: Blob| Blob { offset: b.offset + base, len: b.len };
            let ops = log
                .ops
                .iter()
                .map(|o| match o.clone() {
                    Op::Write { addr, data } => Op::Write { addr, data: shift(data) },
                    Op::Read { addr, data } => Op::Read { addr, data: shift(data) },
                    Op::Constant { module, name, data } => Op::Constant { module, name, data: shift(data) },
                    other => other,
                })
                .collect();
            let mut modules = Vec::new();
            for (m, module) in log.modules.iter().enumerate() {
                let file = format!("d{d}-m{m}.ptx");
                files.push((file.clone(), module.ptx.clone().into_bytes()));
                modules.push(ModuleEntry { name: &module.name, file });
            }
            devices.push(DeviceEntry { modules, unreplayable: log.unreplayable.as_deref(), ops });
        }
        let manifest = Manifest { format: FORMAT, what, devices };
        let json = serde_json::to_vec_pretty(&manifest).unwrap_or_default();
        files.insert(0, ("recording.json".to_string(), json));
        files.insert(1, ("data.bin".to_string(), data));
        files
    }
}

/// FNV-1a (64-bit) of `bytes`, as 16 hex digits: how the replay's fixtures
/// name a read's bytes.
pub fn fnv1a64(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_known_values() {
        // the FNV-1a reference values
        assert_eq!(fnv1a64(b""), "cbf29ce484222325");
        assert_eq!(fnv1a64(b"a"), "af63dc4c8601ec8c");
        assert_eq!(fnv1a64(b"foobar"), "85944171f73967e8");
    }

    #[test]
    fn constants_logged_when_changed() {
        let mut log = DeviceLog::default();
        let m = log.module("k.ptx", "// ptx", vec![("c".into(), vec![0, 0])]);
        let cfg = LaunchConfig::linear(1, 32);
        log.launch(Some(m), vec![("c".into(), vec![0, 0])], "k", &cfg, &[Arg::U32(1)]);
        log.launch(Some(m), vec![("c".into(), vec![1, 2])], "k", &cfg, &[Arg::F32(1.5)]);
        log.launch(Some(m), vec![("c".into(), vec![1, 2])], "k", &cfg, &[]);
        let kinds: Vec<&str> = log
            .ops()
            .iter()
            .map(|o| match o {
                Op::Constant { .. } => "constant",
                Op::Launch { .. } => "launch",
                _ => "other",
            })
            .collect();
        assert_eq!(kinds, ["launch", "constant", "launch", "launch"]);
        let Op::Constant { data, .. } = log.ops()[1] else { unreachable!() };
        assert_eq!(log.bytes(data), [1, 2]);
        let Op::Launch { ref args, .. } = log.ops()[2] else { unreachable!() };
        assert_eq!(args, &[RecordedArg::F32(1.5f32.to_bits())]);
        assert!(log.unreplayable().is_none());
        log.launch(Some(m), vec![], "k", &cfg, &[Arg::Bytes(vec![7, 0, 0, 0])]);
        let Op::Launch { ref args, .. } = log.ops()[4] else { unreachable!() };
        assert_eq!(args, &[RecordedArg::Bytes(vec![7, 0, 0, 0])], "a scalar given as bytes");
        assert!(log.unreplayable().is_none());
        log.launch(Some(m), vec![], "k", &cfg, &[Arg::Bytes(vec![0; 12])]);
        log.launch(None, vec![], "k", &cfg, &[]);
        assert_eq!(log.unreplayable(), Some("a structure passed by value (it may hold device pointers)"));
    }

    #[test]
    fn finish_takes_the_log_of_a_device_still_alive() {
        // (devices that other tests make meanwhile log too; this one is found by its allocation's name)
        start();
        let mut dev = crate::sim::Device::new();
        let p = dev.alloc_bytes(8, "finish-takes-this-log");
        dev.write(p, &[1u32, 2]).unwrap();
        let rec = finish().expect("a recording ran");
        let mine = rec
            .devices
            .iter()
            .find(|d| d.ops().iter().any(|o| matches!(o, Op::Alloc { name, .. } if name == "finish-takes-this-log")))
            .expect("the live device's log");
        assert!(matches!(mine.ops()[1], Op::Write { data, .. } if mine.bytes(data) == [1, 0, 0, 0, 2, 0, 0, 0]));
        // the device goes on after the recording
        assert_eq!(dev.read::<u32>(p, 2), [1, 2]);
        assert!(finish().is_none(), "no recording runs any more");
    }

    #[test]
    fn files_shift_blobs_device_after_device() {
        let mut a = DeviceLog::default();
        a.write(16, &[1, 2, 3]);
        let mut b = DeviceLog::default();
        b.module("k.ptx", "ptx text", vec![]);
        b.read(32, &[9, 9]);
        let files = Recording { devices: vec![a, b] }.files("test");
        let names: Vec<&str> = files.iter().map(|f| f.0.as_str()).collect();
        assert_eq!(names, ["recording.json", "data.bin", "d1-m0.ptx"]);
        assert_eq!(files[1].1, [1, 2, 3, 9, 9]);
        let json: serde_json::Value = serde_json::from_slice(&files[0].1).unwrap();
        assert_eq!(json["format"], FORMAT);
        assert_eq!(json["devices"][1]["ops"][0]["op"], "read");
        assert_eq!(json["devices"][1]["ops"][0]["data"]["offset"], 3);
        assert_eq!(json["devices"][1]["modules"][0]["file"], "d1-m0.ptx");
    }
}
