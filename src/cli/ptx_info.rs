//! `warplight kernels` and `warplight check`.

use std::path::Path;

/// Lists kernels with parameters and resources.
pub fn kernels(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let prog = crate::ptx::load_file(path)?;
    println!("{} (PTX {}, target {})", prog.source_name, prog.version, prog.target.join(","));
    for (k, f) in prog.functions.iter().enumerate().filter(|(_, f)| f.is_entry) {
        let params: Vec<String> = f.params.iter().map(|p| format!(".{} {}", p.ty, p.name)).collect();
        println!("  {}({})", f.name, params.join(", "));
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

/// Validates a PTX file.
pub fn check(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let prog = crate::ptx::load_file(path)?;
    let n: usize = prog.functions.iter().map(|f| f.insts.len()).sum();
    println!(
        "{}: ok ({} kernels, {} functions, {n} instructions)",
        prog.source_name,
        prog.kernel_names().len(),
        prog.functions.len()
    );
    Ok(())
}
