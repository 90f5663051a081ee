//! How `warplight launch` prints a launch's counters for people: grouped in
//! sections as Nsight Compute groups its metrics, with units, zero counters
//! left out unless asked for; and the names a spec's launch will report,
//! known before it runs (for `--list-metrics` and for checking `--metrics`).

use crate::model::{Model, Profile};
use crate::ptx::Program;
use crate::sim::Counters;

/// A section of the counter listing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Section {
    /// CTAs, warps, scheduling rounds.
    Launch,
    /// Instructions issued, by class.
    Instructions,
    /// Branches, divergence, reconvergence, calls, barriers.
    ControlFlow,
    /// Memory instructions by state space.
    MemoryInstructions,
    /// The device profile's memory model: requests, sectors, transactions, banks, caches.
    MemoryWorkload,
    /// Occupancy under the profile.
    Occupancy,
    /// The same counters under the profiler's own names (Nsight Compute, nvprof, the CUDA profiler).
    ProfilerNames,
}

impl Section {
    /// The section's heading.
    pub fn title(self, profile: Profile) -> String {
        match self {
            Section::Launch => "Launch".into(),
            Section::Instructions => "Instructions".into(),
            Section::ControlFlow => "Control flow".into(),
            Section::MemoryInstructions => "Memory instructions (per state space)".into(),
            Section::MemoryWorkload => format!("Memory workload ({} model)", profile.params().name),
            Section::Occupancy => "Occupancy".into(),
            Section::ProfilerNames => format!("Profiler names ({})", profiler(profile)),
        }
    }
}

/// The profiler whose metric names a profile reports.
fn profiler(profile: Profile) -> &'static str {
    match profile {
        Profile::Gt200 => "CUDA Visual Profiler",
        Profile::Maxwell => "nvprof",
        Profile::Hopper => "Nsight Compute",
    }
}

/// The section and unit of counter `name` (warplight's dotted names; anything
/// else is a profiler's name).
pub fn classify(name: &str) -> (Section, &'static str) {
    let last = name.rsplit('.').next().unwrap_or(name);
    let first = name.split('.').next().unwrap_or(name);
    match first {
        "ctas" => (Section::Launch, "CTAs"),
        "warps" => (Section::Launch, "warps"),
        "rounds" => (Section::Launch, "rounds"),
        "warp_instructions" | "by_class" => (Section::Instructions, "warp inst"),
        "thread_instructions" | "thread_instructions_pred_on" => (Section::Instructions, "thread inst"),
        "branches" | "divergent_branches" => (Section::ControlFlow, "warp inst"),
        "reconvergences" => (Section::ControlFlow, "events"),
        "calls" | "barriers" => (Section::ControlFlow, "warp inst"),
        "barrier_warp_arrivals" => (Section::ControlFlow, "warps"),
        "loads" | "stores" | "atomics" => (Section::MemoryInstructions, "warp inst"),
        "atomic_lane_ops" => (Section::MemoryInstructions, "lane ops"),
        "mem" => (
            Section::MemoryWorkload,
            match last {
                "bytes" => "B",
                "requests" => "requests",
                "sectors" | "hits" | "misses" => "sectors",
                "t32" | "t64" | "t128" => "transactions",
                "wavefronts" => "wavefronts",
                "bank_conflicts" => "conflicts",
                "instructions" | "param" => "warp inst",
                "warp_serialize" => "replays",
                _ => "",
            },
        ),
        "occupancy" => (
            Section::Occupancy,
            match last {
                "registers_per_thread" => "registers",
                "shared_per_cta" => "B",
                "ctas_per_sm" => "CTAs",
                "pct" => "%",
                _ => "",
            },
        ),
        _ => (Section::ProfilerNames, ""),
    }
}

/// Every counter name a launch of `prog` under `profile` reports, in the order
/// [`LaunchResult::metrics`](crate::launch_spec::LaunchResult::metrics) gives
/// them: known before any kernel runs.
pub fn metric_names(profile: Profile, prog: &Program) -> Vec<String> {
    let core = Counters::default();
    let mut v: Vec<String> = core.flatten().into_iter().map(|(n, _)| n).collect();
    v.extend(Model::new(profile, prog).finish().metrics(&core).into_iter().map(|(n, _)| n));
    v.extend(OCCUPANCY.iter().map(|s| s.to_string()));
    v
}

/// The occupancy entries of [`LaunchResult::metrics`](crate::launch_spec::LaunchResult::metrics).
const OCCUPANCY: [&str; 4] =
    ["occupancy.registers_per_thread", "occupancy.shared_per_cta", "occupancy.ctas_per_sm", "occupancy.pct"];

/// Edit distance (insertions, deletions, substitutions) of two names.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// Checks `--metrics` names against `known` (and the Nsight Compute aliases of
/// the core counters): an unknown one is an error naming the nearest known
/// names.
pub fn check_metrics(wanted: &[String], known: &[String]) -> Result<(), String> {
    for m in wanted {
        let alias = crate::sim::counters::NCU_ALIASES.iter().any(|(a, _)| a == m);
        if alias || known.contains(m) {
            continue;
        }
        let mut near: Vec<(usize, &String)> = known.iter().map(|k| (distance(m, k), k)).collect();
        near.sort();
        let limit = (m.len() / 3).max(2);
        let close: Vec<&str> = near.iter().take(3).filter(|(d, _)| *d <= limit).map(|(_, k)| k.as_str()).collect();
        return Err(if close.is_empty() {
            format!("unknown metric `{m}` (warplight launch SPEC --list-metrics lists them)")
        } else {
            format!("unknown metric `{m}`; did you mean {}? (--list-metrics lists them all)", close.join(", "))
        });
    }
    Ok(())
}

/// The listing of `metrics` by section: zero counters and profiler names are
/// left out unless `all`; returns the lines and how many counters were left out.
pub fn sections(metrics: &[(String, u64)], profile: Profile, all: bool) -> (Vec<String>, usize) {
    let mut by: std::collections::BTreeMap<Section, Vec<(&str, u64, &str)>> = Default::default();
    let mut hidden = 0;
    for (name, v) in metrics {
        let (section, unit) = classify(name);
        if !all && (*v == 0 || section == Section::ProfilerNames) {
            hidden += 1;
            continue;
        }
        by.entry(section).or_default().push((name, *v, unit));
    }
    let mut out = Vec::new();
    for (section, rows) in by {
        out.push(format!("  {}", section.title(profile)));
        let w = rows.iter().map(|r| r.0.len()).max().unwrap_or(0).max(36);
        for (name, v, unit) in rows {
            out.push(format!("    {name:<w$} {:>15} {unit}", group_digits(v)).trim_end().to_string());
        }
    }
    (out, hidden)
}

/// `v` with its digits in groups of three (`1,234,567`).
pub fn group_digits(v: u64) -> String {
    let s = v.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_fall_into_sections_with_units() {
        assert_eq!(classify("warp_instructions"), (Section::Instructions, "warp inst"));
        assert_eq!(classify("mem.global_ld.sectors"), (Section::MemoryWorkload, "sectors"));
        assert_eq!(classify("mem.shared_st.bank_conflicts"), (Section::MemoryWorkload, "conflicts"));
        assert_eq!(classify("occupancy.pct"), (Section::Occupancy, "%"));
        assert_eq!(classify("smsp__inst_executed.sum").0, Section::ProfilerNames);
        assert_eq!(group_digits(1234567), "1,234,567");
        assert_eq!(group_digits(999), "999");
    }

    #[test]
    fn unknown_metrics_get_the_nearest_names() {
        let known: Vec<String> = ["warp_instructions", "thread_instructions", "ctas"].map(String::from).to_vec();
        let e = check_metrics(&["warp_instruction".into()], &known).unwrap_err();
        assert!(e.contains("did you mean warp_instructions"), "{e}");
        let e = check_metrics(&["zzzzzzzzzzzz".into()], &known).unwrap_err();
        assert!(e.contains("--list-metrics"), "{e}");
        assert!(check_metrics(&["smsp__inst_executed.sum".into(), "ctas".into()], &known).is_ok());
    }

    #[test]
    fn zero_counters_and_profiler_names_are_hidden_unless_all() {
        let m: Vec<(String, u64)> =
            vec![("ctas".into(), 4), ("calls".into(), 0), ("smsp__inst_executed.sum".into(), 9)];
        let (lines, hidden) = sections(&m, Profile::Hopper, false);
        assert_eq!(hidden, 2);
        assert_eq!(lines.len(), 2, "{lines:?}");
        let (lines, hidden) = sections(&m, Profile::Hopper, true);
        assert_eq!(hidden, 0);
        assert!(lines.iter().any(|l| l.contains("Profiler names (Nsight Compute)")), "{lines:?}");
    }
}
