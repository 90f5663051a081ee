//! A reproduced table as data: columns with their units and tolerances, one
//! row per scene with our value, the thesis' value as printed and a verdict per
//! cell, the averages (ours, the thesis' as printed, the thesis' mean over the
//! scenes we ran), qualitative checks, notes and the score. Markdown, aligned
//! text and CSV are made from this one description.

use serde::Serialize;

use super::compare::{Printed, Tolerance, Verdict, mean_sd};

/// How a column's values are written.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Unit {
    /// A plain number with this many decimals.
    Number(usize),
    /// An integer count.
    Count,
    /// A relative change in percent, signed (`+12.3%`).
    Change,
    /// A percentage, unsigned (`97.2%`).
    Percent,
    /// A difference in percentage points, signed (`-1.6pp`).
    Points,
}

impl Unit {
    /// `v` written in this unit.
    pub fn format(&self, v: f64) -> String {
        if !v.is_finite() {
            return "–".into();
        }
        match *self {
            Unit::Number(d) => format!("{v:.d$}"),
            Unit::Count => format!("{}", v.round() as i64),
            Unit::Change => format!("{v:+.1}%"),
            Unit::Percent => format!("{v:.1}%"),
            Unit::Points => format!("{v:+.1}pp"),
        }
    }

    /// A standard deviation in this unit (unsigned).
    pub fn format_spread(&self, v: f64) -> String {
        match self {
            Unit::Change => format!("{v:.1}%"),
            Unit::Points => format!("{v:.1}pp"),
            other => other.format(v),
        }
    }

    /// Whether averages of this column are means of per-scene values (relative
    /// columns); absolute columns get no average, as in the theses.
    pub fn averaged(&self) -> bool {
        matches!(self, Unit::Change | Unit::Points)
    }
}

/// How one column was obtained.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Source {
    /// Measured on the emulator (or by the host code that stands for the thesis' CPU code).
    Measured,
    /// Computed by a model from measured counts; says which.
    Modelled(String),
    /// Not reproducible; says why. Our cells stay empty.
    NotReproducible(String),
}

/// A column of a reproduced table.
#[derive(Debug, Clone, Serialize)]
pub struct Column {
    /// Header.
    pub name: String,
    /// Unit of ours and the thesis' values.
    pub unit: Unit,
    /// How ours was obtained.
    pub source: Source,
    /// The tolerance ours is held to; `None`: shown, not compared (the note says why).
    pub tolerance: Option<Tolerance>,
    /// Why the column is not compared, or other remarks.
    pub note: Option<String>,
    /// Whether the thesis has this column.
    pub has_thesis: bool,
    /// Host timings: they vary from run to run, so baselines do not record their verdicts.
    pub timing: bool,
}

impl Column {
    /// A measured column compared with the thesis under `tolerance`.
    pub fn measured(name: &str, unit: Unit, tolerance: Tolerance) -> Column {
        Column {
            name: name.into(),
            unit,
            source: Source::Measured,
            tolerance: Some(tolerance),
            note: None,
            has_thesis: true,
            timing: false,
        }
    }

    /// A column computed by `model`, compared under `tolerance` (None: not compared, see `note`).
    pub fn modelled(name: &str, unit: Unit, model: &str, tolerance: Option<Tolerance>, note: Option<&str>) -> Column {
        Column {
            name: name.into(),
            unit,
            source: Source::Modelled(model.into()),
            tolerance,
            note: note.map(Into::into),
            has_thesis: true,
            timing: false,
        }
    }

    /// A thesis column we cannot reproduce (`why`); only the thesis' values are shown.
    pub fn not_reproducible(name: &str, unit: Unit, why: &str) -> Column {
        Column {
            name: name.into(),
            unit,
            source: Source::NotReproducible(why.into()),
            tolerance: None,
            note: Some(why.into()),
            has_thesis: true,
            timing: false,
        }
    }

    /// A column of ours the thesis does not have (context such as triangle counts).
    pub fn ours_only(name: &str, unit: Unit) -> Column {
        Column {
            name: name.into(),
            unit,
            source: Source::Measured,
            tolerance: None,
            note: None,
            has_thesis: false,
            timing: false,
        }
    }

    /// The same column, marked as a host timing.
    pub fn timing(mut self) -> Column {
        self.timing = true;
        self
    }

    /// The same column, not compared for `why` (shown only).
    pub fn uncompared(mut self, why: &str) -> Column {
        self.tolerance = None;
        self.note = Some(why.into());
        self
    }
}

/// One cell: ours, the thesis' as printed, the verdict.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Cell {
    /// Our value.
    pub ours: Option<f64>,
    /// The thesis' value as printed.
    pub thesis: Option<String>,
    /// The thesis' value as a number (the printed text read, or a mean we computed).
    pub thesis_value: Option<f64>,
    /// The verdict, for compared cells.
    pub verdict: Option<Verdict>,
}

impl Cell {
    /// Our value `ours` beside the thesis' `printed` text, with the verdict
    /// under `tolerance` where both are numbers (and the column compares).
    pub fn compared(ours: Option<f64>, printed: &str, tolerance: Option<crate::repro::compare::Tolerance>) -> Cell {
        let tv = crate::repro::compare::parse_printed(printed);
        Cell {
            ours,
            thesis: Some(printed.to_string()),
            thesis_value: tv,
            verdict: ours.zip(tv).zip(tolerance).map(|((o, t), tol)| tol.verdict(o, t)),
        }
    }
}

/// What a row is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum RowKind {
    /// One scene.
    Scene,
    /// Our mean beside the thesis' printed average; the verdict compares ours
    /// with the thesis' mean over the same scenes (the next row).
    Average,
    /// The thesis' mean over the scenes we ran (like for like).
    ThesisOurScenes,
    /// Sample standard deviations, ours and as printed.
    StdDev,
}

/// A row.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Scene name or the summary's label.
    pub label: String,
    /// What it is.
    pub kind: RowKind,
    /// One cell per column.
    pub cells: Vec<Cell>,
}

/// A qualitative finding of the thesis, checked on our numbers.
#[derive(Debug, Clone, Serialize)]
pub struct Check {
    /// The claim, as the thesis makes it.
    pub claim: String,
    /// What we measured for it.
    pub evidence: String,
    /// Whether it holds.
    pub holds: bool,
}

/// A reproduced table (or one part of a table with parts).
#[derive(Debug, Clone, Serialize)]
pub struct Table {
    /// Address, `fabianowski:4.5` (parts: `fabianowski:4.8a`).
    pub address: String,
    /// Heading: table number, title as printed, seed and lines.
    pub heading: String,
    /// Columns.
    pub columns: Vec<Column>,
    /// Rows.
    pub rows: Vec<Row>,
    /// Qualitative checks.
    pub checks: Vec<Check>,
    /// Notes printed under the table.
    pub notes: Vec<String>,
}

/// Whether table `address` is the table `of` or one of its parts (`fabianowski:4.8a`
/// of `fabianowski:4.8`). Works on bare ids too (`4.8a` of `4.8`).
pub fn is_part_of(address: &str, of: &str) -> bool {
    address == of
        || address.strip_prefix(of).is_some_and(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_lowercase()))
}

/// A published table row: our scene name and the cells as printed (`""` for blanks).
#[derive(Debug, Clone, Copy)]
pub struct PublishedRow {
    /// The scene as named in `scenes/`.
    pub scene: &'static str,
    /// The cells, exactly as printed, one per column of the published table.
    pub cells: &'static [Printed],
}

/// A published table: rows and the summary rows as printed.
#[derive(Debug, Clone, Copy)]
pub struct Published {
    /// The scene rows.
    pub rows: &'static [PublishedRow],
    /// The "Average" row (`""` where blank).
    pub average: &'static [Printed],
    /// The "Std. Dev." row.
    pub std_dev: &'static [Printed],
}

impl Published {
    /// The row of `scene`.
    pub fn row(&self, scene: &str) -> Option<&PublishedRow> {
        self.rows.iter().find(|r| r.scene == scene)
    }

    /// The scenes, in the table's order.
    pub fn scenes(&self) -> Vec<&'static str> {
        self.rows.iter().map(|r| r.scene).collect()
    }
}

fn printed_cell(p: Option<&Printed>) -> (Option<String>, Option<f64>) {
    match p {
        Some(p) if !p.0.is_empty() => (Some(p.0.to_string()), Some(p.value())),
        _ => (None, None),
    }
}

impl Table {
    /// Builds a table from our per-scene values (one per column; `NaN` where
    /// not measured) and the published table whose columns correspond one to
    /// one (`published` column `k` is ours `k`; columns with `has_thesis ==
    /// false` are skipped in the published cells). Adds the summary rows.
    pub fn compare(
        address: &str,
        heading: &str,
        columns: Vec<Column>,
        published: &Published,
        ours: &[(String, Vec<f64>)],
    ) -> Table {
        // published cell index of each of our columns
        let mut pub_index = Vec::new();
        let mut k = 0;
        for c in &columns {
            if c.has_thesis {
                pub_index.push(Some(k));
                k += 1;
            } else {
                pub_index.push(None);
            }
        }
        let mut rows = Vec::new();
        for (scene, values) in ours {
            let prow = published.row(scene);
            let cells = columns
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    let (thesis, thesis_value) =
                        printed_cell(pub_index[i].and_then(|k| prow.and_then(|r| r.cells.get(k))));
                    let ours = match c.source {
                        Source::NotReproducible(_) => None,
                        _ => values.get(i).copied().filter(|v| v.is_finite()),
                    };
                    let verdict = match (ours, thesis_value, c.tolerance) {
                        (Some(o), Some(t), Some(tol)) => Some(tol.verdict(o, t)),
                        _ => None,
                    };
                    Cell { ours, thesis, thesis_value, verdict }
                })
                .collect();
            rows.push(Row { label: scene.clone(), kind: RowKind::Scene, cells });
        }
        let any_average = columns.iter().any(|c| c.unit.averaged());
        if any_average && !rows.is_empty() {
            let n = rows.len();
            let mut avg = Vec::new();
            let mut like = Vec::new();
            let mut sd = Vec::new();
            for (i, c) in columns.iter().enumerate() {
                if !c.unit.averaged() {
                    avg.push(Cell::default());
                    like.push(Cell::default());
                    sd.push(Cell::default());
                    continue;
                }
                let mine: Vec<f64> = rows.iter().filter_map(|r| r.cells[i].ours).collect();
                let theirs: Vec<f64> = rows.iter().filter_map(|r| r.cells[i].thesis_value).collect();
                let (m, s) = if mine.len() == n { mean_sd(&mine) } else { (f64::NAN, f64::NAN) };
                let (tm, _) = if theirs.len() == n { mean_sd(&theirs) } else { (f64::NAN, f64::NAN) };
                let (pa, pav) = printed_cell(pub_index[i].and_then(|k| published.average.get(k)));
                let (ps, psv) = printed_cell(pub_index[i].and_then(|k| published.std_dev.get(k)));
                let ours_m = m.is_finite().then_some(m);
                let like_m = tm.is_finite().then_some(tm);
                let verdict = match (ours_m, like_m, c.tolerance) {
                    (Some(o), Some(t), Some(tol)) => Some(tol.verdict(o, t)),
                    _ => None,
                };
                avg.push(Cell { ours: ours_m, thesis: pa, thesis_value: pav, verdict });
                like.push(Cell {
                    ours: None,
                    thesis: like_m.map(|t| c.unit.format(t)),
                    thesis_value: like_m,
                    verdict: None,
                });
                sd.push(Cell { ours: s.is_finite().then_some(s), thesis: ps, thesis_value: psv, verdict: None });
            }
            rows.push(Row { label: "Average".into(), kind: RowKind::Average, cells: avg });
            if columns.iter().any(|c| c.unit.averaged() && c.has_thesis) {
                let label = format!("Thesis, mean of our {n} scene{}", if n == 1 { "" } else { "s" });
                rows.push(Row { label, kind: RowKind::ThesisOurScenes, cells: like });
            }
            rows.push(Row { label: "Std. Dev.".into(), kind: RowKind::StdDev, cells: sd });
        }
        Table { address: address.into(), heading: heading.into(), columns, rows, checks: Vec::new(), notes: Vec::new() }
    }

    /// Compared cells within tolerance and compared cells (checks count as cells).
    pub fn score(&self) -> (usize, usize) {
        let mut within = 0;
        let mut compared = 0;
        for r in &self.rows {
            for c in &r.cells {
                if let Some(v) = c.verdict {
                    compared += 1;
                    within += usize::from(v == Verdict::Within);
                }
            }
        }
        for c in &self.checks {
            compared += 1;
            within += usize::from(c.holds);
        }
        (within, compared)
    }

    /// The score line.
    pub fn score_line(&self) -> String {
        let (w, n) = self.score();
        if n == 0 {
            return "Score: no cell compared.".into();
        }
        let mut parts: Vec<String> = Vec::new();
        for t in self.columns.iter().filter_map(|c| c.tolerance.map(|t| t.describe())) {
            if !parts.contains(&t) {
                parts.push(t);
            }
        }
        if !self.checks.is_empty() {
            parts.push(format!("{} qualitative check(s)", self.checks.len()));
        }
        format!("Score: {w}/{n} cells within tolerance ({}).", parts.join("; "))
    }

    /// Every cell with a verdict, as (row label, column name, verdict): what
    /// the baseline file records.
    pub fn verdicts(&self) -> Vec<(String, String, Verdict)> {
        let mut v = Vec::new();
        for r in &self.rows {
            for (i, c) in r.cells.iter().enumerate() {
                if let (Some(x), false) = (c.verdict, self.columns[i].timing) {
                    v.push((r.label.clone(), self.columns[i].name.clone(), x));
                }
            }
        }
        for c in &self.checks {
            v.push(("check".into(), c.claim.clone(), if c.holds { Verdict::Within } else { Verdict::Outside }));
        }
        v
    }

    fn ours_text(&self, i: usize, c: &Cell, kind: RowKind) -> String {
        let col = &self.columns[i];
        match (&col.source, c.ours) {
            (Source::NotReproducible(_), _) if kind == RowKind::Scene => "n/r".into(),
            (_, None) => String::new(),
            (_, Some(v)) => {
                let s = if kind == RowKind::StdDev { col.unit.format_spread(v) } else { col.unit.format(v) };
                match c.verdict {
                    Some(x) => format!("{s} {}", x.mark()),
                    None => s,
                }
            }
        }
    }

    /// The table in markdown: heading, table, checks, score, notes.
    pub fn markdown(&self) -> String {
        let mut s = format!("{}\n\n| Scene |", self.heading);
        let mut ncells = 0;
        for c in &self.columns {
            if c.has_thesis {
                s.push_str(&format!(" {} | thesis |", c.name));
                ncells += 2;
            } else {
                s.push_str(&format!(" {} |", c.name));
                ncells += 1;
            }
        }
        s.push_str(&format!("\n|---|{}\n", "---|".repeat(ncells)));
        for r in &self.rows {
            s.push_str(&format!("| {} |", r.label));
            for (i, c) in r.cells.iter().enumerate() {
                let ours =
                    if r.kind == RowKind::ThesisOurScenes { String::new() } else { self.ours_text(i, c, r.kind) };
                push_cell(&mut s, &ours);
                if self.columns[i].has_thesis {
                    push_cell(&mut s, c.thesis.as_deref().unwrap_or(""));
                }
            }
            s.push('\n');
        }
        if self.rows.is_empty() {
            s.push_str("(no scene of this table was measured)\n");
        }
        s.push('\n');
        for c in &self.checks {
            s.push_str(&format!(
                "- {} {}: {}\n",
                if c.holds { Verdict::Within.mark() } else { Verdict::Outside.mark() },
                c.claim,
                c.evidence
            ));
        }
        if !self.checks.is_empty() {
            s.push('\n');
        }
        s.push_str(&self.score_line());
        s.push_str(
            " ✓/✗ beside our value: within/outside tolerance; averages are compared with the thesis' mean over our scenes.\n",
        );
        // columns that share a source or a reason are named together
        let mut groups: Vec<(String, Vec<String>)> = Vec::new();
        let add = |what: String, name: &str, groups: &mut Vec<(String, Vec<String>)>| match groups
            .iter_mut()
            .find(|(w, _)| *w == what)
        {
            Some((_, v)) => v.push(name.to_string()),
            None => groups.push((what, vec![name.to_string()])),
        };
        for c in &self.columns {
            match &c.source {
                Source::Modelled(m) => add(format!("modelled ({m})"), &c.name, &mut groups),
                Source::NotReproducible(w) => add(format!("not reproducible ({w})"), &c.name, &mut groups),
                Source::Measured => {}
            }
            if let (Some(n), false) = (&c.note, matches!(c.source, Source::NotReproducible(_))) {
                add(format!("not compared ({n})"), &c.name, &mut groups);
            }
        }
        for (what, names) in groups {
            s.push_str(&format!("{}: {what}.\n", names.join(", ")));
        }
        for n in &self.notes {
            s.push_str(n);
            s.push('\n');
        }
        s
    }

    /// The table's rows as CSV records with unique column names: `table,row,
    /// <col>,<col> thesis,<col> verdict,...`; numbers as plain numbers (percent
    /// values without the sign), empty where there is none.
    pub fn csv(&self, header: bool) -> String {
        let mut s = String::new();
        if header {
            let mut h = vec!["table".to_string(), "row".to_string()];
            for c in &self.columns {
                let unit = match c.unit {
                    Unit::Change | Unit::Percent => " (%)",
                    Unit::Points => " (pp)",
                    _ => "",
                };
                h.push(format!("{}{unit}", c.name));
                if c.has_thesis {
                    h.push(format!("{}{unit} thesis", c.name));
                    h.push(format!("{} verdict", c.name));
                }
            }
            s.push_str(&h.iter().map(|x| csv_cell(x)).collect::<Vec<_>>().join(","));
            s.push('\n');
        }
        for r in &self.rows {
            let mut f = vec![csv_cell(&self.address), csv_cell(&r.label)];
            for (i, c) in r.cells.iter().enumerate() {
                f.push(c.ours.map(|v| format!("{v}")).unwrap_or_default());
                if self.columns[i].has_thesis {
                    f.push(c.thesis_value.map(|v| format!("{v}")).unwrap_or_default());
                    f.push(
                        c.verdict.map(|v| if v == Verdict::Within { "within" } else { "outside" }).unwrap_or("").into(),
                    );
                }
            }
            s.push_str(&f.join(","));
            s.push('\n');
        }
        s
    }
}

/// ` text |`, or ` |` for an empty cell.
fn push_cell(s: &mut String, text: &str) {
    if text.is_empty() {
        s.push_str(" |");
    } else {
        s.push_str(&format!(" {text} |"));
    }
}

fn csv_cell(c: &str) -> String {
    if c.contains([',', '"', '\n']) { format!("\"{}\"", c.replace('"', "\"\"")) } else { c.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PUB: Published = Published {
        rows: &[
            PublishedRow { scene: "scene6", cells: &[Printed("7.31"), Printed("+35.7%")] },
            PublishedRow { scene: "sponza", cells: &[Printed("29.81"), Printed("+136.7%")] },
            PublishedRow { scene: "fairy", cells: &[Printed("37.43"), Printed("+182.7%")] },
        ],
        average: &[Printed(""), Printed("+118.4%")],
        std_dev: &[Printed(""), Printed("74.6%")],
    };

    fn table() -> Table {
        Table::compare(
            "t:1",
            "Table 1: test",
            vec![
                Column::measured("stack", Unit::Number(2), Tolerance::COUNT),
                Column::measured("stackless", Unit::Change, Tolerance::RATIO),
            ],
            &PUB,
            &[("scene6".into(), vec![7.5, 62.9]), ("sponza".into(), vec![37.08, 140.0])],
        )
    }

    #[test]
    fn verdicts_score_and_like_for_like_mean() {
        let t = table();
        // scene6: 7.5 vs 7.31 within; +62.9 vs +35.7 outside; sponza: 37.08 vs 29.81 outside,
        // +140.0 vs +136.7 within; average +101.45 vs like-for-like +86.2: 2.0145/1.862 = 1.082 within
        assert_eq!(t.score(), (3, 5));
        let md = t.markdown();
        assert!(md.contains("| scene6 | 7.50 ✓ | 7.31 | +62.9% ✗ | +35.7% |"), "{md}");
        assert!(md.contains("| Average | | | +101.5% ✓ | +118.4% |"), "{md}");
        assert!(md.contains("| Thesis, mean of our 2 scenes | | | | +86.2% |"), "{md}");
        assert!(md.contains("Score: 3/5 cells within tolerance"), "{md}");
    }

    #[test]
    fn csv_has_numeric_cells_and_unique_names() {
        let c = table().csv(true);
        let mut lines = c.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let mut uniq = header.clone();
        uniq.sort();
        uniq.dedup();
        assert_eq!(uniq.len(), header.len(), "{header:?}");
        assert_eq!(lines.next().unwrap(), "t:1,scene6,7.5,7.31,within,62.9,35.7,outside");
    }
}
