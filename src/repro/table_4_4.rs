//! Thesis 000 Table 4.4: construction timings and kd-tree statistics with
//! SIROH relative to the SAH (seed 000, L1711–1721), reproduced on our scenes.

use std::time::Instant;

use crate::host::kdtree::{BuildParams, Heuristic, TreeStats, build};
use crate::host::scene::Scene;

/// The thesis' row: scene, CPU I SAH seconds and SIROH change, CPU II likewise,
/// inner nodes SAH and SIROH change, references SAH and SIROH change (percent).
#[derive(Debug, Clone, Copy)]
pub struct ThesisRow {
    /// Scene name (as in `scenes/`).
    pub scene: &'static str,
    /// CPU I (Pentium D 965) SAH seconds.
    pub cpu1_sah: f64,
    /// CPU I SIROH relative change, %.
    pub cpu1_siroh: f64,
    /// CPU II (Core2 Quad Q9450) SAH seconds.
    pub cpu2_sah: f64,
    /// CPU II SIROH relative change, %.
    pub cpu2_siroh: f64,
    /// Inner nodes with the SAH.
    pub inner_sah: u64,
    /// Inner nodes with SIROH, relative change %.
    pub inner_siroh: f64,
    /// Triangle references with the SAH.
    pub refs_sah: u64,
    /// Triangle references with SIROH, relative change %.
    pub refs_siroh: f64,
}

/// Table 4.4 as printed (seed 000, L1711–1721).
pub const THESIS: [ThesisRow; 5] = [
    ThesisRow {
        scene: "scene6",
        cpu1_sah: 0.01,
        cpu1_siroh: 7.4,
        cpu2_sah: 0.003,
        cpu2_siroh: 11.4,
        inner_sah: 2801,
        inner_siroh: 1.5,
        refs_sah: 4038,
        refs_siroh: 1.6,
    },
    ThesisRow {
        scene: "sponza",
        cpu1_sah: 0.91,
        cpu1_siroh: 5.8,
        cpu2_sah: 0.644,
        cpu2_siroh: 6.2,
        inner_sah: 207425,
        inner_siroh: -1.0,
        refs_sah: 346767,
        refs_siroh: -0.5,
    },
    ThesisRow {
        scene: "sibenik",
        cpu1_sah: 0.95,
        cpu1_siroh: 2.3,
        cpu2_sah: 0.667,
        cpu2_siroh: -11.5,
        inner_sah: 192667,
        inner_siroh: -0.3,
        refs_sah: 317533,
        refs_siroh: -0.3,
    },
    ThesisRow {
        scene: "fairy",
        cpu1_sah: 3.41,
        cpu1_siroh: 13.0,
        cpu2_sah: 2.239,
        cpu2_siroh: 27.7,
        inner_sah: 788603,
        inner_siroh: 1.2,
        refs_sah: 1587203,
        refs_siroh: 1.2,
    },
    ThesisRow {
        scene: "conference",
        cpu1_sah: 3.25,
        cpu1_siroh: 7.6,
        cpu2_sah: 3.232,
        cpu2_siroh: 4.5,
        inner_sah: 611297,
        inner_siroh: 0.0,
        refs_sah: 2155935,
        refs_siroh: -0.7,
    },
];

/// Our measurement for one scene.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Triangles used.
    pub triangles: usize,
    /// The thesis' triangle count.
    pub thesis_triangles: Option<u64>,
    /// SAH build seconds (best of `repeats`).
    pub sah_seconds: f64,
    /// SIROH build seconds.
    pub siroh_seconds: f64,
    /// SAH tree.
    pub sah: TreeStats,
    /// SIROH tree.
    pub siroh: TreeStats,
}

fn timed(tris: &[[glam::Vec3; 3]], h: Heuristic, repeats: u32) -> (f64, TreeStats) {
    let mut best = f64::INFINITY;
    let mut stats = None;
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        let t = build(tris, BuildParams::thesis(h));
        best = best.min(t0.elapsed().as_secs_f64());
        stats = Some(t.stats());
    }
    (best, stats.expect("one build at least"))
}

/// Builds both trees for `scene` and times them.
pub fn measure(scene: &Scene, repeats: u32) -> Row {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let (sah_seconds, sah) = timed(&tris, Heuristic::Sah, repeats);
    let (siroh_seconds, siroh) = timed(&tris, Heuristic::Siroh, repeats);
    Row {
        scene: scene.name.clone(),
        triangles: tris.len(),
        thesis_triangles: scene.thesis.map(|t| t.triangles),
        sah_seconds,
        siroh_seconds,
        sah,
        siroh,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0) * 100.0
}

/// The table as markdown, thesis values beside ours.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::new();
    s.push_str("| Scene | triangles (thesis) | SAH build s | SIROH vs SAH build | thesis CPU II | inner nodes SAH (all nodes) | thesis | SIROH vs SAH | thesis | refs SAH | thesis | SIROH vs SAH | thesis |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    let mut ours = (Vec::new(), Vec::new(), Vec::new());
    for r in rows {
        let th = THESIS.iter().find(|t| t.scene == r.scene);
        let bt = rel(r.siroh_seconds, r.sah_seconds);
        let ni = rel(r.siroh.inner_nodes as f64, r.sah.inner_nodes as f64);
        let nr = rel(r.siroh.tri_refs as f64, r.sah.tri_refs as f64);
        ours.0.push(bt);
        ours.1.push(ni);
        ours.2.push(nr);
        let f = |x: Option<String>| x.unwrap_or_else(|| "–".into());
        s.push_str(&format!(
            "| {} | {} ({}) | {:.3} | {:+.1}% | {} | {} ({}) | {} | {:+.1}% | {} | {} | {} | {:+.1}% | {} |\n",
            r.scene,
            r.triangles,
            r.thesis_triangles.map(|t| t.to_string()).unwrap_or("–".into()),
            r.sah_seconds,
            bt,
            f(th.map(|t| format!("{:+.1}%", t.cpu2_siroh))),
            r.sah.inner_nodes,
            r.sah.inner_nodes + r.sah.leaves,
            f(th.map(|t| t.inner_sah.to_string())),
            ni,
            f(th.map(|t| format!("{:+.1}%", t.inner_siroh))),
            r.sah.tri_refs,
            f(th.map(|t| t.refs_sah.to_string())),
            nr,
            f(th.map(|t| format!("{:+.1}%", t.refs_siroh))),
        ));
    }
    let (m0, s0) = mean_sd(&ours.0);
    let (m1, s1) = mean_sd(&ours.1);
    let (m2, s2) = mean_sd(&ours.2);
    s.push_str(&format!(
        "| Average | | | {m0:+.1}% | +7.7% | | | {m1:+.1}% | +0.3% | | | {m2:+.1}% | +0.3% |\n| Std. Dev. | | | {s0:.1}% | 14.1% | | | {s1:.1}% | 1.0% | | | {s2:.1}% | 1.1% |\n"
    ));
    s
}

/// Mean and sample standard deviation, as the thesis computes them.
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = if v.len() > 1 { v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (v.len() - 1) as f64 } else { 0.0 };
    (m, var.sqrt())
}
