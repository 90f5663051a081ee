//! Markdown tables as aligned columns for a terminal (`--format table`); CSV
//! comes from the tables themselves (`crate::repro::table::Table::csv`).

/// The cells of a markdown table row, or `None` for other lines.
fn cells(line: &str) -> Option<Vec<&str>> {
    let t = line.trim();
    if !t.starts_with('|') || !t.ends_with('|') || t.len() < 2 {
        return None;
    }
    Some(t[1..t.len() - 1].split('|').map(str::trim).collect())
}

/// A separator row (`|---|---|`).
fn is_rule(c: &[&str]) -> bool {
    c.iter().all(|x| !x.is_empty() && x.chars().all(|ch| ch == '-' || ch == ':'))
}

/// Markdown tables as aligned columns (the first column left-aligned, the
/// others right-aligned); other lines unchanged.
pub fn terminal(md: &str) -> String {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < lines.len() {
        if cells(lines[i]).is_none() {
            out.push_str(lines[i]);
            out.push('\n');
            i += 1;
            continue;
        }
        let mut rows = Vec::new();
        while i < lines.len()
            && let Some(c) = cells(lines[i])
        {
            rows.push(c);
            i += 1;
        }
        let n = rows.iter().map(Vec::len).max().unwrap_or(0);
        let mut width = vec![0usize; n];
        for r in rows.iter().filter(|r| !is_rule(r)) {
            for (k, c) in r.iter().enumerate() {
                width[k] = width[k].max(c.chars().count());
            }
        }
        for r in &rows {
            let line: Vec<String> = if is_rule(r) {
                width.iter().map(|w| "-".repeat(*w)).collect()
            } else {
                (0..n)
                    .map(|k| {
                        let c = r.get(k).copied().unwrap_or("");
                        if k == 0 { format!("{c:<w$}", w = width[k]) } else { format!("{c:>w$}", w = width[k]) }
                    })
                    .collect()
            };
            out.push_str(line.join("  ").trim_end());
            out.push('\n');
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const MD: &str = "Table 4.5: nodes per ray\n\n| Scene | stack | thesis |\n|---|---|---|\n| scene6 | 16.05 | 7.31 |\n| Average | | +1,2% |\n\nOurs: a note.\n";

    #[test]
    fn terminal_aligns_columns() {
        let t = terminal(MD);
        assert!(t.contains("Scene    stack  thesis\n-------  -----  ------\nscene6   16.05    7.31\n"), "{t}");
        assert!(t.contains("Ours: a note."));
    }
}
