//! A launch that can be stepped from the start as often as needed. Stepping
//! is deterministic, so going back to step *n* is running a fresh copy of the
//! launch (new device memory, same spec) for *n* steps: that is how the
//! terminal view steps back.

use std::path::{Path, PathBuf};

use crate::launch_spec::{self, Spec};
use crate::sim::access_log::AccessLog;
use crate::sim::stepper::Stepper;
use crate::sim::{Device, LaunchConfig};

/// A launch spec, ready to be stepped.
pub struct Session {
    /// The spec.
    pub spec: Spec,
    /// Its first launch's kernel name.
    pub kernel: String,
}

/// Errors of the teaching views.
pub type Error = Box<dyn std::error::Error>;

impl Session {
    /// Loads a spec; its first launch is the one stepped.
    pub fn load(path: &Path) -> Result<Session, Error> {
        let spec = Spec::load(path)?;
        let kernel = spec.launches.first().ok_or("the spec has no launch")?.kernel.clone();
        Ok(Session { spec, kernel })
    }

    /// The PTX file.
    pub fn ptx_path(&self) -> PathBuf {
        self.spec.ptx.clone()
    }

    /// Runs `f` on a fresh stepper at the start of the launch (fresh buffers),
    /// recording memory accesses.
    pub fn with_stepper<R>(&self, f: impl FnOnce(&mut Stepper) -> Result<R, Error>) -> Result<R, Error> {
        let mut dev = Device::new();
        let prepared = launch_spec::prepare(&self.spec, &mut dev)?;
        let l = &self.spec.launches[0];
        let args = launch_spec::arguments(&self.spec, &prepared, l)?;
        let cfg = LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
        let log = AccessLog::new();
        let mut st = dev.stepper_logged(&prepared.module, &l.kernel, cfg, &args, &log)?;
        f(&mut st)
    }
}
