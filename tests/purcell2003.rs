//! Seed 004 (Purcell et al. 2003) on the emulator: breadth-first photon
//! tracing, the grid photon maps (bitonic sort + binary search, stencil
//! routing), the kNN-grid radiance estimate; small photon counts, each test
//! against a host reference or hand-derived counts.

use glam::Vec3;
use warplight::host::scene::{Light, Material, MaterialKind, Scene, Triangle};
use warplight::repro::purcell2003::bitonic::{self, BUILD_MAP};
use warplight::repro::purcell2003::grid::Grid;
use warplight::repro::purcell2003::passes::{Kernels, Passes};
use warplight::repro::purcell2003::photons::{self, Geometry, TRACE_PHOTONS};
use warplight::sim::Arg;

fn mat(name: &str, kind: MaterialKind, color: [f32; 3]) -> Material {
    Material { name: name.into(), kind, color, emission: [0.0; 3] }
}

fn quad(a: Vec3, b: Vec3, c: Vec3, d: Vec3, m: u32) -> [Triangle; 2] {
    [Triangle { v: [a, b, c], material: m }, Triangle { v: [a, c, d], material: m }]
}

/// A diffuse floor (y = 0, 4 x 4) under a point light at y = 1: photons
/// emitted downwards land on the floor, the others leave the scene.
fn floor_scene(albedo: f32) -> Scene {
    let s = 2.0;
    let tris =
        quad(Vec3::new(-s, 0.0, -s), Vec3::new(-s, 0.0, s), Vec3::new(s, 0.0, s), Vec3::new(s, 0.0, -s), 0).to_vec();
    let mut sc = Scene::assemble(
        "floor",
        std::path::Path::new("floor"),
        tris,
        vec![mat("floor", MaterialKind::Diffuse, [albedo; 3])],
    );
    sc.lights.push(Light::Point { position: [0.0, 1.0, 0.0], intensity: [1.0; 3] });
    sc
}

fn read4(p: &Passes, ptr: warplight::sim::DevicePtr, n: usize) -> Vec<[f32; 4]> {
    p.dev.read::<f32>(ptr, 4 * n).chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
}

#[test]
fn photons_are_emitted_by_the_counter_based_rng_and_traced_one_launch_per_bounce() {
    let scene = floor_scene(0.5);
    let geo = Geometry::of(&scene);
    let mut p = Passes::new(None).unwrap();
    let (n, bounces) = (256, 3);
    let ph = photons::trace(&mut p, &geo, n, bounces, 7).unwrap();
    // one emission pass and one pass per bounce, counted by the emulator
    assert_eq!(p.phase(TRACE_PHOTONS).launches, 1 + bounces as u64);
    let pos = read4(&p, ph.pos, n * (bounces + 1));
    let pow = read4(&p, ph.pow, n * (bounces + 1));
    let out = read4(&p, ph.out, n * (bounces + 1));
    let dir = read4(&p, ph.dir, n * (bounces + 1));
    let flux = 4.0 * std::f32::consts::PI / n as f32;
    let mut down = 0;
    for i in 0..n {
        // frame 0: on the light, the direction the RNG gives (uniform on the sphere)
        assert_eq!(&pos[i][..3], &[0.0, 1.0, 0.0]);
        assert_eq!(pos[i][3], 0.0, "emission frame holds no stored photon");
        assert!((pow[i][0] - flux).abs() < 1e-6 && pow[i][3] == 1.0);
        let z = 1.0 - 2.0 * photons::rng_unit(7, i as u32, 0, 0);
        assert!((out[i][2] - z).abs() < 1e-5, "photon {i}: z {} vs {z}", out[i][2]);
        // frame 1: photons going down are stored on the floor, the others are invalid
        let f1 = n + i;
        let d = Vec3::new(out[i][0], out[i][1], out[i][2]);
        let t = -1.0 / d.y;
        let hit = d.y < 0.0 && (d.x * t).abs() < 2.0 && (d.z * t).abs() < 2.0;
        if hit {
            down += 1;
            assert_eq!(pos[f1][3], 1.0, "photon {i} stored");
            assert!(pos[f1][1].abs() < 1e-5);
            assert!((pos[f1][0] - d.x * t).abs() < 1e-4 && (pos[f1][2] - d.z * t).abs() < 1e-4);
            assert_eq!(&dir[f1][..3], &out[i][..3], "incoming direction");
            // Russian roulette on the albedo 0.5: survivors carry power / 0.5 * 0.5
            let survives = photons::rng_unit(7, i as u32, 1, 0) < 0.5;
            assert_eq!(pow[f1][3], if survives { 1.0 } else { 0.0 });
            if survives {
                assert!(out[f1][1] > 0.0, "bounced up off the floor");
            }
        } else {
            assert_eq!(pos[f1][3], 0.0, "photon {i} escaped: invalid");
            assert_eq!(pow[f1][3], 0.0);
        }
        // frame 2: a photon leaving the floor upwards escapes; nothing is stored any more
        assert_eq!(pos[2 * n + i][3], 0.0);
        assert_eq!(pow[2 * n + i][3], 0.0);
    }
    assert!(down > n / 4 && down < n * 3 / 4, "{down} of {n} hit the floor");
    // deterministic: the same bytes on a second device run
    let mut q = Passes::new(None).unwrap();
    let ph2 = photons::trace(&mut q, &geo, n, bounces, 7).unwrap();
    assert_eq!(read4(&q, ph2.pos, n * (bounces + 1)), pos);
}

#[test]
fn bitonic_pass_schedule_has_the_papers_pass_counts() {
    // Fig. 2: eight elements, 6 passes; 004:L102: 1024 x 1024 photons, 210 passes
    assert_eq!(bitonic::schedule(8), vec![(1, 2), (2, 4), (1, 4), (4, 8), (2, 8), (1, 8)]);
    assert_eq!(bitonic::schedule(1 << 20).len(), 210);
    for p in 1..=20usize {
        assert_eq!(bitonic::schedule(1 << p).len(), p * (p + 1) / 2);
    }
}

fn keys_buffer(p: &mut Passes, keys: &[(u32, u32)]) -> warplight::sim::DevicePtr {
    let flat: Vec<u32> = keys.iter().flat_map(|&(k, v)| [k, v]).collect();
    p.upload(&flat).unwrap()
}

fn read_pairs(p: &Passes, ptr: warplight::sim::DevicePtr, n: usize) -> Vec<(u32, u32)> {
    p.dev.read::<u32>(ptr, 2 * n).chunks_exact(2).map(|c| (c[0], c[1])).collect()
}

#[test]
fn bitonic_sort_of_eight_elements_takes_six_launches_each_matching_fig_3() {
    let keys: Vec<(u32, u32)> = [5u32, 2, 7, 2, 0, 6, 3, 1].iter().enumerate().map(|(i, &k)| (k, i as u32)).collect();
    let mut p = Passes::new(None).unwrap();
    let a = keys_buffer(&mut p, &keys);
    let b = p.dev.alloc_zeroed::<u32>(16);
    // pass by pass against the host's reading of Fig. 3
    let mut host = keys.clone();
    let (mut src, mut dst) = (a, b);
    for (offset, stepno) in bitonic::schedule(8) {
        p.launch_1d(
            "sort",
            Kernels::Grid,
            "bitonic_pass",
            8,
            &[Arg::Ptr(src), Arg::Ptr(dst), Arg::I32(8), Arg::I32(offset as i32), Arg::I32(stepno as i32)],
        )
        .unwrap();
        host = bitonic::reference_pass(&host, offset as usize, stepno as usize);
        assert_eq!(read_pairs(&p, dst, 8), host, "pass offset {offset} stepno {stepno}");
        std::mem::swap(&mut src, &mut dst);
    }
    let out = read_pairs(&p, src, 8);
    let mut ks: Vec<u32> = out.iter().map(|x| x.0).collect();
    assert!(ks.windows(2).all(|w| w[0] <= w[1]), "{out:?}");
    // a permutation: every element once
    let mut idx: Vec<u32> = out.iter().map(|x| x.1).collect();
    idx.sort();
    assert_eq!(idx, (0..8).collect::<Vec<_>>());
    ks.sort();
    // the emulator counted six launches of eight threads, 2 fetches each
    let c = p.phase("sort");
    assert_eq!(c.launches, 6);
    assert_eq!(c.lane_loads, 6 * 8 * 2);
    assert_eq!(c.lane_stores, 6 * 8);
}

#[test]
fn the_2003_faithful_pass_sorts_alike_with_2d_float_addressing() {
    // 256 elements in a 16-texel-wide texture: float4 (photon, key, 0, 0)
    let n = 256;
    let keys: Vec<u32> = (0..n as u32).map(|i| photons::hash32(i) % 37).collect();
    let texels: Vec<f32> = keys.iter().enumerate().flat_map(|(i, &k)| [i as f32, k as f32, 0.0, 0.0]).collect();
    let mut p = Passes::new(None).unwrap();
    let a = p.upload(&texels).unwrap();
    let b = p.dev.alloc_zeroed::<f32>(4 * n);
    let r = bitonic::sort_2003(&mut p, "sort", a, b, n, 16).unwrap();
    let out = p.dev.read::<f32>(r, 4 * n);
    let got: Vec<u32> = out.chunks_exact(4).map(|c| c[1] as u32).collect();
    let mut want = keys.clone();
    want.sort();
    assert_eq!(got, want);
    assert_eq!(p.phase("sort").launches, 36);
    // the natural pass gives the same keys
    let pairs: Vec<(u32, u32)> = keys.iter().enumerate().map(|(i, &k)| (k, i as u32)).collect();
    let a = keys_buffer(&mut p, &pairs);
    let b = p.dev.alloc_zeroed::<u32>(2 * n);
    let r = bitonic::sort(&mut p, "natural", a, b, n).unwrap();
    let nat: Vec<u32> = read_pairs(&p, r, n).iter().map(|x| x.0).collect();
    assert_eq!(nat, want);
}

#[test]
fn map_a_sorts_photons_by_cell_and_the_binary_search_finds_each_cells_first_photon() {
    let scene = floor_scene(0.8);
    let geo = Geometry::of(&scene);
    let mut p = Passes::new(None).unwrap();
    let ph = photons::trace(&mut p, &geo, 300, 2, 3).unwrap();
    let grid = Grid::new(Vec3::new(-2.0, -0.1, -2.0), Vec3::new(2.0, 0.1, 2.0), [8, 1, 8]);
    let map = bitonic::build(&mut p, grid, &ph).unwrap();
    let (first_slot, count) = ph.stored_slots();
    assert_eq!(map.n, 1024, "600 slots padded to 1024");
    // launches: cell keys, 10 * 11 / 2 = 55 sort passes, one binary search
    assert_eq!(p.phase(BUILD_MAP).launches, 1 + 55 + 1);
    let pos = read4(&p, ph.pos, ph.n * ph.frames);
    let mut want: Vec<(u32, u32)> = (first_slot..first_slot + count)
        .map(|s| {
            let q = pos[s];
            let key = if q[3] != 0.0 { grid.cell_of(Vec3::new(q[0], q[1], q[2])) } else { grid.cells() as u32 };
            (key, s as u32)
        })
        .collect();
    want.resize(map.n, (grid.cells() as u32, u32::MAX));
    let sorted = read_pairs(&p, map.sorted, map.n);
    let mut got = sorted.clone();
    got.sort();
    want.sort();
    assert_eq!(got, want, "the same elements");
    assert!(sorted.windows(2).all(|w| w[0].0 <= w[1].0), "sorted by cell");
    let first = p.dev.read::<u32>(map.first, grid.cells() + 1);
    for c in 0..=grid.cells() {
        let lb = sorted.partition_point(|e| e.0 < c as u32) as u32;
        assert_eq!(first[c], lb, "cell {c}");
    }
    let stored = pos[first_slot..first_slot + count].iter().filter(|q| q[3] != 0.0).count();
    assert_eq!(map.photons, stored);
    assert!(stored > 50);
}
