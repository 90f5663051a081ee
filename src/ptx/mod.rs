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
pub fn load(src: &str, name: &str) -> PtxResult<Program> {
    let wrap = |(pos, kind): (Pos, PtxErrorKind)| PtxError {
        file: name.to_string(),
        pos,
        line_text: src.lines().nth(pos.line.saturating_sub(1) as usize).map(|l| shorten(l.trim())),
        kind,
    };
    let toks = lexer::lex(src).map_err(wrap)?;
    let module = parser::parse(&toks).map_err(wrap)?;
    lower::lower(&module, name, src).map_err(wrap)
}

/// Most characters of a source line an error message quotes.
const QUOTED_LINE_CHARS: usize = 160;

/// `line`, cut to [`QUOTED_LINE_CHARS`] characters with `…` when longer.
fn shorten(line: &str) -> String {
    match line.char_indices().nth(QUOTED_LINE_CHARS) {
        Some((cut, _)) => format!("{}…", &line[..cut]),
        None => line.to_string(),
    }
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
