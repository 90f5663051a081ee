//! Grid photon map A (seed 004 §2.2.1): photons sorted by cell with the
//! bitonic merge sort of Fig. 3, one launch per pass, then one binary-search
//! pass giving each cell its first photon (Fig. 4's grid and photon list).

use super::grid::Grid;
use super::passes::{Kernels, Passes};
use super::photons::PhotonArrays;
use crate::sim::{Arg, DevicePtr, LaunchConfig, SimError};

/// Phase name of the map build.
pub const BUILD_MAP: &str = "build map";

/// The passes of a bitonic sort of `n` elements (a power of two), in order:
/// (offset, stepno) with stage = 2 · offset. log2 n · (log2 n + 1) / 2 of them
/// (6 for 8 elements, 210 for 1024², 004:L102).
pub fn schedule(n: usize) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    let mut stepno = 2;
    while stepno <= n {
        let mut offset = stepno / 2;
        while offset >= 1 {
            v.push((offset as u32, stepno as u32));
            offset /= 2;
        }
        stepno *= 2;
    }
    v
}

/// What Fig. 3's program writes at element `e` of one pass over `input`
/// (the host's reference of one pass; keys are `.0`).
pub fn reference_pass(input: &[(u32, u32)], offset: usize, stepno: usize) -> Vec<(u32, u32)> {
    let stage = 2 * offset;
    (0..input.len())
        .map(|e| {
            let csign: i64 = if e % stage < offset { 1 } else { -1 };
            let cdir: i64 = if (e / stepno).is_multiple_of(2) { 1 } else { -1 };
            let v0 = input[e];
            let v1 = input[(e as i64 + csign * offset as i64) as usize];
            let cmin = if v0.0 < v1.0 { v0 } else { v1 };
            let cmax = if v0.0 > v1.0 { v0 } else { v1 };
            if csign == cdir { cmin } else { cmax }
        })
        .collect()
}

/// Sorts the `n` (cell, photon) elements in `a` (a power of two) by cell, one
/// launch of `bitonic_pass` per pass, ping-ponging with `b`; returns the
/// buffer holding the result.
pub fn sort(passes: &mut Passes, phase: &str, a: DevicePtr, b: DevicePtr, n: usize) -> Result<DevicePtr, SimError> {
    let (mut src, mut dst) = (a, b);
    for (offset, stepno) in schedule(n) {
        passes.launch_1d(
            phase,
            Kernels::Grid,
            "bitonic_pass",
            n,
            &[Arg::Ptr(src), Arg::Ptr(dst), Arg::I32(n as i32), Arg::I32(offset as i32), Arg::I32(stepno as i32)],
        )?;
        std::mem::swap(&mut src, &mut dst);
    }
    Ok(src)
}

/// Fig. 3 as the Cg program computes it (`bitonic_pass_2003`): float4
/// elements (key in `.y`) in a texture `width` texels wide, 2-D launches of
/// 16 × 16 threads; returns the buffer holding the result.
pub fn sort_2003(
    passes: &mut Passes,
    phase: &str,
    a: DevicePtr,
    b: DevicePtr,
    n: usize,
    width: usize,
) -> Result<DevicePtr, SimError> {
    let height = n / width;
    let cfg = LaunchConfig {
        grid: [(width as u32).div_ceil(16), (height as u32).div_ceil(16), 1],
        block: [16.min(width as u32), 16.min(height as u32), 1],
        dynamic_shared: 0,
    };
    let (mut src, mut dst) = (a, b);
    for (offset, stepno) in schedule(n) {
        passes.launch(
            phase,
            Kernels::Grid,
            "bitonic_pass_2003",
            cfg,
            &[
                Arg::Ptr(src),
                Arg::Ptr(dst),
                Arg::F32(width as f32),
                Arg::F32(offset as f32),
                Arg::F32(2.0 * offset as f32),
                Arg::F32(stepno as f32),
            ],
        )?;
        std::mem::swap(&mut src, &mut dst);
    }
    Ok(src)
}

/// A grid photon map built by sorting (Fig. 4).
#[derive(Debug, Clone, Copy)]
pub struct BitonicMap {
    /// The grid.
    pub grid: Grid,
    /// Sorted elements (cell, photon slot), `n` of them.
    pub sorted: DevicePtr,
    /// Elements (a power of two).
    pub n: usize,
    /// Per cell (and one past the last) its first element.
    pub first: DevicePtr,
    /// Stored photons (valid elements).
    pub photons: usize,
}

/// Elements to sort for `count` photon slots: the next power of two.
pub fn padded(count: usize) -> usize {
    count.max(2).next_power_of_two()
}

/// Builds map A over the stored slots of `ph`: cell keys (1 pass), the
/// bitonic sort (log2 n (log2 n + 1) / 2 passes), the binary search (1 pass),
/// all in phase [`BUILD_MAP`].
pub fn build(passes: &mut Passes, grid: Grid, ph: &PhotonArrays) -> Result<BitonicMap, SimError> {
    let (first_slot, count) = ph.stored_slots();
    let n = padded(count);
    let a = passes.dev.alloc_zeroed::<u32>(2 * n);
    let b = passes.dev.alloc_zeroed::<u32>(2 * n);
    passes.launch_1d(
        BUILD_MAP,
        Kernels::Grid,
        "cell_keys",
        n,
        &[
            grid.arg(),
            Arg::Ptr(ph.pos),
            Arg::I32(first_slot as i32),
            Arg::I32(count as i32),
            Arg::I32(n as i32),
            Arg::Ptr(a),
        ],
    )?;
    let sorted = sort(passes, BUILD_MAP, a, b, n)?;
    let cells = grid.cells();
    let first = passes.dev.alloc_zeroed::<u32>(cells + 1);
    search(passes, BUILD_MAP, sorted, n, cells, first)?;
    let f = passes.dev.read::<u32>(first, cells + 1);
    Ok(BitonicMap { grid, sorted, n, first, photons: f[cells] as usize })
}

/// The binary-search pass: `first[c]` for c in 0..=cells.
pub fn search(
    passes: &mut Passes,
    phase: &str,
    sorted: DevicePtr,
    n: usize,
    cells: usize,
    first: DevicePtr,
) -> Result<(), SimError> {
    passes.launch_1d(
        phase,
        Kernels::Grid,
        "binary_search",
        cells + 1,
        &[Arg::Ptr(sorted), Arg::I32(n as i32), Arg::I32(cells as i32), Arg::Ptr(first)],
    )?;
    Ok(())
}
