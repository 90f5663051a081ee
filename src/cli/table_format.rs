//! The tables' other output formats, made from their markdown: aligned
//! columns for a terminal, and CSV. Markdown stays the one place the tables are
//! laid out (`crate::repro`).

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

fn csv_cell(c: &str) -> String {
    if c.contains([',', '"', '\n']) { format!("\"{}\"", c.replace('"', "\"\"")) } else { c.to_string() }
}

/// Every markdown table's rows as CSV, each prefixed with its table's name (the
/// last line before it that starts with "Table", up to its colon); a table's
/// header row starts with `table`. Other lines are left out.
pub fn csv(md: &str) -> String {
    let mut out = String::new();
    let mut name = String::new();
    for line in md.lines() {
        match cells(line) {
            None => {
                if line.starts_with("Table") {
                    name = line.split(':').next().unwrap_or(line).to_string();
                }
            }
            Some(c) if is_rule(&c) => {}
            Some(c) => {
                let header = c.first().is_some_and(|x| *x == "Scene" || *x == "Setting");
                let first = if header { "table".to_string() } else { csv_cell(&name) };
                let rest: Vec<String> = c.iter().map(|x| csv_cell(x)).collect();
                out.push_str(&format!("{first},{}\n", rest.join(",")));
            }
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

    #[test]
    fn csv_names_each_row_s_table() {
        let c = csv(MD);
        assert_eq!(c, "table,Scene,stack,thesis\nTable 4.5,scene6,16.05,7.31\nTable 4.5,Average,,\"+1,2%\"\n");
    }
}
