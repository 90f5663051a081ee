//! warplight: a CPU SIMT emulator that runs CUDA kernels (compiled to PTX)
//! warp by warp, with hardware-style counters.
//!
//! Layers, bottom to top: [`ptx`] (front end: text to validated IR), [`sim`]
//! (execution and counters), [`launch_spec`] (kernels described in TOML), and
//! [`cli`] (the `warplight` command).
//!
//! Running a kernel from Rust:
//!
//! ```no_run
//! use warplight::sim::{Arg, Device, LaunchConfig};
//! let mut dev = Device::new();
//! let m = dev.load_ptx(&std::fs::read_to_string("kernels/tests/shared.ptx").unwrap(), "shared.ptx").unwrap();
//! let input: Vec<i32> = (0..256).collect();
//! let inb = dev.alloc_from(&input);
//! let out = dev.alloc_zeroed::<i32>(1);
//! let stats = dev.launch(&m, "reduce_sum", LaunchConfig::linear(1, 256), &[Arg::Ptr(out), Arg::Ptr(inb)]).unwrap();
//! assert_eq!(dev.read::<i32>(out, 1)[0], 32640);
//! println!("{} warp instructions", stats.totals.warp_instructions);
//! ```
#![warn(missing_docs)]

pub mod chart;
pub mod check;
pub mod cli;
pub mod compile;
pub mod files;
pub mod host;
pub mod launch_spec;
pub mod limits;
pub mod model;
pub mod ptx;
pub mod repro;
pub mod sim;
pub mod teach;
pub mod timing;
