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
  warplight chart table fabianowski:4.5 --from a.json -o t45.svg")]
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
    let bar = bar(plan.units(&scenes));
    let t0 = std::time::Instant::now();
    let r = run::execute(&plan, &scenes, &unavailable, crate::repro::COMMIT, &mut |p| {
        if let Some(b) = &bar {
            let frame = p.frame.map(|f| format!(" frame {f}")).unwrap_or_default();
            b.set_message(format!("{} {}{frame} {}", p.scene, p.group, p.variant));
            b.inc(1);
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
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

fn bar(total: u64) -> Option<indicatif::ProgressBar> {
    std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new(total);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} [{elapsed}, eta {eta}]")
                .expect("template"),
        );
        pb
    })
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
