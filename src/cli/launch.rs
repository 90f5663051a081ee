//! `warplight launch SPEC.toml`: run kernels described by a spec and print counters.

use std::io::IsTerminal;
use std::path::PathBuf;

use crate::launch_spec::{self, Spec};
use crate::sim::counters::{LaunchStats, LineCounts};
use crate::sim::{Device, SimConfig};

/// Options of `warplight launch`.
#[derive(Debug, clap::Args)]
pub struct LaunchArgs {
    /// The launch spec (TOML): PTX file, kernel, grid, block, buffers, arguments.
    pub spec: PathBuf,
    /// Print every counter as JSON (stable names) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Print only these counters (warplight names or Nsight Compute aliases such as
    /// smsp__inst_executed.sum), comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub metrics: Vec<String>,
    /// Print the selected counters as CSV (launch, metric, value).
    #[arg(long)]
    pub csv: bool,
    /// After all launches succeed, write buffer NAME's bytes to FILE (repeatable).
    #[arg(long, value_name = "NAME=FILE")]
    pub dump: Vec<String>,
    /// Also print counts per CUDA source line (per PTX line without .loc).
    #[arg(long)]
    pub per_line: bool,
    /// Host threads (0 = all cores). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

type Res = Result<(), Box<dyn std::error::Error>>;

/// Runs the command.
pub fn run(a: LaunchArgs) -> Res {
    let spec = Spec::load(&a.spec)?;
    let dumps: Vec<(String, PathBuf)> = a
        .dump
        .iter()
        .map(|d| match d.split_once('=') {
            Some((n, f)) if spec.buffers.iter().any(|b| b.name == n) => Ok((n.to_string(), PathBuf::from(f))),
            Some((n, _)) => Err(format!("--dump {d}: the spec has no buffer `{n}`")),
            None => Err(format!("--dump {d}: expected NAME=FILE")),
        })
        .collect::<Result<_, _>>()?;
    let mut dev = Device::with_config(SimConfig { threads: a.threads, ..SimConfig::default() });
    let prepared = launch_spec::prepare(&spec, &mut dev)?;
    let spinner = std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new_spinner();
        pb.set_message(format!(
            "running {}",
            spec.launches.iter().map(|l| l.kernel.as_str()).collect::<Vec<_>>().join(", ")
        ));
        pb.enable_steady_tick(std::time::Duration::from_millis(100));
        pb
    });
    let result = launch_spec::run(&spec, &mut dev, &prepared);
    if let Some(pb) = spinner {
        pb.finish_and_clear();
    }
    let stats = result?;
    // Outputs only after every launch succeeded: no partial files.
    for (name, file) in &dumps {
        let (p, b) = &prepared.buffers[name];
        let bytes = dev.read::<u8>(*p, b.len * b.ty.size());
        let tmp = file.with_extension("warplight-tmp");
        std::fs::write(&tmp, &bytes).map_err(|e| format!("{}: {e}", tmp.display()))?;
        std::fs::rename(&tmp, file).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    let prog = &prepared.module.prog;
    if a.json {
        let launches: Vec<serde_json::Value> = stats
            .iter()
            .zip(&spec.launches)
            .map(|(s, l)| {
                let counters: serde_json::Map<String, serde_json::Value> =
                    selected(s, &a.metrics)?.into_iter().map(|(k, v)| (k, v.into())).collect();
                let mut o = serde_json::json!({
                    "kernel": l.kernel, "grid": l.grid, "block": l.block, "counters": counters,
                });
                if a.per_line {
                    o["per_source_line"] = serde_json::to_value(s.per_source_line(prog))?;
                    o["per_ptx_line"] = serde_json::to_value(s.per_ptx_line(prog))?;
                }
                Ok(o)
            })
            .collect::<Result<_, Box<dyn std::error::Error>>>()?;
        let out = serde_json::json!({ "spec": spec.file, "ptx": spec.ptx, "launches": launches });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    if a.csv {
        println!("launch,kernel,metric,value");
        for (i, (s, l)) in stats.iter().zip(&spec.launches).enumerate() {
            for (k, v) in selected(s, &a.metrics)? {
                println!("{i},{},{k},{v}", l.kernel);
            }
        }
        return Ok(());
    }
    for (s, l) in stats.iter().zip(&spec.launches) {
        println!("kernel {}  grid {:?}  block {:?}  ({})", l.kernel, l.grid, l.block, spec.ptx.display());
        for (k, v) in selected(s, &a.metrics)? {
            println!("  {k:<40} {v:>16}");
        }
        if a.per_line {
            let src = s.per_source_line(prog);
            let lines = if src.is_empty() { s.per_ptx_line(prog) } else { src };
            print_lines(&lines, &spec);
        }
    }
    Ok(())
}

fn selected(s: &LaunchStats, metrics: &[String]) -> Result<Vec<(String, u64)>, String> {
    if metrics.is_empty() {
        return Ok(s.totals.flatten());
    }
    metrics
        .iter()
        .map(|m| {
            s.totals.get(m).map(|v| (m.clone(), v)).ok_or_else(|| {
                let names: Vec<String> = s.totals.flatten().into_iter().map(|(n, _)| n).collect();
                format!("unknown metric `{m}`; known: {}", names.join(", "))
            })
        })
        .collect()
}

fn print_lines(lines: &[LineCounts], spec: &Spec) {
    println!("\n  {:<28} {:>12} {:>14} {:>9}  source", "line", "warp inst", "thread inst", "diverged");
    let mut cache: std::collections::HashMap<String, Vec<String>> = Default::default();
    for l in lines {
        let text = cache
            .entry(l.file.clone())
            .or_insert_with(|| {
                let candidates =
                    [PathBuf::from(&l.file), spec.ptx.parent().unwrap_or(std::path::Path::new(".")).join(&l.file)];
                candidates
                    .iter()
                    .find_map(|p| std::fs::read_to_string(p).ok())
                    .map(|s| s.lines().map(|x| x.to_string()).collect())
                    .unwrap_or_default()
            })
            .get(l.line.saturating_sub(1) as usize)
            .map(|s| s.trim().to_string())
            .unwrap_or_default();
        let text = if l.line == 0 { "(compiler-generated: no source line)".to_string() } else { text };
        let short = l.file.rsplit('/').next().unwrap_or(&l.file);
        println!(
            "  {:<28} {:>12} {:>14} {:>9}  {}",
            format!("{short}:{}", l.line),
            l.counts.warp_instructions,
            l.counts.thread_instructions,
            l.counts.divergent_branches,
            text
        );
    }
}
