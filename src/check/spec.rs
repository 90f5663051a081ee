//! Running a launch spec's launches with the checker beside the counter model.

use super::{CheckOptions, Report, launch_checked};
use crate::launch_spec::{LaunchResult, Prepared, Spec, SpecError, arguments};
use crate::model::{Model, Profile, occupancy};
use crate::sim::{Device, LaunchConfig, SimError};

/// What a checked spec run produced: the finished launches' results, the
/// reports (with the launch index), and the error that stopped it, if any.
pub struct CheckedRun {
    /// Results of the launches that finished.
    pub results: Vec<LaunchResult>,
    /// (launch index, report).
    pub reports: Vec<(usize, Report)>,
    /// What stopped the run (a fault, after its report).
    pub error: Option<SpecError>,
}

/// Runs every launch of the spec in order under `profile`, checked.
pub fn run(spec: &Spec, dev: &mut Device, p: &Prepared, profile: Profile, opts: &CheckOptions) -> CheckedRun {
    let mut out = CheckedRun { results: Vec::new(), reports: Vec::new(), error: None };
    for (i, l) in spec.launches.iter().enumerate() {
        let args = match arguments(spec, p, l) {
            Ok(a) => a,
            Err(e) => {
                out.error = Some(e);
                return out;
            }
        };
        let cfg = LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
        let model = Model::new(profile, &p.module.prog);
        let c = match launch_checked(dev, &p.module, &l.kernel, cfg, &args, opts, Some(&model)) {
            Ok(c) => c,
            Err(e) => {
                out.error = Some(e.into());
                return out;
            }
        };
        out.reports.extend(c.reports.into_iter().map(|r| (i, r)));
        match (c.stats, c.fault) {
            (Some(stats), _) => {
                let k = p.module.prog.kernel(&l.kernel).expect("checked by arguments()");
                let threads = l.block.iter().product();
                out.results.push(LaunchResult {
                    stats,
                    memory: model.finish(),
                    occupancy: occupancy(profile, &p.module.prog, k, threads, l.shared),
                });
            }
            (None, Some(f)) => {
                out.error = Some(SimError::Fault(f).into());
                return out;
            }
            (None, None) => unreachable!("a launch either finishes or faults"),
        }
    }
    out
}
