//! Thesis 003 Figs. 16 and 17 as charts (issue 15, item 5): per level of the
//! wavefront path tracer, the useful SIMT lanes (Fig. 16's "rate of useful
//! operations", 003:L505-507) and the active paths (Fig. 17's falling
//! occupancy, 003:L532), with and without thread compaction, counted by the
//! emulator (`warplight chart lin-compaction`). The runs are
//! [`super::fig_17::run`]'s, the table's; the counts are the `@count live`
//! line's (`host::path::wavefront::level`).

use serde::{Deserialize, Serialize};

use super::fig_17;
use crate::chart::{Scatter, Series};
use crate::host::path::wavefront::{Level, Mode};
use crate::host::scene::Scene;
use crate::repro::registry::MeasureError;

/// One level of one mode, counted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LevelCount {
    /// The level (0: camera rays).
    pub level: u32,
    /// Threads launched for it.
    pub threads: u64,
    /// Paths that entered its work.
    pub active: u64,
    /// Warps that issued its work (at least one active lane).
    pub busy_warps: u64,
    /// Warps holding its threads.
    pub warps: u64,
    /// Warp instructions of its `path_level` launch.
    pub warp_instructions: u64,
    /// Warp instructions of the compaction after it (0 without).
    pub compact_warp_instructions: u64,
}

impl LevelCount {
    fn of(level: u32, l: &Level) -> LevelCount {
        LevelCount {
            level,
            threads: l.threads,
            active: l.active,
            busy_warps: l.busy_warps,
            warps: l.warps,
            warp_instructions: l.warp_instructions,
            compact_warp_instructions: l.compact_warp_instructions,
        }
    }

    /// Active lanes over the lanes of the warps that issued the work, in %
    /// (`None` when no warp did).
    pub fn useful_percent(&self) -> Option<f64> {
        (self.busy_warps > 0).then(|| 100.0 * self.active as f64 / (32.0 * self.busy_warps as f64))
    }
}

/// The chart data (`docs/images/lin-compaction-data.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Compaction {
    /// The scene.
    pub scene: String,
    /// Image side in pixels (4 paths a pixel).
    pub size: u32,
    /// Paths of the frame.
    pub paths: u64,
    /// Levels of the frame (the longest path `depth` − 1 bounces).
    pub depth: u32,
    /// Without compaction, per level.
    pub normal: Vec<LevelCount>,
    /// With compaction, per level.
    pub compact: Vec<LevelCount>,
}

/// Runs one frame of each mode ([`fig_17::run`]) and counts its levels.
pub fn measure(scene: &Scene, size: u32, depth: u32) -> Result<Compaction, MeasureError> {
    if size == 0 || depth == 0 {
        return Err(format!("size {size}, depth {depth}: expected both positive").into());
    }
    let counted = |mode: Mode| -> Result<Vec<LevelCount>, MeasureError> {
        let r = fig_17::run(scene, size, depth, mode)?;
        Ok(r.levels.iter().enumerate().map(|(l, lv)| LevelCount::of(l as u32, lv)).collect())
    };
    Ok(Compaction {
        scene: scene.name.clone(),
        size,
        paths: u64::from(size * size * crate::host::path::SAMPLES_PER_FRAME),
        depth,
        normal: counted(Mode::Normal)?,
        compact: counted(Mode::Compacted)?,
    })
}

/// The charts' names (`{}` in `warplight chart lin-compaction -o`).
pub const CHARTS: [&str; 2] = ["lanes", "paths"];

impl Compaction {
    /// The charts, in [`CHARTS`]' order: useful lanes per level (both modes),
    /// and active paths, threads launched and warps with work per level, log y.
    pub fn charts(&self) -> Vec<Scatter> {
        let head = format!(
            "{}: {} paths ({}x{} x 4), next-event estimation, {} levels; counted by the emulator",
            self.scene, self.paths, self.size, self.size, self.depth
        );
        let pts = |v: &[LevelCount], f: &dyn Fn(&LevelCount) -> Option<f64>| -> Vec<(f64, f64)> {
            v.iter().filter_map(|l| Some((l.level as f64, f(l)?))).collect()
        };
        let positive = |x: u64| (x > 0).then_some(x as f64);
        let lanes = vec![
            Series { name: "without compaction".into(), points: pts(&self.normal, &|l| l.useful_percent()) },
            Series { name: "with compaction".into(), points: pts(&self.compact, &|l| l.useful_percent()) },
        ];
        let paths = vec![
            Series { name: "active paths (both)".into(), points: pts(&self.compact, &|l| positive(l.active)) },
            Series {
                name: "threads launched, without compaction".into(),
                points: pts(&self.normal, &|l| positive(l.threads)),
            },
            Series {
                name: "threads launched, with compaction".into(),
                points: pts(&self.compact, &|l| positive(l.threads)),
            },
            Series {
                name: "warps with work x 32, without".into(),
                points: pts(&self.normal, &|l| positive(32 * l.busy_warps)),
            },
            Series {
                name: "warps with work x 32, with".into(),
                points: pts(&self.compact, &|l| positive(32 * l.busy_warps)),
            },
        ];
        vec![
            Scatter {
                title: format!(
                    "Fig. 16 proxy: useful SIMT lanes per level (active lanes / 32 x warps with work)\n{head}"
                ),
                x_label: "level (0: camera rays)".into(),
                y_label: "useful lanes (%)".into(),
                log_x: false,
                log_y: false,
                connect: true,
                series: lanes,
            },
            Scatter {
                title: format!("Fig. 17 proxy: active paths per level\n{head}"),
                x_label: "level (0: camera rays)".into(),
                y_label: "paths, threads, lanes".into(),
                log_x: false,
                log_y: true,
                connect: true,
                series: paths,
            },
        ]
    }
}
