//! Bounds on what input may make warplight allocate or compute, checked before
//! the work starts: the host-memory budget, CUDA's limits on grids and blocks,
//! and sizes of images and flights. Every bound, its default and what changes
//! it: `docs/limits.md`.

use std::sync::OnceLock;

/// The environment variable that sets the host-memory budget (`8G`, `512MiB`, bytes).
pub const MEMORY_BUDGET_ENV: &str = "WARPLIGHT_MEMORY_BUDGET";

/// The budget when the machine's memory is unknown.
pub const FALLBACK_MEMORY_BUDGET: u64 = 8 << 30;

/// CUDA's largest block per dimension (x, y, z).
pub const MAX_BLOCK_DIM: [u32; 3] = [1024, 1024, 64];

/// CUDA's largest grid per dimension (x, y, z).
pub const MAX_GRID_DIM: [u32; 3] = [(1 << 31) - 1, 65535, 65535];

/// CUDA's most threads per block (all dimensions together).
pub const MAX_THREADS_PER_BLOCK: u64 = 1024;

/// The largest single allocation: a launch spec's buffer or a module's
/// `.global` variable (8 GiB).
pub const MAX_ALLOCATION_BYTES: u64 = 8 << 30;

/// CUDA's constant bank: the `.const` variables of a module (64 KiB).
pub const MAX_CONST_BANK_BYTES: u64 = 64 << 10;

/// The most static `.shared` memory a module may declare: the largest shared
/// memory per CTA of the simulated devices (228 KiB; a launch checks its
/// device's own, `SimConfig::max_shared_per_cta`).
pub const MAX_STATIC_SHARED_BYTES: u64 = 228 << 10;

/// The most `.local` memory a function may declare per thread (2 GiB; a
/// launch checks its device's own, `SimConfig::local_limit`, 64 KiB by default).
pub const MAX_LOCAL_BYTES: u64 = 2 << 30;

/// CUDA's largest parameter area (32 764 bytes since CUDA 12.1 on Volta and
/// later), for kernels and device functions alike.
pub const MAX_PARAM_BYTES: u64 = 32764;

/// The largest image `render` makes, in pixels (16384 × 16384).
pub const MAX_PIXELS: u64 = 16384 * 16384;

/// The most frames a flight may have.
pub const MAX_FLIGHT_FRAMES: u32 = 1_000_000;

/// A bound that input went past, or a budget that could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    /// The work would need more host memory than the budget allows.
    #[error(
        "{what} needs {} of host memory; the budget is {} ({}); raise it with --memory-budget SIZE or {MEMORY_BUDGET_ENV}=SIZE",
        show_bytes(*needed),
        show_bytes(budget.bytes),
        budget.source
    )]
    OverBudget {
        /// What needs it.
        what: String,
        /// Bytes needed.
        needed: u64,
        /// The budget in force.
        budget: Budget,
    },
    /// `WARPLIGHT_MEMORY_BUDGET` is not a size.
    #[error("{MEMORY_BUDGET_ENV}={value}: {msg}")]
    BadEnv {
        /// The variable's value.
        value: String,
        /// What is wrong with it.
        msg: String,
    },
}

/// The host-memory budget and where it came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Budget {
    /// Bytes.
    pub bytes: u64,
    /// Its source.
    pub source: BudgetSource,
}

/// Where the budget came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BudgetSource {
    /// `--memory-budget`.
    Flag,
    /// `WARPLIGHT_MEMORY_BUDGET`.
    Env,
    /// Half of the machine's memory.
    HalfOfMemory,
    /// [`FALLBACK_MEMORY_BUDGET`] (the machine's memory is unknown).
    Fallback,
}

impl std::fmt::Display for BudgetSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BudgetSource::Flag => "--memory-budget",
            BudgetSource::Env => MEMORY_BUDGET_ENV,
            BudgetSource::HalfOfMemory => "the default: half of this machine's memory",
            BudgetSource::Fallback => "the default where the machine's memory is unknown",
        })
    }
}

static FLAG: OnceLock<u64> = OnceLock::new();

/// Sets the budget from `--memory-budget` (once, before any work); it wins
/// over the environment variable.
pub fn set_memory_budget(bytes: u64) {
    let _ = FLAG.set(bytes);
}

/// The machine's memory in bytes (`MemTotal` of `/proc/meminfo`), when known.
fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// The budget in force: `--memory-budget`, else `WARPLIGHT_MEMORY_BUDGET`,
/// else half of the machine's memory ([`FALLBACK_MEMORY_BUDGET`] where unknown).
pub fn memory_budget() -> Result<Budget, LimitError> {
    if let Some(&bytes) = FLAG.get() {
        return Ok(Budget { bytes, source: BudgetSource::Flag });
    }
    if let Some(v) = std::env::var_os(MEMORY_BUDGET_ENV) {
        let value = v.to_string_lossy().into_owned();
        return parse_bytes(&value)
            .map(|bytes| Budget { bytes, source: BudgetSource::Env })
            .map_err(|msg| LimitError::BadEnv { value, msg });
    }
    Ok(match physical_memory() {
        Some(m) => Budget { bytes: m / 2, source: BudgetSource::HalfOfMemory },
        None => Budget { bytes: FALLBACK_MEMORY_BUDGET, source: BudgetSource::Fallback },
    })
}

/// An error unless `needed` bytes fit the budget; `what` names the work.
pub fn check_memory(what: impl FnOnce() -> String, needed: u64) -> Result<(), LimitError> {
    let budget = memory_budget()?;
    if needed > budget.bytes {
        return Err(LimitError::OverBudget { what: what(), needed, budget });
    }
    Ok(())
}

/// Parses a size: bytes (`1000000`), or a number with a unit `K`, `M`, `G`,
/// `T` (powers of 1024; `KiB`, `MB`, `g` … are read the same).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let shift = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => return Err(format!("{s:?}: expected a size such as 4G, 512M or 1000000 (bytes)")),
    };
    let x: f64 = num.parse().map_err(|_| format!("{s:?}: expected a size such as 4G, 512M or 1000000 (bytes)"))?;
    let bytes = x * (1u64 << shift) as f64;
    if !bytes.is_finite() || !(1.0..=u64::MAX as f64).contains(&bytes) {
        return Err(format!("{s:?}: expected a size from 1 byte to 16 EiB"));
    }
    Ok(bytes as u64)
}

/// `n` bytes for a reader: `512 B`, `1.5 KiB`, `4 GiB`, `3.6 TiB`.
pub fn show_bytes(n: u64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut x = n as f64;
    let mut u = 0;
    while x >= 1024.0 && u < UNITS.len() - 1 {
        x /= 1024.0;
        u += 1;
    }
    if u == 0 || x.fract() == 0.0 { format!("{x} {}", UNITS[u]) } else { format!("{x:.1} {}", UNITS[u]) }
}

/// Checks a grid or block against CUDA's limits (`what` is `grid` or `block`);
/// returns the message of the first dimension past them.
pub fn check_dims(what: &str, d: [u32; 3]) -> Result<(), String> {
    let max = if what == "block" { MAX_BLOCK_DIM } else { MAX_GRID_DIM };
    for (i, (&x, &m)) in d.iter().zip(&max).enumerate() {
        if x == 0 {
            return Err("dimensions are positive integers".into());
        }
        if x > m {
            let axis = ["x", "y", "z"][i];
            return Err(format!("{what}.{axis} = {x} is more than CUDA allows ({m})"));
        }
    }
    if what == "block" {
        let threads: u64 = d.iter().map(|&x| x as u64).product();
        if threads > MAX_THREADS_PER_BLOCK {
            return Err(format!("{threads} threads per block is more than CUDA allows ({MAX_THREADS_PER_BLOCK})"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units() {
        assert_eq!(parse_bytes("1000"), Ok(1000));
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("512 MiB"), Ok(512 << 20));
        assert_eq!(parse_bytes("1.5k"), Ok(1536));
        assert_eq!(parse_bytes("2TB"), Ok(2 << 40));
        for bad in ["", "x", "4Q", "-1", "0", "1e400", "99999999999T"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sizes_show_in_binary_units() {
        assert_eq!(show_bytes(512), "512 B");
        assert_eq!(show_bytes(1536), "1.5 KiB");
        assert_eq!(show_bytes(4 << 30), "4 GiB");
        assert_eq!(show_bytes(4_000_000_000_000), "3.6 TiB");
        assert_eq!(show_bytes(u64::MAX), "16384 PiB");
    }

    #[test]
    fn dims_follow_cuda() {
        assert!(check_dims("block", [1024, 1, 1]).is_ok());
        assert!(check_dims("block", [32, 32, 1]).is_ok());
        let e = check_dims("block", [32, 32, 2]).unwrap_err();
        assert_eq!(e, "2048 threads per block is more than CUDA allows (1024)");
        assert!(check_dims("block", [1, 1, 65]).unwrap_err().contains("block.z = 65"));
        // a product that overflows 32 bits is still caught
        assert!(check_dims("block", [1024, 1024, 64]).is_err());
        assert!(check_dims("grid", [(1 << 31) - 1, 65535, 65535]).is_ok());
        assert!(check_dims("grid", [1 << 31, 1, 1]).unwrap_err().contains("grid.x = 2147483648"));
        assert!(check_dims("grid", [1, 65536, 1]).is_err());
        assert!(check_dims("grid", [0, 1, 1]).is_err());
    }
}
