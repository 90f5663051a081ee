//! `warplight chart`: charts of reproduced tables (ours beside the thesis, with
//! the tolerance band), of per-frame counters along a flight, and generic
//! speed-against-accuracy scatter plots, as SVG or PNG. What a chart is and how
//! it is drawn lives in `crate::chart`; this module turns tables, results files
//! and JSON into charts.

use std::path::{Path, PathBuf};

mod lin;

use crate::chart::{BarSeries, Bars, Chart, Format, Lines, Scatter, Series};
use crate::repro::compare::Tolerance;
use crate::repro::results::Results;
use crate::repro::table::{RowKind, Table, Unit, is_part_of};

/// Options of `warplight chart`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  warplight tables 4.5 --out r.json                                  measure first (raw results)
  warplight chart table fabianowski:4.5 --from r.json -o t45.svg     ours vs thesis with tolerance bands
  warplight chart table 4.5 --from r.json --columns abs -o t45a.png  the absolute columns, as PNG
  warplight chart table all --from r.json -o chart-{}.svg            one chart per table ({} = table id)
  warplight chart flight --from r.json --scene sponza --counter inner_nodes --per-ray -o f.svg
  warplight chart scatter tests/fixtures/scatter.json -o speed.svg   speed vs accuracy from JSON
  warplight chart lin-convergence --scene cornell-rough -o c-{}.svg  thesis 003: error vs spp and time
  warplight chart lin-compaction -o lanes-{}.svg                     thesis 003: Figs. 16/17 per level
  warplight chart lin-pixel-sampling -o px-{}.svg                    thesis 003: strata (rows, progressive) vs tent

The format follows the output's extension: .svg or .png.")]
pub struct ChartArgs {
    /// What to chart.
    #[command(subcommand)]
    pub what: ChartCommand,
}

/// `warplight chart ...`
#[derive(Debug, clap::Subcommand)]
pub enum ChartCommand {
    /// Ours beside the thesis per table, with the tolerance bands.
    ///
    /// Grouped bars: one group per compared cell of a scene row ("scene /
    /// column"), ours and the thesis' value side by side, and behind them a
    /// grey band: the values within the column's tolerance of the thesis'
    /// (ours is within tolerance exactly when its bar ends inside the band).
    /// Tables with nothing to chart are skipped with a note.
    Table(TableArgs),
    /// A counter frame by frame along a scene's flight, a line per variant.
    ///
    /// The counter of each variant of a measurement group on one scene, frame
    /// by frame, from a results file; `--per-ray` divides by the frame's rays.
    Flight(FlightArgs),
    /// A scatter plot from JSON, such as speed against accuracy.
    ///
    /// x: seconds or samples, y: error, one series per method; either axis
    /// may be logarithmic.
    #[command(after_help = "\
The JSON:
  {\"title\": \"Error against time\", \"x_label\": \"seconds\", \"y_label\": \"RMSE\",
   \"log_x\": false, \"log_y\": true, \"connect\": true,
   \"series\": [{\"name\": \"method A\", \"points\": [[0.5, 0.1], [1.0, 0.05]]}]}
log_x, log_y (logarithmic axes) and connect (join each series' points in order) are optional.")]
    Scatter(ScatterArgs),
    /// Thesis 003's volume march (§5.2): variance against step count, Pauly's
    /// stratified offset (one a ray) against a random point in each step.
    ///
    /// Renders the medium scene natively (nee) with each pattern at each step
    /// count (steps across the medium box's diagonal) and plots a pixel's
    /// variance over frames, averaged over the pixels, log-log (003:L367:
    /// the stratified pattern "can be shown to have a lower variance").
    #[command(after_help = "\
Example:
  warplight chart media --scene smog-room --size 16 --frames 64 -o march.svg")]
    Media(MediaArgs),
    /// Thesis 003: error against the Mitsuba reference vs samples and vs time,
    /// log-log, per integrator (pt, nee, mis, mis-power, bdpt, mlt).
    ///
    /// Renders the scene natively at the reference's size (points at 1, 2, 4,
    /// ... frames; host seconds measured in the same run) and a few frames on
    /// the emulator (warp instructions counted, a GPU-time proxy; each checked
    /// equal to the native render bit for bit). Charts: RMS error vs spp, vs
    /// native seconds, vs emulated warp instructions, and the mean luminance's
    /// relative error vs spp, each with the reference's own noise.
    #[command(
        name = "lin-convergence",
        after_help = "\
Example:
  warplight chart lin-convergence --scene cornell-rough --frames 1024 -o docs/images/lin-convergence-cornell-rough-{}.svg
  Russian roulette against a fixed depth (003:L269):
  warplight chart lin-convergence --scene cornell-lambert --integrators pt,nee --termination roulette,fixed-depth \\
      --emulated-frames 1,2,4,8,16 -o docs/images/lin-roulette-cornell-lambert-{}.svg
  warplight chart lin-convergence --from docs/images/lin-convergence-cornell-rough-data.json -o c-{}.png"
    )]
    LinConvergence(lin::ConvergenceArgs),
    /// Thesis 003 Figs. 16/17 proxies: useful SIMT lanes and active paths per
    /// level, with and without thread compaction, counted by the emulator.
    #[command(
        name = "lin-compaction",
        after_help = "\
Example:
  warplight chart lin-compaction --size 32 --depth 30 -o docs/images/lin-compaction-{}.svg"
    )]
    LinCompaction(lin::CompactionArgs),
    /// Thesis 003 §4.2: stratified pixels (D x D strata of each subpixel,
    /// frame f in stratum f mod D² row by row, or in the progressive order
    /// whose every 4^j frames stratify a 2^j x 2^j grid; the kernel's
    /// stratified build) against the thesis' tent filter, RMS error vs spp
    /// and vs time, log-log.
    ///
    /// Each sampling is measured against its own long native render (other
    /// random numbers, whole rounds of D² frames; its noise, from the spread
    /// of its rounds, taken out), since the filters converge to different
    /// images. Also charted: the points at exactly D² frames (one sample a
    /// stratum, the regime of the O(1/n) claim, 003:L223). One frame of
    /// each build is emulated (warp instructions, checked equal to the native twin).
    #[command(
        name = "lin-pixel-sampling",
        after_help = "\
Examples:
  the pixel integral alone (0 bounces, lit by the environment map):
  warplight chart lin-pixel-sampling --scene env-spheres --integrator pt --bounces 0 -o docs/images/lin-pixels-env-spheres-{}.svg
  the Cornell box at 16 bounces, where the path's other dimensions dominate:
  warplight chart lin-pixel-sampling --scene cornell-lambert -o docs/images/lin-pixels-cornell-lambert-{}.svg
  warplight chart lin-pixel-sampling --from docs/images/lin-pixels-env-spheres-data.json -o p-{}.png"
    )]
    LinPixelSampling(lin::PixelSamplingArgs),
}

/// Options of `warplight chart media`.
#[derive(Debug, clap::Args)]
pub struct MediaArgs {
    /// A scene with a `[medium]` (scenes/ name or path).
    #[arg(long, default_value = "smog-room")]
    pub scene: String,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 16)]
    pub size: u32,
    /// Frames (4 paths a pixel each) per measurement.
    #[arg(long, default_value_t = 64)]
    pub frames: u32,
    /// The longest path in bounces (1: the camera ray's march and direct light only).
    #[arg(long, default_value_t = 1)]
    pub bounces: u32,
    /// Step counts across the medium box's diagonal, comma-separated (1 to 1023, the kernel's march).
    #[arg(long, default_value = "2,4,8,16,32,64", value_delimiter = ',')]
    pub steps: Vec<u32>,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// Output .svg or .png.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Size in pixels, WIDTHxHEIGHT (default 960x540).
    #[arg(long)]
    pub chart_size: Option<String>,
}

/// Which columns of a table to chart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Columns {
    /// The relative columns (changes in %, percentage points) when the table
    /// compares any, else the absolute ones.
    Auto,
    /// Relative changes (%) and differences in percentage points.
    Rel,
    /// Absolute quantities (counts, numbers, percentages).
    Abs,
}

/// Options of `warplight chart table`.
#[derive(Debug, clap::Args)]
pub struct TableArgs {
    /// Tables: `fabianowski:4.5`, a bare id (`4.5`; `4.8` takes its parts 4.8a, 4.8b),
    /// `fabianowski:all` or `all`: among the tables of the results file.
    #[arg(required = true)]
    pub tables: Vec<String>,
    /// The results file (`warplight tables ... --out FILE`, or merged shards).
    #[arg(long)]
    pub from: PathBuf,
    /// Columns to chart. Relative and absolute columns have different scales, so
    /// one chart shows one kind: auto takes the relative ones (changes in %,
    /// percentage points) when the table compares any, else the absolute ones.
    #[arg(long, value_enum, default_value = "auto")]
    pub columns: Columns,
    /// Output .svg or .png; with several tables, `{}` in the name stands for
    /// each table's id (`chart-{}.svg` gives chart-4.5.svg).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Size in pixels, WIDTHxHEIGHT (default: 960x540, wider for many groups).
    #[arg(long)]
    pub size: Option<String>,
}

/// Options of `warplight chart flight`.
#[derive(Debug, clap::Args)]
pub struct FlightArgs {
    /// The results file (`warplight tables ... --out FILE`).
    #[arg(long)]
    pub from: PathBuf,
    /// Measurement group (`fabianowski/traversal`); default: the file's only group with frames.
    #[arg(long)]
    pub group: Option<String>,
    /// Scene; default: the file's only scene.
    #[arg(long)]
    pub scene: Option<String>,
    /// Counter (`inner_nodes`, `warp_instructions`, ...); an unknown name lists those measured.
    #[arg(long)]
    pub counter: String,
    /// Divide by the `rays` counter of the same frame and variant.
    #[arg(long)]
    pub per_ray: bool,
    /// Output .svg or .png.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Size in pixels, WIDTHxHEIGHT (default 960x540).
    #[arg(long)]
    pub size: Option<String>,
}

/// Options of `warplight chart scatter`.
#[derive(Debug, clap::Args)]
pub struct ScatterArgs {
    /// The chart as JSON (see below).
    pub data: PathBuf,
    /// Output .svg or .png.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Size in pixels, WIDTHxHEIGHT (default 960x540).
    #[arg(long)]
    pub size: Option<String>,
}

/// Runs the command.
pub fn run(a: ChartArgs) -> Result<(), Box<dyn std::error::Error>> {
    match a.what {
        ChartCommand::Table(t) => table(t),
        ChartCommand::Flight(f) => flight(f),
        ChartCommand::Scatter(s) => scatter(s),
        ChartCommand::Media(m) => media(m),
        ChartCommand::LinConvergence(c) => lin::lin_convergence(c),
        ChartCommand::LinCompaction(c) => lin::lin_compaction(c),
        ChartCommand::LinPixelSampling(c) => lin::lin_pixel_sampling(c),
    }
}

fn media(a: MediaArgs) -> Result<(), Box<dyn std::error::Error>> {
    use crate::host::scene::Jitter;
    let size = parse_size(a.chart_size.as_deref())?;
    Format::of(&a.output)?;
    if a.steps.is_empty() || a.steps.contains(&0) || a.size == 0 {
        return Err("--steps: expected positive step counts; --size: positive".into());
    }
    let scene = crate::host::scene_file::load(&crate::host::scene_file::resolve(&a.scene))?;
    let v = crate::repro::lin2017::media::march_variance(&scene, a.size, a.frames, a.bounces, &a.steps, a.seed)?;
    let series =
        [(Jitter::Stratified, "stratified: one offset a ray (Pauly)"), (Jitter::PerStep, "random point in each step")]
            .into_iter()
            .map(|(j, name)| Series {
                name: name.into(),
                points: v.iter().filter(|m| m.jitter == j).map(|m| (m.steps as f64, m.variance)).collect(),
            })
            .collect();
    for m in &v {
        println!("{:?} steps {}: variance {:.6e}, mean {:.6}", m.jitter, m.steps, m.variance, m.mean);
    }
    let chart = Scatter {
        title: format!(
            "{}: variance vs march steps ({}x{}, {} frames, nee, {} bounce(s); measured)",
            scene.name, a.size, a.size, a.frames, a.bounces
        ),
        x_label: "steps across the medium's box".into(),
        y_label: "pixel variance over frames".into(),
        log_x: true,
        log_y: true,
        connect: true,
        series,
    };
    write(&Chart::Scatter(chart), &a.output, size)
}

fn parse_size(s: Option<&str>) -> Result<Option<(u32, u32)>, String> {
    let Some(s) = s else { return Ok(None) };
    s.split_once('x')
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)))
        .map(Some)
        .ok_or_else(|| format!("--size {s}: expected WIDTHxHEIGHT, e.g. 1200x600"))
}

/// Draws `chart` into `out` (format by extension), atomically; errors name the file.
fn write(chart: &Chart, out: &Path, size: Option<(u32, u32)>) -> Result<(), Box<dyn std::error::Error>> {
    let format = Format::of(out)?;
    let bytes = chart
        .render(format, size.unwrap_or_else(|| chart.default_size()))
        .map_err(|e| format!("{}: {e}", out.display()))?;
    super::write_atomically(out, &bytes)?;
    eprintln!("wrote {}", out.display());
    Ok(())
}

fn table(a: TableArgs) -> Result<(), Box<dyn std::error::Error>> {
    let size = parse_size(a.size.as_deref())?;
    let out = a.output.display().to_string();
    Format::of(&a.output)?;
    let results = Results::read(&a.from)?;
    let tables = super::tables::render(&results)?;
    let mut chosen: Vec<&Table> = Vec::new();
    for want in &a.tables {
        let found: Vec<&Table> = tables.iter().filter(|t| address_matches(want, &t.address)).collect();
        if found.is_empty() {
            let have: Vec<&str> = tables.iter().map(|t| t.address.as_str()).collect();
            return Err(format!(
                "{want}: not among the tables of {} ({})",
                a.from.display(),
                if have.is_empty() { "none".into() } else { have.join(", ") }
            )
            .into());
        }
        for t in found {
            if !chosen.iter().any(|c| c.address == t.address) {
                chosen.push(t);
            }
        }
    }
    if chosen.len() > 1 && !out.contains("{}") {
        return Err(format!(
            "-o {out}: {} tables match ({}); put {{}} in the name for each table's id, e.g. chart-{{}}.svg",
            chosen.len(),
            chosen.iter().map(|t| t.address.as_str()).collect::<Vec<_>>().join(", ")
        )
        .into());
    }
    let subtitle = format!("protocol {}; warplight {}", results.protocol.describe(), results.commit);
    let mut empty = Vec::new();
    for t in &chosen {
        let id = t.address.split_once(':').map_or(t.address.as_str(), |(_, id)| id);
        let path = PathBuf::from(out.replace("{}", id));
        match table_bars(t, a.columns, &subtitle) {
            Some(bars) => write(&Chart::Bars(bars), &path, size)?,
            None => empty.push(format!("{}: no compared {} cells to chart", t.address, kind_name(t, a.columns))),
        }
    }
    if empty.len() == chosen.len() {
        return Err(empty.join("; ").into());
    }
    for e in empty {
        eprintln!("skipped {e}");
    }
    Ok(())
}

/// Whether the address `want` (`fabianowski:4.5`, `4.5`, `4.8` for parts, `all`, `fabianowski:all`) names `table`.
pub fn address_matches(want: &str, table: &str) -> bool {
    let (thesis, id) = table.split_once(':').unwrap_or(("", table));
    let (w_thesis, w_id) = match want.split_once(':') {
        Some((t, i)) => (Some(t), i),
        None => (None, want),
    };
    if w_thesis.is_some_and(|t| t != thesis) {
        return false;
    }
    w_id == "all" || is_part_of(id, w_id)
}

fn relative(u: Unit) -> bool {
    matches!(u, Unit::Change | Unit::Points)
}

/// The columns `columns` picks in `t`: compared ones (with a tolerance) of the chosen kind.
fn picked(t: &Table, columns: Columns) -> Vec<usize> {
    let of = |rel: bool| -> Vec<usize> {
        t.columns
            .iter()
            .enumerate()
            .filter(|(_, c)| c.tolerance.is_some() && c.has_thesis && relative(c.unit) == rel)
            .map(|(i, _)| i)
            .collect()
    };
    match columns {
        Columns::Rel => of(true),
        Columns::Abs => of(false),
        Columns::Auto => {
            let rel = of(true);
            if rel
                .iter()
                .any(|&i| scene_rows(t).any(|r| r.cells[i].ours.is_some() || r.cells[i].thesis_value.is_some()))
            {
                rel
            } else {
                of(false)
            }
        }
    }
}

fn kind_name(t: &Table, columns: Columns) -> &'static str {
    match columns {
        Columns::Rel => "relative",
        Columns::Abs => "absolute",
        Columns::Auto => {
            if picked(t, columns).iter().any(|&i| relative(t.columns[i].unit)) {
                "relative"
            } else {
                "absolute"
            }
        }
    }
}

fn scene_rows(t: &Table) -> impl Iterator<Item = &crate::repro::table::Row> {
    t.rows.iter().filter(|r| r.kind == RowKind::Scene)
}

/// The tolerance band around the thesis' value `thesis` in the column's units:
/// relative: thesis·(1 ± f); factor (changes in %): (1 + t/100)·(1 ± f)·100 − 100;
/// points: thesis ± p. Ours is within tolerance exactly when it lies in the band.
pub fn band(tolerance: Tolerance, thesis: f64) -> (f64, f64) {
    let (a, b) = match tolerance {
        Tolerance::Relative(f) => (thesis * (1.0 - f), thesis * (1.0 + f)),
        Tolerance::Factor(f) => {
            let base = 1.0 + thesis / 100.0;
            (base * (1.0 - f) * 100.0 - 100.0, base * (1.0 + f) * 100.0 - 100.0)
        }
        Tolerance::Points(p) => (thesis - p, thesis + p),
    };
    (a.min(b), a.max(b))
}

/// Ours beside the thesis for the compared cells of `t`'s scene rows in the
/// columns `columns` picks: a group per cell ("scene / column"), series "ours"
/// and "thesis", the tolerance band per group. `None` when no cell has a value.
pub fn table_bars(t: &Table, columns: Columns, subtitle: &str) -> Option<Bars> {
    let cols = picked(t, columns);
    let mut groups = Vec::new();
    let (mut ours, mut thesis, mut bands) = (Vec::new(), Vec::new(), Vec::new());
    for r in scene_rows(t) {
        for &i in &cols {
            let c = &r.cells[i];
            if c.ours.is_none() && c.thesis_value.is_none() {
                continue;
            }
            groups.push(format!("{} / {}", r.label, t.columns[i].name));
            ours.push(c.ours);
            thesis.push(c.thesis_value);
            bands.push(match (t.columns[i].tolerance, c.thesis_value) {
                (Some(tol), Some(v)) => Some(band(tol, v)),
                _ => None,
            });
        }
    }
    if groups.is_empty() {
        return None;
    }
    let units: Vec<Unit> = cols.iter().map(|&i| t.columns[i].unit).collect();
    let y_label = if units.iter().all(|u| *u == Unit::Change) {
        "relative change (%)".to_string()
    } else if units.iter().all(|u| *u == Unit::Points) {
        "difference (percentage points)".to_string()
    } else if units.iter().all(|u| relative(*u)) {
        "change (%) or difference (pp)".to_string()
    } else if cols.len() == 1 {
        t.columns[cols[0]].name.clone()
    } else {
        "value (the column's units)".to_string()
    };
    let tolerances: Vec<String> = {
        let mut v: Vec<String> = Vec::new();
        for d in cols.iter().filter_map(|&i| t.columns[i].tolerance.map(|t| t.describe())) {
            if !v.contains(&d) {
                v.push(d);
            }
        }
        v
    };
    Some(Bars {
        title: format!("{}\n{subtitle}", t.heading),
        y_label,
        groups,
        series: vec![
            BarSeries { name: "ours".into(), values: ours },
            BarSeries { name: "thesis".into(), values: thesis },
        ],
        bands,
        band_label: format!("thesis, tolerance {}", tolerances.join("; ")),
    })
}

fn one_of(what: &str, given: Option<&String>, have: Vec<String>, file: &Path) -> Result<String, String> {
    match given {
        Some(g) if have.contains(g) => Ok(g.clone()),
        Some(g) => Err(format!("{}: no {what} `{g}` (it has {})", file.display(), have.join(", "))),
        None if have.len() == 1 => Ok(have[0].clone()),
        None => Err(format!("{}: name the {what} (--{what}): it has {}", file.display(), have.join(", "))),
    }
}

fn distinct<'a>(it: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for s in it {
        if !v.iter().any(|x| x == s) {
            v.push(s.to_string());
        }
    }
    v
}

/// The lines of `counter` frame by frame, one per variant of `group` on `scene`.
pub fn flight_lines(r: &Results, group: &str, scene: &str, counter: &str, per_ray: bool) -> Result<Lines, String> {
    let framed = || r.samples.iter().filter(|s| s.group == group && s.scene == scene && s.frame.is_some());
    let variants = distinct(framed().map(|s| s.variant.as_str()));
    let counters = {
        let mut c = distinct(framed().flat_map(|s| s.counters.keys().map(String::as_str)));
        c.sort();
        c
    };
    if !counters.iter().any(|c| c == counter) {
        return Err(format!("no counter `{counter}` in {group} on {scene} (it has {})", counters.join(", ")));
    }
    if per_ray && !counters.iter().any(|c| c == "rays") {
        return Err(format!("--per-ray: {group} has no `rays` counter"));
    }
    let mut series = Vec::new();
    for v in &variants {
        let values = r.per_frame(group, scene, v, counter);
        let points: Vec<(f64, f64)> = if per_ray {
            let rays = r.per_frame(group, scene, v, "rays");
            values
                .iter()
                .filter_map(|&(f, x)| {
                    let n = rays.iter().find(|(g, _)| *g == f)?.1;
                    (n > 0.0).then(|| (f64::from(f), x / n))
                })
                .collect()
        } else {
            values.iter().map(|&(f, x)| (f64::from(f), x)).collect()
        };
        series.push(Series { name: v.clone(), points });
    }
    Ok(Lines {
        title: format!(
            "{counter}{} along the flight of {scene} ({group})\nprotocol {}; warplight {}",
            if per_ray { " per ray" } else { "" },
            r.protocol.describe(),
            r.commit
        ),
        x_label: "frame".into(),
        y_label: if per_ray { format!("{counter} per ray") } else { counter.to_string() },
        series,
    })
}

fn flight(a: FlightArgs) -> Result<(), Box<dyn std::error::Error>> {
    let size = parse_size(a.size.as_deref())?;
    Format::of(&a.output)?;
    let r = Results::read(&a.from)?;
    let groups = distinct(r.samples.iter().filter(|s| s.frame.is_some()).map(|s| s.group.as_str()));
    let group = one_of("group", a.group.as_ref(), groups, &a.from)?;
    let scenes = distinct(r.samples.iter().filter(|s| s.group == group && s.frame.is_some()).map(|s| s.scene.as_str()));
    let scene = one_of("scene", a.scene.as_ref(), scenes, &a.from)?;
    let lines =
        flight_lines(&r, &group, &scene, &a.counter, a.per_ray).map_err(|e| format!("{}: {e}", a.from.display()))?;
    write(&Chart::Lines(lines), &a.output, size)
}

fn scatter(a: ScatterArgs) -> Result<(), Box<dyn std::error::Error>> {
    let size = parse_size(a.size.as_deref())?;
    Format::of(&a.output)?;
    let text = std::fs::read_to_string(&a.data).map_err(|e| format!("{}: {e}", a.data.display()))?;
    let s: Scatter = serde_json::from_str(&text).map_err(|e| {
        format!("{}: not a scatter chart ({e}); see `warplight chart scatter --help`", a.data.display())
    })?;
    write(&Chart::Scatter(s), &a.output, size).map_err(|e| format!("{}: {e}", a.data.display()).into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses() {
        assert!(address_matches("fabianowski:4.5", "fabianowski:4.5"));
        assert!(address_matches("4.5", "fabianowski:4.5"));
        assert!(!address_matches("4.5", "fabianowski:4.51"));
        assert!(address_matches("4.8", "fabianowski:4.8a"));
        assert!(address_matches("all", "fabianowski:4.8a"));
        assert!(address_matches("fabianowski:all", "fabianowski:4.8a"));
        assert!(!address_matches("lin:all", "fabianowski:4.8a"));
        assert!(!address_matches("lin:4.5", "fabianowski:4.5"));
    }

    #[test]
    fn bands_are_the_tolerance() {
        use crate::repro::compare::Verdict;
        for (tol, t) in
            [(Tolerance::Relative(0.05), 7.31), (Tolerance::Factor(0.1), 35.7), (Tolerance::Points(1.0), -2.2)]
        {
            let (lo, hi) = band(tol, t);
            assert_eq!(tol.verdict(lo + 1e-9, t), Verdict::Within);
            assert_eq!(tol.verdict(hi - 1e-9, t), Verdict::Within);
            assert_eq!(tol.verdict(lo - 1e-6, t), Verdict::Outside);
            assert_eq!(tol.verdict(hi + 1e-6, t), Verdict::Outside);
        }
        // +35.7 % within a factor of 1.1: 1.357 · 0.9 and 1.357 · 1.1
        let (lo, hi) = band(Tolerance::Factor(0.1), 35.7);
        assert!((lo - 22.13).abs() < 1e-9 && (hi - 49.27).abs() < 1e-9, "{lo} {hi}");
    }
}
