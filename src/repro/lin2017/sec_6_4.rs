//! Thesis 003 §6.4 (003:L546): the affine ray-triangle test "reduces the 26
//! multiplications, 23 additions/subtractions required in the standard
//! ray-triangle intersection algorithm to 20 multiplications and 13
//! additions/subtractions".
//!
//! Counted by the emulator, not read off the source: `kernels/lin2017/intersect.cu`
//! runs each routine once per (ray, triangle) pair, every pair built to hit
//! (a ray from the camera through the triangle's centroid), so every
//! operation of the routine executes once per pair; the floating-point
//! instructions the emulator executed on the routine's source lines, over
//! the pairs, are the routine's operations. Both compilers' PTX run:
//! clang's (the path tracer's setting, no contraction: every multiplication
//! and addition an instruction of its own) and nvcc's (contracted: a
//! multiplication and an addition fused into one `fma`). The standard
//! routine the thesis does not name is taken to be Möller and Trumbore's
//! (our reading, `docs/fixtures.md`). A test holds `tri_affine`'s
//! instructions equal to those of `affine()` in `kernels/lin2017/path.cu`,
//! the test the path tracer runs.

use std::collections::BTreeMap;
use std::ops::RangeInclusive;

use glam::Vec3;

use crate::host::path::layout::affine_rows;
use crate::host::path::native::affine_test;
use crate::host::rt_kernels::upload;
use crate::host::scene::Scene;
use crate::ptx::ir::Program;
use crate::repro::compare::Tolerance;
use crate::repro::registry::{Entry, MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::repro::table::{Cell, Check, Column, Row, RowKind, Table, Unit};
use crate::sim::counters::InstProfile;
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, Fidelity, LaunchConfig, SimConfig};

/// Measurement group: both routines on the scene's triangles, both PTX dialects.
pub const OPS: &str = "lin/intersection-ops";
/// The scene whose triangles are tested.
pub const SCENE: &str = "cornell-lambert";
/// The kernels' CUDA source.
pub const SOURCE: &str = include_str!("../../../kernels/lin2017/intersect.cu");
/// Its path as the PTX's `.file` directive names it (suffix).
pub const SOURCE_FILE: &str = "kernels/lin2017/intersect.cu";
/// clang-16's PTX (no contraction).
pub const PTX: &str = include_str!("../../../kernels/lin2017/intersect.ptx");
/// nvcc's PTX (contracted).
pub const NVCC_PTX: &str = include_str!("../../../kernels/lin2017/intersect.nvcc.ptx");

/// Threads per CTA.
const THREADS: u32 = 128;

/// The two routines: (variant, kernel entry, device function, thesis' mul and add/sub).
pub const ROUTINES: [(&str, &str, &str, [&str; 2]); 2] =
    [("standard", "tri_standard", "standard", ["26", "23"]), ("affine", "tri_affine", "affine", ["20", "13"])];

/// The two compilers' PTX: (name, source, file name).
pub const DIALECTS: [(&str, &str, &str); 2] =
    [("clang", PTX, "kernels/lin2017/intersect.ptx"), ("nvcc", NVCC_PTX, "kernels/lin2017/intersect.nvcc.ptx")];

/// Floating-point (f32) operations of one routine, per test.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Ops {
    /// `mul`.
    pub mul: u64,
    /// `add` and `sub`.
    pub add: u64,
    /// `fma` (one multiplication and one addition).
    pub fma: u64,
    /// `div` and `rcp`.
    pub div: u64,
    /// `neg`.
    pub neg: u64,
}

impl Ops {
    /// Multiplications with each `fma` counted as one.
    pub fn mul_unfused(&self) -> u64 {
        self.mul + self.fma
    }

    /// Additions/subtractions with each `fma` counted as one.
    pub fn add_unfused(&self) -> u64 {
        self.add + self.fma
    }

    fn counters(&self) -> [(&'static str, u64); 5] {
        [("mul", self.mul), ("add", self.add), ("fma", self.fma), ("div", self.div), ("neg", self.neg)]
    }

    /// Adds `n` executions of `opcode` if it is an f32 operation counted here.
    fn add_opcode(&mut self, opcode: &str, n: u64) {
        if !opcode.ends_with(".f32") {
            return;
        }
        let slot = match opcode.split('.').next() {
            Some("mul") => &mut self.mul,
            Some("add" | "sub") => &mut self.add,
            Some("fma") => &mut self.fma,
            Some("div" | "rcp") => &mut self.div,
            Some("neg") => &mut self.neg,
            _ => return,
        };
        *slot += n;
    }
}

/// The source lines of device function `name` in `source`: from the line
/// that defines it (`static __device__ … name(`) to the first line after it
/// that is a lone `}`.
pub fn function_lines(source: &str, name: &str) -> Option<RangeInclusive<u32>> {
    let lines: Vec<&str> = source.lines().collect();
    let head = format!(" {name}(");
    let start = lines.iter().position(|l| l.starts_with("static __device__") && l.contains(&head))?;
    let end = lines[start..].iter().position(|l| *l == "}")? + start;
    Some(start as u32 + 1..=end as u32 + 1)
}

/// Operations executed (lanes with their guard true) on `lines` of `source_file`, summed over `profile`.
pub fn ops_on_lines(prog: &Program, profile: &InstProfile, source_file: &str, lines: &RangeInclusive<u32>) -> Ops {
    ops_where(prog, source_file, lines, |f, pc| profile.per_fn.get(f).and_then(|c| c.get(pc)).map_or(0, |c| c.pred_on))
}

/// Operations on `lines` of `source_file` in the program's text (each instruction once).
pub fn static_ops(prog: &Program, source_file: &str, lines: &RangeInclusive<u32>) -> Ops {
    ops_where(prog, source_file, lines, |_, _| 1)
}

/// The operations of the instructions `.loc` places on `lines` of
/// `source_file`, each counted `times(function, pc)` times.
fn ops_where(
    prog: &Program,
    source_file: &str,
    lines: &RangeInclusive<u32>,
    times: impl Fn(usize, usize) -> u64,
) -> Ops {
    let mut ops = Ops::default();
    for (f, pc, info, line) in prog.located_in(source_file) {
        if lines.contains(&line) {
            ops.add_opcode(&info.opcode, times(f, pc));
        }
    }
    ops
}

/// One routine measured under one dialect.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// `standard` or `affine`.
    pub routine: &'static str,
    /// `clang` or `nvcc`.
    pub dialect: &'static str,
    /// Pairs tested.
    pub tests: u64,
    /// Pairs the kernel reported hit.
    pub hits: u64,
    /// Operations per test.
    pub ops: Ops,
    /// Whether the kernel's distances equal the Rust reference bit for bit
    /// (clang's PTX, which does the reference's operations in its order).
    pub exact: bool,
    /// Largest relative difference of the distances from the f64 ray-plane distance.
    pub max_rel_error: f64,
}

/// Möller and Trumbore's test in the kernel's operations and order (f32,
/// no contraction): the hit distance in [t_min, t_max], if any.
pub fn standard_test(v: &[Vec3; 3], o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
    let (a, b, c) = (v[0], v[1], v[2]);
    let (e1x, e1y, e1z) = (b.x - a.x, b.y - a.y, b.z - a.z);
    let (e2x, e2y, e2z) = (c.x - a.x, c.y - a.y, c.z - a.z);
    let (px, py, pz) = (d.y * e2z - d.z * e2y, d.z * e2x - d.x * e2z, d.x * e2y - d.y * e2x);
    let det = e1x * px + e1y * py + e1z * pz;
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let (sx, sy, sz) = (o.x - a.x, o.y - a.y, o.z - a.z);
    let u = (sx * px + sy * py + sz * pz) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let (qx, qy, qz) = (sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x);
    let v = (d.x * qx + d.y * qy + d.z * qz) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv;
    (t >= t_min && t <= t_max).then_some(t)
}

/// The pairs: every triangle of `scene` with the ray from the camera through
/// its centroid (unit direction), whose plane does not contain the camera.
pub fn pairs(scene: &Scene) -> Vec<([Vec3; 3], Vec3, Vec3)> {
    let o = Vec3::from(scene.camera.position);
    scene
        .triangles
        .iter()
        .filter_map(|t| {
            let c = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
            let d = (c - o).normalize_or_zero();
            let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).normalize_or_zero();
            (d != Vec3::ZERO && n.dot(d).abs() > 1e-3).then_some((t.v, o, d))
        })
        .collect()
}

/// The f64 distance along (o, d) to the plane of `v`.
fn plane_distance(v: &[Vec3; 3], o: Vec3, d: Vec3) -> f64 {
    let (a, b, c, o, d) = (v[0].as_dvec3(), v[1].as_dvec3(), v[2].as_dvec3(), o.as_dvec3(), d.as_dvec3());
    let n = (b - a).cross(c - a);
    n.dot(a - o) / n.dot(d)
}

/// Why the op count could not be measured.
#[derive(Debug, thiserror::Error)]
pub enum OpsError {
    /// The emulator failed.
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
    /// A pair missed, so its routine did not run to the end and the counts are not per full test.
    #[error("{routine} ({dialect}): {hits} of {tests} pairs hit; every pair must hit for a per-test count")]
    Missed {
        /// The routine.
        routine: &'static str,
        /// The PTX dialect.
        dialect: &'static str,
        /// Pairs hit.
        hits: u64,
        /// Pairs tested.
        tests: u64,
    },
    /// The executed operations are not a whole number per test.
    #[error("{routine} ({dialect}): {what} = {total} over {tests} tests is not a whole number per test")]
    Uneven {
        /// The routine.
        routine: &'static str,
        /// The PTX dialect.
        dialect: &'static str,
        /// The operation class.
        what: &'static str,
        /// Its executions over all tests.
        total: u64,
        /// Pairs tested.
        tests: u64,
    },
    /// The kernel source lost a routine.
    #[error("{SOURCE_FILE}: no device function `{0}`")]
    NoFunction(&'static str),
}

/// Runs both routines on `scene`'s pairs under both dialects.
pub fn measure_on(scene: &Scene) -> Result<Vec<Measured>, OpsError> {
    let pairs = pairs(scene);
    let n = pairs.len();
    let (t_min, t_max) = (1e-4f32, 1e30f32);
    let rays: Vec<f32> = pairs.iter().flat_map(|(_, o, d)| [o.x, o.y, o.z, t_min, d.x, d.y, d.z, t_max]).collect();
    let verts: Vec<f32> = pairs.iter().flat_map(|(v, _, _)| v.iter().flat_map(|p| [p.x, p.y, p.z, 0.0])).collect();
    let rows: Vec<[f32; 12]> = pairs.iter().map(|(v, _, _)| affine_rows(v)).collect();
    let row_floats: Vec<f32> = rows.iter().flatten().copied().collect();
    let plane: Vec<f64> = pairs.iter().map(|(v, o, d)| plane_distance(v, *o, *d)).collect();
    let reference = |routine: &str| -> Vec<Option<f32>> {
        pairs
            .iter()
            .zip(&rows)
            .map(|((v, o, d), m)| match routine {
                "standard" => standard_test(v, *o, *d, t_min, t_max),
                _ => affine_test(m, (*o).into(), (*d).into(), t_min, t_max),
            })
            .collect()
    };
    let references = ROUTINES.map(|(routine, ..)| reference(routine));
    let mut out = Vec::new();
    for (dialect, ptx, file) in DIALECTS {
        let mut dev = Device::with_config(SimConfig { fidelity: Fidelity::Instructions, ..SimConfig::default() });
        let module = dev.load_ptx(ptx, file)?;
        let r = upload(&mut dev, &to_bytes(&rays), "rays")?;
        for ((routine, entry, func, _), reference) in ROUTINES.into_iter().zip(&references) {
            let lines = function_lines(SOURCE, func).ok_or(OpsError::NoFunction(func))?;
            let data = if routine == "standard" { &verts } else { &row_floats };
            let t = upload(&mut dev, &to_bytes(data), "triangles")?;
            let o = dev.alloc_zeroed::<f32>(n.max(1));
            let args = [Arg::Ptr(r), Arg::Ptr(t), Arg::U32(n as u32), Arg::Ptr(o)];
            let grid = LaunchConfig::linear((n as u32).div_ceil(THREADS).max(1), THREADS);
            let stats = dev.launch(&module, entry, grid, &args)?;
            let got = dev.read::<f32>(o, n);
            let hits = got.iter().filter(|t| **t >= 0.0).count() as u64;
            let tests = n as u64;
            if hits != tests {
                return Err(OpsError::Missed { routine, dialect, hits, tests });
            }
            let total = ops_on_lines(&module.prog, &stats.profile, SOURCE_FILE, &lines);
            let mut ops = Ops::default();
            for ((what, sum), slot) in
                total.counters().into_iter().zip([&mut ops.mul, &mut ops.add, &mut ops.fma, &mut ops.div, &mut ops.neg])
            {
                if tests == 0 || sum % tests != 0 {
                    return Err(OpsError::Uneven { routine, dialect, what, total: sum, tests });
                }
                *slot = sum / tests;
            }
            let exact = got.iter().zip(reference).all(|(g, r)| r.is_some_and(|r| r.to_bits() == g.to_bits()));
            let max_rel_error = got.iter().zip(&plane).map(|(g, p)| ((*g as f64 - p) / p).abs()).fold(0.0f64, f64::max);
            out.push(Measured { routine, dialect, tests, hits, ops, exact, max_rel_error });
        }
    }
    Ok(out)
}

fn variant(routine: &str, dialect: &str) -> String {
    format!("{routine}/{dialect}")
}

/// Measurement group [`OPS`].
pub fn measure(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    tick(Tick { frame: None, variant: "intersection ops" });
    let mut out = Vec::new();
    for m in measure_on(ws.scene)? {
        let mut c: BTreeMap<String, f64> = m.ops.counters().iter().map(|(k, v)| (k.to_string(), *v as f64)).collect();
        c.insert("tests".into(), m.tests as f64);
        c.insert("hits".into(), m.hits as f64);
        c.insert("exact".into(), m.exact as u8 as f64);
        c.insert("max_rel_error".into(), m.max_rel_error);
        out.push(Sample {
            group: OPS.into(),
            scene: ws.scene.name.clone(),
            frame: None,
            variant: variant(m.routine, m.dialect),
            counters: c,
        });
    }
    Ok(out)
}

/// The table.
pub fn render(e: &Entry, r: &Results) -> Vec<Table> {
    let get = |routine: &str, dialect: &str, n: &str| r.sum(OPS, SCENE, &variant(routine, dialect), n);
    let exact = Tolerance::Relative(0.0);
    let columns = vec![
        Column::measured("mul (clang, not contracted)", Unit::Count, exact),
        Column::measured("add/sub (clang, not contracted)", Unit::Count, exact),
        Column::ours_only("div/rcp", Unit::Count),
        Column::ours_only("neg", Unit::Count),
        Column::ours_only("fma (nvcc)", Unit::Count),
        Column::ours_only("mul (nvcc)", Unit::Count),
        Column::ours_only("add/sub (nvcc)", Unit::Count),
    ];
    let mut rows = Vec::new();
    for (routine, _, _, printed) in ROUTINES {
        let ours = [get(routine, "clang", "mul"), get(routine, "clang", "add")];
        let mut cells: Vec<Cell> =
            ours.iter().zip(printed).zip(&columns).map(|((o, p), c)| Cell::compared(*o, p, c.tolerance)).collect();
        for (dialect, name) in [("clang", "div"), ("clang", "neg"), ("nvcc", "fma"), ("nvcc", "mul"), ("nvcc", "add")] {
            cells.push(Cell { ours: get(routine, dialect, name), ..Cell::default() });
        }
        let label = if routine == "standard" { "standard (Möller-Trumbore)" } else { "affine (§6.4)" };
        rows.push(Row { label: label.into(), kind: RowKind::Scene, cells });
    }
    let mut table =
        Table { address: e.address(), heading: e.heading(), columns, rows, checks: Vec::new(), notes: Vec::new() };
    let fewer = |d: &str, n: &str| get("affine", d, n).zip(get("standard", d, n)).map(|(a, s)| s - a);
    let (dm, da) = (fewer("clang", "mul"), fewer("clang", "add"));
    table.checks.push(Check {
        claim: "the affine test needs fewer multiplications and fewer additions/subtractions than the standard \
                test: 6 and 10 fewer as printed (003:L546)"
            .into(),
        evidence: format!(
            "clang's PTX: {} fewer mul, {} fewer add/sub",
            dm.map_or("–".into(), |v| format!("{v}")),
            da.map_or("–".into(), |v| format!("{v}"))
        ),
        holds: dm.is_some_and(|v| v > 0.0) && da.is_some_and(|v| v > 0.0),
    });
    let all_exact = ROUTINES.iter().all(|(rt, ..)| get(rt, "clang", "exact") == Some(1.0));
    let err = ROUTINES
        .iter()
        .flat_map(|(rt, ..)| ["clang", "nvcc"].map(|d| get(rt, d, "max_rel_error")))
        .flatten()
        .fold(0.0f64, f64::max);
    table.checks.push(Check {
        claim: "both routines find every hit, at the ray-plane distance".into(),
        evidence: format!(
            "{} pairs each; clang's distances equal the Rust references bit for bit: {all_exact}; largest relative \
             difference from the f64 plane distance (both dialects) {err:.1e}",
            get("affine", "clang", "tests").unwrap_or(f64::NAN)
        ),
        holds: all_exact && err < 1e-4,
    });
    table.notes.push(
        "Counted by the emulator: each routine of kernels/lin2017/intersect.cu (tri_standard, Möller-Trumbore, our \
         reading of the thesis' unnamed \"standard ray-triangle intersection algorithm\"; tri_affine, the path \
         tracer's affine() of kernels/lin2017/path.cu, a test holds the two compiled alike) runs once per triangle \
         of the Cornell box with the ray from the camera through its centroid, so each pair runs the whole routine; \
         the f32 instructions executed on the routine's source lines, per pair. clang's PTX is the path tracer's \
         (contraction off, as the native mirror needs); nvcc's contracts a multiplication and an addition into one \
         fma. Our standard test scales u, v and t by the reciprocal of the determinant (3 mul); the affine test \
         adds three translations (the rows' w) and divides once."
            .into(),
    );
    vec![table]
}
