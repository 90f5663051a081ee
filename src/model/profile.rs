//! Device profiles: the GPU generations whose memory systems warplight models.
//! Sources and rules: `docs/devices.md`.

use std::fmt;

use crate::sim::SimConfig;
use crate::sim::sfu::SfuModel;

/// A modelled GPU generation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Profile {
    /// Compute capability 1.3 (GTX 280/285): half-warp segment coalescing, 16 banks, texture cache.
    Gt200,
    /// Compute capability 5.0 (GTX 960M): 32-byte sectors, 32 banks, read-only loads through the texture path.
    Maxwell,
    /// Compute capability 9.0 (H100): requests and 32-byte sectors, 32 banks, global loads cached in L1.
    Hopper,
}

/// Numbers of a profile.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Params {
    /// Name as given on the command line.
    pub name: &'static str,
    /// Compute capability.
    pub cc: &'static str,
    /// The GPU the numbers describe.
    pub gpu: &'static str,
    /// Streaming multiprocessors.
    pub sms: u32,
    /// Threads resident per SM.
    pub max_threads_per_sm: u32,
    /// CTAs resident per SM.
    pub max_ctas_per_sm: u32,
    /// 32-bit registers per SM.
    pub regs_per_sm: u32,
    /// Register allocation granularity (registers per warp are rounded up to this × 32... see docs).
    pub reg_alloc_unit: u32,
    /// Shared memory per SM in bytes.
    pub shared_per_sm: u32,
    /// Shared memory banks.
    pub banks: u32,
    /// L1 data cache per SM for global loads (0 = global loads not cached in L1).
    pub l1_bytes: u64,
    /// Texture / read-only cache in bytes, one per `tex_shared_sms` SMs (0 = none; read-only loads use L1).
    pub tex_bytes: u64,
    /// Its line size in bytes (a multiple of the 32-byte sector).
    pub tex_line: u64,
    /// Its associativity.
    pub tex_ways: usize,
    /// SMs sharing one texture cache: 3 on GT200 (one per texture processor cluster), else 1.
    pub tex_shared_sms: u32,
}

impl Profile {
    /// All profiles.
    pub const ALL: [Profile; 3] = [Profile::Gt200, Profile::Maxwell, Profile::Hopper];

    /// Whether ptxas contracts for a GPU of this profile: sm_50 and later
    /// (maxwell, hopper) have FFMA; GT200's FMAD truncates the product, which
    /// is not modelled, so the gt200 profile executes every instruction as
    /// written. `flag` (`--fmad`, the spec's `fmad`) decides when given.
    pub fn fmad(self, flag: Option<bool>) -> bool {
        flag.unwrap_or(self != Profile::Gt200)
    }

    /// The special-function unit model of this profile's GPU: the H200's
    /// tables for hopper; the maxwell and gt200 profiles (not measured)
    /// compute correctly rounded.
    pub fn sfu(self) -> SfuModel {
        if self == Profile::Hopper { SfuModel::Sm90 } else { SfuModel::CorrectlyRounded }
    }

    /// Sets what of the simulator's arithmetic depends on the device: FMA
    /// contraction ([`Profile::fmad`] of `fmad`) and the SFU model
    /// ([`Profile::sfu`]). Every command that runs a kernel on a profile goes
    /// through here.
    pub fn configure(self, c: &mut SimConfig, fmad: Option<bool>) {
        c.fmad = self.fmad(fmad);
        c.sfu = self.sfu();
    }

    /// Parses `gt200`, `maxwell` or `hopper`.
    pub fn parse(s: &str) -> Option<Profile> {
        match s.to_ascii_lowercase().as_str() {
            "gt200" | "cc13" | "gtx280" => Some(Profile::Gt200),
            "maxwell" | "cc50" | "gtx960m" => Some(Profile::Maxwell),
            "hopper" | "cc90" | "h100" => Some(Profile::Hopper),
            _ => None,
        }
    }

    /// The profile's numbers.
    pub fn params(self) -> Params {
        match self {
            Profile::Gt200 => Params {
                name: "gt200",
                cc: "1.3",
                gpu: "GeForce GTX 280",
                sms: 30,
                max_threads_per_sm: 1024,
                max_ctas_per_sm: 8,
                regs_per_sm: 16384,
                reg_alloc_unit: 512,
                shared_per_sm: 16 * 1024,
                banks: 16,
                l1_bytes: 0,
                tex_bytes: 5 * 1024,
                tex_line: 32,
                tex_ways: 20,
                tex_shared_sms: 3,
            },
            Profile::Maxwell => Params {
                name: "maxwell",
                cc: "5.0",
                gpu: "GeForce GTX 960M",
                sms: 5,
                max_threads_per_sm: 2048,
                max_ctas_per_sm: 32,
                regs_per_sm: 65536,
                reg_alloc_unit: 256,
                shared_per_sm: 64 * 1024,
                banks: 32,
                l1_bytes: 0,
                tex_bytes: 24 * 1024,
                tex_line: 128,
                tex_ways: 4,
                tex_shared_sms: 1,
            },
            Profile::Hopper => Params {
                name: "hopper",
                cc: "9.0",
                gpu: "H100",
                sms: 132,
                max_threads_per_sm: 2048,
                max_ctas_per_sm: 32,
                regs_per_sm: 65536,
                reg_alloc_unit: 256,
                shared_per_sm: 228 * 1024,
                banks: 32,
                l1_bytes: 256 * 1024,
                tex_bytes: 0,
                tex_line: 128,
                tex_ways: 4,
                tex_shared_sms: 1,
            },
        }
    }
}

impl fmt::Display for Profile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.params().name)
    }
}
