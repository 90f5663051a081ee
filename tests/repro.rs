//! The reproduction platform end to end: the registry's addresses and list,
//! tables with verdicts and scores, shards that merge into exactly what one
//! run prints, the cluster scripts, and the committed baseline of verdicts.

mod support;
use support::warplight;

mod common;

use std::process::Command;

fn tempdir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("warplight-repro-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn list_shows_every_thesis_and_the_status_of_chapter_4() {
    let (ok, out, err) = warplight(&["tables", "--list"]);
    assert!(ok, "{err}");
    for t in ["fabianowski", "engelhardt", "zeidan", "lin", "purcell"] {
        assert!(out.lines().any(|l| l.starts_with(t)), "{t} missing:\n{out}");
    }
    for (addr, status) in [
        ("fabianowski:4.1", "modelled"),
        ("fabianowski:4.2", "partly"),
        ("fabianowski:4.5", "reproduced"),
        ("fabianowski:4.10", "modelled"),
        ("fabianowski:6.6", "modelled"),
        ("fabianowski:7.3", "missing"),
        ("purcell:1", "partly"),
        ("lin:1", "modelled"),
        ("lin:2", "partly"),
    ] {
        let line =
            out.lines().find(|l| l.trim_start().starts_with(&format!("{addr} "))).unwrap_or_else(|| panic!("{addr}"));
        assert!(line.contains(status), "{line}");
    }
    assert!(out.contains("warplight tables fabianowski:4.5"), "{out}");
}

#[test]
fn addresses_and_their_errors() {
    // a table that exists but is not reproduced, a thesis that does not exist, a table id nobody has
    let (ok, _, err) = warplight(&["tables", "fabianowski:7.3"]);
    assert!(!ok && err.contains("fabianowski:7.3 is not reproduced (missing)"), "{err}");
    let (ok, _, err) = warplight(&["tables", "nobody:1"]);
    assert!(!ok && err.contains("no thesis \"nobody\"; theses: fabianowski, engelhardt"), "{err}");
    let (ok, _, err) = warplight(&["tables", "4.11"]);
    assert!(!ok && err.contains("has no table 4.11"), "{err}");
    let (ok, _, err) = warplight(&["tables", "4.2", "--format", "xml"]);
    assert!(!ok && err.contains("expected markdown, table, csv or json"), "{err}");
    let (ok, _, err) = warplight(&["tables", "4.5", "--frames", "60..70"]);
    assert!(!ok && err.contains("the protocol has 3 frames"), "{err}");
    // --plan prints what would run and the estimate, and runs nothing
    let (ok, out, err) = warplight(&["tables", "fabianowski:all", "--protocol", "thesis", "--plan"]);
    assert!(ok && out.contains("protocol thesis: 50 frame(s) of each flight at 512x512"), "{err}");
    assert!(out.contains("estimated time: ") && out.contains(" h on "), "{out}");
    assert!(out.contains("unavailable: scenes/fairy.toml"), "{out}");
    // a group that caps the image side says so when the protocol asks for more
    let (ok, out, err) = warplight(&["tables", "lin:fig3", "--resolution", "256", "--plan"]);
    assert!(ok && out.contains("lin/traversals:"), "{err}");
    assert!(out.contains("(at most 64x64 pixels: the protocol's 256x256 is capped)"), "{out}");
    let (ok, out, _) = warplight(&["tables", "lin:fig3", "--resolution", "48", "--plan"]);
    assert!(ok && out.contains("lin/traversals:") && !out.contains("capped"), "{out}");
    // a group with its own side says the protocol's does not apply, unless they agree
    let (ok, out, err) = warplight(&["tables", "lin:fig8", "--resolution", "256", "--plan"]);
    assert!(ok, "{err}");
    assert!(out.contains("(at 32x32 pixels, its Mitsuba reference's: the protocol's 256x256 does not apply)"), "{out}");
    let (ok, out, _) = warplight(&["tables", "lin:fig8", "--resolution", "32", "--plan"]);
    assert!(ok && !out.contains("does not apply"), "{out}");
    let (ok, _, err) = warplight(&["tables", "4.5", "--protocol", "slow"]);
    assert!(!ok && err.contains("expected quick or thesis"), "{err}");
}

#[test]
fn tables_4_1_and_4_2_print_thesis_as_printed_verdicts_and_scores() {
    let (ok, out, err) =
        warplight(&["tables", "4.1", "fabianowski:4.2", "--scenes", "scene6", "--frames", "1", "--resolution", "16"]);
    assert!(ok, "{err}");
    // the plan and its estimate come first, on stderr
    assert!(
        err.contains("protocol custom: 1 frame(s) of each flight at 16x16") && err.contains("estimated time"),
        "{err}"
    );
    assert!(out.contains("fabianowski Table 4.1: Ray tracing frame rates with the numerical approximation"), "{out}");
    // printed values exactly as printed (Unicode minus, ±), the printed average and the like-for-like mean
    assert!(out.contains("| 341.8 |") && out.contains("| Average |") && out.contains("| +3.5% |"), "{out}");
    assert!(out.contains("| Thesis, mean of our 1 scene |") && out.contains("| +7.5% |"), "{out}");
    assert!(out.contains("Score: ") && out.contains("cells within tolerance"), "{out}");
    assert!(out.contains("Light outside 15.1 −3.8%"), "{out}");
    assert!(out.contains("SIROH does relatively worse for shadow rays from a light outside"), "{out}");
    // CSV: numeric cells and unique column names
    let (ok, csv, _) = warplight(&["tables", "4.2", "--scenes", "scene6", "--resolution", "16", "--format", "csv"]);
    assert!(ok && csv.starts_with("table,row,shadow rays,SAH inside,SIROH inside (%),"), "{csv}");
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let mut uniq = header.clone();
    uniq.sort();
    uniq.dedup();
    assert_eq!(uniq.len(), header.len(), "{header:?}");
    assert!(csv.lines().nth(1).unwrap().starts_with("fabianowski:4.2,scene6,"), "{csv}");
    let (ok, out, _) = warplight(&["tables", "4.2", "--scenes", "scene6", "--resolution", "16", "--format", "table"]);
    assert!(ok && out.contains("\nscene6 ") && !out.contains("| scene6 |"), "{out}");
    // the widest tables fit a 120-column terminal
    let (ok, out, _) =
        warplight(&["tables", "4.3", "4.8", "--from", "docs/results/fabianowski-quick.json", "--format", "table"]);
    assert!(ok && out.lines().all(|l| l.chars().count() <= 120), "{out}");
    assert!(out.contains("Trav. SIROH") && out.contains("7 NC I + SC III"), "{out}");
    // JSON is the raw measurements: the same file --out writes
    let (ok, out, _) = warplight(&["tables", "4.2", "--scenes", "scene6", "--resolution", "16", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(ok && v["format"] == 1 && v["samples"].as_array().unwrap().len() == 4, "{out}");
    assert_eq!(v["fmad"], true, "the run's FMA contraction is recorded");
}

#[test]
fn unavailable_scenes_are_named_once() {
    let (ok, out, err) =
        warplight(&["tables", "4.5", "--scenes", "scene6,fairy", "--frames", "1", "--resolution", "8"]);
    assert!(ok, "{err}");
    assert_eq!(out.matches("Unavailable: scenes/fairy.toml").count(), 1, "{out}");
}

#[test]
fn two_shards_merge_to_exactly_the_unsplit_run() {
    let d = tempdir("shards");
    let p = |n: &str| d.join(n).display().to_string();
    let base = ["tables", "4.5", "4.7", "4.4", "--scenes", "scene6", "--resolution", "16"];
    let run = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        let (ok, out, err) = warplight(&a);
        assert!(ok, "{err}");
        out
    };
    run(&["--out", &p("whole.json")]);
    run(&["--frames", "0..1", "--out", &p("a.json")]);
    run(&["--frames", "1..3", "--out", &p("b.json")]);
    // build timings differ run to run: print both from their raw measurements
    let (ok, whole, err) = warplight(&["tables", "merge", &p("whole.json")]);
    assert!(ok, "{err}");
    let (ok, merged, err) = warplight(&["tables", "merge", &p("b.json"), &p("a.json")]);
    assert!(ok, "{err}");
    // the frame-independent builds come from the shard that starts at frame 0; all else is summed per frame
    let a: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(p("a.json")).unwrap()).unwrap();
    let w: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(p("whole.json")).unwrap()).unwrap();
    let builds = |v: &serde_json::Value| {
        v["samples"].as_array().unwrap().iter().filter(|s| s["frame"].is_null()).cloned().collect::<Vec<_>>()
    };
    // make the unsplit run's timings those of shard a, then both must print byte for byte the same
    let mut w2 = w.clone();
    let other: Vec<serde_json::Value> =
        w["samples"].as_array().unwrap().iter().filter(|s| !s["frame"].is_null()).cloned().collect();
    let mut samples = builds(&a);
    samples.extend(other);
    w2["samples"] = serde_json::Value::Array(samples);
    std::fs::write(p("whole2.json"), serde_json::to_string_pretty(&w2).unwrap()).unwrap();
    let (ok, whole2, err) = warplight(&["tables", "merge", &p("whole2.json")]);
    assert!(ok, "{err}");
    let (_, merged_sorted, _) = warplight(&["tables", "merge", &p("a.json"), &p("b.json")]);
    assert_eq!(merged, merged_sorted, "shard order must not matter");
    assert_eq!(whole2, merged, "merged shards print what the unsplit run prints");
    assert!(whole.contains("frames 0..3") && merged.contains("frames 0..3"), "{merged}");
    // refusals: overlap, a gap, another protocol
    let (ok, _, err) = warplight(&["tables", "merge", &p("a.json"), &p("whole.json")]);
    assert!(!ok && err.contains("overlap"), "{err}");
    let (ok, _, err) = warplight(&["tables", "merge", &p("b.json")]);
    assert!(!ok && err.contains("scene6: frames 0..1 of the protocol are in no shard"), "{err}");
    let (ok, _, _) = warplight(&["tables", "merge", &p("b.json"), "--partial"]);
    assert!(ok);
    let c = p("c.json");
    let (ok, _, err) = warplight(&[
        "tables",
        "4.5",
        "4.7",
        "4.4",
        "--scenes",
        "scene6",
        "--resolution",
        "8",
        "--frames",
        "1..3",
        "--out",
        &c,
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = warplight(&["tables", "merge", &p("a.json"), &p("c.json")]);
    assert!(!ok && err.contains("does not belong with") && err.contains("protocol"), "{err}");
    let (ok, _, err) = warplight(&["tables", "merge", &p("missing.json")]);
    assert!(!ok && err.contains("missing.json"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn gnu_parallel_runs_shards_and_merges_them() {
    if common::external("parallel", "apt-get install parallel").is_none() {
        return;
    }
    let d = tempdir("parallel");
    let o = Command::new("bash")
        .arg("examples/cluster/parallel.sh")
        .env("WARPLIGHT", env!("CARGO_BIN_EXE_warplight"))
        .env("SHARDS", "2")
        .env("OUT", &d)
        .env("TABLES", "fabianowski:4.5 fabianowski:4.7")
        .env("PROTOCOL", "quick")
        .env("JOBS", "2")
        .env("EXTRA", "--scenes scene6 --resolution 16")
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    let (ok, whole, err) =
        warplight(&["tables", "fabianowski:4.5", "fabianowski:4.7", "--scenes", "scene6", "--resolution", "16"]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::read_to_string(d.join("tables.md")).unwrap(), whole);
    // the Slurm script, its array tasks run by hand, then merged
    for i in ["0", "1"] {
        let o = Command::new("bash")
            .arg("examples/cluster/slurm.sh")
            .env("WARPLIGHT", env!("CARGO_BIN_EXE_warplight"))
            .env("SLURM_ARRAY_TASK_ID", i)
            .env("SLURM_ARRAY_TASK_COUNT", "2")
            .env("PROTOCOL", "quick")
            .env("OUT", d.join("slurm"))
            .env("TABLES", "fabianowski:4.5 fabianowski:4.7")
            .env("EXTRA", "--scenes scene6 --resolution 16")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let s = |i: &str| d.join("slurm").join(format!("shard-{i}.json")).display().to_string();
    let (ok, merged, err) = warplight(&["tables", "merge", &s("0"), &s("1")]);
    assert!(ok && merged == whole, "{err}");
    std::fs::remove_dir_all(&d).ok();
}

/// Cells recorded as within tolerance in the committed baseline stay within it.
#[test]
fn no_cell_drops_out_of_tolerance() {
    let (ok, out, err) = warplight(&[
        "tables",
        "fabianowski:all",
        "--scenes",
        "scene6",
        "--frames",
        "1",
        "--resolution",
        "32",
        "--baseline",
        "tests/fixtures/baseline-scene6.json",
    ]);
    assert!(ok, "{err}\n{out}");
    assert!(err.contains("no cell dropped out of tolerance"), "{err}");
}

/// The docs' generated blocks (`<!-- generated: warplight ARGS -->`) hold what
/// `warplight ARGS` prints now: `tools/regen-docs.sh` was run after the last change.
#[test]
fn generated_doc_blocks_are_current() {
    let mut files = vec![std::path::PathBuf::from("README.md")];
    for e in std::fs::read_dir("docs").unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            files.push(p);
        }
    }
    let mut blocks = 0;
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let mut rest = text.as_str();
        while let Some(i) = rest.find("<!-- generated: warplight ") {
            let after = &rest[i + "<!-- generated: warplight ".len()..];
            let (args, body) = after.split_once(" -->\n").unwrap();
            let (content, tail) = body.split_once("<!-- end generated -->").unwrap();
            let args: Vec<&str> = args.split_whitespace().collect();
            let (ok, out, err) = warplight(&args);
            assert!(ok, "{}: warplight {args:?}: {err}", f.display());
            assert_eq!(
                content,
                out,
                "{}: the block of `warplight {}` is stale: run tools/regen-docs.sh",
                f.display(),
                args.join(" ")
            );
            blocks += 1;
            rest = tail;
        }
    }
    assert!(blocks >= 11, "{blocks} generated blocks");
}

/// Every registered table's caption is the seed's, near the lines the registry names.
#[test]
fn captions_are_quoted_from_the_seeds_at_their_lines() {
    let dir = std::path::Path::new("../shared/seeds");
    if !dir.is_dir() {
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "skipped: captions_are_quoted_from_the_seeds_at_their_lines needs ../shared/seeds"
        );
        return;
    }
    let norm = |s: &str| s.replace(['*', '\u{a0}'], " ").split_whitespace().collect::<Vec<_>>().join(" ");
    let mut checked = 0;
    for e in warplight::repro::registry::entries() {
        let text = std::fs::read_to_string(dir.join(e.thesis.seed_file)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let range = e.table.lines.trim_start_matches('L');
        let (a, b) = range.split_once('-').unwrap_or((range, range));
        let (a, b): (usize, usize) = (a.parse().unwrap(), b.trim_start_matches('L').parse().unwrap());
        let window = norm(&lines[a.saturating_sub(15)..(b + 15).min(lines.len())].join(" "));
        let title = norm(e.table.title);
        // the first 60 characters: long captions may wrap around footnote marks
        let head: String = title.chars().take(60).collect();
        assert!(window.contains(&head), "{}: caption {head:?} not near seed lines {}", e.address(), e.table.lines);
        checked += 1;
    }
    assert!(checked >= 48, "{checked}");
}

/// The count tables of Scene 6 (Tables 4.3, 4.4's tree statistics, 4.5, 4.8
/// (a), (b), (d)) give exactly the verdicts the committed baseline records,
/// cell for cell: a count that moves across a tolerance either way fails until
/// the baseline is re-recorded (`warplight tables all --scenes scene6 --frames
/// 1 --resolution 32 --write-baseline tests/fixtures/baseline-scene6.json`).
#[test]
fn scene6_count_verdicts_are_the_baselines() {
    use warplight::repro::baseline::Baseline;
    use warplight::repro::fabianowski2011::{
        BUILDS, CACHES, HEURISTIC_COUNTS, TRAVERSAL, flight, table_4_3, table_4_4,
    };
    use warplight::repro::protocol::Protocol;
    use warplight::repro::registry::{Workspace, resolve};
    use warplight::repro::results::{Results, SceneInfo};
    let text = std::fs::read_to_string("tests/fixtures/baseline-scene6.json").unwrap();
    let base: Baseline = serde_json::from_str(&text).unwrap();
    assert_eq!(base.protocol, "custom: 1 frame(s) of each flight at 32x32");
    let scene = warplight::host::scene_file::load(std::path::Path::new("scenes/scene6.toml")).unwrap();
    let mut ws = Workspace::new(&scene, 0..1, 32);
    let mut samples = table_4_4::measure_group(&mut ws, &mut |_| {}).unwrap();
    samples.extend(table_4_3::measure(&mut ws, &mut |_| {}).unwrap());
    samples.extend(flight::measure_traversal(&mut ws, &mut |_| {}).unwrap());
    samples.extend(flight::measure_caches(&mut ws, &mut |_| {}).unwrap());
    let mut r = Results::new(
        "test",
        Protocol::quick().with(Some(1), Some(32)),
        vec!["fabianowski:all".into()],
        vec![BUILDS.into(), HEURISTIC_COUNTS.into(), TRAVERSAL.into(), CACHES.into()],
    );
    r.scenes.push(SceneInfo {
        name: "scene6".into(),
        triangles: scene.triangles.len(),
        thesis_triangles: scene.thesis.map(|t| t.triangles),
        flight_frames: scene.flight.frames,
        frames: vec![warplight::repro::protocol::FrameRange { start: 0, end: 1 }],
    });
    r.samples = samples;
    let mut tables = Vec::new();
    for id in ["fabianowski:4.3", "fabianowski:4.4", "fabianowski:4.5", "fabianowski:4.8"] {
        let e = resolve(&[id.into()]).unwrap()[0];
        tables.extend((e.table.render.unwrap())(&e, &r));
    }
    let now = Baseline::record(&base.protocol, &base.scenes, &tables);
    let mut checked = 0;
    for addr in [
        "fabianowski:4.3",
        "fabianowski:4.4",
        "fabianowski:4.5",
        "fabianowski:4.8a",
        "fabianowski:4.8b",
        "fabianowski:4.8d",
    ] {
        let (want, got) = (&base.tables[addr], &now.tables[addr]);
        assert!(!want.is_empty(), "{addr}: the baseline records verdicts");
        assert_eq!(got, want, "{addr}: verdicts differ from the committed baseline");
        checked += want.len();
    }
    assert!(checked > 60, "{checked} cells");
}

/// `tables --fmad` is recorded in the results, and shards measured with and
/// without FMA contraction do not merge; files written before it was
/// recorded read as contraction on.
#[test]
fn shards_with_different_fmad_do_not_merge() {
    use warplight::repro::protocol::{FrameRange, Protocol};
    use warplight::repro::results::{Results, SceneInfo};
    let shard = |frames: FrameRange, fmad: bool| {
        let mut r = Results::new("c", Protocol::quick(), vec!["t:1".into()], vec!["g".into()]);
        r.fmad = fmad;
        r.scenes.push(SceneInfo {
            name: "s".into(),
            triangles: 1,
            thesis_triangles: None,
            flight_frames: 3,
            frames: vec![frames],
        });
        r
    };
    let (a, b) = (FrameRange { start: 0, end: 1 }, FrameRange { start: 1, end: 3 });
    let merged = Results::merge(&[("a".into(), shard(a, false)), ("b".into(), shard(b, false))], false).unwrap();
    assert!(!merged.fmad);
    let e = Results::merge(&[("a".into(), shard(a, true)), ("b".into(), shard(b, false))], false).unwrap_err();
    assert_eq!(e.to_string(), "b does not belong with a: FMA contraction off against on (tables --fmad)");
    // written and read back; without the key, on
    let mut v = serde_json::to_value(shard(a, false)).unwrap();
    assert_eq!(v["fmad"], false);
    v.as_object_mut().unwrap().remove("fmad");
    let old: Results = serde_json::from_value(v).unwrap();
    assert!(old.fmad);
}
