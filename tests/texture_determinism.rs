//! GT200's texture caches are shared by the SMs of a cluster and replayed at
//! each round's end, the clusters in parallel on the launch's host threads:
//! every memory counter (hits and misses included) is the same for 1, 2 and 3
//! host threads.

use std::path::Path;

use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::rt_kernels::{self, Variant};
use warplight::host::scene_file;
use warplight::model::Profile;
use warplight::sim::Device;

#[test]
fn texture_counters_do_not_depend_on_host_threads() {
    let s = scene_file::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.toml")).unwrap();
    let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = s.flight.camera(&s.camera, 0);
    cam.resolution = [48, 32];
    let run = |threads: usize| {
        let mut cfg = rt_kernels::sim_config(&cam);
        cfg.threads = threads;
        let mut dev = Device::with_config(cfg);
        let module = rt_kernels::load(&mut dev).unwrap();
        let r = rt_kernels::render(
            &mut dev,
            &module,
            &s,
            &tree,
            &cam,
            s.flight.light_offset(0),
            Variant::Stack,
            Profile::Gt200,
        )
        .unwrap();
        (r.image, r.memory, r.launch.totals)
    };
    let one = run(1);
    assert!(one.1.counters.texture.hits > 0 && one.1.counters.texture.misses > 0);
    for threads in [2, 3] {
        let other = run(threads);
        assert_eq!(other.0, one.0, "image with {threads} threads");
        assert_eq!(other.1, one.1, "memory counters with {threads} threads");
        assert_eq!(other.2, one.2, "core counters with {threads} threads");
    }
}
