//! Which line of the *user's* source an instruction belongs to.
//!
//! A kernel's PTX carries `.loc` lines of three kinds: the user's own file
//! (the `.cu` being taught or measured), library headers whose code the
//! compiler inlined (clang's `__clang_cuda_builtin_vars.h` for `threadIdx.x`,
//! the project's `prelude.h` for `atomicAdd` or `__shfl_down_sync`, the CUDA
//! SDK's `*.hpp` for nvcc) and line 0 (instructions the compiler made up).
//! The views stay on the user's file, and `--per-line` charges inlined library
//! code to the user's line that called it.
//!
//! Neither clang-16 nor nvcc writes `inlined_at` into PTX line tables, so the
//! calling line is found the way the code is laid out: inlined code follows
//! the `.loc` of its call site, so an instruction from a library file belongs
//! to the nearest user line before it in its function (after it, when none
//! comes before).

use std::collections::BTreeMap;

use crate::ptx::Program;
use crate::ptx::ir::SrcLoc;
use crate::sim::LaunchStats;
use crate::sim::counters::{InstCountsSer, LineCounts};

/// Whether a `.file` path names library code rather than the user's kernel:
/// a header (`.h`, `.hpp`, `.cuh`, `.inl`, or a name without extension as in
/// the C++ standard library), or anything under a compiler's `include`
/// folder.
pub fn is_library(path: &str) -> bool {
    let name = path.rsplit('/').next().unwrap_or(path);
    let header = match name.rsplit_once('.') {
        Some((_, ext)) => matches!(ext, "h" | "hpp" | "hh" | "hxx" | "cuh" | "inl" | "inc"),
        None => true,
    };
    header || path.contains("/include/") || path.starts_with("include/")
}

/// The user's location of `s` when it is one already: a line > 0 of a file
/// that is not library code.
pub fn user_loc(prog: &Program, s: Option<SrcLoc>) -> Option<SrcLoc> {
    s.filter(|s| s.line > 0 && prog.files.get(s.file as usize).is_some_and(|p| !is_library(p)))
}

/// For every function and instruction (`[function][pc]`), the user line it is
/// charged to: its own line when that is a user line; for an instruction from
/// a library file, the nearest user line before it in the function (else
/// after it). Line-0 instructions and those without `.loc` keep their own
/// location (`None` without one): the compiler made them for no line.
pub fn attribute(prog: &Program) -> Vec<Vec<Option<SrcLoc>>> {
    prog.functions
        .iter()
        .map(|f| {
            let own: Vec<Option<SrcLoc>> = f.info.iter().map(|i| user_loc(prog, i.src)).collect();
            let mut out = Vec::with_capacity(own.len());
            let mut before: Option<SrcLoc> = None;
            for (pc, i) in f.info.iter().enumerate() {
                if own[pc].is_some() {
                    before = own[pc];
                    out.push(own[pc]);
                    continue;
                }
                let from_library = i.src.is_some_and(|s| s.line > 0);
                if from_library {
                    out.push(before.or_else(|| own[pc..].iter().find_map(|x| *x)).or(i.src));
                } else {
                    out.push(i.src);
                }
            }
            out
        })
        .collect()
}

/// A launch's counts per user source line, library code charged to its
/// calling line ([`attribute`]); instructions without `.loc` are left out.
pub fn per_user_line(stats: &LaunchStats, prog: &Program) -> Vec<LineCounts> {
    let user = attribute(prog);
    let mut map: BTreeMap<(String, u32), InstCountsSer> = BTreeMap::new();
    for (f, counts) in stats.profile.per_fn.iter().enumerate() {
        for (pc, c) in counts.iter().enumerate() {
            let Some(s) = user.get(f).and_then(|u| u.get(pc)).copied().flatten() else { continue };
            if c.warp == 0 {
                continue;
            }
            let e = map.entry((prog.files.get(s.file as usize).cloned().unwrap_or_default(), s.line)).or_default();
            e.warp_instructions += c.warp;
            e.thread_instructions += c.thread;
            e.thread_instructions_pred_on += c.pred_on;
            e.divergent_branches += c.divergent;
        }
    }
    map.into_iter().map(|((file, line), counts)| LineCounts { file, line, counts }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_and_compiler_include_folders_are_library_code() {
        for lib in [
            "/usr/lib/llvm-16/lib/clang/16/include/__clang_cuda_builtin_vars.h",
            "clang/include/__clang_cuda_builtin_vars.h",
            "./kernels/prelude.h",
            "cuda/include/sm_30_intrinsics.hpp",
            "/usr/include/c++/12/cmath",
        ] {
            assert!(is_library(lib), "{lib}");
        }
        for user in ["./kernels/lessons/votes.cu", "kernel.cu", "/home/me/k.cu"] {
            assert!(!is_library(user), "{user}");
        }
    }

    #[test]
    fn inlined_prelude_code_is_charged_to_the_calling_line() {
        let root = env!("CARGO_MANIFEST_DIR");
        let prog = crate::ptx::load_file(&std::path::Path::new(root).join("kernels/lessons/votes.ptx")).unwrap();
        let prelude = prog.files.iter().position(|f| f.ends_with("prelude.h")).unwrap() as u32;
        let f = &prog.functions[0];
        let a = attribute(&prog);
        let mut seen = 0;
        for (pc, i) in f.info.iter().enumerate() {
            if i.src.is_some_and(|s| s.file == prelude) {
                seen += 1;
                let to = a[0][pc].expect("charged to a line");
                assert_ne!(to.file, prelude);
                // __ballot_sync on line 10, __shfl_down_sync on line 12
                assert!([10, 12].contains(&to.line), "PTX line {} charged to {}", i.ptx_line, to.line);
            }
        }
        assert!(seen >= 5, "votes.cu calls the prelude's shuffle and ballot");
    }
}
