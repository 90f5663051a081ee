//! `warplight tables`: runs reproductions and prints them beside the theses'
//! tables; `tables merge` prints the tables of shards; `tables --list` lists
//! every table of every thesis. What a table is and how it is measured lives
//! in `crate::repro`; this module only renders.

use std::io::IsTerminal;
use std::path::PathBuf;

use super::scene_info::scene_path;
use crate::host::scene::Scene;
use crate::host::scene_file;
use crate::repro::baseline::Baseline;
use crate::repro::protocol::{FrameRange, Protocol};
use crate::repro::registry::{self, Entry};
use crate::repro::results::Results;
use crate::repro::run::{self, Plan, Unavailable};
use crate::repro::table::{Table, is_part_of};

/// Options of `warplight tables`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  warplight tables --list                          every table of every thesis, with its status
  warplight tables 4.4                             Table 4.4 of thesis 000 (a bare number works while unambiguous)
  warplight tables fabianowski:4.5 fabianowski:4.7 --protocol quick
  warplight tables fabianowski:all --protocol thesis --plan   what the published protocol runs, and how long it takes
  warplight tables fabianowski:all --protocol thesis   the published protocol (hours: the estimate is printed first)
  warplight tables 4.5 --protocol thesis --frames 0..25 --out a.json   one shard ...
  warplight tables 4.5 --protocol thesis --frames 25..50 --out b.json  ... and the other
  warplight tables merge a.json b.json             prints what the unsplit run prints
  warplight chart table fabianowski:4.5 --from a.json -o t45.svg
  warplight render --method purcell --variant error --scene glass-ball --resolution 32x24 -o gb.png
                                                   seed 004's error charts (not a table: see render --help)")]
pub struct TablesArgs {
    /// Tables: `thesis:id` (`fabianowski:4.5`), a bare id while unambiguous (`4.5`),
    /// `thesis:all` or `all`. `merge FILE...` merges result files instead.
    pub tables: Vec<String>,
    /// List every table (of the theses named, e.g. `--list purcell`) with its status and the command that runs it.
    #[arg(long)]
    pub list: bool,
    /// quick (3 frames of each flight at 96x96, minutes) or thesis (the published protocol: 50 frames at 512x512).
    #[arg(long, default_value = "quick")]
    pub protocol: String,
    /// N: the protocol with N frames of each flight; A..B: frames A to B-1 of the protocol (a shard).
    #[arg(long)]
    pub frames: Option<String>,
    /// Image side in pixels (overrides the protocol's).
    #[arg(long)]
    pub resolution: Option<u32>,
    /// Scenes (names in scenes/), comma-separated; default: every scene of the tables.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Builds per heuristic for build timings; the fastest counts.
    #[arg(long, default_value_t = 1)]
    pub repeats: u32,
    /// Output: markdown (the default for tables), table (aligned columns for a terminal;
    /// the default for --list), csv (numeric cells, one header per table) or json (the raw
    /// measurements, as --out writes them). `--list --format markdown`: full captions and notes.
    #[arg(long)]
    pub format: Option<String>,
    /// Write the raw measurements (a shard) to this JSON file; `tables merge` reads them.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Render from a results file (--out or merged) instead of running.
    #[arg(long)]
    pub from: Option<PathBuf>,
    /// merge: accept shards that leave frames of the protocol out.
    #[arg(long)]
    pub partial: bool,
    /// Compare the verdicts with a baseline file; fail when a cell recorded within tolerance is not.
    #[arg(long)]
    pub baseline: Option<PathBuf>,
    /// Write the verdicts as a baseline file.
    #[arg(long)]
    pub write_baseline: Option<PathBuf>,
    /// Print what would run and the time estimate, and stop.
    #[arg(long)]
    pub plan: bool,
    /// Fidelity of the emulated runs: functional, instructions, memory or caches
    /// (default: the lowest level the named tables need; see docs/performance.md).
    #[arg(long)]
    pub fidelity: Option<crate::sim::Fidelity>,
    /// ptxas's FMA contraction in the emulated runs of maxwell and hopper
    /// tables (--fmad=false: every instruction rounded as written); gt200 runs
    /// never contract. See docs/semantics.md.
    #[arg(long, value_name = "BOOL")]
    pub fmad: Option<bool>,
}

/// Runs the command.
pub fn run(a: TablesArgs) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(f) = &a.format
        && !["markdown", "json", "csv", "table"].contains(&f.as_str())
    {
        return Err(format!("--format {f}: expected markdown, table, csv or json").into());
    }
    if a.list {
        let md = a.format.as_deref() == Some("markdown");
        print!("{}", if md { list_markdown(&a.tables)? } else { list(&a.tables)? });
        return Ok(());
    }
    if a.plan {
        let (plan, scenes, unavailable) = plan(&a)?;
        print!("{}", plan.describe(&scenes, &unavailable, rayon::current_num_threads()));
        return Ok(());
    }
    let results = if a.tables.first().is_some_and(|t| t == "merge") {
        let files: Vec<PathBuf> = a.tables[1..].iter().map(PathBuf::from).collect();
        merge(&files, a.partial)?
    } else if let Some(f) = &a.from {
        Results::read(f)?
    } else {
        if a.tables.is_empty() {
            return Err(
                "name tables (`warplight tables 4.5`, `fabianowski:all`) or see `warplight tables --list`".into()
            );
        }
        measure(&a)?
    };
    if let Some(out) = &a.out {
        super::write_atomically(out, serde_json::to_string_pretty(&results)?.as_bytes())?;
        eprintln!("wrote {}", out.display());
    }
    // with --from, the tables named (default: every table of the file)
    let only = if a.from.is_some() && !a.tables.is_empty() { Some(registry::resolve(&a.tables)?) } else { None };
    let mut tables = render(&results)?;
    if let Some(only) = only {
        let keep: Vec<String> = only.iter().map(|e| e.address()).collect();
        tables.retain(|t| keep.iter().any(|k| is_part_of(&t.address, k)));
        if tables.is_empty() {
            return Err(format!(
                "{}: holds no measurements of {}",
                a.from.as_ref().map(|f| f.display().to_string()).unwrap_or_default(),
                keep.join(" ")
            )
            .into());
        }
    }
    if let Some(f) = &a.write_baseline {
        let b = Baseline::record(&results.protocol.describe(), &scene_names(&results), &tables);
        super::write_atomically(f, serde_json::to_string_pretty(&b)?.as_bytes())?;
        eprintln!("wrote {}", f.display());
    }
    print!("{}", format(&results, &tables, a.format.as_deref().unwrap_or("markdown"))?);
    if let Some(f) = &a.baseline {
        check_baseline(f, &results, &tables)?;
    }
    Ok(())
}

fn scene_names(r: &Results) -> Vec<String> {
    r.scenes.iter().map(|s| s.name.clone()).collect()
}

/// The theses named (default: all).
fn named(theses: &[String]) -> Result<Vec<&'static registry::Thesis>, String> {
    for t in theses {
        if !registry::THESES.iter().any(|x| x.short == t || x.dir == t) {
            let names: Vec<&str> = registry::THESES.iter().map(|x| x.short).collect();
            return Err(format!("--list {t}: no such thesis; theses: {}", names.join(", ")));
        }
    }
    Ok(registry::THESES
        .iter()
        .copied()
        .filter(|x| theses.is_empty() || theses.iter().any(|n| n == x.short || n == x.dir))
        .collect())
}

/// The tables of the named theses as markdown: address, status, caption as printed, seed lines, note.
pub fn list_markdown(theses: &[String]) -> Result<String, String> {
    let mut s = String::new();
    for t in named(theses)? {
        s.push_str(&format!("{} (seed {}, `{}`): {}\n\n", t.short, t.seed, t.seed_file, t.citation));
        s.push_str("| table | status | caption as printed | seed lines | note |\n|---|---|---|---|---|\n");
        for table in t.tables {
            let e = Entry { thesis: t, table };
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} |\n",
                e.address(),
                table.status.name(),
                table.title.replace('|', "\\|"),
                table.lines,
                table.note.replace('|', "\\|")
            ));
        }
        s.push('\n');
    }
    Ok(s)
}

/// Every table of the named theses (default: all): status, address, caption and the command.
pub fn list(theses: &[String]) -> Result<String, String> {
    let chosen = named(theses)?;
    let mut s = String::new();
    for &t in &chosen {
        s.push_str(&format!("{} (seed {}, {}; src/repro/{}/): {}\n", t.short, t.seed, t.seed_file, t.dir, t.citation));
        for table in t.tables {
            let e = Entry { thesis: t, table };
            let cmd = if table.render.is_some() { format!("warplight tables {}", e.address()) } else { "–".into() };
            // the line fits 120 columns
            let title: String = table.title.chars().take(42).collect();
            let ell = if table.title.chars().count() > 42 { "…" } else { "" };
            s.push_str(&format!("  {:<16} {:<18} {:<38} {title}{ell}\n", e.address(), table.status.name(), cmd));
        }
        s.push('\n');
    }
    let all = registry::entries_of(&chosen);
    let count = |st: registry::Status| all.iter().filter(|e| e.table.status == st).count();
    s.push_str(&format!(
        "{} tables: {} reproduced, {} modelled, {} partly, {} missing, {} not reproducible, {} not measurements.\n",
        all.len(),
        count(registry::Status::Reproduced),
        count(registry::Status::Modelled),
        count(registry::Status::Partly),
        count(registry::Status::Missing),
        count(registry::Status::NotReproducible),
        count(registry::Status::NotAMeasurement),
    ));
    Ok(s)
}

fn protocol_of(a: &TablesArgs) -> Result<(Protocol, Option<FrameRange>), String> {
    let base = Protocol::named(&a.protocol)?;
    let (n, range) = match a.frames.as_deref() {
        None => (None, None),
        Some(f) if f.contains("..") => (None, Some(FrameRange::parse(f)?)),
        Some(f) => {
            let n: u32 = f.parse().map_err(|_| format!("--frames {f}: expected N or A..B"))?;
            if n == 0 {
                return Err("--frames 0: run at least one frame".into());
            }
            (Some(n), None)
        }
    };
    if a.resolution == Some(0) {
        return Err("--resolution 0: the image needs at least one pixel".into());
    }
    let p = base.with(n, a.resolution);
    if let Some(r) = range
        && r.start >= p.frames
    {
        return Err(format!("--frames {r}: the protocol has {} frames (0..{})", p.frames, p.frames));
    }
    Ok((p, range))
}

/// A plan with the scenes it could load and those it could not.
type Planned = (Plan, Vec<Scene>, Vec<Unavailable>);

/// The plan of a run with its scenes loaded.
fn plan(a: &TablesArgs) -> Result<Planned, Box<dyn std::error::Error>> {
    let entries = registry::resolve(&a.tables)?;
    let (protocol, frames) = protocol_of(a)?;
    let plan = Plan::new(entries, &a.scenes, protocol, frames, a.repeats);
    let (scenes, unavailable) = load(&plan.scenes());
    if scenes.is_empty() {
        let why: Vec<String> = unavailable.iter().map(|u| u.why.clone()).collect();
        return Err(format!("no scene of these tables could be loaded: {}", why.join("; ")).into());
    }
    Ok((plan, scenes, unavailable))
}

fn measure(a: &TablesArgs) -> Result<Results, Box<dyn std::error::Error>> {
    let needed = registry::resolve(&a.tables)?.iter().map(registry::lowest_fidelity).max();
    crate::sim::fidelity::set_default_level(a.fidelity.or(needed).unwrap_or_default());
    crate::sim::contract::set_default(a.fmad.unwrap_or(true));
    let (plan, scenes, unavailable) = plan(a)?;
    let threads = rayon::current_num_threads();
    eprint!("{}", plan.describe(&scenes, &unavailable, threads));
    let progress = UnitProgress::new(plan.units(&scenes), plan.protocol.resolution);
    let t0 = std::time::Instant::now();
    let r = run::execute(&plan, &scenes, &unavailable, crate::repro::COMMIT, &mut |p| {
        if let Some(u) = &progress {
            let frame = p.frame.map(|f| format!(" frame {f}")).unwrap_or_default();
            u.unit_done(format!("{} {}{frame} {}", p.scene, p.group, p.variant));
        }
    });
    if let Some(u) = progress {
        u.finish();
    }
    eprintln!("  took {}", run::human(t0.elapsed().as_secs_f64()));
    Ok(r?)
}

fn load(names: &[String]) -> (Vec<Scene>, Vec<Unavailable>) {
    let (mut ok, mut missing) = (Vec::new(), Vec::new());
    for n in names {
        match scene_file::load(&scene_path(n)) {
            Ok(s) => ok.push(s),
            Err(e) => missing.push(Unavailable { name: n.clone(), why: e.to_string() }),
        }
    }
    (ok, missing)
}

/// The run's progress on a terminal: a bar over its units (a frame of a
/// variant, or a variant), moved inside a unit by the emulator's progress
/// hook (the share of the kernels' pixels claimed, else of their CTAs
/// retired), with an ETA.
struct UnitProgress {
    bar: indicatif::ProgressBar,
    units: u64,
    /// Each launch in flight (by its device memory's address): the share of it done.
    running: std::sync::Arc<std::sync::Mutex<std::collections::BTreeMap<usize, f64>>>,
    done: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

/// Steps of the bar per unit.
const STEPS: u64 = 1000;

impl UnitProgress {
    /// On a terminal only: `units` units whose ray-casting kernels shade `side`² pixels each.
    fn new(units: u64, side: u32) -> Option<UnitProgress> {
        if !std::io::stderr().is_terminal() {
            return None;
        }
        let bar = indicatif::ProgressBar::new(units * STEPS);
        let style = "{bar:30} {percent:>3}% {msg} [{elapsed}, eta {eta}]";
        bar.set_style(indicatif::ProgressStyle::with_template(style).ok()?);
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        Some(UnitProgress::with_bar(units, side, bar))
    }

    /// The progress on `bar` (of `units` × [`STEPS`]); the hook of every device made until [`UnitProgress::finish`].
    fn with_bar(units: u64, side: u32, bar: indicatif::ProgressBar) -> UnitProgress {
        use std::sync::atomic::Ordering;
        bar.set_message(format!("0/{units} runs"));
        let u = UnitProgress { bar, units, running: Default::default(), done: Default::default() };
        let (bar, running, done) = (u.bar.clone(), u.running.clone(), u.done.clone());
        let pixels = side as u64 * side as u64;
        let hook = move |p: &crate::sim::grid::Progress| {
            let queue = p.memory.allocations().iter().find(|a| a.name == crate::host::rt_kernels::JOB_QUEUE);
            let share = match queue {
                Some(q) if pixels > 0 => q.load(0, 4).min(pixels) as f64 / pixels as f64,
                _ => p.ctas_retired as f64 / p.ctas.max(1) as f64,
            };
            let Ok(mut r) = running.lock() else { return };
            let key = p.memory as *const _ as usize;
            if share >= 1.0 {
                r.remove(&key);
            } else {
                r.insert(key, share);
            }
            let within = (r.values().sum::<f64>() * STEPS as f64) as u64;
            let at = (done.load(Ordering::Relaxed) * STEPS + within).min((units * STEPS).saturating_sub(1));
            if at > bar.position() {
                bar.set_position(at);
            }
        };
        crate::sim::device::set_default_progress(Some(std::sync::Arc::new(hook)));
        u
    }

    /// A unit finished: `what` it was.
    fn unit_done(&self, what: String) {
        let n = self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if let Ok(mut r) = self.running.lock() {
            r.clear();
        }
        self.bar.set_position((n * STEPS).max(self.bar.position()));
        self.bar.set_message(format!("{n}/{} runs, last {what}", self.units));
    }

    fn finish(self) {
        crate::sim::device::set_default_progress(None);
        self.bar.finish_and_clear();
    }
}

fn merge(files: &[PathBuf], partial: bool) -> Result<Results, Box<dyn std::error::Error>> {
    let mut shards = Vec::new();
    for f in files {
        shards.push((f.display().to_string(), Results::read(f)?));
    }
    Ok(Results::merge(&shards, partial)?)
}

/// The tables of a result.
pub fn render(r: &Results) -> Result<Vec<Table>, Box<dyn std::error::Error>> {
    let entries = registry::resolve(&r.tables)?;
    let mut out = Vec::new();
    for e in entries {
        if let Some(render) = e.table.render {
            out.extend(render(&e, r));
        }
    }
    Ok(out)
}

fn format(r: &Results, tables: &[Table], format: &str) -> Result<String, Box<dyn std::error::Error>> {
    let mut s = String::new();
    match format {
        "json" => {
            s.push_str(&serde_json::to_string_pretty(r)?);
            s.push('\n');
        }
        "csv" => {
            for (i, t) in tables.iter().enumerate() {
                if i > 0 {
                    s.push('\n');
                }
                s.push_str(&t.csv(true));
            }
        }
        _ => {
            let mut md = String::new();
            for t in tables {
                md.push_str(&t.markdown());
                md.push('\n');
            }
            if tables.len() > 1 {
                let (w, n) = tables.iter().map(Table::score).fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
                md.push_str(&format!("Overall: {w}/{n} compared cells within tolerance.\n"));
            }
            for u in &r.unavailable {
                md.push_str(&format!("Unavailable: {u}\n"));
            }
            s.push_str(&if format == "table" {
                super::table_format::terminal(&md, super::table_format::WIDTH)
            } else {
                md
            });
        }
    }
    Ok(s)
}

fn check_baseline(f: &std::path::Path, r: &Results, tables: &[Table]) -> Result<(), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
    let b: Baseline = serde_json::from_str(&text).map_err(|e| format!("{}: not a baseline file ({e})", f.display()))?;
    if b.protocol != r.protocol.describe() || b.scenes != scene_names(r) {
        return Err(format!(
            "{}: recorded under {} on {}, this run is {} on {}",
            f.display(),
            b.protocol,
            b.scenes.join(","),
            r.protocol.describe(),
            scene_names(r).join(",")
        )
        .into());
    }
    let (worse, better) = b.compare(tables);
    for x in &better {
        eprintln!("improved: {x}");
    }
    if !worse.is_empty() {
        return Err(format!("{} cell(s) dropped out of tolerance:\n  {}", worse.len(), worse.join("\n  ")).into());
    }
    eprintln!("baseline {}: no cell dropped out of tolerance", f.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Devices made while the progress is on move its bar within the unit:
    /// 480 CTAs, 240 resident at a time, half of them retired after the first round.
    #[test]
    fn the_emulators_hook_moves_the_bar_within_a_unit() {
        let u = UnitProgress::with_bar(2, 0, indicatif::ProgressBar::hidden());
        u.bar.set_length(2 * STEPS);
        let ptx = ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{\n ret;\n}\n";
        let mut dev = crate::sim::Device::new();
        let m = dev.load_ptx(ptx, "k.ptx").unwrap();
        dev.launch(&m, "k", crate::sim::LaunchConfig::linear(480, 32), &[]).unwrap();
        // other tests' devices, made in this process while the hook is set, may move it further
        assert!((STEPS / 2..2 * STEPS).contains(&u.bar.position()), "{}", u.bar.position());
        u.unit_done("one".into());
        assert!(u.bar.position() >= STEPS);
        assert_eq!(u.bar.message(), "1/2 runs, last one");
        u.finish();
    }
}
