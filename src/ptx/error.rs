//! Errors of the PTX front end: every one names the file, line and column
//! and, where there is one, the text of the offending line.

use std::fmt;

/// A position in a PTX source file (1-based line and column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Pos {
    /// 1-based line number.
    pub line: u32,
    /// 1-based column number.
    pub col: u32,
}

impl fmt::Display for Pos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.col)
    }
}

/// What went wrong while reading a PTX module.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PtxErrorKind {
    /// A character or token the lexer cannot read.
    #[error("lexical error: {0}")]
    Lex(String),
    /// The token stream does not follow PTX syntax.
    #[error("syntax error: {0}")]
    Syntax(String),
    /// An instruction (or modifier combination) warplight does not execute.
    #[error("unsupported instruction `{0}`")]
    Unsupported(String),
    /// A directive warplight does not understand.
    #[error("unsupported directive `{0}`")]
    UnsupportedDirective(String),
    /// A well-formed module that breaks a PTX rule (unknown register, type mismatch...).
    #[error("invalid: {0}")]
    Invalid(String),
    /// Input past one of warplight's own bounds (see docs/limits.md).
    #[error("over a limit: {0}")]
    Limit(String),
}

/// A PTX front-end error with its location.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PtxError {
    /// The file name given when the module was read.
    pub file: String,
    /// Where the problem is.
    pub pos: Pos,
    /// The source line (trimmed), when known.
    pub line_text: Option<String>,
    /// What the problem is.
    pub kind: PtxErrorKind,
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

impl PtxError {
    /// The error `kind` at `pos` of the file `file` whose text is `src`
    /// (the line is quoted from it).
    pub fn at(file: &str, src: &str, pos: Pos, kind: PtxErrorKind) -> PtxError {
        PtxError {
            file: file.to_string(),
            pos,
            line_text: src.lines().nth(pos.line.saturating_sub(1) as usize).map(|l| shorten(l.trim())),
            kind,
        }
    }
}

impl fmt::Display for PtxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.file, self.pos, self.kind)?;
        if let Some(t) = &self.line_text {
            write!(f, "\n    | {t}")?;
        }
        Ok(())
    }
}

impl std::error::Error for PtxError {}

/// Result alias of the front end.
pub type PtxResult<T> = Result<T, PtxError>;
