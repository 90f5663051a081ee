//! The lesson kernels (`kernels/lessons/`, specs in `examples/lessons/`):
//! results against Rust references, counters against the hand-derived counts
//! the lessons (`docs/lessons/`) state.

use std::path::Path;

use warplight::launch_spec::{self, LaunchResult, Prepared, Spec};
use warplight::model::Profile;
use warplight::sim::Device;

struct Run {
    spec: Spec,
    dev: Device,
    prepared: Prepared,
    results: Vec<LaunchResult>,
}

fn run(spec: &str, profile: Profile) -> Run {
    let spec = Spec::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(spec)).unwrap();
    let mut dev = Device::new();
    let prepared = launch_spec::prepare(&spec, &mut dev).unwrap();
    let results = launch_spec::run(&spec, &mut dev, &prepared, profile).unwrap();
    Run { spec, dev, prepared, results }
}

impl Run {
    fn read<T: warplight::sim::Element>(&self, name: &str) -> Vec<T> {
        let (p, b) = &self.prepared.buffers[name];
        self.dev.read::<T>(*p, b.len)
    }

    fn initial<T: Copy>(&self, name: &str, decode: impl Fn([u8; 4]) -> T) -> Vec<T> {
        let b = self.spec.buffers.iter().find(|b| b.name == name).unwrap();
        self.spec.initial_bytes(b).unwrap().chunks(4).map(|c| decode(c.try_into().unwrap())).collect()
    }

    /// `name` for every launch, in order.
    fn metrics(&self, name: &str) -> Vec<u64> {
        (0..self.results.len()).map(|l| self.metric(l, name)).collect()
    }

    fn metric(&self, launch: usize, name: &str) -> u64 {
        let r = &self.results[launch];
        let found = r.metrics().into_iter().find(|(k, _)| k == name).map(|(_, v)| v);
        found.or_else(|| r.stats.totals.get(name)).unwrap_or_else(|| panic!("no metric {name}"))
    }
}

#[test]
fn lesson1_divergence() {
    let r = run("examples/lessons/divergence.toml", Profile::Hopper);
    let (odd, even, all, out) =
        (r.read::<i32>("odd"), r.read::<i32>("even"), r.read::<i32>("all"), r.read::<i32>("out"));
    for t in 0..32usize {
        let ti = t as i32;
        if t % 2 == 1 {
            assert_eq!((odd[t], odd[t + 32], even[t]), (3 * ti, ti, 0));
        } else {
            assert_eq!((even[t], odd[t]), (ti + 100, 0));
        }
        assert_eq!(all[t], ti);
        // in = iota: sum of in[32k + t] for k = 0..=t % 4
        assert_eq!(out[t], (0..=(t % 4) as i32).map(|k| 32 * k + ti).sum::<i32>());
    }
    let c = &r.results[0].stats.totals;
    assert_eq!((c.divergent_branches, c.reconvergences, c.warp_instructions, c.thread_instructions), (1, 2, 27, 656));
    // the loop: its exit diverges after iterations 1, 2 and 3
    assert_eq!(r.results[1].stats.totals.divergent_branches, 3);
    // 4 iterations' loads of 32, 24, 16 and 8 lanes: each touches all 4 sectors of its 128 bytes
    assert_eq!(r.metric(1, "l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum"), 4);
    assert_eq!(r.metric(1, "l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum"), 16);
}

#[test]
fn lesson2_coalescing_counts_as_the_measured_micro_kernel() {
    // docs/lessons/02-coalescing.md's tables
    let g = run("examples/lessons/coalescing.toml", Profile::Gt200);
    let by_size: Vec<[u64; 3]> = (0..3).map(|l| ["gld_32b", "gld_64b", "gld_128b"].map(|m| g.metric(l, m))).collect();
    assert_eq!(by_size, [[0, 64, 0], [0, 0, 64], [1024, 0, 0]]);
    let h = run("examples/lessons/coalescing.toml", Profile::Hopper);
    let sectors: Vec<u64> = h.metrics("l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum");
    assert_eq!(sectors, [128, 256, 1024]);
    let requests: Vec<u64> = h.metrics("l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum");
    assert_eq!(requests, [32, 32, 32]);
    // results: out[t] = in[t * stride] with in = iota, for the last launch (stride 32)
    let out = h.read::<f32>("out");
    assert!(out.iter().enumerate().all(|(t, &v)| v == (32 * t) as f32));
    // the same pattern in the H100-validated micro kernel (ld_stride with b = 0,
    // tests/validation.rs) counts the same
    let dir = std::env::temp_dir().join(format!("warplight-lesson2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let micro = Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels/micro/micro.ptx");
    let mut spec = format!(
        "ptx = {:?}\nbuffer = [{{ name = \"out\", type = \"f32\", len = 1024 }}, {{ name = \"in\", type = \"f32\", len = 32768 }}]\n",
        micro.display().to_string()
    );
    for stride in [1, 2, 32] {
        spec += &format!(
            "[[launch]]\nkernel = \"ld_stride\"\ngrid = 4\nblock = 256\nargs = [\"out\", \"in\", {stride}, 0]\n"
        );
    }
    let file = dir.join("micro.toml");
    std::fs::write(&file, spec).unwrap();
    let m = run(file.to_str().unwrap(), Profile::Hopper);
    let micro_sectors: Vec<u64> = m.metrics("l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum");
    assert_eq!(micro_sectors, sectors);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn lesson3_bank_conflicts() {
    let h = run("examples/lessons/banks.toml", Profile::Hopper);
    let input: Vec<f32> = h.initial("in", f32::from_le_bytes);
    let out = h.read::<f32>("out");
    for y in 0..32 {
        for x in 0..32 {
            assert_eq!(out[32 * y + x], input[32 * x + y], "transpose at ({x}, {y})");
        }
    }
    // column reads: 32 lanes in one bank -> 32 wavefronts, 31 conflicts per warp, 32 warps
    let conflicts: Vec<u64> = h.metrics("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_ld.sum");
    assert_eq!(conflicts, [32 * 31, 0]);
    let wavefronts: Vec<u64> = h.metrics("l1tex__data_pipe_lsu_wavefronts_mem_shared_op_ld.sum");
    assert_eq!(wavefronts, [32 * 32, 32]);
    // GT200: 16 banks per half-warp -> 16 passes per half-warp without padding
    let g = run("examples/lessons/banks.toml", Profile::Gt200);
    let passes: Vec<u64> = g.metrics("mem.shared_ld.wavefronts");
    assert_eq!(passes, [32 * 2 * 16, 32 * 2]);
    assert_eq!([g.metric(0, "warp_serialize"), g.metric(1, "warp_serialize")], [32, 0]);
}

#[test]
fn lesson4_votes_and_shuffles_are_per_warp() {
    let r = run("examples/lessons/votes.toml", Profile::Hopper);
    let v: Vec<i32> = r.initial("in", i32::from_le_bytes);
    let (ballots, sums) = (r.read::<u32>("ballots"), r.read::<i32>("sums"));
    for w in 0..2 {
        let lanes = &v[32 * w..32 * w + 32];
        let ballot = lanes.iter().enumerate().filter(|(_, x)| **x > 50).fold(0u32, |b, (l, _)| b | 1 << l);
        assert_eq!(ballots[w], ballot, "warp {w}");
        assert_eq!(sums[w], lanes.iter().sum::<i32>(), "warp {w}");
    }
    assert_eq!(
        (ballots[0], ballots[1], sums[0], sums[1]),
        (0xa52d694a, 0x5ad294b5, 1556, 1620),
        "the lesson's numbers"
    );
}

#[test]
fn lesson5_reduction_orders() {
    let r = run("examples/lessons/reduction.toml", Profile::Hopper);
    let v: Vec<i32> = r.initial("in", i32::from_le_bytes);
    let sums = r.read::<i32>("sums");
    for b in 0..8 {
        assert_eq!(sums[b], v[256 * b..256 * b + 256].iter().sum::<i32>());
    }
    let c: Vec<_> = r.results.iter().map(|x| &x.stats.totals).collect();
    // 9 barriers per CTA; divergence counted by hand in docs/lessons/05-reduction.md
    assert_eq!((c[0].barriers, c[1].barriers), (72, 72));
    assert_eq!((c[0].divergent_branches, c[1].divergent_branches), (8 * 48, 8 * 6));
    let conflicts: Vec<u64> = r.metrics("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_ld.sum");
    // the sequential order's lanes are 2d words apart: conflicts (the lesson's table)
    assert_eq!(conflicts, [0, 560]);
}

/// Lesson 6's kernel against a Rust reference: the nearest segment of each ray
/// by brute force, and the restarts counted as the cell boundaries (x = 4,
/// y = 4) the ray crosses before its hit (or before t = 20).
#[test]
fn lesson6_stackless_matches_brute_force() {
    let r = run("examples/lessons/stackless.toml", Profile::Hopper);
    let (segs, rays): (Vec<f32>, Vec<f32>) =
        (r.initial("segs", f32::from_le_bytes), r.initial("rays", f32::from_le_bytes));
    let (hit, thit, restarts) = (r.read::<i32>("hit"), r.read::<f32>("thit"), r.read::<i32>("restarts"));
    let tmax = 20.0f64;
    for i in 0..32 {
        let [ox, oy, dx, dy] = [0, 1, 2, 3].map(|k| rays[4 * i + k] as f64);
        let mut best: Option<(f64, i32)> = None;
        for s in 0..segs.len() / 4 {
            let [x0, y0, x1, y1] = [0, 1, 2, 3].map(|k| segs[4 * s + k] as f64);
            let (ex, ey) = (x1 - x0, y1 - y0);
            let den = dx * ey - dy * ex;
            if den == 0.0 {
                continue;
            }
            let (qx, qy) = (x0 - ox, y0 - oy);
            let (t, u) = ((qx * ey - qy * ex) / den, (qx * dy - qy * dx) / den);
            if (0.0..=1.0).contains(&u) && t >= 0.0 && t <= tmax && best.is_none_or(|b| t < b.0) {
                best = Some((t, s as i32));
            }
        }
        assert_eq!(hit[i], best.map_or(-1, |b| b.1), "ray {i}");
        if let Some((t, _)) = best {
            assert!((thit[i] as f64 - t).abs() < 1e-4, "ray {i}: t {} vs {t}", thit[i]);
        }
        let end = best.map_or(tmax, |b| b.0);
        let crossings = [(4.0 - ox) / dx, (4.0 - oy) / dy].iter().filter(|&&c| c > 0.0 && c < end).count() as i32;
        assert_eq!(restarts[i], crossings, "ray {i}");
    }
    // the fan has rays with 0, 1 and 2 restarts, so the warp diverges in the restart loop
    assert!(restarts.contains(&0) && restarts.contains(&1) && restarts.contains(&2));
    let c = &r.results[0].stats.totals;
    assert_eq!(
        (c.warp_instructions, c.thread_instructions, c.divergent_branches, c.reconvergences),
        (462, 9838, 4, 8),
        "the lesson's log"
    );
}
