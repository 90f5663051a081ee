//! The `warplight` binary; see `warplight --help`.

fn main() {
    quiet_broken_pipe();
    std::process::exit(warplight::cli::main());
}

/// Ends the process quietly, as C tools do on SIGPIPE (status 141), when the
/// reader of stdout goes away (`warplight step ... | head`): Rust ignores
/// SIGPIPE, so `println!` would otherwise panic with a backtrace.
fn quiet_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.starts_with("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}
