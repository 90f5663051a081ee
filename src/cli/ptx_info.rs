//! `warplight kernels` and `warplight check`.

use std::path::Path;

/// Lists kernels with parameters and resources.
pub fn kernels(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let prog = crate::ptx::load_file(path)?;
    println!("{} (PTX {}, target {})", prog.source_name, prog.version, prog.target.join(","));
    for (k, f) in prog.functions.iter().enumerate().filter(|(_, f)| f.is_entry) {
        let params: Vec<String> = f.params.iter().map(|p| format!(".{} {}", p.ty, p.name)).collect();
        println!("  {}({})", f.name, params.join(", "));
        if let Some(e) = &f.unsupported {
            println!("    unusable{}: {e}", through(&prog, k as u32));
            continue;
        }
        println!(
            "    {} instructions, {} registers (32-bit words declared), {} B local per thread, {} B static shared ({} B in the module layout)",
            f.insts.len(),
            f.declared_reg_words,
            f.local_size,
            prog.kernel_shared_size(k as u32),
            prog.static_shared_size
        );
    }
    let funcs: Vec<&str> = prog.functions.iter().filter(|f| !f.is_entry).map(|f| f.name.as_str()).collect();
    if !funcs.is_empty() {
        println!("  device functions: {}", funcs.join(", "));
    }
    Ok(())
}

/// Validates a PTX file: an error when a kernel cannot run (each such kernel
/// is named with the instruction it needs).
pub fn check(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let prog = crate::ptx::load_file(path)?;
    let unusable: Vec<String> = prog
        .functions
        .iter()
        .enumerate()
        .filter(|(_, f)| f.is_entry)
        .filter_map(|(k, f)| {
            f.unsupported.as_ref().map(|e| format!("kernel `{}`{}: {e}", f.name, through(&prog, k as u32)))
        })
        .collect();
    if !unusable.is_empty() {
        return Err(format!(
            "{}: {} of {} kernels cannot run\n{}",
            prog.source_name,
            unusable.len(),
            prog.kernel_names().len(),
            unusable.join("\n")
        )
        .into());
    }
    let n: usize = prog.functions.iter().map(|f| f.insts.len()).sum();
    println!(
        "{}: ok ({} kernels, {} functions, {n} instructions)",
        prog.source_name,
        prog.kernel_names().len(),
        prog.functions.len()
    );
    Ok(())
}

/// ` (through `f`, which it calls)` when kernel `k` cannot run because of a
/// function it calls; empty otherwise.
fn through(prog: &crate::ptx::Program, k: u32) -> String {
    match prog.unsupported_in(k) {
        Some(f) if f != prog.functions[k as usize].name => format!(" (through `{f}`, which it calls)"),
        _ => String::new(),
    }
}
