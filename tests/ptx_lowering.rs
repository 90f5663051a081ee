//! Snapshot tests of the PTX lowering: every instruction form the front end
//! supports is written in one of `tests/fixtures/lowering/*.ptx` (a file per
//! instruction family), lowered, rendered with `warplight::ptx::ir_text` and
//! compared with the committed `*.ir` beside it.
//!
//! A deliberate change of the lowering updates the snapshots with
//! `WARPLIGHT_BLESS=1 cargo test --release --test ptx_lowering`; review the
//! diff of `tests/fixtures/lowering/*.ir` before committing it.

use std::path::{Path, PathBuf};

use warplight::ptx::ir::{ArithOp, Kind};
use warplight::ptx::{self, ir_text};

const DIR: &str = "tests/fixtures/lowering";

/// The snapshot inputs, sorted.
fn inputs() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(DIR)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ptx"))
        .collect();
    v.sort();
    assert!(v.len() >= 6, "snapshot inputs missing in {DIR}");
    v
}

/// Loads one input and renders it (file name without the directory, so the text
/// does not depend on where the tests run).
fn render(path: &Path) -> (ptx::Program, String) {
    let src = std::fs::read_to_string(path).unwrap();
    let name = path.file_name().unwrap().to_str().unwrap();
    let prog = ptx::load(&src, name).unwrap_or_else(|e| panic!("{e}"));
    let text = ir_text::program(&prog);
    (prog, text)
}

/// `Err` with the first differing line when `actual` is not `expected`.
fn compare(expected: &str, actual: &str) -> Result<(), String> {
    if expected == actual {
        return Ok(());
    }
    let (e, a): (Vec<_>, Vec<_>) = (expected.lines().collect(), actual.lines().collect());
    let i = e.iter().zip(&a).position(|(x, y)| x != y).unwrap_or(e.len().min(a.len()));
    Err(format!(
        "line {}:\n  expected: {}\n  actual:   {}",
        i + 1,
        e.get(i).copied().unwrap_or("(end)"),
        a.get(i).copied().unwrap_or("(end)")
    ))
}

#[test]
fn every_instruction_form_lowers_as_recorded() {
    let bless = std::env::var_os("WARPLIGHT_BLESS").is_some();
    let mut failures = Vec::new();
    for p in inputs() {
        let (_, text) = render(&p);
        let snap = p.with_extension("ir");
        if bless {
            std::fs::write(&snap, &text).unwrap();
            continue;
        }
        let Ok(expected) = std::fs::read_to_string(&snap) else {
            failures.push(format!("{}: no snapshot (run with WARPLIGHT_BLESS=1)", snap.display()));
            continue;
        };
        if let Err(e) = compare(&expected, &text) {
            failures.push(format!("{}: {e}", snap.display()));
        }
    }
    assert!(
        failures.is_empty(),
        "the lowering differs from its snapshots (WARPLIGHT_BLESS=1 updates them after review):\n{}",
        failures.join("\n")
    );
}

/// Changes an instruction in place; false when it does not apply to it.
type Mutation = fn(&mut Kind) -> bool;

/// The comparison above can fail: a changed operation, destination width,
/// address width, rounding mode or guard each changes the rendered text.
#[test]
fn a_changed_lowering_fails_the_snapshot() {
    let (prog, text) = render(&Path::new(DIR).join("arith.ptx"));
    let f = prog.functions.iter().position(|f| f.name == "arith").unwrap();
    let mutations: [(&str, Mutation); 4] = [
        ("operation", |k| match k {
            Kind::Arith { op, .. } if *op == ArithOp::Add => {
                *op = ArithOp::Sub;
                true
            }
            _ => false,
        }),
        ("destination width", |k| match k {
            Kind::Arith { d, .. } => {
                d.mask >>= 1;
                true
            }
            _ => false,
        }),
        ("rounding", |k| match k {
            Kind::Arith { mode, .. } if mode.rnd.is_some() => {
                mode.rnd = None;
                true
            }
            _ => false,
        }),
        ("approximation", |k| match k {
            Kind::Arith { mode, .. } => {
                mode.approx = !mode.approx;
                true
            }
            _ => false,
        }),
    ];
    for (what, m) in mutations {
        let mut changed = prog.clone();
        let i = changed.functions[f].insts.iter_mut().position(|i| m(&mut i.kind)).unwrap();
        assert!(compare(&text, &ir_text::program(&changed)).is_err(), "a changed {what} (instruction {i}) went unseen");
    }
    let mut guarded = prog.clone();
    guarded.functions[f].insts[0].guard = Some(warplight::ptx::ir::PredSrc { reg: 1, neg: true });
    assert!(compare(&text, &ir_text::program(&guarded)).is_err(), "a guard went unseen");

    let (prog, text) = render(&Path::new(DIR).join("memory.ptx"));
    let mut narrow = prog.clone();
    let f = narrow.functions.iter().position(|f| f.name == "memory").unwrap();
    let ld = narrow.functions[f]
        .insts
        .iter_mut()
        .find_map(|i| match &mut i.kind {
            Kind::Ld { addr, .. } => Some(addr),
            _ => None,
        })
        .unwrap();
    ld.wide = !ld.wide;
    assert!(compare(&text, &ir_text::program(&narrow)).is_err(), "an address width went unseen");
}

/// Every opcode the front end accepts is lowered in at least one snapshot.
#[test]
fn the_snapshots_cover_every_supported_opcode() {
    let mut seen = std::collections::BTreeSet::new();
    for p in inputs() {
        let (prog, _) = render(&p);
        for f in &prog.functions {
            for i in &f.info {
                seen.insert(i.opcode.split('.').next().unwrap().to_string());
            }
        }
    }
    let missing: Vec<&&str> = ptx::parser::KNOWN_OPCODES.iter().filter(|o| !seen.contains(**o)).collect();
    assert!(missing.is_empty(), "opcodes with no snapshot: {missing:?}");
}

/// Validation refuses malformed forms with an `invalid` error and valid PTX
/// that warplight does not execute with an `unsupported` one, each at the
/// instruction's line.
#[test]
fn validation_names_what_is_wrong() {
    let cases = [
        ("add.s32 %r1, %r2;", "invalid: `add.s32` takes 3 operands, found 2"),
        ("add %r1, %r2, %r3;", "invalid: `add` needs a type"),
        ("add.s32.u32 %r1, %r2, %r3;", "invalid: `add.s32.u32` has more than one type"),
        ("add.cc.f32 %f1, %f1, %f1;", "invalid: `add.cc.f32`: carry chains take .u32 .s32 .u64 .s64"),
        ("mul.hi.cc.u32 %r1, %r2, %r3;", "invalid: `mul.hi.cc.u32`: no carry-chain form"),
        ("sin.approx.f16 %h1, %h1;", "unsupported instruction `sin.approx.f16 (.f16)`"),
        ("mul.wide.f32 %f1, %f1, %f1;", "invalid: `mul.wide.f32`: .hi/.wide apply to integers"),
        ("min.xorsign.abs.f32 %f1, %f1, %f1;", "unsupported instruction `min.xorsign.abs.f32 (modifier .xorsign)`"),
        ("prmt.b32.f5e %r1, %r2, %r3, %r4;", "unsupported instruction `prmt.b32.f5e (modifier .f5e)`"),
        ("setp.s32 %p1, %r1, %r2;", "invalid: `setp.s32` needs a comparison"),
        ("setp.lt.and.s32 %p1, %r1, %r2;", "invalid: `setp.lt.and.s32` takes 4 operands, found 3"),
        ("set.lt.s32 %r1, %r2, %r3;", "invalid: `set` needs a destination and a source type"),
        ("cvt.f32 %f1, %r1;", "invalid: `cvt` needs a destination and a source type"),
        ("cvt.f32.f16x2 %f1, %r1;", "unsupported instruction `cvt.f32.f16x2 (packed halves)`"),
        ("cvt.rzi.f32.s32 %f1, %r1;", "integer rounding modifier on an int-to-float conversion"),
        ("cvta.u64 %rd1, %rd1;", "invalid: `cvta` needs a state space"),
        ("ld.global.v2.u32 %r1, [%rd1];", "invalid: `ld.global.v2.u32` moves 2 value(s), found 1"),
        ("ld.global.foo.u32 %r1, [%rd1];", "unsupported instruction `ld.global.foo.u32 (modifier .foo)`"),
        ("atom.global.u32 %r1, [%rd1], 1;", "invalid: `atom.global.u32` needs an operation"),
        (
            "atom.global.add.u16 %h1, [%rd1], 1;",
            "unsupported instruction `atom.global.add.u16 (types narrower than 32 bits)`",
        ),
        ("atom.global.cas.b32 %r1, [%rd1], 1;", "invalid: `atom.global.cas.b32` takes 4 operands, found 3"),
        ("bra 5;", "invalid: `bra` needs a label"),
        ("bar.sync;", "takes a barrier id and an optional thread count"),
        ("vote.sync.b32 %r1, %p1, -1;", "invalid: `vote` needs a mode"),
        ("shfl.sync.b32 %r1, %r2, 1, 31, -1;", "invalid: `shfl` needs a mode"),
        ("mov.b64 %rd1, {%r1, %r2, %r3};", "vector move parts must be 8, 16 or 32 bits"),
        ("redux.sync.add.f32 %f1, %f1, -1;", "unsupported instruction `redux.sync.add.f32 (.f32)`"),
        ("redux.sync.add.min.u32 %r1, %r2, -1;", "invalid: `redux.sync.add.min.u32` needs one operation"),
        ("match.sync.b32 %r1, %r2, -1;", "invalid: `match.sync.b32` needs .any or .all"),
        ("dp4a.u32.f32 %r1, %r2, %r3, %r4;", "invalid: `dp4a.u32.f32` needs two types, each .u32 or .s32"),
        ("bfind.u32 %r1, %r2, %r3;", "invalid: `bfind.u32` takes 2 operands, found 3"),
        ("tanh.f32 %f1, %f1;", "invalid: `tanh.f32`: tanh is .approx on .f32 and halves"),
        ("tex.2d.v4.f32.f32 {%f1, %f1, %f1, %f1}, [%rd1, {%f1}];", "takes 2 coordinate(s), found 1"),
        ("sust.p.2d.b32.trap [%rd1, {%r1, %r2}], {%r3};", "`sust.p.2d.b32.trap (modifier .p)`"),
        ("sured.p.add.1d.u32.trap [%rd1, {%r1}], %r3;", "`sured.p.add.1d.u32.trap (modifier .p)`"),
        (
            "tex.level.2d.v4.f32.f32 {%f1, %f1, %f1, %f1}, [%rd1, {%f1, %f1}], %f1;",
            "`tex.level.2d.v4.f32.f32 (mipmapped fetch)`",
        ),
        ("sured.b.xor.1d.b32.trap [%rd1, {%r1}], %r3;", "`sured.b.xor.1d.b32.trap (modifier .xor)`"),
        ("sured.b.add.1d.b32.trap [%rd1, {%r1}], %r3;", "invalid: `sured.b.add.1d.b32.trap`: ptxas takes .add on"),
        ("sured.b.min.1d.u64.trap [%rd1, {%r1}], %rd3;", "invalid: `sured.b.min.1d.u64.trap`: ptxas takes"),
        ("sured.b.or.1d.b64.trap [%rd1, {%r1}], %rd3;", "invalid: `sured.b.or.1d.b64.trap`: ptxas takes"),
        ("sured.b.add.1d.s64.trap [%rd1, {%r1}], %rd1;", "invalid: `sured.b.add.1d.s64.trap`: ptxas takes"),
        ("sured.b.and.1d.b64.trap [%rd1, {%r1}], %rd1;", "invalid: `sured.b.and.1d.b64.trap`: ptxas takes"),
        ("sured.b.min.1d.b32.trap [%rd1, {%r1}], %r3;", "invalid: `sured.b.min.1d.b32.trap`: ptxas takes"),
        ("sured.b.add.1d.u32.trap [%rd1, {%r1}], {%r3, %r3};", "takes an address and one value"),
        (
            "set.lt.f32.f16x2 %r1, %r2, %r3;",
            "invalid: `set.lt.f32.f16x2`: packed halves compare into .f16x2, .u32 or .s32",
        ),
        ("set.lt.f16x2.bf16x2 %r1, %r2, %r3;", "packed halves compare into .bf16x2, .u32 or .s32"),
    ];
    for (inst, expected) in cases {
        let src = format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{{\n\
             .reg .pred %p<2>;\n.reg .b16 %h<2>;\n.reg .b32 %r<5>;\n.reg .f32 %f<2>;\n.reg .b64 %rd<2>;\n\
             {inst}\nret;\n}}\n"
        );
        let e = ptx::load(&src, "v.ptx").map(|_| ()).unwrap_err().to_string();
        assert!(e.starts_with("v.ptx:11:1: ") && e.contains(expected), "{inst}: {e}");
    }
}

/// What each instruction form writes, hand-derived from PTX: the data
/// registers ([`warplight::ptx::ir::Kind::writes`], from the one register visitor) and
/// the predicates ([`warplight::ptx::ir::Kind::pred_writes`]).
#[test]
fn writes_of_every_form_with_a_destination() {
    let cases: &[(&str, &[&str], &[&str])] = &[
        ("mov.u32 %r1, %r2;", &["%r1"], &[]),
        ("mov.b64 %rd1, {%r1, %r2};", &["%rd1"], &[]),
        ("mov.b64 {%r1, %r2}, %rd1;", &["%r1", "%r2"], &[]),
        ("add.cc.u32 %r3, %r1, %r2;", &["%r3", "%cc (carry)"], &[]),
        ("addc.u32 %r3, %r1, %r2;", &["%r3"], &[]),
        ("setp.lt.s32 %p1|%p2, %r1, %r2;", &[], &["%p1", "%p2"]),
        ("and.pred %p1, %p2, %p3;", &[], &["%p1"]),
        ("set.lt.u32.f16x2 %r1, %r2, %r3;", &["%r1"], &[]),
        ("ld.global.v2.u32 {%r1, %r2}, [%rd1];", &["%r1", "%r2"], &[]),
        ("st.global.u32 [%rd1], %r1;", &[], &[]),
        ("atom.global.add.u32 %r1, [%rd1], 1;", &["%r1"], &[]),
        ("red.global.add.u32 [%rd1], 1;", &[], &[]),
        ("vote.sync.ballot.b32 %r1, %p1, -1;", &["%r1"], &[]),
        ("vote.sync.any.pred %p1, %p2, -1;", &[], &["%p1"]),
        ("shfl.sync.down.b32 %r1|%p1, %r2, 1, 31, -1;", &["%r1"], &["%p1"]),
        ("match.all.sync.b32 %r1|%p1, %r2, -1;", &["%r1"], &["%p1"]),
        ("redux.sync.add.u32 %r1, %r2, -1;", &["%r1"], &[]),
        ("bar.red.popc.u32 %r1, 0, %p1;", &["%r1"], &[]),
        ("sured.b.add.1d.u32.trap [%rd1, {%r1}], %r2;", &[], &[]),
        ("bar.warp.sync -1;", &[], &[]),
    ];
    for (inst, want, want_p) in cases {
        let src = format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n.visible .entry k()\n{{\n\
             .reg .pred %p<4>;\n.reg .b32 %r<4>;\n.reg .b64 %rd<2>;\n{inst}\nret;\n}}\n"
        );
        let prog = ptx::load(&src, "w.ptx").unwrap_or_else(|e| panic!("{inst}: {e}"));
        let f = &prog.functions[0];
        let k = &f.insts[0].kind;
        let name = |r: &warplight::ptx::ir::RegId| f.reg_names[*r as usize].clone();
        let got: Vec<String> = k.writes().iter().map(name).collect();
        assert_eq!(got, *want, "{inst}");
        let got_p: Vec<&str> = k.pred_writes().iter().map(|p| f.pred_names[*p as usize].as_str()).collect();
        assert_eq!(got_p, *want_p, "{inst}");
    }
}
