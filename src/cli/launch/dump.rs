//! `launch --dump NAME=FILE`: the files are checked before anything runs and
//! written all or none — each under a temporary name beside it first, then
//! all renamed; a failure removes what was written, so a failed run leaves
//! neither a stray temporary file nor some of the dumps.

use std::path::{Path, PathBuf};

use crate::cli::interrupt::{Temporary, commit};

/// An error unless each file can be made: a file name, in an existing folder.
pub fn check_paths<'a>(files: impl IntoIterator<Item = &'a Path>) -> Result<(), String> {
    for f in files {
        if f.file_name().is_none() || f.is_dir() {
            return Err(format!("--dump {}: expected a file name", f.display()));
        }
        // the dump is written beside the file and renamed over it: that would
        // replace a device or a pipe (/dev/null) with a plain file
        if std::fs::symlink_metadata(f).is_ok_and(|m| !m.file_type().is_file()) {
            return Err(format!(
                "--dump {}: not a regular file (the dump replaces the file it names; give a path to a file)",
                f.display()
            ));
        }
        let parent = f.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if !parent.is_dir() {
            return Err(format!("--dump {}: the folder {} does not exist", f.display(), parent.display()));
        }
    }
    Ok(())
}

/// Writes every `(file, bytes)`, or none of them: each under its temporary
/// name ([`crate::cli::interrupt::temporary_name`]), then all renamed.
pub fn write_all(files: &[(PathBuf, Vec<u8>)]) -> Result<(), String> {
    let mut written: Vec<(Temporary, &Path)> = Vec::new();
    for (file, bytes) in files {
        // on an error the temporaries written so far are dropped, which removes them
        let mut t = Temporary::create(file).map_err(|e| format!("{}: {e}", file.display()))?;
        t.write_all(bytes).map_err(|e| format!("{}: {e}", file.display()))?;
        written.push((t, file));
    }
    // the files renamed before a failing one are complete dumps of this run; the rest are removed
    commit(written).map_err(|(f, e)| format!("{}: {e}", f.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_or_none() {
        let d = std::env::temp_dir().join(format!("warplight-dump-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let (a, b) = (d.join("a.bin"), d.join("b.bin"));
        write_all(&[(a.clone(), vec![1, 2]), (b.clone(), vec![3])]).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), [1, 2]);
        assert_eq!(std::fs::read(&b).unwrap(), [3]);
        std::fs::remove_file(&a).unwrap();
        // the second file cannot be written (its name is a folder): neither is left, nor a temporary
        std::fs::create_dir_all(d.join("dir.bin")).unwrap();
        std::fs::create_dir_all(crate::cli::interrupt::temporary_name(&d.join("dir.bin"))).unwrap();
        let r = write_all(&[(a.clone(), vec![1]), (d.join("dir.bin"), vec![2])]);
        assert!(r.is_err());
        assert!(!a.exists() && !crate::cli::interrupt::temporary_name(&a).exists());
        assert!(check_paths([d.join("x/y.bin").as_path()]).unwrap_err().contains("does not exist"));
        assert!(check_paths([d.join("dir.bin").as_path()]).unwrap_err().contains("expected a file name"));
        assert!(check_paths([a.as_path()]).is_ok());
        // a device is never replaced by a plain file
        assert!(check_paths([Path::new("/dev/null")]).unwrap_err().contains("not a regular file"));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
