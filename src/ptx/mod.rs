//! The PTX front end: text → tokens ([`lexer`]) → syntax tree ([`parser`],
//! [`ast`]) → validated IR ([`lower`], [`ir`]). It knows nothing of execution.
//!
//! ```
//! let src = ".version 7.8\n.target sm_90\n.address_size 64\n\
//!            .visible .entry k(.param .u64 p)\n{\n ret;\n}\n";
//! let prog = warplight::ptx::load(src, "k.ptx").unwrap();
//! assert_eq!(prog.kernel_names(), vec!["k"]);
//! ```

pub mod ast;
pub mod error;
pub mod ir;
pub mod ir_text;
pub mod lexer;
pub mod lower;
pub mod parser;
pub mod types;

pub use error::{Pos, PtxError, PtxErrorKind, PtxResult};
pub use ir::Program;

/// Parses and validates PTX source text. `name` is used in error messages.
///
/// A kernel that needs an instruction warplight does not execute (or calls a
/// function that does) does not stop the module from loading: it is marked
/// ([`ir::Function::unsupported`], [`Program::kernel_error`]) and fails when
/// launched. A module none of whose kernels can run is an error.
pub fn load(src: &str, name: &str) -> PtxResult<Program> {
    let wrap = |(pos, kind): (Pos, PtxErrorKind)| PtxError::at(name, src, pos, kind);
    let toks = lexer::lex(src).map_err(wrap)?;
    let module = parser::parse(&toks).map_err(wrap)?;
    lower::lower(&module, name, src).map_err(wrap)
}

/// Reads a PTX file and loads it.
pub fn load_file(path: &std::path::Path) -> PtxResult<Program> {
    let name = path.display().to_string();
    let src = std::fs::read_to_string(path).map_err(|e| PtxError {
        file: name.clone(),
        pos: Pos::default(),
        line_text: None,
        kind: PtxErrorKind::Invalid(format!("cannot read file: {e}")),
    })?;
    load(&src, &name)
}
