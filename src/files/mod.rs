//! Writing output files: through a temporary file beside the output, renamed
//! when complete ([`write_atomically`]), so that neither a failure nor a
//! signal ([`interrupt`]) leaves a partial file under the final name. Below
//! both the command line (`crate::cli`) and the reproductions
//! (`crate::repro`), which write their charts and summaries through it.

pub mod interrupt;

/// Writes `bytes` to `file` through a temporary file beside it
/// ([`interrupt::Temporary`]), so that neither a failure nor a signal ever
/// leaves a partial file under the final name, or the temporary file.
pub fn write_atomically(file: &std::path::Path, bytes: &[u8]) -> Result<(), String> {
    let err = |e: std::io::Error| format!("{}: {e}", file.display());
    let mut tmp = interrupt::Temporary::create(file).map_err(err)?;
    // on failure the temporary file goes too (dropped): nothing half-written is left
    tmp.write_all(bytes).map_err(err)?;
    interrupt::commit(vec![(tmp, file)]).map_err(|(_, e)| err(e))
}
