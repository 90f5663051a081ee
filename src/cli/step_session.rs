//! The launch that `warplight step` and `warplight trace` step: the options
//! they share (the spec, which of its launches, the watchdog, the device
//! profile of the memory views, checking and the warp schedule) and the
//! [`Session`] they make of them.

use std::path::PathBuf;

use crate::model::Profile;
use crate::teach::session::Session;

/// The stepped launch's options, shared by `step` and `trace`.
#[derive(Debug, clap::Args)]
pub struct SessionArgs {
    /// The launch spec (TOML); `examples/…` is found from any directory.
    pub spec: PathBuf,
    /// Which of the spec's launches is stepped, from 1; those before it run first.
    #[arg(long, default_value_t = 1)]
    pub launch: usize,
    /// The watchdog: stop a launch as a runaway after this many warp instructions
    /// (default: the spec's `max_instructions`, else 2^32). See docs/limits.md.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_instructions: Option<u64>,
    /// Device profile: gt200, maxwell or hopper (default: the spec's `device`,
    /// else hopper). It sets the memory views' transactions, sectors and banks,
    /// and the arithmetic of the stepped launch and of the `--check` run before
    /// it: FMA contraction and the SFU model, so register values can differ
    /// between profiles.
    #[arg(long)]
    pub device: Option<String>,
    /// Checking (`--check`, `--uninit`; the reports come first, on stderr) and
    /// the warp schedule of the stepped launch (`--schedule random --seed N`).
    #[command(flatten)]
    pub checks: crate::check::cli::CheckArgs,
}

impl SessionArgs {
    /// Loads the spec (the checkout's or `$WARPLIGHT_HOME`'s `examples/…` when
    /// not here), runs the checks asked for, and returns the session to step
    /// with the profile of its memory views.
    pub fn open(&self) -> Result<(Session, Profile), Box<dyn std::error::Error>> {
        let mut session = Session::load_launch(&crate::host::scene_file::data_file(&self.spec), self.launch)?;
        session.max_instructions = self.max_instructions;
        session.random_seed = self.checks.random_seed();
        let profile = profile(&session, self.device.as_deref())?;
        session.device = Some(profile);
        crate::check::cli::check_before_stepping(
            &session.spec,
            session.launch,
            &self.checks,
            self.max_instructions,
            profile,
        )?;
        Ok((session, profile))
    }
}

/// The profile of `--device`, else of the spec's `device`, else hopper.
pub fn profile(session: &Session, device: Option<&str>) -> Result<Profile, Box<dyn std::error::Error>> {
    match device {
        Some(d) => Ok(Profile::parse(d).ok_or_else(|| format!("--device {d}: expected gt200, maxwell or hopper"))?),
        None => session.spec_profile(),
    }
}
