//! The command-line options of the checker and the warp schedule, shared by
//! `launch`, `run`, `step` and `trace`.

use super::{CheckError, CheckOptions, Tools};
use crate::sim::SimConfig;

/// Warp schedules inside a CTA.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ScheduleKind {
    /// Loose round robin, one instruction per warp per turn (the default; `docs/scheduler.md`).
    Lockstep,
    /// Every instruction from a ready warp drawn at random with `--seed` (the same seed, the same run).
    Random,
}

/// `--check`, `--uninit`, `--schedule`, `--seed`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// Check the launch like compute-sanitizer's tools, comma-separated:
    /// memcheck, racecheck, initcheck, synccheck (or all). See docs/checking.md.
    #[arg(long, value_delimiter = ',', value_name = "TOOLS")]
    pub check: Vec<String>,
    /// Buffers to treat as allocated without contents (cudaMalloc without a
    /// copy) for initcheck, comma-separated.
    #[arg(long, value_delimiter = ',', value_name = "NAME")]
    pub uninit: Vec<String>,
    /// The warp schedule inside each CTA: lockstep (default) or random.
    #[arg(long, value_enum, default_value_t = ScheduleKind::Lockstep)]
    pub schedule: ScheduleKind,
    /// The random schedule's seed (with --schedule random).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

impl CheckArgs {
    /// The tools asked for.
    pub fn tools(&self) -> Result<Tools, CheckError> {
        Tools::parse(&self.check)
    }

    /// The random schedule's seed, when `--schedule random`.
    pub fn random_seed(&self) -> Option<u64> {
        (self.schedule == ScheduleKind::Random).then_some(self.seed)
    }

    /// Applies the schedule (and, when checking, at least the `memory`
    /// fidelity, where accesses are observed) to a simulator configuration.
    pub fn configure(&self, c: &mut SimConfig) -> Result<(), CheckError> {
        if let Some(seed) = self.random_seed() {
            c.schedule.random_seed = Some(seed);
        }
        if self.tools()?.any() && c.fidelity < crate::sim::Fidelity::Memory {
            c.fidelity = crate::sim::Fidelity::Memory;
        }
        Ok(())
    }

    /// The checker's options for a spec's buffers: `--uninit` names become
    /// ranges, element types name indices.
    pub fn options(&self, p: &crate::launch_spec::Prepared) -> Result<CheckOptions, CheckError> {
        let mut uninit = Vec::new();
        for n in &self.uninit {
            let (ptr, b) = p.buffers.get(n).ok_or_else(|| CheckError::UnknownBuffer(n.clone()))?;
            uninit.push((ptr.0, (b.len * b.ty.size()) as u64));
        }
        let elem_sizes = p.buffers.iter().map(|(n, (_, b))| (n.clone(), b.ty.size() as u32)).collect();
        Ok(CheckOptions { tools: self.tools()?, uninit, elem_sizes })
    }
}

/// Prints the reports (the launch index first when the spec has several)
/// and a summary line, like compute-sanitizer's, to stdout or stderr.
pub fn print_reports(reports: &[(usize, super::Report)], launches: usize, tools: Tools, to_stderr: bool) {
    let mut text = String::new();
    for (i, r) in reports {
        if launches > 1 {
            text.push_str(&format!("launch {i}: "));
        }
        text.push_str(&r.to_string());
        text.push('\n');
    }
    let names: Vec<&str> = [
        (tools.memcheck, "memcheck"),
        (tools.racecheck, "racecheck"),
        (tools.initcheck, "initcheck"),
        (tools.synccheck, "synccheck"),
    ]
    .iter()
    .filter(|t| t.0)
    .map(|t| t.1)
    .collect();
    let n = reports.len();
    text.push_str(&format!(
        "check ({}): {}\n",
        names.join(", "),
        if n == 0 { "no hazards".to_string() } else { format!("{n} hazard{}", if n == 1 { "" } else { "s" }) }
    ));
    if to_stderr {
        eprint!("{text}");
    } else {
        println!("{text}");
    }
}

/// The reports as JSON (`launch`, then the report's fields).
pub fn json(reports: &[(usize, super::Report)]) -> serde_json::Value {
    reports
        .iter()
        .map(|(i, r)| {
            let mut v = serde_json::to_value(r).unwrap_or_default();
            v["launch"] = (*i).into();
            v
        })
        .collect::<Vec<_>>()
        .into()
}

/// `--check` for `step` and `trace`: runs the spec's launches up to and
/// including `launch` (index) checked, under the schedule asked for (the one
/// the stepped launch runs under too, [`CheckArgs::random_seed`]) on the
/// stepped device `profile`'s arithmetic, and prints the stepped launch's
/// reports to stderr before the view opens.
pub fn check_before_stepping(
    spec: &crate::launch_spec::Spec,
    launch: usize,
    a: &CheckArgs,
    max_instructions: Option<u64>,
    profile: crate::model::Profile,
) -> Result<(), Box<dyn std::error::Error>> {
    let tools = a.tools()?;
    if !tools.any() {
        return Ok(());
    }
    let mut spec = spec.clone();
    spec.launches.truncate(launch + 1);
    let mut config = spec.sim_config(0, max_instructions, profile, None);
    a.configure(&mut config)?;
    let mut dev = crate::sim::Device::with_config(config);
    let p = crate::launch_spec::prepare(&spec, &mut dev)?;
    let r = super::spec::run(&spec, &mut dev, &p, profile, &a.options(&p)?);
    let reports: Vec<(usize, super::Report)> = r.reports.into_iter().filter(|(i, _)| *i == launch).collect();
    print_reports(&reports, 1, tools, true);
    Ok(())
}
