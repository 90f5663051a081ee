//! Fidelity levels (`sim::Fidelity`): the emulated ray tracer gives the same
//! image, hit buffer and kernel-counted work at every level; each level keeps
//! the counters of the levels below it exactly and leaves out only its own.

use std::path::Path;

use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::rt_kernels::{self, KernelRender, Variant};
use warplight::host::scene_file;
use warplight::model::{MemCounters, Profile};
use warplight::sim::{Device, Fidelity};

fn render(level: Fidelity, variant: Variant) -> KernelRender {
    let s = scene_file::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.toml")).unwrap();
    let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = s.flight.camera(&s.camera, 0);
    cam.resolution = [48, 32];
    let mut cfg = rt_kernels::sim_config(&cam);
    cfg.fidelity = level;
    let mut dev = Device::with_config(cfg);
    let module = rt_kernels::load(&mut dev).unwrap();
    rt_kernels::render(&mut dev, &module, &s, &tree, &cam, s.flight.light_offset(0), variant, Profile::Gt200).unwrap()
}

/// The memory counters with the cache results cleared.
fn without_caches(m: &MemCounters) -> MemCounters {
    let mut m = m.clone();
    for c in [&mut m.global_ld, &mut m.global_st, &mut m.local_ld, &mut m.local_st, &mut m.texture] {
        c.hits = 0;
        c.misses = 0;
    }
    m
}

#[test]
fn results_are_bit_identical_at_every_level() {
    for variant in [Variant::Stack, Variant::Stackless] {
        let full = render(Fidelity::Caches, variant);
        assert!(full.memory.counters.texture.hits > 0, "the full model simulates the texture cache");
        for level in Fidelity::ALL {
            let r = render(level, variant);
            assert_eq!(r.image, full.image, "{level}");
            assert_eq!(r.hit_tri, full.hit_tri, "{level}");
            // work counts come from per-line counters, which functional does not keep
            assert_eq!(r.counted, level >= Fidelity::Instructions, "{level}");
            if r.counted {
                assert_eq!(r.trace, full.trace, "{level}");
            } else {
                assert_eq!(r.trace.inner_nodes + r.trace.rays, 0, "{level}: unknown counts stay zero");
            }
            // the core's launch totals are counted at every level
            assert_eq!(r.launch.totals, full.launch.totals, "{level}");
            let per_inst_counted = r.launch.profile.per_fn.iter().flatten().any(|c| c.warp > 0);
            assert_eq!(per_inst_counted, level >= Fidelity::Instructions, "{level}");
            if level >= Fidelity::Instructions {
                assert_eq!(r.launch.profile, full.launch.profile, "{level}");
            }
            match level {
                Fidelity::Functional | Fidelity::Instructions => {
                    assert_eq!(r.memory.counters, MemCounters::default(), "{level}: no memory model")
                }
                Fidelity::Memory => {
                    assert_eq!(r.memory.counters, without_caches(&full.memory.counters));
                    assert_eq!(r.memory.per_inst, full.memory.per_inst);
                }
                Fidelity::Caches => assert_eq!(r.memory, full.memory),
            }
        }
    }
}
