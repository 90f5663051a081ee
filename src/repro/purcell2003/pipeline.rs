//! The whole pipeline of seed 004 on one scene, as Table 1 breaks it down:
//! trace photons, build the map (A: bitonic sort + binary search; B: stencil
//! routing), trace eye rays, the radiance estimate in 16 × 16 tiles; each
//! phase's counts from the emulator's counters.

use std::collections::BTreeMap;

use super::bitonic::{self, BUILD_MAP};
use super::grid::Grid;
use super::knn::{self, Map, Params, RADIANCE_ESTIMATE};
use super::passes::{Passes, PhaseCounts};
use super::photons::{self, Geometry, PhotonArrays, Queries, TRACE_PHOTONS, TRACE_RAYS};
use super::scenes::{EYE_DEPTH, Fixture, ITERS_PER_PASS, PILOT_SEED, SEED, emitted_for, fixture};
use super::stencil;
use crate::host::scene::Scene;
use crate::repro::registry::{MeasureError, Tick, Workspace};
use crate::repro::results::Sample;

/// Measurement group: the pipeline with both maps.
pub const PIPELINE: &str = "purcell/pipeline";

/// The two map methods, in Table 1's order, with their variant names in the results.
pub const METHODS: [&str; 2] = ["bitonic", "stencil"];

/// Most radiance-estimate passes before a run is cut off (the estimate then
/// reports itself unfinished).
pub const MAX_PASSES: u64 = 4_000;

/// Watchdog of the pipeline's launches (warp instructions per launch).
const WATCHDOG: u64 = 1 << 36;

/// A scene traced, with its photons and query points, ready for the maps.
pub struct Prepared {
    /// The kernels and their counters.
    pub passes: Passes,
    /// The scene's settings.
    pub fixture: Fixture,
    /// The photons.
    pub photons: PhotonArrays,
    /// The query points.
    pub queries: Queries,
    /// The grid.
    pub grid: Grid,
    /// Direct light per pixel from the shadow rays (r, g, b, 0).
    pub direct: crate::sim::DevicePtr,
}

/// The image of `scene` for an image `width` pixels wide (the paper's aspect).
pub fn camera(scene: &Scene, f: &Fixture, width: u32) -> crate::host::camera::Camera {
    let mut c = scene.camera;
    let h = (width as u64 * f.paper_resolution[1] as u64 / f.paper_resolution[0] as u64).max(1) as u32;
    c.resolution = [width, h];
    c
}

/// The fixture of `scene`, or an error naming it.
pub fn fixture_of(scene: &Scene) -> Result<Fixture, MeasureError> {
    Ok(*fixture(&scene.name).ok_or_else(|| format!("seed 004 has no scene {}", scene.name))?)
}

/// Traces the photons, the eye rays and the shadow rays of `scene` (`width`
/// pixels wide) with its fixture.
pub fn prepare(scene: &Scene, width: u32) -> Result<Prepared, MeasureError> {
    prepare_with(scene, &fixture_of(scene)?, width)
}

/// [`prepare`] with the settings `f` (the scene's fixture, or a reduced one:
/// [`Fixture::reduced`]). The map holds indirect light and caustics: photons
/// that land straight from the light are not stored, the shadow rays
/// (`f.shadow_samples` per pixel) giving direct light.
pub fn prepare_with(scene: &Scene, f: &Fixture, width: u32) -> Result<Prepared, MeasureError> {
    prepare_configured(scene, f, width, &|_| {})
}

/// [`prepare_with`] on a device whose settings `set` adjusts
/// ([`Passes::configured`]).
pub fn prepare_configured(
    scene: &Scene,
    f: &Fixture,
    width: u32,
    set: &dyn Fn(&mut crate::sim::SimConfig),
) -> Result<Prepared, MeasureError> {
    let f = *f;
    let geo = Geometry::of(scene);
    let mut passes = Passes::configured(Some(WATCHDOG), set)?;
    // calibration: a pilot run's share of stored photons sets the emitted count
    let pilot = photons::trace(&mut passes, &geo, f.pilot, f.bounces, PILOT_SEED, false)?;
    let pilot_stored = pilot.count_stored(&passes);
    passes.take_phase(TRACE_PHOTONS);
    let emitted = emitted_for(f.stated_photons, f.pilot, pilot_stored);
    let photons = photons::trace(&mut passes, &geo, emitted, f.bounces, SEED, false)?;
    let queries = photons::eye_rays(&mut passes, &geo, &camera(scene, &f, width), EYE_DEPTH)?;
    let direct = photons::shadow_rays(&mut passes, &geo, &queries, f.shadow_samples, SEED)?;
    let grid = Grid::new(geo.lo, geo.hi, f.grid);
    Ok(Prepared { passes, fixture: f, photons, queries, grid, direct })
}

/// The radiance estimate's parameters for fixture `f`, drawn as tiles.
pub fn params(f: &Fixture) -> Params {
    Params { k: f.k, r_max: f.r_max, iters: ITERS_PER_PASS, tiled: true }
}

fn put(c: &mut BTreeMap<String, f64>, prefix: &str, p: &PhaseCounts) {
    c.insert(format!("{prefix}.launches"), p.launches as f64);
    c.insert(format!("{prefix}.thread_instructions"), p.thread_instructions as f64);
    c.insert(format!("{prefix}.warp_instructions"), p.warp_instructions as f64);
    c.insert(format!("{prefix}.lane_loads"), p.lane_loads as f64);
    c.insert(format!("{prefix}.lane_stores"), p.lane_stores as f64);
    c.insert(format!("{prefix}.lane_atomics"), p.lane_atomics as f64);
}

/// Measurement group [`PIPELINE`]: both maps on the workspace's scene.
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let f = fixture_of(ws.scene)?;
    measure_with(ws, &f, tick)
}

/// [`measure`] with the settings `f`.
pub fn measure_with(ws: &mut Workspace, f: &Fixture, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    let mut pr = prepare_with(ws.scene, f, ws.resolution)?;
    let trace = pr.passes.take_phase(TRACE_PHOTONS);
    let rays = pr.passes.take_phase(TRACE_RAYS);
    let npix = (pr.queries.width * pr.queries.height) as usize;
    let stored = pr.photons.count_stored(&pr.passes);
    let p = params(&pr.fixture);
    let mut out = Vec::new();
    for method in METHODS {
        tick(Tick { frame: None, variant: method });
        let mut c = BTreeMap::new();
        let est = if method == "bitonic" {
            let map = bitonic::build(&mut pr.passes, pr.grid, &pr.photons)?;
            c.insert("sort_elements".into(), map.n as f64);
            knn::estimate(&mut pr.passes, &Map::Bitonic(&map, &pr.photons), &pr.queries, &p, MAX_PASSES)?
        } else {
            let map = stencil::build(&mut pr.passes, pr.grid, &pr.photons, pr.fixture.slots)?;
            let occ = stencil::occupancy(&pr.passes, &map);
            c.insert("stencil_stored".into(), occ.stored as f64);
            c.insert("stencil_lost".into(), occ.lost() as f64);
            c.insert("stencil_overflowing_cells".into(), occ.overflowing_cells as f64);
            knn::estimate(&mut pr.passes, &Map::Stencil(&map), &pr.queries, &p, MAX_PASSES)?
        };
        let build = pr.passes.take_phase(BUILD_MAP);
        let re = pr.passes.take_phase(RADIANCE_ESTIMATE);
        put(&mut c, "trace_photons", &trace);
        put(&mut c, "trace_rays", &rays);
        put(&mut c, "build_map", &build);
        put(&mut c, "radiance_estimate", &re);
        let used: Vec<i32> = est.states.iter().map(|s| s.used).collect();
        let (w, h) = (pr.queries.width, pr.queries.height);
        c.insert("re.lane_iterations".into(), est.lane_iterations as f64);
        c.insert(
            "re.predicted_tiled_lane_iterations".into(),
            knn::predicted_lane_iterations(&used, w, h, p.iters, Some(knn::TILE)) as f64,
        );
        c.insert(
            "re.single_quad_lane_iterations".into(),
            knn::predicted_lane_iterations(&used, w, h, p.iters, None) as f64,
        );
        c.insert("re.lookups".into(), used.iter().map(|&u| u as f64).sum());
        c.insert("re.finished".into(), f64::from(u8::from(est.finished)));
        c.insert("pixels".into(), npix as f64);
        c.insert("width".into(), w as f64);
        c.insert("height".into(), h as f64);
        c.insert("emitted".into(), pr.photons.n as f64);
        c.insert("stored".into(), stored as f64);
        c.insert("shadow_samples".into(), pr.fixture.shadow_samples as f64);
        c.insert("found_k".into(), est.states.iter().filter(|s| s.n as u32 >= p.k).count() as f64);
        out.push(Sample {
            group: PIPELINE.into(),
            scene: ws.scene.name.clone(),
            frame: None,
            variant: method.into(),
            counters: c,
        });
    }
    Ok(out)
}
