//! `warplight tables 4.4 ...`: reproduced thesis tables beside the published values.

use std::io::IsTerminal;

use super::scene_info::scene_path;
use crate::host::scene::Scene;
use crate::host::scene_file;
use crate::repro::{table_4_3, table_4_4, tables_4_5_4_7};

/// Options of `warplight tables`.
#[derive(Debug, clap::Args)]
pub struct TablesArgs {
    /// Tables to reproduce: 4.3, 4.4, 4.5, 4.7, or all.
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
    /// Output: markdown (default) or json.
    #[arg(long, default_value = "markdown")]
    pub format: String,
}

/// Runs the command.
pub fn run(a: TablesArgs) -> Result<(), Box<dyn std::error::Error>> {
    if a.tables.is_empty() {
        return Err("name a table: 4.4".into());
    }
    let mut flights: Option<Vec<tables_4_5_4_7::SceneRun>> = None;
    for t in &a.tables {
        match t.as_str() {
            "4.3" => table_4_3(&a)?,
            "4.4" => table_4_4(&a)?,
            "4.5" | "4.7" => {
                if flights.is_none() {
                    flights = Some(flight_runs(&a)?);
                }
                let runs = flights.as_ref().expect("measured");
                print_4_5_4_7(t, runs, &a);
            }
            "all" => {
                table_4_3(&a)?;
                table_4_4(&a)?;
                let runs = flight_runs(&a)?;
                print_4_5_4_7("4.5", &runs, &a);
                print_4_5_4_7("4.7", &runs, &a);
            }
            other => {
                return Err(format!("table {other} is not reproduced yet; available: 4.3, 4.4, 4.5, 4.7, all").into());
            }
        }
    }
    Ok(())
}

/// Loads each named scene and measures it, with a progress bar; returns the
/// results and the scenes that could not be loaded (with why).
fn per_scene<T>(names: &[String], what: &str, mut f: impl FnMut(&Scene) -> T) -> (Vec<T>, Vec<String>) {
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
    (out, skipped)
}

fn table_4_3(a: &TablesArgs) -> Result<(), Box<dyn std::error::Error>> {
    let names: Vec<String> = if a.scenes.is_empty() {
        table_4_3::THESIS.iter().map(|r| r.0.to_string()).collect()
    } else {
        a.scenes.clone()
    };
    let (rows, skipped) = per_scene(&names, "three trees (the numerical one takes a while) and the flight", |s| {
        table_4_3::measure(s, a.frames, a.resolution)
    });
    for sk in skipped {
        eprintln!("skipped {sk}");
    }
    if a.format == "json" {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    println!(
        "Table 4.3: traversals, plane and triangle intersections per ray with the numerical approximation (4.1.2) and SIROH, relative to the SAH (thesis 000, seed L1699-1709)\n"
    );
    print!("{}", table_4_3::markdown(&rows));
    println!(
        "\nOurs: stack-based traversal (the native caster, step for step the stack kernel), {} frame(s) of each flight at {}x{}.\n",
        a.frames, a.resolution, a.resolution
    );
    Ok(())
}

fn flight_runs(a: &TablesArgs) -> Result<Vec<tables_4_5_4_7::SceneRun>, Box<dyn std::error::Error>> {
    let names: Vec<String> = if a.scenes.is_empty() {
        tables_4_5_4_7::TABLE_4_5.iter().map(|r| r.0.to_string()).collect()
    } else {
        a.scenes.clone()
    };
    let mut scenes = Vec::new();
    for n in &names {
        match scene_file::load(&scene_path(n)) {
            Ok(s) => scenes.push(s),
            Err(e) => eprintln!("skipped {n}: {e}"),
        }
    }
    let total: u64 = scenes.iter().map(|s| a.frames.min(s.flight.frames) as u64 * 5).sum();
    let pb = std::io::stderr().is_terminal().then(|| {
        let pb = indicatif::ProgressBar::new(total);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:30} {pos}/{len} frames x variants, {msg} [{elapsed}, eta {eta}]",
            )
            .expect("template"),
        );
        pb
    });
    let mut runs = Vec::new();
    for s in &scenes {
        let r = tables_4_5_4_7::measure(s, a.frames, a.resolution, |f, v| {
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

fn print_4_5_4_7(t: &str, runs: &[tables_4_5_4_7::SceneRun], a: &TablesArgs) {
    if a.format == "json" {
        println!("{}", serde_json::to_string_pretty(runs).unwrap_or_default());
        return;
    }
    let md = if t == "4.5" {
        tables_4_5_4_7::markdown(
            "Table 4.5: inner node traversals per ray, stackless variants relative to stack-based (thesis 000, seed L1878-1888)",
            &tables_4_5_4_7::TABLE_4_5,
            runs,
            |r| r.inner_per_ray,
        )
    } else {
        tables_4_5_4_7::markdown(
            "Table 4.7: instructions per ray (warp instructions x 32 / rays), relative to stack-based (thesis 000, seed L1914-1924)",
            &tables_4_5_4_7::TABLE_4_7,
            runs,
            |r| r.instr_per_ray,
        )
    };
    println!("{md}");
    println!(
        "Ours: SIROH trees, {} frame(s) of each flight at {}x{}, 30 persistent CTAs x 256 threads, 32-pixel job blocks, clang-16 PTX.",
        a.frames, a.resolution, a.resolution
    );
    println!(
        "Fixtures: docs/fixtures.md. Instructions are PTX instructions, not GT200 SASS; scene variants as in `warplight scene info`.\n"
    );
}

fn table_4_4(a: &TablesArgs) -> Result<(), Box<dyn std::error::Error>> {
    let names: Vec<String> = if a.scenes.is_empty() {
        table_4_4::THESIS.iter().map(|r| r.scene.to_string()).collect()
    } else {
        a.scenes.clone()
    };
    let (rows, skipped) = per_scene(&names, "building the trees", |s| table_4_4::measure(s, a.repeats));
    if a.format == "json" {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    println!("Table 4.4: kd-tree construction with SIROH relative to the SAH (thesis 000, seed L1711-1721)\n");
    print!("{}", table_4_4::markdown(&rows));
    println!(
        "\nOurs: this machine, single-threaded, best of {} build(s); thesis timings are CPU II (Core2 Quad Q9450).\n\
         Fixtures (docs/fixtures.md): C_T = 1, C_I = 3, leaves at <= 4 triangles, empty-space bias 20% above 30% volume,\n\
         depth <= 32, triangle bounds clamped to the node (no clipping), ties to the first candidate in (axis, position) order.\n\
         Scene variants differ from the thesis' where the triangle counts do (`warplight scene info NAME`).",
        a.repeats
    );
    for s in skipped {
        println!("skipped {s}");
    }
    Ok(())
}
