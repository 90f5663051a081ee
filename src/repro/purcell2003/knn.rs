//! The kNN-grid radiance estimate (seed 004 §2.3, Fig. 6) on either map:
//! `iters` photon lookups per launch, the search state carried between
//! launches, launches repeated until every pixel has finished. Drawn either
//! as one quad (every pixel in every pass) or as 16 × 16 tiles that stop
//! being drawn once all their pixels have finished (004:L213–217; the
//! occlusion query becomes a CTA-wide vote over shared memory).

use super::bitonic::BitonicMap;
use super::passes::{Kernels, Passes};
use super::photons::{PhotonArrays, Queries};
use super::stencil::StencilMap;
use crate::sim::{Arg, LaunchConfig, LaunchStats, Module, SimError};

/// Phase name of the radiance estimate.
pub const RADIANCE_ESTIMATE: &str = "radiance estimate";

/// Tile side (threads per CTA side) of the estimate's launches.
pub const TILE: u32 = 16;

/// Texture fetches of one iteration of `knn_bitonic` (first[c], first[c+1],
/// the sorted element, position, power, direction) and of `knn_stencil`
/// (stored, scale, position, power, direction), as the kernels make them.
pub const FETCHES: [u64; 2] = [6, 5];

/// The map the estimate searches.
#[derive(Debug, Clone, Copy)]
pub enum Map<'a> {
    /// Map A with the photon arrays its list points into.
    Bitonic(&'a BitonicMap, &'a PhotonArrays),
    /// Map B.
    Stencil(&'a StencilMap),
}

impl Map<'_> {
    /// Its kernel.
    pub fn kernel(&self) -> &'static str {
        match self {
            Map::Bitonic(..) => "knn_bitonic",
            Map::Stencil(_) => "knn_stencil",
        }
    }
}

/// The search's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Photons sought.
    pub k: u32,
    /// Maximum search radius.
    pub r_max: f32,
    /// Photon lookups per launch.
    pub iters: u32,
    /// Whether finished 16 × 16 tiles are not drawn.
    pub tiled: bool,
}

/// One pixel's search state (the kernels' `State`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// Accumulated photon power (rgb).
    pub sum: [f32; 3],
    /// Search radius.
    pub r: f32,
    /// Photons added.
    pub n: i32,
    /// Current ring.
    pub ring: i32,
    /// Current cell relative to the query's.
    pub cell: [i32; 3],
    /// Next slot in the current cell.
    pub local: i32,
    /// Finished.
    pub done: bool,
    /// Lookups made before finishing.
    pub used: i32,
}

/// Words of a [`State`] on the device.
pub const STATE_WORDS: usize = 12;

impl State {
    /// From the device's words.
    pub fn from_words(w: &[u32]) -> State {
        let f = |i: usize| f32::from_bits(w[i]);
        let i = |k: usize| w[k] as i32;
        State {
            sum: [f(0), f(1), f(2)],
            r: f(3),
            n: i(4),
            ring: i(5),
            cell: [i(6), i(7), i(8)],
            local: i(9),
            done: w[10] != 0,
            used: i(11),
        }
    }

    /// The initial state: finished at once where there is no query point.
    pub fn start(has_query: bool) -> [u32; STATE_WORDS] {
        let mut w = [0u32; STATE_WORDS];
        w[10] = u32::from(!has_query);
        w
    }
}

/// A finished (or stopped) estimate.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Per pixel state.
    pub states: Vec<State>,
    /// Launches (passes) made.
    pub passes: u64,
    /// Lane-iterations executed (lookups run by drawn pixels, finished or
    /// not), from the emulator's per-instruction counts.
    pub lane_iterations: u64,
    /// Whether every pixel finished within the pass limit.
    pub finished: bool,
    /// Thread instructions of the estimate's launches up to and including
    /// each pass (the emulator's counts): the progressive display's time axis.
    pub instructions_after: Vec<u64>,
}

/// Lane-iterations of one launch of the estimate: every iteration makes three
/// float4 fetches (`ld.global.v4.f32`: position, power, direction) and nothing
/// else in the kernels loads 16 bytes at once, so the guard-true lanes of those
/// instructions over 3 (from the emulator's per-instruction profile).
pub fn lane_iterations(module: &Module, s: &LaunchStats) -> u64 {
    let mut v4 = 0;
    for (f, counts) in s.profile.per_fn.iter().enumerate() {
        let info = &module.prog.functions[f].info;
        for (pc, c) in counts.iter().enumerate() {
            if info[pc].opcode.starts_with("ld.global.v4") {
                v4 += c.pred_on;
            }
        }
    }
    v4 / 3
}

/// The kernels' `Search` argument for `map` and `p`.
pub fn search_arg(map: &Map, p: &Params) -> Arg {
    let (grid, slots) = match map {
        Map::Bitonic(m, _) => (m.grid, 1),
        Map::Stencil(m) => (m.grid, m.slots),
    };
    let s = grid.size();
    let mut b = grid.fields();
    // insert the cell size after the inverse size: lo, inv, size, dims
    let dims = b.0.split_off(32);
    b = b.f32s(&[s.x, s.y, s.z, 0.0]);
    b.0.extend_from_slice(&dims);
    b.i32s(&[p.k as i32]).f32s(&[p.r_max]).i32s(&[p.iters as i32, i32::from(p.tiled), slots as i32, 0, 0, 0]).arg()
}

/// The launch configuration over a `w` × `h` image: 16 × 16 tiles.
pub fn tiles(w: u32, h: u32) -> LaunchConfig {
    LaunchConfig { grid: [w.div_ceil(TILE), h.div_ceil(TILE), 1], block: [TILE, TILE, 1], dynamic_shared: 0 }
}

/// The per-pixel state buffer, initialised.
pub fn start_states(passes: &mut Passes, q: &Queries) -> Result<crate::sim::DevicePtr, SimError> {
    let npix = (q.width * q.height) as usize;
    let query = passes.dev.read::<f32>(q.query, 4 * npix);
    let words: Vec<u32> = (0..npix).flat_map(|i| State::start(query[4 * i + 3] != 0.0)).collect();
    passes.upload(&words)
}

/// One pass of the estimate over the state buffer `state`.
pub fn pass(
    passes: &mut Passes,
    phase: &str,
    map: &Map,
    q: &Queries,
    p: &Params,
    state: crate::sim::DevicePtr,
) -> Result<LaunchStats, SimError> {
    let lists = match map {
        Map::Bitonic(m, _) => vec![Arg::Ptr(m.first), Arg::Ptr(m.sorted), Arg::I32(m.n as i32)],
        Map::Stencil(m) => vec![Arg::Ptr(m.stored)],
    };
    launch_pass(passes, phase, map.kernel(), map, vec![search_arg(map, p)], q, state, lists)
}

/// Launches the estimate kernel `kernel` (natural or 2003-faithful) over
/// `q`'s tiles. Its arguments: `head` (the search, and the 2003 texture
/// width), the query points, the state buffer, the image size, `lists` (map
/// A: first photons, sorted list, its length; map B: stored counts), then
/// the photon data of `map` (map A: position, power, direction; map B: the
/// redistribution factors and the cells' blocks).
#[allow(clippy::too_many_arguments)]
pub fn launch_pass(
    passes: &mut Passes,
    phase: &str,
    kernel: &str,
    map: &Map,
    mut args: Vec<Arg>,
    q: &Queries,
    state: crate::sim::DevicePtr,
    lists: Vec<Arg>,
) -> Result<LaunchStats, SimError> {
    args.extend([
        Arg::Ptr(q.query),
        Arg::Ptr(q.normal),
        Arg::Ptr(state),
        Arg::I32(q.width as i32),
        Arg::I32(q.height as i32),
    ]);
    args.extend(lists);
    match map {
        Map::Bitonic(_, ph) => args.extend([Arg::Ptr(ph.pos), Arg::Ptr(ph.pow), Arg::Ptr(ph.dir)]),
        Map::Stencil(m) => args.extend([Arg::Ptr(m.scale), Arg::Ptr(m.pos), Arg::Ptr(m.pow), Arg::Ptr(m.dir)]),
    }
    passes.launch(phase, Kernels::Knn, kernel, tiles(q.width, q.height), &args)
}

/// Reads the state buffer.
pub fn states(passes: &Passes, state: crate::sim::DevicePtr, npix: usize) -> Vec<State> {
    passes.dev.read::<u32>(state, STATE_WORDS * npix).chunks_exact(STATE_WORDS).map(State::from_words).collect()
}

/// Runs the estimate to completion (at most `max_passes` launches), in phase
/// [`RADIANCE_ESTIMATE`]. After each pass the host reads the finished flags
/// (the occlusion query's answer) and stops when every pixel has finished.
pub fn estimate(
    passes: &mut Passes,
    map: &Map,
    q: &Queries,
    p: &Params,
    max_passes: u64,
) -> Result<Estimate, SimError> {
    estimate_with(passes, map, q, p, max_passes, &mut |_, _| {})
}

/// [`estimate`], showing the running states after every pass to
/// `after_pass` (the pass number from 1, the states): the progressive
/// display (004:L142).
pub fn estimate_with(
    passes: &mut Passes,
    map: &Map,
    q: &Queries,
    p: &Params,
    max_passes: u64,
    after_pass: &mut dyn FnMut(u64, &[State]),
) -> Result<Estimate, SimError> {
    let npix = (q.width * q.height) as usize;
    let state = start_states(passes, q)?;
    run_passes(
        passes,
        max_passes,
        &mut |ps| pass(ps, RADIANCE_ESTIMATE, map, q, p, state),
        &|ps| states(ps, state, npix),
        after_pass,
    )
}

/// The host loop of an estimate (natural or 2003-faithful): launches
/// `launch` until every pixel of `read`'s states has finished (at most
/// `max_passes` launches), reading the finished flags after each pass (the
/// occlusion query's answer) and counting lane-iterations.
pub fn run_passes<E: From<SimError>>(
    passes: &mut Passes,
    max_passes: u64,
    launch: &mut dyn FnMut(&mut Passes) -> Result<LaunchStats, E>,
    read: &dyn Fn(&Passes) -> Vec<State>,
    after_pass: &mut dyn FnMut(u64, &[State]),
) -> Result<Estimate, E> {
    let mut n = 0;
    let mut lanes = 0;
    let mut instructions_after = Vec::new();
    let mut st = read(passes);
    while n < max_passes && st.iter().any(|s| !s.done) {
        let s = launch(passes)?;
        lanes += lane_iterations(passes.module(Kernels::Knn), &s);
        let before = instructions_after.last().copied().unwrap_or(0);
        instructions_after.push(before + s.totals.thread_instructions);
        n += 1;
        st = read(passes);
        after_pass(n, &st);
    }
    let finished = st.iter().all(|s| s.done);
    Ok(Estimate { states: st, passes: n, lane_iterations: lanes, finished, instructions_after })
}

/// Radiance towards the eye at each pixel: albedo / π · Σ power / (π r²),
/// r the search radius, or r_max where fewer than k photons lie within it.
pub fn radiance(e: &Estimate, albedo: &[f32], p: &Params) -> Vec<[f32; 3]> {
    radiance_of(&e.states, albedo, p)
}

/// [`radiance`] of final states `states` (`albedo`: 4 floats per pixel).
pub fn radiance_of(states: &[State], albedo: &[f32], p: &Params) -> Vec<[f32; 3]> {
    states
        .iter()
        .enumerate()
        .map(|(i, s)| {
            if s.n == 0 {
                return [0.0; 3];
            }
            let r = if (s.n as u32) < p.k { p.r_max } else { s.r.max(1e-6) };
            let area = std::f32::consts::PI * r * r;
            [0, 1, 2].map(|c| albedo[4 * i + c] / std::f32::consts::PI * s.sum[c] / area)
        })
        .collect()
}

/// The lane-iterations the estimate runs when drawn as tiles of `tile_side`²
/// pixels (or as one quad: `None`), from the per-pixel lookup counts `used`:
/// a tile is drawn in every pass until its slowest pixel finishes, and every
/// drawn pixel runs `iters` lookups per pass.
pub fn predicted_lane_iterations(used: &[i32], w: u32, h: u32, iters: u32, tile_side: Option<u32>) -> u64 {
    let passes_of = |u: i32| (u.max(0) as u64).div_ceil(iters as u64);
    match tile_side {
        None => {
            let p = used.iter().map(|&u| passes_of(u)).max().unwrap_or(0);
            p * (w as u64 * h as u64) * iters as u64
        }
        Some(t) => {
            let mut total = 0;
            for ty in 0..h.div_ceil(t) {
                for tx in 0..w.div_ceil(t) {
                    let mut p = 0;
                    let mut pixels = 0;
                    for y in ty * t..((ty + 1) * t).min(h) {
                        for x in tx * t..((tx + 1) * t).min(w) {
                            p = p.max(passes_of(used[(y * w + x) as usize]));
                            pixels += 1;
                        }
                    }
                    total += p * pixels * iters as u64;
                }
            }
            total
        }
    }
}
