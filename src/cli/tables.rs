//! `warplight tables 4.4 ...`: reproduced thesis tables beside the published values.

use std::io::IsTerminal;

use super::scene_info::scene_path;
use crate::host::rt_kernels::Variant;
use crate::host::scene::Scene;
use crate::host::scene_file;
use crate::repro::{flight_tables, table_4_1, table_4_2, table_4_3, table_4_4};

/// `println!` into the output buffer.
macro_rules! outln {
    ($out:expr, $($arg:tt)*) => {{
        $out.push_str(&format!($($arg)*));
        $out.push('\n');
    }};
}

/// `print!` into the output buffer.
macro_rules! outp {
    ($out:expr, $($arg:tt)*) => {
        $out.push_str(&format!($($arg)*))
    };
}

/// Options of `warplight tables`.
#[derive(Debug, clap::Args)]
pub struct TablesArgs {
    /// Tables to reproduce: 4.1, 4.2 (its part (b), qualitatively), 4.3, 4.4, 4.5, 4.6, 4.7,
    /// 4.8, 4.9, 4.10, or all.
    pub tables: Vec<String>,
    /// Frames of each camera flight (the thesis: 50).
    #[arg(long, default_value_t = 50)]
    pub frames: u32,
    /// Image side in pixels (the thesis: 512).
    #[arg(long, default_value_t = 512)]
    pub resolution: u32,
    /// Scenes (names in scenes/), comma-separated; default: every scene of the table that is available.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Builds per heuristic; the fastest time counts.
    #[arg(long, default_value_t = 1)]
    pub repeats: u32,
    /// Output: markdown (default), table (aligned columns for a terminal), csv (every
    /// table's rows with the table's name in the first column) or json (the raw measurements).
    #[arg(long, default_value = "markdown")]
    pub format: String,
}

/// Runs the command.
pub fn run(a: TablesArgs) -> Result<(), Box<dyn std::error::Error>> {
    if a.tables.is_empty() {
        return Err("name a table: 4.4".into());
    }
    if !["markdown", "json", "csv", "table"].contains(&a.format.as_str()) {
        return Err(format!("--format {}: expected markdown, table, csv or json", a.format).into());
    }
    let mut out = String::new();
    let (mut traversal, mut caches) = (None, None);
    let tables: Vec<&str> = if a.tables.iter().any(|t| t == "all") {
        vec!["4.1", "4.2", "4.3", "4.4", "4.5", "4.6", "4.7", "4.8", "4.9", "4.10"]
    } else {
        a.tables.iter().map(|t| t.as_str()).collect()
    };
    for t in tables {
        match t {
            "4.1" => table_4_1(&a, &mut out)?,
            "4.2" => table_4_2(&a, &mut out)?,
            "4.3" => table_4_3(&a, &mut out)?,
            "4.4" => table_4_4(&a, &mut out)?,
            "4.5" | "4.6" | "4.7" => {
                if traversal.is_none() {
                    traversal = Some(flight_runs(&a, &Variant::ALL)?);
                }
                print_flight_table(t, traversal.as_ref().expect("measured"), &a, &mut out);
            }
            "4.8" | "4.9" | "4.10" => {
                if caches.is_none() {
                    caches = Some(flight_runs(&a, &Variant::CACHES)?);
                }
                print_flight_table(t, caches.as_ref().expect("measured"), &a, &mut out);
            }
            other => {
                return Err(format!(
                    "table {other} is not reproduced; available: 4.1, 4.2, 4.3, 4.4, 4.5, 4.6, 4.7, 4.8, 4.9, 4.10, all"
                )
                .into());
            }
        }
    }
    match a.format.as_str() {
        "csv" => print!("{}", super::table_format::csv(&out)),
        "table" => print!("{}", super::table_format::terminal(&out)),
        _ => print!("{out}"),
    }
    Ok(())
}

/// Loads each named scene and measures it, with a progress bar; reports the
/// scenes that could not be loaded (with why) on stderr.
fn per_scene<T>(names: &[String], what: &str, mut f: impl FnMut(&Scene) -> T) -> Vec<T> {
    let pb = std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new(names.len() as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} [{elapsed}]").expect("template"),
        );
        pb
    });
    let (mut out, mut skipped) = (Vec::new(), Vec::new());
    for n in names {
        if let Some(pb) = &pb {
            pb.set_message(format!("{n}: {what}"));
        }
        match scene_file::load(&scene_path(n)) {
            Ok(s) => out.push(f(&s)),
            Err(e) => skipped.push(format!("{n}: {e}")),
        }
        if let Some(pb) = &pb {
            pb.inc(1);
        }
    }
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    for sk in skipped {
        eprintln!("skipped {sk}");
    }
    out
}

fn table_4_3(a: &TablesArgs, out: &mut String) -> Result<(), Box<dyn std::error::Error>> {
    let all: Vec<&str> = table_4_3::THESIS.iter().map(|r| r.0).collect();
    let rows = per_scene(&scene_names(a, &all), "three trees (the numerical one takes a while) and the flight", |s| {
        table_4_3::measure(s, a.frames, a.resolution)
    });
    let title = "Table 4.3: traversals, plane and triangle intersections per ray with the numerical approximation (4.1.2) and SIROH, relative to the SAH (thesis 000, seed L1699-1709)";
    if emit(a, out, &rows, title, table_4_3::markdown)? {
        outln!(
            out,
            "\nOurs: stack-based traversal (the native caster, step for step the stack kernel), {} frame(s) of each flight at {}x{}.\n",
            a.frames,
            a.resolution,
            a.resolution
        );
    }
    Ok(())
}

/// The scenes asked for with `--scenes`, or `all`.
fn scene_names(a: &TablesArgs, all: &[&str]) -> Vec<String> {
    if a.scenes.is_empty() { all.iter().map(|s| s.to_string()).collect() } else { a.scenes.clone() }
}

/// Prints `rows` as JSON with `--format json`; otherwise prints `title` and the
/// table `markdown` makes of them, and returns true so that the caller adds its notes.
fn emit<T: serde::Serialize>(
    a: &TablesArgs,
    out: &mut String,
    rows: &[T],
    title: &str,
    markdown: impl FnOnce(&[T]) -> String,
) -> Result<bool, Box<dyn std::error::Error>> {
    if a.format == "json" {
        println!("{}", serde_json::to_string_pretty(rows)?);
        return Ok(false);
    }
    out.push_str(&format!("{title}\n\n{}", markdown(rows)));
    Ok(true)
}

/// Loads the named scenes (default: `all`), reporting those that cannot be loaded.
fn load_scenes(a: &TablesArgs, all: &[&str]) -> Vec<Scene> {
    let mut scenes = Vec::new();
    for n in &scene_names(a, all) {
        match scene_file::load(&scene_path(n)) {
            Ok(s) => scenes.push(s),
            Err(e) => eprintln!("skipped {n}: {e}"),
        }
    }
    scenes
}

/// A progress bar over `total` frames (None when stderr is not a terminal).
fn frame_bar(total: u64, unit: &str) -> Option<indicatif::ProgressBar> {
    std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new(total);
        pb.set_style(
            indicatif::ProgressStyle::with_template(&format!(
                "{{bar:30}} {{pos}}/{{len}} {unit}, {{msg}} [{{elapsed}}, eta {{eta}}]"
            ))
            .expect("template"),
        );
        pb
    })
}

fn table_4_1(a: &TablesArgs, out: &mut String) -> Result<(), Box<dyn std::error::Error>> {
    let all: Vec<&str> = table_4_1::THESIS.iter().map(|r| r.0).collect();
    let scenes = load_scenes(a, &all);
    let total: u64 = scenes.iter().map(|s| 3 * a.frames.min(s.flight.frames) as u64).sum();
    let pb = frame_bar(total, "frames x trees");
    let mut rows = Vec::new();
    for s in &scenes {
        rows.push(table_4_1::measure(s, a.frames, a.resolution, |f, h| {
            if let Some(pb) = &pb {
                pb.set_message(format!("{} frame {f} {:?} tree", s.name, table_4_1::HEURISTICS[h]));
                pb.inc(1);
            }
        })?);
    }
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    let title = "Table 4.1: frame rates with the numerical approximation (4.1.2) and SIROH relative to the SAH, two code bases (thesis 000, seed L1664-1674)";
    if emit(a, out, &rows, title, table_4_1::markdown)? {
        outln!(
            out,
            "Ours: the stack-based kernel on each heuristic's tree, {} frame(s) of each flight at {}x{}, frame rates from the GT200 timing model. \
             Code base I is not described beyond its SAH frame rates; compare the signs and sizes of the relative columns. \
             Scenes: {}. Fixtures: docs/fixtures.md.\n",
            a.frames,
            a.resolution,
            a.resolution,
            rows.iter()
                .map(|r| format!("{} {} triangles", r.run.scene, r.run.triangles))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

fn table_4_2(a: &TablesArgs, out: &mut String) -> Result<(), Box<dyn std::error::Error>> {
    let all: Vec<&str> = table_4_1::THESIS.iter().map(|r| r.0).collect();
    let rows =
        per_scene(&scene_names(a, &all), "SAH and SIROH trees, shadow rays", |s| table_4_2::measure(s, a.resolution));
    let title = "Table 4.2 (b), qualitatively: SIROH vs SAH for shadow rays from a light inside and outside the scene (thesis 000, seed L1682-1697)";
    if emit(a, out, &rows, title, table_4_2::markdown)? {
        outln!(
            out,
            "\nOurs: shadow rays traced from the light to every primary hit of frame 0 at {}x{}, inner-node traversals per ray (native caster). \
             Lights at the scene centre + extent x {:?} (inside) and x {:?} (outside). Table 4.2 (a) and the frame rates of (b) \
             measured third-party ray tracers and are not reproduced. Fixtures: docs/fixtures.md.\n",
            a.resolution,
            a.resolution,
            table_4_2::LIGHT_INSIDE,
            table_4_2::LIGHT_OUTSIDE
        );
    }
    Ok(())
}

fn flight_runs(
    a: &TablesArgs,
    variants: &[Variant],
) -> Result<Vec<flight_tables::SceneRun>, Box<dyn std::error::Error>> {
    let all: Vec<&str> = flight_tables::TABLE_4_5.iter().map(|r| r.0).collect();
    let scenes = load_scenes(a, &all);
    let total: u64 = scenes.iter().map(|s| (a.frames.min(s.flight.frames) as usize * variants.len()) as u64).sum();
    let pb = frame_bar(total, "frames x variants");
    let mut runs = Vec::new();
    for s in &scenes {
        let r = flight_tables::measure(s, a.frames, a.resolution, variants, |f, v| {
            if let Some(pb) = &pb {
                pb.set_message(format!("{} frame {f} {}", s.name, v.name()));
                pb.inc(1);
            }
        })?;
        runs.push(r);
    }
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    Ok(runs)
}

fn print_flight_table(t: &str, runs: &[flight_tables::SceneRun], a: &TablesArgs, out: &mut String) {
    use flight_tables as ft;
    if a.format == "json" {
        println!("{}", serde_json::to_string_pretty(runs).unwrap_or_default());
        return;
    }
    let md = match t {
        "4.5" => ft::markdown(
            "Table 4.5: inner node traversals per ray, stackless variants relative to stack-based (thesis 000, seed L1878-1888)",
            &ft::TABLE_4_5,
            runs,
            |r| r.inner_per_ray(),
        ),
        "4.7" => ft::markdown(
            "Table 4.7: instructions per ray (warp instructions x 32 / rays), relative to stack-based (thesis 000, seed L1914-1924)",
            &ft::TABLE_4_7,
            runs,
            |r| r.instr_per_ray(),
        ),
        "4.6" => crate::repro::timing::markdown(
            "Table 4.6: frame rates (GT200 timing model) with stackless traversal, relative to stack-based (thesis 000, seed L1902-1912)",
            &crate::repro::timing::TABLE_4_6,
            runs,
        ),
        "4.10" => crate::repro::timing::markdown(
            "Table 4.10: frame rates (GT200 timing model) with explicitly managed caches, relative to the baseline (thesis 000, seed L2146-2157)",
            &crate::repro::timing::TABLE_4_10,
            runs,
        ),
        "4.9" => ft::markdown(
            "Table 4.9: instructions per ray with explicitly managed caches, relative to the baseline (thesis 000, seed L2123-2134)",
            &ft::TABLE_4_9,
            runs,
            |r| r.instr_per_ray(),
        ),
        _ => {
            let a_ = ft::markdown(
                "Table 4.8 (a): inner nodes loaded through the texturing unit per ray (thesis 000, seed L2066-2119)",
                &ft::TABLE_4_8A,
                runs,
                |r| r.per_ray(|t| t.tex_node_fetches),
            );
            let b_ = ft::markdown(
                "Table 4.8 (b): stack entries accessed in local memory per ray",
                &ft::TABLE_4_8B,
                runs,
                |r| r.per_ray(|t| t.local_stack_accesses),
            );
            let c_ = ft::markdown_with(
                "Table 4.8 (c): texture cache hit ratios, % (gt200 profile: a 5 KB cache per TPC of 3 SMs, all TPCs; differences in percentage points)",
                &ft::TABLE_4_8C,
                runs,
                |r| r.totals.iter().map(|t| t.tex_hits as f64 * 100.0 / t.tex_lookups.max(1) as f64).collect(),
                true,
            );
            let d_ = ft::markdown(
                "Table 4.8 (d): global memory bytes per ray, 8 x ((a) + (b))",
                &ft::TABLE_4_8D,
                runs,
                |r| r.per_ray(|t| 8 * (t.tex_node_fetches + t.local_stack_accesses)),
            );
            format!("{a_}\n{b_}\n{c_}\n{d_}")
        }
    };
    out.push_str(&md);
    out.push('\n');
    outln!(
        out,
        "Ours: SIROH trees, {} frame(s) of each flight at {}x{}, 30 persistent CTAs x 256 threads, 32-pixel job blocks, clang-16 PTX.",
        a.frames,
        a.resolution,
        a.resolution
    );
    let scenes: Vec<String> = runs.iter().map(|r| format!("{} {} triangles", r.scene, r.triangles)).collect();
    outln!(
        out,
        "Scenes: {} (variants as in `warplight scene info NAME`). Fixtures: docs/fixtures.md. Instructions are PTX instructions, not GT200 SASS.\n",
        scenes.join(", ")
    );
}

fn table_4_4(a: &TablesArgs, out: &mut String) -> Result<(), Box<dyn std::error::Error>> {
    let all: Vec<&str> = table_4_4::THESIS.iter().map(|r| r.scene).collect();
    let rows = per_scene(&scene_names(a, &all), "building the trees", |s| table_4_4::measure(s, a.repeats));
    if a.format == "json" {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    outln!(out, "Table 4.4: kd-tree construction with SIROH relative to the SAH (thesis 000, seed L1711-1721)\n");
    outp!(out, "{}", table_4_4::markdown(&rows));
    outln!(
        out,
        "\nOurs: this machine, single-threaded, best of {} build(s); thesis timings are CPU II (Core2 Quad Q9450).\n\
         Fixtures (docs/fixtures.md): C_T = 1, C_I = 3, leaves at <= 4 triangles, empty-space bias 20% above 30% volume,\n\
         depth <= 32, triangle bounds clamped to the node (no clipping), ties to the first candidate in (axis, position) order.\n\
         Scene variants differ from the thesis' where the triangle counts do (`warplight scene info NAME`).",
        a.repeats
    );
    Ok(())
}
