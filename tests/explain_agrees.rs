//! The step view's memory panel (`model::explain`) shows the counters' numbers:
//! for every lesson (`examples/lessons/*.toml`, `examples/*.toml`) under every
//! device profile, stepping each launch and explaining every access gives,
//! instruction by instruction, the requests, sectors (or transactions),
//! wavefronts and bank conflicts that the counter model counts in a normal
//! launch; and the units the view lists are as many as it counts.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use warplight::launch_spec::{self, Spec};
use warplight::model::explain::explain;
use warplight::model::{InstMem, Profile};
use warplight::ptx::ir::MemSpace;
use warplight::sim::access_log::AccessLog;
use warplight::sim::{Device, LaunchConfig};

fn specs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut v = Vec::new();
    for dir in [root.join("lessons"), root] {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}

type PerInst = BTreeMap<(u32, u32), InstMem>;

fn add(m: &mut PerInst, key: (u32, u32), c: &InstMem) {
    let e = m.entry(key).or_default();
    e.requests += c.requests;
    e.sectors += c.sectors;
    e.wavefronts += c.wavefronts;
    e.bank_conflicts += c.bank_conflicts;
}

#[test]
fn the_view_shows_the_counters_for_every_lesson() {
    let specs = specs();
    assert!(specs.len() >= 6, "lessons found: {specs:?}");
    for path in &specs {
        let spec = Spec::load(path).unwrap();
        for profile in [Profile::Gt200, Profile::Maxwell, Profile::Hopper] {
            // the counters, from normal launches
            let mut dev = Device::with_config(spec.sim_config(0, None, profile, None));
            let prepared = launch_spec::prepare(&spec, &mut dev).unwrap();
            let results = launch_spec::run(&spec, &mut dev, &prepared, profile).unwrap();
            // the view, from stepping the same launches in order on a second device
            let mut sdev = Device::with_config(spec.sim_config(0, None, profile, None));
            let sprep = launch_spec::prepare(&spec, &mut sdev).unwrap();
            for (i, l) in spec.launches.iter().enumerate() {
                let args = launch_spec::arguments(&spec, &sprep, l).unwrap();
                let cfg = LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
                let log = AccessLog::new();
                let mut shown = PerInst::new();
                {
                    let mut st = sdev.stepper_logged(&sprep.module, &l.kernel, cfg, &args, &log).unwrap();
                    while let Some(ev) = st.step().unwrap() {
                        for a in &ev.accesses {
                            let e = explain(profile, a);
                            let units = e.units.iter().filter(|u| u.lanes != 0).count() as u64;
                            match a.space {
                                MemSpace::Global | MemSpace::Local => assert_eq!(
                                    units,
                                    e.cost.sectors,
                                    "{} launch {i} {profile}: {}",
                                    path.display(),
                                    e.summary
                                ),
                                MemSpace::Shared => assert!(units > 0 && e.cost.wavefronts > 0, "{}", e.summary),
                                _ => {}
                            }
                            add(&mut shown, (a.func, a.pc), &e.cost);
                        }
                    }
                }
                let mut counted = PerInst::new();
                for (f, v) in results[i].memory.per_inst.iter().enumerate() {
                    for (pc, c) in v.iter().enumerate() {
                        if *c != InstMem::default() {
                            add(&mut counted, (f as u32, pc as u32), c);
                        }
                    }
                }
                shown.retain(|_, c| *c != InstMem::default());
                assert_eq!(shown, counted, "{} launch {i} under {profile}", path.display());
            }
        }
    }
}
