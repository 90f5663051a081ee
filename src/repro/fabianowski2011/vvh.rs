//! The VVH photon map beside the LBVH (thesis 000 §6.1, Tables 6.1–6.3): one
//! measurement group builds both over Table 5.1's kernels, with n_auto and
//! with the fixed leaf-size thresholds 1, 2, 4, …, 128 of Table 6.1, and
//! gathers through each (the complete layout, [`super::pm_layout::gather`],
//! bit for bit `pmgather.cu`'s walk, `tests/photon_bvh.rs`) at the query points
//! of each frame: n_T (nodes tested) and n_I (interactions retrieved) per
//! query point, node counts per tree.
//!
//! The VVH is [`super::sah::Params::vvh`]: eq. 6.2 with eq. 6.3's volume
//! probabilities, C_T = 0, C_I = 1, a leaf at n_P ≤ threshold, depth at most
//! 64 (L2619, L2625), built serially on the host as the thesis does.

use super::lbvh;
use super::photon_image;
use super::pm_layout::{self, Layout, Layouts, PmTree};
use super::sah;
use super::table_6_4::{vkde_maps, vkde_maps_with};
use super::timing;
use super::vkde::{Kernel, Shape};
use crate::host::kdtree::Heuristic;
use crate::host::raycast::Caster;
use crate::repro::registry::{MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::sim::Device;

/// The stage name of a frame's timing counters in [`PM_BUILDERS`]' samples:
/// `raytrace.cu`'s camera rays and `pmgather.cu`'s gather through the
/// complete layout of the variant's photon map, on the emulator.
pub const FRAME: &str = "render";

/// The modelled frame rate of `variant` of row `row` (the camera rays and the
/// gather at 512 x 512 on the GTX 280, one persistent launch at chapter 4's 54
/// registers), NaN when measured without the timing counters.
pub fn frame_rate(r: &Results, row: &str, variant: &str) -> f64 {
    timing::stage_fps(
        r,
        PM_BUILDERS,
        row,
        variant,
        FRAME,
        timing::THESIS_RESOLUTION,
        timing::persistent(timing::REGISTERS),
    )
}

/// What the frame-rate columns of Tables 6.1 and 6.3 model, for their notes.
pub fn fps_note() -> String {
    format!(
        "Modelled FPS: {}. A frame is the thesis' (§A.2): ray tracing and density estimation at 512 x 512, here \
         raytrace.cu's stack kernel for the camera, reflection and shadow rays plus pmgather.cu through the complete \
         layout of the variant's photon map on the emulator (the extract infers the thesis measured Tables 6.1-6.3 \
         with the compact one), their counters of each frame summed and predicted as one persistent launch (30 CTAs \
         x 256 threads, 54 registers). Absolute FPS within {}, relative columns within {}.",
        timing::describe(),
        timing::FPS_TOLERANCE.describe(),
        crate::repro::compare::Tolerance::RATIO.describe()
    )
}

/// Group: VVH and LBVH photon maps, gathered natively over the flight.
pub const PM_BUILDERS: &str = "fabianowski/pm-builders";

/// Table 6.1's fixed leaf-size thresholds.
pub const THRESHOLDS: [u32; 8] = [1, 2, 4, 8, 16, 32, 64, 128];

/// Which builder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Builder {
    /// The serial VVH (§6.1.1).
    Vvh,
    /// The LBVH with the dual merge (§6.1.2).
    Lbvh,
}

impl Builder {
    /// Both, in Table 6.1's order.
    pub const ALL: [Builder; 2] = [Builder::Vvh, Builder::Lbvh];

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Builder::Vvh => "vvh",
            Builder::Lbvh => "lbvh",
        }
    }
}

/// The variant name of `builder` at leaf threshold `threshold` (`None`: n_auto).
pub fn variant(builder: Builder, threshold: Option<u32>) -> String {
    match threshold {
        None => format!("{}-auto", builder.name()),
        Some(t) => format!("{}-{t}", builder.name()),
    }
}

/// The VVH over `kernels` with leaf threshold `threshold`.
pub fn build_vvh(kernels: &[Kernel], threshold: u32) -> PmTree {
    let boxes: Vec<sah::Bounds> = kernels.iter().map(|k| [k.lo, k.hi]).collect();
    sah::build(&boxes, &sah::Params::vvh(threshold as usize))
}

/// The tree of `builder` over `kernels` at `threshold`.
pub fn build(builder: Builder, kernels: &[Kernel], threshold: u32) -> PmTree {
    match builder {
        Builder::Vvh => build_vvh(kernels, threshold),
        Builder::Lbvh => lbvh::build(kernels, threshold).tree(),
    }
}

/// A scenario of §6.1.4 (L2623, "a wider range of image quality settings"):
/// a scene of Table 5.1 with another photon count and spread, a row of its
/// own in Tables 6.1–6.3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario {
    /// The scene it runs on.
    pub scene: &'static str,
    /// Its row's name in the tables (as [`super::table_6_2::THESIS`] names it).
    pub row: &'static str,
    /// Photons emitted.
    pub photons: usize,
    /// Spread s.
    pub spread: f32,
}

/// Tables 6.1–6.3's two scenarios: Scene 6 with 2^18 photons and s = 28,
/// Conference with 2^19 and s = 50 (the extract's §3.9 row reconciliation).
pub const SCENARIOS: [Scenario; 2] = [
    Scenario { scene: "scene6", row: "scene6 (2^18, s=28)", photons: 1 << 18, spread: 28.0 },
    Scenario { scene: "conference", row: "conference (2^19, s=50)", photons: 1 << 19, spread: 50.0 },
];

/// The rows of Tables 6.1–6.3 that `r` has: its scenes of [`PM_BUILDERS`],
/// each followed by its scenario's row where that was run (the thesis'
/// order).
pub fn rows(r: &Results) -> Vec<String> {
    let has = |row: &str| r.samples.iter().any(|s| s.group == PM_BUILDERS && s.scene == row);
    let mut v = Vec::new();
    for s in super::scenes_of(r, PM_BUILDERS) {
        let scenario = SCENARIOS.iter().find(|c| c.scene == s).filter(|c| has(c.row)).map(|c| c.row.to_string());
        v.push(s);
        v.extend(scenario);
    }
    v
}

/// [`super::run_note`] for `rows`, naming the scenes run (a scenario's row
/// runs with its scene, [`scenario_note`]).
pub fn run_note(r: &crate::repro::results::Results, rows: &[String], what: &str) -> String {
    let scenes: Vec<String> = rows.iter().filter(|s| !SCENARIOS.iter().any(|c| c.row == *s)).cloned().collect();
    super::run_note(r, &scenes, what)
}

/// The note on the scenarios' rows.
pub fn scenario_note(rows: &[String]) -> String {
    let run: Vec<&str> = SCENARIOS.iter().filter(|c| rows.iter().any(|r| r == c.row)).map(|c| c.row).collect();
    format!(
        "The scenarios of §6.1.4 (Scene 6 with 2^18 photons and s = 28, Conference with 2^19 and s = 50) run with \
         their scene: the same flight, query points and builders over the photon maps of their photon count and \
         spread; {}.",
        if run.is_empty() { "none was run here".to_string() } else { format!("rows run: {}", run.join(", ")) }
    )
}

/// Measurement group [`PM_BUILDERS`]: the scene with Table 5.1's photons and
/// spread, and, for Scene 6 and Conference, their [`SCENARIOS`] as rows of
/// their own.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let maps = vkde_maps(ws)?;
    let name = ws.scene.name.clone();
    let mut out = measure_maps(ws, maps, &name, tick)?;
    for c in SCENARIOS.iter().filter(|c| c.scene == ws.scene.name) {
        let maps = vkde_maps_with(ws, c.photons, c.spread)?;
        out.extend(measure_maps(ws, maps, c.row, tick)?);
    }
    Ok(out)
}

/// The stage name of the LBVH build's timing counters (`lbvh@...`, [`super::table_6_6::grid_stage`]),
/// recorded once per row with the first frame of `lbvh-auto`.
pub const LBVH_BUILD: &str = "lbvh";

/// Both builders at n_auto and every threshold over `maps`, gathered at the
/// query points of each frame, recorded as row `row`.
fn measure_maps(
    ws: &mut Workspace,
    (maps, n_auto): (photon_image::PhotonMaps, u32),
    row: &str,
    tick: &mut dyn FnMut(Tick),
) -> Result<Vec<Sample>, MeasureError> {
    let tree = ws.tree(Heuristic::Siroh);
    let kernels = &maps.constructed.kernels;
    let mut maps_built = Vec::new();
    for b in Builder::ALL {
        for t in std::iter::once(None).chain(THRESHOLDS.map(Some)) {
            let started = std::time::Instant::now();
            let pm = build(b, kernels, t.unwrap_or(n_auto));
            let seconds = started.elapsed().as_secs_f64();
            let stats = pm.stats();
            maps_built.push((variant(b, t), Layouts::new(&pm, kernels), stats, seconds));
        }
    }
    let caster = Caster::new(ws.scene, tree);
    let mut dev = Device::new();
    let module = pm_layout::load(&mut dev)?;
    // Table 6.2's LBVH ms: the LBVH with n_auto built once by lbvh.cu on the
    // emulator, each launch under its own gt200 model, recorded by grid with
    // the first frame's sample
    let lbvh_module = lbvh::load(&mut dev)?;
    let (_, launches) =
        lbvh::build_kernel_per_launch(&mut dev, &lbvh_module, kernels, n_auto, crate::model::Profile::Gt200)?;
    let lbvh_build = super::table_6_6::by_grid(&lbvh_module.prog, &launches);
    let lbvh_auto = variant(Builder::Lbvh, None);
    let mut out = Vec::new();
    for f in ws.frames.clone() {
        let cam = super::flight::camera(ws.scene, f, ws.resolution);
        let q = photon_image::queries(&caster, &cam);
        let queries = q.iter().flatten().count() as f64;
        // the frame's camera rays, the same for every photon map
        let rays = timing::camera_rays(ws.scene, tree, &cam, [0.0; 3])?;
        for (name, layouts, stats, seconds) in &maps_built {
            tick(Tick { frame: Some(f), variant: name });
            let (_, walk) = pm_layout::gather_all(layouts, Layout::Complete, &q, Shape::Uniform);
            // the frame's timing counters: the camera rays and the gather through this map on the emulator
            let g = pm_layout::gather_kernel(&mut dev, &module, layouts, Layout::Complete, &q, Shape::Uniform)?;
            let mut frame = rays;
            frame.add(&timing::counts_of(&module.prog, &g.launch, &g.memory));
            let c = [
                ("queries", queries),
                ("n_t", walk.nodes as f64),
                ("n_i", walk.retrieved as f64),
                ("nodes", (stats.inner + stats.leaves) as f64),
                ("leaves", stats.leaves as f64),
                ("depth", stats.depth as f64),
                ("interactions", kernels.len() as f64),
                ("n_auto", n_auto as f64),
                ("build_seconds", *seconds),
            ];
            let mut c: Vec<(String, f64)> = c.iter().map(|(n, v)| (n.to_string(), *v)).collect();
            timing::record(&mut c, FRAME, &frame);
            if *name == lbvh_auto && f == ws.frames.start {
                for (shape, counts) in &lbvh_build {
                    timing::record(&mut c, &super::table_6_6::grid_stage(LBVH_BUILD, shape), counts);
                }
            }
            out.push(Sample {
                group: PM_BUILDERS.into(),
                scene: row.to_string(),
                frame: Some(f),
                variant: name.clone(),
                counters: c.into_iter().collect(),
            });
        }
    }
    Ok(out)
}

/// One variant's values for one scene: per query point n_T and n_I, and per
/// frame the tree's nodes, the interactions and n_auto.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    /// Nodes tested per query point.
    pub n_t: f64,
    /// Interactions retrieved per query point.
    pub n_i: f64,
    /// Nodes of the tree (inner and leaves).
    pub nodes: f64,
    /// Stored interactions (kernels).
    pub interactions: f64,
    /// n_auto.
    pub n_auto: f64,
}

/// The values of `variant` of `scene` in `r`.
pub fn measured(r: &crate::repro::results::Results, scene: &str, variant: &str) -> Option<Measured> {
    let g = |c: &str| r.sum(PM_BUILDERS, scene, variant, c);
    let frames =
        r.samples.iter().filter(|s| s.group == PM_BUILDERS && s.scene == scene && s.variant == variant).count() as f64;
    let q = g("queries")?;
    Some(Measured {
        n_t: g("n_t")? / q,
        n_i: g("n_i")? / q,
        nodes: g("nodes")? / frames,
        interactions: g("interactions")? / frames,
        n_auto: g("n_auto")? / frames,
    })
}

/// The note naming how the photon maps of Tables 6.1–6.3 are made.
pub const HOW: &str = "Photon maps over Table 5.1's kernels (native photon tracing and construction, its emissions and \
     spread s per scene): the VVH of src/repro/fabianowski2011/sah.rs (eq. 6.2 with eq. 6.3's volume ratios, C_T = 0, \
     C_I = 1, a leaf at n_P <= threshold, depth <= 64, object partitions swept over the kernels' AABB centroids) and \
     the LBVH with the dual merge (bit for bit lbvh.cu's); n_T and n_I counted by the native walk of the complete \
     layout (bit for bit pmgather.cu's) at the primary and reflection hits of each frame. n_auto follows §6.1.3 as \
     printed, and ours is far above the thesis' (see Table 6.4's note), so our leaves are larger.";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repro::results::{Results, Sample};

    /// A scenario's row is compared only if its name is the printed row's:
    /// every table that shows it prints a row of that name, its scene is a
    /// scene of Table 5.1, and the scenario doubles (Scene 6) or quadruples
    /// (Conference) that scene's emissions, as §6.1.4 says.
    #[test]
    fn every_scenario_names_a_printed_row_of_tables_6_1_to_6_3() {
        for c in SCENARIOS {
            for (t, p) in [
                ("6.1a", &super::super::table_6_1::THESIS_A),
                ("6.1b", &super::super::table_6_1::THESIS_B),
                ("6.2", &super::super::table_6_2::THESIS),
                ("6.3", &super::super::table_6_3::THESIS),
            ] {
                assert!(p.row(c.row).is_some(), "Table {t} prints no row {:?}", c.row);
            }
            let (photons, _) = super::super::table_5_1::parameters(c.scene).expect("a scene of Table 5.1");
            assert_eq!(c.photons / photons, if c.scene == "scene6" { 2 } else { 4 }, "{c:?}");
        }
    }

    /// The scenario's row follows its scene, and only where it was run.
    #[test]
    fn rows_put_a_run_scenario_after_its_scene() {
        let sample = |scene: &str| Sample {
            group: PM_BUILDERS.into(),
            scene: scene.into(),
            frame: Some(0),
            variant: variant(Builder::Vvh, None),
            counters: Default::default(),
        };
        let mut r = Results::new("test", crate::repro::protocol::Protocol::quick(), Vec::new(), Vec::new());
        r.samples = vec![sample("conference"), sample("scene6"), sample("scene6 (2^18, s=28)")];
        assert_eq!(rows(&r), ["scene6", "scene6 (2^18, s=28)", "conference"]);
        assert!(run_note(&r, &rows(&r), "x").contains("Scenes: scene6"));
        assert!(!run_note(&r, &rows(&r), "x").contains("2^18"));
    }
}
