//! The 2003-faithful kNN-grid radiance estimate (`knn_bitonic_2003`,
//! `knn_stencil_2003` in `kernels/purcell2003/knn.cu`): the natural kernels'
//! search with fp30's constraints that Table 2's Addr and Pack columns count
//! (004:L199–203): every array a 2-D float texture addressed by
//! `convert1dto2d` in float arithmetic, and the search state packed into one
//! float4 (a fragment program's 128-bit output) that is unpacked and packed
//! again around every iteration.

use super::grid::Grid;
use super::knn::{self, Estimate, Map, Params, State};
use super::passes::Passes;
use super::photons::Queries;
use crate::sim::{Arg, DevicePtr, LaunchStats, SimError};

/// Texels per row of the 2-D float textures (the paper's 1024 × 1024 buffers).
pub const TEXTURE_WIDTH: u32 = 1024;

/// Most cells per axis the packed state can address (8 bits per coordinate).
pub const MAX_CELLS_PER_AXIS: u32 = 256;

/// Most photons in one cell (the slot counter's 16 bits).
pub const MAX_PHOTONS_PER_CELL: u32 = 65_535;

/// Why a map cannot be searched by the 2003-faithful kernels.
#[derive(Debug, thiserror::Error)]
pub enum Error2003 {
    /// A grid axis has more cells than the packed state addresses.
    #[error(
        "grid of {dims:?} cells: the 2003-faithful estimate packs cell coordinates into 8 bits (at most 256 per axis)"
    )]
    GridTooLarge {
        /// The grid's cells per axis.
        dims: [u32; 3],
    },
    /// A cell holds more photons than the packed slot counter counts.
    #[error("a cell of the map holds {0} photons: the 2003-faithful estimate counts at most 65,535 per cell")]
    CellTooFull(u32),
    /// The emulator failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// A map's arrays as float textures (indices as floats).
#[derive(Debug, Clone, Copy)]
pub struct Textures {
    /// Map A: per cell its first element (float); map B: photons stored per cell (float).
    pub per_cell: DevicePtr,
    /// Map A: the sorted elements as float2 (cell, photon slot; -1 for none).
    pub sorted: DevicePtr,
    /// Map A: elements.
    pub sorted_n: usize,
}

/// The float textures of `map` (a host conversion of its integer arrays,
/// standing for the 2003 layout where every texture holds floats).
pub fn textures(passes: &mut Passes, map: &Map) -> Result<Textures, Error2003> {
    let grid = grid_of(map);
    if grid.dims.iter().any(|&d| d > MAX_CELLS_PER_AXIS) {
        return Err(Error2003::GridTooLarge { dims: grid.dims });
    }
    let cells = grid.cells();
    match map {
        Map::Bitonic(m, _) => {
            let first = passes.dev.read::<u32>(m.first, cells + 1);
            if let Some(w) = first.windows(2).map(|w| w[1] - w[0]).max().filter(|&w| w > MAX_PHOTONS_PER_CELL) {
                return Err(Error2003::CellTooFull(w));
            }
            let firstf: Vec<f32> = first.iter().map(|&x| x as f32).collect();
            let sorted = passes.dev.read::<u32>(m.sorted, 2 * m.n);
            let sortedf: Vec<f32> = sorted
                .chunks_exact(2)
                .flat_map(|e| [e[0] as f32, if e[1] == u32::MAX { -1.0 } else { e[1] as f32 }])
                .collect();
            Ok(Textures { per_cell: passes.upload(&firstf)?, sorted: passes.upload(&sortedf)?, sorted_n: m.n })
        }
        Map::Stencil(m) => {
            let stored = passes.dev.read::<u32>(m.stored, cells);
            let storedf: Vec<f32> = stored.iter().map(|&x| x as f32).collect();
            let per_cell = passes.upload(&storedf)?;
            Ok(Textures { per_cell, sorted: per_cell, sorted_n: 0 })
        }
    }
}

fn grid_of(map: &Map) -> Grid {
    match map {
        Map::Bitonic(m, _) => m.grid,
        Map::Stencil(m) => m.grid,
    }
}

/// The query point's cell per axis, as the kernels compute it.
fn base_cell(grid: &Grid, q: [f32; 3]) -> [i32; 3] {
    let inv = grid.inv().to_array();
    let lo = grid.lo.to_array();
    [0, 1, 2].map(|a| (((q[a] - lo[a]) * inv[a]).floor() as i64).clamp(0, grid.dims[a] as i64 - 1) as i32)
}

/// The packed state of a pixel that has not started: its query point's cell,
/// or finished at once where there is no query point.
pub fn start(grid: &Grid, query: Option<[f32; 3]>) -> [u32; 4] {
    match query {
        None => [1 << 24, 0, 0, 0],
        Some(q) => {
            let b = base_cell(grid, q);
            [b[0] as u32 | (b[1] as u32) << 8 | (b[2] as u32) << 16, 0, 0, 0]
        }
    }
}

/// A packed state read back as a [`State`] (the kernel's `unpack`; `used` is
/// not kept by the packed state and reads 0).
pub fn unpack(w: [u32; 4], base: [i32; 3]) -> State {
    let cell = [w[0] & 0xff, (w[0] >> 8) & 0xff, (w[0] >> 16) & 0xff].map(|c| c as i32);
    let d = [0, 1, 2].map(|a| cell[a] - base[a]);
    let e = w[2] >> 24;
    let unit = if e >= 12 { f32::from_bits((e - 11) << 23) } else { 0.0 };
    State {
        sum: [(w[2] & 0xfff) as f32 * unit, ((w[2] >> 12) & 0xfff) as f32 * unit, (w[3] & 0xfff) as f32 * unit],
        r: half::f16::from_bits((w[3] >> 16) as u16).to_f32(),
        n: (w[1] >> 16) as i32,
        ring: d.iter().map(|x| x.abs()).max().unwrap_or(0),
        cell: d,
        local: (w[1] & 0xffff) as i32,
        done: (w[0] >> 24) & 1 != 0,
        used: 0,
    }
}

/// The packed state buffer for the queries `q` over `grid`.
pub fn start_states(passes: &mut Passes, q: &Queries, grid: &Grid) -> Result<DevicePtr, SimError> {
    let npix = (q.width * q.height) as usize;
    let query = passes.dev.read::<f32>(q.query, 4 * npix);
    let words: Vec<u32> = (0..npix)
        .flat_map(|i| {
            let p = &query[4 * i..4 * i + 4];
            start(grid, (p[3] != 0.0).then_some([p[0], p[1], p[2]]))
        })
        .collect();
    passes.upload(&words)
}

/// The kernel of `map`.
pub fn kernel(map: &Map) -> &'static str {
    match map {
        Map::Bitonic(..) => "knn_bitonic_2003",
        Map::Stencil(_) => "knn_stencil_2003",
    }
}

/// One pass of the 2003-faithful estimate over the packed state buffer `state`.
pub fn pass(
    passes: &mut Passes,
    phase: &str,
    map: &Map,
    tex: &Textures,
    q: &Queries,
    p: &Params,
    state: DevicePtr,
) -> Result<LaunchStats, SimError> {
    let lists = match map {
        Map::Bitonic(..) => vec![Arg::Ptr(tex.per_cell), Arg::Ptr(tex.sorted), Arg::F32(tex.sorted_n as f32)],
        Map::Stencil(_) => vec![Arg::Ptr(tex.per_cell)],
    };
    let head = vec![knn::search_arg(map, p), Arg::F32(TEXTURE_WIDTH as f32)];
    knn::launch_pass(passes, phase, kernel(map), map, head, q, state, lists)
}

/// Reads the packed state buffer back.
pub fn states(passes: &Passes, state: DevicePtr, q: &Queries, grid: &Grid) -> Vec<State> {
    let npix = (q.width * q.height) as usize;
    let query = passes.dev.read::<f32>(q.query, 4 * npix);
    let w = passes.dev.read::<u32>(state, 4 * npix);
    (0..npix)
        .map(|i| {
            let b = base_cell(grid, [query[4 * i], query[4 * i + 1], query[4 * i + 2]]);
            unpack([w[4 * i], w[4 * i + 1], w[4 * i + 2], w[4 * i + 3]], b)
        })
        .collect()
}

/// Runs the 2003-faithful estimate to completion (at most `max_passes`
/// launches) in phase [`knn::RADIANCE_ESTIMATE`].
pub fn estimate(
    passes: &mut Passes,
    map: &Map,
    q: &Queries,
    p: &Params,
    max_passes: u64,
) -> Result<Estimate, Error2003> {
    let grid = grid_of(map);
    let tex = textures(passes, map)?;
    let state = start_states(passes, q, &grid)?;
    knn::run_passes(
        passes,
        max_passes,
        &mut |ps| Ok(pass(ps, knn::RADIANCE_ESTIMATE, map, &tex, q, p, state)?),
        &|ps| states(ps, state, q, &grid),
        &mut |_, _| {},
    )
}
