//! Finding the CUDA source files a PTX module's `.file` directives name.
//! Paths in PTX are as the compiler saw them (relative to where it ran, or
//! absolute on another machine), so several places are tried, those relative
//! to the PTX file first.
//!
//! The names come from the PTX, which may be anyone's: only regular files of
//! at most [`MAX_SOURCE_BYTES`] are read (a `.file "/dev/zero"` or a FIFO is
//! skipped, not read until memory or patience runs out).

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::ptx::Program;

/// The largest source file read for a view or `--per-line` (4 MiB); larger
/// files are shown as not found.
pub const MAX_SOURCE_BYTES: u64 = 4 << 20;

/// The places tried for `file` named by the PTX at `ptx`: for a relative path,
/// `file` under the PTX's folder and each folder above it, then as given
/// (relative to the working directory); for an absolute path, the path itself;
/// then the file name beside the PTX.
pub fn candidates(ptx: &Path, file: &str) -> Vec<PathBuf> {
    let mut v = Vec::new();
    let dir = ptx.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if Path::new(file).is_absolute() {
        v.push(PathBuf::from(file));
    } else {
        let rel = file.trim_start_matches("./");
        for d in dir.ancestors().filter(|d| !d.as_os_str().is_empty()) {
            v.push(d.join(rel));
        }
        v.push(PathBuf::from(file));
    }
    if let Some(name) = Path::new(file).file_name() {
        v.push(dir.join(name));
    }
    v
}

/// The text of `path` if it is a regular file (symbolic links followed) of at
/// most [`MAX_SOURCE_BYTES`] holding UTF-8; `None` otherwise. Devices, FIFOs,
/// sockets and folders are never opened.
pub fn read_regular(path: &Path) -> Option<String> {
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_file() || meta.len() > MAX_SOURCE_BYTES {
        return None;
    }
    let f = std::fs::File::open(path).ok()?;
    // the file may have been replaced since: check the opened one again, and
    // never read more than the limit
    if !f.metadata().ok()?.is_file() {
        return None;
    }
    let mut s = String::new();
    f.take(MAX_SOURCE_BYTES + 1).read_to_string(&mut s).ok()?;
    (s.len() as u64 <= MAX_SOURCE_BYTES).then_some(s)
}

/// The lines of `file` named by the PTX at `ptx`, if any candidate can be read.
pub fn read(ptx: &Path, file: &str) -> Option<Vec<String>> {
    candidates(ptx, file).iter().find_map(|p| read_regular(p)).map(|s| s.lines().map(str::to_string).collect())
}

/// Every `.file` of `prog`, read where found, indexed like [`Program::files`]
/// (and so like [`SrcLoc::file`](crate::ptx::ir::SrcLoc)).
pub fn read_all(prog: &Program, ptx: &Path) -> Vec<Option<Vec<String>>> {
    prog.files.iter().map(|f| read(ptx, f)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_source_relative_to_an_ancestor_of_the_ptx() {
        let root = env!("CARGO_MANIFEST_DIR");
        let ptx = Path::new(root).join("kernels/tests/divergence.ptx");
        let lines = read(&ptx, "./kernels/tests/divergence.cu").expect("found");
        assert!(lines.iter().any(|l| l.contains("if_else")));
        let by_name = read(&ptx, "/elsewhere/kernels/tests/divergence.cu").expect("found by name");
        assert_eq!(lines, by_name);
        assert!(read(&ptx, "no_such_file.cu").is_none());
    }

    #[test]
    fn relative_paths_are_tried_beside_the_ptx_before_the_working_directory() {
        let c = candidates(Path::new("/repo/kernels/lessons/x.ptx"), "./kernels/lessons/x.cu");
        assert_eq!(c[0], Path::new("/repo/kernels/lessons/kernels/lessons/x.cu"));
        assert!(c.contains(&PathBuf::from("/repo/kernels/lessons/x.cu")));
        let repo = c.iter().position(|p| p == Path::new("/repo/kernels/lessons/x.cu")).unwrap();
        let cwd = c.iter().position(|p| p == Path::new("./kernels/lessons/x.cu")).unwrap();
        assert!(repo < cwd, "{c:?}");
    }

    #[test]
    fn devices_fifos_folders_and_huge_files_are_not_read() {
        assert!(read_regular(Path::new("/dev/zero")).is_none());
        assert!(read_regular(Path::new("/")).is_none());
        let dir = std::env::temp_dir().join(format!("warplight-sources-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("fifo.cu");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
        if made {
            // opening it would block until a writer comes: it must not be opened
            assert!(read_regular(&fifo).is_none());
        }
        let big = dir.join("big.cu");
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(MAX_SOURCE_BYTES + 1).unwrap();
        assert!(read_regular(&big).is_none());
        let small = dir.join("small.cu");
        std::fs::write(&small, "int x;\n").unwrap();
        assert_eq!(read_regular(&small).as_deref(), Some("int x;\n"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
