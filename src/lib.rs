//! warplight: a CPU SIMT emulator that runs CUDA kernels (compiled to PTX)
//! warp by warp, with hardware-style counters.
//!
//! Layers, top to bottom: [`ptx`] (front end), [`sim`] (execution).
#![warn(missing_docs)]

pub mod ptx;
pub mod sim;
