//! A launch that can be stepped from the start as often as needed. Stepping
//! is deterministic, so going back to step *n* is running a fresh copy of the
//! launch (new device memory, same spec) for *n* steps: that is how the
//! terminal view steps back.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::launch_spec::{self, BufferSpec, ElemType, Spec};
use crate::model::Profile;
use crate::sim::access_log::AccessLog;
use crate::sim::printf::PrintfRecord;
use crate::sim::stepper::Stepper;
use crate::sim::{Device, DevicePtr, LaunchConfig};

use super::printed::Printed;

/// A launch spec, ready to be stepped.
pub struct Session {
    /// The spec.
    pub spec: Spec,
    /// The launch stepped (index into `spec.launches`).
    pub launch: usize,
    /// Its kernel name.
    pub kernel: String,
    /// The watchdog (warp instructions per launch) over the spec's
    /// `max_instructions`, when given (`--max-instructions`).
    pub max_instructions: Option<u64>,
    /// The random warp schedule's seed (`--schedule random --seed N`): the
    /// stepped launch interleaves its warps as `launch --schedule random`
    /// does with that seed. `None`: the default schedule.
    pub random_seed: Option<u64>,
    /// The device profile over the spec's `device` (`--device`), when given:
    /// stepping runs with its arithmetic (FMA contraction, SFU model), as
    /// `launch` on that device does.
    pub device: Option<Profile>,
    /// The `printf` output of the stepped launch during the last stepping
    /// ([`Session::with_stepper`]), in the deterministic order.
    printf: std::sync::Mutex<Vec<PrintfRecord>>,
}

/// Errors of the teaching views.
pub type Error = Box<dyn std::error::Error>;

impl Session {
    /// Loads a spec; its first launch is the one stepped.
    pub fn load(path: &Path) -> Result<Session, Error> {
        Self::load_launch(path, 1)
    }

    /// Loads a spec to step its `n`-th launch (from 1). The launches before it
    /// run first, unobserved, on the same buffers, as `warplight launch` runs them.
    pub fn load_launch(path: &Path, n: usize) -> Result<Session, Error> {
        let spec = Spec::load(path)?;
        let count = spec.launches.len();
        if count == 0 {
            return Err("the spec has no launch".into());
        }
        if n == 0 || n > count {
            return Err(format!(
                "--launch {n}: the spec has {count} launch{} (1 to {count})",
                if count == 1 { "" } else { "es" }
            )
            .into());
        }
        let kernel = spec.launches[n - 1].kernel.clone();
        Ok(Session {
            spec,
            launch: n - 1,
            kernel,
            max_instructions: None,
            random_seed: None,
            device: None,
            printf: Default::default(),
        })
    }

    /// The stepped launch's spec.
    pub fn launch_spec(&self) -> &launch_spec::LaunchSpec {
        &self.spec.launches[self.launch]
    }

    /// The PTX file.
    pub fn ptx_path(&self) -> PathBuf {
        self.spec.ptx.clone()
    }

    /// The device profile of the spec (`device = ...`), else `hopper`; an
    /// unknown name is an error.
    pub fn spec_profile(&self) -> Result<Profile, Error> {
        let name = self.spec.device.as_deref().unwrap_or("hopper");
        Profile::parse(name).ok_or_else(|| {
            format!("{}: device `{name}`: expected gt200, maxwell or hopper", self.spec.file.display()).into()
        })
    }

    /// Runs `f` on a fresh stepper at the start of the launch (fresh buffers),
    /// recording memory accesses.
    pub fn with_stepper<R>(&self, f: impl FnOnce(&mut Stepper) -> Result<R, Error>) -> Result<R, Error> {
        self.with_stepping(|st, _, _| f(st))
    }

    /// As [`Session::with_stepper`], with the spec's buffers readable while stepping.
    pub fn with_stepper_and_buffers<R>(
        &self,
        f: impl FnOnce(&mut Stepper, &Buffers) -> Result<R, Error>,
    ) -> Result<R, Error> {
        self.with_stepping(|st, bufs, _| f(st, bufs))
    }

    /// As [`Session::with_stepper_and_buffers`], with each step's `printf`
    /// output handed out by [`Printed::take`] after the step.
    pub fn with_stepping<R>(
        &self,
        f: impl FnOnce(&mut Stepper, &Buffers, &Printed) -> Result<R, Error>,
    ) -> Result<R, Error> {
        let profile = match self.device {
            Some(p) => p,
            None => self.spec_profile()?,
        };
        let mut config = self.spec.sim_config(0, self.max_instructions, profile, None);
        config.schedule.random_seed = self.random_seed;
        let mut dev = Device::with_config(config);
        let prepared = launch_spec::prepare(&self.spec, &mut dev)?;
        let config =
            |l: &launch_spec::LaunchSpec| LaunchConfig { grid: l.grid, block: l.block, dynamic_shared: l.shared };
        for l in &self.spec.launches[..self.launch] {
            let args = launch_spec::arguments(&self.spec, &prepared, l)?;
            dev.launch(&prepared.module, &l.kernel, config(l), &args)?;
        }
        let l = self.launch_spec();
        let args = launch_spec::arguments(&self.spec, &prepared, l)?;
        let cfg = config(l);
        let log = AccessLog::new();
        let mut st = dev.stepper_logged(&prepared.module, &l.kernel, cfg, &args, &log)?;
        // the launches before it printed before it
        dev.take_printf();
        let buffers = Buffers { dev: &dev, list: &prepared.buffers, order: &self.spec.buffers };
        let printed = Printed::new(&dev);
        let r = f(&mut st, &buffers, &printed);
        *self.printf.lock().unwrap_or_else(|e| e.into_inner()) = printed.finish();
        r
    }

    /// The `printf` output of the stepped launch's instructions issued in the
    /// last stepping ([`Session::with_stepper`]: up to where the view or log
    /// stopped), in the order of `crate::sim::printf` (CTA, warp, call, lane).
    pub fn printf_output(&self) -> Vec<PrintfRecord> {
        self.printf.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

/// The spec's buffers in device memory, readable while a launch is stepped.
pub struct Buffers<'a> {
    dev: &'a Device,
    list: &'a BTreeMap<String, (DevicePtr, BufferSpec)>,
    order: &'a [BufferSpec],
}

impl Buffers<'_> {
    /// The buffers as the spec declares them, in its order.
    pub fn specs(&self) -> &[BufferSpec] {
        self.order
    }

    /// Elements `first..first + n` of buffer `name` (cut at its end), as
    /// little-endian bytes with the element type; `None` for an unknown name.
    pub fn read(&self, name: &str, first: usize, n: usize) -> Option<(ElemType, Vec<u8>)> {
        let (p, b) = self.list.get(name)?;
        let first = first.min(b.len);
        let n = n.min(b.len - first);
        let size = b.ty.size();
        let at = DevicePtr(p.0 + (first * size) as u64);
        let bytes = if n == 0 { Vec::new() } else { self.dev.try_read::<u8>(at, n * size).ok()? };
        Some((b.ty, bytes))
    }
}
