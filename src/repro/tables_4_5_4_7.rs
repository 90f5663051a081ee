//! Thesis 000 Tables 4.5 and 4.7: inner-node traversals and instructions per
//! ray of the stackless variants relative to stack-based traversal
//! (seed 000, L1878–1888 and L1914–1924), measured by running the kernels on
//! the emulator over each scene's camera flight.

use crate::host::kdtree::{BuildParams, Heuristic, build};
use crate::host::rt_kernels::{self, Variant};
use crate::host::scene::Scene;
use crate::model::Profile;
use crate::sim::{Device, SimError};

/// Published rows: scene, stack-based absolute value, then the four relative changes (%).
pub type Published = (&'static str, f64, [f64; 4]);

/// Table 4.5 (L1878–1888): inner node traversals per ray.
pub const TABLE_4_5: [Published; 5] = [
    ("scene6", 7.31, [35.7, 21.1, 0.0, 0.0]),
    ("sponza", 29.81, [136.7, 97.1, 0.3, 0.2]),
    ("sibenik", 37.63, [151.5, 107.2, 0.8, 0.8]),
    ("fairy", 37.43, [182.7, 98.2, 0.6, 0.6]),
    ("conference", 19.57, [108.1, 59.4, 0.3, 0.3]),
];

/// Table 4.7 (L1914–1924): instructions per ray.
pub const TABLE_4_7: [Published; 5] = [
    ("scene6", 674.2, [18.4, 14.6, 13.6, 16.8]),
    ("sponza", 2249.9, [75.1, 61.5, 24.0, 29.8]),
    ("sibenik", 2294.9, [96.0, 74.8, 27.4, 34.0]),
    ("fairy", 3129.6, [90.5, 59.9, 28.8, 35.3]),
    ("conference", 2246.2, [42.0, 29.6, 16.5, 20.3]),
];

/// One scene's measurement: per variant (in [`Variant::ALL`] order) inner nodes
/// per ray and instructions per ray (warp instructions × 32 / rays, the thesis' rule).
#[derive(Debug, Clone, serde::Serialize)]
pub struct SceneRun {
    /// Scene name.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Frames of the flight used.
    pub frames: u32,
    /// Image side.
    pub resolution: u32,
    /// Rays traced per variant (all variants trace the same rays).
    pub rays: u64,
    /// Inner-node traversals per ray, per variant.
    pub inner_per_ray: [f64; 5],
    /// Instructions per ray, per variant.
    pub instr_per_ray: [f64; 5],
}

/// Runs every variant over `frames` frames of the scene's flight at `res` × `res`.
pub fn measure(scene: &Scene, frames: u32, res: u32, mut tick: impl FnMut(u32, Variant)) -> Result<SceneRun, SimError> {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let (mut inner, mut instr, mut rays) = ([0u64; 5], [0u64; 5], [0u64; 5]);
    for f in 0..frames.min(scene.flight.frames) {
        let mut cam = scene.flight.camera(&scene.camera, f);
        cam.resolution = [res, res];
        for (i, v) in Variant::ALL.into_iter().enumerate() {
            tick(f, v);
            // a fresh device per frame: its memory holds one frame's buffers
            let mut dev = Device::new();
            let module = rt_kernels::load(&mut dev)?;
            let k = rt_kernels::render(
                &mut dev,
                &module,
                scene,
                &tree,
                &cam,
                scene.flight.light_offset(f),
                v,
                Profile::Gt200,
            )?;
            inner[i] += k.trace.inner_nodes;
            instr[i] += k.launch.totals.warp_instructions * 32;
            rays[i] += k.trace.rays;
        }
    }
    let per = |x: [u64; 5]| std::array::from_fn(|i| x[i] as f64 / rays[i].max(1) as f64);
    Ok(SceneRun {
        scene: scene.name.clone(),
        triangles: scene.triangles.len(),
        frames: frames.min(scene.flight.frames),
        resolution: res,
        rays: rays[0],
        inner_per_ray: per(inner),
        instr_per_ray: per(instr),
    })
}

/// One table in markdown: ours and the thesis' per scene, with averages and
/// sample standard deviations of the relative columns as the thesis computes them.
pub fn markdown(
    title: &str,
    published: &[Published],
    runs: &[SceneRun],
    pick: impl Fn(&SceneRun) -> [f64; 5],
) -> String {
    let mut s = format!("{title}\n\n| Scene | Stack-based | thesis |");
    for v in &Variant::ALL[1..] {
        s.push_str(&format!(" {} | thesis |", v.name()));
    }
    s.push_str("\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    let mut cols: [Vec<f64>; 4] = Default::default();
    for r in runs {
        let v = pick(r);
        let th = published.iter().find(|p| p.0 == r.scene);
        s.push_str(&format!("| {} | {:.2} | {} |", r.scene, v[0], th.map_or("–".into(), |t| format!("{:.2}", t.1))));
        for i in 1..5 {
            let rel = (v[i] / v[0] - 1.0) * 100.0;
            cols[i - 1].push(rel);
            s.push_str(&format!(" {:+.1}% | {} |", rel, th.map_or("–".into(), |t| format!("{:+.1}%", t.2[i - 1]))));
        }
        s.push('\n');
    }
    let pub_cols: Vec<Vec<f64>> = (0..4).map(|i| published.iter().map(|p| p.2[i]).collect()).collect();
    s.push_str("| Average | | |");
    for i in 0..4 {
        let (m, _) = super::table_4_4::mean_sd(&cols[i]);
        let (pm, _) = super::table_4_4::mean_sd(&pub_cols[i]);
        s.push_str(&format!(" {m:+.1}% | {pm:+.1}% |"));
    }
    s.push_str("\n| Std. Dev. | | |");
    for i in 0..4 {
        let (_, sd) = super::table_4_4::mean_sd(&cols[i]);
        let (_, psd) = super::table_4_4::mean_sd(&pub_cols[i]);
        s.push_str(&format!(" {sd:.1}% | {psd:.1}% |"));
    }
    s.push('\n');
    s
}
