//! The per-GPU timing model (`src/timing/`, `docs/timing-model.md`): its
//! behaviour on hand-made counter sets, its parameters against the documented
//! values, and the chapter-4 frame rates' independence from the thesis'
//! numbers. `measure_chapter_4_frames` (ignored: minutes) runs the kernels and
//! writes a results file the frame-rate tables print from.

use std::collections::BTreeMap;

use warplight::repro::fabianowski2011::{self as fab, timing as fab_timing};
use warplight::repro::protocol::{FrameRange, Protocol};
use warplight::repro::registry;
use warplight::repro::results::{Results, Sample, SceneInfo};
use warplight::sim::{Arg, Device, LaunchConfig};
use warplight::timing::waits::Waits;
use warplight::timing::{Bound, GTX_280, KernelCounts, Launch, LaunchShape, TimingError, predict};

/// The thesis' launch: 30 persistent CTAs of 256 threads, 54 registers (seed 000 L1896, L2140).
const THESIS_LAUNCH: LaunchShape =
    LaunchShape { ctas: 30, threads_per_cta: 256, registers_per_thread: 54, shared_per_cta: 0 };

fn seconds(counts: KernelCounts, shape: LaunchShape) -> f64 {
    predict(&GTX_280, &Launch { counts, shape }).unwrap().seconds
}

fn instructions(n: f64) -> KernelCounts {
    KernelCounts { warp_instructions: n, ..KernelCounts::default() }
}

#[test]
fn an_issue_bound_kernel_takes_four_cycles_per_warp_instruction_per_sm() {
    // 30 SMs, 8 warps each (>= 6 cover the 24-cycle register latency): 4 cycles an instruction
    let p = predict(&GTX_280, &Launch { counts: instructions(30e6), shape: THESIS_LAUNCH }).unwrap();
    assert!((p.cycles - 4e6).abs() < 1e-6, "{p:?}");
    assert_eq!(p.bound, Bound::Issue);
    assert_eq!(p.warps_per_sm, 8);
}

#[test]
fn doubling_the_instructions_of_an_issue_bound_kernel_halves_the_frame_rate() {
    // loads whose latency the 8 warps hide: one texture hit per 200 instructions
    let c = KernelCounts {
        warp_instructions: 6e7,
        texture_waits: 3e5,
        texture_loads: 3e5,
        texel_fetches: 9.6e6,
        ..Default::default()
    };
    let one = predict(&GTX_280, &Launch { counts: c, shape: THESIS_LAUNCH }).unwrap();
    assert_eq!(one.bound, Bound::Issue);
    let mut c2 = c;
    c2.warp_instructions *= 2.0;
    let two = predict(&GTX_280, &Launch { counts: c2, shape: THESIS_LAUNCH }).unwrap();
    let ratio = two.fps() / one.fps();
    assert!((ratio - 0.5).abs() < 0.02, "fps ratio {ratio}");
}

#[test]
fn sfu_instructions_and_bank_conflicts_cost_their_issue_cycles() {
    let base = seconds(instructions(30e6), THESIS_LAUNCH);
    let sfu = KernelCounts { warp_instructions: 30e6, sfu_instructions: 30e6, ..Default::default() };
    assert!((seconds(sfu, THESIS_LAUNCH) / base - 4.0).abs() < 1e-9, "16 SFU cycles vs 4");
    let conflicts = KernelCounts { warp_instructions: 30e6, shared_extra_passes: 30e6, ..Default::default() };
    assert!((seconds(conflicts, THESIS_LAUNCH) / base - 1.5).abs() < 1e-9, "+2 cycles per extra pass");
}

#[test]
fn residency_follows_the_compute_capability_1_3_limits() {
    let r = |threads, regs, shared, ctas| {
        GTX_280.residency(&LaunchShape {
            ctas,
            threads_per_cta: threads,
            registers_per_thread: regs,
            shared_per_cta: shared,
        })
    };
    // the thesis' check (seed extract §2.2): 54 x 256 = 13,824 registers, 14,336 allocated, one CTA
    let one = r(256, 54, 0, 3000).unwrap();
    assert_eq!((one.ctas_per_sm, one.warps_per_sm, one.limiter), (1, 8, "registers"));
    // 16 registers: four CTAs of 256 threads fill the 32 warps
    let four = r(256, 16, 0, 3000).unwrap();
    assert_eq!((four.ctas_per_sm, four.limiter), (4, "threads"));
    // shared memory: 6 KB per CTA (rounded to 512 B) leaves room for two
    let two = r(64, 8, 6000, 3000).unwrap();
    assert_eq!((two.ctas_per_sm, two.limiter), (2, "shared memory"));
    // small CTAs: the 8 slots bind
    let slots = r(32, 8, 0, 3000).unwrap();
    assert_eq!((slots.ctas_per_sm, slots.limiter), (8, "CTA slots"));
    // the persistent launch gives each SM one CTA whatever fits
    let launch = r(256, 16, 0, 30).unwrap();
    assert_eq!((launch.ctas_per_sm, launch.limiter, launch.active_sms), (1, "launch", 30));
    // 128 registers x 256 threads = 32,768 > 16,384
    assert!(matches!(r(256, 128, 0, 30), Err(TimingError::DoesNotFit { limiter: "registers", .. })));
    assert_eq!(r(0, 16, 0, 30), Err(TimingError::EmptyLaunch));
}

#[test]
fn too_few_warps_expose_the_register_latency() {
    // 2 warps per SM cannot issue a dependent instruction more often than every 24 / 2 cycles
    let two = LaunchShape { threads_per_cta: 64, ..THESIS_LAUNCH };
    let ratio = seconds(instructions(30e6), two) / seconds(instructions(30e6), THESIS_LAUNCH);
    assert!((ratio - 3.0).abs() < 1e-9, "{ratio}");
}

#[test]
fn a_latency_bound_kernel_speeds_up_with_resident_warps() {
    // every 5 instructions a dependent global load of 440 cycles
    let c = KernelCounts { warp_instructions: 5e6 * 30.0, global_waits: 1e6 * 30.0, ..Default::default() };
    let few = LaunchShape { threads_per_cta: 64, registers_per_thread: 16, ..THESIS_LAUNCH };
    let many = LaunchShape { threads_per_cta: 512, registers_per_thread: 16, ..THESIS_LAUNCH };
    let (a, b) = (
        predict(&GTX_280, &Launch { counts: c, shape: few }).unwrap(),
        predict(&GTX_280, &Launch { counts: c, shape: many }).unwrap(),
    );
    assert_eq!(a.bound, Bound::Latency);
    // 2 warps: each waits its load's 440 cycles and issues 5 instructions at
    // 24 / 2 cycles (too few warps for the register latency): two rounds in flight
    assert!((a.cycles / (1e6 * (440.0 + 60.0) / 2.0) - 1.0).abs() < 0.05, "{a:?}");
    // 16 warps hide 8 times as much latency
    assert!(b.cycles < a.cycles / 6.0, "{a:?} {b:?}");
    // and at last the issue port binds: 16 x 20 cycles of issue cover 440 cycles of latency
    let mut c4 = c;
    c4.warp_instructions *= 4.0;
    let p = predict(&GTX_280, &Launch { counts: c4, shape: many }).unwrap();
    assert_eq!(p.bound, Bound::Issue, "{p:?}");
}

#[test]
fn a_bandwidth_bound_kernel_runs_at_the_dram_bandwidth() {
    // a copy: 1 GB read and written in 128-byte transactions, 16 warps per SM
    let bytes = 2e9;
    let c = KernelCounts {
        warp_instructions: 5.0 * bytes / 256.0,
        global_waits: bytes / 256.0,
        dram_bytes: bytes,
        ..Default::default()
    };
    let shape = LaunchShape { ctas: 30 * 64, threads_per_cta: 256, registers_per_thread: 8, shared_per_cta: 0 };
    let p = predict(&GTX_280, &Launch { counts: c, shape }).unwrap();
    assert_eq!(p.bound, Bound::Bandwidth, "{p:?}");
    let at_bandwidth = bytes / 141.7e9;
    assert!(p.seconds >= at_bandwidth && p.seconds < 1.1 * at_bandwidth, "{} vs {at_bandwidth}", p.seconds);
}

#[test]
fn texture_misses_lengthen_a_latency_bound_kernel() {
    let hit = KernelCounts {
        warp_instructions: 3e6,
        texture_waits: 3e6,
        texture_loads: 3e6,
        texel_fetches: 3e6,
        ..Default::default()
    };
    let miss = KernelCounts { texture_misses: 3e6, ..hit };
    let shape = LaunchShape { threads_per_cta: 32, ..THESIS_LAUNCH };
    let ratio = seconds(miss, shape) / seconds(hit, shape);
    // one warp: an instruction every 24 cycles (register latency), a texel, then 261 or 371 cycles
    let texel = 1.0 / GTX_280.texels_per_sm_cycle();
    assert!((ratio - (24.0 + texel + 371.0) / (24.0 + texel + 261.0)).abs() < 1e-9, "{ratio}");
}

#[test]
fn bad_counters_are_an_error_not_a_panic() {
    let bad = KernelCounts { warp_instructions: -1.0, ..Default::default() };
    assert!(matches!(predict(&GTX_280, &Launch { counts: bad, shape: THESIS_LAUNCH }), Err(TimingError::BadCounts(_))));
    let nan = KernelCounts { dram_bytes: f64::NAN, ..Default::default() };
    assert!(predict(&GTX_280, &Launch { counts: nan, shape: THESIS_LAUNCH }).is_err());
    let sfu = KernelCounts { warp_instructions: 1.0, sfu_instructions: 2.0, ..Default::default() };
    assert!(predict(&GTX_280, &Launch { counts: sfu, shape: THESIS_LAUNCH }).is_err());
}

/// The parameter table of `docs/timing-model.md`: `| `field` | value | ... |` rows.
fn documented() -> BTreeMap<String, f64> {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/timing-model.md")).unwrap();
    doc.lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let name = cells.get(1)?.strip_prefix('`')?.strip_suffix('`')?;
            let value: f64 = cells.get(2)?.replace([',', ' '], "").parse().ok()?;
            Some((name.to_string(), value))
        })
        .collect()
}

#[test]
fn the_gtx_280_parameters_are_the_documented_values() {
    let doc = documented();
    let ours = serde_json::to_value(&GTX_280).unwrap();
    let ours = ours.as_object().unwrap();
    let mut checked = 0;
    for (k, v) in ours {
        let Some(v) = v.as_f64() else { continue };
        let d = doc.get(k).unwrap_or_else(|| panic!("docs/timing-model.md has no row for `{k}`"));
        assert!((d / v - 1.0).abs() < 1e-9, "`{k}`: documented {d}, code {v}");
        checked += 1;
    }
    assert_eq!(checked, ours.len() - 1, "every numeric parameter is documented");
}

fn results_with(counts: &[(&str, &str, KernelCounts)], resolution: u32) -> Results {
    let protocol = Protocol { name: "custom".into(), frames: 1, resolution };
    let mut r = Results::new("test", protocol, vec![], vec![fab::TRAVERSAL.into()]);
    r.scenes.push(SceneInfo {
        name: "scene6".into(),
        triangles: 804,
        thesis_triangles: None,
        flight_frames: 50,
        frames: vec![FrameRange { start: 0, end: 1 }],
    });
    for (group, variant, c) in counts {
        r.samples.push(Sample {
            group: group.to_string(),
            scene: "scene6".into(),
            frame: Some(0),
            variant: variant.to_string(),
            counters: c.counters(),
        });
    }
    r.normalise();
    r
}

#[test]
fn chapter_4_frame_rates_come_from_the_model_alone() {
    // an issue-bound frame at 256 x 256: 1/4 of the 512 x 512 work
    let base = KernelCounts { warp_instructions: 30.0 * 1e6, ..Default::default() };
    let slower = base.scaled(1.25);
    let names: Vec<&str> = warplight::host::rt_kernels::Variant::ALL.iter().map(|v| v.name()).collect();
    let rows: Vec<(&str, &str, KernelCounts)> =
        names.iter().enumerate().map(|(i, n)| (fab::TRAVERSAL, *n, if i == 0 { base } else { slower })).collect();
    let r = results_with(&rows, 256);
    // 4e6 cycles per 512 x 512 frame at 1.296 GHz
    let fps = fab_timing::fps(&r, fab::TRAVERSAL, "scene6", names[0]);
    assert!((fps - 1.296e9 / 16e6).abs() < 1e-6, "{fps}");
    let e = registry::resolve(&["fabianowski:4.6".to_string()]).unwrap()[0];
    let t = (e.table.render.unwrap())(&e, &r).remove(0);
    let row = t.rows.iter().find(|r| r.label == "scene6").unwrap();
    // every column is ours, the baseline compared with the thesis' 392.6 (not fitted to it)
    assert!((row.cells[0].ours.unwrap() - fps).abs() < 1e-9);
    assert!(row.cells[0].verdict.is_some(), "the baseline column is compared");
    for c in &row.cells[1..] {
        assert!((c.ours.unwrap() + 20.0).abs() < 1e-9, "1/1.25 - 1 = -20 %: {c:?}");
    }
    assert!(t.notes.iter().any(|n| n.starts_with("Per-cell error")), "{:?}", t.notes);
    assert!(!t.notes.iter().any(|n| n.contains("fitted")), "{:?}", t.notes);
}

#[test]
fn results_without_the_timing_counters_give_no_frame_rates() {
    let mut r = results_with(&[], 64);
    r.samples.push(Sample {
        group: fab::TRAVERSAL.into(),
        scene: "scene6".into(),
        frame: Some(0),
        variant: "stack".into(),
        counters: [("warp_instructions".to_string(), 1e6)].into_iter().collect(),
    });
    assert!(fab_timing::fps(&r, fab::TRAVERSAL, "scene6", "stack").is_nan());
}

#[test]
fn frame_rate_tables_run_with_the_texture_cache_model() {
    // the model charges texture misses more latency: a run of 4.1 or 4.6
    // alone without the cache model would count no misses and predict too fast
    for t in ["fabianowski:4.1", "fabianowski:4.6", "fabianowski:4.10"] {
        let e = registry::resolve(&[t.to_string()]).unwrap()[0];
        assert_eq!(registry::lowest_fidelity(&e), warplight::sim::Fidelity::Caches, "{t}");
    }
}

/// Runs the chapter-4 kernels at `TIMING_RES` (128) over `TIMING_FRAMES` (3)
/// frames of `TIMING_SCENES` (scene6,sponza,sibenik,conference) and writes the
/// timing counters as a results file to `TIMING_OUT`, for
/// `warplight tables 4.1 4.6 4.10 --from FILE`.
#[test]
#[ignore = "minutes: runs the chapter-4 kernels on the emulator"]
fn measure_chapter_4_frames() {
    use warplight::host::kdtree::Heuristic;
    use warplight::host::rt_kernels::{self, Variant};
    use warplight::host::scene_file;
    use warplight::model::Profile;
    let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
    let res: u32 = env("TIMING_RES", "128").parse().unwrap();
    let frames: u32 = env("TIMING_FRAMES", "3").parse().unwrap();
    let scenes = env("TIMING_SCENES", "scene6,sponza,sibenik,conference");
    let out = env("TIMING_OUT", "target/timing-results.json");
    let groups = [fab::TRAVERSAL, fab::CACHES, fab::HEURISTICS];
    let mut r = Results::new(
        "measure_chapter_4_frames",
        Protocol { name: "custom".into(), frames, resolution: res },
        vec!["fabianowski:4.1".into(), "fabianowski:4.6".into(), "fabianowski:4.10".into()],
        groups.iter().map(|g| g.to_string()).collect(),
    );
    for name in scenes.split(',') {
        let scene = scene_file::load(&scene_file::resolve(name)).unwrap();
        let n = frames.min(scene.flight.frames);
        let mut ws = warplight::repro::registry::Workspace::new(&scene, 0..n, res);
        let mut runs: Vec<(&str, String, Variant, Heuristic)> = Vec::new();
        for v in Variant::ALL {
            runs.push((fab::TRAVERSAL, v.name().into(), v, Heuristic::Siroh));
        }
        for v in Variant::CACHES {
            runs.push((fab::CACHES, v.name().into(), v, Heuristic::Siroh));
        }
        for (h, hn) in fab::table_4_1::HEURISTICS_RUN {
            runs.push((fab::HEURISTICS, hn.into(), Variant::Stack, h));
        }
        for h in [Heuristic::Sah, Heuristic::Numerical, Heuristic::Siroh] {
            ws.build(h);
        }
        let jobs: Vec<(u32, usize)> = (0..n).flat_map(|f| (0..runs.len()).map(move |i| (f, i))).collect();
        let next = std::sync::atomic::AtomicUsize::new(0);
        let samples = std::sync::Mutex::new(Vec::new());
        let threads: usize = env("TIMING_THREADS", "2").parse().unwrap();
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(|| {
                    loop {
                        let j = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(&(f, i)) = jobs.get(j) else { break };
                        let (group, vname, v, h) = &runs[i];
                        let cam = fab::flight::camera(&scene, f, res);
                        let mut dev = Device::with_config(rt_kernels::sim_config(&cam));
                        let module = rt_kernels::load(&mut dev).unwrap();
                        let shape = fab_timing::shape(&module.prog, v.kernel());
                        assert_eq!(GTX_280.residency(&shape).unwrap().warps_per_sm, 8, "{vname}: {shape:?}");
                        let k = rt_kernels::render(
                            &mut dev,
                            &module,
                            &scene,
                            ws.tree(*h),
                            &cam,
                            scene.flight.light_offset(f),
                            *v,
                            Profile::Gt200,
                        )
                        .unwrap();
                        let c = fab_timing::counts_of(&module.prog, &k.launch, &k.memory);
                        eprintln!("{name} frame {f} {group} {vname}: {c:?}");
                        samples.lock().unwrap().push(Sample {
                            group: group.to_string(),
                            scene: name.into(),
                            frame: Some(f),
                            variant: vname.clone(),
                            counters: c.counters(),
                        });
                    }
                });
            }
        });
        r.samples.extend(samples.into_inner().unwrap());
        r.scenes.push(SceneInfo {
            name: name.into(),
            triangles: scene.triangles.len(),
            thesis_triangles: None,
            flight_frames: scene.flight.frames,
            frames: vec![FrameRange { start: 0, end: n }],
        });
    }
    r.normalise();
    std::fs::write(&out, serde_json::to_string_pretty(&r).unwrap()).unwrap();
    eprintln!("wrote {out}");
}

/// Where a chapter-4 kernel's waits and instructions come from: renders frame
/// 0 of `TIMING_SCENES`' first scene with `TIMING_VARIANT` (stack) at each of
/// `TIMING_RES` (a list, 48), prints the counters per pixel, the model's
/// prediction at 512 x 512, the seconds the emulator took, and at the last
/// resolution the busiest wait points (CUDA line, PTX line, opcode) and the
/// warp instructions per opcode. A diagnostic for `docs/timing-model.md`'s
/// analysis of the absolute frame rates.
#[test]
#[ignore = "diagnostic: prints where a kernel's waits come from"]
fn where_the_waits_come_from() {
    use warplight::host::kdtree::Heuristic;
    use warplight::host::rt_kernels::{self, Variant};
    use warplight::host::scene_file;
    use warplight::model::Profile;
    use warplight::timing::waits::{WaitSite, wait_sites};
    let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
    let name = env("TIMING_SCENES", "sibenik");
    let name = name.split(',').next().unwrap();
    let vname = env("TIMING_VARIANT", "stack");
    let v = Variant::ALL.iter().chain(Variant::CACHES.iter()).find(|v| v.name() == vname).copied().unwrap();
    let scene = scene_file::load(&scene_file::resolve(name)).unwrap();
    let resolutions: Vec<u32> = env("TIMING_RES", "48").split(',').map(|r| r.parse().unwrap()).collect();
    let last = *resolutions.last().unwrap();
    for res in resolutions {
        let mut ws = warplight::repro::registry::Workspace::new(&scene, 0..1, res);
        ws.build(Heuristic::Siroh);
        let cam = fab::flight::camera(&scene, 0, res);
        let mut dev = Device::with_config(rt_kernels::sim_config(&cam));
        let module = rt_kernels::load(&mut dev).unwrap();
        let start = std::time::Instant::now();
        let k = rt_kernels::render(
            &mut dev,
            &module,
            &scene,
            ws.tree(Heuristic::Siroh),
            &cam,
            scene.flight.light_offset(0),
            v,
            Profile::Gt200,
        )
        .unwrap();
        let secs = start.elapsed().as_secs_f64();
        let prog = &module.prog;
        let c = fab_timing::counts_of(prog, &k.launch, &k.memory);
        let px = (res * res) as f64;
        let at512 = c.scaled(512.0 * 512.0 / px);
        let p = predict(&GTX_280, &Launch { counts: at512, shape: THESIS_LAUNCH }).unwrap();
        eprintln!(
            "{name} {vname} {res}x{res} in {secs:.1} s: per pixel {:.1} warp instructions, {:.2} texture waits, {:.2} global waits, {:.1} texel fetches, {:.2} texture misses, {:.0} DRAM bytes; at 512x512 {:.1} fps ({:?}, issue {:.0} %)",
            c.warp_instructions / px,
            c.texture_waits / px,
            c.global_waits / px,
            c.texel_fetches / px,
            c.texture_misses / px,
            c.dram_bytes / px,
            p.fps(),
            p.bound,
            p.issue_utilisation * 100.0
        );
        if res != last {
            continue;
        }
        let mut sites = wait_sites(prog, &k.launch.profile);
        let n = |s: &WaitSite| s.waits.global + s.waits.texture + s.waits.shared;
        sites.sort_by_key(|s| std::cmp::Reverse(n(s)));
        let total: u64 = sites.iter().map(n).sum();
        eprintln!("{total} waits at {} points", sites.len());
        for s in sites.iter().take(30) {
            let info = &prog.functions[s.function].info[s.pc];
            eprintln!(
                "{:>9} {:5.1}%  {:?}  cu {:?}  ptx {}  {}",
                n(s),
                n(s) as f64 / total as f64 * 100.0,
                s.waits,
                info.src.map(|l| l.line),
                info.ptx_line,
                info.opcode
            );
        }
        let mut ops: BTreeMap<String, u64> = BTreeMap::new();
        for (f, counts) in prog.functions.iter().zip(&k.launch.profile.per_fn) {
            for (info, c) in f.info.iter().zip(counts) {
                *ops.entry(info.opcode.clone()).or_default() += c.warp;
            }
        }
        let mut ops: Vec<_> = ops.into_iter().filter(|(_, c)| *c > 0).collect();
        ops.sort_by_key(|(_, c)| std::cmp::Reverse(*c));
        let all: u64 = ops.iter().map(|(_, c)| c).sum();
        for (o, c) in ops {
            eprintln!("{c:>10} {:5.2}%  {o}", c as f64 / all as f64 * 100.0);
        }
    }
}

/// A label that no branch names (clang's line-table labels) between two
/// loads leaves both pending: one wait at their use. A branch target
/// between them ends the run: a wait there and one at the use.
#[test]
fn only_branch_targets_end_a_run_of_loads() {
    let ptx = |label: &str, branch: &str| {
        format!(
            r#"
.version 7.0
.target sm_50
.address_size 64
.visible .entry k(.param .u64 p)
{{
.reg .pred %p<2>;
.reg .b32 %r<8>;
.reg .b64 %rd<4>;
ld.param.u64 %rd1, [p];
mov.u32 %r7, 0;
setp.eq.s32 %p1, %r7, 1;
{branch}
ld.global.nc.u32 %r1, [%rd1];
{label}:
ld.global.nc.u32 %r2, [%rd1+4];
add.s32 %r3, %r1, %r2;
st.global.u32 [%rd1+8], %r3;
ret;
}}
"#
        )
    };
    let run = |src: String| {
        let mut dev = Device::new();
        let m = dev.load_ptx(&src, "labels.ptx").unwrap();
        let a = dev.alloc_zeroed::<u32>(4);
        let stats = dev.launch(&m, "k", LaunchConfig::linear(1, 32), &[Arg::Ptr(a)]).unwrap();
        warplight::timing::waits::waits(&m.prog, &stats.profile)
    };
    assert_eq!(run(ptx("$L__tmp1", "")), Waits { global: 0, texture: 1, shared: 0 });
    // `%p1` is false: the branch falls through to the first load
    assert_eq!(run(ptx("$L__BB0_1", "@%p1 bra $L__BB0_1;")), Waits { global: 0, texture: 2, shared: 0 });
}
