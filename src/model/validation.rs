//! Measured-versus-emulated comparison for the memory microbenchmarks of
//! `kernels/micro/micro.cu`: the H100 numbers (Nsight Compute) are in
//! `tests/fixtures/h100_micro.json`; this runs the same launches on the
//! hopper profile and lines the two up, metric by metric.

use std::path::{Path, PathBuf};

use super::{Model, Profile};
use crate::sim::{Arg, Device, LaunchConfig, SimError};

/// How a metric is expected to compare.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Expect {
    /// Must be equal.
    Exact,
    /// Shown side by side: PTX and SASS differ (instruction counts), or the
    /// hardware's number depends on things warplight does not model.
    SideBySide,
    /// Varies between identical launches on the GPU (shared wavefronts and
    /// bank conflicts collide between warps' requests; docs/validation.md):
    /// the model's count, what the addresses alone decide, is a lower bound.
    TimingDependent,
}

/// One metric of one launch.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Launch index in the fixture.
    pub launch: usize,
    /// Kernel.
    pub kernel: String,
    /// Its two integer arguments.
    pub args: (i64, i64),
    /// Nsight Compute metric name.
    pub metric: String,
    /// Measured on the GPU.
    pub measured: u64,
    /// Counted by warplight.
    pub emulated: u64,
    /// How they must compare.
    pub expect: Expect,
}

/// Metrics compared exactly, and which launches they are exact for.
fn expectation(metric: &str, kernel: &str) -> Expect {
    let exact_mem = [
        "l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum",
        "l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum",
        "l1tex__t_requests_pipe_lsu_mem_global_op_st.sum",
        "l1tex__t_sectors_pipe_lsu_mem_global_op_st.sum",
        "l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum",
        "l1tex__t_requests_pipe_lsu_mem_local_op_ld.sum",
        "l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum",
        "l1tex__t_requests_pipe_lsu_mem_local_op_st.sum",
        "l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum",
        "l1tex__t_requests_pipe_lsu_mem_global_op_atom.sum",
        "l1tex__t_requests_pipe_lsu_mem_global_op_red.sum",
        "l1tex__t_sectors_pipe_lsu_mem_global_op_atom.sum",
        "l1tex__t_sectors_pipe_lsu_mem_global_op_red.sum",
    ];
    if metric.starts_with("l1tex__data_pipe_lsu_wavefronts_mem_shared_op_")
        || metric.starts_with("l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_")
    {
        return Expect::TimingDependent;
    }
    if kernel == "local_array" && metric.contains("local_op") {
        return Expect::SideBySide;
    }
    // ptxas keeps local_array's buffer in registers, and hoists local_big's 8 distinct
    // input loads out of its loop; clang's PTX loads in every iteration.
    if (kernel == "local_array" || kernel == "local_big") && metric.contains("global_op_ld") {
        return Expect::SideBySide;
    }
    if exact_mem.contains(&metric) { Expect::Exact } else { Expect::SideBySide }
}

/// Why [`compare`] could not run. Every message names the file at fault.
#[derive(Debug, thiserror::Error)]
pub enum ValidationError {
    /// The fixture or the PTX file could not be read.
    #[error("{}: {source}", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The fixture is not JSON.
    #[error("{}: not JSON: {source}", file.display())]
    Json {
        /// The fixture.
        file: PathBuf,
        /// Where and why.
        source: serde_json::Error,
    },
    /// The fixture lacks something a comparison needs.
    #[error("{}: {what}", file.display())]
    Fixture {
        /// The fixture.
        file: PathBuf,
        /// What is missing, and where.
        what: String,
    },
    /// The PTX does not load (the message names the file and line).
    #[error(transparent)]
    Ptx(Box<SimError>),
    /// A launch of the fixture failed on the emulator.
    #[error("{}: launch {launch} (`{kernel}`): {source}", fixture.display())]
    Launch {
        /// The fixture.
        fixture: PathBuf,
        /// The launch's `id` in the fixture.
        launch: usize,
        /// Its kernel.
        kernel: String,
        /// Why (names the PTX file where it is about the PTX).
        source: Box<SimError>,
    },
}

/// Runs every launch of the fixture at `fixture` on the hopper profile using the
/// PTX at `ptx`, and returns the comparison rows.
pub fn compare(fixture: &Path, ptx: &Path) -> Result<Vec<Row>, ValidationError> {
    let read = |file: &Path| {
        std::fs::read_to_string(file).map_err(|source| ValidationError::Read { file: file.to_path_buf(), source })
    };
    let missing = |what: String| ValidationError::Fixture { file: fixture.to_path_buf(), what };
    let fx: serde_json::Value = serde_json::from_str(&read(fixture)?)
        .map_err(|source| ValidationError::Json { file: fixture.to_path_buf(), source })?;
    let src = read(ptx)?;
    let mut rows = Vec::new();
    let launches = fx["launches"].as_array().ok_or_else(|| missing("no `launches` array".into()))?;
    for (i, l) in launches.iter().enumerate() {
        let id = l["id"].as_u64().unwrap_or(0) as usize;
        let kernel = l["kernel"].as_str().ok_or_else(|| missing(format!("launches[{i}] has no `kernel`")))?.to_string();
        let (a, b) = (l["a"].as_i64().unwrap_or(0), l["b"].as_i64().unwrap_or(0));
        let (grid, block) = (l["grid"].as_u64().unwrap_or(64) as u32, l["block"].as_u64().unwrap_or(256) as u32);
        let mut dev = Device::new();
        let m = dev.load_ptx(&src, &ptx.display().to_string()).map_err(|e| ValidationError::Ptx(Box::new(e)))?;
        let n = 1usize << 20;
        let out = dev.alloc_zeroed::<f32>(n);
        let inb = dev.alloc_zeroed::<f32>(n);
        let model = Model::new(Profile::Hopper, &m.prog);
        let args = [Arg::Ptr(out), Arg::Ptr(inb), Arg::I32(a as i32), Arg::I32(b as i32)];
        let core = dev.launch_observed(&m, &kernel, LaunchConfig::linear(grid, block), &args, Some(&model)).map_err(
            |source| ValidationError::Launch {
                fixture: fixture.to_path_buf(),
                launch: id,
                kernel: kernel.clone(),
                source: Box::new(source),
            },
        )?;
        let stats = model.finish();
        let ours: std::collections::HashMap<&str, u64> = stats.profiler_names(&core.totals).into_iter().collect();
        let mut metrics: Vec<(&String, &serde_json::Value)> = l["metrics"]
            .as_object()
            .ok_or_else(|| missing(format!("launches[{i}] has no `metrics`")))?
            .iter()
            .collect();
        metrics.sort_by_key(|(k, _)| k.as_str());
        for (name, v) in metrics {
            let measured = v.as_u64().unwrap_or(0);
            // warplight counts atom and red together where PTX and SASS choose differently
            let emulated = match name.as_str() {
                "lts__t_sectors_op_atom.sum" | "lts__t_sectors_op_red.sum" => {
                    ours.get(name.as_str()).copied().unwrap_or(0)
                }
                n => match ours.get(n) {
                    Some(v) => *v,
                    None => continue,
                },
            };
            rows.push(Row {
                launch: id,
                kernel: kernel.clone(),
                args: (a, b),
                metric: name.clone(),
                measured,
                emulated,
                expect: expectation(name, &kernel),
            });
        }
    }
    Ok(rows)
}

/// The comparison as a markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from("| launch | kernel (a, b) | metric | H100 | warplight | |\n|---|---|---|---|---|---|\n");
    for r in rows {
        let mark = match (r.expect, r.measured == r.emulated) {
            (_, true) => "=",
            (Expect::Exact, false) => "**differs**",
            (Expect::SideBySide, false) => "PTX vs SASS / unmodelled",
            (Expect::TimingDependent, false) if r.measured > r.emulated => "timing-dependent (above the model)",
            (Expect::TimingDependent, false) => "**below the model**",
        };
        s.push_str(&format!(
            "| {} | {} ({}, {}) | `{}` | {} | {} | {} |\n",
            r.launch, r.kernel, r.args.0, r.args.1, r.metric, r.measured, r.emulated, mark
        ));
    }
    s
}
