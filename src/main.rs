//! The `warplight` binary; see `warplight --help`.

fn main() {
    std::process::exit(warplight::cli::main());
}
