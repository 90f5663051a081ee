//! `warplight launch SPEC.toml`: run kernels described by a spec and print
//! counters — for people, a header per launch and the counters in sections
//! with units ([`report`]); for programs, JSON or CSV — and result buffers
//! ([`print_buffer`]).

pub mod dump;
pub mod print_buffer;
pub mod report;

use std::io::IsTerminal;
use std::path::PathBuf;

use crate::launch_spec::{self, ArgSpec, LaunchResult, Spec};
use crate::model::{InstMem, Profile};
use crate::ptx::Program;
use crate::sim::Device;
use crate::sim::counters::LineCounts;
use crate::sim::device::cap_host_threads;
use crate::teach::{sources, user_lines};

/// Options of `warplight launch`.
#[derive(Debug, clap::Args)]
pub struct LaunchArgs {
    /// The launch spec (TOML): PTX file, kernel, grid, block, buffers, arguments.
    pub spec: PathBuf,
    /// How to run and what to print.
    #[command(flatten)]
    pub options: LaunchOptions,
}

/// How `launch` (and `run`) run a spec and what they print.
#[derive(Debug, Clone, clap::Args)]
pub struct LaunchOptions {
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
    /// Host threads (0 = all cores; at most 4 per core and 1024). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// The watchdog: stop a launch as a runaway after this many warp instructions
    /// (default: the spec's `max_instructions`, else 2^32). See docs/limits.md.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_instructions: Option<u64>,
    /// Device profile for the memory counters: gt200, maxwell or hopper
    /// (default: the spec's `device`, else hopper). See docs/devices.md.
    #[arg(long)]
    pub device: Option<String>,
    /// Also list zero counters and the profiler's names of the counters.
    #[arg(long)]
    pub all: bool,
    /// ptxas's FMA contraction of unrounded mul + add/sub pairs: --fmad=false
    /// rounds every instruction as written (default: the spec's `fmad`, else on
    /// for maxwell and hopper, off for gt200). See docs/semantics.md.
    #[arg(long, value_name = "BOOL")]
    pub fmad: Option<bool>,
    /// After all launches succeed, print buffer NAME's elements (repeatable): NAME (the
    /// first 256), NAME:I, NAME:A..B (B excluded), NAME:A.. or NAME:..B.
    #[arg(long, value_name = "NAME[:RANGE]")]
    pub print: Vec<String>,
    /// List the counter names of the spec's device by section, without running.
    #[arg(long)]
    pub list_metrics: bool,
    /// What to model beyond the results: functional, instructions, memory or
    /// caches (the full model). Results are the same at every level; see docs/performance.md.
    #[arg(long, default_value_t = crate::sim::Fidelity::Caches)]
    pub fidelity: crate::sim::Fidelity,
    /// Checking (`--check`, `--uninit`) and the warp schedule (`--schedule`, `--seed`).
    #[command(flatten)]
    pub checks: crate::check::cli::CheckArgs,
}

type Res = Result<(), Box<dyn std::error::Error>>;

/// Runs the command.
pub fn run(a: LaunchArgs) -> Res {
    // `examples/…` from any directory, as `step`, `trace` and `run` find them
    let spec = Spec::load(&crate::host::scene_file::data_file(&a.spec))?;
    run_spec(spec, &a.options)
}

/// Runs a spec (loaded from a file, or made from `warplight run`'s options).
pub fn run_spec(spec: Spec, a: &LaunchOptions) -> Res {
    let dev_name = a.device.clone().or(spec.device.clone()).unwrap_or_else(|| "hopper".into());
    let profile = Profile::parse(&dev_name)
        .ok_or_else(|| format!("unknown device profile `{dev_name}`; known: gt200, maxwell, hopper"))?;
    let dumps: Vec<(String, PathBuf)> = a
        .dump
        .iter()
        .map(|d| match d.split_once('=') {
            Some((n, f)) if spec.buffers.iter().any(|b| b.name == n) => Ok((n.to_string(), PathBuf::from(f))),
            Some((n, _)) => Err(format!("--dump {d}: the spec has no buffer `{n}`")),
            None => Err(format!("--dump {d}: expected NAME=FILE")),
        })
        .collect::<Result<_, _>>()?;
    dump::check_paths(dumps.iter().map(|(_, f)| f.as_path()))?;
    let prints: Vec<print_buffer::PrintRequest> =
        a.print.iter().map(|p| print_buffer::parse(p, &spec.buffers)).collect::<Result<_, _>>()?;
    if a.csv && !prints.is_empty() {
        return Err("--print writes text or JSON, not CSV: leave out --csv or --print".into());
    }
    let (threads, capped) = cap_host_threads(a.threads);
    if let Some(why) = capped {
        eprintln!("warning: --threads {}: {why}", a.threads);
    }
    let mut config = spec.sim_config(threads, a.max_instructions, profile, a.fmad);
    config.fidelity = a.fidelity;
    a.checks.configure(&mut config)?;
    let mut dev = Device::with_config(config);
    let prepared = launch_spec::prepare(&spec, &mut dev)?;
    let prog = &prepared.module.prog;
    // metric names are known before anything runs: list them, or check --metrics
    let known = report::metric_names(profile, prog);
    if a.list_metrics {
        list_metrics(&known, profile);
        return Ok(());
    }
    report::check_metrics(&a.metrics, &known)?;
    // on a terminal: CTAs retired of the launch's grid, with an ETA (the simulator's progress hook)
    let spinner = std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new(0);
        let style = "{msg} [{bar:30}] {pos}/{len} CTAs [{elapsed}, eta {eta}]";
        pb.set_style(indicatif::ProgressStyle::with_template(style).expect("template"));
        pb.set_message(format!(
            "running {}",
            spec.launches.iter().map(|l| l.kernel.as_str()).collect::<Vec<_>>().join(", ")
        ));
        pb.enable_steady_tick(std::time::Duration::from_millis(200));
        let bar = pb.clone();
        dev.set_progress(Some(std::sync::Arc::new(move |p: &crate::sim::grid::Progress| {
            if p.ctas_retired < bar.position() || p.ctas != bar.length().unwrap_or(0) {
                // the next launch of the spec
                bar.reset();
                bar.set_length(p.ctas);
            }
            bar.set_position(p.ctas_retired);
        })));
        pb
    });
    let tools = a.checks.tools()?;
    let (result, checked) = if tools.any() {
        let r = crate::check::spec::run(&spec, &mut dev, &prepared, profile, &a.checks.options(&prepared)?);
        (r.error.map_or(Ok(r.results), Err), Some(r.reports))
    } else {
        (launch_spec::run(&spec, &mut dev, &prepared, profile), None)
    };
    if let Some(pb) = spinner {
        pb.finish_and_clear();
    }
    // the kernels' printf output comes first, also when a launch faulted (it shows how far it got)
    let printf = dev.take_printf();
    if !a.json || result.is_err() {
        show_printf(&printf, a.csv || a.json);
    }
    if let Some(reports) = checked.as_ref().filter(|_| !a.json || result.is_err()) {
        crate::check::cli::print_reports(reports, spec.launches.len(), tools, a.csv || a.json);
    }
    let stats = result?;
    // Outputs only after every launch succeeded: no partial files.
    let files: Vec<(PathBuf, Vec<u8>)> = dumps
        .iter()
        .map(|(name, file)| {
            let (p, b) = &prepared.buffers[name];
            (file.clone(), dev.read::<u8>(*p, b.len * b.ty.size()))
        })
        .collect();
    dump::write_all(&files)?;
    let printed: Vec<(&print_buffer::PrintRequest, launch_spec::ElemType, Vec<u8>)> = prints
        .iter()
        .map(|r| {
            let (p, b) = &prepared.buffers[&r.name];
            let size = b.ty.size();
            let at = crate::sim::DevicePtr(p.0 + (r.first * size) as u64);
            (r, b.ty, dev.read::<u8>(at, (r.end - r.first) * size))
        })
        .collect();
    if a.json {
        let launches: Vec<serde_json::Value> = stats
            .iter()
            .zip(&spec.launches)
            .map(|(s, l)| {
                let counters: serde_json::Map<String, serde_json::Value> =
                    selected(s, &a.metrics)?.into_iter().map(|(k, v)| (k, v.into())).collect();
                let mut o = serde_json::json!({
                    "kernel": l.kernel, "grid": l.grid, "block": l.block, "device": profile.to_string(),
                    "counters": counters, "occupancy": s.occupancy,
                });
                if a.per_line {
                    o["per_source_line"] = serde_json::to_value(user_lines::per_user_line(&s.stats, prog))?;
                    o["per_ptx_line"] = serde_json::to_value(s.stats.per_ptx_line(prog))?;
                    o["memory_per_ptx_line"] = serde_json::to_value(memory_per_ptx_line(prog, &s.memory.per_inst))?;
                }
                Ok(o)
            })
            .collect::<Result<_, Box<dyn std::error::Error>>>()?;
        let mut out = serde_json::json!({
            "spec": spec.file, "ptx": spec.ptx, "device": profile.params(), "launches": launches,
        });
        if let Some(reports) = &checked {
            out["check"] = crate::check::cli::json(reports);
        }
        if !printf.is_empty() {
            let recs: Vec<serde_json::Value> = printf
                .iter()
                .map(|r| serde_json::json!({ "cta": r.cta, "warp": r.warp, "lane": r.lane, "text": r.text }))
                .collect();
            out["printf"] = recs.into();
        }
        if !printed.is_empty() {
            let bufs: serde_json::Map<String, serde_json::Value> = printed
                .iter()
                .map(|(r, ty, bytes)| {
                    let v = serde_json::json!({ "first": r.first, "values": print_buffer::json(*ty, bytes) });
                    (format!("{}:{}..{}", r.name, r.first, r.end), v)
                })
                .collect();
            out["print"] = bufs.into();
        }
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    if a.csv {
        println!("launch,kernel,metric,value");
        for (i, (s, l)) in stats.iter().zip(&spec.launches).enumerate() {
            for (k, v) in selected(s, &a.metrics)? {
                println!("{i},{},{k},{v}", l.kernel);
            }
            // the cells stay numeric: the registers the PTX declares beside the clamped count, the words on stderr
            let declared = prog.kernel(&l.kernel).map(|k| prog.functions[k as usize].declared_reg_words);
            if a.metrics.is_empty()
                && let Some(d) = declared.filter(|d| *d > s.occupancy.registers_per_thread)
            {
                println!("{i},{},occupancy.registers_declared,{d}", l.kernel);
            }
            if let Some(n) = &s.occupancy.notice {
                eprintln!("note: launch {i} ({}): {n}", l.kernel);
            }
        }
        return Ok(());
    }
    let p = profile.params();
    println!("device {} ({}, compute capability {}, {} SMs)", p.name, p.gpu, p.cc, p.sms);
    println!(
        "{}: {} launch{} of {}",
        tidy(&spec.file),
        spec.launches.len(),
        if spec.launches.len() == 1 { "" } else { "es" },
        tidy(&spec.ptx)
    );
    let n = stats.len();
    for (i, (s, l)) in stats.iter().zip(&spec.launches).enumerate() {
        println!("\n{}", launch_header(i, n, l));
        if a.metrics.is_empty() {
            let (lines, hidden) = report::sections(&s.metrics(), profile, a.all);
            for line in lines {
                println!("{line}");
            }
            let o = &s.occupancy;
            println!(
                "    limited by {}; {} registers/thread (PTX), {} B shared/CTA",
                o.limiter, o.registers_per_thread, o.shared_per_cta
            );
            if let Some(n) = &o.notice {
                println!("    note: {n}");
            }
            if hidden > 0 {
                println!("  ({hidden} zero counters and profiler names not shown: --all shows them)");
            }
        } else {
            for (k, v) in selected(s, &a.metrics)? {
                let unit = report::classify(&k).1;
                println!("  {k:<44} {:>15} {unit}", report::group_digits(v));
            }
        }
        if a.per_line {
            let src = user_lines::per_user_line(&s.stats, prog);
            let by_source = !src.is_empty();
            let lines = if by_source { src } else { s.stats.per_ptx_line(prog) };
            print_lines(&lines, &spec, &memory_by_line(prog, &s.memory.per_inst, by_source));
        }
    }
    for (r, ty, bytes) in &printed {
        println!(
            "\n{}[{}..{}]{}:",
            r.name,
            r.first,
            r.end,
            if r.cut { " (the first 256; NAME:A..B for others)" } else { "" }
        );
        for line in print_buffer::lines(*ty, r.first, bytes) {
            println!("{line}");
        }
    }
    Ok(())
}

/// Prints the kernels' `printf` output (in the order of `crate::sim::printf`:
/// CTA, warp, call, lane) to stdout, or to stderr when stdout carries CSV or
/// JSON, followed by a blank line that separates it from the report.
pub fn show_printf(recs: &[crate::sim::printf::PrintfRecord], to_stderr: bool) {
    if recs.is_empty() {
        return;
    }
    let mut text = crate::sim::printf::text(recs);
    if !text.ends_with('\n') {
        text.push('\n');
    }
    if to_stderr {
        eprint!("{text}");
    } else {
        println!("{text}");
    }
}

/// `p` without `dir/..` pairs (`examples/lessons/../../kernels/x.ptx` is
/// `kernels/x.ptx`), for display.
fn tidy(p: &std::path::Path) -> String {
    use std::path::Component;
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.iter().collect::<PathBuf>().display().to_string()
}

/// `launch 2 of 3: kernel<<<(4,1,1), (256,1,1)>>>(out, in, 1)` with the thread count.
fn launch_header(i: usize, n: usize, l: &launch_spec::LaunchSpec) -> String {
    let dim = |d: [u32; 3]| format!("({},{},{})", d[0], d[1], d[2]);
    let args: Vec<String> = l
        .args
        .iter()
        .map(|a| match a {
            ArgSpec::Buffer(b, 0) => b.clone(),
            ArgSpec::Buffer(b, off) => format!("{b}+{off}"),
            ArgSpec::Int(v) => v.to_string(),
            ArgSpec::Float(v) => v.to_string(),
            ArgSpec::Object(n) => n.clone(),
        })
        .collect();
    let threads: u64 = l.grid.iter().chain(&l.block).map(|&x| x as u64).product();
    let shared = if l.shared > 0 { format!(", {} B dynamic shared", l.shared) } else { String::new() };
    format!(
        "launch {} of {n}: {}<<<{}, {}>>>({})  {} threads{shared}",
        i + 1,
        l.kernel,
        dim(l.grid),
        dim(l.block),
        args.join(", "),
        report::group_digits(threads)
    )
}

/// `--list-metrics`: every counter name by section, with its unit.
fn list_metrics(known: &[String], profile: Profile) {
    let mut by: std::collections::BTreeMap<report::Section, Vec<(&str, &str)>> = Default::default();
    for k in known {
        let (s, unit) = report::classify(k);
        by.entry(s).or_default().push((k, unit));
    }
    println!(
        "counters of a launch on {} (for --metrics; Nsight Compute names of the core counters work on every device)",
        profile.params().name
    );
    for (s, rows) in by {
        println!("\n  {}", s.title(profile));
        for (k, unit) in rows {
            println!("    {k:<60} {unit}");
        }
    }
}

fn selected(s: &LaunchResult, metrics: &[String]) -> Result<Vec<(String, u64)>, String> {
    let all = s.metrics();
    if metrics.is_empty() {
        return Ok(all);
    }
    metrics
        .iter()
        .map(|m| {
            let found = all.iter().find(|(n, _)| n == m).map(|(_, v)| *v).or_else(|| s.stats.totals.get(m));
            found.map(|v| (m.clone(), v)).ok_or_else(|| {
                let names: Vec<String> = all.iter().map(|(n, _)| n.clone()).collect();
                format!("unknown metric `{m}`; known: {}", names.join(", "))
            })
        })
        .collect()
}

/// Memory counts summed per PTX line.
fn memory_per_ptx_line(prog: &Program, per_inst: &[Vec<InstMem>]) -> Vec<(u32, InstMem)> {
    let mut map: std::collections::BTreeMap<u32, InstMem> = Default::default();
    for (f, v) in per_inst.iter().enumerate() {
        for (pc, m) in v.iter().enumerate() {
            if *m == InstMem::default() {
                continue;
            }
            let e = map.entry(prog.functions[f].info[pc].ptx_line).or_default();
            e.requests += m.requests;
            e.sectors += m.sectors;
            e.wavefronts += m.wavefronts;
            e.bank_conflicts += m.bank_conflicts;
        }
    }
    map.into_iter().collect()
}

/// Memory counts per (file, line): the user's CUDA source lines when
/// `by_source` (library code charged to its calling line, as
/// [`user_lines::attribute`] says), else PTX lines.
fn memory_by_line(
    prog: &Program,
    per_inst: &[Vec<InstMem>],
    by_source: bool,
) -> std::collections::HashMap<(String, u32), InstMem> {
    let user = user_lines::attribute(prog);
    let mut map: std::collections::HashMap<(String, u32), InstMem> = Default::default();
    for (f, v) in per_inst.iter().enumerate() {
        for (pc, m) in v.iter().enumerate() {
            let info = &prog.functions[f].info[pc];
            let key = if by_source {
                match user[f][pc] {
                    Some(l) => (prog.files.get(l.file as usize).cloned().unwrap_or_default(), l.line),
                    None => continue,
                }
            } else {
                (prog.source_name.clone(), info.ptx_line)
            };
            let e = map.entry(key).or_default();
            e.requests += m.requests;
            e.sectors += m.sectors;
            e.wavefronts += m.wavefronts;
            e.bank_conflicts += m.bank_conflicts;
        }
    }
    map
}

fn print_lines(lines: &[LineCounts], spec: &Spec, mem: &std::collections::HashMap<(String, u32), InstMem>) {
    println!(
        "\n  {:<26} {:>10} {:>12} {:>8} {:>8} {:>8} {:>8} {:>8}  source",
        "line", "warp inst", "thread inst", "diverged", "requests", "sectors", "wavefr.", "conflict"
    );
    let mut cache: std::collections::HashMap<String, Vec<String>> = Default::default();
    for l in lines {
        let text = cache
            .entry(l.file.clone())
            .or_insert_with(|| sources::read(&spec.ptx, &l.file).unwrap_or_default())
            .get(l.line.saturating_sub(1) as usize)
            .map(|s| s.trim().to_string())
            .unwrap_or_default();
        let text = if l.line == 0 { "(compiler-generated: no source line)".to_string() } else { text };
        let short = l.file.rsplit('/').next().unwrap_or(&l.file);
        let m = mem.get(&(l.file.clone(), l.line)).copied().unwrap_or_default();
        println!(
            "  {:<26} {:>10} {:>12} {:>8} {:>8} {:>8} {:>8} {:>8}  {}",
            format!("{short}:{}", l.line),
            l.counts.warp_instructions,
            l.counts.thread_instructions,
            l.counts.divergent_branches,
            m.requests,
            m.sectors,
            m.wavefronts,
            m.bank_conflicts,
            text
        );
    }
}
