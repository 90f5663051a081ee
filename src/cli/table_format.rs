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

/// The width `--format table` fits its output to.
pub const WIDTH: usize = 120;

/// Markdown tables as aligned columns (the first column left-aligned, the
/// others right-aligned), split into blocks of columns that fit `width` (the
/// first column repeated in each; a `thesis` column stays with the column
/// before it); other lines wrapped at `width` on spaces.
pub fn terminal(md: &str, width: usize) -> String {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < lines.len() {
        if cells(lines[i]).is_none() {
            out.push_str(&wrap(lines[i], width));
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
        out.push_str(&aligned(&rows, width));
    }
    out
}

/// One table's rows, aligned and split into blocks of columns that fit `width`.
fn aligned(rows: &[Vec<&str>], width: usize) -> String {
    let n = rows.iter().map(Vec::len).max().unwrap_or(0);
    let mut w = vec![0usize; n];
    for r in rows.iter().filter(|r| !is_rule(r)) {
        for (k, c) in r.iter().enumerate() {
            w[k] = w[k].max(c.chars().count());
        }
    }
    // groups of columns after the first: a "thesis" column joins the one before it
    let header = rows.first().cloned().unwrap_or_default();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for k in 1..n {
        match groups.last_mut() {
            Some(g) if header.get(k).is_some_and(|h| *h == "thesis") => g.push(k),
            _ => groups.push(vec![k]),
        }
    }
    let gw = |g: &Vec<usize>| g.iter().map(|k| w[*k] + 2).sum::<usize>();
    let mut blocks: Vec<Vec<usize>> = Vec::new();
    let mut cur: Vec<usize> = Vec::new();
    let mut used = w.first().copied().unwrap_or(0);
    for g in groups {
        if !cur.is_empty() && used + gw(&g) > width {
            blocks.push(std::mem::take(&mut cur));
            used = w.first().copied().unwrap_or(0);
        }
        used += gw(&g);
        cur.extend(g);
    }
    if !cur.is_empty() || blocks.is_empty() {
        blocks.push(cur);
    }
    let mut out = String::new();
    for (b, cols) in blocks.iter().enumerate() {
        if b > 0 {
            out.push('\n');
        }
        let cols: Vec<usize> = std::iter::once(0).chain(cols.iter().copied()).filter(|k| *k < n).collect();
        for r in rows {
            let line: Vec<String> = cols
                .iter()
                .map(|&k| {
                    if is_rule(r) {
                        "-".repeat(w[k])
                    } else {
                        let c = r.get(k).copied().unwrap_or("");
                        if k == 0 { format!("{c:<x$}", x = w[k]) } else { format!("{c:>x$}", x = w[k]) }
                    }
                })
                .collect();
            out.push_str(line.join("  ").trim_end());
            out.push('\n');
        }
    }
    out
}

/// `line` wrapped at `width` on spaces (a word longer than the width stays whole).
fn wrap(line: &str, width: usize) -> String {
    let mut out = String::new();
    let mut cur = String::new();
    for word in line.split(' ') {
        if !cur.is_empty() && cur.chars().count() + 1 + word.chars().count() > width {
            out.push_str(&cur);
            out.push('\n');
            cur.clear();
        } else if !cur.is_empty() {
            cur.push(' ');
        }
        cur.push_str(word);
    }
    out.push_str(&cur);
    out.push('\n');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const MD: &str = "Table 4.5: nodes per ray\n\n| Scene | stack | thesis |\n|---|---|---|\n| scene6 | 16.05 | 7.31 |\n| Average | | +1,2% |\n\nOurs: a note.\n";

    #[test]
    fn terminal_aligns_columns() {
        let t = terminal(MD, WIDTH);
        assert!(t.contains("Scene    stack  thesis\n-------  -----  ------\nscene6   16.05    7.31\n"), "{t}");
        assert!(t.contains("Ours: a note."));
    }

    #[test]
    fn wide_tables_split_into_blocks_that_fit() {
        let md = "| Scene | aaaaaaaaaa | thesis | bbbbbbbbbb | thesis | cccccccccc | thesis |\n|---|---|---|---|---|---|---|\n| scene6 | 1 | 2 | 3 | 4 | 5 | 6 |\n\none two three four five six seven eight nine\n";
        let t = terminal(md, 40);
        assert!(t.lines().all(|l| l.chars().count() <= 40), "{t}");
        // every block repeats the scene column and keeps each column with its thesis column
        assert_eq!(t.matches("Scene").count(), 3, "{t}");
        assert!(t.contains("Scene   aaaaaaaaaa  thesis\n"), "{t}");
        assert!(t.contains("scene6           5       6\n"), "{t}");
        // long lines wrap on spaces
        assert!(t.contains("one two three four five six seven eight\nnine\n"), "{t}");
    }
}
