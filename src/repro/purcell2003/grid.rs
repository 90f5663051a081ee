//! The uniform grid of the photon maps (seed 004 §2.2): a box split into
//! `nx × ny × nz` cells, as the kernels' `Grid` structure lays it out.

use glam::Vec3;

use super::passes::Bytes;
use crate::sim::Arg;

/// A uniform grid over a box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Lower corner.
    pub lo: Vec3,
    /// Upper corner.
    pub hi: Vec3,
    /// Cells per axis.
    pub dims: [u32; 3],
}

impl Grid {
    /// A grid of `dims` cells over the box [`lo`, `hi`], widened by a small
    /// margin so that points on the box's faces fall inside.
    pub fn new(lo: Vec3, hi: Vec3, dims: [u32; 3]) -> Grid {
        let m = (hi - lo).max(Vec3::splat(1e-3)) * 1e-3;
        Grid { lo: lo - m, hi: hi + m, dims }
    }

    /// Cells.
    pub fn cells(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Cell size per axis.
    pub fn size(&self) -> Vec3 {
        (self.hi - self.lo) / Vec3::new(self.dims[0] as f32, self.dims[1] as f32, self.dims[2] as f32)
    }

    /// Inverse cell size per axis.
    pub fn inv(&self) -> Vec3 {
        Vec3::ONE / self.size()
    }

    /// The cell of point `p` (clamped into the grid), as the kernels compute it.
    pub fn cell_of(&self, p: Vec3) -> u32 {
        let inv = self.inv();
        let c = |a: usize, x: f32, lo: f32, i: f32| {
            (((x - lo) * i).floor() as i64).clamp(0, self.dims[a] as i64 - 1) as u32
        };
        let (x, y, z) = (c(0, p.x, self.lo.x, inv.x), c(1, p.y, self.lo.y, inv.y), c(2, p.z, self.lo.z, inv.z));
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// Its fields in the order of the kernels' `Grid` (lower corner, inverse
    /// size, cells per axis and in all).
    pub fn fields(&self) -> Bytes {
        let inv = self.inv();
        Bytes::default().f32s(&[self.lo.x, self.lo.y, self.lo.z, 0.0, inv.x, inv.y, inv.z, 0.0]).i32s(&[
            self.dims[0] as i32,
            self.dims[1] as i32,
            self.dims[2] as i32,
            self.cells() as i32,
        ])
    }

    /// The kernels' `Grid` argument.
    pub fn arg(&self) -> Arg {
        self.fields().arg()
    }
}
