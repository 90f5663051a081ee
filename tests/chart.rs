//! `warplight chart`: the values plotted in the SVG, read back through the
//! pixel mapping the SVG states in its `warplight-chart` comment, equal the
//! table's and the JSON's to within half a pixel; PNGs are valid images of the
//! size asked for; names other than .svg/.png fail and write nothing.

mod support;
use support::warplight;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use warplight::repro::compare::Tolerance;
use warplight::repro::results::Results;
use warplight::repro::table::{RowKind, Table, Unit};

const OURS: &str = "#0072B2";
const THESIS: &str = "#E69F00";
const BAND: &str = "#999999";
/// Okabe–Ito, in the order series take them.
const PALETTE: [&str; 9] =
    ["#0072B2", "#E69F00", "#009E73", "#D55E00", "#56B4E9", "#CC79A7", "#F0E442", "#000000", "#8C564B"];

fn tempdir() -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    let d = std::env::temp_dir().join(format!(
        "warplight-chart-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small results file: Table 4.5 on scene6, 2 frames at 16x16 (about a second in release).
fn results() -> &'static Path {
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| {
        let f = tempdir().join("r.json");
        let (ok, _, err) = warplight(&[
            "tables",
            "fabianowski:4.5",
            "--frames",
            "2",
            "--resolution",
            "16",
            "--scenes",
            "scene6",
            "--out",
            f.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        f
    })
}

/// The pixel mapping an SVG states.
#[derive(Debug)]
struct Meta {
    kind: String,
    x_pixels: (f64, f64),
    y_pixels: (f64, f64),
    x_range: (f64, f64),
    y_range: (f64, f64),
    log_x: bool,
    log_y: bool,
}

fn pair(s: &str) -> (f64, f64) {
    let (a, b) = s.split_once(',').unwrap();
    (a.parse().unwrap(), b.parse().unwrap())
}

fn meta(svg: &str) -> Meta {
    let start = svg.find("<!-- warplight-chart ").expect("the SVG states its pixel mapping");
    // right after the opening <svg ...> tag
    assert!(svg[..start].trim_end().ends_with('>') && svg[..start].matches('<').count() == 1, "{}", &svg[..start]);
    let end = start + svg[start..].find("-->").unwrap();
    let kv: HashMap<&str, &str> = svg[start + 21..end].split_whitespace().map(|w| w.split_once('=').unwrap()).collect();
    Meta {
        kind: kv["kind"].into(),
        x_pixels: pair(kv["x-pixels"]),
        y_pixels: pair(kv["y-pixels"]),
        x_range: pair(kv["x-range"]),
        y_range: pair(kv["y-range"]),
        log_x: kv["x-scale"] == "log",
        log_y: kv["y-scale"] == "log",
    }
}

fn axis(v: f64, (lo, hi): (f64, f64), (p0, p1): (f64, f64), log: bool) -> f64 {
    let f = |x: f64| if log { x.log10() } else { x };
    p0 + (f(v) - f(lo)) / (f(hi) - f(lo)) * (p1 - p0)
}

fn unaxis(p: f64, (lo, hi): (f64, f64), (p0, p1): (f64, f64)) -> f64 {
    lo + (p - p0) / (p1 - p0) * (hi - lo)
}

impl Meta {
    fn x(&self, v: f64) -> f64 {
        axis(v, self.x_range, self.x_pixels, self.log_x)
    }
    fn y(&self, v: f64) -> f64 {
        axis(v, self.y_range, self.y_pixels, self.log_y)
    }
    /// The y value at pixel row `p` (linear axes).
    fn y_value(&self, p: f64) -> f64 {
        assert!(!self.log_y);
        unaxis(p, self.y_range, self.y_pixels)
    }
    /// Half a pixel's worth of y.
    fn half_pixel_y(&self) -> f64 {
        0.5 * (self.y_range.1 - self.y_range.0).abs() / (self.y_pixels.1 - self.y_pixels.0).abs()
    }
    /// Whether (x, y) lies in the plot area (the legend lies above it).
    fn inside(&self, x: f64, y: f64) -> bool {
        let (x0, x1) = self.x_pixels;
        let (y0, y1) = (self.y_pixels.0.max(self.y_pixels.1), self.y_pixels.0.min(self.y_pixels.1));
        x >= x0 - 0.5 && x <= x1 + 0.5 && y <= y0 + 0.5 && y >= y1 - 0.5
    }
}

/// The attributes of every `<tag .../>` of the SVG, in order.
fn elements(svg: &str, tag: &str) -> Vec<HashMap<String, String>> {
    let open = format!("<{tag} ");
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find(&open) {
        let body = &rest[i + open.len()..];
        let end = body.find('>').unwrap();
        let mut attrs = HashMap::new();
        let mut s = &body[..end];
        while let Some(eq) = s.find("=\"") {
            let key = s[..eq].trim().to_string();
            let close = s[eq + 2..].find('"').unwrap();
            attrs.insert(key, s[eq + 2..eq + 2 + close].to_string());
            s = &s[eq + 2 + close + 1..];
        }
        out.push(attrs);
        rest = &body[end..];
    }
    out
}

fn num(a: &HashMap<String, String>, k: &str) -> f64 {
    a[k].parse().unwrap_or_else(|_| panic!("{k} = {}", a[k]))
}

/// Filled rects of colour `fill` inside the plot area: (x, y, width, height).
fn rects(svg: &str, m: &Meta, fill: &str) -> Vec<(f64, f64, f64, f64)> {
    elements(svg, "rect")
        .iter()
        .filter(|a| a["fill"] == fill)
        .map(|a| (num(a, "x"), num(a, "y"), num(a, "width"), num(a, "height")))
        .filter(|&(x, y, w, h)| m.inside(x + w / 2.0, y + h / 2.0))
        .collect()
}

/// Filled circles of colour `fill` inside the plot area: (cx, cy).
fn circles(svg: &str, m: &Meta, fill: &str) -> Vec<(f64, f64)> {
    elements(svg, "circle")
        .iter()
        .filter(|a| a["fill"] == fill)
        .map(|a| (num(a, "cx"), num(a, "cy")))
        .filter(|&(x, y)| m.inside(x, y))
        .collect()
}

fn table_45() -> Table {
    let r = Results::read(results()).unwrap();
    let tables = warplight::cli::tables::render(&r).unwrap();
    tables.into_iter().find(|t| t.address == "fabianowski:4.5").expect("Table 4.5 in the results")
}

/// The band the chart must draw: the thesis' value ± the tolerance in the column's units.
fn expected_band(tol: Tolerance, t: f64) -> (f64, f64) {
    let (a, b) = match tol {
        Tolerance::Relative(f) => (t * (1.0 - f), t * (1.0 + f)),
        Tolerance::Factor(f) => {
            ((1.0 + t / 100.0) * (1.0 - f) * 100.0 - 100.0, (1.0 + t / 100.0) * (1.0 + f) * 100.0 - 100.0)
        }
        Tolerance::Points(p) => (t - p, t + p),
    };
    (a.min(b), a.max(b))
}

/// (ours, thesis, band) per group: the compared cells of the scene rows in columns `rel` (or absolute ones).
type Group = (Option<f64>, Option<f64>, Option<(f64, f64)>);

fn expected_groups(t: &Table, rel: bool) -> Vec<Group> {
    let mut g = Vec::new();
    for r in t.rows.iter().filter(|r| r.kind == RowKind::Scene) {
        for (c, cell) in t.columns.iter().zip(&r.cells) {
            let is_rel = matches!(c.unit, Unit::Change | Unit::Points);
            if c.tolerance.is_none() || !c.has_thesis || is_rel != rel {
                continue;
            }
            if cell.ours.is_none() && cell.thesis_value.is_none() {
                continue;
            }
            g.push((cell.ours, cell.thesis_value, cell.thesis_value.map(|v| expected_band(c.tolerance.unwrap(), v))));
        }
    }
    g
}

/// Reads the bars of an SVG back into (ours, thesis, band) per group.
fn read_bars(svg: &str) -> (Meta, Vec<Group>) {
    let m = meta(svg);
    assert_eq!(m.kind, "bars");
    let n = m.x_range.1 as usize;
    assert_eq!(m.x_range.0, 0.0);
    let slot = |x: f64| ((x - m.x_pixels.0) / (m.x_pixels.1 - m.x_pixels.0) * n as f64).floor() as usize;
    let zero = m.y(0.0).round();
    let mut groups: Vec<Group> = vec![(None, None, None); n];
    for (colour, which) in [(OURS, 0), (THESIS, 1)] {
        for (x, y, w, h) in rects(svg, &m, colour) {
            let g = slot(x + w / 2.0);
            // the edge away from the zero line is the value
            let edge = if (y - zero).abs() >= (y + h - zero).abs() { y } else { y + h };
            let v = m.y_value(edge);
            let cell = &mut groups[g];
            let prev = if which == 0 { cell.0.replace(v) } else { cell.1.replace(v) };
            assert!(prev.is_none(), "two bars of one series in group {g}");
        }
    }
    for (x, y, w, h) in rects(svg, &m, BAND) {
        let g = slot(x + w / 2.0);
        assert!(groups[g].2.replace((m.y_value(y + h), m.y_value(y))).is_none(), "two bands in group {g}");
    }
    (m, groups)
}

fn close(got: Option<f64>, want: Option<f64>, tol: f64, what: &str) {
    match (got, want) {
        (None, None) => {}
        (Some(g), Some(w)) => assert!((g - w).abs() <= tol + 1e-9, "{what}: plotted {g}, table {w} (± {tol})"),
        _ => panic!("{what}: plotted {got:?}, table {want:?}"),
    }
}

#[test]
fn table_chart_plots_the_tables_values() {
    let dir = tempdir();
    let out = dir.join("t45.svg");
    let (ok, _, err) = warplight(&[
        "chart",
        "table",
        "fabianowski:4.5",
        "--from",
        results().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("wrote"), "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"));
    let t = table_45();
    // Table 4.5 compares relative columns (changes): those are charted by default
    let want = expected_groups(&t, true);
    assert_eq!(want.len(), 4, "scene6 x Stackless, push-down, short-stack, push-down + short-stack");
    let (m, got) = read_bars(&svg);
    let half = m.half_pixel_y();
    assert!(half < 0.5, "a pixel is {} %: too coarse to check", 2.0 * half);
    assert_eq!(got.len(), want.len());
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        close(g.0, w.0, half, &format!("group {i} ours"));
        close(g.1, w.1, half, &format!("group {i} thesis"));
        close(g.2.map(|b| b.0), w.2.map(|b| b.0), half, &format!("group {i} band low"));
        close(g.2.map(|b| b.1), w.2.map(|b| b.1), half, &format!("group {i} band high"));
    }
    // the legend and the group labels
    for s in ["ours", "thesis", "scene6 / Stackless", "scene6 / push-down + short-stack"] {
        assert!(svg.contains(&format!(">\n{s}\n</text>")), "{s}");
    }

    // the absolute column (Stack-based: inner nodes per ray, ±5 % relative)
    let out = dir.join("t45-abs.svg");
    let (ok, _, err) = warplight(&[
        "chart",
        "table",
        "4.5",
        "--from",
        results().to_str().unwrap(),
        "--columns",
        "abs",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (m, got) = read_bars(&std::fs::read_to_string(&out).unwrap());
    let want = expected_groups(&t, false);
    assert_eq!((got.len(), want.len()), (1, 1));
    let half = m.half_pixel_y();
    close(got[0].0, want[0].0, half, "ours");
    close(got[0].1, want[0].1, half, "thesis");
    close(got[0].2.map(|b| b.0), want[0].2.map(|b| b.0), half, "band low");
    close(got[0].2.map(|b| b.1), want[0].2.map(|b| b.1), half, "band high");
}

#[test]
fn flight_chart_plots_each_frame() {
    let dir = tempdir();
    let out = dir.join("flight.svg");
    let (ok, _, err) = warplight(&[
        "chart",
        "flight",
        "--from",
        results().to_str().unwrap(),
        "--counter",
        "inner_nodes",
        "--per-ray",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    let m = meta(&svg);
    assert_eq!(m.kind, "lines");
    let r = Results::read(results()).unwrap();
    let group = "fabianowski/traversal";
    let mut variants: Vec<&str> = r.samples.iter().filter(|s| s.group == group).map(|s| s.variant.as_str()).collect();
    variants.dedup();
    variants.sort();
    variants.dedup();
    assert!(variants.len() >= 2, "{variants:?}");
    for (k, v) in variants.iter().enumerate() {
        let nodes = r.per_frame(group, "scene6", v, "inner_nodes");
        let rays = r.per_frame(group, "scene6", v, "rays");
        let want: Vec<(f64, f64)> = nodes.iter().zip(&rays).map(|(a, b)| (f64::from(a.0), a.1 / b.1)).collect();
        assert_eq!(want.len(), 2);
        let got = circles(&svg, &m, PALETTE[k]);
        assert_eq!(got.len(), want.len(), "{v}");
        for ((cx, cy), (x, y)) in got.iter().zip(&want) {
            assert!(
                (cx - m.x(*x)).abs() <= 0.5 + 1e-9 && (cy - m.y(*y)).abs() <= 0.5 + 1e-9,
                "{v}: ({cx}, {cy}) for ({x}, {y})"
            );
        }
        assert!(svg.contains(&format!(">\n{v}\n</text>")), "legend names {v}");
    }
    // an unknown counter lists the measured ones
    let (ok, _, err) =
        warplight(&["chart", "flight", "--from", results().to_str().unwrap(), "--counter", "nope", "-o", "x.svg"]);
    assert!(!ok && err.contains("no counter `nope`") && err.contains("inner_nodes"), "{err}");
}

#[test]
fn scatter_chart_plots_the_json_points() {
    let dir = tempdir();
    let out = dir.join("scatter.svg");
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/scatter.json");
    let (ok, _, err) = warplight(&["chart", "scatter", fixture, "-o", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    let m = meta(&svg);
    assert_eq!(m.kind, "scatter");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(fixture).unwrap()).unwrap();
    assert_eq!((m.log_x, m.log_y), (json["log_x"].as_bool().unwrap(), json["log_y"].as_bool().unwrap()));
    let series = json["series"].as_array().unwrap();
    assert!(series.len() >= 3);
    for (k, s) in series.iter().enumerate() {
        let want: Vec<(f64, f64)> =
            s["points"].as_array().unwrap().iter().map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap())).collect();
        let got = circles(&svg, &m, PALETTE[k]);
        assert_eq!(got.len(), want.len(), "{}", s["name"]);
        for ((cx, cy), (x, y)) in got.iter().zip(&want) {
            // half a pixel either way, on the log scales the SVG states
            assert!((cx - m.x(*x)).abs() <= 0.5 + 1e-9, "{}: x {cx} for {x} (expected {})", s["name"], m.x(*x));
            assert!((cy - m.y(*y)).abs() <= 0.5 + 1e-9, "{}: y {cy} for {y} (expected {})", s["name"], m.y(*y));
        }
        assert!(svg.contains(&format!(">\n{}\n</text>", s["name"].as_str().unwrap())), "legend");
    }
}

#[test]
fn png_is_a_png_of_the_size_asked() {
    let dir = tempdir();
    let out = dir.join("t45.png");
    let (ok, _, err) = warplight(&[
        "chart",
        "table",
        "4.5",
        "--from",
        results().to_str().unwrap(),
        "--size",
        "800x450",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (800, 450));
    // ours' blue and the thesis' orange are there, and text: only glyph edges are antialiased greys
    let has = |rgb: [u8; 3]| img.pixels().any(|p| p.0 == rgb);
    assert!(has([0x00, 0x72, 0xB2]) && has([0xE6, 0x9F, 0x00]));
    let dark = img.pixels().filter(|p| p.0.iter().all(|&c| c < 80)).count();
    let grey = img.pixels().filter(|p| p.0.iter().all(|&c| (100..200).contains(&c))).count();
    assert!(dark > 500 && grey > 1000, "text drawn: {dark} dark, {grey} antialiased pixels");
    // the scatter plot as PNG at the default size
    let out = dir.join("s.png");
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/scatter.json");
    let (ok, _, err) = warplight(&["chart", "scatter", fixture, "-o", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert_eq!(image::open(&out).unwrap().to_rgb8().dimensions(), (960, 540));
}

#[test]
fn bad_names_fail_and_write_nothing() {
    let dir = tempdir();
    let from = results().to_str().unwrap();
    let jpg = dir.join("t.jpg");
    let (ok, _, err) = warplight(&["chart", "table", "4.5", "--from", from, "-o", jpg.to_str().unwrap()]);
    assert!(!ok && err.contains("t.jpg") && err.contains(".svg or .png"), "{err}");
    let none = dir.join("t");
    let (ok, _, err) = warplight(&["chart", "scatter", "tests/fixtures/scatter.json", "-o", none.to_str().unwrap()]);
    assert!(!ok && err.contains("no extension"), "{err}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
    // a table the results do not have, a results file that does not exist, JSON that is no chart
    let (ok, _, err) = warplight(&["chart", "table", "4.7", "--from", from, "-o", "x.svg"]);
    assert!(!ok && err.contains("4.7: not among the tables of") && err.contains("fabianowski:4.5"), "{err}");
    let (ok, _, err) = warplight(&["chart", "table", "4.5", "--from", "no-such.json", "-o", "x.svg"]);
    assert!(!ok && err.contains("no-such.json"), "{err}");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\"title\": 3}").unwrap();
    let (ok, _, err) =
        warplight(&["chart", "scatter", bad.to_str().unwrap(), "-o", dir.join("b.svg").to_str().unwrap()]);
    assert!(!ok && err.contains("bad.json: not a scatter chart"), "{err}");
    let (ok, _, err) = warplight(&["chart", "scatter", "tests/fixtures/scatter.json", "--size", "big", "-o", "x.svg"]);
    assert!(!ok && err.contains("--size big"), "{err}");
    assert!(!Path::new("x.svg").exists());
}

#[test]
fn docs_charts_are_current() {
    // the charts in docs/images/ are drawn by tools/charts.sh (tools/regen-docs.sh runs it), never by hand
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let results = root.join("docs/results/fabianowski-quick.json");
    let dir = tempdir();
    let mut charts =
        vec![("docs/images/speed-accuracy-example.svg", vec!["chart", "scatter", "tests/fixtures/scatter.json"])];
    if results.exists() {
        charts.push((
            "docs/images/chart-4.5.svg",
            vec!["chart", "table", "fabianowski:4.5", "--from", "docs/results/fabianowski-quick.json"],
        ));
    }
    for (doc, args) in charts {
        let out = dir.join("c.svg");
        let mut args = args.clone();
        args.extend(["-o", out.to_str().unwrap()]);
        let (ok, _, err) = warplight(&args);
        assert!(ok, "{err}");
        let have = std::fs::read_to_string(root.join(doc)).unwrap_or_default();
        assert!(have == std::fs::read_to_string(&out).unwrap(), "{doc} is stale: run tools/charts.sh");
    }
}

/// Nine series (eight methods and a reference line, as the rough box's
/// roulette chart has) take nine colours: the ninth is the palette's brown,
/// neither the first series' blue again nor the tolerance band's grey.
#[test]
fn nine_series_take_nine_colours() {
    assert!(!PALETTE.contains(&BAND), "a series drawn in the tolerance band's colour");
    let dir = tempdir();
    let series: Vec<serde_json::Value> = (0..9)
        .map(|k| serde_json::json!({"name": format!("s{k}"), "points": [[1.0 + k as f64, 1.0 + k as f64]]}))
        .collect();
    let data = serde_json::json!({
        "title": "nine", "x_label": "x", "y_label": "y", "log_x": false, "log_y": false, "connect": false,
        "series": series
    });
    let input = dir.join("nine.json");
    std::fs::write(&input, data.to_string()).unwrap();
    let out = dir.join("nine.svg");
    let (ok, _, err) = warplight(&["chart", "scatter", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    let m = meta(&svg);
    for (k, colour) in PALETTE.iter().enumerate() {
        let got = circles(&svg, &m, colour);
        assert_eq!(got.len(), 1, "series {k} ({colour}): {got:?}");
        assert!((got[0].0 - m.x(1.0 + k as f64)).abs() <= 0.5 + 1e-9, "series {k}");
    }
}
