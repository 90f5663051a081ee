//! PTX text → tokens. Comments are dropped; every token keeps its position and
//! whether whitespace preceded it (PTX glues modifiers to opcodes: `ld.global.f32`).

use super::error::{Pos, PtxErrorKind};

/// One lexical token.
#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// An identifier: `ld`, `%r12`, `$L__BB0_2`, `_Z3fibi`.
    Ident(String),
    /// A dotted word: `.reg`, `.u32`, `.x`.
    Dot(String),
    /// An integer literal (its magnitude; a minus sign is its own token).
    Int(u64),
    /// A 32-bit float literal given as bits (`0f3F800000`).
    F32Bits(u32),
    /// A 64-bit float literal given as bits (`0d3FF0000000000000`).
    F64Bits(u64),
    /// A decimal float literal (`1.5`, `2e3`).
    Float(f64),
    /// A string literal, without its quotes.
    Str(String),
    /// One punctuation character: `{ } [ ] ( ) , ; : + - < > @ ! | =`.
    Punct(char),
}

/// A token with its position.
#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    /// The token.
    pub tok: Tok,
    /// Where it starts.
    pub pos: Pos,
    /// True when no whitespace or comment separates it from the previous token.
    pub glued: bool,
}

fn is_ident_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_' || c == b'$' || c == b'%'
}

fn is_ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// Splits PTX source text into tokens.
pub fn lex(src: &str) -> Result<Vec<Token>, (Pos, PtxErrorKind)> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let (mut i, mut line, mut line_start) = (0usize, 1u32, 0usize);
    let mut glued = false;
    while i < b.len() {
        let c = b[i];
        let pos = Pos { line, col: (i - line_start + 1) as u32 };
        if c == b'\n' {
            i += 1;
            line += 1;
            line_start = i;
            glued = false;
            continue;
        }
        if c.is_ascii_whitespace() {
            i += 1;
            glued = false;
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            glued = false;
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            loop {
                if i + 1 >= b.len() {
                    return Err((pos, PtxErrorKind::Lex("unterminated /* comment".into())));
                }
                if b[i] == b'\n' {
                    line += 1;
                    line_start = i + 1;
                }
                if b[i] == b'*' && b[i + 1] == b'/' {
                    i += 2;
                    break;
                }
                i += 1;
            }
            glued = false;
            continue;
        }
        let start = i;
        let tok = if is_ident_start(c) {
            i += 1;
            while i < b.len() && is_ident_char(b[i]) {
                i += 1;
            }
            Tok::Ident(src[start..i].to_string())
        } else if c == b'.' && i + 1 < b.len() && (is_ident_start(b[i + 1]) || b[i + 1].is_ascii_digit()) {
            i += 1;
            while i < b.len() && is_ident_char(b[i]) {
                i += 1;
            }
            // cache-hint modifiers such as `.L2::128B` keep their `::` parts
            while i + 2 < b.len() && b[i] == b':' && b[i + 1] == b':' && is_ident_char(b[i + 2]) {
                i += 2;
                while i < b.len() && is_ident_char(b[i]) {
                    i += 1;
                }
            }
            Tok::Dot(src[start + 1..i].to_string())
        } else if c.is_ascii_digit() {
            lex_number(src, &mut i).map_err(|m| (pos, PtxErrorKind::Lex(m)))?
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\n' {
                    return Err((pos, PtxErrorKind::Lex("unterminated string".into())));
                }
                i += 1;
            }
            if i >= b.len() {
                return Err((pos, PtxErrorKind::Lex("unterminated string".into())));
            }
            i += 1;
            Tok::Str(src[start + 1..i - 1].to_string())
        } else if b"{}[](),;:+-<>@!|=".contains(&c) {
            i += 1;
            Tok::Punct(c as char)
        } else {
            let ch = src[i..].chars().next().unwrap_or('?');
            return Err((pos, PtxErrorKind::Lex(format!("unexpected character {ch:?}"))));
        };
        out.push(Token { tok, pos, glued });
        glued = true;
    }
    Ok(out)
}

fn lex_number(src: &str, i: &mut usize) -> Result<Tok, String> {
    let b = src.as_bytes();
    let start = *i;
    let word_end = |mut j: usize| {
        while j < b.len() && (b[j].is_ascii_alphanumeric() || b[j] == b'_') {
            j += 1;
        }
        j
    };
    if b[start] == b'0' && start + 1 < b.len() {
        let p = b[start + 1];
        if p == b'f' || p == b'F' || p == b'd' || p == b'D' {
            let end = word_end(start + 2);
            let digits = &src[start + 2..end];
            *i = end;
            let is_f = p == b'f' || p == b'F';
            let want = if is_f { 8 } else { 16 };
            if digits.len() != want {
                return Err(format!("float literal `{}` needs {want} hex digits", &src[start..end]));
            }
            let v =
                u64::from_str_radix(digits, 16).map_err(|_| format!("bad hex float literal `{}`", &src[start..end]))?;
            return Ok(if is_f { Tok::F32Bits(v as u32) } else { Tok::F64Bits(v) });
        }
        if p == b'x' || p == b'X' {
            let end = word_end(start + 2);
            *i = end;
            let mut digits = &src[start + 2..end];
            if let Some(d) = digits.strip_suffix(['U', 'u']) {
                digits = d;
            }
            return u64::from_str_radix(digits, 16)
                .map(Tok::Int)
                .map_err(|_| format!("bad hex literal `{}`", &src[start..end]));
        }
        if p == b'b' || p == b'B' {
            let end = word_end(start + 2);
            *i = end;
            let mut digits = &src[start + 2..end];
            if let Some(d) = digits.strip_suffix(['U', 'u']) {
                digits = d;
            }
            return u64::from_str_radix(digits, 2)
                .map(Tok::Int)
                .map_err(|_| format!("bad binary literal `{}`", &src[start..end]));
        }
    }
    let mut j = start;
    while j < b.len() && b[j].is_ascii_digit() {
        j += 1;
    }
    let mut is_float = false;
    if j < b.len() && b[j] == b'.' && j + 1 < b.len() && b[j + 1].is_ascii_digit() {
        is_float = true;
        j += 1;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
    }
    if j < b.len() && (b[j] == b'e' || b[j] == b'E') {
        let mut k = j + 1;
        if k < b.len() && (b[k] == b'+' || b[k] == b'-') {
            k += 1;
        }
        if k < b.len() && b[k].is_ascii_digit() {
            is_float = true;
            j = k;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
        }
    }
    let text = &src[start..j];
    if is_float {
        *i = j;
        return text.parse::<f64>().map(Tok::Float).map_err(|_| format!("bad float literal `{text}`"));
    }
    let mut end = j;
    if end < b.len() && (b[end] == b'U' || b[end] == b'u') {
        end += 1;
    }
    *i = end;
    if text.len() > 1 && text.starts_with('0') {
        return u64::from_str_radix(&text[1..], 8).map(Tok::Int).map_err(|_| format!("bad octal literal `{text}`"));
    }
    text.parse::<u64>().map(Tok::Int).map_err(|_| format!("integer literal `{text}` out of range"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lexes_instruction_with_glued_modifiers() {
        let t = lex("ld.global.f32 %f1, [%rd2+-4]; // c\n").unwrap();
        let toks: Vec<_> = t.iter().map(|t| t.tok.clone()).collect();
        assert_eq!(toks[0], Tok::Ident("ld".into()));
        assert_eq!(toks[1], Tok::Dot("global".into()));
        assert!(t[1].glued && !t[3].glued);
        assert_eq!(toks[3], Tok::Ident("%f1".into()));
        assert!(toks.contains(&Tok::Int(4)));
    }

    #[test]
    fn lexes_float_literals() {
        let t = lex("0f3F800000 0d3FF0000000000000 1.5 0x10 017 2e3").unwrap();
        let toks: Vec<_> = t.into_iter().map(|t| t.tok).collect();
        assert_eq!(
            toks,
            vec![
                Tok::F32Bits(0x3F80_0000),
                Tok::F64Bits(0x3FF0_0000_0000_0000),
                Tok::Float(1.5),
                Tok::Int(16),
                Tok::Int(15),
                Tok::Float(2000.0)
            ]
        );
    }

    #[test]
    fn reports_position_of_bad_character() {
        let e = lex("add.s32 %r1,\n  %r2 # 3;").unwrap_err();
        assert_eq!(e.0, Pos { line: 2, col: 7 });
    }
}
