//! The regression corpus of issue 17 (`tests/corpus/`): each hostile or
//! careless input runs through the `warplight` binary and must end with the
//! expected exit code and a clear message — never a panic (101), an abort
//! (134) or a hang. Also: the installed binary from another directory
//! (issue 18), and a bounded mutation fuzz of launch specs and scene files
//! (PTX is fuzzed by `tests/fuzz_parser.rs`).

use std::path::{Path, PathBuf};
use std::process::Command;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

/// Runs the binary in `dir` with a fixed memory budget (machine-independent messages).
fn warplight_in(dir: &Path, args: &[&str]) -> (Option<i32>, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(args)
        .current_dir(dir)
        .env("WARPLIGHT_MEMORY_BUDGET", "2G")
        .env_remove("WARPLIGHT_HOME")
        .output()
        .unwrap();
    (o.status.code(), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("warplight-corpus-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// (command line, exit code, text the output must contain).
const CASES: &[(&str, i32, &str)] = &[
    // 1. a kernel that falls off its end runs
    ("launch empty.toml", 0, "empty.ptx"),
    // 2. recursion without frames
    ("launch recursion.toml", 1, "call stack overflow"),
    // 3. the watchdog
    ("launch runaway.toml", 1, "runaway kernel: more than 50000 warp instructions"),
    // 4. sizes checked before allocation
    ("check regs_range.ptx", 1, "more registers than a function can have"),
    ("launch local_1gb.toml", 1, "kernel `k` has 1 GiB of .local memory per thread; the simulated device has 64 KiB"),
    ("launch len_1e12.toml", 1, "`buffer[0].len`: 1000000000000 elements of 1 bytes is more than a buffer may hold"),
    ("launch global_4tb.toml", 1, "global_4tb.ptx:4:1: over a limit: .global variable `g` is 3.6 TiB; one allocation"),
    ("check local_4gb.ptx", 1, "local_4gb.ptx:7:1: over a limit: .local variable `b` is 2 GiB (4 GiB with"),
    ("check shared_40gb.ptx", 1, "shared_40gb.ptx:6:1: over a limit: .shared variable `s` is 37.3 GiB; a CTA's"),
    ("check const_40gb.ptx", 1, "const_40gb.ptx:4:1: over a limit: .const variable `c` is 37.3 GiB; the constant"),
    ("check dims_overflow.ptx", 1, "dims_overflow.ptx:4:1: over a limit: `h`: its dimensions multiply past 2^64 bytes"),
    ("check param_100k.ptx", 1, "param_100k.ptx:4:19: over a limit: .param variable `p` is 97.7 KiB"),
    ("launch regs_60000.toml", 1, "needs 109.9 GiB of host memory; the budget is 2 GiB (WARPLIGHT_MEMORY_BUDGET)"),
    ("render --scene disc.toml --resolution 100000x100000 -o o.png", 1, "10000000000 pixels is more than 268435456"),
    ("render --scene disc.toml --resolution 16384x16384 -o o.png", 1, "a render of 16384 x 16384 pixels needs 8 GiB"),
    ("render --scene huge_resolution.toml -o o.png", 1, "camera.resolution: 100000 x 100000 pixels is more than"),
    // 5. no silent wrap-around
    ("launch block_overflow.toml", 1, "`block`: block.x = 65536 is more than CUDA allows (1024)"),
    ("launch block_2048.toml", 1, "2048 threads per block is more than CUDA allows (1024)"),
    ("launch grid_wrap.toml", 1, "`grid`: grid.y = 65536 is more than CUDA allows (65535)"),
    ("launch len_2_62.toml", 1, "4611686018427387904 elements of 4 bytes is more than a buffer may hold"),
    ("launch len_2_61.toml", 1, "2305843009213693952 elements of 8 bytes is more than a buffer may hold"),
    ("launch shared_2_32.toml", 1, "`shared`: expected bytes of dynamic shared memory, at most 233472"),
    ("render --scene resolution_wrap.toml -o o.png", 1, "4294967297 x 1 pixels is more than"),
    ("render --scene huge_flight.toml -o o.png", 1, "flight.frames: expected a positive integer, at most 1000000"),
    // 6. the kd-tree of a flat disc (1,998 triangles) builds within its reference budget
    ("render --scene disc.toml --resolution 8x8 -o o.png", 0, "1998 triangles"),
    // 7. the output format is checked first
    ("render --scene disc.toml -o o.jpg", 1, "-o o.jpg: expected a .png or .exr file"),
    ("render --scene disc.toml --frames 2..1 -o o.png", 1, "--frames 2..1: the range is empty"),
    ("render --scene disc.toml --frames 0..2000000 -o o.png", 1, "--frames 0..2000000: the flight has"),
    // 8. nesting
    ("check nesting.ptx", 1, "nested more than 256 deep"),
    // 10. host threads
    ("launch empty.toml --threads 100000", 0, "host threads instead of 100000"),
    // 11. silently accepted input
    ("launch shraed.toml", 1, "`shraed`: unknown key; did you mean `shared`?"),
    ("launch launch_empty.toml", 1, "`launch`: no launch: an empty list runs nothing"),
    ("launch init_wrap.toml", 1, "`buffer[0].init[1]`: 300 is out of range for u8 (0 to 255)"),
    ("launch init_negative.toml", 1, "`buffer[0].init[0]`: -1 is out of range for u32"),
    ("launch iota_wrap.toml", 1, "iota over 1000 elements reaches 999: 999 is out of range for u8"),
    ("render --scene nan_camera.toml -o o.png", 1, "camera.position: nan is not a finite number"),
    ("render --scene nan_scale.toml -o o.png", 1, "scale: nan is not a finite number"),
    ("render --scene inf_translate.toml -o o.png", 1, "translate: inf is not a finite number"),
    ("render --scene up_parallel.toml -o o.png", 1, "camera.up: must not be zero or parallel to the direction"),
    // the budget itself
    ("--memory-budget 100 launch runaway.toml", 1, "the budget is 100 B (--memory-budget)"),
    ("--memory-budget lots launch empty.toml", 2, "expected a size such as 4G"),
];

#[test]
fn every_corpus_input_gives_its_exit_code_and_a_clear_message() {
    let dir = corpus();
    let mut failures = Vec::new();
    for (line, code, text) in CASES {
        let args: Vec<&str> = line.split_whitespace().collect();
        let (got, out) = warplight_in(&dir, &args);
        if got != Some(*code) || !out.contains(text) || out.contains("panicked") {
            failures.push(format!("`warplight {line}`: exit {got:?} (expected {code}), output:\n{out}"));
        }
    }
    for f in ["o.png", "o.jpg"] {
        let _ = std::fs::remove_file(dir.join(f));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Issue 18: from a folder outside the checkout, scene names, the validation
/// fixtures and `--scene-dir DIR` resolve, and a file error names the file.
#[test]
fn the_binary_works_from_any_directory() {
    let dir = tempdir("anywhere");
    let (code, out) = warplight_in(&dir, &["scene", "info", "cornell-box"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("scene cornell-box") && out.contains("36"), "{out}");
    let (code, out) = warplight_in(&dir, &["scene", "info", "no-such-scene"]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("scenes/no-such-scene.toml: No such file or directory"), "{out}");
    assert!(out.contains("no such scene in") && out.contains("--scene-dir DIR"), "{out}");
    assert!(!out.contains(": -:"), "{out}");
    let (code, out) = warplight_in(&dir, &["scene", "info", "disc", "--scene-dir", corpus().to_str().unwrap()]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("1998"), "{out}");
    let (code, out) = warplight_in(&dir, &["launch", "missing.toml"]);
    assert_eq!(code, Some(1));
    assert!(out.contains("missing.toml: No such file or directory"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Values that have broken parsers and sizes before.
const HOSTILE: &[&str] = &[
    "0",
    "-1",
    "1e12",
    "4294967296",
    "4611686018427387904",
    "9223372036854775807",
    "nan",
    "inf",
    "-inf",
    "[]",
    "[0, 0, 0]",
    "[65536, 65536, 65536]",
    "\"\"",
    "\"/dev/zero\"",
    "{ file = \"/dev/zero\" }",
    "{ hash = 0, modulo = 0 }",
    "[nan, 1, 2]",
    "1.5",
    "true",
];

/// Replaces the value of a random `key = value` line with a hostile value,
/// or drops or duplicates a line.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for _ in 0..1 + rng.below(3) {
        let i = rng.below(lines.len());
        match rng.below(6) {
            0 => {
                lines.remove(i);
            }
            1 => {
                let l = lines[i].clone();
                lines.insert(i, l);
            }
            _ => {
                if let Some((k, _)) = lines[i].split_once('=') {
                    lines[i] = format!("{k}= {}", HOSTILE[rng.below(HOSTILE.len())]);
                }
            }
        }
        if lines.is_empty() {
            break;
        }
    }
    lines.join("\n")
}

/// Mutated launch specs and scene files load or give an error naming the
/// file; those that load are prepared (specs: the module loaded and the
/// buffers allocated under a small budget; scenes: the kd-tree built)
/// without a panic.
#[test]
fn mutated_specs_and_scenes_never_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let specs: Vec<(PathBuf, String)> =
        ["examples/reduce.toml", "examples/if_else.toml", "tests/corpus/recursion.toml"]
            .iter()
            .map(|p| (root.join(p), std::fs::read_to_string(root.join(p)).unwrap()))
            .collect();
    let scenes: Vec<(PathBuf, String)> = ["scenes/cornell-box.toml", "scenes/scene6.toml", "tests/corpus/disc.toml"]
        .iter()
        .map(|p| (root.join(p), std::fs::read_to_string(root.join(p)).unwrap()))
        .collect();
    warplight::limits::set_memory_budget(256 << 20);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    let mut runs = 0;
    while std::time::Instant::now() < deadline && runs < 2000 {
        runs += 1;
        let (path, text) = &specs[rng.below(specs.len())];
        let m = mutate(text, &mut rng);
        let r = std::panic::catch_unwind(|| {
            let spec = match warplight::launch_spec::Spec::parse(&m, path) {
                Ok(s) => s,
                Err(e) => {
                    assert!(e.to_string().starts_with(&path.display().to_string()), "{e}");
                    return;
                }
            };
            let mut dev = warplight::sim::Device::with_config(spec.sim_config(
                1,
                Some(200_000),
                warplight::model::Profile::Hopper,
                None,
            ));
            let _ = warplight::launch_spec::prepare(&spec, &mut dev);
        });
        assert!(r.is_ok(), "spec {} mutated to:\n{m}", path.display());
        let (path, text) = &scenes[rng.below(scenes.len())];
        let m = mutate(text, &mut rng);
        let file = path.with_file_name(format!("fuzz-{}.toml", std::process::id()));
        std::fs::write(&file, &m).unwrap();
        let r = std::panic::catch_unwind(|| match warplight::host::scene_file::load(&file) {
            Ok(s) => {
                let tris: Vec<[glam::Vec3; 3]> = s.triangles.iter().map(|t| t.v).collect();
                use warplight::host::kdtree::{BuildParams, Heuristic, build};
                let _ = build(&tris, BuildParams::thesis(Heuristic::Sah));
            }
            Err(e) => assert!(e.to_string().starts_with(&file.display().to_string()), "{e}"),
        });
        std::fs::remove_file(&file).ok();
        assert!(r.is_ok(), "scene {} mutated to:\n{m}", path.display());
    }
    assert!(runs >= 20, "only {runs} runs");
}

/// Numbers that have broken sizes, ids and counts in PTX before.
const HOSTILE_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "15",
    "16",
    "33",
    "65535",
    "2147483648",
    "4294967295",
    "4294967296",
    "4000000000000",
    "18446744073709551615",
];

/// Lines that have broken the front end or the simulator before.
const HOSTILE_LINES: &[&str] = &[
    "bar.sync 16;",
    "bar.sync 1, 33;",
    "bar.sync 0, 4096;",
    "shfl.sync.down.b32 %r1, %r1, 1, 31, -1;",
    "vote.sync.ballot.b32 %r1, %p1, 65535;",
    ".local .align 4 .b8 __fuzz_l[4294967296];",
    ".shared .align 4 .b8 __fuzz_s[40000000000];",
    ".global .align 4 .b8 __fuzz_g[4000000000000];",
    ".const .align 4 .b8 __fuzz_c[100000];",
    ".reg .b32 %fuzz<4294967295>;",
    "ret;",
    "exit;",
    "trap;",
    "{",
    "}",
    "$L__fuzz: bra $L__fuzz;",
];

/// One mutation of PTX text: a number replaced by a hostile one, a line
/// dropped, duplicated or swapped, a hostile line inserted, or a byte changed.
fn mutate_ptx(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for _ in 0..1 + rng.below(3) {
        if lines.is_empty() {
            break;
        }
        let i = rng.below(lines.len());
        match rng.below(7) {
            0 => {
                lines.remove(i);
            }
            1 => {
                let l = lines[i].clone();
                lines.insert(i, l);
            }
            2 => {
                let j = rng.below(lines.len());
                lines.swap(i, j);
            }
            3 => lines.insert(i, HOSTILE_LINES[rng.below(HOSTILE_LINES.len())].to_string()),
            4 => {
                let mut b = std::mem::take(&mut lines[i]).into_bytes();
                if !b.is_empty() {
                    let p = rng.below(b.len());
                    b[p] = b"{}[]();,.%@!-0123456789 x"[rng.below(25)];
                }
                lines[i] = String::from_utf8_lossy(&b).into_owned();
            }
            _ => {
                // a run of digits (in a size, an id, an immediate) becomes a hostile number
                let l = &lines[i];
                let starts: Vec<usize> = l
                    .char_indices()
                    .filter(|&(k, c)| c.is_ascii_digit() && (k == 0 || !l.as_bytes()[k - 1].is_ascii_alphanumeric()))
                    .map(|(k, _)| k)
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let e = l[s..].find(|c: char| !c.is_ascii_digit()).map_or(l.len(), |n| s + n);
                    lines[i] = format!("{}{}{}", &l[..s], HOSTILE_NUMBERS[rng.below(HOSTILE_NUMBERS.len())], &l[e..]);
                }
            }
        }
    }
    lines.join("\n")
}

/// Issue 17's bounded PTX fuzz: the committed PTX (test kernels, lessons and
/// this corpus) mutated with a fixed seed, loaded and, when it loads, every
/// kernel launched on small buffers under a small watchdog — for a few seconds.
/// A panic fails the test; an abort (allocation failure) or hang would end
/// the test binary, which fails the run as well.
#[test]
fn mutated_ptx_loads_and_runs_without_panic() {
    use warplight::sim::{Arg, Device, LaunchConfig, SimConfig};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<(String, String)> = Vec::new();
    for dir in ["kernels/tests", "kernels/lessons", "tests/corpus"] {
        let mut names: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "ptx"))
            .collect();
        names.sort();
        for p in names {
            let text = std::fs::read_to_string(&p).unwrap();
            if text.len() < 64 * 1024 {
                files.push((p.file_name().unwrap().to_string_lossy().into_owned(), text));
            }
        }
    }
    assert!(files.len() >= 20, "{} PTX files", files.len());
    warplight::limits::set_memory_budget(256 << 20);
    let mut cfg = SimConfig { threads: 1, max_call_depth: 8, ..SimConfig::default() };
    cfg.schedule.max_warp_instructions = 20_000;
    cfg.schedule.round_quantum = 2_000;
    let mut rng = Rng(0x5DEE_CE66_D1CE_5EED);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(6);
    let (mut runs, mut loaded, mut launched) = (0, 0, 0);
    while std::time::Instant::now() < deadline && runs < 5000 {
        runs += 1;
        let (name, text) = &files[rng.below(files.len())];
        let m = mutate_ptx(text, &mut rng);
        let ctas = 1 + rng.below(2) as u32;
        let threads = [32, 48, 64][rng.below(3)];
        let r = std::panic::catch_unwind(|| {
            let mut dev = Device::with_config(cfg.clone());
            let module = match dev.load_ptx(&m, name) {
                Ok(module) => module,
                Err(e) => {
                    assert!(e.to_string().contains(name.as_str()), "{e}");
                    return (0, 0);
                }
            };
            let mut n = 0;
            for k in module.prog.kernel_names() {
                let f = &module.prog.functions[module.prog.kernel(k).unwrap() as usize];
                let args: Vec<Arg> = f
                    .params
                    .iter()
                    .map(|p| match p.size {
                        8 => Arg::Ptr(dev.alloc_zeroed::<u8>(64 << 10)),
                        4 => Arg::U32(1),
                        s => Arg::Bytes(vec![0; s as usize]),
                    })
                    .collect();
                // faults and errors are expected; panics are not
                let _ = dev.launch(&module, k, LaunchConfig::linear(ctas, threads), &args);
                n += 1;
            }
            (1, n)
        });
        match r {
            Ok((l, n)) => {
                loaded += l;
                launched += n;
            }
            Err(_) => panic!("{name} mutated to:\n{m}"),
        }
    }
    assert!(runs >= 50 && loaded >= 10 && launched >= 10, "{runs} runs, {loaded} loaded, {launched} launches");
}

/// Issue 17 item 7: `--dump` files are checked before the launch and written
/// all or none; a failed run leaves no dump and no temporary file.
#[test]
fn dumps_are_written_all_or_none() {
    let dir = tempdir("dump");
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/reduce.toml");
    let spec = spec.to_str().unwrap();
    let (code, out) = warplight_in(&dir, &["launch", spec, "--dump", "input=a.bin", "--dump", "sums=nodir/b.bin"]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("--dump nodir/b.bin: the folder nodir does not exist"), "{out}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing is written");
    let (code, out) = warplight_in(&dir, &["launch", spec, "--dump", "input=a.bin", "--dump", "sums=b.bin"]);
    assert_eq!(code, Some(0), "{out}");
    let mut left: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, ["a.bin", "b.bin"]);
    std::fs::remove_dir_all(&dir).ok();
}
