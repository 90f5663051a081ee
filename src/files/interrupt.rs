//! SIGINT, SIGTERM and SIGHUP: the command's temporary files are removed and
//! the process exits with the shell's conventional status, 128 + the signal's
//! number (130, 143, 129). Without this, a signal during the final write of an
//! image, a JSON or a dump would leave a `.NAME.warplight-tmp` file beside it.
//!
//! Output files are written through [`Temporary`]: a file created beside the
//! output under a temporary name and registered here, written through its open
//! handle, then renamed by [`commit`]. Creation with registration, renaming
//! with deregistration, and the handler's removal with the exit each hold one
//! lock, so the handler sees every temporary file that exists and none is
//! renamed after it started: a signal leaves either the complete output or
//! none, never a partial one, and no temporary file.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

/// The temporary files that exist now (created, not yet renamed or removed).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    // a panic elsewhere while the list was held leaves it consistent (each change is one push or retain)
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// The number of the first signal received (0: none), set by the signal
/// handler itself, synchronously, before the handler thread wakes: [`commit`]
/// checks it under the lock, so an output whose signal arrived before its
/// rename is never published even when the handler thread has not run yet.
static RECEIVED: OnceLock<Arc<AtomicUsize>> = OnceLock::new();

/// The signal received so far, if any.
fn received() -> Option<i32> {
    let n = RECEIVED.get()?.load(Ordering::SeqCst);
    (n != 0).then_some(n as i32)
}

/// The exit status of a process ended by `signal`, as shells report it.
pub fn exit_status(signal: i32) -> i32 {
    128 + signal
}

/// Starts a thread that waits for SIGINT, SIGTERM and SIGHUP; on the first, it
/// removes the temporary files and exits with [`exit_status`]. When the
/// handler cannot be installed, the signals keep their default action.
pub fn install() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let flag = RECEIVED.get_or_init(|| Arc::new(AtomicUsize::new(0)));
    for sig in [SIGINT, SIGTERM, SIGHUP] {
        // the action is one atomic store (async-signal-safe); without it, commit relies on the thread alone
        let _ = signal_hook::flag::register_usize(sig, Arc::clone(flag), sig as usize);
    }
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    // a thread that cannot start (the host is out of threads) is not worth failing the command for
    let _ = std::thread::Builder::new().name("signals".into()).spawn(move || {
        if let Some(sig) = signals.forever().next() {
            let held = pending();
            remove_all(&held);
            // the lock is held until the process ends: nothing is created or renamed any more
            std::process::exit(exit_status(sig));
        }
    });
}

/// Removes `files` (those that still exist).
fn remove_all(files: &[PathBuf]) {
    for f in files {
        let _ = std::fs::remove_file(f);
    }
}

/// The temporary name of `file` while it is written: `.NAME.warplight-tmp`
/// beside it (hidden, and distinct for `out.json` and `out.csv`).
pub fn temporary_name(file: &Path) -> PathBuf {
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    file.with_file_name(format!(".{name}.warplight-tmp"))
}

/// A temporary file being written: removed when dropped uncommitted, and by
/// the signal handler.
#[derive(Debug)]
pub struct Temporary {
    path: PathBuf,
    file: Option<File>,
    /// Renamed or removed by [`commit`]: nothing is left to clean.
    done: bool,
}

impl Temporary {
    /// Creates the temporary file for `output` ([`temporary_name`]), replacing
    /// one a killed run left; it is made new (never opened through an
    /// existing link or FIFO).
    pub fn create(output: &Path) -> std::io::Result<Temporary> {
        // the rename would replace a device, FIFO or socket (`-o /dev/null` run as root) with a plain file
        if std::fs::symlink_metadata(output).is_ok_and(|m| !m.file_type().is_file() && !m.file_type().is_symlink()) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file: the output is written beside it and renamed over it, which would replace it",
            ));
        }
        let path = temporary_name(output);
        let mut held = pending();
        if let Err(e) = std::fs::remove_file(&path)
            && e.kind() != std::io::ErrorKind::NotFound
        {
            return Err(e);
        }
        let file = std::fs::OpenOptions::new().write(true).create_new(true).open(&path)?;
        held.push(path.clone());
        Ok(Temporary { path, file: Some(file), done: false })
    }

    /// The temporary file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes `bytes` and flushes them to the file.
    pub fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        match &mut self.file {
            Some(f) => f.write_all(bytes).and_then(|_| f.flush()),
            None => Err(std::io::Error::other("the temporary file is closed")),
        }
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        self.file = None;
        if self.done {
            return;
        }
        let mut held = pending();
        if let Some(i) = held.iter().position(|p| *p == self.path) {
            let _ = std::fs::remove_file(&self.path);
            held.remove(i);
        }
    }
}

/// Renames each temporary file to its output, in order. On an error, the
/// outputs renamed before it are complete; the rest are removed, and the
/// output that failed is returned with the error.
pub fn commit(files: Vec<(Temporary, &Path)>) -> Result<(), (PathBuf, std::io::Error)> {
    let mut held = pending();
    if let Some(sig) = received() {
        // the signal came before the rename: the handler thread is about to
        // remove the temporaries and exit; do it here, holding the lock
        remove_all(&held);
        std::process::exit(exit_status(sig));
    }
    let mut failed = None;
    for (mut t, output) in files {
        t.file = None;
        if failed.is_none()
            && let Err(e) = std::fs::rename(&t.path, output)
        {
            failed = Some((output.to_path_buf(), e));
        }
        if failed.is_some() {
            let _ = std::fs::remove_file(&t.path);
        }
        held.retain(|p| *p != t.path);
        // dropped while the lock is held: Drop must not take it again
        t.done = true;
    }
    failed.map_or(Ok(()), Err)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("warplight-interrupt-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_device_is_never_an_output() {
        // `-o /dev/null` run as root would otherwise rename a plain file over the device
        let Err(e) = Temporary::create(Path::new("/dev/null")) else { panic!("a temporary for /dev/null") };
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("not a regular file"), "{e}");
        assert!(crate::files::write_atomically(Path::new("/dev/null"), b"x").is_err());
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    }

    #[test]
    fn a_committed_temporary_becomes_the_output_and_a_dropped_one_goes() {
        let d = dir("commit");
        let out = d.join("a.json");
        let mut t = Temporary::create(&out).unwrap();
        assert_eq!(t.path(), d.join(".a.json.warplight-tmp"));
        assert!(pending().contains(&t.path().to_path_buf()));
        t.write_all(b"{}").unwrap();
        commit(vec![(t, out.as_path())]).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"{}");
        assert!(!temporary_name(&out).exists());
        assert!(!pending().contains(&temporary_name(&out)));
        let t = Temporary::create(&d.join("b.png")).unwrap();
        let p = t.path().to_path_buf();
        assert!(p.exists());
        drop(t);
        assert!(!p.exists() && !pending().contains(&p));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_stale_temporary_is_replaced_not_followed() {
        let d = dir("stale");
        let out = d.join("c.png");
        let target = d.join("target");
        std::fs::write(&target, b"keep").unwrap();
        std::os::unix::fs::symlink(&target, temporary_name(&out)).unwrap();
        let mut t = Temporary::create(&out).unwrap();
        t.write_all(b"new").unwrap();
        commit(vec![(t, out.as_path())]).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"keep");
        assert_eq!(std::fs::read(&out).unwrap(), b"new");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failed_rename_removes_the_temporaries_after_it() {
        let d = dir("fail");
        let (a, b, c) = (d.join("a"), d.join("sub/b"), d.join("c"));
        let ta = Temporary::create(&a).unwrap();
        let tc = Temporary::create(&c).unwrap();
        // b's folder does not exist: its temporary is made in d, the rename fails
        let tb = Temporary::create(&d.join("b")).unwrap();
        let (pb, pc) = (tb.path().to_path_buf(), tc.path().to_path_buf());
        let (f, _) = commit(vec![(ta, a.as_path()), (tb, b.as_path()), (tc, c.as_path())]).unwrap_err();
        assert_eq!(f, b);
        assert!(a.exists() && !c.exists() && !pb.exists() && !pc.exists());
        assert!(!pending().iter().any(|p| p.starts_with(&d)));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn statuses_are_the_shells() {
        assert_eq!(exit_status(signal_hook::consts::SIGINT), 130);
        assert_eq!(exit_status(signal_hook::consts::SIGTERM), 143);
    }
}
