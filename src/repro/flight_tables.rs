//! Thesis 000 Tables 4.5, 4.7, 4.8 and 4.9: traversal work, memory accesses
//! and instructions per ray of the kernel variants relative to plain
//! stack-based traversal (seed 000, L1878–1888, L1914–1924, L2066–2134),
//! measured by running the kernels on the emulator over camera flights.

use crate::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use crate::host::rt_kernels::{self, Variant};
use crate::host::scene::Scene;
use crate::model::Profile;
use crate::sim::{Device, SimError};

/// Published rows: scene, the baseline's absolute value, then the other columns' relative changes (%).
pub type Published = (&'static str, f64, &'static [f64]);

/// Table 4.5 (L1878–1888): inner node traversals per ray.
pub const TABLE_4_5: [Published; 5] = [
    ("scene6", 7.31, &[35.7, 21.1, 0.0, 0.0]),
    ("sponza", 29.81, &[136.7, 97.1, 0.3, 0.2]),
    ("sibenik", 37.63, &[151.5, 107.2, 0.8, 0.8]),
    ("fairy", 37.43, &[182.7, 98.2, 0.6, 0.6]),
    ("conference", 19.57, &[108.1, 59.4, 0.3, 0.3]),
];

/// Table 4.7 (L1914–1924): instructions per ray.
pub const TABLE_4_7: [Published; 5] = [
    ("scene6", 674.2, &[18.4, 14.6, 13.6, 16.8]),
    ("sponza", 2249.9, &[75.1, 61.5, 24.0, 29.8]),
    ("sibenik", 2294.9, &[96.0, 74.8, 27.4, 34.0]),
    ("fairy", 3129.6, &[90.5, 59.9, 28.8, 35.3]),
    ("conference", 2246.2, &[42.0, 29.6, 16.5, 20.3]),
];

/// Totals of one variant over a flight.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Totals {
    /// Rays traced.
    pub rays: u64,
    /// Inner-node traversal steps.
    pub inner_nodes: u64,
    /// Inner-node fetches through the texture path.
    pub tex_node_fetches: u64,
    /// Local-memory stack pushes and pops.
    pub local_stack_accesses: u64,
    /// Warp instructions issued.
    pub warp_instructions: u64,
    /// Texture-cache lookups and hits of the gt200 profile.
    pub tex_lookups: u64,
    /// Texture-cache hits.
    pub tex_hits: u64,
    /// Memory transactions of the gt200 profile: global and local segment
    /// transactions plus texture-cache misses (for the timing model).
    pub mem_transactions: u64,
}

/// One scene's flight, per variant.
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
    /// The variants, in the order measured.
    pub variants: Vec<Variant>,
    /// Their totals.
    pub totals: Vec<Totals>,
}

impl SceneRun {
    /// A per-ray quantity of every variant.
    pub fn per_ray(&self, f: impl Fn(&Totals) -> u64) -> Vec<f64> {
        self.totals.iter().map(|t| f(t) as f64 / t.rays.max(1) as f64).collect()
    }

    /// Inner-node traversals per ray (Table 4.5).
    pub fn inner_per_ray(&self) -> Vec<f64> {
        self.per_ray(|t| t.inner_nodes)
    }

    /// Instructions per ray by the thesis' rule: warp instructions × 32 / rays (Tables 4.7, 4.9).
    pub fn instr_per_ray(&self) -> Vec<f64> {
        self.per_ray(|t| 32 * t.warp_instructions)
    }
}

/// Runs `variants` over `frames` frames of the scene's flight at `res` × `res`
/// (SIROH trees, gt200 profile).
pub fn measure(
    scene: &Scene,
    frames: u32,
    res: u32,
    variants: &[Variant],
    tick: impl FnMut(u32, Variant),
) -> Result<SceneRun, SimError> {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    measure_tree(scene, &tree, frames, res, variants, tick)
}

/// As [`measure`], over a given tree.
pub fn measure_tree(
    scene: &Scene,
    tree: &KdTree,
    frames: u32,
    res: u32,
    variants: &[Variant],
    mut tick: impl FnMut(u32, Variant),
) -> Result<SceneRun, SimError> {
    let mut totals = vec![Totals::default(); variants.len()];
    for f in 0..frames.min(scene.flight.frames) {
        let mut cam = scene.flight.camera(&scene.camera, f);
        cam.resolution = [res, res];
        for (i, v) in variants.iter().enumerate() {
            tick(f, *v);
            // a fresh device per frame: its memory holds one frame's buffers
            let mut dev = Device::new();
            let module = rt_kernels::load(&mut dev)?;
            let k = rt_kernels::render(
                &mut dev,
                &module,
                scene,
                tree,
                &cam,
                scene.flight.light_offset(f),
                *v,
                Profile::Gt200,
            )?;
            let t = &mut totals[i];
            t.rays += k.trace.rays;
            t.inner_nodes += k.trace.inner_nodes;
            t.tex_node_fetches += k.trace.tex_node_fetches;
            t.local_stack_accesses += k.trace.local_stack_accesses;
            t.warp_instructions += k.launch.totals.warp_instructions;
            t.tex_lookups += k.memory.counters.texture.sectors;
            t.tex_hits += k.memory.counters.texture.hits;
            let m = &k.memory.counters;
            t.mem_transactions += m.global_ld.sectors
                + m.global_st.sectors
                + m.local_ld.sectors
                + m.local_st.sectors
                + m.global_atom.sectors
                + m.texture.misses;
        }
    }
    Ok(SceneRun {
        scene: scene.name.clone(),
        triangles: scene.triangles.len(),
        frames: frames.min(scene.flight.frames),
        resolution: res,
        variants: variants.to_vec(),
        totals,
    })
}

/// One table in markdown: ours and the thesis' per scene, with averages and
/// sample standard deviations of the relative columns as the thesis computes
/// them. `pick` gives a scene's per-variant values (the first is the baseline);
/// `absolute` prints the other columns as differences in percentage points
/// instead of relative changes (texture hit ratios).
pub fn markdown(
    title: &str,
    published: &[Published],
    runs: &[SceneRun],
    pick: impl Fn(&SceneRun) -> Vec<f64>,
) -> String {
    markdown_with(title, published, runs, pick, false)
}

/// As [`markdown`], choosing relative changes or percentage-point differences.
pub fn markdown_with(
    title: &str,
    published: &[Published],
    runs: &[SceneRun],
    pick: impl Fn(&SceneRun) -> Vec<f64>,
    points: bool,
) -> String {
    let Some(first) = runs.first() else { return format!("{title}\n\n(no scenes)\n") };
    let names: Vec<&str> = first.variants.iter().map(|v| v.name()).collect();
    let ncol = names.len();
    let mut s = format!("{title}\n\n| Scene | {} | thesis |", names[0]);
    for n in &names[1..] {
        s.push_str(&format!(" {n} | thesis |"));
    }
    s.push_str(&format!("\n|---|{}\n", "---|".repeat(2 * ncol)));
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); ncol - 1];
    let unit = if points { "pp" } else { "%" };
    for r in runs {
        let v = pick(r);
        let th = published.iter().find(|p| p.0 == r.scene);
        s.push_str(&format!("| {} | {:.2} | {} |", r.scene, v[0], th.map_or("–".into(), |t| format!("{:.2}", t.1))));
        for i in 1..ncol {
            let rel = if points { v[i] - v[0] } else { (v[i] / v[0] - 1.0) * 100.0 };
            cols[i - 1].push(rel);
            let t = th.and_then(|t| t.2.get(i - 1).copied());
            s.push_str(&format!(" {:+.1}{unit} | {} |", rel, t.map_or("–".into(), |t| format!("{t:+.1}{unit}"))));
        }
        s.push('\n');
    }
    let pub_cols: Vec<Vec<f64>> =
        (0..ncol - 1).map(|i| published.iter().filter_map(|p| p.2.get(i).copied()).collect()).collect();
    for (label, sd) in [("Average", false), ("Std. Dev.", true)] {
        s.push_str(&format!("| {label} | | |"));
        for i in 0..ncol - 1 {
            let (m, d) = super::table_4_4::mean_sd(&cols[i]);
            let (pm, pd) = super::table_4_4::mean_sd(&pub_cols[i]);
            if sd {
                s.push_str(&format!(" {d:.1}{unit} | {pd:.1}{unit} |"));
            } else {
                s.push_str(&format!(" {m:+.1}{unit} | {pm:+.1}{unit} |"));
            }
        }
        s.push('\n');
    }
    s
}

/// Table 4.8 (a) (L2066–2119): inner nodes loaded through the texture path per
/// ray; columns 2-7 relative to column 1.
pub const TABLE_4_8A: [Published; 5] = [
    ("scene6", 7.31, &[-96.4, 0.0, 16.0, -96.4, -93.2, -94.3]),
    ("sponza", 29.81, &[-63.8, 0.0, 13.6, -63.8, -49.9, -52.0]),
    ("sibenik", 37.63, &[-60.9, 0.0, 11.1, -60.9, -43.8, -49.1]),
    ("fairy", 37.43, &[-62.6, 0.0, 13.0, -62.6, -52.5, -53.4]),
    ("conference", 19.57, &[-77.7, 0.0, 12.5, -77.7, -64.3, -68.9]),
];

/// Table 4.8 (b): stack entries accessed in local memory per ray.
pub const TABLE_4_8B: [Published; 5] = [
    ("scene6", 2.01, &[0.0, -88.7, 2.2, -88.7, -88.1, 2.2]),
    ("sponza", 12.31, &[0.0, -63.7, 8.9, -63.7, -48.1, 8.9]),
    ("sibenik", 14.46, &[0.0, -60.4, 5.0, -60.4, -37.1, 5.0]),
    ("fairy", 16.96, &[0.0, -68.6, 4.1, -68.6, -48.7, 4.1]),
    ("conference", 6.69, &[0.0, -74.1, 5.8, -74.1, -59.7, 5.8]),
];

/// Table 4.8 (c): texture cache hit ratios (%, differences in points).
pub const TABLE_4_8C: [Published; 5] = [
    ("scene6", 97.2, &[-0.3, 0.4, 0.1, -0.3, -0.4, -0.4]),
    ("sponza", 90.8, &[-1.6, 0.4, -0.4, -1.4, -1.6, -2.1]),
    ("sibenik", 90.1, &[-3.1, 0.3, 0.1, -2.6, -2.3, -2.5]),
    ("fairy", 86.3, &[-4.1, -0.1, -1.4, -4.0, -4.1, -5.6]),
    ("conference", 90.7, &[-2.0, -0.3, -1.2, -1.7, -2.1, -3.4]),
];

/// Table 4.8 (d): global memory bytes per ray, 8 × ((a) + (b)).
pub const TABLE_4_8D: [Published; 5] = [
    ("scene6", 74.51, &[-75.6, -19.1, 13.0, -94.7, -92.1, -73.5]),
    ("sponza", 336.95, &[-45.2, -18.6, 12.2, -63.8, -49.4, -34.2]),
    ("sibenik", 416.72, &[-44.0, -16.8, 9.4, -60.8, -41.9, -34.1]),
    ("fairy", 435.06, &[-43.1, -21.4, 10.2, -64.5, -51.3, -35.5]),
    ("conference", 210.03, &[-57.9, -18.9, 10.8, -76.8, -63.2, -49.9]),
];

/// Table 4.9 (L2123–2134): instructions per ray.
pub const TABLE_4_9: [Published; 5] = [
    ("scene6", 674.2, &[7.7, 2.4, 11.8, 8.7, 17.1, 18.8]),
    ("sponza", 2249.9, &[12.8, 4.1, 44.2, 14.7, 23.3, 58.3]),
    ("sibenik", 2294.9, &[15.2, 4.6, 39.6, 17.2, 26.1, 55.7]),
    ("fairy", 3129.6, &[13.5, 4.6, 91.5, 15.9, 25.8, 110.7]),
    ("conference", 2246.2, &[8.5, 2.5, 53.6, 9.3, 17.3, 63.4]),
];
