//! The checker (`--check`, `src/check`) on planted bugs: each planted kernel
//! (kernels/tests/planted_*.cu) gets the hazards compute-sanitizer reported
//! for it on an H200 (tests/fixtures/sanitizer/<tool>.txt, recorded by
//! tools/device/sanitizer.sh), classes and CUDA lines, plus the ones
//! compute-sanitizer does not look for (docs/checking.md); clean kernels get
//! none; reports do not depend on host threads; the random schedule shows
//! the race that lockstep scheduling hides.

use std::collections::BTreeSet;
use std::path::Path;

use warplight::check::cli::{CheckArgs, ScheduleKind};
use warplight::check::{Hazard, Report};
use warplight::launch_spec::{self, Spec};
use warplight::model::Profile;
use warplight::sim::Device;

const PLANTED: [&str; 10] = [
    "planted_race_raw",
    "planted_race_waw",
    "planted_race_global",
    "planted_uninit_global",
    "planted_uninit_shared",
    "planted_oob",
    "planted_barrier_divergent",
    "planted_barrier_mismatch",
    "planted_warp_race_synced",
    "planted_warp_race_nosync",
];

fn args(tools: &str, uninit: &[&str], seed: Option<u64>) -> CheckArgs {
    CheckArgs {
        check: tools.split(',').map(String::from).collect(),
        uninit: uninit.iter().map(|s| s.to_string()).collect(),
        schedule: if seed.is_some() { ScheduleKind::Random } else { ScheduleKind::Lockstep },
        seed: seed.unwrap_or(1),
    }
}

/// Runs a spec checked; returns the reports and buffer `out`'s (or `read`'s) values.
fn run(spec: &Path, a: &CheckArgs, threads: usize, read: &str) -> (Vec<Report>, Vec<i32>) {
    let spec = Spec::load(spec).unwrap();
    let mut config = spec.sim_config(threads, None, warplight::model::Profile::Hopper, None);
    a.configure(&mut config).unwrap();
    let mut dev = Device::with_config(config);
    let p = launch_spec::prepare(&spec, &mut dev).unwrap();
    let opts = a.options(&p).unwrap();
    let r = warplight::check::spec::run(&spec, &mut dev, &p, Profile::Hopper, &opts);
    let values = p.buffers.get(read).map(|(ptr, b)| dev.read::<i32>(*ptr, b.len)).unwrap_or_default();
    (r.reports.into_iter().map(|(_, r)| r).collect(), values)
}

fn planted(name: &str) -> (Vec<Report>, Vec<i32>) {
    let uninit: &[&str] = if name == "planted_uninit_global" { &["in"] } else { &[] };
    run(&Path::new("tests/fixtures/sanitizer").join(format!("{name}.toml")), &args("all", uninit, None), 2, "out")
}

/// A hazard as both tools can state it: tool, class and the CUDA lines
/// (races: the unordered pair of accesses, each "write@L"/"read@L").
type Sig = (String, String, Vec<String>);

/// compute-sanitizer's hazards per kernel, from a fixture.
fn sanitizer(tool: &str, kernel: &str) -> BTreeSet<Sig> {
    let text = std::fs::read_to_string(format!("tests/fixtures/sanitizer/{tool}.txt")).unwrap();
    // sections start with "=== KERNEL" (compute-sanitizer's own lines with "=========")
    let lines: Vec<&str> = text
        .lines()
        .skip_while(|l| *l != format!("=== {kernel}"))
        .skip(1)
        .take_while(|l| !l.starts_with("=== ") || l.starts_with("===="))
        .collect();
    assert!(!lines.is_empty(), "{tool}.txt has a section for {kernel}");
    let line_of = |s: &str| s.rsplit(':').next().unwrap().split_whitespace().next().unwrap().to_string();
    let mut out = BTreeSet::new();
    for (i, l) in lines.iter().enumerate() {
        let at = || line_of(lines[i + 1]);
        if l.contains("Invalid __global__") {
            out.insert((tool.into(), "out of bounds".into(), vec![at()]));
        } else if l.contains("Uninitialized __global__ memory read") {
            out.insert((tool.into(), "uninitialised global read".into(), vec![at()]));
        } else if l.contains("Divergent thread(s) in warp") {
            out.insert((tool.into(), "divergent barrier".into(), vec![at()]));
        } else if l.contains("Divergent thread(s) in block") {
            out.insert((tool.into(), "barriers not met by the whole block".into(), vec![at()]));
        } else if l.contains("Race reported between") {
            let first = format!("{}@{}", access(l), line_of(l.split(" and ").next().unwrap()));
            for other in lines[i + 1..].iter().take_while(|o| o.contains("and ") && o.contains("access at")) {
                let mut pair = vec![first.clone(), format!("{}@{}", access(other), line_of(other))];
                pair.sort();
                pair.dedup();
                out.insert((tool.into(), "shared race".into(), pair));
            }
        }
    }
    out
}

fn access(l: &str) -> &'static str {
    if l.contains("Write access") { "write" } else { "read" }
}

/// warplight's hazards in the same terms.
fn warplight(reports: &[Report]) -> BTreeSet<Sig> {
    let line = |r: &Report, i: usize| r.sites[i].source.as_ref().unwrap().1.to_string();
    reports
        .iter()
        .map(|r| {
            let tool = r.hazard.tool().to_string();
            match r.hazard {
                Hazard::OutOfBounds => (tool, "out of bounds".into(), vec![line(r, 0)]),
                Hazard::UninitializedRead => (tool, format!("uninitialised {} read", r.space), vec![line(r, 0)]),
                Hazard::DivergentBarrier => (tool, "divergent barrier".into(), vec![line(r, 0)]),
                // compute-sanitizer names the barrier the first warp waits at
                Hazard::MismatchedBarrier => (tool, "barriers not met by the whole block".into(), vec![line(r, 0)]),
                h => {
                    let [a, b] = h.roles();
                    let mut pair = vec![format!("{a}@{}", line(r, 0)), format!("{b}@{}", line(r, 1))];
                    pair.sort();
                    pair.dedup();
                    (tool, format!("{} race", r.space), pair)
                }
            }
        })
        .collect()
}

/// What warplight finds that compute-sanitizer does not look for
/// (docs/checking.md): races on global memory, uninitialised shared memory.
fn beyond_sanitizer(s: &Sig) -> bool {
    s.1 == "global race" || s.1 == "uninitialised shared read"
}

#[test]
fn planted_bugs_give_the_hazards_compute_sanitizer_reports() {
    for k in PLANTED {
        let (reports, _) = planted(k);
        let ours = warplight(&reports);
        let theirs: BTreeSet<Sig> =
            ["memcheck", "racecheck", "initcheck", "synccheck"].iter().flat_map(|t| sanitizer(t, k)).collect();
        let ours_comparable: BTreeSet<Sig> = ours.iter().filter(|s| !beyond_sanitizer(s)).cloned().collect();
        assert_eq!(ours_comparable, theirs, "{k}: warplight (left) vs compute-sanitizer (right)\n{reports:#?}");
        let extra: Vec<&Sig> = ours.iter().filter(|s| beyond_sanitizer(s)).collect();
        match k {
            "planted_race_global" => {
                let race =
                    |p: &[&str]| ("racecheck".into(), "global race".into(), p.iter().map(|x| x.to_string()).collect());
                let want: Vec<Sig> = vec![race(&["read@6", "write@6"]), race(&["write@6"])];
                assert_eq!(extra, want.iter().collect::<Vec<_>>(), "{k}: the global race between CTAs")
            }
            "planted_uninit_shared" => assert_eq!(extra.len(), 1, "{k}: the uninitialised shared read: {extra:?}"),
            _ => assert!(extra.is_empty(), "{k}: {extra:?}"),
        }
        // the one clean kernel: the lanes swap values across __syncwarp()
        let clean = k == "planted_warp_race_synced";
        assert_eq!(reports.is_empty(), clean, "{k}: every planted kernel but the synced swap has a hazard");
    }
}

#[test]
fn reports_name_buffers_threads_and_lines() {
    let (r, _) = planted("planted_oob");
    let oob = &r[0];
    assert_eq!(oob.location, "data[4096]");
    assert!(oob.note.contains("one past the end of `data` (4096 elements of 4 bytes)"), "{}", oob.note);
    // compute-sanitizer: "by thread (255,0,0) in block (15,0,0)"
    assert_eq!((oob.sites[0].cta, oob.sites[0].first_thread), ([15, 0, 0], [255, 0, 0]));
    let (r, _) = planted("planted_uninit_global");
    // compute-sanitizer: threads 0..31 of block 0 read `in` uninitialised
    assert_eq!((r[0].location.as_str(), r[0].sites[0].lanes, r[0].count), ("in[0]", u32::MAX, 32));
    let (r, _) = planted("planted_barrier_divergent");
    assert_eq!(r[0].sites[0].lanes, 0xFFFF, "threads 0..15 reach the barrier, as compute-sanitizer reports");
    let (r, _) = planted("planted_race_waw");
    let waw = r.iter().find(|r| r.hazard == Hazard::WriteAfterWrite).unwrap();
    assert_eq!(waw.location, "winner[0] (shared offset 0x0)");
    assert_ne!(waw.sites[0].warp, waw.sites[1].warp, "the race is between warps");
    let text = waw.to_string();
    assert!(text.contains("planted_race_waw.cu:7") && text.contains("PTX line"), "{text}");
}

#[test]
fn reports_do_not_depend_on_host_threads() {
    for k in ["planted_race_raw", "planted_race_global", "planted_oob"] {
        let spec = Path::new("tests/fixtures/sanitizer").join(format!("{k}.toml"));
        let one = run(&spec, &args("all", &[], None), 1, "out").0;
        let many = run(&spec, &args("all", &[], None), 8, "out").0;
        assert_eq!(one, many, "{k}");
    }
}

#[test]
fn clean_kernels_report_nothing() {
    for lesson in ["banks", "coalescing", "divergence", "reduction", "stackless", "votes"] {
        let spec = Path::new("examples/lessons").join(format!("{lesson}.toml"));
        let (r, _) = run(&spec, &args("all", &[], None), 2, "");
        assert!(r.is_empty(), "lesson {lesson}: {r:#?}");
    }
    let (r, _) = run(Path::new("examples/reduce.toml"), &args("all", &[], None), 2, "");
    assert!(r.is_empty(), "examples/reduce.toml: {r:#?}");
}

#[test]
fn lockstep_hides_the_race_and_the_random_schedule_shows_it() {
    let spec = Path::new("tests/fixtures/sanitizer/planted_race_raw.toml");
    // in[i] = i mod 7: the true sums of the two CTAs' 256 elements
    let truth: Vec<i32> = (0..2).map(|c| (0..256).map(|i| (256 * c + i) % 7).sum()).collect();
    let (_, lockstep) = run(spec, &args("memcheck", &[], None), 2, "sums");
    assert_eq!(lockstep, truth, "without the barrier the lockstep schedule still gives the right sums");
    let seeds: Vec<Vec<i32>> = (1..=4).map(|s| run(spec, &args("memcheck", &[], Some(s)), 2, "sums").1).collect();
    assert!(seeds.iter().any(|s| *s != truth), "some seed shows the race: {seeds:?}");
    assert_eq!(run(spec, &args("memcheck", &[], Some(3)), 1, "sums").1, seeds[2], "a seed is one run");
    // the race-free lesson is right under any schedule
    let (_, sums) = run(Path::new("examples/lessons/reduction.toml"), &args("memcheck", &[], Some(5)), 2, "sums");
    let (_, reference) = run(Path::new("examples/lessons/reduction.toml"), &args("memcheck", &[], None), 2, "sums");
    assert_eq!(sums, reference);
}

#[test]
fn the_command_line_checks_and_names() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["launch", "tests/fixtures/sanitizer/planted_oob.toml", "--check", "memcheck", "--metrics", "ctas"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!out.status.success(), "the out-of-bounds read stops the launch");
    assert!(text.contains("memcheck: out-of-bounds access on global memory at data[4096]"), "{text}");
    assert!(text.contains("check (memcheck): 1 hazard"), "{text}");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["launch", "examples/lessons/reduction.toml", "--check", "racecheck,synccheck", "--json"])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["check"], serde_json::json!([]));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["launch", "examples/lessons/reduction.toml", "--check", "racecheque"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown tool"));
}

/// The thesis' ray-tracing kernel (every variant) on a 12×12 frame of the
/// Cornell box, its buffers laid out by `rt_kernels::upload_scene` as
/// `rt_kernels::render` lays them out, reports nothing.
#[test]
fn the_ray_tracing_kernel_reports_nothing() {
    use glam::Vec3;
    use warplight::check::{CheckOptions, Tools, launch_checked};
    use warplight::host::kdtree::layout::layout;
    use warplight::host::kdtree::{BuildParams, Heuristic, build};
    use warplight::host::rt_kernels::{self, Variant};
    use warplight::sim::LaunchConfig;

    let scene = warplight::host::scene_file::load(Path::new("scenes/cornell-box.toml")).unwrap();
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = scene.flight.camera(&scene.camera, 0);
    cam.resolution = [12, 12];
    let mut dev = Device::new();
    let module = rt_kernels::load(&mut dev).unwrap();
    let opts = CheckOptions { tools: Tools::ALL, ..Default::default() };
    for v in Variant::ALL {
        let lay = layout(&tree, &tris, v.heap_levels());
        let bufs = rt_kernels::upload_scene(&mut dev, &scene, &tree, &lay, &cam, Vec3::ZERO).unwrap();
        let cfg = LaunchConfig::linear(rt_kernels::CTAS, rt_kernels::THREADS);
        let c = launch_checked(&mut dev, &module, v.kernel(), cfg, &bufs.launch_args(), &opts, None).unwrap();
        assert!(c.fault.is_none(), "{v:?}: {:?}", c.fault);
        assert!(c.reports.is_empty(), "{v:?}: {:#?}", c.reports);
    }
}

/// `__syncwarp()` (`bar.warp.sync`) orders the lanes of a warp: lanes that
/// swap values through shared memory across it do not race; the same kernel
/// without it races between lanes of one warp (kernels/tests/planted_warp_race.cu;
/// compute-sanitizer's racecheck reports the same three pairs on the H200 and
/// nothing for the synced kernel: `planted_bugs_give_the_hazards_compute_sanitizer_reports`).
#[test]
fn syncwarp_orders_the_lanes_of_a_warp() {
    let dir = Path::new("tests/fixtures/sanitizer");
    let (r, synced) = run(&dir.join("planted_warp_race_synced.toml"), &args("all", &[], None), 2, "out");
    assert!(r.is_empty(), "across __syncwarp: {r:#?}");
    // out[64c + t] = s[t ^ 1] = v(t ^ 1) + (t ^ 1), v(u) = s[u ^ 1] = 3 (u ^ 1) + c
    let want: Vec<i32> = (0..128).map(|i| 3 * (i % 64) + i / 64 + ((i % 64) ^ 1)).collect();
    assert_eq!(synced, want);
    // what the H200 computed (tests/fixtures/sanitizer/plain.txt)
    let plain = std::fs::read_to_string(dir.join("plain.txt")).unwrap();
    for k in ["planted_warp_race_synced", "planted_warp_race_nosync"] {
        let section = plain.split(&format!("=== {k}\n")).nth(1).unwrap();
        let gpu: Vec<i32> = section
            .lines()
            .next()
            .unwrap()
            .trim_start_matches("out:")
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(gpu, want, "{k} on the H200");
    }
    let (r, nosync) = run(&dir.join("planted_warp_race_nosync.toml"), &args("all", &[], None), 2, "out");
    assert_eq!(nosync, want, "lockstep execution hides the race");
    let race = |p: &[&str]| ("racecheck".into(), "shared race".into(), p.iter().map(|x| x.to_string()).collect());
    let want: BTreeSet<Sig> =
        [race(&["read@24", "write@23"]), race(&["read@26", "write@25"]), race(&["read@24", "write@25"])].into();
    assert_eq!(warplight(&r), want, "{r:#?}");
    for x in &r {
        assert_eq!(x.sites[0].warp, x.sites[1].warp, "a race between lanes of one warp: {x}");
        assert_eq!(x.sites[0].cta, x.sites[1].cta);
    }
}

/// Reads by lanes that a partial `__syncwarp(mask)` does not order still
/// race with a write after it, however many lanes read the same element
/// (`v = s[0]` by the whole warp; lanes 16-31 pass `__syncwarp(0xFFFF0000)`;
/// lane 31 writes `s[0]`: lanes 0-15's reads race with it).
#[test]
fn a_partial_syncwarp_leaves_the_other_lanes_reads_racing() {
    let dir = std::env::temp_dir().join(format!("warplight-partial-syncwarp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = r#".version 7.8
.target sm_90
.address_size 64
.visible .entry partial_sync(.param .u64 out)
{
    .reg .pred %p<3>;
    .reg .b32 %r<3>;
    .reg .b64 %rd<4>;
    .shared .align 4 .b32 s[1];
    mov.u32 %r1, %tid.x;
    ld.shared.u32 %r2, [s];
    setp.lt.u32 %p1, %r1, 16;
    @%p1 bra DONE;
    bar.warp.sync -65536;
    setp.ne.u32 %p2, %r1, 31;
    @%p2 bra DONE;
    st.shared.u32 [s], 1;
DONE:
    ld.param.u64 %rd1, [out];
    cvta.to.global.u64 %rd1, %rd1;
    mul.wide.u32 %rd2, %r1, 4;
    add.s64 %rd3, %rd1, %rd2;
    st.global.u32 [%rd3], %r2;
    ret;
}
"#;
    std::fs::write(dir.join("partial_sync.ptx"), ptx).unwrap();
    let spec = "ptx = \"partial_sync.ptx\"\nkernel = \"partial_sync\"\ngrid = 1\nblock = 32\nargs = [\"out\"]\n\
                [[buffer]]\nname = \"out\"\ntype = \"i32\"\nlen = 32\n";
    std::fs::write(dir.join("spec.toml"), spec).unwrap();
    let (r, _) = run(&dir.join("spec.toml"), &args("racecheck", &[], None), 1, "out");
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(r.len(), 1, "{r:#?}");
    assert_eq!(r[0].hazard, Hazard::WriteAfterRead, "{r:#?}");
    assert_eq!((r[0].sites[0].lanes, r[0].sites[1].lanes), (1 << 31, 0xFFFF), "{r:#?}");
}

/// Writes `spec` and `ptx` to a fresh folder and runs the spec checked with
/// `tools` (`uninit`: buffers tracked as uninitialised).
fn run_files(tag: &str, spec: &str, ptx: &str, tools: &str, uninit: &[&str]) -> Vec<Report> {
    let dir = std::env::temp_dir().join(format!("warplight-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("k.ptx"), ptx).unwrap();
    std::fs::write(dir.join("spec.toml"), spec).unwrap();
    let (r, _) = run(&dir.join("spec.toml"), &args(tools, uninit, None), 1, "out");
    std::fs::remove_dir_all(&dir).ok();
    r
}

/// Surface stores and loads (`sust`, `suld`) and texel fetches (`tex`) are
/// global accesses to the checker: `sust` initialises what `ld.global` then
/// reads, two CTAs storing one element race, and a texel fetch of a
/// `--uninit` buffer nothing wrote is an uninitialised read.
#[test]
fn the_checker_sees_surface_and_texture_accesses() {
    let ptx = r#".version 7.8
.target sm_90
.address_size 64
.visible .entry store_then_load(.param .u64 img, .param .u64 pix, .param .u64 out)
{
    .reg .b32 %r<5>;
    .reg .b64 %rd<8>;
    ld.param.u64 %rd1, [img];
    ld.param.u64 %rd2, [pix];
    ld.param.u64 %rd3, [out];
    cvta.to.global.u64 %rd2, %rd2;
    cvta.to.global.u64 %rd3, %rd3;
    mov.u32 %r1, %tid.x;
    shl.b32 %r2, %r1, 2;
    sust.b.1d.b32.trap [%rd1, {%r2}], {%r1};
    bar.sync 0;
    mul.wide.u32 %rd4, %r1, 4;
    add.s64 %rd5, %rd2, %rd4;
    ld.global.u32 %r3, [%rd5];
    add.s64 %rd6, %rd3, %rd4;
    st.global.u32 [%rd6], %r3;
    ret;
}
.visible .entry store_one(.param .u64 img, .param .u64 pix, .param .u64 out)
{
    .reg .b32 %r<3>;
    .reg .b64 %rd<2>;
    ld.param.u64 %rd1, [img];
    mov.u32 %r1, 0;
    mov.u32 %r2, %ctaid.x;
    sust.b.1d.b32.trap [%rd1, {%r1}], {%r2};
    ret;
}
.visible .entry fetch(.param .u64 tex, .param .u64 pix, .param .u64 out)
{
    .reg .b32 %r<6>;
    .reg .b64 %rd<5>;
    ld.param.u64 %rd1, [tex];
    ld.param.u64 %rd2, [out];
    cvta.to.global.u64 %rd2, %rd2;
    mov.u32 %r1, %tid.x;
    tex.1d.v4.s32.s32 {%r2, %r3, %r4, %r5}, [%rd1, {%r1}];
    mul.wide.u32 %rd3, %r1, 4;
    add.s64 %rd4, %rd2, %rd3;
    st.global.u32 [%rd4], %r2;
    ret;
}
"#;
    let spec = |kernel: &str, grid: u32, object: &str| {
        format!(
            "ptx = \"k.ptx\"\nkernel = \"{kernel}\"\ngrid = {grid}\nblock = 32\nargs = [\"img\", \"pix\", \"out\"]\n\
             [[buffer]]\nname = \"pix\"\ntype = \"i32\"\nlen = 32\n\
             [[buffer]]\nname = \"out\"\ntype = \"i32\"\nlen = 32\n\
             [[{object}]]\nname = \"img\"\nbuffer = \"pix\"\nformat = \"s32\"\nwidth = 32\n"
        )
    };
    // sust initialises: the loads after it read written bytes
    let r = run_files("surface-init", &spec("store_then_load", 1, "surface"), ptx, "all", &["pix"]);
    assert!(r.is_empty(), "{r:#?}");
    // two CTAs store element 0 with nothing between them
    let r = run_files("surface-race", &spec("store_one", 2, "surface"), ptx, "racecheck", &[]);
    assert_eq!(r.iter().map(|x| x.hazard).collect::<Vec<_>>(), [Hazard::WriteAfterWrite], "{r:#?}");
    // texels nothing wrote
    let r = run_files("texture-uninit", &spec("fetch", 1, "texture"), ptx, "initcheck", &["pix"]);
    assert_eq!(r.iter().map(|x| x.hazard).collect::<Vec<_>>(), [Hazard::UninitializedRead], "{r:#?}");
}
