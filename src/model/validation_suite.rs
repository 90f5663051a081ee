//! The validation suite against the GPU: every case of
//! `tests/fixtures/validation/h200.json` (kernels of
//! `kernels/validation/suite.cu`, as clang's and nvcc's PTX, measured on an
//! H200 by `tools/device/validation_run.sh`) is run again on the hopper
//! profile, and its output buffers and Nsight Compute metrics are lined up
//! with the GPU's. Inputs are made by the same formulas as on the device
//! (`tools/device/validation.py`), checked by their FNV-1a hashes.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use serde_json::Value;

use super::{Model, Profile};
use crate::sim::{Arg, Device, LaunchConfig};

/// What went wrong reading or running the fixture.
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    /// The fixture or a PTX file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// The fixture is not what the device script writes.
    #[error("{0}: malformed fixture: {1}")]
    Fixture(String, String),
    /// An input buffer differs from the one the device used.
    #[error("case {case} ({dialect}): input `{buffer}` hashes to {ours}, the device's to {theirs}")]
    Input {
        /// Case.
        case: String,
        /// Dialect.
        dialect: String,
        /// Buffer.
        buffer: String,
        /// Our hash.
        ours: String,
        /// The fixture's.
        theirs: String,
    },
    /// Loading or running a kernel failed.
    #[error("case {case} ({dialect}): {msg}")]
    Run {
        /// Case.
        case: String,
        /// Dialect.
        dialect: String,
        /// The simulator's error.
        msg: String,
    },
}

/// How a metric is compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Expect {
    /// Decided by the addresses alone: must be equal.
    Exact,
    /// Shared wavefronts and bank conflicts where several warps share an SM:
    /// the requests of different warps collide, which varies from launch to
    /// launch; the model's count is a lower bound.
    TimingDependent,
    /// Shown side by side: SASS instruction counts against PTX ones, divergent
    /// branch targets of SASS, L2 sectors of atomics (not modelled).
    SideBySide,
    /// Measured differently in repeated identical runs on the H200
    /// ([`VARIES_BETWEEN_RUNS`]): L1 hits where several warps of an SM load
    /// the same sectors, a hit depending on which request arrived first;
    /// the model, which sees the warps' loads in one fixed order, gives an
    /// upper bound.
    VariesBetweenRuns,
}

/// Metrics (case, metric) that the H200 counted differently in identical
/// repeated runs (five per dialect, `tests/fixtures/validation/h200_bfs_repeat.json`,
/// docs/validation.md "L1 hit sectors where warps of an SM load the same
/// sectors"); compared as [`Expect::VariesBetweenRuns`].
pub const VARIES_BETWEEN_RUNS: &[(&str, &str)] =
    &[("bfs", "l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum")];

/// One metric of one case.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// `clang` or `nvcc`.
    pub dialect: String,
    /// Nsight Compute metric.
    pub metric: String,
    /// Summed over the case's launches on the GPU.
    pub measured: u64,
    /// Counted by warplight.
    pub emulated: u64,
    /// How they compare.
    pub expect: Expect,
}

/// One case's outputs.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Outputs {
    /// Case name.
    pub case: String,
    /// `clang` or `nvcc`.
    pub dialect: String,
    /// Output buffers whose every word equals the GPU's.
    pub equal: Vec<String>,
    /// Output buffers that differ: (name, differing words, words).
    pub differ: Vec<(String, usize, usize)>,
}

/// The comparison of the whole suite.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Report {
    /// Every metric of every case.
    pub rows: Vec<Row>,
    /// Every case's outputs.
    pub outputs: Vec<Outputs>,
}

/// The 32-bit hash the inputs are made from (lowbias32).
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    x
}

/// FNV-1a, 64 bits, of little-endian words.
fn fnv1a64(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    crate::sim::recording::fnv1a64(&bytes)
}

/// The words of a buffer of `n` elements made by `init` (as `validation.py`'s `init_words`).
pub fn init_words(init: &Value, n: usize) -> Result<Vec<u32>, String> {
    let kind = init["kind"].as_str().ok_or("init without kind")?;
    let int = |k: &str| init[k].as_i64().ok_or(format!("init `{kind}` without `{k}`"));
    let seed = init["seed"].as_u64().unwrap_or(0) as u32;
    let h = |i: usize| hash32((i as u32).wrapping_add(seed << 20));
    Ok(match kind {
        "zero" => vec![0; n],
        "fill" => {
            let mut w = vec![int("v")? as u32; n];
            if let (Some(f), Some(x)) = (init["first"].as_i64(), w.first_mut()) {
                *x = f as u32;
            }
            w
        }
        "iota" => {
            let (a, b) = (int("a")?, int("b")?);
            (0..n).map(|i| (a * i as i64 + b) as u32).collect()
        }
        "hash" => match init["mod"].as_u64() {
            Some(m) if m > 0 => (0..n).map(|i| h(i) % m as u32).collect(),
            _ => (0..n).map(h).collect(),
        },
        "hash_small" => {
            let (m, off) = (int("mod")?, int("off")?);
            (0..n).map(|i| ((h(i) as i64 % m) - off) as u32).collect()
        }
        "f32" => (0..n).map(|i| ((h(i) & 0xFFFF) as f32 / 65536.0 - 0.5).to_bits()).collect(),
        k => return Err(format!("unknown init `{k}`")),
    })
}

/// Decodes standard base64 (with padding).
fn base64(s: &str) -> Result<Vec<u8>, String> {
    let val = |c: u8| -> Result<u32, String> {
        Ok(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return Err(format!("not base64: {:?}", c as char)),
        } as u32)
    };
    let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let mut acc = 0u32;
        for (i, &c) in chunk.iter().enumerate() {
            acc |= val(c)? << (18 - 6 * i);
        }
        let n = chunk.len() * 6 / 8;
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Ok(out)
}

/// How `metric` compares in `case`, whose launches are `launches` (see [`Expect`]).
fn expectation(case: &str, metric: &str, launches: &[Value]) -> Expect {
    if VARIES_BETWEEN_RUNS.iter().any(|&(c, m)| (c, m) == (case, metric)) {
        return Expect::VariesBetweenRuns;
    }
    let shared = metric.starts_with("l1tex__data_pipe_lsu_wavefronts_mem_shared_op_")
        || metric.starts_with("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_");
    if shared {
        // one warp in the whole grid: nothing to collide with
        let one_warp = launches.iter().all(|l| {
            let t: u64 = l["block"].as_array().map_or(0, |b| b.iter().filter_map(Value::as_u64).product());
            let g: u64 = l["grid"].as_array().map_or(0, |b| b.iter().filter_map(Value::as_u64).product());
            t <= 32 && g == 1
        });
        return if one_warp { Expect::Exact } else { Expect::TimingDependent };
    }
    if metric.starts_with("l1tex__t_") || metric.starts_with("smsp__sass_inst_executed_op_") {
        return Expect::Exact;
    }
    Expect::SideBySide
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> SuiteError + '_ {
    move |source| SuiteError::Io { path: path.display().to_string(), source }
}

/// Runs every case of the fixture at `fixture` (PTX paths in it are relative
/// to `root`) on the hopper profile and compares.
pub fn compare(fixture: &Path, root: &Path) -> Result<Report, SuiteError> {
    let name = fixture.display().to_string();
    let bad = |m: &str| SuiteError::Fixture(name.clone(), m.to_string());
    let fx: Value = serde_json::from_str(&std::fs::read_to_string(fixture).map_err(io(fixture))?)
        .map_err(|e| bad(&e.to_string()))?;
    let mut sources: HashMap<String, String> = HashMap::new();
    let mut report = Report::default();
    for c in fx["cases"].as_array().ok_or_else(|| bad("no cases"))? {
        let case = c["name"].as_str().ok_or_else(|| bad("case without name"))?.to_string();
        let dialect = c["dialect"].as_str().ok_or_else(|| bad("case without dialect"))?.to_string();
        let run_err = |msg: String| SuiteError::Run { case: case.clone(), dialect: dialect.clone(), msg };
        let ptx = c["ptx"].as_str().ok_or_else(|| bad("case without ptx"))?;
        if !sources.contains_key(ptx) {
            let p = root.join(ptx);
            sources.insert(ptx.to_string(), std::fs::read_to_string(&p).map_err(io(&p))?);
        }
        let mut dev = Device::new();
        let m = dev.load_ptx(&sources[ptx], ptx).map_err(|e| run_err(e.to_string()))?;
        let mut bufs = BTreeMap::new();
        for b in c["buffers"].as_array().ok_or_else(|| bad("case without buffers"))? {
            let bname = b["name"].as_str().ok_or_else(|| bad("buffer without name"))?.to_string();
            let n = b["n"].as_u64().ok_or_else(|| bad("buffer without n"))? as usize;
            let words = init_words(&b["init"], n).map_err(|e| bad(&e))?;
            let theirs = c["input_fnv1a64"][&bname].as_str().unwrap_or_default().to_string();
            let ours = fnv1a64(&words);
            if ours != theirs {
                return Err(SuiteError::Input { case, dialect, buffer: bname, ours, theirs });
            }
            let p = dev.alloc_from(&words);
            bufs.insert(bname, (p, n, b["output"].as_bool().unwrap_or(false)));
        }
        let launches = c["launches"].as_array().ok_or_else(|| bad("case without launches"))?;
        let mut ours: BTreeMap<&'static str, u64> = BTreeMap::new();
        for l in launches {
            let kernel = l["kernel"].as_str().ok_or_else(|| bad("launch without kernel"))?;
            let dim = |k: &str| -> Result<[u32; 3], SuiteError> {
                let v: Vec<u32> = l[k]
                    .as_array()
                    .ok_or_else(|| bad("launch without dims"))?
                    .iter()
                    .map(|x| x.as_u64().unwrap_or(1) as u32)
                    .collect();
                Ok([v.first().copied().unwrap_or(1), v.get(1).copied().unwrap_or(1), v.get(2).copied().unwrap_or(1)])
            };
            let cfg = LaunchConfig { grid: dim("grid")?, block: dim("block")?, dynamic_shared: 0 };
            let mut args = Vec::new();
            for a in l["args"].as_array().ok_or_else(|| bad("launch without args"))? {
                if let Some(b) = a["buf"].as_str() {
                    args.push(Arg::Ptr(bufs.get(b).ok_or_else(|| bad(&format!("no buffer {b}")))?.0));
                } else {
                    args.push(Arg::I32(a["i32"].as_i64().ok_or_else(|| bad("argument neither buf nor i32"))? as i32));
                }
            }
            let model = Model::new(Profile::Hopper, &m.prog);
            let core = dev.launch_observed(&m, kernel, cfg, &args, Some(&model)).map_err(|e| run_err(e.to_string()))?;
            for (k, v) in model.finish().profiler_names(&core.totals) {
                *ours.entry(k).or_default() += v;
            }
        }
        let mut out = Outputs { case: case.clone(), dialect: dialect.clone(), equal: Vec::new(), differ: Vec::new() };
        for (bname, (p, n, is_out)) in &bufs {
            if !is_out {
                continue;
            }
            let got: Vec<u32> = dev.read(*p, *n);
            let want = base64(c["outputs"][bname].as_str().unwrap_or_default()).map_err(|e| bad(&e))?;
            let want: Vec<u32> = want.chunks(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
            let diff = got.iter().zip(&want).filter(|(a, b)| a != b).count() + got.len().abs_diff(want.len());
            if diff == 0 {
                out.equal.push(bname.clone());
            } else {
                out.differ.push((bname.clone(), diff, *n));
            }
        }
        report.outputs.push(out);
        let measured = c["metrics"].as_object().ok_or_else(|| bad("case without metrics"))?;
        for (metric, v) in measured {
            let (Some(measured), Some(emulated)) = (v.as_u64(), ours.get(metric.as_str())) else { continue };
            report.rows.push(Row {
                case: case.clone(),
                dialect: dialect.clone(),
                metric: metric.clone(),
                measured,
                emulated: *emulated,
                expect: expectation(&case, metric, launches),
            });
        }
    }
    Ok(report)
}

impl Report {
    /// Exact metrics that differ.
    pub fn exact_differences(&self) -> Vec<&Row> {
        self.rows.iter().filter(|r| r.expect == Expect::Exact && r.measured != r.emulated).collect()
    }

    /// Timing-dependent metrics outside the model's bound: shared-memory
    /// ones the GPU counted fewer of than the model, and ones that vary
    /// between runs that it counted more of.
    pub fn outside_the_bound(&self) -> Vec<&Row> {
        self.rows
            .iter()
            .filter(|r| match r.expect {
                Expect::TimingDependent => r.measured < r.emulated,
                Expect::VariesBetweenRuns => r.measured > r.emulated,
                _ => false,
            })
            .collect()
    }

    /// Per case and dialect: outputs, and how many metrics of each kind agree.
    pub fn summary_markdown(&self) -> String {
        let mut s = String::from(
            "| case | dialect | outputs | exact metrics equal | timing-dependent: equal / within the bound | side by side: equal |\n|---|---|---|---|---|---|\n",
        );
        for o in &self.outputs {
            let rows: Vec<&Row> = self.rows.iter().filter(|r| r.case == o.case && r.dialect == o.dialect).collect();
            let count = |e: Expect, f: &dyn Fn(&Row) -> bool| rows.iter().filter(|r| r.expect == e && f(r)).count();
            let outputs = if o.differ.is_empty() {
                "equal".to_string()
            } else {
                let d: Vec<String> =
                    o.differ.iter().map(|(n, k, w)| format!("`{n}`: {k} of {w} words differ")).collect();
                format!("**{}**", d.join("; "))
            };
            let exact = format!(
                "{} / {}",
                count(Expect::Exact, &|r| r.measured == r.emulated),
                count(Expect::Exact, &|_| true)
            );
            let timed = format!(
                "{} / {}",
                count(Expect::TimingDependent, &|r| r.measured == r.emulated)
                    + count(Expect::VariesBetweenRuns, &|r| r.measured == r.emulated),
                count(Expect::TimingDependent, &|r| r.measured > r.emulated)
                    + count(Expect::VariesBetweenRuns, &|r| r.measured < r.emulated)
            );
            let side = format!(
                "{} / {}",
                count(Expect::SideBySide, &|r| r.measured == r.emulated),
                count(Expect::SideBySide, &|_| true)
            );
            s.push_str(&format!("| {} | {} | {} | {} | {} | {} |\n", o.case, o.dialect, outputs, exact, timed, side));
        }
        s
    }

    /// The metrics that are not equal (all kinds), as a markdown table.
    pub fn differences_markdown(&self) -> String {
        let rows: Vec<Row> = self.rows.iter().filter(|r| r.measured != r.emulated).cloned().collect();
        Report { rows, outputs: Vec::new() }.markdown()
    }

    /// Every metric as a markdown table.
    pub fn markdown(&self) -> String {
        let mut s = String::from("| case | dialect | metric | H200 | warplight | |\n|---|---|---|---|---|---|\n");
        for r in &self.rows {
            let mark = match (r.expect, r.measured == r.emulated) {
                (_, true) => "=",
                (Expect::Exact, false) => "**differs**",
                (Expect::SideBySide, false) => "SASS vs PTX / unmodelled",
                (Expect::TimingDependent, false) if r.measured > r.emulated => "timing-dependent (above the model)",
                (Expect::TimingDependent, false) => "**below the model**",
                (Expect::VariesBetweenRuns, false) if r.measured < r.emulated => {
                    "timing-dependent (varies between runs; below the model)"
                }
                (Expect::VariesBetweenRuns, false) => "**above the model**",
            };
            s.push_str(&format!(
                "| {} | {} | `{}` | {} | {} | {} |\n",
                r.case, r.dialect, r.metric, r.measured, r.emulated, mark
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_as_the_device_script_makes_them() {
        // tools/device/validation.py: hash32(0) = 0, hash32(1) = 1753845952
        assert_eq!(hash32(0), 0);
        assert_eq!(hash32(1), 1_753_845_952);
        let f = init_words(&serde_json::json!({"kind": "f32", "seed": 1}), 4).unwrap();
        assert_eq!(f, [3_196_510_720, 3_200_969_216, 3_178_766_336, 1_055_416_320]);
        let s = init_words(&serde_json::json!({"kind": "hash_small", "seed": 8, "mod": 21, "off": 10}), 4).unwrap();
        assert_eq!(s, [4_294_967_288, 9, 4_294_967_294, 9]);
        let c = init_words(&serde_json::json!({"kind": "fill", "v": -1, "first": 0}), 3).unwrap();
        assert_eq!(c, [0, u32::MAX, u32::MAX]);
    }

    #[test]
    fn base64_round_trip() {
        assert_eq!(base64("AQIDBA==").unwrap(), [1, 2, 3, 4]);
        assert_eq!(base64("AQID").unwrap(), [1, 2, 3]);
        assert!(base64("A*").is_err());
    }
}
