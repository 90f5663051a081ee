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
    let ph = photons::trace(&mut p, &geo, n, bounces, 7, true).unwrap();
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
    let ph2 = photons::trace(&mut q, &geo, n, bounces, 7, true).unwrap();
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
    let ph = photons::trace(&mut p, &geo, 300, 2, 3, true).unwrap();
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
    for (c, &f) in first.iter().enumerate() {
        let lb = sorted.partition_point(|e| e.0 < c as u32) as u32;
        assert_eq!(f, lb, "cell {c}");
    }
    let stored = pos[first_slot..first_slot + count].iter().filter(|q| q[3] != 0.0).count();
    assert_eq!(map.photons, stored);
    assert!(stored > 50);
}

use warplight::repro::purcell2003::knn::{self, Map, Params, RADIANCE_ESTIMATE};
use warplight::repro::purcell2003::knn_2003;
use warplight::repro::purcell2003::photons::{PhotonArrays, Queries};
use warplight::repro::purcell2003::stencil;

/// Photon arrays holding `photons` (position, power) in frame 1 (stored,
/// arriving straight down), frame 0 empty.
fn photon_arrays(p: &mut Passes, photons: &[(Vec3, f32)]) -> PhotonArrays {
    let n = photons.len();
    let mut pos = vec![0.0f32; 8 * n];
    let mut pow = vec![0.0f32; 8 * n];
    let mut dir = vec![0.0f32; 8 * n];
    for (i, (x, w)) in photons.iter().enumerate() {
        let s = 4 * (n + i);
        pos[s..s + 4].copy_from_slice(&[x.x, x.y, x.z, 1.0]);
        pow[s..s + 4].copy_from_slice(&[*w, *w, *w, 0.0]);
        dir[s..s + 4].copy_from_slice(&[0.0, -1.0, 0.0, 0.0]);
    }
    let out = p.dev.alloc_zeroed::<f32>(8 * n);
    PhotonArrays {
        n,
        frames: 2,
        pos: p.upload(&pos).unwrap(),
        pow: p.upload(&pow).unwrap(),
        dir: p.upload(&dir).unwrap(),
        out,
    }
}

/// Query points (facing up) on a `w` x `h` image.
fn queries(p: &mut Passes, w: u32, h: u32, points: &[Option<Vec3>]) -> Queries {
    let q: Vec<f32> = points.iter().flat_map(|x| x.map_or([0.0; 4], |v| [v.x, v.y, v.z, 1.0])).collect();
    let nrm: Vec<f32> = points.iter().flat_map(|_| [0.0, 1.0, 0.0, 0.0]).collect();
    let alb: Vec<f32> = points.iter().flat_map(|_| [1.0, 1.0, 1.0, 0.0]).collect();
    Queries {
        width: w,
        height: h,
        query: p.upload(&q).unwrap(),
        normal: p.upload(&nrm).unwrap(),
        albedo: p.upload(&alb).unwrap(),
    }
}

#[test]
fn stencil_routing_keeps_the_first_m2_photons_of_each_cell_in_draw_order_and_redistributes_power() {
    // 4 x 1 x 4 cells of 1 x 1; m = 2 (4 slots, as Fig. 5); 40 photons drawn
    // into cell 5 (x 1, z 1), 3 into cell 0, the rest nowhere
    let grid = Grid::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 1.0, 4.0), [4, 1, 4]);
    let mut photons = Vec::new();
    for i in 0..43 {
        let x = if i % 14 == 3 { Vec3::new(0.5, 0.5, 0.5) } else { Vec3::new(1.5, 0.5, 1.5) };
        photons.push((x, 1.0 + i as f32));
    }
    let mut p = Passes::new(None).unwrap();
    let ph = photon_arrays(&mut p, &photons);
    let map = stencil::build(&mut p, grid, &ph, 4).unwrap();
    assert_eq!(p.phase(BUILD_MAP).launches, 2, "one routing pass and one fill pass");
    let slots = p.dev.read::<u32>(map.cell_slots, 16 * 4);
    let in5: Vec<u32> = (0..43).filter(|i| i % 14 != 3).map(|i| (43 + i) as u32).collect();
    let in0: Vec<u32> = (0..43).filter(|i| i % 14 == 3).map(|i| (43 + i) as u32).collect();
    assert_eq!(&slots[5 * 4..6 * 4], &in5[..4], "the first four in draw order");
    assert_eq!(&slots[..3], &in0[..]);
    assert_eq!(slots[3], u32::MAX, "an empty slot");
    for c in (1..16).filter(|&c| c != 5) {
        assert!(slots[4 * c..4 * c + 4].iter().all(|&s| s == u32::MAX), "cell {c} empty");
    }
    let occ = stencil::occupancy(&p, &map);
    assert_eq!(occ.destined, 43);
    assert_eq!(occ.stored, 7);
    assert_eq!(occ.lost(), 36);
    assert_eq!(occ.overflowing_cells, 1);
    let scale = p.dev.read::<f32>(map.scale, 16);
    assert_eq!(scale[5], 40.0 / 4.0);
    assert_eq!(scale[0], 1.0);
    let bpow = p.dev.read::<f32>(map.pow, 4 * 16 * 4);
    assert_eq!(bpow[4 * 20], photons[(in5[0] - 43) as usize].1, "the block holds the routed photon's data");
    // the same slots when every photon is drawn by a CTA of its own (CTAs
    // run in any order on the host's threads)
    let cs = p.upload(&vec![u32::MAX; 64]).unwrap();
    let ds = p.dev.alloc_zeroed::<u32>(16);
    let args = [grid.arg(), Arg::Ptr(ph.pos), Arg::I32(43), Arg::I32(43), Arg::I32(4), Arg::Ptr(cs), Arg::Ptr(ds)];
    p.launch("again", Kernels::Grid, "stencil_route", warplight::sim::LaunchConfig::linear(43, 1), &args).unwrap();
    assert_eq!(p.dev.read::<u32>(cs, 64), slots);
}

/// Fig. 6 with k = 4 (004:L154): a query at the centre of cell (2, 2) of a
/// 5 x 1 x 5 grid of unit cells, maximum radius 1.4.
fn fig6_photons() -> Vec<(Vec3, f32)> {
    let at = |x: f32, z: f32| (Vec3::new(x, 0.5, z), 1.0);
    vec![
        at(2.8, 2.5),  // (b-c) first cell: added, d = 0.30
        at(2.05, 2.5), // (b-c) added, d = 0.45, the radius grows
        at(1.9, 1.83), // (d) next cell: added, d = 0.90, the radius grows
        at(1.1, 1.5),  // (d) rejected: d = 1.72 > r_max
        at(2.5, 1.7),  // (e) added, d = 0.80: k = 4 reached
        at(2.5, 1.3),  // (e) rejected: d = 1.2 outside the radius, which no longer grows
        at(3.1, 1.9),  // (f) added: d = 0.85 within the radius
        at(1.6, 3.4),  // (g) rejected: d = 1.27 outside the radius
    ]
}

#[test]
fn knn_grid_follows_fig_6s_accept_reject_sequence_with_k_4() {
    let grid = Grid::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 1.0, 5.0), [5, 1, 5]);
    let mut p = Passes::new(None).unwrap();
    let ph = photon_arrays(&mut p, &fig6_photons());
    // the stencil map keeps a cell's photons in draw order, so the order of lookups is the list's
    let smap = stencil::build(&mut p, grid, &ph, 4).unwrap();
    let q = queries(&mut p, 1, 1, &[Some(Vec3::new(2.5, 0.5, 2.5))]);
    let params = Params { k: 4, r_max: 1.4, iters: 1, tiled: false };
    let map = Map::Stencil(&smap);
    let state = knn::start_states(&mut p, &q).unwrap();
    let mut prev = knn::states(&p, state, 1)[0];
    let mut events = String::new();
    for _ in 0..40 {
        knn::pass(&mut p, "fig6", &map, &q, &params, state).unwrap();
        let s = knn::states(&p, state, 1)[0];
        if s.local > prev.local {
            events.push(if s.n > prev.n { 'A' } else { 'R' });
        } else {
            events.push('|');
        }
        prev = s;
        if s.done {
            break;
        }
    }
    // cells in order: (2,2) | ring 1: (1,1) (2,1) (3,1) | (1,2) (3,2) | (1,3) (2,3) (3,3)
    assert_eq!(events, "AA|AR|AR|A|||R|||");
    assert!(prev.done && prev.ring == 1);
    assert_eq!(prev.n, 5);
    assert!((prev.r - 0.9).abs() < 1e-3, "radius {}", prev.r);
    assert_eq!(prev.sum, [5.0; 3]);
    // on the bitonic map (whose sort orders a cell's photons its own way) the
    // search also ends with every photon within its radius, at least k
    let bmap = bitonic::build(&mut p, grid, &ph).unwrap();
    let e = knn::estimate(&mut p, &Map::Bitonic(&bmap, &ph), &q, &Params { iters: 4, ..params }, 100).unwrap();
    assert!(e.finished);
    let s = e.states[0];
    let within = fig6_photons().iter().filter(|(x, _)| (*x - Vec3::new(2.5, 0.5, 2.5)).length() <= s.r).count();
    assert!(s.n >= 4 && s.n as usize == within, "{s:?}");
    assert_eq!(s.used, prev.used, "one lookup per photon or cell end, on both maps");
}

#[test]
fn knn_grid_finds_every_photon_within_its_sphere_and_fewer_than_k_only_at_r_max() {
    // random photons on the plane y = 0.5 of a 16 x 1 x 16 grid; queries on a 16 x 16 image
    let grid = Grid::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(16.0, 1.0, 16.0), [16, 1, 16]);
    let u = |i: u32, d: u32| photons::rng_unit(11, i, 0, d);
    let mut pts = Vec::new();
    for i in 0..400 {
        // denser towards x = 0
        let x = 16.0 * u(i, 0) * u(i, 0);
        pts.push((Vec3::new(x, 0.5, 16.0 * u(i, 1)), 1.0));
    }
    let mut p = Passes::new(None).unwrap();
    let ph = photon_arrays(&mut p, &pts);
    let bmap = bitonic::build(&mut p, grid, &ph).unwrap();
    let qs: Vec<Option<Vec3>> =
        (0..256).map(|i| Some(Vec3::new((i % 16) as f32 + 0.5, 0.5, (i / 16) as f32 + 0.5))).collect();
    let q = queries(&mut p, 16, 16, &qs);
    let params = Params { k: 8, r_max: 3.0, iters: 16, tiled: false };
    let check = |states: &[knn::State]| {
        for (i, s) in states.iter().enumerate() {
            let x = qs[i].unwrap();
            let mut d: Vec<f32> = pts.iter().map(|(y, _)| (*y - x).length()).collect();
            d.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let within_max = d.iter().filter(|&&v| v <= 3.0).count();
            if within_max < 8 {
                // fewer than k within r_max: all of them
                assert_eq!(s.n as usize, within_max, "pixel {i}");
            } else {
                // at least k: exactly the photons within the radius, which is the k-th nearest's or more
                assert!(s.n >= 8, "pixel {i}");
                assert!(s.r >= d[7] - 1e-5, "pixel {i}: radius {} below the 8th nearest {}", s.r, d[7]);
                let inside = d.iter().filter(|&&v| v <= s.r).count();
                assert_eq!(s.n as usize, inside, "pixel {i}");
            }
        }
    };
    let e = knn::estimate(&mut p, &Map::Bitonic(&bmap, &ph), &q, &params, 1000).unwrap();
    assert!(e.finished);
    check(&e.states);
    // the stencil map with room for every photon: the same property (the
    // radius itself depends on the order a cell's photons are looked at,
    // which differs between the maps)
    let smap = stencil::build(&mut p, grid, &ph, 64).unwrap();
    assert_eq!(stencil::occupancy(&p, &smap).lost(), 0);
    let e2 = knn::estimate(&mut p, &Map::Stencil(&smap), &q, &params, 1000).unwrap();
    assert!(e2.finished);
    check(&e2.states);
}

#[test]
fn tiles_that_finish_stop_being_drawn_and_the_saving_follows_from_per_pixel_lookups() {
    // 32 x 32 pixels (four 16 x 16 tiles); photons only near one corner, so
    // pixels there finish fast and far pixels search out to r_max
    let grid = Grid::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(32.0, 1.0, 32.0), [32, 1, 32]);
    let mut pts = Vec::new();
    for i in 0..300u32 {
        let (a, b) = (photons::rng_unit(5, i, 0, 0), photons::rng_unit(5, i, 0, 1));
        pts.push((Vec3::new(12.0 * a, 0.5, 12.0 * b), 1.0));
    }
    let mut p = Passes::new(None).unwrap();
    let ph = photon_arrays(&mut p, &pts);
    let smap = stencil::build(&mut p, grid, &ph, 16).unwrap();
    let qs: Vec<Option<Vec3>> =
        (0..1024).map(|i| Some(Vec3::new((i % 32) as f32 + 0.5, 0.5, (i / 32) as f32 + 0.5))).collect();
    let q = queries(&mut p, 32, 32, &qs);
    let single = Params { k: 4, r_max: 6.0, iters: 8, tiled: false };
    let tiled = Params { tiled: true, ..single };
    let map = Map::Stencil(&smap);
    let a = knn::estimate(&mut p, &map, &q, &single, 10_000).unwrap();
    let before = p.phase(RADIANCE_ESTIMATE);
    let b = knn::estimate(&mut p, &map, &q, &tiled, 10_000).unwrap();
    let after = p.phase(RADIANCE_ESTIMATE);
    assert!(a.finished && b.finished);
    assert_eq!(a.states, b.states, "the same estimate");
    assert_eq!(a.passes, b.passes, "as many passes: the slowest tile sets both");
    let used: Vec<i32> = a.states.iter().map(|s| s.used).collect();
    // the emulator's lane-iterations are exactly what the per-pixel lookup counts predict
    assert_eq!(a.lane_iterations, knn::predicted_lane_iterations(&used, 32, 32, 8, None));
    assert_eq!(b.lane_iterations, knn::predicted_lane_iterations(&used, 32, 32, 8, Some(16)));
    assert!(b.lane_iterations < a.lane_iterations, "{} vs {}", b.lane_iterations, a.lane_iterations);
    // and the tiled passes ran fewer thread instructions
    let tiled_inst = after.thread_instructions - before.thread_instructions;
    assert!(tiled_inst < before.thread_instructions);
}

#[test]
fn the_2003_faithful_estimate_with_float_addressing_and_packed_state_finds_the_same_photons() {
    // the setting of the test above, photon powers varied; the packed state
    // keeps the radius as a half and the power as 12-bit mantissas
    let grid = Grid::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(16.0, 1.0, 16.0), [16, 1, 16]);
    let u = |i: u32, d: u32| photons::rng_unit(11, i, 0, d);
    let pts: Vec<(Vec3, f32)> =
        (0..400).map(|i| (Vec3::new(16.0 * u(i, 0) * u(i, 0), 0.5, 16.0 * u(i, 1)), 0.5 + u(i, 2))).collect();
    let mut p = Passes::new(None).unwrap();
    let ph = photon_arrays(&mut p, &pts);
    let bmap = bitonic::build(&mut p, grid, &ph).unwrap();
    let smap = stencil::build(&mut p, grid, &ph, 64).unwrap();
    // the last pixel has no query point: finished from the start
    let qs: Vec<Option<Vec3>> =
        (0..256).map(|i| (i < 255).then(|| Vec3::new((i % 16) as f32 + 0.5, 0.5, (i / 16) as f32 + 0.5))).collect();
    let q = queries(&mut p, 16, 16, &qs);
    let params = Params { k: 8, r_max: 3.0, iters: 16, tiled: true };
    for map in [Map::Bitonic(&bmap, &ph), Map::Stencil(&smap)] {
        let a = knn::estimate(&mut p, &map, &q, &params, 1000).unwrap();
        let b = knn_2003::estimate(&mut p, &map, &q, &params, 1000).unwrap();
        assert!(a.finished && b.finished);
        assert_eq!(b.states[255].n, 0, "no query point, nothing searched");
        let mut same = 0;
        for (i, (x, y)) in a.states.iter().zip(&b.states).enumerate() {
            if x.n == y.n {
                same += 1;
                assert!((x.r - y.r).abs() <= 1e-3 * x.r, "pixel {i}: radius {} vs {}", x.r, y.r);
                for c in 0..3 {
                    assert!((x.sum[c] - y.sum[c]).abs() <= 1e-3 * x.sum[c], "pixel {i}: {:?} vs {:?}", x.sum, y.sum);
                }
            }
        }
        // a photon at the radius's distance can fall either side of its half
        assert!(same >= 250, "{same} of 256 pixels found as many photons");
    }
}
