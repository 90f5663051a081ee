//! Fidelity levels: how much of the machine a launch models beyond the
//! results. Results (memory contents, faults) are the same at every level;
//! lower levels skip counting work nobody will read.
//!
//! | level          | results | core counters (launch totals) | per-instruction counts | memory model (coalescing, sectors, banks) | caches (texture, L1) |
//! |----------------|---------|-------------------------------|------------------------|-------------------------------------------|----------------------|
//! | `functional`   | yes     | yes (they cost nothing measurable) | no                | no                                        | no                   |
//! | `instructions` | yes     | yes                           | yes                    | no                                        | no                   |
//! | `memory`       | yes     | yes                           | yes                    | yes                                       | no (hits, misses 0)  |
//! | `caches`       | yes     | yes                           | yes                    | yes                                       | yes (the full model) |

use std::sync::atomic::{AtomicU8, Ordering};

/// How much a launch models. Ordered: each level includes the ones before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fidelity {
    /// Results only (and the core's launch totals).
    Functional,
    /// + per-instruction counts (instructions, branches, divergence by line).
    Instructions,
    /// + the memory counter model without caches: coalescing, sectors, banks.
    Memory,
    /// + cache simulation (texture, L1): the full model.
    #[default]
    Caches,
}

impl Fidelity {
    /// Every level, lowest first.
    pub const ALL: [Fidelity; 4] = [Fidelity::Functional, Fidelity::Instructions, Fidelity::Memory, Fidelity::Caches];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Functional => "functional",
            Fidelity::Instructions => "instructions",
            Fidelity::Memory => "memory",
            Fidelity::Caches => "caches",
        }
    }

    /// Parses a name (`functional`, `instructions`, `memory`, `caches`).
    pub fn parse(s: &str) -> Option<Fidelity> {
        Fidelity::ALL.into_iter().find(|f| f.name() == s)
    }
}

impl std::fmt::Display for Fidelity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Fidelity {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Fidelity::parse(s)
            .ok_or_else(|| format!("unknown fidelity `{s}`; expected functional, instructions, memory or caches"))
    }
}

static DEFAULT: AtomicU8 = AtomicU8::new(Fidelity::Caches as u8);

/// The level new [`super::SimConfig`]s start with (`caches` unless changed):
/// lets a command (`tables --fidelity`) lower it for every device the code
/// it calls creates.
pub fn default_level() -> Fidelity {
    Fidelity::ALL[DEFAULT.load(Ordering::Relaxed) as usize]
}

/// Sets [`default_level`].
pub fn set_default_level(f: Fidelity) {
    DEFAULT.store(f as u8, Ordering::Relaxed);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_levels_are_ordered() {
        for f in Fidelity::ALL {
            assert_eq!(Fidelity::parse(f.name()), Some(f));
            assert_eq!(f.to_string().parse::<Fidelity>(), Ok(f));
        }
        assert!(Fidelity::Functional < Fidelity::Instructions && Fidelity::Memory < Fidelity::Caches);
        assert!("fast".parse::<Fidelity>().unwrap_err().contains("expected functional"));
    }
}
