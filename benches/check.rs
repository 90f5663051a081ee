//! What `--check` costs: the same launches run as `warplight launch` runs
//! them (fidelity `memory`, the Hopper memory model observing) without a
//! checker, with racecheck alone and with all four tools. Besides criterion's
//! timings it prints, in one run, each checked time as a ratio of the
//! unchecked one (the number `docs/checking.md` quotes).

use std::path::Path;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use warplight::check::{CheckOptions, Tools, launch_checked};
use warplight::launch_spec::{self, Prepared, Spec};
use warplight::model::{Model, Profile};
use warplight::sim::{Arg, Device, Fidelity, LaunchConfig};

/// A reduction in shared memory (barriers, shared traffic), a lesson with
/// divergence and the ray-tracing lesson's stackless traversal (global loads).
const SPECS: [&str; 3] =
    ["examples/reduce.toml", "examples/lessons/divergence.toml", "examples/lessons/stackless.toml"];

/// A spec's first launch, ready to run again and again.
struct Case {
    name: &'static str,
    dev: Device,
    prepared: Prepared,
    kernel: String,
    cfg: LaunchConfig,
    args: Vec<Arg>,
}

fn case(path: &'static str) -> Case {
    let spec = Spec::load(Path::new(path)).expect("spec");
    let mut config = spec.sim_config(1, None, warplight::model::Profile::Hopper, None);
    if config.fidelity < Fidelity::Memory {
        config.fidelity = Fidelity::Memory;
    }
    let mut dev = Device::with_config(config);
    let prepared = launch_spec::prepare(&spec, &mut dev).expect("prepares");
    let l = &spec.launches[0];
    let args = launch_spec::arguments(&spec, &prepared, l).expect("arguments");
    let cfg = LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
    Case { name: path, dev, prepared, kernel: l.kernel.clone(), cfg, args }
}

/// The checker's options: `tools`, no buffer left uninitialised.
fn options(tools: &[&str]) -> CheckOptions {
    let names: Vec<String> = tools.iter().map(|t| t.to_string()).collect();
    CheckOptions { tools: Tools::parse(&names).expect("tools"), uninit: Vec::new(), elem_sizes: Default::default() }
}

/// One launch: unchecked (`opts` none) or checked.
fn launch(c: &mut Case, opts: Option<&CheckOptions>) {
    let m = &c.prepared.module;
    let model = Model::new(Profile::Hopper, &m.prog);
    match opts {
        None => {
            c.dev.launch_observed(m, &c.kernel, c.cfg, &c.args, Some(&model)).expect("runs");
        }
        Some(o) => {
            let r = launch_checked(&mut c.dev, m, &c.kernel, c.cfg, &c.args, o, Some(&model)).expect("runs");
            assert!(r.reports.is_empty(), "{}: the clean kernel reports hazards", c.name);
        }
    }
}

/// Seconds per launch of each configuration (unchecked, racecheck, all four):
/// the least of five rounds, the configurations interleaved within a round so
/// that the machine's load drifts alike for all three; each round runs a
/// configuration for about 50 ms.
fn seconds(c: &mut Case, configs: [Option<&CheckOptions>; 3]) -> [f64; 3] {
    for o in configs {
        launch(c, o);
    }
    let t0 = Instant::now();
    launch(c, None);
    let reps = (0.05 / t0.elapsed().as_secs_f64().max(1e-6)).ceil().clamp(3.0, 10_000.0) as u32;
    let mut best = [f64::INFINITY; 3];
    for _ in 0..5 {
        for (k, o) in configs.iter().enumerate() {
            let t0 = Instant::now();
            for _ in 0..reps {
                launch(c, *o);
            }
            best[k] = best[k].min(t0.elapsed().as_secs_f64() / reps as f64);
        }
    }
    best
}

fn report() {
    eprintln!("\n--check cost (1 host thread): time checked / time unchecked, same launch, same run");
    eprintln!("{:<36} {:>14} {:>12} {:>12}", "spec", "unchecked ms", "racecheck", "all four");
    let (race, all) = (options(&["racecheck"]), options(&["all"]));
    for path in SPECS {
        let mut c = case(path);
        let [off, r, a] = seconds(&mut c, [None, Some(&race), Some(&all)]);
        eprintln!("{:<36} {:>14.3} {:>11.2}x {:>11.2}x", path, off * 1e3, r / off, a / off);
    }
}

fn bench(cr: &mut Criterion) {
    report();
    let mut g = cr.benchmark_group("check");
    g.sample_size(10);
    let all = options(&["all"]);
    for path in SPECS {
        let mut c = case(path);
        let short = Path::new(path).file_stem().and_then(|s| s.to_str()).unwrap_or(path).to_string();
        g.bench_function(format!("{short}/unchecked"), |b| b.iter(|| launch(&mut c, None)));
        g.bench_function(format!("{short}/all"), |b| b.iter(|| launch(&mut c, Some(&all))));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
