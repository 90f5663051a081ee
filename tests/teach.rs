//! The teaching views: the interactive step view driven with scripted keys on
//! a test backend (80×24), and the trace recorder behind `warplight trace`.

use std::path::Path;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use warplight::model::Profile;
use warplight::teach::breakpoints::Breakpoints;
use warplight::teach::session::Session;
use warplight::teach::trace::{self, TraceOptions};
use warplight::teach::tui::{self, TuiOptions};

fn session(spec: &str) -> Session {
    Session::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(spec)).expect("spec loads")
}

fn options(profile: Profile) -> TuiOptions {
    TuiOptions { breaks: Breakpoints::default(), watches: vec![], start: (0, 0), profile, max_steps: 100_000 }
}

/// Keys from a script: characters, with `\n` for Enter.
fn keys(script: &str) -> Vec<KeyEvent> {
    script
        .chars()
        .map(|c| {
            let code = match c {
                '\n' => KeyCode::Enter,
                c => KeyCode::Char(c),
            };
            KeyEvent::new(code, KeyModifiers::NONE)
        })
        .collect()
}

/// Runs the view over `script` and returns the final screen, one string per row.
fn screen(spec: &str, o: TuiOptions, script: &str) -> (Vec<String>, tui::App) {
    let s = session(spec);
    let mut term = Terminal::new(TestBackend::new(80, 24)).unwrap();
    let mut k = keys(script).into_iter();
    let app = tui::drive(&mut term, &s, o, || Ok(k.next())).expect("view runs");
    let buf = term.backend().buffer();
    let rows = (0..24).map(|y| (0..80).map(|x| buf[(x, y)].symbol().to_string()).collect::<String>()).collect();
    (rows, app)
}

fn text(rows: &[String]) -> String {
    rows.join("\n")
}

#[test]
fn the_view_starts_at_the_first_instruction_with_all_lanes() {
    let (rows, app) = screen("examples/if_else.toml", options(Profile::Hopper), "");
    let t = text(&rows);
    assert!(rows[0].contains("if_else") && rows[0].contains("step 0"), "{t}");
    // at 80 columns one code pane: the source, the next PTX instruction under it
    assert!(rows[1].contains("divergence.cu") && rows[1].contains("v: PTX"), "{t}");
    assert!(t.contains("PTX 24: mov.u32  %r10, %tid.x;"), "{t}");
    assert!(t.contains("lanes 0-31 ################################ active ffffffff (32)"), "{t}");
    assert!(t.contains("stack[0] pc 0"), "{t}");
    assert_eq!(app.steps, 0);
}

#[test]
fn stepping_to_the_branch_shows_the_divergence() {
    // 12 instructions up to and including the conditional branch (PTX line 44)
    let (rows, app) = screen("examples/if_else.toml", options(Profile::Hopper), &"s".repeat(12));
    let t = text(&rows);
    assert_eq!(app.steps, 12);
    assert!(app.message.contains("ran PTX 44") && app.message.ends_with("diverged"), "{}", app.message);
    // odd lanes run first, even lanes wait
    assert!(t.contains("lanes 0-31 .#.#.#.#.#.#.#.#.#.#.#.#.#.#.#.# active aaaaaaaa (16)"), "{t}");
    assert!(t.contains("mask aaaaaaaa (16) <- running"), "{t}");
    assert!(t.contains("mask 55555555 (16)"), "{t}");
    assert!(t.contains("if (t % 2) {"), "the source pane shows the branch's line:\n{t}");
}

#[test]
fn stepping_back_restores_the_same_screen() {
    let o = || options(Profile::Hopper);
    let (ahead, _) = screen("examples/if_else.toml", o(), &"s".repeat(14));
    let (back, app) = screen("examples/if_else.toml", o(), &format!("{}uu", "s".repeat(16)));
    assert_eq!(app.steps, 14);
    assert!(app.message.contains("stepped back to step 14"), "{}", app.message);
    // everything but the message line is identical
    for y in (0..24).filter(|&y| y != 22) {
        assert_eq!(ahead[y], back[y], "row {y}\n{}\n---\n{}", text(&ahead), text(&back));
    }
    let (_, app) = screen("examples/if_else.toml", o(), "u");
    assert_eq!(app.message, "nothing to step back to");
}

#[test]
fn source_line_steps_and_goto_and_breakpoints() {
    // `n` runs until the warp leaves its CUDA line: from the first instruction of
    // line 10 (`if (t % 2)`, step 5) through the compiler's line-0 instructions to the branch
    // line 10 ends in the branch that splits the warp: `n` stops there first
    let (rows, a) = screen("examples/if_else.toml", options(Profile::Hopper), "sssssn");
    assert_eq!(a.steps, 12, "line 10 is several instructions up to the branch");
    assert!(a.message.ends_with("diverged"), "{}", a.message);
    assert!(text(&rows).contains(">  10"), "{}", text(&rows));
    let (rows, _) = screen("examples/if_else.toml", options(Profile::Hopper), "sssssnn");
    let t = text(&rows);
    assert!(!t.contains(">  10") && t.contains(">  11"), "the source pane moved on to line 11:\n{t}");
    // g 71 Enter: the warp runs to the reconvergence point
    let (rows, a) = screen("examples/if_else.toml", options(Profile::Hopper), "g71\nv");
    assert!(text(&rows).contains(">  71"), "{}", text(&rows));
    assert!(rows[11].contains("################################"), "reconverged: {}", rows[11]);
    assert!(a.steps > 20);
    // b 48 Enter sets a breakpoint (marked *), c continues to it: the even path's first line
    let (rows, a) = screen("examples/if_else.toml", options(Profile::Hopper), "b48\nc");
    assert!(a.message.contains("breakpoint: warp 0:0 before PTX line 48"), "{}", a.message);
    assert!(text(&rows).contains("active 55555555 (16)"), "{}", text(&rows));
    // a line without an instruction is refused
    let (_, a) = screen("examples/if_else.toml", options(Profile::Hopper), "b1\n");
    assert_eq!(a.message, "PTX line 1 holds no instruction");
}

#[test]
fn memory_panel_explains_coalescing_per_profile() {
    // run to the load of in[t * stride] (PTX line 46, stride 1 in the spec's first launch) and over it
    let script = "g46\ns3";
    let (rows, _) = screen("examples/lessons/coalescing.toml", options(Profile::Gt200), script);
    let t = text(&rows);
    assert!(t.contains("last memory instruction"), "{t}");
    assert!(t.contains("gt200 2 transactions, 128 B moved for 128 B used"), "{t}");
    assert!(t.contains("0=half-warp 0: 64 B at"), "{t}");
    let (rows, _) = screen("examples/lessons/coalescing.toml", options(Profile::Hopper), script);
    assert!(text(&rows).contains("hopper 1 request, 4 sectors"), "{}", text(&rows));
}

#[test]
fn register_panel_and_warp_selection() {
    let mut o = options(Profile::Hopper);
    o.watches = vec!["%r10".into()];
    // after 2 instructions %r10 = tid.x; radix cycles dec -> hex
    // one row a register, one column a lane (8 lanes at 80 columns; l shows the next 8)
    let (rows, _) = screen("examples/if_else.toml", o.clone(), "ss2");
    let t = text(&rows);
    assert!(t.contains("registers 1-7 of"), "several registers at once:\n{t}");
    let row = |name: &str, cells: &[&str]| {
        format!("│{name:<6}{}", cells.iter().map(|c| format!("{c:>9}")).collect::<String>())
    };
    assert!(rows.iter().any(|r| r.starts_with(&row("%r10", &["0", "1", "2", "3", "4", "5", "6", "7"]))), "{t}");
    let (rows, _) = screen("examples/if_else.toml", o.clone(), "ss2lll");
    let t = text(&rows);
    assert!(rows.iter().any(|r| r.starts_with(&row("lane", &["24", "25", "26"]))), "{t}");
    assert!(rows.iter().any(|r| r.starts_with(&row("%r10", &["24", "25", "26"]))), "{t}");
    let (rows, _) = screen("examples/if_else.toml", o, "ss2lllx");
    assert!(rows.iter().any(|r| r.starts_with(&row("%r10", &["18", "19", "1a", "1b"]))), "{}", text(&rows));
    // a CTA of 256 threads has 8 warps: w moves to warp 1, W back, W wraps to 7
    let (_, a) = screen("examples/reduce.toml", options(Profile::Hopper), "w");
    assert_eq!(a.sel, (0, 1));
    let (_, a) = screen("examples/reduce.toml", options(Profile::Hopper), "wWW");
    assert_eq!(a.sel, (0, 7));
}

#[test]
fn barrier_key_and_help() {
    let (rows, a) = screen("examples/reduce.toml", options(Profile::Hopper), "a");
    assert!(a.message.contains("bar"), "{}", a.message);
    assert!(text(&rows).contains("Barrier"), "the warp waits at the barrier:\n{}", text(&rows));
    let (rows, _) = screen("examples/reduce.toml", options(Profile::Hopper), "?");
    assert!(text(&rows).contains("keys (any key closes)"), "{}", text(&rows));
    let (rows, _) = screen("examples/reduce.toml", options(Profile::Hopper), "?s");
    assert!(!text(&rows).contains("keys (any key closes)"));
}

fn trace_options() -> TraceOptions {
    TraceOptions { ctas: vec![], warps: vec![], from: 1, to: u64::MAX, max_events: 20_000, profile: Profile::Hopper }
}

#[test]
fn trace_records_every_instruction_with_divergence_marks() {
    let t = trace::record(&session("examples/if_else.toml"), &trace_options()).unwrap();
    assert_eq!(t.events.len(), 28, "the log's 28 warp instructions");
    assert!(t.finished && !t.truncated);
    let fx: Vec<(u32, &str)> = t.events.iter().filter(|e| !e.fx.is_empty()).map(|e| (e.line, e.fx.as_str())).collect();
    // the branch splits the warp; the odd path ends and hands over to the even
    // path, which then reconverges with it; the warp exits
    assert_eq!(fx, [(44, "diverged"), (68, "other path"), (58, "reconverged"), (74, "exited")]);
    let thread_insts: u64 = t.events.iter().map(|e| e.mask.count_ones() as u64).sum();
    assert_eq!(thread_insts, 688, "as the counters say");
    // the stores: each side stores every other word of its array (16 lanes, 4
    // sectors); the compiler merged the two `[i + 1024]` stores after the
    // reconvergence point into one store of all 32 lanes to two arrays (8 sectors)
    let stores: Vec<&str> = t
        .events
        .iter()
        .flat_map(|e| &e.mem)
        .map(|m| m.summary.as_str())
        .filter(|s| s.starts_with("global store"))
        .collect();
    assert_eq!(
        stores,
        [
            "global store 4B x16: hopper 1 request, 4 sectors",
            "global store 4B x16: hopper 1 request, 4 sectors",
            "global store 4B x32: hopper 1 request, 8 sectors"
        ]
    );
}

#[test]
fn trace_selection_bounds_its_size() {
    let s = session("examples/reduce.toml");
    let all = trace::record(&s, &trace_options()).unwrap();
    let mut o = trace_options();
    o.ctas = vec![0];
    o.warps = vec![1];
    let one = trace::record(&s, &o).unwrap();
    assert_eq!(one.warps.len(), 1);
    assert!(one.events.iter().all(|e| e.w == 0));
    assert!(one.events.len() < all.events.len());
    o.max_events = 5;
    let cut = trace::record(&s, &o).unwrap();
    assert_eq!(cut.events.len(), 5);
    assert!(cut.truncated);
    let mut o = trace_options();
    o.from = 10;
    o.to = 19;
    let range = trace::record(&s, &o).unwrap();
    assert_eq!(range.events.iter().map(|e| e.step).collect::<Vec<_>>(), (10..=19).collect::<Vec<_>>());
    assert!(!range.finished);
}

#[test]
fn trace_page_is_self_contained() {
    let t = trace::record(&session("examples/if_else.toml"), &trace_options()).unwrap();
    let page = trace::html(&t).unwrap();
    assert!(!page.contains("/*TRACE_DATA*/"));
    // outside its data (which holds source text, comments and all), nothing refers elsewhere
    let code = page.split("id=\"data\">").next().unwrap().to_string() + page.rsplit("</script>").nth(1).unwrap();
    for external in ["http:", "https:", "src=\"", "<link", "@import", "url("] {
        assert!(!code.contains(external), "the page must not load anything ({external})");
    }
    // the data cannot end its script element early
    let data = page.split("id=\"data\">").nth(1).unwrap().split("</script>").next().unwrap();
    assert!(!data.contains('<'));
    let back: serde_json::Value = serde_json::from_str(data).unwrap();
    assert_eq!(back["events"].as_array().unwrap().len(), 28);
}

#[test]
fn a_fault_keeps_the_view_on_the_faulting_warp() {
    // thread 37 of `out_of_bounds` stores past the end of its buffer
    let dir = std::env::temp_dir().join(format!("warplight-fault-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ptx = Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels/tests/memory.ptx");
    let spec = dir.join("fault.toml");
    std::fs::write(
        &spec,
        format!(
            "ptx = {:?}\nkernel = \"out_of_bounds\"\ngrid = 2\nblock = 32\nargs = [\"out\"]\n[[buffer]]\nname = \"out\"\ntype = \"i32\"\nlen = 40\n",
            ptx.display().to_string()
        ),
    )
    .unwrap();
    let spec = spec.to_str().unwrap().to_string();
    let (rows, app) = screen(&spec, options(Profile::Hopper), "c");
    let t = text(&rows);
    assert!(app.fault.as_deref().is_some_and(|f| f.contains("out-of-bounds")), "{:?}", app.fault);
    assert!(t.contains("fault (u steps back)") && t.contains("CTA (1, 0, 0), warp 0, lane 5"), "{t}");
    assert_eq!(app.sel, (1, 0), "the faulting CTA's warp is selected");
    assert!(t.contains("PTX 234: st.global.u32"), "the faulting store is named under the source:\n{t}");
    let (rows, _) = screen(&spec, options(Profile::Hopper), "cv");
    assert!(text(&rows).contains("> 234 st.global.u32"), "the PTX pane shows the faulting store:\n{}", text(&rows));
    // stepping on is refused; stepping back clears the fault
    let (_, app) = screen(&spec, options(Profile::Hopper), "cs");
    assert_eq!(app.message, "the launch faulted: u steps back, q quits");
    let (_, app) = screen(&spec, options(Profile::Hopper), "cu");
    assert!(app.fault.is_none() && app.steps == 0, "{:?} at {}", app.fault, app.steps);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_view_survives_small_and_large_terminals() {
    for (w, h) in [(20, 5), (40, 12), (200, 60)] {
        let s = session("examples/lessons/coalescing.toml");
        let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
        let mut k = keys("sss?x3nn2jjkxw]1g46\ns").into_iter();
        let app = tui::drive(&mut term, &s, options(Profile::Gt200), || Ok(k.next())).expect("view runs");
        assert!(app.steps > 0, "{w}x{h}");
    }
}

/// Runs the view of launch `launch` of `spec` in a `w`×`h` terminal over `script`.
fn screen_at(spec: &str, launch: usize, (w, h): (u16, u16), script: &str) -> (Vec<String>, tui::App) {
    let s = Session::load_launch(&Path::new(env!("CARGO_MANIFEST_DIR")).join(spec), launch).expect("spec loads");
    let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
    let mut k = keys(script).into_iter();
    let app = tui::drive(&mut term, &s, options(Profile::Hopper), || Ok(k.next())).expect("view runs");
    let buf = term.backend().buffer();
    let rows = (0..h).map(|y| (0..w).map(|x| buf[(x, y)].symbol().to_string()).collect::<String>()).collect();
    (rows, app)
}

/// The active-lane count the lane strip ends with: `... active 00ffffff (24)`.
fn active_lanes(strip: &str) -> u32 {
    let n = strip.trim_end().rsplit('(').next().unwrap().trim_end_matches(')');
    n.parse().unwrap_or_else(|_| panic!("no lane count in {strip:?}"))
}

#[test]
fn next_line_stops_where_the_loop_thins_the_warp_out() {
    // lesson 1's uneven loop: lane t runs t % 4 + 1 iterations, so the loop's exit
    // branch diverges after iterations 1, 2 and 3 and the lane strip thins out
    // 32 -> 24 -> 16 -> 8; `n` must stop there although the loop is one line
    let mut seen = Vec::new();
    for n in 1..=40 {
        let (rows, app) = screen_at("examples/lessons/divergence.toml", 2, (80, 24), &"n".repeat(n));
        seen.push(active_lanes(&rows[11]));
        if app.message.contains("finished") || app.steps > 200 {
            break;
        }
    }
    let thin: Vec<u32> = seen.iter().copied().filter(|c| [24, 16, 8].contains(c)).collect();
    let mut order = thin.clone();
    order.dedup();
    assert_eq!(order, [24, 16, 8], "lane counts after each n: {seen:?}");
}

#[test]
fn the_source_pane_stays_on_the_users_file() {
    // votes.cu reads threadIdx.x (clang's header) and calls the prelude's
    // __ballot_sync and __shfl_down_sync: the pane never leaves votes.cu
    for k in 0..24 {
        let (rows, _) = screen_at("examples/lessons/votes.toml", 1, (80, 24), &"s".repeat(k));
        assert!(rows[1].contains("votes.cu"), "after {k} steps:\n{}", text(&rows));
        assert!(rows[2..10].iter().any(|r| r.contains("│>")), "the current line is marked:\n{}", text(&rows));
    }
    for k in 1..8 {
        let (rows, _) = screen_at("examples/lessons/votes.toml", 1, (80, 24), &"n".repeat(k));
        assert!(rows[1].contains("votes.cu"), "after {k} n:\n{}", text(&rows));
    }
}

#[test]
fn wide_terminals_show_both_panes_and_narrow_ones_toggle_and_scroll() {
    let (rows, _) = screen_at("examples/if_else.toml", 1, (120, 30), "sssss");
    assert!(rows[1].contains("divergence.cu") && rows[1].contains("PTX if_else"), "{}", text(&rows));
    let (rows, app) = screen_at("examples/if_else.toml", 1, (80, 24), "sssssv");
    assert_eq!(app.code, tui::CodePane::Ptx);
    assert!(rows[1].contains("PTX if_else") && rows[1].contains("v: source"), "{}", text(&rows));
    assert!(rows[10].contains("line 10: if (t % 2) {"), "the source line under the PTX:\n{}", text(&rows));
    // > scrolls the code 8 columns right; the line numbers stay
    let (rows, _) = screen_at("examples/if_else.toml", 1, (80, 24), "sssss>");
    assert!(rows.iter().any(|r| r.contains(">  10 % 2) {")), "{}", text(&rows));
    // the help fits 80x24 whole
    let (rows, _) = screen_at("examples/if_else.toml", 1, (80, 24), "?");
    let t = text(&rows);
    assert!(t.contains("keys (any key closes)") && t.contains("Lanes: # running"), "{t}");
    assert!(
        rows.iter().any(|r| r.contains("│x         decimal (signed), hex or float;  j k  scroll;  l  more lanes│")),
        "{t}"
    );
}

#[test]
fn memory_panel_shows_shared_variables_and_buffers_by_name() {
    // warp 0 of reduce_sum runs to its barrier: s[t] = in[t] for its 32 lanes
    let (rows, _) = screen_at("examples/reduce.toml", 1, (80, 24), "a4");
    let t = text(&rows);
    assert!(t.contains("[reduce_sum::s]") && t.contains("input") && t.contains("sums"), "{t}");
    assert!(t.contains("shared _ZZ10reduce_sumE1s (1024 B"), "{t}");
    let input = |i: u64| (i * 2654435761) % 100;
    let first: String = (0..8).map(|i| format!("{:>8} ", input(i))).collect();
    assert!(rows.iter().any(|r| r.contains(&format!("    0 {}", first.trim_end()))), "s[0..8] = in[0..8]:\n{t}");
    // o: the next region, the spec's buffer `input`
    let (rows, _) = screen_at("examples/reduce.toml", 1, (80, 24), "a4o");
    let t = text(&rows);
    assert!(t.contains("[input]") && t.contains("buffer input (2048 x i32)"), "{t}");
    assert!(rows.iter().any(|r| r.contains(&format!("    0 {}", first.trim_end()))), "{t}");
}

#[test]
fn trace_shows_the_users_line_for_generated_and_library_code() {
    let t = trace::record(&session("examples/lessons/votes.toml"), &trace_options()).unwrap();
    let user = t.sources.iter().position(|s| s.name.ends_with("votes.cu")).unwrap() as u32;
    assert!(t.events.iter().all(|e| e.src.is_some_and(|(f, l)| f == user && l > 0)), "every event on votes.cu");
    // the shuffles come from the prelude and are shown at a calling line of votes.cu
    let shfl: Vec<&trace::TraceEvent> = t.events.iter().filter(|e| e.op.starts_with("shfl")).collect();
    assert!(!shfl.is_empty() && shfl.iter().all(|e| e.src_inherited), "shuffles are inlined library code");
    assert!(t.events.iter().any(|e| !e.src_inherited), "the kernel's own lines are its own");
}

/// `a·a − 1` for a = 1 + 2^-12 (unrounded `mul` then `sub`: ptxas contracts
/// them into one FMA) and `rcp.approx` of `x`, stored to `out[0..2]`.
const ARITH_PTX: &str = ".version 7.8\n.target sm_90\n.address_size 64\n\
    .visible .entry k(.param .u64 in, .param .u64 out)\n{\n.reg .b64 %rd<3>;\n.reg .f32 %f<6>;\n\
    ld.param.u64 %rd1, [in];\nld.param.u64 %rd2, [out];\ncvta.to.global.u64 %rd1, %rd1;\ncvta.to.global.u64 %rd2, %rd2;\n\
    ld.global.f32 %f1, [%rd1];\nld.global.f32 %f2, [%rd1+4];\nmul.f32 %f3, %f1, %f1;\nsub.f32 %f4, %f3, 0f3F800000;\n\
    rcp.approx.f32 %f5, %f2;\nst.global.f32 [%rd2], %f4;\nst.global.f32 [%rd2+4], %f5;\nret;\n}\n";

/// `out` after stepping the spec's launch to its end.
fn stepped_out(s: &Session) -> Vec<u32> {
    s.with_stepper_and_buffers(|st, b| {
        while !st.finished() {
            st.step()?;
        }
        let (_, bytes) = b.read("out", 0, 2).expect("buffer out");
        Ok(bytes.chunks(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect())
    })
    .expect("steps")
}

/// `step` (and `trace`, `--check`, which build their device the same way)
/// computes as `launch` does: the spec's `fmad` and the device profile's FMA
/// contraction and SFU model (stepping used hopper's whatever the device).
#[test]
fn stepping_computes_with_the_fmad_and_sfu_of_launch() {
    // an input where the H200's MUFU table differs from the correctly rounded reciprocal
    let x = (2..1000)
        .map(|i| 1.0 + i as f32 / 1024.0)
        .find(|x| warplight::sim::sfu::rcp(x.to_bits(), false) != (1.0 / x).to_bits())
        .expect("an input where the models differ");
    let a = 1.0 + 2f32.powi(-12);
    // a·a = 1 + 2^-11 + 2^-24: rounded (a tie, to even) 1 + 2^-11; fused, exact
    let (fused, rounded) = ((2f32.powi(-11) + 2f32.powi(-24)).to_bits(), 2f32.powi(-11).to_bits());
    let (mufu, exact) = (warplight::sim::sfu::rcp(x.to_bits(), false), (1.0 / x).to_bits());
    let dir = std::env::temp_dir().join(format!("warplight-teach-arith-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("k.ptx"), ARITH_PTX).unwrap();
    let cases = [
        ("", None, [fused, mufu]),
        ("fmad = false\n", None, [rounded, mufu]),
        ("device = \"gt200\"\n", None, [rounded, exact]),
        ("device = \"gt200\"\nfmad = true\n", None, [fused, exact]),
        // `step --device gt200` over the spec's hopper
        ("", Some(Profile::Gt200), [rounded, exact]),
    ];
    for (i, (keys, device, want)) in cases.into_iter().enumerate() {
        let spec = dir.join(format!("s{i}.toml"));
        std::fs::write(
            &spec,
            format!(
                "{keys}ptx = \"k.ptx\"\nkernel = \"k\"\ngrid = 1\nblock = 1\nargs = [\"in\", \"out\"]\n\
                 [[buffer]]\nname = \"in\"\ntype = \"f32\"\nlen = 2\ninit = [{:?}, {:?}]\n\
                 [[buffer]]\nname = \"out\"\ntype = \"f32\"\nlen = 2\n",
                a as f64, x as f64
            ),
        )
        .unwrap();
        let mut s = Session::load(&spec).unwrap();
        s.device = device;
        assert_eq!(stepped_out(&s), want, "step, spec {i} ({keys:?}, {device:?})");
        // launch, on the same device
        let dump = dir.join(format!("out{i}.bin"));
        let mut args = vec!["launch".to_string(), spec.display().to_string(), "--dump".into()];
        args.push(format!("out={}", dump.display()));
        if let Some(d) = device {
            args.extend(["--device".to_string(), d.to_string()]);
        }
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_warplight")).args(&args).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let bytes = std::fs::read(&dump).unwrap();
        let launched: Vec<u32> = bytes.chunks(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
        assert_eq!(launched, want, "launch, spec {i}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
