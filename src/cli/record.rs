//! `--record DIR`: what a command does with its emulated devices, written
//! as a recording ([`crate::sim::recording`]) for `tools/device/replay.py`.

use std::path::{Path, PathBuf};

use crate::sim::recording;

/// An error unless `dir` can hold the recording: a folder, or nothing yet.
pub fn check(dir: &Path) -> Result<(), String> {
    if dir.exists() && !dir.is_dir() {
        return Err(format!("--record {}: not a folder", dir.display()));
    }
    Ok(())
}

/// Ends the recording and writes it into `dir` (made if missing; its files
/// all or none). An error when the command emulated nothing.
pub fn write(dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let rec = recording::finish().unwrap_or_default();
    if rec.launches() == 0 {
        return Err(format!(
            "--record {}: the command ran no emulated kernel, so there is nothing to record (a native variant?)",
            dir.display()
        )
        .into());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("--record {}: {e}", dir.display()))?;
    let what = std::env::args().collect::<Vec<_>>().join(" ");
    let files: Vec<(PathBuf, Vec<u8>)> = rec.files(&what).into_iter().map(|(n, b)| (dir.join(n), b)).collect();
    super::launch::dump::write_all(&files)?;
    let bytes: usize = files.iter().map(|f| f.1.len()).sum();
    // on stderr: stdout stays the command's own (`launch --json | jq`)
    eprintln!(
        "recorded {} device(s), {} launches, {:.1} MB into {} (replay: python3 tools/device/replay.py {})",
        rec.devices.len(),
        rec.launches(),
        bytes as f64 / 1e6,
        dir.display(),
        dir.display()
    );
    for (i, d) in rec.devices.iter().enumerate() {
        if let Some(why) = d.unreplayable() {
            eprintln!("note: device {i} cannot be replayed: {why}");
        }
    }
    Ok(())
}
