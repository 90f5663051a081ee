//! Grid photon map B (seed 004 §2.2.2, Fig. 5): stencil routing. Each cell
//! owns `slots` (m²) slots; one routing pass keeps the first m² photons of
//! every cell in draw order (photon index order), whatever the schedule, and
//! counts the photons destined to it; one fill pass copies the routed photons
//! into the cells' blocks with each cell's power redistribution factor
//! (destined / stored, 004:L124).

use super::bitonic::BUILD_MAP;
use super::grid::Grid;
use super::passes::{Kernels, Passes};
use super::photons::PhotonArrays;
use crate::sim::{Arg, DevicePtr, SimError};

/// A grid photon map built by stencil routing.
#[derive(Debug, Clone, Copy)]
pub struct StencilMap {
    /// The grid.
    pub grid: Grid,
    /// Slots per cell (m²).
    pub slots: usize,
    /// Per cell slot, the routed photon's slot in the photon arrays (`u32::MAX`: empty).
    pub cell_slots: DevicePtr,
    /// Photons destined to each cell.
    pub destined: DevicePtr,
    /// Per cell slot, the photon's position, power and incoming direction.
    pub pos: DevicePtr,
    /// Power.
    pub pow: DevicePtr,
    /// Incoming direction.
    pub dir: DevicePtr,
    /// Photons stored per cell (min(destined, m²)).
    pub stored: DevicePtr,
    /// Power redistribution factor per cell.
    pub scale: DevicePtr,
}

/// What routing kept and lost, read back from the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Occupancy {
    /// Photons drawn (valid photons).
    pub destined: u64,
    /// Photons stored.
    pub stored: u64,
    /// Cells that overflowed (more than m² photons destined).
    pub overflowing_cells: u64,
}

impl Occupancy {
    /// Photons dropped by overflowing cells.
    pub fn lost(&self) -> u64 {
        self.destined - self.stored
    }
}

/// Builds map B over the stored slots of `ph` with `slots` photons per cell:
/// the routing pass and the fill pass, in phase [`BUILD_MAP`]. The slots
/// start empty (the stencil initialisation, a host upload here).
pub fn build(passes: &mut Passes, grid: Grid, ph: &PhotonArrays, slots: usize) -> Result<StencilMap, SimError> {
    let cells = grid.cells();
    let (first, count) = ph.stored_slots();
    let cell_slots = passes.upload(&vec![u32::MAX; cells * slots])?;
    let destined = passes.dev.alloc_zeroed::<u32>(cells);
    passes.launch_1d(
        BUILD_MAP,
        Kernels::Grid,
        "stencil_route",
        count,
        &[
            grid.arg(),
            Arg::Ptr(ph.pos),
            Arg::I32(first as i32),
            Arg::I32(count as i32),
            Arg::I32(slots as i32),
            Arg::Ptr(cell_slots),
            Arg::Ptr(destined),
        ],
    )?;
    let pos = passes.dev.alloc_zeroed::<f32>(4 * cells * slots);
    let pow = passes.dev.alloc_zeroed::<f32>(4 * cells * slots);
    let dir = passes.dev.alloc_zeroed::<f32>(4 * cells * slots);
    let stored = passes.dev.alloc_zeroed::<u32>(cells);
    let scale = passes.dev.alloc_zeroed::<f32>(cells);
    passes.launch_1d(
        BUILD_MAP,
        Kernels::Grid,
        "stencil_fill",
        cells * slots,
        &[
            Arg::Ptr(cell_slots),
            Arg::Ptr(destined),
            Arg::I32(cells as i32),
            Arg::I32(slots as i32),
            Arg::Ptr(ph.pos),
            Arg::Ptr(ph.pow),
            Arg::Ptr(ph.dir),
            Arg::Ptr(pos),
            Arg::Ptr(pow),
            Arg::Ptr(dir),
            Arg::Ptr(stored),
            Arg::Ptr(scale),
        ],
    )?;
    Ok(StencilMap { grid, slots, cell_slots, destined, pos, pow, dir, stored, scale })
}

/// What the map kept and lost.
pub fn occupancy(passes: &Passes, map: &StencilMap) -> Occupancy {
    let cells = map.grid.cells();
    let d = passes.dev.read::<u32>(map.destined, cells);
    let s = passes.dev.read::<u32>(map.stored, cells);
    Occupancy {
        destined: d.iter().map(|&x| x as u64).sum(),
        stored: s.iter().map(|&x| x as u64).sum(),
        overflowing_cells: d.iter().filter(|&&x| x as usize > map.slots).count() as u64,
    }
}
