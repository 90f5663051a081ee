//! `warplight launch --print NAME[:RANGE]`: a result buffer's elements,
//! printed after every launch succeeded.

use crate::launch_spec::{BufferSpec, ElemType};

/// Most elements printed when no range is given.
pub const DEFAULT_ELEMENTS: usize = 256;

/// One `--print` request, checked against the spec's buffers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PrintRequest {
    /// The buffer.
    pub name: String,
    /// First element.
    pub first: usize,
    /// One past the last element.
    pub end: usize,
    /// Whether the buffer was cut at [`DEFAULT_ELEMENTS`] for want of a range.
    pub cut: bool,
}

/// Parses `NAME`, `NAME:I`, `NAME:A..B`, `NAME:A..` or `NAME:..B` (element
/// indices, B exclusive) against `buffers`.
pub fn parse(arg: &str, buffers: &[BufferSpec]) -> Result<PrintRequest, String> {
    let (name, range) = match arg.split_once(':') {
        Some((n, r)) => (n, Some(r)),
        None => (arg, None),
    };
    let Some(b) = buffers.iter().find(|b| b.name == name) else {
        let names: Vec<&str> = buffers.iter().map(|b| b.name.as_str()).collect();
        return Err(format!("--print {arg}: the spec has no buffer `{name}` (buffers: {})", names.join(", ")));
    };
    let num = |s: &str| {
        s.trim().parse::<usize>().map_err(|_| format!("--print {arg}: expected NAME[:I | :A..B], e.g. {name}:0..16"))
    };
    let (first, end, cut) = match range {
        None => (0, b.len.min(DEFAULT_ELEMENTS), b.len > DEFAULT_ELEMENTS),
        Some(r) => match r.split_once("..") {
            None => {
                let i = num(r)?;
                (i, i.saturating_add(1), false)
            }
            Some((a, e)) => {
                let a = if a.is_empty() { 0 } else { num(a)? };
                let e = if e.is_empty() { b.len } else { num(e)? };
                (a, e, false)
            }
        },
    };
    if first >= end || end > b.len {
        return Err(format!("--print {arg}: elements {first}..{end} are not within `{name}` (0..{})", b.len));
    }
    Ok(PrintRequest { name: name.to_string(), first, end, cut })
}

/// The elements `bytes` (of type `ty`, the first being element `first`) as
/// lines of 8, each led by its first index.
pub fn lines(ty: ElemType, first: usize, bytes: &[u8]) -> Vec<String> {
    let values: Vec<String> = bytes.chunks(ty.size()).map(|c| ty.show(c)).collect();
    let w = values.iter().map(|v| v.len()).max().unwrap_or(1).max(6);
    let iw = (first + values.len()).to_string().len();
    values
        .chunks(8)
        .enumerate()
        .map(|(i, row)| {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:>w$}")).collect();
            format!("  [{:>iw$}] {}", first + i * 8, cells.join(" "))
        })
        .collect()
}

/// The elements as JSON values (numbers).
pub fn json(ty: ElemType, bytes: &[u8]) -> Vec<serde_json::Value> {
    bytes
        .chunks(ty.size())
        .map(|c| {
            let s = ty.show(c);
            serde_json::from_str::<serde_json::Value>(&s).unwrap_or(serde_json::Value::String(s))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::launch_spec::Init;

    fn bufs() -> Vec<BufferSpec> {
        vec![BufferSpec { name: "out".into(), ty: ElemType::I32, len: 300, init: Init::Zeros }]
    }

    #[test]
    fn ranges_are_checked_against_the_buffer() {
        let r = parse("out", &bufs()).unwrap();
        assert_eq!((r.first, r.end, r.cut), (0, DEFAULT_ELEMENTS, true));
        assert_eq!(parse("out:5", &bufs()).unwrap().end, 6);
        let r = parse("out:10..", &bufs()).unwrap();
        assert_eq!((r.first, r.end), (10, 300));
        assert_eq!(parse("out:..4", &bufs()).unwrap().end, 4);
        assert!(parse("out:299..301", &bufs()).unwrap_err().contains("not within `out` (0..300)"));
        assert!(parse("in", &bufs()).unwrap_err().contains("no buffer `in` (buffers: out)"));
        assert!(parse("out:x", &bufs()).unwrap_err().contains("expected NAME"));
    }

    #[test]
    fn elements_print_in_rows_of_eight_with_their_index() {
        let bytes: Vec<u8> = (0..10i32).map(|i| i - 3).flat_map(|i| i.to_le_bytes()).collect();
        let l = lines(ElemType::I32, 4, &bytes);
        assert_eq!(l.len(), 2);
        assert!(l[0].starts_with("  [ 4]") && l[0].contains("    -3") && l[0].ends_with("     4"), "{l:?}");
        assert!(l[1].starts_with("  [12]"), "{l:?}");
        assert_eq!(json(ElemType::I32, &bytes[..8]), [serde_json::json!(-3), serde_json::json!(-2)]);
    }
}
